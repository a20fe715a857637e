/* SPDX-License-Identifier: Apache-2.0 */
/* Host engine: determinism of cells and grids, thread-count independence, the lanes of a
 * thread, cancellation and resume, argument checks, cell accounting, trajectory recorder. */
#define _POSIX_C_SOURCE 199309L /* nanosleep */
#include "test_common.h"

#include <pthread.h>
#include <time.h>

#include "test_sim_common.h"

static icoac_sim_cell_t make_cell(double x0, double theta0, uint64_t seed)
{
    icoac_sim_cell_t c;
    memset(&c, 0, sizeof c);
    c.x0 = x0;
    c.theta0 = theta0;
    c.seed = seed;
    c.outcome = ICOAC_SIM_PENDING;
    return c;
}

static void check_accounting(const icoac_sim_cell_t *c, const icoac_sim_run_t *run)
{
    TEST_ASSERT_TRUE(c->outcome == ICOAC_SIM_SUCCESS || c->outcome == ICOAC_SIM_FAILED);
    TEST_ASSERT_EQUAL_INT(ICOAC_SIM_OK, c->status);
    TEST_ASSERT_TRUE(c->trials >= 1 && c->trials <= run->max_trials);
    TEST_ASSERT_TRUE(c->total_steps >= c->trials);
    TEST_ASSERT_TRUE(c->last_trial_steps >= 1 && c->last_trial_steps <= c->total_steps);
    assert_close(c->elapsed_time, 0.01 * (double)c->total_steps, 1e-9);
    if (c->outcome == ICOAC_SIM_SUCCESS) {
        TEST_ASSERT_EQUAL_INT64(run->success_steps, c->last_trial_steps);
    } else {
        TEST_ASSERT_EQUAL_INT64(run->max_trials, c->trials);
        TEST_ASSERT_TRUE(c->last_trial_steps <= run->success_steps); /* = when it fell at the last step */
    }
}

static void test_run_cell_deterministic(void)
{
    const icoac_sim_model_t model = test_cart_pole();
    const icoac_sim_run_t run = test_small_run(15, 1500);
    int mode;
    for (mode = ICOAC_MODE_ICO; mode <= ICOAC_MODE_RL; ++mode) {
        icoac_config_t cfg = test_default_config();
        icoac_sim_cell_t a = make_cell(-1.5, DEG(-7.0), 123u);
        icoac_sim_cell_t b = a;
        icoac_sim_cell_t c = make_cell(-1.5, DEG(-7.0), 124u);
        cfg.mode = mode;
        TEST_ASSERT_EQUAL_INT(ICOAC_SIM_OK, icoac_sim_run_cell(&cfg, &model, &run, NULL, &a, NULL, NULL));
        TEST_ASSERT_EQUAL_INT(ICOAC_SIM_OK, icoac_sim_run_cell(&cfg, &model, &run, NULL, &b, NULL, NULL));
        TEST_ASSERT_EQUAL_MEMORY(&b, &a, sizeof a);
        check_accounting(&a, &run);
        /* a different seed changes the run (velocities, exploration noise) */
        TEST_ASSERT_EQUAL_INT(ICOAC_SIM_OK, icoac_sim_run_cell(&cfg, &model, &run, NULL, &c, NULL, NULL));
        TEST_ASSERT_TRUE(memcmp(a.weights, c.weights, sizeof a.weights) != 0 || a.total_steps != c.total_steps);
    }
}

