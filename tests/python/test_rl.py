# SPDX-License-Identifier: Apache-2.0
"""RL / ICO->RL: priors, RL grids, the Bayesian actor step against numpy, sweep and bench CLI."""
import csv
import ctypes
import json
import math
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from icoac.core import binding as B
from icoac.core import grid, results
from icoac.studies import prior as P
from icoac.core.config import build_config, make_prior, named_sets, parse_sets
from icoac.core.registry import CONDITIONS, REGISTRY

REPO = Path(__file__).resolve().parents[2]
PNG = b"\x89PNG\r\n\x1a\n"
TINY_RL = {"max_trials": 30, "success_steps": 500}
# The paper's literal reading of the actor (--configuration literal): the posterior update with
# sigma_L = sigma_u, per tick, exploring at every tick. The defaults use the gradient reading.
LITERAL = parse_sets(named_sets("literal"))


def run_cli(*args, timeout=60):
    return subprocess.run([sys.executable, "-m", "icoac", *args], cwd=REPO, capture_output=True, text=True,
                          timeout=timeout)


def one_line_error(res, words):
    assert res.returncode == 2, res.stderr
    assert "Traceback" not in res.stderr
    lines = res.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("icoac: error: "), res.stderr
    assert words in lines[0], lines[0]


# -- prior computation -----------------------------------------------------------------------------
def hand_cells():
    """Six cells: four successful inside the central frame, one successful outside, one failed inside."""
    cells = np.zeros(6, dtype=B.CELL_DTYPE)
    xs = [0.0, 1.2, -1.2, 0.5, 2.0, 0.1]
    th = [0.0, 6.0, -6.0, 3.0, 0.0, 1.0]
    cells["x0"] = xs
    cells["theta0"] = np.radians(th)
    cells["outcome"] = [B.SUCCESS] * 5 + [B.FAILED]
    rng = np.random.default_rng(3)
    cells["weights"][:, :4] = rng.normal(size=(6, 4))
    return cells


def test_prior_exact_mean_cov_and_frame():
    cells = hand_cells()
    info = P.compute(cells, P.DEFAULT_FRAME, ridge=1e-3)
    w = cells["weights"][:4, :4]  # frame bounds are inclusive: x0 = +-1.2 m, theta0 = +-6 deg are in
    assert info.n_cells == 4
    np.testing.assert_allclose(info.mean, w.mean(axis=0), rtol=0, atol=1e-15)
    d = w - w.mean(axis=0)
    np.testing.assert_allclose(info.cov, d.T @ d / 3 + 1e-3 * np.eye(4), rtol=1e-13, atol=1e-15)
    assert np.array_equal(info.cov, info.cov.T)
    # all successful cells
    every = P.compute(cells, None, ridge=0.0)
    assert every.n_cells == 5
    np.testing.assert_allclose(every.cov, np.cov(cells["weights"][:5, :4], rowvar=False))
    # narrower frame, ridge default
    narrow = P.compute(cells, (0.6, 3.0))
    assert narrow.n_cells == 2 and narrow.ridge == P.DEFAULT_RIDGE
    d = narrow.to_dict()
    assert d["frame"] == {"x0_abs_max": 0.6, "theta0_abs_max_deg": 3.0} and d["n_cells"] == 2
    # the prior taken apart: each condition's mean and covariance, and its provenance
    both = P.condition_prior("ico-rl", info)
    assert np.array_equal(both.mean, info.mean) and np.array_equal(both.cov, info.cov)
    ico_mean = P.condition_prior("ico-mean-rl", info, std=0.5)
    assert np.array_equal(ico_mean.mean, info.mean) and np.array_equal(ico_mean.cov, 0.25 * np.eye(4))
    ico_cov = P.condition_prior("rl-ico-cov", info)
    assert np.all(ico_cov.mean == 0) and np.array_equal(ico_cov.cov, info.cov)
    alone = P.condition_prior("rl", info, std=2.0)
    assert np.all(alone.mean == 0) and np.array_equal(alone.cov, 4.0 * np.eye(4))
    # nothing that ICO produced reaches RL alone: no source, no frame, no cell count
    d = alone.to_dict()
    assert (d["source"], d["frame"], d["n_cells"], d["mean_from"], d["cov_from"]) == (None, None, 0, "zero",
                                                                                      "isotropic")
    assert P.condition_prior("rl", None, std=2.0).to_dict() == d
    assert np.array_equal(P.condition_prior("search", None).cov, np.eye(4))
    with pytest.raises(P.PriorError, match="needs an ICO prior"):
        P.condition_prior("rl-ico-cov", None)
    with pytest.raises(P.PriorError, match="prior-std"):
        P.condition_prior("rl", None, std=0.0)


