# SPDX-License-Identifier: Apache-2.0
"""The best single w found (method.md, L5, icoac.studies.ceiling): fixed-w evaluation, the search, the
first-step bound, the command and its files, the bench's reference lines."""
import json
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from icoac.core import binding as B
from icoac.core import signs
from icoac.studies import bench, figures
from icoac.core import geometry, grid, options, results
from icoac.studies.ceiling import fixed, lqr, records, weights
from icoac.studies.ceiling.bound import first_step_bound, initial_states
from icoac.studies.ceiling import search as S
from icoac.core.config import build_config, make_prior
from icoac.core.errors import UsageError

REPO = Path(__file__).resolve().parents[2]
W = (0.3, 0.5, 0.8, 1.2)
# Corners, edges, the centre row and a few cells the typical ICO weights lose.
CELLS = [0, 24, 48, 300, 349, 600, 610, 611, 612, 620, 900, 1176, 1200, 1224]
SMALL = ["--cells", "600-624", "--candidates", "12", "--screen-steps", "200", "--success-steps", "1000",
         "--max-trials", "5", "--confirm", "2", "--threads", "2", "--quiet"]


def run(*args, timeout=120):
    return subprocess.run([sys.executable, "-m", "icoac", *args], cwd=REPO, capture_output=True, text=True,
                          timeout=timeout)


# -- fixed-w evaluation ----------------------------------------------------------------------------------
@pytest.mark.parametrize("protocol, cap", [("first", 1), ("retries", 20)])
def test_fixed_w_equals_a_grid_run_with_learning_off(protocol, cap):
    got = fixed.evaluate(W, protocol, seed=3, cells=CELLS, max_trials=20, success_steps=2000, threads=2)
    cfg = build_config({"learn": 0, "max_trials": cap, "success_steps": 2000}, condition="ico",
                       prior=make_prior(W, np.eye(4)))
    ref = grid.make_cells(3, CELLS)
    grid.run_grid(cfg, ref, threads=1, progress=False)
    assert got.tobytes() == ref.tobytes()
    # the weights stay exactly w (as the controller's reals)
    assert np.all(got["weights"][:, :4] == np.asarray(W, dtype=B.real_dtype).astype(np.float64))
    assert np.all(got["weights"][:, 4:] == 0)  # the inputs the cart-pole task does not use
    # ... and acting is that of ICO learning at rate 0
    same = grid.make_cells(3, CELLS)
    grid.run_grid(build_config({"max_trials": cap, "success_steps": 2000, "ico.rate": 0}, condition="ico",
                               prior=make_prior(W, np.eye(4))), same, progress=False)
    for name in ("outcome", "trials", "total_steps", "last_trial_steps", "weights"):
        assert np.array_equal(got[name], same[name]), name
    assert (got["outcome"] == B.FAILED).any() and (got["outcome"] == B.SUCCESS).any()


def test_first_protocol_runs_one_trial_per_cell_and_retries_up_to_the_cap():
    first = fixed.evaluate(options.TYPICAL_ICO_WEIGHTS, "first", cells=CELLS, success_steps=2000)
    assert np.all(first["trials"] == 1)
    retries = fixed.evaluate(options.TYPICAL_ICO_WEIGHTS, "retries", cells=CELLS, max_trials=7,
                               success_steps=2000)
    failed = retries["outcome"] == B.FAILED
    assert failed.any() and np.all(retries["trials"][failed] == 7)
    assert np.all(retries["trials"][retries["outcome"] == B.SUCCESS] <= 7)
    # a first trial that succeeds is the retries protocol's first trial too
    ok = first["outcome"] == B.SUCCESS
    assert np.all(retries["outcome"][ok] == B.SUCCESS) and np.all(retries["trials"][ok] == 1)


def test_weights_are_validated_and_rounded():
    w = weights.parse_weights("0.1, 0.2,0.3,0.4")
    assert w == tuple(float(B.real_dtype.type(v)) for v in (0.1, 0.2, 0.3, 0.4))
    for bad in ("1,2,3", "1,2,3,nan", "a,b,c,d", "1,2,3,1e7", "1,2,3,1e-45"):
        with pytest.raises(UsageError):
            weights.parse_weights(bad, n=4)  # a task of 4 inputs
    # without a task's n: 1 to MAX_INPUTS weights
    assert len(weights.parse_weights(",".join(["1"] * B.MAX_INPUTS))) == B.MAX_INPUTS
    with pytest.raises(UsageError, match="expected"):
        weights.parse_weights(",".join(["1"] * (B.MAX_INPUTS + 1)))
    with pytest.raises(UsageError, match="set by the ceiling command"):
        fixed.check_overrides(["learn=1"])


