# SPDX-License-Identifier: Apache-2.0
"""The actor readings (method.md, L2), the per-trial batch (A14), the exploration schedule (L3) and the
critic quirks (A10) through the binding: every actor step against an independent numpy formula,
from the observed states and what the ticks output (exploration noise eps, TD error delta):

    posterior  S = h^T Sigma h + sigma_L^2, mu += Sigma h iota / S, Sigma -= Sigma h h^T Sigma / S
    mean       mu += Sigma0 h iota / (h^T Sigma0 h + sigma_L^2), Sigma stays Sigma0
    gradient   mu += beta delta eps h / sigma_u^2, Sigma stays

with iota = alpha delta eps (+ h^T (w_act - mu) when acting with a sample) and h = G x~(s_t);
sigma_L = actor.likelihood_std, or sigma_u (actor.noise_std) when it is 0 (the default).
"""
import numpy as np
import pytest

from icoac.core import binding as B
from icoac.core.config import build_config

from stepping import (FAILED, REAL, controller, features, likelihood_var, posterior, random_prior, random_state, reset,
                      stored, tick)

READINGS = ("posterior", "mean", "gradient")
FLOAT = B.real_dtype == np.float32
RTOL = 2e-5 if FLOAT else 1e-12
BASE = np.array([0.2, 0.1, 0.12, 0.3])  # near the failure state FAILED (theta 0.25 rad)


def near_failure(rng):
    """A state around BASE: after a failure from there the (dense) critic's V is clearly not 0, so
    the TD errors of these transitions are not either."""
    return stored(BASE + rng.uniform(-1, 1, size=4) * np.array([0.5, 0.5, 0.05, 0.5]))


def trace(cov):
    """The library's trace of Sigma_w: (c00 + c11) + (c22 + c33) in the real type."""
    c = np.asarray(cov).astype(REAL)
    return (c[0, 0] + c[1, 1]) + (c[2, 2] + c[3, 3])


def reading_step(cfg, mu, sigma, h, delta, eps, offset=0.0):
    """One step of the configured reading, in float64."""
    a = cfg.controller.actor
    iota = offset + a.scale * delta * eps
    if a.update == B.ACTOR_UPDATES["gradient"]:
        return mu + a.rate * delta * eps * h / a.noise_std ** 2, sigma
    sh = sigma @ h
    s = h @ sh + likelihood_var(cfg)
    if a.update == B.ACTOR_UPDATES["mean"]:
        return mu + sh * iota / s, sigma
    return mu + sh * iota / s, sigma - np.outer(sh, sh) / s


def rl_config(reading, **over):
    """RL with the reading and a dense critic (threshold 0: V is not 0 away from the units' centres)."""
    return build_config({"actor.update": reading, "critic.threshold": 0.0, **over}, condition="rl")


@pytest.mark.parametrize("likelihood_std", [2.5, 0.0], ids=["sigma_L", "sigma_u"])
@pytest.mark.parametrize("sample", [False, True], ids=["act-mu", "act-sample"])
@pytest.mark.parametrize("reading", READINGS)
def test_each_step_matches_numpy(reading, sample, likelihood_std):
    """Along trials ending in failures (so that the critic learns and delta varies), every tick's
    step equals the reading's formula from the posterior it started from; sigma_L != sigma_u, or
    likelihood_std 0: sigma_L = sigma_u (0.7, not 1)."""
    rng = np.random.default_rng(READINGS.index(reading) * 2 + sample)
    cfg = rl_config(reading, **{"actor.likelihood_std": likelihood_std, "actor.noise_std": 0.7, "actor.scale": 1.5,
                                "actor.rate": 0.02, "actor.act_with_sample": sample})
    mean0, cov0 = random_prior(rng, 0.3)
    state = controller(cfg, mean0, cov0, seed=5)
    checked = moved = 0
    for trial in range(12):
        reset(cfg, state)
        prev = prev_out = None
        for t in range(16):
            terminal = t == 15
            s = FAILED if terminal else (near_failure(rng) if t % 3 else random_state(rng))
            mu, sigma = posterior(state)
            out = tick(cfg, state, s, terminal=terminal)
            mu1, sigma1 = posterior(state)
            if prev is not None:
                h = features(cfg, prev)
                # h^T w_act = G z: the acting weights' part of the innovation when sampling
                offset = cfg.controller.policy.gain * prev_out.z - h @ mu if sample else 0.0
                want_mu, want_sigma = reading_step(cfg, mu, sigma, h, out.td_error, prev_out.noise, offset)
                scale = 1.0 + np.abs(mu).max() + np.abs(want_mu - mu).max()
                np.testing.assert_allclose(mu1, want_mu, rtol=RTOL, atol=RTOL * scale)
                np.testing.assert_allclose(sigma1, want_sigma, rtol=RTOL, atol=RTOL * (1 + np.abs(sigma).max()))
                checked += 1
                moved += not np.allclose(mu1, mu, rtol=0, atol=1e-4)
            if reading != "posterior":
                assert np.array_equal(sigma1, cov0) and out.cov_trace == trace(cov0)
            prev, prev_out = (None, None) if terminal else (s, out)
    assert checked == 12 * 15 and moved > checked // 2


