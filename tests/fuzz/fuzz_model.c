/* SPDX-License-Identifier: Apache-2.0 */
/* libFuzzer target of the sim API (icoac_sim.h): the plant registry, the model functions and the
 * benchmark runs on a model; linked with libicoac_sim.so.
 *
 * Input format, read front to back (a byte past the end reads as 0):
 *   model   mode byte m, plant byte p (registry plant p % icoac_sim_plant_count). m % 4: 1: the
 *           sizeof(icoac_sim_model_t) raw bytes laid over icoac_sim_model_default of plant p;
 *           3: a NULL model; 0, 2: that default with (m >> 2) % 8 mutations, each a field byte
 *           (% 35: 0 plant, 1 integrator as int32; 2 dt, 3-18 param[f - 3] as doubles;
 *           19-34 param[f - 19] set to a bound of plant p's range by a byte b % 4: min, max,
 *           the double below min, the double above max; past n_params: -0, 0, DBL_TRUE_MIN,
 *           -DBL_TRUE_MIN).
 *   ops     at most FZ_MODEL_OPS, until the input ends. Op byte o; o in [0x80, 0xC0): a run op
 *           (below); else o & 7:
 *           0 step      6 doubles state, 1 double u: icoac_sim_model_step.
 *           1 deriv     6 doubles state, 1 double u: icoac_sim_model_derivatives.
 *           2 failed    6 doubles state: icoac_sim_model_failed.
 *           3 energy    6 doubles state: icoac_sim_model_energy.
 *           4 start     cell x0, theta0 (doubles), cell seed byte, noise (double), rng seed byte
 *                       (icoac_rng_seed with ICOAC_SIM_START_STREAM): icoac_sim_model_start.
 *           5 grid      index (int32), size byte c (c % 8: the plant's rows.count * cols.count
 *                       (the cart-pole's for a bad index), 0, -1, that - 1, that + 1, INT64_MAX,
 *                       INT64_MIN, 1; c & 128: NULL cells), seed byte: icoac_sim_plant_grid.
 *           6 registry  index (int32): icoac_sim_plant_info, icoac_sim_model_default; name
 *                       selector byte k % 4: 0 NULL, 1 the name of plant (byte % count),
 *                       2 that name less its last character, 3 a length byte (% 24) and that
 *                       many bytes: icoac_sim_plant_find.
 *           7 lanes     lane count byte (% 5), then per lane 6 doubles state, 1 double u and an
 *                       ended byte (% 3: 0, 1, -5): icoac_sim_model_step_lanes, each lane
 *                       against icoac_sim_model_step and _failed on a copy of its state.
 *           o >= 0xC0: NULL pointers, bit 3 the state array, bit 4 the output (ds, failed,
 *           energy; start: the cell; lanes: u), bit 5 the rng (lanes: ended).
 *           A state's entries past the plant's n_state are replaced by a canary.
 *   run ops o & 3, on the model; o & 0x20: NULL pointers, bit 2 the configuration, bit 3 the
 *           cell / cells / trajectory states, bit 4 the run / trajectory forces.
 *           0 cell      run, config, prior sections, cell spec: icoac_sim_run_cell.
 *           1 grid      run, config, prior sections, count byte (1 + n % 4 cells; n % 32 == 31:
 *                       0 cells), threads byte (% 16: 13-14 two threads, 15 -1, else 1), a cell
 *                       spec per cell: icoac_sim_run_grid.
 *           2 traj      config, prior sections, cell spec (x0, theta0, seed), noise (double),
 *                       steps byte b (max_steps = (b & 127) % 66 - 1; b & 128: NULL n_steps):
 *                       icoac_sim_trajectory.
 *           3 cancel    as grid, with the cancel flag raised.
 *           run section: a mode byte b; b odd: the raw bytes of icoac_sim_run_t over
 *           icoac_sim_run_default; b even: (b >> 1) % 4 mutations, each a field byte (% 3:
 *           0 max_trials, 1 success_steps as int64; 2 init_velocity_noise as double) and a value
 *           (fz_run); then max_trials clamped to <= 3 and success_steps to <= 300. Config and
 *           prior as in fuzz_controller.c (float controller). Cell spec: kind byte k; k & 1 == 0:
 *           seed byte and 2 bytes i (little endian), cell i % size of icoac_sim_plant_grid of
 *           plant p with that seed; k & 1 == 1: x0, theta0 (doubles), seed byte. (k >> 1) & 3
 *           (grid ops): 0 PENDING, else a finished cell preset with outcome SUCCESS, FAILED, ERROR
 *           (recognisable fields) that the grid must keep. The run ops of one input run at most
 *           FZ_SIM_TICK_BUDGET controller ticks in cells and grids; refused calls are not charged.
 *   value   double: selector byte k % 40. k < 28: special value (table in fuzz_input.c: 0, -0,
 *           1e-310, DBL_TRUE_MIN, DBL_MIN, DBL_MAX, 1e300, 1e30, NaN, +Inf, -Inf, -1, 1, 0.5,
 *           -1e30, 1e-20, -DBL_MAX, 2, 0.25, 2.4, -2.4, 9.8, 0.01, 1e-6, 1e6, 0.1, 1e-39, 3.2);
 *           28-35: int16 (2 bytes) / 32768 * {1e-3, ..., 1e4}[k - 28]; 36-39: 8 raw bytes.
 *           int64: selector % 12: 0, 1, 2, 3, -1, 300, 1000, 100000, INT64_MAX, INT64_MIN, 10,
 *           11 = 8 raw bytes. int32: selector % 8: 0, 1, 2, -1, INT32_MAX, INT32_MIN, 3, 7 = 4 raw bytes.
 *
 * Contract (abort on violation): statuses are known (icoac_sim_status_str not "unknown");
 * icoac_sim_model_check accepts exactly the documented models (registry plant, Euler or RK4, dt
 * in [1e-6, 1], each parameter 0 or normal inside its range, unused ones 0), and
 * icoac_sim_run_check refuses a NULL run with ICOAC_SIM_ERR_BAD_ARGUMENT. A refused model is
 * refused by step, derivatives, failed, energy and start with the check's status. Every call
 * that does not return OK leaves its state and outputs bitwise untouched; the state-taking
 * calls read and write only the plant's n_state entries (each runs twice, with a NaN and with a
 * finite canary past them, and must agree). With an accepted model: a NULL pointer or a plant
 * without energy is ICOAC_SIM_ERR_BAD_ARGUMENT (or NONFINITE when the input is not finite too);
 * a non-finite state or u is NONFINITE; step and derivatives return OK with finite values or
 * NONFINITE, and an OK Euler step is s + dt * derivatives (within a rounding); failed is OK
 * with 0 or 1, 1 for a non-finite state, and the cart-pole's is its definition (outside |x| <=
 * x_limit and |theta| <= theta_limit, or not finite); energy is OK and finite or NONFINITE; start
 * refuses a non-finite cell or a negative or non-finite noise, accepts the documented noises (0,
 * [1e-12, 1e3]), and gives the swept components from the cell, start[] elsewhere and drawn
 * components with |v| <= noise. The grid is OK exactly for a registry plant, non-NULL cells and
 * n_cells = rows.count * cols.count, then fills them with the sweeps' values, PENDING outcomes
 * and the seeds icoac_mix_seed(seed, i), the other fields 0; the cart-pole's is the paper's grid
 * (theta0 = -12 ... 12 deg, x0 = -2.4 ... 2.4 m); info is NULL exactly out of range;
 * model_default gives the documented default; every plant parameter has the tier "essential" or
 * "advanced" and a one-line doc; find returns the plant of that name or -1.
 *
 * Run ops: a call refused returns the status of the first failing check, in order: a NULL
 * configuration or model (ICOAC_SIM_ERR_BAD_ARGUMENT), the configuration check, the model check,
 * the observation fit (a plant whose n_state is not the task's n_inputs is
 * ICOAC_SIM_ERR_BAD_PLANT), the run check (cells and grids; a NULL run is BAD_ARGUMENT), then the
 * arguments (NULL cell(s) or outputs, no cells, negative threads, a non-finite x0 or theta0 in
 * any cell, max_steps < 1, a noise not 0 or in [1e-12, 1e3]: all BAD_ARGUMENT), then
 * icoac_prior_check of the prior; and it leaves the cells, states, forces and n_steps bitwise
 * untouched. An accepted cell or grid returns OK (a grid also ICOAC_SIM_ERR_THREAD, its cells
 * untouched), every run cell ends SUCCESS, FAILED or ERROR with its inputs kept and counts that
 * fit the outcome (fz_check_finished_cell: trials in [1, max_trials] unless ERROR, total_steps >=
 * last_trial_steps, elapsed_time == dt * total_steps exactly), and a non-ERROR cell has status OK
 * and finite weights and cov; a finished cell given to the grid is kept bitwise. With the cancel
 * flag raised an accepted grid returns ICOAC_SIM_CANCELLED (OK when no cell is pending), finished
 * cells kept and the others PENDING. An accepted trajectory returns OK or a controller status
 * (< 100) with n_steps in [0, max_steps]; its first row is icoac_sim_model_start of the cell (rng
 * seeded with icoac_rng_seed(seed, ICOAC_SIM_START_STREAM)), rows of n_state values; no row
 * before the last is failed or non-finite, an OK trajectory shorter than max_steps ends failed,
 * forces are finite, and nothing past n_steps is written (exact heap blocks for ASan).
 */
