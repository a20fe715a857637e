# SPDX-License-Identifier: Apache-2.0
"""What a Dask worker runs for icoac.cluster.backend: check that it can load the C library with the
client's ABI, and run one chunk of cells through grid.run_grid (threads=1), the same engine entry
as the local threaded path.

Nothing here imports the binding at module level: a worker that cannot load the library must be
able to unpickle these functions and say so (WorkerError naming the worker and the library path)
instead of failing to deserialize the task. Only the standard library and numpy are imported
before a task runs.
"""
from __future__ import annotations

import os
import socket
import threading
import time
from typing import Any, Mapping

import numpy as np

from icoac.core.errors import LibraryError, WorkerError
from icoac.core.options import DASK_PROGRESS_EVERY

PROGRESS_TOPIC = "icoac-progress"   # log_event topic of a running chunk's progress

# run id -> threading.Event: set by cancel_run (client.run on every worker) to stop that run's
# chunks; a running chunk passes it to run_grid as its cancel_event, a chunk that starts after it
# was set returns at once with every cell PENDING.
_CANCEL: dict[str, threading.Event] = {}
_LOCK = threading.Lock()


def _cancel_event(run_id: str) -> threading.Event:
    with _LOCK:
        return _CANCEL.setdefault(run_id, threading.Event())


def cancel_run(run_id: str) -> bool:
    """Stop every chunk of ``run_id`` on this worker (running ones at their next 0.2 s poll)."""
    _cancel_event(run_id).set()
    return True


def ignore_sigint_plugin():
    """Worker plugin of the LocalCluster of `--workers N`: its worker processes ignore SIGINT, so
    Ctrl-C in the terminal (sent to the whole process group) reaches the client alone, which then
    stops the run in order. Made on demand: importing this module does not import Dask."""
    from distributed import WorkerPlugin

    class IgnoreSigint(WorkerPlugin):
        def setup(self, worker):  # runs in the worker's event loop, the main thread of its process
            import signal
            try:
                signal.signal(signal.SIGINT, signal.SIG_IGN)
            except ValueError:  # pragma: no cover - not the main thread
                pass
    return IgnoreSigint()


def _library_hint() -> str:
    """The library path the binding loads (ICOAC_SIM_LIBRARY or the development build), computed
    without loading it."""
    env = os.environ.get("ICOAC_SIM_LIBRARY")
    if env:
        return env
    from pathlib import Path
    return str(Path(__file__).resolve().parent.parent / "build" / "release" / "sim_host" / "libicoac_sim.so")


def worker_name(worker=None) -> str:
    """'tcp://10.0.0.5:40123 (name 0) on host node17, pid 4242', or host and pid outside a worker."""
    where = f"host {socket.gethostname()}, pid {os.getpid()}"
    if worker is None:
        try:
            from distributed import get_worker
            worker = get_worker()
        except (ImportError, ValueError):
            return where
    return f"{worker.address} (name {worker.name}) on {where}"


def _binding(worker=None):
    """The binding module, loaded (and ABI-checked by its import); WorkerError naming this worker
    and the library path if the library is missing, unloadable or stale."""
    try:
        from icoac.core import binding as B
    except LibraryError as exc:
        raise WorkerError(f"Dask worker {worker_name(worker)} cannot use the icoac_sim library "
                          f"({_library_hint()}): {exc}") from None
    except Exception as exc:  # an unexpected import failure: still one clear line
        raise WorkerError(f"Dask worker {worker_name(worker)} cannot load the icoac_sim library "
                          f"{_library_hint()}: {type(exc).__name__}: {exc}") from None
    return B


def abi_of(B) -> dict[str, Any]:
    """What client and workers must agree on: the ABI versions, the real type, the critic kernel
    (its V rounds differently), the struct and cell sizes (everything a chunk's bytes depend on),
    and the harness version."""
    from icoac import __version__
    return {"abi_version": int(B.lib.icoac_abi_version()), "sim_abi_version": int(B.lib.icoac_sim_abi_version()),
            "sizeof_real": int(B.lib.icoac_sizeof_real()), "critic_dense": int(B.CONSTANTS["ICOAC_CRITIC_DENSE"]),
            "sizeof_config": int(B.lib.icoac_sizeof_config()),
            "sizeof_prior": int(B.lib.icoac_sizeof_prior()), "sizeof_model": B.mirror_size(B.Model),
            "sizeof_run": int(B.lib.icoac_sim_sizeof_run()), "sizeof_cell": int(B.CELL_DTYPE.itemsize),
            "plants": [B.plant_info(i)["name"] for i in range(int(B.lib.icoac_sim_plant_count()))],
            "harness_version": __version__}


