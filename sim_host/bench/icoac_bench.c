/* Speed benchmark: nanoseconds per closed-loop tick (controller step + plant step) on one
 * core, and grid throughput on all cores. Prints figures; asserts nothing. */
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

/* Run cells one after another on this thread; returns ns per tick. */
static double single_core(const icoac_config_t *cfg, const icoac_sim_plant_t *plant,
                          const icoac_sim_run_t *run, icoac_sim_cell_t *cells, int n, int64_t *ticks)
{
    volatile int64_t progress[ICOAC_SIM_PROGRESS_LEN] = {0, 0, 0};
    double t0, t1;
    int i;
    t0 = now_seconds();
    for (i = 0; i < n; ++i) {
        if (icoac_sim_run_cell(cfg, plant, run, 0, &cells[i], 0, progress) != ICOAC_SIM_OK) {
            fprintf(stderr, "run_cell failed\n");
            exit(1);
        }
    }
    t1 = now_seconds();
    /* Every trial also makes one learn-only terminal tick; count plant steps only. */
    *ticks = progress[ICOAC_SIM_PROGRESS_STEPS];
    return 1e9 * (t1 - t0) / (double)*ticks;
}

int main(int argc, char **argv)
{
    icoac_config_t cfg;
    icoac_sim_plant_t plant;
    icoac_sim_run_t run;
    icoac_sim_cell_t *grid = calloc(ICOAC_SIM_GRID_CELLS, sizeof *grid);
    icoac_sim_cell_t sample[8];
    volatile int64_t progress[ICOAC_SIM_PROGRESS_LEN] = {0, 0, 0};
    int64_t ticks;
    double ns, t0, wall;
    int quick = argc > 1 && strcmp(argv[1], "--quick") == 0;
    int mode, i;
    const char *names[2] = {"ICO", "RL"};

    if (grid == 0) {
        return 1;
    }
    icoac_sim_plant_default(&plant);
    icoac_sim_run_default(&run);
    icoac_sim_paper_grid(grid, ICOAC_SIM_GRID_CELLS, 1u);
    printf("icoac_bench (real = %u-byte, reference build, no fast-math)\n", icoac_sizeof_real());
    for (mode = 0; mode < 2; ++mode) {
        icoac_config_default(&cfg);
        cfg.mode = mode;
        run.max_trials = quick ? 200 : 2000;
        run.success_steps = 100000;
        /* A fixed spread of cells across the grid: mixes long and short trials. */
        for (i = 0; i < 8; ++i) {
            sample[i] = grid[(i * 157 + 300) % ICOAC_SIM_GRID_CELLS];
        }
        ns = single_core(&cfg, &plant, &run, sample, 8, &ticks);
        printf("%-3s tick, one core: %7.1f ns per tick (controller + plant), %lld ticks\n",
               names[mode], ns, (long long)ticks);
    }
    icoac_config_default(&cfg);
    run.max_trials = quick ? 100 : 1000;
    t0 = now_seconds();
    if (icoac_sim_run_grid(&cfg, &plant, &run, 0, grid, ICOAC_SIM_GRID_CELLS, 0, 0, progress) !=
        ICOAC_SIM_OK) {
        fprintf(stderr, "run_grid failed\n");
        return 1;
    }
    wall = now_seconds() - t0;
    printf("ICO grid, all cores, max_trials %lld: %.2f s, %.3g ticks per second\n",
           (long long)run.max_trials, wall, (double)progress[ICOAC_SIM_PROGRESS_STEPS] / wall);
    free(grid);
    return 0;
}
