# SPDX-License-Identifier: Apache-2.0
"""A kill between every pair of writes: a grid and a bench run in a forked child that SIGKILLs
itself just before its k-th write (every file the store replaces or removes), for k = 1, 2, ...
until the run ends by itself. After each kill the run is resumed (--resume), and the result must
equal an uninterrupted run's bitwise: every cells.npz, summary.md, and every run.json naming and
summarising the cells beside it."""
import json
import os
import shutil
import signal
import sys
import tempfile
import traceback
from pathlib import Path

import numpy as np
import pytest

from icoac.studies import bench
from icoac import cli
from icoac.core import geometry, metrics, results, store
from icoac.core.registry import CONDITIONS

from conftest import SMALL

GRID_ARGS = ["--cells", "300,610-613,900", "--seed", "3", "--threads", "1", "--checkpoint-cells", "1",
             "--max-trials", str(SMALL["max_trials"]), "--success-steps", str(SMALL["success_steps"]), "--quiet"]
# A bench of one seed on four central cells at small caps: every stage, priors included, in well under a second.
TINY_PROFILE = {"seeds": 1, "ico": dict(SMALL),
                "rl": {"max_trials": 300, "success_steps": 500},
                "cells": lambda plant_grid: [610, 611, 612, 613]}
MAX_WRITES = 400


def _exists(path, dir_fd) -> bool:
    try:
        os.stat(Path(path).name if dir_fd is not None else path, dir_fd=dir_fd, follow_symlinks=False)
        return True
    except FileNotFoundError:
        return False


def run_killed_at(k: int, argv: list[str], log: Path, refused: str | None = None) -> bool:
    """Run the command line ``argv`` in a forked child that SIGKILLs itself just before its k-th
    write (k = 0: never), its output in ``log``; True if it was killed, False if it ended with
    status 0 (or with status 2 and a one-line error containing ``refused``)."""
    sys.stdout.flush()
    sys.stderr.flush()
    pid = os.fork()
    if pid == 0:  # the child: never returns
        status = 99
        try:
            fd = os.open(log, os.O_WRONLY | os.O_CREAT | os.O_TRUNC, 0o644)
            os.dup2(fd, 1)
            os.dup2(fd, 2)
            sys.stdout = sys.stderr = os.fdopen(fd, "w", buffering=1)  # past pytest's capture
            count = [0]
            real_write, real_remove = store.write_bytes, store.remove

            def before_write():
                count[0] += 1
                if count[0] == k:
                    os.kill(os.getpid(), signal.SIGKILL)

            def write_bytes(path, data, dir_fd=None):
                before_write()
                return real_write(path, data, dir_fd)

            def remove(path, dir_fd=None):
                if _exists(path, dir_fd):
                    before_write()
                return real_remove(path, dir_fd)

            store.write_bytes, store.remove = write_bytes, remove
            status = cli.main(argv)
        except BaseException:
            traceback.print_exc()
        finally:
            sys.stderr.flush()
            os._exit(status)
    _, status = os.waitpid(pid, 0)
    if os.WIFSIGNALED(status):
        assert os.WTERMSIG(status) == signal.SIGKILL, status
        return True
    if refused is not None and os.WEXITSTATUS(status) == 2:
        lines = log.read_text().splitlines()
        assert len(lines) == 1 and refused in lines[0], lines
        return False
    assert os.WIFEXITED(status) and os.WEXITSTATUS(status) == 0, \
        f"kill point {k}: exit status {status}: {log.read_text()[-2000:]}"
    return False


def result_dirs(out: Path) -> list[Path]:
    return sorted(p.parent for p in out.rglob(results.RUN_FILE))


