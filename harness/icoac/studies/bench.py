# SPDX-License-Identifier: Apache-2.0
"""The paper's comparison (Fig. 2b, 3): ICO grids per seed, priors, ICO->RL, RL, ICO->search and
search grids with their no-learning controls (method.md, L1), summary, figures.

Layout: OUT/<condition>/seed-<n>/ (results directories), OUT/bench.json (wall time per stage),
OUT/summary.md and OUT/summary.json (mean and sd over seeds next to the paper's numbers).

The best single w found (method.md, L5) is not a bench stage: `python -m icoac ceiling --out
OUT/ceiling` measures it, and the bench shows it (a section of summary.md, reference lines in
Fig. 3a) when OUT/ceiling/ceiling.json exists or --ceiling names one.
"""
from __future__ import annotations

import math
import sys
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Callable, Mapping, Sequence

import numpy as np

from icoac.core import geometry, grid, metrics, plants, results, stats, store
from icoac.studies import tables
from icoac.studies import prior as P
from icoac.studies.ceiling.records import bench_ceiling, load_ceiling, reference_lines
from icoac.studies.ceiling.weights import format_w
from icoac.studies.conditions import run_condition
from icoac.core.config import build_config, command_overrides, named_sets
from icoac.core.errors import ResultsError
from icoac.core.metrics import percent
from icoac.core.options import CART_POLE, PROFILE_NAMES
from icoac.core.registry import CONDITIONS, PRIOR_CONDITIONS, REGISTRY

# Paper (Fig. 1b, 2b, 3a): ~68 % ICO, ~84 % ICO->RL; RL alone only "smaller" and "very slow" (Fig. 3 bars).
PAPER = {
    "ico": {"success_rate": 0.68, "note": "Fig. 1b; fast (Fig. 3b)"},
    "ico-rl": {"success_rate": 0.84, "note": "Fig. 2b; most cells 5-2000 trials, a few > 2000"},
    "rl": {"success_rate": None, "note": "Fig. 3: smaller domain than ICO, very slow; no number in the text"},
}
# The paired comparisons of the summary beyond each learner against its control: the paper's
# method against the learners a user would pick instead (same caps only).
COMPARISONS = (("ico-rl", "rl"), ("ico-rl", "search"), ("ico-rl", "ico-search"), ("ico-rl", "search-control"),
               ("ico-rl", "lqr"), ("ico-rl", "cma-es"), ("cma-es", "search-control"))
# The learners after ICO and its prior, in stage order.
LEARNERS = PRIOR_CONDITIONS

# The profiles' cells on a plant's grid: all (None), or a spread subset for smoke tests.
QUICK_CELLS = geometry.PlantGrid.quick_cells

PROFILES: dict[str, dict[str, Any]] = {
    # ICO at the paper's caps (1e5 trials, 1e5 steps), the learners' conditions with a 1000-trial
    # cap. Each bench records its wall time per stage in bench.json (docs/results.md quotes it).
    "default": {"seeds": 5, "ico": {}, "rl": {"max_trials": 1000}, "cells": None},
    "paper": {"seeds": 5, "ico": {}, "rl": {}, "cells": None},
    "quick": {"seeds": 2, "ico": {"max_trials": 6000, "success_steps": 2000},
              "rl": {"max_trials": 600, "success_steps": 2000}, "cells": QUICK_CELLS},
}
assert tuple(PROFILES) == PROFILE_NAMES


def learner_caps(profile: str, plant: str = CART_POLE) -> tuple[int, int]:
    """(trial cap, steps of a successful trial) of a profile's learner grids: the profile's, else the
    C defaults. The ceiling's retries take them (`ceiling --profile`)."""
    run = build_config(PROFILES[profile]["rl"], condition="rl", plant=plant).run
    return int(run.max_trials), int(run.success_steps)


def seed_dir(out: Path, condition: str, seed: int) -> Path:
    return Path(out) / condition / f"seed-{seed}"