static void test_run_cell_outcomes(void)
{
    const icoac_sim_model_t model = test_cart_pole();
    icoac_config_t cfg = test_default_config();
    icoac_sim_run_t run = test_small_run(5, 1);
    icoac_sim_cell_t c = make_cell(0.0, 0.0, 1u);
    int64_t progress[ICOAC_SIM_PROGRESS_LEN] = {0, 0, 0};
    /* one step from the upright cannot fail: success in the first trial */
    TEST_ASSERT_EQUAL_INT(ICOAC_SIM_OK, icoac_sim_run_cell(&cfg, &model, &run, NULL, &c, NULL, progress));
    TEST_ASSERT_EQUAL_INT(ICOAC_SIM_SUCCESS, c.outcome);
    TEST_ASSERT_EQUAL_INT64(1, c.trials);
    TEST_ASSERT_EQUAL_INT64(1, c.total_steps);
    TEST_ASSERT_EQUAL_INT64(1, progress[ICOAC_SIM_PROGRESS_CELLS]);
    TEST_ASSERT_EQUAL_INT64(1, progress[ICOAC_SIM_PROGRESS_TRIALS]);
    TEST_ASSERT_EQUAL_INT64(1, progress[ICOAC_SIM_PROGRESS_STEPS]);
    check_accounting(&c, &run);
    /* leaning 11.9 deg with w = 0 and the 1 N reflex: every trial falls */
    run = test_small_run(4, 100000);
    c = make_cell(0.0, DEG(11.9), 1u);
    TEST_ASSERT_EQUAL_INT(ICOAC_SIM_OK, icoac_sim_run_cell(&cfg, &model, &run, NULL, &c, NULL, NULL));
    TEST_ASSERT_EQUAL_INT(ICOAC_SIM_FAILED, c.outcome);
    TEST_ASSERT_EQUAL_INT64(4, c.trials);
    check_accounting(&c, &run);
    /* it learned something: the first tick of the run entered the zone */
    TEST_ASSERT_TRUE(c.weights[2] > 0.0);
}

/* A controller that faults numerically mid-run (the largest accepted prior covariance,
 * inflated by forgetting in the directions the observations inform least: the posterior
 * reading, the one forgetting belongs to, as in the literal configuration) ends its cell as
 * ERROR with ICOAC_ERR_NUMERIC and finite recorded weights; such cells used to end SUCCESS or
 * FAILED with NaN weights. */
static void test_numeric_fault_marks_cell_error(void)
{
    const icoac_sim_model_t model = test_cart_pole();
    icoac_config_t cfg = test_default_config();
    icoac_sim_run_t run = test_small_run(50, 5000);
    icoac_sim_cell_t cells[2];
    const icoac_prior_t prior = test_prior(0.1, 0.1, 0.5, 0.1, (double)ICOAC_PRIOR_COV_MAX);
    int i, j, k;
    cfg.mode = ICOAC_MODE_RL;
    test_literal_reading(&cfg);
    cfg.actor.forgetting = ICOAC_FORGETTING_MIN;
    cells[0] = make_cell(0.0, 0.0, 1u);
    cells[1] = make_cell(0.5, DEG(1.0), 2u);
    TEST_ASSERT_EQUAL_INT(ICOAC_SIM_OK, icoac_sim_run_grid(&cfg, &model, &run, &prior, cells, 2, 1, NULL, NULL));
    for (k = 0; k < 2; ++k) {
        TEST_ASSERT_EQUAL_INT(ICOAC_SIM_ERROR, cells[k].outcome);
        TEST_ASSERT_EQUAL_INT(ICOAC_ERR_NUMERIC, cells[k].status);
        for (i = 0; i < ICOAC_CARTPOLE_INPUTS; ++i) {
            TEST_ASSERT_TRUE(isfinite(cells[k].weights[i]));
            for (j = 0; j < ICOAC_CARTPOLE_INPUTS; ++j) {
                TEST_ASSERT_TRUE(isfinite(cells[k].cov[i][j]));
            }
        }
    }
}

/* Success is success_steps steps without a failure: a trial that fails at its last step has
 * failed (it used to count as a success). A fixed controller (w = 0, no learning) and no
 * initial-velocity noise make every trial the same, falling at step n. */
static void test_failure_at_the_last_step(void)
{
    const icoac_sim_model_t model = test_cart_pole();
    icoac_config_t cfg = test_default_config();
    icoac_sim_run_t run = test_small_run(1, 100000);
    icoac_sim_cell_t c = make_cell(0.0, DEG(11.9), 1u);
    int64_t n;
    cfg.learn = 0;
    run.init_velocity_noise = 0.0;
    TEST_ASSERT_EQUAL_INT(ICOAC_SIM_OK, icoac_sim_run_cell(&cfg, &model, &run, NULL, &c, NULL, NULL));
    TEST_ASSERT_EQUAL_INT(ICOAC_SIM_FAILED, c.outcome);
    n = c.last_trial_steps;
    TEST_ASSERT_TRUE(n > 1 && n < 1000);
    run = test_small_run(2, n);
    c = make_cell(0.0, DEG(11.9), 1u);
    TEST_ASSERT_EQUAL_INT(ICOAC_SIM_OK, icoac_sim_run_cell(&cfg, &model, &run, NULL, &c, NULL, NULL));
    TEST_ASSERT_EQUAL_INT(ICOAC_SIM_FAILED, c.outcome);
    TEST_ASSERT_EQUAL_INT64(2, c.trials);
    TEST_ASSERT_EQUAL_INT64(n, c.last_trial_steps);
    check_accounting(&c, &run);
    run = test_small_run(2, n - 1);
    c = make_cell(0.0, DEG(11.9), 1u);
    TEST_ASSERT_EQUAL_INT(ICOAC_SIM_OK, icoac_sim_run_cell(&cfg, &model, &run, NULL, &c, NULL, NULL));
    TEST_ASSERT_EQUAL_INT(ICOAC_SIM_SUCCESS, c.outcome);
    TEST_ASSERT_EQUAL_INT64(1, c.trials);
    check_accounting(&c, &run);
}

