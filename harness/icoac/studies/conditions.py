# SPDX-License-Identifier: Apache-2.0
"""Orchestration of one learning condition: its prior (condition_prior) and a validated,
checkpointed, resumable grid run into a results directory (run_condition). The command line
(icoac.cli), the benchmark stages (icoac.studies.bench) and the sweep call these; none of them
reimplements a step."""
from __future__ import annotations

import functools
import sys
import time
from pathlib import Path
from typing import Any

import numpy as np

from icoac.core import binding as B
from icoac.core import geometry, grid, results, store
from icoac.studies import prior as P
from icoac.core.config import RunConfig, build_config
from icoac.core.errors import UsageError
from icoac.core.options import CART_POLE, DEFAULT_CHECKPOINT_CELLS, DEFAULT_CHECKPOINT_EVERY
from icoac.core.registry import CONDITIONS, REGISTRY


def check_condition(condition: Any) -> str:
    if condition not in CONDITIONS:
        raise UsageError(f"unknown condition {condition!r:.40}; valid: {', '.join(CONDITIONS)}")
    return condition


def condition_prior(condition: str, prior_from, frame, ridge: float, std: float = P.DEFAULT_STD,
                    plant: str = CART_POLE, overrides: dict | None = None) -> P.PriorInfo | None:
    """PriorInfo of a condition (None for ico) by its rule (icoac.core.registry); a no-learning
    control has the prior of its condition. --prior-from is required exactly when the rule takes
    the mean or the covariance from ICO: a condition that takes nothing from ICO refuses it. The
    LQR mean is that of the configuration the condition runs with (``overrides`` on the plant)."""
    cond = REGISTRY[check_condition(condition)]
    condition, rule = cond.base, cond.prior
    if rule is None or not rule.takes_ico:
        if prior_from is not None:
            raise UsageError(f"condition {condition} takes nothing from ICO; drop --prior-from")
        if rule is None:
            return None
        cfg = build_config(overrides or {}, condition=condition, plant=plant) if rule.mean == "lqr" else None
        return P.condition_prior(condition, None, std, geometry.of(plant).n_inputs, cfg=cfg)
    if prior_from is None:
        raise UsageError(f"condition {condition} needs --prior-from ICO_RESULTS_DIR")
    return P.condition_prior(condition, P.from_results(prior_from, frame, ridge, plant), std,
                             geometry.of(plant).n_inputs)


def local_runner(condition: str):
    """What runs a condition's grid on this machine: the engine (grid.run_grid), or for an optimiser
    its own runner with the same contract."""
    if REGISTRY[condition].optimiser is not None:
        from icoac.studies.baselines import cma_es
        return cma_es.run_grid
    return grid.run_grid


def nothing_to_resume(out: Path) -> UsageError:
    return UsageError(f"--resume: no results to resume in {str(out)!r} (none written yet: run the command "
                      "without --resume)")


def prior_extra(info: P.PriorInfo | None) -> dict | None:
    """What run.json records of a prior (None: nothing)."""
    return {"prior_info": info.to_dict()} if info is not None else None


