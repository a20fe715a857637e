# SPDX-License-Identifier: Apache-2.0
"""Results directories: cells.npz (structured cell array) + run.json (provenance, config, summary).

run.json names the content hash of the cells it describes (``cells_sha256``, cells_digest). The
results store writes run.json first and cells.npz second, so a run stopped between the two leaves
a record that does not name its cells: reading such a directory is refused (StaleRecord) and a
resumed run repairs it (store.ResultsStore.load). The summary of a record is recomputed from the
cells it sits beside whenever a directory is read."""
from __future__ import annotations

import datetime as _dt
import errno
import hashlib
import json
import os
import subprocess
import zipfile
from pathlib import Path
from typing import Any, Mapping

import numpy as np

from icoac.core import binding as B
from icoac.core import geometry, metrics
from icoac.core.schema import FORMAT_VERSION, check_run_record
from icoac.core.config import CART_POLE, RunConfig, config_from_dict
from icoac.core.errors import ResultsError
from icoac.core.grid import make_cells, parse_cell_indices

CELLS_FILE = "cells.npz"
RUN_FILE = "run.json"
MAX_JSON_BYTES = 16 * 2 ** 20   # run.json is a few KiB; refuse anything absurd before parsing


def _err(message: str) -> ResultsError:
    return ResultsError(message)


class StaleRecord(ResultsError):
    """run.json does not describe the cells beside it: the run that wrote them stopped between its
    two writes. Resuming the run repairs it."""


# What runs themselves write into the tree: `make bench`'s data and figures (Makefile BENCH_DATA
# and BENCH_FIGURES) and `make fuzz`'s ledger. A change there does not change what the tree
# computes, so it does not make the tree dirty; otherwise every plant after the first of
# `make bench BENCH_PLANTS=all` would be, and every grid started while a fuzzing run appends.
RUN_OUTPUTS = ("docs/data", "docs/figures", "tests/fuzz/ledger")


def git_info(repo: Path = B.REPO_ROOT) -> dict[str, Any]:
    """Commit of the repository and whether the working tree has uncommitted changes (but in
    RUN_OUTPUTS). For an
    installed package (repo = its site-packages), the commit its wheel was built from, as the
    build recorded it (harness/icoac/lib/build_info.json); None for both when unknown: a directory
    that is not the top of a git work tree is not taken for the repository around it."""
    if Path(repo) == B.REPO_ROOT and B.BUILD_INFO.is_file():
        try:
            info = json.loads(B.BUILD_INFO.read_text())
            return {"commit": info.get("commit"), "dirty": info.get("dirty")}
        except (OSError, ValueError, AttributeError):
            return {"commit": None, "dirty": None}

    def git(*args: str) -> str | None:
        try:
            res = subprocess.run(["git", "-C", str(repo), *args], capture_output=True, text=True, timeout=10)
        except (OSError, subprocess.SubprocessError):
            return None
        return res.stdout if res.returncode == 0 else None

    top = git("rev-parse", "--show-toplevel")
    if top is None or Path(top.strip()).resolve() != Path(repo).resolve():
        return {"commit": None, "dirty": None}
    commit = git("rev-parse", "HEAD")
    status = git("status", "--porcelain", "--untracked-files=no", "--", ".",
                 *(f":(exclude){path}" for path in RUN_OUTPUTS))
    return {"commit": commit.strip() if commit else None,
            "dirty": bool(status.strip()) if status is not None else None}


def timestamp() -> str:
    """Now, in UTC, to the second (ISO 8601): the time stamps of the records."""
    return _dt.datetime.now(_dt.timezone.utc).isoformat(timespec="seconds")


def build_entry(git: Mapping[str, Any]) -> dict[str, Any]:
    """The entry of ``builds`` (see make_record) describing this process: the commit it runs from
    (git_info()), the library's ABI and the time."""
    return {"commit": git.get("commit"), "dirty": git.get("dirty"), "abi": B.abi_info(),
            "timestamp": timestamp()}


def recorded_builds(record: Mapping[str, Any]) -> list[dict[str, Any]]:
    """The ``builds`` of a run record."""
    return [dict(b) for b in record["builds"]]


def cells_digest(cells: np.ndarray) -> str:
    """The content hash of a cell array: SHA-256 over its fields' bytes in order (padding excluded)."""
    digest = hashlib.sha256()
    for name in cells.dtype.names:
        digest.update(np.ascontiguousarray(cells[name]).tobytes())
    return digest.hexdigest()


