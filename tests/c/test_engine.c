/* SPDX-License-Identifier: Apache-2.0 */
/* Host engine: determinism of cells and grids, thread-count independence, the lanes of a
 * thread, cancellation and resume, argument checks, cell accounting, trajectory recorder. */
#define _POSIX_C_SOURCE 199309L /* nanosleep */
#include "test_common.h"

#include <pthread.h>
#include <time.h>

#include "test_sim_common.h"

static icoac_sim_plant_t default_plant(void)
{
    icoac_sim_plant_t p;
    icoac_sim_plant_default(&p);
    return p;
}

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
    assert_true(c->outcome == ICOAC_SIM_SUCCESS || c->outcome == ICOAC_SIM_FAILED);
    assert_int_equal(c->status, ICOAC_SIM_OK);
    assert_true(c->trials >= 1 && c->trials <= run->max_trials);
    assert_true(c->total_steps >= c->trials);
    assert_true(c->last_trial_steps >= 1 && c->last_trial_steps <= c->total_steps);
    assert_close(c->elapsed_time, 0.01 * (double)c->total_steps, 1e-9);
    if (c->outcome == ICOAC_SIM_SUCCESS) {
        assert_int_equal(c->last_trial_steps, run->success_steps);
    } else {
        assert_int_equal(c->trials, run->max_trials);
        assert_true(c->last_trial_steps <= run->success_steps); /* = when it fell at the last step */
    }
}

static void test_run_cell_deterministic(void **unused)
{
    const icoac_sim_plant_t plant = default_plant();
    const icoac_sim_run_t run = test_small_run(15, 1500);
    int mode;
    (void)unused;
    for (mode = ICOAC_MODE_ICO; mode <= ICOAC_MODE_RL; ++mode) {
        icoac_config_t cfg = test_default_config();
        icoac_sim_cell_t a = make_cell(-1.5, DEG(-7.0), 123u);
        icoac_sim_cell_t b = a;
        icoac_sim_cell_t c = make_cell(-1.5, DEG(-7.0), 124u);
        cfg.mode = mode;
        assert_int_equal(icoac_sim_run_cell(&cfg, &plant, &run, NULL, &a, NULL, NULL), ICOAC_SIM_OK);
        assert_int_equal(icoac_sim_run_cell(&cfg, &plant, &run, NULL, &b, NULL, NULL), ICOAC_SIM_OK);
        assert_memory_equal(&a, &b, sizeof a);
        check_accounting(&a, &run);
        /* a different seed changes the run (velocities, exploration noise) */
        assert_int_equal(icoac_sim_run_cell(&cfg, &plant, &run, NULL, &c, NULL, NULL), ICOAC_SIM_OK);
        assert_true(memcmp(a.weights, c.weights, sizeof a.weights) != 0 || a.total_steps != c.total_steps);
    }
}

static void test_run_cell_outcomes(void **unused)
{
    const icoac_sim_plant_t plant = default_plant();
    icoac_config_t cfg = test_default_config();
    icoac_sim_run_t run = test_small_run(5, 1);
    icoac_sim_cell_t c = make_cell(0.0, 0.0, 1u);
    int64_t progress[ICOAC_SIM_PROGRESS_LEN] = {0, 0, 0};
    (void)unused;
    /* one step from the upright cannot fail: success in the first trial */
    assert_int_equal(icoac_sim_run_cell(&cfg, &plant, &run, NULL, &c, NULL, progress), ICOAC_SIM_OK);
    assert_int_equal(c.outcome, ICOAC_SIM_SUCCESS);
    assert_int_equal(c.trials, 1);
    assert_int_equal(c.total_steps, 1);
    assert_int_equal(progress[ICOAC_SIM_PROGRESS_CELLS], 1);
    assert_int_equal(progress[ICOAC_SIM_PROGRESS_TRIALS], 1);
    assert_int_equal(progress[ICOAC_SIM_PROGRESS_STEPS], 1);
    check_accounting(&c, &run);
    /* leaning 11.9 deg with w = 0 and the 1 N reflex: every trial falls */
    run = test_small_run(4, 100000);
    c = make_cell(0.0, DEG(11.9), 1u);
    assert_int_equal(icoac_sim_run_cell(&cfg, &plant, &run, NULL, &c, NULL, NULL), ICOAC_SIM_OK);
    assert_int_equal(c.outcome, ICOAC_SIM_FAILED);
    assert_int_equal(c.trials, 4);
    check_accounting(&c, &run);
    /* it learned something: the first tick of the run entered the zone */
    assert_true(c.weights[2] > 0.0);
}

