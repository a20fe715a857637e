# SPDX-License-Identifier: Apache-2.0
"""PPO and SAC (Stable-Baselines3, icoac.studies.baselines.sb3) on a plant, trained once per seed
over random grid cells and evaluated on every cell of that seed's grid:

    python -m icoac.tools.rl_baselines --plant PLANT --out results/rl-baselines-PLANT \\
        --bench results/bench-PLANT --data docs/data/rl-baselines-PLANT.json

Needs the [baselines] extra (`make baselines`). The plant's actuator limit (the parameter its C
file names; --limited holds it to a real actuator's, --set to any other) bounds the actions. Each (algorithm, seed) is OUT/<algo>/seed-<s>/ with the
trained model and result.json; a stopped run resumes at the first unfinished one (one run is not
resumed inside); --jobs N runs N of them at once, each in its own process on one thread. --bench
DIR (grids with the same plant parameters) adds the paired per-cell tests against its conditions,
seed for seed. --report runs nothing.

--tune runs the held-out tuning instead (icoac.studies.heldout, BASELINE_SPACES; docs/tuning.md):
each setting of each algorithm with the tuning seeds, trained on the plant's tuning cells only and
scored on them, into OUT/tuning/<algo>/<setting>/seed-<s>/; OUT/tuning.json ranks the settings by
the protocol's criterion. With --data FILE that record is written after every finished run and read
at the start: the runs it holds are not trained again, so a tuning longer than a machine's life goes
on from its committed record. --tuned RECORD runs the evaluation with each algorithm's choice in
that finished tuning record (the same plant and --set); --hyper NAME=VALUE with a setting of one's
own."""
from __future__ import annotations

import argparse
import concurrent.futures
import json
import multiprocessing
import os
import sys
import time
from pathlib import Path
from typing import Any, Callable, Mapping

import numpy as np

from icoac.core import metrics, results, stats
from icoac.core.config import build_config, model_to_dict, parse_sets
from icoac.core.errors import UsageError
from icoac.core.plants import PLANTS
from icoac.core.registry import REGISTRY
from icoac.studies import bench, heldout, tables
from icoac.studies.baselines import sb3
from icoac.tools.resumable import guarded

RESULT = "result.json"


def _mask(text: str) -> np.ndarray:
    return np.frombuffer(text.encode(), dtype=np.uint8) == ord("1")


def run_one(args, cfg, algo: str, seed: int, steps: int, out: Path | None = None,
            overrides: Mapping[str, Any] | None = None, cells: list[int] | None = None) -> dict[str, Any]:
    """Train and evaluate one seed on every cell, or on ``cells`` (the success string then
    follows their order), into ``out`` (default OUT/<algo>/seed-<s>), or read its finished
    result."""
    out = _out(args, algo, seed, steps, out)
    if (out / RESULT).is_file():
        done = json.loads((out / RESULT).read_text())
        if done["overrides"] != dict(overrides or {}):
            raise UsageError(f"{out} was trained with {done['overrides'] or 'the defaults'}, not "
                             f"{dict(overrides or {}) or 'the defaults'}; move it aside")
        return done
    if args.report:
        return {}
    out.mkdir(parents=True, exist_ok=True)
    print(f"[{algo} seed {seed}] training {steps} steps", file=sys.stderr, flush=True)
    git = results.git_info()  # the tree the run starts from (it may change while the run trains)
    trained = sb3.train(algo, cfg, seed, steps, overrides, cells)
    trained.model.save(out / "model.zip")
    if trained.normalizer is not None:
        trained.normalizer.save(str(out / "vecnormalize.pkl"))
    t0 = time.monotonic()
    lasted, ok = sb3.evaluate(trained.act, cfg, seed, cells)
    eval_wall = time.monotonic() - t0
    result = {"algo": algo, "seed": seed, "overrides": dict(overrides or {}),
              "training_cells": "all" if cells is None else len(cells),
              "steps": trained.steps, "episodes": trained.episodes,
              "simulated_time": trained.steps * float(cfg.model.dt), "train_wall_time": trained.wall_time,
              "eval_wall_time": eval_wall, "success": "".join("1" if x else "0" for x in ok),
              "lasted": [int(v) for v in lasted], "git": git}
    tmp = out / (RESULT + ".tmp")
    tmp.write_text(json.dumps(result))
    os.replace(tmp, out / RESULT)
    print(f"[{algo} seed {seed}] {100 * ok.mean():.1f} % of {ok.size} cells; train {trained.wall_time:.0f} s, "
          f"evaluation {eval_wall:.0f} s", file=sys.stderr, flush=True)
    return result