def make_record(cells: np.ndarray, cfg: RunConfig, *, condition: str, seed: int, wall_time: float, threads: int,
                builds: list[Mapping[str, Any]], cell_indices: list[int] | None = None,
                extra: Mapping[str, Any] | None = None) -> dict[str, Any]:
    """The run record (run.json) of ``cells``. ``builds`` lists every build that wrote cells of this
    run, oldest first (one entry per session: build_entry); ``git`` and ``abi`` repeat the last."""
    last = builds[-1]
    record: dict[str, Any] = {
        "format_version": FORMAT_VERSION,
        "condition": condition,
        "seed": int(seed),
        "cells": cell_indices,
        "cells_sha256": cells_digest(cells),
        "complete": bool(np.all(cells["outcome"] != B.PENDING)),
        "config": cfg.to_dict(),
        "git": {"commit": last.get("commit"), "dirty": last.get("dirty")},
        "abi": last.get("abi"),
        "builds": [dict(b) for b in builds],
        "timestamp": timestamp(),
        "wall_time": float(wall_time),
        "threads": int(threads),
        "summary": metrics.summary(cells, geometry.of(cfg.plant_name)),
    }
    if extra:
        record.update(extra)
    return record


def exists(path: str | Path) -> bool:
    path = Path(path)
    return (path / RUN_FILE).is_file() and (path / CELLS_FILE).is_file()


def present(path: str | Path) -> list[str]:
    """Which of the two results files are in path (a partial directory has exactly one)."""
    path = Path(path)
    return [name for name in (CELLS_FILE, RUN_FILE) if (path / name).is_file()]


def open_file(file: Path, follow: bool = True):
    """``file`` opened for reading in binary; with ``follow`` False a symbolic link is refused
    (O_NOFOLLOW) rather than read through. OSError as open() raises it."""
    if follow:
        return open(file, "rb")
    try:
        fd = os.open(file, os.O_RDONLY | os.O_CLOEXEC | os.O_NOFOLLOW)
    except OSError as exc:
        if exc.errno == errno.ELOOP and file.is_symlink():
            raise _err(f"{str(file)!r} is a symbolic link; the results of a directory that is written are "
                       "never read or written through a link (replace it with the file)") from None
        raise
    return os.fdopen(fd, "rb")


def read_cells(file: str | Path, follow: bool = True) -> np.ndarray:
    """The cell array of a cells.npz, read without trusting it: one member ``cells.npy`` whose
    header says a 1-D CELL_DTYPE array of at most geometry.MAX_CELLS cells and whose size matches.
    Anything else (truncated, empty, not a zip, other dtype or shape) raises ResultsError, and
    so does a symbolic link unless ``follow``."""
    file = Path(file)
    where = repr(str(file))
    try:
        with open_file(file, follow) as raw, zipfile.ZipFile(raw) as zf:
            names = zf.namelist()
            if names != ["cells.npy"]:
                raise _err(f"{where} is not a cells file (members {names[:4]!r:.80}, expected ['cells.npy'])")
            info = zf.getinfo("cells.npy")
            with zf.open(info) as fh:
                version = np.lib.format.read_magic(fh)
                if version == (1, 0):
                    shape, fortran, dtype = np.lib.format.read_array_header_1_0(fh)
                elif version == (2, 0):
                    shape, fortran, dtype = np.lib.format.read_array_header_2_0(fh)
                else:
                    raise _err(f"{where}: unsupported .npy version {version}")
                layout = B.CELL_DTYPE
                if dtype != layout:
                    raise _err(f"{where} has a different cell layout than this library "
                               f"({_dtype_difference(dtype)}); it was written by another version")
                if len(shape) != 1 or not 1 <= shape[0] <= geometry.MAX_CELLS:
                    raise _err(f"{where}: expected 1 to {geometry.MAX_CELLS} cells, got shape {shape}")
                nbytes = shape[0] * layout.itemsize
                if info.file_size != fh.tell() + nbytes:
                    raise _err(f"{where}: size {info.file_size} does not match its header ({shape[0]} cells)")
                data = fh.read(nbytes + 1)
            if len(data) != nbytes:
                raise _err(f"{where} is truncated")
    except ResultsError:
        raise
    except zipfile.BadZipFile as exc:
        raise _err(f"{where} is not a valid cells file (truncated or corrupt: {exc})") from None
    except OSError as exc:
        raise _err(f"cannot read {where}: {exc.strerror or exc}") from None
    except Exception as exc:  # any other decoding failure of untrusted bytes: zlib, EOF, header syntax
        raise _err(f"{where} is not a valid cells file ({type(exc).__name__}: {str(exc):.100})") from None
    return np.frombuffer(data, dtype=layout).copy()


