# SPDX-License-Identifier: Apache-2.0
"""`sweep`: full-factorial (or one-at-a-time) sweep of RL parameters on a cell subset, resumable.

DIR/sweep.csv holds one row per finished setting; DIR/sweep.md is regenerated from it; DIR/sweep.json
records what the rows were computed with, so a resumed sweep with other cells/seeds/caps is refused.
"""
from __future__ import annotations

import csv
import dataclasses
import io
import itertools
import json
import math
import sys
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Sequence

import numpy as np

from icoac.core import binding as B
from icoac.core import geometry, grid, metrics, results, store
from icoac.studies import prior as P
from icoac.studies.conditions import local_runner
from icoac.core.binding import ConfigError
from icoac.core.config import build_config, canonical, command_overrides, given_twice, named_sets, parse_sets, parse_value
from icoac.core.errors import SweepError, UsageError
from icoac.core.metrics import percent
from icoac.core.options import FRAME_NAMES, PRIOR_STD, SWEEP_MAX_TRIALS
from icoac.core.registry import REGISTRY

PRIOR_PARAMS = ("prior_frame", "prior_ridge", "prior_std")
COLUMNS = ("key", "n_seeds", "n_cells", "success_rate_mean", "success_rate_sd", "success_rate_ico_failed",
           "n_ico_failed", "median_trials", "mean_elapsed_time", "wall_time")


def _name(name: str) -> str:
    """Canonical name of a sweep parameter (configuration fields through config.canonical)."""
    return name if name in PRIOR_PARAMS else canonical(name)


def parse_params(items: Sequence[str]) -> dict[str, list[Any]]:
    """['actor.noise_std=0.5,1', ...] -> {'actor.noise_std': [0.5, 1.0]}: canonical names of
    configuration fields, or prior_frame / prior_ridge / prior_std."""
    out: dict[str, list[Any]] = {}
    for item in items:
        if "=" not in item:
            raise SweepError(f"--param expects name=v1,v2,..., got {item!r}")
        name, values = (t.strip() for t in item.split("=", 1))
        try:
            name = _name(name)
        except ConfigError as exc:  # names the valid names
            raise SweepError(f"--param: {exc}") from None
        vals = [parse_value(v.strip()) for v in values.split(",") if v.strip()]
        if not vals:
            raise SweepError(f"--param {name}: no values")
        if name == "prior_frame" and any(v not in FRAME_NAMES for v in vals):
            raise SweepError(f"--param prior_frame: values must be {' or '.join(FRAME_NAMES)}")
        checks = {"prior_ridge": P.check_prior_ridge, "prior_std": P.check_prior_std}
        if name in checks:
            try:
                vals = [checks[name](v, f"--param {name}") for v in vals]
            except P.PriorError as exc:
                raise SweepError(str(exc)) from None
        if name in out:
            raise SweepError(f"--param {name} given twice")
        out[name] = vals
    if not out:
        raise SweepError("sweep needs at least one --param NAME=V1,V2,...")
    return out


def settings(params: dict[str, list[Any]], one_at_a_time: bool = False) -> list[dict[str, Any]]:
    names = list(params)
    if not one_at_a_time:
        return [dict(zip(names, combo)) for combo in itertools.product(*(params[n] for n in names))]
    base = {n: params[n][0] for n in names}
    out = [dict(base)]
    for n in names:
        for v in params[n][1:]:
            s = dict(base)
            s[n] = v
            out.append(s)
    return out


def key_of(setting: dict[str, Any]) -> str:
    return json.dumps(setting, sort_keys=True)


def canonical_key(key: str) -> str:
    """The key of a sweep.csv row, its names checked; SweepError if it is not a setting."""
    try:
        setting = json.loads(key)
        if not isinstance(setting, dict):
            raise ValueError("not an object")
        return key_of({_name(k): v for k, v in setting.items()})
    except (ValueError, RecursionError, ConfigError) as exc:
        raise SweepError(f"bad setting key {key!r:.60} in sweep.csv ({exc}); use another --out") from None


