# SPDX-License-Identifier: Apache-2.0
"""The sweeps that chose the learners' defaults (method.md, L2-L4), as one command:

    python -m icoac.tools.learner_sweeps --prior-from results/bench/ico/seed-0 --out results/sweeps

Every sweep starts from the literal configuration (`--configuration literal`: the defaults before
these sweeps chose new ones), so it reproduces at any later commit. Each sweep runs on two cell
selections, 2 seeds each: `spread` (49 cells evenly over the grid)
and `ico-failed` (every cell where the ICO run of --prior-from failed). Stage 1 compares the actor
readings and their rates (with the no-learning control), and the search's parameters one at a
time, then small factorial grids of the search's breadth (cov_scale x floor x batch); stage 2 (``--stage 2 --base NAME=VALUE ...``) varies the exploration schedule, the batch
granularity, the critic quirks and the exploration scale around the stage-1 choice. Every sweep
resumes (finished settings are skipped), so an interrupted run loses nothing.
"""
from __future__ import annotations

import argparse
import csv
import hashlib
import json
import sys
from pathlib import Path

import numpy as np

from icoac.core import geometry, results, store
from icoac.core.config import NAMED_CONFIGURATIONS
from icoac.studies.sweep import SweepOptions, run_sweep

SEEDS = 2
MAX_TRIALS = 1000
SPREAD_CELLS = 49

# (name, condition, parameters, one at a time)
STAGE_1 = (
    ("ico-rl-control", "ico-rl-control", ["actor.update=posterior"], False),
    ("ico-rl-posterior", "ico-rl", ["actor.update=posterior", "actor.likelihood_std=0.3,1,3,10"], False),
    ("ico-rl-mean", "ico-rl", ["actor.update=mean", "actor.likelihood_std=0.03,0.1,0.3,1,3,10"], False),
    ("ico-rl-gradient", "ico-rl", ["actor.update=gradient",
                                     "actor.rate=0.0001,0.0003,0.001,0.003,0.01,0.03,0.1"], False),
    ("rl-control", "rl-ico-cov-control", ["actor.update=posterior"], False),
    ("rl-posterior", "rl-ico-cov", ["actor.update=posterior", "actor.likelihood_std=1,10"], False),
    ("rl-mean", "rl-ico-cov", ["actor.update=mean", "actor.likelihood_std=0.1,0.3,1,10"], False),
    ("rl-gradient", "rl-ico-cov", ["actor.update=gradient", "actor.rate=0.001,0.003,0.01,0.03,0.1"], False),
    ("ico-search-control", "ico-search-control", ["search.cov_scale=1,16,256"], False),
    ("ico-search", "ico-search", ["search.batch=2,4,8", "search.elite_fraction=0.25,0.5",
                                  "search.step=0.5,1", "search.floor=0.01,0.1,1",
                                  "search.cov_scale=1,4,16,64,256"], True),
    ("ico-search-grid", "ico-search", ["search.cov_scale=16,64,256", "search.floor=0.1,1", "search.batch=4,8",
                                       "search.elite_fraction=0.25"], False),
    ("search-control", "search-control", ["search.cov_scale=1,4"], False),
    ("search-grid", "search", ["search.cov_scale=1,4", "search.floor=0.1,1", "search.batch=4,8",
                               "search.elite_fraction=0.25"], False),
    ("search", "search", ["search.batch=2,4,8", "search.elite_fraction=0.25,0.5",
                          "search.step=0.5,1", "search.floor=0.01,0.1,1",
                          "search.cov_scale=1,4,16"], True),
)
# One at a time: the first value of each list is the base (the defaults around the stage-1 choice).
STAGE_2 = (
    ("ico-rl-stage2", "ico-rl", ["actor.explore_ticks=0,100,1000", "actor.batch=0,1", "critic.quirks=0,1",
                                 "actor.noise_std=1,0.3,0.5,2", "actor.scale=0.5,0.25,2"], True),
    ("ico-rl-schedule-grid", "ico-rl", ["actor.explore_ticks=30,100,300", "actor.rate=0.0003,0.001,0.003"], False),
    ("ico-rl-schedule-grid2", "ico-rl", ["actor.explore_ticks=100,300,1000", "actor.rate=0.003,0.01,0.03"], False),
    ("ico-rl-noise-grid", "ico-rl", ["actor.explore_ticks=1000", "actor.noise_std=1,2,3,5",
                                        "actor.rate=0.0003,0.001,0.003,0.01"],
     False),
    ("rl-stage2", "rl-ico-cov", ["actor.explore_ticks=0,100,1000", "actor.batch=0,1", "critic.quirks=0,1",
                         "actor.noise_std=1,0.3,0.5,2", "actor.scale=0.5,0.25,2"], True),
    ("rl-schedule-grid", "rl-ico-cov", ["actor.explore_ticks=30,100,300", "actor.likelihood_std=0.03,0.1,0.3"], False),
    ("rl-noise-grid", "rl-ico-cov", ["actor.noise_std=1,2,3", "actor.scale=0.5,2,8"], False),
    ("rl-noise-grid2", "rl-ico-cov", ["actor.noise_std=3,5", "actor.scale=0.25,0.5", "actor.explore_ticks=0,1000"], False),
    ("rl-noise-grid3", "rl-ico-cov", ["actor.explore_ticks=1000", "actor.noise_std=5,8", "actor.scale=0.1,0.25"], False),
)


