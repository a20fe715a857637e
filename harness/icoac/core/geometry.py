# SPDX-License-Identifier: Apache-2.0
"""Grids of initial conditions, defined once per plant by its C descriptor (icoac_sim_plant_grid):
row i starts the row component at rows.first + i * rows.step, column j the column component at
cols.first + j * cols.step (in degrees when the sweep says so), row-major. A cell stores the
column value as x0 and the row value as theta0, in the plant's units (radians for angles).

PlantGrid(name) is that geometry for any registry plant; the module-level names are the
cart-pole's, the paper's grid: row i is theta0 = -12 + i deg, column j is x0 = -2.4 + 0.1 j m.
"""
from __future__ import annotations

from functools import lru_cache

import numpy as np

from icoac.core import binding as B
from icoac.core.options import CART_POLE as CART_POLE_NAME

TOL = 1e-6  # plant units (m, rad): a cell coordinate must be this close to a grid point

# The quick profile's spread subset, rows x columns of the cart-pole's 25 x 49 grid: Fig. 1g's
# start (row 8, column 19) and enough central cells for a prior. Another grid takes the rows and
# columns at the same fractions of its own (PlantGrid.quick_cells).
QUICK_ROWS = (2, 8, 10, 12, 14, 22)
QUICK_COLS = (4, 19, 22, 24, 26, 44)


def _start_name(component: str) -> str:
    return f"{component}_0" if component[-1:].isdigit() else f"{component}0"


