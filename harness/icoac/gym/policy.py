# SPDX-License-Identifier: Apache-2.0
"""IcoacPolicy: an icoac controller (any mode, learning as it acts) driving a Gymnasium env whose
observation is the plant's state, one controller input per component in the descriptor's order
((x m, x_dot m/s, theta rad, theta_dot rad/s) for the cart-pole; ``plant``: its task settings,
icoac.core.plants), and whose action is one number, a force (N) or the plant's input.

Per episode, as the engine per trial: icoac_reset, then per env step one icoac_step on the
observation, its force the action; the observation of a terminating step (terminated=True) goes
to icoac_step once more with ICOAC_INPUT_TERMINAL, so the controller learns from the failure. A
truncated episode ends without that tick (nothing failed). Every call is one ctypes call on the
C library; any status other than ICOAC_OK raises the binding's IcoacError naming it.
"""
from __future__ import annotations

import ctypes
from dataclasses import dataclass, field
from typing import Any, Mapping

import gymnasium
import numpy as np

from icoac.core import binding as B
from icoac.core.config import RunConfig, build_config
from icoac.core.options import CART_POLE


@dataclass
class Episode:
    """One episode: steps taken, summed reward, how it ended, the info of its reset; with
    ``trace``, the observations (steps + 1, the start included) and the forces (steps)."""
    steps: int
    total_reward: float
    terminated: bool
    truncated: bool
    reset_info: dict = field(default_factory=dict, repr=False)
    observations: np.ndarray | None = field(default=None, repr=False)
    forces: np.ndarray | None = field(default=None, repr=False)


def check_layout(env: gymnasium.Env, n_inputs: int = B.N_INPUTS) -> None:
    """ValueError unless the env observes n_inputs numbers (the task's inputs; the cart-pole's 4 by
    default) and takes a 1-number Box action."""
    obs, act = env.observation_space, env.action_space
    if not isinstance(obs, gymnasium.spaces.Box) or obs.shape != (n_inputs,):
        layout = " (x, x_dot, theta, theta_dot)" if n_inputs == B.N_INPUTS else ""
        raise ValueError(f"the env's observation must be a Box of {n_inputs}{layout}, got {obs}")
    if not isinstance(act, gymnasium.spaces.Box) or act.shape != (1,):
        raise ValueError(f"the env's action must be a Box of one force (N), got {act} "
                         "(for Gymnasium's CartPole-v1 use icoac.gym.continuous_cartpole)")


def env_plant(env: gymnasium.Env) -> str | None:
    """The registry plant an env simulates: an icoac env's, the cart-pole for Gymnasium's
    CartPole, None for any other env (its plant is not known)."""
    from gymnasium.envs.classic_control.cartpole import CartPoleEnv

    from icoac.gym.env import IcoacPlantEnv
    from icoac.gym.plants import gym_name

    inner = env.unwrapped
    if isinstance(inner, CartPoleEnv):
        return CART_POLE
    if isinstance(inner, IcoacPlantEnv):
        names = (B.plant_info(i)["name"] for i in range(int(B.lib.icoac_sim_plant_count())))
        return next(name for name in names if gym_name(name) == inner.plant.name)
    return None


def check_plant(env: gymnasium.Env, plant: str) -> None:
    """ValueError unless the env simulates ``plant`` (the plant the controller's task is for), when
    the env's plant is known (env_plant)."""
    other = env_plant(env)
    if other is not None and other != plant:
        raise ValueError(f"the policy's task is for the {plant}, but the env simulates the {other}; "
                         f"build the policy with plant={other!r}")


