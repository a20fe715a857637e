# SPDX-License-Identifier: Apache-2.0
"""The LQR starting points of the search: the discrete-time LQR gains of the plant linearised at the
upright state (A, B by central differences of the C plant step ``icoac_sim_model_step``; Q =
diag(1 / input_range^2), R = 1 / F^2 for F = 1, 3, 10, 30 N), converted to weights by
w_i = -K_i * input_range_i * sign_i / G, sign_i = task.input_sign[i] (so F = G w^T x~ equals -K s
while no input is clipped). The Riccati equation is solved by scipy.linalg.solve_discrete_are."""
from __future__ import annotations

import ctypes

import numpy as np

from .. import _binding as B
from ..config import RunConfig
from .weights import as_weights

LQR_FORCES = (1.0, 3.0, 10.0, 30.0)           # N: R = 1 / F^2


def linearise(cfg: RunConfig, h: float = 1e-6) -> tuple[np.ndarray, np.ndarray]:
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
    import scipy.linalg  # here: only the search needs it, and it takes a second to import

    rr = np.array([[float(r)]])
    try:
        p = scipy.linalg.solve_discrete_are(a, b, q, rr)
    except (np.linalg.LinAlgError, ValueError):
        return None
    k = np.linalg.solve(rr + b.T @ p @ b, b.T @ p @ a).ravel()
    return k if np.all(np.isfinite(k)) else None


def lqr_starts(cfg: RunConfig) -> list[tuple[str, tuple[float, ...]]]:
    """LQR gains of the linearised plant as weights, one per R = 1 / F^2 (LQR_FORCES)."""
    gain = float(cfg.controller.policy.gain)
    if gain <= 0:
        return []
    n = cfg.controller.task.n_inputs
    ranges = np.array(list(cfg.controller.policy.input_range)[:n], dtype=np.float64)
    signs = np.array(list(cfg.controller.task.input_sign)[:n], dtype=np.float64)
    a, b = linearise(cfg)
    q = np.diag(1.0 / ranges ** 2)
    out = []
    for force in LQR_FORCES:
        k = lqr_gain(a, b, q, 1.0 / force ** 2)
        if k is None:
            continue
        w = -k * ranges * signs / gain
        if np.all(np.isfinite(w)) and np.all(np.abs(w) <= 1e6):
            out.append((f"lqr R=1/{force:g}^2", as_weights(w)))
    return out
