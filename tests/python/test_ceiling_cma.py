# SPDX-License-Identifier: Apache-2.0
"""CMA-ES as the optimiser of the best single w (icoac.studies.ceiling.cma_search, `ceiling
--optimiser cma-es`) and `--cells tuning`: determinism, the budget, the recorded w's screen, errors."""
import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from icoac.core import binding as B
from icoac.core import grid, metrics, options
from icoac.core.errors import UsageError
from icoac.studies import heldout
from icoac.studies.ceiling import cma_search as C
from icoac.studies.ceiling import command, fixed, weights
from icoac.studies.ceiling import search as S
from icoac.tools import one_w

REPO = Path(__file__).resolve().parents[2]
STARTS = [("a", (0.1, 0.1, 0.4, 0.1)), ("b", (1.0, 2.0, 1.0, 3.0))]
CAP = 10 ** 6
# A few tuning cells near the edge (some fail), short screens, two candidates confirmed.
SMALL = ["--optimiser", "cma-es", "--cells", "tuning", "--candidates", "20", "--screen-steps", "200",
         "--success-steps", "400", "--max-trials", "3", "--confirm", "2", "--protocol", "first",
         "--threads", "1", "--quiet"]


def run(*args, timeout=120):
    return subprocess.run([sys.executable, "-m", "icoac", *args], cwd=REPO, capture_output=True, text=True,
                          timeout=timeout)


def _synthetic(w):
    """A smooth score with its optimum at (0.5, 0.5, 4, 4)."""
    d = float(np.sum(np.log(np.abs(np.asarray(w)) / np.array([0.5, 0.5, 4.0, 4.0])) ** 2))
    return S.Screen(int(1000 / (1.0 + d)), 0, int(CAP / (1.0 + d)))


def test_cma_search_is_seeded_spends_the_budget_and_leaves_numpy_alone():
    state = np.random.get_state()[1].copy()
    r1 = C.cma_search(_synthetic, STARTS, 60, seed=3, total_steps_cap=CAP)
    r2 = C.cma_search(_synthetic, STARTS, 60, seed=3, total_steps_cap=CAP)
    r3 = C.cma_search(_synthetic, STARTS, 60, seed=4, total_steps_cap=CAP)
    assert np.array_equal(np.random.get_state()[1], state)  # the global numpy state is not read or seeded
    assert r1.trace == r2.trace and r1.best == r2.best and r1.trace != r3.trace
    assert len(r1.trace) == 60 and r1.stop == "budget" and len({tuple(e["w"]) for e in r1.trace}) == 60
    assert [e["phase"] for e in r1.trace] == ["start"] * 2 + ["cma"] * 58
    opt = r1.optimiser
    assert opt["name"] == "cma-es" and opt["start"] == "b" and opt["mean0"] == [1.0, 2.0, 1.0, 3.0]
    assert opt["sigma0"] == pytest.approx(C.SIGMA0_FRACTION * 3.0) and opt["popsize"] == 8
    assert all(S.rank_key(r1.best) >= S.rank_key(e) for e in r1.trace)
    assert r1.best["phase"] == "cma"  # it improved on its starts
    assert [e["label"] for e in C.cma_search(_synthetic, STARTS, 1, seed=3, total_steps_cap=CAP).trace] == ["a"]


def test_cma_search_restarts_when_it_stops_before_the_budget():
    def flat(w):
        return S.Screen(1, 1, 5)

    r = C.cma_search(flat, STARTS, 40, seed=0, total_steps_cap=CAP)
    runs = r.optimiser["runs"]
    assert len(r.trace) == 40 and r.stop == "budget" and len(runs) > 1
    assert all(run["stop"] for run in runs[:-1])  # every run but the last stopped on its own


def test_fitness_is_lexicographic():
    better_cells = {"n_success": 2, "total_steps": 0}
    more_steps = {"n_success": 1, "total_steps": CAP}
    assert C.fitness(better_cells, CAP) < C.fitness(more_steps, CAP)


