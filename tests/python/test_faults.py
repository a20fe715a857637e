# SPDX-License-Identifier: Apache-2.0
"""Every harness fault is one line `icoac: error: ...` on stderr, exit status 2, and nothing
on disk is rewritten. The CLI runs in-process through icoac.cli.main."""
import errno
import json
import shutil
import tempfile
import time
import tracemalloc
from pathlib import Path

import numpy as np
import pytest

from icoac.core import binding as B
from icoac import cli
from icoac.core import grid, metrics, results, store
from icoac.core.config import build_config

CELLS = [610, 611, 612, 613]
SEED = 3
TINY = {"max_trials": 50, "success_steps": 200}
TINY_ARGS = ["--max-trials", "50", "--success-steps", "200", "--quiet"]


def main(capsys, *args):
    rc = cli.main([str(a) for a in args])
    out, err = capsys.readouterr()
    return rc, out, err


def assert_one_line_error(rc, err, *words):
    assert rc == 2, err
    assert "Traceback" not in err
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("icoac: error: "), err
    for w in words:
        assert w in lines[0], lines[0]
    return lines[0]


def snapshot(root: Path) -> dict:
    """Every file under root with its bytes and modification time (a rewrite with equal bytes counts)."""
    if not root.exists():
        return {}
    return {str(p.relative_to(root)): (p.read_bytes(), p.stat().st_mtime_ns) if p.is_file() else None
            for p in sorted(root.rglob("*"))}


def write_partial(out: Path) -> Path:
    """A 4-cell results directory at out, two cells finished and two PENDING (a resume would run them)."""
    cfg = build_config(TINY)
    cells = grid.make_cells(SEED, CELLS)
    grid.run_grid(cfg, cells, threads=2, progress=False)
    grid.reset_pending(cells, np.arange(cells.size) >= 2)
    store.save(out, cells, cfg, condition="ico", seed=SEED, wall_time=0.5, threads=2, cell_indices=CELLS)
    return out


@pytest.fixture(scope="module")
def partial_dir(tmp_path_factory):
    return write_partial(tmp_path_factory.mktemp("partial") / "res")


@pytest.fixture
def res(partial_dir, tmp_path):
    d = tmp_path / "res"
    shutil.copytree(partial_dir, d)
    return d


def load_cells(d):
    with np.load(d / "cells.npz") as z:
        return z["cells"]


def save_cells(d, cells):
    np.savez(d / "cells.npz", cells=cells)


def edit_record(d, fn):
    rec = json.loads((d / "run.json").read_text())
    rec = fn(rec)
    (d / "run.json").write_text(json.dumps(rec))


def _set(path, value):
    def fn(rec):
        node = rec
        for k in path[:-1]:
            node = node[k]
        node[path[-1]] = value
        return rec
    return fn


def _del(key):
    def fn(rec):
        del rec[key]
        return rec
    return fn


def _del_in(path, key):
    def fn(rec):
        node = rec
        for k in path:
            node = node[k]
        del node[key]
        return rec
    return fn


def _cells_edit(fn):
    def apply(d):
        c = load_cells(d)
        c = fn(c)
        save_cells(d, c)
    return apply


def _x0_nan(c):
    c["x0"][1] = np.nan
    return c


def _outcome(c):
    c["outcome"][0] = 7
    return c


def _field(name, value):
    def fn(c):
        c[name][2] = value
        return c
    return fn


def _other_dtype(c):
    d = [(n, c.dtype[n]) for n in c.dtype.names]
    d[3] = ("outcome", "<i8")
    return c.astype(d)