def _mean_sd(values: Sequence[float | None]) -> tuple[float | None, float | None, int]:
    v = np.array([x for x in values if x is not None and math.isfinite(x)], dtype=float)
    if v.size == 0:
        return None, None, 0
    sd = float(np.std(v, ddof=1)) if v.size > 1 else 0.0
    return float(np.mean(v)), sd, int(v.size)


def seed_stat(values: Sequence[float | None]) -> dict[str, Any]:
    """A statistic over seeds as the summaries store it: mean, sd, n and the per-seed values."""
    mean, sd, n = _mean_sd(values)
    return {"mean": mean, "sd": sd, "n": n, "per_seed": list(values)}


STATS = (
    ("success_rate", "success rate (all)"),
    ("success_rate_interior", "success rate (interior)"),
    ("median_trials_to_success", "median trials to success"),
    ("mean_elapsed_time_success", "mean elapsed simulated time of successful cells (s)"),
)


def _per_k(rows: Sequence[Sequence[float | None]]) -> dict[str, list[float | None]]:
    """Mean and sd over seeds (rows) of each column (a budget k, or a quantile)."""
    columns = list(zip(*rows))
    stats = [_mean_sd(list(col)) for col in columns]
    return {"mean": [m for m, _, _ in stats], "sd": [s for _, s, _ in stats]}


def _curves_and_quantiles(recs: Sequence[Mapping[str, Any]]) -> dict[str, Any]:
    """The learning curve (success within k trials, all cells and interior) and the quantiles of
    trials and simulated time to success, mean and sd over seeds; empty for records written before
    the summaries had them."""
    summaries = [r["summary"] for r in recs]
    out: dict[str, Any] = {}
    if all(s.get("success_within") for s in summaries):
        out["success_within"] = {"k": summaries[0]["success_within"]["k"],
                                 **{part: _per_k([s["success_within"][part] for s in summaries])
                                    for part in ("all", "interior")}}
    for key in ("trials_to_success_quantiles", "elapsed_time_quantiles"):
        if all(s.get(key) for s in summaries):
            qs = list(summaries[0][key])
            out[key] = {"q": qs, **_per_k([[s[key][q] for q in qs] for s in summaries])}
    return out


def _paper_plant(plant: str) -> bool:
    """Whether the paper's results apply to the plant's records (its C task says so)."""
    return plants.PLANTS[plant].paper


def intervals(cells: Mapping[int, np.ndarray], grid: geometry.PlantGrid) -> dict[str, list[float] | None]:
    """The bootstrap intervals (icoac.core.stats) of a condition's statistics from its cells per seed:
    success rate (all cells, interior cells) and median trials to success."""
    seeds = sorted(cells)
    success = np.stack([metrics.success_mask(cells[s]) for s in seeds])
    trials = np.stack([metrics.trials_to_success(cells[s]) for s in seeds])
    inner = grid.interior_mask(cells[seeds[0]])
    return {"success_rate": stats.interval(success, stats.rate),
            "success_rate_interior": stats.interval(success[:, inner], stats.rate),
            "median_trials_to_success": stats.interval(trials, stats.median_of_successes)}


# What a grid cost, per seed: every trial and simulated second of every cell (successful or not),
# and the wall time of the grid run (its record's, on its threads).
COST = (("trials", lambda r: r["summary"]["total_trials"]),
        ("simulated_time", lambda r: r["summary"]["total_elapsed_time"]),
        ("wall_time", lambda r: r["wall_time"]))


def _cost(recs: Sequence[Mapping[str, Any]], ico: Sequence[Mapping[str, Any]] | None) -> dict[str, Any]:
    """Mean/sd over seeds of a condition's whole-grid cost (COST); for a condition whose prior comes
    from ICO, also with the ICO grid of the same seed added (``with_ico``), the phase its own
    trial counts leave out. Empty for records written before the summaries counted totals."""
    if not all("total_trials" in r["summary"] and "wall_time" in r for r in recs):
        return {}
    out: dict[str, Any] = {key: seed_stat([float(get(r)) for r in recs]) for key, get in COST}
    if ico:
        by_seed = {r.get("seed"): r for r in ico}
        paired = [(r, by_seed[r.get("seed")]) for r in recs if r.get("seed") in by_seed]
        if paired and _cost([i for _, i in paired], None):
            out["with_ico"] = {key: seed_stat([float(get(r)) + float(get(i)) for r, i in paired]) for key, get in COST}
    return out


