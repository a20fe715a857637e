# SPDX-License-Identifier: Apache-2.0
"""Kill tests: a grid run as `python -m icoac grid` is killed (SIGKILL) or interrupted (SIGINT) at
a random moment, resumed with --resume, and must equal an uninterrupted run bitwise, cell by cell.

The delays come from a seeded RNG (ICOAC_KILL_SEED, default 8) as fractions of the measured
uninterrupted wall time, so they land inside the run on a slow or loaded machine too; every
assertion message carries them."""
import math
import os
import random
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from icoac.core import binding as B
from icoac.core import geometry, grid, results
from icoac.core.config import build_config

REPO = Path(__file__).resolve().parents[2]
CELLS = "539-685"          # rows theta0 = -1, 0, +1 deg: 147 cells, about 4 s on 2 threads
CAPS = {"max_trials": 100000, "success_steps": 5000}  # sized for the engine with lanes
GRID_ARGS = ["--cells", CELLS, "--seed", "5", "--threads", "2", "--max-trials", str(CAPS["max_trials"]),
             "--success-steps", str(CAPS["success_steps"]), "--quiet"]
KILL_SEED = int(os.environ.get("ICOAC_KILL_SEED", "8"))


@pytest.fixture(scope="module")
def reference():
    """The uninterrupted run (in-process, same C runner) and its wall time."""
    cells = grid.make_cells(5, grid.parse_cell_indices(CELLS, geometry.CELLS))
    t0 = time.monotonic()
    res = grid.run_grid(build_config(CAPS), cells, threads=2, progress=False)
    assert res.complete
    return cells, time.monotonic() - t0


def harness(*args):
    return [sys.executable, "-m", "icoac", "grid", *map(str, args)]


def start_and_signal(out: Path, sig: int, delay: float, args):
    """Start a grid, wait until its results directory exists, then send sig after delay seconds."""
    proc = subprocess.Popen(harness("--out", out, *args), cwd=REPO, stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True)
    deadline = time.monotonic() + 30
    while not (out / "run.json").exists() and proc.poll() is None and time.monotonic() < deadline:
        time.sleep(0.01)
    time.sleep(delay)
    proc.send_signal(sig)
    stdout, stderr = proc.communicate(timeout=60)
    return proc.returncode, stdout, stderr


def assert_partial_consistent(out: Path, ref: np.ndarray, note: str) -> int:
    """The directory left behind loads, and every finished cell in it equals the reference."""
    cells, record = results.load(out)
    results.check_cells_match(cells, record)
    done = cells["outcome"] != B.PENDING
    assert cells[done].tobytes() == ref[done].tobytes(), note
    assert not cells["trials"][~done].any(), note  # unfinished cells are clean
    return int(done.sum())


def assert_equal_bitwise(out: Path, ref: np.ndarray, note: str) -> None:
    cells, record = results.load(out)
    assert record["complete"], note
    for name in B.CELL_DTYPE.names:
        assert np.array_equal(cells[name], ref[name]), f"{name} differs; {note}"
    assert cells.tobytes() == ref.tobytes(), note


def test_sigkill_twice_then_resume_equals_uninterrupted(tmp_path, reference):
    ref, wall = reference
    rng = random.Random(KILL_SEED)
    d1, d2 = rng.uniform(0.1, 0.8) * wall, rng.uniform(0.05, 0.5) * wall
    out = tmp_path / "k"
    note = f"ICOAC_KILL_SEED={KILL_SEED}: SIGKILL after {d1:.3f} s, then the resume after {d2:.3f} s " \
           f"(uninterrupted run {wall:.2f} s)"
    rc, _, err = start_and_signal(out, signal.SIGKILL, d1, GRID_ARGS)
    assert rc == -signal.SIGKILL, f"{note}; rc {rc}: {err}"
    first = assert_partial_consistent(out, ref, note)
    # Kill the resume too: the checkpoint of a resumed run is as safe as that of a fresh one.
    rc, _, err = start_and_signal(out, signal.SIGKILL, d2, ["--resume", "--quiet"])
    assert rc in (-signal.SIGKILL, 0), f"{note}; rc {rc}: {err}"
    second = assert_partial_consistent(out, ref, note)
    assert second >= first, note
    res = subprocess.run(harness("--out", out, "--resume", "--quiet"), cwd=REPO, capture_output=True, text=True,
                         timeout=120)
    assert res.returncode == 0, f"{note}: {res.stderr}"
    assert_equal_bitwise(out, ref, f"{note}; {first} then {second} cells had been saved")