/* A controller that faults numerically mid-run (the largest accepted prior covariance,
 * inflated by forgetting in the directions the observations inform least: the posterior
 * reading, the one forgetting belongs to, as in the literal configuration) ends its cell as
 * ERROR with ICOAC_ERR_NUMERIC and finite recorded weights; such cells used to end SUCCESS or
 * FAILED with NaN weights. */
static void test_numeric_fault_marks_cell_error(void **unused)
{
    const icoac_sim_plant_t plant = default_plant();
    icoac_config_t cfg = test_default_config();
    icoac_sim_run_t run = test_small_run(50, 5000);
    icoac_sim_cell_t cells[2];
    const icoac_prior_t prior = test_prior(0.1, 0.1, 0.5, 0.1, (double)ICOAC_PRIOR_COV_MAX);
    int i, j, k;
    (void)unused;
    cfg.mode = ICOAC_MODE_RL;
    test_literal_reading(&cfg);
    cfg.actor.forgetting = ICOAC_FORGETTING_MIN;
    cells[0] = make_cell(0.0, 0.0, 1u);
    cells[1] = make_cell(0.5, DEG(1.0), 2u);
    assert_int_equal(icoac_sim_run_grid(&cfg, &plant, &run, &prior, cells, 2, 1, NULL, NULL), ICOAC_SIM_OK);
    for (k = 0; k < 2; ++k) {
        assert_int_equal(cells[k].outcome, ICOAC_SIM_ERROR);
        assert_int_equal(cells[k].status, ICOAC_ERR_NUMERIC);
        for (i = 0; i < ICOAC_CARTPOLE_INPUTS; ++i) {
            assert_true(isfinite(cells[k].weights[i]));
            for (j = 0; j < ICOAC_CARTPOLE_INPUTS; ++j) {
                assert_true(isfinite(cells[k].cov[i][j]));
            }
        }
    }
}

/* Success is success_steps steps without a failure: a trial that fails at its last step has
 * failed (it used to count as a success). A fixed controller (w = 0, no learning) and no
 * initial-velocity noise make every trial the same, falling at step n. */
static void test_failure_at_the_last_step(void **unused)
{
    const icoac_sim_plant_t plant = default_plant();
    icoac_config_t cfg = test_default_config();
    icoac_sim_run_t run = test_small_run(1, 100000);
    icoac_sim_cell_t c = make_cell(0.0, DEG(11.9), 1u);
    int64_t n;
    (void)unused;
    cfg.learn = 0;
    run.init_velocity_noise = 0.0;
    assert_int_equal(icoac_sim_run_cell(&cfg, &plant, &run, NULL, &c, NULL, NULL), ICOAC_SIM_OK);
    assert_int_equal(c.outcome, ICOAC_SIM_FAILED);
    n = c.last_trial_steps;
    assert_true(n > 1 && n < 1000);
    run = test_small_run(2, n);
    c = make_cell(0.0, DEG(11.9), 1u);
    assert_int_equal(icoac_sim_run_cell(&cfg, &plant, &run, NULL, &c, NULL, NULL), ICOAC_SIM_OK);
    assert_int_equal(c.outcome, ICOAC_SIM_FAILED);
    assert_int_equal(c.trials, 2);
    assert_int_equal(c.last_trial_steps, n);
    check_accounting(&c, &run);
    run = test_small_run(2, n - 1);
    c = make_cell(0.0, DEG(11.9), 1u);
    assert_int_equal(icoac_sim_run_cell(&cfg, &plant, &run, NULL, &c, NULL, NULL), ICOAC_SIM_OK);
    assert_int_equal(c.outcome, ICOAC_SIM_SUCCESS);
    assert_int_equal(c.trials, 1);
    check_accounting(&c, &run);
}

