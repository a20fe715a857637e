# SPDX-License-Identifier: Apache-2.0
"""Markdown tables of a bench summary (the aggregate of icoac.studies.bench, as stored in summary.json
and docs/data/*.json): the prior taken apart, success within k trials, and the distributions of
trials and simulated time to success. Pure formatting: bench.py writes them into summary.md and
icoac.tools.results_tables into docs/results.md, from the same numbers."""
from __future__ import annotations

from typing import Any, Mapping, Sequence

from icoac.core.metrics import percent
from icoac.core.registry import CONDITIONS, COV_RULES, MEAN_RULES, REGISTRY

# The budgets k of the success-within-k table (those up to the largest cap of the summary).
TABLE_BUDGETS = (1, 10, 100, 1000, 10_000, 100_000)
# The actor-critic priors, ICO->RL first: (condition, what its mean and covariance are).
PRIOR_WORDS = {"ico": "ICO", "zero": "0", "lqr": "LQR", "isotropic": "σ_w²·I", "identity": "I"}
assert set(PRIOR_WORDS) == set(MEAN_RULES + COV_RULES)
PRIOR_TABLE = tuple(c.name for c in REGISTRY.values() if c.mode == "rl" and c.learns)


def _interval(stat: Mapping[str, Any], scale: float, fmt: str) -> str:
    ci = stat.get("ci95")
    return "" if not ci else f" ({scale * ci[0]:{fmt}}–{scale * ci[1]:{fmt}})"


def rate(stat: Mapping[str, Any] | None) -> str:
    """A rate's mean ± sd over seeds, with its 95 % interval in brackets when it has one."""
    if not stat or stat.get("mean") is None:
        return "n/a"
    return f"{percent(stat['mean'])} ± {percent(stat['sd'])}{_interval(stat, 100.0, '.1f')}"


def number(stat: Mapping[str, Any] | None) -> str:
    """A statistic's mean ± sd over seeds, with its 95 % interval in brackets when it has one."""
    if not stat or stat.get("mean") is None:
        return "n/a"
    return f"{stat['mean']:.4g} ± {stat['sd']:.2g}{_interval(stat, 1.0, '.4g')}"


def _at(series: Mapping[str, Sequence], i: int) -> dict[str, Any]:
    return {"mean": series["mean"][i], "sd": series["sd"][i]}


def prior_table(agg: Mapping[str, Any]) -> list[str]:
    """The actor-critic from the four priors (mean ICO or 0, covariance ICO or σ_w²·I), each beside
    its no-learning control: success (all cells, interior), median trials to success."""
    rows = [c for c in PRIOR_TABLE if c in agg]
    if not rows:
        return []
    lines = ["| condition | prior mean | prior covariance | success (all) | success (interior) | median trials | "
             "control: success (all) | control: median trials | gain over control (points) |",
             "|---|---|---|---|---|---|---|---|---|"]
    for cond in rows:
        e = agg[cond]
        mean, cov = REGISTRY[cond].prior
        c = agg.get(REGISTRY[cond].control or "", {})
        gain = (e.get("gain_over_control") or {}).get("points")
        lines.append(f"| {REGISTRY[cond].label} | {PRIOR_WORDS[mean]} | {PRIOR_WORDS[cov]} | {rate(e['success_rate'])} | "
                     f"{rate(e['success_rate_interior'])} | {number(e['median_trials_to_success'])} | "
                     f"{rate(c.get('success_rate'))} | {number(c.get('median_trials_to_success'))} | {number(gain)} |")
    return lines


def _p_value(p: float) -> str:
    """A p-value to two digits; one below the smallest double scipy returns as 0 is shown as such."""
    return "< 1e-300" if p == 0 else f"{p:.2g}"


def paired_table(agg: Mapping[str, Any]) -> list[str]:
    """Each learner against its no-learning control, and the summary's comparisons (``versus``):
    the difference of success rates (all cells) in points with its 95 % interval, the cells only
    one of the two succeeds in (mean over seeds) and McNemar's p, the largest over the seeds."""
    rows = []
    for cond in CONDITIONS:
        e = agg.get(cond) or {}
        if (e.get("gain_over_control") or {}).get("paired"):
            rows.append((cond, REGISTRY[cond].control, e["gain_over_control"]["paired"]))
        rows += [(cond, other, test) for other, test in (e.get("versus") or {}).items()]
    if not rows:
        return []
    lines = ["| condition | against | points of success (all) | 95 % interval | cells only the condition | "
             "cells only the other | McNemar p (largest over seeds) |", "|---|---|---|---|---|---|---|"]
    for cond, other, t in rows:
        if t.get("points") is None:
            continue
        ci = t.get("ci95")
        only_a = sum(m["only_a"] for m in t["mcnemar"]) / len(t["mcnemar"])
        only_b = sum(m["only_b"] for m in t["mcnemar"]) / len(t["mcnemar"])
        lines.append(f"| {REGISTRY[cond].label} | {REGISTRY[other].label} | {t['points']:+.1f} | "
                     f"{'n/a' if ci is None else f'{ci[0]:+.1f} to {ci[1]:+.1f}'} | {only_a:.4g} | {only_b:.4g} | "
                     f"{_p_value(t['p_max'])} |")
    return lines


