"""The sweeps that chose the learners' defaults (method.md, L2-L4), as one command:

    python -m harness.tools.learner_sweeps --prior-from results/bench/ico/seed-0 --out results/sweeps

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
import json
import sys
from pathlib import Path

import numpy as np

from .. import results, store
from ..sweep import SweepOptions, run_sweep

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
# sigma_w around it, then grids. At least the settings ICO->RL was given (63 rows).
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
    ("rl-alone-noise-grid", "rl", ["actor.explore_ticks=1000", "actor.noise_std=2,3,5,8", "actor.scale=0.1,0.25,0.5"],
     False),
    ("rl-alone-schedule-grid", "rl", ["actor.noise_std=3", "actor.explore_ticks=100,300,1000",
                                      "prior_std=0.3,1,3"], False),
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
    lines = [f"# Learner sweeps ({out}; `make sweeps`, `python -m harness.tools.learner_sweeps --report`)", "",
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
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(prog="python -m harness.tools.learner_sweeps", description=__doc__.split("\n")[0])
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
    args = ap.parse_args(argv)
    if args.report:
        path = args.out / "summary.md"
        store.write_text(path, report(args.out))
        print(path)
        return 0
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