def _run_job(job) -> None:
    run_one(*job)


def run_all(args, cfg, jobs: list[tuple], done: Callable[[], None] = lambda: None) -> None:
    """The unfinished ones of ``jobs`` (run_one's arguments after args and cfg), --jobs at a time,
    each in a process of its own, calling ``done`` after each; the callers then read their
    results. Nothing under --report."""
    todo = [(args, cfg, *job) for job in jobs if not args.report and not (_out(args, *job) / RESULT).is_file()]
    if args.jobs <= 1 or len(todo) <= 1:
        for job in todo:
            _run_job(job)
            done()
        return
    # spawned, not forked: the parent may hold torch's threads
    with concurrent.futures.ProcessPoolExecutor(max_workers=args.jobs, mp_context=multiprocessing.get_context("spawn")) as pool:
        for finished in concurrent.futures.as_completed([pool.submit(_run_job, job) for job in todo]):
            finished.result()
            done()


def _out(args, algo: str, seed: int, steps: int, out: Path | None = None, *_) -> Path:
    return out if out is not None else args.out / algo / f"seed-{seed}"


def bench_masks(args, cfg, seeds: list[int]) -> dict[str, dict[int, np.ndarray]]:
    """Each condition of --bench that has grids for these seeds: its success masks; the plant
    parameters must be ours."""
    out: dict[str, dict[int, np.ndarray]] = {}
    ours = model_to_dict(cfg.model)
    for condition in REGISTRY:
        masks = {}
        for seed in seeds:
            d = bench.seed_dir(args.bench, condition, seed)
            if not results.exists(d):
                continue
            cells, record = results.load(d)
            theirs = model_to_dict(results.load_config(record).model)
            if theirs != ours:
                raise UsageError(f"--bench {d} ran the plant with other parameters ({theirs} against {ours})")
            masks[seed] = metrics.success_mask(cells)
        if masks:
            out[condition] = masks
    return out


def collect(args, cfg) -> dict[str, Any]:
    name, limit = sb3.actuator_limit(cfg)
    held = heldout.heldout_mask(cfg.plant_name)
    data: dict[str, Any] = {"plant": cfg.plant_name, "set": args.set, "actuator": {"parameter": name, "limit": limit},
                            "success_steps": int(cfg.run.success_steps), "plant_parameters": model_to_dict(cfg.model),
                            "n_cells": int(held.size), "n_heldout": int(np.count_nonzero(held)),
                            "intervals": stats.settings(), "algorithms": {}}
    others = bench_masks(args, cfg, args.seeds) if args.bench is not None else {}
    if args.bench is not None:
        data["bench"] = str(args.bench)
    if args.tuned is not None:
        data["tuned"] = {"record": str(args.tuned), "chosen": {a: heldout.key(h) for a, h in args.hyper.items()}}
    run_all(args, cfg, [(algo, s, args.steps or sb3.ALGORITHMS[algo].budget, None, args.hyper.get(algo))
                        for algo in args.algos for s in args.seeds])
    for algo in args.algos:
        steps = args.steps or sb3.ALGORITHMS[algo].budget
        hyper = args.hyper.get(algo)
        runs = {s: r for s in args.seeds if (r := run_one(args, cfg, algo, s, steps, overrides=hyper))}
        entry: dict[str, Any] = {"settings": sb3.settings(algo, steps, hyper), "runs": runs}
        if runs:
            masks = {s: _mask(r["success"]) for s, r in runs.items()}
            entry["all"] = stats.success(masks)
            entry["heldout"] = stats.success({s: m[held] for s, m in masks.items()})
            entry["paired"] = {c: stats.paired(masks, m) for c, m in others.items()}
        if runs:
            entry["cost"] = {key: {"mean": float(np.mean([r[field] for r in runs.values()]))}
                             for key, field in (("trials", "episodes"), ("steps", "steps"),
                                                ("simulated_time", "simulated_time"))}
            entry["cost"]["wall_time"] = {"mean": float(np.mean([r["train_wall_time"] + r["eval_wall_time"]
                                                                 for r in runs.values()]))}
        data["algorithms"][algo] = entry
    gits = [r["git"] for e in data["algorithms"].values() for r in e["runs"].values()]
    data.update(profile="rl-baselines", configuration="default", git=results.git_info(),
                seeds=sorted({int(s) for e in data["algorithms"].values() for s in e["runs"]}),
                cell_builds=[g for i, g in enumerate(gits) if g not in gits[:i]])
    return data


