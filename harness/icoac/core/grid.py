# SPDX-License-Identifier: Apache-2.0
"""Run grids of cells through icoac_sim_run_grid (any registry plant) with progress, Ctrl-C cancellation and checkpoints."""
from __future__ import annotations

import ctypes
import math
import os
import re
import sys
import threading
import time
from dataclasses import dataclass
from typing import Callable, Iterable, Mapping, Optional, Sequence

import numpy as np

from icoac.core import binding as B
from icoac.core.config import RunConfig
from icoac.core.options import CART_POLE, DEFAULT_CHECKPOINT_CELLS, DEFAULT_CHECKPOINT_EVERY, MAX_THREADS, MAX_TRAJECTORY_STEPS, SEED_LIMIT, TRAJECTORY_DURATION

# What icoac_sim_run_grid fills in; the caller sets the others (icoac_sim_cell_t).
INPUT_FIELDS = ("x0", "theta0", "seed")
RESULT_FIELDS = tuple(n for n in B.CELL_DTYPE.names if n not in INPUT_FIELDS)


def _bad_arg(message: str) -> B.ConfigError:
    return B.ConfigError(B.SIM_ERR_BAD_ARGUMENT, message)


def _is_int(value) -> bool:
    return isinstance(value, (int, np.integer)) and not isinstance(value, (bool, np.bool_))


def check_seed(seed, what: str = "seed") -> int:
    """A grid seed as an int in [0, 2^64) (uint64); anything else raises ConfigError."""
    if not _is_int(seed) or not 0 <= int(seed) < SEED_LIMIT:
        raise _bad_arg(f"{what} must be an integer in [0, 2^64), got {seed!r:.60}")
    return int(seed)


def seed_range(first, count, what: str = "--seed") -> list[int]:
    """The seeds first .. first + count - 1 (the meaning of --seed S --seeds N everywhere);
    ConfigError unless they are all uint64 and count >= 1."""
    first = check_seed(first, what)
    if not _is_int(count) or int(count) < 1:
        raise _bad_arg(f"number of seeds must be an integer >= 1, got {count!r:.60}")
    if first + int(count) > SEED_LIMIT:
        raise _bad_arg(f"{what} {first} with {int(count)} seeds goes past 2^64 - 1")
    return [first + i for i in range(int(count))]


def check_threads(threads) -> int:
    """Thread count for the C runner: 0 (all cores) .. MAX_THREADS."""
    if not _is_int(threads) or not 0 <= int(threads) <= MAX_THREADS:
        raise _bad_arg(f"threads must be an integer in [0, {MAX_THREADS}] (0: all cores), got {threads!r:.60}")
    return int(threads)


# ASCII digits, as every number of the harness (icoac.core.literals)
_INDEX = re.compile(r"[0-9]{1,18}", re.ASCII)
_RANGE = re.compile(r"([0-9]{1,18})\s*-\s*([0-9]{1,18})", re.ASCII)


def parse_cell_indices(text: str | Sequence[int] | None, n_cells: int) -> Optional[list[int]]:
    """'i,j,k' or 'a-b' ranges -> sorted unique indices in [0, n_cells) (a grid's cells); None means every cell.

    Ranges are checked against n_cells before they are expanded; anything malformed raises ConfigError."""
    if text is None:
        return None
    out: set[int] = set()
    if isinstance(text, str):
        for part in text.split(","):
            part = part.strip(" \t\n\r\f\v")
            if not part:
                continue
            m = _RANGE.fullmatch(part)
            if m:
                lo, hi = int(m.group(1)), int(m.group(2))
                if lo > hi:
                    raise _bad_arg(f"bad cell range {part!r:.40}: start > end")
                if hi >= n_cells:
                    raise _bad_arg(f"cell index {hi} out of range [0, {n_cells})")
                out.update(range(lo, hi + 1))
            elif _INDEX.fullmatch(part):
                i = int(part)
                if i >= n_cells:
                    raise _bad_arg(f"cell index {i} out of range [0, {n_cells})")
                out.add(i)
            else:
                raise _bad_arg(f"bad cell index {part!r:.40}; expected i or a-b in ASCII digits, 0 <= i < {n_cells}")
    else:
        if isinstance(text, (bytes, bytearray, Mapping)) or not isinstance(text, Iterable):
            raise _bad_arg(f"cell indices must be a string or a sequence of integers, got {text!r:.60}")
        for i in text:
            if not _is_int(i):
                raise _bad_arg(f"bad cell index {i!r:.40}; expected an integer")
            if not 0 <= int(i) < n_cells:
                raise _bad_arg(f"cell index {int(i)} out of range [0, {n_cells})")
            out.add(int(i))
    if not out:
        raise _bad_arg("empty cell list")
    return sorted(out)