def aggregate(records: Mapping[str, Sequence[Mapping[str, Any]]],
              cells: Mapping[str, Mapping[int, np.ndarray]] | None = None) -> dict[str, Any]:
    """{condition: [run.json records over seeds]} -> mean/sd per statistic and condition; with the
    conditions' cells ({condition: {seed: cells}}) each statistic of STATS but the elapsed time gets
    its 95 % interval (``ci95``, icoac.core.stats)."""
    out: dict[str, Any] = {}
    for cond, recs in records.items():
        if not recs:
            continue
        cis = (intervals(cells[cond], geometry.of(results.record_plant(recs[0])))
               if cells is not None and cells.get(cond) else {})
        entry: dict[str, Any] = {"seeds": [r.get("seed") for r in recs],
                                 "n_cells": recs[0]["summary"]["n_cells"],
                                 "n_interior": recs[0]["summary"]["n_interior"],
                                 "max_trials": recs[0]["config"]["run"]["max_trials"],
                                 "success_steps": recs[0]["config"]["run"]["success_steps"],
                                 "paper": PAPER.get(cond) if _paper_plant(results.record_plant(recs[0])) else None}
        for key, _ in STATS:
            entry[key] = seed_stat([r["summary"].get(key) for r in recs])
            if key in cis:
                entry[key]["ci95"] = cis[key]
        entry.update(_curves_and_quantiles(recs))
        rule = REGISTRY[cond].prior
        entry["cost"] = _cost(recs, records.get("ico") if rule is not None and rule.takes_ico else None)
        if cond == "ico-rl":
            entry["ico_phase_simulated_time"] = seed_stat(
                [(r.get("prior_info") or {}).get("ico_phase_simulated_time") for r in recs])
        out[cond] = entry
    return out


def gain_over_control(cells: Mapping[int, np.ndarray], control: Mapping[int, np.ndarray]) -> dict[str, Any]:
    """Per seed {seed: cell array} of a condition and of its no-learning control -> mean/sd of the
    cells it gains (succeed, the control does not), loses, and the difference in points of
    success rate (all cells), with that difference's interval and McNemar's test per seed
    (``paired``, icoac.core.stats.paired)."""
    gained, lost, points = [], [], []
    for seed in sorted(set(cells) & set(control)):
        a = metrics.success_mask(cells[seed])
        b = metrics.success_mask(control[seed])
        gained.append(float(np.count_nonzero(a & ~b)))
        lost.append(float(np.count_nonzero(~a & b)))
        points.append(100.0 * (float(a.mean()) - float(b.mean())))
    out: dict[str, Any] = {key: seed_stat(values) for key, values in
                           (("cells_gained", gained), ("cells_lost", lost), ("points", points))}
    out["paired"] = compare(cells, control)
    return out


def compare(a: Mapping[int, np.ndarray], b: Mapping[int, np.ndarray]) -> dict[str, Any]:
    """Two conditions' cells per seed -> the paired difference of their success rates (points, its
    interval) and McNemar's test per seed (icoac.core.stats.paired)."""
    return stats.paired({s: metrics.success_mask(c) for s, c in a.items()},
                        {s: metrics.success_mask(c) for s, c in b.items()})


def add_comparisons(agg: dict[str, Any], cells: Mapping[str, Mapping[int, np.ndarray]]) -> None:
    """Each learner against its no-learning control (``gain_over_control``), and the COMPARISONS that
    the summary holds at the same caps (``versus``: {B: compare(A, B)} in A's entry)."""
    for cond in REGISTRY.values():
        if cond.control is not None and cells.get(cond.name) and cells.get(cond.control) and cond.name in agg:
            agg[cond.name]["gain_over_control"] = gain_over_control(cells[cond.name], cells[cond.control])
    for a, b in COMPARISONS:
        if a in agg and b in agg and cells.get(a) and cells.get(b) and all(
                agg[a][k] == agg[b][k] for k in ("max_trials", "success_steps", "n_cells")):
            agg[a].setdefault("versus", {})[b] = compare(cells[a], cells[b])


