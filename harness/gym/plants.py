"""The plants the Gymnasium envs serve, each described once: its state (names, units), its action,
its parameters and the C functions that step it, test failure and draw start states.

A plant is a PlantSpec in PLANTS; harness.gym registers ``icoac/<name>-v0`` for each. Only the
cart-pole is here; another plant is another PlantSpec built on its own C functions.
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
CART_POLE_OPTIONS = ("state", "cell", "grid_seed")
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
    return bool(B.lib.icoac_sim_failed(ctypes.byref(cfg.plant), state))


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


def cart_pole_start(cfg: RunConfig, rng: np.random.Generator, options: Mapping[str, Any]) -> tuple[np.ndarray, dict]:
    """Options: ``state`` (x, x_dot, theta, theta_dot), any finite state; or ``cell`` (index in the
    paper grid, row-major over theta0 then x0) and ``grid_seed`` (the seed of the grid's cell
    seeds): the start of that cell's first engine trial. Each of cell and grid_seed not given is
    drawn from rng."""
    unknown = sorted(set(options) - set(CART_POLE_OPTIONS))
    if unknown:
        raise ValueError(f"unknown reset option {unknown[0]!r}; valid: {', '.join(CART_POLE_OPTIONS)}")
    if "state" in options:
        if len(options) > 1:
            raise ValueError("reset option 'state' excludes 'cell' and 'grid_seed'")
        try:
            state = np.array(options["state"], dtype=np.float64)
        except (TypeError, ValueError):
            state = None
        if state is None or state.shape != (B.N_INPUTS,) or not np.all(np.isfinite(state)):
            raise ValueError(f"reset option 'state' must be {B.N_INPUTS} finite numbers "
                             f"(x, x_dot, theta, theta_dot), got {options['state']!r:.60}")
        return state, {}
    cell = _index(options, "cell", B.GRID_CELLS, rng)
    grid_seed = _index(options, "grid_seed", UINT64_LIMIT, rng)
    row = paper_grid(grid_seed)[cell]
    state = engine_start(cfg, row["x0"], row["theta0"], int(row["seed"]))
    # seeds as numpy uint64: a vector env gathers info values into arrays of their type
    return state, {"cell": cell, "grid_seed": np.uint64(grid_seed), "cell_seed": np.uint64(row["seed"])}


CART_POLE = PlantSpec(
    name="CartPole",
    state=(Variable("x", "m", "cart position", "x_limit"), Variable("x_dot", "m/s", "cart velocity"),
           Variable("theta", "rad", "pole angle, > 0 leaning toward +x", "theta_limit"),
           Variable("theta_dot", "rad/s", "pole angular velocity")),
    action=Variable("force", "N", "horizontal force on the cart, held for one period"),
    action_limit=float(B.constant("ICOAC_FORCE_MAX")),
    parameter_names=CART_POLE_PARAMETERS,
    reset_options=CART_POLE_OPTIONS,
    max_episode_steps=int(_run_default().success_steps),
    configure=cart_pole_configure,
    step=cart_pole_step,
    failed=cart_pole_failed,
    start=cart_pole_start,
    period=lambda cfg: float(cfg.plant.dt),
)

PLANTS: dict[str, PlantSpec] = {spec.name: spec for spec in (CART_POLE,)}
assert all(math.isfinite(spec.action_limit) and spec.action_limit > 0 for spec in PLANTS.values())


def env_id(spec: PlantSpec) -> str:
    return f"icoac/{spec.name}-v0"
