# SPDX-License-Identifier: Apache-2.0
"""The sweep that chose a plant's task settings (its C file's task), as one command:

    python -m icoac.tools.plant_sweeps --plant PLANT --out results/sweeps-PLANT

The task settings are what the controller needs to know of a plant beyond the cart-pole's
defaults: the input scaling (arm angle, arm velocity and pendulum velocity ranges; the pendulum
angle is scaled to its failure limit), the reflex zone's angle, ICO's rate and the policy gain.
The criterion, fixed before the runs: ICO's success rate (all cells, mean over seeds); settings
within one point of the best are ordered by fewer median trials to success.

Stage 1 draws SAMPLES settings from the plant's space (TASK_SPACES; a seeded generator,
so the same settings every time)
and runs ICO on the 36 spread cells of the quick profile, seed 0. Stage 2 runs the best
STAGE_2_TOP of stage 1 on the grid's spread cells (one per column; 49 on a 25 x 49 grid), seeds 0 and 1; stage 3 varies one
parameter at a time over its values around stage 2's best, on the same cells and seeds. The
choice is the best of stages 2 and 3. Every stage resumes (finished settings are skipped);
--report writes summary.md (docs/sweeps-<plant>.md).

The learners (``--stage learners --prior-from ICO_DIR``, an ICO grid of the plant with the chosen
task settings): the scale of their exploration noise is in the plant's input unit (N, V), and the
actor reading each took from the cart-pole's sweeps may not carry over. Each actor-critic learner
(LEARNER_SPACE) runs its own reading at four noise scales and the other learner's reading at three,
on at most LEARNER_FAILED cells the ICO grid failed (evenly thinned) and on the grid's spread cells,
2 seeds, cap 1000 trials, as the cart-pole's learner sweeps; criterion fixed before the runs:
success on the ICO-failed cells, ties within one point by the spread cells, then fewer median
trials.
"""
from __future__ import annotations

import argparse
import csv
import io
import json
import math
import sys
import time
from pathlib import Path

import numpy as np

from icoac.core import binding as B
from icoac.core import geometry, grid, metrics, results, store
from icoac.core.config import build_config
from icoac.studies.sweep import SweepOptions, run_sweep

SAMPLES = 80
STAGE_2_TOP = 5
MAX_TRIALS = 20000
SUCCESS_STEPS = 2000
FIELDS = ["key", "seed", "cells", "success_rate", "median_trials", "wall_time"]
LEARNER_SPACE = {"ico-rl": ("actor.noise_std", (0.1, 0.3, 1.0, 3.0)),
                 "rl": ("actor.noise_std", (0.3, 1.0, 3.0, 12.0))}
# The two actor readings the cart-pole's sweeps chose (ICO->RL's, the C defaults; RL alone's), and
# each learner's own. Each learner also runs the other's reading at OTHER_READING_NOISE, so both
# get the same settings: their own reading at four noise scales, the other's at three.
READINGS = {"gradient": {"actor.update": "gradient", "actor.likelihood_std": 0, "actor.scale": 0.5},
            "mean": {"actor.update": "mean", "actor.likelihood_std": 0.1, "actor.scale": 0.1}}
OWN_READING = {"ico-rl": "gradient", "rl": "mean"}
OTHER_READING_NOISE = (0.3, 1.0, 3.0)
LEARNER_FAILED = 200
LEARNER_MAX_TRIALS = 1000

# Each swept plant's task space: values of its task's knobs (its C file, `icoac params --plant`),
# ICO's rate and the policy gain; a setting is a configuration override of each. Each of the double
# pendulum's spaces put its best at its edges, and the next extends those dimensions beyond it: the
# first (rate 0.01, gain 30 N, both velocity ranges and the zone at their largest), the second
# (cart velocity range 10 m/s, rate 0.1, gain 3 N).
TASK_SPACES: dict[str, tuple[tuple[str, tuple[float, ...]], ...]] = {
    "furuta": (("arm_range", (0.5, 1.0, 1.5708, 3.0)),
               ("arm_velocity_range", (1.0, 2.3, 6.4, 15.0, 40.0)),
               ("pendulum_velocity_range", (0.3, 0.6, 1.0, 2.0, 5.6)),
               ("zone_deg", (11.5, 10.0, 8.0, 6.0)),
               ("ico.rate", (1e-4, 1e-3, 1e-2)),
               ("policy.gain", (1.0, 3.0, 10.0))),
    "double_cart_pole": (("cart_velocity_range", (1.0, 2.0, 3.5, 6.0, 10.0, 17.0, 30.0)),
                         ("link_velocity_range", (0.5, 1.0, 2.0, 4.0, 8.0)),
                         ("zone_deg", (11.0, 10.0, 8.0, 6.0, 4.0)),
                         ("upper_reflex", (1.0, -1.0)),
                         ("cart_reflex", (1.0, -1.0)),
                         ("ico.rate", (1e-4, 1e-3, 1e-2, 1e-1, 0.3, 1.0)),
                         ("policy.gain", (0.3, 1.0, 3.0, 10.0, 30.0, 100.0))),
}


