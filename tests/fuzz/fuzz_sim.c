/* SPDX-License-Identifier: Apache-2.0 */
/* libFuzzer target of the sim API (icoac_sim.h), linked with libicoac_sim.so.
 *
 * Input format, read front to back (a byte past the end reads as 0):
 *   plant   mode byte b. b odd: sizeof(icoac_sim_plant_t) raw bytes laid over
 *           icoac_sim_plant_default; b even: the default with (b >> 1) % 8 mutations, each a
 *           field byte (% 9: 0 gravity, 1 cart_mass, 2 pole_mass, 3 half_length, 4 dt,
 *           5 x_limit, 6 theta_limit as doubles; 7 integrator, 8 reserved as int32) and a value.
 *   run     (fz_run) mode byte b. b odd: raw bytes over icoac_sim_run_default; b even: (b >> 1) % 4
 *           mutations, each a field byte (% 3: 0 max_trials, 1 success_steps as int64;
 *           2 init_velocity_noise as double) and a value.
 *   config, prior   as in fuzz_controller.c (float controller).
 *   ops     at most FZ_SIM_OPS, until the input ends. Op byte o, o % 5:
 *           0 plant   4 doubles state, 1 double force: icoac_sim_plant_step, icoac_sim_failed.
 *           1 cell    x0, theta0 (doubles), seed byte: icoac_sim_run_cell.
 *           2 grid    count byte (1 + n % 4 cells; n % 32 == 31: 0 cells), threads byte
 *                     (% 16: 13-14 two threads, 15 -1, else 1), then per cell x0, theta0,
 *                     seed byte, kind byte (% 4 == 3: preset as a finished cell, kept):
 *                     icoac_sim_run_grid.
 *           3 traj    x0, theta0, noise (doubles), seed byte, steps byte (max_steps = b % 66 - 1):
 *                     icoac_sim_trajectory.
 *           4 paper   size byte b (b % 8: 0, -1, 1, 1224, 1226, INT64_MAX, INT64_MIN, 1225;
 *                     b & 128: NULL cells): icoac_sim_paper_grid.
 *   value   double: selector byte k % 40. k < 28: special value (table in fuzz_input.c: 0, -0,
 *           1e-310, DBL_TRUE_MIN, DBL_MIN, DBL_MAX, 1e300, 1e30, NaN, +Inf, -Inf, -1, 1, 0.5,
 *           -1e30, 1e-20, -DBL_MAX, 2, 0.25, 2.4, -2.4, 9.8, 0.01, 1e-6, 1e6, 0.1, 1e-39, 3.2);
 *           28-35: int16 (2 bytes) / 32768 * {1e-3, ..., 1e4}[k - 28]; 36-39: 8 raw bytes.
 *           int64: selector % 12: 0, 1, 2, 3, -1, 300, 1000, 100000, INT64_MAX, INT64_MIN, 10,
 *           11 = 8 raw bytes. int32: as in fuzz_controller.c.
 * Runs are kept small: run_check sees the run as decoded, then max_trials is clamped to <= 3
 * and success_steps to <= 300 (the check must agree on both), and the ops of one input may
 * run at most FZ_SIM_TICK_BUDGET controller ticks in cells and grids.
 *
 * Contract (abort on violation): statuses are known (icoac_sim_status_str not "unknown");
 * a call refused by a check returns one of the failing checks' statuses; the checks accept
 * only documented ranges; icoac_sim_plant_step refuses a refused plant, a non-finite state or
 * force and a step made non-finite, with its status and the state unchanged, and never returns OK
 * with a non-finite state; NULL arguments get ICOAC_SIM_ERR_BAD_ARGUMENT; icoac_sim_failed
 * matches its definition (ICOAC_SIM_ERR_BAD_PLANT for a refused plant); after a run every cell is
 * SUCCESS, FAILED or ERROR with counts that fit the outcome, and a non-ERROR cell has status
 * OK and finite weights and cov; a refused grid leaves its cells untouched and a finished cell
 * is never rerun; a trajectory has n_steps in [0, max_steps], finite recorded states but for a
 * final failure state, and finite forces.
 */
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "fuzz_check.h"
#include "fuzz_input.h"
#include "icoac_sim/icoac_sim.h"

