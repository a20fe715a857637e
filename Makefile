# Quick start: `make bench` (grid benchmark + figures) and `make test` (every test).
# Both install what they need: Debian packages via apt-get, Python packages into .venv.

SHELL := /bin/bash
PYTHON ?= python3
VENV := .venv
VPY := $(VENV)/bin/python
APT_PACKAGES := cmake ninja-build gcc libc6-dev libcmocka-dev python3 python3-venv git \
  gcc-arm-none-eabi libnewlib-arm-none-eabi qemu-system-arm binutils-arm-none-eabi
SUDO := $(shell [ "$$(id -u)" = 0 ] || echo sudo)
BENCH_PROFILE ?= default
BENCH_OUT ?= results/bench

.PHONY: all deps venv build build-asan test test-c test-asan test-python bench bench-speed clean target-report

all: build

# System packages, installed only when one is missing.
deps:
	@missing=""; for p in $(APT_PACKAGES); do dpkg -s $$p >/dev/null 2>&1 || missing="$$missing $$p"; done; \
	if [ -n "$$missing" ]; then \
	  echo "installing Debian packages:$$missing"; \
	  $(SUDO) apt-get update -qq && DEBIAN_FRONTEND=noninteractive $(SUDO) apt-get install -y -qq --no-install-recommends $$missing; \
	fi

# Project venv; reinstalled when pyproject.toml changes.
venv: $(VENV)/.installed
$(VENV)/.installed: pyproject.toml | deps
	@[ -x $(VPY) ] || $(PYTHON) -m venv $(VENV)
	$(VPY) -m pip install -q --upgrade pip
	$(VPY) -m pip install -q -e '.[test]'
	@touch $@

build: deps
	cmake --preset release >/dev/null
	cmake --build --preset release

build-asan: deps
	cmake --preset debug-asan >/dev/null
	cmake --build --preset debug-asan

test-asan: build-asan
	ctest --preset debug-asan

test-c: build
	ctest --preset release

test-python: build venv
	$(VPY) -m pytest -q tests/python

test: test-asan test-c test-python

bench-speed: build
	./build/release/sim_host/icoac_bench

bench: build venv bench-speed
	$(VPY) -m harness bench --profile $(BENCH_PROFILE) --out $(BENCH_OUT) --figures docs/figures

# Microcontroller resource report: cross builds, QEMU runs, table in docs/porting.md.
target-report: deps
	$(PYTHON) firmware/port/report.py --update docs/porting.md

clean:
	rm -rf build
