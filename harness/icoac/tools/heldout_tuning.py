# SPDX-License-Identifier: Apache-2.0
"""The held-out tuning of every learner on a plant (the protocol: icoac.studies.heldout,
docs/tuning.md):

    python -m icoac.tools.heldout_tuning --plant cart_pole --out results/tuning-cart_pole

ICO first: its settings on the tuning cells and seeds. Its chosen setting's grids then give the
learners that take ICO's output their priors, seed for seed (the central frame's cells among the
tuning cells). Every (learner, setting, seed) is a results directory
OUT/<learner>/<setting>/seed-<s>/, so a stopped run resumes where it stopped (rerun the command).
OUT/tuning.json and OUT/summary.md hold each learner's ranking and choice.

--data FILE (docs/data/...) is written after every finished setting and read at the start: a
setting whose row it holds (same plant and protocol) is not run again. So a tuning longer than a
machine's life goes on from its committed record; only ICO's chosen grids, which the learners after
it take as priors, are rerun when they are missing, and must give the recorded rates.

--evaluate --bench DIR then runs each learner's choice on every cell with the bench's seeds (ICO
first again; the others' priors from its evaluated grids) into OUT/evaluation/, and sets it beside
the bench's grids of the current defaults: success on the held-out cells and on all cells, and the
paired difference. A learner that kept its default and takes nothing from ICO is the bench's grid
itself, read, not rerun. The no-learning control of a rerun learner runs too, with its learner's
choice and prior. OUT/evaluation/bench/ then holds a whole bench of the tuned settings (links to
those grids, and to --bench's for every condition that kept its grid), and --bench-data FILE
writes its summary (`bench --summary-only`), labelled as tuned, for docs/data."""
from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path
from typing import Any

import numpy as np

from icoac.core import binding as B
from icoac.core import metrics, results, stats
from icoac.core.errors import ResultsError, UsageError
from icoac.core.plants import PLANTS
from icoac.core.registry import REGISTRY
from icoac.studies import bench, heldout
from icoac.studies import prior as P
from icoac.studies.conditions import condition_prior, run_condition
from icoac.tools.resumable import guarded

ORDER = heldout.LEARNERS  # ICO first: the others may take its output


def finished(out: Path) -> bool:
    return results.exists(out) and bool(results.load(out)[1].get("complete"))


def run_setting(args, learner: str, index: int, setting: dict[str, Any], ico_dirs: dict[int, Path] | None,
                rerun: bool = False) -> dict[str, Any] | None:
    """Every tuning seed of one setting; its row of the ranking (None with --report when a seed's
    grid is not finished: nothing runs then). A row --data holds is read, unless `rerun`."""
    kept = args.kept.get((learner, heldout.key(setting)))
    if kept is not None and not rerun:
        return kept
    caps = bench.PROFILES["default"]["ico" if learner == "ico" else "rl"]
    cells_spec = [int(i) for i in heldout.tuning_cells(args.plant)]
    rates, trials, cost, wall, records = [], [], 0, 0.0, []
    for seed in heldout.TUNING_SEEDS:
        out = args.out / learner / heldout.key(setting) / f"seed-{seed}"
        if args.report and not finished(out):
            return None
        rule = REGISTRY[learner].prior
        info = None if rule is None else condition_prior(
            learner, ico_dirs[seed] if rule.takes_ico else None, P.CENTRAL, P.DEFAULT_RIDGE, plant=args.plant,
            overrides={**caps, **setting})
        cells, record, cancelled = run_condition(
            condition=learner, out=out, seed=seed, threads=args.threads, overrides={**caps, **setting},
            cell_spec=cells_spec, resume=bool(results.present(out)), progress=not args.quiet, info=info,
            plant=args.plant)
        if cancelled:
            raise KeyboardInterrupt
        ok = metrics.success_mask(cells)
        rates.append(float(ok.mean()))
        trials.extend(cells["trials"][ok].tolist())
        cost += int(np.sum(cells["trials"]))
        wall += float(record["wall_time"])
        records.append(record)
    row = {"order": index, "setting": setting, "key": heldout.key(setting), "success_rate": float(np.mean(rates)),
           "success_rates": rates, "median_trials": float(np.median(trials)) if trials else None,
           "trials": cost, "wall_time": wall, "builds": bench.cell_builds(records)}
    print(f"[tuning] {learner} {row['key']}: {100 * row['success_rate']:.1f} %, median "
          f"{row['median_trials']} trials, {wall:.0f} s", file=sys.stderr, flush=True)
    return row


