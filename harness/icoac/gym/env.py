# SPDX-License-Identifier: Apache-2.0
"""IcoacPlantEnv: a plant of icoac.gym.plants.ENVS as a gymnasium.Env, stepped by the C simulator.

One env step is one control period: the input (a force, or the Furuta's voltage) is held for the
plant's dt (0.01 s by default, the controller's 100 Hz tick) and the state advanced by the C step
function, for the cart-pole exactly what the engine does per tick. Termination is the plant's
failure test; truncation is the TimeLimit of the registration (max_episode_steps). The reward is
1 per step, the failing one included.
"""
from __future__ import annotations

import math
from typing import Any

import gymnasium
import numpy as np
from gymnasium import spaces
from gymnasium.error import ResetNeeded

from icoac.core import binding as B
from icoac.gym.plants import ENVS, EnvPlant


def parse_force(action: Any, limit: float) -> float:
    """One finite force from an action (a real number, or an array of one), clipped to
    [-limit, limit]; ValueError for anything else (strings and booleans included)."""
    values = np.asarray(action)
    if values.dtype.kind not in "iuf" or values.size != 1 or not math.isfinite(values.reshape(-1)[0]):
        raise ValueError(f"action must be one finite force (N), got {action!r:.60}")
    return float(min(max(float(values.reshape(-1)[0]), -limit), limit))


class IcoacPlantEnv(gymnasium.Env):
    """A plant as an env. ``plant``: a name in icoac.gym.plants.ENVS; ``force_limit``: the
    action bound (in the plant's input unit, default the plant's); every other keyword is a plant
    parameter (its EnvPlant.parameter_names), checked by C. No rendering."""

    metadata = {"render_modes": []}

    def __init__(self, plant: str = "CartPole", render_mode: str | None = None,
                 force_limit: float | None = None, **parameters: Any):
        if render_mode is not None:
            raise ValueError(f"render_mode must be None (this env does not render), got {render_mode!r:.40}")
        if plant not in ENVS:
            raise ValueError(f"unknown plant {plant!r:.40}; valid: {', '.join(ENVS)}")
        self.plant: EnvPlant = ENVS[plant]
        self.render_mode = None
        self.parameters = self.plant.configure(parameters)
        limit = self.plant.action_limit if force_limit is None else force_limit
        if isinstance(limit, bool) or not isinstance(limit, (int, float, np.integer, np.floating)) \
                or not 0 < limit <= self.plant.action_limit:
            raise ValueError(f"force_limit must be a number in (0, {self.plant.action_limit:g}] N, "
                             f"got {force_limit!r:.40}")
        self.force_limit = float(limit)
        self.dt = self.plant.period(self.parameters)
        self.action_space = spaces.Box(-self.force_limit, self.force_limit, shape=(1,), dtype=np.float64)
        # Unbounded: a failing step may leave the limits by any amount, and it is observed as it is.
        n = len(self.plant.state)
        self.observation_space = spaces.Box(-np.inf, np.inf, shape=(n,), dtype=np.float64)
        self._state: np.ndarray | None = None
        self._terminated = False

    def reset(self, *, seed: int | None = None, options: dict[str, Any] | None = None):
        super().reset(seed=seed)
        if options is not None and not isinstance(options, dict):
            raise ValueError(f"options must be a dict, got {options!r:.60}")
        self._state, info = self.plant.start(self.parameters, self.np_random, options or {})
        self._terminated = False
        return self._state.copy(), info

    def step(self, action: Any):
        if self._state is None or self._terminated:
            raise ResetNeeded("call reset() before step() (and after an episode terminated)")
        force = parse_force(action, self.force_limit)
        try:
            self.plant.step(self.parameters, self._state, force)
        except B.IcoacError as err:  # the step would leave no finite state: it ends, the state kept
            if err.status != B.SIM_ERR_NONFINITE:
                raise
            self._terminated = True
        else:
            self._terminated = self.plant.failed(self.parameters, self._state)
        return self._state.copy(), 1.0, self._terminated, False, {"force": force}
