# SPDX-License-Identifier: Apache-2.0
"""Driving one controller tick by tick through the binding (icoac_init / icoac_reset / icoac_step),
shared by test_readings.py and test_search.py; the numpy side of those tests is in them."""
import ctypes

import numpy as np

from icoac.core import binding as B
from icoac.core.config import make_prior

REAL = B.real_dtype.type  # np.float32 for the float library


def controller(cfg, mean=None, cov=None, seed=1):
    """An initialised state for cfg (a RunConfig), prior (mean, cov) or NULL."""
    state = B.State()
    prior = None if mean is None else ctypes.byref(make_prior(mean, cov))
    B.check_status(B.lib.icoac_init(ctypes.byref(cfg.controller), ctypes.byref(state), prior, seed))
    return state


def assert_in_force(cfg, state):
    """cfg (a RunConfig) is the configuration the state keeps (icoac_get_config): the one it was
    initialised or last retuned with."""
    in_force = B.Config()
    B.check_status(B.lib.icoac_get_config(ctypes.byref(state), ctypes.byref(in_force)))
    assert bytes(in_force) == bytes(cfg.controller)


def retune(cfg, state):
    """Make cfg the state's configuration (icoac_retune: live tuning, keeps what was learned)."""
    B.check_status(B.lib.icoac_retune(ctypes.byref(state), ctypes.byref(cfg.controller)))


def reset(cfg, state):
    assert_in_force(cfg, state)
    B.check_status(B.lib.icoac_reset(ctypes.byref(state)))


def tick(cfg, state, s, terminal=False, expect=B.OK):
    """One icoac_step on s; the output (its status must be `expect`)."""
    assert_in_force(cfg, state)
    inp = B.Input()
    for i in range(B.N_INPUTS):
        inp.s[i] = float(s[i])
    inp.flags = B.INPUT_TERMINAL if terminal else 0
    out = B.Output()
    status = B.lib.icoac_step(ctypes.byref(state), ctypes.byref(inp), ctypes.byref(out))
    assert status == expect == out.status, (status, out.status)
    return out


def posterior(state):
    """(mu_w, Sigma_w) as float64 arrays."""
    post = B.get_posterior(state)
    n = B.N_INPUTS  # the cart-pole task's weights: the leading entries
    return np.array(post.mean[:n], dtype=float), np.array([list(r)[:n] for r in post.cov[:n]], dtype=float)


def likelihood_var(cfg):
    """sigma_L^2 of the posterior and mean readings: actor.likelihood_std squared, or sigma_u^2
    (actor.noise_std) when it is 0 (the literal reading, the default)."""
    a = cfg.controller.actor
    std = a.likelihood_std if a.likelihood_std != 0 else a.noise_std
    return float(std) ** 2


def stored(s):
    """The state as the controller stores it (icoac_real_t)."""
    return np.asarray(s, dtype=float).astype(REAL).astype(float)


def scaled(cfg, s):
    """x~ = clip(s / input_range, -1, 1), in the real type like the library (s * (1 / range))."""
    c = cfg.controller.policy
    inv = (REAL(1.0) / np.array(c.input_range[:B.N_INPUTS], dtype=REAL)).astype(REAL)
    x = (np.asarray(s, dtype=float).astype(REAL) * inv).astype(float)
    return np.clip(x, -1.0, 1.0) if c.clip_inputs else x


def features(cfg, s):
    """h = G x~(s)."""
    return float(cfg.controller.policy.gain) * scaled(cfg, s)


def random_state(rng, n=None):
    """States inside the failure limits, velocities beyond the scaling ranges now and then."""
    size = (4,) if n is None else (n, 4)
    lo, hi = np.array([-2.3, -4.0, -0.2, -2.5]), np.array([2.3, 4.0, 0.2, 2.5])
    return stored(rng.uniform(lo, hi, size=size))


FAILED = np.array([0.1, 0.2, 0.25, 0.3])  # theta beyond 12 deg: a failure state


def random_prior(rng, scale=0.5):
    """(mean, cov) of a random Gaussian with a full, well-conditioned covariance."""
    a = rng.uniform(-1, 1, size=(4, 4))
    cov = scale * (a @ a.T + 0.05 * np.eye(4))
    cov = stored((cov + cov.T) / 2)
    return stored(rng.uniform(-0.5, 0.5, size=4)), cov