#define FZ_SIM_OPS 4
#define FZ_SIM_MAX_CELLS 4
#define FZ_TRAJ_MAX_STEPS 64
#define N ICOAC_CARTPOLE_INPUTS

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

/* Everything one input sets up. */
typedef struct {
    icoac_config_t cfg;
    icoac_sim_plant_t plant;
    icoac_sim_run_t run;          /* clamped */
    icoac_prior_t prior_storage;
    const icoac_prior_t *prior;
    int32_t failing[3];           /* statuses of the failing checks: config, plant or observation, run */
    int n_failing;                /* config and plant only */
    int run_failing;              /* the run check failed (failing[n_failing]) */
    int32_t prior_status;
    int64_t budget;               /* controller ticks left for cells and grids */
} setup_t;

static int finite_positive(double v)
{
    return isfinite(v) && v > 0.0;
}

/* Necessary conditions from the documented plant ranges; the check may be stricter. */
static int plant_documented(const icoac_sim_plant_t *p)
{
    return finite_positive(p->gravity) && finite_positive(p->cart_mass) && finite_positive(p->pole_mass) &&
           finite_positive(p->half_length) && finite_positive(p->dt) && p->dt <= 1.0 &&
           finite_positive(p->x_limit) && finite_positive(p->theta_limit) &&
           (p->integrator == ICOAC_SIM_EULER || p->integrator == ICOAC_SIM_RK4);
}

/* Definition of icoac_sim_failed: outside the strict limits, or not finite. */
static int failed_reference(const icoac_sim_plant_t *p, const double s[N])
{
    return !(fabs(s[0]) <= p->x_limit && fabs(s[2]) <= p->theta_limit && isfinite(s[1]) && isfinite(s[3]));
}

static void decode_plant(fz_reader_t *r, icoac_sim_plant_t *plant)
{
    const uint8_t mode = fz_u8(r);
    int n;
    icoac_sim_plant_default(plant);
    if (mode & 1u) {
        fz_overlay(r, plant, sizeof *plant);
        return;
    }
    for (n = (mode >> 1) % 8; n > 0; --n) {
        double *reals[7];
        const int field = fz_u8(r) % 9;
        reals[0] = &plant->gravity;
        reals[1] = &plant->cart_mass;
        reals[2] = &plant->pole_mass;
        reals[3] = &plant->half_length;
        reals[4] = &plant->dt;
        reals[5] = &plant->x_limit;
        reals[6] = &plant->theta_limit;
        if (field < 7) {
            *reals[field] = fz_double(r);
        } else if (field == 7) {
            plant->integrator = fz_i32(r);
        } else {
            plant->reserved = fz_i32(r);
        }
    }
}

