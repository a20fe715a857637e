# SPDX-License-Identifier: Apache-2.0
"""PPO and SAC from Stable-Baselines3 (the ``[baselines]`` extra): the policies an RL user would
train instead, on the plant's Gymnasium env (icoac.gym), on the same grid and success criterion.

- Training: one policy over random grid cells (or over a given set of them: the held-out tuning's
  cells). Each episode starts from a cell and a grid seed drawn by the env's generator, lasts at most TRAIN_EPISODE_STEPS control periods, and earns 1 per
  period until the plant fails. Actions are rescaled to [-1, 1] and map linearly onto the plant's
  actuator limit (the parameter its C file names: the cart's force, the Furuta's voltage), which every
  method meets in the plant itself. The budget is a number of env steps (control periods).
- Evaluation: the deterministic policy from every cell of the grid of a seed, from the start state
  the engine gives that cell's first trial, for ``success_steps`` periods (the learners'
  criterion); one trial per cell. The plant steps in C, all cells at once
  (icoac_sim_model_step_lanes); the network runs once per period for the whole grid.

The settings start from the RL Baselines3 Zoo's: PPO its tuned InvertedPendulum-v3 (MuJoCo) entry,
the continuous cart-pole; SAC its MuJoCo defaults (Stable-Baselines3's SAC defaults, 10,000
steps of random actions first). torch runs on one CPU thread.
"""
from __future__ import annotations

import time
from dataclasses import dataclass
from typing import Any, Callable, Mapping, Sequence

import numpy as np

from icoac.core import binding as B
from icoac.core.config import RunConfig, model_to_dict
from icoac.core.errors import UsageError
from icoac.core.plants import PLANTS
from icoac.gym.plants import ModelParameters, gym_name, model_start, plant_grid

TRAIN_EPISODE_STEPS = 1000  # 10 s at 100 Hz, the Zoo's MuJoCo episode length


@dataclass(frozen=True)
class Algorithm:
    label: str
    source: str
    hyper: Mapping[str, Any]
    normalize: bool              # VecNormalize of observations and rewards (the Zoo's ``normalize``)
    budget: int                  # env steps of the default run
    zoo_budget: int              # the Zoo's n_timesteps for its entry


ALGORITHMS: Mapping[str, Algorithm] = {
    "ppo": Algorithm(
        "PPO", "RL Zoo hyperparams/ppo.yml, InvertedPendulum-v3",
        {"n_steps": 32, "batch_size": 64, "gamma": 0.999, "learning_rate": 2.22425e-4, "ent_coef": 1.37976e-7,
         "clip_range": 0.4, "n_epochs": 5, "gae_lambda": 0.9, "max_grad_norm": 0.3, "vf_coef": 0.19816},
        normalize=True, budget=200_000, zoo_budget=1_000_000),
    "sac": Algorithm(
        "SAC", "RL Zoo hyperparams/sac.yml, MuJoCo defaults",
        {"learning_starts": 10_000},
        normalize=False, budget=30_000, zoo_budget=1_000_000),
}


def _sb3():
    try:
        import stable_baselines3
        import torch
    except ImportError:
        raise UsageError("PPO and SAC need the [baselines] extra: `make baselines`, or "
                         "`pip install -e '.[baselines]'`") from None
    return stable_baselines3, torch


def actuator_limit(cfg: RunConfig) -> tuple[str, float]:
    """(name, value) of the plant's input saturation (its C file's actuator parameter); a UsageError
    when the plant has none or it is beyond the controller's output bound (no limit an action space
    can map)."""
    name = PLANTS[cfg.plant_name].actuator()["param"]
    limit = float(model_to_dict(cfg.model)[name])
    if not limit < float(B.constant("ICOAC_FORCE_MAX")):
        raise UsageError(f"plant {cfg.plant_name}: {name} = {limit:g} is no actuator limit; hold it to a real "
                         f"actuator's with --limited (or --set {name}=...)")
    return name, limit


def _env_parameters(cfg: RunConfig) -> dict[str, Any]:
    params = model_to_dict(cfg.model)
    params.pop("name")
    return {**params, "init_velocity_noise": float(cfg.run.init_velocity_noise)}


def make_env(cfg: RunConfig, cells: Sequence[int] | None = None):
    """The plant's env for training: the configured model, episodes of TRAIN_EPISODE_STEPS, actions
    in [-1, 1] onto the actuator limit, episode statistics kept (Monitor); with cells, each episode
    starts from one of them (drawn by the env's generator) instead of any cell of the grid."""
    import gymnasium
    from stable_baselines3.common.monitor import Monitor
    from icoac.gym.env import IcoacPlantEnv
    _, limit = actuator_limit(cfg)
    env = IcoacPlantEnv(gym_name(cfg.plant_name), force_limit=limit, **_env_parameters(cfg))
    if cells is not None:
        env = _StartCells(env, cells)
    env = gymnasium.wrappers.TimeLimit(env, TRAIN_EPISODE_STEPS)
    return Monitor(gymnasium.wrappers.RescaleAction(env, -1.0, 1.0))


