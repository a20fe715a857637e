"""Command line: `python -m harness grid|figures|bench|sweep ...`."""
from __future__ import annotations

import argparse
import math
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
                  checkpoint_every: float | None = None, checkpoint_cells: int | None = None, prior=None,
                  explicit: bool = True, cancel_after: float | None = None, extra: dict | None = None,
                  start_over: str = "rerun with --overwrite") -> tuple:
    """Run (or resume) one condition into a results directory; returns (cells, record, cancelled).

    Everything is validated before the first byte is written: the arguments, the configuration
    (C checks), the output directory (a real write probe) and, when results exist, both files,
    the recorded configuration and that the cells are exactly the recorded selection. A resume
    writes nothing until new cells have finished; ``fresh`` discards existing results (after the
    checks). A directory holding only one of the two files is refused unless ``fresh``.
    """
    from . import grid, results
    from ._binding import ConfigError
    from .config import build_config

    out = Path(out)
    seed = grid.check_seed(seed)
    threads = grid.check_threads(threads)
    if resume and fresh:
        raise UsageError("--resume and --overwrite exclude each other")
    if out.exists() and not out.is_dir():
        raise UsageError(f"--out {str(out)!r} exists and is not a directory")
    have = results.present(out) if out.is_dir() else []
    if resume and not have:
        raise UsageError(f"--resume: no results to resume in {str(out)!r}")
    if len(have) == 1 and not fresh:
        missing = results.RUN_FILE if have[0] == results.CELLS_FILE else results.CELLS_FILE
        raise UsageError(f"{str(out)!r} holds {have[0]} but no {missing}: refusing to "
                         f"{'resume' if resume else 'replace'} it; restore {missing}, or {start_over} "
                         "to discard it and start over")
    try:
        indices = grid.parse_cell_indices(cell_spec)
    except ConfigError as exc:
        raise UsageError(f"--cells: {exc}") from None
    existing = len(have) == 2 and not fresh
    if existing:
        try:
            cells, record = results.load(out)
        except results.ResultsError as exc:
            raise UsageError(f"{exc} ({start_over} to discard these results and start over)") from None
        if resume and not explicit:
            cfg = results.load_config(record)
            condition, seed, indices = record["condition"], record["seed"], record["cells"]
            if extra is None and record.get("prior_info") is not None:
                extra = {"prior_info": record["prior_info"]}
        else:
            cfg = build_config(overrides, condition=condition, prior=prior)
        results.check_resumable(record, condition=condition, seed=seed, cfg=cfg, cell_indices=indices)
        try:
            results.check_cells_match(cells, record, repr(str(out / results.CELLS_FILE)))
        except results.ResultsError as exc:
            raise UsageError(f"{exc} ({start_over} to discard these results and start over)") from None
        wall_before = float(record.get("wall_time", 0.0))
        n_pending = int((cells["outcome"] == 0).sum())
        if progress:
            print(f"resuming {out}: {n_pending} of {cells.size} cells pending", file=sys.stderr)
    else:
        cfg = build_config(overrides, condition=condition, prior=prior)
        cells = grid.make_cells(seed, indices)
        wall_before = 0.0
    n_threads = threads if threads > 0 else grid.default_threads()
    results.check_writable(out)
    git = results.git_info()

    def save(snapshot, wall):
        return results.save(out, snapshot, cfg, condition=condition, seed=seed, wall_time=wall,
                            threads=n_threads, cell_indices=indices, extra=extra, git=git)

    t0 = time.monotonic()
    if not existing:
        if fresh:  # run.json first: an interruption leaves a partial directory, refused later
            for name in (results.RUN_FILE, results.CELLS_FILE):
                if (out / name).is_file():
                    (out / name).unlink()
        save(cells, 0.0)  # every cell PENDING: resumable from the first second
    run = grid.run_grid(cfg, cells, threads=threads, progress=progress,
                        checkpoint=lambda snap: save(snap, wall_before + time.monotonic() - t0),
                        checkpoint_every=grid.DEFAULT_CHECKPOINT_EVERY if checkpoint_every is None
                        else checkpoint_every,
                        checkpoint_cells=grid.DEFAULT_CHECKPOINT_CELLS if checkpoint_cells is None
                        else checkpoint_cells,
                        cancel_after=cancel_after, desc=condition)
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
        overrides=_overrides(args), cell_spec=args.cells, resume=args.resume, fresh=args.overwrite,
        progress=not args.quiet, checkpoint_every=args.checkpoint_every,
        checkpoint_cells=args.checkpoint_cells, explicit=explicit or not args.resume,
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
    figures.check_duration(record, args.duration)  # before anything is drawn
    results.check_writable(args.out)
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
    if seeds[-1] >= SEED_LIMIT:
        raise UsageError(f"--seed {args.seed} with {n_seeds} seeds goes past 2^64 - 1")
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
                start_over="rerun bench without --resume",
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

    from .config import build_config
    for condition in bench.CONDITIONS:  # every override valid before the first grid runs
        build_config(overrides(condition), condition=condition)

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
    stages = bench_stages(args)  # validates the arguments before anything is written
    from . import results
    results.check_writable(args.out)
    log = bench.BenchLog(Path(args.out), {
        "profile": args.profile, "seeds": [args.seed + i for i in range(n_seeds)],
        "rl_max_trials": args.rl_max_trials, "resume": bool(args.resume), "threads": args.threads,
        "set": args.set or [], "argv": sys.argv[1:]})
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


