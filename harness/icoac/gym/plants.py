# SPDX-License-Identifier: Apache-2.0
"""The envs of the plants: every plant of the C registry (icoac.core.plants.PLANTS, docs/plants.md)
as an EnvPlant derived from its C descriptor: its state (names, units), its action, its parameters
and the model API functions that step it (bit for bit the engine's trial loop), test failure and
draw start states. icoac.gym registers ``icoac/<name>-v0`` for each entry of ENVS.
"""
from __future__ import annotations

import ctypes
import functools
import math
from dataclasses import dataclass
from typing import Any, Callable, Mapping

import numpy as np

from icoac.core import binding as B
from icoac.core.plants import PLANTS


@dataclass(frozen=True)
class Variable:
    """One component of a plant's state or action."""
    name: str
    unit: str
    meaning: str


@dataclass(frozen=True)
class EnvPlant:
    """What an env needs to know about a plant. ``configure`` turns constructor keyword arguments
    into the plant's parameters (checked by C); ``step`` advances a float64 state in place by one
    control period under a force; ``failed`` is the termination test; ``start`` gives a start state
    and the reset info from the env's random generator and the reset options."""
    name: str
    state: tuple[Variable, ...]
    action: Variable
    action_limit: float
    parameter_names: tuple[str, ...]
    reset_options: tuple[str, ...]
    max_episode_steps: int
    configure: Callable[[Mapping[str, Any]], Any]
    step: Callable[[Any, np.ndarray, float], None]
    failed: Callable[[Any, np.ndarray], bool]
    start: Callable[[Any, np.random.Generator, Mapping[str, Any]], tuple[np.ndarray, dict]]
    period: Callable[[Any], float]


RESET_OPTIONS = ("state", "cell", "grid_seed")
UINT64_LIMIT = 2 ** 64


def _run_default() -> B.Run:
    run = B.Run()
    B.lib.icoac_sim_run_default(ctypes.byref(run))
    return run


def _index(options: Mapping[str, Any], name: str, limit: int, rng: np.random.Generator) -> int:
    """An integer option in [0, limit), or a draw from rng when it is absent."""
    if name not in options:
        return int(rng.integers(limit, dtype=np.uint64))
    value = options[name]
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, (int, np.integer)) or not 0 <= value < limit:
        raise ValueError(f"reset option {name!r} must be an integer in [0, {limit}), got {value!r:.40}")
    return int(value)


def _grid_start(options: Mapping[str, Any], names: tuple[str, ...], n_cells: int, rng: np.random.Generator,
                grid: Callable[[int], np.ndarray],
                start_of: Callable[[np.ndarray], np.ndarray]) -> tuple[np.ndarray, dict]:
    """Options: ``state`` (one finite value per name), any state; or ``cell`` (index in the plant's
    grid, row-major) and ``grid_seed`` (the seed of the grid's cell seeds): start_of(that cell, as
    an array of one). Each of cell and grid_seed not given is drawn from rng."""
    unknown = sorted(set(options) - set(RESET_OPTIONS))
    if unknown:
        raise ValueError(f"unknown reset option {unknown[0]!r}; valid: {', '.join(RESET_OPTIONS)}")
    if "state" in options:
        if len(options) > 1:
            raise ValueError("reset option 'state' excludes 'cell' and 'grid_seed'")
        try:
            state = np.array(options["state"], dtype=np.float64)
        except (TypeError, ValueError):
            state = None
        if state is None or state.shape != (len(names),) or not np.all(np.isfinite(state)):
            raise ValueError(f"reset option 'state' must be {len(names)} finite numbers "
                             f"({', '.join(names)}), got {options['state']!r:.60}")
        return state, {}
    cell = _index(options, "cell", n_cells, rng)
    grid_seed = _index(options, "grid_seed", UINT64_LIMIT, rng)
    row = grid(grid_seed)[cell:cell + 1]
    # seeds as numpy uint64: a vector env gathers info values into arrays of their type
    return start_of(row), {"cell": cell, "grid_seed": np.uint64(grid_seed),
                           "cell_seed": np.uint64(row[0]["seed"])}


# -- every registry plant: icoac_sim_model_t, icoac_sim_model_step / _failed / _start, its grid ----
MODEL_OPTIONS = ("dt", "integrator", "init_velocity_noise")


@dataclass(frozen=True)
class ModelParameters:
    """A registry plant's checked model (parameters, dt, integrator) and its start-velocity noise."""
    model: B.Model
    init_velocity_noise: float