def format_cell_indices(indices: Iterable[int]) -> str:
    """Inverse of parse_cell_indices: sorted unique indices with runs as ranges, e.g. '0,5,600-610'."""
    idx = sorted(set(int(i) for i in indices))
    parts = []
    k = 0
    while k < len(idx):
        j = k
        while j + 1 < len(idx) and idx[j + 1] == idx[j] + 1:
            j += 1
        parts.append(str(idx[k]) if j == k else f"{idx[k]}-{idx[j]}")
        k = j + 1
    return ",".join(parts)


def plant_grid(plant: str, seed: int = 0) -> np.ndarray:
    """The grid of initial conditions of a registry plant (icoac_sim_plant_grid): x0 the start of
    its column component, theta0 of its row component; the cart-pole's is the paper grid."""
    info = B.plant_info(plant)
    cells = np.zeros(info["rows"]["count"] * info["cols"]["count"], dtype=B.CELL_DTYPE)
    B.check_status(B.lib.icoac_sim_plant_grid(info["index"], cells, cells.size, check_seed(seed)), "plant grid")
    return cells


def make_cells(seed: int = 0, indices: Iterable[int] | None = None, plant: str = CART_POLE) -> np.ndarray:
    """Grid cells of the plant (seeds as in the full grid), optionally a subset of cell indices."""
    cells = plant_grid(plant, seed)
    if indices is None:
        return cells
    indices = list(indices)
    parse_cell_indices(indices, cells.size)  # integers in range, else ConfigError
    return np.ascontiguousarray(cells[np.asarray(indices, dtype=np.intp)])


def finished_snapshot(cells: np.ndarray) -> np.ndarray:
    """Consistent copy of cells that may be written by running C threads: a cell counts only if its
    outcome (stored last, with release order) was already final; the others are reset to PENDING."""
    outcome = cells["outcome"].copy()
    snap = cells.copy()
    pending = outcome == B.PENDING
    reset_pending(snap, pending)
    return snap


def pending_cells(cells: np.ndarray) -> np.ndarray:
    """The indices of the PENDING cells a grid run is to run; when there are some, the coordinates
    are checked (ConfigError) and the pending cells' result fields cleared."""
    pending = np.flatnonzero(cells["outcome"] == B.PENDING)
    if pending.size:
        check_coordinates(cells)
        reset_pending(cells)
    return pending


def reset_pending(cells: np.ndarray, mask: np.ndarray | None = None) -> None:
    """Clear the result fields of cells in mask (default: every PENDING cell)."""
    if mask is None:
        mask = cells["outcome"] == B.PENDING
    for name in RESULT_FIELDS:
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


class Progress:
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


def check_run_args(cells, checkpoint_every, checkpoint_cells) -> None:
    """The arguments of a grid run that do not depend on the backend; ConfigError otherwise."""
    if not isinstance(cells, np.ndarray) or cells.dtype != B.CELL_DTYPE or not cells.flags.c_contiguous \
            or cells.ndim != 1 or not cells.flags.writeable:
        raise _bad_arg("cells must be a 1-D contiguous writeable CELL_DTYPE array")
    if not (isinstance(checkpoint_every, (int, float)) and math.isfinite(checkpoint_every) and checkpoint_every > 0):
        raise _bad_arg(f"checkpoint_every must be a finite number of seconds > 0, got {checkpoint_every!r}")
    if not _is_int(checkpoint_cells) or checkpoint_cells < 1:
        raise _bad_arg(f"checkpoint_cells must be an integer >= 1, got {checkpoint_cells!r}")


