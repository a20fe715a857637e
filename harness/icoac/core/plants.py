# SPDX-License-Identifier: Apache-2.0
"""The plants a benchmark runs, each described once, in its C file (sim_host/src/plants/,
docs/plants.md): dynamics, parameters, failure test, grid, and the controller task it is
benchmarked with (icoac_sim_task_t: input ranges, rule table, critic grid, learner settings,
written from the task's knobs). This
module reads the C registry: PLANTS has every registry plant, and spec(name) refuses a plant whose
file has no task, rather than run it on another plant's settings.

The controller's task takes one input per state component, so a plant of n states runs with a
task of n inputs (n up to the build's ICOAC_MAX_INPUTS; config.check_model refuses more).
"""
from __future__ import annotations

import ctypes
from dataclasses import dataclass
from typing import Any, Mapping

from icoac.core import binding as B
from icoac.core.errors import UsageError
from icoac.core.registry import CONDITIONS

# The cells of an ICO grid an ICO prior may average (PlantSpec.prior_cells): the paper's
# "successful", or "finished" where ICO balances too few cells for a prior.
PRIOR_CELLS = ("successful", "finished")


@dataclass(frozen=True)
class PlantSpec:
    """A registry plant as the harness runs it, read from its C descriptor."""
    name: str
    index: int
    title: str
    task_source: str | None  # where its task's settings come from; None: it has no task
    learners: tuple[str, ...] = ()  # the conditions its task has settings for
    knobs: tuple[str, ...] = ()  # the names of its task's knobs, in their C order
    paper: bool = False  # the paper's plant and task: its published results apply
    prior_cells: str = PRIOR_CELLS[0]
    prior_why: str = ""

    @property
    def has_task(self) -> bool:
        return self.task_source is not None

    def task_config(self, cfg: B.Config, knobs: Mapping[str, float] | None = None) -> None:
        """cfg = the C defaults, then the plant's task written from its knobs (icoac_sim_plant_task):
        their defaults, replaced by ``knobs`` by name."""
        values = {k["name"]: k["value"] for k in B.plant_info(self.index)["task"]["knobs"]} if self.has_task else {}
        for name, value in (knobs or {}).items():
            if name not in values:
                raise B.ConfigError(B.SIM_ERR_BAD_PLANT, f"plant {self.name}'s task has no knob {name!r}; its knobs: "
                                    f"{', '.join(values) or 'none'}")
            values[name] = _knob_value(self.name, name, value)
        array = (ctypes.c_double * max(1, len(values)))(*values.values())
        if B.lib.icoac_sim_plant_task(self.index, array, ctypes.byref(cfg)) != B.SIM_OK:
            # the knob C refused, named with its range from the C table
            for k in B.plant_info(self.index)["task"]["knobs"]:
                if not k["min"] <= values[k["name"]] <= k["max"]:
                    raise B.ConfigError(B.SIM_ERR_BAD_PLANT, f"plant {self.name} task knob {k['name']}="
                                        f"{values[k['name']]:g} is outside [{k['min']:g}, {k['max']:g}] {k['unit']}")
            B.check_status(B.SIM_ERR_BAD_PLANT, f"plant {self.name} task")

    def actuator(self) -> dict:
        """{param, limit, source} of its C file's icoac_sim_actuator_t; a UsageError when it has none."""
        actuator = B.plant_info(self.index)["actuator"]
        if actuator is None:
            raise UsageError(f"plant {self.name} has no actuator limit in its C file (icoac_sim_actuator_t)")
        return actuator

    def limited_sets(self) -> list[str]:
        """The --set items that hold the plant to a real actuator's limit (its C file's
        icoac_sim_actuator_t; `--limited`): none where its default is that limit."""
        info = B.plant_info(self.index)
        actuator = self.actuator()
        default = next(p["value"] for p in info["params"] if p["name"] == actuator["param"])
        return [] if default == actuator["limit"] else [f"{actuator['param']}={actuator['limit']:.15g}"]

    def limited(self, sets: list[str] | None) -> list[str]:
        """`--limited` with these --set items: limited_sets() before them; a UsageError when they
        set the actuator's parameter too."""
        param = self.actuator()["param"]
        clash = [s for s in sets or [] if s.split("=", 1)[0].strip() == param]
        if clash:
            raise UsageError(f"--limited and --set {clash[0]} both set {param}; give one")
        return self.limited_sets() + list(sets or [])

    def learner_config(self, condition: str, cfg: B.Config) -> None:
        """The plant's settings of a learning condition over cfg, if it has some."""
        B.check_status(B.lib.icoac_sim_plant_learner(self.index, condition.encode(), ctypes.byref(cfg)),
                       f"plant {self.name} learner settings")


def _knob_value(plant: str, name: str, value: Any) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise B.ConfigError(B.SIM_ERR_BAD_PLANT, f"plant {plant} task knob {name} must be a number, got {value!r:.40}")
    return float(value)


def _spec(index: int) -> PlantSpec:
    info = B.plant_info(index)
    task = info["task"]
    if task is None:
        return PlantSpec(info["name"], index, info["title"], None)
    learners = tuple(c for group in task["learners"] for c in group)
    unknown = sorted(set(learners) - set(CONDITIONS))
    if unknown or len(set(learners)) != len(learners):
        raise B.LibraryError(f"plant {info['name']}: its task's learner settings name "
                             f"{', '.join(unknown) or 'a condition twice'}; conditions: {', '.join(CONDITIONS)}")
    why = task["prior_all_finished"]
    knobs = tuple(k["name"] for k in task["knobs"])
    taken = set(knobs) & ({p["name"] for p in info["params"]} | {"dt", "integrator"})
    if taken:
        raise B.LibraryError(f"plant {info['name']}: task knob {sorted(taken)[0]} has the name of a plant parameter")
    return PlantSpec(info["name"], index, info["title"], task["source"], learners, knobs, task["paper"],
                     PRIOR_CELLS[1] if why else PRIOR_CELLS[0], why or "")


# Every plant of the C registry, in its order.
PLANTS: dict[str, PlantSpec] = {s.name: s for s in map(_spec, range(int(B.lib.icoac_sim_plant_count())))}


def spec(name: str) -> PlantSpec:
    """The plant called name, with its task; ConfigError when the registry has no such plant or
    the plant's C file gives no task."""
    B.plant_index(name)  # an unknown name: the registry's message
    plant = PLANTS[name]
    if not plant.has_task:
        raise B.ConfigError(B.SIM_ERR_BAD_PLANT,
                            f"plant {name} has no controller task: its C file (sim_host/src/plants/) must give "
                            f"one (icoac_sim_task_t: input ranges, rule table, critic grid; docs/plants.md) "
                            f"before it can run; no other plant's settings are used")
    return plant
