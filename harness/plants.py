"""The plants a benchmark runs, each defined once: the C registry's plant (dynamics, parameters,
failure test and grid: sim_host/src/plants/, docs/plants.md) and the controller settings of its
task for this controller build (the input scaling, the reflex zone and the critic grid), applied
under every condition's overrides and the user's --set. The cart-pole's are the C defaults.

A plant whose state the controller build cannot take (the 6-state double pendulum: the controller
reads 4 inputs) is listed with why it cannot run; config.check_model refuses it by name.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

from . import _binding as B
from .options import CART_POLE


@dataclass(frozen=True)
class PlantSpec:
    name: str
    controller: dict[str, Any] = field(default_factory=dict)  # the task's controller settings
    why: str = ""  # where the settings come from
    # a learner's settings on this plant where its cart-pole defaults do not carry over, by the
    # learner's condition name (its control takes them too), from the plant's learner sweep
    learners: dict[str, dict[str, Any]] = field(default_factory=dict)


# The cart-pole's reflex zone along its position, 2.35 of 2.4 m, as a fraction of the input range
# (checked against the C defaults below).
ZONE_FRACTION = 2.35 / 2.4


def _check_zone_fraction() -> None:
    default = B.Config()
    B.lib.icoac_config_default(default)
    assert math.isclose(ZONE_FRACTION, default.policy.zone_x / default.policy.input_range[0], rel_tol=1e-6)


_check_zone_fraction()


def task_overrides(plant: str, setting: dict[str, float]) -> dict[str, Any]:
    """The controller settings of a task setting (the plant sweep's space, harness.tools.plant_sweeps):
    input ranges (arm angle, arm velocity, pendulum angle = its failure limit, pendulum velocity),
    the critic grid over the same ranges, the reflex zone (ZONE_FRACTION of the arm range; the
    pendulum's at zone_deg), ICO's rate and the policy gain."""
    limit = {p["name"]: p["value"] for p in B.plant_info(plant)["params"]}["pendulum_limit"]
    ranges = [setting["arm_range"], setting["arm_velocity_range"], limit, setting["pendulum_velocity_range"]]
    return {"policy.input_range": ranges, "critic.range": ranges,
            "policy.zone_x": ZONE_FRACTION * setting["arm_range"],
            "policy.zone_theta": math.radians(setting["zone_deg"]),
            "ico.rate": setting["ico.rate"], "policy.gain": setting["policy.gain"]}


# The Furuta's task setting, chosen by its sweep (docs/sweeps-furuta.md).
FURUTA_SETTING = {"arm_range": 1.0, "arm_velocity_range": 2.3, "pendulum_velocity_range": 0.6, "zone_deg": 8.0,
                  "ico.rate": 0.01, "policy.gain": 1.0}

# ICO->RL's reading and noise on the Furuta, chosen by its learner sweep (docs/sweeps-furuta.md).
FURUTA_ICO_RL = {"actor.update": "mean", "actor.likelihood_std": 0.1, "actor.scale": 0.1, "actor.noise_std": 1.0}

PLANTS: dict[str, PlantSpec] = {
    CART_POLE: PlantSpec(CART_POLE, {}, "the C defaults (the paper's task)"),
    "furuta": PlantSpec("furuta", task_overrides("furuta", FURUTA_SETTING),
                        "its sweep (docs/sweeps-furuta.md): input scaling, reflex zone, ICO rate, gain",
                        # reading and exploration noise (V) by the learner sweeps of docs/sweeps-furuta.md:
                        # ICO->RL takes RL alone's (mean) reading here; the prior's decomposition takes
                        # the settings of the learner whose prior mean it shares
                        learners={"ico-rl": FURUTA_ICO_RL, "ico-mean-rl": FURUTA_ICO_RL,
                                  "rl": {"actor.noise_std": 3.0}, "rl-ico-cov": {"actor.noise_std": 3.0}}),
}
# Registry plants the controller build cannot run, and why.
UNRUNNABLE: dict[str, str] = {
    "double_cart_pole": "6 state components; this controller build reads 4 inputs (the task description "
                        "with up to 6 inputs is not merged yet)",
}
assert set(PLANTS) | set(UNRUNNABLE) == {B.plant_info(i)["name"] for i in range(int(B.lib.icoac_sim_plant_count()))}


def spec(name: str) -> PlantSpec:
    """The plant called name; ConfigError naming why a registry plant cannot run, or that the
    registry has no such plant."""
    if name in PLANTS:
        return PLANTS[name]
    if name in UNRUNNABLE:
        raise B.ConfigError(B.SIM_ERR_BAD_PLANT, f"plant {name} cannot run: {UNRUNNABLE[name]}")
    B.plant_index(name)  # an unknown name: the registry's message
    raise AssertionError(name)