static void run_grid_ok(const icoac_config_t *cfg, icoac_sim_cell_t *cells, int64_t n, int32_t threads,
                        int64_t progress[ICOAC_SIM_PROGRESS_LEN])
{
    const icoac_sim_plant_t plant = default_plant();
    const icoac_sim_run_t run = test_small_run(10, 1000);
    assert_int_equal(icoac_sim_run_grid(cfg, &plant, &run, NULL, cells, n, threads, NULL, progress), ICOAC_SIM_OK);
}

#define NSUB 8

static void subset(icoac_sim_cell_t out[NSUB])
{
    static icoac_sim_cell_t grid[ICOAC_SIM_GRID_CELLS];
    static const int pick[NSUB] = {0, 100, 333, 600, 612, 777, 1000, 1224};
    int i;
    assert_int_equal(icoac_sim_paper_grid(grid, ICOAC_SIM_GRID_CELLS, 2010u), ICOAC_SIM_OK);
    for (i = 0; i < NSUB; ++i) {
        out[i] = grid[pick[i]];
    }
}

static void test_grid_thread_independent(void **unused)
{
    icoac_sim_cell_t one[NSUB], two[NSUB], solo[NSUB];
    int64_t p1[ICOAC_SIM_PROGRESS_LEN] = {0, 0, 0}, p2[ICOAC_SIM_PROGRESS_LEN] = {0, 0, 0};
    const icoac_sim_plant_t plant = default_plant();
    const icoac_sim_run_t run = test_small_run(10, 1000);
    int mode, i;
    (void)unused;
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
        assert_memory_equal(one, two, sizeof one);
        assert_memory_equal(p1, p2, sizeof p1);
        for (i = 0; i < NSUB; ++i) {
            /* a grid cell is the same independent run as icoac_sim_run_cell */
            assert_int_equal(icoac_sim_run_cell(&cfg, &plant, &run, NULL, &solo[i], NULL, NULL), ICOAC_SIM_OK);
            check_accounting(&one[i], &run);
            trials += one[i].trials;
            steps += one[i].total_steps;
        }
        assert_memory_equal(one, solo, sizeof one);
        assert_int_equal(p1[ICOAC_SIM_PROGRESS_CELLS], NSUB);
        assert_int_equal(p1[ICOAC_SIM_PROGRESS_TRIALS], trials);
        assert_int_equal(p1[ICOAC_SIM_PROGRESS_STEPS], steps);
    }
}

/* The lanes of a worker thread (ICOAC_SIM_LANES cells in lockstep, a lane refilled as its cell
 * ends): every mode, cells of very different lengths (one-trial successes next to cells that
 * run out of trials), a finished cell mixed in, an odd
 * count, and 1 to 3 threads. Each cell equals its run alone through icoac_sim_run_cell. */