def test_prior_errors():
    cells = hand_cells()
    failed = cells.copy()
    failed["outcome"][:4] = B.FAILED  # only the cell at x0 = 2 m (outside the frame) succeeded
    with pytest.raises(P.PriorError, match="no ICO-successful cell"):
        P.compute(failed, P.DEFAULT_FRAME)
    assert P.compute(cells, None).n_cells == 5
    with pytest.raises(P.PriorError, match="at least 2"):
        P.compute(cells, (0.05, 0.5))
    with pytest.raises(P.PriorError):
        P.compute(cells, ridge=-1.0)
    with pytest.raises(P.PriorError):
        P.parse_frame("corner")


# -- the ICO results directory of the CLI tests: the ico_dir fixture of conftest.py ------------------
def test_prior_from_results_records_provenance(ico_dir):
    info = P.from_results(ico_dir)
    cells, record = results.load(ico_dir)
    ok = (cells["outcome"] == B.SUCCESS) & (np.abs(cells["x0"]) <= 1.2)
    assert info.n_cells == int(ok.sum()) >= 2
    np.testing.assert_allclose(info.mean, cells["weights"][ok][:, :4].mean(axis=0))
    assert info.source_commit == record["git"]["commit"]
    assert info.ico_phase_simulated_time == pytest.approx(float(cells["elapsed_time"].sum()))
    d = info.to_dict()
    assert (d["source_plant"], d["source_condition"], d["source_learn"]) == ("cart_pole", "ico", 1)


def test_prior_from_refuses_another_plant_or_a_run_that_did_not_learn(ico_dir, tmp_path):
    """A prior is for the plant of its ICO run, and only a run that learned is an ICO prior."""
    assert P.from_results(ico_dir, plant="cart_pole").source_seed is not None
    with pytest.raises(P.PriorError, match="an ICO run of the cart_pole, not of the furuta"):
        P.from_results(ico_dir, plant="furuta")
    cells, record = results.load(ico_dir)
    record["config"]["controller"]["learn"] = False  # e.g. a ceiling's evaluation of a fixed w
    fixed = tmp_path / "fixed"
    shutil.copytree(ico_dir, fixed)
    (fixed / results.RUN_FILE).write_text(json.dumps(record))
    with pytest.raises(P.PriorError, match="did not learn"):
        P.from_results(fixed)


# -- RL grids ------------------------------------------------------------------------------------------
@pytest.mark.parametrize("configuration", ["default", "literal"])
def test_rl_grid_deterministic_records_posterior(ico_dir, configuration):
    """Deterministic for any thread count; each cell records the mu_w and Sigma_w it learned: the
    literal (posterior) reading shrinks Sigma_w (no forgetting), the default gradient reading
    keeps it at the prior, bit for bit."""
    info = P.from_results(ico_dir)
    over = {**TINY_RL, **(LITERAL if configuration == "literal" else {})}
    cfg = build_config(over, condition="ico-rl", prior=info.prior())
    assert cfg.controller.mode == B.MODE_RL
    assert cfg.controller.actor.update == B.ACTOR_UPDATES["posterior" if configuration == "literal" else "gradient"]
    prior_cov = np.array([list(r)[:B.N_INPUTS] for r in info.prior().cov[:B.N_INPUTS]], dtype=float)  # in the real type
    a = grid.make_cells(5, [300, 611, 900])
    b = grid.make_cells(5, [300, 611, 900])
    grid.run_grid(cfg, a, threads=2, progress=False)
    grid.run_grid(cfg, b, threads=1, progress=False)
    for f in B.CELL_DTYPE.names:
        assert np.array_equal(a[f], b[f]), f
    assert np.all(a["outcome"] != B.PENDING) and np.all(a["status"] == 0)
    assert not np.array_equal(a["weights"][0][:4], info.mean)  # mu_w learned
    for cov in a["cov"]:
        assert np.array_equal(cov, cov.T) and not cov[4:].any()  # 0 after the cart-pole's 4 inputs
        assert np.all(np.linalg.eigvalsh(cov[:4, :4]) > 0)
        if configuration == "literal":
            assert np.trace(cov) < 0.99 * np.trace(prior_cov)  # no forgetting: Sigma_w shrinks
        else:
            assert np.array_equal(cov[:4, :4], prior_cov)  # the gradient reading moves mu_w only
    rl = build_config(TINY_RL, condition="rl", prior=P.condition_prior("rl", None).prior())
    c = grid.make_cells(5, [611])
    grid.run_grid(rl, c, progress=False)
    assert c["outcome"][0] != B.PENDING


