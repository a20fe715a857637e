# SPDX-License-Identifier: Apache-2.0
"""The results store (icoac.core.store): writes that follow no planted link, one run per output
directory (the lock, a stale one taken over), resume only of cells written by this ABI with the
list of builds kept, write errors that name their file. Each fault is one line
`icoac: error: ...`, exit status 2, nothing on disk rewritten. (Strict parsing of the
command line: tests/python/test_faults.py.)"""
import errno
import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from icoac.core import binding as B
from icoac.studies import conditions
from icoac.core import grid, results, store
from icoac.core.config import build_config
from icoac.core.errors import ResultsError

from test_faults import CELLS, SEED, TINY, TINY_ARGS, assert_one_line_error, main, snapshot, write_partial

REPO = Path(__file__).resolve().parents[2]
GRID = ["--cells", "611", *TINY_ARGS]
# A grid of a few seconds on one thread: long enough to meet a second run while it is running.
SLOW_ARGS = ["--cells", "590-640", "--threads", "1", "--max-trials", "20000", "--success-steps", "5000",
             "--checkpoint-every", "0.2", "--quiet"]


def victim(tmp_path) -> Path:
    v = tmp_path / "victim"
    v.write_text("precious\n")
    return v


def no_temporary_files(d: Path) -> bool:
    return not [p.name for p in d.iterdir() if p.name.endswith(".tmp") and not p.is_symlink()]


# -- writes follow no link -------------------------------------------------------------------------------
@pytest.mark.parametrize("name", ["run.json.tmp", "cells.npz.tmp", "run.json.tmp+cells.npz.tmp"])
def test_planted_temporary_name_link_is_not_followed(capsys, tmp_path, name):
    out = tmp_path / "out"
    out.mkdir()
    v = victim(tmp_path)
    for n in name.split("+"):
        (out / n).symlink_to(v)
    rc, _, err = main(capsys, "grid", "--out", out, *GRID)
    assert rc == 0, err
    assert v.read_text() == "precious\n"
    for n in ("cells.npz", "run.json"):
        assert not (out / n).is_symlink() and (out / n).is_file(), n
    for n in name.split("+"):  # the planted link is left alone, neither followed nor reused
        assert (out / n).is_symlink() and os.readlink(out / n) == str(v)
    cells, record = results.load(out)
    assert record["cells"] == [611] and record["complete"] and cells.size == 1
    assert no_temporary_files(out) and not (out / store.LOCK_FILE).exists()


@pytest.mark.parametrize("name", ["run.json", "cells.npz"])
def test_results_file_that_is_a_link_is_refused_on_resume(capsys, tmp_path, name):
    out = tmp_path / "out"
    rc, _, err = main(capsys, "grid", "--out", out, *GRID)
    assert rc == 0, err
    real = tmp_path / f"real-{name}"
    (out / name).rename(real)
    (out / name).symlink_to(real)
    before, kept = snapshot(out), real.read_bytes()
    rc, _, err = main(capsys, "grid", "--out", out, "--resume", "--quiet")
    assert_one_line_error(rc, err, name, "symbolic link")
    assert snapshot(out) == before and real.read_bytes() == kept


def test_overwrite_replaces_a_link_instead_of_writing_through_it(capsys, tmp_path):
    out = tmp_path / "out"
    rc, _, err = main(capsys, "grid", "--out", out, *GRID)
    assert rc == 0, err
    v = victim(tmp_path)
    (out / "run.json").unlink()
    (out / "run.json").symlink_to(v)
    rc, _, err = main(capsys, "grid", "--out", out, "--overwrite", *GRID)
    assert rc == 0, err
    assert v.read_text() == "precious\n" and not (out / "run.json").is_symlink()
    results.load(out)


def test_lock_file_that_is_a_link_is_refused(capsys, tmp_path):
    out = tmp_path / "out"
    out.mkdir()
    v = victim(tmp_path)
    (out / store.LOCK_FILE).symlink_to(v)
    rc, _, err = main(capsys, "grid", "--out", out, *GRID)
    assert_one_line_error(rc, err, store.LOCK_FILE, "symbolic link")
    assert v.read_text() == "precious\n" and sorted(p.name for p in out.iterdir()) == [store.LOCK_FILE]


def test_write_bytes_replaces_atomically_and_names_the_file_on_error(tmp_path, monkeypatch):
    target = tmp_path / "x.json"
    target.write_text("old")
    store.write_bytes(target, b"new")
    assert target.read_bytes() == b"new" and sorted(p.name for p in tmp_path.iterdir()) == ["x.json"]

    def full(fd, data):
        raise OSError(errno.ENOSPC, "No space left on device")

    monkeypatch.setattr(store.os, "write", full)
    with pytest.raises(ResultsError, match=r"cannot write '.*x\.json': No space left on device"):
        store.write_bytes(target, b"newer")
    assert target.read_bytes() == b"new" and sorted(p.name for p in tmp_path.iterdir()) == ["x.json"]