#include <float.h>
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "fuzz_check.h"
#include "fuzz_input.h"
#include "icoac_sim/icoac_sim.h"

#define FZ_MODEL_OPS 16
#define MAXS ICOAC_SIM_MAX_STATE
#define FZ_MODEL_FIELDS (3 + 2 * ICOAC_SIM_MAX_PARAMS)
#define FZ_NAME_MAX 24

/* Op kinds (op byte (o & 7) % OP_KINDS) and NULL-pointer bits of the op byte. */
enum { OP_STEP, OP_DERIVATIVES, OP_FAILED, OP_ENERGY, OP_START, OP_GRID, OP_REGISTRY, OP_LANES, OP_KINDS };
#define NULL_STATE 0x08u
#define NULL_OUT 0x10u
#define NULL_RNG 0x20u

#define FAILED_CANARY (-7)

/* Run ops: op bytes RUN_OP..0xBF, kind o & 3; with RUN_NULLS, NULL pointers by bits. */
#define RUN_OP 0x80u
enum { OP_RUN_CELL, OP_RUN_GRID, OP_RUN_TRAJECTORY, OP_RUN_CANCELLED };
#define RUN_NULLS 0x20u
#define NULL_CFG 0x04u
#define NULL_CELLS 0x08u /* the cell, the cells, the trajectory's states */
#define NULL_RUN 0x10u   /* the run, the trajectory's forces */
#define FZ_MODEL_MAX_CELLS 4
#define FZ_TRAJ_MAX_STEPS 64

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

typedef struct {
    icoac_sim_model_t storage;
    const icoac_sim_model_t *model;     /* NULL in mode 3 */
    int32_t check;                      /* icoac_sim_model_check(model) */
    const icoac_sim_plant_desc_t *desc; /* the plant of an accepted model, else NULL */
    int n;                              /* state entries the model uses: n_state, MAXS if refused */
    int32_t index;                      /* the plant byte's registry plant: run ops' grid cells */
    int64_t budget;                     /* controller ticks left for the run ops' cells and grids */
} setup_t;

/* One state-taking call: its status and the arrays after it. */
typedef struct {
    int32_t status;
    double s[MAXS];
    double out[MAXS]; /* ds; energy in out[0] */
    int32_t failed;
} call_t;

/* Canaries past n_state: a NaN with a payload (reading it makes the state non-finite) and a
 * finite value (reading it changes the result). */
static double canary(int finite)
{
    const uint64_t bits = 0x7FF8C0A5C0A5C0A5ull;
    double v;
    if (finite) {
        return 12345.678;
    }
    memcpy(&v, &bits, sizeof v);
    return v;
}

static int same(const double *a, const double *b, int n)
{
    return memcmp(a, b, (size_t)n * sizeof a[0]) == 0;
}

/* entries [from, MAXS) of v equal fill bitwise */
static int tail_is(const double *v, int from, double fill)
{
    int i;
    for (i = from; i < MAXS; ++i) {
        if (memcmp(&v[i], &fill, sizeof fill) != 0) {
            return 0;
        }
    }
    return 1;
}

/* The documented valid models (icoac_sim_model_check, icoac_sim_param_t). */
static int model_documented(const icoac_sim_model_t *m)
{
    const icoac_sim_plant_desc_t *d;
    int i;
    if (m->plant < 0 || m->plant >= icoac_sim_plant_count() ||
        !(m->dt >= ICOAC_SIM_DT_MIN && m->dt <= ICOAC_SIM_DT_MAX) ||
        (m->integrator != ICOAC_SIM_EULER && m->integrator != ICOAC_SIM_RK4)) {
        return 0;
    }
    d = icoac_sim_plant_info(m->plant);
    for (i = 0; i < ICOAC_SIM_MAX_PARAMS; ++i) {
        const double v = m->param[i];
        if (i < d->n_params ? !((v == 0.0 || isnormal(v)) && v >= d->params[i].min && v <= d->params[i].max)
                            : v != 0.0) {
            return 0;
        }
    }
    return 1;
}

/* What the target relies on in a descriptor: state and parameter counts, sweep components. */
static void check_desc(const icoac_sim_plant_desc_t *d)
{
    FZ_CHECK(d->name != 0 && d->n_state >= 1 && d->n_state <= MAXS && d->n_params >= 0 &&
                 d->n_params <= ICOAC_SIM_MAX_PARAMS && (d->n_params == 0 || d->params != 0) &&
                 d->rows.component >= 0 && d->rows.component < d->n_state && d->cols.component >= 0 &&
                 d->cols.component < d->n_state && d->rows.component != d->cols.component &&
                 !d->drawn[d->rows.component] && !d->drawn[d->cols.component] && d->rows.count >= 0 &&
                 d->cols.count >= 0 && d->step != 0 &&
                 d->derivatives != 0 && d->failed != 0,
             "descriptor %s: n_state %d n_params %d rows %d x %d cols %d x %d", d->name != 0 ? d->name : "(null)",
             (int)d->n_state, (int)d->n_params, (int)d->rows.component, (int)d->rows.count, (int)d->cols.component,
             (int)d->cols.count);
}

/* A bound of parameter i of d, or a value about 0 for an unused parameter. */
static double param_bound(const icoac_sim_plant_desc_t *d, int i, int b)
{
    if (i >= d->n_params) {
        static const double near_zero[4] = {-0.0, 0.0, DBL_TRUE_MIN, -DBL_TRUE_MIN};
        return near_zero[b];
    }
    switch (b) {
    case 0: return d->params[i].min;
    case 1: return d->params[i].max;
    case 2: return nextafter(d->params[i].min, -(double)INFINITY);
    default: return nextafter(d->params[i].max, (double)INFINITY);
    }
}

