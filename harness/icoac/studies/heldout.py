# SPDX-License-Identifier: Apache-2.0
"""The held-out tuning protocol (docs/tuning.md, "The held-out protocol"), fixed before its runs:
which cells and seeds tune, which evaluate, each learner's space, the budget and the criterion.

- Cells: per plant, a fixed random TUNING_FRACTION of the grid's cells tunes (numpy PCG64 seeded
  by SPLIT_STREAM and the plant's name); the rest is held out. Evaluation reports the held-out
  cells and all cells.
- Seeds: TUNING_SEEDS tune; the bench's seeds (0 to 4) evaluate. The two sets are disjoint, so
  no tuning run shares a start velocity or an exploration draw with an evaluation run.
- Budget: every learner, ICO included, gets SETTINGS settings x len(TUNING_SEEDS) seeds, at the
  default profile's caps (ICO 1e5 trials, the learners 1000), from its space on the plant
  (spaces(): derived from the plant's defaults and input unit).
- Criterion: the highest mean success rate over the tuning seeds on the tuning cells; ties (equal
  to 1e-9) go to fewer median trials to success, then to the earlier setting of the space (each
  space lists the current default first, so a tie keeps it).
- The learners that take ICO's output take it from ICO's chosen setting, run on the tuning cells
  with the same tuning seed.
"""
from __future__ import annotations

import hashlib
import itertools
import math
from typing import Any, Mapping, Sequence

import numpy as np

from icoac.core import geometry
from icoac.core.options import CART_POLE

SPLIT_STREAM = 0x7E57_5E7
TUNING_FRACTION = 0.3
TUNING_SEEDS = (100, 101)
SETTINGS = 12
TIE = 1e-9
TUNING_CELLS = "tuning"  # the cell spec that names the tuning cells (`ceiling --cells tuning`)

# The learners, ICO first (the others may take its output).
LEARNERS = ("ico", "ico-rl", "ico-mean-rl", "rl-ico-cov", "rl", "ico-search", "search", "cma-es")
# Each learner's space on a plant (spaces()): parameter -> values, full factorial, SETTINGS settings
# each, the plant's default first. Derived from the plant's own defaults, so no plant is named here:
# - ICO: its rate at the first six of these multiples of the plant's default rate that the rate's
#   valid range takes, x the two timings.
# - The four actor-critic priors: the two readings (gradient beta = 0.001; mean sigma_L = 0.1,
#   alpha = 0.1), the plant's default reading first, x the exploration noise from the list of the
#   plant's input unit (newtons; the Furuta's volts under its +-10 V: both of its defaults and the
#   same breadth), the default first, exploring until tick 1000 (the defaults of all four).
# - The two searches share the breadth x the floor; CMA-ES gets its start breadth (sigma0^2 =
#   cov_scale; the check takes 1 to 1000). These do not depend on the plant.
_ICO_MULTIPLES = (1, 0.1, 0.3, 3, 10, 30, 0.03, 0.01, 0.003)
_NOISE_BY_UNIT = {"N": (1, 2, 3, 5, 8, 12), "V": (0.3, 0.5, 1, 2, 3, 5)}
_READINGS = {"gradient": {"actor.update": "gradient", "actor.rate": 0.001},
             "mean": {"actor.update": "mean", "actor.likelihood_std": 0.1, "actor.scale": 0.1}}
_ACTOR_CRITIC = ("ico-rl", "ico-mean-rl", "rl-ico-cov", "rl")
_FIXED: Mapping[str, Mapping[str, Sequence[Any]]] = {
    "ico-search": {"search.cov_scale": [64, 1, 4, 16, 256, 1000], "search.floor": [1, 0.1]},
    "search": {"search.cov_scale": [4, 1, 2, 8, 16, 64], "search.floor": [1, 0.1]},
    "cma-es": {"search.cov_scale": [4, 1, 1.5, 2, 3, 6, 8, 12, 16, 32, 64, 256]},
}


def _default_first(default: Any, values: Sequence[Any]) -> list[Any]:
    return [default] + [v for v in values if v != default]


def spaces(plant: str) -> dict[str, Mapping[str, Sequence[Any]]]:
    """Every learner's space on the plant (see LEARNERS' comment)."""
    from icoac.core import binding as B
    from icoac.core.config import ConfigError, build_config

    def valid(overrides: Mapping[str, Any], learner: str) -> bool:
        try:
            build_config(overrides, condition=learner, plant=plant)
        except ConfigError:
            return False
        return True
    out: dict[str, Mapping[str, Sequence[Any]]] = {}
    rate = float(build_config(condition="ico", plant=plant).controller.ico.rate)
    rates = [float(f"{rate * m:.6g}") for m in _ICO_MULTIPLES]
    out["ico"] = {"ico.rate": [r for r in rates if valid({"ico.rate": r}, "ico")][:6],
                  "ico.timing": ["code", "literal"]}
    updates = {value: name for name, value in B.ACTOR_UPDATES.items()}
    noises = _NOISE_BY_UNIT[B.plant_info(plant)["input"][1]]
    for learner in _ACTOR_CRITIC:
        actor = build_config(condition=learner, plant=plant).controller.actor
        noise = float(f"{float(actor.noise_std):.6g}")
        out[learner] = {"reading": [_READINGS[r] for r in _default_first(updates[int(actor.update)], list(_READINGS))],
                        "actor.noise_std": _default_first(int(noise) if noise.is_integer() else noise, noises),
                        "actor.explore_ticks": [1000]}
    out.update(_FIXED)
    return {learner: out[learner] for learner in LEARNERS}


