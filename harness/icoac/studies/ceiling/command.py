# SPDX-License-Identifier: Apache-2.0
"""`python -m icoac ceiling`: validate everything, then the first-step bound, the search for the
best w (or a given --w), its full-horizon evaluations and the summary (icoac.studies.ceiling)."""
from __future__ import annotations

import sys
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Sequence

import numpy as np

from icoac.core import binding as B
from icoac.core import geometry, grid, results, store
from icoac.studies import heldout
from icoac.studies import prior as P
from icoac.core.errors import UsageError
from icoac.core.options import CART_POLE, CEILING_CANDIDATES, CEILING_CONFIRM, CEILING_FILE, CEILING_MAX_CANDIDATES, CEILING_MAX_TRIALS, CEILING_OPTIMISERS, CEILING_PROTOCOLS, CEILING_SCREEN_STEPS, INT64_MAX
from icoac.studies.ceiling.bound import first_step_bound
from icoac.studies.ceiling.cma_search import CMA_ES, cma_search
from icoac.studies.ceiling.fixed import check_overrides, eval_dir, evaluate_into, fixed_config, protocol_summary, protocols_of
from icoac.studies.ceiling.lqr import lqr_starts
from icoac.studies.ceiling.records import FORMAT_VERSION, SEARCH_FILE, SUMMARY_MD, ScreenStore, summary_markdown
from icoac.studies.ceiling.search import PATTERN, screen_cells, search
from icoac.studies.ceiling.weights import as_weights, format_w, parse_weights, typical_weights


@dataclass
class CeilingOptions:
    """What `ceiling` runs (see icoac.cli): a given w (no search) or the search and its optimiser
    (None: the pattern search), the protocols of the final evaluation, caps, cells ('tuning': the
    held-out split's tuning cells), budgets."""
    out: Path
    prior_from: Path | None = None
    w: Sequence[float] | str | None = None
    protocol: str = "both"
    max_trials: int = CEILING_MAX_TRIALS
    success_steps: int | None = None
    cells: str | Sequence[int] | None = None
    candidates: int | None = None
    screen_steps: int | None = None
    confirm: int | None = None
    seed: int = 0
    optimiser: str | None = None
    threads: int = 0
    sets: Sequence[str] = ()
    quiet: bool = False
    plant: str = CART_POLE


OPTIMISERS = (PATTERN, CMA_ES)  # --optimiser, the first the default
assert OPTIMISERS == CEILING_OPTIMISERS


def _positive(name: str, value: Any, hi: int = INT64_MAX) -> int:
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or not 1 <= int(value) <= hi:
        raise UsageError(f"{name} must be an integer in [1, {hi}], got {value!r:.40}")
    return int(value)


def _log(quiet: bool, message: str) -> None:
    if not quiet:
        print(f"[ceiling] {message}", file=sys.stderr, flush=True)