def test_readings_are_different_steps():
    """One observation, three readings: posterior and mean take the same first step (Sigma =
    Sigma0) and the gradient another; only the posterior moves Sigma_w."""
    rng = np.random.default_rng(3)
    mean0, cov0 = random_prior(rng, 0.5)
    got = {}
    for reading in READINGS:
        cfg = rl_config(reading, **{"actor.rate": 0.05, "actor.likelihood_std": 2.0})
        state = controller(cfg, mean0, cov0, seed=9)
        tick(cfg, state, [0.5, -0.3, 0.05, 0.4])
        tick(cfg, state, FAILED, terminal=True)
        got[reading] = posterior(state)
    np.testing.assert_allclose(got["posterior"][0], got["mean"][0], rtol=1e-6)
    assert not np.allclose(got["gradient"][0], got["mean"][0], rtol=1e-3)
    assert not np.array_equal(got["posterior"][1], cov0)
    assert np.array_equal(got["mean"][1], cov0) and np.array_equal(got["gradient"][1], cov0)


@pytest.mark.parametrize("likelihood_std", [3.0, 0.0], ids=["sigma_L", "sigma_u"])
@pytest.mark.parametrize("explore", [0, 6], ids=["always", "until-6"])
@pytest.mark.parametrize("reading", READINGS)
def test_batch_matches_accumulated_closed_form(reading, explore, likelihood_std):
    """actor.batch: mu_w and Sigma_w stay over a trial; at its failure the closed form over the
    trial's (explored) observations: P = Sigma^-1 + sum h h^T / sigma_L^2, mu' = mu + P^-1 sum h
    iota / sigma_L^2, Sigma' = P^-1 (posterior) or Sigma (mean); gradient: mu' = mu + beta /
    sigma_u^2 sum delta eps h. A trial cut by a reset learns nothing and leaves no sums behind."""
    rng = np.random.default_rng(40 + READINGS.index(reading) + explore)
    cfg = rl_config(reading, **{"actor.batch": True, "actor.explore_ticks": explore,
                                "actor.likelihood_std": likelihood_std, "actor.noise_std": 1.3, "actor.rate": 0.01})
    a = cfg.controller.actor
    mean0, cov0 = random_prior(rng, 0.5)
    state = controller(cfg, mean0, cov0, seed=2)
    for x in [near_failure(rng) for _ in range(5)]:  # a first failure: the critic's V is not 0 from here on
        tick(cfg, state, x)
    tick(cfg, state, FAILED, terminal=True)
    for trial in range(5):
        cut = trial == 1
        length = int(rng.integers(12, 25))
        reset(cfg, state)
        mu, sigma = posterior(state)
        hs, eps, deltas = [], [], []
        for t in range(length + (0 if cut else 1)):
            terminal = t == length
            s = FAILED if terminal else near_failure(rng)
            out = tick(cfg, state, s, terminal=terminal)
            if t > 0:
                deltas.append(out.td_error)
            if not terminal:
                hs.append(features(cfg, s))
                eps.append(out.noise)
                assert (out.noise != 0) == (explore == 0 or t < explore)
                now = posterior(state)
                assert np.array_equal(now[0], mu) and np.array_equal(now[1], sigma)
        mu1, sigma1 = posterior(state)
        if cut:
            assert np.array_equal(mu1, mu) and np.array_equal(sigma1, sigma)
            continue
        n = length if explore == 0 else min(explore, length)  # transitions whose first tick explored
        h = np.array(hs[:n])
        de = np.array(deltas[:n]) * np.array(eps[:n])
        if reading == "gradient":
            want_mu, want_sigma = mu + a.rate / a.noise_std ** 2 * (de @ h), sigma
        else:
            var = likelihood_var(cfg)
            p = np.linalg.inv(sigma) + h.T @ h / var
            inv = np.linalg.inv(p)
            want_mu = mu + inv @ (h.T @ (a.scale * de)) / var
            want_sigma = inv if reading == "posterior" else sigma
        step = np.abs(want_mu - mu).max()
        assert step > 1e-5  # a real step, not a vacuous comparison
        tol = 1e-4 if FLOAT else 1e-9
        np.testing.assert_allclose(mu1, want_mu, rtol=0, atol=tol * (step + 1e-2 * (1 + np.abs(sigma).max())))
        np.testing.assert_allclose(sigma1, want_sigma, rtol=0, atol=tol * np.abs(want_sigma).max())
        if reading != "posterior":
            assert np.array_equal(sigma1, sigma)


