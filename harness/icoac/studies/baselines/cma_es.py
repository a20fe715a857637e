# SPDX-License-Identifier: Apache-2.0
"""CMA-ES per cell (condition ``cma-es``, method.md L9): a baseline a black-box optimiser user
would pick, on the learners' own linear policy, cells and trial cap.

Each cell runs its own CMA-ES (the ``cma`` package) over w. An evaluation is one trial of the
fixed policy w from the cell (the engine's icoac_sim_run_cell with ``max_trials = 1`` and every
controller update off); its fitness is the ticks the trial lasted. The cell succeeds at the first
trial that lasts ``success_steps`` and fails when ``max_trials`` trials are spent, as a learner's
cell does. The optimiser starts from the condition's prior, N(mean, cov_scale * cov): the search
control's distribution, so the search control is CMA-ES without its adaptation. When CMA-ES
stops on its own (flat fitness, tolerances) before the cap, it restarts from that distribution.

Evaluation k of a cell starts from the cell's start with the velocities drawn by the seed
icoac_mix_seed(cell seed, k); the optimiser's normal draws come from numpy's PCG64 seeded by the
cell seed. A cell's result depends on nothing but its seed and the configuration: not on the
threads, the order of the cells or a resume.

Python runs per trial, never per tick: the ticks of a trial run in C. This module implements
grid.run_grid's contract (pending cells only, checkpoints, cancellation), so the results
directory, resume and bench stages are those of every condition."""
from __future__ import annotations

import ctypes
import math
import queue
import threading
import time
from typing import Callable

import numpy as np

from icoac.core import binding as B
from icoac.core import grid
from icoac.core.config import RunConfig
from icoac.core.options import DEFAULT_CHECKPOINT_CELLS, DEFAULT_CHECKPOINT_EVERY

# cma's termination tests other than the budget are left on; "maxfevals" is the cap itself.
CMA_OPTIONS = {"verbose": -9, "verb_log": 0, "verb_disp": 0, "seed": math.nan}


def start_distribution(cfg: RunConfig) -> tuple[np.ndarray, float, np.ndarray]:
    """(mean, sigma0, per-input std multipliers) of the search's start N(mean, cov_scale * cov):
    the prior's mean and diagonal (CMA-ES starts axis-aligned, so a prior with covariances is
    refused)."""
    n = cfg.n_inputs
    mean = np.array([cfg.prior.mean[i] for i in range(n)], dtype=np.float64)
    cov = np.array([[cfg.prior.cov[i][j] for j in range(n)] for i in range(n)], dtype=np.float64)
    if np.any(cov != np.diag(np.diag(cov))) or not np.all(np.diag(cov) > 0.0):
        raise B.ConfigError(B.ERR_BAD_PRIOR, "cma-es: the prior's covariance must be diagonal and positive")
    return mean, math.sqrt(float(cfg.controller.search.cov_scale)), np.sqrt(np.diag(cov))


class _Trials:
    """One worker's C objects for single trials of a fixed w: the configuration with one trial per
    run, a prior whose mean is set per trial, one cell record."""

    def __init__(self, cfg: RunConfig):
        self.n = cfg.n_inputs
        self.controller = ctypes.byref(cfg.controller)
        self.model = cfg.engine_model()
        self.run = B.Run.from_buffer_copy(cfg.run)
        self.run.max_trials = 1
        self.prior = B.Prior.from_buffer_copy(cfg.prior)
        self.cell = np.zeros(1, dtype=B.CELL_DTYPE)

    def trial(self, x0: float, theta0: float, seed: int, w: np.ndarray) -> np.ndarray:
        for i in range(self.n):
            self.prior.mean[i] = float(w[i])
        self.cell[:] = 0
        self.cell["x0"], self.cell["theta0"], self.cell["seed"] = x0, theta0, seed
        status = B.lib.icoac_sim_run_cell(self.controller, ctypes.byref(self.model), ctypes.byref(self.run),
                                          ctypes.byref(self.prior), self.cell, None, None)
        B.check_status(status, "cma-es trial")
        return self.cell[0]


W_LIMIT = 1.0e6  # the prior check's bound on |w_i|


def real_weights(w: np.ndarray) -> np.ndarray:
    """A candidate as the trial runs it: clipped to the prior check's |w_i| <= 1e6, rounded to the
    controller's real type, components below its smallest normal number set to 0."""
    with np.errstate(under="ignore"):
        real = np.clip(np.asarray(w, dtype=np.float64), -W_LIMIT, W_LIMIT).astype(B.real_dtype)
    real[np.abs(real) < np.finfo(B.real_dtype).tiny] = 0
    return real.astype(np.float64)