def test_sigint_exits_130_then_resume_equals_uninterrupted(tmp_path, reference):
    ref, wall = reference
    rng = random.Random(KILL_SEED + 1)
    delay = rng.uniform(0.1, 0.6) * wall
    out = tmp_path / "i"
    note = f"ICOAC_KILL_SEED={KILL_SEED}: SIGINT after {delay:.3f} s (uninterrupted run {wall:.2f} s)"
    rc, _, err = start_and_signal(out, signal.SIGINT, delay, GRID_ARGS)
    assert rc == 130, f"{note}; rc {rc}: {err}"
    assert "Traceback" not in err and "--resume" in err, f"{note}: {err}"
    saved = assert_partial_consistent(out, ref, note)
    cells, _ = results.load(out)
    assert (cells["outcome"] == B.PENDING).any(), note  # interrupted inside the run
    res = subprocess.run(harness("--out", out, "--resume", "--quiet"), cwd=REPO, capture_output=True, text=True,
                         timeout=120)
    assert res.returncode == 0, f"{note}: {res.stderr}"
    assert_equal_bitwise(out, ref, f"{note}; {saved} cells had been saved")


# -- the checkpoint triggers, in-process ------------------------------------------------------------------
def _timed_snapshots():
    snaps = []

    def checkpoint(snap):
        snaps.append((time.monotonic(), int(np.count_nonzero(snap["outcome"] != B.PENDING)), snap))
    return snaps, checkpoint


ROW = list(range(588, 637))  # theta0 = 0: the middle 49 of the reference cells


def test_checkpoint_by_finished_cells(reference):
    ref = reference[0][49:98]
    cells = grid.make_cells(5, ROW)
    snaps, checkpoint = _timed_snapshots()
    grid.run_grid(build_config(CAPS), cells, threads=2, progress=False, checkpoint=checkpoint,
                  checkpoint_cells=8, checkpoint_every=1e4, poll_interval=0.02)
    counts = [n for _, n, _ in snaps]
    assert len(counts) >= 3, counts  # several count-triggered checkpoints, no time trigger
    assert all(b - a >= 8 for a, b in zip([0] + counts, counts)), counts
    assert cells.size - counts[-1] < 8 + 16, counts  # the last one is not far from the end
    for _, _, snap in snaps:
        done = snap["outcome"] != B.PENDING
        assert snap[done].tobytes() == ref[done].tobytes()


def test_checkpoint_by_time():
    """The time trigger: a checkpoint at the first poll at which checkpoint_every seconds have passed
    since the previous one and a cell finished since. Checked poll by poll (each poll's time and
    finished count, from on_progress), so a loaded machine that polls late cannot fail it."""
    every = 0.1
    cells = grid.make_cells(5, ROW)
    snaps, checkpoint = _timed_snapshots()
    polls = []
    t0 = time.monotonic()
    grid.run_grid(build_config(CAPS), cells, threads=2, progress=False, checkpoint=checkpoint,
                  checkpoint_cells=10 ** 6, checkpoint_every=every, poll_interval=0.02,
                  on_progress=lambda c: polls.append((time.monotonic(), int(c[B.PROGRESS_CELLS]))))
    times = [t for t, _, _ in snaps]
    counts = [n for _, n, _ in snaps]
    assert times, "no checkpoint by time"
    assert all(b - a >= every for a, b in zip([t0] + times, times)), times
    assert all(b > a for a, b in zip([0] + counts, counts)), counts  # only when something new finished
    # no poll let a due checkpoint pass: the first poll at which one was due takes it, before the
    # next poll (the margin covers the time from a checkpoint's snapshot to the runner's clock; the
    # last poll, after which the C threads have ended, takes none)
    margin = 0.5
    for (a, n_a), b in zip([(t0, 0)] + list(zip(times, counts)), times + [math.inf]):
        due = [t for t, n in polls[:-1] if a + every + margin <= t < b and n > n_a]
        assert not due or not any(due[0] < t < b for t, _ in polls), (a, b, due[:3])


def test_checkpoint_failure_stops_the_c_threads():
    cells = grid.make_cells(5, ROW)

    def checkpoint(snap):
        raise OSError(28, "No space left on device")

    with pytest.raises(OSError, match="No space"):
        grid.run_grid(build_config(CAPS), cells, threads=2, progress=False, checkpoint=checkpoint,
                      checkpoint_cells=5, poll_interval=0.05)
    before = cells.copy()
    time.sleep(0.5)
    assert cells.tobytes() == before.tobytes()  # nothing runs on in the background
    assert (cells["outcome"] == B.PENDING).any()