/* Decode the setup, run the checks and clamp the run. */
static void decode_setup(fz_reader_t *r, setup_t *su)
{
    int32_t status;
    decode_plant(r, &su->plant);
    fz_run(r, &su->run);
    fz_config(r, &su->cfg);
    su->prior = fz_prior(r, &su->prior_storage);
    su->n_failing = 0;
    su->run_failing = 0;
    su->budget = FZ_SIM_TICK_BUDGET;

    status = (int32_t)icoac_config_check(&su->cfg);
    const int config_ok = status == ICOAC_OK;
    if (status != ICOAC_OK) {
        su->failing[su->n_failing++] = status;
    }
    status = icoac_sim_plant_check(&su->plant);
    FZ_CHECK(status == ICOAC_SIM_OK || status == ICOAC_SIM_ERR_BAD_PLANT, "plant_check returned %d", (int)status);
    FZ_CHECK(status != ICOAC_SIM_OK || plant_documented(&su->plant),
             "plant_check accepted g %g mc %g mp %g l %g dt %g x %g th %g integrator %d", su->plant.gravity,
             su->plant.cart_mass, su->plant.pole_mass, su->plant.half_length, su->plant.dt, su->plant.x_limit,
             su->plant.theta_limit, (int)su->plant.integrator);
    if (status != ICOAC_SIM_OK) {
        su->failing[su->n_failing++] = status;
    }
    /* the plant is the cart-pole: a task of another input count does not fit its observation */
    if (config_ok && status == ICOAC_SIM_OK && su->cfg.task.n_inputs != ICOAC_CARTPOLE_INPUTS) {
        su->failing[su->n_failing++] = ICOAC_SIM_ERR_BAD_PLANT;
    }
    status = fz_run_clamp(&su->run);
    if (status != ICOAC_SIM_OK) {
        su->failing[su->n_failing] = status;
        su->run_failing = 1;
    }
    su->prior_status = su->prior != 0 ? (int32_t)icoac_prior_check(su->prior, ICOAC_CARTPOLE_INPUTS) : ICOAC_OK;
}

/* A call refused by the checks returns one of the failing checks' statuses. */
static int refused_as_expected(const setup_t *su, int32_t status, int with_run)
{
    const int n = su->n_failing + (with_run && su->run_failing ? 1 : 0);
    int i;
    for (i = 0; i < n; ++i) {
        if (status == su->failing[i]) {
            return 1;
        }
    }
    return 0;
}

static int checks_fail(const setup_t *su, int with_run)
{
    return su->n_failing > 0 || (with_run && su->run_failing);
}

static void op_plant(fz_reader_t *r, const setup_t *su)
{
    double s[N];
    double before[N];
    double force;
    int32_t step;
    int32_t failed;
    const int plant_ok = icoac_sim_plant_check(&su->plant) == ICOAC_SIM_OK;
    int finite = 1;
    int i;
    for (i = 0; i < N; ++i) {
        s[i] = fz_double(r);
        finite = finite && isfinite(s[i]);
    }
    force = fz_double(r);
    memcpy(before, s, sizeof s);
    step = icoac_sim_plant_step(&su->plant, s, force);
    if (!plant_ok) {
        FZ_CHECK(step == ICOAC_SIM_ERR_BAD_PLANT, "plant_step of a plant the check refuses: status %d", (int)step);
    } else if (!finite || !isfinite(force)) {
        FZ_CHECK(step == ICOAC_SIM_ERR_NONFINITE, "plant_step of a non-finite state or force: status %d", (int)step);
    } else {
        FZ_CHECK(step == ICOAC_SIM_OK || step == ICOAC_SIM_ERR_NONFINITE, "plant_step: status %d", (int)step);
    }
    if (step == ICOAC_SIM_OK) {
        for (i = 0; i < N; ++i) {
            FZ_CHECK(isfinite(s[i]), "plant_step returned OK with a non-finite state");
        }
    } else {
        FZ_CHECK(memcmp(before, s, sizeof s) == 0, "a refused plant_step changed the state");
    }
    FZ_CHECK(icoac_sim_plant_step(0, s, force) == ICOAC_SIM_ERR_BAD_ARGUMENT, "plant_step(NULL plant)");
    FZ_CHECK(icoac_sim_plant_step(&su->plant, 0, force) == ICOAC_SIM_ERR_BAD_ARGUMENT, "plant_step(NULL state)");
    FZ_CHECK(icoac_sim_failed(0, s) == ICOAC_SIM_ERR_BAD_ARGUMENT, "icoac_sim_failed(NULL plant)");
    FZ_CHECK(icoac_sim_failed(&su->plant, 0) == ICOAC_SIM_ERR_BAD_ARGUMENT, "icoac_sim_failed(NULL state)");
    failed = icoac_sim_failed(&su->plant, s);
    if (plant_ok) {
        FZ_CHECK(failed == failed_reference(&su->plant, s), "icoac_sim_failed(%g, %g, %g, %g) = %d", s[0], s[1], s[2],
                 s[3], (int)failed);
    } else {
        FZ_CHECK(failed == ICOAC_SIM_ERR_BAD_PLANT, "icoac_sim_failed of a plant the check refuses: %d", (int)failed);
    }
}