# -- the no-learning controls (method.md, L1) -----------------------------------------------------------------
@pytest.mark.parametrize("configuration", ["default", "literal"])
@pytest.mark.parametrize("condition", ["ico-rl-control", "rl-ico-cov-control", "rl-control"])
def test_control_learns_nothing_and_equals_zero_rates(ico_dir, condition, configuration):
    """A control keeps the prior exactly (mu_w and Sigma_w of every cell), and its outcomes equal
    those of its condition with the learning rates at 0: the critic rate and the actor's, the
    rate beta of the gradient reading (ICO->RL's default), the scale alpha of the mean (RL
    alone's default) and posterior (literal) ones."""
    info = P.condition_prior(REGISTRY[condition].control_of, P.from_results(ico_dir))
    prior = info.prior()
    named = LITERAL if configuration == "literal" else {}
    control = build_config({**TINY_RL, **named}, condition=condition, prior=prior)
    assert control.controller.learn == 0 and control.controller.mode == B.MODE_RL
    base = REGISTRY[condition].control_of
    reading = build_config({**TINY_RL, **named}, condition=base).flat()["actor.update"]
    actor_rate = "actor.rate" if reading == "gradient" else "actor.scale"  # beta, or alpha of u_ob
    zero = build_config({**TINY_RL, **named, "critic.rate": 0, actor_rate: 0}, condition=base, prior=prior)
    learning = build_config({**TINY_RL, **named}, condition=base, prior=prior)
    cells = {name: grid.make_cells(5, [300, 611, 612, 900]) for name in ("control", "zero", "learning")}
    for name, cfg in (("control", control), ("zero", zero), ("learning", learning)):
        grid.run_grid(cfg, cells[name], threads=2, progress=False)
    mean = np.array(prior.mean, dtype=float)  # zero after the task's 4 inputs, as the cells' weights
    cov = np.array([list(r) for r in prior.cov], dtype=float)
    for w, c in zip(cells["control"]["weights"], cells["control"]["cov"]):
        assert np.array_equal(w, mean) and np.array_equal(c, cov)
    for f in ("outcome", "status", "trials", "total_steps", "last_trial_steps"):
        assert np.array_equal(cells["control"][f], cells["zero"][f]), f
    assert not np.array_equal(cells["learning"]["weights"], cells["control"]["weights"])


def test_cli_control_condition_records_its_prior(ico_dir, tmp_path):
    out = tmp_path / "control"
    res = run_cli("grid", "--condition", "ico-rl-control", "--prior-from", str(ico_dir), "--out", str(out),
                  "--cells", "611", "--max-trials", "5", "--success-steps", "300", "--quiet")
    assert res.returncode == 0, res.stderr
    record = json.loads((out / "run.json").read_text())
    assert record["condition"] == "ico-rl-control" and record["config"]["controller"]["learn"] is False
    assert record["prior_info"]["mean"] == P.from_results(ico_dir).to_dict()["mean"]


# -- the Bayesian actor step against the closed-form posterior -----------------------------------------
def controller(cfg, mean, cov, seed=1):
    state = B.State()
    B.check_status(B.lib.icoac_init(ctypes.byref(cfg.controller), ctypes.byref(state),
                                    ctypes.byref(make_prior(mean, cov)), seed))
    return state


def tick(cfg, state, s, terminal=False):
    inp = B.Input()
    for i in range(4):
        inp.s[i] = s[i]
    inp.flags = B.INPUT_TERMINAL if terminal else 0
    out = B.Output()
    B.check_status(B.lib.icoac_step(ctypes.byref(state), ctypes.byref(inp), ctypes.byref(out)))
    return out


def posterior(state):
    post = B.get_posterior(state)
    return (np.array(post.mean[:B.N_INPUTS], dtype=float),
            np.array([list(r)[:B.N_INPUTS] for r in post.cov[:B.N_INPUTS]], dtype=float))


