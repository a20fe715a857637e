# SPDX-License-Identifier: Apache-2.0
"""Priors of the RL conditions (method.md, A15-A17) from the final weights of an ICO grid.

ICO->RL: mean and n x n sample covariance (ddof 1) of the final ICO weights of the ICO-successful cells
inside a frame (default |x0| <= 1.2 m, |theta0| <= 6 deg; or every successful cell), plus ridge * I.
The other actor-critic priors take the ICO mean, the ICO covariance, both or neither
(each condition's rule: icoac.core.registry; method.md, A16 and L6); the search's is N(0, I) or the
ICO prior.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from icoac.core import binding as B
from icoac.core import geometry, metrics, results
from icoac.core.config import make_prior
from icoac.core.errors import PriorError
from icoac.core.options import FRAME_NAMES, PRIOR_FRAME as DEFAULT_FRAME, PRIOR_RIDGE as DEFAULT_RIDGE
from icoac.core.options import PRIOR_STD as DEFAULT_STD
from icoac.core.plants import PRIOR_CELLS, spec as plant_spec
from icoac.core.signs import lqr_weights
from icoac.core.registry import COV_RULES, MEAN_RULES, REGISTRY

_TOL = 1e-9
CENTRAL = "central"  # parse_frame without bounds: the central frame of the prior's plant


@dataclass
class PriorInfo:
    """The prior actually used and where it came from (stored in run.json as ``prior_info``)."""
    mean: np.ndarray
    cov: np.ndarray
    frame: tuple[float, float] | None      # None: every ICO-successful cell
    n_cells: int
    ridge: float
    kind: str = "ico-rl"                   # the condition it is the prior of
    source: str | None = None
    source_commit: str | None = None
    source_seed: int | None = None
    ico_phase_simulated_time: float | None = None  # A17: total simulated time of the ICO grid (s)
    extra: dict = field(default_factory=dict)
    frame_keys: tuple[str, str] = geometry.CART_POLE.frame_keys()  # the grid's (PlantGrid.frame_keys)

    def to_dict(self) -> dict[str, Any]:
        out = {
            "kind": self.kind,
            "mean": [float(v) for v in self.mean],
            "cov": [[float(v) for v in row] for row in self.cov],
            "frame": None if self.source is None and self.n_cells == 0 else
                     "all" if self.frame is None else dict(zip(self.frame_keys, self.frame)),
            "n_cells": int(self.n_cells),
            "ridge": float(self.ridge),
            "source": self.source,
            "source_commit": self.source_commit,
            "source_seed": self.source_seed,
            "ico_phase_simulated_time": self.ico_phase_simulated_time,
        }
        out.update(self.extra)
        return out

    def prior(self) -> B.Prior:
        return make_prior(self.mean, self.cov)


def frame_mask(cells: np.ndarray, frame: tuple[float, float] | None,
               grid: geometry.PlantGrid = geometry.CART_POLE) -> np.ndarray:
    """Cells with |column value| <= frame[0] and |row value| <= frame[1] in the grid's display
    units (the cart-pole: |x0| <= frame[0] m, |theta0| <= frame[1] deg); every cell when frame is
    None."""
    if frame is None:
        return np.ones(cells.size, dtype=bool)
    half_col, half_row = frame
    return ((np.abs(grid.col_display(cells["x0"])) <= half_col + _TOL)
            & (np.abs(grid.row_display(cells["theta0"])) <= half_row + _TOL))


def parse_frame(text: str | None, x_max: float | None = None, theta_max_deg: float | None = None
                ) -> tuple[float, float] | None:
    """'central' (default, bounds overridable) or 'all' -> frame tuple, CENTRAL (no bound given:
    the central frame of whichever plant's grid the prior comes from) or None."""
    name = (text or "central").strip().lower()
    if name not in FRAME_NAMES:
        raise PriorError(f"bad prior frame {text!r}; valid: {', '.join(FRAME_NAMES)}")
    if name == "all":
        return None
    if x_max is None and theta_max_deg is None:
        return CENTRAL
    x = DEFAULT_FRAME[0] if x_max is None else float(x_max)
    th = DEFAULT_FRAME[1] if theta_max_deg is None else float(theta_max_deg)
    if not (math.isfinite(x) and math.isfinite(th) and x > 0 and th > 0):
        raise PriorError(f"prior frame bounds must be > 0, got x {x}, theta {th}")
    return (x, th)


def compute(cells: np.ndarray, frame: tuple[float, float] | str | None = DEFAULT_FRAME,
            ridge: float = DEFAULT_RIDGE, grid: geometry.PlantGrid = geometry.CART_POLE,
            use: str = PRIOR_CELLS[0]) -> PriorInfo:
    """ICO->RL prior from an ICO cell array of the plant's grid: the cells inside frame (CENTRAL:
    the grid's central frame) that ICO balanced ("successful", the paper's) or that it finished
    ("finished": balanced or failed, its weights learned either way; icoac.core.plants says which
    plant takes it), mean and sample cov + ridge*I."""
    check_prior_ridge(ridge)
    if use not in PRIOR_CELLS:
        raise PriorError(f"prior cells must be one of {', '.join(PRIOR_CELLS)}, got {use!r:.40}")
    if frame == CENTRAL:
        frame = grid.central_frame()
    taken = metrics.success_mask(cells) if use == "successful" else np.isin(cells["outcome"], (B.SUCCESS, B.FAILED))
    sel = taken & frame_mask(cells, frame, grid)
    n = int(np.count_nonzero(sel))
    where = "any cell" if frame is None else (f"|{grid.col_start()}| <= {frame[0]:g} {grid.col_unit}, "
                                              f"|{grid.row_start()}| <= {frame[1]:g} {grid.row_unit}")
    what = "ICO-successful" if use == "successful" else "ICO-finished"
    if n == 0:
        raise PriorError(f"no {what} cell in the prior frame ({where}); widen the frame or use --prior-frame all")
    if n < 2:
        raise PriorError(f"only {n} {what} cell in the prior frame ({where}); a sample covariance needs at least 2")
    w = cells["weights"][sel][:, :grid.n_inputs].astype(np.float64)
    mean = w.mean(axis=0)
    cov = np.cov(w, rowvar=False, ddof=1) + ridge * np.eye(grid.n_inputs)
    cov = 0.5 * (cov + cov.T)
    # entries that would be subnormal in the controller's reals are 0 to it on a host that
    # flushes subnormals, so the C prior check rejects them: store them as 0
    cov[np.abs(cov) < np.finfo(B.real_dtype).tiny] = 0.0
    return PriorInfo(mean=mean, cov=cov, frame=frame, n_cells=n, ridge=float(ridge),
                     extra={} if use == PRIOR_CELLS[0] else {"prior_cells": use}, frame_keys=grid.frame_keys())


# The words of a prior rule (icoac.core.registry) -> the mean (from the ICO prior) and covariance (from
# the ICO prior and sigma_w).
_MEANS = {"ico": lambda ico, n, cfg: ico.mean.copy(), "zero": lambda ico, n, cfg: np.zeros(n),
          "lqr": lambda ico, n, cfg: _lqr_mean(cfg)}
_COVS = {"ico": lambda ico, std, n: ico.cov.copy(), "isotropic": lambda ico, std, n: std ** 2 * np.eye(n),
         "identity": lambda ico, std, n: np.eye(n)}
assert tuple(_MEANS) == MEAN_RULES and tuple(_COVS) == COV_RULES


def _lqr_mean(cfg) -> np.ndarray:
    if cfg is None:
        raise PriorError("the LQR prior needs the run's configuration (its plant and task)")
    w = lqr_weights(cfg)
    if w is None:
        raise PriorError(f"plant {cfg.plant_name}: no stabilising LQR gain at the upright (or policy.gain <= 0)")
    return np.array(w)


# sigma_w of an isotropic prior: sigma_w^2 must be a covariance the controller takes (at most
# ICOAC_PRIOR_COV_MAX, and a normal float).
PRIOR_STD_RANGE = (1e-18, math.sqrt(B.constant("ICOAC_PRIOR_COV_MAX")))


def check_prior_ridge(ridge: Any, what: str = "--prior-ridge") -> float:
    """The ridge added to an ICO prior's covariance: in [0, ICOAC_PRIOR_COV_MAX] (a covariance the
    controller takes); PriorError otherwise."""
    hi = B.constant("ICOAC_PRIOR_COV_MAX")
    if isinstance(ridge, bool) or not isinstance(ridge, (int, float)) or not 0 <= ridge <= hi:
        raise PriorError(f"{what} must be a number in [0, {hi:g}], got {ridge!r:.40}")
    return float(ridge)


def check_prior_std(std: Any, what: str = "--prior-std") -> float:
    """std as a float in PRIOR_STD_RANGE; PriorError (one line) otherwise."""
    lo, hi = PRIOR_STD_RANGE
    if isinstance(std, bool) or not isinstance(std, (int, float)) or not lo <= std <= hi:
        raise PriorError(f"{what} must be a number in [{lo:g}, {hi:g}] (sigma_w^2 is the prior's variance), "
                         f"got {std!r:.40}")
    return float(std)


def condition_prior(condition: str, ico: PriorInfo | None, std: float = DEFAULT_STD,
                    n_inputs: int = B.N_INPUTS, cfg=None) -> PriorInfo:
    """The prior of a condition by its rule (icoac.core.registry) for a task of n_inputs inputs (the
    cart-pole's 4 unless given; an ICO prior of another size is refused): the
    mean and the covariance each from the ICO prior ``ico`` or not ("zero" mean, "isotropic" std^2 I,
    "identity" I), or the mean from the LQR gain of the plant of ``cfg`` (the RunConfig the condition
    runs with; "lqr"). Provenance is recorded only for what came from ICO: a prior that takes nothing
    from it carries no source."""
    rule = REGISTRY[condition].prior
    if rule is None:
        raise PriorError(f"condition {condition} has no prior")
    mean_rule, cov_rule = rule
    from_ico = rule.takes_ico
    if from_ico and ico is None:
        raise PriorError(f"condition {condition} needs an ICO prior (--prior-from ICO_RESULTS_DIR)")
    if cov_rule == "isotropic":
        check_prior_std(std)
    if ico is not None and len(ico.mean) != n_inputs:
        raise PriorError(f"condition {condition}: the ICO prior has {len(ico.mean)} weights, the task {n_inputs} inputs")
    mean, cov = _MEANS[mean_rule](ico, n_inputs, cfg), _COVS[cov_rule](ico, std, n_inputs)
    extra = {"mean_from": mean_rule, "cov_from": cov_rule}
    if cov_rule == "isotropic":
        extra["prior_std"] = float(std)
    if not from_ico:
        return PriorInfo(mean=mean, cov=cov, frame=None, n_cells=0, ridge=0.0, kind=condition, extra=extra)
    origin = {key: value for key, value in ico.extra.items() if key.startswith("source_")}
    return PriorInfo(mean=mean, cov=cov, frame=ico.frame, n_cells=ico.n_cells, ridge=ico.ridge, kind=condition,
                     source=ico.source, source_commit=ico.source_commit, source_seed=ico.source_seed,
                     ico_phase_simulated_time=ico.ico_phase_simulated_time, extra={**origin, **extra},
                     frame_keys=ico.frame_keys)


def check_origin_task(info: PriorInfo, cfg) -> None:
    """PriorError unless a prior taken from an ICO run (its ``source_task``) was learned on the
    inputs of the task ``cfg`` runs, sign for sign (task.input_sign): weights learned on other
    signs are in other coordinates."""
    task = info.extra.get("source_task")
    if not isinstance(task, dict):
        return
    n = cfg.n_inputs
    source, target = list(task.get("input_sign", [])[:n]), [int(v) for v in cfg.controller.task.input_sign[:n]]
    if source != target:
        raise PriorError(f"--prior-from: the ICO run's input signs {source} are not this task's {target} "
                         "(task.input_sign): its weights are in other coordinates")


def from_results(path: str | Path, frame: tuple[float, float] | str | None = DEFAULT_FRAME,
                 ridge: float = DEFAULT_RIDGE, plant: str | None = None) -> PriorInfo:
    """ICO->RL prior from an ICO results directory, with its provenance (its plant, condition, task
    description and learning flag: schema.PRIOR_ORIGIN) and ICO-phase simulated time. ``plant``: the plant the prior is for, which must
    be the ICO run's (None: whatever the run's is)."""
    path = Path(path)
    cells, record = results.load(path, what="--prior-from")
    if record.get("condition") != "ico":
        raise PriorError(f"--prior-from: {str(path)!r} holds condition {record.get('condition')!r}, not ico")
    if not record["config"]["controller"]["learn"]:
        raise PriorError(f"--prior-from: {str(path)!r} is a run that did not learn (learn = 0), not an ICO prior")
    if not record.get("complete", False):
        raise PriorError(f"--prior-from: {str(path)!r} is incomplete (PENDING cells); finish it with --resume")
    source_plant = results.record_plant(record)
    if plant is not None and source_plant != plant:
        raise PriorError(f"--prior-from: {str(path)!r} is an ICO run of the {source_plant}, not of the {plant}")
    plant = source_plant
    info = compute(cells, frame, ridge, geometry.of(plant), plant_spec(plant).prior_cells)
    info.source = str(path.resolve())
    info.source_commit = (record.get("git") or {}).get("commit")
    info.source_seed = record.get("seed")
    info.ico_phase_simulated_time = float(np.sum(cells["elapsed_time"]))
    info.extra = {**info.extra, "source_plant": plant, "source_condition": "ico", "source_learn": 1,
                  "source_task": record["config"]["controller"]["task"],
                  "source_cells": int(cells.size),
                  "source_success_rate": record.get("summary", {}).get("success_rate")}
    return info