static void decode_model(fz_reader_t *r, setup_t *su)
{
    const uint8_t mode = fz_u8(r);
    const int32_t index = fz_u8(r) % icoac_sim_plant_count();
    const icoac_sim_plant_desc_t *d = icoac_sim_plant_info(index);
    int32_t status;
    int n;
    check_desc(d);
    status = icoac_sim_model_default(&su->storage, index);
    FZ_CHECK(status == ICOAC_SIM_OK, "model_default(%d) returned %d", (int)index, (int)status);
    su->model = &su->storage;
    if (mode % 4 == 1) {
        fz_overlay(r, &su->storage, sizeof su->storage);
    } else if (mode % 4 == 3) {
        su->model = 0;
    } else {
        for (n = (mode >> 2) % 8; n > 0; --n) {
            const int field = fz_u8(r) % FZ_MODEL_FIELDS;
            if (field == 0) {
                su->storage.plant = fz_i32(r);
            } else if (field == 1) {
                su->storage.integrator = fz_i32(r);
            } else if (field == 2) {
                su->storage.dt = fz_double(r);
            } else if (field < 3 + ICOAC_SIM_MAX_PARAMS) {
                su->storage.param[field - 3] = fz_double(r);
            } else {
                const int i = field - 3 - ICOAC_SIM_MAX_PARAMS;
                su->storage.param[i] = param_bound(d, i, fz_u8(r) % 4);
            }
        }
    }
    su->check = icoac_sim_model_check(su->model);
    FZ_CHECK(fz_sim_status_known(su->check), "model_check returned unknown status %d", (int)su->check);
    su->desc = 0;
    su->n = MAXS;
    su->index = index;
    su->budget = FZ_SIM_TICK_BUDGET;
    if (su->model == 0) {
        FZ_CHECK(su->check == ICOAC_SIM_ERR_BAD_ARGUMENT, "model_check(NULL) returned %d", (int)su->check);
        return;
    }
    FZ_CHECK(su->check == ICOAC_SIM_OK || su->check == ICOAC_SIM_ERR_BAD_PLANT, "model_check returned %d",
             (int)su->check);
    FZ_CHECK((su->check == ICOAC_SIM_OK) == model_documented(su->model),
             "model_check returned %d for plant %d integrator %d dt %g param %g %g %g %g ... (documented: %d)",
             (int)su->check, (int)su->model->plant, (int)su->model->integrator, su->model->dt, su->model->param[0],
             su->model->param[1], su->model->param[2], su->model->param[3], model_documented(su->model));
    if (su->check == ICOAC_SIM_OK) {
        su->desc = icoac_sim_plant_info(su->model->plant);
        check_desc(su->desc);
        su->n = su->desc->n_state;
    }
}

/* Parameter name of the model's plant (abort when it has none). */
static double param_named(const icoac_sim_model_t *m, const char *name)
{
    const icoac_sim_plant_desc_t *d = icoac_sim_plant_info(m->plant);
    int i;
    for (i = 0; i < d->n_params && strcmp(d->params[i].name, name) != 0; ++i) {
    }
    FZ_CHECK(i < d->n_params, "plant %s has no parameter %s", d->name, name);
    return m->param[i];
}

/* The cart-pole's failure test, as defined: outside the closed limits, or not finite. */
static int cart_pole_failed(const icoac_sim_model_t *m, const double s[4])
{
    const double x_limit = param_named(m, "x_limit");
    const double theta_limit = param_named(m, "theta_limit");
    return !(fabs(s[0]) <= x_limit && fabs(s[2]) <= theta_limit && isfinite(s[1]) && isfinite(s[3]));
}

/* A state-taking call (step, derivatives, failed, energy) on s0's first n entries, fill past
 * them and in the outputs. */
static void call_state(int op, const setup_t *su, const double *s0, double u, double fill, unsigned nulls,
                       call_t *c)
{
    double *s = (nulls & NULL_STATE) ? 0 : c->s;
    const int null_out = (nulls & NULL_OUT) != 0;
    int i;
    for (i = 0; i < MAXS; ++i) {
        c->s[i] = i < su->n ? s0[i] : fill;
        c->out[i] = fill;
    }
    c->failed = FAILED_CANARY;
    switch (op) {
    case OP_STEP: c->status = icoac_sim_model_step(su->model, s, u); break;
    case OP_DERIVATIVES: c->status = icoac_sim_model_derivatives(su->model, s, u, null_out ? 0 : c->out); break;
    case OP_FAILED: c->status = icoac_sim_model_failed(su->model, s, null_out ? 0 : &c->failed); break;
    default: c->status = icoac_sim_model_energy(su->model, s, null_out ? 0 : c->out); break;
    }
}

static const char *const op_names[] = {"step", "derivatives", "failed", "energy"};

/* An OK Euler step is s0 + dt * ds(s0) (within a rounding, for a fused multiply-add). */
static void check_euler(const setup_t *su, const double *s0, double u, const double *s1)
{
    double ds[MAXS];
    const double dt = su->model->dt;
    const int32_t status = icoac_sim_model_derivatives(su->model, s0, u, ds);
    int i;
    FZ_CHECK(status == ICOAC_SIM_OK, "an Euler step was OK, its derivatives returned %d", (int)status);
    for (i = 0; i < su->n; ++i) {
        const double want = s0[i] + dt * ds[i];
        FZ_CHECK(fabs(s1[i] - want) <= 2.0 * DBL_EPSILON * (fabs(s0[i]) + fabs(dt * ds[i])) + 2.0 * DBL_TRUE_MIN,
                 "Euler step: component %d is %.17g, s + dt ds %.17g", i, s1[i], want);
    }
}