MU = np.array([0.08, 0.05, 0.3, 0.09])
A = np.array([[1.0, 0.2, 0.0, 0.1], [0.0, 0.7, 0.3, 0.0], [0.2, 0.0, 0.9, 0.2], [0.0, 0.1, 0.0, 0.5]])
SIGMA = 0.05 * A @ A.T + 0.01 * np.eye(4)
S_T = np.array([0.3, -0.4, 0.05, 0.6])  # inside the limits and outside the reflex zone
S_T1 = np.array([0.31, -0.38, 0.052, 0.58])


def closed_form(cfg, mu, sigma, s_t, delta, eps):
    c = cfg.controller
    rng = np.array(c.policy.input_range[:B.N_INPUTS], dtype=float)
    h = c.policy.gain * np.clip(s_t / rng, -1.0, 1.0)
    y = h @ mu + c.actor.scale * delta * eps  # u_ob = mu_u + alpha * delta * eps
    # the likelihood std sigma_L (method.md, L2), not sigma_u; but sigma_u when likelihood_std is 0
    sigma_l = c.actor.likelihood_std if c.actor.likelihood_std != 0 else c.actor.noise_std
    S = h @ sigma @ h + sigma_l ** 2
    return mu + sigma @ h * (y - h @ mu) / S, sigma - np.outer(sigma @ h, sigma @ h) / S


@pytest.mark.parametrize("noise_std, actor_scale, likelihood_std",
                         [(1.0, 0.5, None), (2.0, 1.0, None), (2.0, 1.0, 2.0), (1.0, 0.5, 3.0), (0.5, 1.0, None)])
def test_bayes_step_terminal_matches_closed_form(noise_std, actor_scale, likelihood_std):
    """The posterior reading (the literal configuration) after one transition into a failure."""
    over = {**LITERAL, "actor.noise_std": noise_std, "actor.scale": actor_scale}
    if likelihood_std is not None:
        over["actor.likelihood_std"] = likelihood_std
    cfg = build_config(over, condition="rl")
    assert cfg.controller.actor.update == B.ACTOR_UPDATES["posterior"]
    # default sigma_L: 0, sigma_L = sigma_u (literal)
    assert cfg.controller.actor.likelihood_std == (likelihood_std or 0.0)
    state = controller(cfg, MU, SIGMA, seed=11)
    out1 = tick(cfg, state, S_T)
    assert out1.status == 0 and out1.value == 0.0 and out1.noise != 0.0
    mu0, sig0 = posterior(state)
    np.testing.assert_allclose(mu0, MU, rtol=1e-6)  # no update on the first tick
    out2 = tick(cfg, state, S_T1, terminal=True)
    delta = float(out2.td_error)
    assert delta == pytest.approx(-1.0)  # r = -1, V(terminal) = 0, V(s_t) = 0
    mu_ref, cov_ref = closed_form(cfg, mu0, sig0, S_T, delta, float(out1.noise))
    mu, cov = posterior(state)
    np.testing.assert_allclose(mu, mu_ref, rtol=2e-5, atol=1e-6)
    np.testing.assert_allclose(cov, cov_ref, rtol=2e-4, atol=2e-6)
    assert not np.allclose(mu, MU, rtol=1e-4)


def test_bayes_step_zero_td_error_keeps_mean():
    """Posterior reading: delta = 0 keeps mu_w, and Sigma_w still shrinks."""
    cfg = build_config({**LITERAL, "critic.discount": 0.95}, condition="rl")
    state = controller(cfg, MU, SIGMA, seed=5)
    mu0, sig0 = posterior(state)
    out1 = tick(cfg, state, S_T)
    out2 = tick(cfg, state, S_T1)  # non-terminal: r = 0, V = 0 (untrained critic) -> delta = 0
    assert out1.value == 0.0 and out2.value == 0.0 and out2.td_error == 0.0
    mu, cov = posterior(state)
    assert np.array_equal(mu, mu0)
    _, cov_ref = closed_form(cfg, mu0, sig0, S_T, 0.0, float(out1.noise))
    np.testing.assert_allclose(cov, cov_ref, rtol=2e-4, atol=2e-6)
    assert np.trace(cov) < np.trace(sig0) * (1 - 1e-3)


