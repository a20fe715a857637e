# SPDX-License-Identifier: Apache-2.0
"""The Dask backend (icoac.cluster.backend): a LocalCluster on loopback (2 worker processes, 1 thread
each) gives the threaded engine's cells, bitwise, for every condition family, also when a worker
is killed mid-chunk and through cancel and resume; workers that cannot load the library say so.

One cluster serves the module (DaskSpec(workers=2), the `--workers 2` path); the --scheduler path
connects to it by address. Caps are small, so the whole module takes a few tens of seconds."""
import os
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path

import numpy as np
import pytest

from icoac.core import binding as B
from icoac.cluster import worker as _worker, backend as cluster
from icoac import cli
from icoac.core import geometry, grid, results
from icoac.studies import prior as P
from icoac.studies.conditions import condition_prior, run_condition
from icoac.core.config import build_config
from icoac.core.errors import WorkerError
from icoac.core.registry import REGISTRY

from conftest import SMALL

pytestmark = pytest.mark.dask

REPO = Path(__file__).resolve().parents[2]
ICO_CAPS = {"max_trials": 3000, "success_steps": 2000}
RL_CAPS = {"max_trials": 20, "success_steps": 500}
# Rows theta0 = 0 and +1 deg around the centre, two corner cells that fail, an edge cell.
CELLS = [0, 48, 606, 608, 610, 611, 612, 613, 614, 616, 657, 659, 661, 1224]
CELL_SPEC = grid.format_cell_indices(CELLS)


# A slower grid for the kill, cancel and Ctrl-C tests (rows theta0 = -1, 0, +1 deg; a few seconds on
# 2 threads), so that an interruption lands inside the run on a fast machine too.
SLOW_CAPS = {"max_trials": 100000, "success_steps": 5000}  # about 3 s threaded (engine with lanes)
SLOW_SEED = 5
SLOW_SPEC = "560-679"
SLOW_CELLS = grid.parse_cell_indices(SLOW_SPEC, geometry.CELLS)


@pytest.fixture(scope="module")
def slow_ref():
    """The threaded run of the slow grid."""
    cells = grid.make_cells(SLOW_SEED, SLOW_CELLS)
    assert grid.run_grid(build_config(SLOW_CAPS), cells, threads=2, progress=False).complete
    return cells


@pytest.fixture(scope="module")
def session():
    with cluster.DaskSession(cluster.DaskSpec(workers=2, threads_per_worker=1)) as s:
        yield s


def threaded(cfg, seed, indices):
    cells = grid.make_cells(seed, indices)
    res = grid.run_grid(cfg, cells, threads=2, progress=False)
    assert res.complete
    return cells


def assert_same(a: np.ndarray, b: np.ndarray, note: str = "") -> None:
    for name in B.CELL_DTYPE.names:
        assert np.array_equal(a[name], b[name]), f"{name} differs {note}"
    assert a.tobytes() == b.tobytes(), note


def test_session_checked_every_worker(session):
    assert len(session.workers) == 2 and session.nthreads() == 2
    for address, info in session.workers.items():
        assert address in info["worker"] and info["library"] == str(B.LIBRARY_PATH)
        assert info["abi"] == _worker.abi_of(B)
    assert session.describe()["kind"] == "dask" and session.describe()["local_workers"] == 2


@pytest.mark.parametrize("condition", ["ico", "ico-rl", "rl", "ico-search"])
def test_condition_same_cells_npz_as_threads(session, ico_dir, tmp_path, condition):
    """run_condition with the Dask session writes the cells.npz of the threaded engine."""
    caps = SMALL if condition == "ico" else RL_CAPS
    takes_ico = REGISTRY[condition].prior is not None and REGISTRY[condition].prior.takes_ico
    info = condition_prior(condition, ico_dir if takes_ico else None, P.DEFAULT_FRAME, P.DEFAULT_RIDGE)
    common = dict(condition=condition, seed=3, overrides=caps, cell_spec=CELL_SPEC, progress=False, info=info)
    ref, ref_record, _ = run_condition(out=tmp_path / "threads", threads=2, **common)
    got, record, cancelled = run_condition(out=tmp_path / "dask", threads=0, dask=session, **common)
    assert not cancelled and record["complete"]
    assert_same(got, ref, condition)
    on_disk, _ = results.load(tmp_path / "dask")
    assert_same(on_disk, results.load(tmp_path / "threads")[0], condition)
    assert record["backend"]["kind"] == "dask" and record["threads"] == 2
    assert "backend" not in ref_record  # the threaded record is unchanged
    assert record["summary"] == ref_record["summary"]


