# SPDX-License-Identifier: Apache-2.0
"""ContinuousCartPole: Gymnasium's own CartPole-v1 driven by a continuous force.

CartPole-v1 pushes with +force_mag (action 1) or -force_mag (action 0), force_mag read at every
step. The wrapper takes a force F (N) and, per step, sets force_mag = |F| and passes action 1 for
F >= 0, else 0: the plant then integrates exactly F. Gymnasium's dynamics are the same frictionless
cart-pole as icoac's (same equations, explicit Euler in the same order, theta in rad with theta > 0
leaning toward +x, the same 2.4 m and 12 deg limits, the same masses and lengths), so no sign or
unit conversion is needed; what differs is listed in docs/gymnasium.md (period 0.02 s unless
``dt`` is given, float32 observations, start states, the 500-step limit).
"""
from __future__ import annotations

import math
from typing import Any

import gymnasium
import numpy as np
from gymnasium import spaces
from gymnasium.envs.classic_control.cartpole import CartPoleEnv

from icoac.gym.env import parse_force
from icoac.gym.plants import ENVS


class ContinuousCartPole(gymnasium.Wrapper):
    """A force Box action on a CartPoleEnv (possibly under Gymnasium's own wrappers).
    ``force_limit`` (N) bounds the force (default the icoac env's; 10 keeps CartPole-v1's
    actuator); ``dt`` (s), when given, replaces the env's period tau (0.02 s)."""

    def __init__(self, env: gymnasium.Env, force_limit: float = ENVS["CartPole"].action_limit, dt: float | None = None):
        super().__init__(env)
        if not isinstance(env.unwrapped, CartPoleEnv):
            raise TypeError(f"ContinuousCartPole wraps Gymnasium's CartPoleEnv, got {type(env.unwrapped).__name__}")
        if isinstance(force_limit, bool) or not isinstance(force_limit, (int, float)) \
                or not 0 < force_limit < math.inf:
            raise ValueError(f"force_limit must be a finite number > 0 (N), got {force_limit!r:.40}")
        if dt is not None:
            if isinstance(dt, bool) or not isinstance(dt, (int, float)) or not 0 < dt < math.inf:
                raise ValueError(f"dt must be a finite number > 0 (s), got {dt!r:.40}")
            env.unwrapped.tau = float(dt)
        self.force_limit = float(force_limit)
        self.action_space = spaces.Box(-self.force_limit, self.force_limit, shape=(1,), dtype=np.float64)

    def step(self, action: Any):
        force = parse_force(action, self.force_limit)
        self.env.unwrapped.force_mag = abs(force)
        obs, reward, terminated, truncated, info = self.env.step(1 if force >= 0 else 0)
        return obs, reward, terminated, truncated, {**info, "force": force}


def continuous_cartpole(force_limit: float = ENVS["CartPole"].action_limit, dt: float | None = None,
                        **make_kwargs: Any) -> ContinuousCartPole:
    """gymnasium.make("CartPole-v1", **make_kwargs) with a continuous force."""
    return ContinuousCartPole(gymnasium.make("CartPole-v1", **make_kwargs), force_limit=force_limit, dt=dt)