def gym_name(registry_name: str) -> str:
    """The env name of a C registry plant: its words capitalised and joined ("a_b" -> "AB")."""
    return "".join(word.capitalize() for word in registry_name.split("_"))


@functools.lru_cache(maxsize=4)
def plant_grid(index: int, seed: int) -> np.ndarray:
    """A registry plant's grid cells for a seed (icoac_sim_plant_grid), read-only."""
    info = B.plant_info(index)
    cells = np.zeros(info["rows"]["count"] * info["cols"]["count"], dtype=B.CELL_DTYPE)
    B.check_status(B.lib.icoac_sim_plant_grid(index, cells, cells.size, seed), "plant grid")
    cells.flags.writeable = False
    return cells


def model_start(parameters: ModelParameters, cell: np.ndarray) -> np.ndarray:
    """The start state (all MAX_STATE values) of a trial from a grid cell (an array of one), its
    drawn components from the generator the engine seeds for that cell."""
    rng = B.Rng()
    B.lib.icoac_rng_seed(ctypes.byref(rng), int(cell[0]["seed"]), int(B.constant("ICOAC_SIM_START_STREAM")))
    state = np.zeros(B.MAX_STATE)
    B.check_status(B.lib.icoac_sim_model_start(ctypes.byref(parameters.model), cell,
                                               parameters.init_velocity_noise, ctypes.byref(rng), state),
                   "start state")
    return state


def registry_spec(registry_name: str) -> EnvPlant:
    """The EnvPlant of a C registry plant: state, action and parameter names and units from its
    descriptor; stepped, tested and started by icoac_sim_model_step / _failed / _start."""
    info = B.plant_info(registry_name)
    index, n = info["index"], len(info["state"])
    names = tuple(p["name"] for p in info["params"]) + MODEL_OPTIONS
    cells = info["rows"]["count"] * info["cols"]["count"]

    def configure(parameters: Mapping[str, Any]) -> ModelParameters:
        unknown = sorted(set(parameters) - set(names))
        if unknown:
            raise ValueError(f"unknown {registry_name} parameter {unknown[0]!r}; valid: {', '.join(names)}")
        given = dict(parameters)
        if isinstance(given.get("integrator"), str) and given["integrator"] not in B.INTEGRATORS:
            raise ValueError(f"integrator must be one of {', '.join(B.INTEGRATORS)}, got {given['integrator']!r:.40}")
        noise = float(given.pop("init_velocity_noise", _run_default().init_velocity_noise))
        result = ModelParameters(B.model_default(index, **given), noise)
        model_start(result, plant_grid(index, 0)[:1])  # C checks the noise
        return result

    def to_model(state: np.ndarray) -> np.ndarray:
        full = np.zeros(B.MAX_STATE)
        full[:n] = state
        return full

    def step(parameters: ModelParameters, state: np.ndarray, u: float) -> None:
        full = to_model(state)
        B.check_status(B.lib.icoac_sim_model_step(ctypes.byref(parameters.model), full, u), "plant step")
        state[:] = full[:n]

    def failed(parameters: ModelParameters, state: np.ndarray) -> bool:
        flag = ctypes.c_int32(0)
        B.check_status(B.lib.icoac_sim_model_failed(ctypes.byref(parameters.model), to_model(state),
                                                    ctypes.byref(flag)), "failure test")
        return bool(flag.value)

    def start(parameters: ModelParameters, rng: np.random.Generator,
              options: Mapping[str, Any]) -> tuple[np.ndarray, dict]:
        return _grid_start(options, tuple(name for name, _ in info["state"]), cells, rng,
                           lambda seed: plant_grid(index, seed), lambda cell: model_start(parameters, cell)[:n].copy())

    return EnvPlant(
        name=gym_name(info["name"]),
        state=tuple(Variable(name, unit, f"state component {i} of {info['title']}")
                    for i, (name, unit) in enumerate(info["state"])),
        action=Variable(*info["input"], "plant input, held for one period"),
        action_limit=float(B.constant("ICOAC_FORCE_MAX")),  # the controller's output bound
        parameter_names=names,
        reset_options=RESET_OPTIONS,
        max_episode_steps=int(_run_default().success_steps),
        configure=configure, step=step, failed=failed, start=start,
        period=lambda parameters: float(parameters.model.dt),
    )


# The env of every plant of the registry (icoac.core.plants.PLANTS), by env name.
ENVS: dict[str, EnvPlant] = {env.name: env for env in map(registry_spec, PLANTS)}
assert all(math.isfinite(env.action_limit) and env.action_limit > 0 for env in ENVS.values())


def env_id(spec: EnvPlant) -> str:
    return f"icoac/{spec.name}-v0"
