# SPDX-License-Identifier: Apache-2.0
"""The Dask backend: grids run on a dask.distributed cluster, an existing one (``--scheduler
ADDRESS``) or a LocalCluster of worker processes on this machine (``--workers N``).

The pending cells of a grid go out in chunks, one task each; a worker runs its chunk through
grid.run_grid on one C thread (icoac.cluster.worker.run_chunk), the engine entry of the local threaded
path, so a cell's result does not depend on the backend (cells are independent and seeded per
cell). Finished chunks are merged into the caller's cells array as they arrive and checkpointed
by the policy of grid.run_grid (``checkpoint_cells`` / ``checkpoint_every``), so a resume loses
no merged chunk. A worker that dies mid-chunk costs a rerun of that chunk (Dask reschedules it;
a task that raises is retried DASK_RETRIES times). Progress is the bar of grid.run_grid over
cells, with trials and ticks/s of finished chunks plus the running chunks' latest reports.
Ctrl-C, ``cancel_event`` or ``cancel_after`` stop the run: queued chunks are cancelled, running
ones stop at their next poll and return their finished cells (for up to DASK_CANCEL_GRACE
seconds), everything finished is kept, the rest stays PENDING for a resume.

Every worker loads the library and compares its ABI with the client's before it runs anything
(check_worker at connection, and again in every task, for workers that join later); a worker
that cannot is a WorkerError naming the worker and the library path.

dask.distributed is imported only when a session opens: the threaded path does not need it.
"""
from __future__ import annotations

import logging
import math
import queue
import sys
import threading
import time
import uuid
from dataclasses import dataclass
from typing import Any, Callable, Iterator

import numpy as np

from icoac.core import binding as B
from icoac.cluster import worker as _worker
from icoac.core import grid
from icoac.core.config import RunConfig
from icoac.core.errors import MissingExtra, UsageError, WorkerError
from icoac.core.options import AUTO_CHUNK_MAX, AUTO_CHUNKS_PER_THREAD, DASK_CANCEL_GRACE, DASK_CONNECT_TIMEOUT, DASK_RETRIES, DASK_WORKER_TIMEOUT, DEFAULT_CHECKPOINT_CELLS, DEFAULT_CHECKPOINT_EVERY, MAX_CHUNK_CELLS, MAX_THREADS, MAX_WORKERS

INSTALL_HINT = ("install the harness and its library on every node (`pip install -e .` in a checkout with "
                "`make build`, or the repository on PYTHONPATH and ICOAC_SIM_LIBRARY naming the library)")


def _is_int(v: Any) -> bool:
    return isinstance(v, (int, np.integer)) and not isinstance(v, (bool, np.bool_))


@dataclass(frozen=True)
class DaskSpec:
    """Where grids run: ``scheduler`` (an address such as tcp://host:8786) or ``workers`` (a
    LocalCluster of that many worker processes with ``threads_per_worker`` threads each); cells
    per task ``chunk_cells`` (None: auto_chunk)."""
    scheduler: str | None = None
    workers: int | None = None
    threads_per_worker: int = 1
    chunk_cells: int | None = None

    def check(self) -> "DaskSpec":
        if (self.scheduler is None) == (self.workers is None):
            raise UsageError("the Dask backend needs exactly one of --scheduler ADDRESS and --workers N")
        if self.scheduler is not None and (not isinstance(self.scheduler, str) or not self.scheduler.strip()):
            raise UsageError(f"--scheduler expects an address such as tcp://host:8786, got {self.scheduler!r:.60}")
        if self.workers is not None and (not _is_int(self.workers) or not 1 <= self.workers <= MAX_WORKERS):
            raise UsageError(f"--workers expects an integer in [1, {MAX_WORKERS}], got {self.workers!r:.40}")
        if not _is_int(self.threads_per_worker) or not 1 <= self.threads_per_worker <= MAX_THREADS:
            raise UsageError(f"--threads-per-worker expects an integer in [1, {MAX_THREADS}], "
                             f"got {self.threads_per_worker!r:.40}")
        if self.chunk_cells is not None and (not _is_int(self.chunk_cells)
                                             or not 1 <= self.chunk_cells <= MAX_CHUNK_CELLS):
            raise UsageError(f"--chunk-cells expects an integer in [1, {MAX_CHUNK_CELLS}], got {self.chunk_cells!r:.40}")
        _import_distributed()  # installed, before any work
        return self