def subset_cells(n: int, plant_grid: geometry.PlantGrid) -> list[int]:
    """n cell indices evenly spread over the plant's grid (1 <= n <= its cells)."""
    if isinstance(n, bool) or not isinstance(n, int) or not 1 <= n <= plant_grid.cells:
        raise SweepError(f"--subset expects a number of cells in [1, {plant_grid.cells}] (the {plant_grid.plant}'s "
                         f"grid), got {n!r:.40}")
    return plant_grid.subset(n)


def _write_md(path: Path, rows: list[dict[str, str]], names: list[str], meta: dict[str, Any], dir_fd: int) -> None:
    lines = [f"# Sweep ({meta['condition']}, {meta['n_cells']} cells, seeds {meta['seeds']}, "
             f"max_trials {meta['max_trials']})", "",
             "| " + " | ".join(names) + " | success (mean ± sd) | success where ICO failed | median trials | "
             "mean elapsed time (s) |",
             "|" + "---|" * (len(names) + 4)]

    def number(v):
        return None if v in (None, "", "nan") or math.isnan(float(v)) else float(v)

    def f(v, pct=False):
        v = number(v)
        if v is None:
            return "n/a"
        return percent(v) if pct else f"{v:.4g}"

    for r in rows:
        setting = json.loads(r["key"])
        lines.append("| " + " | ".join(str(setting.get(n, "")) for n in names)
                     + f" | {f(r['success_rate_mean'], True)} ± {f(r['success_rate_sd'], True)}"
                     + f" | {f(r['success_rate_ico_failed'], True)} of {r['n_ico_failed']}"
                     + f" | {f(r['median_trials'])} | {f(r['mean_elapsed_time'])} |")
    store.write_text(path, "\n".join(lines) + "\n", dir_fd=dir_fd)


@dataclass
class SweepOptions:
    """What `sweep` runs (see icoac.cli): parameter lists, a cell selection (cells or subset),
    seeds --seed .. --seed + seeds - 1, caps, fixed overrides."""
    prior_from: Path
    out: Path
    params: Sequence[str]
    condition: str = "ico-rl"
    cells: str | None = None
    subset: int | None = None
    seed: int = 0
    seeds: int = 1
    max_trials: int | None = None     # None: --set max_trials, else SWEEP_MAX_TRIALS
    success_steps: int | None = None
    configuration: str = "default"    # a named configuration (config.NAMED_CONFIGURATIONS), then sets
    sets: Sequence[str] = ()
    one_at_a_time: bool = False
    threads: int = 0
    prior_std: float = PRIOR_STD
    quiet: bool = False
    dask: Any = None              # a icoac.cluster.backend.DaskSpec: every grid on that Dask cluster (None: threads)


def _read_table(csv_path: Path) -> tuple[list[str] | None, list[dict[str, str]], str]:
    """(header, rows with canonical keys, text) of an existing sweep.csv (read through no link),
    (None, [], "") if there is none."""
    if not csv_path.is_file():
        return None, [], ""
    try:
        with results.open_file(csv_path, follow=False) as fh:
            text = fh.read().decode()
        reader = csv.DictReader(io.StringIO(text, newline=""))
        rows = list(reader)
        header = list(reader.fieldnames or [])
    except (OSError, ValueError, csv.Error) as exc:
        raise UsageError(f"cannot read {str(csv_path)!r}: {exc}; use another --out")
    if any(not isinstance(r.get("key"), str) for r in rows) or (rows and "key" not in header):
        raise UsageError(f"{str(csv_path)!r} is not a sweep table (no key column); use another --out")
    for r in rows:
        r["key"] = canonical_key(r["key"])
    return header, rows, text


def _csv_lines(header: list[str], rows: list[dict[str, Any]], with_header: bool) -> str:
    buf = io.StringIO(newline="")
    writer = csv.DictWriter(buf, fieldnames=header, extrasaction="ignore")
    if with_header:
        writer.writeheader()
    writer.writerows(rows)
    return buf.getvalue()


def _param_columns(header: list[str]) -> dict[str, str]:
    """{canonical name: column} of the parameter columns of a sweep.csv header."""
    out = {}
    for col in header:
        if col in COLUMNS:
            continue
        try:
            out[_name(col)] = col
        except ConfigError:
            continue
    return out


