"""The paper's comparison (Fig. 2b, 3): ICO grids per seed, priors, ICO->RL and RL grids, summary, figures.

Layout: OUT/<condition>/seed-<n>/ (results directories), OUT/bench.json (wall time per stage),
OUT/summary.md and OUT/summary.json (mean and sd over seeds next to the paper's numbers).
"""
from __future__ import annotations

import json
import math
import sys
import time
from pathlib import Path
from typing import Any, Mapping, Sequence

import numpy as np

from . import _binding as B
from . import metrics

CONDITIONS = ("ico", "ico-rl", "rl")
LABELS = {"ico": "ICO", "rl": "RL", "ico-rl": "ICO->RL"}
# Paper (Fig. 1b, 2b, 3a): ~68 % ICO, ~84 % ICO->RL; RL alone only "smaller" and "very slow" (Fig. 3 bars).
PAPER = {
    "ico": {"success_rate": 0.68, "note": "Fig. 1b: ~68 %; fast (Fig. 3b)"},
    "ico-rl": {"success_rate": 0.84, "note": "Fig. 2b: ~84 %; most cells 5-2000 trials, a few > 2000"},
    "rl": {"success_rate": None, "note": "Fig. 3: smaller domain than ICO, very slow; no number in the text"},
}

# Spread subset for smoke tests: rows (theta0 + 12 deg) x columns ((x0 + 2.4) / 0.1); includes
# Fig. 1g's start (row 8, column 19) and enough central cells for a prior.
QUICK_ROWS = (2, 8, 10, 12, 14, 22)
QUICK_COLS = (4, 19, 22, 24, 26, 44)
QUICK_CELLS = sorted(r * B.GRID_XS + c for r in QUICK_ROWS for c in QUICK_COLS)

PROFILES: dict[str, dict[str, Any]] = {
    # ICO at the paper's caps (1e5 trials, 1e5 steps), RL conditions with a reduced trial cap.
    # Measured on 2 cores (bench --seeds 1): ICO full grid ~111 s, ICO->RL ~72 s at a 2000-trial
    # cap (most of it in cells that never succeed; successes need a median of ~12 trials), RL alone
    # ~14 s. With a 1000-trial RL cap, 5 seeds take ~14 min, inside the 30 min budget.
    "default": {"seeds": 5, "ico": {}, "rl": {"max_trials": 1000}, "cells": None},
    "paper": {"seeds": 5, "ico": {}, "rl": {}, "cells": None},
    "quick": {"seeds": 2, "ico": {"max_trials": 6000, "success_steps": 2000},
              "rl": {"max_trials": 600, "success_steps": 2000}, "cells": QUICK_CELLS},
}


def seed_dir(out: Path, condition: str, seed: int) -> Path:
    return Path(out) / condition / f"seed-{seed}"


def _mean_sd(values: Sequence[float | None]) -> tuple[float | None, float | None, int]:
    v = np.array([x for x in values if x is not None and math.isfinite(x)], dtype=float)
    if v.size == 0:
        return None, None, 0
    sd = float(np.std(v, ddof=1)) if v.size > 1 else 0.0
    return float(np.mean(v)), sd, int(v.size)


STATS = (
    ("success_rate", "success rate (all)"),
    ("success_rate_interior", "success rate (interior)"),
    ("median_trials_to_success", "median trials to success"),
    ("mean_elapsed_time_success", "mean elapsed simulated time of successful cells (s)"),
)


def aggregate(records: Mapping[str, Sequence[Mapping[str, Any]]]) -> dict[str, Any]:
    """{condition: [run.json records over seeds]} -> mean/sd per statistic and condition."""
    out: dict[str, Any] = {}
    for cond, recs in records.items():
        if not recs:
            continue
        entry: dict[str, Any] = {"seeds": [r.get("seed") for r in recs],
                                 "n_cells": recs[0]["summary"]["n_cells"],
                                 "n_interior": recs[0]["summary"]["n_interior"],
                                 "max_trials": recs[0]["config"]["run"]["max_trials"],
                                 "success_steps": recs[0]["config"]["run"]["success_steps"],
                                 "paper": PAPER.get(cond)}
        for key, _ in STATS:
            values = [r["summary"].get(key) for r in recs]
            mean, sd, n = _mean_sd(values)
            entry[key] = {"mean": mean, "sd": sd, "n": n, "per_seed": values}
        if cond == "ico-rl":
            t = [(r.get("prior_info") or {}).get("ico_phase_simulated_time") for r in recs]
            mean, sd, n = _mean_sd(t)
            entry["ico_phase_simulated_time"] = {"mean": mean, "sd": sd, "n": n, "per_seed": t}
        out[cond] = entry
    return out


def _fmt(stat: Mapping[str, Any] | None, pct: bool = False) -> str:
    if not stat or stat.get("mean") is None:
        return "n/a"
    if pct:
        return f"{100 * stat['mean']:.1f} ± {100 * stat['sd']:.1f} %"
    return f"{stat['mean']:.4g} ± {stat['sd']:.2g}"


