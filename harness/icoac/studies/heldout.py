# SPDX-License-Identifier: Apache-2.0
"""The held-out tuning protocol (docs/tuning.md, "The held-out protocol"), fixed before its runs:
which cells and seeds tune, which evaluate, each learner's space, the budget and the criterion.

- Cells: per plant, a fixed random TUNING_FRACTION of the grid's cells tunes (numpy PCG64 seeded
  by SPLIT_STREAM and the plant's name); the rest is held out. Evaluation reports the held-out
  cells and all cells.
- Seeds: TUNING_SEEDS tune; the bench's seeds (0 to 4) evaluate. The two sets are disjoint, so
  no tuning run shares a start velocity or an exploration draw with an evaluation run.
- Budget: every learner, ICO included, gets SETTINGS settings x len(TUNING_SEEDS) seeds, at the
  default profile's caps (ICO 1e5 trials, the learners 1000), from its space on the plant (SPACES,
  and PLANT_SPACES where a plant's defaults or units differ).
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

SPLIT_STREAM = 0x7E57_5E7
TUNING_FRACTION = 0.3
TUNING_SEEDS = (100, 101)
SETTINGS = 12
TIE = 1e-9
TUNING_CELLS = "tuning"  # the cell spec that names the tuning cells (`ceiling --cells tuning`)

# Each learner's space: parameter -> values, full factorial, SETTINGS settings each, the current
# cart-pole default first. The four actor-critic priors share one space: the two readings with their
# defaults (gradient beta = 0.001; mean sigma_L = 0.1, alpha = 0.1) x the exploration noise, with
# exploration until tick 1000 (the defaults of all four); the two searches share the breadth x the
# floor; CMA-ES gets its start breadth (sigma0^2 = cov_scale; the check takes 1 to 1000).
_ACTOR_CRITIC = {
    "reading": [{"actor.update": "gradient", "actor.rate": 0.001},
                {"actor.update": "mean", "actor.likelihood_std": 0.1, "actor.scale": 0.1}],
    "actor.noise_std": [3, 1, 2, 5, 8, 12],
    "actor.explore_ticks": [1000],
}
SPACES: Mapping[str, Mapping[str, Sequence[Any]]] = {
    "ico": {"ico.rate": [1e-4, 1e-5, 3e-5, 3e-4, 1e-3, 3e-3], "ico.timing": ["code", "literal"]},
    "ico-rl": _ACTOR_CRITIC,
    "ico-mean-rl": _ACTOR_CRITIC,
    "rl-ico-cov": {**_ACTOR_CRITIC, "reading": _ACTOR_CRITIC["reading"][::-1], "actor.noise_std": [5, 1, 2, 3, 8, 12]},
    "rl": {**_ACTOR_CRITIC, "reading": _ACTOR_CRITIC["reading"][::-1], "actor.noise_std": [12, 1, 2, 3, 5, 8]},
    "ico-search": {"search.cov_scale": [64, 1, 4, 16, 256, 1000], "search.floor": [1, 0.1]},
    "search": {"search.cov_scale": [4, 1, 2, 8, 16, 64], "search.floor": [1, 0.1]},
    "cma-es": {"search.cov_scale": [4, 1, 1.5, 2, 3, 6, 8, 12, 16, 32, 64, 256]},
}

# The other plants' spaces where their defaults differ from the cart-pole's (a learner not listed
# takes SPACES'), each with the plant's default first. ICO's rate: the cart-pole's multiples of the
# plant's default (0.1 to 30), or of the largest valid rate (1) below it. The Furuta's actor-critic noise in volts, under its +-10 V limit:
# both of its defaults (1 V, 3 V) and the same six-value breadth.
_FURUTA_NOISE = [0.3, 0.5, 1, 2, 3, 5]
PLANT_SPACES: Mapping[str, Mapping[str, Mapping[str, Sequence[Any]]]] = {
    "furuta": {
        "ico": {"ico.rate": [0.01, 0.001, 0.003, 0.03, 0.1, 0.3], "ico.timing": ["code", "literal"]},
        "ico-rl": {**SPACES["rl"], "actor.noise_std": [1] + [v for v in _FURUTA_NOISE if v != 1]},
        "ico-mean-rl": {**SPACES["rl"], "actor.noise_std": [1] + [v for v in _FURUTA_NOISE if v != 1]},
        "rl-ico-cov": {**SPACES["rl"], "actor.noise_std": [3] + [v for v in _FURUTA_NOISE if v != 3]},
        "rl": {**SPACES["rl"], "actor.noise_std": [3] + [v for v in _FURUTA_NOISE if v != 3]},
    },
    "double_cart_pole": {
        "ico": {"ico.rate": [1.0, 0.003, 0.01, 0.03, 0.1, 0.3], "ico.timing": ["code", "literal"]},
    },
}


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


def spaces(plant: str) -> dict[str, Mapping[str, Sequence[Any]]]:
    """Every learner's space on the plant."""
    own = PLANT_SPACES.get(plant, {})
    return {learner: own.get(learner, space) for learner, space in SPACES.items()}


def settings(learner: str, plant: str = "cart_pole") -> list[dict[str, Any]]:
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


def protocol(plant: str = "cart_pole") -> dict[str, Any]:
    """The protocol on the plant as data (recorded beside every tuning result)."""
    return {"split_stream": SPLIT_STREAM, "tuning_fraction": TUNING_FRACTION, "tuning_seeds": list(TUNING_SEEDS),
            "settings": SETTINGS, "tie": TIE,
            "criterion": "mean success rate over the tuning seeds on the tuning cells; then fewer median trials "
                         "to success; then the space's order (its default first)",
            "spaces": {name: {k: list(v) for k, v in space.items()} for name, space in spaces(plant).items()},
            "baseline_spaces": {name: {k: list(v) for k, v in space.items()} for name, space in BASELINE_SPACES.items()}}


assert all(len(settings(name, plant)) == SETTINGS for plant in ("cart_pole", *PLANT_SPACES) for name in SPACES)
assert all(len(baseline_settings(name)) == SETTINGS for name in BASELINE_SPACES)