def ceiling_markdown(record: Mapping[str, Any]) -> list[str]:
    """Lines of summary.md for a ceiling record (icoac.studies.ceiling)."""
    st, best = record["settings"], record["best"]
    parts = []
    for p, s in best["protocols"].items():
        cap = "one trial per cell" if p == "first" else f"retries up to {s.get('max_trials', st['max_trials']):g} trials"
        parts.append(f"{cap}: {percent(s['success_rate'])} of {s['n_cells']} cells, "
                     f"{percent(s['success_rate_interior'])} of {s['n_interior']} interior")
    lines = ["", f"Best single w found (method.md, L5; no learning, the best single w = {format_w(best['w'])} "
             f"of `python -m icoac ceiling`, seed {st['seed']}, horizon {st['success_steps']:g} steps): "
             + "; ".join(parts) + "."]
    b = record.get("first_step_bound") or {}
    if b.get("computed"):
        lines[-1] += (f" First-step bound: {b['n_lost']} cells fail at the first step whatever the force, so no "
                      f"controller exceeds {percent(b['success_rate_bound'])} of {b['n_cells']} cells on its first trial.")
    return lines


def summary_markdown(agg: Mapping[str, Any], ceiling: Mapping[str, Any] | None = None,
                     grid: geometry.PlantGrid = geometry.CART_POLE) -> str:
    title = "" if grid is geometry.CART_POLE else f" ({grid.plant})"
    lines = [f"# ICO and the learners with their no-learning controls{title}: mean ± sd over seeds "
             "(95 % interval over cells and seeds)", "",
             "| condition | seeds | caps (trials / steps) | success (all) | success (interior) | "
             "median trials to success | mean elapsed sim. time of successes (s) | paper |",
             "|---|---|---|---|---|---|---|---|"]
    for cond in CONDITIONS:
        if cond not in agg:
            continue
        e = agg[cond]
        paper = e["paper"] or {}
        ptxt = (f"{percent(paper['success_rate'], 0)}; " if paper.get("success_rate") else "") + paper.get("note", "")
        lines.append(f"| {REGISTRY[cond].label} | {len(e['seeds'])} | {e['max_trials']:g} / {e['success_steps']:g} | "
                     f"{tables.rate(e['success_rate'])} of {e['n_cells']} | "
                     f"{tables.rate(e['success_rate_interior'])} of {e['n_interior']} | "
                     f"{tables.number(e['median_trials_to_success'])} | {tables.number(e['mean_elapsed_time_success'])} | {ptxt} |")
    paired = tables.paired_table(agg)
    if paired:
        lines += ["", "Paired comparisons: each learner against its no-learning control (same prior, acting weights, "
                  "noise stream, resets and caps, every update off), and ICO->RL against the other learners at the "
                  "same caps; cells and seeds drawn together (icoac.core.stats):", ""] + paired
    if "ico-rl" in agg and agg["ico-rl"].get("ico_phase_simulated_time", {}).get("mean") is not None:
        lines += ["", "ICO->RL counts RL-phase trials only (A17); the ICO phase that produced each prior took "
                  f"{tables.number(agg['ico-rl']['ico_phase_simulated_time'])} s of simulated time (whole ICO grid)."]
    if ceiling is not None:
        lines += ceiling_markdown(ceiling)
    lines += tables.curve_tables(agg, ceiling)
    lines += ["", f"Success rates use the cells run as denominator ({grid.cells} / {grid.n_interior} on "
              "the full grid)."]
    if _paper_plant(grid.plant):
        lines[-1] += (f" The paper's ~{percent(PAPER['ico']['success_rate'], 0)} / "
                      f"~{percent(PAPER['ico-rl']['success_rate'], 0)} are read as fractions of all "
                      f"{grid.cells} cells.")
    return "\n".join(lines) + "\n"