static void run_grid_ok(const icoac_config_t *cfg, icoac_sim_cell_t *cells, int64_t n, int32_t threads,
                        int64_t progress[ICOAC_SIM_PROGRESS_LEN])
{
    const icoac_sim_model_t model = test_cart_pole();
    const icoac_sim_run_t run = test_small_run(10, 1000);
    TEST_ASSERT_EQUAL_INT(ICOAC_SIM_OK, icoac_sim_run_grid(cfg, &model, &run, NULL, cells, n, threads, NULL, progress));
}

#define NSUB 8

static void subset(icoac_sim_cell_t out[NSUB])
{
    static icoac_sim_cell_t grid[TEST_PAPER_CELLS];
    static const int pick[NSUB] = {0, 100, 333, 600, 612, 777, 1000, 1224};
    int i;
    TEST_ASSERT_EQUAL_INT(ICOAC_SIM_OK, icoac_sim_plant_grid(ICOAC_SIM_CART_POLE, grid, TEST_PAPER_CELLS, 2010u));
    for (i = 0; i < NSUB; ++i) {
        out[i] = grid[pick[i]];
    }
}

static void test_grid_thread_independent(void)
{
    icoac_sim_cell_t one[NSUB], two[NSUB], solo[NSUB];
    int64_t p1[ICOAC_SIM_PROGRESS_LEN] = {0, 0, 0}, p2[ICOAC_SIM_PROGRESS_LEN] = {0, 0, 0};
    const icoac_sim_model_t model = test_cart_pole();
    const icoac_sim_run_t run = test_small_run(10, 1000);
    int mode, i;
    for (mode = ICOAC_MODE_ICO; mode <= ICOAC_MODE_RL; ++mode) {
        icoac_config_t cfg = test_default_config();
        int64_t trials = 0, steps = 0;
        cfg.mode = mode;
        subset(one);
        subset(two);
        subset(solo);
        memset(p1, 0, sizeof p1);
        memset(p2, 0, sizeof p2);
        run_grid_ok(&cfg, one, NSUB, 1, p1);
        run_grid_ok(&cfg, two, NSUB, 2, p2);
        TEST_ASSERT_EQUAL_MEMORY(two, one, sizeof one);
        TEST_ASSERT_EQUAL_MEMORY(p2, p1, sizeof p1);
        for (i = 0; i < NSUB; ++i) {
            /* a grid cell is the same independent run as icoac_sim_run_cell */
            TEST_ASSERT_EQUAL_INT(ICOAC_SIM_OK, icoac_sim_run_cell(&cfg, &model, &run, NULL, &solo[i], NULL, NULL));
            check_accounting(&one[i], &run);
            trials += one[i].trials;
            steps += one[i].total_steps;
        }
        TEST_ASSERT_EQUAL_MEMORY(solo, one, sizeof one);
        TEST_ASSERT_EQUAL_INT64(NSUB, p1[ICOAC_SIM_PROGRESS_CELLS]);
        TEST_ASSERT_EQUAL_INT64(trials, p1[ICOAC_SIM_PROGRESS_TRIALS]);
        TEST_ASSERT_EQUAL_INT64(steps, p1[ICOAC_SIM_PROGRESS_STEPS]);
    }
}

/* The lanes of a worker thread (the run's `lanes` cells in lockstep, a lane refilled as its cell
 * ends): every mode, cells of very different lengths (one-trial successes next to cells that
 * run out of trials), a finished cell mixed in, an odd count, 1 to 3 threads, and blocks of 1, 3,
 * 16 (the default: more than twice as many cells, so lanes are refilled and rest at the end) and
 * 64 lanes (more lanes than cells). Each cell equals its run alone through icoac_sim_run_cell. */