INT64_MAX = 2 ** 63 - 1
SEED_LIMIT = 2 ** 64
MAX_THREADS = 1024      # grid.MAX_THREADS (not imported: the parser must work without the library)
MAX_DURATION_STEPS = "1e6"   # grid.MAX_TRAJECTORY_STEPS
CHECKPOINT_CELLS = 25        # grid.DEFAULT_CHECKPOINT_CELLS
CHECKPOINT_EVERY = 2.0       # grid.DEFAULT_CHECKPOINT_EVERY (s)


def _integer(text: str) -> int:
    """An integer written as digits or as an integral float ('6000', '1e5'); never inf/nan."""
    t = text.strip()
    try:
        return int(t, 10)
    except ValueError:
        pass
    try:
        value = float(t)
    except ValueError:
        raise argparse.ArgumentTypeError(f"invalid integer {text!r:.40}") from None
    if not math.isfinite(value) or not value.is_integer():
        raise argparse.ArgumentTypeError(f"expected an integer, got {text!r:.40}")
    return int(value)


def _int_in(lo: int, hi: int, what: str):
    def parse(text: str) -> int:
        value = _integer(text)
        if not lo <= value <= hi:
            raise argparse.ArgumentTypeError(f"expected {what}, got {text!r:.40}")
        return value
    parse.__name__ = "integer"
    return parse


_positive_int = _int_in(1, INT64_MAX, "an integer in [1, 2^63 - 1]")
_nonneg_int = _int_in(0, INT64_MAX, "an integer in [0, 2^63 - 1]")
_seed = _int_in(0, SEED_LIMIT - 1, "a seed in [0, 2^64 - 1]")
_threads = _int_in(0, MAX_THREADS, f"a thread count in [0, {MAX_THREADS}] (0: all cores)")
_subset = _int_in(1, 1225, "a number of cells in [1, 1225]")


def _positive_float(hi: float, what: str):
    def parse(text: str) -> float:
        try:
            value = float(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"invalid number {text!r:.40}") from None
        if not (math.isfinite(value) and 0 < value <= hi):
            raise argparse.ArgumentTypeError(f"expected {what}, got {text!r:.40}")
        return value
    parse.__name__ = "number"
    return parse


_checkpoint_seconds = _positive_float(86400.0, "seconds in (0, 86400]")
_duration = _positive_float(1e300, "a finite duration > 0 (s)")