static void op_cell(fz_reader_t *r, setup_t *su)
{
    icoac_sim_cell_t cell;
    icoac_sim_cell_t given;
    int32_t status;
    memset(&cell, 0, sizeof cell);
    cell.x0 = fz_double(r);
    cell.theta0 = fz_double(r);
    cell.seed = fz_u8(r);
    if (!fz_charge(&su->budget, &su->run, 1)) {
        return;
    }
    given = cell;
    status = icoac_sim_run_cell(&su->cfg, &su->plant, &su->run, su->prior, &cell, 0, 0);
    FZ_CHECK(fz_sim_status_known(status), "run_cell returned unknown status %d", (int)status);
    if (checks_fail(su, 1)) {
        FZ_CHECK(refused_as_expected(su, status, 1), "run_cell returned %d (%s) though a check failed with %d",
                 (int)status, icoac_sim_status_str(status), (int)su->failing[0]);
        return;
    }
    if (!isfinite(given.x0) || !isfinite(given.theta0)) {
        FZ_CHECK(status == ICOAC_SIM_ERR_BAD_ARGUMENT, "run_cell(x0 %g, theta0 %g) returned %d", given.x0,
                 given.theta0, (int)status);
        return;
    }
    if (su->prior_status != ICOAC_OK) {
        FZ_CHECK(status == su->prior_status, "run_cell with a bad prior returned %d", (int)status);
        return;
    }
    FZ_CHECK(status == ICOAC_SIM_OK, "run_cell returned %d (%s) for a valid setup", (int)status,
             icoac_sim_status_str(status));
    FZ_CHECK(cell.x0 == given.x0 && cell.theta0 == given.theta0 && cell.seed == given.seed,
             "run_cell changed the cell's inputs");
    fz_check_finished_cell(&su->run, su->plant.dt, &cell, "run_cell");
}

static void op_grid(fz_reader_t *r, setup_t *su)
{
    icoac_sim_cell_t cells[FZ_SIM_MAX_CELLS];
    icoac_sim_cell_t given[FZ_SIM_MAX_CELLS];
    int preset[FZ_SIM_MAX_CELLS];
    const uint8_t count = fz_u8(r);
    const int n = count % 32 == 31 ? 0 : 1 + count % FZ_SIM_MAX_CELLS;
    const int32_t threads = fz_threads(r);
    int all_finite = 1;
    int pending = 0;
    int32_t status;
    int i;
    memset(cells, 0, sizeof cells);
    for (i = 0; i < n; ++i) {
        cells[i].x0 = fz_double(r);
        cells[i].theta0 = fz_double(r);
        cells[i].seed = fz_u8(r);
        preset[i] = fz_u8(r) % 4 == 3;
        if (preset[i]) {
            /* A finished cell, recognisable by its fields: the grid must skip it. */
            cells[i].outcome = ICOAC_SIM_SUCCESS;
            cells[i].trials = 7;
            cells[i].weights[0] = (double)NAN;
        } else {
            ++pending;
        }
        all_finite = all_finite && isfinite(cells[i].x0) && isfinite(cells[i].theta0);
    }
    if (!fz_charge(&su->budget, &su->run, pending)) {
        return;
    }
    memcpy(given, cells, sizeof cells);
    status = icoac_sim_run_grid(&su->cfg, &su->plant, &su->run, su->prior, cells, n, threads, 0, 0);
    FZ_CHECK(fz_sim_status_known(status), "run_grid returned unknown status %d", (int)status);
    if (status != ICOAC_SIM_OK) {
        FZ_CHECK(memcmp(cells, given, sizeof cells) == 0, "run_grid returned %d (%s) but changed cells",
                 (int)status, icoac_sim_status_str(status));
    }
    if (checks_fail(su, 1)) {
        FZ_CHECK(refused_as_expected(su, status, 1), "run_grid returned %d (%s) though a check failed with %d",
                 (int)status, icoac_sim_status_str(status), (int)su->failing[0]);
        return;
    }
    if (n == 0 || threads < 0 || !all_finite) {
        FZ_CHECK(status == ICOAC_SIM_ERR_BAD_ARGUMENT, "run_grid(%d cells, %d threads, finite %d) returned %d", n,
                 (int)threads, all_finite, (int)status);
        return;
    }
    if (su->prior_status != ICOAC_OK) {
        FZ_CHECK(status == su->prior_status, "run_grid with a bad prior returned %d", (int)status);
        return;
    }
    FZ_CHECK(status == ICOAC_SIM_OK || status == ICOAC_SIM_ERR_THREAD, "run_grid returned %d (%s) for a valid setup",
             (int)status, icoac_sim_status_str(status));
    if (status != ICOAC_SIM_OK) {
        return;
    }
    for (i = 0; i < n; ++i) {
        if (preset[i]) {
            FZ_CHECK(memcmp(&cells[i], &given[i], sizeof cells[i]) == 0, "run_grid reran finished cell %d", i);
        } else {
            fz_check_finished_cell(&su->run, su->plant.dt, &cells[i], "run_grid");
        }
    }
}

