"""Command line: `python -m harness grid|figures|bench|sweep ...`."""
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
                  cancel_after: float | None = None, extra: dict | None = None) -> tuple:
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
            if extra is None and record.get("prior_info") is not None:
                extra = {"prior_info": record["prior_info"]}
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
                            threads=n_threads, cell_indices=indices, extra=extra)

    t0 = time.monotonic()
    save(grid.finished_snapshot(cells), wall_before)
    run = grid.run_grid(cfg, cells, threads=threads, progress=progress,
                        checkpoint=lambda snap: save(snap, wall_before + time.monotonic() - t0),
                        checkpoint_every=checkpoint_every, cancel_after=cancel_after,
                        desc=condition)
    record = save(cells, wall_before + run.wall_time)
    return cells, record, run.cancelled


# -- commands ------------------------------------------------------------------------------------------
def _frame(args):
    from . import prior as P
    return P.parse_frame(args.prior_frame, args.prior_x, args.prior_theta)


def condition_prior(condition: str, prior_from, frame, ridge: float, rl_cov: str = "ico"):
    """PriorInfo of a condition (None for ico): ico-rl from an ICO results dir, rl with mean 0 (A16)."""
    from . import prior as P
    if condition == "ico":
        return None
    if prior_from is not None and not Path(prior_from).is_dir():
        raise UsageError(f"--prior-from: directory {str(prior_from)!r} does not exist")
    base = P.from_results(prior_from, frame, ridge) if prior_from is not None else None
    if condition == "ico-rl":
        if base is None:
            raise UsageError("condition ico-rl needs --prior-from ICO_RESULTS_DIR")
        return base
    return P.rl_prior(base, rl_cov)


def _add_prior_args(parser, rl_cov: bool = True) -> None:
    parser.add_argument("--prior-frame", choices=["central", "all"], default="central",
                        help="ICO cells for the prior: central frame (default) or all successful cells")
    parser.add_argument("--prior-x", type=float, default=None, help="frame half-width |x0| (m), default 1.2")
    parser.add_argument("--prior-theta", type=float, default=None, help="frame half-height |theta0| (deg), default 6")
    parser.add_argument("--prior-ridge", type=float, default=1e-6, help="ridge added to the prior covariance")
    if rl_cov:
        parser.add_argument("--rl-cov", choices=["ico", "identity"], default="ico",
                            help="RL-alone prior covariance: that of ICO->RL (default) or 1*I")


def cmd_grid(args) -> int:
    from . import metrics

    explicit = any(v is not None for v in (args.condition, args.seed, args.max_trials, args.success_steps,
                                            args.cells, args.prior_from)) or bool(args.set)
    condition = args.condition or "ico"
    info = None
    if explicit or not args.resume:
        if condition == "ico" and args.prior_from is not None:
            raise UsageError("--prior-from applies to the conditions rl and ico-rl")
        info = condition_prior(condition, args.prior_from, _frame(args), args.prior_ridge, args.rl_cov)
    cells, record, cancelled = run_condition(
        condition=condition, out=Path(args.out), seed=args.seed or 0, threads=args.threads,
        overrides=_overrides(args), cell_spec=args.cells, resume=args.resume, progress=not args.quiet,
        checkpoint_every=args.checkpoint_every, explicit=explicit or not args.resume,
        prior=info.prior() if info is not None else None,
        extra={"prior_info": info.to_dict()} if info is not None else None)
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


def _profiles():
    from .bench import PROFILES
    return PROFILES


PROFILE_NAMES = ("default", "paper", "quick")