class PlantGrid:
    """The grid of a registry plant: shape, axis values and labels, (row, column) of cells, the
    interior (off the outermost rows and columns) and maps."""

    def __init__(self, plant: str):
        info = B.plant_info(plant)
        self.plant = info["name"]
        self.n_inputs = len(info["state"])  # the task's inputs: one per state component
        self.state_names = tuple(name for name, _ in info["state"])
        self.rows, self.cols = info["rows"]["count"], info["cols"]["count"]
        self.cells = self.rows * self.cols
        self.n_interior = max(self.rows - 2, 0) * max(self.cols - 2, 0)
        self._sweeps = (info["rows"], info["cols"])
        (rname, runit), (cname, cunit) = (info["state"][s["component"]] for s in self._sweeps)
        self.row_name, self.col_name = rname, cname
        # axes in display units: degrees for a sweep given in degrees
        self.row_unit = "deg" if info["rows"]["degrees"] else runit
        self.col_unit = "deg" if info["cols"]["degrees"] else cunit
        self.row_first, self.row_step = info["rows"]["first"], info["rows"]["step"]
        self.col_first, self.col_step = info["cols"]["first"], info["cols"]["step"]
        self.row_last = self.row_first + (self.rows - 1) * self.row_step
        self.col_last = self.col_first + (self.cols - 1) * self.col_step

    def _display(self, values, sweep: int) -> np.ndarray:
        v = np.asarray(values, dtype=float)
        return np.degrees(v) if self._sweeps[sweep]["degrees"] else v

    def col_display(self, x0) -> np.ndarray:
        """Cells' x0 (plant units) in the column axis' display units."""
        return self._display(x0, 1)

    def row_display(self, theta0) -> np.ndarray:
        """Cells' theta0 (plant units) in the row axis' display units."""
        return self._display(theta0, 0)

    def _internal(self, values, sweep: int) -> np.ndarray:
        v = np.asarray(values, dtype=float)
        return np.radians(v) if self._sweeps[sweep]["degrees"] else v

    def row_value(self, row):
        """The row component's start (display units) of a row."""
        return self.row_first + np.asarray(row) * self.row_step

    def col_value(self, col):
        """The column component's start (display units) of a column."""
        return self.col_first + np.asarray(col) * self.col_step

    def row_col(self, col_display, row_display) -> tuple[np.ndarray, np.ndarray]:
        """Nearest (row, column) of column and row values in display units; not range-checked."""
        rows = np.rint((np.asarray(row_display, dtype=float) - self.row_first) / self.row_step).astype(int)
        cols = np.rint((np.asarray(col_display, dtype=float) - self.col_first) / self.col_step).astype(int)
        return rows, cols

    def grid_index(self, cells: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(row, column) of each cell."""
        return self.row_col(self._display(cells["x0"], 1), self._display(cells["theta0"], 0))

    def cell_index(self, row, col):
        """Index in the full grid of (row, column)."""
        return np.asarray(row) * self.cols + np.asarray(col)

    def interior(self, rows, cols) -> np.ndarray:
        rows, cols = np.asarray(rows), np.asarray(cols)
        return (rows > 0) & (rows < self.rows - 1) & (cols > 0) & (cols < self.cols - 1)

    def interior_mask(self, cells: np.ndarray) -> np.ndarray:
        """True for the interior cells of a cell array."""
        return self.interior(*self.grid_index(cells))

    def on_grid(self, cells: np.ndarray) -> np.ndarray:
        """True for cells with finite coordinates within TOL of a grid point."""
        with np.errstate(all="ignore"):  # absurd values are found here, not warned about
            x0, th0 = cells["x0"], cells["theta0"]
            finite = np.isfinite(x0) & np.isfinite(th0)
            rows, cols = self.row_col(self._display(np.where(finite, x0, 0.0), 1),
                                      self._display(np.where(finite, th0, 0.0), 0))
            rows, cols = np.where(finite, rows, -1), np.where(finite, cols, -1)
            inside = finite & (cols >= 0) & (cols < self.cols) & (rows >= 0) & (rows < self.rows)
            return (inside & (np.abs(x0 - self._internal(self.col_value(cols), 1)) <= TOL)
                    & (np.abs(th0 - self._internal(self.row_value(rows), 0)) <= TOL))

    def to_grid(self, cells: np.ndarray, values: np.ndarray, fill: float = np.nan) -> np.ndarray:
        """Scatter per-cell values into a (rows, cols) map (both ascending)."""
        values = np.asarray(values, dtype=float)
        out = np.full((self.rows, self.cols) + values.shape[1:], fill, dtype=float)
        rows, cols = self.grid_index(cells)
        out[rows, cols] = values
        return out

    def map_extent(self) -> tuple[float, float, float, float]:
        """(left, right, bottom, top) of a map whose cells are centred on the grid points."""
        return tuple(round(v, 9) for v in (self.col_first - self.col_step / 2, self.col_last + self.col_step / 2,
                                           self.row_first - self.row_step / 2, self.row_last + self.row_step / 2))

    def col_start(self) -> str:
        """The column component's start by name: x0; a name ending in a digit gets _0 (theta1_0)."""
        return _start_name(self.col_name)

    def row_start(self) -> str:
        return _start_name(self.row_name)

    def col_label(self) -> str:
        return f"{self.col_start()} ({self.col_unit})"

    def row_label(self) -> str:
        return f"{self.row_start()} ({self.row_unit})"

    def quick_cells(self) -> list[int]:
        """The quick profile's cells on this grid (QUICK_ROWS x QUICK_COLS at the same fractions)."""
        def at(positions, n, paper_n):
            return sorted({int(np.rint(p * (n - 1) / (paper_n - 1))) for p in positions})
        paper = of(CART_POLE_NAME)
        rows, cols = at(QUICK_ROWS, self.rows, paper.rows), at(QUICK_COLS, self.cols, paper.cols)
        return [int(self.cell_index(r, c)) for r in rows for c in cols]

    def spread_cells(self) -> list[int]:
        """One cell per column, every rows-th cell in index order: spread over rows and columns
        (the cart-pole's 49 cells 0, 25, ..., 1200)."""
        return list(range(0, self.cells, self.rows))

    def subset(self, n: int) -> list[int]:
        """n cells (fewer when indices coincide) evenly spaced in index order; every cell for n = cells."""
        if n >= self.cells:
            return list(range(self.cells))
        return sorted(set(int(round(v)) for v in np.linspace(0, self.cells - 1, n)))

    def frame_keys(self) -> tuple[str, str]:
        """The names a prior's frame is recorded by: the column's and the row's start, "_deg" for an
        axis in degrees (else the value is in the component's unit): x0_abs_max, theta0_abs_max_deg."""
        return tuple(f"{start}_abs_max" + ("_deg" if sweep["degrees"] else "")
                     for start, sweep in ((self.col_start(), self._sweeps[1]), (self.row_start(), self._sweeps[0])))

    def central_frame(self) -> tuple[float, float]:
        """Half the grid's half-extent along each axis (display units): the default prior frame
        (|x0| <= 1.2 m, |theta0| <= 6 deg for the cart-pole)."""
        return (round(max(abs(self.col_first), abs(self.col_last)) / 2, 9),
                round(max(abs(self.row_first), abs(self.row_last)) / 2, 9))


@lru_cache(maxsize=None)
def of(plant: str = CART_POLE_NAME) -> PlantGrid:
    """The grid of a registry plant."""
    return PlantGrid(plant)


# The most cells of any registry plant's grid (a results file holds at most that many).
MAX_CELLS = max(of(B.plant_info(i)["name"]).cells for i in range(int(B.lib.icoac_sim_plant_count())))

# The cart-pole's, the paper's grid, under its historical names.
CART_POLE = of(CART_POLE_NAME)
THETAS = CART_POLE.rows
XS = CART_POLE.cols
CELLS = CART_POLE.cells
N_INTERIOR = CART_POLE.n_interior
THETA_FIRST_DEG = CART_POLE.row_first
THETA_STEP_DEG = CART_POLE.row_step
THETA_LAST_DEG = CART_POLE.row_last
X_FIRST = CART_POLE.col_first
X_STEP = CART_POLE.col_step
X_LAST = CART_POLE.col_last
X_TOL = TOL
theta_deg = CART_POLE.row_value
x_of = CART_POLE.col_value
row_col = CART_POLE.row_col
grid_index = CART_POLE.grid_index
cell_index = CART_POLE.cell_index
interior = CART_POLE.interior
interior_mask = CART_POLE.interior_mask
on_grid = CART_POLE.on_grid
to_grid = CART_POLE.to_grid
map_extent = CART_POLE.map_extent

