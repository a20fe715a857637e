# SPDX-License-Identifier: Apache-2.0
"""The search for the best single w (``search``), all of it with the first protocol:

1. Starting points: the typical ICO weights - the mean final weight of the successful cells in
   the central frame of an ICO results directory (``--prior-from``, the ICO->RL prior mean), else
   options.TYPICAL_ICO_WEIGHTS - and the LQR gains of the linearised plant as weights (icoac.studies.ceiling.lqr).
2. Random search (seeded: numpy's PCG64 from (seed, 0x1C0AC)), half the remaining budget:
   alternately a global draw (magnitudes log-uniform on [1e-3, 10], all positive signs - the
   LQR pattern - with probability 1/2, else random signs) and a local draw around a random
   starting point (magnitudes times exp(0.7 N(0, 1)), each sign flipped with probability 0.1).
3. Local refinement, the rest of the budget: a pattern search from the best candidate so far,
   in rounds of 8 coordinate moves (each |w_i| times e^+step or e^-step) and 4 Gaussian moves
   (w times exp(step N(0, 1)) per component); the centre moves to the round's best if that
   improves on it, else the step halves, from 0.5 down to 1/32. A converged pattern search
   restarts from the next best starting point or random candidate, until the budget is spent
   (or every one of them has been refined: the search then stops early).

Every candidate is rounded to the controller's real type (so the w recorded is the w run), its
magnitudes clipped to [1e-4, 1e3] (starting points are kept as they are), and screened once: a
grid run at ``screen_steps`` (default 1000) steps, first protocol, scored by (cells that
succeed, total steps survived). The best ``confirm`` screened w are then run at the full horizon
(first protocol, a results directory each); the best of them (most successes, then most interior
successes, then the screening score) is the reported w, and is run under the retries protocol
too. The search is deterministic for a seed, the cells and the configuration (the engine's cells
do not depend on threads); its incumbent is at least as good as every starting point on the
screening set, by construction.
"""
from __future__ import annotations

import math
from dataclasses import asdict, dataclass, field
from typing import Any, Callable, Mapping, Sequence

import numpy as np

from icoac.core import binding as B
from icoac.core import geometry, grid, metrics
from icoac.core.config import RunConfig
from icoac.core.errors import UsageError
from icoac.core.options import TYPICAL_ICO_WEIGHTS
from icoac.studies.ceiling.fixed import check_weights_kept
from icoac.studies.ceiling.weights import as_weights, weight_name

SEARCH_STREAM = 0x1C0AC
GLOBAL_MAGNITUDES = (1e-3, 10.0)
LOCAL_SPREAD = 0.7
LOCAL_FLIP = 0.1
STEP_START, STEP_MIN = 0.5, 1.0 / 32.0
GAUSS_MOVES = 4
CLIP_MAGNITUDES = (1e-4, 1e3)
PATTERN = "pattern"   # this search's name (--optimiser)
PATTERN_PHASES = ("start", "random", "refine")


@dataclass(frozen=True)
class Screen:
    """Screening result of one w (first protocol, screen_steps): its score is (n_success, total_steps)."""
    n_success: int
    n_success_interior: int
    total_steps: int

    @property
    def key(self) -> tuple[int, int]:
        return (self.n_success, self.total_steps)


def screen_cells(w: Sequence[float], cells: np.ndarray, cfg_for: Callable[[Sequence[float]], RunConfig],
                 threads: int) -> Screen:
    """One screening run of w on a copy of ``cells`` (PENDING template cells)."""
    arr = cells.copy()
    res = grid.run_grid(cfg_for(w), arr, threads=threads, progress=False)
    if res.cancelled:
        raise KeyboardInterrupt
    check_weights_kept(arr, w)
    ok = metrics.success_mask(arr)
    inner = geometry.of(cfg_for(w).plant_name).interior_mask(arr)
    return Screen(int(ok.sum()), int((ok & inner).sum()), int(arr["total_steps"].sum()))


def rank_key(entry: Mapping[str, Any]) -> tuple[int, int]:
    """The screening score of a screened candidate: (cells that succeed, total steps survived)."""
    return (entry["n_success"], entry["total_steps"])


class BudgetSpent(Exception):
    """The candidate budget is spent."""


@dataclass
class SearchResult:
    starts: list[dict]
    trace: list[dict]       # every screened candidate in order: index, phase, label, w, score
    best: dict              # the incumbent: the best screened candidate (first of equals)
    stop: str               # "budget", or "exhausted" (every start and random candidate refined)
    refinement_steps: list[float]
    refinement_origins: list[int]   # index of the candidate each refinement started from
    optimiser: dict = field(default_factory=lambda: {"name": PATTERN})  # its name and settings
    phases: tuple[str, ...] = PATTERN_PHASES  # the phases of its trace, in order

    def ranked(self) -> list[dict]:
        """Screened candidates, best first (ties: earlier first)."""
        return sorted(self.trace, key=lambda e: (-e["n_success"], -e["total_steps"], e["index"]))