def config_bytes(cfg) -> tuple:
    """A RunConfig as the bytes of its C structs (controller, model, run, prior or None), which a
    worker turns back into the same configuration (config_from_bytes)."""
    return (bytes(cfg.controller), bytes(cfg.model), bytes(cfg.run), None if cfg.prior is None else bytes(cfg.prior))


def config_from_bytes(B, cfg_bytes: tuple):
    from icoac.core.config import RunConfig
    controller, model, run, prior = cfg_bytes
    return RunConfig(controller=B.Config.from_buffer_copy(controller), model=B.Model.from_buffer_copy(model),
                     run=B.Run.from_buffer_copy(run), prior=None if prior is None else B.Prior.from_buffer_copy(prior))


def check_worker(expected: Mapping[str, Any], dask_worker=None) -> dict[str, Any]:
    """Load the library here and compare its ABI with the client's; returns this worker's
    description (name, library path, ABI); WorkerError on any difference. (client.run passes
    the worker as ``dask_worker``; in a task it is found by get_worker.)"""
    B = _binding(dask_worker)
    abi = abi_of(B)
    diff = [f"{k} {abi.get(k)!r} != client's {v!r}" for k, v in expected.items() if abi.get(k) != v]
    if diff:
        raise WorkerError(f"Dask worker {worker_name(dask_worker)}: the icoac_sim library {B.LIBRARY_PATH} does "
                          f"not match the client's ({'; '.join(diff)}); build the same version on every node")
    return {"worker": worker_name(dask_worker), "library": str(B.LIBRARY_PATH), "abi": abi}


def run_chunk(run_id: str, chunk: int, cfg_bytes: tuple, cells: np.ndarray, expected: Mapping[str, Any]) -> dict:
    """Run one chunk: ``cells`` (a small CELL_DTYPE array, some or all PENDING) through
    grid.run_grid on one C thread, with the configuration rebuilt bitwise from the client's struct
    bytes (config_bytes). Returns {"chunk", "cells", "wall_time",
    "worker"}; cells left PENDING were cancelled (cancel_run)."""
    B = _binding()
    check_worker(expected)
    from icoac.core import grid

    cells = np.array(cells, dtype=B.CELL_DTYPE, copy=True, order="C")
    stop = _cancel_event(run_id)
    if stop.is_set():
        grid.reset_pending(cells)
        return {"chunk": chunk, "cells": cells, "wall_time": 0.0, "worker": worker_name()}
    cfg = config_from_bytes(B, cfg_bytes)
    report = _progress_reporter(B, run_id, chunk)
    res = grid.run_grid(cfg, cells, threads=1, progress=False, cancel_event=stop, on_progress=report)
    return {"chunk": chunk, "cells": cells, "wall_time": res.wall_time, "worker": worker_name()}


def _progress_reporter(B, run_id: str, chunk: int):
    """on_progress hook of a chunk: a log_event (cells, trials, steps) at most every
    DASK_PROGRESS_EVERY seconds, or None outside a Dask worker."""
    try:
        from distributed import get_worker
        worker = get_worker()
    except (ImportError, ValueError):
        return None
    last = [time.monotonic()]
    index = (B.PROGRESS_CELLS, B.PROGRESS_TRIALS, B.PROGRESS_STEPS)

    def report(counters: np.ndarray) -> None:
        now = time.monotonic()
        if now - last[0] < DASK_PROGRESS_EVERY:
            return
        last[0] = now
        worker.log_event(PROGRESS_TOPIC, {"run": run_id, "chunk": int(chunk),
                                          "progress": [int(counters[i]) for i in index]})
    return report