def auto_chunk(pending: int, threads: int) -> int:
    """Cells per task when --chunk-cells is not given: about AUTO_CHUNKS_PER_THREAD chunks per
    worker thread, at most AUTO_CHUNK_MAX cells each."""
    return max(1, min(AUTO_CHUNK_MAX, math.ceil(pending / (AUTO_CHUNKS_PER_THREAD * max(1, threads)))))


def chunks_of(pending: np.ndarray, size: int) -> list[np.ndarray]:
    """The pending cell indices in order, cut into consecutive chunks of ``size`` (the last shorter)."""
    return [pending[i:i + size] for i in range(0, pending.size, size)]


def _import_distributed():
    try:
        import distributed
    except ImportError as exc:
        raise MissingExtra("the Dask backend (--workers, --scheduler)", "dask", exc) from None
    return distributed


class DaskSession:
    """A client of a Dask cluster (a LocalCluster it owns, or an existing scheduler), as a context
    manager; run_grid runs one grid on it. One session serves every grid of a bench or a sweep."""

    def __init__(self, spec: DaskSpec):
        self.spec = spec.check()
        self.cluster = None
        self.client = None
        self.workers: dict[str, dict] = {}
        self.expected = _worker.abi_of(B)

    # -- opening and closing ------------------------------------------------------------------------
    def __enter__(self) -> "DaskSession":
        distributed = _import_distributed()
        try:
            self._open(distributed)
            self.check_workers()
        except BaseException:
            self.close()
            raise
        return self

    def __exit__(self, *exc) -> None:
        self.close()

    def _open(self, distributed) -> None:
        spec = self.spec
        if spec.workers is not None:
            # Dask's statistical profiler samples every worker thread's stack every 10 ms: about 5 %
            # of the CPU of a busy worker here, for a profile of one C call; and the event-loop
            # health tick (20 ms), memory monitor (100 ms) and system monitor (500 ms) of the five
            # event loops (scheduler, two nannies, two workers) cost 4.5 % of a core when idle. Off,
            # or slower (1.2 % of a core), for the cluster this process starts (the nannies pass the
            # configuration on to their workers, restarts included).
            import dask
            dask.config.set({"distributed.worker.profile.enabled": False,
                             "distributed.admin.tick.interval": "500ms",
                             "distributed.worker.memory.monitor-interval": "1s",
                             "distributed.admin.system-monitor.interval": "2s"})
            try:
                self.cluster = distributed.LocalCluster(
                    n_workers=spec.workers, threads_per_worker=spec.threads_per_worker, processes=True,
                    host="127.0.0.1", dashboard_address=None, silence_logs=logging.ERROR,
                    # no dashboard (bokeh is no dependency); its HTTP server on a free loopback port
                    scheduler_kwargs={"dashboard": False, "dashboard_address": "127.0.0.1:0"})
                self.client = distributed.Client(self.cluster, timeout=DASK_CONNECT_TIMEOUT)
            except Exception as exc:
                raise WorkerError(f"cannot start a local Dask cluster of {spec.workers} workers: "
                                  f"{type(exc).__name__}: {exc}") from None
            try:
                self.client.register_plugin(_worker.ignore_sigint_plugin(), name="icoac-ignore-sigint")
            except Exception:  # pragma: no cover - only a nicer Ctrl-C
                pass
        else:
            try:
                self.client = distributed.Client(spec.scheduler, timeout=DASK_CONNECT_TIMEOUT)
            except Exception as exc:
                raise WorkerError(f"cannot reach the Dask scheduler at {spec.scheduler} within "
                                  f"{DASK_CONNECT_TIMEOUT:g} s: {type(exc).__name__}: {exc}") from None
        try:
            self.client.wait_for_workers(1, timeout=DASK_WORKER_TIMEOUT)
        except Exception:
            raise WorkerError(f"no Dask worker joined the scheduler at {self.address} within "
                              f"{DASK_WORKER_TIMEOUT:g} s (start some with `dask worker {self.address}`)") from None

    def close(self) -> None:
        for what in ("client", "cluster"):
            obj = getattr(self, what)
            setattr(self, what, None)
            if obj is not None:
                try:
                    obj.close()
                except Exception:  # pragma: no cover - closing a broken connection
                    pass

    @property
    def address(self) -> str:
        if self.client is not None:
            return str(self.client.scheduler.address)
        return str(self.spec.scheduler)

    def nthreads(self) -> int:
        """Threads of the workers connected now (0 if none)."""
        return int(sum(self.client.nthreads().values()))

    def describe(self) -> dict[str, Any]:
        """What run.json and bench.json record of the backend."""
        return {"kind": "dask", "scheduler": None if self.spec.workers is not None else self.address,
                "local_workers": self.spec.workers, "threads": self.nthreads(),
                "chunk_cells": self.spec.chunk_cells}

    def check_workers(self) -> dict[str, dict]:
        """Every connected worker loads the library and has the client's ABI (WorkerError naming
        the first that does not); returns {address: description}."""
        try:
            answers = self.client.run(_worker.check_worker, self.expected, on_error="return")
        except Exception as exc:
            raise WorkerError(f"cannot check the Dask workers of {self.address}: {type(exc).__name__}: {exc}") from None
        for address, answer in sorted(answers.items()):
            if isinstance(answer, WorkerError):
                raise WorkerError(str(answer))
            if isinstance(answer, BaseException):
                raise WorkerError(f"Dask worker {address} cannot run the harness ({type(answer).__name__}: "
                                  f"{str(answer):.200}); {INSTALL_HINT}")
        self.workers = dict(answers)
        return self.workers

    # -- one grid -------------------------------------------------------------------------------------
    def run_grid(self, cfg: RunConfig, cells: np.ndarray, progress: bool = True,
                 checkpoint: Callable[[np.ndarray], None] | None = None,
                 checkpoint_every: float = DEFAULT_CHECKPOINT_EVERY,
                 checkpoint_cells: int = DEFAULT_CHECKPOINT_CELLS,
                 poll_interval: float = 0.2, cancel_after: float | None = None,
                 cancel_event: threading.Event | None = None, desc: str = "grid",
                 chunk_cells: int | None = None) -> grid.GridRun:
        """grid.run_grid on the cluster: every PENDING cell of ``cells`` (modified in place), the
        same arguments and result (threads: the cluster's), cancellation and checkpoints;
        ``chunk_cells`` overrides the session's cells per task."""
        grid.check_run_args(cells, checkpoint_every, checkpoint_cells)
        cfg.check()
        t_start = time.monotonic()
        pending = grid.pending_cells(cells)
        if pending.size == 0:
            return grid.GridRun(cells, False, 0.0, B.OK)
        if chunk_cells is not None:
            DaskSpec(workers=1, chunk_cells=chunk_cells).check()
        size = chunk_cells or self.spec.chunk_cells or auto_chunk(pending.size, self.nthreads())
        run = _Run(self, cfg, cells, pending, size, progress=progress, desc=desc, poll_interval=poll_interval)
        return run.execute(checkpoint, checkpoint_every, checkpoint_cells, cancel_after, cancel_event, t_start)


