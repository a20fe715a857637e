# SPDX-License-Identifier: Apache-2.0
"""Fixed-w evaluation. A controller in mode ICO with ``learn = 0`` and a prior whose mean is w (and
covariance I, which ICO mode does not read) acts with exactly w in every cell and every trial;
nothing is updated, so a grid run of condition ``ico`` with ``learn = 0`` evaluates w. Two
protocols:

- ``first``: one trial per cell (``max_trials = 1``), the cell's first initial-velocity draw;
- ``retries``: the engine's trial loop, fresh initial velocities every trial, up to a trial cap
  (default 1000). A fixed controller can succeed on a later draw where its first trial failed.

The horizon is ``success_steps`` (default the paper's 1e5 steps = 1000 s).
"""
from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any, Mapping, Sequence

import numpy as np

from icoac.core import binding as B
from icoac.core import geometry, grid, metrics, results
from icoac.studies.conditions import run_condition
from icoac.core.config import RunConfig, build_config, make_prior, parse_sets
from icoac.core.errors import LibraryError, UsageError
from icoac.core.options import CART_POLE, CEILING_MAX_TRIALS, CEILING_PROTOCOL_CHOICES, CEILING_PROTOCOLS
from icoac.studies.ceiling.weights import as_weights, format_w, weights_key

EVALS_DIR = "evals"   # OUT/evals/<w key>_<protocol>_h<steps>/: one results directory per evaluation
# Parameters the command sets itself (--set may not change them).
RESERVED = {"mode": "ICO mode is the fixed-w evaluation", "learn": "every update is off (learn = 0)",
            "max_trials": "use --protocol and --max-trials", "success_steps": "use --success-steps"}


def check_overrides(sets: Sequence[str] | Mapping[str, Any] | None, plant: str = CART_POLE) -> dict[str, Any]:
    """--set items (or a mapping) as canonical overrides (a plant's parameters by name), refusing
    the parameters the command sets."""
    over = dict(sets) if isinstance(sets, Mapping) else parse_sets(sets or [], plant=plant)
    for name in over:
        if name in RESERVED:
            raise UsageError(f"--set {name}: set by the ceiling command ({RESERVED[name]})")
    return over


def fixed_config(w: Sequence[float], protocol: str = "first", *, max_trials: int = CEILING_MAX_TRIALS,
                 success_steps: int | None = None, overrides: Mapping[str, Any] | None = None,
                 plant: str = CART_POLE) -> RunConfig:
    """Condition ico, learn = 0, prior mean w and covariance I on the plant: the engine evaluates w.
    Protocol first: max_trials = 1; retries: max_trials as given. success_steps None: the C
    default (1e5)."""
    check_protocol(protocol)
    over = dict(check_overrides(overrides, plant))
    over["learn"] = 0
    over["max_trials"] = 1 if protocol == "first" else max_trials
    if success_steps is not None:
        over["success_steps"] = success_steps
    return build_config(over, condition="ico", prior=make_prior(as_weights(w), np.eye(len(w))),
                        plant=plant)


def check_protocol(protocol: Any) -> str:
    if protocol not in CEILING_PROTOCOLS:
        raise UsageError(f"unknown protocol {protocol!r:.40}; valid: {', '.join(CEILING_PROTOCOLS)}")
    return protocol


def protocols_of(choice: str) -> tuple[str, ...]:
    if choice not in CEILING_PROTOCOL_CHOICES:
        raise UsageError(f"--protocol {choice!r:.40}: valid: {', '.join(CEILING_PROTOCOL_CHOICES)}")
    return CEILING_PROTOCOLS if choice == "both" else (choice,)


@dataclass
class FixedWeights:
    """The 'prior' of a fixed-w evaluation as run_condition takes it (prior(), to_dict()); run.json
    records it as prior_info with kind 'fixed-w'."""
    w: tuple[float, ...]
    protocol: str

    def prior(self) -> B.Prior:
        return make_prior(self.w, np.eye(len(self.w)))

    def to_dict(self) -> dict[str, Any]:
        return {"kind": "fixed-w", "mean": list(self.w), "cov": np.eye(len(self.w)).tolist(),
                "protocol": self.protocol, "source": "python -m icoac ceiling"}