def run_ceiling(opt: CeilingOptions, argv: Sequence[str] = ()) -> int:
    """Validate everything, then search (or take --w), evaluate, bound, summarise; 130 if interrupted
    (finished screens and cells are kept; the same command resumes)."""
    t_start = time.monotonic()
    out = store.check_out_dir(opt.out)
    protocols = protocols_of(opt.protocol)
    seed = grid.check_seed(opt.seed, "--seed")
    threads = grid.check_threads(opt.threads)
    max_trials = _positive("--max-trials", opt.max_trials)
    overrides = check_overrides(opt.sets, opt.plant)
    optimiser = PATTERN if opt.optimiser is None else opt.optimiser
    if optimiser not in OPTIMISERS:
        raise UsageError(f"--optimiser {optimiser!r:.40}: valid: {', '.join(OPTIMISERS)}")
    try:
        indices = grid.parse_cell_indices(heldout.cell_spec(opt.cells, opt.plant), geometry.of(opt.plant).cells)
    except B.ConfigError as exc:
        raise UsageError(f"--cells: {exc}") from None
    n_inputs = geometry.of(opt.plant).n_inputs
    typical_w = typical_weights(n_inputs)
    probe = fixed_config(typical_w, "retries", max_trials=max_trials, success_steps=opt.success_steps,
                         overrides=overrides, plant=opt.plant)  # C checks of everything
    success_steps = int(probe.run.success_steps)
    given = None
    if opt.w is not None:
        given = parse_weights(opt.w, n=n_inputs) if isinstance(opt.w, str) else as_weights(opt.w, "--w", n_inputs)
        extra = [name for name, v in (("--prior-from", opt.prior_from), ("--candidates", opt.candidates),
                                      ("--screen-steps", opt.screen_steps), ("--confirm", opt.confirm),
                                      ("--optimiser", opt.optimiser)) if v is not None]
        if extra:
            raise UsageError(f"--w evaluates the given w without a search; {', '.join(extra)} apply to the search")
        fixed_config(given, "first", success_steps=success_steps, overrides=overrides, plant=opt.plant)
    candidates = _positive("--candidates", CEILING_CANDIDATES if opt.candidates is None else opt.candidates,
                           CEILING_MAX_CANDIDATES)
    screen_steps = _positive("--screen-steps", CEILING_SCREEN_STEPS if opt.screen_steps is None else opt.screen_steps)
    confirm = _positive("--confirm", CEILING_CONFIRM if opt.confirm is None else opt.confirm, CEILING_MAX_CANDIDATES)
    if given is None and screen_steps > success_steps:
        raise UsageError(f"--screen-steps {screen_steps} is longer than the full horizon --success-steps "
                         f"{success_steps}")
    prior_info = None
    typical = ("typical ICO", as_weights(typical_w))
    if opt.prior_from is not None:
        prior_info = P.from_results(opt.prior_from, plant=opt.plant)
        P.check_origin_task(prior_info, probe)  # its weights are in this task's coordinates
        typical = ("ICO mean (--prior-from)", as_weights(prior_info.mean, "--prior-from mean", n_inputs))
    template = grid.make_cells(seed, indices, plant=opt.plant)
    screen_settings = None
    if given is None:
        base = fixed_config(typical_w, "first", success_steps=screen_steps, overrides=overrides,
                            plant=opt.plant).to_dict()
        base["prior"] = None
        screen_settings = {"seed": seed, "cells": indices, "screen_steps": screen_steps, "config": base}
    with store.DirectoryLock(out) as held:  # the whole run: search.json, evals/, ceiling.json
        screens = None
        if screen_settings is not None:
            screens = ScreenStore(out / SEARCH_FILE, screen_settings, held.dir_fd)
            screens.load()
        git = results.git_info()

        settings = {"seed": seed, "cells": indices, "n_cells": int(template.size), "protocol": opt.protocol,
                    "max_trials": max_trials, "success_steps": success_steps, "set": overrides,
                    **({} if opt.plant == CART_POLE else {"plant": opt.plant}),
                    "w": list(given) if given is not None else None, "threads": threads,
                    "prior_from": None if prior_info is None else {
                        "path": prior_info.source, "mean": list(prior_info.mean), "n_cells": prior_info.n_cells,
                        "commit": prior_info.source_commit}}
        if given is None:
            settings.update(candidates=candidates, screen_steps=screen_steps, confirm=confirm, optimiser=optimiser)
        record: dict[str, Any] = {"format_version": FORMAT_VERSION, "command": "ceiling", "argv": list(argv),
                                  "settings": settings, "git": git, "abi": B.abi_info(),
                                  "policy": {"gain": float(probe.controller.policy.gain),
                                             "reflex_mode": probe.to_dict()["controller"]["policy"]["reflex_mode"],
                                             "reflex_force": float(probe.controller.policy.reflex_force)}}

        def full_eval(w, protocol):
            d = eval_dir(out, w, protocol, success_steps, max_trials)
            cells, rec = evaluate_into(d, w, protocol, seed=seed, indices=indices, max_trials=max_trials,
                                       success_steps=success_steps, overrides=overrides, threads=threads,
                                       progress=not opt.quiet, plant=opt.plant)
            return protocol_summary(cells, rec, out, d)

        try:
            _log(opt.quiet, f"first-step bound on {template.size} cells ...")
            bound = first_step_bound(probe, template, threads)
            record["first_step_bound"] = bound
            if bound.get("computed"):
                _log(opt.quiet, f"  {bound['n_lost']} cells lost at step 1 whatever the force "
                                f"({bound['n_lost_interior']} interior): at most {bound['max_success']} of "
                                f"{bound['n_cells']}")
            if given is None:
                cfg_cache: dict = {}

                def cfg_for(w):
                    if w not in cfg_cache:
                        cfg_cache.clear()
                        cfg_cache[w] = fixed_config(w, "first", success_steps=screen_steps, overrides=overrides,
                                                    plant=opt.plant)
                    return cfg_cache[w]

                def screen(w):
                    s = screens.get(w)
                    if s is None:
                        s = screen_cells(w, template, cfg_for, threads)
                        screens.add(w, s)
                    return s

                def report(entry, best):
                    if entry is best or (entry["index"] + 1) % 50 == 0:
                        _log(opt.quiet, f"  #{entry['index'] + 1}/{candidates} {entry['phase']} ({entry['label']}): "
                                        f"{entry['n_success']} cells; best {best['n_success']} {format_w(best['w'])}")

                starts = [typical] + lqr_starts(probe)
                _log(opt.quiet, f"search ({optimiser}): {candidates} candidates screened at {screen_steps} steps "
                                f"(first trial), {len(starts)} starting points")
                t0 = time.monotonic()
                if optimiser == CMA_ES:  # its fitness needs the most steps a screen can survive
                    res = cma_search(screen, starts, candidates, seed, template.size * screen_steps, report=report)
                else:
                    res = search(screen, starts, candidates, seed, report=report)
                screens.flush()
                screen_wall = time.monotonic() - t0
                _log(opt.quiet, f"  {len(res.trace)} screened ({screens.reused} from {SEARCH_FILE}) in "
                                f"{screen_wall:.1f} s, stop: {res.stop}")
                confirmed = []
                t0 = time.monotonic()
                for entry in res.ranked()[:confirm]:
                    w = tuple(entry["w"])
                    summ = full_eval(w, "first")
                    confirmed.append({"index": entry["index"], "w": list(w), "screen": {
                        k: entry[k] for k in ("n_success", "n_success_interior", "total_steps")}, "first": summ})
                    _log(opt.quiet, f"  confirm #{entry['index'] + 1} {format_w(w)}: {summ['n_success']} of "
                                    f"{summ['n_cells']} at {success_steps} steps")
                best = max(confirmed, key=lambda c: (c["first"]["n_success"], c["first"]["n_success_interior"],
                                                     c["screen"]["n_success"], c["screen"]["total_steps"], -c["index"]))
                record["search"] = {
                    "candidates": candidates, "screen_steps": screen_steps, "confirm": confirm, "seed": seed,
                    "stop": res.stop, "refinement_steps": res.refinement_steps,
                    "refinement_origins": res.refinement_origins, "screened": len(res.trace),
                    "phases": {p: sum(1 for e in res.trace if e["phase"] == p) for p in res.phases},
                    "optimiser": res.optimiser,
                    "reused_screens": screens.reused, "screen_wall_time": screen_wall,
                    "confirm_wall_time": time.monotonic() - t0,
                    "starts": res.starts, "screen_best": res.best, "confirmed": confirmed, "trace": res.trace}
                best_w = tuple(best["w"])
                protos = {"first": best["first"]}
                source = "search"
            else:
                best_w, protos, source = given, {}, "--w"
            for protocol in protocols:
                if protocol not in protos:
                    _log(opt.quiet, f"{protocol} protocol of {format_w(best_w)} at {success_steps} steps ...")
                    protos[protocol] = full_eval(best_w, protocol)
            record["best"] = {"w": list(best_w), "source": source,
                              "protocols": {p: protos[p] for p in CEILING_PROTOCOLS if p in protos}}
        except KeyboardInterrupt:
            if screens is not None:
                screens.flush()
            print("interrupted: finished screens and cells are saved; rerun the same command to resume",
                  file=sys.stderr)
            return 130
        record["timestamp"] = results.timestamp()
        record["wall_time"] = time.monotonic() - t_start
        text = summary_markdown(record)
        store.write_json(out / CEILING_FILE, record, indent=1, dir_fd=held.dir_fd)
        store.write_text(out / SUMMARY_MD, text, dir_fd=held.dir_fd)
        print(text, end="")
        print(f"wall time {record['wall_time']:.1f} s -> {out / CEILING_FILE}")
        return 0