# RL alone from N(0, sigma_w^2 I) (--stage rl-alone): nothing from ICO reaches it; the ICO grid
# of --prior-from only names the ICO-failed cells, the same selection every condition is chosen
# on. The criterion is the one above, fixed before these runs: the highest success on the
# ICO-failed cells, ties (within one point) broken by the spread cells, then by fewer median
# trials. Stage 1 varies the reading with its rate and the prior's sigma_w; stage 2 (``--base``
# the stage-1 choice) the exploration schedule, the batch, the critic quirks, sigma_u, alpha and
# sigma_w one at a time, then grids over what the chosen reading uses, and the mean reading at
# the schedule stage 1 left out; --confirm runs the best 3 on every cell with 5 seeds. More
# settings than ICO->RL was given (63 rows).
RL_ALONE_1 = (
    ("rl-alone-control", "rl-control", ["actor.update=posterior"], False),
    ("rl-alone-posterior", "rl", ["actor.update=posterior", "actor.likelihood_std=1,10", "prior_std=0.1,1,10"],
     False),
    ("rl-alone-mean", "rl", ["actor.update=mean", "actor.likelihood_std=0.1,0.3,1,10", "prior_std=0.1,0.3,1,3,10"],
     False),
    ("rl-alone-gradient", "rl", ["actor.update=gradient", "actor.rate=0.0003,0.001,0.003,0.01,0.03,0.1"], False),
)
RL_ALONE_2 = (
    ("rl-alone-stage2", "rl", ["actor.explore_ticks=0,100,1000", "actor.batch=0,1", "critic.quirks=0,1",
                               "actor.noise_std=1,0.5,2,3,5", "actor.scale=0.5,0.1,0.25,2", "prior_std=1,0.3,3"],
     True),
    # The grids vary what the gradient reading uses (beta, sigma_u, the schedule, the batch);
    # alpha and sigma_w play no part in it (the spread cells of stage 2: identical rows).
    ("rl-alone-schedule-grid", "rl", ["actor.explore_ticks=300,1000,3000", "actor.batch=0,1",
                                      "actor.rate=0.01,0.03,0.1"], False),
    # sigma_u x beta at the schedule grid's choice (--base)
    ("rl-alone-noise-grid", "rl", ["actor.noise_std=0.5,1,2,3", "actor.rate=0.01,0.03,0.1"], False),
    # The mean reading at the schedule its stage 1 never tried (exploring until tick 1000, alpha =
    # 0.1): sigma_u x sigma_w, which it uses as the preconditioner of every step.
    ("rl-alone-mean-grid", "rl", ["actor.update=mean", "actor.likelihood_std=0.1", "actor.explore_ticks=1000",
                                  "actor.scale=0.1", "actor.noise_std=3,5,8", "prior_std=0.3,1,3"], False),
    # past the mean grid's edge (its best sigma_u, 8 N, was the largest tried)
    ("rl-alone-mean-edge", "rl", ["actor.update=mean", "actor.likelihood_std=0.1", "actor.explore_ticks=1000",
                                  "actor.scale=0.1", "actor.noise_std=12,16", "prior_std=1"], False),
)


