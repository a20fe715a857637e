/* SPDX-License-Identifier: Apache-2.0 */
/* Speed benchmark: nanoseconds per closed-loop tick (controller step + plant step) on one
 * core, in the engine and for one cell alone; per plant, mode and block size (lanes), on one core
 * over a spread of the plant's grid cells; and grid throughput on all cores. Prints figures, and
 * with --json FILE writes them; asserts nothing.
 * Usage: icoac_bench [--quick] [--json FILE]  */
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
 * throughput, the run's default block of cells in lockstep). */
static double ns_per_tick(int mode, int64_t steps, int n_cells, int64_t *ticks_out)
{
    icoac_config_t cfg;
    icoac_sim_model_t model;
    icoac_sim_run_t run;
    icoac_sim_cell_t cells[ICOAC_SIM_MAX_LANES];
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

static void print_tick(FILE *json, const char *name, int mode, int64_t steps, double target)
{
    int64_t ticks;
    icoac_sim_run_t run;
    double one, engine;
    icoac_sim_run_default(&run);
    one = ns_per_tick(mode, steps, 1, &ticks);
    engine = ns_per_tick(mode, steps, (int)run.lanes, &ticks);
    printf("%s tick, one core: %6.1f ns in the engine (%d cells in lockstep; target <= %.0f ns), "
           "%6.1f ns for one cell alone  [%lld ticks]\n",
           name, engine, (int)run.lanes, target, one, (long long)ticks);
    if (json != 0) {
        fprintf(json, "%s    {\"mode\": \"%s\", \"engine_ns\": %.2f, \"lanes\": %d, \"one_cell_ns\": %.2f, \"ticks\": %lld}",
                mode == ICOAC_MODE_ICO ? "" : ",\n",
                mode == ICOAC_MODE_ICO ? "ico" : "rl", engine, (int)run.lanes, one, (long long)ticks);
    }
}

/* ns per tick of one plant, mode and block size on one thread: from a fresh controller (the
 * plant's task, no prior) over every stride-th cell of the plant's grid, each capped at
 * max_trials trials of up to 1000 steps: the engine's real work, trial starts included. */
static double ns_per_grid_tick(int32_t plant, int mode, int64_t lanes, int64_t stride, int64_t max_trials,
                               int64_t *ticks_out)
{
    const icoac_sim_plant_desc_t *desc = icoac_sim_plant_info(plant);
    const int64_t n_grid = (int64_t)desc->rows.count * desc->cols.count;
    icoac_sim_cell_t *grid = calloc((size_t)n_grid, sizeof *grid);
    icoac_sim_cell_t *cells = calloc((size_t)n_grid, sizeof *cells);
    volatile int64_t progress[ICOAC_SIM_PROGRESS_LEN] = {0, 0, 0};
    icoac_config_t cfg;
    icoac_sim_model_t model;
    icoac_sim_run_t run;
    int64_t i, n = 0;
    double t0, elapsed;
    if (grid == 0 || cells == 0 || icoac_sim_plant_task(plant, 0, &cfg) != ICOAC_SIM_OK ||
        icoac_sim_model_default(&model, plant) != ICOAC_SIM_OK ||
        icoac_sim_plant_grid(plant, grid, n_grid, 1u) != ICOAC_SIM_OK) {
        fprintf(stderr, "icoac_bench: cannot set up plant %d\n", (int)plant);
        exit(1);
    }
    cfg.mode = mode;
    icoac_sim_run_default(&run);
    run.max_trials = max_trials;
    run.success_steps = 1000;
    run.lanes = lanes;
    for (i = 0; i < n_grid; i += stride) {
        cells[n++] = grid[i];
    }
    t0 = now_seconds();
    if (icoac_sim_run_grid(&cfg, &model, &run, 0, cells, n, 1, 0, progress) != ICOAC_SIM_OK) {
        fprintf(stderr, "icoac_bench: run_grid failed on plant %d\n", (int)plant);
        exit(1);
    }
    elapsed = now_seconds() - t0;
    free(grid);
    free(cells);
    *ticks_out = progress[ICOAC_SIM_PROGRESS_STEPS];
    return 1e9 * elapsed / (double)*ticks_out;
}

/* The table of every plant, mode and block size. */
static void print_lane_table(FILE *json, int quick)
{
    static const int64_t lanes[] = {1, 2, 8, 16, 64};
    static const struct {
        const char *name;
        int mode;
        int64_t max_trials;
    } modes[] = {{"ico", ICOAC_MODE_ICO, 20}, {"rl", ICOAC_MODE_RL, 3}, {"search", ICOAC_MODE_SEARCH, 10}};
    const int64_t stride = quick ? 37 : 7;
    int32_t plant;
    size_t m, l;
    int first = 1;
    printf("ns per tick on one core, by block size (the run's lanes): every %lld-th cell of each plant's grid,"
           " fresh controllers, capped trials\n%-18s %-7s", (long long)stride, "plant", "mode");
    for (l = 0; l < sizeof lanes / sizeof lanes[0]; ++l) {
        printf(" %7lld", (long long)lanes[l]);
    }
    printf("\n");
    if (json != 0) {
        fprintf(json, "  \"lanes\": [\n");
    }
    for (plant = 0; plant < icoac_sim_plant_count(); ++plant) {
        const icoac_sim_plant_desc_t *desc = icoac_sim_plant_info(plant);
        if (desc->task == 0) {
            continue;
        }
        for (m = 0; m < sizeof modes / sizeof modes[0]; ++m) {
            printf("%-18s %-7s", desc->name, modes[m].name);
            for (l = 0; l < sizeof lanes / sizeof lanes[0]; ++l) {
                int64_t ticks;
                const double ns = ns_per_grid_tick(plant, modes[m].mode, lanes[l], stride, modes[m].max_trials, &ticks);
                printf(" %7.1f", ns);
                if (json != 0) {
                    fprintf(json, "%s    {\"plant\": \"%s\", \"mode\": \"%s\", \"lanes\": %lld, \"ns_per_tick\": %.2f, "
                            "\"ticks\": %lld}", first ? "" : ",\n", desc->name, modes[m].name, (long long)lanes[l], ns,
                            (long long)ticks);
                    first = 0;
                }
            }
            printf("\n");
        }
    }
    if (json != 0) {
        fprintf(json, "\n  ],\n");
    }
}

int main(int argc, char **argv)
{
    int quick = 0;
    FILE *json = 0;
    int a;
    icoac_config_t cfg;
    icoac_sim_model_t model;
    icoac_sim_run_t run;
    const icoac_sim_plant_desc_t *cart_pole = icoac_sim_plant_info(ICOAC_SIM_CART_POLE);
    const int64_t n_cells = (int64_t)cart_pole->rows.count * cart_pole->cols.count;
    icoac_sim_cell_t *grid = calloc((size_t)n_cells, sizeof *grid);
    volatile int64_t progress[ICOAC_SIM_PROGRESS_LEN] = {0, 0, 0};
    double t0;
    double wall;

    for (a = 1; a < argc; ++a) {
        if (strcmp(argv[a], "--quick") == 0) {
            quick = 1;
        } else if (strcmp(argv[a], "--json") == 0 && a + 1 < argc) {
            json = fopen(argv[++a], "w");
            if (json == 0) {
                fprintf(stderr, "icoac_bench: cannot write %s\n", argv[a]);
                return 1;
            }
        } else {
            fprintf(stderr, "usage: icoac_bench [--quick] [--json FILE]\n");
            return 2;
        }
    }
    if (grid == 0) {
        return 1;
    }
    printf("icoac_bench: %u-byte reals, reference build (no fast-math)\n", icoac_sizeof_real());
    if (json != 0) {
        fprintf(json, "{\n  \"sizeof_real\": %u,\n  \"balanced\": [\n", icoac_sizeof_real());
    }
    print_tick(json, "ICO", ICOAC_MODE_ICO, quick ? 200000 : 5000000, 25.0);
    print_tick(json, "RL ", ICOAC_MODE_RL, quick ? 50000 : 1000000, 150.0);
    if (json != 0) {
        fprintf(json, "\n  ],\n");
    }
    print_lane_table(json, quick);

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
    if (json != 0) {
        fprintf(json, "  \"grid\": {\"cells\": %lld, \"max_trials\": %lld, \"wall_s\": %.3f, \"ticks\": %lld}\n}\n",
                (long long)n_cells, (long long)run.max_trials, wall, (long long)progress[ICOAC_SIM_PROGRESS_STEPS]);
        fclose(json);
    }
    free(grid);
    return 0;
}