def space(plant: str) -> tuple:
    """The plant's task space: (name, values) pairs (TASK_SPACES)."""
    return TASK_SPACES[plant]


def samples(plant: str, seed: int = 1) -> list[dict]:
    """The stage-1 settings, drawn in a fixed order from a seeded generator."""
    rng = np.random.default_rng(seed)
    return [{name: float(rng.choice(values)) for name, values in space(plant)} for _ in range(SAMPLES)]


def key(setting: dict) -> str:
    return ",".join(f"{name}={value:g}" for name, value in setting.items())


def overrides(plant: str, setting: dict) -> dict:
    """The controller settings of a sample, with the sweep's caps."""
    return {**setting, "max_trials": MAX_TRIALS, "success_steps": SUCCESS_STEPS}


def run_one(plant: str, setting: dict, seed: int, cells: list[int]) -> dict:
    cfg = build_config(overrides(plant, setting), plant=plant)
    arr = grid.make_cells(seed, cells, plant=plant)
    t0 = time.monotonic()
    run = grid.run_grid(cfg, arr, progress=False)
    if run.cancelled:
        raise KeyboardInterrupt
    ok = metrics.success_mask(arr)
    return {"key": key(setting), "seed": seed, "cells": len(cells), "success_rate": float(ok.mean()),
            "median_trials": float(np.median(arr["trials"][ok])) if ok.any() else "",
            "wall_time": round(time.monotonic() - t0, 2)}


def read_rows(path: Path) -> list[dict]:
    if not path.is_file():
        return []
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def run_stage(plant: str, path: Path, settings: list[dict], seeds: list[int], cells: list[int]) -> list[dict]:
    rows = read_rows(path)
    done = {(r["key"], int(r["seed"])) for r in rows}
    for i, setting in enumerate(settings, 1):
        for seed in seeds:
            if (key(setting), seed) in done:
                continue
            rows.append(run_one(plant, setting, seed, cells))
            text = io.StringIO(newline="")
            writer = csv.DictWriter(text, fieldnames=FIELDS)
            writer.writeheader()
            writer.writerows(rows)
            store.write_text(path, text.getvalue())
            r = rows[-1]
            print(f"[{i}/{len(settings)}] seed {seed}: {r['key']}: success {r['success_rate']:.3f}", file=sys.stderr)
    return rows


def ranked(rows: list[dict]) -> list[dict]:
    """Settings by the criterion: mean success over seeds; within one point of the best, fewer
    median trials first (no success: last)."""
    by_key: dict[str, list[dict]] = {}
    for r in rows:
        by_key.setdefault(r["key"], []).append(r)
    out = []
    for k, rs in by_key.items():
        med = [float(r["median_trials"]) for r in rs if r["median_trials"] not in ("", None)]
        out.append({"key": k, "seeds": len(rs), "success_rate": float(np.mean([float(r["success_rate"]) for r in rs])),
                    "median_trials": float(np.median(med)) if med else math.inf})
    out.sort(key=lambda r: -r["success_rate"])
    if out:
        best = out[0]["success_rate"]
        top = sorted([r for r in out if r["success_rate"] >= best - 0.01], key=lambda r: r["median_trials"])
        out = top + [r for r in out if r["success_rate"] < best - 0.01]
    return out


def one_at_a_time(plant: str, out: Path) -> list[dict]:
    """Stage 3's settings: stage 2's best with one parameter changed to each of its other values."""
    best = setting_of(ranked(read_rows(out / "stage2.csv"))[0]["key"])
    return [{**best, name: float(v)} for name, values in space(plant) for v in values if float(v) != best[name]]


def setting_of(k: str) -> dict:
    return {name: float(value) for name, value in (item.split("=") for item in k.split(","))}


def _trials(median: float) -> str:
    return "-" if math.isinf(median) else f"{median:g}"