static void test_lanes_match_single_cells(void)
{
#define NLANE 37
    static const int listed[11] = {612, 0, 1224, 600, 24, 611, 613, 100, 1000, 587, 637};
    int pick[NLANE];
    static icoac_sim_cell_t grid[TEST_PAPER_CELLS];
    const icoac_sim_model_t model = test_cart_pole();
    const icoac_sim_run_t run = test_small_run(40, 600);
    const icoac_prior_t prior = test_prior(0.094, 0.066, 0.365, 0.080, 1e-3);
    icoac_sim_cell_t solo[NLANE], cells[NLANE];
    int mode, threads, i;
    TEST_ASSERT_EQUAL_INT(ICOAC_SIM_OK, icoac_sim_plant_grid(ICOAC_SIM_CART_POLE, grid, TEST_PAPER_CELLS, 99u));
    for (i = 0; i < NLANE; ++i) {
        pick[i] = i < 11 ? listed[i] : (i * 97 + 13) % TEST_PAPER_CELLS; /* the rest spread over the grid */
    }
    for (mode = ICOAC_MODE_ICO; mode <= ICOAC_MODE_SEARCH; ++mode) {
        icoac_config_t cfg = test_default_config();
        int64_t short_cells = 0, long_cells = 0; /* <= 10 trials, all max_trials */
        cfg.mode = mode;
        for (i = 0; i < NLANE; ++i) {
            solo[i] = grid[pick[i]];
            if (i == 4) {
                solo[i].outcome = ICOAC_SIM_SUCCESS; /* finished before: skipped */
                solo[i].trials = -3;
                continue;
            }
            TEST_ASSERT_EQUAL_INT(ICOAC_SIM_OK, icoac_sim_run_cell(&cfg, &model, &run, &prior, &solo[i], NULL, NULL));
            short_cells += solo[i].trials <= 10;
            long_cells += solo[i].trials == run.max_trials;
        }
        TEST_ASSERT_TRUE(short_cells > 0 && long_cells > 0); /* the lanes do end at different times */
        for (threads = 1; threads <= 3; ++threads) {
            static const int64_t block[4] = {1, 3, 16, ICOAC_SIM_MAX_LANES};
            int b;
            for (b = 0; b < 4; ++b) {
                int64_t progress[ICOAC_SIM_PROGRESS_LEN] = {0, 0, 0};
                icoac_sim_run_t lanes_run = run;
                lanes_run.lanes = block[b];
                memcpy(cells, solo, sizeof cells);
                for (i = 0; i < NLANE; ++i) {
                    if (i != 4) {
                        cells[i] = grid[pick[i]];
                    }
                }
                TEST_ASSERT_EQUAL_INT(ICOAC_SIM_OK, icoac_sim_run_grid(&cfg, &model, &lanes_run, &prior, cells, NLANE,
                                                                       threads, NULL, progress));
                TEST_ASSERT_EQUAL_MEMORY(solo, cells, sizeof cells);
                TEST_ASSERT_EQUAL_INT64(NLANE - 1, progress[ICOAC_SIM_PROGRESS_CELLS]);
            }
        }
    }
#undef NLANE
}

typedef struct {
    volatile int32_t *cancel;
    volatile int64_t *progress;
    int64_t after_trials;
} canceller_t;

static void *cancel_later(void *arg)
{
    canceller_t *c = (canceller_t *)arg;
    const struct timespec pause = {0, 100000};
    while (__atomic_load_n(&c->progress[ICOAC_SIM_PROGRESS_TRIALS], __ATOMIC_RELAXED) < c->after_trials) {
        nanosleep(&pause, NULL);
    }
    __atomic_store_n(c->cancel, 1, __ATOMIC_RELAXED);
    return NULL;
}

/* A cancel that arrives while lanes are mid-cell: every cell is either finished and equal to
 * its uncancelled result, or still PENDING and untouched; a second call completes the grid. */