def _StartCells(env, cells: Sequence[int]):
    """env whose reset draws its cell from ``cells`` (the env's generator) unless told one."""
    import gymnasium
    allowed = np.asarray(cells, dtype=np.int64)
    if allowed.size == 0:
        raise UsageError("training cells: none given")

    class StartCells(gymnasium.Wrapper):
        def reset(self, *, seed=None, options=None):
            if seed is not None:  # seed the generator the draw below uses
                self.env.reset(seed=seed)
            options = dict(options or {})
            if "state" not in options:
                options.setdefault("cell", int(self.np_random.choice(allowed)))
            return self.env.reset(options=options)
    return StartCells(env)


@dataclass
class Trained:
    """A trained policy: ``act`` maps a (cells, n_state) array of states to actions in [-1, 1]."""
    act: Callable[[np.ndarray], np.ndarray]
    steps: int
    episodes: int
    wall_time: float
    model: Any
    normalizer: Any


def hyperparameters(algo: str, overrides: Mapping[str, Any] | None = None) -> dict[str, Any]:
    """The algorithm's hyperparameters: its RL Zoo start, then ``overrides`` (a tuning setting)."""
    return {**ALGORITHMS[algo].hyper, **(overrides or {})}


def train(algo: str, cfg: RunConfig, seed: int, steps: int, overrides: Mapping[str, Any] | None = None,
          cells: Sequence[int] | None = None) -> Trained:
    """Train ``algo`` for ``steps`` env steps on the configured plant, seeded by ``seed`` (the
    env's cell draws, the networks, the exploration), with its hyperparameters (``overrides`` on
    the Zoo's start), from random grid cells or from ``cells``."""
    sb3, torch = _sb3()
    from stable_baselines3.common.vec_env import DummyVecEnv, VecNormalize
    spec = ALGORITHMS[algo]
    hyper = hyperparameters(algo, overrides)
    torch.set_num_threads(1)
    t0 = time.monotonic()
    venv = DummyVecEnv([lambda: make_env(cfg, cells)])
    venv.seed(seed)
    if spec.normalize:
        venv = VecNormalize(venv, gamma=hyper.get("gamma", 0.99))
    cls = getattr(sb3, spec.label)
    model = cls("MlpPolicy", venv, seed=seed, device="cpu", verbose=0, **hyper)
    model.learn(total_timesteps=steps)
    monitor = venv.venv.envs[0] if spec.normalize else venv.envs[0]
    normalizer = venv if spec.normalize else None
    if normalizer is not None:
        normalizer.training = False

    def act(states: np.ndarray) -> np.ndarray:
        obs = normalizer.normalize_obs(states) if normalizer is not None else states
        action, _ = model.predict(obs, deterministic=True)
        return np.clip(np.asarray(action, dtype=np.float64).reshape(len(states)), -1.0, 1.0)
    return Trained(act, int(model.num_timesteps), len(monitor.get_episode_lengths()),
                   time.monotonic() - t0, model, normalizer)


def evaluate(act: Callable[[np.ndarray], np.ndarray], cfg: RunConfig, grid_seed: int,
             only: Sequence[int] | None = None) -> tuple[np.ndarray, np.ndarray]:
    """(periods lasted, success) of each cell of the plant's grid seeded by grid_seed (or of the
    cells ``only``, in that order) under the deterministic policy, from the start of the cell's
    first trial: a cell succeeds when it survives success_steps periods (the period a cell fails
    in counts as lasted)."""
    _, limit = actuator_limit(cfg)
    index = int(cfg.model.plant)
    n = len(B.plant_info(index)["state"])
    cells = plant_grid(index, grid_seed)
    if only is not None:
        cells = cells[np.asarray(only, dtype=np.intp)]
    parameters = ModelParameters(cfg.model, float(cfg.run.init_velocity_noise))
    states = np.stack([model_start(parameters, cells[i:i + 1]) for i in range(cells.size)])
    ended = np.zeros(cells.size, dtype=np.int32)
    lasted = np.zeros(cells.size, dtype=np.int64)
    for _ in range(int(cfg.run.success_steps)):
        alive = ended == 0
        if not alive.any():
            break
        forces = act(states[:, :n]) * limit
        if not np.all(np.isfinite(forces)):
            raise B.LibraryError("the policy returned a non-finite action")
        lasted += alive
        B.model_step_lanes(cfg.model, states, forces, ended)
    return lasted, ended == 0


def settings(algo: str, steps: int, overrides: Mapping[str, Any] | None = None) -> dict[str, Any]:
    """What a run records of its algorithm's settings."""
    spec = ALGORITHMS[algo]
    sb3, torch = _sb3()
    return {"algorithm": spec.label, "source": spec.source, "hyperparameters": hyperparameters(algo, overrides),
            "overrides": dict(overrides or {}),
            "normalize": spec.normalize, "policy": "MlpPolicy", "steps": steps, "zoo_steps": spec.zoo_budget,
            "train_episode_steps": TRAIN_EPISODE_STEPS, "torch_threads": 1,
            "stable_baselines3": sb3.__version__, "torch": torch.__version__}