CORRUPTIONS = {
    "truncated cells.npz": (lambda d: (d / "cells.npz").write_bytes((d / "cells.npz").read_bytes()[:700]),
                            ["cells.npz", "not a valid cells file"]),
    "empty cells.npz": (lambda d: (d / "cells.npz").write_bytes(b""), ["cells.npz", "not a valid cells file"]),
    "cut inside the data": (lambda d: (d / "cells.npz").write_bytes((d / "cells.npz").read_bytes()[:-30]),
                            ["cells.npz"]),
    "cells.npz not a zip": (lambda d: (d / "cells.npz").write_bytes(b"\x93NUMPY garbage"), ["cells.npz"]),
    "run.json [1,2]": (lambda d: (d / "run.json").write_text("[1, 2]"), ["run.json", "[1, 2] is not of type 'object'"]),
    "run.json {}": (lambda d: (d / "run.json").write_text("{}"), ["run.json", "format_version None is not 3"]),
    "run.json not JSON": (lambda d: (d / "run.json").write_text('{"seed": '), ["run.json", "not valid JSON"]),
    "run.json config 5": (lambda d: edit_record(d, _set(["config"], 5)), ["config: 5 is not of type 'object'"]),
    "run.json controller 5": (lambda d: edit_record(d, _set(["config", "controller"], 5)), ["controller"]),
    "run.json no seed": (lambda d: edit_record(d, _del("seed")), ["'seed' is a required property"]),
    "run.json no config": (lambda d: edit_record(d, _del("config")), ["'config' is a required property"]),
    "run.json seed 2^64": (lambda d: edit_record(d, _set(["seed"], 2 ** 64)), ["seed"]),
    "run.json seed string": (lambda d: edit_record(d, _set(["seed"], "3")), ["seed"]),
    "run.json cells out of range": (lambda d: edit_record(d, _set(["cells"], [5000])), ["cells", "5000"]),
    "run.json bad condition": (lambda d: edit_record(d, _set(["condition"], "pid")), ["condition"]),
    "run.json gain -1": (lambda d: edit_record(d, _set(["config", "controller", "gain"], -1)), ["gain"]),
    "run.json dt NaN": (lambda d: edit_record(d, _set(["config", "plant", "dt"], float("nan"))), ["dt"]),
    "run.json wall_time string": (lambda d: edit_record(d, _set(["wall_time"], "x")), ["wall_time"]),
    "run.json without a group": (lambda d: edit_record(d, _del_in(["config"], "run")), ["config: 'run' is a required"]),
    "run.json empty config": (lambda d: edit_record(d, _set(["config"], {})), ["config: 'controller' is a required"]),
    "run.json without a field": (lambda d: edit_record(d, _del_in(["config", "run"], "max_trials")),
                                 ["config.run: 'max_trials' is a required"]),
    "run.json unknown field": (lambda d: edit_record(d, _set(["config", "run", "max_trails"], 3)),
                               ["config.run: Additional properties are not allowed ('max_trails'"]),
    "NaN cell coordinate": (_cells_edit(_x0_nan), ["cell 1", "x0 = nan"]),
    "unknown outcome": (_cells_edit(_outcome), ["unknown outcome 7"]),
    "negative trials": (_cells_edit(_field("trials", -3)), ["cell 2 has trials = -3"]),
    "negative elapsed time": (_cells_edit(_field("elapsed_time", -1.0)), ["cell 2 has elapsed_time = -1.0"]),
    "NaN elapsed time": (_cells_edit(_field("elapsed_time", np.nan)), ["cell 2 has elapsed_time = nan"]),
    "other dtype": (_cells_edit(_other_dtype), ["different cell layout"]),
}


@pytest.mark.parametrize("name", list(CORRUPTIONS))
def test_resume_of_corrupt_results_refused_nothing_written(capsys, res, name):
    corrupt, words = CORRUPTIONS[name]
    corrupt(res)
    before = snapshot(res)
    rc, _, err = main(capsys, "grid", "--out", res, "--resume", "--quiet")
    assert_one_line_error(rc, err, *words)
    assert snapshot(res) == before
    # The same directory given with explicit (matching) settings, as a plain `grid`, fails alike.
    rc, _, err = main(capsys, "grid", "--out", res, "--cells", "610-613", "--seed", SEED, *TINY_ARGS)
    assert_one_line_error(rc, err)
    assert snapshot(res) == before


@pytest.mark.parametrize("name", list(CORRUPTIONS))
def test_figures_of_corrupt_results_refused(capsys, res, tmp_path, name):
    corrupt, words = CORRUPTIONS[name]
    corrupt(res)
    rc, _, err = main(capsys, "figures", "--results", res, "--out", tmp_path / "fig")
    assert_one_line_error(rc, err, *words)
    assert not (tmp_path / "fig").exists()