def _hyper(items: list[str]) -> dict[str, Any]:
    """--hyper NAME=VALUE items as numbers (a name given twice: the last)."""
    out: dict[str, Any] = {}
    for item in items:
        name, sep, text = item.partition("=")
        try:
            value = float(text)
        except ValueError:
            value = None
        if not sep or not name or value is None or not np.isfinite(value):
            raise UsageError(f"--hyper takes NAME=NUMBER, got {item!r:.60}")
        out[name] = int(value) if value.is_integer() and "." not in text and "e" not in text.lower() else value
    return out


def _tuning_record(args, path: Path, plant: str) -> dict[str, Any]:
    """A tuning record of this plant, --set and protocol."""
    try:
        record = json.loads(path.read_text())
    except (OSError, ValueError) as err:
        raise UsageError(f"cannot read the tuning record {path}: {err}") from None
    if (record.get("plant"), record.get("set"), record.get("protocol")) != (plant, args.set, heldout.protocol(plant)):
        raise UsageError(f"{path} holds the tuning of another plant, --set or protocol")
    return record


def _kept_runs(args, plant: str) -> dict[str, Any]:
    """The runs the tuning record --data holds: {algo: {setting key: {seed: summary}}}."""
    if args.data is None or not args.data.exists():
        return {}
    old = _tuning_record(args, args.data, plant)
    return {algo: entry.get("runs", {}) for algo, entry in old["algorithms"].items()}


def _chosen(args, plant: str) -> dict[str, dict[str, Any]]:
    """Each algorithm's choice by the criterion from the runs of the tuning record --tuned, which
    must all have finished."""
    algorithms = _tuning_record(args, args.tuned, plant)["algorithms"]
    out = {}
    for algo in args.algos:
        if algo not in algorithms:
            raise UsageError(f"{args.tuned}: {algo} was not tuned")
        entry = _ranking(algo, algorithms[algo]["steps"], algorithms[algo]["runs"])
        if "chosen" not in entry:
            raise UsageError(f"{args.tuned}: {algo} has no choice yet ({entry['pending']} settings unfinished)")
        out[algo] = entry["chosen"]
    return out


def tune(args, cfg) -> dict[str, Any]:
    """The held-out tuning of each algorithm (see the module's head): its rows, best first, and its
    choice; an algorithm with unfinished runs is listed as pending, with its finished runs."""
    cells = [int(i) for i in heldout.tuning_cells(cfg.plant_name)]
    runs = _kept_runs(args, cfg.plant_name)
    data: dict[str, Any] = {"plant": cfg.plant_name, "set": args.set, "protocol": heldout.protocol(cfg.plant_name),
                            "profile": "rl-baselines tuning", "configuration": "the Zoo's start",
                            "seeds": list(heldout.TUNING_SEEDS), "n_tuning_cells": len(cells), "algorithms": {},
                            "git": results.git_info()}

    def out(algo, key, seed):
        return args.out / "tuning" / algo / key / f"seed-{seed}"

    def steps_of(algo):
        return args.steps or sb3.ALGORITHMS[algo].budget

    def summarise() -> None:
        """Each finished run's summary into the record, then each algorithm's rows or pending."""
        for algo in args.algos:
            for setting in heldout.baseline_settings(algo):
                key = heldout.key(setting)
                for seed in heldout.TUNING_SEEDS:
                    kept = runs.setdefault(algo, {}).setdefault(key, {})
                    if str(seed) in kept or not (out(algo, key, seed) / RESULT).is_file():
                        continue
                    r = json.loads((out(algo, key, seed) / RESULT).read_text())
                    if len(r["success"]) != len(cells):
                        raise UsageError(f"{out(algo, key, seed)} was not scored on the tuning cells; move it aside")
                    kept[str(seed)] = {"success_rate": float(_mask(r["success"]).mean()), "steps": r["steps"],
                                       "episodes": r["episodes"], "train_wall_time": r["train_wall_time"],
                                       "eval_wall_time": r["eval_wall_time"], "git": r["git"]}
            data["algorithms"][algo] = _ranking(algo, steps_of(algo), runs[algo])
        gits = [r["git"] for by_key in runs.values() for by_seed in by_key.values() for r in by_seed.values()]
        data["cell_builds"] = [g for i, g in enumerate(gits) if g not in gits[:i]]
        if args.data is not None:  # under --report too: the record rewritten from the runs it holds
            args.data.write_text(json.dumps(data, indent=1))

    run_all(args, cfg, [(algo, seed, steps_of(algo), out(algo, heldout.key(setting), seed), setting, cells)
                        for algo in args.algos for setting in heldout.baseline_settings(algo)
                        for seed in heldout.TUNING_SEEDS
                        if str(seed) not in runs.get(algo, {}).get(heldout.key(setting), {})],
            done=summarise)
    summarise()
    return data