static void op_trajectory(fz_reader_t *r, const setup_t *su)
{
    double states[(FZ_TRAJ_MAX_STEPS + 1) * N];
    double forces[FZ_TRAJ_MAX_STEPS];
    const double x0 = fz_double(r);
    const double theta0 = fz_double(r);
    const double noise = fz_double(r);
    const uint64_t seed = fz_u8(r);
    const int64_t max_steps = (int64_t)(fz_u8(r) % (FZ_TRAJ_MAX_STEPS + 2)) - 1;
    int64_t n_steps = -7;
    int32_t status;
    int64_t k;
    int i;
    for (k = 0; k < (FZ_TRAJ_MAX_STEPS + 1) * N; ++k) {
        states[k] = (double)NAN;
    }
    for (k = 0; k < FZ_TRAJ_MAX_STEPS; ++k) {
        forces[k] = (double)NAN;
    }
    status = icoac_sim_trajectory(&su->cfg, &su->plant, su->prior, x0, theta0, noise, seed, max_steps, states,
                                  forces, &n_steps);
    FZ_CHECK(fz_sim_status_known(status), "trajectory returned unknown status %d", (int)status);
    if (checks_fail(su, 0)) {
        FZ_CHECK(refused_as_expected(su, status, 0), "trajectory returned %d though a check failed with %d",
                 (int)status, (int)su->failing[0]);
        return;
    }
    if (max_steps < 1 || !isfinite(x0) || !isfinite(theta0) || !isfinite(noise) || noise < 0.0) {
        FZ_CHECK(status == ICOAC_SIM_ERR_BAD_ARGUMENT, "trajectory(max_steps %lld, x0 %g, theta0 %g, noise %g) "
                 "returned %d", (long long)max_steps, x0, theta0, noise, (int)status);
        return;
    }
    if (status == ICOAC_SIM_ERR_BAD_ARGUMENT || (su->prior_status != ICOAC_OK && status == su->prior_status)) {
        return; /* a noise outside the documented minimum, or the bad prior */
    }
    FZ_CHECK(su->prior_status == ICOAC_OK, "trajectory with a bad prior returned %d", (int)status);
    FZ_CHECK(status < 100, "trajectory returned %d (%s) for a valid setup", (int)status,
             icoac_sim_status_str(status));
    FZ_CHECK(n_steps >= 0 && n_steps <= max_steps, "trajectory: n_steps %lld of max_steps %lld", (long long)n_steps,
             (long long)max_steps);
    for (k = 0; k <= n_steps; ++k) {
        const double *s = states + 4 * k;
        int finite = 1;
        for (i = 0; i < N; ++i) {
            finite = finite && isfinite(s[i]);
        }
        if (k == n_steps && k > 0) {
            FZ_CHECK(finite || icoac_sim_failed(&su->plant, s),
                     "trajectory: final state %lld not finite and not failed", (long long)k);
            if (status == ICOAC_SIM_OK && n_steps < max_steps) {
                FZ_CHECK(icoac_sim_failed(&su->plant, s), "trajectory stopped at %lld of %lld without a failure",
                         (long long)n_steps, (long long)max_steps);
            }
        } else {
            FZ_CHECK(finite, "trajectory: state %lld of %lld not finite", (long long)k, (long long)n_steps);
            FZ_CHECK(k == 0 || !icoac_sim_failed(&su->plant, s), "trajectory ran on past the failure at %lld",
                     (long long)k);
        }
        if (k < n_steps) {
            FZ_CHECK(isfinite(forces[k]), "trajectory: force %lld is %g", (long long)k, forces[k]);
        }
    }
}

