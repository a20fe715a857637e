"""Command line: `python -m harness grid|figures|bench ...`."""
from __future__ import annotations

import argparse
import shutil
import sys
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Callable

PROG = "icoac-harness"


class UsageError(Exception):
    """A user mistake: reported as one line, exit status 2."""


class _Parser(argparse.ArgumentParser):
    def error(self, message):  # one line, status 2, no usage dump
        raise UsageError(message)


def _parse_sets(items) -> dict:
    from .config import parse_value
    out = {}
    for item in items or []:
        if "=" not in item:
            raise UsageError(f"--set expects name=value, got {item!r}")
        name, value = item.split("=", 1)
        out[name.strip()] = parse_value(value.strip())
    return out


def _overrides(args) -> dict:
    over = _parse_sets(args.set)
    if args.max_trials is not None:
        over["max_trials"] = args.max_trials
    if args.success_steps is not None:
        over["success_steps"] = args.success_steps
    return over


def run_condition(*, condition: str, out: Path, seed: int, threads: int, overrides: dict,
                  cell_spec=None, resume: bool = False, fresh: bool = False, progress: bool = True,
                  checkpoint_every: float = 30.0, prior=None, explicit: bool = True,
                  cancel_after: float | None = None) -> tuple:
    """Run (or resume) one condition into a results directory; returns (cells, record, cancelled)."""
    from . import grid, results
    from .config import build_config

    out = Path(out)
    have = results.exists(out)
    if resume and not have:
        raise UsageError(f"--resume: no results to resume in {str(out)!r}")
    if have and fresh:
        for name in (results.CELLS_FILE, results.RUN_FILE):
            (out / name).unlink()
        have = False
    indices = grid.parse_cell_indices(cell_spec)
    if have:
        cells, record = results.load(out)
        if resume and not explicit:
            cfg = results.load_config(record)
            condition, seed, indices = record["condition"], record["seed"], record.get("cells")
        else:
            cfg = build_config(overrides, condition=condition, prior=prior)
        results.check_resumable(record, condition=condition, seed=seed, cfg=cfg, cell_indices=indices)
        wall_before = float(record.get("wall_time", 0.0))
        n_pending = int((cells["outcome"] == 0).sum())
        if progress:
            print(f"resuming {out}: {n_pending} of {cells.size} cells pending", file=sys.stderr)
    else:
        cfg = build_config(overrides, condition=condition, prior=prior)
        cells = grid.make_cells(seed, indices)
        wall_before = 0.0
    n_threads = threads if threads > 0 else grid.default_threads()

    def save(snapshot, wall):
        return results.save(out, snapshot, cfg, condition=condition, seed=seed, wall_time=wall,
                            threads=n_threads, cell_indices=indices)

    t0 = time.monotonic()
    save(grid.finished_snapshot(cells), wall_before)
    run = grid.run_grid(cfg, cells, threads=threads, progress=progress,
                        checkpoint=lambda snap: save(snap, wall_before + time.monotonic() - t0),
                        checkpoint_every=checkpoint_every, cancel_after=cancel_after,
                        desc=condition)
    record = save(cells, wall_before + run.wall_time)
    return cells, record, run.cancelled


# -- commands ------------------------------------------------------------------------------------------
def cmd_grid(args) -> int:
    from . import metrics

    explicit = any(v is not None for v in (args.condition, args.seed, args.max_trials, args.success_steps,
                                            args.cells)) or bool(args.set)
    cells, record, cancelled = run_condition(
        condition=args.condition or "ico", out=Path(args.out), seed=args.seed or 0, threads=args.threads,
        overrides=_overrides(args), cell_spec=args.cells, resume=args.resume, progress=not args.quiet,
        checkpoint_every=args.checkpoint_every, explicit=explicit or not args.resume)
    print(metrics.format_summary(record["condition"], record["summary"]))
    print(f"wall time {record['wall_time']:.1f} s on {record['threads']} threads -> {args.out}")
    if cancelled:
        print(f"interrupted: finished cells saved; resume with `python -m harness grid --out {args.out} --resume`",
              file=sys.stderr)
        return 130
    return 0


def cmd_figures(args) -> int:
    from . import figures, results

    cells, record = results.load(args.results)
    for path in figures.make_figures(cells, record, args.out, duration=args.duration):
        print(path)
    return 0


@dataclass
class Stage:
    name: str
    run: Callable[[dict], None]


PROFILES = {
    "default": {"overrides": {}},                       # paper caps: 1e5 trials, 1e5 steps
    "quick": {"overrides": {"max_trials": 2000}},       # smoke test
}


