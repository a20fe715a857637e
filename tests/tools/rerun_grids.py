# SPDX-License-Identifier: Apache-2.0
"""Bit-for-bit check of finished grids against the current library: a spread subset of the cells
of each condition's grid of a bench directory (seed 0) rerun from that grid's own run.json
(configuration and prior), every result field compared (weights and covariance included).

    python -m tests.tools.rerun_grids results/bench 30 ico ico-rl search ...

Exit 1 when any cell differs. It needs the bench's results (make bench), so it is a tool, not a
test; tests/python/test_reference_cells.py is the committed check.
"""
from __future__ import annotations

import sys

import numpy as np

from icoac.core import binding as B
from icoac.core import grid, results
from icoac.core.config import config_from_dict

FIELDS = ("outcome", "status", "trials", "total_steps", "last_trial_steps", "elapsed_time", "weights", "cov")


def rerun(directory: str, n_cells: int) -> tuple[int, int, dict]:
    """(identical cells, cells rerun, the grid's record)."""
    cells, record = results.load(directory)
    old = cells[np.round(np.linspace(0, cells.size - 1, n_cells)).astype(int)]
    new = old.copy()
    for f in FIELDS:
        new[f] = 0
    new["outcome"] = B.PENDING
    grid.run_grid(config_from_dict(record["config"]), new, threads=2, progress=False)
    same = np.ones(old.size, dtype=bool)
    for f in FIELDS:
        same &= (new[f].reshape(old.size, -1) == old[f].reshape(old.size, -1)).all(axis=1)
    return int(same.sum()), int(old.size), record


def main(argv: list[str]) -> int:
    root, n_cells, conditions = argv[0], int(argv[1]), argv[2:]
    ok = True
    for condition in conditions:
        same, n, record = rerun(f"{root}/{condition}/seed-0", n_cells)
        ok &= same == n
        print(f"{condition:22s} {same}/{n} cells bit-identical (grid written at "
              f"{((record.get('git') or {}).get('commit') or '?')[:7]})", flush=True)
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
