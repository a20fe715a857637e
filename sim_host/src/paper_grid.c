/* SPDX-License-Identifier: Apache-2.0 */
/* The paper's grid of initial conditions (method.md, benchmark protocol): 25 angles x 49 positions. */
#include <string.h>

#include "icoac_sim/icoac_sim.h"

int32_t icoac_sim_paper_grid(icoac_sim_cell_t *cells, int64_t n_cells, uint64_t seed)
{
    int64_t i;
    if (cells == 0 || n_cells != ICOAC_SIM_GRID_CELLS) {
        return ICOAC_SIM_ERR_BAD_ARGUMENT;
    }
    memset(cells, 0, (size_t)n_cells * sizeof *cells);
    for (i = 0; i < n_cells; ++i) {
        const int64_t row = i / ICOAC_SIM_GRID_XS;
        const int64_t col = i % ICOAC_SIM_GRID_XS;
        cells[i].theta0 = (double)(ICOAC_SIM_GRID_THETA_FIRST_DEG + row) * ICOAC_SIM_PI / 180.0;
        cells[i].x0 = ICOAC_SIM_GRID_X_FIRST + ICOAC_SIM_GRID_X_STEP * (double)col;
        cells[i].seed = icoac_mix_seed(seed, (uint64_t)i);
        cells[i].outcome = ICOAC_SIM_PENDING;
    }
    return ICOAC_SIM_OK;
}
