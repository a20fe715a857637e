"""Run grids of cells through icoac_sim_run_grid with progress, Ctrl-C cancellation and checkpoints."""
from __future__ import annotations

import ctypes
import math
import os
import sys
import threading
import time
from dataclasses import dataclass
from typing import Callable, Iterable, Optional, Sequence

import numpy as np

from . import _binding as B
from .config import RunConfig


def paper_grid(seed: int = 0) -> np.ndarray:
    """The paper's 25 x 49 grid (row-major over theta0, then x0), every cell PENDING."""
    cells = np.zeros(B.GRID_CELLS, dtype=B.CELL_DTYPE)
    B.check_status(B.lib.icoac_sim_paper_grid(cells, cells.size, int(seed) & 0xFFFFFFFFFFFFFFFF), "paper grid")
    return cells


def parse_cell_indices(text: str | Sequence[int] | None, n_cells: int = B.GRID_CELLS) -> Optional[list[int]]:
    """'i,j,k' or 'a-b' ranges -> sorted unique indices in [0, n_cells); None means every cell."""
    if text is None:
        return None
    if isinstance(text, str):
        out: list[int] = []
        for part in text.split(","):
            part = part.strip()
            if not part:
                continue
            try:
                if "-" in part[1:]:
                    lo, hi = part.split("-", 1) if not part.startswith("-") else (None, None)
                    out.extend(range(int(lo), int(hi) + 1))
                else:
                    out.append(int(part))
            except (TypeError, ValueError):
                raise B.ConfigError(B.SIM_ERR_BAD_ARGUMENT, f"bad cell index {part!r}")
    else:
        out = [int(i) for i in text]
    if not out:
        raise B.ConfigError(B.SIM_ERR_BAD_ARGUMENT, "empty cell list")
    bad = [i for i in out if not 0 <= i < n_cells]
    if bad:
        raise B.ConfigError(B.SIM_ERR_BAD_ARGUMENT, f"cell index {bad[0]} out of range [0, {n_cells})")
    return sorted(set(out))


def make_cells(seed: int = 0, indices: Iterable[int] | None = None) -> np.ndarray:
    """Paper-grid cells (seeds as in the full grid), optionally a subset of cell indices."""
    cells = paper_grid(seed)
    if indices is None:
        return cells
    return np.ascontiguousarray(cells[np.asarray(list(indices), dtype=np.intp)])


def finished_snapshot(cells: np.ndarray) -> np.ndarray:
    """Consistent copy of cells that may be written by running C threads: a cell counts only if its
    outcome (stored last, with release order) was already final; the others are reset to PENDING."""
    outcome = cells["outcome"].copy()
    snap = cells.copy()
    pending = outcome == B.PENDING
    reset_pending(snap, pending)
    return snap


def reset_pending(cells: np.ndarray, mask: np.ndarray | None = None) -> None:
    """Clear the result fields of cells in mask (default: every PENDING cell)."""
    if mask is None:
        mask = cells["outcome"] == B.PENDING
    for name in ("outcome", "status", "trials", "total_steps", "last_trial_steps", "elapsed_time",
                 "weights", "cov"):
        cells[name][mask] = 0


@dataclass
class GridRun:
    cells: np.ndarray
    cancelled: bool
    wall_time: float
    status: int

    @property
    def complete(self) -> bool:
        return bool(np.all(self.cells["outcome"] != B.PENDING))


class _Progress:
    """tqdm bar over cells with trials and ticks/s in the postfix (silent when disabled)."""

    def __init__(self, total: int, initial: int, enabled: bool, desc: str):
        self.bar = None
        if enabled:
            from tqdm import tqdm
            self.bar = tqdm(total=total, initial=initial, unit="cell", desc=desc, file=sys.stderr,
                            dynamic_ncols=True, smoothing=0.05, mininterval=0.5)
        self.last_cells = 0
        self.t0 = time.monotonic()

    def update(self, progress: np.ndarray) -> None:
        if self.bar is None:
            return
        cells, trials, steps = (int(v) for v in progress)
        if cells > self.last_cells:
            self.bar.update(cells - self.last_cells)
            self.last_cells = cells
        elapsed = max(time.monotonic() - self.t0, 1e-9)
        self.bar.set_postfix_str(f"trials={trials} ticks/s={steps / elapsed:.3g}", refresh=False)

    def close(self) -> None:
        if self.bar is not None:
            self.bar.close()


def default_threads() -> int:
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:  # pragma: no cover
        return os.cpu_count() or 1


