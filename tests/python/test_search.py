# SPDX-License-Identifier: Apache-2.0
"""The episodic search (mode search, method.md, L4; conditions ico-search and search) through the binding:
the update after each batch of trials against a numpy reference of the same step (with its
fallback: when Sigma' is not positive definite, the floor is added to the whole diagonal), a step
of 1 with small elites over many updates, the per-trial draws in distribution, determinism, and
the no-learning control (learn = 0).

Each trial's sampled w is read off the controller's output: its first four ticks observe
s = r_i e_i / 2 (r the input ranges), where z = w^T x~ = w_i x~_i."""
from pathlib import Path

import numpy as np
import pytest

from icoac.core import binding as B
from icoac.studies import conditions
from icoac.core import grid
from icoac.studies import prior as P
from icoac.core.config import build_config

from stepping import FAILED, REAL, controller, posterior, random_prior, random_state, reset, retune, scaled, stored, tick

FIXTURES = Path(__file__).resolve().parent / "fixtures"
FLOAT = B.real_dtype == np.float32
TINY = {"max_trials": 12, "success_steps": 300}


def probes(cfg):
    """The four probe states and their scaled value on the probed axis."""
    ranges = np.array(cfg.controller.policy.input_range[:B.N_INPUTS], dtype=float)
    states = [stored(0.5 * ranges[i] * np.eye(4)[i]) for i in range(4)]
    return states, np.array([scaled(cfg, s)[i] for i, s in enumerate(states)])


def run_trial(cfg, state, length, rng, terminal=True):
    """reset, `length` (>= 4) non-terminal ticks, the first four the probes, then a failure;
    returns the trial's w as read from z."""
    states, x = probes(cfg)
    reset(cfg, state)
    z = np.array([tick(cfg, state, s).z for s in states], dtype=float)
    for _ in range(length - 4):
        tick(cfg, state, random_state(rng))
    if terminal:
        out = tick(cfg, state, FAILED, terminal=True)
        assert out.force == 0 and out.noise == 0
    return z / x


def elite_size(cfg):
    """n_e = max(1, round(rho K)), halves up, on the configured real values."""
    s = cfg.controller.search
    return max(1, int(REAL(s.elite_fraction) * REAL(s.batch) + REAL(0.5)))


def min_relative_pivot(m):
    """The smallest pivot of the Cholesky factorisation of m, each relative to its diagonal entry;
    the first one <= 0 when m is not positive definite (the factorisation stops there)."""
    lower = np.zeros((4, 4))
    smallest = 1.0
    for j in range(4):
        diag = m[j, j] - lower[j, :j] @ lower[j, :j]
        smallest = min(smallest, diag / m[j, j])
        if not diag > 0:
            return smallest
        lower[j, j] = np.sqrt(diag)
        for i in range(j + 1, 4):
            lower[i, j] = (m[i, j] - lower[i, :j] @ lower[j, :j]) / lower[j, j]
    return smallest


def reference_update(cfg, mu, sigma, floor, ws, lengths):
    """mu' = (1-a) mu + a mean_elite, Sigma' = (1-a) Sigma + a Cov_elite (about mu', / n_e), then
    Sigma'_ii >= floor_i; the elite: the n_e longest trials, ties to the earlier one. When Sigma'
    is not positive definite, or a relative Cholesky pivot is below 1e-4 (a rank-deficient elite,
    n_e <= 4, with a step near 1), the fallback Sigma' + diag(floor). Returns mu', Sigma', the fallback and min_relative_pivot(Sigma')."""
    a = cfg.controller.search.step
    order = sorted(range(len(lengths)), key=lambda k: -lengths[k])  # stable: earlier first among ties
    elite = np.array([ws[k] for k in order[:elite_size(cfg)]])
    mu1 = (1 - a) * mu + a * elite.mean(axis=0)
    d = elite - mu1
    sigma1 = (1 - a) * sigma + a * d.T @ d / len(elite)
    idx = np.arange(4)
    sigma1[idx, idx] = np.maximum(sigma1[idx, idx], floor)
    return mu1, sigma1, sigma1 + np.diag(floor), min_relative_pivot(sigma1)