def kept_rows(args) -> dict[tuple[str, str], dict[str, Any]]:
    """The rows of the settings --data already holds, by (learner, setting key)."""
    if args.data is None or not args.data.exists():
        return {}
    old = json.loads(args.data.read_text())
    if old.get("plant") != args.plant or old.get("protocol") != heldout.protocol(args.plant):
        raise UsageError(f"{args.data} holds another plant's or protocol's tuning; move it aside")
    return {(name, r["key"]): r for name, t in old["learners"].items() for r in t.get("rows", [])}


def save(args, data: dict[str, Any]) -> None:
    """The record so far: OUT/tuning.json, and --data."""
    args.out.mkdir(parents=True, exist_ok=True)
    text = json.dumps(data, indent=1)
    (args.out / "tuning.json").write_text(text)
    if args.data is not None:
        args.data.write_text(text)


def tune(args, learner: str, ico_dirs: dict[int, Path] | None, data: dict[str, Any]) -> dict[str, Any]:
    """The learner's rows and choice into data["learners"]; while settings are unfinished,
    {"pending": the number unfinished, ...} with the finished rows. Saved after each setting (not
    with --report)."""
    settings = heldout.settings(learner, args.plant)
    rows = []
    for i, s in enumerate(settings):
        rows.append(run_setting(args, learner, i, s, ico_dirs))
        done = [r for r in rows if r is not None]
        data["learners"][learner] = {"learner": learner, "pending": len(settings) - len(done),
                                     "settings": len(settings), "rows": done}
        if not args.report:
            save(args, data)
    if None in rows:
        return data["learners"][learner]
    ranked = heldout.rank(rows)
    data["learners"][learner] = {
        "learner": learner, "rows": rows, "chosen": ranked[0]["setting"], "chosen_key": ranked[0]["key"],
        "default_kept": ranked[0]["order"] == 0, "trials": sum(r["trials"] for r in rows),
        "wall_time": sum(r["wall_time"] for r in rows)}
    if not args.report:
        save(args, data)
    return data["learners"][learner]


def run(args) -> dict[str, Any]:
    """ICO, then every learner asked for, from ICO's chosen grids."""
    data: dict[str, Any] = {"plant": args.plant, "profile": "default", "configuration": "default", "set": [],
                            "seeds": list(heldout.TUNING_SEEDS), "protocol": heldout.protocol(args.plant),
                            "n_tuning_cells": int(heldout.tuning_cells(args.plant).size),
                            "n_cells": int(heldout.heldout_mask(args.plant).size), "learners": {},
                            "git": results.git_info()}
    ico = tune(args, "ico", None, data)
    ico_dirs = None if "pending" in ico else \
        {s: args.out / "ico" / ico["chosen_key"] / f"seed-{s}" for s in heldout.TUNING_SEEDS}
    if ico_dirs and not args.report and not all(finished(d) for d in ico_dirs.values()):
        chosen = next(r for r in ico["rows"] if r["key"] == ico["chosen_key"])
        again = run_setting(args, "ico", chosen["order"], chosen["setting"], None, rerun=True)
        if again["success_rates"] != chosen["success_rates"]:
            raise ResultsError(f"ICO's chosen setting {chosen['key']} rerun gives {again['success_rates']}, "
                               f"not the recorded {chosen['success_rates']}: the code changed since the record")
    for learner in ORDER[1:]:
        if learner in args.learners:
            if ico_dirs or not REGISTRY[learner].prior.takes_ico:
                tune(args, learner, ico_dirs, data)
            else:
                n = len(heldout.settings(learner, args.plant))
                data["learners"][learner] = {"learner": learner, "pending": n, "settings": n}
    builds = [b for t in data["learners"].values() for r in t.get("rows", []) for b in r["builds"]]
    data["cell_builds"] = [b for i, b in enumerate(builds) if b not in builds[:i]]
    return data