# -- CLI: grid, sweep, bench -------------------------------------------------------------------------
def test_cli_grid_ico_rl_records_prior(ico_dir, tmp_path):
    out = tmp_path / "icorl"
    res = run_cli("grid", "--condition", "ico-rl", "--prior-from", str(ico_dir), "--out", str(out),
                  "--cells", "611,612", "--max-trials", "30", "--success-steps", "500", "--quiet")
    assert res.returncode == 0, res.stderr
    record = json.loads((out / "run.json").read_text())
    pi = record["prior_info"]
    assert record["condition"] == "ico-rl" and record["config"]["controller"]["mode"] == "rl"
    assert record["config"]["controller"]["actor"]["noise_std"] == 3.0  # the default sigma_u
    assert pi["source"] == str(ico_dir.resolve()) and pi["n_cells"] >= 2 and pi["ico_phase_simulated_time"] > 0
    assert pi["frame"] == {"x0_abs_max": 1.2, "theta0_abs_max_deg": 6.0} and len(pi["cov"]) == 4
    res = run_cli("grid", "--out", str(out), "--resume", "--quiet")
    assert res.returncode == 0, res.stderr
    assert json.loads((out / "run.json").read_text())["prior_info"] == pi


def test_cli_configuration_literal(ico_dir, tmp_path):
    """--configuration literal records the paper's literal reading, before --set (a later --set
    wins); the default configuration records the gradient reading chosen by the sweeps."""
    common = ["--prior-from", str(ico_dir), "--cells", "611", "--max-trials", "5", "--success-steps", "300", "--quiet"]
    actors = {}
    for name, extra in (("default", []), ("literal", ["--configuration", "literal"]),
                        ("literal-set", ["--configuration", "literal", "--set", "actor.explore_ticks=7"])):
        res = run_cli("grid", "--condition", "ico-rl", "--out", str(tmp_path / name), *common, *extra)
        assert res.returncode == 0, res.stderr
        actors[name] = json.loads((tmp_path / name / "run.json").read_text())["config"]["controller"]["actor"]
    assert actors["default"]["update"] == "gradient" and actors["default"]["explore_ticks"] == 1000
    assert actors["literal"]["update"] == "posterior" and actors["literal"]["explore_ticks"] == 0
    assert actors["literal"]["likelihood_std"] == 0.0 and actors["literal"]["batch"] is False
    assert actors["literal-set"] == {**actors["literal"], "explore_ticks": 7}


@pytest.mark.parametrize("args, words", [
    (["grid", "--condition", "ico-rl", "--prior-from", "{tmp}/none", "--out", "{tmp}/a"], "does not exist"),
    (["grid", "--condition", "ico-rl", "--out", "{tmp}/a"], "--prior-from"),
    (["grid", "--condition", "ico-rl", "--prior-from", "{ico}", "--prior-x", "0.01", "--prior-theta", "0.1",
      "--out", "{tmp}/a"], "ICO-successful cell in the prior frame"),
    (["sweep", "--prior-from", "{ico}", "--out", "{tmp}/w", "--param", "actor.noise_std"], "--param"),
    (["sweep", "--prior-from", "{ico}", "--out", "{tmp}/w", "--param", "nosie_std=1,2"], "unknown parameter"),
    (["sweep", "--prior-from", "{ico}", "--out", "{tmp}/w", "--param", "actor.noise_std=1,-2"], "actor"),
    (["sweep", "--prior-from", "{ico}", "--out", "{tmp}/w", "--param", "prior_frame=wide"], "prior_frame"),
    (["sweep", "--prior-from", "{tmp}/none", "--out", "{tmp}/w", "--param", "actor.noise_std=1"], "does not exist"),
])
def test_cli_rl_errors(ico_dir, tmp_path, args, words):
    res = run_cli(*[a.format(tmp=tmp_path, ico=ico_dir) for a in args])
    one_line_error(res, words)


