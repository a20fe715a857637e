# SPDX-License-Identifier: Apache-2.0
"""The LQR starting points of the search: the discrete-time LQR gains of the plant linearised at the
upright state (icoac.core.signs.lqr_weights: Q = diag(1 / input_range^2), R = 1 / F^2 for F = 1, 3,
10, 30 N) as weights. The Riccati equation is solved by scipy.linalg.solve_discrete_are."""
from __future__ import annotations

import numpy as np

from icoac.core.config import RunConfig
from icoac.core.signs import lqr_weights
from icoac.studies.ceiling.weights import as_weights

LQR_FORCES = (1.0, 3.0, 10.0, 30.0)           # N: R = 1 / F^2


def lqr_starts(cfg: RunConfig) -> list[tuple[str, tuple[float, ...]]]:
    """LQR gains of the linearised plant as weights, one per R = 1 / F^2 (LQR_FORCES)."""
    out = []
    for force in LQR_FORCES:
        w = lqr_weights(cfg, force)
        if w is not None and np.all(np.isfinite(w)) and np.all(np.abs(w) <= 1e6):
            out.append((f"lqr R=1/{force:g}^2", as_weights(w)))
    return out
