# SPDX-License-Identifier: Apache-2.0
"""The uncertainty of a bench's numbers: bootstrap intervals over cells and seeds, and the exact
McNemar test of two conditions' per-cell outcomes.

A grid's cells are read as a sample of the initial conditions of the plant's frame, and a run's
seed as a sample of its initial velocities and noise. Seeds alone understate the uncertainty: they
move the start velocities by about 1e-4 and the noise, so the seed spread of a success rate is a
fraction of a point while the cells that decide it are a few hundred. The interval of a statistic
is therefore a two-way bootstrap: each resample draws the cells with replacement (the same cells in
every seed, since a cell's seeds are not independent of each other) and the seeds with
replacement, computes the statistic per drawn seed over the drawn cells, and averages over the
drawn seeds, as the bench averages its seeds. The interval is the 2.5 and 97.5 percentiles of
BOOTSTRAP_RESAMPLES resamples drawn from a generator seeded with BOOTSTRAP_SEED, so a summary's
intervals are reproducible bit for bit. With one seed only the cells are drawn.

Paired comparisons draw the same cells and seeds for both conditions (the interval of the
difference), and test each seed's cells with McNemar's exact test: of the cells where exactly one
condition succeeds, b are A's and c are B's; under "no difference" b is Binomial(b + c, 1/2)
(scipy.stats.binomtest, two-sided). The grid's cells are not independent draws either (neighbours
share their fate), so p is read as a screen, beside the interval.
"""
from __future__ import annotations

import warnings
from typing import Any, Callable, Mapping, Sequence

import numpy as np
from scipy.stats import binomtest

BOOTSTRAP_RESAMPLES = 2000
BOOTSTRAP_SEED = 20261206
CONFIDENCE = 0.95

# A statistic of one seed: an (..., cells) array -> one value for each row of its last axis (NaN
# when undefined); it takes every seed of a block of resamples at once.
SeedStatistic = Callable[[np.ndarray], np.ndarray]
# Resamples computed at once: bounds the drawn copy to seeds x RESAMPLE_BLOCK x cells values.
RESAMPLE_BLOCK = 250


def rate(values: np.ndarray) -> np.ndarray:
    """Per row, the fraction of cells that succeeded (values: booleans)."""
    return values.mean(axis=-1)