def report(plant: str, out: Path) -> Path:
    plant_grid = geometry.of(plant)
    s1, s2, s3 = (ranked(read_rows(out / f"stage{i}.csv")) for i in (1, 2, 3))
    final = ranked(read_rows(out / "stage2.csv") + read_rows(out / "stage3.csv"))
    lines = [f"# The {plant}'s task settings: sweep", "",
             f"Written by `python -m icoac.tools.plant_sweeps --plant {plant} --out {out} --report`.", "",
             "Criterion, fixed before the runs: ICO's success rate (all cells, mean over seeds); settings within "
             "one point of the best are ordered by fewer median trials to success.", "",
             f"Space: {', '.join(f'{n} in {list(v)}' for n, v in space(plant))}; the angles are scaled to their "
             "failure limits and the critic grid spans the same ranges (the names other than ico.rate and policy.gain "
             f"are knobs of the plant's task, which its C file writes the controller's task from: `python -m icoac "
             f"params --plant {plant}`). Stage 1: "
             f"{SAMPLES} settings drawn from it (seeded), ICO on the quick profile's "
             f"{len(plant_grid.quick_cells())} spread cells, "
             f"seed 0, cap {MAX_TRIALS} trials, success {SUCCESS_STEPS} steps. Stage 2: the best {STAGE_2_TOP} "
             f"on {len(plant_grid.spread_cells())} cells evenly over the grid, seeds 0 and 1, same caps. Stage 3: one "
             "parameter at a time over its values around stage 2's best, same cells, seeds and caps. The choice "
             "is the best of stages 2 and 3 by the criterion.", ""]
    for title, rows in (("Stages 2 and 3, ranked together", final), ("Stage 3", s3), ("Stage 2", s2),
                        ("Stage 1", s1)):
        lines += [f"## {title}", "", "| rank | setting | seeds | success | median trials |", "|---|---|---|---|---|"]
        lines += [f"| {i} | {r['key']} | {r['seeds']} | {100 * r['success_rate']:.1f} % | "
                  f"{_trials(r['median_trials'])} |" for i, r in enumerate(rows, 1)]
        lines.append("")
    if final:
        lines += ["## Choice", "", f"`{final[0]['key']}` (the task of sim_host/src/plants/{plant}.c).", ""]
    if any(learner_ranking(out, c) for c in LEARNER_SPACE):
        lines += ["## Learners", "",
                  f"On the plant's ICO grid of seed 0 at the chosen task settings (`--stage learners`): each "
                  "actor-critic learner at its own reading (from the cart-pole's sweeps) and four exploration "
                  f"noise scales, and at the other learner's reading and noise {list(OTHER_READING_NOISE)}, on at "
                  f"most {LEARNER_FAILED} cells that grid failed (evenly thinned) and on the {len(plant_grid.spread_cells())} "
                  f"spread cells, 2 seeds, cap {LEARNER_MAX_TRIALS} trials. Readings: "
                  + "; ".join(f"{r}: {', '.join(f'{k}={v}' for k, v in s.items())}" for r, s in READINGS.items())
                  + ". Criterion, fixed before the runs: success on the ICO-failed cells; within one point, the "
                  "spread cells, then fewer median trials. The learners' other settings are the cart-pole's; "
                  "the searches keep theirs.", ""]
    for condition in LEARNER_SPACE:
        table = learner_ranking(out, condition)
        if not table:
            continue
        lines += [f"## Learner {condition}: reading and exploration noise", "",
                  "| rank | reading | setting | success, ICO-failed cells | success, spread cells | median trials |",
                  "|---|---|---|---|---|---|"]
        lines += [f"| {i} | {r['reading']} | {r['key']} | {100 * r['ico_failed']:.1f} % | {100 * r['spread']:.1f} % | "
                  f"{_trials(r['median_trials'])} |" for i, r in enumerate(table, 1)]
        if table[0]["ico_failed"] > 0 or table[0]["spread"] > 0:
            lines += ["", f"Choice: `{table[0]['key']}`.", ""]
        else:
            lines += ["", "No setting balances a cell: the learner keeps its defaults.", ""]
    path = out / "summary.md"
    store.write_text(path, "\n".join(lines) + "\n")
    return path


def learner_cells(ico_dir: Path) -> dict[str, list[int]]:
    """The learner sweeps' cell sets: the ICO-failed cells (at most LEARNER_FAILED, evenly thinned)
    and the spread cells."""
    cells, record = results.load(ico_dir, what="--prior-from")
    failed = np.flatnonzero(cells["outcome"] == B.FAILED)
    if failed.size > LEARNER_FAILED:
        failed = failed[np.round(np.linspace(0, failed.size - 1, LEARNER_FAILED)).astype(int)]
    return {"ico-failed": [int(i) for i in failed], "spread": geometry.of(results.record_plant(record)).spread_cells()}


