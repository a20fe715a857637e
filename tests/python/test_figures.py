# SPDX-License-Identifier: Apache-2.0
import numpy as np

from icoac.studies import figures
from icoac.core import metrics, results, store
from icoac.core.config import build_config
from icoac.core.grid import make_cells, run_grid

PNG = b"\x89PNG\r\n\x1a\n"


def test_figures_from_small_run(tmp_path):
    # Cells around Fig. 1g's start (x0 = -0.5 m, theta0 = -4 deg is row 8, column 19).
    idx = [r * 49 + c for r in (7, 8, 12) for c in (18, 19, 24)]
    cfg = build_config({"max_trials": 6000, "success_steps": 2000})
    cells = make_cells(0, idx)
    run_grid(cfg, cells, progress=False)
    store.save(tmp_path / "res", cells, cfg, condition="ico", seed=0, wall_time=0.0, threads=1, cell_indices=idx)
    cells, record = results.load(tmp_path / "res")
    paths = figures.make_figures(cells, record, tmp_path / "fig", duration=3.0)
    names = sorted(p.name for p in paths)
    assert names == ["fig1b_success_map.png", "fig1cf_weights.png", "fig1g_trajectory.png"]
    for p in paths:
        data = p.read_bytes()
        assert data[:8] == PNG and len(data) > 10_000
    # byte-stable: drawing again gives identical files
    again = figures.make_figures(cells, record, tmp_path / "fig2", duration=3.0)
    for a, b in zip(paths, again):
        assert a.read_bytes() == b.read_bytes()


def test_map_with_outline_and_bars(tmp_path):
    cells = make_cells(0)
    cells["outcome"] = 1
    cells["trials"] = np.arange(cells.size) + 1
    mask = metrics.to_grid(cells, np.abs(cells["x0"]) < 1.0, fill=0) > 0
    p = figures.plot_success_map(cells, tmp_path / "m.png", label="RL", outline=mask, frame=figures.PRIOR_FRAME)
    assert p.read_bytes()[:8] == PNG
    b = figures.plot_bars(tmp_path / "b.png", ["ICO", "RL", "ICO->RL"], [0.68, 0.3, 0.84], [0.01, 0.02, 0.01],
                          ylabel="success rate")
    assert b.read_bytes()[:8] == PNG


def test_success_title_counts_pending_cells():
    """A partial grid's map says how many cells are still pending (they are in the denominator)."""
    cells = make_cells(0, range(400))
    cells["outcome"][:22] = 1  # success
    cells["outcome"][22:100] = 2  # failed; the other 300 pending
    title = figures.success_title("ICO", metrics.summary(cells))
    assert title.startswith("ICO: success 5.5 % (400 cells, 300 still pending), interior")
    cells["outcome"][100:] = 2
    assert "pending" not in figures.success_title("ICO", metrics.summary(cells))
