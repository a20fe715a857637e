# SPDX-License-Identifier: Apache-2.0
"""Benchmark metrics (method.md, benchmark protocol) from a cell array."""
from __future__ import annotations

import math
from typing import Any

import numpy as np

from icoac.core import binding as B
from icoac.core import geometry
from icoac.core.geometry import grid_index, interior_mask, to_grid  # noqa: F401 (part of this API; the cart-pole's)


def success_mask(cells: np.ndarray) -> np.ndarray:
    return cells["outcome"] == B.SUCCESS


def trials_to_success(cells: np.ndarray) -> np.ndarray:
    """Trials to success per cell (successful trial included); NaN for cells that did not succeed."""
    out = cells["trials"].astype(float)
    out[~success_mask(cells)] = np.nan
    return out


# Trial budgets k of the learning curves (success within k trials): 1, 2, 3, 5 per decade up to
# 1e5, the paper's cap. A budget beyond a run's cap repeats its final rate.
CURVE_BUDGETS = tuple(m * 10 ** e for e in range(6) for m in (1, 2, 3, 5) if m * 10 ** e <= 100_000)
# Quantiles of the distributions of trials and simulated time to success.
QUANTILES = (0.1, 0.25, 0.5, 0.75, 0.9)


def success_within(cells: np.ndarray, budgets=CURVE_BUDGETS, interior: bool = False,
                   grid: geometry.PlantGrid = geometry.CART_POLE) -> list[float | None]:
    """Fraction of the cells (all, or the interior ones of the plant's grid) that succeeded within
    k trials, per budget k: the learning curve of a run, read from the recorded trials to success
    (no rerun). None when there is no such cell."""
    mask = grid.interior_mask(cells) if interior else np.ones(cells.size, dtype=bool)
    trials = cells["trials"][success_mask(cells) & mask]
    n = int(np.count_nonzero(mask))
    return [float(np.count_nonzero(trials <= k)) / n if n else None for k in budgets]


def quantiles(values: np.ndarray) -> dict[str, float] | None:
    """{"0.1": ..., "0.5": ..., ...} of values (None when there are none)."""
    if values.size == 0:
        return None
    return {f"{q:g}": float(v) for q, v in zip(QUANTILES, np.quantile(values.astype(float), QUANTILES))}


def weights(cells: np.ndarray, successful_only: bool = False,
            grid: geometry.PlantGrid = geometry.CART_POLE) -> np.ndarray:
    """Learned weights per cell, one per input of the plant's task (the cart-pole's w_x, w_xdot,
    w_theta, w_thetadot); NaN rows for unsuccessful cells if asked."""
    w = cells["weights"][:, :grid.n_inputs].astype(float)
    if successful_only:
        w[~success_mask(cells)] = np.nan
    return w


def percent(value, digits: int = 1) -> str:
    """A rate in [0, 1] as a percentage, e.g. 0.6016 -> '60.2 %'; 'n/a' for None or NaN. The one
    formatting of rates in summaries, tables, progress lines and figure titles."""
    if value is None or math.isnan(float(value)):
        return "n/a"
    return f"{100.0 * float(value):.{digits}f} %"


def error_statuses(cells: np.ndarray) -> dict[str, int]:
    """{status code (as a string, for JSON): number of ERROR cells with that status}."""
    status = cells["status"][cells["outcome"] == B.ERROR]
    codes, counts = np.unique(status, return_counts=True)
    return {str(int(c)): int(n) for c, n in zip(codes, counts)}


def _rate(num: int, den: int) -> float:
    return float(num) / den if den else float("nan")


def summary(cells: np.ndarray, grid: geometry.PlantGrid = geometry.CART_POLE) -> dict[str, Any]:
    """Aggregate metrics. Success rates use the cells given as denominator (the full grid's
    and its interior's when every cell is present); interior cells are those of the plant's grid."""
    ok = success_mask(cells)
    inner = grid.interior_mask(cells)
    trials = cells["trials"][ok]
    elapsed = cells["elapsed_time"][ok]
    counts = {name: int(np.count_nonzero(cells["outcome"] == code)) for code, name in B.OUTCOME_NAMES.items()}
    out: dict[str, Any] = {
        "n_cells": int(cells.size),
        "n_interior": int(np.count_nonzero(inner)),
        "outcomes": counts,
        "n_success": int(np.count_nonzero(ok)),
        "n_success_interior": int(np.count_nonzero(ok & inner)),
        "success_rate": _rate(np.count_nonzero(ok), cells.size),
        "success_rate_interior": _rate(np.count_nonzero(ok & inner), np.count_nonzero(inner)),
        "median_trials_to_success": float(np.median(trials)) if trials.size else None,
        "mean_trials_to_success": float(np.mean(trials)) if trials.size else None,
        "max_trials_to_success": int(np.max(trials)) if trials.size else None,
        "mean_elapsed_time_success": float(np.mean(elapsed)) if elapsed.size else None,
        "total_elapsed_time": float(np.sum(cells["elapsed_time"])),
        "total_trials": int(np.sum(cells["trials"])),
        # ERROR cells (e.g. status 4, ICOAC_ERR_NUMERIC) are neither successes nor failures.
        "error_statuses": error_statuses(cells),
        "trials_to_success_quantiles": quantiles(trials),
        "elapsed_time_quantiles": quantiles(elapsed),
        "success_within": {"k": list(CURVE_BUDGETS), "all": success_within(cells),
                           "interior": success_within(cells, interior=True, grid=grid)},
    }
    if trials.size:
        w = cells["weights"][ok][:, :grid.n_inputs]
        out["mean_weights_success"] = [float(v) for v in w.mean(axis=0)]
    else:
        out["mean_weights_success"] = None
    for key, value in list(out.items()):
        if isinstance(value, float) and math.isnan(value):
            out[key] = None
    return out


def format_summary(name: str, s: dict[str, Any]) -> str:
    pct = percent

    lines = [
        f"{name}: success {pct(s['success_rate'])} of {s['n_cells']} cells "
        f"({s['n_success']}), interior {pct(s['success_rate_interior'])} of {s['n_interior']} "
        f"({s['n_success_interior']})",
    ]
    if s["median_trials_to_success"] is not None:
        lines.append(f"  trials to success: median {s['median_trials_to_success']:g}, "
                     f"max {s['max_trials_to_success']}; mean simulated time of successful cells "
                     f"{s['mean_elapsed_time_success']:.1f} s")
    if s["outcomes"].get("pending"):
        lines.append(f"  {s['outcomes']['pending']} cells still PENDING")
    if s["outcomes"].get("error"):
        by = s.get("error_statuses") or {}
        detail = ", ".join(f"{B.status_name(int(k))} ({k}): {n}" for k, n in by.items())
        lines.append(f"  {s['outcomes']['error']} cells reported a controller ERROR, counted neither as "
                     f"success nor as failure" + (f" [{detail}]" if detail else ""))
    return "\n".join(lines)