def check_update(mu, sigma, want, ws, what=""):
    """The library's (mu', Sigma') against reference_update's: Sigma' when it is positive definite
    with a margin (every relative pivot above a band for the rounding of Sigma' in the real type,
    with the cancellation in w - mu'); in the band below, where Sigma' is singular up to rounding
    (in exact arithmetic it is positive semidefinite) and the library's own Cholesky factorisation
    passes or fails by rounding, Sigma' or the fallback. Returns True for the fallback."""
    want_mu, want_sigma, fallback, pivot = want
    scale = 1 + np.abs(np.array(ws)).max()
    tol = 2e-6 if FLOAT else 1e-12
    band = (1e-4 if FLOAT else 1e-10) * (1 + scale / np.sqrt(want_sigma.diagonal().min()))
    band = max(band, 1.01e-4)  # the library also treats a relative pivot below 1e-4 as singular
    np.testing.assert_allclose(mu, want_mu, rtol=0, atol=tol * scale, err_msg=what)
    close = np.abs(sigma - want_sigma).max() <= 2 * tol * scale ** 2
    if pivot > band or close:
        np.testing.assert_allclose(sigma, want_sigma, rtol=0, atol=2 * tol * scale ** 2, err_msg=what)
        return False
    np.testing.assert_allclose(sigma, fallback, rtol=0, atol=2 * tol * scale ** 2, err_msg=what)
    return True


def assert_spd(sigma, floor, singular=False):
    """Symmetric, above the floor, positive definite; with `singular` (a step near 1 and an elite
    of 2 to 4, where the library may keep a Sigma' singular up to rounding) positive semidefinite
    up to rounding."""
    assert np.array_equal(sigma, sigma.T) and np.all(sigma.diagonal() >= floor)
    margin = (1e-5 if FLOAT else 1e-13) * np.abs(sigma).max() if singular else 0.0
    assert np.linalg.eigvalsh(sigma).min() > -margin


def initial_cov(cfg, cov):
    """Sigma0 = c * the prior covariance, in the real type."""
    return (np.asarray(cov).astype(REAL) * REAL(cfg.controller.search.cov_scale)).astype(float)


SETTINGS = [  # (batch, elite_fraction, step, floor, cov_scale)
    (8, 0.25, 0.5, 1.0, 64.0),    # the defaults
    (4, 0.5, 0.5, 0.1, 1.0),      # the defaults before the learner sweeps
    (5, 0.5, 0.3, 1.5, 1.0),      # round(2.5) = 3; the floor above Sigma0: active from the first update
    (8, 0.25, 0.7, 0.01, 4.0),
    (3, 1.0, 0.9, 0.05, 2.0),
    (6, 0.3, 0.5, 0.2, 16.0),     # round(1.8) = 2
    (16, 1.0, 1.0, 0.1, 1.0),     # a = 1: Sigma' = Cov of 16 trials (full rank)
    (4, 0.5, 1.0, 0.1, 1.0),      # a = 1, n_e = 2: Sigma' of rank 1 but for the floor (the fallback)
    (8, 0.25, 1.0, 1.0, 64.0),    # the defaults with a = 1
    (1, 1.0, 0.5, 0.1, 1.0),
]


def small_elite_near_one(cfg):
    """A step near 1 and an elite of 2 to 4: Sigma' can be singular (see assert_spd)."""
    return cfg.controller.search.step >= 0.7 and 2 <= elite_size(cfg) <= 4


@pytest.mark.parametrize("condition", ["search", "ico-search"])
@pytest.mark.parametrize("setting", SETTINGS, ids=[f"K{s[0]}-rho{s[1]}-a{s[2]}-f{s[3]}-c{s[4]}" for s in SETTINGS])
def test_update_matches_numpy(setting, condition):
    """Several batches: mu_w and Sigma_w stay until the batch's last failure, then equal the numpy
    step from the trials' w and lengths (lengths drawn from a few values: many ties), with its
    fallback where Sigma' is singular."""
    batch, rho, step, floor_f, cov_scale = setting
    rng = np.random.default_rng(batch * 100 + int(10 * step))
    if condition == "search":
        mean0, cov0 = np.zeros(4), np.eye(4)  # method.md, L4: search starts from N(0, I)
    else:
        mean0, cov0 = random_prior(rng, 0.3)
    cfg = build_config({"search.batch": batch, "search.elite_fraction": rho, "search.step": step,
                        "search.floor": floor_f, "search.cov_scale": cov_scale}, condition=condition)
    assert cfg.controller.mode == B.MODE_SEARCH
    state = controller(cfg, mean0, cov0, seed=batch + 7)
    sigma0 = initial_cov(cfg, cov0)
    floor = (REAL(floor_f) * sigma0.diagonal().astype(REAL)).astype(float)
    mu, sigma = posterior(state)
    assert np.array_equal(mu, stored(mean0)) and np.array_equal(sigma, sigma0)
    floored = 0
    for _ in range(4):
        lengths = [int(v) for v in rng.choice([4, 5, 5, 9, 12], size=batch)]
        ws = []
        for k, length in enumerate(lengths):
            ws.append(run_trial(cfg, state, length, rng))
            if k + 1 < batch:
                now = posterior(state)
                assert np.array_equal(now[0], mu) and np.array_equal(now[1], sigma)
        want = reference_update(cfg, mu, sigma, floor, ws, lengths)
        mu, sigma = posterior(state)
        check_update(mu, sigma, want, ws)
        assert_spd(sigma, floor, singular=small_elite_near_one(cfg))
        floored += int(np.sum(sigma.diagonal() == floor))
    if floor_f > 1:
        assert floored >= 4  # the floor was exercised