@pytest.mark.parametrize("plant,condition", [("furuta", "ico"), ("double_cart_pole", "search")])
def test_other_plants_same_cells_npz_as_threads(session, tmp_path, plant, condition):
    """A chunk carries the plant's model: a grid of another plant on the cluster is the threaded one."""
    info = condition_prior(condition, None, P.DEFAULT_FRAME, P.DEFAULT_RIDGE, plant=plant)
    common = dict(condition=condition, seed=2, overrides={"max_trials": 40, "success_steps": 300}, cell_spec="600-611",
                  progress=False, plant=plant, info=info)
    ref, ref_record, _ = run_condition(out=tmp_path / "threads", threads=2, **common)
    got, record, cancelled = run_condition(out=tmp_path / "dask", threads=0, dask=session, **common)
    assert not cancelled and record["complete"] and results.record_plant(record) == plant
    assert (ref["outcome"] != B.PENDING).all()
    assert_same(got, ref, plant)
    assert record["summary"] == ref_record["summary"]


def test_chunk_sizes_and_scheduler_address_give_the_same_cells(session):
    cfg = build_config(ICO_CAPS)
    ref = threaded(cfg, 4, CELLS)
    with cluster.DaskSession(cluster.DaskSpec(scheduler=session.address, chunk_cells=5)) as other:
        assert other.nthreads() == 2
        for size in (None, 1, 3, len(CELLS)):
            cells = grid.make_cells(4, CELLS)
            res = other.run_grid(cfg, cells, progress=False, chunk_cells=size)
            assert res.complete and not res.cancelled
            assert_same(cells, ref, f"chunk_cells {size}")


def test_resume_skips_finished_cells(session):
    """Finished cells are not sent again (a resume); the rest equals the threaded run."""
    cfg = build_config(ICO_CAPS)
    ref = threaded(cfg, 4, CELLS)
    cells = grid.make_cells(4, CELLS)
    cells[:5] = ref[:5]
    cells["trials"][5:] = 99  # stale results of PENDING cells are cleared, as by run_grid
    res = session.run_grid(cfg, cells, progress=False, chunk_cells=2)
    assert res.complete
    assert_same(cells, ref)


def test_killed_worker_costs_a_rerun_of_its_chunk(session, slow_ref):
    """SIGKILL of a worker while it runs a chunk (and others are pending): the chunk is rerun
    elsewhere (or on the restarted worker) and the grid equals the threaded one."""
    cfg = build_config(SLOW_CAPS)
    pids = session.client.run(os.getpid)
    killed = {}

    def checkpoint(snap):  # the first merged chunk: kill a worker that is running another one
        if killed:
            return
        running = {w: keys for w, keys in session.client.processing().items() if keys}
        if not running:
            return
        victim = sorted(running)[0]
        killed.update(address=victim, pid=pids[victim], keys=list(running[victim]),
                      pending=int(np.count_nonzero(snap["outcome"] == B.PENDING)))
        os.kill(pids[victim], signal.SIGKILL)

    cells = grid.make_cells(SLOW_SEED, SLOW_CELLS)
    res = session.run_grid(cfg, cells, progress=False, chunk_cells=4, checkpoint=checkpoint, checkpoint_cells=1)
    assert killed, "no worker was running a chunk at any checkpoint"
    assert killed["pending"] > 0
    assert res.complete and not res.cancelled
    assert_same(cells, slow_ref, f"after killing {killed}")
    deadline = time.monotonic() + 30  # the nanny restarts the worker: the next tests have two again
    while session.nthreads() < 2 and time.monotonic() < deadline:
        time.sleep(0.1)
    assert pids[killed["address"]] not in session.client.run(os.getpid).values()


def test_cancel_then_resume_equals_uninterrupted(session, slow_ref):
    """cancel_event during a run: merged chunks saved (checkpoints hold only final cells), the
    rest PENDING and clean; a resume through the Dask backend gives the threaded cells."""
    cfg = build_config(SLOW_CAPS)
    ref = slow_ref
    stop = threading.Event()
    snaps = []

    def checkpoint(snap):
        snaps.append(snap)
        stop.set()

    cells = grid.make_cells(SLOW_SEED, SLOW_CELLS)
    res = session.run_grid(cfg, cells, progress=False, chunk_cells=2, checkpoint=checkpoint,
                           checkpoint_cells=1, cancel_event=stop)
    assert res.cancelled and res.status == B.SIM_CANCELLED
    pending = cells["outcome"] == B.PENDING
    assert pending.any() and (~pending).any()
    assert not cells["trials"][pending].any()
    assert_same(cells[~pending], ref[~pending])
    for snap in snaps:
        done = snap["outcome"] != B.PENDING
        assert_same(snap[done], ref[done])
    res = session.run_grid(cfg, cells, progress=False)
    assert res.complete
    assert_same(cells, ref)