@pytest.mark.parametrize("make, words", [
    (lambda: grid.make_cells(SEED, range(10)), ["holds 10 cells", "describes 4"]),
    (lambda: grid.make_cells(SEED), ["holds 1225 cells"]),
    (lambda: grid.make_cells(SEED, [0, 1, 2, 3]), ["cell 0 has x0"]),
    (lambda: grid.make_cells(SEED + 1, CELLS), ["cell 0 has seed"]),
])
def test_resume_checks_number_and_coordinates_of_cells(capsys, res, make, words):
    save_cells(res, make())
    before = snapshot(res)
    rc, _, err = main(capsys, "grid", "--out", res, "--resume", "--quiet")
    assert_one_line_error(rc, err, *words, "do not belong together")
    assert snapshot(res) == before


def test_resume_with_other_settings_writes_nothing(capsys, res):
    before = snapshot(res)
    rc, _, err = main(capsys, "grid", "--out", res, "--cells", "610-613", "--seed", SEED, "--set", "policy.gain=5",
                      *TINY_ARGS)
    assert_one_line_error(rc, err, "does not match", "gain")
    assert snapshot(res) == before


def test_c_failure_during_resume_leaves_files_intact(capsys, res, monkeypatch):
    calls = []

    def failing_run_grid(*args):
        calls.append(args)
        return B.SIM_ERR_THREAD

    monkeypatch.setattr(B.lib, "icoac_sim_run_grid", failing_run_grid)
    before = snapshot(res)
    rc, _, err = main(capsys, "grid", "--out", res, "--resume", "--quiet")
    assert calls, "the C runner was not reached"
    assert_one_line_error(rc, err, B.status_str(B.SIM_ERR_THREAD))
    assert snapshot(res) == before


def test_resume_then_succeeds_and_keeps_finished_cells(capsys, res):
    old = load_cells(res)
    rc, _, err = main(capsys, "grid", "--out", res, "--resume", "--quiet")
    assert rc == 0, err
    new = load_cells(res)
    assert np.all(new["outcome"] != B.PENDING)
    assert new[:2].tobytes() == old[:2].tobytes()
    ref = grid.make_cells(SEED, CELLS)
    grid.run_grid(build_config(TINY), ref, threads=1, progress=False)
    assert new.tobytes() == ref.tobytes()


# -- one of the two files missing ----------------------------------------------------------------------
@pytest.mark.parametrize("keep", ["cells.npz", "run.json"])
def test_lone_results_file_is_not_replaced(capsys, res, keep):
    """A lone cells.npz is never left by a run (run.json is written first): it is refused, resume
    included. A lone run.json is what a run stopped before its first cells leaves: a new run is
    refused, and --resume runs the recorded cells."""
    (res / ({"cells.npz", "run.json"} - {keep}).pop()).unlink()
    before = snapshot(res)
    rc, _, err = main(capsys, "grid", "--out", res, "--cells", "610-613", "--seed", SEED, *TINY_ARGS)
    assert_one_line_error(rc, err, keep, "--overwrite")
    assert snapshot(res) == before
    rc, _, err = main(capsys, "grid", "--out", res, "--resume", "--quiet")
    if keep == "cells.npz":
        assert_one_line_error(rc, err, keep, "no run leaves behind")
        assert snapshot(res) == before
    else:
        assert rc == 0, err
        ref = grid.make_cells(SEED, CELLS)
        grid.run_grid(build_config(TINY), ref, threads=1, progress=False)
        assert results.load(res)[0].tobytes() == ref.tobytes()
    # told to start over: a complete new result
    rc, _, err = main(capsys, "grid", "--out", res, "--cells", "611", "--seed", 9, "--overwrite", *TINY_ARGS)
    assert rc == 0, err
    cells, record = results.load(res)
    assert record["cells"] == [611] and record["seed"] == 9 and record["complete"]
    assert cells.size == 1


def test_overwrite_replaces_complete_results_after_checks(capsys, res):
    before = snapshot(res)
    rc, _, err = main(capsys, "grid", "--out", res, "--overwrite", "--set", "policy.gain=-1", *TINY_ARGS)
    assert_one_line_error(rc, err, "gain")
    assert snapshot(res) == before  # a bad configuration deletes nothing
    rc, _, err = main(capsys, "grid", "--out", res, "--cells", "612", "--overwrite", *TINY_ARGS)
    assert rc == 0, err
    assert results.load(res)[1]["cells"] == [612]


