# SPDX-License-Identifier: Apache-2.0
"""Command line: `python -m icoac grid|figures|bench|sweep|ceiling|params ...`.

This module only parses arguments and reports; the work is done by icoac.studies.conditions (one
condition's grid and prior), icoac.studies.bench (the benchmark stages), icoac.studies.sweep,
icoac.studies.ceiling and icoac.studies.figures. Nothing imports this module. The parser is built without loading the shared
library (names and limits come from icoac.core.options, the conditions from icoac.core.registry), so `--help`
works without it.

Options have one meaning in every command: ``--seed S`` is the first (for `grid` the only) seed
and ``--seeds N`` the number of seeds, S .. S+N-1; ``--set NAME=VALUE`` takes canonical names
(``policy.gain``) or their flat aliases (``gain``); ``--out`` is the directory written.
"""
from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path

from icoac.core import literals
from icoac.core import options as O
from icoac.core import registry as R
from icoac.core.errors import HarnessError, UsageError

PROG = "icoac"


class _Parser(argparse.ArgumentParser):
    def error(self, message):  # one line, status 2, no usage dump
        raise UsageError(message)


# -- argument types ------------------------------------------------------------------------------------
def _integer(text: str) -> int:
    """An integer written as ASCII digits or as an integral real ('6000', '1e5'); never inf/nan."""
    try:
        return literals.integer(text)
    except literals.NumberError as exc:
        raise argparse.ArgumentTypeError(f"expected an integer, got {text!r:.40}, which {exc}") from None


def _real(text: str) -> float:
    """A real number (icoac.core.literals: ASCII digits, no value that rounds to 0 or a subnormal)."""
    try:
        return literals.real(text)
    except literals.NumberError as exc:
        raise argparse.ArgumentTypeError(f"value {text!r:.40} {exc}") from None


_real.__name__ = "number"


def _int_in(lo: int, hi: int, what: str):
    def parse(text: str) -> int:
        value = _integer(text)
        if not lo <= value <= hi:
            raise argparse.ArgumentTypeError(f"expected {what}, got {text!r:.40}")
        return value
    parse.__name__ = "integer"
    return parse


_positive_int = _int_in(1, O.INT64_MAX, "an integer in [1, 2^63 - 1]")
_seed = _int_in(0, O.SEED_LIMIT - 1, "a seed in [0, 2^64 - 1]")
_threads = _int_in(0, O.MAX_THREADS, f"a thread count in [0, {O.MAX_THREADS}] (0: all cores)")
_subset = _int_in(1, O.INT64_MAX, "a number of cells >= 1")  # at most the grid's cells: checked by sweep
_count = _int_in(1, O.MAX_SEEDS, f"a number of seeds in [1, {O.MAX_SEEDS}]")


def _seed_count(text: str) -> int:
    """--seeds N: a number of seeds (a list such as '0,1' gets a hint to the one meaning)."""
    if "," in text:
        parts = [p.strip() for p in text.split(",")]
        hint = ""
        if all(literals.is_integer_text(p) for p in parts) and [int(p) for p in parts] == list(
                range(int(parts[0]), int(parts[0]) + len(parts))):
            hint = f"; for the seeds {text.strip()} write --seed {int(parts[0])} --seeds {len(parts)}"
        raise argparse.ArgumentTypeError(f"--seeds is a number of seeds (seeds --seed .. --seed + N - 1), "
                                         f"not a list, got {text!r:.40}{hint}")
    return _count(text)


_seed_count.__name__ = "integer"


def _positive_float(hi: float, what: str):
    def parse(text: str) -> float:
        value = _real(text)
        if not (math.isfinite(value) and 0 < value <= hi):
            raise argparse.ArgumentTypeError(f"expected {what}, got {text!r:.40}")
        return value
    parse.__name__ = "number"
    return parse


def _plant(text: str) -> str:
    """--plant NAME: a plant of the C registry."""
    from icoac.core import binding as B
    try:
        B.plant_index(text)
    except B.ConfigError as exc:
        raise argparse.ArgumentTypeError(str(exc)) from None
    return text


_plant.__name__ = "plant"


_checkpoint_seconds = _positive_float(86400.0, "seconds in (0, 86400]")
_duration = _positive_float(1e300, "a finite duration > 0 (s)")

PLANT_HELP = ("registry plant (docs/plants.md; default cart_pole): its grid, dynamics and task settings "
              "(its C file, sim_host/src/plants/); its parameters by name through --set")