def test_cancel_after_through_run_condition_and_resume(session, tmp_path, slow_ref):
    common = dict(condition="ico", seed=SLOW_SEED, threads=0, overrides=SLOW_CAPS, cell_spec=SLOW_SPEC,
                  progress=False)
    ref = slow_ref
    # The first finished cell comes later on a slow or loaded machine: widen the deadline until a
    # cancelled run has kept some cells (each try starts a fresh directory).
    for n, after in enumerate((1.0, 2.0, 4.0, 8.0, 16.0)):
        out = tmp_path / f"c{n}"
        common["out"] = out
        cells, record, cancelled = run_condition(dask=session, cancel_after=after, checkpoint_cells=1, **common)
        saved, _ = results.load(out)
        done = saved["outcome"] != B.PENDING
        if cancelled and done.any():
            break
    assert cancelled and not record["complete"], f"not cancelled after {after} s"
    assert done.any() and not done.all(), f"cancel after {after} s kept {np.count_nonzero(done)} cells"
    assert_same(saved[done], ref[done])
    cells, record, cancelled = run_condition(dask=session, resume=True, **common)
    assert not cancelled and record["complete"]
    assert_same(results.load(out)[0], ref)


def test_worker_without_the_library_is_a_clear_error(tmp_path):
    """A worker whose ICOAC_SIM_LIBRARY names no file: WorkerError naming the worker and the path."""
    from distributed import LocalCluster
    missing = tmp_path / "no" / "libicoac_sim.so"
    with LocalCluster(n_workers=1, threads_per_worker=1, processes=True, host="127.0.0.1", dashboard_address=None,
                      scheduler_kwargs={"dashboard": False, "dashboard_address": "127.0.0.1:0"},
                      env={"ICOAC_SIM_LIBRARY": str(missing)}) as lc:
        t0 = time.monotonic()
        with pytest.raises(WorkerError) as err:
            with cluster.DaskSession(cluster.DaskSpec(scheduler=lc.scheduler_address)):
                pass
        assert time.monotonic() - t0 < 30
    text = str(err.value)
    assert "Dask worker tcp://127.0.0.1:" in text and str(missing) in text and "not found" in text, text


def test_abi_mismatch_names_the_difference():
    expected = {**_worker.abi_of(B), "abi_version": 999}
    with pytest.raises(WorkerError, match=rf"abi_version {B.ABI_VERSION} != client's 999"):
        _worker.check_worker(expected)
    assert _worker.check_worker(_worker.abi_of(B))["library"] == str(B.LIBRARY_PATH)


def test_c_error_on_a_worker_comes_back_as_the_same_exception(session):
    """A configuration the C check rejects, sent past the client's check: the worker's ConfigError
    (status and C message) reaches the client as it is, after the task's retries."""
    cfg = build_config(SMALL)
    cfg.controller.mode = 99
    with pytest.raises(B.ConfigError) as want:
        cfg.check()
    cfg_bytes = _worker.config_bytes(cfg)
    fut = session.client.submit(_worker.run_chunk, "test-error", 0, cfg_bytes, grid.make_cells(0, [611]),
                                _worker.abi_of(B), pure=False, retries=1)
    exc = fut.exception(timeout=30)
    assert type(exc) is B.ConfigError and exc.status == want.value.status and str(exc) == str(want.value)


def test_sweep_on_the_cluster_equals_threads(session, ico_dir, tmp_path):
    from icoac.studies import sweep
    common = dict(prior_from=ico_dir, params=["actor.noise_std=0.5,2"], cells="608-614", max_trials=20,
                  success_steps=500, quiet=True)
    assert sweep.run_sweep(sweep.SweepOptions(out=tmp_path / "t", threads=2, **common)) == 0
    assert sweep.run_sweep(sweep.SweepOptions(out=tmp_path / "d", dask=cluster.DaskSpec(scheduler=session.address),
                                              **common)) == 0

    def rows(d):
        lines = (d / "sweep.csv").read_text().splitlines()
        col = lines[0].split(",").index("wall_time")
        return [",".join(v for i, v in enumerate(line.split(",")) if i != col) for line in lines]
    assert rows(tmp_path / "d") == rows(tmp_path / "t")


# -- the command line --------------------------------------------------------------------------------
def harness(*args):
    return [sys.executable, "-m", "icoac", *map(str, args)]