@pytest.mark.parametrize("reading", READINGS)
def test_explore_schedule(reading):
    """explore_ticks = N: noise exactly 0 from tick N of each trial on (not before); no actor
    update for a transition that starts at an unexplored tick; the critic keeps learning (its TD
    errors change over the unexplored ticks of repeated trials)."""
    n_explore = 4
    rng = np.random.default_rng(7)
    cfg = rl_config(reading, **{"actor.explore_ticks": n_explore, "actor.rate": 0.05})
    mean0, cov0 = random_prior(rng, 0.3)
    state = controller(cfg, mean0, cov0, seed=3)
    states = [near_failure(rng) for _ in range(10)]
    late_td = []
    for trial in range(6):
        reset(cfg, state)
        for t, s in enumerate(states + [FAILED]):
            terminal = t == len(states)
            before = posterior(state)
            out = tick(cfg, state, s, terminal=terminal)
            after = posterior(state)
            assert (out.noise != 0) == (t < n_explore and not terminal)
            if t > n_explore:
                assert np.array_equal(after[0], before[0]) and np.array_equal(after[1], before[1])
            elif t > 0 and trial > 0:
                assert not np.array_equal(after[0], before[0])  # an explored transition moves mu_w
            if t == len(states) - 1:
                late_td.append(out.td_error)
    # the same unexplored transition, trial after trial: the critic learned (V moved)
    assert len(set(late_td[1:])) > 1 and late_td[-1] != 0


@pytest.mark.parametrize("quirks", [False, True])
def test_critic_quirks_first_td_error(quirks):
    """critic.quirks (A10): V_old = 0 at a reset, so a trial's first TD error is gamma V(s_1);
    without quirks it is gamma V(s_1) - V(s_0). Later TD errors are gamma V(s_t+1) - V(s_t) in
    both, and the terminal one -1 - V(s_t) (clipped to +-1)."""
    gamma = 0.9
    cfg = build_config({"critic.quirks": quirks, "critic.discount": gamma, "critic.threshold": 0.0}, condition="rl")
    state = controller(cfg, seed=4)
    s = [np.array([0.3, -0.2, 0.1, 0.4]), np.array([0.32, -0.2, 0.15, 0.45]), np.array([0.35, -0.1, 0.18, 0.5])]
    # a failure first, so that V is not 0 near it
    for _ in range(3):
        reset(cfg, state)
        for x in s:
            tick(cfg, state, x)
        tick(cfg, state, FAILED, terminal=True)
    reset(cfg, state)
    outs = [tick(cfg, state, x) for x in s]
    assert all(o.value != 0 for o in outs)
    v = [float(o.value) for o in outs]
    first = gamma * v[1] - (0.0 if quirks else v[0])
    assert outs[0].td_error == 0
    assert outs[1].td_error == pytest.approx(np.clip(first, -1, 1), rel=1e-5, abs=1e-7)
    assert outs[2].td_error == pytest.approx(np.clip(gamma * v[2] - v[1], -1, 1), rel=1e-5, abs=1e-7)
    assert abs(v[0]) > 1e-3  # so the two readings of the first TD error differ
    end = tick(cfg, state, FAILED, terminal=True)
    assert end.value == 0 and end.td_error == pytest.approx(np.clip(-1 - v[2], -1, 1), rel=1e-5)


def test_critic_quirks_update_on_the_next_state():
    """The quirks' TD update uses b(s_t+1): after one transition s_0 -> s_1 (delta fixed by a
    terminal tick), V changes most at s_1 with quirks and at s_0 without."""
    far, near = np.array([-1.5, 0.0, -0.15, 0.0]), np.array([1.5, 0.0, 0.15, 0.0])
    change = {}
    for quirks in (False, True):
        cfg = build_config({"critic.quirks": quirks, "critic.threshold": 0.0}, condition="rl")
        state = controller(cfg, seed=8)
        tick(cfg, state, far)
        tick(cfg, state, near, terminal=True)  # delta = -1 (V = 0 everywhere before)
        reset(cfg, state)
        # V read back by a fresh trial's first tick (no learning on it)
        change[quirks] = [float(tick(cfg, state, x).value) for x in (far, near)]
        reset(cfg, state)
    # v += eta delta b(s): V(s) = -eta sum_k b_k(s)^2 where the update was, about 0 far from it
    assert change[False][0] < -0.02 and abs(change[False][1]) < 1e-2 * abs(change[False][0])  # b(s_t)
    assert change[True][1] < -0.02 and abs(change[True][0]) < 1e-2 * abs(change[True][1])     # b(s_t+1)