def load_all(out: Path) -> dict[Path, np.ndarray]:
    """{directory relative to out: cells} of every results directory of ``out``, each checked to be
    named and summarised by the run.json beside it."""
    found = {}
    for d in result_dirs(out):
        cells, _ = results.load(d)
        raw = json.loads((d / results.RUN_FILE).read_text())
        assert raw["cells_sha256"] == results.cells_digest(cells) and raw["complete"], d
        plant = geometry.of(results.record_plant(raw))
        assert json.loads(json.dumps(metrics.summary(cells, plant))) == raw["summary"], d
        found[d.relative_to(out)] = cells
    return found


def assert_same_results(out: Path, ref: dict[Path, np.ndarray], note: str) -> None:
    """Every results directory of ``out`` equals the reference's cell by cell (load_all)."""
    found = load_all(out)
    assert sorted(found) == sorted(ref), note
    for d, cells in found.items():
        assert cells.tobytes() == ref[d].tobytes(), f"{note}: {d}"


def kill_at_every_write(tmp_path: Path, argv: list[str], resume: list[str], ref, check) -> int:
    """For every write k of the run: kill it there, resume, check; returns the number of kill points."""
    for k in range(1, MAX_WRITES):
        out = tmp_path / f"k{k}"
        log = tmp_path / f"k{k}.log"
        if not run_killed_at(k, [*argv[:1], "--out", str(out), *argv[1:]], log):
            return k - 1
        if not (out / results.RUN_FILE).exists() and argv[0] == "grid":
            # killed before its first write: --resume has no settings to resume, and says so
            run_killed_at(0, [*resume[:1], "--out", str(out), *resume[1:]], log, "run the command without --resume")
            assert not run_killed_at(0, [*argv[:1], "--out", str(out), *argv[1:]], log)
        else:
            assert not run_killed_at(0, [*resume[:1], "--out", str(out), *resume[1:]], log), f"resume after {k}"
        check(out, ref, f"killed before write {k}")
    pytest.fail(f"the run wrote more than {MAX_WRITES} times")


@pytest.fixture
def fast_tmp(tmp_path):
    """A directory in memory when the machine has one (every write here is fsynced), else tmp_path."""
    shm = Path("/dev/shm")
    if not (shm.is_dir() and os.access(shm, os.W_OK)):
        yield tmp_path
        return
    d = Path(tempfile.mkdtemp(prefix="icoac-kill-", dir=shm))
    yield d
    shutil.rmtree(d, ignore_errors=True)


def test_grid_killed_at_every_write_resumes_to_the_same_cells(fast_tmp):
    ref = fast_tmp / "ref"
    assert not run_killed_at(0, ["grid", "--out", str(ref), *GRID_ARGS], fast_tmp / "ref.log")
    points = kill_at_every_write(fast_tmp, ["grid", *GRID_ARGS], ["grid", "--resume", "--quiet"], load_all(ref),
                                 assert_same_results)
    print(f"grid: {points} kill points, each resumed to the uninterrupted cells")
    assert points >= 6  # the first record and cells, checkpoints, the last record and cells


@pytest.fixture
def tiny_bench(monkeypatch):
    monkeypatch.setitem(bench.PROFILES, "quick", TINY_PROFILE)


def test_bench_killed_at_every_write_resumes_to_the_same_results(fast_tmp, tiny_bench):
    argv = ["bench", "--profile", "quick", "--quiet"]
    ref = fast_tmp / "ref"
    assert not run_killed_at(0, [argv[0], "--out", str(ref), *argv[1:]], fast_tmp / "ref.log")
    ref_cells, ref_summary = load_all(ref), (ref / "summary.md").read_text()
    assert len(ref_cells) == len(CONDITIONS)

    def same_bench(out: Path, ref, note: str) -> None:
        assert_same_results(out, ref, note)
        assert (out / "summary.md").read_text() == ref_summary, note
        assert json.loads((out / "bench.json").read_text())["complete"], note

    points = kill_at_every_write(fast_tmp, argv, [*argv, "--resume"], ref_cells, same_bench)
    print(f"bench: {points} kill points, each resumed to the uninterrupted results")
    assert points >= len(CONDITIONS) * 4