def _other(condition: str) -> str:
    return next(r for r in READINGS if r != OWN_READING[condition])


def learner_dirs(out: Path, condition: str) -> dict[str, tuple[str, list[float]]]:
    """{directory stem: (reading, noise values)} of a learner's sweeps (its own reading's under
    learners/<condition>-<cells>, the other's under learners/<condition>-<reading>-<cells>)."""
    name, values = LEARNER_SPACE[condition]
    return {f"{condition}": (OWN_READING[condition], list(values)),
            f"{condition}-{_other(condition)}": (_other(condition), list(OTHER_READING_NOISE))}


def run_learners(ico_dir: Path, out: Path) -> None:
    for condition, (name, _) in LEARNER_SPACE.items():
        for stem, (reading, values) in learner_dirs(out, condition).items():
            # both readings pinned: a plant's learner defaults (its C file) may hold either
            fixed = [f"{k}={v}" for k, v in READINGS[reading].items()]
            for label, cells in learner_cells(ico_dir).items():
                run_sweep(SweepOptions(prior_from=ico_dir, out=out / "learners" / f"{stem}-{label}",
                                       params=[f"{name}={','.join(f'{v:g}' for v in values)}"], condition=condition,
                                       cells=grid.format_cell_indices(cells), seeds=2, sets=fixed,
                                       max_trials=LEARNER_MAX_TRIALS, quiet=True))


def learner_ranking(out: Path, condition: str) -> list[dict]:
    """A learner's settings (reading and noise) by the criterion (module docstring)."""
    table = []
    for stem, (reading, _) in learner_dirs(out, condition).items():
        def rows(label):
            return {r["key"]: r for r in read_rows(out / "learners" / f"{stem}-{label}" / "sweep.csv")}
        failed, spread = rows("ico-failed"), rows("spread")
        table += [{"key": json.dumps({**READINGS[reading], **json.loads(k)}),
                   "reading": reading,
                   "ico_failed": float(r["success_rate_ico_failed"] or r["success_rate_mean"]),
                   "spread": float(spread[k]["success_rate_mean"]) if k in spread else math.nan,
                   "median_trials": float(r["median_trials"]) if r["median_trials"] else math.inf}
                  for k, r in failed.items()]
    table.sort(key=lambda r: -r["ico_failed"])
    if table:
        best = table[0]["ico_failed"]
        top = sorted([r for r in table if r["ico_failed"] >= best - 0.01], key=lambda r: (-r["spread"], r["median_trials"]))
        table = top + [r for r in table if r["ico_failed"] < best - 0.01]
    return table


def main(argv=None) -> int:
    p = argparse.ArgumentParser(prog="python -m icoac.tools.plant_sweeps", description=__doc__.split("\n")[0])
    p.add_argument("--plant", required=True, choices=sorted(TASK_SPACES))
    p.add_argument("--out", required=True, type=Path)
    p.add_argument("--stage", choices=("1", "2", "3", "all", "learners"), default="all")
    p.add_argument("--prior-from", type=Path, default=None, help="the plant's ICO grid (stage learners)")
    p.add_argument("--report", action="store_true", help="only write summary.md")
    args = p.parse_args(argv)
    args.out.mkdir(parents=True, exist_ok=True)
    plant_grid = geometry.of(args.plant)
    if args.stage == "learners" and not args.report:
        if args.prior_from is None:
            p.error("--stage learners needs --prior-from ICO_DIR")
        run_learners(args.prior_from, args.out)
    elif not args.report:
        if args.stage in ("1", "all"):
            run_stage(args.plant, args.out / "stage1.csv", samples(args.plant), [0], plant_grid.quick_cells())
        if args.stage in ("2", "all"):
            top = [setting_of(r["key"]) for r in ranked(read_rows(args.out / "stage1.csv"))[:STAGE_2_TOP]]
            run_stage(args.plant, args.out / "stage2.csv", top, [0, 1], plant_grid.spread_cells())
        if args.stage in ("3", "all"):
            run_stage(args.plant, args.out / "stage3.csv", one_at_a_time(args.plant, args.out), [0, 1],
                      plant_grid.spread_cells())
    print(report(args.plant, args.out))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