def test_elite_ties_go_to_the_earlier_trial():
    """K = 4, rho = 1/4 (one elite), a = 1/2 from mu = 0: mu' = w_elite / 2; of two longest trials of
    equal length the first is the elite."""
    cfg = build_config({"search.batch": 4, "search.elite_fraction": 0.25, "search.step": 0.5}, condition="search")
    rng = np.random.default_rng(1)
    state = controller(cfg, seed=3)
    ws = [run_trial(cfg, state, length, rng) for length in (6, 9, 9, 4)]
    mu, _ = posterior(state)
    np.testing.assert_allclose(mu, ws[1] / 2, rtol=1e-6, atol=1e-7)
    assert not np.allclose(mu, ws[2] / 2, rtol=1e-3)


def check_draws(cfg, state, rng, n):
    """The next n trials' w have mean mu_w and covariance Sigma_w (5 standard errors)."""
    mu, sigma = posterior(state)
    ws = np.array([run_trial(cfg, state, 4, rng, terminal=k % 2 == 0) for k in range(n)])
    d = ws - mu
    np.testing.assert_array_less(np.abs(d.mean(axis=0)), 5 * np.sqrt(sigma.diagonal() / n))
    se = np.sqrt((np.outer(sigma.diagonal(), sigma.diagonal()) + sigma ** 2) / n)
    np.testing.assert_array_less(np.abs(d.T @ d / n - sigma), 5 * se)
    return sigma, se


def test_draws_have_the_search_distribution():
    """Over many trials without learning, the sampled w have mean mu_w and covariance Sigma_w
    (within 5 standard errors): Sigma_w = c times a correlated prior covariance at first, then
    the Sigma_w of an update (the draws follow the new Cholesky factor)."""
    rng = np.random.default_rng(11)
    mean0, cov0 = random_prior(rng, 0.5)
    # a floor below Sigma0 (the default, f = 1, holds every variance at least at Sigma0's)
    over = {"search.cov_scale": 3.0, "search.batch": 6, "search.elite_fraction": 0.5, "search.step": 0.9,
            "search.floor": 0.1}
    frozen = build_config({**over, "learn": False}, condition="ico-search")
    learning = build_config(over, condition="ico-search")
    state = controller(frozen, mean0, cov0, seed=21)
    sigma, se = check_draws(frozen, state, rng, 20000)
    assert np.abs(sigma[0, 1]) > 10 * se[0, 1]  # the correlations are there to be matched
    retune(learning, state)
    for length in (4, 9, 5, 12, 6, 7):  # one update
        run_trial(learning, state, length, rng)
    retune(frozen, state)
    updated, _ = check_draws(frozen, state, rng, 20000)
    assert np.abs(updated - sigma).max() > 20 * se.max()  # a different distribution to match


@pytest.mark.parametrize("setting", [(4, 0.5, 0.1, 1.0), (8, 0.25, 1.0, 64.0), (3, 1.0, 0.01, 1.0)],
                         ids=["K4-rho0.5-f0.1", "K8-rho0.25-f1-c64", "K3-rho1-f0.01"])