def test_sweep_two_settings_resumable(ico_dir, tmp_path):
    out = tmp_path / "sweep"
    args = ["sweep", "--prior-from", str(ico_dir), "--out", str(out), "--param", "actor.noise_std=0.5,2",
            "--cells", "0,611", "--max-trials", "20", "--success-steps", "500", "--quiet"]
    res = run_cli(*args)
    assert res.returncode == 0, res.stderr
    with open(out / "sweep.csv", newline="") as fh:
        rows = list(csv.DictReader(fh))
    assert len(rows) == 2 and [r["actor.noise_std"] for r in rows] == ["0.5", "2"]
    assert [json.loads(r["key"]) for r in rows] == [{"actor.noise_std": 0.5}, {"actor.noise_std": 2}]
    assert rows[0]["n_ico_failed"] == "1" and rows[0]["n_cells"] == "2"
    assert (out / "sweep.md").read_text().count("\n| ") >= 3
    assert json.loads((out / "sweep.json").read_text())["seeds"] == [0]
    res = run_cli(*args)  # resumed: nothing rerun, still two rows
    assert res.returncode == 0 and res.stderr.count("skipped") == 2
    with open(out / "sweep.csv", newline="") as fh:
        assert len(list(csv.DictReader(fh))) == 2


def test_sweep_seed_and_seeds(ico_dir, tmp_path):
    out = tmp_path / "sweep"
    res = run_cli("sweep", "--prior-from", str(ico_dir), "--out", str(out), "--param", "actor.scale=0.5",
                  "--cells", "611", "--max-trials", "5", "--success-steps", "100", "--seed", "3", "--seeds", "2",
                  "--quiet")
    assert res.returncode == 0, res.stderr
    assert json.loads((out / "sweep.json").read_text())["seeds"] == [3, 4]
    with open(out / "sweep.csv", newline="") as fh:
        assert [r["n_seeds"] for r in csv.DictReader(fh)] == ["2"]


