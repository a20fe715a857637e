# SPDX-License-Identifier: Apache-2.0
"""ICO's input signs from the plant's linearisation (docs/method.md, L8, a step beyond the paper),
and that linearisation and its LQR gain (which the ceiling's LQR starts use too).

ICO's weights only grow, so the force G * sum_i w_i * sign_i * x~_i it learns pushes on each input
with the sign task.input_sign gives it. The sign a plant needs is that of its stabilising linear
feedback: here the discrete LQR gain K (u = -K s) of the plant linearised at the upright, with the
ceiling's weights Q = diag(1 / input_range^2) and R = 1 / G^2 (G = policy.gain, the force of a unit
feature; 1 N when G is 0). sign_i = sign(-K_i), +1 where K_i is 0. build_config applies them unless
a layer (the plant's task, a condition, --set) gives task.input_sign itself.
"""
from __future__ import annotations

import ctypes
import warnings

import numpy as np

from icoac.core import binding as B


def linearise(cfg, h: float = 1e-6) -> tuple[np.ndarray, np.ndarray]:
    """(A, B) of one plant step at the upright state with zero input, by central differences of
    the C plant step (icoac_sim_model_step): s' ~ A s + B u."""
    model = cfg.engine_model()
    n = cfg.n_inputs  # the task observes the whole state

    def step(s, force):
        full = np.zeros(B.MAX_STATE)
        full[:n] = s
        B.check_status(B.lib.icoac_sim_model_step(ctypes.byref(model), full, float(force)), "plant step")
        return full[:n]

    eye = np.eye(n)
    a = np.column_stack([(step(h * eye[j], 0.0) - step(-h * eye[j], 0.0)) / (2 * h) for j in range(n)])
    b = ((step(np.zeros(n), h) - step(np.zeros(n), -h)) / (2 * h)).reshape(n, 1)
    return a, b


def lqr_gain(a: np.ndarray, b: np.ndarray, q: np.ndarray, r: float) -> np.ndarray | None:
    """K of the discrete LQR with one input (u = -K s) from the stabilising solution of the discrete
    algebraic Riccati equation; None if there is none."""
    import scipy.linalg  # here: only the LQR needs it, and it takes a second to import

    rr = np.array([[float(r)]])
    try:
        p = scipy.linalg.solve_discrete_are(a, b, q, rr)
    except (np.linalg.LinAlgError, ValueError):
        return None
    k = np.linalg.solve(rr + b.T @ p @ b, b.T @ p @ a).ravel()
    return k if np.all(np.isfinite(k)) else None


def lqr_weights(cfg, force: float | None = None) -> tuple[float, ...] | None:
    """The discrete LQR gain of cfg's plant at the upright (Q = diag(1 / input_range^2), R = 1 / F^2
    with F = ``force``, default G = policy.gain) as the w of the controller's policy:
    w_i = -K_i * input_range_i * input_sign_i / G, so that F = G w^T x~ equals -K s while no input
    is clipped. None when G is not positive or the Riccati equation has no stabilising solution."""
    gain = float(cfg.controller.policy.gain)
    if gain <= 0:
        return None
    n = cfg.n_inputs
    ranges = np.array(list(cfg.controller.policy.input_range)[:n], dtype=np.float64)
    signs = np.array(list(cfg.controller.task.input_sign)[:n], dtype=np.float64)
    a, b = linearise(cfg)
    f = gain if force is None else float(force)
    k = lqr_gain(a, b, np.diag(1.0 / ranges ** 2), 1.0 / f ** 2)
    return None if k is None else tuple(float(v) for v in -k * ranges * signs / gain)


def lqr_signs(a: np.ndarray, b: np.ndarray, ranges: np.ndarray, gain: float) -> tuple[int, ...] | None:
    """sign(-K_i) of the LQR gain of (a, b) with Q = diag(1 / ranges^2), R = 1 / gain^2 (gain 0: 1);
    None when the Riccati equation has no stabilising solution."""
    force = gain if gain > 0 else 1.0
    k = lqr_gain(a, b, np.diag(1.0 / ranges ** 2), 1.0 / force ** 2)
    return None if k is None else tuple(-1 if ki > 0 else 1 for ki in k)


# (plant, model bytes, ranges, gain) -> signs: build_config derives them once per plant setting
_CACHE: dict[tuple, "tuple[int, ...] | None"] = {}


def derive_input_signs(cfg) -> tuple[int, ...] | None:
    """The input signs of cfg's plant (a RunConfig): sign(-K_i) of its LQR gain at the upright, one
    per task input; None, with a warning, when the plant has no stabilising LQR gain."""
    n = cfg.n_inputs
    ranges = tuple(float(r) for r in list(cfg.controller.policy.input_range)[:n])
    gain = float(cfg.controller.policy.gain)
    model = cfg.engine_model()
    key = (cfg.plant_name, ctypes.string_at(ctypes.addressof(model), ctypes.sizeof(model)), ranges, gain)
    if key not in _CACHE:
        a, b = linearise(cfg)
        _CACHE[key] = lqr_signs(a, b, np.array(ranges), gain)
    signs = _CACHE[key]
    if signs is None:
        warnings.warn(f"plant {cfg.plant_name}: no stabilising LQR gain at the upright; task.input_sign kept "
                      "as given (+1)", stacklevel=2)
    return signs