def test_no_space_left_names_the_file(capsys, tmp_path, monkeypatch):
    """An ENOSPC (no file name in the OSError, as the kernel reports it) at the second checkpoint."""
    real_replace = os.replace
    calls = []

    def replace(src, dst, **kw):
        calls.append(dst)
        if len(calls) > 2:
            raise OSError(errno.ENOSPC, "No space left on device")
        return real_replace(src, dst, **kw)

    monkeypatch.setattr(os, "replace", replace)
    out = tmp_path / "o"
    rc, _, err = main(capsys, "grid", "--out", out, *GRID)
    line = assert_one_line_error(rc, err, "No space left on device")
    assert str(out / "run.json") in line, line  # the commit point of the second checkpoint
    results.load(out)  # the first (all PENDING) save is intact
    assert no_temporary_files(out)


# -- one run per directory ---------------------------------------------------------------------------------
def start_slow(out: Path) -> subprocess.Popen:
    proc = subprocess.Popen([sys.executable, "-m", "icoac", "grid", "--out", str(out), *SLOW_ARGS], cwd=REPO,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    deadline = time.monotonic() + 30
    while not (out / "run.json").exists() and proc.poll() is None and time.monotonic() < deadline:
        time.sleep(0.02)
    assert proc.poll() is None, proc.communicate()
    return proc


def test_second_run_on_a_running_directory_is_refused_then_a_killed_run_is_taken_over(capsys, tmp_path):
    out = tmp_path / "busy"
    proc = start_slow(out)
    try:
        for extra in ([], ["--overwrite"], ["--resume"], ["--seed", "3"]):
            args = ["--resume", "--quiet"] if extra == ["--resume"] else [*SLOW_ARGS, *extra]
            rc, _, err = main(capsys, "grid", "--out", out, *args)
            line = assert_one_line_error(rc, err, "in use by", f"pid {proc.pid}", "grid")
            assert str(out) in line
        assert proc.poll() is None, "the refused runs disturbed the running one"
        holder = json.loads((out / store.LOCK_FILE).read_text())
        assert holder["pid"] == proc.pid and "grid" in holder["command"] and holder["since"]
    finally:
        proc.send_signal(signal.SIGKILL)
        proc.communicate(timeout=30)
    assert (out / store.LOCK_FILE).exists()  # left behind by the killed run: a stale lock
    rc, _, err = main(capsys, "grid", "--out", out, "--resume", "--quiet")
    assert rc == 0, err
    cells, record = results.load(out)
    assert record["complete"] and not (out / store.LOCK_FILE).exists()
    ref = grid.make_cells(0, range(590, 641))
    grid.run_grid(build_config({"max_trials": 20000, "success_steps": 5000}), ref, threads=2, progress=False)
    assert cells.tobytes() == ref.tobytes()


class _Backend:
    """A stand-in for a Dask session: while its grid runs, another run tries the same directory."""

    def __init__(self, out, capsys):
        self.out, self.capsys, self.seen = out, capsys, None

    def nthreads(self):
        return 1

    def describe(self):
        return {"kind": "test"}

    def run_grid(self, cfg, cells, **kw):
        self.seen = main(self.capsys, "grid", "--out", self.out, "--cells", "611", *TINY_ARGS)
        kw.pop("chunk_cells", None)
        return grid.run_grid(cfg, cells, threads=1, **kw)


def test_the_dask_path_holds_the_directory_too(capsys, tmp_path):
    out = tmp_path / "d"
    backend = _Backend(out, capsys)
    cells, record, cancelled = conditions.run_condition(
        condition="ico", out=out, seed=SEED, threads=0, overrides=TINY, cell_spec="610-613", progress=False,
        dask=backend)
    assert not cancelled and record["complete"] and record["backend"] == {"kind": "test"}
    rc, _, err = backend.seen
    assert_one_line_error(rc, err, "in use by", f"pid {os.getpid()}")
    assert not (out / store.LOCK_FILE).exists()


@pytest.mark.parametrize("command", [
    ["grid", *GRID],
    ["bench", "--profile", "quick", "--seeds", "1", "--quiet"],
    ["sweep", "--param", "actor.noise_std=1", "--cells", "611", "--max-trials", "5", "--quiet"],
    ["ceiling", "--w", "0.1,0.07,0.4,0.08", "--cells", "611", "--protocol", "first", "--success-steps", "200",
     "--quiet"],
], ids=lambda c: c[0])
def test_every_command_holds_its_out(capsys, ico_dir, tmp_path, command):
    out = tmp_path / "held"
    extra = ["--prior-from", ico_dir] if command[0] == "sweep" else []
    with store.DirectoryLock(out):
        before = snapshot(out)
        rc, _, err = main(capsys, command[0], "--out", out, *command[1:], *extra)
        assert_one_line_error(rc, err, f"{str(out)!r} is in use by pid {os.getpid()}", "wait for that run to end")
        assert snapshot(out) == before
    assert list(out.iterdir()) == []


# -- resume: the ABI, and the builds that wrote the cells ---------------------------------------------------
@pytest.fixture
def partial(tmp_path):
    """A 4-cell results directory of the current build, two cells finished, two PENDING."""
    return write_partial(tmp_path / "res")


def edit(d: Path, fn) -> None:
    rec = json.loads((d / "run.json").read_text())
    fn(rec)
    (d / "run.json").write_text(json.dumps(rec))


@pytest.mark.parametrize("key, value", [("sizeof_real", 8), ("abi_version", 3), ("sim_abi_version", 1),
                                        ("critic_kernel", "sparse")])
def test_resume_of_another_abi_is_refused(capsys, partial, key, value):
    if B.abi_info()[key] == value:
        value = {"sizeof_real": 4, "critic_kernel": "dense"}.get(key, value)

    edit(partial, lambda rec: rec["abi"].update({key: value}))
    before = snapshot(partial)
    rc, _, err = main(capsys, "grid", "--out", partial, "--resume", "--quiet")
    assert_one_line_error(rc, err, "another ABI", f"{key} {value!r}", f"this library {B.abi_info()[key]!r}")
    assert snapshot(partial) == before


def test_resume_of_a_record_without_abi_is_refused(capsys, partial):
    edit(partial, lambda rec: rec.update(abi=None))
    before = snapshot(partial)
    rc, _, err = main(capsys, "grid", "--out", partial, "--resume", "--quiet")
    assert_one_line_error(rc, err, "abi: None is not of type 'object'")
    assert snapshot(partial) == before


def test_resume_keeps_the_builds_that_wrote_the_cells(capsys, partial):
    old_commit = "0" * 40

    def older(rec):  # another commit of the same ABI wrote the cells so far
        rec["git"] = {"commit": old_commit, "dirty": True}
        rec["abi"]["library"] = "/elsewhere/libicoac_sim.so"
        rec["builds"] = [{"commit": old_commit, "dirty": True, "abi": rec["abi"],
                          "timestamp": "2020-01-01T00:00:00+00:00"}]
    edit(partial, older)
    rc, _, err = main(capsys, "grid", "--out", partial, "--resume", "--quiet")
    assert rc == 0, err
    record = results.load(partial)[1]
    first, second = record["builds"]
    assert first == {"commit": old_commit, "dirty": True, "timestamp": "2020-01-01T00:00:00+00:00",
                     "abi": dict(B.abi_info(), library="/elsewhere/libicoac_sim.so")}
    assert second["commit"] == results.git_info()["commit"] and second["abi"] == B.abi_info()
    assert record["git"] == {"commit": second["commit"], "dirty": second["dirty"]} and record["abi"] == B.abi_info()
    # the list grows with every session that writes cells, and is never replaced (here the cells
    # of an earlier checkpoint beside the last record, as a stop between two writes leaves them)
    cells = results.read_cells(partial / "cells.npz")
    grid.reset_pending(cells, np.arange(cells.size) == 3)
    np.savez(partial / "cells.npz", cells=cells)
    rc, _, err = main(capsys, "grid", "--out", partial, "--resume", "--quiet")
    assert rc == 0, err
    assert results.load(partial)[1]["builds"][:2] == [first, second] and len(results.load(partial)[1]["builds"]) == 3
    # a resume with nothing pending writes nothing
    before = snapshot(partial)
    rc, _, err = main(capsys, "grid", "--out", partial, "--resume", "--quiet")
    assert rc == 0, err
    assert snapshot(partial) == before


def test_old_records_are_refused_in_one_line(ico_dir):
    """Before 1.0 an old record format is refused, never filled in from today's defaults."""
    rec = json.loads((Path(ico_dir) / "run.json").read_text())
    results.check_record(rec)
    with pytest.raises(ResultsError, match=r"run.json: format_version 1 is not 3; this version reads only the records "):
        results.check_record({**rec, "format_version": 1})
    del rec["builds"]  # as every record before the list of builds
    with pytest.raises(ResultsError, match=r"the record: 'builds' is a required property"):
        results.check_record(rec)
