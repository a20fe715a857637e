# SPDX-License-Identifier: Apache-2.0
import numpy as np
import pytest

from icoac.core import binding as B
from icoac.core import metrics
from icoac.core.grid import plant_grid


def hand_cells():
    cells = plant_grid("cart_pole", 0)
    cells["outcome"] = B.FAILED
    cells["trials"] = 100
    cells["total_steps"] = 1000
    # successes: two interior cells and one edge cell (theta0 = -12 deg row, index 5)
    spec = {5: (10, 5000), 12 * 49 + 24: (3, 3000), 600: (50, 9000)}
    for i, (trials, steps) in spec.items():
        cells["outcome"][i] = B.SUCCESS
        cells["trials"][i] = trials
        cells["total_steps"][i] = steps
        cells["weights"][i, :4] = [0.1, 0.2, 0.3, 0.4]
    cells["elapsed_time"] = 0.01 * cells["total_steps"]
    return cells


def test_summary_exact():
    s = metrics.summary(hand_cells())
    assert s["n_cells"] == 1225 and s["n_interior"] == 23 * 47 == 1081
    assert s["n_success"] == 3 and s["n_success_interior"] == 2
    assert s["success_rate"] == pytest.approx(3 / 1225)
    assert s["success_rate_interior"] == pytest.approx(2 / 1081)
    assert s["median_trials_to_success"] == 10.0
    assert s["max_trials_to_success"] == 50
    assert s["mean_elapsed_time_success"] == pytest.approx((50 + 30 + 90) / 3)
    assert s["outcomes"] == {"pending": 0, "success": 3, "failed": 1222, "error": 0}
    assert s["mean_weights_success"] == pytest.approx([0.1, 0.2, 0.3, 0.4])


def test_interior_mask():
    cells = plant_grid("cart_pole", 0)
    m = metrics.interior_mask(cells)
    grid = m.reshape(25, 49)
    assert m.sum() == 1081
    assert not grid[0].any() and not grid[-1].any() and not grid[:, 0].any() and not grid[:, -1].any()
    assert grid[1:-1, 1:-1].all()


def test_trials_and_grid_maps():
    cells = hand_cells()
    t = metrics.trials_to_success(cells)
    assert np.isnan(t).sum() == 1222 and t[5] == 10 and t[600] == 50
    g = metrics.to_grid(cells, t)
    assert g.shape == (25, 49) and g[0, 5] == 10 and g[12, 24] == 3 and np.isnan(g[0, 0])
    w = metrics.weights(cells, successful_only=True)
    assert np.isnan(w[0]).all() and list(w[5]) == [0.1, 0.2, 0.3, 0.4]
    wg = metrics.to_grid(cells, w)
    assert wg.shape == (25, 49, 4)


def test_empty_success():
    cells = plant_grid("cart_pole", 0)
    cells["outcome"] = B.FAILED
    s = metrics.summary(cells)
    assert s["success_rate"] == 0.0 and s["median_trials_to_success"] is None
    assert s["mean_elapsed_time_success"] is None