def ico_failed_cells(prior_from: Path) -> str:
    """Cell indices (a --cells spec) where the ICO run failed."""
    cells, _ = results.load(prior_from, what="--prior-from")
    failed = np.nonzero(cells["outcome"] != 1)[0]
    return ",".join(str(int(i)) for i in failed)


SELECTIONS = ("spread", "ico-failed")
PLANS = {"1": STAGE_1, "2": STAGE_2, "rl-alone": RL_ALONE_1, "rl-alone-2": RL_ALONE_2}


def _pct(row: dict | None, key: str) -> str:
    if not row or row.get(key) in (None, ""):
        return "n/a"
    return f"{100 * float(row[key]):.1f}"


def report(out: Path) -> str:
    """One markdown table per sweep of OUT: each setting on the spread and the ICO-failed cells
    (success mean ± sd over the seeds, %; median trials to success), in run order."""
    lines = [f"# Learner sweeps ({out}; `make sweeps`, `python -m icoac.tools.learner_sweeps --report`)", "",
             "Success in % of the selection's cells, mean ± sd over the seeds; median trials to success. "
             "Spread: 49 cells evenly over the grid; ICO-failed: the cells where the ICO grid of --prior-from failed.",
             ""]
    for name, condition, _params, _one in STAGE_1 + STAGE_2 + RL_ALONE_1 + RL_ALONE_2:
        tables = {}
        for sel in SELECTIONS:
            path = out / f"{name}-{sel}" / "sweep.csv"
            if path.is_file():
                with open(path, newline="") as fh:
                    tables[sel] = {r["key"]: r for r in csv.DictReader(fh)}
        if not tables:
            continue
        meta = json.loads((out / f"{name}-{next(iter(tables))}" / "sweep.json").read_text())
        commits = []
        for sel in tables:
            for run in json.loads((out / f"{name}-{sel}" / "sweep.json").read_text()).get("runs", []):
                git = run.get("git") or {}
                label = (git.get("commit") or "unknown")[:7] + ("+dirty" if git.get("dirty") else "")
                if run.get("settings") and label not in commits:
                    commits.append(label)
        keys = list(dict.fromkeys(k for t in tables.values() for k in t))
        n_failed = next((r["n_ico_failed"] for r in tables.get("ico-failed", {}).values()), "?")
        lines += [f"## {name} ({condition}; seeds {meta['seeds']}, cap {meta['max_trials']} trials; "
                  f"run at {', '.join(commits) or 'unrecorded commits'})", "",
                  f"Fixed: {', '.join(meta['set']) or 'the defaults'}.", "",
                  f"| setting | spread 49 cells: success % (± sd) | median trials | ICO-failed {n_failed} cells: "
                  "success % (± sd) | median trials |", "|---|---|---|---|---|"]
        for k in keys:
            setting = ", ".join(f"{a}={b}" for a, b in json.loads(k).items())
            cols = []
            for sel in SELECTIONS:
                r = tables.get(sel, {}).get(k)
                cols += [f"{_pct(r, 'success_rate_mean')} ± {_pct(r, 'success_rate_sd')}",
                         (r or {}).get("median_trials") or "n/a"]
            lines.append(f"| {setting} | " + " | ".join(cols) + " |")
        lines.append("")
    return "\n".join(lines + rl_alone_report(out))