def run_one(trials: _Trials, start: tuple[np.ndarray, float, np.ndarray], cap: int, x0: float, theta0: float,
            seed: int, stop: threading.Event | None = None) -> np.ndarray | None:
    """CMA-ES on one cell; its result record (outcome, trials, steps, the final w, the optimiser's
    covariance), or None when ``stop`` was raised before it finished."""
    import cma
    mean, sigma0, stds = start
    rng = np.random.Generator(np.random.PCG64(seed))
    out = np.zeros((), dtype=B.CELL_DTYPE)
    out["x0"], out["theta0"], out["seed"] = x0, theta0, seed
    used = steps = 0
    elapsed = 0.0
    n = trials.n
    while True:
        es = cma.CMAEvolutionStrategy(mean, sigma0, {**CMA_OPTIONS, "CMA_stds": stds,
                                                     "randn": lambda *shape: rng.standard_normal(shape)})
        while not es.stop():
            if stop is not None and stop.is_set():
                return None
            candidates = es.ask()
            fitness = []
            for w in candidates:
                w = real_weights(w)
                r = trials.trial(x0, theta0, int(B.lib.icoac_mix_seed(seed, used)), w)
                used += 1
                steps += int(r["total_steps"])
                elapsed += float(r["elapsed_time"])
                if r["outcome"] != B.FAILED or used == cap:
                    out["outcome"] = r["outcome"]
                    out["status"] = r["status"]
                    out["trials"], out["total_steps"], out["elapsed_time"] = used, steps, elapsed
                    out["last_trial_steps"] = r["last_trial_steps"]
                    out["weights"][:n] = w
                    out["cov"][:n, :n] = es.sigma ** 2 * es.C
                    return out
                fitness.append(-float(r["last_trial_steps"]))
            es.tell(candidates, fitness)


def run_grid(cfg: RunConfig, cells: np.ndarray, threads: int = 0, progress: bool = True,
             checkpoint: Callable[[np.ndarray], None] | None = None,
             checkpoint_every: float = DEFAULT_CHECKPOINT_EVERY, checkpoint_cells: int = DEFAULT_CHECKPOINT_CELLS,
             cancel_after: float | None = None, desc: str = "cma-es", poll_interval: float = 0.2) -> grid.GridRun:
    """Every PENDING cell of ``cells`` (in place) on ``threads`` worker threads (0: all cores), with
    grid.run_grid's progress, checkpoints and cancellation (Ctrl-C or ``cancel_after``: finished
    cells are kept, the others stay PENDING)."""
    grid.check_run_args(cells, checkpoint_every, checkpoint_cells)
    threads = grid.check_threads(threads) or grid.default_threads()
    cfg.check()
    if cfg.prior is None:
        raise B.ConfigError(B.ERR_BAD_PRIOR, "cma-es needs a prior (its start distribution)")
    start = start_distribution(cfg)
    cap = int(cfg.run.max_trials)
    t_start = time.monotonic()
    pending = grid.pending_cells(cells)
    if pending.size == 0:
        return grid.GridRun(cells, False, 0.0, B.OK)
    todo: queue.SimpleQueue = queue.SimpleQueue()
    for i in pending:
        todo.put(int(i))
    lock = threading.Lock()
    stop = threading.Event()
    counters = np.zeros(B.PROGRESS_LEN, dtype=np.int64)
    errors: list[BaseException] = []

    def worker() -> None:
        trials = _Trials(cfg)
        try:
            while not stop.is_set():
                try:
                    i = todo.get_nowait()
                except queue.Empty:
                    return
                c = cells[i]
                r = run_one(trials, start, cap, float(c["x0"]), float(c["theta0"]), int(c["seed"]),
                            stop)
                if r is None:
                    return
                with lock:
                    for name in grid.RESULT_FIELDS:
                        if name != "outcome":
                            cells[name][i] = r[name]
                    cells["outcome"][i] = r["outcome"]  # last: a snapshot counts the cell from here
                    counters[B.PROGRESS_CELLS] += 1
                    counters[B.PROGRESS_TRIALS] += int(r["trials"])
                    counters[B.PROGRESS_STEPS] += int(r["total_steps"])
        except BaseException as exc:  # reported by the polling thread
            errors.append(exc)
            stop.set()

    def snapshot() -> np.ndarray:
        with lock:
            return grid.finished_snapshot(cells)

    workers = [threading.Thread(target=worker, name=f"icoac-cma-{k}", daemon=True)
               for k in range(min(threads, pending.size))]
    for t in workers:
        t.start()
    bar = grid.Progress(cells.size, cells.size - pending.size, progress, desc)
    checkpoints = grid.Checkpoints(checkpoint, checkpoint_every, checkpoint_cells)
    cancelled = False
    try:
        while any(t.is_alive() for t in workers):
            if cancel_after is not None and time.monotonic() - t_start >= cancel_after:
                cancelled = True
                stop.set()
            stop.wait(poll_interval)
            with lock:
                bar.update(counters)
                finished = int(counters[B.PROGRESS_CELLS])
            if not stop.is_set():
                checkpoints.poll(finished, snapshot)
    except KeyboardInterrupt:
        cancelled = True
        if progress:
            print("\ninterrupted: stopping the workers, keeping finished cells ...", flush=True)
    finally:
        stop.set()
        for t in workers:
            while t.is_alive():
                try:
                    t.join(0.5)
                except KeyboardInterrupt:
                    cancelled = True
        bar.update(counters)
        bar.close()
    if errors:
        raise errors[0]
    grid.reset_pending(cells)
    if cancelled or np.any(cells["outcome"] == B.PENDING):
        return grid.GridRun(cells, True, time.monotonic() - t_start, B.SIM_CANCELLED)
    return grid.GridRun(cells, False, time.monotonic() - t_start, B.OK)