def _run(args, condition: str, out: Path, seed: int, overrides: dict[str, Any], info) -> None:
    """One grid of the evaluation, resumed if started."""
    _, _, cancelled = run_condition(condition=condition, out=out, seed=seed, threads=args.threads,
                                    overrides=overrides, resume=bool(results.present(out)),
                                    progress=not args.quiet, info=info, plant=args.plant)
    if cancelled:
        raise KeyboardInterrupt


def assemble(args, data: dict[str, Any]) -> Path:
    """OUT/evaluation/bench/<condition>/seed-<s>: a link to the evaluation's grid of each condition
    that was rerun with its learner's choice (its control with it), else to --bench's."""
    ev = data["evaluation"]
    root = args.out / "evaluation"
    rerun = {name for name, e in ev["learners"].items() if e["rerun"]}
    rerun |= {REGISTRY[name].control for name, e in ev["learners"].items() if e.get("control_rerun")}
    target = root / "bench"
    for condition in REGISTRY:
        for seed in ev["seeds"]:
            source = bench.seed_dir(root if condition in rerun else args.bench, condition, seed)
            if not results.exists(source):
                continue
            link = bench.seed_dir(target, condition, seed)
            link.parent.mkdir(parents=True, exist_ok=True)
            if link.is_symlink() or link.exists():
                link.unlink()
            link.symlink_to(source.resolve(), target_is_directory=True)
    ceiling = args.bench / "ceiling"  # the best single w found: no learner's setting in it
    if ceiling.is_dir() and not (target / "ceiling").exists():
        (target / "ceiling").symlink_to(ceiling.resolve(), target_is_directory=True)
    return target


def bench_summary(args, data: dict[str, Any]) -> None:
    """The assembled bench's summary (`bench --summary-only`) into --bench-data, with the tuning's
    choices recorded (and shown in the tables' plant label)."""
    target = assemble(args, data)
    opt = bench.BenchOptions(profile="default", out=target, data=args.bench_data, summary_only=True,
                             quiet=args.quiet, plant=args.plant)
    if bench.run_bench(opt) != 0:
        raise KeyboardInterrupt
    record = json.loads(args.bench_data.read_text())
    record["tuned"] = {"protocol": "held-out (docs/tuning.md)", "tuning_git": data["git"],
                       "chosen": {name: t["chosen_key"] for name, t in data["learners"].items() if "chosen_key" in t}}
    args.bench_data.write_text(json.dumps(record, indent=1))


def evaluate(args, data: dict[str, Any]) -> dict[str, Any]:
    """Each tuned learner's choice on every cell with the bench's seeds, against the bench's grids
    of the defaults (see the module's head)."""
    seeds = list(range(bench.PROFILES["default"]["seeds"]))
    held = heldout.heldout_mask(args.plant)
    root = args.out / "evaluation"
    ico = data["learners"]["ico"]
    ico_dirs = {s: (bench.seed_dir(args.bench, "ico", s) if ico["default_kept"] else root / "ico" / f"seed-{s}")
                for s in seeds}
    out: dict[str, Any] = {}
    for learner, t in data["learners"].items():
        if "pending" in t:
            continue
        caps = bench.PROFILES["default"]["ico" if learner == "ico" else "rl"]
        rule = REGISTRY[learner].prior
        reuse = t["default_kept"] and (rule is None or not rule.takes_ico or ico["default_kept"])
        chosen, default = {}, {}
        control = REGISTRY[learner].control
        for seed in seeds:
            d = bench.seed_dir(args.bench if reuse else root, learner, seed)
            if not reuse:
                info = None if rule is None else condition_prior(
                    learner, ico_dirs[seed] if rule.takes_ico else None, P.CENTRAL, P.DEFAULT_RIDGE,
                    plant=args.plant, overrides={**caps, **t["chosen"]})
                for condition in (learner,) + ((control,) if control else ()):
                    _run(args, condition, bench.seed_dir(root, condition, seed), seed, {**caps, **t["chosen"]}, info)
            chosen[seed] = metrics.success_mask(results.load(d)[0])
            default[seed] = metrics.success_mask(results.load(bench.seed_dir(args.bench, learner, seed))[0])
        out[learner] = {"chosen_key": t["chosen_key"], "default_kept": t["default_kept"], "rerun": not reuse,
                        "control_rerun": bool(control) and not reuse,
                        "all": {"chosen": stats.success(chosen), "default": stats.success(default),
                                "paired": stats.paired(chosen, default)},
                        "heldout": {"chosen": stats.success({s: m[held] for s, m in chosen.items()}),
                                    "default": stats.success({s: m[held] for s, m in default.items()}),
                                    "paired": stats.paired({s: m[held] for s, m in chosen.items()},
                                                           {s: m[held] for s, m in default.items()})}}
        print(f"[evaluation] {learner}: held-out {100 * out[learner]['heldout']['default']['mean']:.1f} -> "
              f"{100 * out[learner]['heldout']['chosen']['mean']:.1f} %", file=sys.stderr, flush=True)
    return {"seeds": seeds, "bench": str(args.bench), "n_heldout": int(np.count_nonzero(held)), "learners": out}


