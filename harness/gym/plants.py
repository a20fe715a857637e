# SPDX-License-Identifier: Apache-2.0
"""The plants the Gymnasium envs serve, each described once: its state (names, units), its action,
its parameters and the C functions that step it, test failure and draw start states.

A plant is a PlantSpec in PLANTS; harness.gym registers ``icoac/<name>-v0`` for each. The
cart-pole is stepped by its own C functions (bit for bit the engine's trial loop); every other
plant of the C registry (docs/plants.md) by the model API, described from its C descriptor.
"""
from __future__ import annotations

import ctypes
import functools
import math
from dataclasses import dataclass
from typing import Any, Callable, Mapping

import numpy as np

from .. import _binding as B
from ..config import PLANT_FIELDS, RunConfig, build_config


@dataclass(frozen=True)
class Variable:
    """One component of a plant's state or action; ``limit``: the parameter bounding it (the
    failure test: |value| > that parameter), if any."""
    name: str
    unit: str
    meaning: str
    limit: str | None = None


@dataclass(frozen=True)
class PlantSpec:
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


# -- the cart-pole: icoac_sim_plant_t, icoac_sim_plant_step, icoac_sim_failed, the paper grid ----------
CART_POLE_PARAMETERS = PLANT_FIELDS + ("init_velocity_noise",)
RESET_OPTIONS = ("state", "cell", "grid_seed")
UINT64_LIMIT = 2 ** 64


def _run_default() -> B.Run:
    run = B.Run()
    B.lib.icoac_sim_run_default(ctypes.byref(run))
    return run


def cart_pole_configure(parameters: Mapping[str, Any]) -> RunConfig:
    """Plant fields (gravity, cart_mass, pole_mass, half_length, dt, x_limit, theta_limit,
    integrator) and init_velocity_noise over the C defaults; ConfigError (naming the field) for a
    value C refuses, ValueError for another name."""
    unknown = sorted(set(parameters) - set(CART_POLE_PARAMETERS))
    if unknown:
        raise ValueError(f"unknown cart-pole parameter {unknown[0]!r}; valid: {', '.join(CART_POLE_PARAMETERS)}")
    return build_config(dict(parameters))


def cart_pole_step(cfg: RunConfig, state: np.ndarray, force: float) -> None:
    B.check_status(B.lib.icoac_sim_plant_step(ctypes.byref(cfg.plant), state, force), "plant step")


def cart_pole_failed(cfg: RunConfig, state: np.ndarray) -> bool:
    failed = B.lib.icoac_sim_failed(ctypes.byref(cfg.plant), state)
    if failed not in (0, 1):  # a status: the plant or the arguments refused
        B.check_status(failed, "failure test")
    return failed == 1


@functools.lru_cache(maxsize=1)
def paper_grid(seed: int) -> np.ndarray:
    """The paper grid's cells for a seed (icoac_sim_paper_grid), read-only; the last one is kept."""
    cells = np.zeros(B.GRID_CELLS, dtype=B.CELL_DTYPE)
    B.check_status(B.lib.icoac_sim_paper_grid(cells, cells.size, seed), "paper grid")
    cells.flags.writeable = False
    return cells


def _index(options: Mapping[str, Any], name: str, limit: int, rng: np.random.Generator) -> int:
    """An integer option in [0, limit), or a draw from rng when it is absent."""
    if name not in options:
        return int(rng.integers(limit, dtype=np.uint64))
    value = options[name]
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, (int, np.integer)) or not 0 <= value < limit:
        raise ValueError(f"reset option {name!r} must be an integer in [0, {limit}), got {value!r:.40}")
    return int(value)


def engine_start(cfg: RunConfig, x0: float, theta0: float, cell_seed: int) -> np.ndarray:
    """The start state of the engine's first trial from (x0, theta0) with a cell seed: velocities
    U(-a, a), a = init_velocity_noise, from the engine's own generator. icoac_sim_trajectory
    records the start state first; its one controller tick (C default configuration) is discarded."""
    controller = B.Config()
    B.lib.icoac_config_default(ctypes.byref(controller))
    states = np.zeros(2 * B.N_INPUTS)
    forces = np.zeros(1)
    n = ctypes.c_int64(0)
    status = B.lib.icoac_sim_trajectory(ctypes.byref(controller), ctypes.byref(cfg.plant), None, float(x0),
                                        float(theta0), float(cfg.run.init_velocity_noise), int(cell_seed), 1,
                                        states, forces, ctypes.byref(n))
    B.check_status(status, "start state")
    return states[:B.N_INPUTS].copy()


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


def cart_pole_start(cfg: RunConfig, rng: np.random.Generator, options: Mapping[str, Any]) -> tuple[np.ndarray, dict]:
    """The options of _grid_start on the paper grid; a cell starts where its first engine trial does."""
    return _grid_start(options, tuple(v.name for v in CART_POLE.state), B.GRID_CELLS, rng, paper_grid,
                       lambda row: engine_start(cfg, row[0]["x0"], row[0]["theta0"], int(row[0]["seed"])))


CART_POLE = PlantSpec(
    name="CartPole",
    state=(Variable("x", "m", "cart position", "x_limit"), Variable("x_dot", "m/s", "cart velocity"),
           Variable("theta", "rad", "pole angle, > 0 leaning toward +x", "theta_limit"),
           Variable("theta_dot", "rad/s", "pole angular velocity")),
    action=Variable("force", "N", "horizontal force on the cart, held for one period"),
    action_limit=float(B.constant("ICOAC_FORCE_MAX")),
    parameter_names=CART_POLE_PARAMETERS,
    reset_options=RESET_OPTIONS,
    max_episode_steps=int(_run_default().success_steps),
    configure=cart_pole_configure,
    step=cart_pole_step,
    failed=cart_pole_failed,
    start=cart_pole_start,
    period=lambda cfg: float(cfg.plant.dt),
)

# -- any other registry plant: icoac_sim_model_t, icoac_sim_model_step / _failed / _start, its grid --
MODEL_OPTIONS = ("dt", "integrator", "init_velocity_noise")
# Every plant of the C registry but the cart-pole (which has its own spec above).
REGISTRY_PLANTS = tuple(B.plant_info(i)["name"] for i in range(int(B.lib.icoac_sim_plant_count()))
                        if i != B.constant("ICOAC_SIM_CART_POLE"))


@dataclass(frozen=True)
class ModelParameters:
    """A registry plant's checked model (parameters, dt, integrator) and its start-velocity noise."""
    model: B.Model
    init_velocity_noise: float


def gym_name(registry_name: str) -> str:
    """The env name of a C registry plant: "double_cart_pole" -> "DoubleCartPole"."""
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


def registry_spec(registry_name: str) -> PlantSpec:
    """The PlantSpec of a C registry plant: state, action and parameter names and units from its
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

    return PlantSpec(
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


PLANTS: dict[str, PlantSpec] = {spec.name: spec for spec in
                                (CART_POLE, *(registry_spec(name) for name in REGISTRY_PLANTS))}
assert all(math.isfinite(spec.action_limit) and spec.action_limit > 0 for spec in PLANTS.values())


def env_id(spec: PlantSpec) -> str:
    return f"icoac/{spec.name}-v0"
