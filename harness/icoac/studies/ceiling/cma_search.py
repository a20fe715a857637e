# SPDX-License-Identifier: Apache-2.0
"""CMA-ES as the optimiser of the best single w (``cma_search``, `ceiling --optimiser cma-es`): one w
for all the cells, on the pattern search's screening, budget and candidate space
(icoac.studies.ceiling.search):

1. The pattern search's starting points are screened first, so the incumbent is at least as good
   as each of them.
2. CMA-ES (the ``cma`` package) on w itself starts from the best of them, with
   sigma0 = SIGMA0_FRACTION x its largest |w_i| (x 1 for a zero start); the package's options are its defaults but for
   silence and its normal draws, which come from numpy's PCG64 seeded by (seed, CMA_STREAM) (the
   global numpy state is never seeded or read). A candidate is clipped and rounded as the pattern
   search's are; CMA-ES is told the screening score of the w run, as one number: cells that
   succeed first, then total steps survived (exact, since a screen's steps are at most
   ``total_steps_cap``).
3. When CMA-ES stops on its own before the budget, it restarts from the same start and sigma0,
   its draws continuing.

The budget counts distinct w, as the pattern search's does: a repeated w is told its earlier
score for free. Should CMA-ES propose MAX_REPEATS repeats in a row, the search stops (stop
"exhausted"). Deterministic for a seed, the cells and the configuration.
"""
from __future__ import annotations

from typing import Any, Callable, Sequence

import numpy as np

from icoac.core import grid
from icoac.studies.baselines.cma_es import CMA_OPTIONS
from icoac.studies.ceiling.search import BudgetSpent, Screen, Screening, SearchResult, rank_key
from icoac.studies.ceiling.weights import as_weights

CMA_ES = "cma-es"     # this search's name (--optimiser)
CMA_PHASES = ("start", "cma")
CMA_STREAM = 0xC3A1
SIGMA0_FRACTION = 0.3
MAX_REPEATS = 10_000


def fitness(entry: dict, total_steps_cap: int) -> float:
    """The screening score as CMA-ES minimises it: lexicographic in (cells that succeed, total steps)."""
    return -float(entry["n_success"] * (total_steps_cap + 1) + entry["total_steps"])


def cma_search(screen: Callable[[tuple[float, ...]], Screen], starts: Sequence[tuple[str, Sequence[float]]],
               candidates: int, seed: int, total_steps_cap: int,
               report: Callable[[dict, dict], None] | None = None) -> SearchResult:
    """The search of the module docstring: ``candidates`` distinct w screened by ``screen``, the
    starting points first, then CMA-ES from the best of them."""
    import cma
    screening = Screening(screen, candidates, report)
    rng = np.random.default_rng([int(grid.check_seed(seed)), CMA_STREAM])
    options = {**CMA_OPTIONS, "randn": lambda *shape: rng.standard_normal(shape)}
    start_list = [(label, as_weights(w, f"starting point {label}")) for label, w in starts]
    runs: list[dict[str, Any]] = []
    settings: dict[str, Any] = {"name": CMA_ES, "package": f"cma {cma.__version__}", "rng": "numpy PCG64",
                                "stream": CMA_STREAM, "sigma0_fraction": SIGMA0_FRACTION,
                                "options": {k: v for k, v in CMA_OPTIONS.items() if k != "seed"}, "runs": runs}
    stop = "exhausted"
    try:
        entries = [screening.trial(w, "start", label) for label, w in start_list]
        first = max(entries, key=lambda e: (rank_key(e), -e["index"]))
        mean0 = np.asarray(first["w"], dtype=np.float64)
        sigma0 = SIGMA0_FRACTION * (float(np.max(np.abs(mean0))) or 1.0)
        settings.update(start=first["label"], mean0=list(first["w"]), sigma0=sigma0)
        repeats = 0
        while repeats < MAX_REPEATS:
            es = cma.CMAEvolutionStrategy(mean0, sigma0, options)
            settings["popsize"] = es.popsize
            run = {"first_index": len(screening.trace), "iterations": 0, "stop": None}
            runs.append(run)
            while not es.stop() and repeats < MAX_REPEATS:
                asked = es.ask()
                scores = []
                for w in asked:
                    known = len(screening.trace)
                    entry = screening.trial(w, "cma", f"run {len(runs)} gen {es.countiter + 1}")
                    repeats = repeats + 1 if len(screening.trace) == known else 0
                    scores.append(fitness(entry, total_steps_cap))
                es.tell(asked, scores)
                run["iterations"] = es.countiter
            run["stop"] = {k: _plain(v) for k, v in es.stop().items()}
    except BudgetSpent:
        stop = "budget"
    return SearchResult(starts=[{"label": label, "w": list(w)} for label, w in start_list],
                        trace=screening.trace, best=screening.best, stop=stop, refinement_steps=[],
                        refinement_origins=[], optimiser=settings, phases=CMA_PHASES)


def _plain(value: Any) -> Any:
    """A termination value of cma as JSON takes it."""
    return float(value) if isinstance(value, (int, float, np.number)) else str(value)