def bench_stages(args) -> list[Stage]:
    """Benchmark as a list of stages sharing a context dict; add conditions (RL, ICO->RL) here."""
    from . import figures, metrics

    profile = PROFILES[args.profile]
    out = Path(args.out)
    figdir = Path(args.figures) if args.figures else None

    def grid_stage(condition: str):
        def run(ctx):
            overrides = dict(profile["overrides"])
            overrides.update(_parse_sets(args.set))
            cells, record, cancelled = run_condition(
                condition=condition, out=out / condition, seed=args.seed, threads=args.threads,
                overrides=overrides, resume=args.resume, fresh=not args.resume, progress=not args.quiet)
            ctx[condition] = (cells, record)
            if cancelled:
                raise KeyboardInterrupt
        return Stage(f"grid {condition}", run)

    def figures_stage(condition: str):
        def run(ctx):
            if figdir is None:
                return
            cells, record = ctx[condition]
            for path in figures.make_figures(cells, record, figdir):
                print(f"  wrote {path}")
        return Stage(f"figures {condition}", run)

    def summary_stage(ctx):
        for condition in ("ico",):
            if condition in ctx:
                record = ctx[condition][1]
                print(metrics.format_summary(condition.upper(), record["summary"]))
                print(f"  wall time {record['wall_time']:.1f} s on {record['threads']} threads")

    return [grid_stage("ico"), figures_stage("ico"), Stage("summary", summary_stage)]


def cmd_bench(args) -> int:
    ctx: dict = {}
    t0 = time.monotonic()
    for stage in bench_stages(args):
        print(f"[bench] {stage.name}", file=sys.stderr)
        try:
            stage.run(ctx)
        except KeyboardInterrupt:
            print(f"interrupted during {stage.name}; finished cells saved, rerun with --resume", file=sys.stderr)
            return 130
    print(f"[bench] total wall time {time.monotonic() - t0:.1f} s", file=sys.stderr)
    return 0


def _positive_int(text: str) -> int:
    try:
        value = int(float(text))
    except ValueError:
        raise argparse.ArgumentTypeError(f"invalid integer {text!r}")
    if value < 1 or value != float(text):
        raise argparse.ArgumentTypeError(f"expected a positive integer, got {text!r}")
    return value


def _nonneg_int(text: str) -> int:
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"invalid integer {text!r}")
    if value < 0:
        raise argparse.ArgumentTypeError(f"expected an integer >= 0, got {text!r}")
    return value


def build_parser() -> argparse.ArgumentParser:
    p = _Parser(prog=PROG, description="icoac grid benchmarks, results and figures")
    sub = p.add_subparsers(dest="command", metavar="{grid,figures,bench}", parser_class=_Parser)
    sub.required = True

    g = sub.add_parser("grid", help="run (or resume) a 25x49 grid of one condition")
    g.add_argument("--condition", choices=["ico", "rl"], default=None, help="learning condition (default ico)")
    g.add_argument("--out", required=True, help="results directory")
    g.add_argument("--seed", type=_nonneg_int, default=None, help="grid seed (default 0)")
    g.add_argument("--threads", type=_nonneg_int, default=0, help="C threads (0: all cores)")
    g.add_argument("--max-trials", type=_positive_int, default=None)
    g.add_argument("--success-steps", type=_positive_int, default=None)
    g.add_argument("--set", action="append", metavar="NAME=VALUE", help="override a parameter (repeatable)")
    g.add_argument("--cells", default=None, help="subset of cell indices, e.g. 0,5,600-610")
    g.add_argument("--resume", action="store_true", help="continue PENDING cells of --out")
    g.add_argument("--checkpoint-every", type=float, default=30.0, help="seconds between checkpoints")
    g.add_argument("--quiet", action="store_true", help="no progress bar")
    g.set_defaults(func=cmd_grid)

    f = sub.add_parser("figures", help="draw Fig. 1b, 1c-f, 1g from a results directory")
    f.add_argument("--results", required=True)
    f.add_argument("--out", required=True, help="figure directory")
    f.add_argument("--duration", type=float, default=30.0, help="Fig. 1g trajectory length (s)")
    f.set_defaults(func=cmd_figures)

    b = sub.add_parser("bench", help="benchmark stages: grids, figures, summary")
    b.add_argument("--profile", choices=sorted(PROFILES), default="default")
    b.add_argument("--out", required=True)
    b.add_argument("--figures", default=None, help="figure directory")
    b.add_argument("--seed", type=_nonneg_int, default=0)
    b.add_argument("--threads", type=_nonneg_int, default=0)
    b.add_argument("--set", action="append", metavar="NAME=VALUE")
    b.add_argument("--resume", action="store_true", help="continue earlier results instead of starting over")
    b.add_argument("--quiet", action="store_true")
    b.set_defaults(func=cmd_bench)
    return p


def main(argv=None) -> int:
    try:
        args = build_parser().parse_args(argv)
        try:
            from ._binding import ConfigError, IcoacError, LibraryError
        except Exception as exc:  # missing or mismatched shared library: one line, status 2
            if type(exc).__name__ == "LibraryError":
                raise UsageError(str(exc))
            raise
        try:
            return args.func(args)
        except (ConfigError, LibraryError) as exc:
            raise UsageError(str(exc))
        except IcoacError as exc:
            print(f"{PROG}: error: {exc}", file=sys.stderr)
            return 1
    except UsageError as exc:
        print(f"{PROG}: error: {exc}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print(f"{PROG}: interrupted", file=sys.stderr)
        return 130
