/* SPDX-License-Identifier: Apache-2.0 */
/* Speed benchmark: nanoseconds per closed-loop tick (controller step + plant step) on one
 * core, in the engine and for one cell alone, and grid throughput on all cores. Prints
 * figures; asserts nothing.
 * Usage: icoac_bench [--quick]  */
#define _POSIX_C_SOURCE 199309L
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "icoac_sim/icoac_sim.h"

static double now_seconds(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* Typical learned ICO weights of a central cell: the pole stays up, so every tick is a
 * full controller + plant tick with no trial resets. */
static const icoac_prior_t balanced_prior = {
    {0.094f, 0.066f, 0.365f, 0.080f},
    {{1e-4f, 0, 0, 0}, {0, 1e-4f, 0, 0}, {0, 0, 1e-4f, 0}, {0, 0, 0, 1e-4f}}};

/* A cell that balances for steps ticks from the bench's start. */
static void balanced_cell(icoac_sim_cell_t *cell, uint64_t seed)
{
    memset(cell, 0, sizeof *cell);
    cell->x0 = -0.5;
    cell->theta0 = -4.0 * ICOAC_SIM_PI / 180.0;
    cell->seed = seed;
}

/* ns per plant step of n_cells balanced cells: n_cells == 1 through icoac_sim_run_cell (one
 * cell alone: the latency of a tick), else icoac_sim_run_grid on one thread (the engine's
 * throughput, ICOAC_SIM_LANES cells in lockstep). */
static double ns_per_tick(int mode, int64_t steps, int n_cells, int64_t *ticks_out)
{
    icoac_config_t cfg;
    icoac_sim_model_t model;
    icoac_sim_run_t run;
    icoac_sim_cell_t cells[ICOAC_SIM_LANES];
    volatile int64_t progress[ICOAC_SIM_PROGRESS_LEN] = {0, 0, 0};
    double t0;
    double elapsed;
    int32_t status;
    int i;
    icoac_config_default(&cfg);
    cfg.mode = mode;
    (void)icoac_sim_model_default(&model, ICOAC_SIM_CART_POLE);
    icoac_sim_run_default(&run);
    run.success_steps = steps;
    run.max_trials = 1000;
    for (i = 0; i < n_cells; ++i) {
        balanced_cell(&cells[i], 7u + (uint64_t)i);
    }
    t0 = now_seconds();
    status = n_cells == 1 ? icoac_sim_run_cell(&cfg, &model, &run, &balanced_prior, &cells[0], 0, progress)
                          : icoac_sim_run_grid(&cfg, &model, &run, &balanced_prior, cells, n_cells, 1, 0, progress);
    elapsed = now_seconds() - t0;
    if (status != ICOAC_SIM_OK) {
        fprintf(stderr, "icoac_bench: %s\n", icoac_sim_status_str(status));
        exit(1);
    }
    *ticks_out = progress[ICOAC_SIM_PROGRESS_STEPS];
    return 1e9 * elapsed / (double)*ticks_out;
}

static void print_tick(const char *name, int mode, int64_t steps, double target)
{
    int64_t ticks;
    double one = ns_per_tick(mode, steps, 1, &ticks);
    double engine = ns_per_tick(mode, steps, ICOAC_SIM_LANES, &ticks);
    printf("%s tick, one core: %6.1f ns in the engine (%d cells in lockstep; target <= %.0f ns), "
           "%6.1f ns for one cell alone  [%lld ticks]\n",
           name, engine, ICOAC_SIM_LANES, target, one, (long long)ticks);
}

int main(int argc, char **argv)
{
    const int quick = argc > 1 && strcmp(argv[1], "--quick") == 0;
    icoac_config_t cfg;
    icoac_sim_model_t model;
    icoac_sim_run_t run;
    const icoac_sim_plant_desc_t *cart_pole = icoac_sim_plant_info(ICOAC_SIM_CART_POLE);
    const int64_t n_cells = (int64_t)cart_pole->rows.count * cart_pole->cols.count;
    icoac_sim_cell_t *grid = calloc((size_t)n_cells, sizeof *grid);
    volatile int64_t progress[ICOAC_SIM_PROGRESS_LEN] = {0, 0, 0};
    double t0;
    double wall;

    if (grid == 0) {
        return 1;
    }
    printf("icoac_bench: %u-byte reals, reference build (no fast-math)\n", icoac_sizeof_real());
    print_tick("ICO", ICOAC_MODE_ICO, quick ? 200000 : 5000000, 25.0);
    print_tick("RL ", ICOAC_MODE_RL, quick ? 50000 : 1000000, 150.0);

    icoac_config_default(&cfg);
    (void)icoac_sim_model_default(&model, ICOAC_SIM_CART_POLE);
    icoac_sim_run_default(&run);
    run.max_trials = quick ? 200 : 2000;
    (void)icoac_sim_plant_grid(ICOAC_SIM_CART_POLE, grid, n_cells, 1u);
    t0 = now_seconds();
    if (icoac_sim_run_grid(&cfg, &model, &run, 0, grid, n_cells, 0, 0, progress) != ICOAC_SIM_OK) {
        fprintf(stderr, "icoac_bench: run_grid failed\n");
        return 1;
    }
    wall = now_seconds() - t0;
    printf("ICO grid, %lld cells, max_trials %lld, all cores: %.2f s, %.3g ticks/s, %.3g trials/s\n",
           (long long)n_cells, (long long)run.max_trials, wall, (double)progress[ICOAC_SIM_PROGRESS_STEPS] / wall,
           (double)progress[ICOAC_SIM_PROGRESS_TRIALS] / wall);
    free(grid);
    return 0;
}