/* Step, derivatives, failed or energy, twice (NaN and finite canaries), against the contract. */
static void op_state(fz_reader_t *r, const setup_t *su, int op, unsigned nulls)
{
    const char *what = op_names[op];
    const int n_out = op == OP_DERIVATIVES ? su->n : (op == OP_ENERGY ? 1 : 0);
    double s0[MAXS];
    double u = 0.0;
    call_t a;
    call_t b;
    int nonfinite;
    int untouched;
    int i;
    for (i = 0; i < MAXS; ++i) {
        s0[i] = fz_double(r);
    }
    if (op == OP_STEP || op == OP_DERIVATIVES) {
        u = fz_double(r);
    }
    call_state(op, su, s0, u, canary(0), nulls, &a);
    call_state(op, su, s0, u, canary(1), nulls, &b);
    FZ_CHECK(fz_sim_status_known(a.status), "%s returned unknown status %d", what, (int)a.status);
    FZ_CHECK(a.status == b.status && same(a.s, b.s, su->n) && a.failed == b.failed &&
                 (a.status != ICOAC_SIM_OK || same(a.out, b.out, n_out)),
             "%s: the entries past n_state %d changed the result (status %d / %d)", what, su->n, (int)a.status,
             (int)b.status);
    FZ_CHECK(tail_is(a.s, su->n, canary(0)) && tail_is(b.s, su->n, canary(1)) &&
                 tail_is(a.out, n_out, canary(0)) && tail_is(b.out, n_out, canary(1)),
             "%s wrote past n_state %d or its output", what, su->n);
    untouched = same(a.s, s0, su->n) && tail_is(a.out, 0, canary(0)) && tail_is(b.out, 0, canary(1)) &&
                a.failed == FAILED_CANARY;
    if (a.status != ICOAC_SIM_OK) {
        FZ_CHECK(untouched, "%s returned %d (%s) but wrote its state or output", what, (int)a.status,
                 icoac_sim_status_str(a.status));
    }
    if (su->check != ICOAC_SIM_OK) {
        FZ_CHECK(a.status == su->check, "%s returned %d for a model the check refused with %d", what,
                 (int)a.status, (int)su->check);
        return;
    }
    nonfinite = !fz_all_finite_double(s0, su->n) || ((op == OP_STEP || op == OP_DERIVATIVES) && !isfinite(u));
    if ((nulls & NULL_STATE) || ((nulls & NULL_OUT) && op != OP_STEP) ||
        (op == OP_ENERGY && su->desc->energy == 0)) {
        FZ_CHECK(a.status == ICOAC_SIM_ERR_BAD_ARGUMENT || (nonfinite && a.status == ICOAC_SIM_ERR_NONFINITE),
                 "%s with a NULL pointer or no energy function returned %d", what, (int)a.status);
        return;
    }
    if (op == OP_FAILED) {
        FZ_CHECK(a.status == ICOAC_SIM_OK && (a.failed == 0 || a.failed == 1) && (a.failed == 1 || !nonfinite),
                 "failed returned %d, *failed %d (state finite: %d)", (int)a.status, (int)a.failed, !nonfinite);
        FZ_CHECK(same(a.s, s0, su->n), "failed changed the state");
        FZ_CHECK(su->model->plant != ICOAC_SIM_CART_POLE || a.failed == cart_pole_failed(su->model, s0),
                 "the cart-pole's failed(%g, %g, %g, %g) is %d", s0[0], s0[1], s0[2], s0[3], (int)a.failed);
        return;
    }
    if (nonfinite) {
        FZ_CHECK(a.status == ICOAC_SIM_ERR_NONFINITE, "%s of a non-finite state or u %g returned %d", what, u,
                 (int)a.status);
        return;
    }
    FZ_CHECK(a.status == ICOAC_SIM_OK || a.status == ICOAC_SIM_ERR_NONFINITE, "%s returned %d (%s)", what,
             (int)a.status, icoac_sim_status_str(a.status));
    if (a.status != ICOAC_SIM_OK) {
        return;
    }
    if (op == OP_STEP) {
        FZ_CHECK(fz_all_finite_double(a.s, su->n), "step returned OK with a non-finite state");
        if (su->model->integrator == ICOAC_SIM_EULER) {
            check_euler(su, s0, u, a.s);
        }
    } else {
        FZ_CHECK(same(a.s, s0, su->n), "%s changed the state", what);
        FZ_CHECK(fz_all_finite_double(a.out, n_out), "%s returned OK with non-finite output", what);
    }
}

static void call_start(const setup_t *su, const icoac_sim_cell_t *cell, double noise, uint64_t rng_seed,
                       double fill, unsigned nulls, call_t *c)
{
    icoac_rng_t rng;
    int i;
    icoac_rng_seed(&rng, rng_seed, ICOAC_SIM_START_STREAM);
    for (i = 0; i < MAXS; ++i) {
        c->s[i] = fill;
    }
    c->status = icoac_sim_model_start(su->model, (nulls & NULL_OUT) ? 0 : cell, noise, (nulls & NULL_RNG) ? 0 : &rng,
                                      (nulls & NULL_STATE) ? 0 : c->s);
}

/* Op 7: icoac_sim_model_step_lanes over 0-4 lanes. A refused call leaves every lane as it was; an
 * accepted one leaves the lanes given as ended alone and gives each other lane what
 * icoac_sim_model_step and icoac_sim_model_failed give on a copy of it (ended = 1 when the step
 * is refused), and writes no entry past n_state. */
static void op_lanes(fz_reader_t *r, const setup_t *su, unsigned nulls)
{
    enum { LANES = 4 };
    static const int32_t ended_values[3] = {0, 1, -5};
    double states[LANES][MAXS], s0[LANES][MAXS], u[LANES];
    int32_t ended[LANES], ended0[LANES];
    const int lanes = fz_u8(r) % (LANES + 1);
    int32_t status;
    int i, k;
    for (i = 0; i < lanes; ++i) {
        for (k = 0; k < MAXS; ++k) {
            s0[i][k] = fz_double(r);
        }
        u[i] = fz_double(r);
        ended0[i] = ended_values[fz_u8(r) % 3];
    }
    memcpy(states, s0, sizeof states);
    memcpy(ended, ended0, sizeof ended);
    status = icoac_sim_model_step_lanes(su->model, (nulls & NULL_STATE) ? 0 : &states[0][0],
                                        (nulls & NULL_OUT) ? 0 : u, (nulls & NULL_RNG) ? 0 : ended, lanes);
    FZ_CHECK(fz_sim_status_known(status), "step_lanes returned unknown status %d", (int)status);
    if (su->check != ICOAC_SIM_OK || (lanes > 0 && (nulls & (NULL_STATE | NULL_OUT | NULL_RNG)))) {
        FZ_CHECK(status == (su->check != ICOAC_SIM_OK ? su->check : ICOAC_SIM_ERR_BAD_ARGUMENT),
                 "step_lanes returned %d (model check %d, nulls %u)", (int)status, (int)su->check, nulls);
        FZ_CHECK(memcmp(states, s0, sizeof states) == 0 && memcmp(ended, ended0, sizeof ended) == 0,
                 "step_lanes returned %d but changed a lane", (int)status);
        return;
    }
    FZ_CHECK(status == ICOAC_SIM_OK, "step_lanes of a valid model returned %d", (int)status);
    for (i = 0; i < lanes; ++i) {
        double ref[MAXS];
        int32_t failed = 1;
        memcpy(ref, s0[i], sizeof ref);
        if (ended0[i] == 0 && icoac_sim_model_step(su->model, ref, u[i]) == ICOAC_SIM_OK) {
            FZ_CHECK(icoac_sim_model_failed(su->model, ref, &failed) == ICOAC_SIM_OK, "failed refused a stepped state");
        }
        FZ_CHECK(ended[i] == (ended0[i] != 0 ? ended0[i] : failed) && memcmp(states[i], ref, sizeof ref) == 0,
                 "step_lanes lane %d: ended %d (given %d, expected %d) or its state differs", i, (int)ended[i],
                 (int)ended0[i], (int)failed);
    }
}

