# SPDX-License-Identifier: Apache-2.0
"""The LQR starting points of the search: the discrete-time LQR gains of the plant linearised at the
upright state (icoac.core.signs: A, B by central differences of the C plant step; Q =
diag(1 / input_range^2), R = 1 / F^2 for F = 1, 3, 10, 30 N), converted to weights by
w_i = -K_i * input_range_i * sign_i / G, sign_i = task.input_sign[i] (so F = G w^T x~ equals -K s
while no input is clipped). The Riccati equation is solved by scipy.linalg.solve_discrete_are."""
from __future__ import annotations

import numpy as np

from icoac.core.config import RunConfig
from icoac.core.signs import linearise, lqr_gain  # the plant's linearisation and LQR gain, shared with the input signs
from icoac.studies.ceiling.weights import as_weights

LQR_FORCES = (1.0, 3.0, 10.0, 30.0)           # N: R = 1 / F^2


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
