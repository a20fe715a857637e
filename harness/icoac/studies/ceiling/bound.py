# SPDX-License-Identifier: Apache-2.0
"""The first-step bound (``first_step_bound``): the first explicit Euler step moves x and theta by
dt times the initial velocities only (x1 = x0 + dt x_dot0, theta1 = theta0 + dt theta_dot0); the
force changes only the velocities, which stay finite. So a cell on a failure threshold
(|x0| = 2.4 m or |theta0| = 12 deg; the grid's last x0 is 2.400000000000001 in double) whose
first draw points outward fails at step 1 whatever any controller does. The engine's first
draws are recomputed through the C API (``icoac_sim_trajectory`` with one step gives the
start state of the cell's first trial), stepped once by ``icoac_sim_model_step`` under several
forces from -1e4 N to 1e4 N and tested with ``icoac_sim_model_failed``; the cells failing under
every force
are lost, and failure must not depend on the force (checked). The same set is checked against
the engine itself: one trial of 1 step per cell. The bound - cells minus lost cells - is an upper
bound on the successes of ANY controller under the first-trial protocol with this seed's draws;
with retries a boundary cell may still succeed on a later, inward draw. It is defined for the
Euler integrator only (with RK4 the force enters x1 and theta1) and reported as not computed
otherwise. Any registry plant integrated by Euler (positions move by their velocities only) has the
same bound on its own grid and limits.
"""
from __future__ import annotations

import ctypes
from typing import Any

import numpy as np

from icoac.core import binding as B
from icoac.core import geometry, grid
from icoac.core.config import CART_POLE, RunConfig
from icoac.core.errors import LibraryError

# Forces (N) of the first-step check: failure at step 1 must be the same under each.
BOUND_FORCES = (-1e4, -10.0, -1.0, 0.0, 1.0, 10.0, 1e4)


def initial_states(cfg: RunConfig, cells: np.ndarray) -> np.ndarray:
    """(cells, n) start states of each cell's first trial, as the engine draws them: icoac_sim_trajectory
    of one step from (x0, theta0) with the cell's seed records the start first."""
    n_state = cfg.n_inputs  # the task observes the whole state
    out = np.zeros((cells.size, n_state))
    states = np.zeros(2 * n_state)
    forces = np.zeros(1)
    n = ctypes.c_int64(0)
    prior = ctypes.byref(cfg.prior) if cfg.prior is not None else None
    model = cfg.engine_model()
    for i, cell in enumerate(cells):
        status = B.lib.icoac_sim_trajectory(ctypes.byref(cfg.controller), ctypes.byref(model), prior,
                                            float(cell["x0"]), float(cell["theta0"]),
                                            float(cfg.run.init_velocity_noise), int(cell["seed"]), 1,
                                            states, forces, ctypes.byref(n))
        B.check_status(status, "trajectory")
        out[i] = states[:n_state]
    return out


def first_step_bound(cfg: RunConfig, cells: np.ndarray, threads: int = 0) -> dict[str, Any]:
    """Cells lost at the first step whatever the force (module docstring), for the cells of
    ``cells`` (PENDING template) and the run's initial-velocity noise; cfg gives plant and noise."""
    n = int(cells.size)
    plant_grid = geometry.of(cfg.plant_name)
    inner = plant_grid.interior_mask(cells)
    base = {"protocol": "first", "n_cells": n, "n_interior": int(inner.sum())}
    model = cfg.engine_model()
    if int(model.integrator) != B.INTEGRATORS["euler"]:
        return {**base, "computed": False,
                "reason": "defined for the Euler integrator only (with RK4 the force enters x and theta "
                          "within the first step)"}
    s0 = initial_states(cfg, cells)
    failed = np.zeros((len(BOUND_FORCES), n), dtype=bool)
    after = np.zeros((n, cfg.n_inputs))
    flag = ctypes.c_int32(0)
    for k, force in enumerate(BOUND_FORCES):
        for i in range(n):
            s = np.zeros(B.MAX_STATE)
            s[: cfg.n_inputs] = s0[i]
            B.check_status(B.lib.icoac_sim_model_step(ctypes.byref(model), s, float(force)), "plant step")
            B.check_status(B.lib.icoac_sim_model_failed(ctypes.byref(model), s, ctypes.byref(flag)), "plant failed")
            failed[k, i] = bool(flag.value)
            if force == 0.0:
                after[i] = s[: cfg.n_inputs]
    lost = failed.all(axis=0)
    if not np.array_equal(lost, failed.any(axis=0)):
        raise LibraryError("failure at the first Euler step depends on the force; the first-step bound's "
                           "premise does not hold for this plant")
    # The engine itself: one trial of 1 step per cell; the lost cells are exactly its failures.
    probe = RunConfig(controller=B.Config.from_buffer_copy(cfg.controller), model=B.Model.from_buffer_copy(cfg.model),
                      run=B.Run.from_buffer_copy(cfg.run), prior=cfg.prior)
    probe.run.max_trials, probe.run.success_steps = 1, 1
    eng = cells.copy()
    run = grid.run_grid(probe, eng, threads=threads, progress=False)
    if run.cancelled:
        raise KeyboardInterrupt
    eng_lost = (eng["outcome"] == B.FAILED) & (eng["last_trial_steps"] == 1)
    if not np.array_equal(eng_lost, lost):
        raise LibraryError(f"first-step bound: the engine loses {int(eng_lost.sum())} cells at step 1, the plant "
                           f"steps {int(lost.sum())}; the recomputed initial velocities do not match the engine's")
    rows, cols = plant_grid.grid_index(cells)
    lost_cells = []
    for i in np.flatnonzero(lost):
        cell = int(plant_grid.cell_index(rows[i], cols[i]))
        if cfg.plant_name != CART_POLE:
            lost_cells.append({"cell": cell, "start": [float(v) for v in s0[i]], "exits": ["outside the plant's limits"]})
            continue
        limit = {p["name"]: cfg.model.param[k] for k, p in enumerate(B.plant_info(CART_POLE)["params"])}
        xl, tl = float(limit["x_limit"]), float(limit["theta_limit"])
        x1, th1 = after[i, 0], after[i, 2]
        exits = [name for name, hit in (("x > x_limit", x1 > xl), ("x < -x_limit", x1 < -xl),
                                        ("theta > theta_limit", th1 > tl), ("theta < -theta_limit", th1 < -tl)) if hit]
        lost_cells.append({"cell": cell, "x0": float(s0[i, 0]), "theta0_deg": float(np.degrees(s0[i, 2])),
                           "x_dot0": float(s0[i, 1]), "theta_dot0": float(s0[i, 3]), "exits": exits})
    n_lost, n_lost_in = int(lost.sum()), int((lost & inner).sum())
    return {**base, "computed": True, "integrator": "euler", "forces_tested": list(BOUND_FORCES),
            "engine_agrees": True, "init_velocity_noise": float(cfg.run.init_velocity_noise),
            "n_lost": n_lost, "n_lost_interior": n_lost_in,
            "n_boundary": int((~inner).sum()),
            "max_success": n - n_lost, "max_success_interior": int(inner.sum()) - n_lost_in,
            "success_rate_bound": (n - n_lost) / n if n else None,
            "success_rate_interior_bound": (int(inner.sum()) - n_lost_in) / int(inner.sum()) if inner.any() else None,
            "lost_cells": lost_cells}
