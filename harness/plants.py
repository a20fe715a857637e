# SPDX-License-Identifier: Apache-2.0
"""The plants a benchmark runs, each defined once: the C registry's plant (dynamics, parameters,
failure test and grid: sim_host/src/plants/, docs/plants.md) and the controller settings of its
task for this controller build (the input scaling, the reflex zone and the critic grid), applied
under every condition's overrides and the user's --set. The cart-pole's are the C defaults.

The controller's task takes one input per state component, so a plant of n states runs with a
task of n inputs (n up to the build's ICOAC_MAX_INPUTS). A registry plant that cannot run is listed
with why; config.check_model refuses it by name.
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
    # the ICO cells the ICO prior averages (harness.prior.compute): "successful" (the paper's), or
    # "finished" where ICO balances too few cells for a prior (why: prior_why)
    prior_cells: str = "successful"
    prior_why: str = ""


# The cells of an ICO grid an ICO prior may average (PlantSpec.prior_cells).
PRIOR_CELLS = ("successful", "finished")


# The cart-pole's reflex zone along its position, 2.35 of 2.4 m, as a fraction of the input range
# (checked against the C defaults below).
ZONE_FRACTION = 2.35 / 2.4


def _check_zone_fraction() -> None:
    default = B.Config()
    B.lib.icoac_config_default(default)
    assert math.isclose(ZONE_FRACTION, default.task.rule_threshold[3] / default.policy.input_range[0], rel_tol=1e-6)


_check_zone_fraction()


def _param(plant: str, name: str) -> float:
    return {p["name"]: p["value"] for p in B.plant_info(plant)["params"]}[name]


def furuta_task(plant: str, setting: dict[str, float]) -> dict[str, Any]:
    """The Furuta's controller settings of a task setting: input ranges (arm angle, arm velocity,
    pendulum angle = its failure limit, pendulum velocity), the critic grid over the same ranges,
    the reflex zone (ZONE_FRACTION of the arm range; the pendulum's at zone_deg), ICO's rate and
    the policy gain. The cart-pole's rule table and critic units carry over."""
    limit = _param(plant, "pendulum_limit")
    ranges = [setting["arm_range"], setting["arm_velocity_range"], limit, setting["pendulum_velocity_range"]]
    return {"policy.input_range": ranges, "critic.range": ranges,
            "policy.zone_x": ZONE_FRACTION * setting["arm_range"],
            "policy.zone_theta": math.radians(setting["zone_deg"]),
            "ico.rate": setting["ico.rate"], "policy.gain": setting["policy.gain"]}


# The double pendulum's critic units per input (x, x_dot, theta1, theta1_dot, theta2, theta2_dot):
# the build's ICOAC_MAX_CRITIC_UNITS (216), three along both angles and the lower link's velocity.
DOUBLE_CRITIC_UNITS = (2, 2, 3, 3, 3, 2)


def double_task(plant: str, setting: dict[str, float]) -> dict[str, Any]:
    """The double pendulum's controller settings of a task setting: six inputs, scaled to the
    track and angle limits and to the swept velocity ranges (both links' alike); the critic grid
    over the same ranges; six rules, first match wins: the lower link beyond +-zone_deg gives the
    cart-pole's reflex (+1 when it leans toward +x), the cart beyond ZONE_FRACTION of the track
    gives cart_reflex times the push back to the centre (+1: the cart-pole's; -1: away, the sign
    of the plant's LQR gain on x), and the upper link beyond +-zone_deg gives upper_reflex times its sign (+1: push
    under it as under the lower link; -1: tip the lower link under it, the sign of the plant's LQR
    gain); ICO's rate and the policy gain."""
    x_limit, limit = _param(plant, "x_limit"), _param(plant, "angle_limit")
    v = setting["link_velocity_range"]
    ranges = [x_limit, setting["cart_velocity_range"], limit, v, limit, v]
    z, zx = math.radians(setting["zone_deg"]), ZONE_FRACTION * x_limit
    up, cart = setting["upper_reflex"], setting["cart_reflex"]
    above, below = B.RULE_SIDES["above"], B.RULE_SIDES["below"]
    return {"task.n_inputs": 6, "task.n_rules": 6, "task.rule_input": [2, 0, 2, 0, 4, 4],
            "task.rule_side": [above, below, below, above, above, below],
            "task.rule_threshold": [z, -zx, -z, zx, z, -z], "task.rule_reflex": [1.0, cart, -1.0, -cart, up, -up],
            "policy.input_range": ranges, "critic.range": ranges, "critic.units": list(DOUBLE_CRITIC_UNITS),
            "ico.rate": setting["ico.rate"], "policy.gain": setting["policy.gain"]}


# Each swept plant's task: the space its sweep draws settings from (harness.tools.plant_sweeps) and
# the controller settings of a setting.
TASK_SPACES: dict[str, tuple[tuple[tuple[str, tuple[float, ...]], ...], Any]] = {
    "furuta": ((("arm_range", (0.5, 1.0, 1.5708, 3.0)),
                ("arm_velocity_range", (1.0, 2.3, 6.4, 15.0, 40.0)),
                ("pendulum_velocity_range", (0.3, 0.6, 1.0, 2.0, 5.6)),
                ("zone_deg", (11.5, 10.0, 8.0, 6.0)),
                ("ico.rate", (1e-4, 1e-3, 1e-2)),
                ("policy.gain", (1.0, 3.0, 10.0))), furuta_task),
    # Each space put its best at its edges, and the next extends those dimensions beyond it: the
    # first (rate 0.01, gain 30 N, both velocity ranges and the zone at their largest), the second
    # (cart velocity range 10 m/s, rate 0.1, gain 3 N).
    "double_cart_pole": ((("cart_velocity_range", (1.0, 2.0, 3.5, 6.0, 10.0, 17.0, 30.0)),
                          ("link_velocity_range", (0.5, 1.0, 2.0, 4.0, 8.0)),
                          ("zone_deg", (11.0, 10.0, 8.0, 6.0, 4.0)),
                          ("upper_reflex", (1.0, -1.0)),
                          ("cart_reflex", (1.0, -1.0)),
                          ("ico.rate", (1e-4, 1e-3, 1e-2, 1e-1, 0.3, 1.0)),
                          ("policy.gain", (0.3, 1.0, 3.0, 10.0, 30.0, 100.0))), double_task),
}


def task_overrides(plant: str, setting: dict[str, float]) -> dict[str, Any]:
    """The controller settings of a setting of the plant's task space (TASK_SPACES)."""
    return TASK_SPACES[plant][1](plant, setting)


# The Furuta's task setting, chosen by its sweep (docs/sweeps-furuta.md).
FURUTA_SETTING = {"arm_range": 1.0, "arm_velocity_range": 2.3, "pendulum_velocity_range": 0.6, "zone_deg": 8.0,
                  "ico.rate": 0.01, "policy.gain": 1.0}

# ICO->RL's reading and noise on the Furuta, chosen by its learner sweep (docs/sweeps-furuta.md).
FURUTA_ICO_RL = {"actor.update": "mean", "actor.likelihood_std": 0.1, "actor.scale": 0.1, "actor.noise_std": 1.0}

# The double pendulum's task setting, chosen by its sweep (docs/sweeps-double_cart_pole.md).
DOUBLE_SETTING = {"cart_velocity_range": 30.0, "link_velocity_range": 4.0, "zone_deg": 10.0, "upper_reflex": -1.0,
                  "cart_reflex": -1.0, "ico.rate": 1.0, "policy.gain": 10.0}

PLANTS: dict[str, PlantSpec] = {
    CART_POLE: PlantSpec(CART_POLE, {}, "the C defaults (the paper's task)"),
    "furuta": PlantSpec("furuta", task_overrides("furuta", FURUTA_SETTING),
                        "its sweep (docs/sweeps-furuta.md): input scaling, reflex zone, ICO rate, gain",
                        # reading and exploration noise (V) by the learner sweeps of docs/sweeps-furuta.md:
                        # ICO->RL takes RL alone's (mean) reading here; the prior's decomposition takes
                        # the settings of the learner whose prior mean it shares
                        learners={"ico-rl": FURUTA_ICO_RL, "ico-mean-rl": FURUTA_ICO_RL,
                                  "rl": {"actor.noise_std": 3.0}, "rl-ico-cov": {"actor.noise_std": 3.0}}),
    "double_cart_pole": PlantSpec("double_cart_pole", task_overrides("double_cart_pole", DOUBLE_SETTING),
                                  "its sweep (docs/sweeps-double_cart_pole.md): velocity scaling, reflex zone "
                                  "and the upper link's reflex sign, ICO rate, gain",
                                  # the learner sweeps (docs/sweeps-double_cart_pole.md): no setting of
                                  # either actor-critic learner balances a cell, so both keep their
                                  # defaults
                                  prior_cells="finished",
                                  prior_why="ICO balances at most 1 of its 1225 cells at the default caps (no prior "
                                            "of 2 or more successful cells in any frame), but it learns weights in "
                                            "every cell: the ICO prior averages them, balanced or not"),
}
# Registry plants the controller build cannot run, and why.
UNRUNNABLE: dict[str, str] = {}
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
assert all(p.prior_cells in PRIOR_CELLS and (p.prior_cells == PRIOR_CELLS[0]) != bool(p.prior_why) for p in PLANTS.values())