def _pct(r: dict[str, Any]) -> str:
    lo, hi = r["ci95"] or (None, None)
    return f"{100 * r['mean']:.1f} %" + (f" ({100 * lo:.1f}–{100 * hi:.1f})" if lo is not None else "")


def evaluation_table(data: dict[str, Any]) -> list[str]:
    """The choices on the evaluation seeds (docs/results.md, block tuning-evaluation): held-out and
    all cells, the default's and the choice's, and the paired difference on the held-out cells."""
    ev = data["evaluation"]
    lines = [f"| learner | setting | held-out cells ({ev['n_heldout']}): default | chosen | difference (points) | "
             "all cells: default | chosen |", "|---|---|---|---|---|---|---|"]
    for name, e in ev["learners"].items():
        p = e["heldout"]["paired"]
        lo, hi = p["ci95"] or (None, None)
        diff = f"{p['points']:+.1f}" + (f" ({lo:+.1f} to {hi:+.1f})" if lo is not None else "")
        setting = "the default" if e["default_kept"] else f"`{e['chosen_key']}`"
        lines.append(f"| {REGISTRY[name].label} | {setting} | {_pct(e['heldout']['default'])} | "
                     f"{_pct(e['heldout']['chosen'])} | {diff} | {_pct(e['all']['default'])} | "
                     f"{_pct(e['all']['chosen'])} |")
    return lines


def choices_table(data: dict[str, Any]) -> list[str]:
    """Each learner's choice (docs/results.md, block tuning): the setting, its success on the
    tuning cells beside the default's, and what the tuning cost."""
    lines = ["| learner | chosen setting | success, tuning cells (%) | the default's (%) | trials | wall time (s) |",
             "|---|---|---|---|---|---|"]
    for name, t in data["learners"].items():
        if "pending" in t:
            done = t["settings"] - t["pending"]
            lines.append(f"| {REGISTRY[name].label} | unfinished ({done} of {t['settings']} settings finished) "
                         "| | | | |")
            continue
        best = heldout.rank(t["rows"])[0]
        default = next(r for r in t["rows"] if r["order"] == 0)
        chosen = "the default" if t["default_kept"] else f"`{t['chosen_key']}`"
        lines.append(f"| {REGISTRY[name].label} | {chosen} | {100 * best['success_rate']:.1f} | "
                     f"{100 * default['success_rate']:.1f} | {t['trials']:.3g} | {t['wall_time']:.0f} |")
    return lines


READING_OF = {"gradient": "gradient (β = 0.001)", "mean": "mean (σ_L = 0.1, α = 0.1)"}