static void test_lanes_match_single_cells(void **unused)
{
#define NLANE 11
    static const int pick[NLANE] = {612, 0, 1224, 600, 24, 611, 613, 100, 1000, 587, 637};
    static icoac_sim_cell_t grid[ICOAC_SIM_GRID_CELLS];
    const icoac_sim_plant_t plant = default_plant();
    const icoac_sim_run_t run = test_small_run(40, 600);
    const icoac_prior_t prior = test_prior(0.094, 0.066, 0.365, 0.080, 1e-3);
    icoac_sim_cell_t solo[NLANE], cells[NLANE];
    int mode, threads, i;
    (void)unused;
    assert_int_equal(icoac_sim_paper_grid(grid, ICOAC_SIM_GRID_CELLS, 99u), ICOAC_SIM_OK);
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
            assert_int_equal(icoac_sim_run_cell(&cfg, &plant, &run, &prior, &solo[i], NULL, NULL), ICOAC_SIM_OK);
            short_cells += solo[i].trials <= 10;
            long_cells += solo[i].trials == run.max_trials;
        }
        assert_true(short_cells > 0 && long_cells > 0); /* the lanes do end at different times */
        for (threads = 1; threads <= 3; ++threads) {
            int64_t progress[ICOAC_SIM_PROGRESS_LEN] = {0, 0, 0};
            memcpy(cells, solo, sizeof cells);
            for (i = 0; i < NLANE; ++i) {
                if (i != 4) {
                    cells[i] = grid[pick[i]];
                }
            }
            assert_int_equal(icoac_sim_run_grid(&cfg, &plant, &run, &prior, cells, NLANE, threads, NULL, progress),
                             ICOAC_SIM_OK);
            assert_memory_equal(cells, solo, sizeof cells);
            assert_int_equal(progress[ICOAC_SIM_PROGRESS_CELLS], NLANE - 1);
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
static void test_cancel_mid_run(void **unused)
{
    icoac_config_t cfg = test_default_config();
    const icoac_sim_plant_t plant = default_plant();
    const icoac_sim_run_t run = test_small_run(300, 1000);
    icoac_sim_cell_t cells[NSUB], reference[NSUB], before[NSUB];
    volatile int64_t progress[ICOAC_SIM_PROGRESS_LEN] = {0, 0, 0};
    volatile int32_t cancel = 0;
    canceller_t canceller;
    pthread_t thread;
    int i, pending = 0;
    (void)unused;
    cfg.mode = ICOAC_MODE_RL;
    subset(reference);
    assert_int_equal(icoac_sim_run_grid(&cfg, &plant, &run, NULL, reference, NSUB, 1, NULL, NULL), ICOAC_SIM_OK);
    subset(cells);
    memcpy(before, cells, sizeof cells);
    canceller.cancel = &cancel;
    canceller.progress = progress;
    canceller.after_trials = 200;
    assert_int_equal(pthread_create(&thread, NULL, cancel_later, &canceller), 0);
    assert_int_equal(icoac_sim_run_grid(&cfg, &plant, &run, NULL, cells, NSUB, 1, &cancel, progress),
                     ICOAC_SIM_CANCELLED);
    assert_int_equal(pthread_join(thread, NULL), 0);
    for (i = 0; i < NSUB; ++i) {
        if (cells[i].outcome == ICOAC_SIM_PENDING) {
            assert_memory_equal(&cells[i], &before[i], sizeof cells[i]);
            ++pending;
        } else {
            assert_memory_equal(&cells[i], &reference[i], sizeof cells[i]);
        }
    }
    assert_true(pending > 0);
    cancel = 0;
    assert_int_equal(icoac_sim_run_grid(&cfg, &plant, &run, NULL, cells, NSUB, 1, &cancel, NULL), ICOAC_SIM_OK);
    assert_memory_equal(cells, reference, sizeof cells);
}

static void test_cancel_and_resume(void **unused)
{
    icoac_config_t cfg = test_default_config();
    const icoac_sim_plant_t plant = default_plant();
    const icoac_sim_run_t run = test_small_run(10, 1000);
    icoac_sim_cell_t cells[NSUB], reference[NSUB], before[NSUB];
    int64_t progress[ICOAC_SIM_PROGRESS_LEN] = {0, 0, 0};
    volatile int32_t cancel = 1;
    int i;
    (void)unused;
    subset(reference);
    run_grid_ok(&cfg, reference, NSUB, 1, NULL);
    subset(cells);
    memcpy(before, cells, sizeof cells);
    assert_int_equal(icoac_sim_run_grid(&cfg, &plant, &run, NULL, cells, NSUB, 2, &cancel, progress),
                     ICOAC_SIM_CANCELLED);
    for (i = 0; i < NSUB; ++i) {
        assert_int_equal(cells[i].outcome, ICOAC_SIM_PENDING);
    }
    assert_memory_equal(cells, before, sizeof cells);
    assert_int_equal(progress[ICOAC_SIM_PROGRESS_CELLS], 0);
    /* single cell too */
    assert_int_equal(icoac_sim_run_cell(&cfg, &plant, &run, NULL, &cells[0], &cancel, NULL), ICOAC_SIM_CANCELLED);
    assert_int_equal(cells[0].outcome, ICOAC_SIM_PENDING);
    /* resume: lower the flag, call again */
    cancel = 0;
    assert_int_equal(icoac_sim_run_grid(&cfg, &plant, &run, NULL, cells, NSUB, 2, &cancel, progress), ICOAC_SIM_OK);
    assert_memory_equal(cells, reference, sizeof cells);
    assert_int_equal(progress[ICOAC_SIM_PROGRESS_CELLS], NSUB);
    /* finished cells are final: a further call changes nothing */
    cells[3].trials = -7; /* marker */
    assert_int_equal(icoac_sim_run_grid(&cfg, &plant, &run, NULL, cells, NSUB, 2, NULL, NULL), ICOAC_SIM_OK);
    assert_int_equal(cells[3].trials, -7);
    cells[3].trials = reference[3].trials;
    assert_memory_equal(cells, reference, sizeof cells);
}

static void test_bad_parameters(void **unused)
{
    const icoac_config_t good_cfg = test_default_config();
    const icoac_sim_plant_t good_plant = default_plant();
    const icoac_sim_run_t good_run = test_small_run(3, 100);
    icoac_config_t cfg = good_cfg;
    icoac_sim_plant_t plant = good_plant;
    icoac_sim_run_t run = good_run;
    icoac_sim_cell_t cells[2], copy[2];
    icoac_prior_t bad_prior = test_prior(0, 0, 0, 0, 1.0);
    (void)unused;
    cells[0] = make_cell(0.1, 0.01, 1u);
    cells[1] = make_cell(-0.1, -0.01, 2u);
    memcpy(copy, cells, sizeof cells);

    plant.dt = 0.0;
    assert_int_equal(icoac_sim_run_cell(&cfg, &plant, &run, NULL, &cells[0], NULL, NULL), ICOAC_SIM_ERR_BAD_PLANT);
    assert_int_equal(icoac_sim_run_grid(&cfg, &plant, &run, NULL, cells, 2, 1, NULL, NULL), ICOAC_SIM_ERR_BAD_PLANT);
    plant = good_plant;
    plant.integrator = 7;
    assert_int_equal(icoac_sim_run_grid(&cfg, &plant, &run, NULL, cells, 2, 1, NULL, NULL), ICOAC_SIM_ERR_BAD_PLANT);
    plant = good_plant;

    run.max_trials = 0;
    assert_int_equal(icoac_sim_run_cell(&cfg, &plant, &run, NULL, &cells[0], NULL, NULL), ICOAC_SIM_ERR_BAD_RUN);
    assert_int_equal(icoac_sim_run_grid(&cfg, &plant, &run, NULL, cells, 2, 1, NULL, NULL), ICOAC_SIM_ERR_BAD_RUN);
    plant.dt = 1e-310; /* subnormal: flushed to 0 by the workers, the plant would never move */
    assert_int_equal(icoac_sim_run_grid(&cfg, &plant, &run, NULL, cells, 2, 1, NULL, NULL), ICOAC_SIM_ERR_BAD_PLANT);
    plant = good_plant;
    run = good_run;
    run.init_velocity_noise = -1.0;
    assert_int_equal(icoac_sim_run_grid(&cfg, &plant, &run, NULL, cells, 2, 1, NULL, NULL), ICOAC_SIM_ERR_BAD_RUN);
    run = good_run;

    cfg.policy.gain = (icoac_real_t)NAN;
    assert_int_equal(icoac_sim_run_cell(&cfg, &plant, &run, NULL, &cells[0], NULL, NULL), ICOAC_ERR_BAD_GAIN);
    assert_int_equal(icoac_sim_run_grid(&cfg, &plant, &run, NULL, cells, 2, 1, NULL, NULL), ICOAC_ERR_BAD_GAIN);
    cfg = good_cfg;

    bad_prior.cov[0][1] = (icoac_real_t)0.5; /* not symmetric */
    assert_int_equal(icoac_sim_run_grid(&cfg, &plant, &run, &bad_prior, cells, 2, 1, NULL, NULL), ICOAC_ERR_BAD_PRIOR);

    assert_int_equal(icoac_sim_run_grid(&cfg, &plant, &run, NULL, NULL, 2, 1, NULL, NULL), ICOAC_SIM_ERR_BAD_ARGUMENT);
    assert_int_equal(icoac_sim_run_grid(&cfg, &plant, &run, NULL, cells, 0, 1, NULL, NULL), ICOAC_SIM_ERR_BAD_ARGUMENT);
    assert_int_equal(icoac_sim_run_grid(&cfg, &plant, &run, NULL, cells, 2, -1, NULL, NULL), ICOAC_SIM_ERR_BAD_ARGUMENT);
    assert_int_equal(icoac_sim_run_cell(&cfg, &plant, NULL, NULL, &cells[0], NULL, NULL), ICOAC_SIM_ERR_BAD_ARGUMENT);
    assert_int_equal(icoac_sim_run_cell(&cfg, &plant, &run, NULL, NULL, NULL, NULL), ICOAC_SIM_ERR_BAD_ARGUMENT);
    assert_int_equal(icoac_sim_run_cell(NULL, &plant, &run, NULL, &cells[0], NULL, NULL), ICOAC_SIM_ERR_BAD_ARGUMENT);
    /* the rejected calls left the cells untouched */
    assert_memory_equal(cells, copy, sizeof cells);
    cells[1].x0 = (double)NAN;
    assert_int_equal(icoac_sim_run_cell(&cfg, &plant, &run, NULL, &cells[1], NULL, NULL), ICOAC_SIM_ERR_BAD_ARGUMENT);
    assert_int_equal(icoac_sim_run_grid(&cfg, &plant, &run, NULL, cells, 2, 1, NULL, NULL), ICOAC_SIM_ERR_BAD_ARGUMENT);
    assert_int_equal(cells[0].outcome, ICOAC_SIM_PENDING);
}

static void test_trajectory_recorder(void **unused)
{
    icoac_config_t cfg = test_default_config();
    const icoac_sim_plant_t plant = default_plant();
    const icoac_prior_t prior = test_prior(0.075, 0.049, 0.318, 0.085, 1.0);
    enum { MAX = 300 };
    static double states[(MAX + 1) * 4], forces[MAX], states2[(MAX + 1) * 4], forces2[MAX];
    int64_t n = -1, n2 = -1, k;
    int i;
    (void)unused;
    cfg.ico.rate = 0; /* fixed w: the recorded force can be recomputed */
    assert_int_equal(icoac_sim_trajectory(&cfg, &plant, &prior, -0.5, DEG(-4.0), 1e-4, 9u, MAX, states, forces, &n),
                     ICOAC_SIM_OK);
    assert_true(n >= 1 && n <= MAX);
    /* start state: (x0, small v, theta0, small v) */
    assert_true(states[0] == -0.5);
    assert_true(states[2] == DEG(-4.0));
    assert_true(fabs(states[1]) <= 1e-4 && fabs(states[3]) <= 1e-4);
    assert_true(states[1] != 0.0 && states[3] != 0.0);
    for (k = 0; k < n; ++k) {
        double s[4], z = 0, u = 0;
        const double *cur = states + 4 * k;
        memcpy(s, cur, sizeof s);
        /* each recorded state is one plant step from the previous under the recorded force */
        assert_int_equal(icoac_sim_plant_step(&plant, s, forces[k]), ICOAC_SIM_OK);
        assert_memory_equal(s, states + 4 * (k + 1), sizeof s);
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
            assert_int_equal(icoac_sim_failed(&plant, states + 4 * (k + 1)), 0);
        }
    }
    if (n < MAX) {
        assert_int_equal(icoac_sim_failed(&plant, states + 4 * n), 1);
    }
    /* same seed: identical; other seed: other initial velocities */
    assert_int_equal(icoac_sim_trajectory(&cfg, &plant, &prior, -0.5, DEG(-4.0), 1e-4, 9u, MAX, states2, forces2, &n2),
                     ICOAC_SIM_OK);
    assert_int_equal(n2, n);
    assert_memory_equal(states2, states, sizeof(double) * 4 * (size_t)(n + 1));
    assert_int_equal(icoac_sim_trajectory(&cfg, &plant, &prior, -0.5, DEG(-4.0), 1e-4, 10u, MAX, states2, forces2, &n2),
                     ICOAC_SIM_OK);
    assert_true(states2[1] != states[1] && states2[3] != states[3]);
    assert_true(states2[0] == states[0] && states2[2] == states[2]);
    assert_true(fabs(states2[1]) <= 1e-4 && fabs(states2[3]) <= 1e-4);
}