def write_summary(out: Path, agg: Mapping[str, Any], ceiling: Mapping[str, Any] | None = None,
                  grid: geometry.PlantGrid = geometry.CART_POLE) -> tuple[Path, Path]:
    out = Path(out)
    md = out / "summary.md"
    js = out / "summary.json"
    store.write_text(md, summary_markdown(agg, ceiling, grid))
    store.write_json(js, agg)
    return md, js


def cell_builds(records: Sequence[Mapping[str, Any]]) -> list[dict[str, Any]]:
    """The builds (commit, dirty) that wrote the cells of the records, each once, in first-seen order."""
    out: list[dict[str, Any]] = []
    for record in records:
        for build in results.recorded_builds(record):
            entry = {"commit": build.get("commit"), "dirty": build.get("dirty")}
            if entry not in out:
                out.append(entry)
    return out


def write_data(opt: "BenchOptions", agg: Mapping[str, Any], ceiling: Mapping[str, Any] | None,
               builds: Sequence[Mapping[str, Any]] = ()) -> Path:
    """The summary docs/results.md's tables are written from (icoac.tools.results_tables): the
    aggregate, the ceiling's best w with its protocols, and what produced them: the commit that
    summarised (``git``), the builds that wrote the cells (``cell_builds``) and the intervals'
    settings."""
    record = {**({} if opt.plant == CART_POLE else {"plant": opt.plant}),
              "profile": opt.profile, "seeds": opt.seed_list(), "configuration": opt.configuration,
              "set": list(opt.sets), "prior_std": opt.prior_std, "git": results.git_info(),
              "cell_builds": list(builds), "intervals": stats.settings(),
              "timestamp": results.timestamp(), "aggregate": agg,
              "ceiling": None if ceiling is None else {"settings": ceiling["settings"], "best": ceiling["best"]}}
    Path(opt.data).parent.mkdir(parents=True, exist_ok=True)
    store.write_json(Path(opt.data), record, indent=1)
    return Path(opt.data)


def comparison_figures(agg: Mapping[str, Any], figdir: Path, ico_cells: np.ndarray | None,
                       icorl_cells: np.ndarray | None, frame=None,
                       ceiling: Mapping[str, Any] | None = None,
                       grid: geometry.PlantGrid = geometry.CART_POLE) -> list[Path]:
    """Fig. 2b (first ICO->RL seed, ICO success domain outlined), Fig. 3a (with the linear-policy
    ceiling's reference lines when a ceiling record is given), Fig. 3b."""
    from icoac.studies import figures

    figdir = Path(figdir)
    written = []
    if icorl_cells is not None:
        outline = None
        if ico_cells is not None:
            outline = grid.to_grid(ico_cells, metrics.success_mask(ico_cells).astype(float), fill=0) > 0
        written.append(figures.plot_success_map(icorl_cells, figdir / "fig2b_icorl_success_map.png",
                                                label="ICO->RL", outline=outline, frame=frame, grid=grid))
    conds = [c for c in CONDITIONS if c in agg]
    if conds:
        written.append(figures.plot_fig3a(figdir / "fig3a_success_rate.png", [REGISTRY[c].label for c in conds],
                                          [agg[c]["success_rate"] for c in conds],
                                          [agg[c]["success_rate_interior"] for c in conds],
                                          [(agg[c].get("paper") or {}).get("success_rate") for c in conds],
                                          ceiling=reference_lines(ceiling)))
        written.append(figures.plot_fig3b(figdir / "fig3b_elapsed_time.png", [REGISTRY[c].label for c in conds],
                                          [agg[c]["mean_elapsed_time_success"] for c in conds]))
        curved = [c for c in conds if agg[c].get("success_within")]
        if curved:
            bases = [c.name for c in REGISTRY.values() if c.control_of is None]
            curves = [{"label": REGISTRY[c].label, "mean": agg[c]["success_within"]["all"]["mean"],
                       "sd": agg[c]["success_within"]["all"]["sd"], "control": not REGISTRY[c].learns,
                       "color": bases.index(REGISTRY[c].base)} for c in curved]
            retries = ((ceiling or {}).get("best", {}).get("protocols", {}) or {}).get("retries") or {}
            line = None
            if retries.get("success_within"):
                line = {"label": f"best single w found (retries, cap {retries.get('max_trials', 0):g})",
                        "rate": retries["success_within"]["all"]}
            written.append(figures.plot_fig3c(figdir / "fig3c_learning_curves.png",
                                              agg[curved[0]]["success_within"]["k"], curves,
                                              cap=max(agg[c]["max_trials"] for c in curved), ceiling=line))
    return written


