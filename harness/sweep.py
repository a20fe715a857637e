"""`sweep`: full-factorial (or one-at-a-time) sweep of RL parameters on a cell subset, resumable.

DIR/sweep.csv holds one row per finished setting; DIR/sweep.md is regenerated from it; DIR/sweep.json
records what the rows were computed with, so a resumed sweep with other cells/seeds/caps is refused.
"""
from __future__ import annotations

import csv
import itertools
import json
import math
import sys
import time
from pathlib import Path
from typing import Any

import numpy as np

from . import _binding as B
from . import metrics

PRIOR_PARAMS = ("prior_frame", "prior_ridge")
DEFAULT_CELLS = list(range(0, B.GRID_CELLS, 25))  # 49 cells spread over the grid
COLUMNS = ("key", "n_seeds", "n_cells", "success_rate_mean", "success_rate_sd", "success_rate_ico_failed",
           "n_ico_failed", "median_trials", "mean_elapsed_time", "wall_time")


class SweepError(B.ConfigError):
    pass


def _err(msg: str) -> SweepError:
    return SweepError(B.SIM_ERR_BAD_ARGUMENT, msg)


def parse_params(items: list[str]) -> dict[str, list[Any]]:
    """['noise_std=0.5,1', ...] -> {'noise_std': [0.5, 1.0]}; names checked against the config fields."""
    from .config import ALL_FIELDS, parse_value
    out: dict[str, list[Any]] = {}
    for item in items:
        if "=" not in item:
            raise _err(f"--param expects name=v1,v2,..., got {item!r}")
        name, values = (t.strip() for t in item.split("=", 1))
        if name not in ALL_FIELDS and name not in PRIOR_PARAMS or name == "reserved":
            raise _err(f"--param: unknown parameter {name!r}")
        vals = [parse_value(v.strip()) for v in values.split(",") if v.strip()]
        if not vals:
            raise _err(f"--param {name}: no values")
        if name == "prior_frame" and any(v not in ("central", "all") for v in vals):
            raise _err("--param prior_frame: values must be central or all")
        if name == "prior_ridge" and any(isinstance(v, bool) or not isinstance(v, (int, float))
                                         or not math.isfinite(v) or v < 0 for v in vals):
            raise _err("--param prior_ridge: values must be finite numbers >= 0")
        if name in out:
            raise _err(f"--param {name} given twice")
        out[name] = vals
    if not out:
        raise _err("sweep needs at least one --param NAME=V1,V2,...")
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


def subset_cells(n: int) -> list[int]:
    if n >= B.GRID_CELLS:
        return list(range(B.GRID_CELLS))
    return sorted(set(int(round(v)) for v in np.linspace(0, B.GRID_CELLS - 1, n)))


def _read_rows(path: Path) -> list[dict[str, str]]:
    if not path.is_file():
        return []
    with open(path, newline="") as fh:
        return list(csv.DictReader(fh))


def _write_md(path: Path, rows: list[dict[str, str]], names: list[str], meta: dict[str, Any]) -> None:
    lines = [f"# Sweep ({meta['condition']}, {meta['n_cells']} cells, seeds {meta['seeds']}, "
             f"max_trials {meta['max_trials']})", "",
             "| " + " | ".join(names) + " | success (mean ± sd) | success where ICO failed | median trials | "
             "mean elapsed time (s) |",
             "|" + "---|" * (len(names) + 4)]

    def f(v, pct=False):
        if v in (None, "", "nan"):
            return "n/a"
        v = float(v)
        if math.isnan(v):
            return "n/a"
        return f"{100 * v:.1f} %" if pct else f"{v:.4g}"

    for r in rows:
        setting = json.loads(r["key"])
        lines.append("| " + " | ".join(str(setting.get(n, "")) for n in names)
                     + f" | {f(r['success_rate_mean'], True)} ± {f(r['success_rate_sd'], True)}"
                     + f" | {f(r['success_rate_ico_failed'], True)} of {r['n_ico_failed']}"
                     + f" | {f(r['median_trials'])} | {f(r['mean_elapsed_time'])} |")
    path.write_text("\n".join(lines) + "\n")


