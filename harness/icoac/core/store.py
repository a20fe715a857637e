# SPDX-License-Identifier: Apache-2.0
"""The results store: every file the harness writes into an output directory - cells.npz and
run.json of a results directory, and the JSON, CSV and Markdown files of bench, sweep and
ceiling - is written here, and every "the recorded settings must match" check of a resumed
directory is made here.

Writes follow no symbolic link. A file is replaced atomically: its bytes go to a temporary file
this module creates under a fresh random name in the same directory (``O_CREAT | O_EXCL |
O_NOFOLLOW``, so no existing name is ever opened, a planted link included), are fsynced, and
the temporary file is renamed over the target, which replaces a link at the target's name
rather than writing through it. A reader (or a kill) sees the old file or the new one. An I/O
error (no space, read-only file system, ...) is a ResultsError naming the file.

A run holds its output directory for its whole duration: an exclusive ``flock`` on
``DIR/.icoac.lock`` (DirectoryLock), which records the holder's pid, host, start time and
command line. A second run on the same directory is refused with one line naming the holder.
The kernel drops the lock of a process that dies, so the lock file a killed run leaves behind
is simply locked again by the next run; a run that ends removes it.

ResultsStore is one results directory held by one grid run (icoac.studies.conditions.run_condition,
for the threaded and the Dask backend alike; Dask workers write nothing): it reads the existing
results without following links, refuses to resume cells written by a library of another ABI
(versions, real size, critic kernel), keeps the list of builds that wrote the cells
(``builds`` of run.json, one entry appended per session) and writes the checkpoints.
"""
from __future__ import annotations

import errno
import fcntl
import io
import json
import os
import secrets
import shlex
import socket
import stat
import sys
import tempfile
from pathlib import Path
from typing import Any, Mapping

import numpy as np

from icoac.core import binding as B
from icoac.core import results
from icoac.core.config import RunConfig, config_from_dict, plant_params
from icoac.core.errors import ResultsError, UsageError
from icoac.core.grid import make_cells

LOCK_FILE = ".icoac.lock"
# What a resumed run must share with the build that wrote the cells: anything else changes the
# cells a configuration gives (the critic kernel rounds V differently) or their layout.
ABI_KEYS = ("abi_version", "sim_abi_version", "sizeof_real", "critic_kernel")
_TEMP_ATTEMPTS = 16


# -- output directories --------------------------------------------------------------------------------
def check_out_dir(out: str | Path, what: str = "--out") -> Path:
    """An output directory path that is not a file (it may not exist yet); nothing is created."""
    out = Path(out)
    if out.exists() and not out.is_dir():
        raise ResultsError(f"{what} {str(out)!r} exists and is not a directory")
    return out


def check_writable(out: str | Path, what: str = "--out") -> Path:
    """Create the directory ``out`` if needed and prove it is writable by creating (and removing) a
    temporary file in it; any failure is a ResultsError. Permission bits alone are not enough:
    they do not apply to root, and a read-only mount or a path under a regular file must fail too."""
    out = check_out_dir(out, what)
    try:
        out.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise ResultsError(f"{what}: cannot create directory {str(out)!r}: {exc.strerror or exc}") from None
    if not os.access(out, os.W_OK | os.X_OK):
        raise ResultsError(f"{what}: directory {str(out)!r} is not writable")
    try:
        fd, probe = tempfile.mkstemp(prefix=".icoac-write-test-", dir=out)
        os.close(fd)
        os.unlink(probe)
    except OSError as exc:
        raise ResultsError(f"{what}: directory {str(out)!r} is not writable: {exc.strerror or exc}") from None
    return out


def _open_dir(directory: Path) -> int:
    try:
        return os.open(directory, os.O_RDONLY | os.O_DIRECTORY | os.O_CLOEXEC)
    except OSError as exc:
        raise ResultsError(f"cannot open directory {str(directory)!r}: {exc.strerror or exc}") from None