def rl_alone_report(out: Path, prefix: str = "rl-alone", top: int = 10) -> list[str]:
    """RL alone's ranking by the criterion and its 5-seed confirmations (every cell)."""
    rows = ranked_rows(out, prefix)
    if not rows:
        return []
    lines = [f"## RL alone: the best {top} distinct settings by the criterion", "",
             "Highest success on the ICO-failed cells; rows within one point of the best ordered by the spread "
             "cells, then by fewer median trials (2 seeds, cap 1000).", "",
             "| rank | sweep | setting (beside the literal configuration) | ICO-failed % (± sd) | spread % | "
             "median trials |", "|---|---|---|---|---|---|"]
    for i, r in enumerate(rows[:top], 1):
        lines.append(f"| {i} | {r['sweep']} | {', '.join(literal_items(r['setting']))} | "
                     f"{100 * r['ico_failed']:.1f} ± {100 * r['ico_failed_sd']:.1f} | {100 * r['spread']:.1f} | "
                     f"{r['median_trials']:g} |")
    confirmed = sorted(out.glob(f"{prefix}-confirm-*/sweep.csv"))
    if confirmed:
        lines += ["", f"## RL alone: {CONFIRM_SEEDS}-seed grids of every cell (`--confirm`)", "",
                  "| setting | success, all cells % (± sd) | ICO-failed cells % | median trials |", "|---|---|---|---|"]
        for path in confirmed:
            with open(path, newline="") as fh:
                for r in csv.DictReader(fh):
                    setting = ", ".join(f"{a}={b}" for a, b in json.loads(r["key"]).items())
                    lines.append(f"| {setting} | {_pct(r, 'success_rate_mean')} ± {_pct(r, 'success_rate_sd')} | "
                                 f"{_pct(r, 'success_rate_ico_failed')} | {r['median_trials'] or 'n/a'} |")
    return lines + [""]


# RL alone's confirmation: the best few distinct settings of its sweeps, on every cell of the grid
# with 5 seeds, ranked by the same criterion (its ICO-failed cells are those of --prior-from).
CONFIRM_SEEDS = 5
CONFIRM_FEW = 3
ALL_CELLS = f"0-{geometry.CELLS - 1}"
ONE_POINT = 0.01


def _effective(items: list[str]) -> dict[str, str]:
    """NAME=VALUE items applied in order (a later item overrides an earlier one)."""
    return dict(item.split("=", 1) for item in items)


def ranked_rows(out: Path, prefix: str) -> list[dict]:
    """Every learning row of the sweeps OUT/PREFIX-*-ico-failed (no-learning controls and
    confirmations left out), each with its full setting (the sweep's fixed items, then the row's)
    and its spread row, best first by the criterion: the highest ICO-failed success; rows within
    one point of the best are ordered by spread success, then by fewer median trials. Rows with
    identical results on both selections (parameters the reading does not use) count once."""
    rows, seen = [], set()
    for path in sorted(out.glob(f"{prefix}-*-ico-failed/sweep.csv")):
        name = path.parent.name[: -len("-ico-failed")]
        meta = json.loads((path.parent / "sweep.json").read_text())
        if meta["condition"].endswith("-control") or "-confirm" in name:
            continue
        spread_path = out / f"{name}-spread" / "sweep.csv"
        spread = {}
        if spread_path.is_file():
            with open(spread_path, newline="") as fh:
                spread = {r["key"]: r for r in csv.DictReader(fh)}
        with open(path, newline="") as fh:
            for r in csv.DictReader(fh):
                s = spread.get(r["key"], {})
                setting = _effective(meta["set"] + [f"{a}={b}" for a, b in json.loads(r["key"]).items()])
                row = {"sweep": name, "setting": setting, "ico_failed": float(r["success_rate_mean"]),
                       "ico_failed_sd": float(r["success_rate_sd"]),
                       "spread": float(s["success_rate_mean"]) if s else float("nan"),
                       "median_trials": float(r["median_trials"]) if r["median_trials"] else float("inf")}
                signature = (r["success_rate_mean"], r["success_rate_sd"], r["median_trials"],
                             s.get("success_rate_mean"), s.get("median_trials"))
                if signature not in seen:
                    seen.add(signature)
                    rows.append(row)
    rows.sort(key=lambda r: -r["ico_failed"])
    if rows:
        best = rows[0]["ico_failed"]
        near = [r for r in rows if r["ico_failed"] >= best - ONE_POINT]
        near.sort(key=lambda r: (-r["spread"], r["median_trials"]))
        rows = near + rows[len(near):]
    return rows