def _rows(algo: str, steps: int, runs: Mapping[str, Mapping[str, Any]]) -> tuple[list[dict[str, Any]], int]:
    """The rows of the settings whose seeds have all finished, in the space's order, and the count
    of the others."""
    rows, pending = [], 0
    for index, setting in enumerate(heldout.baseline_settings(algo)):
        key = heldout.key(setting)
        done = [runs.get(key, {}).get(str(seed)) for seed in heldout.TUNING_SEEDS]
        if None in done:
            pending += 1
            continue
        rates = [r["success_rate"] for r in done]
        rows.append({"order": index, "setting": setting, "key": key, "success_rate": float(np.mean(rates)),
                     "success_rates": rates, "median_trials": None, "steps": steps,
                     "wall_time": float(sum(r["train_wall_time"] + r["eval_wall_time"] for r in done))})
    return rows, pending


def _ranking(algo: str, steps: int, runs: Mapping[str, Mapping[str, Any]]) -> dict[str, Any]:
    """An algorithm's entry of the tuning record from its finished runs: the rows of the settings
    whose seeds have all finished, best first, and the choice, or the count still pending."""
    rows, pending = _rows(algo, steps, runs)
    entry: dict[str, Any] = {"settings": len(heldout.baseline_settings(algo)), "steps": steps, "runs": dict(runs)}
    if pending:
        entry["pending"] = pending
    else:
        ranked = heldout.rank(rows)
        entry.update(rows=ranked, chosen=ranked[0]["setting"], chosen_key=ranked[0]["key"],
                     default_kept=ranked[0]["order"] == 0)
    return entry


def tuning_table(data: Mapping[str, Any]) -> list[str]:
    """The tuning record's settings per algorithm, best first by the criterion once every run is
    in (the choice in bold), else in the space's order with the count unfinished: success on the
    tuning cells per tuning seed and their mean, and the wall time of both runs."""
    seeds = data["seeds"]
    lines = ["| algorithm | setting (over the Zoo's start) | " + " | ".join(f"seed {s}" for s in seeds) +
             " | mean success, tuning cells | wall time, both seeds (s) |", "|---|---|" + "---|" * (len(seeds) + 2)]
    for algo, entry in data["algorithms"].items():
        label = sb3.ALGORITHMS[algo].label
        rows = entry.get("rows") or _rows(algo, entry["steps"], entry["runs"])[0]
        for row in rows:
            setting = ", ".join(f"{k} {v:g}" for k, v in sorted(row["setting"].items()))
            chosen = row["key"] == entry.get("chosen_key")
            mean = tables.percent(row["success_rate"])
            lines.append(f"| {label} | {'**' + setting + '**' if chosen else setting} | " +
                         " | ".join(tables.percent(r) for r in row["success_rates"]) +
                         f" | {'**' + mean + '**' if chosen else mean} | {row['wall_time']:.0f} |")
        if entry.get("pending"):
            lines.append(f"| {label} | {entry['pending']} of {entry['settings']} settings unfinished |" +
                         " |" * (len(seeds) + 2))
    return lines


def _points(p: Mapping[str, Any]) -> str:
    if p.get("points") is None:
        return "n/a"
    lo, hi = p["ci95"] or (None, None)
    ci = f" ({lo:+.1f} to {hi:+.1f})" if lo is not None else ""
    return f"{p['points']:+.1f}{ci}, p ≤ {p['p_max']:.2g}"


PAIRED_WITH = ("ico-rl", "rl", "search", "cma-es", "lqr")