def run_sweep(opt: SweepOptions) -> int:
    """Run every setting not yet in OUT/sweep.csv; 130 if interrupted. With ``opt.dask`` one Dask
    session (icoac.cluster.backend), opened after every check, runs every grid."""
    ico_dir = results.check_results_dir(opt.prior_from, "--prior-from")
    try:
        P.check_prior_std(opt.prior_std)
    except P.PriorError as exc:
        raise SweepError(str(exc)) from None
    params = parse_params(opt.params)
    names = list(params)
    todo = settings(params, opt.one_at_a_time)
    seeds = grid.seed_range(opt.seed, opt.seeds)
    ico_cells, ico_record = results.load(ico_dir, what="--prior-from")
    plant = results.record_plant(ico_record)  # the sweep runs on the plant of its ICO grid
    plant_grid = geometry.of(plant)
    if opt.cells is not None:
        indices = grid.parse_cell_indices(opt.cells, plant_grid.cells)
    elif opt.subset is not None:
        indices = subset_cells(opt.subset, plant_grid)
    else:
        indices = plant_grid.spread_cells()
    priors: dict = {}

    # ICO outcome on the sweep cells (matched by grid position).
    ico_rc = {(int(r), int(c)) for r, c in zip(*plant_grid.grid_index(ico_cells[metrics.success_mask(ico_cells)]))}
    ico_known = {(int(r), int(c)) for r, c in zip(*plant_grid.grid_index(ico_cells))}
    probe = grid.make_cells(0, indices, plant=plant)
    pr, pc = plant_grid.grid_index(probe)
    ico_failed = np.array([(int(r), int(c)) in ico_known and (int(r), int(c)) not in ico_rc
                           for r, c in zip(pr, pc)], dtype=bool)

    flags = {"--max-trials": ("max_trials", opt.max_trials), "--success-steps": ("success_steps", opt.success_steps)}
    fixed = command_overrides(opt.configuration, opt.sets, flags, plant=plant)
    explicit = {name: f"--set {name}" for name in parse_sets(opt.sets, plant=plant)}
    explicit.update({name: option for option, (name, value) in flags.items() if value is not None})
    for name in params:
        if name in explicit:
            raise given_twice(name, f"--param {name}", explicit[name])
    fixed.setdefault("max_trials", SWEEP_MAX_TRIALS)
    out = store.check_out_dir(opt.out)

    def prior_for(setting):
        """The condition's prior; the ICO grid of --prior-from reaches it only when its rule takes
        the mean or the covariance from ICO (its rule: icoac.core.registry)."""
        condition = REGISTRY[opt.condition].base
        std = float(setting.get("prior_std", opt.prior_std))
        if not REGISTRY[condition].prior.takes_ico:
            return P.condition_prior(condition, None, std, plant_grid.n_inputs)
        frame = P.parse_frame(str(setting.get("prior_frame", FRAME_NAMES[0])))
        ridge = float(setting.get("prior_ridge", P.DEFAULT_RIDGE))
        k = (frame, ridge)
        if k not in priors:
            priors[k] = P.from_results(ico_dir, frame, ridge)
        return P.condition_prior(condition, priors[k], std, plant_grid.n_inputs)

    def config_for(setting):
        over = dict(fixed)
        over.update({k: v for k, v in setting.items() if k not in PRIOR_PARAMS})
        return build_config(over, condition=opt.condition, prior=prior_for(setting).prior(), plant=plant)

    for setting in todo:  # every setting valid before the first grid runs (and before any write)
        config_for(setting)
    meta = {"condition": opt.condition, "prior_from": str(ico_dir.resolve()), "cells": indices,
            "n_cells": len(indices), "seeds": seeds,
            "max_trials": int(build_config({"max_trials": fixed["max_trials"]}, check=False).run.max_trials),
            "success_steps": opt.success_steps, "set": named_sets(opt.configuration, opt.sets), "prior_std": opt.prior_std}
    with store.DirectoryLock(out) as held:
        return _run_settings(opt, out, held, meta, todo, names, seeds, indices, ico_failed, config_for)