# -- search ----------------------------------------------------------------------------------------------
def _synthetic(w):
    """A smooth screening score with its optimum at (0.5, 0.5, 4, 4) and positive signs."""
    w = np.asarray(w)
    d = np.sum(np.log(np.abs(w) / np.array([0.5, 0.5, 4.0, 4.0])) ** 2) + 5.0 * np.sum(w < 0)
    n = int(1000 / (1.0 + d))
    return S.Screen(n, n, int(1e6 / (1.0 + d)))


def test_search_budget_phases_and_determinism():
    starts = [("a", (0.1, 0.1, 0.4, 0.1)), ("b", (1.0, 2.0, 1.0, 3.0))]
    r1 = S.search(_synthetic, starts, 80, seed=5)
    r2 = S.search(_synthetic, starts, 80, seed=5)
    r3 = S.search(_synthetic, starts, 80, seed=6)
    assert r1.trace == r2.trace and r1.best == r2.best
    assert r1.trace != r3.trace
    assert len(r1.trace) == 80 and r1.stop == "budget"
    assert len({tuple(e["w"]) for e in r1.trace}) == 80
    phases = [e["phase"] for e in r1.trace]
    assert phases[:2] == ["start", "start"] and phases.count("random") == 39 and phases.count("refine") == 39
    for e in r1.trace:  # every candidate is what the controller runs
        assert tuple(e["w"]) == weights.as_weights(e["w"])
    assert all(S.rank_key(r1.best) >= S.rank_key(e) for e in r1.trace)
    long = S.search(_synthetic, starts, 400, seed=5)
    before = max(S.rank_key(e) for e in long.trace if e["phase"] != "refine")
    assert S.rank_key(long.best) > before and long.best["phase"] == "refine"
    assert long.best["n_success"] > 900  # the refinement found the optimum's neighbourhood
    tiny = S.search(_synthetic, starts, 1, seed=5)
    assert [e["label"] for e in tiny.trace] == ["a"]


def test_search_on_the_engine_is_deterministic_and_no_worse_than_its_starts():
    cells = grid.make_cells(0, list(range(0, geometry.CELLS, 30)))

    def cfg_for(w):
        return fixed.fixed_config(w, "first", success_steps=300)

    def screen(w):
        return S.screen_cells(w, cells, cfg_for, threads=2)

    starts = [("typical", options.TYPICAL_ICO_WEIGHTS)] + lqr.lqr_starts(cfg_for(W))
    r1 = S.search(screen, starts, 24, seed=1)
    r2 = S.search(screen, starts, 24, seed=1)
    assert r1.trace == r2.trace
    for e in r1.trace[:len(starts)]:
        assert e["phase"] == "start" and S.rank_key(r1.best) >= S.rank_key(e)
    # a screen is one first-trial run at the screening horizon
    best = fixed.evaluate(r1.best["w"], "first", cells=list(range(0, geometry.CELLS, 30)), success_steps=300)
    assert int((best["outcome"] == B.SUCCESS).sum()) == r1.best["n_success"]
    assert int(best["total_steps"].sum()) == r1.best["total_steps"]


def _riccati_iteration(a, b, q, r, iterations=20_000):
    """The plain fixed-point iteration of the discrete Riccati equation (the solver the harness had)."""
    p, rr = q.copy(), np.array([[r]])
    for _ in range(iterations):
        k = np.linalg.solve(rr + b.T @ p @ b, b.T @ p @ a)
        p = q + a.T @ p @ (a - b @ k)
    return k.ravel()