LIMITED_HELP = ("hold the plant to a real actuator's limit, as its C file gives it (the cart-pole's +-10 N, the "
                "double pendulum's 25 N): --set LIMIT=VALUE before any other --set; none where the default is "
                "that limit (the Furuta's +-10 V)")
SET_HELP = ("override a parameter (repeatable): NAME is group.field (policy.gain, ico.timing, critic.range, "
            "actor.noise_std, ...), a plant or run parameter (dt, integrator, max_trials, ...) or a flat "
            "alias (gain, ico_timing, noise_std, ...); reals must be finite and normal, integers must fit "
            "their C type, ranges are checked by the C library; `params` lists every controller and run "
            "parameter with its unit, default and range")


def _add_prior_args(parser, prior_std: bool = True) -> None:
    parser.add_argument("--prior-frame", choices=O.FRAME_NAMES, default=O.FRAME_NAMES[0],
                        help="ICO cells for the prior: central frame (default) or all successful cells")
    parser.add_argument("--prior-x", type=_real, default=None,
                        help=f"frame half-width |x0| (m), default {O.PRIOR_FRAME[0]:g}")
    parser.add_argument("--prior-theta", type=_real, default=None,
                        help=f"frame half-height |theta0| (deg), default {O.PRIOR_FRAME[1]:g}")
    parser.add_argument("--prior-ridge", type=_real, default=O.PRIOR_RIDGE,
                        help=f"ridge added to the prior covariance (default {O.PRIOR_RIDGE:g})")
    if prior_std:
        _add_prior_std(parser)


def _add_prior_std(parser) -> None:
    parser.add_argument("--prior-std", type=_real, default=O.PRIOR_STD,
                        help=f"sigma_w of the isotropic prior covariance sigma_w^2 I of the conditions rl and "
                             f"ico-mean-rl (default {O.PRIOR_STD:g})")


THREADS_HELP = (f"C threads of the local engine, in [0, {O.MAX_THREADS}] (0, the default: all cores); "
                "not with --scheduler or --workers")


def _add_backend(parser) -> None:
    """--scheduler / --workers (the Dask backend, icoac.cluster.backend), --threads-per-worker, --chunk-cells."""
    d = parser.add_argument_group(
        "Dask backend", "run the grids on a dask.distributed cluster instead of local C threads (same cells, "
                        "checkpoints and resume; docs/cluster.md)")
    where = d.add_mutually_exclusive_group()
    where.add_argument("--scheduler", default=None, metavar="ADDRESS",
                       help="address of a running Dask scheduler, e.g. tcp://host:8786")
    where.add_argument("--workers", type=_int_in(1, O.MAX_WORKERS, f"a number of workers in [1, {O.MAX_WORKERS}]"),
                       default=None, metavar="N", help="start a local Dask cluster of N worker processes")
    d.add_argument("--threads-per-worker", type=_int_in(1, O.MAX_THREADS, f"an integer in [1, {O.MAX_THREADS}]"),
                   default=None, metavar="N", help="threads of each --workers process (default 1)")
    d.add_argument("--chunk-cells", type=_int_in(1, O.MAX_CHUNK_CELLS, f"an integer in [1, {O.MAX_CHUNK_CELLS}]"),
                   default=None, metavar="N",
                   help=f"cells per Dask task (default: about {O.AUTO_CHUNKS_PER_THREAD} tasks per worker thread, "
                        f"at most {O.AUTO_CHUNK_MAX} cells each)")


def _add_seeds(parser, default_count: str) -> None:
    parser.add_argument("--seed", type=_seed, default=0, help="first seed, in [0, 2^64 - 1] (default 0)")
    parser.add_argument("--seeds", type=_seed_count, default=None, metavar="N",
                        help=f"number of seeds: --seed .. --seed + N - 1, below 2^64 ({default_count})")


class _VersionAction(argparse.Action):
    """--version: the harness version (no library needed), then the C library's, if it loads."""

    def __init__(self, option_strings, dest=argparse.SUPPRESS, default=argparse.SUPPRESS, help=None):
        super().__init__(option_strings, dest=dest, default=default, nargs=0, help=help)

    def __call__(self, parser, namespace, values, option_string=None):
        from icoac import __version__
        lines = [f"{PROG} {__version__}"]
        try:
            from icoac.core import binding as B
            lines.append(f"icoac library {B.library_version()} (ABI {int(B.lib.icoac_abi_version())}): {B.LIBRARY_PATH}")
        except HarnessError as exc:
            lines.append(f"icoac library not loaded: {_one_line(str(exc))}")
        print("\n".join(lines))
        parser.exit(0)