def _run_settings(opt: SweepOptions, out: Path, held: store.DirectoryLock, meta: dict[str, Any], todo, names,
                  seeds, indices, ico_failed, config_for) -> int:
    """The settings not yet in OUT/sweep.csv, in the held directory ``out``."""
    from icoac.cluster.backend import open_backend

    meta_path = out / "sweep.json"
    csv_path = out / "sweep.csv"
    runs: list = []  # provenance of each invocation that ran settings (not compared on resume)
    if meta_path.is_file() and csv_path.is_file():
        old = results.read_json(meta_path, follow=False)
        store.check_same_settings(old, meta, out, "a sweep")
        runs = old.get("runs") if isinstance(old.get("runs"), list) else []
    header, rows, table = _read_table(csv_path)
    if header is not None:
        missing = [n for n in names if n not in _param_columns(header)]
        if missing:
            raise UsageError(f"{csv_path} has other parameter columns (no {', '.join(missing)}); use another --out")
    done = {r["key"] for r in rows}
    pending = [key_of(st) for st in todo if key_of(st) not in done]
    if pending or not runs:
        runs = runs + [{"git": results.git_info(), "library": str(B.LIBRARY_PATH), "settings": pending,
                        **({"dask": dataclasses.asdict(opt.dask)} if opt.dask is not None else {})}]
    store.write_json(meta_path, {**meta, "runs": runs}, dir_fd=held.dir_fd)

    with open_backend(opt.dask if pending else None) as session:
        t_all = time.monotonic()
        for i, setting in enumerate(todo, 1):
            key = key_of(setting)
            label = ", ".join(f"{k}={v}" for k, v in setting.items())
            if key in done:
                print(f"[sweep] ({i}/{len(todo)}) {label}: already in {csv_path.name}, skipped", file=sys.stderr)
                continue
            cfg = config_for(setting)
            t0 = time.monotonic()
            rates, rates_failed, trials, elapsed = [], [], [], []
            for seed in seeds:
                cells = grid.make_cells(seed, indices, plant=cfg.plant_name)
                res = (local_runner(opt.condition)(cfg, cells, threads=opt.threads, progress=False)
                       if session is None or REGISTRY[opt.condition].optimiser is not None
                       else session.run_grid(cfg, cells, progress=False))
                if res.cancelled:
                    print("[sweep] interrupted: finished settings are in the CSV; rerun to resume", file=sys.stderr)
                    return 130
                ok = metrics.success_mask(cells)
                rates.append(float(ok.mean()))
                if ico_failed.any():
                    rates_failed.append(float(ok[ico_failed].mean()))
                trials.extend(cells["trials"][ok].tolist())
                elapsed.extend(cells["elapsed_time"][ok].tolist())
            wall = time.monotonic() - t0
            row = {"key": key, "n_seeds": len(seeds), "n_cells": len(indices),
                   "success_rate_mean": f"{np.mean(rates):.6g}",
                   "success_rate_sd": f"{np.std(rates, ddof=1) if len(rates) > 1 else 0.0:.6g}",
                   "success_rate_ico_failed": f"{np.mean(rates_failed):.6g}" if rates_failed else "",
                   "n_ico_failed": int(ico_failed.sum()),
                   "median_trials": f"{np.median(trials):.6g}" if trials else "",
                   "mean_elapsed_time": f"{np.mean(elapsed):.6g}" if elapsed else "",
                   "wall_time": f"{wall:.3f}"}
            if header is None:
                header = names + list(COLUMNS)
                table = _csv_lines(header, [], with_header=True)
            columns = _param_columns(header)
            for n in names:
                row[columns[n]] = setting.get(n, "")
            table += _csv_lines(header, [row], with_header=False)
            store.write_text(csv_path, table, dir_fd=held.dir_fd)
            rows.append({k: str(v) for k, v in row.items()})
            done.add(key)
            rf = f", ICO-failed cells {percent(np.mean(rates_failed))}" if rates_failed else ""
            print(f"[sweep] ({i}/{len(todo)}) {label}: success {percent(np.mean(rates))}{rf}, "
                  f"{wall:.1f} s", file=sys.stderr, flush=True)
    _write_md(out / "sweep.md", rows, names, meta, held.dir_fd)
    print(f"[sweep] {len(todo)} settings, wall time {time.monotonic() - t_all:.1f} s -> {csv_path}")
    return 0