static void op_start(fz_reader_t *r, const setup_t *su, unsigned nulls)
{
    icoac_sim_cell_t cell;
    double noise;
    uint64_t rng_seed;
    call_t a;
    call_t b;
    int valid;
    int i;
    memset(&cell, 0, sizeof cell);
    cell.x0 = fz_double(r);
    cell.theta0 = fz_double(r);
    cell.seed = fz_u8(r);
    noise = fz_double(r);
    rng_seed = fz_u8(r);
    call_start(su, &cell, noise, rng_seed, canary(0), nulls, &a);
    call_start(su, &cell, noise, rng_seed, canary(1), nulls, &b);
    FZ_CHECK(fz_sim_status_known(a.status), "start returned unknown status %d", (int)a.status);
    FZ_CHECK(a.status == b.status, "start returned %d, then %d", (int)a.status, (int)b.status);
    if (a.status == ICOAC_SIM_OK) {
        FZ_CHECK(same(a.s, b.s, su->n) && tail_is(a.s, su->n, canary(0)) && tail_is(b.s, su->n, canary(1)),
                 "start: the state's entries past n_state %d written or read", su->n);
    } else {
        FZ_CHECK(tail_is(a.s, 0, canary(0)) && tail_is(b.s, 0, canary(1)), "start returned %d but wrote the state",
                 (int)a.status);
    }
    if (su->check != ICOAC_SIM_OK) {
        FZ_CHECK(a.status == su->check, "start returned %d for a model the check refused with %d", (int)a.status,
                 (int)su->check);
        return;
    }
    if (nulls & (NULL_STATE | NULL_OUT | NULL_RNG)) {
        FZ_CHECK(a.status == ICOAC_SIM_ERR_BAD_ARGUMENT, "start with a NULL pointer returned %d", (int)a.status);
        return;
    }
    if (!isfinite(cell.x0) || !isfinite(cell.theta0) || !isfinite(noise) || noise < 0.0) {
        FZ_CHECK(a.status != ICOAC_SIM_OK, "start accepted x0 %g theta0 %g noise %g", cell.x0, cell.theta0, noise);
        return;
    }
    valid = noise == 0.0 || (noise >= ICOAC_SIM_NOISE_MIN && noise <= ICOAC_SIM_NOISE_MAX);
    FZ_CHECK(a.status == ICOAC_SIM_OK || !valid, "start refused noise %g with %d", noise, (int)a.status);
    if (a.status != ICOAC_SIM_OK) {
        return;
    }
    for (i = 0; i < su->n; ++i) {
        const double v = a.s[i];
        if (i == su->desc->rows.component) {
            FZ_CHECK(memcmp(&v, &cell.theta0, sizeof v) == 0, "start: row component %d is %g, theta0 %g", i, v,
                     cell.theta0);
        } else if (i == su->desc->cols.component) {
            FZ_CHECK(memcmp(&v, &cell.x0, sizeof v) == 0, "start: column component %d is %g, x0 %g", i, v, cell.x0);
        } else if (su->desc->drawn[i]) {
            FZ_CHECK(fabs(v) <= noise, "start: drawn component %d is %g, noise %g", i, v, noise);
        } else {
            FZ_CHECK(memcmp(&v, &su->desc->start[i], sizeof v) == 0, "start: component %d is %g, start[] %g", i, v,
                     su->desc->start[i]);
        }
    }
}

/* Value i of a sweep, as documented: first + step * i, times pi / 180 in degrees. */
static double sweep_value(const icoac_sim_sweep_t *sweep, int64_t i)
{
    const double v = sweep->first + sweep->step * (double)i;
    return sweep->degrees ? v * ICOAC_SIM_PI / 180.0 : v;
}

static int close_to(double a, double b)
{
    return fabs(a - b) <= 1e-12 * (1.0 + fabs(b));
}

/* The paper's grid (method.md), the cart-pole's: row i is theta0 = (-12 + i) deg, column j is
 * x0 = -2.4 + 0.1 j m. */
#define PAPER_ROWS 25
#define PAPER_COLS 49

static int64_t grid_size(const icoac_sim_plant_desc_t *d)
{
    return (int64_t)d->rows.count * d->cols.count;
}

static void op_grid(fz_reader_t *r)
{
    const int32_t index = fz_i32(r);
    const uint8_t c = fz_u8(r);
    const uint64_t seed = fz_u8(r);
    const icoac_sim_plant_desc_t *d = icoac_sim_plant_info(index);
    const int64_t exact = grid_size(d != 0 ? d : icoac_sim_plant_info(ICOAC_SIM_CART_POLE));
    const int64_t sizes[8] = {exact, 0, -1, exact - 1, exact + 1, INT64_MAX, INT64_MIN, 1};
    const int64_t n = sizes[c % 8];
    const int null_cells = (c & 0x80u) != 0u;
    /* a heap block of exactly n cells when n is plausible, so ASan sees any overrun */
    const int64_t alloc = n >= 1 && n <= exact + 1 ? n : 1;
    icoac_sim_cell_t *cells = 0;
    icoac_sim_cell_t *given = 0;
    int32_t status;
    int64_t i;
    if (!null_cells) {
        cells = (icoac_sim_cell_t *)malloc((size_t)alloc * sizeof *cells);
        given = (icoac_sim_cell_t *)malloc((size_t)alloc * sizeof *given);
        FZ_CHECK(cells != 0 && given != 0, "out of memory");
        memset(cells, 0xA5, (size_t)alloc * sizeof *cells);
        memcpy(given, cells, (size_t)alloc * sizeof *cells);
    }
    status = icoac_sim_plant_grid(index, cells, n, seed);
    FZ_CHECK(fz_sim_status_known(status), "plant_grid returned unknown status %d", (int)status);
    if (d == 0 || null_cells || n != exact) {
        FZ_CHECK(status != ICOAC_SIM_OK && (d == 0 || status == ICOAC_SIM_ERR_BAD_ARGUMENT),
                 "plant_grid(%d, %s, %lld of %lld) returned %d", (int)index, null_cells ? "NULL" : "cells",
                 (long long)n, (long long)exact, (int)status);
        FZ_CHECK(null_cells || memcmp(cells, given, (size_t)alloc * sizeof *cells) == 0,
                 "plant_grid returned %d but changed the cells", (int)status);
    } else {
        FZ_CHECK(status == ICOAC_SIM_OK, "plant_grid(%d, %lld cells) returned %d", (int)index, (long long)n,
                 (int)status);
        FZ_CHECK(index != ICOAC_SIM_CART_POLE || (d->rows.count == PAPER_ROWS && d->cols.count == PAPER_COLS),
                 "the cart-pole's grid has %d x %d cells, the paper's %d x %d", (int)d->rows.count,
                 (int)d->cols.count, PAPER_ROWS, PAPER_COLS);
        for (i = 0; i < n; ++i) {
            const icoac_sim_cell_t *cell = &cells[i];
            const int64_t row = i / d->cols.count;
            const int64_t col = i % d->cols.count;
            icoac_sim_cell_t want;
            /* the documented fields, the rest 0 */
            memset(&want, 0, sizeof want);
            want.x0 = cell->x0;
            want.theta0 = cell->theta0;
            want.seed = icoac_mix_seed(seed, (uint64_t)i);
            want.outcome = ICOAC_SIM_PENDING;
            FZ_CHECK(close_to(cell->theta0, sweep_value(&d->rows, row)) &&
                         close_to(cell->x0, sweep_value(&d->cols, col)) && memcmp(cell, &want, sizeof want) == 0,
                     "plant_grid(%d) cell %lld: theta0 %g x0 %g seed %llu outcome %d", (int)index, (long long)i,
                     cell->theta0, cell->x0, (unsigned long long)cell->seed, (int)cell->outcome);
            FZ_CHECK(index != ICOAC_SIM_CART_POLE ||
                         (close_to(cell->theta0, (double)(row - 12) * ICOAC_SIM_PI / 180.0) &&
                          close_to(cell->x0, -2.4 + 0.1 * (double)col)),
                     "the cart-pole's grid cell %lld (theta0 %g, x0 %g) is not the paper's", (long long)i,
                     cell->theta0, cell->x0);
        }
    }
    free(cells);
    free(given);
}

