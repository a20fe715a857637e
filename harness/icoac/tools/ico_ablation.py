# SPDX-License-Identifier: Apache-2.0
"""How much ICO the actor-critic's prior needs (method.md, L10): ICO learned on k cells of the
central frame (k = 1, 5, 25, nested, drawn at random once per seed) and on the whole frame, then
the learner from that prior on every cell of the grid, against what the ICO phase cost.

    python -m icoac.tools.ico_ablation --bench results/bench --out results/ico-ablation

ICO's cells are the ICO grid of a bench (--bench, the same seeds): ICO learns in each cell
independently of the others, so the records of k cells are what running ICO on those k cells
alone costs and gives. The prior's mean is that of the ICO-successful ones among them, as the
bench makes it (icoac.studies.prior). The learner is ICO mean->RL: ICO->RL's gradient reading does
not read the prior's covariance, so their grids are the same cell for cell (a bench shows it), and
the mean alone is defined from one cell. For the whole frame the learner grids are the bench's own
(the same prior and configuration), read, not rerun.

Output: OUT/k-<k>/seed-<s>/ results directories (resumable), OUT/ablation.json and OUT/summary.md.
Each row: the ICO phase's cells, trials and simulated time; the learner's success (with its
interval), success within 10, 100 and 1000 trials, its trials; and the totals."""
from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path
from typing import Any

import numpy as np

from icoac.core import binding as B
from icoac.core import geometry, metrics, results
from icoac.core.errors import PriorError
from icoac.core.plants import spec as plant_spec
from icoac.core.registry import REGISTRY
from icoac.studies import bench, tables
from icoac.studies import prior as P
from icoac.studies.conditions import run_condition
from icoac.tools.resumable import guarded

SIZES = (1, 5, 25)           # ICO cells of the ablation; "frame": every cell of the central frame
LEARNER = "ico-mean-rl"
DRAW_STREAM = 0xAB1A7E       # the cells' draw: numpy PCG64 from (DRAW_STREAM, seed)
WITHIN = (10, 100, 1000)     # success within these many trials


def frame_cells(ico: np.ndarray, grid: geometry.PlantGrid) -> np.ndarray:
    """Indices of the ICO grid's cells in the plant's central frame (the bench prior's)."""
    return np.flatnonzero(P.frame_mask(ico, grid.central_frame(), grid))


def drawn_cells(ico: np.ndarray, grid: geometry.PlantGrid, seed: int) -> np.ndarray:
    """The central frame's cells in a fixed random order for this seed: k cells are its first k."""
    rng = np.random.Generator(np.random.PCG64([DRAW_STREAM, seed]))
    return rng.permutation(frame_cells(ico, grid))


def subset_prior(ico_dir: Path, picked: np.ndarray, plant: str, ridge: float, std: float) -> P.PriorInfo:
    """The learner's prior from the ICO cells ``picked`` of the bench's ICO run (PriorError when
    none of them is one the prior takes), with the run's provenance."""
    info = P.from_results(ico_dir, P.CENTRAL, ridge, plant)  # provenance and checks of the run
    ico, _ = results.load(ico_dir)
    grid = geometry.of(plant)
    sub = ico[picked]
    taken = metrics.success_mask(sub) if plant_spec(plant).prior_cells == "successful" else \
        np.isin(sub["outcome"], (B.SUCCESS, B.FAILED))
    if not np.any(taken):
        raise PriorError(f"no ICO-successful cell among the {picked.size}")
    info.mean = sub["weights"][taken][:, :grid.n_inputs].astype(np.float64).mean(axis=0)
    info.n_cells = int(np.count_nonzero(taken))
    info.ico_phase_simulated_time = float(np.sum(sub["elapsed_time"]))
    info.extra = {**info.extra, "source_cell_indices": [int(i) for i in picked]}
    return P.condition_prior(LEARNER, info, std, grid.n_inputs)


def ico_cost(ico: np.ndarray, picked: np.ndarray) -> dict[str, float]:
    sub = ico[picked]
    return {"cells": int(picked.size), "trials": int(np.sum(sub["trials"])),
            "simulated_time": float(np.sum(sub["elapsed_time"]))}


def run(args) -> dict[str, Any]:
    grid = geometry.of(args.plant)
    profile = bench.PROFILES[args.profile]
    cells_spec = profile["cells"](grid) if profile["cells"] else None
    rows: dict[str, Any] = {}
    every: list = []  # every learner record read or written: the builds behind the table
    for k in [*SIZES, "frame"]:
        recs, cells, ico_costs, note = [], {}, [], None
        grid_costs = []
        for seed in args.seeds:
            ico_dir = bench.seed_dir(args.bench, "ico", seed)
            ico, _ = results.load(ico_dir)
            order = drawn_cells(ico, grid, seed)
            picked = order if k == "frame" else order[:k]
            ico_costs.append(ico_cost(ico, picked))
            grid_costs.append(ico_cost(ico, np.arange(ico.size)))
            if k == "frame":
                c, r = results.load(bench.seed_dir(args.bench, LEARNER, seed))
            else:
                try:
                    info = subset_prior(ico_dir, picked, args.plant, args.ridge, args.prior_std)
                except PriorError as exc:
                    note = str(exc)
                    continue
                out = args.out / f"k-{k}" / f"seed-{seed}"
                c, r, cancelled = run_condition(
                    condition=LEARNER, out=out, seed=seed, threads=args.threads, overrides=dict(profile["rl"]),
                    cell_spec=cells_spec, resume=bool(results.present(out)), progress=not args.quiet, info=info,
                    plant=args.plant)
                if cancelled:
                    raise KeyboardInterrupt
            recs.append(r)
            every.append(r)
            cells[seed] = c
        rows[str(k)] = row(k, recs, cells, ico_costs, note)
        ico_grid = {key: bench.seed_stat([c[key] for c in grid_costs]) for key in grid_costs[0]}
        print(f"[ablation] k={k}: {tables.rate(rows[str(k)].get('success_rate'))}", file=sys.stderr)
    return {"plant": args.plant, "profile": args.profile, "configuration": "default", "set": [],
            "seeds": list(args.seeds), "bench": str(args.bench),
            "learner": LEARNER, "sizes": [*SIZES, "frame"], "draw_stream": DRAW_STREAM, "caps": dict(profile["rl"]),
            "rows": rows, "ico_grid": ico_grid, "git": results.git_info(), "cell_builds": bench.cell_builds(every)}