class IcoacPolicy:
    """A controller state initialised from ``config`` (a RunConfig: its controller and prior; e.g.
    icoac.studies.ceiling.fixed.fixed_config(w) for a fixed w) or else from ``condition``, ``overrides``,
    ``prior`` and ``plant`` as icoac.core.config.build_config takes them (a registry plant's name:
    its own task settings, for that plant's env). ``seed`` seeds the exploration noise (icoac_init)."""

    def __init__(self, config: RunConfig | None = None, *, condition: str = "ico",
                 overrides: Mapping[str, Any] | None = None, prior: B.Prior | None = None, seed: int = 0,
                 plant: str = CART_POLE):
        if config is None:
            config = build_config(overrides, condition=condition, prior=prior, plant=plant)
        elif overrides is not None or prior is not None:
            raise ValueError("give either config or condition/overrides/prior, not both")
        if isinstance(seed, bool) or not isinstance(seed, (int, np.integer)) or not 0 <= seed < 2 ** 64:
            raise ValueError(f"seed must be an integer in [0, 2^64), got {seed!r:.40}")
        self.config = config.check()
        self._state = B.State()
        self._input = B.Input()
        self._output = B.Output()
        prior_ref = ctypes.byref(config.prior) if config.prior is not None else None
        B.check_status(B.lib.icoac_init(ctypes.byref(config.controller), ctypes.byref(self._state), prior_ref,
                                        int(seed)), "icoac_init")

    def reset(self) -> None:
        """Start an episode (icoac_reset): the previous one is forgotten, what was learned kept."""
        B.check_status(B.lib.icoac_reset(ctypes.byref(self._state)), "icoac_reset")

    def _tick(self, observation: Any, flags: int) -> float:
        s = np.asarray(observation)
        n = self.config.n_inputs
        if s.dtype.kind not in "iuf" or s.shape != (n,):
            raise ValueError(f"observation must be {n} numbers (the task's inputs), got {observation!r:.80}")
        s = s.astype(np.float64)
        with np.errstate(over="ignore"):  # beyond the real type: inf, which icoac_step rejects
            real = s.astype(B.real_dtype)
        for i in range(n):
            self._input.s[i] = real[i]
        self._input.flags = flags
        status = B.lib.icoac_step(ctypes.byref(self._state), ctypes.byref(self._input), ctypes.byref(self._output))
        B.check_status(status, f"icoac_step on observation {s.tolist()}")
        return float(self._output.force)

    def act(self, observation: Any) -> float:
        """One tick on an observation: learn from the transition into it, return the force (N)."""
        return self._tick(observation, 0)

    def learn_from_failure(self, observation: Any) -> None:
        """The terminal tick on a failure observation: learn, no action; the episode is over."""
        self._tick(observation, B.INPUT_TERMINAL)

    @property
    def weights(self) -> np.ndarray:
        """w (ICO) or mu_w (RL, search), one per task input (the cart-pole's w_x, w_xdot, w_theta, w_thetadot)."""
        return np.array(B.get_posterior(self._state).mean, dtype=np.float64)[:self.config.n_inputs]

    @property
    def covariance(self) -> np.ndarray:
        """Sigma_w (RL, search)."""
        n = self.config.n_inputs
        return np.array([list(row) for row in B.get_posterior(self._state).cov], dtype=np.float64)[:n, :n]

    @property
    def ticks(self) -> int:
        return int(B.get_counters(self._state).ticks)

    def run_episode(self, env: gymnasium.Env, *, seed: int | None = None, options: dict | None = None,
                    trace: bool = False) -> Episode:
        """One episode of env (reset with seed and options) under this controller, learning as
        the configuration says."""
        check_plant(env, self.config.plant_name)
        check_layout(env, self.config.n_inputs)
        obs, reset_info = env.reset(seed=seed, options=options)
        self.reset()
        dtype = env.action_space.dtype
        observations, forces = [np.asarray(obs, dtype=np.float64)], []
        steps, total, terminated, truncated = 0, 0.0, False, False
        while not (terminated or truncated):
            force = self.act(obs)
            obs, reward, terminated, truncated, _ = env.step(np.array([force], dtype=dtype))
            steps += 1
            total += float(reward)
            if trace:
                observations.append(np.asarray(obs, dtype=np.float64))
                forces.append(force)
        if terminated:
            self.learn_from_failure(obs)
        return Episode(steps, total, bool(terminated), bool(truncated), reset_info,
                       np.array(observations) if trace else None, np.array(forces) if trace else None)