def check_coordinates(cells: np.ndarray) -> None:
    if not (np.all(np.isfinite(cells["x0"])) and np.all(np.isfinite(cells["theta0"]))):
        raise _bad_arg("cells must have finite x0 and theta0")


class Checkpoints:
    """The checkpoint policy of a running grid (the threaded engine's and the Dask backend's):
    ``save(snapshot)`` at the first poll at which ``cells`` cells finished since the last save, or
    ``every`` seconds passed since it and at least one cell finished. ``save`` None: never."""

    def __init__(self, save: Callable[[np.ndarray], None] | None, every: float, cells: int):
        self.save, self.every, self.cells = save, every, cells
        self.saved = 0  # finished cells at the last save
        self.last = time.monotonic()

    def unsaved(self, finished: int) -> bool:
        return self.save is not None and finished > self.saved

    def poll(self, finished: int, snapshot: Callable[[], np.ndarray]) -> None:
        """Save if the policy says so; ``finished``: cells finished so far."""
        if self.unsaved(finished) and (finished - self.saved >= self.cells
                                       or time.monotonic() - self.last >= self.every):
            self.flush(finished, snapshot)

    def flush(self, finished: int, snapshot: Callable[[], np.ndarray]) -> None:
        self.save(snapshot())
        self.saved = finished
        self.last = time.monotonic()