def build_parser() -> argparse.ArgumentParser:
    p = _Parser(prog=PROG, description="icoac grid benchmarks, results and figures")
    p.add_argument("--version", action=_VersionAction,
                   help="print the harness version and, if the C library loads, its version and ABI, then exit")
    sub = p.add_subparsers(dest="command", metavar="{grid,figures,bench,sweep,ceiling,params}", parser_class=_Parser)
    sub.required = True
    cells_, every = O.DEFAULT_CHECKPOINT_CELLS, O.DEFAULT_CHECKPOINT_EVERY

    g = sub.add_parser(
        "grid", help="run (or resume) the plant's grid (or some of its cells) for one condition",
        epilog=f"Checkpoints: cells.npz and run.json are rewritten atomically and fsynced (about 25 ms for "
               f"the full grid on a local disk, at most once per 0.2 s poll) whenever --checkpoint-cells N "
               f"cells (default {cells_}) finished since the last checkpoint, or --checkpoint-every SECONDS "
               f"(default {every:g}) passed with at least one newly finished cell. A SIGKILL "
               f"therefore loses at most max({cells_} cells, {every:g} s) of finished "
               f"work; in fact both limits hold at once, up to one 0.2 s poll: fewer than "
               f"{cells_} cells plus those of the last poll, none finished more than "
               f"{every:g} s + 0.2 s before the kill. Cells in progress (at most one per thread) "
               "are lost too and rerun by --resume, which finishes the grid with bitwise the same cells. "
               "Ctrl-C (SIGINT) saves every finished cell and exits with status 130.")
    g.add_argument("--condition", choices=R.CONDITIONS, default=None,
                   help="learning condition (default ico); rl and ico-rl run the actor-critic")
    g.add_argument("--prior-from", default=None, metavar="ICO_DIR",
                   help="ICO results directory the rl / ico-rl prior is computed from")
    g.add_argument("--out", required=True, help="results directory (cells.npz, run.json); created if missing")
    g.add_argument("--seed", type=_seed, default=None, help="the grid's seed, in [0, 2^64 - 1] (default 0)")
    g.add_argument("--threads", type=_threads, default=None, help=THREADS_HELP)
    g.add_argument("--max-trials", type=_positive_int, default=None,
                   help="trials before a cell fails, in [1, 2^63 - 1] (default 1e5)")
    g.add_argument("--success-steps", type=_positive_int, default=None,
                   help="steps of a successful trial, in [1, 2^63 - 1] (default 1e5)")
    g.add_argument("--configuration", choices=O.CONFIGURATION_NAMES, default=O.CONFIGURATION_NAMES[0],
                   help="named configuration applied before --set: the defaults, or the paper's literal "
                        "reading of the actor-critic (posterior actor, exploration always on, per-tick updates)")
    g.add_argument("--set", action="append", metavar="NAME=VALUE", help=SET_HELP)
    g.add_argument("--limited", action="store_true", help=LIMITED_HELP)
    g.add_argument("--plant", type=_plant, default=None, help=PLANT_HELP)
    g.add_argument("--cells", default=None, help="subset of the plant grid's cell indices (row-major, from 0), e.g. 0,5,600-610")
    again = g.add_mutually_exclusive_group()
    again.add_argument("--resume", action="store_true",
                       help="continue the PENDING cells of --out with its recorded settings")
    again.add_argument("--overwrite", action="store_true",
                       help="discard the results in --out (both files, or a lone cells.npz or run.json) and "
                            "start over. Without it, a grid on an existing results directory resumes it if "
                            "the settings match and refuses otherwise, and refuses a directory holding only "
                            "one of the two files")
    g.add_argument("--checkpoint-cells", type=_int_in(1, O.INT64_MAX, "an integer >= 1"), default=None,
                   metavar="N", help=f"checkpoint after N newly finished cells (default {cells_})")
    g.add_argument("--checkpoint-every", type=_checkpoint_seconds, default=None, metavar="SECONDS",
                   help=f"... or after SECONDS with at least one newly finished cell (default "
                        f"{every:g}, at most 86400)")
    g.add_argument("--quiet", action="store_true", help="no progress bar")
    _add_prior_args(g)
    _add_backend(g)
    g.set_defaults(func=cmd_grid)

    f = sub.add_parser("figures", help="draw Fig. 1b, 1c-f, 1g from a results directory")
    f.add_argument("--results", required=True, help="results directory (cells.npz, run.json)")
    f.add_argument("--out", required=True, help="figure directory")
    f.add_argument("--duration", type=_duration, default=O.TRAJECTORY_DURATION,
                   help=f"Fig. 1g trajectory length in s (default {O.TRAJECTORY_DURATION:g}); finite, > 0 and at "
                        f"most {f'{O.MAX_TRAJECTORY_STEPS:.0e}'.replace('e+0', 'e')} plant steps (duration / dt, i.e. 10000 s at the "
                        "default dt = 0.01 s)")
    f.add_argument("--plant", type=_plant, default=None,
                   help="the plant --results must hold (default: whichever it records)")
    f.set_defaults(func=cmd_figures)

    b = sub.add_parser("bench", help="benchmark stages: grids, figures, summary")
    b.add_argument("--profile", choices=O.PROFILE_NAMES, default=O.PROFILE_NAMES[0],
                   help="default: ICO at the paper's caps, the learners capped at 1000 trials; "
                        "paper: 5 seeds, all at 1e5/1e5; quick: smoke test")
    b.add_argument("--out", required=True, help="bench directory (one results directory per condition and seed)")
    b.add_argument("--figures", default=None, help="figure directory")
    b.add_argument("--summary-only", action="store_true",
                   help="run nothing: the summary, --data and figures of the grids OUT holds complete")
    b.add_argument("--data", default=None,
                   help="also write the summary that docs/results.md's tables come from (e.g. docs/data/bench-default.json)")
    _add_seeds(b, "default: the profile's")
    b.add_argument("--rl-max-trials", type=_positive_int, default=None,
                   help="trial cap of the RL and ICO->RL grids (overrides the profile)")
    b.add_argument("--threads", type=_threads, default=None, help=THREADS_HELP)
    b.add_argument("--configuration", choices=O.CONFIGURATION_NAMES, default=O.CONFIGURATION_NAMES[0],
                   help="named configuration applied before --set: the defaults, or the paper's literal "
                        "reading of the actor-critic (posterior actor, exploration always on, per-tick updates)")
    b.add_argument("--set", action="append", metavar="NAME=VALUE", help=SET_HELP)
    b.add_argument("--limited", action="store_true", help=LIMITED_HELP)
    b.add_argument("--resume", action="store_true", help="continue earlier results instead of starting over")
    b.add_argument("--quiet", action="store_true", help="no progress bars")
    b.add_argument("--ceiling", default=None, metavar="CEILING",
                   help="ceiling.json of `ceiling` (or its directory) shown in summary.md and Fig. 3a "
                        f"(default OUT/{O.CEILING_DIR}/{O.CEILING_FILE} if it exists)")
    b.add_argument("--plant", type=_plant, default=O.CART_POLE, help=PLANT_HELP)
    _add_prior_args(b)
    _add_backend(b)
    b.set_defaults(func=cmd_bench)

    w = sub.add_parser("sweep", help="factorial sweep of RL parameters on a cell subset")
    w.add_argument("--prior-from", required=True, metavar="ICO_DIR", help="ICO results directory")
    w.add_argument("--out", required=True, help="sweep directory (sweep.csv, sweep.md)")
    w.add_argument("--plant", type=_plant, default=None,
                   help="the plant --prior-from must hold (the sweep runs on that grid's plant)")
    w.add_argument("--param", action="append", default=[], metavar="NAME=V1,V2,...",
                   help="values of one parameter (repeatable; names as for --set); prior_frame=central,all "
                        "and prior_ridge allowed")
    w.add_argument("--condition", choices=R.SWEEP_CONDITIONS, default=R.SWEEP_CONDITIONS[0])
    sel = w.add_mutually_exclusive_group()
    sel.add_argument("--cells", default=None, help="cell indices, e.g. 0,5,600-610")
    sel.add_argument("--subset", type=_subset, default=None, help="N evenly spread cells, at most the grid's cell count")
    _add_seeds(w, "default 1")
    w.add_argument("--max-trials", type=_positive_int, default=None,
                   help=f"trials before a cell fails (default {O.SWEEP_MAX_TRIALS})")
    w.add_argument("--success-steps", type=_positive_int, default=None)
    w.add_argument("--configuration", choices=O.CONFIGURATION_NAMES, default=O.CONFIGURATION_NAMES[0],
                   help="named configuration applied before --set: the defaults, or the paper's literal "
                        "reading of the actor-critic (posterior actor, exploration always on, per-tick updates)")
    w.add_argument("--set", action="append", metavar="NAME=VALUE", help="fixed override for every setting")
    w.add_argument("--one-at-a-time", action="store_true",
                   help="vary one parameter at a time around the first value of each")
    w.add_argument("--threads", type=_threads, default=None, help=THREADS_HELP)
    _add_prior_std(w)
    w.add_argument("--quiet", action="store_true")
    _add_backend(w)
    w.set_defaults(func=cmd_sweep)

    c = sub.add_parser(
        "ceiling", help="the best single w found (method.md, L5): fixed-w evaluation, search for the best w, "
                        "first-step bound",
        epilog="Without --w: a seeded search (typical ICO weights - the mean of --prior-from - and LQR gains "
               "as starting points, random search over magnitudes and signs, local refinement; or CMA-ES from "
               "the best starting point, --optimiser cma-es), screened "
               "with one trial per cell at --screen-steps steps; the best --confirm are run at the full "
               "horizon and the best of them under every --protocol. Writes OUT/search.json (every screen; "
               "rerunning the same command resumes), OUT/evals/*/ (results directories), "
               "OUT/ceiling.json and OUT/ceiling.md. Ctrl-C keeps finished work and exits with status 130.")
    c.add_argument("--out", required=True, help="ceiling directory; created if missing")
    c.add_argument("--prior-from", default=None, metavar="ICO_DIR",
                   help="ICO results directory whose central-frame mean weight starts the search "
                        f"(default the typical ICO weights {','.join(f'{v:g}' for v in O.TYPICAL_ICO_WEIGHTS)})")
    c.add_argument("--w", default=None, metavar="W1,W2,W3,W4",
                   help="evaluate this w = (w_x, w_xdot, w_theta, w_thetadot) only, no search")
    c.add_argument("--protocol", choices=O.CEILING_PROTOCOL_CHOICES, default="both",
                   help="final evaluation: one trial per cell (first), fresh initial velocities up to "
                        "--max-trials (retries), or both (default)")
    c.add_argument("--max-trials", type=_positive_int, default=None,
                   help=f"trial cap of the retries protocol (default: --profile's, else {O.CEILING_MAX_TRIALS})")
    c.add_argument("--success-steps", type=_positive_int, default=None,
                   help="full horizon: steps of a successful trial (default 1e5)")
    c.add_argument("--cells", default=None,
                   help="subset of the plant grid's cell indices (row-major, from 0), e.g. 0,5,600-610, or 'tuning': "
                        "the held-out split's tuning cells (docs/tuning.md)")
    c.add_argument("--optimiser", choices=O.CEILING_OPTIMISERS, default=None,
                   help="the search: pattern (starting points, random search, pattern refinement; the default) or "
                        "cma-es (CMA-ES on w from the best starting point), each screening --candidates w")
    c.add_argument("--candidates", type=_int_in(1, O.CEILING_MAX_CANDIDATES, f"an integer in [1, {O.CEILING_MAX_CANDIDATES}]"),
                   default=None, metavar="N", help=f"distinct w screened by the search (default {O.CEILING_CANDIDATES})")
    c.add_argument("--screen-steps", type=_positive_int, default=None, metavar="N",
                   help=f"horizon of the screening runs (default {O.CEILING_SCREEN_STEPS})")
    c.add_argument("--confirm", type=_int_in(1, O.CEILING_MAX_CANDIDATES, "an integer >= 1"), default=None,
                   metavar="N", help=f"best screened w run at the full horizon (default {O.CEILING_CONFIRM})")
    c.add_argument("--seed", type=_seed, default=0,
                   help="grid seed (initial velocities) and search seed, in [0, 2^64 - 1] (default 0)")
    c.add_argument("--threads", type=_threads, default=0, help=f"C threads in [0, {O.MAX_THREADS}] (0: all cores)")
    c.add_argument("--set", action="append", metavar="NAME=VALUE",
                   help=SET_HELP + "; mode, learn, max_trials and success_steps are set by the command")
    c.add_argument("--profile", choices=O.PROFILE_NAMES, default=None,
                   help="take --max-trials and --success-steps, unless given, from this bench profile's learner "
                        "grids, so that the ceiling's retries get the learners' trial cap")
    c.add_argument("--plant", type=_plant, default=O.CART_POLE, help=PLANT_HELP)
    c.add_argument("--quiet", action="store_true", help="no progress output")
    c.set_defaults(func=cmd_ceiling)
    pa = sub.add_parser("params", help="list the controller and run parameters: unit, default, range, modes, tier "
                                       "and description, from the C parameter table")
    pa.add_argument("--tier", choices=("all", "essential", "advanced"), default="all",
                    help="the parameters of one tier only (default all)")
    pa.add_argument("--plant", type=_plant, default=None, help="also list this registry plant's parameters")
    pa.set_defaults(func=cmd_params)
    return p