def row(k, recs, cells, ico_costs, note) -> dict[str, Any]:
    out: dict[str, Any] = {"k": k,
                           "ico": {key: bench.seed_stat([c[key] for c in ico_costs]) for key in ico_costs[0]}}
    if not recs:
        out["note"] = note
        return out
    agg = bench.aggregate({LEARNER: recs}, {LEARNER: cells})[LEARNER]
    within = np.array([[metrics.success_within(cells[s], WITHIN)[i] for i in range(len(WITHIN))] for s in cells])
    out.update(success_rate=agg["success_rate"], median_trials_to_success=agg["median_trials_to_success"],
               within={str(b): bench.seed_stat(list(within[:, i])) for i, b in enumerate(WITHIN)},
               learner=agg["cost"], n_seeds=len(recs))
    out["total_trials"] = bench.seed_stat([float(r["summary"]["total_trials"]) + c["trials"]
                                       for r, c in zip(recs, ico_costs)])
    out["total_simulated_time"] = bench.seed_stat([float(r["summary"]["total_elapsed_time"]) + c["simulated_time"]
                                               for r, c in zip(recs, ico_costs)])
    return out


def table(data: dict[str, Any]) -> list[str]:
    """The ablation's table (docs/results.md, block ico-ablation) and the ICO grid's cost under it."""
    within = " | ".join(f"≤ {b} trials" for b in WITHIN)
    lines = [f"| ICO cells | ICO trials | success | {within} | learner trials | total trials | "
             "total simulated time (s) |", "|---|---|---|" + "---|" * len(WITHIN) + "---|---|---|"]
    for r in data["rows"].values():
        cells = f"central frame ({r['ico']['cells']['mean']:.0f})" if r["k"] == "frame" else str(r["k"])
        head = f"| {cells} | {tables.number(r['ico']['trials'])} | "
        if "success_rate" not in r:
            lines.append(head + f"n/a ({r['note']}) |" + " |" * (len(WITHIN) + 3))
            continue
        lines.append(head + f"{tables.rate(r['success_rate'])} | "
                     + " | ".join(tables.rate(r["within"][str(b)]) for b in WITHIN)
                     + f" | {tables.number(r['learner']['trials'])} | {tables.number(r['total_trials'])} | "
                     f"{tables.number(r['total_simulated_time'])} |")
    grid = data["ico_grid"]
    return lines + ["", f"The bench runs ICO on every cell of the grid ({grid['cells']['mean']:.0f}): "
                    f"{tables.number(grid['trials'])} trials, {tables.number(grid['simulated_time'])} simulated s "
                    "per seed; the prior takes only its central frame."]


def markdown(data: dict[str, Any]) -> str:
    return "\n".join([f"ICO-phase ablation, {data['plant']}, seeds {data['seeds']}, learners' cap "
                      f"{data['caps'].get('max_trials', 'C default')} trials, learner "
                      f"{REGISTRY[data['learner']].label} (python -m icoac.tools.ico_ablation).", "",
                      *table(data)]) + "\n"


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(prog="python -m icoac.tools.ico_ablation", description=__doc__.split("\n")[0])
    ap.add_argument("--bench", required=True, type=Path, help="a bench's output directory (its ico and "
                    "ico-mean-rl grids)")
    ap.add_argument("--out", required=True, type=Path)
    ap.add_argument("--plant", default="cart_pole")
    ap.add_argument("--profile", default="default", choices=tuple(bench.PROFILES), help="the learners' caps")
    ap.add_argument("--seeds", type=int, nargs="+", default=[0, 1])
    ap.add_argument("--ridge", type=float, default=P.DEFAULT_RIDGE)
    ap.add_argument("--prior-std", type=float, default=P.DEFAULT_STD)
    ap.add_argument("--threads", type=int, default=0)
    ap.add_argument("--data", type=Path, help="also write the summary's data here (docs/data/...)")
    ap.add_argument("--quiet", action="store_true")
    args = ap.parse_args(argv)
    status, data = guarded(lambda: run(args))
    if data is None:
        return status
    text = json.dumps(data, indent=1)
    (args.out / "ablation.json").write_text(text)
    (args.out / "summary.md").write_text(markdown(data))
    if args.data is not None:
        args.data.write_text(text)
    print(markdown(data), end="")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