def cost_table(agg: Mapping[str, Any], wall_time: bool = True) -> list[str]:
    """What each condition's whole grid cost (every cell, successful or not), mean over seeds: trials,
    simulated time and (``wall_time``) wall time; for a condition with an ICO prior, the same with
    its ICO grid added. Without wall time the table is the same for every run of the same cells
    (summary.md: a resumed bench writes the same summary as an uninterrupted one)."""
    conds = [c for c in CONDITIONS if c in agg and agg[c].get("cost")]
    if not conds:
        return []
    keys = ("trials", "simulated_time", "wall_time") if wall_time else ("trials", "simulated_time")
    heads = {"trials": "trials", "simulated_time": "simulated time (s)", "wall_time": "wall time (s)"}
    lines = ["| condition | cap | " + " | ".join(heads[k] for k in keys) + " | "
             + " | ".join(("with the ICO phase: " if i == 0 else "") + heads[k] for i, k in enumerate(keys)) + " |",
             "|---|---|" + "---|" * (2 * len(keys))]
    for cond in conds:
        e, cost = agg[cond], agg[cond]["cost"]
        ico = cost.get("with_ico") or {}
        own = " | ".join(f"{cost[k]['mean']:.3g}" for k in keys)
        both = " | ".join(f"{ico[k]['mean']:.3g}" if k in ico else "" for k in keys)
        lines.append(f"| {REGISTRY[cond].label} | {e['max_trials']:g} | {own} | {both} |")
    return lines


# The rows of the headline table beside the method to use: the paper's method, the learner it is
# compared with in the paper, the per-trial random w (the search's control: no learning, no model)
# and the baseline that needs the model.
HEADLINE_ROWS = ("ico-rl", "rl", "search-control", "cma-es", "lqr")


def _total_cost(entry: Mapping[str, Any]) -> Mapping[str, Any]:
    """A condition's whole-grid cost, its ICO phase included where its prior comes from ICO."""
    cost = entry.get("cost") or {}
    return cost.get("with_ico") or cost


def recommended(agg: Mapping[str, Any]) -> str | None:
    """The method to use at the learners' cap (ICO->RL's): of the conditions whose mean success over
    all cells lies within the 95 % interval of the highest, the one whose whole grid took the fewest
    trials (ICO phase included); the highest itself when intervals or costs are missing."""
    if "ico-rl" not in agg:
        return None
    cap = agg["ico-rl"]["max_trials"]
    same_cap = [c for c in CONDITIONS if c in agg and agg[c]["max_trials"] == cap]
    best = max(same_cap, key=lambda c: agg[c]["success_rate"]["mean"])
    ci = agg[best]["success_rate"].get("ci95")
    if not ci or not all("trials" in _total_cost(agg[c]) for c in same_cap):
        return best
    tied = [c for c in same_cap if agg[c]["success_rate"]["mean"] >= ci[0]]
    return min(tied, key=lambda c: _total_cost(agg[c])["trials"]["mean"])


def _plant_label(data: Mapping[str, Any]) -> str:
    notes = list(data.get("set") or []) + (["held-out tuned"] if data.get("tuned") else [])
    return data.get("plant", "cart_pole") + (f" ({', '.join(notes)})" if notes else "")