def literal_items(setting: dict[str, str]) -> list[str]:
    """The items of a full setting that differ from the literal configuration."""
    base = _effective(list(NAMED_CONFIGURATIONS["literal"]))
    return [f"{k}={v}" for k, v in setting.items() if base.get(k) != v]


def confirm_name(prefix: str, items: list[str]) -> str:
    """Directory of a setting's confirmation, named by the setting (a later ranking keeps it)."""
    return f"{prefix}-confirm-" + hashlib.sha1(",".join(items).encode()).hexdigest()[:8]


def confirm(args, prefix: str = "rl-alone") -> int:
    """5-seed grids (every cell) of the best few settings of the sweeps OUT/PREFIX-*."""
    for row in ranked_rows(args.out, prefix)[:CONFIRM_FEW]:
        items = literal_items(row["setting"])
        name = confirm_name(prefix, items)
        print(f"[learner_sweeps] {name}: {', '.join(items)}", file=sys.stderr, flush=True)
        code = run_sweep(SweepOptions(prior_from=args.prior_from, out=args.out / name,
                                      params=items, condition="rl", seeds=CONFIRM_SEEDS, cells=ALL_CELLS,
                                      max_trials=MAX_TRIALS, configuration="literal", sets=[],
                                      one_at_a_time=False, threads=args.threads, quiet=True))
        if code:
            return code
    return 0


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(prog="python -m icoac.tools.learner_sweeps", description=__doc__.split("\n")[0])
    ap.add_argument("--prior-from", required=True, type=Path, help="ICO results directory (one seed)")
    ap.add_argument("--out", required=True, type=Path, help="one subdirectory per sweep and selection")
    ap.add_argument("--stage", choices=tuple(PLANS), default="1",
                    help="1, 2: the sweeps that chose ICO->RL's, RL with the ICO covariance's and the search's "
                         "defaults; rl-alone, rl-alone-2: RL alone from N(0, sigma_w^2 I)")
    ap.add_argument("--base", action="append", default=[], metavar="NAME=VALUE",
                    help="stage 2: the stage-1 choice, fixed in every setting (repeatable)")
    ap.add_argument("--only", action="append", default=[], help="run only the sweeps of these names")
    ap.add_argument("--threads", type=int, default=0)
    ap.add_argument("--report", action="store_true", help="only write OUT/summary.md from the finished sweeps")
    ap.add_argument("--confirm", action="store_true",
                    help=f"RL alone: {CONFIRM_SEEDS}-seed grids of every cell for the best {CONFIRM_FEW} settings "
                         "of OUT's rl-alone sweeps")
    args = ap.parse_args(argv)
    if args.report:
        path = args.out / "summary.md"
        store.write_text(path, report(args.out))
        print(path)
        return 0
    if args.confirm:
        return confirm(args)
    selections = {"spread": dict(subset=SPREAD_CELLS), "ico-failed": dict(cells=ico_failed_cells(args.prior_from))}
    plan = PLANS[args.stage]
    for name, condition, params, one_at_a_time in plan:
        if args.only and name not in args.only:
            continue
        for label, selection in selections.items():
            print(f"[learner_sweeps] {name} on {label} cells", file=sys.stderr, flush=True)
            code = run_sweep(SweepOptions(prior_from=args.prior_from, out=args.out / f"{name}-{label}",
                                          params=params, condition=condition, seeds=SEEDS,
                                          max_trials=MAX_TRIALS, configuration="literal", sets=args.base,
                                          one_at_a_time=one_at_a_time, threads=args.threads, quiet=True,
                                          **selection))
            if code:
                return code
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