def run_grid(cfg: RunConfig, cells: np.ndarray, threads: int = 0, progress: bool = True,
             checkpoint: Callable[[np.ndarray], None] | None = None, checkpoint_every: float = 30.0,
             poll_interval: float = 0.2, cancel_after: float | None = None,
             cancel_event: threading.Event | None = None, desc: str = "grid") -> GridRun:
    """Run every PENDING cell of ``cells`` (modified in place) on ``threads`` C threads (0: all cores).

    The C call runs in a worker thread (ctypes releases the GIL); this thread polls the progress
    counters. Ctrl-C (or ``cancel_event``, or ``cancel_after`` seconds) raises the C cancel flag and
    waits for the worker: finished cells are kept, the others stay PENDING so a later call resumes
    them. ``checkpoint(snapshot)`` is called every ``checkpoint_every`` seconds with the finished cells.
    Errors other than cancellation raise IcoacError.
    """
    if cells.dtype != B.CELL_DTYPE or not cells.flags.c_contiguous or cells.ndim != 1:
        raise B.ConfigError(B.SIM_ERR_BAD_ARGUMENT, "cells must be a 1-D contiguous CELL_DTYPE array")
    if threads < 0:
        raise B.ConfigError(B.SIM_ERR_BAD_ARGUMENT, "threads must be >= 0")
    cfg.check()
    pending = int(np.count_nonzero(cells["outcome"] == B.PENDING))
    t_start = time.monotonic()
    if pending == 0 or cells.size == 0:
        return GridRun(cells, False, 0.0, B.OK)
    reset_pending(cells)

    cancel = np.zeros(1, dtype=np.int32)
    counters = np.zeros(B.PROGRESS_LEN, dtype=np.int64)
    result: dict[str, object] = {}
    prior = ctypes.byref(cfg.prior) if cfg.prior is not None else None

    def worker() -> None:
        try:
            result["status"] = B.lib.icoac_sim_run_grid(
                ctypes.byref(cfg.controller), ctypes.byref(cfg.plant), ctypes.byref(cfg.run), prior,
                cells, cells.size, int(threads), cancel, counters)
        except BaseException as exc:  # pragma: no cover - ctypes argument errors
            result["error"] = exc

    bar = _Progress(cells.size, cells.size - pending, progress, desc)
    thread = threading.Thread(target=worker, name="icoac-grid", daemon=True)
    thread.start()
    last_checkpoint = time.monotonic()
    user_cancelled = False
    try:
        while thread.is_alive():
            thread.join(poll_interval)
            bar.update(counters)
            now = time.monotonic()
            if cancel_event is not None and cancel_event.is_set() and not cancel[0]:
                cancel[0] = 1
            if cancel_after is not None and now - t_start >= cancel_after and not cancel[0]:
                cancel[0] = 1
            if checkpoint is not None and now - last_checkpoint >= checkpoint_every and thread.is_alive():
                checkpoint(finished_snapshot(cells))
                last_checkpoint = now
    except KeyboardInterrupt:
        user_cancelled = True
        cancel[0] = 1
        if progress:
            print("\ninterrupted: stopping threads, keeping finished cells ...", file=sys.stderr)
        while thread.is_alive():
            try:
                thread.join(0.5)
            except KeyboardInterrupt:
                pass
    finally:
        bar.update(counters)
        bar.close()
    wall = time.monotonic() - t_start
    if "error" in result:
        raise result["error"]  # type: ignore[misc]
    status = int(result.get("status", B.SIM_CANCELLED))
    if status == B.SIM_CANCELLED or user_cancelled:
        reset_pending(cells)
        return GridRun(cells, True, wall, B.SIM_CANCELLED)
    B.check_status(status, "run grid")
    return GridRun(cells, False, wall, status)


def run_cell(cfg: RunConfig, x0: float, theta0: float, seed: int = 0) -> np.ndarray:
    """One independent run of one cell (icoac_sim_run_cell); returns a 0-d CELL_DTYPE record."""
    cfg.check()
    cell = np.zeros(1, dtype=B.CELL_DTYPE)
    cell["x0"], cell["theta0"], cell["seed"] = x0, theta0, seed
    prior = ctypes.byref(cfg.prior) if cfg.prior is not None else None
    status = B.lib.icoac_sim_run_cell(ctypes.byref(cfg.controller), ctypes.byref(cfg.plant),
                                      ctypes.byref(cfg.run), prior, cell, None, None)
    B.check_status(status, "run cell")
    return cell[0]


@dataclass
class Trajectory:
    states: np.ndarray   # (n_steps + 1, 4): x, x_dot, theta, theta_dot (start included)
    forces: np.ndarray   # (n_steps,)
    dt: float

    @property
    def n_steps(self) -> int:
        return int(self.forces.size)

    @property
    def time(self) -> np.ndarray:
        return np.arange(self.states.shape[0]) * self.dt


def trajectory(cfg: RunConfig, x0: float, theta0: float, duration: float = 30.0,
               seed: int = 0, init_velocity_noise: float | None = None) -> Trajectory:
    """One trial from (x0, theta0) with the controller initialised from cfg.prior (learning on),
    recorded for up to ``duration`` simulated seconds (icoac_sim_trajectory)."""
    cfg.check()
    max_steps = int(math.ceil(duration / cfg.plant.dt - 1e-9))
    if max_steps < 1:
        raise B.ConfigError(B.SIM_ERR_BAD_ARGUMENT, "trajectory duration must cover at least one step")
    noise = cfg.run.init_velocity_noise if init_velocity_noise is None else float(init_velocity_noise)
    states = np.zeros((max_steps + 1) * B.N_INPUTS)
    forces = np.zeros(max_steps)
    n = ctypes.c_int64(0)
    prior = ctypes.byref(cfg.prior) if cfg.prior is not None else None
    status = B.lib.icoac_sim_trajectory(ctypes.byref(cfg.controller), ctypes.byref(cfg.plant), prior,
                                        float(x0), float(theta0), noise, int(seed), max_steps,
                                        states, forces, ctypes.byref(n))
    B.check_status(status, "trajectory")
    k = int(n.value)
    return Trajectory(states.reshape(-1, B.N_INPUTS)[: k + 1].copy(), forces[:k].copy(), cfg.plant.dt)
