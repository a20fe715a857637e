# SPDX-License-Identifier: Apache-2.0
"""Gymnasium for icoac: the simulator's plants as registered envs, an icoac controller as a policy
on any env with the cart-pole's observation layout, and a continuous-force Gymnasium CartPole-v1.

Importing this package registers ``icoac/CartPole-v0``, ``icoac/Furuta-v0`` and
``icoac/DoubleCartPole-v0`` (one id per plant of icoac.gym.plants);
``gymnasium.make("icoac.gym:icoac/CartPole-v0")`` imports it on the way. Modules: plants (what
each plant is), env (IcoacPlantEnv), policy (IcoacPolicy), cartpole_v1 (ContinuousCartPole).
docs/gymnasium.md describes them.
"""
import gymnasium

from icoac.gym.cartpole_v1 import ContinuousCartPole, continuous_cartpole
from icoac.gym.env import IcoacPlantEnv
from icoac.gym.plants import ENVS, env_id
from icoac.gym.policy import Episode, IcoacPolicy

for _spec in ENVS.values():
    if env_id(_spec) not in gymnasium.registry:
        gymnasium.register(id=env_id(_spec), entry_point="icoac.gym.env:IcoacPlantEnv",
                           kwargs={"plant": _spec.name}, max_episode_steps=_spec.max_episode_steps)

__all__ = ["ContinuousCartPole", "Episode", "IcoacPlantEnv", "IcoacPolicy", "continuous_cartpole", "env_id"]
