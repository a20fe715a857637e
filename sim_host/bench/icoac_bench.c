/* Speed benchmark: nanoseconds per closed-loop tick (controller step + plant step) on one
 * core, and grid throughput on all cores. Prints figures; asserts nothing.
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

/* Ticks of one cell run on this thread, in ns per plant step. */
static double ns_per_tick(int mode, int64_t steps, int64_t *ticks_out)
{
    icoac_config_t cfg;
    icoac_sim_plant_t plant;
    icoac_sim_run_t run;
    icoac_sim_cell_t cell;
    volatile int64_t progress[ICOAC_SIM_PROGRESS_LEN] = {0, 0, 0};
    double t0;
    double elapsed;
    icoac_config_default(&cfg);
    cfg.mode = mode;
    icoac_sim_plant_default(&plant);
    icoac_sim_run_default(&run);
    run.success_steps = steps;
    run.max_trials = 1000;
    memset(&cell, 0, sizeof cell);
    cell.x0 = -0.5;
    cell.theta0 = -4.0 * ICOAC_SIM_PI / 180.0;
    cell.seed = 7u;
    t0 = now_seconds();
    if (icoac_sim_run_cell(&cfg, &plant, &run, &balanced_prior, &cell, 0, progress) != ICOAC_SIM_OK) {
        fprintf(stderr, "icoac_bench: run_cell failed\n");
        exit(1);
    }
    elapsed = now_seconds() - t0;
    *ticks_out = progress[ICOAC_SIM_PROGRESS_STEPS];
    return 1e9 * elapsed / (double)*ticks_out;
}

int main(int argc, char **argv)
{
    const int quick = argc > 1 && strcmp(argv[1], "--quick") == 0;
    icoac_config_t cfg;
    icoac_sim_plant_t plant;
    icoac_sim_run_t run;
    icoac_sim_cell_t *grid = calloc(ICOAC_SIM_GRID_CELLS, sizeof *grid);
    volatile int64_t progress[ICOAC_SIM_PROGRESS_LEN] = {0, 0, 0};
    int64_t ticks;
    double ns;
    double t0;
    double wall;

    if (grid == 0) {
        return 1;
    }
    printf("icoac_bench: %u-byte reals, reference build (no fast-math)\n", icoac_sizeof_real());
    ns = ns_per_tick(ICOAC_MODE_ICO, quick ? 200000 : 5000000, &ticks);
    printf("ICO tick (controller + Euler plant), one core: %6.1f ns  [%lld ticks; target <= 40 ns]\n",
           ns, (long long)ticks);
    ns = ns_per_tick(ICOAC_MODE_RL, quick ? 50000 : 1000000, &ticks);
    printf("RL  tick (critic + actor + plant),  one core: %6.1f ns  [%lld ticks; target <= 300 ns]\n",
           ns, (long long)ticks);

    icoac_config_default(&cfg);
    icoac_sim_plant_default(&plant);
    icoac_sim_run_default(&run);
    run.max_trials = quick ? 200 : 2000;
    icoac_sim_paper_grid(grid, ICOAC_SIM_GRID_CELLS, 1u);
    t0 = now_seconds();
    if (icoac_sim_run_grid(&cfg, &plant, &run, 0, grid, ICOAC_SIM_GRID_CELLS, 0, 0, progress) !=
        ICOAC_SIM_OK) {
        fprintf(stderr, "icoac_bench: run_grid failed\n");
        return 1;
    }
    wall = now_seconds() - t0;
    printf("ICO grid, 1225 cells, max_trials %lld, all cores: %.2f s, %.3g ticks/s, %.3g trials/s\n",
           (long long)run.max_trials, wall, (double)progress[ICOAC_SIM_PROGRESS_STEPS] / wall,
           (double)progress[ICOAC_SIM_PROGRESS_TRIALS] / wall);
    free(grid);
    return 0;
}