def test_bench_quick_writes_comparison(tmp_path):
    out, fig = tmp_path / "b", tmp_path / "fig"
    res = run_cli("bench", "--profile", "quick", "--out", str(out), "--figures", str(fig), "--quiet",
                  "--rl-max-trials", "100", timeout=120)
    assert res.returncode == 0, res.stderr
    for name in ("fig2b_icorl_success_map.png", "fig3a_success_rate.png", "fig3b_elapsed_time.png",
                 "fig3c_learning_curves.png", "fig1b_success_map.png"):
        data = (fig / name).read_bytes()
        assert data[:8] == PNG and len(data) > 5000
    # every condition: ICO, the actor-critic from the four priors, ICO->search and search, each
    # learner with its control, the LQR baseline and CMA-ES
    conds = ("ico", "ico-rl", "ico-rl-control", "ico-mean-rl", "ico-mean-rl-control", "rl-ico-cov",
             "rl-ico-cov-control", "rl", "rl-control", "ico-search", "ico-search-control", "search",
             "search-control", "lqr", "cma-es")
    assert CONDITIONS == conds
    for cond in conds:
        for seed in (0, 1):
            assert results.exists(out / cond / f"seed-{seed}")
    summary = json.loads((out / "summary.json").read_text())
    assert set(summary) == set(conds) and summary["ico"]["paper"]["success_rate"] == 0.68
    text = (out / "summary.md").read_text()
    assert "ICO->RL" in text
    for cond, control in ((c.name, c.control) for c in REGISTRY.values() if c.control):
        assert f"| {REGISTRY[cond].label} | {REGISTRY[control].label} |" in text
        # the gain over the control, recomputed from the cells
        gain = summary[cond]["gain_over_control"]
        for i, seed in enumerate((0, 1)):
            a, _ = results.load(out / cond / f"seed-{seed}")
            b, _ = results.load(out / control / f"seed-{seed}")
            sa, sb = a["outcome"] == B.SUCCESS, b["outcome"] == B.SUCCESS
            assert gain["cells_gained"]["per_seed"][i] == np.count_nonzero(sa & ~sb)
            assert gain["cells_lost"]["per_seed"][i] == np.count_nonzero(~sa & sb)
        assert "gain_over_control" not in summary[control]
    # the learning curve of every condition: its cells' trials to success, averaged over the seeds
    for cond in conds:
        curve = summary[cond]["success_within"]
        per_seed = []
        for seed in (0, 1):
            a, _ = results.load(out / cond / f"seed-{seed}")
            ok = a["outcome"] == B.SUCCESS
            per_seed.append([np.count_nonzero(ok & (a["trials"] <= k)) / a.size for k in curve["k"]])
        np.testing.assert_allclose(curve["all"]["mean"], np.mean(per_seed, axis=0), rtol=1e-12)
        assert all(np.diff(curve["all"]["mean"]) >= 0)
    assert "prior mean | prior covariance" in text and "k = 100 |" in text
    # RL alone takes nothing from ICO; under the default (gradient) reading the prior covariance
    # plays no part, so the ICO mean with sigma_w^2 I gives ICO->RL's cells bit for bit
    for seed in (0, 1):
        record = json.loads((out / "rl" / f"seed-{seed}" / "run.json").read_text())
        assert record["prior_info"]["source"] is None and record["prior_info"]["cov_from"] == "isotropic"
        a, _ = results.load(out / "ico-rl" / f"seed-{seed}")
        b, _ = results.load(out / "ico-mean-rl" / f"seed-{seed}")
        for f in ("outcome", "trials", "weights"):
            assert np.array_equal(a[f], b[f]), f
    bench = json.loads((out / "bench.json").read_text())
    assert bench["complete"] and len(bench["stages"]) == 2 * len(conds) + 2 + 2  # grids, priors, summary, figures
    # the search conditions: Sigma0 = 64 x the ICO prior's covariance (ico-search), 4 I (search)
    for cond, scale in (("ico-search", 64.0), ("ico-search-control", 64.0), ("search", 4.0),
                        ("search-control", 4.0)):
        record = json.loads((out / cond / "seed-0" / "run.json").read_text())
        controller = record["config"]["controller"]
        assert controller["mode"] == "search" and controller["search"]["cov_scale"] == scale
        assert controller["learn"] is REGISTRY[cond].learns
        identity = record["prior_info"]["cov"] == np.eye(4).tolist()
        assert identity is cond.startswith("search"), cond
    icorl = json.loads((out / "ico-rl" / "seed-0" / "run.json").read_text())
    assert icorl["prior_info"]["source"] == str((out / "ico" / "seed-0").resolve())
    assert icorl["config"]["run"]["max_trials"] == 100
    # resume: every grid is complete, nothing reruns, figures are byte-identical
    before = (fig / "fig3a_success_rate.png").read_bytes()
    cells_before, _ = results.load(out / "rl" / "seed-1")
    res = run_cli("bench", "--profile", "quick", "--out", str(out), "--figures", str(fig), "--quiet",
                  "--rl-max-trials", "100", "--resume", timeout=120)
    assert res.returncode == 0, res.stderr
    assert (fig / "fig3a_success_rate.png").read_bytes() == before
    cells_after, record = results.load(out / "rl" / "seed-1")
    assert np.array_equal(cells_before, cells_after) and record["complete"]
    assert json.loads((out / "bench.json").read_text())["meta"]["resume"] is True
    # --summary-only runs nothing and summarises the grids OUT holds: the same summary as the bench's
    res = run_cli("bench", "--profile", "quick", "--out", str(out), "--summary-only", "--quiet",
                  "--data", str(tmp_path / "data.json"), timeout=120)
    assert res.returncode == 0, res.stderr
    assert json.loads((out / "summary.json").read_text()) == summary
    assert json.loads((tmp_path / "data.json").read_text())["aggregate"] == summary
    assert json.loads((out / "bench.json").read_text())["meta"]["resume"] is True  # the grids' log stays


def test_prior_from_a_run_of_other_input_signs_is_refused(tmp_path, ico_dir):
    """An ICO prior's weights are in its run's signed inputs (task.input_sign): a task of other
    signs refuses it in one line, before any write."""
    out = tmp_path / "icorl"
    res = run_cli("grid", "--condition", "ico-rl", "--prior-from", str(ico_dir), "--out", str(out), "--cells", "611",
              "--max-trials", "5", "--set", "task.input_sign=[-1,1,1,1]")
    assert res.returncode == 2, res.stderr
    lines = res.stderr.strip().splitlines()
    assert len(lines) == 1 and "the ICO run's input signs [1, 1, 1, 1] are not this task's [-1, 1, 1, 1]" in lines[0]
    assert not out.exists()
    # the ceiling's search starts from the same mean, in the same coordinates
    out = tmp_path / "ceiling"
    res = run_cli("ceiling", "--prior-from", str(ico_dir), "--out", str(out), "--cells", "611",
                  "--set", "task.input_sign=[-1,1,1,1]")
    assert res.returncode == 2, res.stderr
    lines = res.stderr.strip().splitlines()
    assert len(lines) == 1 and "the ICO run's input signs [1, 1, 1, 1] are not this task's [-1, 1, 1, 1]" in lines[0]
    assert not out.exists()