# -- writing files -----------------------------------------------------------------------------------
def write_bytes(path: str | Path, data: bytes, dir_fd: int | None = None) -> None:
    """Replace the file ``path`` by ``data`` atomically, following no link (module docstring).
    ``dir_fd``: an open descriptor of path's directory (a held directory), used instead of its
    path. ResultsError naming the file on any I/O error; no temporary file is left behind."""
    path = Path(path)
    own = dir_fd is None
    if own:
        dir_fd = _open_dir(path.parent)
    tmp = None
    try:
        for _ in range(_TEMP_ATTEMPTS):
            name = f".{path.name}.{secrets.token_hex(8)}.tmp"
            try:
                fd = os.open(name, os.O_WRONLY | os.O_CREAT | os.O_EXCL | os.O_NOFOLLOW | os.O_CLOEXEC, 0o666,
                             dir_fd=dir_fd)
            except FileExistsError:
                continue
            tmp = name
            break
        else:
            raise OSError(errno.EEXIST, "no free temporary name")
        try:
            view = memoryview(data)
            while view:
                view = view[os.write(fd, view):]
            os.fsync(fd)
        finally:
            os.close(fd)
        os.replace(tmp, path.name, src_dir_fd=dir_fd, dst_dir_fd=dir_fd)
        tmp = None
        try:
            os.fsync(dir_fd)  # the rename itself survives a crash
        except OSError as exc:
            if exc.errno not in (errno.EINVAL, errno.EBADF):
                raise
    except OSError as exc:
        raise ResultsError(f"cannot write {str(path)!r}: {exc.strerror or exc}") from None
    finally:
        if tmp is not None:
            try:
                os.unlink(tmp, dir_fd=dir_fd)
            except OSError:
                pass
        if own:
            os.close(dir_fd)


def write_text(path: str | Path, text: str, dir_fd: int | None = None) -> None:
    write_bytes(path, text.encode(), dir_fd)


def write_json(path: str | Path, data: Any, indent: int = 2, dir_fd: int | None = None) -> None:
    write_text(path, json.dumps(data, indent=indent) + "\n", dir_fd)


def remove(path: str | Path, dir_fd: int | None = None) -> None:
    """Remove the file (or link) ``path`` if it exists; ResultsError naming it otherwise."""
    path = Path(path)
    try:
        os.unlink(path.name if dir_fd is not None else path, dir_fd=dir_fd)
    except FileNotFoundError:
        pass
    except OSError as exc:
        raise ResultsError(f"cannot remove {str(path)!r}: {exc.strerror or exc}") from None


# -- the lock of a directory ---------------------------------------------------------------------------
def command_line() -> str:
    """This process's command, as the user typed it for the harness."""
    argv = list(sys.argv)
    if argv and Path(argv[0]).name == "__main__.py" and Path(argv[0]).parent.name == "icoac":
        return shlex.join(["python", "-m", "icoac", *argv[1:]])
    return shlex.join(argv)


class DirectoryLock:
    """An output directory held by this process (module docstring): ``with DirectoryLock(out):``.
    Acquiring creates the directory if needed and proves it writable (check_writable); a
    directory held by another run is a ResultsError naming the holder. ``dir_fd`` is a
    descriptor of the held directory, for writes into it."""

    def __init__(self, directory: str | Path, what: str = "--out"):
        self.directory = Path(directory)
        self.what = what
        self.path = self.directory / LOCK_FILE
        self.fd: int | None = None
        self.dir_fd: int | None = None

    def __enter__(self) -> "DirectoryLock":
        return self.acquire()

    def __exit__(self, *exc) -> None:
        self.release()

    def acquire(self) -> "DirectoryLock":
        check_writable(self.directory, self.what)
        dir_fd = _open_dir(self.directory)
        try:
            self.fd = self._lock(dir_fd)
        except BaseException:
            os.close(dir_fd)
            raise
        self.dir_fd = dir_fd
        info = {"pid": os.getpid(), "host": socket.gethostname(),
                "since": results.timestamp(), "command": command_line()}
        data = (json.dumps(info) + "\n").encode()
        try:
            os.ftruncate(self.fd, 0)
            os.pwrite(self.fd, data, 0)
        except OSError as exc:
            self.release()
            raise ResultsError(f"cannot write the lock file {str(self.path)!r}: {exc.strerror or exc}") from None
        return self

    def _lock(self, dir_fd: int) -> int:
        while True:
            try:
                fd = os.open(LOCK_FILE, os.O_RDWR | os.O_CREAT | os.O_NOFOLLOW | os.O_CLOEXEC, 0o644, dir_fd=dir_fd)
            except OSError as exc:
                why = "it is a symbolic link" if exc.errno == errno.ELOOP else exc.strerror or str(exc)
                raise ResultsError(f"cannot open the lock file {str(self.path)!r}: {why}") from None
            try:
                mine = os.fstat(fd)
                if not stat.S_ISREG(mine.st_mode):
                    raise ResultsError(f"the lock file {str(self.path)!r} is not a regular file")
                try:
                    fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
                except BlockingIOError:
                    raise ResultsError(f"{str(self.directory)!r} is in use by {self._holder(fd)}; wait for that "
                                       f"run to end, or use another {self.what}") from None
                except OSError as exc:
                    raise ResultsError(f"cannot lock {str(self.path)!r}: {exc.strerror or exc}") from None
                try:  # a run that ended removed the file we opened: lock the one at the name now
                    now = os.stat(LOCK_FILE, dir_fd=dir_fd, follow_symlinks=False)
                except FileNotFoundError:
                    now = None
                if now is not None and (now.st_dev, now.st_ino) == (mine.st_dev, mine.st_ino):
                    return fd
            except BaseException:
                os.close(fd)
                raise
            os.close(fd)

    @staticmethod
    def _holder(fd: int) -> str:
        try:
            info = json.loads(os.pread(fd, 4096, 0) or b"null")
            return (f"pid {int(info['pid'])} on {info['host']} ({info['command']}) since {info['since']}")
        except (OSError, ValueError, TypeError, KeyError):
            return "another run (it has not recorded itself yet)"

    def release(self) -> None:
        if self.fd is None:
            return
        try:  # remove the file while holding it (see _lock), unless it is no longer ours
            now = os.stat(LOCK_FILE, dir_fd=self.dir_fd, follow_symlinks=False)
            mine = os.fstat(self.fd)
            if (now.st_dev, now.st_ino) == (mine.st_dev, mine.st_ino):
                os.unlink(LOCK_FILE, dir_fd=self.dir_fd)
        except OSError:
            pass
        finally:
            os.close(self.fd)
            os.close(self.dir_fd)
            self.fd = self.dir_fd = None