static void test_trajectory_falls(void **unused)
{
    const icoac_config_t cfg = test_default_config();
    const icoac_sim_plant_t plant = default_plant();
    enum { MAX = 500 };
    static double states[(MAX + 1) * 4], forces[MAX];
    int64_t n = -1;
    (void)unused;
    /* w = 0: only the 1 N reflex, which cannot hold 11.9 deg */
    assert_int_equal(icoac_sim_trajectory(&cfg, &plant, NULL, 0.0, DEG(11.9), 0.0, 1u, MAX, states, forces, &n),
                     ICOAC_SIM_OK);
    assert_true(n >= 1 && n < MAX);
    assert_true(states[1] == 0.0 && states[3] == 0.0); /* zero noise: zero velocities */
    assert_int_equal(icoac_sim_failed(&plant, states + 4 * n), 1);
    assert_true(states[4 * n + 2] > DEG(12.0));
    assert_close(forces[0], 1.0, 0.0); /* reflex only */
    assert_int_equal(icoac_sim_trajectory(&cfg, &plant, NULL, 0.0, 0.0, 0.0, 1u, 0, states, forces, &n),
                     ICOAC_SIM_ERR_BAD_ARGUMENT);
    assert_int_equal(icoac_sim_trajectory(&cfg, &plant, NULL, 0.0, 0.0, 0.0, 1u, MAX, NULL, forces, &n),
                     ICOAC_SIM_ERR_BAD_ARGUMENT);
    assert_int_equal(icoac_sim_trajectory(&cfg, &plant, NULL, 0.0, 0.0, -1.0, 1u, MAX, states, forces, &n),
                     ICOAC_SIM_ERR_BAD_ARGUMENT);
}