def median_of_successes(values: np.ndarray) -> np.ndarray:
    """Per row, the median over the cells that succeeded (values: NaN for a cell that did not), as
    numpy's median of those cells: the mean of the two middle values of the sorted successes."""
    ordered = np.sort(values, axis=-1)  # NaN last
    n = np.count_nonzero(~np.isnan(values), axis=-1)[..., None]
    low = np.take_along_axis(ordered, np.maximum(n - 1, 0) // 2, axis=-1)[..., 0]
    high = np.take_along_axis(ordered, n // 2, axis=-1)[..., 0]
    return np.where(n[..., 0] > 0, (low + high) / 2.0, np.nan)


def settings() -> dict[str, Any]:
    """What a summary's intervals were computed with (recorded beside them)."""
    return {"method": "two-way percentile bootstrap over cells and seeds", "resamples": BOOTSTRAP_RESAMPLES,
            "seed": BOOTSTRAP_SEED, "confidence": CONFIDENCE}


def _resample_indices(n_seeds: int, n_cells: int) -> tuple[np.ndarray, np.ndarray]:
    """(resamples, seeds) and (resamples, cells) indices, the same for every statistic of a summary."""
    rng = np.random.default_rng(BOOTSTRAP_SEED)
    cells = rng.integers(0, n_cells, size=(BOOTSTRAP_RESAMPLES, n_cells))
    seeds = rng.integers(0, n_seeds, size=(BOOTSTRAP_RESAMPLES, n_seeds))
    if n_seeds == 1:
        seeds[:] = 0
    return seeds, cells


def _percentiles(draws: np.ndarray) -> list[float] | None:
    draws = draws[np.isfinite(draws)]
    if draws.size == 0:
        return None
    tail = 100.0 * (1.0 - CONFIDENCE) / 2.0
    lo, hi = np.percentile(draws, [tail, 100.0 - tail])
    return [float(lo), float(hi)]


def _draws(samples: Sequence[np.ndarray], statistic: SeedStatistic) -> np.ndarray:
    """Each resample's statistic (mean over the drawn seeds) for each (seeds, cells) sample, drawing
    the same cells and seeds for all; the differences of the first two when two are given."""
    shape = samples[0].shape
    if any(s.shape != shape for s in samples):
        raise ValueError(f"paired samples differ in shape: {[s.shape for s in samples]}")
    if shape[0] == 0 or shape[1] == 0:
        return np.empty(0)
    seeds, cells = _resample_indices(*shape)
    means = []
    for sample in samples:
        per_seed = np.empty((BOOTSTRAP_RESAMPLES, shape[0]))  # each resample's statistic, every seed
        for start in range(0, BOOTSTRAP_RESAMPLES, RESAMPLE_BLOCK):
            block = cells[start:start + RESAMPLE_BLOCK]
            per_seed[start:start + len(block)] = statistic(sample[:, block]).T
        drawn = np.take_along_axis(per_seed, seeds, axis=1)
        with warnings.catch_warnings():  # a resample whose drawn seeds are all undefined: NaN
            warnings.simplefilter("ignore", RuntimeWarning)
            means.append(np.nanmean(drawn, axis=1))
    return means[0] if len(means) == 1 else means[0] - means[1]


def interval(values: np.ndarray, statistic: SeedStatistic) -> list[float] | None:
    """The bootstrap interval of the mean over seeds of ``statistic`` on a (seeds, cells) array;
    None when the statistic is undefined in every resample."""
    return _percentiles(_draws([np.asarray(values)], statistic))


def difference_interval(a: np.ndarray, b: np.ndarray, statistic: SeedStatistic = rate) -> list[float] | None:
    """The bootstrap interval of statistic(a) - statistic(b) for paired (seeds, cells) arrays (the same
    cells and seeds in both)."""
    return _percentiles(_draws([np.asarray(a), np.asarray(b)], statistic))


def mcnemar(a: np.ndarray, b: np.ndarray) -> dict[str, Any]:
    """McNemar's exact test of paired success masks over the same cells: b = cells only A succeeds
    in, c = cells only B succeeds in, p two-sided (1 when no cell differs)."""
    a = np.asarray(a, dtype=bool)
    b = np.asarray(b, dtype=bool)
    if a.shape != b.shape:
        raise ValueError(f"paired masks differ in shape: {a.shape} and {b.shape}")
    only_a = int(np.count_nonzero(a & ~b))
    only_b = int(np.count_nonzero(~a & b))
    p = 1.0 if only_a + only_b == 0 else float(binomtest(only_a, only_a + only_b, 0.5).pvalue)
    return {"only_a": only_a, "only_b": only_b, "p": p}


def success(masks: Mapping[int, np.ndarray]) -> dict[str, Any]:
    """Success masks per seed ({seed: (cells,) bool}) -> the mean success over seeds, its sd over
    seeds (0 for one seed) and its bootstrap interval over cells and seeds."""
    stack = np.stack([np.asarray(masks[s], dtype=bool) for s in sorted(masks)])
    per_seed = stack.mean(axis=1)
    return {"mean": float(per_seed.mean()), "sd": float(per_seed.std(ddof=1)) if len(masks) > 1 else 0.0,
            "ci95": interval(stack, rate)}


def paired(a: Mapping[int, np.ndarray], b: Mapping[int, np.ndarray]) -> dict[str, Any]:
    """Two conditions' success masks per seed ({seed: (cells,) bool}) over the same cells -> the
    difference of their success rates in points (mean over the common seeds, its interval) and
    McNemar's test per seed, with the largest p over the seeds."""
    seeds = sorted(set(a) & set(b))
    if not seeds:
        return {"seeds": [], "points": None, "ci95": None, "mcnemar": [], "p_max": None}
    ma = np.stack([np.asarray(a[s], dtype=bool) for s in seeds])
    mb = np.stack([np.asarray(b[s], dtype=bool) for s in seeds])
    ci = difference_interval(ma, mb)
    tests = [mcnemar(x, y) for x, y in zip(ma, mb)]
    return {"seeds": seeds, "points": 100.0 * float(ma.mean() - mb.mean()),
            "ci95": None if ci is None else [100.0 * ci[0], 100.0 * ci[1]],
            "mcnemar": tests, "p_max": max(t["p"] for t in tests)}