# PPO's and SAC's spaces (icoac.studies.baselines.sb3): hyperparameters over their RL Zoo start,
# which comes first; the same SETTINGS x TUNING_SEEDS, each run at the algorithm's budget of env
# steps, trained on the tuning cells only and scored on them by the same criterion (no trials to
# success: ties go to the space's order). The same space on every plant.
BASELINE_SPACES: Mapping[str, Mapping[str, Sequence[Any]]] = {
    "ppo": {"learning_rate": [2.22425e-4, 1e-4, 5e-4, 1e-3], "gamma": [0.999, 0.99, 0.98]},
    "sac": {"learning_rate": [3e-4, 1e-4, 1e-3], "learning_starts": [10_000, 1_000], "gamma": [0.99, 0.98]},
}


def baseline_settings(algo: str) -> list[dict[str, Any]]:
    """PPO's or SAC's settings as hyperparameter overrides, in the space's order (the first: the
    Zoo's)."""
    space = BASELINE_SPACES[algo]
    return [dict(zip(space, combo)) for combo in itertools.product(*space.values())]


def settings(learner: str, plant: str = CART_POLE) -> list[dict[str, Any]]:
    """The learner's settings on the plant as configuration overrides, in the space's order (the
    first: the plant's current default)."""
    space = spaces(plant)[learner]
    out = []
    for combo in itertools.product(*space.values()):
        setting: dict[str, Any] = {}
        for name, value in zip(space, combo):
            setting.update(value if name == "reading" else {name: value})
        out.append(setting)
    return out


def key(setting: Mapping[str, Any]) -> str:
    """A setting's directory name: its items, sorted."""
    return ",".join(f"{k}={v}" for k, v in sorted(setting.items()))


def _plant_seed(plant: str) -> int:
    return int.from_bytes(hashlib.sha256(plant.encode()).digest()[:8], "little")


def tuning_cells(plant: str) -> np.ndarray:
    """The plant's tuning cells (sorted grid indices): round(TUNING_FRACTION * cells) of them."""
    grid = geometry.of(plant)
    rng = np.random.Generator(np.random.PCG64([SPLIT_STREAM, _plant_seed(plant)]))
    n = int(round(TUNING_FRACTION * grid.cells))
    return np.sort(rng.choice(grid.cells, size=n, replace=False))


def cell_spec(spec: Any, plant: str) -> Any:
    """A command's --cells with the name TUNING_CELLS replaced by the plant's tuning cells (a list of
    indices); any other spec unchanged."""
    if isinstance(spec, str) and spec.strip() == TUNING_CELLS:
        return [int(i) for i in tuning_cells(plant)]
    return spec


def heldout_mask(plant: str) -> np.ndarray:
    """True for the cells evaluation holds out (not tuned on), over the plant's whole grid."""
    mask = np.ones(geometry.of(plant).cells, dtype=bool)
    mask[tuning_cells(plant)] = False
    return mask


def rank(rows: Sequence[Mapping[str, Any]]) -> list[Mapping[str, Any]]:
    """Rows (each with 'order', 'success_rate' and 'median_trials', None when nothing succeeded)
    best first by the criterion."""
    def sort_key(r):
        median = r["median_trials"] if r["median_trials"] is not None else math.inf
        return (-round(r["success_rate"] / TIE), median, r["order"])
    return sorted(rows, key=sort_key)


def protocol(plant: str = CART_POLE) -> dict[str, Any]:
    """The protocol on the plant as data (recorded beside every tuning result)."""
    return {"split_stream": SPLIT_STREAM, "tuning_fraction": TUNING_FRACTION, "tuning_seeds": list(TUNING_SEEDS),
            "settings": SETTINGS, "tie": TIE,
            "criterion": "mean success rate over the tuning seeds on the tuning cells; then fewer median trials "
                         "to success; then the space's order (its default first)",
            "spaces": {name: {k: list(v) for k, v in space.items()} for name, space in spaces(plant).items()},
            "baseline_spaces": {name: {k: list(v) for k, v in space.items()} for name, space in BASELINE_SPACES.items()}}


assert all(len(baseline_settings(name)) == SETTINGS for name in BASELINE_SPACES)