# The speed figures `make bench` writes before the bench (icoac_bench --json OUT/speed.json).
SPEED_FILE = "speed.json"


class BenchLog:
    """OUT/bench.json (a --summary-only run: OUT/bench-summary.json, so the grids' log stays):
    wall time per stage and of the whole bench, rewritten after every stage, and the engine's
    speed figures when OUT/speed.json holds them (key "speed")."""

    def __init__(self, out: Path, meta: Mapping[str, Any], name: str = "bench.json"):
        self.path = Path(out) / name
        self.t0 = time.monotonic()
        self.data: dict[str, Any] = {"meta": dict(meta), "stages": [], "total_wall_time": 0.0,
                                     "complete": False}
        previous = None
        if self.path.is_file():
            try:  # a damaged log is replaced, and a link is not followed
                previous = results.read_json(self.path, follow=False)
            except ResultsError:
                previous = None
        if not isinstance(previous, dict):
            previous = None
        speed = self.path.parent / SPEED_FILE
        if speed.is_file():
            try:
                self.data["speed"] = results.read_json(speed, follow=False)
            except ResultsError:
                progress(f"{speed} is not readable JSON: bench.json goes without the speed figures")
        if previous and meta.get("resume") and isinstance(previous.get("previous_runs", []), list):
            self.data["previous_runs"] = previous.get("previous_runs", []) + [
                {"stages": previous.get("stages", []), "total_wall_time": previous.get("total_wall_time")}]

    def stage(self, name: str, wall: float, **info) -> None:
        self.data["stages"].append({"name": name, "wall_time": round(float(wall), 3), **info})
        self.flush()

    def flush(self, complete: bool = False) -> None:
        self.data["total_wall_time"] = round(time.monotonic() - self.t0, 3)
        self.data["complete"] = complete
        store.write_json(self.path, self.data)


def progress(msg: str) -> None:
    print(f"[bench] {msg}", file=sys.stderr, flush=True)


# -- the stages ---------------------------------------------------------------------------------------
@dataclass
class Stage:
    name: str
    run: Callable[[dict], None]


@dataclass
class BenchOptions:
    """What `bench` runs: a profile, seeds --seed .. --seed + seeds - 1 (seeds None: the profile's
    number), overrides and prior options; see icoac.cli for the command line."""
    profile: str
    out: Path
    figures: Path | None = None
    data: Path | None = None      # the summary for docs (docs/data/*.json): aggregate, ceiling, provenance
    summary_only: bool = False    # only the summary and figures of the grids OUT holds complete; nothing runs
    seed: int = 0
    seeds: int | None = None
    rl_max_trials: int | None = None
    threads: int = 0
    configuration: str = "default"   # a named configuration (config.NAMED_CONFIGURATIONS), then sets
    sets: Sequence[str] = ()
    resume: bool = False
    quiet: bool = False
    frame: tuple[float, float] | str | None = P.CENTRAL  # the plant's central frame unless given
    ridge: float = P.DEFAULT_RIDGE
    prior_std: float = P.DEFAULT_STD
    ceiling: Path | None = None   # a ceiling.json (or its directory); default OUT/ceiling/ceiling.json
    dask: Any = None              # a icoac.cluster.backend.DaskSpec: every grid on that Dask cluster (None: threads)
    plant: str = CART_POLE        # a registry plant (icoac.core.plants): its grid, dynamics and task settings

    def seed_list(self) -> list[int]:
        n = self.seeds if self.seeds is not None else PROFILES[self.profile]["seeds"]
        return grid.seed_range(self.seed, n)