@pytest.mark.parametrize("force", lqr.LQR_FORCES)
def test_dare_gain_solves_the_riccati_equation(force):
    """The gain of scipy's DARE solver: its P solves the discrete Riccati equation, the closed loop
    of the linearised C plant is stable, and K is the fixed point of the Riccati iteration."""
    import scipy.linalg

    cfg = fixed.fixed_config(W)
    a, b = signs.linearise(cfg)
    q = np.diag(1.0 / np.array(list(cfg.controller.policy.input_range)[:4], dtype=float) ** 2)
    r = 1.0 / force ** 2
    k = signs.lqr_gain(a, b, q, r)
    p = scipy.linalg.solve_discrete_are(a, b, q, np.array([[r]]))
    gain = np.linalg.solve(r + b.T @ p @ b, b.T @ p @ a)
    residual = a.T @ p @ a - p - a.T @ p @ b @ gain + q
    assert np.max(np.abs(residual)) <= 1e-9 * np.max(np.abs(p))
    np.testing.assert_allclose(k, gain.ravel(), rtol=1e-12)
    assert np.max(np.abs(np.linalg.eigvals(a - b @ k.reshape(1, 4)))) < 1.0
    np.testing.assert_allclose(k, _riccati_iteration(a, b, q, r), rtol=1e-9)


def test_dare_gain_none_without_a_stabilising_solution():
    a = np.diag([1.5, 0.5, 0.5, 0.5])       # an unstable mode the input cannot reach
    b = np.array([[0.0], [1.0], [0.0], [0.0]])
    assert signs.lqr_gain(a, b, np.eye(4), 1.0) is None
    assert signs.lqr_gain(np.diag([0.5, 0.5, 0.5, 0.5]), b, np.eye(4), 1.0) is not None


def test_lqr_starting_points_stabilise_the_linearised_plant():
    cfg = fixed.fixed_config(W)
    a, b = signs.linearise(cfg)
    starts = lqr.lqr_starts(cfg)
    assert len(starts) == len(lqr.LQR_FORCES)
    ranges = np.array(list(cfg.controller.policy.input_range)[:B.N_INPUTS], dtype=float)
    for _, w in starts:
        assert all(v > 0 for v in w)  # the sign pattern of a stabilising linear policy here
        k = -np.asarray(w) * cfg.controller.policy.gain / ranges
        assert np.max(np.abs(np.linalg.eigvals(a - b @ k.reshape(1, 4)))) < 1.0


# -- first-step bound ------------------------------------------------------------------------------------
def test_first_step_bound_is_the_outward_boundary_draws():
    cfg = fixed.fixed_config(W, success_steps=1000)
    cells = grid.make_cells(2)
    bound = first_step_bound(cfg, cells, threads=2)
    s0 = initial_states(cfg, cells)  # the engine's first draws, through icoac_sim_trajectory
    assert np.array_equal(s0[:, 0], cells["x0"]) and np.array_equal(s0[:, 2], cells["theta0"])
    assert np.all(np.abs(s0[:, [1, 3]]) <= cfg.run.init_velocity_noise)
    rows, cols = geometry.grid_index(cells)
    outward = (((cols == geometry.XS - 1) & (s0[:, 1] > 0)) | ((cols == 0) & (s0[:, 1] < 0))
               | ((rows == geometry.THETAS - 1) & (s0[:, 3] > 0)) | ((rows == 0) & (s0[:, 3] < 0)))
    lost = sorted(c["cell"] for c in bound["lost_cells"])
    assert lost == sorted(np.flatnonzero(outward).tolist())
    assert bound["n_lost"] == int(outward.sum()) > 40 and bound["n_lost_interior"] == 0
    assert bound["max_success"] == geometry.CELLS - bound["n_lost"]
    assert bound["max_success_interior"] == geometry.N_INTERIOR
    # the engine agrees: one first trial of 1 step (any controller) fails exactly there
    probe = grid.make_cells(2)
    grid.run_grid(fixed.fixed_config(options.TYPICAL_ICO_WEIGHTS, success_steps=1), probe, progress=False)
    assert np.array_equal(probe["outcome"] == B.FAILED, outward)
    # ... and so does every controller's first trial at the full horizon: no lost cell succeeds
    first = fixed.evaluate(W, "first", seed=2, success_steps=300, threads=2)
    assert not np.any(first["outcome"][outward] == B.SUCCESS)