/* The engine may flush subnormals on its threads, but restores the caller's FPU mode. */
static void test_fpu_mode_restored(void **unused)
{
    const icoac_config_t cfg = test_default_config();
    const icoac_sim_plant_t plant = default_plant();
    const icoac_sim_run_t run = test_small_run(2, 50);
    icoac_sim_cell_t c = make_cell(0.0, 0.0, 5u);
    double states[(50 + 1) * 4], forces[50];
    int64_t n;
    volatile double tiny = 1e-300, big = 1e10;
    (void)unused;
    assert_true(tiny / big > 0.0); /* subnormal, not flushed */
    assert_int_equal(icoac_sim_run_cell(&cfg, &plant, &run, NULL, &c, NULL, NULL), ICOAC_SIM_OK);
    assert_true(tiny / big > 0.0);
    assert_int_equal(icoac_sim_trajectory(&cfg, &plant, NULL, 0.0, 0.0, 1e-4, 1u, 50, states, forces, &n), ICOAC_SIM_OK);
    assert_true(tiny / big > 0.0);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_run_cell_deterministic),
        cmocka_unit_test(test_run_cell_outcomes),
        cmocka_unit_test(test_grid_thread_independent),
        cmocka_unit_test(test_cancel_and_resume),
        cmocka_unit_test(test_lanes_match_single_cells),
        cmocka_unit_test(test_cancel_mid_run),
        cmocka_unit_test(test_bad_parameters),
        cmocka_unit_test(test_numeric_fault_marks_cell_error),
        cmocka_unit_test(test_failure_at_the_last_step),
        cmocka_unit_test(test_trajectory_recorder),
        cmocka_unit_test(test_trajectory_falls),
        cmocka_unit_test(test_fpu_mode_restored),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
