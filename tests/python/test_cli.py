# SPDX-License-Identifier: Apache-2.0
import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

REPO = Path(__file__).resolve().parents[2]
SMALL_ARGS = ["--max-trials", "6000", "--success-steps", "2000", "--quiet"]


def run(*args, timeout=60):
    return subprocess.run([sys.executable, "-m", "icoac", *args], cwd=REPO, capture_output=True, text=True,
                          timeout=timeout)


@pytest.mark.parametrize("args, words", [
    (["grid", "--out", "{tmp}/a", "--set", "policy.gain=-1"], "gain"),
    (["grid", "--out", "{tmp}/a", "--set", "gian=1"], "unknown parameter 'gian'"),
    (["grid", "--out", "{tmp}/a", "--set", "gain"], "name=value"),
    (["grid", "--out", "{tmp}/a", "--set", "policy.reflex_mode=huge"], "unit, gain"),
    (["grid", "--out", "{tmp}/a", "--set", "dt=nan"], "plant"),
    (["grid", "--out", "{tmp}/a", "--max-trials", "0"], "max-trials"),
    (["grid", "--out", "{tmp}/a", "--cells", "5000"], "out of range"),
    (["grid", "--out", "{tmp}/a", "--bogus"], "unrecognized"),
    (["grid", "--out", "{tmp}/a", "--resume"], "no results to resume"),
    (["grid"], "--out"),
    (["figures", "--results", "{tmp}/missing", "--out", "{tmp}/f"], "does not exist"),
    (["bench", "--profile", "huge", "--out", "{tmp}/b"], "invalid choice"),
    # sigma_w of the isotropic prior: its square must be a variance the controller takes, checked
    # before any stage (before: an OverflowError traceback, or after both ICO grids of a bench)
    (["grid", "--condition", "rl", "--out", "{tmp}/a", "--prior-std", "1.35e154"], "--prior-std must be"),
    (["grid", "--condition", "rl", "--out", "{tmp}/a", "--prior-std", "2e6"], "--prior-std must be"),
    (["bench", "--profile", "quick", "--out", "{tmp}/b", "--prior-std", "1e20"], "--prior-std must be"),
    (["bench", "--profile", "quick", "--out", "{tmp}/b", "--prior-ridge", "-1"], "--prior-ridge must be"),
    (["bench", "--profile", "quick", "--out", "{tmp}/b", "--prior-ridge", "1e200"], "--prior-ridge must be"),
    (["grid", "--condition", "ico-rl", "--prior-from", "{ico}", "--out", "{tmp}/a", "--prior-ridge", "1e40"],
     "--prior-ridge must be"),
    (["sweep", "--prior-from", "{ico}", "--out", "{tmp}/s", "--param", "prior_ridge=-1"], "--param prior_ridge must be"),
    (["sweep", "--prior-from", "{ico}", "--out", "{tmp}/s", "--param", "prior_std=1e200"],
     "--param prior_std must be"),
    ([], "required"),
])
def test_user_errors_one_line_exit_2(tmp_path, ico_dir, args, words):
    res = run(*[a.format(tmp=tmp_path, ico=ico_dir) for a in args])
    assert res.returncode == 2, res.stderr
    assert "Traceback" not in res.stderr and "Traceback" not in res.stdout
    lines = res.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("icoac: error: ")
    assert words in lines[0]
    assert not any(tmp_path.iterdir())  # refused before anything was written


def test_grid_resume_and_mismatch(tmp_path):
    out = tmp_path / "g"
    res = run("grid", "--out", str(out), "--cells", "610,611", "--seed", "4", *SMALL_ARGS)
    assert res.returncode == 0, res.stderr
    record = json.loads((out / "run.json").read_text())
    assert record["complete"] and record["cells"] == [610, 611] and record["seed"] == 4
    res = run("grid", "--out", str(out), "--resume", "--quiet")
    assert res.returncode == 0, res.stderr
    res = run("grid", "--out", str(out), "--cells", "610,611", "--seed", "4", "--set", "policy.gain=5", *SMALL_ARGS)
    assert res.returncode == 2 and "does not match" in res.stderr and "gain" in res.stderr
    assert "Traceback" not in res.stderr