# -- commands: arguments in, report out ----------------------------------------------------------------
def _overrides(args) -> dict:
    """--configuration's items, replaced by --set's, with --max-trials and --success-steps (each
    field given once)."""
    from icoac.core.config import command_overrides
    return command_overrides(args.configuration, args.set, {"--max-trials": ("max_trials", args.max_trials),
                                                            "--success-steps": ("success_steps", args.success_steps)},
                             plant=getattr(args, "plant", None) or O.CART_POLE)


def _frame(args):
    from icoac.studies import prior as P
    return P.parse_frame(args.prior_frame, args.prior_x, args.prior_theta)


def _threads_arg(args) -> int:
    return 0 if args.threads is None else args.threads


def cmd_params(args) -> int:
    from icoac.core import params
    sys.stdout.write(params.text_table(None if args.tier == "all" else args.tier, args.plant))
    return 0


def _dask_spec(args):
    """The DaskSpec of --scheduler / --workers (None: the local threaded engine); the options that
    apply to one backend only are refused with the other."""
    dask = args.scheduler is not None or args.workers is not None
    if not dask:
        for flag, value in (("--threads-per-worker", args.threads_per_worker), ("--chunk-cells", args.chunk_cells)):
            if value is not None:
                raise UsageError(f"{flag} applies to the Dask backend (--scheduler ADDRESS or --workers N)")
        return None
    if args.threads is not None:
        raise UsageError("--threads sets the local engine's C threads; with --scheduler or --workers every worker "
                         "thread runs one chunk on one C thread (--threads-per-worker sets them for --workers)")
    if args.scheduler is not None and args.threads_per_worker is not None:
        raise UsageError("--threads-per-worker applies to --workers N; the workers of --scheduler have their own")
    from icoac.cluster.backend import DaskSpec
    return DaskSpec(scheduler=args.scheduler, workers=args.workers,
                    threads_per_worker=args.threads_per_worker or 1, chunk_cells=args.chunk_cells).check()