class _Run:
    """One grid on a session: the chunks, their futures, the merge, progress and stopping."""

    def __init__(self, session: DaskSession, cfg: RunConfig, cells: np.ndarray, pending: np.ndarray, size: int, *,
                 progress: bool, desc: str, poll_interval: float):
        self.session = session
        self.client = session.client
        self.cells = cells
        self.run_id = uuid.uuid4().hex[:16]
        self.cfg_bytes = _worker.config_bytes(cfg)
        self.chunk_size = size
        self.chunks: dict[int, np.ndarray] = {}      # chunk id -> cell indices
        self.futures: dict[int, Any] = {}            # chunk id -> future not yet merged
        self.by_key: dict[str, int] = {}             # its key -> chunk id
        self.done: queue.Queue = queue.Queue()        # futures that finished, erred or were cancelled
        self.partial: dict[int, list[int]] = {}      # chunk id -> latest (cells, trials, steps) report
        self.lock = threading.Lock()
        self.merged = np.zeros(3, dtype=np.int64)    # cells, trials, steps of merged chunks
        self.progress = progress
        self.desc = desc
        self.poll_interval = poll_interval
        self.bar = grid.Progress(cells.size, cells.size - pending.size, progress, desc)
        self.stopping = False
        for idx in chunks_of(pending, size):
            self._submit(idx)

    # -- tasks ----------------------------------------------------------------------------------------
    def _submit(self, idx: np.ndarray) -> None:
        k = len(self.chunks)
        self.chunks[k] = idx
        fut = self.client.submit(_worker.run_chunk, self.run_id, k, self.cfg_bytes, self.cells[idx].copy(),
                                 self.session.expected, key=f"icoac-chunk-{self.run_id}-{k}", pure=False,
                                 retries=DASK_RETRIES)
        with self.lock:
            self.futures[k] = fut
            self.by_key[fut.key] = k
        fut.add_done_callback(self.done.put)

    def _on_event(self, event) -> None:  # the client's event loop: record a running chunk's report
        msg = event[1] if isinstance(event, tuple) and len(event) == 2 else None
        if not isinstance(msg, dict) or msg.get("run") != self.run_id:
            return
        k = msg.get("chunk")
        with self.lock:
            if k in self.futures:
                self.partial[k] = list(msg.get("progress", (0, 0, 0)))[:3]

    def _chunk_of(self, fut) -> int | None:
        k = self.by_key.get(fut.key)
        return k if k is not None and self.futures.get(k) is fut else None

    def _handle(self, fut) -> int:
        """A future that left the pending state: merge its cells (returns how many finished), or
        resubmit its chunk if its result was lost, or raise its error."""
        k = self._chunk_of(fut)
        if k is None:  # already merged or resubmitted
            return 0
        status = fut.status
        if status == "cancelled":
            if self.stopping:
                self._forget(k)
                return 0
            raise WorkerError(f"the Dask scheduler at {self.session.address} cancelled chunk {k} "
                              f"(cells {grid.format_cell_indices(self.chunks[k])}) of this run; "
                              "finished chunks are saved, rerun to resume")
        if status == "error":
            exc = fut.exception()
            self._forget(k)
            raise self._task_error(k, exc)
        try:
            out = fut.result()
        except Exception:  # the worker holding the result died before it was gathered
            if self.stopping:
                self._forget(k)
                return 0
            idx = self.chunks[k]
            self._forget(k)
            self._submit(idx)
            return 0
        return self._merge(k, out)

    def _task_error(self, k: int, exc: BaseException) -> BaseException:
        cells = grid.format_cell_indices(self.chunks[k])
        if type(exc).__name__ == "KilledWorker":
            return WorkerError(f"chunk {k} (cells {cells}) was running on Dask workers that died every time it "
                               f"was tried (last {getattr(exc, 'last_worker', '?')}); see the workers' logs")
        if isinstance(exc, (WorkerError, B.IcoacError)):
            return exc
        return WorkerError(f"chunk {k} (cells {cells}) failed on a Dask worker: {type(exc).__name__}: "
                           f"{str(exc):.300}")

    def _merge(self, k: int, out: Any) -> int:
        idx = self.chunks[k]
        res = out.get("cells") if isinstance(out, dict) else None
        if not isinstance(res, np.ndarray) or res.dtype != B.CELL_DTYPE or res.shape != idx.shape \
                or any(not np.array_equal(res[n], self.cells[n][idx]) for n in grid.INPUT_FIELDS):
            raise WorkerError(f"Dask worker {out.get('worker') if isinstance(out, dict) else '?'} returned "
                              f"something else than the cells of chunk {k}")
        finished = res["outcome"] != B.PENDING
        self.cells[idx[finished]] = res[finished]
        self._forget(k)
        n = int(finished.sum())
        self.merged += (n, int(res["trials"][finished].sum()), int(res["total_steps"][finished].sum()))
        if n < idx.size and not self.stopping:  # stopped on the worker by someone else: run the rest again
            self._submit(idx[~finished])
        return n

    def _forget(self, k: int) -> None:
        with self.lock:
            fut = self.futures.pop(k, None)
            self.partial.pop(k, None)
            if fut is not None:
                self.by_key.pop(fut.key, None)
        if fut is not None:
            fut.release()

    def _counters(self) -> np.ndarray:
        with self.lock:
            live = np.array(list(self.partial.values()), dtype=np.int64).reshape(-1, 3).sum(axis=0)
        total = self.merged + live
        out = np.zeros(B.PROGRESS_LEN, dtype=np.int64)
        out[B.PROGRESS_CELLS], out[B.PROGRESS_TRIALS], out[B.PROGRESS_STEPS] = total
        return out

    def _drain(self, timeout: float) -> int:
        """Handle every future that is done, waiting up to ``timeout`` for the first."""
        finished = 0
        try:
            fut = self.done.get(timeout=timeout) if timeout > 0 else self.done.get_nowait()
        except queue.Empty:
            return 0
        while True:
            finished += self._handle(fut)
            try:
                fut = self.done.get_nowait()
            except queue.Empty:
                return finished

    # -- the run --------------------------------------------------------------------------------------
    def execute(self, checkpoint, checkpoint_every, checkpoint_cells, cancel_after, cancel_event,
                t_start) -> grid.GridRun:
        self.client.subscribe_topic(_worker.PROGRESS_TOPIC, self._on_event)
        checkpoints = grid.Checkpoints(checkpoint, checkpoint_every, checkpoint_cells)
        last_worker_seen = time.monotonic()
        last_worker_check = time.monotonic()
        cancelled = user_cancelled = False
        try:
            try:
                while self.futures:
                    self._drain(self.poll_interval)
                    self.bar.update(self._counters())
                    now = time.monotonic()
                    if (cancel_event is not None and cancel_event.is_set()) or \
                            (cancel_after is not None and now - t_start >= cancel_after):
                        cancelled = True
                        break
                    if self.futures:
                        checkpoints.poll(int(self.merged[0]), self.cells.copy)
                    if now - last_worker_check >= 5.0:
                        last_worker_check = now
                        if self.session.nthreads() > 0:
                            last_worker_seen = now
                        elif now - last_worker_seen >= DASK_WORKER_TIMEOUT:
                            raise WorkerError(f"no Dask worker has been connected to {self.session.address} "
                                              f"for {DASK_WORKER_TIMEOUT:g} s; finished chunks are saved, "
                                              "rerun to resume")
            except KeyboardInterrupt:
                user_cancelled = cancelled = True
                if self.progress:
                    print("\ninterrupted: stopping the Dask workers' chunks, keeping finished cells ...",
                          file=sys.stderr)
            if cancelled:
                self._stop(DASK_CANCEL_GRACE)
        except BaseException:
            self._stop(0.0)
            if checkpoints.unsaved(int(self.merged[0])):
                try:  # an error in one chunk does not lose the merged ones
                    checkpoints.flush(int(self.merged[0]), self.cells.copy)
                except Exception:
                    pass
            raise
        finally:
            try:
                self.client.unsubscribe_topic(_worker.PROGRESS_TOPIC)
            except Exception:  # pragma: no cover
                pass
            self.bar.update(self._counters())
            self.bar.close()
        wall = time.monotonic() - t_start
        if cancelled or user_cancelled:
            grid.reset_pending(self.cells)
            return grid.GridRun(self.cells, True, wall, B.SIM_CANCELLED)
        return grid.GridRun(self.cells, False, wall, B.OK)

    def _stop(self, grace: float) -> None:
        """Stop this run on the cluster: every worker stops its chunks (cancel_run), queued chunks
        are cancelled, running ones may return their finished cells for ``grace`` seconds (a second
        Ctrl-C gives up on them), then whatever is left is cancelled."""
        self.stopping = True
        if not self.futures:
            return
        _call_with_timeout(lambda: self.client.run(_worker.cancel_run, self.run_id, on_error="ignore"), 10.0)
        try:
            running = {key for keys in self.client.processing().values() for key in keys}
        except Exception:
            running = set()
        queued = [f for f in self.futures.values() if f.key not in running]
        if queued:
            try:
                self.client.cancel(queued)
            except Exception:  # pragma: no cover
                pass
        deadline = time.monotonic() + grace
        try:
            while self.futures and time.monotonic() < deadline:
                self._drain(min(self.poll_interval, max(0.0, deadline - time.monotonic())))
        except KeyboardInterrupt:
            pass
        except Exception:
            pass
        rest = list(self.futures.values())
        for k in list(self.futures):
            self._forget(k)
        if rest:
            try:
                self.client.cancel(rest)
            except Exception:  # pragma: no cover
                pass


def _call_with_timeout(fn: Callable[[], Any], timeout: float) -> None:
    """fn() in a daemon thread, waited for at most ``timeout`` seconds (a cancel must not hang on
    an unresponsive worker); its errors are ignored."""
    def target():
        try:
            fn()
        except Exception:
            pass
    t = threading.Thread(target=target, name="icoac-dask-cancel", daemon=True)
    t.start()
    t.join(timeout)


def open_backend(spec: DaskSpec | None):
    """Context manager: a DaskSession for ``spec``, or None (the local threaded engine) when spec
    is None."""
    from contextlib import contextmanager

    @contextmanager
    def manager() -> Iterator[DaskSession | None]:
        if spec is None:
            yield None
            return
        with DaskSession(spec) as session:
            yield session
    return manager()