def test_limited_holds_each_plant_to_its_actuator(tmp_path):
    """--limited runs the plant at the actuator limit its C file gives; where the default is that
    limit it adds nothing; with a --set of the same parameter it is a one-line error."""
    from icoac.core import binding as B
    from icoac.core.plants import PLANTS
    for name in PLANTS:
        actuator = B.plant_info(name)["actuator"]
        out = tmp_path / name
        res = run("grid", "--plant", name, "--limited", "--condition", "lqr", "--cells", "0", "--max-trials", "1",
                  "--success-steps", "20", "--quiet", "--out", str(out))
        assert res.returncode == 0, res.stderr
        plant = json.loads((out / "run.json").read_text())["config"]["plant"]
        assert plant[actuator["param"]] == actuator["limit"]
        default = next(p["value"] for p in B.plant_info(name)["params"] if p["name"] == actuator["param"])
        assert PLANTS[name].limited_sets() == ([] if default == actuator["limit"] else
                                               [f"{actuator['param']}={actuator['limit']:.15g}"])
    res = run("grid", "--plant", "double_cart_pole", "--limited", "--set", "max_force=30", "--out", str(tmp_path / "x"))
    assert res.returncode == 2 and res.stderr.strip() == ("icoac: error: --limited and --set max_force=30 both set "
                                                          "max_force; give one")
    assert not (tmp_path / "x").exists()


def test_sigint_then_resume(tmp_path):
    out = tmp_path / "s"
    args = [sys.executable, "-m", "icoac", "grid", "--out", str(out), "--cells", "590-640", "--threads", "1",
            "--max-trials", "20000", "--success-steps", "5000", "--checkpoint-every", "0.2", "--quiet"]
    proc = subprocess.Popen(args, cwd=REPO, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    deadline = time.monotonic() + 20
    while not (out / "run.json").exists() and time.monotonic() < deadline:
        time.sleep(0.05)
    time.sleep(0.6)
    proc.send_signal(signal.SIGINT)
    stdout, stderr = proc.communicate(timeout=30)
    assert "Traceback" not in stderr
    assert proc.returncode in (0, 130)
    with np.load(out / "cells.npz") as data:
        partial = data["cells"]
    if proc.returncode == 130:
        assert (partial["outcome"] == 0).any()
    res = subprocess.run(args[:4] + ["--out", str(out), "--resume", "--quiet"], cwd=REPO, capture_output=True,
                         text=True, timeout=60)
    assert res.returncode == 0, res.stderr
    with np.load(out / "cells.npz") as data:
        final = data["cells"]
    assert (final["outcome"] != 0).all()
    done = partial["outcome"] != 0
    assert np.array_equal(final[done], partial[done])
    # Same result as an uninterrupted run.
    from icoac.core import grid
    from icoac.core.config import build_config
    ref = grid.make_cells(0, range(590, 641))
    grid.run_grid(build_config({"max_trials": 20000, "success_steps": 5000}), ref, progress=False)
    assert np.array_equal(ref, final)


def test_missing_library_is_one_line(tmp_path):
    env = dict(os.environ, ICOAC_SIM_LIBRARY=str(tmp_path / "libnone.so"))
    res = subprocess.run([sys.executable, "-m", "icoac", "grid", "--out", str(tmp_path / "x")], cwd=REPO,
                         capture_output=True, text=True, env=env, timeout=60)
    assert res.returncode == 2 and "Traceback" not in res.stderr
    lines = res.stderr.strip().splitlines()
    assert len(lines) == 1 and "make build" in lines[0] and lines[0].startswith("icoac: error: ")


def test_help_exits_zero():
    res = run("grid", "--help")
    assert res.returncode == 0 and "--set" in res.stdout and "--resume" in res.stdout


@pytest.mark.parametrize("missing, args, words", [
    ("matplotlib", ["figures", "--results", "{ico}", "--out", "{tmp}/f"],
     "drawing figures needs the 'plot' extra (matplotlib): pip install 'icoac[plot]'"),
    ("matplotlib", ["bench", "--profile", "quick", "--out", "{tmp}/b", "--figures", "{tmp}/bf"], "'plot' extra"),
    ("distributed", ["grid", "--out", "{tmp}/g", "--cells", "611", "--workers", "1"],
     "the Dask backend (--workers, --scheduler) needs the 'dask' extra (distributed): pip install"),
])
def test_a_missing_extra_is_one_line_before_any_work(tmp_path, ico_dir, missing, args, words):
    """Plotting and Dask are extras: without them, the commands that need them say which, in one
    line (exit 2), and write nothing; every other command runs without them."""
    code = (f"import sys; sys.modules[{missing!r}] = None\n"
            "from icoac.cli import main\nraise SystemExit(main(sys.argv[1:]))")
    argv = [a.format(tmp=tmp_path, ico=ico_dir) for a in args]
    res = subprocess.run([sys.executable, "-c", code, *argv], cwd=REPO, capture_output=True, text=True, timeout=120)
    assert res.returncode == 2, res.stderr
    lines = res.stderr.strip().splitlines()
    assert len(lines) == 1 and words in lines[0], lines
    assert not any(p.name in ("f", "b", "bf", "g") for p in tmp_path.iterdir())
    grid = subprocess.run([sys.executable, "-c", code, "grid", "--out", str(tmp_path / "ok"), "--cells", "611",
                           "--max-trials", "5", "--quiet"], cwd=REPO, capture_output=True, text=True, timeout=120)
    assert grid.returncode == 0, grid.stderr