def test_overwrite_and_resume_exclude_each_other(capsys, res):
    before = snapshot(res)
    rc, _, err = main(capsys, "grid", "--out", res, "--resume", "--overwrite")
    assert_one_line_error(rc, err, "--overwrite", "--resume")
    assert snapshot(res) == before


# -- bad numbers on the command line --------------------------------------------------------------------
BAD_GRID_ARGS = [
    (["--max-trials", "inf"], "--max-trials"),
    (["--max-trials", "nan"], "--max-trials"),
    (["--max-trials", "1e30"], "--max-trials"),
    (["--max-trials", "9223372036854775808"], "--max-trials"),
    (["--max-trials", "1.5"], "--max-trials"),
    (["--success-steps", "inf"], "--success-steps"),
    (["--success-steps", "-1"], "--success-steps"),
    (["--seed", "18446744073709551616"], "--seed"),
    (["--seed", "-1"], "--seed"),
    (["--seed", "1e400"], "--seed"),
    (["--threads", "4294967296"], "--threads"),
    (["--threads", "2000"], "--threads"),
    (["--threads", "-1"], "--threads"),
    (["--cells", "5-3"], "start > end"),
    (["--cells", "-5"], "bad cell index"),
    (["--cells", "1_0"], "bad cell index"),
    (["--cells", "1225"], "out of range"),
    (["--cells", ","], "empty cell list"),
    (["--checkpoint-every", "nan"], "--checkpoint-every"),
    (["--checkpoint-every", "0"], "--checkpoint-every"),
    (["--checkpoint-every", "inf"], "--checkpoint-every"),
    (["--checkpoint-cells", "0"], "--checkpoint-cells"),
    (["--set", "dt=1e-310"], "dt"),           # subnormal
    (["--set", "dt=2"], "dt=2.0"),            # rejected by C, parameter named
    (["--set", "gravity=-1"], "gravity=-1.0"),
    (["--set", "x_limit=0"], "x_limit=0.0"),
    (["--set", "dt=nan"], "dt"),
    (["--set", "policy.gain=Infinity"], "gain"),
    (["--set", "policy.gain=1e999"], "gain"),
    (["--set", "policy.gain=1e39"], "gain"),          # overflows float32
    (["--set", "actor.noise_std=1e-50"], "noise_std"),  # underflows float32
    (["--set", "init_velocity_noise=1e-320"], "init_velocity_noise"),
    (["--set", "policy.input_range=[1,2,3,NaN]"], "input_range"),
    (["--set", "mode=4294967296"], "int32"),
    (["--set", "integrator=4294967297"], "int32"),
    (["--set", "policy.clip_inputs=4294967297"], "clip_inputs"),
    (["--set", "max_trials=1e30"], "int64"),
    (["--set", "max_trials=9223372036854775808"], "int64"),
    (["--set", "success_steps=inf"], "success_steps"),
    (["--set", "max_trials=" + "9" * 5000], "max_trials"),
    (["--set", "policy.gain=" + "[" * 5000], "gain"),
]


@pytest.mark.parametrize("args, words", BAD_GRID_ARGS, ids=[" ".join(a)[:40] for a, _ in BAD_GRID_ARGS])
def test_bad_grid_numbers(capsys, tmp_path, args, words):
    out = tmp_path / "out"
    rc, _, err = main(capsys, "grid", "--out", out, "--cells", "611", "--quiet", *args)
    assert_one_line_error(rc, err, words)
    assert not out.exists()


def test_huge_cell_range_checked_before_expanding(capsys, tmp_path):
    tracemalloc.start()
    t0 = time.monotonic()
    try:
        rc, _, err = main(capsys, "grid", "--out", tmp_path / "o", "--cells", "0-30000000", *TINY_ARGS)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert_one_line_error(rc, err, "--cells", "30000000", "out of range")
    assert peak < 20 * 2 ** 20 and time.monotonic() - t0 < 5, (peak, time.monotonic() - t0)


@pytest.mark.parametrize("duration, words", [("nan", "--duration"), ("inf", "--duration"), ("-1", "--duration"),
                                             ("0", "--duration"), ("1e12", "steps"), ("20000", "steps")])