static void test_cancel_mid_run(void)
{
    icoac_config_t cfg = test_default_config();
    const icoac_sim_model_t model = test_cart_pole();
    const icoac_sim_run_t run = test_small_run(300, 1000);
    icoac_sim_cell_t cells[NSUB], reference[NSUB], before[NSUB];
    volatile int64_t progress[ICOAC_SIM_PROGRESS_LEN] = {0, 0, 0};
    volatile int32_t cancel = 0;
    canceller_t canceller;
    pthread_t thread;
    int i, pending = 0;
    cfg.mode = ICOAC_MODE_RL;
    subset(reference);
    TEST_ASSERT_EQUAL_INT(ICOAC_SIM_OK, icoac_sim_run_grid(&cfg, &model, &run, NULL, reference, NSUB, 1, NULL, NULL));
    subset(cells);
    memcpy(before, cells, sizeof cells);
    canceller.cancel = &cancel;
    canceller.progress = progress;
    canceller.after_trials = 200;
    TEST_ASSERT_EQUAL_INT(0, pthread_create(&thread, NULL, cancel_later, &canceller));
    TEST_ASSERT_EQUAL_INT(ICOAC_SIM_CANCELLED,
                          icoac_sim_run_grid(&cfg, &model, &run, NULL, cells, NSUB, 1, &cancel, progress));
    TEST_ASSERT_EQUAL_INT(0, pthread_join(thread, NULL));
    for (i = 0; i < NSUB; ++i) {
        if (cells[i].outcome == ICOAC_SIM_PENDING) {
            TEST_ASSERT_EQUAL_MEMORY(&before[i], &cells[i], sizeof cells[i]);
            ++pending;
        } else {
            TEST_ASSERT_EQUAL_MEMORY(&reference[i], &cells[i], sizeof cells[i]);
        }
    }
    TEST_ASSERT_TRUE(pending > 0);
    cancel = 0;
    TEST_ASSERT_EQUAL_INT(ICOAC_SIM_OK, icoac_sim_run_grid(&cfg, &model, &run, NULL, cells, NSUB, 1, &cancel, NULL));
    TEST_ASSERT_EQUAL_MEMORY(reference, cells, sizeof cells);
}

static void test_cancel_and_resume(void)
{
    icoac_config_t cfg = test_default_config();
    const icoac_sim_model_t model = test_cart_pole();
    const icoac_sim_run_t run = test_small_run(10, 1000);
    icoac_sim_cell_t cells[NSUB], reference[NSUB], before[NSUB];
    int64_t progress[ICOAC_SIM_PROGRESS_LEN] = {0, 0, 0};
    volatile int32_t cancel = 1;
    int i;
    subset(reference);
    run_grid_ok(&cfg, reference, NSUB, 1, NULL);
    subset(cells);
    memcpy(before, cells, sizeof cells);
    TEST_ASSERT_EQUAL_INT(ICOAC_SIM_CANCELLED,
                          icoac_sim_run_grid(&cfg, &model, &run, NULL, cells, NSUB, 2, &cancel, progress));
    for (i = 0; i < NSUB; ++i) {
        TEST_ASSERT_EQUAL_INT(ICOAC_SIM_PENDING, cells[i].outcome);
    }
    TEST_ASSERT_EQUAL_MEMORY(before, cells, sizeof cells);
    TEST_ASSERT_EQUAL_INT64(0, progress[ICOAC_SIM_PROGRESS_CELLS]);
    /* single cell too */
    TEST_ASSERT_EQUAL_INT(ICOAC_SIM_CANCELLED, icoac_sim_run_cell(&cfg, &model, &run, NULL, &cells[0], &cancel, NULL));
    TEST_ASSERT_EQUAL_INT(ICOAC_SIM_PENDING, cells[0].outcome);
    /* resume: lower the flag, call again */
    cancel = 0;
    TEST_ASSERT_EQUAL_INT(ICOAC_SIM_OK, icoac_sim_run_grid(&cfg, &model, &run, NULL, cells, NSUB, 2, &cancel, progress));
    TEST_ASSERT_EQUAL_MEMORY(reference, cells, sizeof cells);
    TEST_ASSERT_EQUAL_INT64(NSUB, progress[ICOAC_SIM_PROGRESS_CELLS]);
    /* finished cells are final: a further call changes nothing */
    cells[3].trials = -7; /* marker */
    TEST_ASSERT_EQUAL_INT(ICOAC_SIM_OK, icoac_sim_run_grid(&cfg, &model, &run, NULL, cells, NSUB, 2, NULL, NULL));
    TEST_ASSERT_EQUAL_INT64(-7, cells[3].trials);
    cells[3].trials = reference[3].trials;
    TEST_ASSERT_EQUAL_MEMORY(reference, cells, sizeof cells);
}

