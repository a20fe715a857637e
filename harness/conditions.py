"""Orchestration of one learning condition: its prior (condition_prior) and a validated,
checkpointed, resumable grid run into a results directory (run_condition). The command line
(harness.cli), the benchmark stages (harness.bench) and the sweep call these; none of them
reimplements a step."""
from __future__ import annotations

import functools
import sys
import time
from pathlib import Path
from typing import Any

import numpy as np

from . import _binding as B
from . import grid, results
from . import prior as P
from .config import RunConfig, build_config
from .errors import ResultsError, UsageError
from .options import CONDITIONS, CONTROL_OF, DEFAULT_CHECKPOINT_CELLS, DEFAULT_CHECKPOINT_EVERY


def check_condition(condition: Any) -> str:
    if condition not in CONDITIONS:
        raise UsageError(f"unknown condition {condition!r:.40}; valid: {', '.join(CONDITIONS)}")
    return condition


def condition_prior(condition: str, prior_from, frame, ridge: float, rl_cov: str = "ico") -> P.PriorInfo | None:
    """PriorInfo of a condition (None for ico): ico-rl and ico-search from an ICO results dir, rl
    with mean 0 (A16), search N(0, I) (L4); a no-learning control has the prior of its condition."""
    condition = CONTROL_OF.get(check_condition(condition), condition)
    if condition == "ico":
        if prior_from is not None:
            raise UsageError("--prior-from applies to the conditions rl and ico-rl")
        return None
    base = P.from_results(prior_from, frame, ridge) if prior_from is not None else None
    if condition in ("ico-rl", "ico-search"):
        if base is None:
            raise UsageError(f"condition {condition} needs --prior-from ICO_RESULTS_DIR")
        return base
    if condition == "search":
        return P.rl_prior(base, "identity")
    return P.rl_prior(base, rl_cov)


def prior_extra(info: P.PriorInfo | None) -> dict | None:
    """What run.json records of a prior (None: nothing)."""
    return {"prior_info": info.to_dict()} if info is not None else None


def run_condition(*, condition: str, out: Path, seed: int, threads: int, overrides: dict,
                  cell_spec=None, resume: bool = False, fresh: bool = False, progress: bool = True,
                  checkpoint_every: float | None = None, checkpoint_cells: int | None = None,
                  info: P.PriorInfo | None = None, explicit: bool = True, cancel_after: float | None = None,
                  start_over: str = "rerun with --overwrite", dask=None) -> tuple[np.ndarray, dict, bool]:
    """Run (or resume) one condition into a results directory; returns (cells, record, cancelled).

    ``dask`` (a harness.cluster.DaskSession, or a DaskSpec for a session opened after every check
    and closed after this grid) runs the grid on a Dask cluster instead of ``threads`` local C
    threads, with the same cells, checkpoints and resume; run.json then records the backend
    (``backend``) and the cluster's thread count.

    Everything is validated before the first byte is written: the arguments, the configuration
    (C checks), the output directory (a real write probe) and, when results exist, both files,
    the recorded configuration and that the cells are exactly the recorded selection. A resume
    writes nothing until new cells have finished; ``fresh`` discards existing results (after the
    checks). A directory holding only one of the two files is refused unless ``fresh``. With
    ``resume`` and not ``explicit`` the recorded condition, seed, cells, configuration and prior
    are used.
    """
    out = results.check_out_dir(out)
    seed = grid.check_seed(seed)
    threads = grid.check_threads(threads)
    check_condition(condition)
    if resume and fresh:
        raise UsageError("--resume and --overwrite exclude each other")
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
    except B.ConfigError as exc:
        raise UsageError(f"--cells: {exc}") from None
    extra = prior_extra(info)
    prior = info.prior() if info is not None else None
    existing = len(have) == 2 and not fresh
    if existing:
        try:
            cells, record = results.load(out)
        except ResultsError as exc:
            raise UsageError(f"{exc} ({start_over} to discard these results and start over)") from None
        if resume and not explicit:
            cfg = results.load_config(record)
            condition, seed, indices = record["condition"], record["seed"], record["cells"]
            if record.get("prior_info") is not None:
                extra = {"prior_info": record["prior_info"]}
        else:
            cfg = build_config(overrides, condition=condition, prior=prior)
        results.check_resumable(record, condition=condition, seed=seed, cfg=cfg, cell_indices=indices)
        try:
            results.check_cells_match(cells, record, repr(str(out / results.CELLS_FILE)))
        except ResultsError as exc:
            raise UsageError(f"{exc} ({start_over} to discard these results and start over)") from None
        wall_before = float(record.get("wall_time", 0.0))
        n_pending = int((cells["outcome"] == B.PENDING).sum())
        if progress:
            print(f"resuming {out}: {n_pending} of {cells.size} cells pending", file=sys.stderr)
    else:
        cfg = build_config(overrides, condition=condition, prior=prior)
        cells = grid.make_cells(seed, indices)
        wall_before = 0.0
    return _run(cfg, cells, out=out, condition=condition, seed=seed, threads=threads, indices=indices,
                extra=extra, existing=existing, fresh=fresh, wall_before=wall_before, progress=progress,
                checkpoint_every=checkpoint_every, checkpoint_cells=checkpoint_cells, cancel_after=cancel_after,
                dask=dask)


def _run(cfg: RunConfig, cells: np.ndarray, *, out: Path, condition: str, seed: int, threads: int,
         indices, extra, existing: bool, fresh: bool, wall_before: float, progress: bool,
         checkpoint_every, checkpoint_cells, cancel_after, dask=None) -> tuple[np.ndarray, dict, bool]:
    if dask is not None and not hasattr(dask, "run_grid"):  # a DaskSpec: a session for this grid
        from .cluster import open_backend
        with open_backend(dask) as session:
            return _run(cfg, cells, out=out, condition=condition, seed=seed, threads=threads, indices=indices,
                        extra=extra, existing=existing, fresh=fresh, wall_before=wall_before, progress=progress,
                        checkpoint_every=checkpoint_every, checkpoint_cells=checkpoint_cells,
                        cancel_after=cancel_after, dask=session)
    if dask is not None:
        n_threads = dask.nthreads()
        extra = {**(extra or {}), "backend": dask.describe()}
    else:
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
    runner = functools.partial(grid.run_grid, threads=threads) if dask is None else dask.run_grid
    run = runner(cfg, cells, progress=progress,
                 checkpoint=lambda snap: save(snap, wall_before + time.monotonic() - t0),
                 checkpoint_every=DEFAULT_CHECKPOINT_EVERY if checkpoint_every is None else checkpoint_every,
                 checkpoint_cells=DEFAULT_CHECKPOINT_CELLS if checkpoint_cells is None else checkpoint_cells,
                 cancel_after=cancel_after, desc=condition)
    record = save(cells, wall_before + run.wall_time)
    return cells, record, run.cancelled