def check_weights_kept(cells: np.ndarray, w: Sequence[float]) -> None:
    """learn = 0: every finished cell ends with exactly w; anything else is a library fault."""
    done = cells["outcome"] != B.PENDING
    if not np.all(cells["weights"][done][:, :len(w)] == np.asarray(w, dtype=np.float64)):
        raise LibraryError(f"a fixed-w evaluation changed the weights {format_w(w)}: learn = 0 is not honoured; "
                           "rebuild the library")


def evaluate(w: Sequence[float], protocol: str = "first", *, seed: int = 0, cells=None,
             max_trials: int = CEILING_MAX_TRIALS, success_steps: int | None = None,
             overrides: Mapping[str, Any] | None = None, threads: int = 0, plant: str = CART_POLE) -> np.ndarray:
    """Fixed-w evaluation in memory: the cells (all, or the indices / 'a-b' string ``cells``) of
    one grid run of fixed_config. KeyboardInterrupt if cancelled."""
    cfg = fixed_config(w, protocol, max_trials=max_trials, success_steps=success_steps, overrides=overrides,
                       plant=plant)
    arr = grid.make_cells(seed, grid.parse_cell_indices(cells, geometry.of(plant).cells), plant=plant)
    res = grid.run_grid(cfg, arr, threads=threads, progress=False)
    if res.cancelled:
        raise KeyboardInterrupt
    check_weights_kept(arr, as_weights(w))
    return arr


def eval_dir(out: Path, w: Sequence[float], protocol: str, success_steps: int, max_trials: int) -> Path:
    cap = "" if protocol == "first" else str(max_trials)
    return Path(out) / EVALS_DIR / f"{weights_key(w)}_{protocol}{cap}_h{success_steps}"


def evaluate_into(out: Path, w: Sequence[float], protocol: str, *, seed: int, indices, max_trials: int,
                  success_steps: int, overrides: Mapping[str, Any], threads: int,
                  progress: bool, plant: str = CART_POLE) -> tuple[np.ndarray, dict]:
    """Fixed-w evaluation into a results directory (run_condition: checkpoints, resume of a
    matching directory); KeyboardInterrupt if interrupted (its finished cells are saved)."""
    over = dict(overrides)
    over.update(learn=0, max_trials=1 if protocol == "first" else max_trials, success_steps=success_steps)
    cells, record, cancelled = run_condition(
        condition="ico", out=out, seed=seed, threads=threads, overrides=over, cell_spec=indices,
        resume=bool(results.present(out)), progress=progress, info=FixedWeights(tuple(w), protocol),
        start_over="use another --out", plant=plant)
    if cancelled:
        raise KeyboardInterrupt
    check_weights_kept(cells, w)
    return cells, record


SUMMARY_KEYS = ("n_cells", "n_interior", "n_success", "n_success_interior", "success_rate",
                "success_rate_interior", "median_trials_to_success", "max_trials_to_success", "total_trials",
                "outcomes", "success_within")


def protocol_summary(cells: np.ndarray, record: Mapping[str, Any] | None = None,
                     root: Path | None = None, directory: Path | None = None) -> dict[str, Any]:
    s = metrics.summary(cells, geometry.of(results.record_plant(record)) if record is not None else geometry.CART_POLE)
    out = {k: s[k] for k in SUMMARY_KEYS}
    if record is not None:
        out["max_trials"] = record["config"]["run"]["max_trials"]
        out["success_steps"] = record["config"]["run"]["success_steps"]
        out["wall_time"] = record.get("wall_time")
    if directory is not None:
        out["dir"] = str(directory.relative_to(root)) if root is not None else str(directory)
    return out