def run_condition(*, condition: str, out: Path, seed: int, threads: int, overrides: dict,
                  cell_spec=None, resume: bool = False, fresh: bool = False, progress: bool = True,
                  checkpoint_every: float | None = None, checkpoint_cells: int | None = None,
                  info: P.PriorInfo | None = None, explicit: bool = True, cancel_after: float | None = None,
                  start_over: str = "rerun with --overwrite", dask=None,
                  plant: str = CART_POLE) -> tuple[np.ndarray, dict, bool]:
    """Run (or resume) one condition into a results directory; returns (cells, record, cancelled).

    ``dask`` (a icoac.cluster.backend.DaskSession, or a DaskSpec for a session opened after every check
    and closed after this grid) runs the grid on a Dask cluster instead of ``threads`` local C
    threads, with the same cells, checkpoints and resume; run.json then records the backend
    (``backend``) and the cluster's thread count.

    Everything is validated before the first byte is written: the arguments and the configuration
    (C checks) first; then the output directory is held (store.ResultsStore: created if missing,
    a real write probe, the lock) and, when results exist, both files, the ABI of the library that
    wrote them, the recorded configuration and that the cells are exactly the recorded selection
    are checked. A resume writes nothing until new cells have finished (nothing at all when none
    is pending), except that it first commits the cells of a run stopped between two writes (a
    record that does not name its cells, repaired by store.ResultsStore.load); ``fresh`` discards
    existing results (after the checks). With ``resume`` and not ``explicit`` the recorded
    condition, seed, cells, configuration and prior are used.
    """
    out = store.check_out_dir(out)
    seed = grid.check_seed(seed)
    threads = grid.check_threads(threads)
    check_condition(condition)
    if resume and fresh:
        raise UsageError("--resume and --overwrite exclude each other")
    if resume and not (out.is_dir() and results.present(out)):
        raise nothing_to_resume(out)
    try:
        indices = grid.parse_cell_indices(cell_spec, geometry.of(plant).cells)
    except B.ConfigError as exc:
        raise UsageError(f"--cells: {exc}") from None
    extra = prior_extra(info)
    prior = info.prior() if info is not None else None
    cfg = None if resume and not explicit else build_config(overrides, condition=condition, prior=prior, plant=plant)
    if cfg is not None and isinstance(info, P.PriorInfo):
        P.check_origin_task(info, cfg)
    with store.ResultsStore(out, start_over=start_over) as st:
        have = st.present()
        if resume and not have:
            raise nothing_to_resume(out)
        if have == [results.CELLS_FILE] and not fresh:  # never left by a run (store.ResultsStore)
            raise UsageError(f"{str(out)!r} holds {results.CELLS_FILE} but no {results.RUN_FILE}, which no run "
                             f"leaves behind: refusing to {'resume' if resume else 'replace'} it; {start_over} "
                             "to discard it and start over")
        record = None
        if have and not fresh:
            cells, record, stale = st.load(repair=resume)
            if cfg is None:
                cfg = results.load_config(record)
                condition, seed, indices = record["condition"], record["seed"], record["cells"]
                if record.get("prior_info") is not None:
                    extra = {"prior_info": record["prior_info"]}
            store.check_resumable(record, condition=condition, seed=seed, cfg=cfg, cell_indices=indices)
            n_pending = int((cells["outcome"] == B.PENDING).sum())
            if progress:
                print(f"resuming {out}: {n_pending} of {cells.size} cells pending", file=sys.stderr)
            if n_pending == 0 and not stale:  # nothing to run: nothing is written, the record stays as it is
                return cells, record, False
        else:
            cells = grid.make_cells(seed, indices, plant=cfg.plant_name)
        return _run(st, cfg, cells, previous=record, condition=condition, seed=seed, threads=threads,
                    indices=indices, extra=extra, fresh=fresh, progress=progress, checkpoint_every=checkpoint_every,
                    checkpoint_cells=checkpoint_cells, cancel_after=cancel_after, dask=dask)


def _run(st: store.ResultsStore, cfg: RunConfig, cells: np.ndarray, *, previous: dict | None, condition: str,
         seed: int, threads: int, indices, extra, fresh: bool, progress: bool, checkpoint_every, checkpoint_cells,
         cancel_after, dask=None) -> tuple[np.ndarray, dict, bool]:
    if REGISTRY[condition].optimiser is not None:  # Python between its trials: local threads only
        dask = None
    if dask is not None and not hasattr(dask, "run_grid"):  # a DaskSpec: a session for this grid
        from icoac.cluster.backend import open_backend
        with open_backend(dask) as session:
            return _run(st, cfg, cells, previous=previous, condition=condition, seed=seed, threads=threads,
                        indices=indices, extra=extra, fresh=fresh, progress=progress,
                        checkpoint_every=checkpoint_every, checkpoint_cells=checkpoint_cells,
                        cancel_after=cancel_after, dask=session)
    if dask is not None:
        n_threads = dask.nthreads()
        extra = {**(extra or {}), "backend": dask.describe()}
    else:
        n_threads = threads if threads > 0 else grid.default_threads()
    wall_before = float(previous.get("wall_time", 0.0)) if previous is not None else 0.0
    st.begin(previous, fresh=fresh, git=results.git_info())

    def save(snapshot, wall):
        return st.save(snapshot, cfg, condition=condition, seed=seed, wall_time=wall, threads=n_threads,
                       cell_indices=indices, extra=extra)

    t0 = time.monotonic()
    if previous is None:
        save(cells, 0.0)  # every cell PENDING: resumable from the first second
    runner = functools.partial(local_runner(condition), threads=threads) if dask is None else dask.run_grid
    run = runner(cfg, cells, progress=progress,
                 checkpoint=lambda snap: save(snap, wall_before + time.monotonic() - t0),
                 checkpoint_every=DEFAULT_CHECKPOINT_EVERY if checkpoint_every is None else checkpoint_every,
                 checkpoint_cells=DEFAULT_CHECKPOINT_CELLS if checkpoint_cells is None else checkpoint_cells,
                 cancel_after=cancel_after, desc=condition)
    record = save(cells, wall_before + run.wall_time)
    return cells, record, run.cancelled