def stages(opt: BenchOptions) -> list[Stage]:
    """ICO grid per seed, prior per seed, then each learner and its control per seed (ICO->RL, RL,
    ICO->search, search), summary, figures. Every argument and override is validated here, before
    anything runs or is written."""
    profile = PROFILES[opt.profile]
    P.check_prior_std(opt.prior_std)
    P.check_prior_ridge(opt.ridge)
    grid.check_threads(opt.threads)
    out = Path(opt.out)
    figdir = Path(opt.figures) if opt.figures else None
    if figdir is not None:
        from icoac.studies import figures  # noqa: F401  (MissingExtra before any stage without matplotlib)
    seeds = opt.seed_list()
    ico_sets = command_overrides(opt.configuration, opt.sets, plant=opt.plant)
    rl_sets = command_overrides(opt.configuration, opt.sets, {"--rl-max-trials": ("max_trials", opt.rl_max_trials)},
                                plant=opt.plant)
    plant_grid = geometry.of(opt.plant)
    cells_spec = profile["cells"](plant_grid) if profile["cells"] else None
    frame = plant_grid.central_frame() if opt.frame == P.CENTRAL else opt.frame

    def overrides(condition):
        if condition == "ico":
            return {**profile["ico"], **ico_sets}
        return {**profile["rl"], **rl_sets}

    def grid_stage(condition: str, seed: int):
        def run(ctx):
            d = seed_dir(out, condition, seed)
            cells, record, cancelled = run_condition(
                condition=condition, out=d, seed=seed, threads=opt.threads, overrides=overrides(condition),
                cell_spec=cells_spec, resume=opt.resume and bool(results.present(d)), fresh=not opt.resume,
                progress=not opt.quiet, info=ctx.get(("prior", condition, seed)),
                start_over="rerun bench without --resume", dask=ctx.get("dask"), plant=opt.plant)
            ctx[(condition, seed)] = (cells, record)
            s = record["summary"]
            progress(f"  {condition} seed {seed}: success {s['n_success']}/{s['n_cells']}, "
                     f"grid wall time {record['wall_time']:.1f} s")
            if cancelled:
                raise KeyboardInterrupt
        return Stage(f"grid {condition} seed-{seed}", run)

    def prior_stage(seed: int):
        def run(ctx):
            info = P.from_results(seed_dir(out, "ico", seed), frame, opt.ridge, opt.plant)
            for cond in REGISTRY.values():
                if cond.prior is not None and cond.control_of is None:
                    ctx[("prior", cond.name, seed)] = P.condition_prior(
                        cond.name, info, opt.prior_std, plant_grid.n_inputs,
                        cfg=build_config(overrides(cond.name), condition=cond.name, plant=opt.plant))
            for cond in REGISTRY.values():  # a control shares its condition's prior
                if cond.control_of is not None:
                    ctx[("prior", cond.name, seed)] = ctx[("prior", cond.base, seed)]
            progress(f"  prior seed {seed}: {info.n_cells} cells, mean "
                     + ", ".join(f"{v:.4g}" for v in info.mean))
        return Stage(f"prior seed-{seed}", run)

    def ceiling_record():
        """The ceiling shown (--ceiling, else OUT/ceiling/ceiling.json if present); a damaged default
        file is reported and skipped rather than failing the bench at its end."""
        try:
            return bench_ceiling(out, opt.ceiling)
        except ResultsError as exc:
            if opt.ceiling is not None:
                raise
            progress(f"  ceiling not shown: {exc}")
            return None

    def figures_stage(ctx):
        if figdir is None:
            return
        from icoac.studies import figures
        cells, record = ctx[("ico", seeds[0])]
        for path in figures.make_figures(cells, record, figdir):
            progress(f"  wrote {path}")
        for path in comparison_figures(ctx["aggregate"], figdir, cells, ctx[("ico-rl", seeds[0])][0],
                                       frame=frame, ceiling=ceiling_record(), grid=plant_grid):
            progress(f"  wrote {path}")

    def summary_stage(ctx):
        recs = {c: [ctx[(c, s)][1] for s in seeds if (c, s) in ctx] for c in CONDITIONS}
        cells = {c: {s: ctx[(c, s)][0] for s in seeds if (c, s) in ctx} for c in CONDITIONS}
        agg = aggregate(recs, cells)
        add_comparisons(agg, cells)
        ctx["aggregate"] = agg
        md, js = write_summary(out, agg, ceiling_record(), plant_grid)
        if opt.data is not None:
            write_data(opt, agg, ceiling_record(), cell_builds([r for rs in recs.values() for r in rs]))
            progress(f"  wrote {opt.data}")
        print(md.read_text(), end="")
        progress(f"  wrote {md} and {js}")

    def finished_stage(ctx):
        found = []
        for condition in CONDITIONS:
            for seed in seeds:
                d = seed_dir(out, condition, seed)
                if results.exists(d):
                    cells, record = results.load(d)
                    if record.get("complete"):
                        ctx[(condition, seed)] = (cells, record)
                        found.append(f"{condition}/seed-{seed}")
        progress(f"  {len(found)} complete grids: " + ", ".join(found))

    if opt.summary_only:
        return [Stage("complete grids", finished_stage), Stage("summary", summary_stage),
                Stage("figures", figures_stage)]
    for condition in CONDITIONS:  # every override valid before the first grid runs
        build_config(overrides(condition), condition=condition, plant=opt.plant)
    if opt.ceiling is not None:
        load_ceiling(opt.ceiling)

    out_stages = [grid_stage("ico", s) for s in seeds]
    out_stages += [prior_stage(s) for s in seeds]
    for condition in LEARNERS:
        out_stages += [grid_stage(condition, s) for s in seeds]
    out_stages += [Stage("summary", summary_stage), Stage("figures", figures_stage)]
    return out_stages