def _clip(w: np.ndarray) -> np.ndarray:
    lo, hi = CLIP_MAGNITUDES
    return np.sign(w) * np.clip(np.abs(w), lo, hi)


class Screening:
    """The screened candidates of a search: each distinct w (as the controller runs it) screened
    once by ``screen``, in order, until ``candidates`` are spent (then BudgetSpent); the incumbent is
    the best screened (first of equals)."""

    def __init__(self, screen: Callable[[tuple[float, ...]], Screen], candidates: int,
                 report: Callable[[dict, dict], None] | None = None):
        if isinstance(candidates, bool) or not isinstance(candidates, int) or candidates < 1:
            raise UsageError(f"--candidates must be an integer >= 1, got {candidates!r:.40}")
        self.screen, self.candidates, self.report = screen, candidates, report
        self.trace: list[dict] = []
        self.seen: dict[tuple[float, ...], dict] = {}
        self.best: dict | None = None

    def trial(self, w, phase: str, label: str) -> dict:
        """The screened entry of w (clipped unless a starting point); an earlier equal w's entry
        is returned without spending the budget."""
        w = as_weights(w if phase == "start" else _clip(np.asarray(w, dtype=np.float64)), "candidate")
        if w in self.seen:
            return self.seen[w]
        if len(self.trace) >= self.candidates:
            raise BudgetSpent
        s = self.screen(w)
        entry = {"index": len(self.trace), "phase": phase, "label": label, "w": list(w), **asdict(s)}
        self.trace.append(entry)
        self.seen[w] = entry
        if self.best is None or rank_key(entry) > rank_key(self.best):
            self.best = entry
        if self.report is not None:
            self.report(entry, self.best)
        return entry


def search(screen: Callable[[tuple[float, ...]], Screen], starts: Sequence[tuple[str, Sequence[float]]],
           candidates: int, seed: int, report: Callable[[dict, dict], None] | None = None) -> SearchResult:
    """The search of the module docstring: ``candidates`` distinct w are screened by ``screen``
    (starting points first), the random phase takes half of what remains, refinement the rest."""
    screening = Screening(screen, candidates, report)
    trial, trace = screening.trial, screening.trace
    rng = np.random.default_rng([int(grid.check_seed(seed)), SEARCH_STREAM])
    start_list = [(label, as_weights(w, f"starting point {label}")) for label, w in starts]
    steps: list[float] = []
    origins: list[int] = []
    stop = "exhausted"
    try:
        for label, w in start_list:
            trial(w, "start", label)
        n_random = max(0, (candidates - len(trace)) // 2)
        bases = [np.asarray(w) for _, w in start_list] or [np.asarray(TYPICAL_ICO_WEIGHTS)]
        n = len(bases[0])
        lo, hi = (math.log(v) for v in GLOBAL_MAGNITUDES)
        for k in range(n_random):
            if k % 2 == 0:
                mag = np.exp(rng.uniform(lo, hi, n))
                signs = np.ones(n) if rng.random() < 0.5 else rng.choice([-1.0, 1.0], n)
                trial(signs * mag, "random", "global")
            else:
                b = int(rng.integers(len(bases)))
                flips = np.where(rng.random(n) < LOCAL_FLIP, -1.0, 1.0)
                trial(bases[b] * flips * np.exp(LOCAL_SPREAD * rng.standard_normal(n)), "random",
                      f"near {start_list[b][0] if start_list else 'typical'}")
        origins_left = sorted(trace, key=lambda e: (-e["n_success"], -e["total_steps"], e["index"]))
        for origin in origins_left:
            origins.append(origin["index"])
            incumbent = origin
            step = STEP_START
            while step >= STEP_MIN:
                steps.append(step)
                w0 = np.asarray(incumbent["w"], dtype=np.float64)
                moves = []
                for i in range(n):
                    for sign in (1.0, -1.0):
                        w = w0.copy()
                        w[i] *= math.exp(sign * step)
                        moves.append((w, f"{weight_name(i, n)} x e^{sign * step:+g}"))
                for _ in range(GAUSS_MOVES):
                    moves.append((w0 * np.exp(step * rng.standard_normal(n)), f"gauss {step:g}"))
                round_best = incumbent
                for w, label in moves:
                    entry = trial(w, "refine", label)
                    if rank_key(entry) > rank_key(round_best):
                        round_best = entry
                if round_best is incumbent:
                    step /= 2.0
                else:
                    incumbent = round_best
    except BudgetSpent:
        stop = "budget"
    return SearchResult(starts=[{"label": label, "w": list(w)} for label, w in start_list], trace=trace,
                        best=screening.best, stop=stop, refinement_steps=steps, refinement_origins=origins)