def test_first_step_bound_without_noise_and_with_rk4():
    cells = grid.make_cells(0)
    cfg = fixed.fixed_config(W, overrides={"init_velocity_noise": 0})
    bound = first_step_bound(cfg, cells)
    limit = cfg.flat()
    beyond = (np.abs(cells["x0"]) > limit["x_limit"]) | (np.abs(cells["theta0"]) > limit["theta_limit"])
    assert sorted(c["cell"] for c in bound["lost_cells"]) == np.flatnonzero(beyond).tolist()
    rk4 = first_step_bound(fixed.fixed_config(W, overrides={"integrator": "rk4"}), cells[:5])
    assert rk4["computed"] is False and "Euler" in rk4["reason"]


# -- the command -----------------------------------------------------------------------------------------
@pytest.fixture(scope="module")
def small_ceiling(tmp_path_factory):
    out = tmp_path_factory.mktemp("ceiling") / "c"
    res = run("ceiling", "--out", str(out), *SMALL)
    assert res.returncode == 0, res.stderr
    return out, res


def test_command_writes_its_records(small_ceiling):
    out, res = small_ceiling
    record = json.loads((out / "ceiling.json").read_text())
    assert "Best single w found" in (out / "ceiling.md").read_text() and "Best w" in res.stdout
    s = record["search"]
    assert s["screened"] == len(s["trace"]) == 12 and s["seed"] == 0 and len(s["confirmed"]) == 2
    assert record["settings"]["cells"] == list(range(600, 625)) and record["git"]["commit"]
    best = record["best"]
    assert best["source"] == "search" and set(best["protocols"]) == {"first", "retries"}
    assert best["w"] in [c["w"] for c in s["confirmed"]]
    for protocol, summ in best["protocols"].items():
        cells, rec = results.load(out / summ["dir"])
        assert rec["condition"] == "ico" and rec["config"]["controller"]["learn"] is False
        assert rec["config"]["run"]["max_trials"] == (1 if protocol == "first" else 5)
        assert rec["config"]["run"]["success_steps"] == 1000
        assert rec["prior_info"]["kind"] == "fixed-w" and rec["prior_info"]["mean"] == best["w"]
        assert np.all(cells["weights"][:, :4] == np.asarray(best["w"]))
        assert summ["n_success"] == int((cells["outcome"] == B.SUCCESS).sum()) and summ["n_cells"] == 25
        ref = fixed.evaluate(best["w"], protocol, cells="600-624", max_trials=5, success_steps=1000)
        assert ref.tobytes() == cells.tobytes()
    assert record["first_step_bound"]["computed"] and record["first_step_bound"]["n_cells"] == 25


def test_rerun_reuses_everything_and_gives_the_same_record(small_ceiling, tmp_path):
    out, _ = small_ceiling
    copy = tmp_path / "again"
    shutil.copytree(out, copy)
    before = json.loads((copy / "ceiling.json").read_text())
    res = run("ceiling", "--out", str(copy), *SMALL[:-1])
    assert res.returncode == 0, res.stderr
    text = (copy / "ceiling.json").read_text()
    after = json.loads(text)
    assert after["search"]["reused_screens"] == 12
    assert before["first_step_bound"] == after["first_step_bound"]
    for record in (before, after):
        for p in record["best"]["protocols"].values():
            p.pop("wall_time")
    assert before["best"] == after["best"]
    assert before["search"]["trace"] == after["search"]["trace"]
    # other screening settings in the same directory are refused, nothing rewritten
    res = run("ceiling", "--out", str(copy), *SMALL[:4], "--screen-steps", "300", *SMALL[6:])
    assert res.returncode == 2 and "other screen_steps" in res.stderr
    assert (copy / "ceiling.json").read_text() == text


def test_given_w_is_evaluated_without_a_search(tmp_path):
    out = tmp_path / "w"
    res = run("ceiling", "--out", str(out), "--w", "0.3,0.5,0.8,1.2", "--protocol", "first", "--cells", "0-30",
              "--success-steps", "500", "--quiet")
    assert res.returncode == 0, res.stderr
    record = json.loads((out / "ceiling.json").read_text())
    assert "search" not in record and not (out / "search.json").exists()
    assert record["best"]["source"] == "--w" and list(record["best"]["protocols"]) == ["first"]
    assert record["best"]["w"] == list(weights.as_weights(W))
    ref = fixed.evaluate(W, "first", cells="0-30", success_steps=500)
    assert record["best"]["protocols"]["first"]["n_success"] == int((ref["outcome"] == B.SUCCESS).sum())