def cmd_grid(args) -> int:
    from icoac.studies import conditions
    from icoac.core import metrics

    explicit = any(v is not None for v in (args.condition, args.seed, args.max_trials, args.success_steps,
                                            args.cells, args.prior_from, args.plant)) or bool(_overrides(args))
    condition = args.condition or R.CONDITIONS[0]
    info = None
    if explicit or not args.resume:
        info = conditions.condition_prior(condition, args.prior_from, _frame(args), args.prior_ridge, args.prior_std,
                                           plant=args.plant or O.CART_POLE, overrides=_overrides(args))
    spec = _dask_spec(args)
    cells, record, cancelled = conditions.run_condition(
        condition=condition, out=Path(args.out), seed=args.seed or 0, threads=_threads_arg(args),
        overrides=_overrides(args), cell_spec=args.cells, resume=args.resume, fresh=args.overwrite,
        progress=not args.quiet, checkpoint_every=args.checkpoint_every,
        checkpoint_cells=args.checkpoint_cells, explicit=explicit or not args.resume, info=info, dask=spec,
        plant=args.plant or O.CART_POLE)
    print(metrics.format_summary(record["condition"], record["summary"]))
    where = "Dask worker threads" if spec is not None else "threads"
    print(f"wall time {record['wall_time']:.1f} s on {record['threads']} {where} -> {args.out}")
    if cancelled:
        print(f"interrupted: finished cells saved; resume with `python -m icoac grid --out {args.out} --resume`",
              file=sys.stderr)
        return 130
    return 0