def headline_table(summaries: Sequence[Mapping[str, Any]]) -> list[str]:
    """Per plant (one bench data file each): the recommended method, then HEADLINE_ROWS, then the
    policies trained once over the grid (PPO, SAC: an rl-baselines data file of the same plant and
    settings, beside the bench tuned as they are; tuned ones, where the plant has no tuned bench,
    beside the untuned one, never the other way round); each with its success,
    95 % interval, and the whole grid's total cost (_total_cost; a policy trained once: its training
    episodes and steps, and its training and evaluation wall time)."""
    lines = ["| plant | method | success, all cells (95 % interval) | trials, whole grid | "
             "simulated time (s) | wall time (s) |", "|---|---|---|---|---|---|"]
    benches = [d for d in summaries if "aggregate" in d]

    def settings(d: Mapping[str, Any]) -> tuple[str, list[str]]:
        return d.get("plant", "cart_pole"), list(d.get("set") or [])
    beside: dict[int, list[Mapping[str, Any]]] = {}
    for other in (d for d in summaries if "algorithms" in d):
        matches = [i for i, d in enumerate(benches) if settings(d) == settings(other)]
        tuned_alike = [i for i in matches if ("tuned" in benches[i]) == ("tuned" in other)]
        place = tuned_alike or (matches if "tuned" in other else [])
        if place:
            beside.setdefault(place[0], []).append(other)

    def row(plant: str, name: str, success: Mapping[str, Any], cost: Mapping[str, Any]) -> str:
        total = " | ".join(f"{cost[k]['mean']:.3g}" if k in cost else "n/a"
                           for k in ("trials", "simulated_time", "wall_time"))
        return f"| {plant} | {name} | {rate(success)} | {total} |"
    for index, data in enumerate(benches):
        agg = data["aggregate"]
        best = recommended(agg)
        if best is None:
            continue
        plant = _plant_label(data)
        for cond in [best] + [c for c in HEADLINE_ROWS if c in agg and c != best]:
            name = f"**{REGISTRY[cond].label}** (use)" if cond == best else REGISTRY[cond].label
            lines.append(row(plant, name, agg[cond]["success_rate"], _total_cost(agg[cond])))
        for other in beside.get(index, []):
            how = "held-out tuned, trained once" if "tuned" in other else "trained once"
            for e in other["algorithms"].values():
                if "all" in e:
                    lines.append(row(plant, f"{e['settings']['algorithm']} ({how})", e["all"], e["cost"]))
    return lines if len(lines) > 2 else []


def budgets_of(agg: Mapping[str, Any]) -> list[int]:
    """The table's budgets up to the largest trial cap of the summary."""
    cap = max((e["max_trials"] for e in agg.values() if isinstance(e, Mapping) and "max_trials" in e), default=0)
    return [k for k in TABLE_BUDGETS if k <= cap]


def within_table(agg: Mapping[str, Any], ceiling: Mapping[str, Any] | None = None) -> list[str]:
    """Success (all cells) within k trials, mean ± sd over seeds, for every condition in the
    summary, with the best single w found's rows (its first trial is k = 1; its retries run to
    their own cap)."""
    ks = budgets_of(agg)
    conds = [c for c in CONDITIONS if c in agg and agg[c].get("success_within")]
    if not ks or not conds:
        return []
    lines = ["| condition | cap | " + " | ".join(f"k = {k:g}" for k in ks) + " |",
             "|---|---|" + "---|" * len(ks)]
    for cond in conds:
        e = agg[cond]
        curve = e["success_within"]
        cells = []
        for k in ks:
            cells.append(rate(_at(curve["all"], curve["k"].index(k))) if k <= e["max_trials"] else "")
        lines.append(f"| {REGISTRY[cond].label} | {e['max_trials']:g} | " + " | ".join(cells) + " |")
    for name, proto in ((ceiling or {}).get("best", {}).get("protocols", {}) or {}).items():
        curve = proto.get("success_within")
        cap = proto.get("max_trials", 1 if name == "first" else None)
        if curve is None:
            continue
        cells = [percent(curve["all"][curve["k"].index(k)]) if cap is None or k <= cap else "" for k in ks]
        lines.append(f"| best single w found ({'first trial' if name == 'first' else name}) | "
                     f"{'' if cap is None else f'{cap:g}'} | " + " | ".join(cells) + " |")
    return lines


def quantile_table(agg: Mapping[str, Any], key: str = "trials_to_success_quantiles") -> list[str]:
    """Quantiles of trials (or simulated time) to success over the successful cells, mean ± sd
    over seeds, per condition."""
    conds = [c for c in CONDITIONS if c in agg and agg[c].get(key)]
    if not conds:
        return []
    qs = agg[conds[0]][key]["q"]
    lines = ["| condition | " + " | ".join(f"{float(q) * 100:g} %" for q in qs) + " |", "|---|" + "---|" * len(qs)]
    for cond in conds:
        series = agg[cond][key]
        lines.append(f"| {REGISTRY[cond].label} | " + " | ".join(number(_at(series, i)) for i in range(len(qs))) + " |")
    return lines


def curve_tables(agg: Mapping[str, Any], ceiling: Mapping[str, Any] | None = None) -> list[str]:
    """The tables after the comparison, with their headings, for summary.md."""
    out: list[str] = []
    for title, lines in (
            ("The actor-critic from the four priors, each beside its no-learning control", prior_table(agg)),
            ("What each whole grid cost (every cell), mean over seeds; wall times in bench.json and "
             "docs/data", cost_table(agg, wall_time=False)),
            ("Success within k trials (all cells), mean ± sd over seeds", within_table(agg, ceiling)),
            ("Trials to success: quantiles over the successful cells, mean ± sd over seeds", quantile_table(agg)),
            ("Simulated time to success (s): quantiles over the successful cells, mean ± sd over seeds",
             quantile_table(agg, "elapsed_time_quantiles"))):
        if lines:
            out += ["", title + ":", ""] + lines
    return out