@pytest.mark.parametrize("extra, cap, horizon", [
    ([], 600, 2000),                                           # the quick profile's learner caps
    (["--max-trials", "9", "--success-steps", "700"], 9, 700),  # given options win
])
def test_profile_gives_the_retries_the_learners_caps(tmp_path, extra, cap, horizon):
    assert bench.learner_caps("quick") == (600, 2000)
    assert bench.learner_caps("paper") == (100000, 100000)
    assert bench.learner_caps("default")[0] == options.CEILING_MAX_TRIALS
    out = tmp_path / "w"
    res = run("ceiling", "--out", str(out), "--w", "0.3,0.5,0.8,1.2", "--protocol", "retries", "--cells", "0-3",
              "--profile", "quick", *extra, "--quiet")
    assert res.returncode == 0, res.stderr
    record = json.loads((out / "ceiling.json").read_text())
    assert (record["settings"]["max_trials"], record["settings"]["success_steps"]) == (cap, horizon)
    assert record["best"]["protocols"]["retries"]["max_trials"] == cap


def test_prior_from_starts_the_search_at_the_ico_mean(tmp_path, ico_dir):
    from icoac.studies import prior as P
    ico = Path(ico_dir)
    out = tmp_path / "p"
    res = run("ceiling", "--out", str(out), "--prior-from", str(ico), "--cells", "600-610", "--candidates", "3",
              "--screen-steps", "100", "--success-steps", "200", "--confirm", "1", "--protocol", "first", "--quiet")
    assert res.returncode == 0, res.stderr
    record = json.loads((out / "ceiling.json").read_text())
    start = record["search"]["starts"][0]
    assert start["label"] == "ICO mean (--prior-from)"
    assert start["w"] == list(weights.as_weights(P.from_results(ico).mean))
    assert record["settings"]["prior_from"]["path"] == str(ico.resolve())
    assert [e["phase"] for e in record["search"]["trace"]] == ["start"] * 3


@pytest.mark.parametrize("args, words", [
    (["--w", "1,2,3"], "4 numbers"),
    (["--w", "1,2,nan,4"], "finite"),
    (["--w", "a,b,c,d"], "comma-separated"),
    (["--w", "0.1,0.1,0.3,0.1", "--candidates", "5"], "without a search"),
    (["--protocol", "all"], "invalid choice"),
    (["--cells", "5000"], "out of range"),
    (["--set", "learn=1"], "set by the ceiling command"),
    (["--set", "max_trials=3"], "--max-trials"),
    (["--set", "gian=1"], "unknown parameter"),
    (["--screen-steps", "5000", "--success-steps", "1000"], "longer than"),
    (["--candidates", "0"], "candidates"),
    (["--max-trials", "0"], "max-trials"),
    (["--prior-from", "{tmp}/missing"], "does not exist"),
])
def test_user_errors_one_line_exit_2(tmp_path, args, words):
    out = tmp_path / "c"
    res = run("ceiling", "--out", str(out), *[a.format(tmp=tmp_path) for a in args])
    assert res.returncode == 2, res.stderr
    assert "Traceback" not in res.stderr and "Traceback" not in res.stdout
    lines = res.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("icoac: error: ") and words in lines[0]
    assert not out.exists()


def test_out_that_is_a_file_or_a_damaged_search_record(tmp_path):
    f = tmp_path / "file"
    f.write_text("x")
    res = run("ceiling", "--out", str(f), "--quiet")
    assert res.returncode == 2 and "not a directory" in res.stderr and len(res.stderr.strip().splitlines()) == 1
    d = tmp_path / "d"
    d.mkdir()
    (d / "search.json").write_text("{broken")
    res = run("ceiling", "--out", str(d), *SMALL)
    assert res.returncode == 2 and "search.json" in res.stderr and "Traceback" not in res.stderr
    assert (d / "search.json").read_text() == "{broken" and not (d / "ceiling.json").exists()