def cmd_figures(args) -> int:
    from icoac.studies import figures
    from icoac.core import results, store

    cells, record = results.load(args.results, what="--results")
    _check_plant(args.plant, record, "--results")
    figures.check_duration(record, args.duration)  # before anything is drawn
    store.check_writable(args.out)
    for path in figures.make_figures(cells, record, args.out, duration=args.duration):
        print(path)
    return 0


def cmd_bench(args) -> int:
    from icoac.studies import bench

    opt = bench.BenchOptions(
        profile=args.profile, out=Path(args.out), figures=Path(args.figures) if args.figures else None,
        data=Path(args.data) if args.data else None, summary_only=args.summary_only,
        seed=args.seed, seeds=args.seeds, rl_max_trials=args.rl_max_trials, threads=_threads_arg(args),
        configuration=args.configuration, sets=args.set or [], resume=args.resume, quiet=args.quiet,
        frame=_frame(args), ridge=args.prior_ridge, prior_std=args.prior_std,
        ceiling=Path(args.ceiling) if args.ceiling else None, dask=_dask_spec(args), plant=args.plant)
    return bench.run_bench(opt, argv=sys.argv[1:])


def _check_plant(plant: str | None, record: dict, what: str) -> None:
    """--plant, when given, must be the plant a results directory records."""
    from icoac.core import results
    if plant is not None and plant != results.record_plant(record):
        raise UsageError(f"--plant {plant}, but {what} holds a grid of the {results.record_plant(record)}")