def prior_reading_table(data: dict[str, Any]) -> list[str]:
    """The four actor-critic priors x the two readings at every exploration noise of their shared
    space (docs/results.md, block prior-reading): success on the tuning cells, mean over the tuning
    seeds; the paper's same-parameter protocol is a column."""
    def rows_of(name):
        return [r for r in data["learners"].get(name, {}).get("rows", [])
                if {"actor.update", "actor.noise_std"} <= set(r["setting"])]
    names = [n for n in ("ico-rl", "ico-mean-rl", "rl-ico-cov", "rl") if rows_of(n)]
    if not names:
        return []
    noises = sorted({r["setting"]["actor.noise_std"] for n in names for r in rows_of(n)})
    unit = B.plant_info(data["plant"])["input"][1]  # the noise is in the plant's input unit
    lines = ["| prior (learner) | reading | " + " | ".join(f"σ_u = {v:g} {unit}" for v in noises) + " |",
             "|---|---|" + "---|" * len(noises)]
    for name in names:
        for reading in READING_OF:
            rows = {r["setting"]["actor.noise_std"]: r for r in rows_of(name)
                    if r["setting"]["actor.update"] == reading}
            cells = [f"{100 * rows[v]['success_rate']:.1f}" if v in rows else "" for v in noises]
            lines.append(f"| {REGISTRY[name].label} | {READING_OF[reading]} | " + " | ".join(cells) + " |")
    return lines


def markdown(data: dict[str, Any]) -> str:
    lines = [f"# Held-out tuning, {data['plant']}", "",
             f"Tuning cells: {data['n_tuning_cells']} of {data['n_cells']}; seeds {data['protocol']['tuning_seeds']}; "
             f"criterion: {data['protocol']['criterion']}.", "", *choices_table(data), ""]
    if "evaluation" in data:
        lines += [f"On the evaluation seeds {data['evaluation']['seeds']}, against the bench's defaults:", "",
                  *evaluation_table(data), ""]
    grid = prior_reading_table(data)
    if grid:
        lines += ["Success on the tuning cells (%), prior x reading x exploration noise:", "", *grid, ""]
    for name, t in data["learners"].items():
        if "pending" in t:
            continue
        lines += [f"## {REGISTRY[name].label} (`{name}`)", "",
                  f"Chosen: `{t['chosen_key']}`{' (the default)' if t['default_kept'] else ''}; "
                  f"{t['trials']} trials, {t['wall_time']:.0f} s.", "",
                  "| rank | setting | success (%) | per seed (%) | median trials |", "|---|---|---|---|---|"]
        for i, r in enumerate(heldout.rank(t["rows"]), 1):
            seeds = ", ".join(f"{100 * v:.1f}" for v in r["success_rates"])
            lines.append(f"| {i} | `{r['key']}`{' (default)' if r['order'] == 0 else ''} | "
                         f"{100 * r['success_rate']:.2f} | {seeds} | {r['median_trials']} |")
        lines.append("")
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(prog="python -m icoac.tools.heldout_tuning", description=__doc__.split("\n")[0])
    ap.add_argument("--plant", default="cart_pole", choices=tuple(PLANTS))
    ap.add_argument("--out", required=True, type=Path)
    ap.add_argument("--learners", nargs="+", choices=ORDER, default=list(ORDER),
                    help="the learners to tune (ICO always runs first: the others take its chosen grids)")
    ap.add_argument("--threads", type=int, default=0)
    ap.add_argument("--data", type=Path, help="also write tuning.json here (docs/data/...), after every finished "
                    "setting; the settings it holds are not run again")
    ap.add_argument("--report", action="store_true",
                    help="run nothing: report the learners whose settings have all finished")
    ap.add_argument("--evaluate", action="store_true",
                    help="then run each choice on every cell with the bench's seeds, against --bench's defaults")
    ap.add_argument("--bench", type=Path, help="the bench whose grids are the defaults' (--evaluate)")
    ap.add_argument("--bench-data", type=Path,
                    help="with --evaluate: the summary of the bench of the tuned settings (docs/data/...)")
    ap.add_argument("--quiet", action="store_true")
    args = ap.parse_args(argv)
    if args.evaluate and args.bench is None:
        ap.error("--evaluate needs --bench")
    if args.bench_data is not None and not args.evaluate:
        ap.error("--bench-data needs --evaluate")

    def body():
        args.kept = kept_rows(args)
        data = run(args)
        if args.evaluate and "pending" not in data["learners"]["ico"]:
            data["evaluation"] = evaluate(args, data)
            if args.bench_data is not None:
                bench_summary(args, data)
        return data
    status, data = guarded(body)
    if data is None:
        return status
    save(args, data)
    (args.out / "summary.md").write_text(markdown(data))
    print(markdown(data))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
