# SPDX-License-Identifier: Apache-2.0
# Quick start: `make bench` (grid benchmark + figures) and `make test` (every test).
# Both install what they need: Debian packages via apt-get, Python packages into .venv.

SHELL := /bin/bash
PYTHON ?= python3
VENV := .venv
VPY := $(VENV)/bin/python
APT_PACKAGES := cmake ninja-build gcc libc6-dev python3 python3-venv git \
  gcc-arm-none-eabi libnewlib-arm-none-eabi qemu-system-arm binutils-arm-none-eabi \
  clang libclang-rt-14-dev cppcheck clang-tidy
SUDO := $(shell [ "$$(id -u)" = 0 ] || echo sudo)
# Unity (the C test framework): empty, CMake fetches v2.6.1 from GitHub; else a local copy of that
# release (offline builds), given to the configures that build the C tests (release, debug-asan;
# the fuzz preset builds none) as FETCHCONTENT_SOURCE_DIR_UNITY.
UNITY_DIR ?=
CMAKE_UNITY = $(if $(UNITY_DIR),-DFETCHCONTENT_SOURCE_DIR_UNITY=$(abspath $(UNITY_DIR)))
BENCH_PROFILE ?= default
# The default profile writes results/bench and docs/figures; any other profile its own directories
# (results/paper, docs/figures/paper), so the profiles never overwrite each other.
BENCH_SUFFIX = $(if $(filter default,$(BENCH_PROFILE)),,/$(BENCH_PROFILE))
BENCH_OUT ?= results/$(if $(BENCH_SUFFIX),$(BENCH_PROFILE),bench)
BENCH_FIGURES ?= docs/figures$(BENCH_SUFFIX)
# The summary docs/results.md's tables come from (python -m icoac.tools.results_tables --update).
BENCH_DATA ?= docs/data/bench-$(BENCH_PROFILE).json
# Plants the bench runs (harness/icoac/core/plants.py; `all`: every plant the controller build takes). The
# cart-pole writes the directories above, another plant P their names with -P (results, data) or
# /P (figures) added.
BENCH_PLANTS ?= cart_pole
# `make fuzz`: seconds per target, targets run at once, extra libFuzzer options, and the ledger
# (one <target>.tsv each, committed, so that a campaign adds up across checkouts);
# `make fuzz-campaign`: hours of wall time and the longest run, in seconds.
FUZZ_TIME ?= 600
FUZZ_HOURS ?= 2
FUZZ_CHUNK ?= 1800
FUZZ_JOBS ?= 2
FUZZ_FLAGS ?=
FUZZ_LEDGER ?= tests/fuzz/ledger
# The C sources a fuzzing run tests (the id of their git trees, "-modified" for uncommitted
# changes): the ledger adds up only runs of the same sources.
FUZZ_C_SOURCES = firmware sim_host $(wildcard tests/fuzz/*.c tests/fuzz/*.h)
FUZZ_SOURCES = $(shell git ls-tree HEAD $(FUZZ_C_SOURCES) 2>/dev/null | git hash-object --stdin | \
  cut -c1-12)$(shell git diff --quiet HEAD -- $(FUZZ_C_SOURCES) 2>/dev/null || echo -modified)
FUZZ_TARGETS := fuzz_controller fuzz_controller_double fuzz_controller_fast_exp fuzz_state fuzz_state_double fuzz_state_mcu fuzz_model fuzz_batch

.PHONY: all deps venv build dist build-asan build-fuzz lint test test-c test-asan test-python test-baselines limited-bench baselines baselines-tuned baselines-venv test-fuzz fuzz fuzz-campaign fuzz-ledger bench tuning tuning-baselines ablation \
  bench-speed clean target-report sweeps sweeps-rl-alone sweeps-plants bench-plant

all: build

# System packages, installed only when one is missing.
deps:
	@missing=""; for p in $(APT_PACKAGES); do dpkg -s $$p >/dev/null 2>&1 || missing="$$missing $$p"; done; \
	if [ -n "$$missing" ]; then \
	  echo "installing Debian packages:$$missing"; \
	  $(SUDO) apt-get update -qq && DEBIAN_FRONTEND=noninteractive $(SUDO) apt-get install -y -qq --no-install-recommends $$missing; \
	fi

# Project venv; reinstalled when pyproject.toml changes. It gets the dependencies listed in
# pyproject.toml (with the test extra) and this checkout on its path (a .pth file, behind the
# current directory, so that a worktree's own harness/ wins) plus an `icoac` script;
# the library is the `make build` one. No wheel is built here (`pip install .` builds one: README).
VENV_SITE = $$($(VPY) -c 'import sysconfig; print(sysconfig.get_path("purelib"))')
venv: $(VENV)/.installed
$(VENV)/.installed: pyproject.toml | deps
	@[ -x $(VPY) ] || $(PYTHON) -m venv $(VENV)
	$(VPY) -m pip install -q --upgrade pip
	@# the setuptools editable install of before, and its metadata in the checkout
	@$(VPY) -m pip uninstall -q -y icoac 2>/dev/null || true; rm -rf icoac.egg-info
	$(VPY) -c 'import tomllib; p = tomllib.load(open("pyproject.toml", "rb"))["project"]; \
	  print("\n".join(p["dependencies"] + p["optional-dependencies"]["test"]))' > $(VENV)/requirements.txt
	$(VPY) -m pip install -q -r $(VENV)/requirements.txt
	@echo "$(CURDIR)/harness" > $(VENV_SITE)/icoac-checkout.pth
	@printf '#!%s\nfrom icoac.cli import main\nraise SystemExit(main())\n' "$(CURDIR)/$(VPY)" > $(VENV)/bin/icoac
	@chmod +x $(VENV)/bin/icoac
	@touch $@

build: deps
	cmake --preset release $(CMAKE_UNITY) >/dev/null
	cmake --build --preset release

# The library-only release archive build/release/dist/icoac-<version>.tar.gz (docs/porting.md).
dist: deps
	cmake --preset release >/dev/null
	cmake --build --preset release --target icoac_dist

build-asan: deps
	cmake --preset debug-asan $(CMAKE_UNITY) >/dev/null
	cmake --build --preset debug-asan

test-asan: build-asan
	ctest --preset debug-asan

test-c: build
	ctest --preset release

# Every Python test, the slow wheel build of tests/python/test_wheel.py too (about 30 s; skipped,
# with its reason, when pip cannot reach a package index); PYTEST_ARGS='-m "not slow"' leaves it out.
PYTEST_ARGS ?=
test-python: build venv
	$(VPY) -m pytest -q tests/python -m "not baselines" $(PYTEST_ARGS)

# The [baselines] extra (Stable-Baselines3 with torch: about 3 GB), installed once into .venv.
baselines-venv: $(VENV)/.baselines
$(VENV)/.baselines: $(VENV)/.installed
	$(VPY) -m pip install -q "$$($(VPY) -c 'import tomllib; \
	  print(tomllib.load(open("pyproject.toml", "rb"))["project"]["optional-dependencies"]["baselines"][0])')"
	@touch $@

# The smoke tests of the PPO and SAC adapters (marker baselines), which need that extra.
test-baselines: build baselines-venv
	$(VPY) -m pytest -q tests/python -m baselines $(PYTEST_ARGS)

# The learners' bench of PLANT held to its actuator's limit (`--limited`: the cart-pole's +-10 N of
# Barto et al., the double pendulum's 25 N, as their C files give them), which PPO and SAC pair
# with; the Furuta's default bench (`make bench BENCH_PLANTS=furuta`) is at its +-10 V already.
# BENCH_ARGS=--resume continues a stopped bench.
LIMIT_TAG_cart_pole := 10N
LIMIT_TAG_double_cart_pole := 25N
LIMITED_OUT = results/bench-$(PLANT)-$(LIMIT_TAG_$(PLANT))
limited-bench: build venv
	@[ -n "$(LIMIT_TAG_$(PLANT))" ] || { echo "limited-bench: $(PLANT) has no limited variant (its default is its limit)"; exit 2; }
	$(VPY) -m icoac bench --plant $(PLANT) --out $(LIMITED_OUT) --limited --figures $(LIMITED_OUT)/figures \
	  --data docs/data/bench-default-$(PLANT)-$(LIMIT_TAG_$(PLANT)).json $(BENCH_ARGS)

# PPO and SAC at the RL Zoo's settings (docs/results.md, "PPO and SAC") on the cart-pole at +-10 N
# (its limited bench runs first) and on the Furuta, paired with those learners' grids. They resume
# by themselves and train BASELINE_JOBS runs at once (one core each).
BASELINE_JOBS ?= $(shell nproc)
baselines: build baselines-venv
	$(MAKE) --no-print-directory limited-bench PLANT=cart_pole
	$(VPY) -m icoac.tools.rl_baselines --plant cart_pole --limited --out results/rl-baselines-cart_pole-10N \
	  --bench results/bench-cart_pole-10N --data docs/data/rl-baselines-cart_pole-10N.json --jobs $(BASELINE_JOBS)
	$(VPY) -m icoac.tools.rl_baselines --plant furuta --out results/rl-baselines-furuta \
	  --bench $(BENCH_OUT)-furuta --data docs/data/rl-baselines-furuta.json --jobs $(BASELINE_JOBS)

# The held-out tuning of PPO and SAC on PLANT held to its actuator's limit (docs/tuning.md),
# resumable; its ranking in results/rl-baselines-tuning-$(PLANT)/tuning.json.
tuning-baselines: build baselines-venv
	$(VPY) -m icoac.tools.rl_baselines --plant $(PLANT) --limited --tune \
	  --out results/rl-baselines-tuning-$(PLANT) --jobs $(BASELINE_JOBS) \
	  --data docs/data/rl-baselines-tuning-$(PLANT).json

# PPO and SAC on PLANT with the choices of that finished tuning, evaluated as `make baselines` does
# (every cell, the evaluation seeds), paired with the learners' grids at the same limit where they
# are there (else `--report` adds the pairing later without training again): the limited bench of
# the cart-pole and the double pendulum (whose learners were tuned without the limit), the Furuta's
# learners at their held-out choices (`python -m icoac.tools.heldout_tuning --plant furuta
# --evaluate`, docs/tuning.md). BASELINE_ARGS: more options (`--algos ppo`, `--seeds 0 1 2`).
BASELINE_BENCH_cart_pole := results/bench-cart_pole-10N
BASELINE_BENCH_furuta := results/tuning-furuta/evaluation/bench
BASELINE_BENCH_double_cart_pole := results/bench-double_cart_pole-25N
baselines-tuned: build baselines-venv
	$(VPY) -m icoac.tools.rl_baselines --plant $(PLANT) --limited \
	  --tuned docs/data/rl-baselines-tuning-$(PLANT).json --out results/rl-baselines-tuned-$(PLANT) \
	  --bench $(BASELINE_BENCH_$(PLANT)) --jobs $(BASELINE_JOBS) --data docs/data/rl-baselines-tuned-$(PLANT).json \
	  $(BASELINE_ARGS)

build-fuzz: deps
	cmake --preset fuzz >/dev/null
	cmake --build --preset fuzz

# Each fuzz target over its committed corpus, then a short fuzzing run (tests/fuzz).
test-fuzz: build-fuzz
	ctest --preset fuzz

# Static analysis of the library (firmware/lint/run.py): gcc -fanalyzer and clang-tidy clean, cppcheck's
# MISRA C:2012 findings within the record of docs/misra.md; every variant of the library.
lint: deps
	$(PYTHON) firmware/lint/run.py

test: lint test-asan test-c test-python test-fuzz

# Long fuzzing: FUZZ_TIME s per target, FUZZ_JOBS at a time, from tests/fuzz/corpus/<target>;
# new inputs, logs and crash reproducers go to build/fuzz/work/<target>/, a line per run to
# $(FUZZ_LEDGER)/<target>.tsv.
fuzz: build-fuzz
	@printf '%s\n' $(FUZZ_TARGETS) | ICOAC_FUZZ_SOURCES=$(FUZZ_SOURCES) xargs -P $(FUZZ_JOBS) -I '{}' \
	  env ICOAC_FUZZ_LEDGER=$(FUZZ_LEDGER)/'{}'.tsv \
	  sh tests/fuzz/run_fuzzer.sh fuzz $(FUZZ_TIME) build/fuzz/tests/fuzz/'{}' tests/fuzz/corpus/'{}' \
	  build/fuzz/work/'{}' $(FUZZ_FLAGS)
	@$(PYTHON) tests/fuzz/ledger.py $(FUZZ_LEDGER) $(FUZZ_SOURCES)

# Fuzz the targets short of 1e7 executions of the current sources, FUZZ_JOBS at a time, in runs of
# at most FUZZ_CHUNK s, for FUZZ_HOURS (tests/fuzz/campaign.py); each run adds its ledger line.
fuzz-campaign: build-fuzz
	@$(PYTHON) tests/fuzz/campaign.py --sources $(FUZZ_SOURCES) --ledger $(FUZZ_LEDGER) --build build/fuzz/tests/fuzz \
	  --corpus tests/fuzz/corpus --work build/fuzz/work --hours $(FUZZ_HOURS) --jobs $(FUZZ_JOBS) \
	  --chunk $(FUZZ_CHUNK) $(FUZZ_TARGETS)

# What every long fuzzing run of the current sources adds up to, per target.
fuzz-ledger:
	@$(PYTHON) tests/fuzz/ledger.py $(FUZZ_LEDGER) $(FUZZ_SOURCES)

# The speed figures, after the plain-C reference tick; `make bench` records them in
# $(BENCH_OUT)/bench.json (key "speed").
bench-speed: build
	mkdir -p $(BENCH_OUT)
	./build/release/sim_host/reference_tick
	./build/release/sim_host/icoac_bench --json $(BENCH_OUT)/speed.json

# BENCH_ARGS: more bench options, e.g. BENCH_ARGS=--resume to continue a stopped run.
# Per plant (bench-plant), the linear-policy ceiling first (about 40 s; a rerun replays its
# cached search), its retries capped as the profile's learners, then the bench, which shows it in
# summary.md and Fig. 3a.
bench: build venv bench-speed
	@plants="$(BENCH_PLANTS)"; \
	if [ "$$plants" = all ]; then plants=$$($(VPY) -c 'from icoac.core.plants import PLANTS; print(" ".join(PLANTS))'); fi; \
	for p in $$plants; do $(MAKE) --no-print-directory bench-plant PLANT=$$p || exit 1; done

PLANT ?= cart_pole
PLANT_OUT = $(if $(filter cart_pole,$(PLANT)),$(BENCH_OUT),$(BENCH_OUT)-$(PLANT))
PLANT_FIGURES = $(if $(filter cart_pole,$(PLANT)),$(BENCH_FIGURES),$(BENCH_FIGURES)/$(PLANT))
PLANT_DATA = $(if $(filter cart_pole,$(PLANT)),$(BENCH_DATA),$(basename $(BENCH_DATA))-$(PLANT).json)
bench-plant:
	$(VPY) -m icoac ceiling --plant $(PLANT) --profile $(BENCH_PROFILE) --out $(PLANT_OUT)/ceiling --quiet
	$(VPY) -m icoac bench --plant $(PLANT) --profile $(BENCH_PROFILE) --out $(PLANT_OUT) \
	  --figures $(PLANT_FIGURES) --data $(PLANT_DATA) $(BENCH_ARGS)

# The learner sweeps that chose the defaults (docs/results.md), on the ICO grid of seed 0 of a
# bench (make bench first); resumable, summary in $(SWEEP_OUT)/summary.md.
SWEEP_OUT ?= results/sweeps
SWEEP_ICO ?= $(BENCH_OUT)/ico/seed-0
SWEEP = $(VPY) -m icoac.tools.learner_sweeps --prior-from $(SWEEP_ICO) --out $(SWEEP_OUT)
sweeps: build venv
	$(SWEEP)
	$(SWEEP) --stage 2 --only ico-rl-stage2 --only ico-rl-schedule-grid --only ico-rl-schedule-grid2 \
	  --only ico-rl-noise-grid --base actor.update=gradient --base actor.rate=0.001
	$(SWEEP) --stage 2 --only rl-stage2 --only rl-schedule-grid --only rl-noise-grid --only rl-noise-grid2 \
	  --only rl-noise-grid3 --base actor.update=mean --base actor.likelihood_std=0.1
	$(SWEEP) --report
	cp $(SWEEP_OUT)/summary.md docs/sweeps.md

# RL alone's own sweep (N(0, sigma_w^2 I), nothing from ICO; the ICO grid only names the
# ICO-failed cells): stage 1, readings x sigma_w; stage 2 one at a time around its choice
# (RL_ALONE_BASE), the schedule grid, the noise grid at the schedule's choice (RL_ALONE_SCHEDULE);
# then 5-seed grids of every cell for the best 3 settings (--confirm).
RL_ALONE_OUT ?= results/sweeps-rl-alone
RL_ALONE_BASE ?= --base actor.update=gradient --base actor.rate=0.03
RL_ALONE_SCHEDULE ?= --base actor.update=gradient --base actor.explore_ticks=1000 --base actor.batch=0
RL_ALONE_SWEEP = $(VPY) -m icoac.tools.learner_sweeps --prior-from $(SWEEP_ICO) --out $(RL_ALONE_OUT)
sweeps-rl-alone: build venv
	$(RL_ALONE_SWEEP) --stage rl-alone
	$(RL_ALONE_SWEEP) --stage rl-alone-2 --only rl-alone-stage2 $(RL_ALONE_BASE)
	$(RL_ALONE_SWEEP) --stage rl-alone-2 --only rl-alone-schedule-grid --base actor.update=gradient
	$(RL_ALONE_SWEEP) --stage rl-alone-2 --only rl-alone-noise-grid $(RL_ALONE_SCHEDULE)
	$(RL_ALONE_SWEEP) --confirm
	$(RL_ALONE_SWEEP) --report
	cp $(RL_ALONE_OUT)/summary.md docs/sweeps-rl-alone.md

# The task settings and learner noise of each plant but the cart-pole (harness/icoac/core/plants.py), by
# their sweeps (icoac.tools.plant_sweeps; resumable): the task on spread cells, then the
# learners on the plant's ICO grid of seed 0 (make bench BENCH_PLANTS=<plant> first).
PLANT_SWEEPS = $(VPY) -m icoac.tools.plant_sweeps --plant furuta --out results/sweeps-furuta
DOUBLE_SWEEPS = $(VPY) -m icoac.tools.plant_sweeps --plant double_cart_pole --out results/sweeps-double_cart_pole
sweeps-plants: build venv
	$(PLANT_SWEEPS)
	$(PLANT_SWEEPS) --stage learners --prior-from $(BENCH_OUT)-furuta/ico/seed-0
	$(PLANT_SWEEPS) --report
	cp results/sweeps-furuta/summary.md docs/sweeps-furuta.md
	$(DOUBLE_SWEEPS)
	$(DOUBLE_SWEEPS) --stage learners --prior-from $(BENCH_OUT)-double_cart_pole/ico/seed-0
	$(DOUBLE_SWEEPS) --report
	cp results/sweeps-double_cart_pole/summary.md docs/sweeps-double_cart_pole.md

# The held-out tuning of every learner on PLANT (docs/tuning.md), resumable; its choices in
# results/tuning-$(PLANT)/summary.md. Its record, docs/data/tuning-$(PLANT).json, grows after every
# finished setting, and a run starts from it (commit it to keep a long tuning across machines).
tuning: build venv
	$(VPY) -m icoac.tools.heldout_tuning --plant $(PLANT) --out results/tuning-$(PLANT) \
	    --data docs/data/tuning-$(PLANT).json

# How much ICO the prior needs (method.md, L10): on the cart-pole bench's ICO grids (make bench
# first); the table in docs/results.md comes from docs/data/ico-ablation.json.
ablation: build venv
	$(VPY) -m icoac.tools.ico_ablation --bench $(BENCH_OUT) --out results/ico-ablation --seeds 0 1 2 3 4 \
	  --data docs/data/ico-ablation.json

# Microcontroller resource report: cross builds, QEMU runs, table in docs/porting.md.
target-report: deps
	$(PYTHON) firmware/port/report.py --update docs/porting.md

clean:
	rm -rf build