static void op_paper_grid(fz_reader_t *r)
{
    static const int64_t sizes[8] = {0, -1, 1, ICOAC_SIM_GRID_CELLS - 1, ICOAC_SIM_GRID_CELLS + 1, INT64_MAX,
                                     INT64_MIN, ICOAC_SIM_GRID_CELLS};
    const uint8_t b = fz_u8(r);
    const int64_t n = sizes[b % 8];
    const int null_cells = (b & 0x80u) != 0u;
    icoac_sim_cell_t *cells = null_cells ? 0 : (icoac_sim_cell_t *)calloc(ICOAC_SIM_GRID_CELLS, sizeof *cells);
    int32_t status;
    int64_t i;
    FZ_CHECK(null_cells || cells != 0, "out of memory");
    status = icoac_sim_paper_grid(cells, n, 5u);
    if (null_cells || n != ICOAC_SIM_GRID_CELLS) {
        FZ_CHECK(status == ICOAC_SIM_ERR_BAD_ARGUMENT, "paper_grid(%s, %lld) returned %d",
                 null_cells ? "NULL" : "cells", (long long)n, (int)status);
    } else {
        FZ_CHECK(status == ICOAC_SIM_OK, "paper_grid returned %d", (int)status);
        for (i = 0; i < n; ++i) {
            FZ_CHECK(cells[i].outcome == ICOAC_SIM_PENDING && fabs(cells[i].x0) <= 2.4 + 1e-9 &&
                         fabs(cells[i].theta0) <= 0.21 && isfinite(cells[i].x0),
                     "paper_grid cell %lld: outcome %d x0 %g theta0 %g", (long long)i, (int)cells[i].outcome,
                     cells[i].x0, cells[i].theta0);
        }
    }
    free(cells);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    fz_reader_t r;
    setup_t su;
    int ops;
    fz_reader_init(&r, data, size);
    decode_setup(&r, &su);
    FZ_CHECK(icoac_sim_plant_check(0) == ICOAC_SIM_ERR_BAD_ARGUMENT &&
                 icoac_sim_run_check(0) == ICOAC_SIM_ERR_BAD_ARGUMENT,
             "a NULL check argument was not refused");
    for (ops = 0; ops < FZ_SIM_OPS && !fz_done(&r); ++ops) {
        const uint8_t op = fz_u8(&r);
        switch (op % 5) {
        case 0: op_plant(&r, &su); break;
        case 1: op_cell(&r, &su); break;
        case 2: op_grid(&r, &su); break;
        case 3: op_trajectory(&r, &su); break;
        default: op_paper_grid(&r); break;
        }
    }
    return 0;
}