static void test_bad_parameters(void)
{
    const icoac_config_t good_cfg = test_default_config();
    const icoac_sim_model_t good_model = test_cart_pole();
    const icoac_sim_run_t good_run = test_small_run(3, 100);
    icoac_config_t cfg = good_cfg;
    icoac_sim_model_t model = good_model;
    icoac_sim_run_t run = good_run;
    icoac_sim_cell_t cells[2], copy[2];
    icoac_prior_t bad_prior = test_prior(0, 0, 0, 0, 1.0);
    cells[0] = make_cell(0.1, 0.01, 1u);
    cells[1] = make_cell(-0.1, -0.01, 2u);
    memcpy(copy, cells, sizeof cells);

    model.dt = 0.0;
    TEST_ASSERT_EQUAL_INT(ICOAC_SIM_ERR_BAD_PLANT, icoac_sim_run_cell(&cfg, &model, &run, NULL, &cells[0], NULL, NULL));
    TEST_ASSERT_EQUAL_INT(ICOAC_SIM_ERR_BAD_PLANT, icoac_sim_run_grid(&cfg, &model, &run, NULL, cells, 2, 1, NULL, NULL));
    model = good_model;
    model.integrator = 7;
    TEST_ASSERT_EQUAL_INT(ICOAC_SIM_ERR_BAD_PLANT, icoac_sim_run_grid(&cfg, &model, &run, NULL, cells, 2, 1, NULL, NULL));
    model = good_model;

    run.max_trials = 0;
    TEST_ASSERT_EQUAL_INT(ICOAC_SIM_ERR_BAD_RUN, icoac_sim_run_cell(&cfg, &model, &run, NULL, &cells[0], NULL, NULL));
    TEST_ASSERT_EQUAL_INT(ICOAC_SIM_ERR_BAD_RUN, icoac_sim_run_grid(&cfg, &model, &run, NULL, cells, 2, 1, NULL, NULL));
    model.dt = 1e-310; /* subnormal: flushed to 0 by the workers, the plant would never move */
    TEST_ASSERT_EQUAL_INT(ICOAC_SIM_ERR_BAD_PLANT, icoac_sim_run_grid(&cfg, &model, &run, NULL, cells, 2, 1, NULL, NULL));
    model = good_model;
    run = good_run;
    run.init_velocity_noise = -1.0;
    TEST_ASSERT_EQUAL_INT(ICOAC_SIM_ERR_BAD_RUN, icoac_sim_run_grid(&cfg, &model, &run, NULL, cells, 2, 1, NULL, NULL));
    run = good_run;
    run.lanes = ICOAC_SIM_MAX_LANES + 1; /* a block larger than the worker's arrays */
    TEST_ASSERT_EQUAL_INT(ICOAC_SIM_ERR_BAD_RUN, icoac_sim_run_grid(&cfg, &model, &run, NULL, cells, 2, 1, NULL, NULL));
    run = good_run;

    cfg.policy.gain = (icoac_real_t)NAN;
    TEST_ASSERT_EQUAL_INT(ICOAC_ERR_BAD_GAIN, icoac_sim_run_cell(&cfg, &model, &run, NULL, &cells[0], NULL, NULL));
    TEST_ASSERT_EQUAL_INT(ICOAC_ERR_BAD_GAIN, icoac_sim_run_grid(&cfg, &model, &run, NULL, cells, 2, 1, NULL, NULL));
    cfg = good_cfg;

    bad_prior.cov[0][1] = (icoac_real_t)0.5; /* not symmetric */
    TEST_ASSERT_EQUAL_INT(ICOAC_ERR_BAD_PRIOR, icoac_sim_run_grid(&cfg, &model, &run, &bad_prior, cells, 2, 1, NULL, NULL));

    TEST_ASSERT_EQUAL_INT(ICOAC_SIM_ERR_BAD_ARGUMENT, icoac_sim_run_grid(&cfg, &model, &run, NULL, NULL, 2, 1, NULL, NULL));
    TEST_ASSERT_EQUAL_INT(ICOAC_SIM_ERR_BAD_ARGUMENT, icoac_sim_run_grid(&cfg, &model, &run, NULL, cells, 0, 1, NULL, NULL));
    TEST_ASSERT_EQUAL_INT(ICOAC_SIM_ERR_BAD_ARGUMENT, icoac_sim_run_grid(&cfg, &model, &run, NULL, cells, 2, -1, NULL, NULL));
    TEST_ASSERT_EQUAL_INT(ICOAC_SIM_ERR_BAD_ARGUMENT, icoac_sim_run_cell(&cfg, &model, NULL, NULL, &cells[0], NULL, NULL));
    TEST_ASSERT_EQUAL_INT(ICOAC_SIM_ERR_BAD_ARGUMENT, icoac_sim_run_cell(&cfg, &model, &run, NULL, NULL, NULL, NULL));
    TEST_ASSERT_EQUAL_INT(ICOAC_SIM_ERR_BAD_ARGUMENT, icoac_sim_run_cell(NULL, &model, &run, NULL, &cells[0], NULL, NULL));
    /* the rejected calls left the cells untouched */
    TEST_ASSERT_EQUAL_MEMORY(copy, cells, sizeof cells);
    cells[1].x0 = (double)NAN;
    TEST_ASSERT_EQUAL_INT(ICOAC_SIM_ERR_BAD_ARGUMENT, icoac_sim_run_cell(&cfg, &model, &run, NULL, &cells[1], NULL, NULL));
    TEST_ASSERT_EQUAL_INT(ICOAC_SIM_ERR_BAD_ARGUMENT, icoac_sim_run_grid(&cfg, &model, &run, NULL, cells, 2, 1, NULL, NULL));
    TEST_ASSERT_EQUAL_INT(ICOAC_SIM_PENDING, cells[0].outcome);
}