def _dtype_difference(dtype: np.dtype) -> str:
    """First difference between a stored dtype and CELL_DTYPE, in words."""
    want = B.CELL_DTYPE
    if dtype.names is None:
        return f"plain {dtype.str} array, not cell records"
    if dtype.names != want.names:
        extra = [n for n in dtype.names if n not in want.names]
        missing = [n for n in want.names if n not in dtype.names]
        if extra or missing:
            return (f"fields {', '.join(missing)} missing" if missing else "") + \
                   ("; " if extra and missing else "") + (f"unknown fields {', '.join(extra)}" if extra else "")
        return "fields in another order"
    for name in want.names:
        if dtype.fields[name][0] != want.fields[name][0]:
            return f"field {name} is {dtype.fields[name][0]}, expected {want.fields[name][0]}"
        if dtype.fields[name][1] != want.fields[name][1]:
            return f"field {name} at offset {dtype.fields[name][1]}, expected {want.fields[name][1]}"
    return f"record size {dtype.itemsize}, expected {want.itemsize}"


def record_plant(record: Mapping[str, Any]) -> str:
    """The plant a run record names (the cart-pole when it names none, as every record before the
    registry plants)."""
    plant = record.get("config", {}).get("plant") if isinstance(record.get("config"), Mapping) else None
    name = plant.get("name", CART_POLE) if isinstance(plant, Mapping) else CART_POLE
    return name if isinstance(name, str) else CART_POLE


def check_cells(cells: np.ndarray, where: str = "cells", plant: str = CART_POLE) -> None:
    """Structural checks of a cell array: known outcomes, counts and elapsed times finite and >= 0,
    finite coordinates on the plant's grid."""
    bad = ~np.isin(cells["outcome"], list(B.OUTCOME_NAMES))
    if bad.any():
        i = int(np.flatnonzero(bad)[0])
        raise _err(f"{where}: cell {i} has unknown outcome {int(cells['outcome'][i])} "
                   f"(valid: {', '.join(f'{k} {v}' for k, v in B.OUTCOME_NAMES.items())})")
    for name in ("trials", "total_steps", "last_trial_steps", "elapsed_time"):
        bad = ~(np.isfinite(cells[name]) & (cells[name] >= 0))
        if bad.any():
            i = int(np.flatnonzero(bad)[0])
            raise _err(f"{where}: cell {i} has {name} = {cells[name][i].item()!r}, which must be finite and >= 0")
    try:
        on_grid = geometry.of(plant).on_grid(cells)
    except B.ConfigError:
        raise _err(f"{where}: the record names the plant {plant!r:.40}, which the registry does not hold") from None
    if not on_grid.all():
        i = int(np.flatnonzero(~on_grid)[0])
        grid_name = "the paper grid" if plant == CART_POLE else f"the {plant} grid"
        raise _err(f"{where}: cell {i} has x0 = {float(cells['x0'][i])!r}, theta0 = {float(cells['theta0'][i])!r}, "
                   f"not a point of {grid_name}")


def check_record(record: Any, where: str = RUN_FILE) -> dict[str, Any]:
    """A run record (a run.json) checked against the schema (icoac.core.schema), its cell selection
    parsed and its configuration accepted by the C library. Returns the record; raises
    ResultsError naming the first problem."""
    check_run_record(record, where)
    cells = record["cells"]
    if cells is not None:
        try:
            parsed = parse_cell_indices(cells, geometry.of(record_plant(record)).cells)
        except B.ConfigError as exc:
            raise _err(f"{where}: cells: {exc}") from None
        if parsed != cells:
            raise _err(f"{where}: cells must be sorted and unique")
    try:
        config_from_dict(record["config"])
    except B.ConfigError as exc:
        raise _err(f"{where}: config: {exc}") from None
    return record