def run_grid(cfg: RunConfig, cells: np.ndarray, threads: int = 0, progress: bool = True,
             checkpoint: Callable[[np.ndarray], None] | None = None,
             checkpoint_every: float = DEFAULT_CHECKPOINT_EVERY,
             checkpoint_cells: int = DEFAULT_CHECKPOINT_CELLS,
             poll_interval: float = 0.2, cancel_after: float | None = None,
             cancel_event: threading.Event | None = None, desc: str = "grid",
             on_progress: Callable[[np.ndarray], None] | None = None) -> GridRun:
    """Run every PENDING cell of ``cells`` (modified in place) on ``threads`` C threads (0: all cores).

    The C call runs in a worker thread (ctypes releases the GIL); this thread polls the progress
    counters every ``poll_interval`` seconds. Ctrl-C (or ``cancel_event``, or ``cancel_after``
    seconds) raises the C cancel flag and waits for the worker: finished cells are kept, the others
    stay PENDING so a later call resumes them.

    ``checkpoint(snapshot)`` is called with the finished cells at the first poll at which either
    ``checkpoint_cells`` cells finished since the previous checkpoint, or ``checkpoint_every``
    seconds passed since it and at least one cell finished. Unsaved work is therefore always fewer
    than ``checkpoint_cells`` finished cells, none finished more than ``checkpoint_every +
    poll_interval`` seconds ago (plus the cells in progress). An exception from ``checkpoint``
    stops the C threads and is raised. Errors other than cancellation raise IcoacError.

    ``on_progress(counters)``, if given, is called after every poll with the C progress counters
    (cells, trials, steps so far; indices B.PROGRESS_*); the Dask workers (icoac.cluster.worker) report
    a running chunk's progress through it. An exception from it stops the C threads and is raised.
    """
    check_run_args(cells, checkpoint_every, checkpoint_cells)
    threads = check_threads(threads)
    cfg.check()
    t_start = time.monotonic()
    pending = pending_cells(cells).size
    if pending == 0:
        return GridRun(cells, False, 0.0, B.OK)

    cancel = np.zeros(1, dtype=np.int32)
    counters = np.zeros(B.PROGRESS_LEN, dtype=np.int64)
    result: dict[str, object] = {}
    prior = ctypes.byref(cfg.prior) if cfg.prior is not None else None
    model = cfg.engine_model()

    def worker() -> None:
        try:
            result["status"] = B.lib.icoac_sim_run_grid(
                ctypes.byref(cfg.controller), ctypes.byref(model), ctypes.byref(cfg.run), prior,
                cells, cells.size, int(threads), cancel, counters)
        except BaseException as exc:  # pragma: no cover - ctypes argument errors
            result["error"] = exc

    def stop_worker() -> None:
        cancel[0] = 1
        while thread.is_alive():
            try:
                thread.join(0.5)
            except KeyboardInterrupt:
                pass

    bar = Progress(cells.size, cells.size - pending, progress, desc)
    thread = threading.Thread(target=worker, name="icoac-grid", daemon=True)
    thread.start()
    checkpoints = Checkpoints(checkpoint, checkpoint_every, checkpoint_cells)
    user_cancelled = False
    try:
        while thread.is_alive():
            thread.join(poll_interval)
            bar.update(counters)
            if on_progress is not None:
                on_progress(counters)
            now = time.monotonic()
            if cancel_event is not None and cancel_event.is_set() and not cancel[0]:
                cancel[0] = 1
            if cancel_after is not None and now - t_start >= cancel_after and not cancel[0]:
                cancel[0] = 1
            if thread.is_alive():
                checkpoints.poll(int(counters[B.PROGRESS_CELLS]), lambda: finished_snapshot(cells))
    except KeyboardInterrupt:
        user_cancelled = True
        if progress:
            print("\ninterrupted: stopping threads, keeping finished cells ...", file=sys.stderr)
        stop_worker()
    except BaseException:
        stop_worker()  # e.g. a checkpoint that could not be written: stop C before raising
        raise
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
    cell["x0"], cell["theta0"], cell["seed"] = x0, theta0, check_seed(seed)
    prior = ctypes.byref(cfg.prior) if cfg.prior is not None else None
    status = B.lib.icoac_sim_run_cell(ctypes.byref(cfg.controller), ctypes.byref(cfg.engine_model()),
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


def trajectory_steps(duration: float, dt: float) -> int:
    """Plant steps of a trajectory of ``duration`` seconds; ConfigError unless finite, at least one
    step and at most MAX_TRAJECTORY_STEPS."""
    if isinstance(duration, bool) or not isinstance(duration, (int, float, np.integer, np.floating)) \
            or not math.isfinite(duration) or duration <= 0:
        raise _bad_arg(f"trajectory duration must be a finite number of seconds > 0, got {duration!r:.40}")
    steps = math.ceil(float(duration) / dt - 1e-9)
    if steps < 1:
        raise _bad_arg("trajectory duration must cover at least one step")
    if steps > MAX_TRAJECTORY_STEPS:
        raise _bad_arg(f"trajectory duration {float(duration):g} s needs {steps:.3g} steps at dt = {dt:g} s; "
                       f"at most {MAX_TRAJECTORY_STEPS:.0e} are allowed ({MAX_TRAJECTORY_STEPS * dt:g} s)")
    return int(steps)


def trajectory(cfg: RunConfig, x0: float, theta0: float, duration: float = TRAJECTORY_DURATION,
               seed: int = 0, init_velocity_noise: float | None = None) -> Trajectory:
    """One trial from (x0, theta0) with the controller initialised from cfg.prior (learning on),
    recorded for up to ``duration`` simulated seconds (icoac_sim_trajectory)."""
    cfg.check()
    model = cfg.engine_model()
    max_steps = trajectory_steps(duration, model.dt)
    noise = cfg.run.init_velocity_noise if init_velocity_noise is None else float(init_velocity_noise)
    n_state = len(B.plant_info(model.plant)["state"])
    states = np.zeros((max_steps + 1) * n_state)
    forces = np.zeros(max_steps)
    n = ctypes.c_int64(0)
    prior = ctypes.byref(cfg.prior) if cfg.prior is not None else None
    status = B.lib.icoac_sim_trajectory(ctypes.byref(cfg.controller), ctypes.byref(model), prior,
                                        float(x0), float(theta0), noise, check_seed(seed), max_steps,
                                        states, forces, ctypes.byref(n))
    B.check_status(status, "trajectory")
    k = int(n.value)
    return Trajectory(states.reshape(-1, n_state)[: k + 1].copy(), forces[:k].copy(), model.dt)