def cmd_sweep(args) -> int:
    from icoac.core import results
    from icoac.studies import sweep

    if args.plant is not None:
        _check_plant(args.plant, results.load(args.prior_from, what="--prior-from")[1], "--prior-from")

    opt = sweep.SweepOptions(
        prior_from=Path(args.prior_from), out=Path(args.out), params=args.param, condition=args.condition,
        cells=args.cells, subset=args.subset, seed=args.seed, seeds=1 if args.seeds is None else args.seeds,
        max_trials=args.max_trials, success_steps=args.success_steps, configuration=args.configuration,
        sets=args.set or [], one_at_a_time=args.one_at_a_time, threads=_threads_arg(args), prior_std=args.prior_std,
        quiet=args.quiet, dask=_dask_spec(args))
    return sweep.run_sweep(opt)


def cmd_ceiling(args) -> int:
    from icoac.studies.ceiling import command as ceiling

    max_trials, success_steps = args.max_trials, args.success_steps
    if args.profile is not None:
        from icoac.studies.bench import learner_caps

        cap, horizon = learner_caps(args.profile, args.plant)
        max_trials = cap if max_trials is None else max_trials
        success_steps = horizon if success_steps is None else success_steps
    opt = ceiling.CeilingOptions(
        out=Path(args.out), prior_from=Path(args.prior_from) if args.prior_from else None, w=args.w,
        protocol=args.protocol, max_trials=O.CEILING_MAX_TRIALS if max_trials is None else max_trials,
        success_steps=success_steps, cells=args.cells,
        candidates=args.candidates, screen_steps=args.screen_steps, confirm=args.confirm, seed=args.seed,
        optimiser=args.optimiser, threads=args.threads, sets=args.set or [], quiet=args.quiet, plant=args.plant)
    return ceiling.run_ceiling(opt, argv=sys.argv[1:])


def main(argv=None) -> int:
    """Entry point. Every fault - a bad argument, a missing or mismatched library, a malformed
    results directory, a C rejection, an unwritable output - is one line
    ``icoac: error: ...`` on stderr and exit status 2; Ctrl-C is status 130."""
    try:
        args = build_parser().parse_args(argv)
        try:
            if getattr(args, "limited", False):
                from icoac.core.plants import PLANTS
                args.set = PLANTS[args.plant or O.CART_POLE].limited(args.set)
            return args.func(args)
        except OSError as exc:  # the file system refused a read or write
            name = f": {exc.filename!r}" if getattr(exc, "filename", None) else ""
            raise UsageError(f"{exc.strerror or exc}{name}")
    except HarnessError as exc:  # UsageError, LibraryError, ResultsError, PriorError, C statuses
        print(f"{PROG}: error: {_one_line(str(exc))}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print(f"{PROG}: interrupted", file=sys.stderr)
        return 130


def _one_line(text: str) -> str:
    return " ".join(text.split())