def bench_stages(args) -> list[Stage]:
    """ICO grid per seed, prior per seed, ICO->RL and RL grids per seed, figures, summary."""
    from . import bench, figures
    from . import prior as P
    from . import results

    profile = _profiles()[args.profile]
    out = Path(args.out)
    figdir = Path(args.figures) if args.figures else None
    n_seeds = args.seeds if args.seeds is not None else profile["seeds"]
    seeds = [args.seed + i for i in range(n_seeds)]
    sets = _parse_sets(args.set)
    frame = _frame(args)
    cells_spec = profile["cells"]

    def overrides(condition):
        over = dict(profile["ico"] if condition == "ico" else profile["rl"])
        if condition != "ico" and args.rl_max_trials is not None:
            over["max_trials"] = args.rl_max_trials
        over.update(sets)
        return over

    def grid_stage(condition: str, seed: int):
        def run(ctx):
            d = bench.seed_dir(out, condition, seed)
            info = ctx.get(("prior", condition, seed))
            cells, record, cancelled = run_condition(
                condition=condition, out=d, seed=seed, threads=args.threads, overrides=overrides(condition),
                cell_spec=cells_spec, resume=args.resume and results.exists(d), fresh=not args.resume,
                progress=not args.quiet, prior=info.prior() if info is not None else None,
                extra={"prior_info": info.to_dict()} if info is not None else None)
            ctx[(condition, seed)] = (cells, record)
            s = record["summary"]
            bench.progress(f"  {condition} seed {seed}: success {s['n_success']}/{s['n_cells']}, "
                           f"grid wall time {record['wall_time']:.1f} s")
            if cancelled:
                raise KeyboardInterrupt
        return Stage(f"grid {condition} seed-{seed}", run)

    def prior_stage(seed: int):
        def run(ctx):
            info = P.from_results(bench.seed_dir(out, "ico", seed), frame, args.prior_ridge)
            ctx[("prior", "ico-rl", seed)] = info
            ctx[("prior", "rl", seed)] = P.rl_prior(info, args.rl_cov)
            bench.progress(f"  prior seed {seed}: {info.n_cells} cells, mean "
                           + ", ".join(f"{v:.4g}" for v in info.mean))
        return Stage(f"prior seed-{seed}", run)

    def figures_stage(ctx):
        if figdir is None:
            return
        cells, record = ctx[("ico", seeds[0])]
        for path in figures.make_figures(cells, record, figdir):
            bench.progress(f"  wrote {path}")
        agg = ctx["aggregate"]
        for path in bench.comparison_figures(agg, figdir, cells, ctx[("ico-rl", seeds[0])][0], frame=frame):
            bench.progress(f"  wrote {path}")

    def summary_stage(ctx):
        recs = {c: [ctx[(c, s)][1] for s in seeds if (c, s) in ctx] for c in bench.CONDITIONS}
        agg = bench.aggregate(recs)
        ctx["aggregate"] = agg
        md, js = bench.write_summary(out, agg)
        print(md.read_text(), end="")
        bench.progress(f"  wrote {md} and {js}")

    stages = [grid_stage("ico", s) for s in seeds]
    stages += [prior_stage(s) for s in seeds]
    stages += [grid_stage("ico-rl", s) for s in seeds]
    stages += [grid_stage("rl", s) for s in seeds]
    stages += [Stage("summary", summary_stage), Stage("figures", figures_stage)]
    return stages


def cmd_bench(args) -> int:
    from . import bench

    ctx: dict = {}
    profile = _profiles()[args.profile]
    n_seeds = args.seeds if args.seeds is not None else profile["seeds"]
    log = bench.BenchLog(Path(args.out), {
        "profile": args.profile, "seeds": [args.seed + i for i in range(n_seeds)],
        "rl_max_trials": args.rl_max_trials, "resume": bool(args.resume), "threads": args.threads,
        "set": args.set or [], "argv": sys.argv[1:]})
    stages = bench_stages(args)
    for i, stage in enumerate(stages, 1):
        bench.progress(f"({i}/{len(stages)}) {stage.name}")
        t0 = time.monotonic()
        try:
            stage.run(ctx)
        except KeyboardInterrupt:
            log.stage(stage.name, time.monotonic() - t0, interrupted=True)
            print(f"interrupted during {stage.name}; finished cells saved, rerun with --resume", file=sys.stderr)
            return 130
        log.stage(stage.name, time.monotonic() - t0)
    log.flush(complete=True)
    bench.progress(f"total wall time {log.data['total_wall_time']:.1f} s -> {Path(args.out) / 'bench.json'}")
    return 0


