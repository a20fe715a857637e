# SPDX-License-Identifier: Apache-2.0
"""The bench's intervals and paired tests (icoac.core.stats), against closed forms."""
import math
import subprocess

import numpy as np
import pytest

from icoac.core import binding as B
from icoac.core import metrics, results, stats
from icoac.core.grid import make_cells
from icoac.studies import bench


def _bernoulli(p, shape, seed=1):
    return np.random.default_rng(seed).random(shape) < p


def test_rate_interval_matches_the_normal_approximation():
    """One seed of 2000 cells at 60 %: the percentile interval is within a few percent of
    p +- 1.96 sqrt(p (1 - p) / n) and contains the sample's rate."""
    success = _bernoulli(0.6, (1, 2000))
    p = success.mean()
    lo, hi = stats.interval(success, stats.rate)
    half = 1.96 * math.sqrt(p * (1 - p) / success.size)
    assert lo < p < hi
    assert (hi - lo) / 2 == pytest.approx(half, rel=0.1)


def test_cells_are_drawn_once_for_every_seed():
    """Seeds that agree on every cell add no information: five copies of one seed give the one seed's
    interval. Drawing each seed's cells on their own would narrow it by about sqrt(5)."""
    one = _bernoulli(0.3, (1, 800))
    five = np.repeat(one, 5, axis=0)
    lo1, hi1 = stats.interval(one, stats.rate)
    lo5, hi5 = stats.interval(five, stats.rate)
    assert (hi5 - lo5) == pytest.approx(hi1 - lo1, rel=0.15)


def test_seeds_that_disagree_widen_the_interval():
    """Seeds whose rates differ (cells decided independently per seed) are drawn too: the interval
    of seeds at 20 % and 80 % spans far more than one seed's cells would."""
    success = np.stack([_bernoulli(0.2, 500, 1), _bernoulli(0.8, 500, 2)])
    lo, hi = stats.interval(success, stats.rate)
    assert lo < 0.3 and hi > 0.7


def test_intervals_are_reproducible_and_recorded():
    success = _bernoulli(0.5, (3, 300))
    assert stats.interval(success, stats.rate) == stats.interval(success.copy(), stats.rate)
    assert stats.settings()["resamples"] == stats.BOOTSTRAP_RESAMPLES


def test_median_interval():
    """Trials to success 1..999 in one seed (NaN cells excluded): the median 500 lies inside an
    interval about the normal approximation's width for a median of a uniform sample."""
    trials = np.arange(1.0, 1000.0)
    trials = np.concatenate([trials, np.full(500, np.nan)])[None, :]
    lo, hi = stats.interval(trials, stats.median_of_successes)
    assert lo < 500 < hi
    assert (hi - lo) / 2 == pytest.approx(1.96 * 0.5 * 999 / math.sqrt(999), rel=0.25)
    assert stats.interval(np.full((2, 10), np.nan), stats.median_of_successes) is None


def test_statistics_take_a_block_of_resamples_at_once():
    """The statistics reduce the last axis of any array (the bootstrap passes seeds x resamples x
    cells): the success rate per row, and the median of a row's successes equal to numpy's median of
    its non-NaN values, NaN for a row without one, for odd and even counts."""
    rng = np.random.default_rng(3)
    trials = rng.integers(1, 1000, (4, 6, 9)).astype(float)
    trials[rng.random(trials.shape) < 0.4] = np.nan
    trials[0, 0] = np.nan
    medians = stats.median_of_successes(trials)
    assert medians.shape == (4, 6)
    for index in np.ndindex(4, 6):
        row = trials[index][~np.isnan(trials[index])]
        assert np.isnan(medians[index]) if row.size == 0 else medians[index] == np.median(row), index
    assert np.isnan(medians[0, 0]) and np.unique(np.count_nonzero(~np.isnan(trials), axis=-1) % 2).size == 2
    success = ~np.isnan(trials)
    assert np.array_equal(stats.rate(success), success.sum(axis=-1) / 9)


def test_difference_interval_is_paired():
    """A condition against itself differs by exactly 0 in every resample; against a copy with 30
    more successes out of 1000, by 3 points with a narrow interval (the pairing removes the
    cells' common variation)."""
    a = _bernoulli(0.5, (2, 1000))
    assert stats.difference_interval(a, a) == [0.0, 0.0]
    b = a.copy()
    for row_a, row_b in zip(a, b):
        row_b[np.flatnonzero(~row_a)[:30]] = True
    lo, hi = stats.difference_interval(b, a)
    assert 0 < lo < 0.03 < hi < 0.06
    with pytest.raises(ValueError, match="differ in shape"):
        stats.difference_interval(a, a[:, :10])