@pytest.mark.parametrize("args, words", [
    (["--workers", "2", "--threads", "2"], "--threads sets the local engine"),
    (["--chunk-cells", "4"], "--chunk-cells applies to the Dask backend"),
    (["--threads-per-worker", "2"], "--threads-per-worker applies to the Dask backend"),
    (["--scheduler", "tcp://127.0.0.1:1", "--threads-per-worker", "2"], "applies to --workers N"),
    (["--scheduler", "tcp://127.0.0.1:1", "--workers", "2"], "not allowed with argument"),
    (["--workers", "0"], "a number of workers"),
    (["--workers", "1", "--chunk-cells", "0"], "--chunk-cells"),
])
def test_cli_backend_options_rejected(tmp_path, capsys, args, words):
    assert cli.main(["grid", "--out", str(tmp_path / "x"), *args]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("icoac: error: ") and words in err[0], err
    assert not (tmp_path / "x").exists()


def test_cli_unreachable_scheduler_is_one_line(tmp_path, capsys, monkeypatch):
    import socket
    with socket.socket() as s:  # a loopback port nobody listens on
        s.bind(("127.0.0.1", 0))
        port = s.getsockname()[1]
    monkeypatch.setattr(cluster, "DASK_CONNECT_TIMEOUT", 2.0)
    assert cli.main(["grid", "--out", str(tmp_path / "x"), "--cells", "611", "--scheduler",
                     f"tcp://127.0.0.1:{port}", "--quiet"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert err[-1].startswith("icoac: error: cannot reach the Dask scheduler at tcp://127.0.0.1:"), err


def test_cli_sigint_to_the_process_group_then_resume(tmp_path, slow_ref):
    """`grid --workers 2` and Ctrl-C as a terminal sends it (SIGINT to the whole process group,
    workers included): exit 130 without a traceback, finished cells saved; `--resume` (threaded
    here, the results do not depend on the backend) finishes with the threaded engine's cells."""
    out = tmp_path / "g"
    ref = slow_ref
    args = ["grid", "--out", out, "--cells", SLOW_SPEC, "--seed", SLOW_SEED, "--max-trials", SLOW_CAPS["max_trials"],
            "--success-steps", SLOW_CAPS["success_steps"], "--workers", 2, "--chunk-cells", 2,
            "--checkpoint-cells", 1, "--quiet"]
    proc = subprocess.Popen(harness(*args), cwd=REPO, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            start_new_session=True)
    deadline = time.monotonic() + 60
    saved = 0
    while proc.poll() is None and time.monotonic() < deadline and saved == 0:
        time.sleep(0.05)
        try:
            saved = int(np.count_nonzero(results.load(out)[0]["outcome"] != B.PENDING))
        except Exception:
            saved = 0
    assert proc.poll() is None, proc.communicate()
    os.killpg(proc.pid, signal.SIGINT)
    stdout, stderr = proc.communicate(timeout=60)
    assert proc.returncode == 130, stderr
    assert "Traceback" not in stderr and "--resume" in stderr, stderr
    cells, record = results.load(out)
    done = cells["outcome"] != B.PENDING
    assert done.sum() >= saved and not done.all()
    assert_same(cells[done], ref[done])
    res = subprocess.run(harness("grid", "--out", out, "--resume", "--quiet"), cwd=REPO, capture_output=True,
                         text=True, timeout=120)
    assert res.returncode == 0, res.stderr
    assert_same(results.load(out)[0], ref)


def test_bench_on_the_cluster_equals_threads(session, tmp_path):
    """Every grid of a bench (one seed, the quick profile's cells, small caps) on the cluster:
    each results directory holds the threaded bench's cells; bench.json records the backend."""
    from icoac.studies import bench
    from icoac.core.registry import CONDITIONS
    common = dict(profile="quick", seeds=1, seed=1, rl_max_trials=10, sets=["success_steps=1000"], quiet=True)
    assert bench.run_bench(bench.BenchOptions(out=tmp_path / "t", threads=2, **common)) == 0
    assert bench.run_bench(bench.BenchOptions(out=tmp_path / "d", dask=cluster.DaskSpec(scheduler=session.address),
                                              **common)) == 0
    for condition in CONDITIONS:
        got = results.load(bench.seed_dir(tmp_path / "d", condition, 1))[0]
        assert_same(got, results.load(bench.seed_dir(tmp_path / "t", condition, 1))[0], condition)
    import json
    meta = json.loads((tmp_path / "d" / "bench.json").read_text())["meta"]
    assert meta["backend"]["kind"] == "dask" and meta["backend"]["threads"] == 2