static void op_registry(fz_reader_t *r)
{
    const int32_t count = icoac_sim_plant_count();
    const int32_t index = fz_i32(r);
    const icoac_sim_plant_desc_t *d = icoac_sim_plant_info(index);
    const int in_range = index >= 0 && index < count;
    char name[FZ_NAME_MAX + 1];
    const char *query = name;
    icoac_sim_model_t m;
    int32_t status;
    int32_t found;
    int i;
    FZ_CHECK((d != 0) == in_range, "plant_info(%d) of %d plants returned %p", (int)index, (int)count,
             (const void *)d);
    status = icoac_sim_model_default(0, index);
    FZ_CHECK(fz_sim_status_known(status) && status != ICOAC_SIM_OK && (status == ICOAC_SIM_ERR_BAD_ARGUMENT || !in_range),
             "model_default(NULL, %d) returned %d", (int)index, (int)status);
    status = icoac_sim_model_default(&m, index);
    FZ_CHECK(fz_sim_status_known(status) && (status == ICOAC_SIM_OK) == in_range, "model_default(%d) returned %d",
             (int)index, (int)status);
    if (in_range) {
        check_desc(d);
        FZ_CHECK(icoac_sim_plant_find(d->name) == index, "plant_find(%s) is not %d", d->name, (int)index);
        FZ_CHECK(m.plant == index && m.integrator == ICOAC_SIM_EULER && m.dt == 0.01 &&
                     icoac_sim_model_check(&m) == ICOAC_SIM_OK,
                 "model_default(%d): plant %d integrator %d dt %g", (int)index, (int)m.plant, (int)m.integrator, m.dt);
        for (i = 0; i < ICOAC_SIM_MAX_PARAMS; ++i) {
            const double want = i < d->n_params ? d->params[i].value : 0.0;
            FZ_CHECK(memcmp(&m.param[i], &want, sizeof want) == 0, "model_default(%d): param[%d] %g", (int)index, i,
                     m.param[i]);
        }
        for (i = 0; i < d->n_params; ++i) {
            const icoac_sim_param_t *p = &d->params[i];
            FZ_CHECK(p->name != 0 && p->unit != 0 && p->tier != 0 &&
                         (strcmp(p->tier, "essential") == 0 || strcmp(p->tier, "advanced") == 0) && p->doc != 0 &&
                         p->doc[0] != '\0' && strchr(p->doc, '\n') == 0,
                     "plant %s: parameter %d (%s) has tier %s, doc \"%s\"", d->name, i,
                     p->name != 0 ? p->name : "(null)", p->tier != 0 ? p->tier : "(null)",
                     p->doc != 0 ? p->doc : "(null)");
        }
    }
    {
        const uint8_t k = fz_u8(r) % 4;
        if (k == 0) {
            query = 0;
        } else if (k == 3) {
            const int len = fz_u8(r) % (FZ_NAME_MAX + 1);
            for (i = 0; i < len; ++i) {
                name[i] = (char)fz_u8(r);
            }
            name[len] = '\0';
        } else {
            const char *full = icoac_sim_plant_info(fz_u8(r) % count)->name;
            const size_t len = strlen(full);
            FZ_CHECK(len >= 1 && len <= FZ_NAME_MAX, "registry name %s", full);
            memcpy(name, full, len + 1);
            if (k == 2) {
                name[len - 1] = '\0';
            }
        }
    }
    found = icoac_sim_plant_find(query);
    if (query == 0) {
        FZ_CHECK(found == -1, "plant_find(NULL) returned %d", (int)found);
        return;
    }
    for (i = 0; i < count && strcmp(icoac_sim_plant_info(i)->name, query) != 0; ++i) {
    }
    FZ_CHECK(found == (i < count ? i : -1), "plant_find(\"%s\") returned %d", query, (int)found);
}

/* ---- Run ops: icoac_sim_run_cell, icoac_sim_run_grid, icoac_sim_trajectory ---------------- */

/* What a run op decodes: the controller configuration and prior and, for cells and grids, the
 * run (clamped) with the verdicts of their checks. */
typedef struct {
    icoac_config_t cfg;
    icoac_sim_run_t run;
    icoac_prior_t prior_storage;
    const icoac_prior_t *prior;
    int32_t run_status;   /* fz_run_clamp's verdict */
    int32_t prior_status; /* icoac_prior_check, OK for a NULL prior */
} control_t;

static void decode_control(fz_reader_t *r, int with_run, control_t *c)
{
    c->run_status = ICOAC_SIM_OK;
    if (with_run) {
        fz_run(r, &c->run);
        c->run_status = fz_run_clamp(&c->run);
    }
    fz_config(r, &c->cfg);
    c->prior = fz_prior(r, &c->prior_storage);
    c->prior_status = c->prior != 0 ? (int32_t)icoac_prior_check(c->prior, c->cfg.task.n_inputs) : ICOAC_OK;
}

/* The status of the documented checks in their order: a NULL configuration or model is refused
 * first, then the configuration check, the model check, the observation fit (the task reads the
 * plant's n_state components), and last run_status (the run check, BAD_ARGUMENT for a NULL run,
 * OK for a trajectory). */
static int32_t checks_status(const setup_t *su, const icoac_config_t *cfg, int32_t run_status)
{
    int32_t status;
    if (cfg == 0 || su->model == 0) {
        return ICOAC_SIM_ERR_BAD_ARGUMENT;
    }
    status = (int32_t)icoac_config_check(cfg);
    if (status != ICOAC_OK) {
        return status;
    }
    if (su->check != ICOAC_SIM_OK) {
        return su->check;
    }
    if (su->desc->n_state != cfg->task.n_inputs) {
        return ICOAC_SIM_ERR_BAD_PLANT;
    }
    return run_status;
}

/* Cell i of the grid of plant index with seed; the grid of the last (index, seed) is kept. */
static int cell_of_grid(int32_t index, uint64_t seed, uint32_t i, icoac_sim_cell_t *cell)
{
    static icoac_sim_cell_t *grid;
    static int64_t grid_cells;
    static int32_t grid_index = -1;
    static uint64_t grid_seed;
    const icoac_sim_plant_desc_t *d = icoac_sim_plant_info(index);
    const int64_t n = (int64_t)d->rows.count * d->cols.count;
    if (n < 1) {
        return 0;
    }
    if (grid_index != index || grid_seed != seed) {
        free(grid);
        grid = (icoac_sim_cell_t *)malloc((size_t)n * sizeof *grid);
        FZ_CHECK(grid != 0, "out of memory");
        FZ_CHECK(icoac_sim_plant_grid(index, grid, n, seed) == ICOAC_SIM_OK, "plant_grid(%d) refused its size",
                 (int)index);
        grid_cells = n;
        grid_index = index;
        grid_seed = seed;
    }
    *cell = grid[(int64_t)i % grid_cells];
    return 1;
}

/* A cell spec: kind byte k; k & 1 == 0: seed byte and a 2-byte index i, cell i % size of the
 * plant byte's grid with that seed; k & 1 == 1: x0, theta0 (doubles) and a seed byte. Returns
 * the finished outcome the grid op presets it with, (k >> 1) & 3: 0 none (PENDING), 1 SUCCESS,
 * 2 FAILED, 3 ERROR. */
static int32_t decode_cell(fz_reader_t *r, const setup_t *su, icoac_sim_cell_t *cell)
{
    const uint8_t k = fz_u8(r);
    memset(cell, 0, sizeof *cell);
    if ((k & 1u) == 0u) {
        const uint64_t seed = fz_u8(r);
        const uint32_t i = fz_u8(r);
        const uint32_t index = i | (uint32_t)fz_u8(r) << 8;
        (void)cell_of_grid(su->index, seed, index, cell);
    } else {
        cell->x0 = fz_double(r);
        cell->theta0 = fz_double(r);
        cell->seed = fz_u8(r);
    }
    return (k >> 1) & 3;
}

static int cell_inputs_kept(const icoac_sim_cell_t *a, const icoac_sim_cell_t *b)
{
    return memcmp(&a->x0, &b->x0, sizeof a->x0) == 0 && memcmp(&a->theta0, &b->theta0, sizeof a->theta0) == 0 &&
           a->seed == b->seed;
}