def _exact_two_sided(k, n):
    tail = sum(math.comb(n, i) for i in range(0, min(k, n - k) + 1)) / 2 ** n
    return min(1.0, 2 * tail)


@pytest.mark.parametrize("only_a,only_b", [(0, 0), (3, 0), (10, 4), (4, 10), (25, 25), (40, 12)])
def test_mcnemar_is_the_exact_binomial_test(only_a, only_b):
    both = 7
    a = np.array([True] * only_a + [False] * only_b + [True] * both + [False] * 5)
    b = np.array([False] * only_a + [True] * only_b + [True] * both + [False] * 5)
    t = stats.mcnemar(a, b)
    assert (t["only_a"], t["only_b"]) == (only_a, only_b)
    expect = 1.0 if only_a + only_b == 0 else _exact_two_sided(only_a, only_a + only_b)
    assert t["p"] == pytest.approx(expect, rel=1e-9)


def test_paired_uses_the_common_seeds():
    a = {0: _bernoulli(0.7, 400, 3), 1: _bernoulli(0.7, 400, 4), 5: _bernoulli(0.7, 400, 5)}
    b = {0: _bernoulli(0.5, 400, 6), 1: _bernoulli(0.5, 400, 7)}
    out = stats.paired(a, b)
    assert out["seeds"] == [0, 1] and len(out["mcnemar"]) == 2
    assert out["points"] == pytest.approx(100 * (np.mean([a[0], a[1]]) - np.mean([b[0], b[1]])))
    assert out["ci95"][0] < out["points"] < out["ci95"][1]
    assert out["p_max"] == max(t["p"] for t in out["mcnemar"]) and out["p_max"] < 1e-6
    assert stats.paired(a, {})["points"] is None


def _cells(success, trials):
    cells = make_cells()
    cells["outcome"] = np.where(success, B.SUCCESS, B.FAILED)
    cells["trials"] = trials
    return cells


def test_aggregate_gets_intervals_from_the_cells():
    """With the cells, each rate and median of the summary carries the interval of its cells; the
    comparison of ICO->RL against RL alone is paired cell by cell."""
    n = 1225
    rng = np.random.default_rng(0)
    cells = {c: {s: _cells(rng.random(n) < p, rng.integers(1, 100, n)) for s in (0, 1)}
             for c, p in (("ico-rl", 0.8), ("rl", 0.6))}
    recs = {c: [{"seed": s, "summary": metrics.summary(x),
                 "config": {"run": {"max_trials": 1000, "success_steps": 100000}, "plant": {"name": "cart_pole"}}}
                for s, x in by_seed.items()] for c, by_seed in cells.items()}
    agg = bench.aggregate(recs, cells)
    for c in cells:
        lo, hi = agg[c]["success_rate"]["ci95"]
        assert lo < agg[c]["success_rate"]["mean"] < hi
        assert agg[c]["success_rate_interior"]["ci95"] is not None
        assert agg[c]["median_trials_to_success"]["ci95"][0] <= agg[c]["median_trials_to_success"]["mean"]
    bench.add_comparisons(agg, cells)
    versus = agg["ico-rl"]["versus"]["rl"]
    assert versus["ci95"][0] > 10 and versus["p_max"] < 1e-10


def test_bench_outputs_do_not_make_the_tree_dirty(tmp_path):
    """`make bench` writes docs/data and docs/figures; a change there leaves the tree clean, a
    change anywhere else makes it dirty."""
    def git(*args):
        subprocess.run(["git", "-C", str(tmp_path), *args], check=True, capture_output=True)
    for path in ("src.c", "docs/data/bench.json", "docs/figures/f.png"):
        (tmp_path / path).parent.mkdir(parents=True, exist_ok=True)
        (tmp_path / path).write_text("0")
    git("init", "-q")
    git("add", ".")
    git("-c", "user.name=t", "-c", "user.email=t@t", "commit", "-qm", "x")
    assert results.git_info(tmp_path)["dirty"] is False
    (tmp_path / "docs/data/bench.json").write_text("1")
    (tmp_path / "docs/figures/f.png").write_text("1")
    assert results.git_info(tmp_path)["dirty"] is False
    (tmp_path / "src.c").write_text("1")
    assert results.git_info(tmp_path)["dirty"] is True