def run_sweep(args) -> int:
    from . import grid
    from . import prior as P
    from .cli import UsageError, _parse_sets
    from .config import build_config

    ico_dir = Path(args.prior_from)
    if not ico_dir.is_dir():
        raise UsageError(f"--prior-from: directory {str(ico_dir)!r} does not exist")
    params = parse_params(args.param)
    names = list(params)
    todo = settings(params, args.one_at_a_time)
    try:
        seeds = [int(s) for s in args.seeds.split(",") if s.strip()]
    except ValueError:
        raise UsageError(f"--seeds expects comma-separated integers, got {args.seeds!r:.60}")
    if not seeds or any(not 0 <= s < grid.SEED_LIMIT for s in seeds):
        raise UsageError(f"--seeds expects integers in [0, 2^64), got {args.seeds!r:.60}")
    if args.cells is not None:
        indices = grid.parse_cell_indices(args.cells)
    elif args.subset is not None:
        indices = subset_cells(args.subset)
    else:
        indices = DEFAULT_CELLS
    from . import results
    ico_cells, _ = results.load(ico_dir)
    priors: dict = {}

    # ICO outcome on the sweep cells (matched by grid position).
    ico_rc = {(int(r), int(c)) for r, c in zip(*metrics.grid_index(ico_cells[metrics.success_mask(ico_cells)]))}
    ico_known = {(int(r), int(c)) for r, c in zip(*metrics.grid_index(ico_cells))}
    probe = grid.make_cells(0, indices)
    pr, pc = metrics.grid_index(probe)
    ico_failed = np.array([(int(r), int(c)) in ico_known and (int(r), int(c)) not in ico_rc
                           for r, c in zip(pr, pc)], dtype=bool)

    fixed = _parse_sets(args.set)
    fixed["max_trials"] = args.max_trials
    if args.success_steps is not None:
        fixed["success_steps"] = args.success_steps
    out = Path(args.out)
    meta = {"condition": args.condition, "prior_from": str(ico_dir.resolve()), "cells": indices,
            "n_cells": len(indices), "seeds": seeds, "max_trials": args.max_trials,
            "success_steps": args.success_steps, "set": args.set or [], "rl_cov": args.rl_cov}
    meta_path = out / "sweep.json"
    csv_path = out / "sweep.csv"
    if meta_path.is_file() and csv_path.is_file():
        try:
            old = json.loads(meta_path.read_bytes())
        except (OSError, ValueError, RecursionError) as exc:
            raise UsageError(f"cannot read {str(meta_path)!r}: {exc}; use another --out")
        if not isinstance(old, dict):
            raise UsageError(f"{str(meta_path)!r} is not a sweep record; use another --out")
        diff = [k for k in meta if old.get(k) != meta[k]]
        if diff:
            raise UsageError(f"{str(out)!r} holds a sweep with other {', '.join(diff)}; use another --out")
    try:
        rows = _read_rows(csv_path)
    except (OSError, ValueError, csv.Error) as exc:
        raise UsageError(f"cannot read {str(csv_path)!r}: {exc}; use another --out")
    if any(not isinstance(r.get("key"), str) for r in rows):
        raise UsageError(f"{str(csv_path)!r} is not a sweep table (no key column); use another --out")
    done = {r["key"] for r in rows}

    def prior_for(setting):
        frame = P.parse_frame(str(setting.get("prior_frame", "central")))
        ridge = float(setting.get("prior_ridge", P.DEFAULT_RIDGE))
        k = (frame, ridge)
        if k not in priors:
            priors[k] = P.from_results(ico_dir, frame, ridge)
        info = priors[k]
        return info if args.condition == "ico-rl" else P.rl_prior(info, args.rl_cov)

    for setting in todo:  # every setting valid before the first grid runs (and before any write)
        over = dict(fixed)
        over.update({k: v for k, v in setting.items() if k not in PRIOR_PARAMS})
        build_config(over, condition=args.condition, prior=prior_for(setting).prior())
    results.check_writable(out)
    meta_path.write_text(json.dumps(meta, indent=2) + "\n")

    t_all = time.monotonic()
    for i, setting in enumerate(todo, 1):
        key = key_of(setting)
        label = ", ".join(f"{k}={v}" for k, v in setting.items())
        if key in done:
            print(f"[sweep] ({i}/{len(todo)}) {label}: already in {csv_path.name}, skipped", file=sys.stderr)
            continue
        over = dict(fixed)
        over.update({k: v for k, v in setting.items() if k not in PRIOR_PARAMS})
        info = prior_for(setting)
        cfg = build_config(over, condition=args.condition, prior=info.prior())
        t0 = time.monotonic()
        rates, rates_failed, trials, elapsed = [], [], [], []
        for seed in seeds:
            cells = grid.make_cells(seed, indices)
            res = grid.run_grid(cfg, cells, threads=args.threads, progress=False)
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
        for n in names:
            row[n] = setting.get(n, "")
        new_file = not csv_path.is_file()
        header = names + list(COLUMNS)
        if not new_file:
            with open(csv_path, newline="") as fh:
                header = next(csv.reader(fh), header)
            missing = [n for n in names if n not in header]
            if missing:
                raise UsageError(f"{csv_path} has other parameter columns; use another --out")
        with open(csv_path, "a", newline="") as fh:
            w = csv.DictWriter(fh, fieldnames=header, extrasaction="ignore")
            if new_file:
                w.writeheader()
            w.writerow(row)
        rows.append({k: str(v) for k, v in row.items()})
        done.add(key)
        rf = f", ICO-failed cells {100 * np.mean(rates_failed):.1f} %" if rates_failed else ""
        print(f"[sweep] ({i}/{len(todo)}) {label}: success {100 * np.mean(rates):.1f} %{rf}, "
              f"{wall:.1f} s", file=sys.stderr, flush=True)
    _write_md(out / "sweep.md", rows, names, meta)
    print(f"[sweep] {len(todo)} settings, wall time {time.monotonic() - t_all:.1f} s -> {csv_path}")
    return 0