static void op_run_cell(fz_reader_t *r, setup_t *su, unsigned nulls)
{
    control_t c;
    icoac_sim_cell_t cell;
    icoac_sim_cell_t given;
    const icoac_config_t *cfg;
    const icoac_sim_run_t *run;
    int32_t expected;
    int32_t status;
    decode_control(r, 1, &c);
    (void)decode_cell(r, su, &cell);
    cfg = (nulls & NULL_CFG) ? 0 : &c.cfg;
    run = (nulls & NULL_RUN) ? 0 : &c.run;
    expected = checks_status(su, cfg, run != 0 ? c.run_status : ICOAC_SIM_ERR_BAD_ARGUMENT);
    if (expected == ICOAC_SIM_OK && ((nulls & NULL_CELLS) || !isfinite(cell.x0) || !isfinite(cell.theta0))) {
        expected = ICOAC_SIM_ERR_BAD_ARGUMENT;
    }
    if (expected == ICOAC_SIM_OK) {
        expected = c.prior_status;
    }
    /* refused calls run nothing: only runs are charged */
    if (expected == ICOAC_SIM_OK && !fz_charge(&su->budget, &c.run, 1)) {
        return;
    }
    given = cell;
    status = icoac_sim_run_cell(cfg, su->model, run, c.prior, (nulls & NULL_CELLS) ? 0 : &cell, 0, 0);
    FZ_CHECK(fz_sim_status_known(status), "run_cell returned unknown status %d", (int)status);
    if (expected != ICOAC_SIM_OK) {
        FZ_CHECK(status == expected, "run_cell returned %d (%s), the first failing check %d (%s)", (int)status,
                 icoac_sim_status_str(status), (int)expected, icoac_sim_status_str(expected));
        FZ_CHECK(memcmp(&cell, &given, sizeof cell) == 0, "run_cell refused with %d but wrote the cell",
                 (int)status);
    } else {
        FZ_CHECK(status == ICOAC_SIM_OK, "run_cell returned %d (%s) for a valid setup", (int)status,
                 icoac_sim_status_str(status));
        FZ_CHECK(cell_inputs_kept(&cell, &given), "run_cell changed the cell's inputs");
        fz_check_finished_cell(&c.run, su->model->dt, &cell, "run_cell");
    }
}

/* Grid op (cancel: with the cancel flag raised). */
static void op_run_grid(fz_reader_t *r, setup_t *su, unsigned nulls, int cancel)
{
    static const int32_t preset_outcomes[4] = {ICOAC_SIM_PENDING, ICOAC_SIM_SUCCESS, ICOAC_SIM_FAILED, ICOAC_SIM_ERROR};
    control_t c;
    icoac_sim_cell_t *cells;
    icoac_sim_cell_t *given;
    const icoac_config_t *cfg;
    const icoac_sim_run_t *run;
    const volatile int32_t raised = 1;
    const volatile int32_t *flag = cancel ? &raised : 0;
    uint8_t count;
    int n;
    int32_t threads;
    int preset[FZ_MODEL_MAX_CELLS] = {0};
    int all_finite = 1;
    int pending = 0;
    int32_t expected;
    int32_t status;
    size_t bytes;
    int i;
    decode_control(r, 1, &c);
    count = fz_u8(r);
    n = count % 32 == 31 ? 0 : 1 + count % FZ_MODEL_MAX_CELLS;
    threads = fz_threads(r);
    /* heap blocks of exactly n cells, so ASan sees any overrun */
    bytes = (size_t)(n > 0 ? n : 1) * sizeof *cells;
    cells = (icoac_sim_cell_t *)malloc(bytes);
    given = (icoac_sim_cell_t *)malloc(bytes);
    FZ_CHECK(cells != 0 && given != 0, "out of memory");
    memset(cells, 0, bytes);
    for (i = 0; i < n; ++i) {
        const int32_t outcome = preset_outcomes[decode_cell(r, su, &cells[i])];
        if (outcome != ICOAC_SIM_PENDING) {
            /* A finished cell, recognisable by its fields: the grid must skip it. */
            preset[i] = 1;
            cells[i].outcome = outcome;
            cells[i].status = 77;
            cells[i].trials = 7;
            cells[i].weights[0] = (double)NAN;
        } else {
            ++pending;
        }
        all_finite = all_finite && isfinite(cells[i].x0) && isfinite(cells[i].theta0);
    }
    cfg = (nulls & NULL_CFG) ? 0 : &c.cfg;
    run = (nulls & NULL_RUN) ? 0 : &c.run;
    expected = checks_status(su, cfg, run != 0 ? c.run_status : ICOAC_SIM_ERR_BAD_ARGUMENT);
    if (expected == ICOAC_SIM_OK && ((nulls & NULL_CELLS) || n < 1 || threads < 0 || !all_finite)) {
        expected = ICOAC_SIM_ERR_BAD_ARGUMENT;
    }
    if (expected == ICOAC_SIM_OK) {
        expected = c.prior_status;
    }
    if (expected != ICOAC_SIM_OK || cancel || fz_charge(&su->budget, &c.run, pending)) {
        memcpy(given, cells, bytes);
        status = icoac_sim_run_grid(cfg, su->model, run, c.prior, (nulls & NULL_CELLS) ? 0 : cells, n, threads, flag,
                                    0);
        FZ_CHECK(fz_sim_status_known(status), "run_grid returned unknown status %d", (int)status);
        if (expected != ICOAC_SIM_OK || status == ICOAC_SIM_ERR_THREAD) {
            FZ_CHECK(status == expected || (expected == ICOAC_SIM_OK && status == ICOAC_SIM_ERR_THREAD),
                     "run_grid(%d cells, %d threads) returned %d (%s), the first failing check %d (%s)", n,
                     (int)threads, (int)status, icoac_sim_status_str(status), (int)expected,
                     icoac_sim_status_str(expected));
            FZ_CHECK(memcmp(cells, given, bytes) == 0, "run_grid returned %d but changed cells", (int)status);
        } else if (cancel) {
            /* nothing starts: every trial start sees the flag */
            FZ_CHECK(status == ICOAC_SIM_CANCELLED || (pending == 0 && status == ICOAC_SIM_OK),
                     "run_grid with the cancel flag raised returned %d (%d pending cells)", (int)status, pending);
            for (i = 0; i < n; ++i) {
                FZ_CHECK(preset[i] ? memcmp(&cells[i], &given[i], sizeof cells[i]) == 0
                                   : cells[i].outcome == ICOAC_SIM_PENDING,
                         "run_grid cancelled: cell %d (preset %d) has outcome %d", i, preset[i],
                         (int)cells[i].outcome);
            }
        } else {
            FZ_CHECK(status == ICOAC_SIM_OK, "run_grid returned %d (%s) for a valid setup", (int)status,
                     icoac_sim_status_str(status));
            for (i = 0; i < n; ++i) {
                if (preset[i]) {
                    FZ_CHECK(memcmp(&cells[i], &given[i], sizeof cells[i]) == 0,
                             "run_grid reran finished cell %d (outcome %d)", i, (int)given[i].outcome);
                } else {
                    FZ_CHECK(cell_inputs_kept(&cells[i], &given[i]), "run_grid changed cell %d's inputs", i);
                    fz_check_finished_cell(&c.run, su->model->dt, &cells[i], "run_grid");
                }
            }
        }
    }
    free(cells);
    free(given);
}

/* The recorded trajectory of an accepted call: the first row is the model's start of the cell,
 * the trial runs until it fails (only its last row may fail or be non-finite), forces are finite,
 * and nothing past n_steps is written. */