def run_bench(opt: BenchOptions, argv: Sequence[str] = ()) -> int:
    """Validate, then run every stage, logging wall times to OUT/bench.json; 130 if interrupted.
    With ``opt.dask`` one Dask session (icoac.cluster.backend) serves every grid."""
    todo = stages(opt)  # validates the arguments before anything is written
    if opt.dask is None:  # the local engine: Dask is not imported
        with store.DirectoryLock(opt.out):
            return _run_stages(opt, todo, {"dask": None}, argv)
    from icoac.cluster.backend import open_backend
    with store.DirectoryLock(opt.out), open_backend(opt.dask) as session:
        return _run_stages(opt, todo, {"dask": session}, argv)


def _run_stages(opt: BenchOptions, todo: list[Stage], ctx: dict, argv: Sequence[str]) -> int:
    session = ctx.get("dask")
    log = BenchLog(Path(opt.out), {
        "profile": opt.profile, "seeds": opt.seed_list(),
        "rl_max_trials": opt.rl_max_trials, "resume": bool(opt.resume), "threads": opt.threads,
        "set": named_sets(opt.configuration, opt.sets), "argv": list(argv),
        **({"backend": session.describe()} if session is not None else {})},
        "bench-summary.json" if opt.summary_only else "bench.json")
    for i, stage in enumerate(todo, 1):
        progress(f"({i}/{len(todo)}) {stage.name}")
        t0 = time.monotonic()
        try:
            stage.run(ctx)
        except KeyboardInterrupt:
            log.stage(stage.name, time.monotonic() - t0, interrupted=True)
            print(f"interrupted during {stage.name}; finished cells saved, rerun with --resume", file=sys.stderr)
            return 130
        log.stage(stage.name, time.monotonic() - t0)
    log.flush(complete=True)
    progress(f"total wall time {log.data['total_wall_time']:.1f} s -> {Path(opt.out) / 'bench.json'}")
    return 0