def read_json(file: str | Path, lead: str = "", follow: bool = True) -> Any:
    """A JSON file of the harness (at most MAX_JSON_BYTES), parsed; ResultsError, prefixed with
    ``lead``, if it cannot be read or parsed, or (unless ``follow``) if it is a symbolic link."""
    file = Path(file)
    where = repr(str(file))
    try:
        with open_file(file, follow) as fh:
            if os.fstat(fh.fileno()).st_size > MAX_JSON_BYTES:
                raise _err(f"{lead}{where} is larger than {MAX_JSON_BYTES} bytes")
            return json.loads(fh.read(MAX_JSON_BYTES + 1))
    except ResultsError:
        raise
    except OSError as exc:
        raise _err(f"{lead}cannot read {where}: {exc.strerror or exc}") from None
    except (ValueError, RecursionError) as exc:  # JSONDecodeError, UnicodeDecodeError, nesting
        raise _err(f"{lead}{where} is not valid JSON ({str(exc):.100})") from None


def read_record(file: str | Path, follow: bool = True) -> dict[str, Any]:
    """A run.json, parsed and checked (check_record)."""
    return check_record(read_json(file, follow=follow), repr(str(file)))


def check_results_dir(path: str | Path, what: str | None = None) -> Path:
    """A directory holding both results files; ResultsError (prefixed with ``what``, e.g. the
    option that named it) if it does not exist, is not a directory or lacks a file."""
    path = Path(path)
    lead = f"{what}: " if what else ""
    if not path.exists():
        raise _err(f"{lead}results directory {str(path)!r} does not exist")
    if not path.is_dir():
        raise _err(f"{lead}results directory {str(path)!r} does not exist (it is not a directory)")
    have = present(path)
    if len(have) != 2:
        detail = f"; it holds only {have[0]}" if have else ""
        raise _err(f"{lead}{str(path)!r} is not a results directory (needs {CELLS_FILE} and {RUN_FILE}{detail})")
    return path


def load(path: str | Path, what: str | None = None, follow: bool = True) -> tuple[np.ndarray, dict[str, Any]]:
    """(cells, run record) of a results directory, both validated (check_results_dir, read_cells,
    check_cells, read_record, check_cells_match) and the record naming these cells (StaleRecord
    otherwise); its summary and completeness are recomputed from the cells. Every failure is a
    ResultsError. ``follow`` False: a results file that is a symbolic link is refused (the
    results store reads the directory it writes so)."""
    path = check_results_dir(path, what)
    record = read_record(path / RUN_FILE, follow)
    cells = read_cells(path / CELLS_FILE, follow)
    check_cells(cells, repr(str(path / CELLS_FILE)), record_plant(record))
    check_cells_match(cells, record, repr(str(path / CELLS_FILE)))
    if record["cells_sha256"] != cells_digest(cells):
        lead = f"{what}: " if what else ""
        raise StaleRecord(f"{lead}{str(path / RUN_FILE)!r} does not describe the cells beside it (the run that wrote "
                          "them stopped between its two writes); resume that run with --resume to complete it")
    return cells, with_summary(record, cells)


def with_summary(record: Mapping[str, Any], cells: np.ndarray) -> dict[str, Any]:
    """``record`` with its summary and completeness recomputed from ``cells``."""
    return {**record, "complete": bool(np.all(cells["outcome"] != B.PENDING)),
            "summary": metrics.summary(cells, geometry.of(record_plant(record)))}


def check_cells_match(cells: np.ndarray, record: Mapping[str, Any], where: str = CELLS_FILE) -> None:
    """The cells of a results directory are exactly those its record describes: the number of cells
    and every (x0, theta0, seed) equal make_cells(record seed, record cells), bitwise."""
    expected = make_cells(record["seed"], record["cells"], plant=record_plant(record))
    if cells.size != expected.size:
        raise _err(f"{where} holds {cells.size} cells but run.json describes {expected.size} "
                   "(cell selection and seed); the two files do not belong together")
    for name in ("x0", "theta0", "seed"):
        diff = cells[name] != expected[name]
        if diff.any():
            i = int(np.flatnonzero(diff)[0])
            raise _err(f"{where}: cell {i} has {name} {cells[name][i].item()!r} but run.json's cell selection and "
                       f"seed give {expected[name][i].item()!r}; the two files do not belong together")


def load_config(record: Mapping[str, Any]) -> RunConfig:
    return config_from_dict(record["config"])