static void check_trajectory(const setup_t *su, const icoac_sim_cell_t *cell, double noise, int64_t max_steps,
                             int32_t status, const double *states, const double *forces, int64_t n_steps)
{
    const int n = su->desc->n_state;
    double start[MAXS];
    icoac_rng_t rng;
    int64_t k;
    FZ_CHECK(status < 100, "trajectory returned %d (%s) for a valid setup", (int)status,
             icoac_sim_status_str(status));
    FZ_CHECK(n_steps >= 0 && n_steps <= max_steps, "trajectory: n_steps %lld of max_steps %lld",
             (long long)n_steps, (long long)max_steps);
    icoac_rng_seed(&rng, cell->seed, ICOAC_SIM_START_STREAM);
    FZ_CHECK(icoac_sim_model_start(su->model, cell, noise, &rng, start) == ICOAC_SIM_OK,
             "model_start refused what trajectory accepted");
    FZ_CHECK(same(states, start, n), "trajectory: the first row is not the model's start");
    for (k = 1; k <= n_steps; ++k) {
        const double *s = states + (size_t)n * (size_t)k;
        int32_t failed = FAILED_CANARY;
        FZ_CHECK(icoac_sim_model_failed(su->model, s, &failed) == ICOAC_SIM_OK, "model_failed refused a row");
        if (k < n_steps) {
            FZ_CHECK(fz_all_finite_double(s, n) && !failed, "trajectory ran on past row %lld (failed %d)",
                     (long long)k, (int)failed);
        } else if (status == ICOAC_SIM_OK && n_steps < max_steps) {
            FZ_CHECK(failed, "trajectory stopped at %lld of %lld without a failure", (long long)n_steps,
                     (long long)max_steps);
        }
    }
    FZ_CHECK(fz_all_finite_double(forces, (int)n_steps), "trajectory recorded a non-finite force");
    for (k = (n_steps + 1) * n; k < (max_steps + 1) * n; ++k) {
        FZ_CHECK(isnan(states[k]), "trajectory wrote state entry %lld past its %lld steps", (long long)k,
                 (long long)n_steps);
    }
    for (k = n_steps; k < max_steps; ++k) {
        FZ_CHECK(isnan(forces[k]), "trajectory wrote force %lld past its %lld steps", (long long)k,
                 (long long)n_steps);
    }
}

/* Heap blocks of the trajectory's exact sizes (rows of row values), filled with NaN. */
static double *nan_block(int64_t count)
{
    double *p = (double *)malloc((size_t)count * sizeof *p);
    int64_t i;
    FZ_CHECK(p != 0, "out of memory");
    for (i = 0; i < count; ++i) {
        p[i] = (double)NAN;
    }
    return p;
}

static void op_run_trajectory(fz_reader_t *r, const setup_t *su, unsigned nulls)
{
    control_t c;
    icoac_sim_cell_t cell;
    const icoac_config_t *cfg;
    double noise;
    uint8_t steps_byte;
    int64_t max_steps;
    int64_t rows;
    int64_t row;
    double *states;
    double *forces;
    double *given_states;
    double *given_forces;
    int64_t n_steps = -7;
    int64_t *n_steps_out;
    int32_t expected;
    int32_t status;
    decode_control(r, 0, &c);
    (void)decode_cell(r, su, &cell);
    noise = fz_double(r);
    steps_byte = fz_u8(r);
    max_steps = (int64_t)((steps_byte & 0x7Fu) % (FZ_TRAJ_MAX_STEPS + 2)) - 1;
    n_steps_out = (steps_byte & 0x80u) ? 0 : &n_steps;
    rows = max_steps >= 1 ? max_steps + 1 : 1;
    row = su->n;
    states = nan_block(rows * row);
    forces = nan_block(rows - 1 > 0 ? rows - 1 : 1);
    given_states = nan_block(rows * row);
    given_forces = nan_block(rows - 1 > 0 ? rows - 1 : 1);
    cfg = (nulls & NULL_CFG) ? 0 : &c.cfg;
    status = icoac_sim_trajectory(cfg, su->model, c.prior, cell.x0, cell.theta0, noise, cell.seed, max_steps,
                                  (nulls & NULL_CELLS) ? 0 : states, (nulls & NULL_RUN) ? 0 : forces, n_steps_out);
    FZ_CHECK(fz_sim_status_known(status), "trajectory returned unknown status %d", (int)status);
    expected = checks_status(su, cfg, ICOAC_SIM_OK);
    if (expected == ICOAC_SIM_OK &&
        ((nulls & (NULL_CELLS | NULL_RUN)) || n_steps_out == 0 || max_steps < 1 || !isfinite(cell.x0) ||
         !isfinite(cell.theta0) || !(noise == 0.0 || (noise >= ICOAC_SIM_NOISE_MIN && noise <= ICOAC_SIM_NOISE_MAX)))) {
        expected = ICOAC_SIM_ERR_BAD_ARGUMENT;
    }
    if (expected == ICOAC_SIM_OK) {
        expected = c.prior_status;
    }
    if (expected != ICOAC_SIM_OK) {
        FZ_CHECK(status == expected, "trajectory returned %d (%s), the first failing check %d (%s)",
                 (int)status, icoac_sim_status_str(status), (int)expected, icoac_sim_status_str(expected));
        FZ_CHECK(n_steps == -7 && memcmp(states, given_states, (size_t)(rows * row) * sizeof *states) == 0 &&
                     memcmp(forces, given_forces, (size_t)(rows > 1 ? rows - 1 : 1) * sizeof *forces) == 0,
                 "trajectory refused with %d but wrote its outputs", (int)status);
    } else {
        check_trajectory(su, &cell, noise, max_steps, status, states, forces, n_steps);
    }
    free(states);
    free(forces);
    free(given_states);
    free(given_forces);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    fz_reader_t r;
    setup_t su;
    int ops;
    fz_reader_init(&r, data, size);
    FZ_CHECK(icoac_sim_plant_count() >= 1, "empty registry");
    FZ_CHECK(icoac_sim_run_check(0) == ICOAC_SIM_ERR_BAD_ARGUMENT, "run_check(NULL) was not refused");
    decode_model(&r, &su);
    for (ops = 0; ops < FZ_MODEL_OPS && !fz_done(&r); ++ops) {
        const uint8_t op = fz_u8(&r);
        const unsigned nulls = op >= 0xC0u ? op & (NULL_STATE | NULL_OUT | NULL_RNG) : 0u;
        if (op >= RUN_OP && op < 0xC0u) {
            const unsigned run_nulls = (op & RUN_NULLS) ? op & (NULL_CFG | NULL_CELLS | NULL_RUN) : 0u;
            switch (op & 3) {
            case OP_RUN_CELL: op_run_cell(&r, &su, run_nulls); break;
            case OP_RUN_GRID: op_run_grid(&r, &su, run_nulls, 0); break;
            case OP_RUN_TRAJECTORY: op_run_trajectory(&r, &su, run_nulls); break;
            default: op_run_grid(&r, &su, run_nulls, 1); break;
            }
            continue;
        }
        switch ((op & 7) % OP_KINDS) {
        case OP_START: op_start(&r, &su, nulls); break;
        case OP_GRID: op_grid(&r); break;
        case OP_REGISTRY: op_registry(&r); break;
        case OP_LANES: op_lanes(&r, &su, nulls); break;
        default: op_state(&r, &su, (op & 7) % OP_KINDS, nulls); break;
        }
    }
    return 0;
}