# -- "the recorded settings must match" ----------------------------------------------------------------
def check_same_settings(recorded: Any, requested: Mapping[str, Any], directory: Path, kind: str) -> None:
    """UsageError unless the settings a directory's record holds equal the requested ones, naming
    the keys that differ (``kind``: what the directory holds, e.g. "a sweep")."""
    old = recorded if isinstance(recorded, Mapping) else {}
    diff = [k for k in requested if old.get(k) != requested[k]]
    if diff or not isinstance(recorded, Mapping):
        raise UsageError(f"{str(directory)!r} holds {kind} with other {', '.join(diff) or 'settings'}; "
                         "use another --out")


def check_build(record: Mapping[str, Any], where: str = results.RUN_FILE) -> None:
    """ResultsError unless the cells of a record were written by a library of this library's ABI
    (ABI_KEYS of its ``abi``); a resumed run adds cells to them."""
    abi = record.get("abi")
    if not isinstance(abi, Mapping):
        raise ResultsError(f"{where} records no library ABI, so nothing says which build wrote its cells")
    mine = B.abi_info()
    diff = [f"{k} {abi.get(k, 'not recorded')!r}, this library {mine[k]!r}" for k in ABI_KEYS if abi.get(k) != mine[k]]
    if diff:
        raise ResultsError(f"{where} was written by a library of another ABI ({'; '.join(diff)}); its cells "
                           "cannot be continued by this one")


def check_resumable(record: Mapping[str, Any], *, condition: str, seed: int, cfg: RunConfig,
                    cell_indices: list[int] | None) -> None:
    """ResultsError naming every difference between a recorded run and the requested one."""
    diffs = []
    if record.get("condition") != condition:
        diffs.append(f"condition {record.get('condition')!r} != {condition!r}")
    if record.get("seed") != seed:
        diffs.append(f"seed {record.get('seed')} != {seed}")
    if record.get("cells") != cell_indices:
        diffs.append("cell selection differs")
    new = cfg.flat()
    try:
        old_cfg = config_from_dict(record["config"])
    except B.ConfigError as exc:
        raise ResultsError(f"recorded configuration: {exc}") from None
    old = old_cfg.flat()
    if old_cfg.plant_name != cfg.plant_name:  # another plant: its name says it, not its parameters
        diffs.append(f"plant name {old_cfg.plant_name!r} != {cfg.plant_name!r}")
        old, new = ({k: v for k, v in d.items() if k not in plant_params(c.plant_name)}
                    for d, c in ((old, old_cfg), (new, cfg)))
    own = plant_params(cfg.plant_name)
    diffs += [f"{'plant ' if key in own else ''}{key} {old[key]!r} != {new[key]!r}" for key in new if old[key] != new[key]]
    if old_cfg.to_dict()["prior"] != cfg.to_dict()["prior"]:
        diffs.append("prior differs")
    if diffs:
        raise ResultsError("recorded run does not match the requested configuration (" + "; ".join(diffs)
                           + "); use another --out directory")


