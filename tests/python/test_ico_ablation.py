# SPDX-License-Identifier: Apache-2.0
"""The ICO-phase ablation (icoac.tools.ico_ablation): nested random cells of the central frame, the
prior from exactly those cells, the ICO phase's cost counted, the whole frame read from the bench."""
import json
import shutil

import numpy as np
import pytest

from icoac.core import geometry, grid, metrics, results
from icoac.core.errors import PriorError
from icoac.studies import bench
from icoac.studies import prior as P
from icoac.studies.conditions import condition_prior, run_condition
from icoac.tools import ico_ablation as A

GRID = geometry.CART_POLE


def test_cells_are_nested_fixed_and_in_the_frame():
    ico = grid.make_cells(0)
    a, b = A.drawn_cells(ico, GRID, 0), A.drawn_cells(ico, GRID, 0)
    assert np.array_equal(a, b) and not np.array_equal(a, A.drawn_cells(ico, GRID, 1))
    assert sorted(a) == sorted(A.frame_cells(ico, GRID)) and len(set(a)) == a.size
    assert np.all(P.frame_mask(ico[a], GRID.central_frame(), GRID))
    assert A.frame_cells(ico, GRID).size < GRID.cells


@pytest.fixture(scope="module")
def bench_dir(ico_dir, tmp_path_factory):
    out = tmp_path_factory.mktemp("bench")
    shutil.copytree(ico_dir, bench.seed_dir(out, "ico", 0))
    info = condition_prior(A.LEARNER, bench.seed_dir(out, "ico", 0), P.CENTRAL, P.DEFAULT_RIDGE)
    profile = bench.PROFILES["quick"]
    run_condition(condition=A.LEARNER, out=bench.seed_dir(out, A.LEARNER, 0), seed=0, threads=2,
                  overrides=dict(profile["rl"]), cell_spec=profile["cells"](GRID), info=info, progress=False)
    return out


def test_the_prior_is_that_of_the_picked_cells(ico_dir):
    ico, _ = results.load(ico_dir)
    ok = np.flatnonzero(metrics.success_mask(ico))
    assert ok.size >= 2
    info = A.subset_prior(ico_dir, ok[:1], "cart_pole", P.DEFAULT_RIDGE, P.DEFAULT_STD)
    assert np.array_equal(info.mean, ico["weights"][ok[0]][:4]) and info.n_cells == 1
    assert np.array_equal(info.cov, P.DEFAULT_STD ** 2 * np.eye(4))  # the learner's reading: sigma_w^2 I
    two = A.subset_prior(ico_dir, ok[:2], "cart_pole", P.DEFAULT_RIDGE, P.DEFAULT_STD)
    assert np.allclose(two.mean, ico["weights"][ok[:2]][:, :4].mean(axis=0)) and two.n_cells == 2
    failed = np.flatnonzero(~metrics.success_mask(ico))
    if failed.size:
        with pytest.raises(PriorError, match="no ICO-successful"):
            A.subset_prior(ico_dir, failed[:1], "cart_pole", P.DEFAULT_RIDGE, P.DEFAULT_STD)


def test_end_to_end(bench_dir, tmp_path, capsys):
    out = tmp_path / "abl"
    out.mkdir()
    assert A.main(["--bench", str(bench_dir), "--out", str(out), "--profile", "quick", "--seeds", "0", "--quiet"]) == 0
    data = json.loads((out / "ablation.json").read_text())
    rows = data["rows"]
    assert list(rows) == ["1", "5", "25", "frame"]
    ico, _ = results.load(bench.seed_dir(bench_dir, "ico", 0))
    order = A.drawn_cells(ico, GRID, 0)
    assert rows["1"]["ico"]["trials"]["mean"] == ico["trials"][order[0]]
    assert rows["frame"]["ico"]["trials"]["mean"] == ico["trials"][order].sum()
    assert data["ico_grid"]["trials"]["mean"] == ico["trials"].sum()
    _, frame_record = results.load(bench.seed_dir(bench_dir, A.LEARNER, 0))
    assert rows["frame"]["success_rate"]["mean"] == frame_record["summary"]["success_rate"]
    if "success_rate" in rows["1"]:
        _, rec = results.load(out / "k-1" / "seed-0")
        assert rec["prior_info"]["source_cell_indices"] == [int(order[0])]
        assert rows["1"]["total_trials"]["mean"] == rec["summary"]["total_trials"] + ico["trials"][order[0]]
    assert "| 1 |" in (out / "summary.md").read_text()