def test_figures_duration_bounded(capsys, res, tmp_path, duration, words):
    rc, _, err = main(capsys, "figures", "--results", res, "--out", tmp_path / "fig", "--duration", duration)
    assert_one_line_error(rc, err, words)
    assert not (tmp_path / "fig").exists()


def test_sweep_and_bench_numbers(capsys, res, tmp_path):
    for args, words in [
        (["sweep", "--prior-from", res, "--out", tmp_path / "w", "--param", "actor.noise_std=1", "--subset", "inf"],
         "--subset"),
        (["sweep", "--prior-from", res, "--out", tmp_path / "w", "--param", "actor.noise_std=1", "--subset", "5000"],
         "--subset"),
        (["sweep", "--prior-from", res, "--out", tmp_path / "w", "--param", "actor.noise_std=1",
          "--seeds", "18446744073709551616"], "--seeds"),
        (["sweep", "--prior-from", res, "--out", tmp_path / "w", "--param", "actor.noise_std=1",
          "--seeds", "0,1"], "for the seeds 0,1 write --seed 0 --seeds 2"),
        (["sweep", "--prior-from", res, "--out", tmp_path / "w", "--param", "actor.noise_std=1",
          "--seed", "18446744073709551615", "--seeds", "2"], "2^64"),
        (["bench", "--out", tmp_path / "b", "--seeds", "0"], "--seeds"),
        (["bench", "--out", tmp_path / "b", "--seeds", "1,2,3"], "--seed 1 --seeds 3"),
        (["sweep", "--prior-from", res, "--out", tmp_path / "w", "--param", "prior_ridge=abc"], "prior_ridge"),
        (["sweep", "--prior-from", res, "--out", tmp_path / "w", "--param", "actor.noise_std=1", "--threads", "1e10"],
         "--threads"),
        (["bench", "--out", tmp_path / "b", "--seed", "18446744073709551615", "--seeds", "2"], "2^64"),
        (["bench", "--out", tmp_path / "b", "--set", "policy.gain=nan"], "gain"),
        (["bench", "--out", tmp_path / "b", "--rl-max-trials", "inf"], "--rl-max-trials"),
    ]:
        rc, _, err = main(capsys, *args)
        assert_one_line_error(rc, err, words)
        assert not (tmp_path / "w").exists() and not (tmp_path / "b").exists(), args


# -- output directories ---------------------------------------------------------------------------------
def test_out_is_a_regular_file(capsys, tmp_path):
    f = tmp_path / "file"
    f.write_text("keep me")
    rc, _, err = main(capsys, "grid", "--out", f, "--cells", "611", *TINY_ARGS)
    assert_one_line_error(rc, err, "not a directory")
    rc, _, err = main(capsys, "grid", "--out", f / "sub", "--cells", "611", *TINY_ARGS)
    assert_one_line_error(rc, err, "cannot create directory", "Not a directory")
    assert f.read_text() == "keep me" and sorted(p.name for p in tmp_path.iterdir()) == ["file"]


def test_figures_out_is_a_regular_file(capsys, res, tmp_path):
    f = tmp_path / "file"
    f.write_text("keep me")
    rc, _, err = main(capsys, "figures", "--results", res, "--out", f)
    assert_one_line_error(rc, err, "not a directory")
    assert f.read_text() == "keep me"


def test_read_only_directory(capsys, tmp_path, monkeypatch):
    """chmod does not stop root: the permission bits are checked (os.access) and honoured here even
    for root, and a real write probe catches what permission bits do not show."""
    ro = tmp_path / "ro"
    ro.mkdir()
    ro.chmod(0o555)
    real_access = results.os.access

    def access(path, mode, *a, **k):  # what a non-root user sees
        if Path(path) == ro and mode & results.os.W_OK:
            return False
        return real_access(path, mode, *a, **k)

    monkeypatch.setattr(results.os, "access", access)
    try:
        rc, _, err = main(capsys, "grid", "--out", ro, "--cells", "611", *TINY_ARGS)
        assert_one_line_error(rc, err, "not writable")
        assert list(ro.iterdir()) == []
    finally:
        ro.chmod(0o755)


