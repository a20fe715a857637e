"""The paper's grid of initial conditions, defined once: row i is theta0 = FIRST_DEG + i deg,
column j is x0 = X_FIRST + j * X_STEP m (icoac_sim_paper_grid, row-major over theta then x).

The counts, first values and the x step come from the C constant table; the theta step is part
of C's row definition and is read off icoac_sim_paper_grid at import, which also checks that the
index maths below reproduces every cell of the C grid.
"""
from __future__ import annotations

import math

import numpy as np

from . import _binding as B

THETAS = B.GRID_THETAS              # rows
XS = B.GRID_XS                      # columns
CELLS = B.GRID_CELLS
THETA_FIRST_DEG = B.GRID_THETA_FIRST_DEG
X_FIRST = B.GRID_X_FIRST
X_STEP = B.GRID_X_STEP
X_TOL = 1e-6                        # m, rad: a cell coordinate must be this close to a grid point

# Interior cells: every cell off the outermost rows (|theta0| = 12 deg) and columns (|x0| = 2.4 m).
N_INTERIOR = (THETAS - 2) * (XS - 2)


def _c_grid() -> np.ndarray:
    cells = np.zeros(CELLS, dtype=B.CELL_DTYPE)
    B.check_status(B.lib.icoac_sim_paper_grid(cells, cells.size, 0), "paper grid")
    return cells


_GRID = _c_grid()
THETA_STEP_DEG = float(np.rint(1e9 * np.degrees(_GRID["theta0"][XS] - _GRID["theta0"][0])) / 1e9)
THETA_LAST_DEG = THETA_FIRST_DEG + (THETAS - 1) * THETA_STEP_DEG
X_LAST = X_FIRST + (XS - 1) * X_STEP


def theta_deg(row):
    """theta0 (deg) of a row."""
    return THETA_FIRST_DEG + np.asarray(row) * THETA_STEP_DEG


def x_of(col):
    """x0 (m) of a column."""
    return X_FIRST + np.asarray(col) * X_STEP


def row_col(x0, theta0_deg) -> tuple[np.ndarray, np.ndarray]:
    """Nearest (row, column) of positions x0 (m), theta0 (deg); not range-checked."""
    rows = np.rint((np.asarray(theta0_deg, dtype=float) - THETA_FIRST_DEG) / THETA_STEP_DEG).astype(int)
    cols = np.rint((np.asarray(x0, dtype=float) - X_FIRST) / X_STEP).astype(int)
    return rows, cols


def grid_index(cells: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(row, column) of each cell in the paper grid."""
    return row_col(cells["x0"], np.degrees(cells["theta0"]))


def cell_index(row, col):
    """Index in the full paper grid of (row, column)."""
    return np.asarray(row) * XS + np.asarray(col)


def interior(rows, cols) -> np.ndarray:
    """True for interior (row, column) pairs: the outermost rows and columns excluded."""
    rows, cols = np.asarray(rows), np.asarray(cols)
    return (rows > 0) & (rows < THETAS - 1) & (cols > 0) & (cols < XS - 1)


def interior_mask(cells: np.ndarray) -> np.ndarray:
    """True for the interior cells of a cell array."""
    return interior(*grid_index(cells))


def on_grid(cells: np.ndarray) -> np.ndarray:
    """True for cells with finite coordinates within X_TOL of a paper-grid point."""
    with np.errstate(all="ignore"):  # absurd values are found here, not warned about
        x0, th0 = cells["x0"], np.degrees(cells["theta0"])
        finite = np.isfinite(x0) & np.isfinite(th0)
        rows, cols = row_col(np.where(finite, x0, X_FIRST - 10 * X_STEP), np.where(finite, th0, 0.0))
        inside = finite & (cols >= 0) & (cols < XS) & (rows >= 0) & (rows < THETAS)
        return (inside & (np.abs(x0 - x_of(cols)) <= X_TOL)
                & (np.abs(np.radians(th0) - np.radians(theta_deg(rows))) <= X_TOL))


def to_grid(cells: np.ndarray, values: np.ndarray, fill: float = np.nan) -> np.ndarray:
    """Scatter per-cell values into a (THETAS, XS) map (rows theta0 ascending, columns x0 ascending)."""
    values = np.asarray(values, dtype=float)
    out = np.full((THETAS, XS) + values.shape[1:], fill, dtype=float)
    rows, cols = grid_index(cells)
    out[rows, cols] = values
    return out


def map_extent() -> tuple[float, float, float, float]:
    """(left, right, bottom, top) of a map whose cells are centred on the grid points."""
    return tuple(round(v, 9) for v in (X_FIRST - X_STEP / 2, X_LAST + X_STEP / 2,
                                       THETA_FIRST_DEG - THETA_STEP_DEG / 2, THETA_LAST_DEG + THETA_STEP_DEG / 2))


def _check() -> None:
    rows, cols = grid_index(_GRID)
    k = np.arange(CELLS)
    if not (np.array_equal(rows, k // XS) and np.array_equal(cols, k % XS) and on_grid(_GRID).all()
            and math.isclose(THETA_STEP_DEG, round(THETA_STEP_DEG, 6))):
        raise B.LibraryError("icoac_sim_paper_grid does not follow the grid constants "
                             "(ICOAC_SIM_GRID_*); rebuild the library")


_check()