static void test_trajectory_recorder(void)
{
    icoac_config_t cfg = test_default_config();
    const icoac_sim_model_t model = test_cart_pole();
    const icoac_prior_t prior = test_prior(0.075, 0.049, 0.318, 0.085, 1.0);
    enum { MAX = 300 };
    static double states[(MAX + 1) * 4], forces[MAX], states2[(MAX + 1) * 4], forces2[MAX];
    int64_t n = -1, n2 = -1, k;
    int i;
    cfg.ico.rate = 0; /* fixed w: the recorded force can be recomputed */
    TEST_ASSERT_EQUAL_INT(ICOAC_SIM_OK,
                          icoac_sim_trajectory(&cfg, &model, &prior, -0.5, DEG(-4.0), 1e-4, 9u, MAX, states, forces, &n));
    TEST_ASSERT_TRUE(n >= 1 && n <= MAX);
    /* start state: (x0, small v, theta0, small v) */
    TEST_ASSERT_TRUE(states[0] == -0.5);
    TEST_ASSERT_TRUE(states[2] == DEG(-4.0));
    TEST_ASSERT_TRUE(fabs(states[1]) <= 1e-4 && fabs(states[3]) <= 1e-4);
    TEST_ASSERT_TRUE(states[1] != 0.0 && states[3] != 0.0);
    for (k = 0; k < n; ++k) {
        double s[4], z = 0, u = 0;
        const double *cur = states + 4 * k;
        memcpy(s, cur, sizeof s);
        /* each recorded state is one plant step from the previous under the recorded force */
        TEST_ASSERT_EQUAL_INT(ICOAC_SIM_OK, test_cart_pole_step(&model, s, forces[k]));
        TEST_ASSERT_EQUAL_MEMORY(states + 4 * (k + 1), s, sizeof s);
        /* and the force is G w^T x~ + U (1 N) of the previous state */
        for (i = 0; i < 4; ++i) {
            z += (double)prior.mean[i] * test_scale(i, (double)(icoac_real_t)cur[i], 1);
        }
        if (cur[2] > DEG(11.5) || cur[0] < -2.35) {
            u = 1;
        } else if (cur[2] < DEG(-11.5) || cur[0] > 2.35) {
            u = -1;
        }
        assert_close(forces[k], 10.0 * z + u, 1e-4);
        if (k + 1 < n) {
            TEST_ASSERT_EQUAL_INT(0, test_cart_pole_failed(&model, states + 4 * (k + 1)));
        }
    }
    if (n < MAX) {
        TEST_ASSERT_EQUAL_INT(1, test_cart_pole_failed(&model, states + 4 * n));
    }
    /* same seed: identical; other seed: other initial velocities */
    TEST_ASSERT_EQUAL_INT(ICOAC_SIM_OK,
                          icoac_sim_trajectory(&cfg, &model, &prior, -0.5, DEG(-4.0), 1e-4, 9u, MAX, states2, forces2, &n2));
    TEST_ASSERT_EQUAL_INT64(n, n2);
    TEST_ASSERT_EQUAL_MEMORY(states, states2, sizeof(double) * 4 * (size_t)(n + 1));
    TEST_ASSERT_EQUAL_INT(ICOAC_SIM_OK,
                          icoac_sim_trajectory(&cfg, &model, &prior, -0.5, DEG(-4.0), 1e-4, 10u, MAX, states2, forces2, &n2));
    TEST_ASSERT_TRUE(states2[1] != states[1] && states2[3] != states[3]);
    TEST_ASSERT_TRUE(states2[0] == states[0] && states2[2] == states[2]);
    TEST_ASSERT_TRUE(fabs(states2[1]) <= 1e-4 && fabs(states2[3]) <= 1e-4);
}