def test_sigint_keeps_the_screens_and_the_rerun_finishes_identically(tmp_path):
    args = ["ceiling", "--candidates", "80", "--screen-steps", "1000",
            "--success-steps", "1000", "--confirm", "1", "--protocol", "first", "--threads", "1", "--quiet"]
    out = tmp_path / "i"
    proc = subprocess.Popen([sys.executable, "-m", "icoac", *args, "--out", str(out)], cwd=REPO,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    time.sleep(1.5)
    proc.send_signal(signal.SIGINT)
    _, stderr = proc.communicate(timeout=60)
    assert "Traceback" not in stderr and proc.returncode in (0, 130), stderr
    if proc.returncode == 130:
        assert not (out / "ceiling.json").exists()
        if (out / "search.json").exists():
            saved = json.loads((out / "search.json").read_text())
            assert 0 < len(saved["screens"]) < 80
    res = run(*args, "--out", str(out))
    assert res.returncode == 0, res.stderr
    ref_out = tmp_path / "ref"
    ref = run(*args, "--out", str(ref_out))
    assert ref.returncode == 0, ref.stderr
    a = json.loads((out / "ceiling.json").read_text())
    b = json.loads((ref_out / "ceiling.json").read_text())
    assert a["search"]["trace"] == b["search"]["trace"] and a["best"]["w"] == b["best"]["w"]
    assert a["best"]["protocols"]["first"]["n_success"] == b["best"]["protocols"]["first"]["n_success"]


# -- bench and Fig. 3a -----------------------------------------------------------------------------------
AGG_STATS = {"mean": 0.6, "sd": 0.01}


def test_fig3a_reference_lines(tmp_path):
    args = (["ICO", "ICO->RL"], [AGG_STATS, AGG_STATS], [AGG_STATS, AGG_STATS], [0.68, 0.84])
    plain = figures.plot_fig3a(tmp_path / "a.png", *args).read_bytes()
    none = figures.plot_fig3a(tmp_path / "b.png", *args, ceiling=None).read_bytes()
    lines = figures.plot_fig3a(tmp_path / "c.png", *args, ceiling={"first trial": 0.915, "retries": 0.967})
    assert plain == none and lines.read_bytes() != plain and lines.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_bench_shows_a_ceiling_when_there_is_one(small_ceiling, tmp_path):
    out, _ = small_ceiling
    assert records.bench_ceiling(tmp_path) is None
    record = records.bench_ceiling(tmp_path, explicit=out)
    lines = records.reference_lines(record)
    assert set(lines) == {"first trial", "retries"}
    assert lines["first trial"] == record["best"]["protocols"]["first"]["success_rate"]
    (tmp_path / "ceiling").mkdir()
    (tmp_path / "ceiling" / "ceiling.json").write_text((out / "ceiling.json").read_text())
    assert records.bench_ceiling(tmp_path) == record
    agg = bench.aggregate({"ico": [{"seed": 0, "summary": {"n_cells": 25, "n_interior": 25, "success_rate": 0.5,
                                                          "success_rate_interior": 0.5,
                                                          "median_trials_to_success": 3.0,
                                                          "mean_elapsed_time_success": 10.0},
                                    "config": {"run": {"max_trials": 10, "success_steps": 100}}}]})
    assert "Best single w found" not in bench.summary_markdown(agg)
    text = bench.summary_markdown(agg, record)
    assert "Best single w found" in text and "First-step bound" in text
    plain = bench.comparison_figures(agg, tmp_path / "f1", None, None)
    shown = bench.comparison_figures(agg, tmp_path / "f2", None, None, ceiling=record)
    assert [p.name for p in plain] == [p.name for p in shown] == ["fig3a_success_rate.png", "fig3b_elapsed_time.png"]
    assert plain[0].read_bytes() != shown[0].read_bytes() and plain[1].read_bytes() == shown[1].read_bytes()
    bad = tmp_path / "bad.json"
    bad.write_text('{"format_version": 1}')
    with pytest.raises(results.ResultsError, match="not a ceiling record"):
        records.load_ceiling(bad)
    res = run("bench", "--profile", "quick", "--out", str(tmp_path / "b"), "--ceiling", str(bad), "--quiet")
    assert res.returncode == 2 and "not a ceiling record" in res.stderr and not (tmp_path / "b").exists()