@pytest.fixture(scope="module")
def small_cma(tmp_path_factory):
    root = tmp_path_factory.mktemp("cma")
    for name in ("a", "b"):
        res = run("ceiling", "--out", str(root / name), *SMALL)
        assert res.returncode == 0, res.stderr
    return [json.loads((root / name / "ceiling.json").read_text()) for name in ("a", "b")]


def test_command_is_deterministic_and_records_the_optimiser(small_cma):
    a, b = small_cma
    assert a["search"]["trace"] == b["search"]["trace"] and a["best"]["w"] == b["best"]["w"]
    assert a["settings"]["optimiser"] == "cma-es" and a["search"]["optimiser"]["name"] == "cma-es"
    assert a["search"]["screened"] == len(a["search"]["trace"]) == 20 and a["search"]["stop"] == "budget"
    assert a["search"]["phases"] == {"start": 5, "cma": 15}
    assert a["settings"]["cells"] == [int(i) for i in heldout.tuning_cells("cart_pole")]


def test_recorded_w_replays_to_its_screen(small_cma):
    record = small_cma[0]
    best = record["search"]["screen_best"]
    cells = fixed.evaluate(best["w"], "first", cells=record["settings"]["cells"], success_steps=200, threads=1)
    assert int(cells["total_steps"].sum()) == best["total_steps"]
    assert int(metrics.success_mask(cells).sum()) == best["n_success"]
    assert tuple(best["w"]) == weights.as_weights(best["w"])


def test_pattern_is_the_default_and_the_names_agree():
    assert command.OPTIMISERS == options.CEILING_OPTIMISERS and command.OPTIMISERS[0] == S.PATTERN


@pytest.mark.parametrize("args, words", [
    (["--optimiser", "bfgs"], "invalid choice"),
    (["--w", "0.1,0.1,0.3,0.1", "--optimiser", "cma-es"], "without a search"),
    (["--cells", "tuned"], "bad cell index"),
])
def test_user_errors_one_line_exit_2(tmp_path, args, words):
    out = tmp_path / "c"
    res = run("ceiling", "--out", str(out), *args)
    assert res.returncode == 2, res.stderr
    lines = res.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("icoac: error: ") and words in lines[0]
    assert not out.exists()


def test_unknown_optimiser_in_the_options_is_a_usage_error(tmp_path):
    with pytest.raises(UsageError, match="--optimiser 'bfgs': valid: pattern, cma-es"):
        command.run_ceiling(command.CeilingOptions(out=tmp_path / "c", optimiser="bfgs"))
    assert not (tmp_path / "c").exists()


def test_one_w_splits_an_all_cells_evaluation_by_the_heldout_mask():
    cells = grid.make_cells(0)
    held = heldout.heldout_mask("cart_pole")
    cells["outcome"] = np.where(np.arange(cells.size) % 2 == 0, B.SUCCESS, B.FAILED)
    s = one_w.split_success(cells, "cart_pole")
    even = np.arange(held.size) % 2 == 0
    assert s["tuning"] == {"n_success": int((even & ~held).sum()), "n_cells": 368,
                           "success_rate": int((even & ~held).sum()) / 368}
    assert s["heldout"]["n_cells"] == 857 and s["heldout"]["n_success"] == int((even & held).sum())
    assert s["all"]["n_success"] == 613 and s["all"]["n_cells"] == 1225
    with pytest.raises(Exception, match="all-cells"):
        one_w.split_success(cells[:10], "cart_pole")
    args = one_w.ceiling_args("cart_pole", Path("o"), 0, 1, w=(0.5, 1.0, 2.0, 3.0))
    assert args[-2:] == ["--w", "0.5,1.0,2.0,3.0"]
    assert one_w.ceiling_args("cart_pole", Path("o"), 0, 1, "cma-es")[-4:] == ["--optimiser", "cma-es", "--cells", "tuning"]
