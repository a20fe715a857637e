"""Results directories: cells.npz (structured cell array) + run.json (provenance, config, summary)."""
from __future__ import annotations

import datetime as _dt
import json
import os
import subprocess
from pathlib import Path
from typing import Any, Mapping

import numpy as np

from . import _binding as B
from . import metrics
from .config import RunConfig, config_from_dict

CELLS_FILE = "cells.npz"
RUN_FILE = "run.json"
FORMAT_VERSION = 1


class ResultsError(B.ConfigError):
    """Missing, unreadable or mismatching results directory."""


def git_info(repo: Path = B.REPO_ROOT) -> dict[str, Any]:
    """Commit of the repository and whether the working tree has uncommitted changes."""
    def git(*args: str) -> str | None:
        try:
            res = subprocess.run(["git", "-C", str(repo), *args], capture_output=True, text=True, timeout=10)
        except (OSError, subprocess.SubprocessError):
            return None
        return res.stdout if res.returncode == 0 else None

    commit = git("rev-parse", "HEAD")
    status = git("status", "--porcelain", "--untracked-files=no")
    return {"commit": commit.strip() if commit else None,
            "dirty": bool(status.strip()) if status is not None else None}


def _atomic_write(path: Path, write) -> None:
    tmp = path.with_name(path.name + ".tmp")
    write(tmp)
    os.replace(tmp, path)


def save(out: str | Path, cells: np.ndarray, cfg: RunConfig, *, condition: str, seed: int,
         wall_time: float, threads: int, cell_indices: list[int] | None = None,
         extra: Mapping[str, Any] | None = None) -> dict[str, Any]:
    """Write cells.npz and run.json (atomically, so a checkpoint never leaves half a file)."""
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    summ = metrics.summary(cells)
    record: dict[str, Any] = {
        "format_version": FORMAT_VERSION,
        "condition": condition,
        "seed": int(seed),
        "cells": cell_indices,
        "complete": bool(np.all(cells["outcome"] != B.PENDING)),
        "config": cfg.to_dict(),
        "git": git_info(),
        "abi": B.abi_info(),
        "timestamp": _dt.datetime.now(_dt.timezone.utc).isoformat(timespec="seconds"),
        "wall_time": float(wall_time),
        "threads": int(threads),
        "summary": summ,
    }
    if extra:
        record.update(extra)

    def write_cells(tmp: Path) -> None:
        with open(tmp, "wb") as fh:
            np.savez(fh, cells=cells)

    _atomic_write(out / CELLS_FILE, write_cells)
    _atomic_write(out / RUN_FILE, lambda tmp: tmp.write_text(json.dumps(record, indent=2, sort_keys=False) + "\n"))
    return record


def exists(path: str | Path) -> bool:
    path = Path(path)
    return (path / RUN_FILE).is_file() and (path / CELLS_FILE).is_file()


def load(path: str | Path) -> tuple[np.ndarray, dict[str, Any]]:
    """(cells, run record) of a results directory."""
    path = Path(path)
    if not path.is_dir():
        raise ResultsError(B.SIM_ERR_BAD_ARGUMENT, f"results directory {str(path)!r} does not exist")
    if not exists(path):
        raise ResultsError(B.SIM_ERR_BAD_ARGUMENT,
                           f"{str(path)!r} is not a results directory (needs {CELLS_FILE} and {RUN_FILE})")
    try:
        record = json.loads((path / RUN_FILE).read_text())
        with np.load(path / CELLS_FILE, allow_pickle=False) as data:
            cells = np.ascontiguousarray(data["cells"])
    except (OSError, ValueError, KeyError) as exc:
        raise ResultsError(B.SIM_ERR_BAD_ARGUMENT, f"cannot read results in {str(path)!r}: {exc}")
    if cells.dtype != B.CELL_DTYPE:
        raise ResultsError(B.SIM_ERR_BAD_ARGUMENT,
                           f"{str(path / CELLS_FILE)!r} has a different cell layout than this library")
    return cells, record


def load_config(record: Mapping[str, Any]) -> RunConfig:
    return config_from_dict(record["config"])


def check_resumable(record: Mapping[str, Any], *, condition: str, seed: int, cfg: RunConfig,
                    cell_indices: list[int] | None) -> None:
    """Raise ResultsError naming every difference between a recorded run and the requested one."""
    diffs = []
    if record.get("condition") != condition:
        diffs.append(f"condition {record.get('condition')!r} != {condition!r}")
    if record.get("seed") != seed:
        diffs.append(f"seed {record.get('seed')} != {seed}")
    if record.get("cells") != cell_indices:
        diffs.append("cell selection differs")
    new = cfg.to_dict()
    old = record.get("config", {})
    for group in ("controller", "plant", "run", "prior"):
        a, b = old.get(group), new.get(group)
        if isinstance(a, dict) and isinstance(b, dict):
            for key in sorted(set(a) | set(b)):
                if a.get(key) != b.get(key):
                    diffs.append(f"{key} {a.get(key)!r} != {b.get(key)!r}")
        elif a != b:
            diffs.append(f"{group} differs")
    if diffs:
        raise ResultsError(B.SIM_ERR_BAD_ARGUMENT,
                           "recorded run does not match the requested configuration (" + "; ".join(diffs)
                           + "); use another --out directory")