static void test_trajectory_falls(void)
{
    const icoac_config_t cfg = test_default_config();
    const icoac_sim_model_t model = test_cart_pole();
    enum { MAX = 500 };
    static double states[(MAX + 1) * 4], forces[MAX];
    int64_t n = -1;
    /* w = 0: only the 1 N reflex, which cannot hold 11.9 deg */
    TEST_ASSERT_EQUAL_INT(ICOAC_SIM_OK,
                          icoac_sim_trajectory(&cfg, &model, NULL, 0.0, DEG(11.9), 0.0, 1u, MAX, states, forces, &n));
    TEST_ASSERT_TRUE(n >= 1 && n < MAX);
    TEST_ASSERT_TRUE(states[1] == 0.0 && states[3] == 0.0); /* zero noise: zero velocities */
    TEST_ASSERT_EQUAL_INT(1, test_cart_pole_failed(&model, states + 4 * n));
    TEST_ASSERT_TRUE(states[4 * n + 2] > DEG(12.0));
    assert_close(forces[0], 1.0, 0.0); /* reflex only */
    TEST_ASSERT_EQUAL_INT(ICOAC_SIM_ERR_BAD_ARGUMENT,
                          icoac_sim_trajectory(&cfg, &model, NULL, 0.0, 0.0, 0.0, 1u, 0, states, forces, &n));
    TEST_ASSERT_EQUAL_INT(ICOAC_SIM_ERR_BAD_ARGUMENT,
                          icoac_sim_trajectory(&cfg, &model, NULL, 0.0, 0.0, 0.0, 1u, MAX, NULL, forces, &n));
    TEST_ASSERT_EQUAL_INT(ICOAC_SIM_ERR_BAD_ARGUMENT,
                          icoac_sim_trajectory(&cfg, &model, NULL, 0.0, 0.0, -1.0, 1u, MAX, states, forces, &n));
}

/* The engine may flush subnormals on its threads, but restores the caller's FPU mode. */
static void test_fpu_mode_restored(void)
{
    const icoac_config_t cfg = test_default_config();
    const icoac_sim_model_t model = test_cart_pole();
    const icoac_sim_run_t run = test_small_run(2, 50);
    icoac_sim_cell_t c = make_cell(0.0, 0.0, 5u);
    double states[(50 + 1) * 4], forces[50];
    int64_t n;
    volatile double tiny = 1e-300, big = 1e10;
    TEST_ASSERT_TRUE(tiny / big > 0.0); /* subnormal, not flushed */
    TEST_ASSERT_EQUAL_INT(ICOAC_SIM_OK, icoac_sim_run_cell(&cfg, &model, &run, NULL, &c, NULL, NULL));
    TEST_ASSERT_TRUE(tiny / big > 0.0);
    TEST_ASSERT_EQUAL_INT(ICOAC_SIM_OK, icoac_sim_trajectory(&cfg, &model, NULL, 0.0, 0.0, 1e-4, 1u, 50, states, forces, &n));
    TEST_ASSERT_TRUE(tiny / big > 0.0);
}

void setUp(void) {}
void tearDown(void) {}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_run_cell_deterministic);
    RUN_TEST(test_run_cell_outcomes);
    RUN_TEST(test_grid_thread_independent);
    RUN_TEST(test_cancel_and_resume);
    RUN_TEST(test_lanes_match_single_cells);
    RUN_TEST(test_cancel_mid_run);
    RUN_TEST(test_bad_parameters);
    RUN_TEST(test_numeric_fault_marks_cell_error);
    RUN_TEST(test_failure_at_the_last_step);
    RUN_TEST(test_trajectory_recorder);
    RUN_TEST(test_trajectory_falls);
    RUN_TEST(test_fpu_mode_restored);
    return UNITY_END();
}