def test_step_one_small_elites(setting):
    """a = 1 with an elite of 2 or 3 trials: Sigma' = Cov_elite (floored) is singular unless the
    floor repairs it; then the floor is added to the whole diagonal (the update used to fail with
    ICOAC_ERR_NUMERIC). Over many random updates from N(0, I): every terminal tick OK, every
    update the reference's (its fallback where the library's Cholesky factorisation of Sigma'
    fails), Sigma_w positive (semi)definite, the fallback taken in many updates."""
    batch, rho, floor_f, cov_scale = setting
    rng = np.random.default_rng(batch)
    cfg = build_config({"search.batch": batch, "search.elite_fraction": rho, "search.step": 1.0,
                        "search.floor": floor_f, "search.cov_scale": cov_scale}, condition="search")
    updates = fallbacks = 0
    for restart in range(6):  # mu_w random-walks at a = 1: a fresh start now and then
        state = controller(cfg, seed=restart + 1)
        floor = (REAL(floor_f) * initial_cov(cfg, np.eye(4)).diagonal().astype(REAL)).astype(float)
        for _ in range(60):
            mu, sigma = posterior(state)
            lengths = [int(v) for v in rng.integers(4, 8, size=batch)]
            ws = [run_trial(cfg, state, length, rng) for length in lengths]  # every terminal tick OK
            want = reference_update(cfg, mu, sigma, floor, ws, lengths)
            mu, sigma = posterior(state)
            fallbacks += check_update(mu, sigma, want, ws, what=f"update {updates}")
            assert_spd(sigma, floor, singular=True)
            updates += 1
    assert fallbacks > updates // 20, (fallbacks, updates)


def test_deterministic_for_a_seed():
    """Same seed and observations: the same trials' w and posterior; another seed, other draws.
    A grid of the search condition: the same cells on 1 and 2 threads."""
    cfg = build_config({"search.batch": 2}, condition="search")
    runs = []
    for seed in (5, 5, 6):
        rng = np.random.default_rng(0)
        state = controller(cfg, seed=seed)
        ws = [run_trial(cfg, state, 4 + k % 5, rng) for k in range(10)]
        runs.append((np.array(ws), posterior(state)))
    assert np.array_equal(runs[0][0], runs[1][0]) and np.array_equal(runs[0][1][1], runs[1][1][1])
    assert not np.array_equal(runs[0][0][0], runs[2][0][0])
    tiny = build_config({**TINY, "search.batch": 2}, condition="search")
    a, b = grid.make_cells(3, [300, 611, 900]), grid.make_cells(3, [300, 611, 900])
    grid.run_grid(tiny, a, threads=1, progress=False)
    grid.run_grid(tiny, b, threads=2, progress=False)
    assert a.tobytes() == b.tobytes() and np.all(a["status"] == 0)


@pytest.mark.parametrize("condition", ["ico-search", "search"])
def test_no_learning_control_learns_nothing(condition, ico_dir):
    """The condition with learn = 0 (its no-learning control, method.md, L1): over a grid every cell ends
    with mu_w = the prior mean and Sigma_w = Sigma0 = c Sigma_prior exactly; tick by tick, full
    batches of failures change neither; the learning condition does change them."""
    info = conditions.condition_prior(condition, ico_dir if condition == "ico-search" else None,
                                      P.DEFAULT_FRAME, P.DEFAULT_RIDGE)
    prior = info.prior()
    over = {**TINY, "search.cov_scale": 2.0, "search.batch": 2}
    control = build_config({**over, "learn": False}, condition=condition, prior=prior)
    learning = build_config(over, condition=condition, prior=prior)
    mean = np.array(prior.mean[:B.N_INPUTS], dtype=float)
    sigma0 = initial_cov(control, [list(r)[:B.N_INPUTS] for r in prior.cov[:B.N_INPUTS]])
    cells = {}
    for name, cfg in (("control", control), ("learning", learning)):
        cells[name] = grid.make_cells(9, [0, 300, 611, 900, 1224])
        grid.run_grid(cfg, cells[name], threads=2, progress=False)
        assert np.all(cells[name]["status"] == 0)
    for w, c in zip(cells["control"]["weights"], cells["control"]["cov"]):
        assert np.array_equal(w[:4], mean) and np.array_equal(c[:4, :4], sigma0)
    assert np.any(cells["control"]["trials"] > 2)  # full batches were run
    learned = cells["learning"][cells["learning"]["trials"] > 2]
    assert len(learned) and not np.array_equal(learned["weights"][0][:4], mean)
    # tick by tick, through the batch's terminal ticks
    rng = np.random.default_rng(2)
    state = controller(control, mean, [list(r)[:B.N_INPUTS] for r in prior.cov[:B.N_INPUTS]], seed=4)
    start = posterior(state)
    draws = set()
    for k in range(10):
        draws.add(tuple(run_trial(control, state, 4 + k, rng)))
        now = posterior(state)
        assert np.array_equal(now[0], start[0]) and np.array_equal(now[1], start[1])
    assert len(draws) == 10  # a new w every trial all the same