def cmd_sweep(args) -> int:
    from . import sweep
    return sweep.run_sweep(args)


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
    sub = p.add_subparsers(dest="command", metavar="{grid,figures,bench,sweep}", parser_class=_Parser)
    sub.required = True

    g = sub.add_parser("grid", help="run (or resume) a 25x49 grid of one condition")
    g.add_argument("--condition", choices=["ico", "rl", "ico-rl"], default=None,
                   help="learning condition (default ico); rl and ico-rl run the actor-critic")
    g.add_argument("--prior-from", default=None, metavar="ICO_DIR",
                   help="ICO results directory the rl / ico-rl prior is computed from")
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
    _add_prior_args(g)
    g.set_defaults(func=cmd_grid)

    f = sub.add_parser("figures", help="draw Fig. 1b, 1c-f, 1g from a results directory")
    f.add_argument("--results", required=True)
    f.add_argument("--out", required=True, help="figure directory")
    f.add_argument("--duration", type=float, default=30.0, help="Fig. 1g trajectory length (s)")
    f.set_defaults(func=cmd_figures)

    b = sub.add_parser("bench", help="benchmark stages: grids, figures, summary")
    b.add_argument("--profile", choices=PROFILE_NAMES, default="default",
                   help="default: ICO at paper caps + RL conditions capped (< 30 min on 2 cores); "
                        "paper: 5 seeds, all at 1e5/1e5; quick: smoke test")
    b.add_argument("--out", required=True)
    b.add_argument("--figures", default=None, help="figure directory")
    b.add_argument("--seed", type=_nonneg_int, default=0, help="first seed (seeds are seed .. seed+N-1)")
    b.add_argument("--seeds", type=_positive_int, default=None, help="number of seeds (overrides the profile)")
    b.add_argument("--rl-max-trials", type=_positive_int, default=None,
                   help="trial cap of the RL and ICO->RL grids (overrides the profile)")
    b.add_argument("--threads", type=_nonneg_int, default=0)
    b.add_argument("--set", action="append", metavar="NAME=VALUE")
    b.add_argument("--resume", action="store_true", help="continue earlier results instead of starting over")
    b.add_argument("--quiet", action="store_true")
    _add_prior_args(b)
    b.set_defaults(func=cmd_bench)

    w = sub.add_parser("sweep", help="factorial sweep of RL parameters on a cell subset")
    w.add_argument("--prior-from", required=True, metavar="ICO_DIR", help="ICO results directory")
    w.add_argument("--out", required=True, help="sweep directory (sweep.csv, sweep.md)")
    w.add_argument("--param", action="append", default=[], metavar="NAME=V1,V2,...",
                   help="values of one parameter (repeatable); prior_frame=central,all and prior_ridge allowed")
    w.add_argument("--condition", choices=["ico-rl", "rl"], default="ico-rl")
    sel = w.add_mutually_exclusive_group()
    sel.add_argument("--cells", default=None, help="cell indices, e.g. 0,5,600-610")
    sel.add_argument("--subset", type=_positive_int, default=None, help="N evenly spread cells")
    w.add_argument("--seeds", default="0", help="comma-separated seeds (default 0)")
    w.add_argument("--max-trials", type=_positive_int, default=2000)
    w.add_argument("--success-steps", type=_positive_int, default=None)
    w.add_argument("--set", action="append", metavar="NAME=VALUE", help="fixed override for every setting")
    w.add_argument("--one-at-a-time", action="store_true",
                   help="vary one parameter at a time around the first value of each")
    w.add_argument("--threads", type=_nonneg_int, default=0)
    w.add_argument("--rl-cov", choices=["ico", "identity"], default="ico")
    w.add_argument("--quiet", action="store_true")
    w.set_defaults(func=cmd_sweep)
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
