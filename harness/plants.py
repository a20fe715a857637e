"""The plants a benchmark runs, each defined once: the C registry's plant (dynamics, parameters,
failure test and grid: sim_host/src/plants/, docs/plants.md) and the controller settings of its
task for this controller build (the input scaling, the reflex zone and the critic grid), applied
under every condition's overrides and the user's --set. The cart-pole's are the C defaults.

A plant whose state the controller build cannot take (the 6-state double pendulum: the controller
reads 4 inputs) is listed with why it cannot run; config.check_model refuses it by name.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

from . import _binding as B

CART_POLE = "cart_pole"  # the registry's first plant, the one of the B.Plant struct


@dataclass(frozen=True)
class PlantSpec:
    name: str
    controller: dict[str, Any] = field(default_factory=dict)  # the task's controller settings
    why: str = ""  # where the settings come from


def _furuta_ranges() -> list[float]:
    """Arm angle and pendulum angle scaled to +-1 at the plant's limits; the velocity ranges chosen
    by the Furuta sweep (docs/plants.md)."""
    params = {p["name"]: p["value"] for p in B.plant_info("furuta")["params"]}
    return [params["arm_limit"], FURUTA_VELOCITY_RANGES[0], params["pendulum_limit"], FURUTA_VELOCITY_RANGES[1]]


# The Furuta's arm and pendulum velocity ranges (rad/s), from its sweep (docs/plants.md).
FURUTA_VELOCITY_RANGES = (6.4, 5.6)
# The cart-pole's reflex zone, 2.35 of 2.4 m and 11.5 of 12 deg, as fractions of the limits.
ZONE_FRACTION = (2.35 / 2.4, 11.5 / 12.0)


def _furuta() -> PlantSpec:
    params = {p["name"]: p["value"] for p in B.plant_info("furuta")["params"]}
    ranges = _furuta_ranges()
    return PlantSpec("furuta", {
        "policy.input_range": ranges, "critic.range": ranges,
        "policy.zone_x": ZONE_FRACTION[0] * params["arm_limit"],
        "policy.zone_theta": ZONE_FRACTION[1] * params["pendulum_limit"],
    }, "the cart-pole's settings scaled to the Furuta's limits; velocity ranges from its sweep")


PLANTS: dict[str, PlantSpec] = {
    CART_POLE: PlantSpec(CART_POLE, {}, "the C defaults (the paper's task)"),
    "furuta": _furuta(),
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