def summary_markdown(agg: Mapping[str, Any]) -> str:
    lines = ["# ICO, RL and ICO->RL: mean ± sd over seeds", "",
             "| condition | seeds | caps (trials / steps) | success (all) | success (interior) | "
             "median trials to success | mean elapsed sim. time of successes (s) | paper |",
             "|---|---|---|---|---|---|---|---|"]
    for cond in CONDITIONS:
        if cond not in agg:
            continue
        e = agg[cond]
        paper = e["paper"] or {}
        ptxt = (f"{100 * paper['success_rate']:.0f} %; " if paper.get("success_rate") else "") + paper.get("note", "")
        lines.append(f"| {LABELS[cond]} | {len(e['seeds'])} | {e['max_trials']:g} / {e['success_steps']:g} | "
                     f"{_fmt(e['success_rate'], True)} of {e['n_cells']} | "
                     f"{_fmt(e['success_rate_interior'], True)} of {e['n_interior']} | "
                     f"{_fmt(e['median_trials_to_success'])} | {_fmt(e['mean_elapsed_time_success'])} | {ptxt} |")
    if "ico-rl" in agg and agg["ico-rl"].get("ico_phase_simulated_time", {}).get("mean") is not None:
        lines += ["", "ICO->RL counts RL-phase trials only (A17); the ICO phase that produced each prior took "
                  f"{_fmt(agg['ico-rl']['ico_phase_simulated_time'])} s of simulated time (whole ICO grid)."]
    lines += ["", "Success rates use the cells run as denominator (1225 / 1081 on the full grid). "
              "The paper's ~68 % / ~84 % are read as fractions of all 1225 cells."]
    return "\n".join(lines) + "\n"


def write_summary(out: Path, agg: Mapping[str, Any]) -> tuple[Path, Path]:
    out = Path(out)
    md = out / "summary.md"
    js = out / "summary.json"
    md.write_text(summary_markdown(agg))
    js.write_text(json.dumps(agg, indent=2) + "\n")
    return md, js


def comparison_figures(agg: Mapping[str, Any], figdir: Path, ico_cells: np.ndarray | None,
                       icorl_cells: np.ndarray | None, frame=None) -> list[Path]:
    """Fig. 2b (first ICO->RL seed, ICO success domain outlined), Fig. 3a, Fig. 3b."""
    from . import figures

    figdir = Path(figdir)
    written = []
    if icorl_cells is not None:
        outline = None
        if ico_cells is not None:
            outline = metrics.to_grid(ico_cells, metrics.success_mask(ico_cells).astype(float), fill=0) > 0
        written.append(figures.plot_success_map(icorl_cells, figdir / "fig2b_icorl_success_map.png",
                                                label="ICO->RL", outline=outline, frame=frame))
    conds = [c for c in CONDITIONS if c in agg]
    if conds:
        written.append(figures.plot_fig3a(figdir / "fig3a_success_rate.png", [LABELS[c] for c in conds],
                                          [agg[c]["success_rate"] for c in conds],
                                          [agg[c]["success_rate_interior"] for c in conds],
                                          [(PAPER.get(c) or {}).get("success_rate") for c in conds]))
        written.append(figures.plot_fig3b(figdir / "fig3b_elapsed_time.png", [LABELS[c] for c in conds],
                                          [agg[c]["mean_elapsed_time_success"] for c in conds]))
    return written


class BenchLog:
    """OUT/bench.json: wall time per stage and of the whole bench, rewritten after every stage."""

    def __init__(self, out: Path, meta: Mapping[str, Any]):
        self.path = Path(out) / "bench.json"
        self.path.parent.mkdir(parents=True, exist_ok=True)
        self.t0 = time.monotonic()
        self.data: dict[str, Any] = {"meta": dict(meta), "stages": [], "total_wall_time": 0.0,
                                     "complete": False}
        previous = None
        if self.path.is_file():
            try:
                previous = json.loads(self.path.read_text())
            except ValueError:
                previous = None
        if not isinstance(previous, dict):
            previous = None
        if previous and meta.get("resume") and isinstance(previous.get("previous_runs", []), list):
            self.data["previous_runs"] = previous.get("previous_runs", []) + [
                {"stages": previous.get("stages", []), "total_wall_time": previous.get("total_wall_time")}]

    def stage(self, name: str, wall: float, **info) -> None:
        self.data["stages"].append({"name": name, "wall_time": round(float(wall), 3), **info})
        self.flush()

    def flush(self, complete: bool = False) -> None:
        self.data["total_wall_time"] = round(time.monotonic() - self.t0, 3)
        self.data["complete"] = complete
        self.path.write_text(json.dumps(self.data, indent=2) + "\n")


def progress(msg: str) -> None:
    print(f"[bench] {msg}", file=sys.stderr, flush=True)