def test_write_probe_failure_is_one_line(capsys, tmp_path, monkeypatch):
    """A read-only mount: permission bits say yes, creating a file fails (EROFS)."""
    def mkstemp(*a, **k):
        raise OSError(errno.EROFS, "Read-only file system")

    monkeypatch.setattr(tempfile, "mkstemp", mkstemp)
    out = tmp_path / "rofs"
    rc, _, err = main(capsys, "grid", "--out", out, "--cells", "611", *TINY_ARGS)
    assert_one_line_error(rc, err, "not writable", "Read-only file system")
    assert list(out.iterdir()) == []


def test_checkpoint_write_failure_is_one_line(capsys, tmp_path, monkeypatch):
    real_save = store.ResultsStore.save
    calls = []

    def save(*a, **k):
        calls.append(1)
        if len(calls) > 1:
            raise OSError(errno.ENOSPC, "No space left on device", str(tmp_path / "o" / "cells.npz"))
        return real_save(*a, **k)

    monkeypatch.setattr(store.ResultsStore, "save", save)
    rc, _, err = main(capsys, "grid", "--out", tmp_path / "o", "--cells", "611", *TINY_ARGS)
    assert_one_line_error(rc, err, "No space left on device", "cells.npz")
    assert len(calls) == 2
    results.load(tmp_path / "o")  # the first (all PENDING) save is intact


# -- ERROR cells -----------------------------------------------------------------------------------------
def test_error_cells_are_neither_success_nor_failure():
    cells = grid.make_cells(0, range(610, 620))
    cells["outcome"] = [B.SUCCESS] * 4 + [B.FAILED] * 3 + [B.ERROR] * 3
    cells["status"][7:] = [B.ERR_NUMERIC, B.ERR_NUMERIC, B.ERR_NONFINITE_INPUT]
    cells["trials"] = 5
    s = metrics.summary(cells)
    assert s["outcomes"] == {"pending": 0, "success": 4, "failed": 3, "error": 3}
    assert s["n_success"] == 4 and s["success_rate"] == pytest.approx(0.4)
    assert s["error_statuses"] == {str(B.ERR_NONFINITE_INPUT): 1, str(B.ERR_NUMERIC): 2}
    assert np.isnan(metrics.trials_to_success(cells)[7:]).all()
    text = metrics.format_summary("ico", s)
    assert "3 cells reported a controller ERROR" in text and "numeric failure (4): 2" in text
    assert B.ERR_NUMERIC == 4 and B.lib.icoac_abi_version() == B.ABI_VERSION


def test_help_documents_bounds(capsys):
    with pytest.raises(SystemExit):
        cli.main(["grid", "--help"])
    text = " ".join(capsys.readouterr().out.split())
    assert "--overwrite" in text and f"max({grid.DEFAULT_CHECKPOINT_CELLS} cells" in text
    assert cli.O.DEFAULT_CHECKPOINT_CELLS is grid.DEFAULT_CHECKPOINT_CELLS  # defined once, in icoac.core.options
    assert cli.O.MAX_TRAJECTORY_STEPS is grid.MAX_TRAJECTORY_STEPS and cli.O.MAX_THREADS is grid.MAX_THREADS
    with pytest.raises(SystemExit):
        cli.main(["figures", "--help"])
    assert "1e6 plant steps" in " ".join(capsys.readouterr().out.split())


# -- strict parsing: numbers in ASCII digits that survive rounding, no parameter given twice ----------------
STRICT = [
    (["--set", "policy.gain=1e-400"], ["policy.gain", "'1e-400'", "rounds to 0"]),
    (["--set", "dt=1e-400"], ["dt", "rounds to 0"]),
    (["--set", "policy.input_range=[1e-400,3.5,0.2,2]"], ["input_range", "rounds to 0"]),
    (["--prior-ridge", "1e-400"], ["--prior-ridge", "rounds to 0"]),
    (["--max-trials", "50", "--set", "max_trials=true"], ["--max-trials 50", "--set max_trials", "both set"]),
    (["--max-trials", "50", "--set", "max_trials=-3"], ["--max-trials 50", "--set max_trials", "both set"]),
    (["--success-steps", "50", "--set", "success_steps=60"], ["--success-steps", "--set success_steps"]),
    (["--set", "policy.gain=3", "--set", "policy.gain=4"], ["policy.gain=3", "policy.gain=4", "both set policy.gain"]),
    (["--set", "max_trials=５０"], ["max_trials", "ASCII"]),
    (["--set", "policy.gain=１"], ["policy.gain", "ASCII"]),
    (["--cells", "６１１"], ["bad cell index", "ASCII"]),
    (["--max-trials", "５０"], ["--max-trials"]),
    (["--seed", "１"], ["--seed"]),
    (["--max-trials", "1_000"], ["--max-trials"]),
    (["--set", "max_trials=1_000"], ["max_trials"]),
    (["--checkpoint-every", "１"], ["--checkpoint-every"]),
]