def table(data: Mapping[str, Any]) -> list[str]:
    """PPO and SAC on one plant: budget, success (all and held-out cells), cost, and the paired
    difference against the bench's conditions (points, their interval, McNemar's largest p)."""
    paired = [c for c in PAIRED_WITH if any(c in e.get("paired", {}) for e in data["algorithms"].values())]
    header = ["method", "env steps (RL Zoo's)", "seeds", "success, all cells (95 % interval)", "held-out cells",
              "training episodes", "simulated time (s)", "wall time (s)"] + \
        [f"against {REGISTRY[c].label} (points)" for c in paired]
    lines = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    for algo, e in data["algorithms"].items():
        if "all" not in e:
            continue
        st, cost = e["settings"], e["cost"]
        cells = [f"{st['algorithm']}", f"{st['steps']:.3g} ({st['zoo_steps']:.0e})", str(len(e["runs"])),
                 tables.rate(e["all"]), tables.percent(e["heldout"]["mean"]),
                 f"{cost['trials']['mean']:.3g}", f"{cost['simulated_time']['mean']:.3g}",
                 f"{cost['wall_time']['mean']:.3g}"] + [_points(e["paired"][c]) if c in e["paired"] else "n/a"
                                                        for c in paired]
        lines.append("| " + " | ".join(cells) + " |")
    return lines


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(prog="python -m icoac.tools.rl_baselines", description=__doc__.split("\n")[0])
    ap.add_argument("--plant", default=next(iter(PLANTS)), choices=tuple(PLANTS), help="default: the registry's first")
    ap.add_argument("--set", action="append", default=[], metavar="NAME=VALUE",
                    help="a plant or run parameter (success_steps: the evaluation's horizon)")
    ap.add_argument("--limited", action="store_true",
                    help="hold the plant to a real actuator's limit, as its C file gives it (`icoac grid --help`)")
    ap.add_argument("--algos", nargs="+", choices=tuple(sb3.ALGORITHMS), default=list(sb3.ALGORITHMS))
    ap.add_argument("--seeds", nargs="+", type=int, default=list(range(bench.PROFILES["default"]["seeds"])))
    ap.add_argument("--steps", type=int, help="env steps per training run (default: each algorithm's budget)")
    ap.add_argument("--out", required=True, type=Path)
    ap.add_argument("--bench", type=Path, help="grids of the same plant to pair with (OUT/<condition>/seed-<s>)")
    ap.add_argument("--data", type=Path, help="also write the summary here (docs/data/...); with --tune, the "
                    "record written after every run, whose runs are not trained again")
    ap.add_argument("--report", action="store_true", help="run nothing: summarise the finished runs")
    ap.add_argument("--jobs", type=int, default=1, help="training runs at once, each a process on one thread")
    ap.add_argument("--tune", action="store_true", help="the held-out tuning of the algorithms (docs/tuning.md)")
    ap.add_argument("--hyper", action="append", default=[], metavar="NAME=VALUE",
                    help="a hyperparameter over the RL Zoo's start, for the evaluation runs of one algorithm")
    ap.add_argument("--tuned", type=Path, metavar="RECORD",
                    help="evaluate each algorithm with its choice in this finished tuning record (--tune --data)")
    args = ap.parse_args(argv)

    def body():
        if args.limited:
            args.set = PLANTS[args.plant].limited(args.set)
        if args.steps is not None and args.steps < 1:
            raise UsageError(f"--steps must be at least 1, got {args.steps}")
        if not 1 <= args.jobs <= (os.cpu_count() or 1) * 4:
            raise UsageError(f"--jobs must be from 1 to {(os.cpu_count() or 1) * 4}, got {args.jobs}")
        if args.tune and (args.hyper or args.tuned):
            raise UsageError("--tune runs the tuning space's settings; --hyper and --tuned are for the evaluation runs")
        if args.hyper and args.tuned:
            raise UsageError("--hyper and --tuned both set the hyperparameters: give one")
        hyper = _hyper(args.hyper)
        if hyper and len(args.algos) != 1:
            raise UsageError("--hyper sets one algorithm's hyperparameters: give --algos with one of them")
        known = set(sb3.ALGORITHMS[args.algos[0]].hyper) | set(heldout.BASELINE_SPACES[args.algos[0]])
        unknown = sorted(set(hyper) - known)
        if unknown:
            raise UsageError(f"--hyper {unknown[0]}: not a tuned hyperparameter of {args.algos[0]} "
                             f"(valid: {', '.join(sorted(known))})")
        cfg = build_config(parse_sets(args.set, plant=args.plant), plant=args.plant)
        sb3.actuator_limit(cfg)
        # each algorithm's overrides of the Zoo's start
        args.hyper = _chosen(args, cfg.plant_name) if args.tuned else {args.algos[0]: hyper} if hyper else {}
        return tune(args, cfg) if args.tune else collect(args, cfg)
    status, data = guarded(body)
    if data is None:
        return status
    text = json.dumps(data, indent=1)
    args.out.mkdir(parents=True, exist_ok=True)
    if args.tune:
        (args.out / "tuning.json").write_text(text)
        for algo, entry in data["algorithms"].items():
            state = f"chose {entry['chosen_key']}" if "chosen" in entry else f"{entry['pending']} settings unfinished"
            print(f"{algo}: {state}")
        return 0
    (args.out / "rl-baselines.json").write_text(text)
    if args.data is not None:
        args.data.write_text(text)
    for algo, entry in data["algorithms"].items():
        if "all" in entry:
            print(f"{algo}: {100 * entry['all']['mean']:.1f} % of all cells over seeds {sorted(entry['runs'])}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