def build_parser() -> argparse.ArgumentParser:
    p = _Parser(prog=PROG, description="icoac grid benchmarks, results and figures")
    sub = p.add_subparsers(dest="command", metavar="{grid,figures,bench,sweep}", parser_class=_Parser)
    sub.required = True

    g = sub.add_parser(
        "grid", help="run (or resume) a 25x49 grid of one condition",
        epilog=f"Checkpoints: cells.npz and run.json are rewritten atomically (about 1 ms for the full "
               f"grid, at most once per 0.2 s poll) whenever --checkpoint-cells N cells (default "
               f"{CHECKPOINT_CELLS}) finished since the last checkpoint, or --checkpoint-every SECONDS "
               f"(default {CHECKPOINT_EVERY:g}) passed with at least one newly finished cell. A SIGKILL "
               f"therefore loses at most max({CHECKPOINT_CELLS} cells, {CHECKPOINT_EVERY:g} s) of finished "
               f"work; in fact both limits hold at once, up to one 0.2 s poll: fewer than "
               f"{CHECKPOINT_CELLS} cells plus those of the last poll, none finished more than "
               f"{CHECKPOINT_EVERY:g} s + 0.2 s before the kill. Cells in progress (at most one per thread) "
               "are lost too and rerun by --resume, which finishes the grid with bitwise the same cells. "
               "Ctrl-C (SIGINT) saves every finished cell and exits with status 130.")
    g.add_argument("--condition", choices=["ico", "rl", "ico-rl"], default=None,
                   help="learning condition (default ico); rl and ico-rl run the actor-critic")
    g.add_argument("--prior-from", default=None, metavar="ICO_DIR",
                   help="ICO results directory the rl / ico-rl prior is computed from")
    g.add_argument("--out", required=True, help="results directory (cells.npz, run.json); created if missing")
    g.add_argument("--seed", type=_seed, default=None, help="grid seed in [0, 2^64 - 1] (default 0)")
    g.add_argument("--threads", type=_threads, default=0, help=f"C threads in [0, {MAX_THREADS}] (0: all cores)")
    g.add_argument("--max-trials", type=_positive_int, default=None,
                   help="trials before a cell fails, in [1, 2^63 - 1] (default 1e5)")
    g.add_argument("--success-steps", type=_positive_int, default=None,
                   help="steps of a successful trial, in [1, 2^63 - 1] (default 1e5)")
    g.add_argument("--set", action="append", metavar="NAME=VALUE",
                   help="override a parameter (repeatable); reals must be finite and normal, integers must "
                        "fit their C type, ranges are checked by the C library")
    g.add_argument("--cells", default=None, help="subset of cell indices in [0, 1225), e.g. 0,5,600-610")
    again = g.add_mutually_exclusive_group()
    again.add_argument("--resume", action="store_true",
                       help="continue the PENDING cells of --out with its recorded settings")
    again.add_argument("--overwrite", action="store_true",
                       help="discard the results in --out (both files, or a lone cells.npz or run.json) and "
                            "start over. Without it, a grid on an existing results directory resumes it if "
                            "the settings match and refuses otherwise, and refuses a directory holding only "
                            "one of the two files")
    g.add_argument("--checkpoint-cells", type=_int_in(1, INT64_MAX, "an integer >= 1"), default=None,
                   metavar="N", help=f"checkpoint after N newly finished cells (default {CHECKPOINT_CELLS})")
    g.add_argument("--checkpoint-every", type=_checkpoint_seconds, default=None, metavar="SECONDS",
                   help=f"... or after SECONDS with at least one newly finished cell (default "
                        f"{CHECKPOINT_EVERY:g}, at most 86400)")
    g.add_argument("--quiet", action="store_true", help="no progress bar")
    _add_prior_args(g)
    g.set_defaults(func=cmd_grid)

    f = sub.add_parser("figures", help="draw Fig. 1b, 1c-f, 1g from a results directory")
    f.add_argument("--results", required=True)
    f.add_argument("--out", required=True, help="figure directory")
    f.add_argument("--duration", type=_duration, default=30.0,
                   help=f"Fig. 1g trajectory length in s (default 30); finite, > 0 and at most "
                        f"{MAX_DURATION_STEPS} plant steps (duration / dt, i.e. 10000 s at the default "
                        "dt = 0.01 s)")
    f.set_defaults(func=cmd_figures)

    b = sub.add_parser("bench", help="benchmark stages: grids, figures, summary")
    b.add_argument("--profile", choices=PROFILE_NAMES, default="default",
                   help="default: ICO at paper caps + RL conditions capped (< 30 min on 2 cores); "
                        "paper: 5 seeds, all at 1e5/1e5; quick: smoke test")
    b.add_argument("--out", required=True)
    b.add_argument("--figures", default=None, help="figure directory")
    b.add_argument("--seed", type=_seed, default=0, help="first seed (seeds are seed .. seed+N-1 < 2^64)")
    b.add_argument("--seeds", type=_int_in(1, 1000, "a number of seeds in [1, 1000]"), default=None,
                   help="number of seeds (overrides the profile)")
    b.add_argument("--rl-max-trials", type=_positive_int, default=None,
                   help="trial cap of the RL and ICO->RL grids (overrides the profile)")
    b.add_argument("--threads", type=_threads, default=0, help=f"C threads in [0, {MAX_THREADS}] (0: all cores)")
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
    sel.add_argument("--subset", type=_subset, default=None, help="N evenly spread cells, 1 <= N <= 1225")
    w.add_argument("--seeds", default="0", help="comma-separated seeds (default 0)")
    w.add_argument("--max-trials", type=_positive_int, default=2000)
    w.add_argument("--success-steps", type=_positive_int, default=None)
    w.add_argument("--set", action="append", metavar="NAME=VALUE", help="fixed override for every setting")
    w.add_argument("--one-at-a-time", action="store_true",
                   help="vary one parameter at a time around the first value of each")
    w.add_argument("--threads", type=_threads, default=0, help=f"C threads in [0, {MAX_THREADS}] (0: all cores)")
    w.add_argument("--rl-cov", choices=["ico", "identity"], default="ico")
    w.add_argument("--quiet", action="store_true")
    w.set_defaults(func=cmd_sweep)
    return p


def main(argv=None) -> int:
    """Entry point. Every fault - a bad argument, a malformed results directory, a C rejection, an
    unwritable output - is one line ``icoac-harness: error: ...`` on stderr and exit status 2;
    Ctrl-C is status 130."""
    try:
        args = build_parser().parse_args(argv)
        try:
            from ._binding import IcoacError, LibraryError
        except Exception as exc:  # missing or mismatched shared library: one line, status 2
            if type(exc).__name__ == "LibraryError":
                raise UsageError(str(exc))
            raise
        try:
            return args.func(args)
        except (IcoacError, LibraryError) as exc:  # ConfigError, ResultsError, C statuses
            raise UsageError(str(exc))
        except OSError as exc:  # the file system refused a read or write
            name = f": {exc.filename!r}" if getattr(exc, "filename", None) else ""
            raise UsageError(f"{exc.strerror or exc}{name}")
    except UsageError as exc:
        print(f"{PROG}: error: {_one_line(str(exc))}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print(f"{PROG}: interrupted", file=sys.stderr)
        return 130


def _one_line(text: str) -> str:
    return " ".join(text.split())
