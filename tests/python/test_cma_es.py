# SPDX-License-Identifier: Apache-2.0
"""CMA-ES per cell (icoac.studies.baselines.cma_es): its start is the search control's, every cell's
result is reproducible from its seed alone, the w it records is the one that succeeded, and the
budget is the learners' trial cap."""
import numpy as np
import pytest

from icoac.core import binding as B
from icoac.core import grid
from icoac.core.config import build_config, make_prior
from icoac.core.registry import REGISTRY
from icoac.studies import conditions as C
from icoac.studies.baselines import cma_es

CAPS = {"max_trials": 40, "success_steps": 2000}
CELLS = list(range(3, 1225, 97))  # 13 cells across the cart-pole's grid


def config(plant="cart_pole", caps=CAPS):
    info = C.condition_prior("cma-es", None, None, 0.0, plant=plant)
    return build_config(caps, condition="cma-es", prior=info.prior(), plant=plant)


@pytest.fixture(scope="module")
def reference():
    cells = grid.make_cells(5, CELLS)
    run = cma_es.run_grid(config(), cells, threads=1, progress=False)
    assert not run.cancelled and run.complete
    return cells


def test_start_is_the_search_controls():
    cma, control = REGISTRY["cma-es"], REGISTRY["search-control"]
    assert cma.prior == control.prior and cma.overrides["search.cov_scale"] == control.overrides["search.cov_scale"]
    mean, sigma0, stds = cma_es.start_distribution(config())
    assert np.all(mean == 0) and sigma0 == 2.0 and np.all(stds == 1.0)
    assert config().controller.learn == 0  # the controller acts with the candidate, never updates it


def test_outcomes_and_budget(reference):
    out = reference["outcome"]
    assert set(out) <= {B.SUCCESS, B.FAILED}
    assert np.count_nonzero(out == B.SUCCESS) >= 6  # it balances most of these cells within 40 trials
    assert np.all(reference["trials"][out == B.FAILED] == CAPS["max_trials"])
    assert np.all((reference["trials"] >= 1) & (reference["trials"] <= CAPS["max_trials"]))
    ok = out == B.SUCCESS
    assert np.all(reference["last_trial_steps"][ok] == CAPS["success_steps"])
    assert np.all(reference["total_steps"] >= reference["last_trial_steps"])
    assert np.all(reference["total_steps"] <= reference["trials"] * CAPS["success_steps"])


def test_the_recorded_w_is_the_one_that_succeeded(reference):
    """Replaying the successful evaluation (its w, its start seed) as a fixed-w trial succeeds; and
    the w is one CMA-ES found, not its start."""
    trials = cma_es._Trials(config())
    for cell in reference[reference["outcome"] == B.SUCCESS]:
        seed = int(B.lib.icoac_mix_seed(int(cell["seed"]), int(cell["trials"]) - 1))
        w = cell["weights"][:4]
        again = trials.trial(float(cell["x0"]), float(cell["theta0"]), seed, w)
        assert again["outcome"] == B.SUCCESS and again["last_trial_steps"] == CAPS["success_steps"]
        assert np.array_equal(w, cma_es.real_weights(w)) and np.any(w != 0)


def test_independent_of_threads_and_of_a_resume(reference):
    cells = grid.make_cells(5, CELLS)
    cma_es.run_grid(config(), cells, threads=2, progress=False)
    assert np.array_equal(cells, reference)
    partial = reference.copy()
    grid.reset_pending(partial, np.arange(partial.size) % 2 == 1)
    partial["outcome"][1::2] = B.PENDING
    cma_es.run_grid(config(), partial, threads=2, progress=False)
    assert np.array_equal(partial, reference)


def test_cancel_keeps_finished_cells_only(reference):
    cells = grid.make_cells(5, CELLS)
    run = cma_es.run_grid(config(), cells, threads=1, progress=False, cancel_after=0.0)
    assert run.cancelled
    done = cells["outcome"] != B.PENDING
    assert np.array_equal(cells[done], reference[done])
    assert np.all(cells["trials"][~done] == 0)


def test_a_plant_of_six_inputs():
    cells = grid.make_cells(1, [0, 600, 1000], plant="double_cart_pole")
    cma_es.run_grid(config("double_cart_pole", {"max_trials": 16, "success_steps": 500}), cells, threads=1,
                    progress=False)
    assert np.all(cells["outcome"] != B.PENDING) and np.all(cells["trials"] >= 1)
    assert np.all(cells["weights"][:, 6:] == 0) and np.any(cells["weights"][:, :6] != 0)


def test_refuses_a_prior_with_covariances():
    cfg = build_config(CAPS, condition="cma-es", prior=make_prior(np.zeros(4), np.full((4, 4), 0.5) + 0.5 * np.eye(4)))
    with pytest.raises(B.ConfigError, match="diagonal"):
        cma_es.run_grid(cfg, grid.make_cells(0, [0]), threads=1, progress=False)


def test_candidates_as_the_controller_runs_them():
    w = cma_es.real_weights(np.array([1e-45, -3e7, 0.1, 2.0]))
    assert w[0] == 0 and w[1] == -cma_es.W_LIMIT and w[2] == np.float64(np.float32(0.1)) and w[3] == 2.0


def test_every_runner_of_the_condition_is_cma_es():
    """A bench stage, a condition run and a sweep all run cma-es through its own runner, never the
    engine's fixed-w evaluation of its start mean."""
    assert C.local_runner("cma-es") is cma_es.run_grid and C.local_runner("search") is grid.run_grid