# -- results directories -------------------------------------------------------------------------------
class ResultsStore:
    """One results directory (cells.npz + run.json) held by one run::

        with ResultsStore(out) as store:
            cells, record, stale = store.load()   # existing results, if any
            store.begin(record, fresh=False, git=results.git_info())
            store.save(cells, cfg, condition=..., seed=..., wall_time=..., threads=...)

    The commit point of a checkpoint is run.json, which names the content hash of its cells
    (results.cells_digest): save writes run.json, then cells.npz, and begin(fresh=True) removes
    cells.npz, then run.json. So cells.npz never exists without a run.json of the same run, and a
    run stopped between two writes leaves a record of that run beside its cells of the checkpoint
    before (or none yet): load(repair=True) takes those cells, which the resumed run continues
    and commits. ``start_over`` is the hint a refused directory's message gives."""

    def __init__(self, out: str | Path, what: str = "--out", start_over: str = "rerun with --overwrite"):
        self.out = check_out_dir(out, what)
        self.start_over = start_over
        self.lock = DirectoryLock(self.out, what)
        self.builds: list[dict[str, Any]] | None = None

    def __enter__(self) -> "ResultsStore":
        self.lock.acquire()
        return self

    def __exit__(self, *exc) -> None:
        self.lock.release()

    def present(self) -> list[str]:
        return results.present(self.out)

    def load(self, repair: bool = False) -> tuple[np.ndarray, dict[str, Any], bool]:
        """(cells, record, stale) of the directory: validated (results.load, no link followed) and
        written by a library of this ABI (check_build); UsageError with the start-over hint
        otherwise. A record that does not name the cells beside it (a run stopped between two
        writes, results.StaleRecord), or that has no cells yet, is refused unless ``repair``: then
        the cells are those on disk (or the record's selection, all pending) and ``stale`` is True,
        so that the caller commits them."""
        run_file = self.out / results.RUN_FILE
        try:
            try:
                if self.present() == [results.RUN_FILE]:
                    raise results.StaleRecord(f"{str(self.out)!r} holds {results.RUN_FILE} but no "
                                              f"{results.CELLS_FILE} (the run stopped before writing its cells); "
                                              "resume it with --resume")
                cells, record = results.load(self.out, follow=False)
                stale = False
            except results.StaleRecord:
                if not repair:
                    raise
                cells, record = self._repaired()
                stale = True
            check_build(record, repr(str(run_file)))
        except ResultsError as exc:
            raise UsageError(f"{exc} ({self.start_over} to discard these results and start over)") from None
        return cells, record, stale

    def _repaired(self) -> tuple[np.ndarray, dict[str, Any]]:
        """The record and the cells of a run stopped between two writes (see the class)."""
        record = results.read_record(self.out / results.RUN_FILE, follow=False)
        plant = results.record_plant(record)
        cells_file = self.out / results.CELLS_FILE
        if results.CELLS_FILE in self.present():
            cells = results.read_cells(cells_file, follow=False)
            results.check_cells(cells, repr(str(cells_file)), plant)
            results.check_cells_match(cells, record, repr(str(cells_file)))
        else:
            cells = make_cells(record["seed"], record["cells"], plant=plant)
        return cells, results.with_summary(record, cells)

    def begin(self, previous: Mapping[str, Any] | None, *, fresh: bool, git: Mapping[str, Any]) -> None:
        """Start this session's writes: ``fresh`` removes the results first (cells.npz first; see
        the class); the builds of the run are those of ``previous`` (the record resumed, if any)
        and this one."""
        if fresh:
            for name in (results.CELLS_FILE, results.RUN_FILE):
                remove(self.out / name, self.lock.dir_fd)
        self.builds = (results.recorded_builds(previous) if previous is not None else []) + [results.build_entry(git)]

    def save(self, cells: np.ndarray, cfg: RunConfig, **fields) -> dict[str, Any]:
        """Commit a checkpoint: run.json (results.make_record of ``fields``, naming the cells' hash),
        then cells.npz; returns the record."""
        if self.builds is None:
            raise RuntimeError("ResultsStore.save before begin")
        record = results.make_record(cells, cfg, builds=self.builds, **fields)
        buf = io.BytesIO()
        np.savez(buf, cells=cells)
        write_text(self.out / results.RUN_FILE, json.dumps(record, indent=2) + "\n", self.lock.dir_fd)
        write_bytes(self.out / results.CELLS_FILE, buf.getvalue(), self.lock.dir_fd)
        return record


def save(out: str | Path, cells: np.ndarray, cfg: RunConfig, *, git: Mapping[str, Any] | None = None,
         **fields) -> dict[str, Any]:
    """Write a results directory in one go (a new run of ``cells``; ``fields`` as make_record)."""
    with ResultsStore(out) as store:
        store.begin(None, fresh=False, git=results.git_info() if git is None else git)
        return store.save(cells, cfg, **fields)