@pytest.mark.parametrize("args, words", STRICT, ids=[" ".join(a)[:40] for a, _ in STRICT])
def test_strict_parsing(capsys, tmp_path, args, words):
    out = tmp_path / "out"
    caps = [a for field, cap in (("max_trials", ["--max-trials", "50"]), ("success_steps", ["--success-steps", "200"]))
            if not any(field in arg or field.replace("_", "-") in arg for arg in args) for a in cap]
    rc, _, err = main(capsys, "grid", "--out", out, "--cells", "611", "--quiet", *caps, *args)
    assert_one_line_error(rc, err, *words)
    assert not out.exists()


def test_zero_and_small_normal_values_pass(capsys, tmp_path):
    rc, _, err = main(capsys, "grid", "--out", tmp_path / "o", "--cells", "611", *TINY_ARGS,
                      "--set", "critic.threshold=0.0e-400", "--set", "ico.rate=2.5e-38")
    assert rc == 0, err
    controller = results.load(tmp_path / "o")[1]["config"]["controller"]
    assert controller["critic"]["threshold"] == 0.0 and controller["ico"]["rate"] == pytest.approx(2.5e-38)


SWEEP = ["sweep", "--out", "{tmp}/w", "--cells", "611"]
BENCH = ["bench", "--profile", "quick", "--seeds", "1", "--out", "{tmp}/b"]
CEILING = ["ceiling", "--out", "{tmp}/c", "--cells", "611", "--protocol", "first", "--success-steps", "200", "--quiet"]
STRICT_COMMANDS = [
    ([*SWEEP, "--param", "actor.noise_std=1", "--max-trials", "50", "--set", "max_trials=60"],
     ["--max-trials 50", "--set max_trials"]),
    ([*SWEEP, "--param", "actor.noise_std=1,2", "--set", "actor.noise_std=3"], ["--param actor.noise_std", "--set"]),
    ([*SWEEP, "--param", "max_trials=10,20", "--max-trials", "50"], ["--param max_trials", "--max-trials"]),
    ([*SWEEP, "--param", "actor.noise_std=1", "--set", "policy.gain=1e-400"], ["gain", "rounds to 0"]),
    ([*BENCH, "--rl-max-trials", "5", "--set", "max_trials=6"], ["--rl-max-trials 5", "--set max_trials"]),
    ([*BENCH, "--set", "max_trials=3", "--set", "actor.noise_std=1", "--set", "actor.noise_std=2"],
     ["both set actor.noise_std"]),
    ([*CEILING, "--w", "1e-400,1,1,1"], ["--w", "rounds to 0"]),
    ([*CEILING, "--w", "１,1,1,1"], ["--w", "ASCII"]),
]


@pytest.mark.parametrize("args, words", STRICT_COMMANDS,
                         ids=[" ".join(a[:1] + a[-4:])[:50] for a, _ in STRICT_COMMANDS])
def test_strict_parsing_of_sweep_bench_ceiling(capsys, ico_dir, tmp_path, args, words):
    args = [a.format(tmp=tmp_path) for a in args] + (["--prior-from", ico_dir] if args[0] == "sweep" else [])
    rc, _, err = main(capsys, *args)
    assert_one_line_error(rc, err, *words)
    assert not [p for p in tmp_path.iterdir() if p.name in ("w", "b", "c")]


def test_configuration_then_set_is_no_duplicate(capsys, tmp_path):
    """--set replaces an item of the named configuration: that is its purpose, not a field given twice."""
    rc, _, err = main(capsys, "grid", "--out", tmp_path / "o", "--cells", "611", *TINY_ARGS,
                      "--configuration", "literal", "--set", "actor.noise_std=2")
    assert rc == 0, err
    assert results.load(tmp_path / "o")[1]["config"]["controller"]["actor"]["noise_std"] == 2.0

