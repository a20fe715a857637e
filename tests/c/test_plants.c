/* SPDX-License-Identifier: Apache-2.0 */
/* The plant registry (sim_host/src/plant_registry.c, model.c, plants/): descriptors consistent,
 * parameter checks, named statuses for non-finite input, grids and trial starts, and energy conservation
 * of every plant without input and friction. The dynamics against independently derived
 * equations are in tests/python/test_plants.py. */
#include "test_common.h"

#include <float.h>

#include "icoac_sim/icoac_sim.h"

static const icoac_sim_plant_desc_t *plant(int32_t i)
{
    const icoac_sim_plant_desc_t *d = icoac_sim_plant_info(i);
    TEST_ASSERT_NOT_NULL(d);
    return d;
}

/* The actuator's limit is a valid value of its parameter, at which the input saturates: any larger
 * input moves the plant as the limit does, a smaller one does not. */
static void check_actuator(const icoac_sim_plant_desc_t *d, const icoac_sim_model_t *defaults)
{
    const icoac_sim_actuator_t *a = &d->actuator;
    icoac_sim_model_t model = *defaults;
    double at[ICOAC_SIM_MAX_STATE], beyond[ICOAC_SIM_MAX_STATE], within[ICOAC_SIM_MAX_STATE];
    int32_t c, differs = 0;
    if (a->param == -1) { /* none: the input is not saturated */
        TEST_ASSERT_TRUE(a->limit == 0.0 && a->source == NULL);
        return;
    }
    TEST_ASSERT_TRUE(a->param >= 0 && a->param < d->n_params);
    TEST_ASSERT_TRUE(a->source != NULL && strlen(a->source) > 0);
    TEST_ASSERT_TRUE(a->limit > 0.0 && a->limit >= d->params[a->param].min && a->limit <= d->params[a->param].max);
    model.param[a->param] = a->limit;
    TEST_ASSERT_EQUAL_INT(ICOAC_SIM_OK, icoac_sim_model_check(&model));
    memcpy(at, d->start, sizeof at);
    memcpy(beyond, d->start, sizeof beyond);
    memcpy(within, d->start, sizeof within);
    TEST_ASSERT_EQUAL_INT(ICOAC_SIM_OK, icoac_sim_model_step(&model, at, a->limit));
    TEST_ASSERT_EQUAL_INT(ICOAC_SIM_OK, icoac_sim_model_step(&model, beyond, 3.0 * a->limit));
    TEST_ASSERT_EQUAL_INT(ICOAC_SIM_OK, icoac_sim_model_step(&model, within, 0.5 * a->limit));
    for (c = 0; c < d->n_state; ++c) {
        TEST_ASSERT_TRUE(beyond[c] == at[c]);
        differs |= within[c] != at[c];
    }
    TEST_ASSERT_TRUE(differs);
}

static void test_registry(void)
{
    const int32_t n = icoac_sim_plant_count();
    int32_t i, j, c;
    TEST_ASSERT_TRUE(n >= 3);
    TEST_ASSERT_EQUAL_STRING("cart_pole", plant(ICOAC_SIM_CART_POLE)->name);
    TEST_ASSERT_EQUAL_INT(1, icoac_sim_plant_find("furuta"));
    TEST_ASSERT_EQUAL_INT(2, icoac_sim_plant_find("double_cart_pole"));
    TEST_ASSERT_EQUAL_INT(-1, icoac_sim_plant_find("no_such_plant"));
    TEST_ASSERT_EQUAL_INT(-1, icoac_sim_plant_find(NULL));
    TEST_ASSERT_NULL(icoac_sim_plant_info(-1));
    TEST_ASSERT_NULL(icoac_sim_plant_info(n));
    for (i = 0; i < n; ++i) {
        const icoac_sim_plant_desc_t *d = plant(i);
        icoac_sim_model_t model;
        double s[ICOAC_SIM_MAX_STATE];
        int32_t failed = -1;
        TEST_ASSERT_EQUAL_INT(i, icoac_sim_plant_find(d->name));
        TEST_ASSERT_TRUE(d->n_state >= 2 && d->n_state <= ICOAC_SIM_MAX_STATE);
        TEST_ASSERT_TRUE(d->n_params >= 1 && d->n_params <= ICOAC_SIM_MAX_PARAMS);
        TEST_ASSERT_TRUE(strlen(d->title) > 0 && strlen(d->source) > 0 && strlen(d->input.name) > 0);
        TEST_ASSERT_TRUE(d->step != NULL && d->derivatives != NULL && d->failed != NULL);
        for (c = 0; c < d->n_state; ++c) {
            TEST_ASSERT_TRUE(strlen(d->state[c].name) > 0 && strlen(d->state[c].unit) > 0);
            TEST_ASSERT_TRUE(d->observed[c] >= -1 && d->observed[c] < d->n_state);
            TEST_ASSERT_TRUE(d->drawn[c] == 0 || d->drawn[c] == 1);
        }
        for (j = 0; j < d->n_params; ++j) {
            TEST_ASSERT_TRUE(strlen(d->params[j].name) > 0 && d->params[j].min <= d->params[j].max);
            for (c = 0; c < j; ++c) {
                TEST_ASSERT_TRUE(strcmp(d->params[j].name, d->params[c].name) != 0);
            }
        }
        TEST_ASSERT_TRUE(d->rows.component != d->cols.component);
        TEST_ASSERT_TRUE(d->rows.component >= 0 && d->rows.component < d->n_state && !d->drawn[d->rows.component]);
        TEST_ASSERT_TRUE(d->cols.component >= 0 && d->cols.component < d->n_state && !d->drawn[d->cols.component]);
        TEST_ASSERT_TRUE(d->rows.count >= 1 && d->cols.count >= 1 && d->rows.count * d->cols.count <= 25 * 49);
        /* the defaults are valid and the start state balances */
        TEST_ASSERT_EQUAL_INT(ICOAC_SIM_OK, icoac_sim_model_default(&model, i));
        TEST_ASSERT_EQUAL_INT(ICOAC_SIM_OK, icoac_sim_model_check(&model));
        memcpy(s, d->start, sizeof s);
        TEST_ASSERT_EQUAL_INT(ICOAC_SIM_OK, icoac_sim_model_failed(&model, s, &failed));
        TEST_ASSERT_EQUAL_INT(0, failed);
        /* the upright, at rest and without input, is an equilibrium */
        TEST_ASSERT_EQUAL_INT(ICOAC_SIM_OK, icoac_sim_model_step(&model, s, 0.0));
        for (c = 0; c < d->n_state; ++c) {
            TEST_ASSERT_TRUE(s[c] == 0.0);
        }
        check_actuator(d, &model);
    }
    TEST_ASSERT_EQUAL_INT(ICOAC_SIM_ERR_BAD_ARGUMENT, icoac_sim_model_default(NULL, 0));
    {
        icoac_sim_model_t model;
        TEST_ASSERT_EQUAL_INT(ICOAC_SIM_ERR_BAD_PLANT, icoac_sim_model_default(&model, n));
    }
}

static void test_model_checks(void)
{
    static const double bad[] = {(double)NAN, (double)INFINITY, -(double)INFINITY, 1e-310, -1.0, 2e6};
    int32_t i, j;
    size_t b;
    for (i = 0; i < icoac_sim_plant_count(); ++i) {
        const icoac_sim_plant_desc_t *d = plant(i);
        icoac_sim_model_t model;
        for (j = 0; j < ICOAC_SIM_MAX_PARAMS; ++j) {
            for (b = 0; b < sizeof bad / sizeof bad[0]; ++b) {
                TEST_ASSERT_EQUAL_INT(ICOAC_SIM_OK, icoac_sim_model_default(&model, i));
                model.param[j] = bad[b];
                TEST_ASSERT_EQUAL_INT(ICOAC_SIM_ERR_BAD_PLANT, icoac_sim_model_check(&model));
            }
            if (j < d->n_params) { /* the bounds themselves are valid */
                model.param[j] = d->params[j].min;
                TEST_ASSERT_EQUAL_INT(ICOAC_SIM_OK, icoac_sim_model_check(&model));
                model.param[j] = d->params[j].max;
                TEST_ASSERT_EQUAL_INT(ICOAC_SIM_OK, icoac_sim_model_check(&model));
            } else { /* unused parameters must be 0 */
                model.param[j] = 1.0;
                TEST_ASSERT_EQUAL_INT(ICOAC_SIM_ERR_BAD_PLANT, icoac_sim_model_check(&model));
            }
        }
        TEST_ASSERT_EQUAL_INT(ICOAC_SIM_OK, icoac_sim_model_default(&model, i));
        model.dt = 0.0;
        TEST_ASSERT_EQUAL_INT(ICOAC_SIM_ERR_BAD_PLANT, icoac_sim_model_check(&model));
        model.dt = 0.01;
        model.integrator = 2;
        TEST_ASSERT_EQUAL_INT(ICOAC_SIM_ERR_BAD_PLANT, icoac_sim_model_check(&model));
        model.integrator = ICOAC_SIM_RK4;
        model.plant = icoac_sim_plant_count();
        TEST_ASSERT_EQUAL_INT(ICOAC_SIM_ERR_BAD_PLANT, icoac_sim_model_check(&model));
        model.plant = -1;
        TEST_ASSERT_EQUAL_INT(ICOAC_SIM_ERR_BAD_PLANT, icoac_sim_model_check(&model));
    }
    TEST_ASSERT_EQUAL_INT(ICOAC_SIM_ERR_BAD_ARGUMENT, icoac_sim_model_check(NULL));
}

/* Non-finite state or input, or a step that overflows: a named status, the state untouched. */
static void test_nonfinite_input(void)
{
    int32_t i, c;
    for (i = 0; i < icoac_sim_plant_count(); ++i) {
        const icoac_sim_plant_desc_t *d = plant(i);
        icoac_sim_model_t model;
        double s[ICOAC_SIM_MAX_STATE] = {0}, before[ICOAC_SIM_MAX_STATE], ds[ICOAC_SIM_MAX_STATE], e = 0.0;
        int32_t failed = 0;
        TEST_ASSERT_EQUAL_INT(ICOAC_SIM_OK, icoac_sim_model_default(&model, i));
        for (c = 0; c < d->n_state; ++c) {
            s[c] = 0.01 * (c + 1);
        }
        memcpy(before, s, sizeof s);
        TEST_ASSERT_EQUAL_INT(ICOAC_SIM_ERR_NONFINITE, icoac_sim_model_step(&model, s, (double)NAN));
        TEST_ASSERT_EQUAL_INT(ICOAC_SIM_ERR_NONFINITE, icoac_sim_model_step(&model, s, (double)INFINITY));
        TEST_ASSERT_EQUAL_INT(ICOAC_SIM_ERR_NONFINITE, icoac_sim_model_derivatives(&model, s, (double)NAN, ds));
        TEST_ASSERT_EQUAL_MEMORY(before, s, sizeof s);
        /* a step that overflows: the last component is a velocity whose square enters every plant's
         * equations (an input may saturate, as the Furuta's voltage does) */
        s[d->n_state - 1] = 1e200;
        memcpy(before, s, sizeof s);
        TEST_ASSERT_EQUAL_INT(ICOAC_SIM_ERR_NONFINITE, icoac_sim_model_step(&model, s, 0.0));
        TEST_ASSERT_EQUAL_MEMORY(before, s, sizeof s);
        s[d->n_state - 1] = 0.01 * d->n_state;
        for (c = 0; c < d->n_state; ++c) {
            s[c] = (double)NAN;
            TEST_ASSERT_EQUAL_INT(ICOAC_SIM_ERR_NONFINITE, icoac_sim_model_step(&model, s, 0.0));
            TEST_ASSERT_EQUAL_INT(ICOAC_SIM_ERR_NONFINITE, icoac_sim_model_energy(&model, s, &e));
            TEST_ASSERT_EQUAL_INT(ICOAC_SIM_OK, icoac_sim_model_failed(&model, s, &failed));
            TEST_ASSERT_EQUAL_INT(1, failed);
            s[c] = (double)INFINITY;
            TEST_ASSERT_EQUAL_INT(ICOAC_SIM_OK, icoac_sim_model_failed(&model, s, &failed));
            TEST_ASSERT_EQUAL_INT(1, failed);
            TEST_ASSERT_TRUE(isnan(s[c] - s[c]));
            s[c] = before[c];
        }
        TEST_ASSERT_EQUAL_INT(ICOAC_SIM_ERR_BAD_ARGUMENT, icoac_sim_model_step(&model, NULL, 0.0));
        TEST_ASSERT_EQUAL_INT(ICOAC_SIM_ERR_BAD_ARGUMENT, icoac_sim_model_failed(&model, s, NULL));
        TEST_ASSERT_EQUAL_INT(ICOAC_SIM_ERR_BAD_ARGUMENT, icoac_sim_model_energy(&model, s, NULL));
        TEST_ASSERT_EQUAL_INT(ICOAC_SIM_ERR_BAD_ARGUMENT, icoac_sim_model_derivatives(&model, s, 0.0, NULL));
        model.dt = (double)NAN;
        TEST_ASSERT_EQUAL_INT(ICOAC_SIM_ERR_BAD_PLANT, icoac_sim_model_step(&model, s, 0.0));
        TEST_ASSERT_EQUAL_MEMORY(before, s, sizeof s);
    }
    TEST_ASSERT_NOT_NULL(icoac_sim_status_str(ICOAC_SIM_ERR_NONFINITE));
    TEST_ASSERT_TRUE(strstr(icoac_sim_status_str(ICOAC_SIM_ERR_NONFINITE), "not finite") != NULL);
}

/* icoac_sim_model_step_lanes: each lane as icoac_sim_model_step then icoac_sim_model_failed on its
 * own state; an ended lane untouched; a lane with a non-finite input ends with its state kept. */
static void test_step_lanes(void)
{
    int32_t i, c;
    for (i = 0; i < icoac_sim_plant_count(); ++i) {
        const icoac_sim_plant_desc_t *d = plant(i);
        icoac_sim_model_t model;
        double lanes[4][ICOAC_SIM_MAX_STATE] = {{0}}, before[4][ICOAC_SIM_MAX_STATE], one[ICOAC_SIM_MAX_STATE];
        const double u[4] = {0.5, 0.5, (double)NAN, 0.0};
        int32_t ended[4] = {0, 1, 0, 0}, failed = -1;
        TEST_ASSERT_EQUAL_INT(ICOAC_SIM_OK, icoac_sim_model_default(&model, i));
        for (c = 0; c < d->n_state; ++c) {
            lanes[0][c] = lanes[1][c] = lanes[2][c] = 0.01 * (c + 1);
        }
        lanes[3][0] = 1e3; /* outside every plant's limit on its first component */
        memcpy(before, lanes, sizeof lanes);
        memcpy(one, lanes[0], sizeof one);
        TEST_ASSERT_EQUAL_INT(ICOAC_SIM_OK, icoac_sim_model_step_lanes(&model, &lanes[0][0], u, ended, 4));
        TEST_ASSERT_EQUAL_INT(ICOAC_SIM_OK, icoac_sim_model_step(&model, one, u[0]));
        TEST_ASSERT_EQUAL_INT(ICOAC_SIM_OK, icoac_sim_model_failed(&model, one, &failed));
        TEST_ASSERT_EQUAL_MEMORY(one, lanes[0], sizeof one);
        TEST_ASSERT_EQUAL_INT(failed, ended[0]);
        TEST_ASSERT_EQUAL_MEMORY(before[1], lanes[1], sizeof one);
        TEST_ASSERT_EQUAL_INT(1, ended[1]);
        TEST_ASSERT_EQUAL_MEMORY(before[2], lanes[2], sizeof one);
        TEST_ASSERT_EQUAL_INT(1, ended[2]);
        TEST_ASSERT_EQUAL_INT(1, ended[3]);
        TEST_ASSERT_EQUAL_INT(ICOAC_SIM_OK, icoac_sim_model_step_lanes(&model, NULL, NULL, NULL, 0));
        TEST_ASSERT_EQUAL_INT(ICOAC_SIM_ERR_BAD_ARGUMENT, icoac_sim_model_step_lanes(&model, NULL, u, ended, 1));
        TEST_ASSERT_EQUAL_INT(ICOAC_SIM_ERR_BAD_ARGUMENT, icoac_sim_model_step_lanes(&model, &lanes[0][0], u, ended, -1));
        model.dt = (double)NAN;
        TEST_ASSERT_EQUAL_INT(ICOAC_SIM_ERR_BAD_PLANT, icoac_sim_model_step_lanes(&model, &lanes[0][0], u, ended, 4));
    }
}

/* Every plant with an input saturation (a parameter named max_...) applies at most that input: a
 * step under ten times the limit equals the step under the limit, and a step under half of it
 * differs from both. */
static void test_input_saturation(void)
{
    int32_t i, k, n_saturating = 0;
    for (i = 0; i < icoac_sim_plant_count(); ++i) {
        const icoac_sim_plant_desc_t *d = plant(i);
        for (k = 0; k < d->n_params; ++k) {
            icoac_sim_model_t model;
            double at[ICOAC_SIM_MAX_STATE] = {0}, beyond[ICOAC_SIM_MAX_STATE] = {0}, half[ICOAC_SIM_MAX_STATE] = {0};
            if (strncmp(d->params[k].name, "max_", 4) != 0) {
                continue;
            }
            ++n_saturating;
            TEST_ASSERT_EQUAL_INT(ICOAC_SIM_OK, icoac_sim_model_default(&model, i));
            model.param[k] = 2.0;
            TEST_ASSERT_EQUAL_INT(ICOAC_SIM_OK, icoac_sim_model_step(&model, at, 2.0));
            TEST_ASSERT_EQUAL_INT(ICOAC_SIM_OK, icoac_sim_model_step(&model, beyond, 20.0));
            TEST_ASSERT_EQUAL_INT(ICOAC_SIM_OK, icoac_sim_model_step(&model, half, 1.0));
            TEST_ASSERT_EQUAL_MEMORY(at, beyond, sizeof at);
            TEST_ASSERT_TRUE(memcmp(at, half, sizeof at) != 0);
            TEST_ASSERT_EQUAL_INT(ICOAC_SIM_OK, icoac_sim_model_step(&model, beyond, -20.0));
            TEST_ASSERT_EQUAL_INT(ICOAC_SIM_OK, icoac_sim_model_step(&model, at, -2.0));
            TEST_ASSERT_EQUAL_MEMORY(at, beyond, sizeof at);
        }
    }
    TEST_ASSERT_EQUAL_INT(icoac_sim_plant_count(), n_saturating);
}

/* 1 when the default model of plant i fails with component c at value v (the rest 0). */
static int32_t fails_at(int32_t i, int32_t c, double v)
{
    icoac_sim_model_t model;
    double s[ICOAC_SIM_MAX_STATE] = {0};
    int32_t failed = -1;
    TEST_ASSERT_EQUAL_INT(ICOAC_SIM_OK, icoac_sim_model_default(&model, i));
    s[c] = v;
    TEST_ASSERT_EQUAL_INT(ICOAC_SIM_OK, icoac_sim_model_failed(&model, s, &failed));
    return failed;
}

/* Each plant's failure test: every parameter named a limit bounds at least one state component,
 * inside on the limit, outside just beyond it on either side. */
static void test_failure_limits(void)
{
    int32_t i, j, c;
    for (i = 0; i < icoac_sim_plant_count(); ++i) {
        const icoac_sim_plant_desc_t *d = plant(i);
        for (j = 0; j < d->n_params; ++j) {
            const double lim = d->params[j].value;
            int bounded = 0;
            if (strstr(d->params[j].name, "limit") == NULL) {
                continue;
            }
            for (c = 0; c < d->n_state; ++c) {
                if (fails_at(i, c, lim) != 0 || fails_at(i, c, nextafter(lim, 1e9)) == 0) {
                    continue; /* not bounded by this limit (inside beyond it, or outside another one) */
                }
                ++bounded;
                TEST_ASSERT_EQUAL_INT(0, fails_at(i, c, -lim));
                TEST_ASSERT_EQUAL_INT(1, fails_at(i, c, -nextafter(lim, 1e9)));
            }
            if (bounded == 0) {
                TEST_PRINTF("%s: %s bounds no state component", d->name, d->params[j].name);
                TEST_FAIL();
            }
        }
    }
}

static void test_grids(void)
{
    static icoac_sim_cell_t cells[4096];
    int32_t i;
    for (i = 0; i < icoac_sim_plant_count(); ++i) {
        const icoac_sim_plant_desc_t *d = plant(i);
        const int64_t n = (int64_t)d->rows.count * d->cols.count;
        const double to_rad = ICOAC_SIM_PI / 180.0;
        const double row_last = d->rows.first + d->rows.step * (d->rows.count - 1);
        const double col_last = d->cols.first + d->cols.step * (d->cols.count - 1);
        TEST_ASSERT_TRUE(n >= 2 && n <= (int64_t)(sizeof cells / sizeof cells[0]));
        TEST_ASSERT_EQUAL_INT(ICOAC_SIM_OK, icoac_sim_plant_grid(i, cells, n, 7u));
        assert_close(cells[0].theta0, d->rows.first * (d->rows.degrees ? to_rad : 1.0), 1e-15);
        assert_close(cells[0].x0, d->cols.first * (d->cols.degrees ? to_rad : 1.0), 1e-15);
        assert_close(cells[n - 1].theta0, row_last * (d->rows.degrees ? to_rad : 1.0), 1e-12);
        assert_close(cells[n - 1].x0, col_last * (d->cols.degrees ? to_rad : 1.0), 1e-12);
        TEST_ASSERT_EQUAL_INT(ICOAC_SIM_PENDING, cells[n - 1].outcome);
        TEST_ASSERT_TRUE(cells[1].seed != cells[0].seed && cells[0].seed == icoac_mix_seed(7u, 0u));
        TEST_ASSERT_EQUAL_INT(ICOAC_SIM_ERR_BAD_ARGUMENT, icoac_sim_plant_grid(i, cells, n - 1, 7u));
    }
    TEST_ASSERT_EQUAL_INT(ICOAC_SIM_ERR_BAD_PLANT, icoac_sim_plant_grid(-1, cells, 1, 7u));
    TEST_ASSERT_EQUAL_INT(ICOAC_SIM_ERR_BAD_ARGUMENT, icoac_sim_plant_grid(0, NULL, 1225, 7u));
}

/* A trial's start through the interface is the trial loop's (the state a one-step trajectory
 * records first): the cell's coordinates, the plant's start values, and the drawn components. */
static void test_trial_start(void)
{
    int32_t i, c;
    for (i = 0; i < icoac_sim_plant_count(); ++i) {
        const icoac_sim_plant_desc_t *d = plant(i);
        icoac_config_t cfg;
        icoac_sim_model_t model;
        icoac_sim_cell_t cell;
        icoac_rng_t rng;
        double states[2 * ICOAC_SIM_MAX_STATE], forces[1], s[ICOAC_SIM_MAX_STATE];
        int64_t n_steps = 0;
        TEST_ASSERT_EQUAL_INT(ICOAC_SIM_OK, icoac_sim_plant_task(i, NULL, &cfg));
        TEST_ASSERT_EQUAL_INT(ICOAC_SIM_OK, icoac_sim_model_default(&model, i));
        memset(&cell, 0, sizeof cell);
        cell.x0 = 0.7;
        cell.theta0 = -0.1;
        TEST_ASSERT_EQUAL_INT(ICOAC_SIM_OK, icoac_sim_trajectory(&cfg, &model, NULL, cell.x0, cell.theta0, 0.05, 99u,
                                                                 1, states, forces, &n_steps));
        icoac_rng_seed(&rng, 99u, ICOAC_SIM_START_STREAM);
        TEST_ASSERT_EQUAL_INT(ICOAC_SIM_OK, icoac_sim_model_start(&model, &cell, 0.05, &rng, s));
        TEST_ASSERT_EQUAL_MEMORY(states, s, (size_t)d->n_state * sizeof s[0]);
        for (c = 0; c < d->n_state; ++c) {
            if (c == d->rows.component) {
                TEST_ASSERT_TRUE(s[c] == cell.theta0);
            } else if (c == d->cols.component) {
                TEST_ASSERT_TRUE(s[c] == cell.x0);
            } else if (d->drawn[c]) {
                TEST_ASSERT_TRUE(fabs(s[c]) < 0.05 && s[c] != 0.0);
            } else {
                TEST_ASSERT_TRUE(s[c] == d->start[c]);
            }
        }
        TEST_ASSERT_EQUAL_INT(ICOAC_SIM_ERR_BAD_ARGUMENT, icoac_sim_model_start(&model, &cell, -1.0, &rng, s));
        cell.x0 = (double)NAN;
        TEST_ASSERT_EQUAL_INT(ICOAC_SIM_ERR_BAD_ARGUMENT, icoac_sim_model_start(&model, &cell, 0.05, &rng, s));
    }
}

/* No input, no friction (the Furuta motor disconnected: torque constant 0), RK4 at 1 ms for
 * 20 s from a tilted start: the energy stays within 1e-6 of its scale. */
static void test_energy_conserved(void)
{
    int32_t i, c, k;
    for (i = 0; i < icoac_sim_plant_count(); ++i) {
        const icoac_sim_plant_desc_t *d = plant(i);
        icoac_sim_model_t model;
        double s[ICOAC_SIM_MAX_STATE] = {0}, e0 = 0.0, e = 0.0, scale, drift = 0.0;
        TEST_ASSERT_EQUAL_INT(ICOAC_SIM_OK, icoac_sim_model_default(&model, i));
        for (c = 0; c < d->n_params; ++c) {
            if (strcmp(d->params[c].name, "torque_constant") == 0 || strstr(d->params[c].name, "damping") != NULL) {
                model.param[c] = 0.0;
            }
            if (strstr(d->params[c].name, "limit") != NULL) {
                model.param[c] = d->params[c].max; /* let it swing */
            }
        }
        model.integrator = ICOAC_SIM_RK4;
        model.dt = 1e-3;
        for (c = 0; c < d->n_state; ++c) {
            s[c] = 0.3 / (c + 1);
        }
        TEST_ASSERT_EQUAL_INT(ICOAC_SIM_OK, icoac_sim_model_energy(&model, s, &e0));
        /* the scale: the energy of the upright at rest, or the start's above it, whichever is the
         * larger (a plant's potential may be 0 or negative at its upright) */
        {
            double up[ICOAC_SIM_MAX_STATE] = {0}, e_up = 0.0;
            TEST_ASSERT_EQUAL_INT(ICOAC_SIM_OK, icoac_sim_model_energy(&model, up, &e_up));
            scale = fmax(fabs(e_up), fabs(e0 - e_up));
            TEST_ASSERT_TRUE(scale > 0.0);
        }
        for (k = 0; k < 20000; ++k) {
            TEST_ASSERT_EQUAL_INT(ICOAC_SIM_OK, icoac_sim_model_step(&model, s, 0.0));
            if (k % 100 == 99) {
                TEST_ASSERT_EQUAL_INT(ICOAC_SIM_OK, icoac_sim_model_energy(&model, s, &e));
                drift = fmax(drift, fabs(e - e0));
            }
        }
        TEST_PRINTF("%s: energy drift %g of %g", d->name, drift, scale);
        if (!(drift <= 1e-6 * scale)) {
            TEST_PRINTF("%s: energy drift %g, scale %g", d->name, drift, scale);
            TEST_FAIL();
        }
        /* and it moved: a real test */
        TEST_ASSERT_TRUE(fabs(s[d->rows.component] - 0.3 / (d->rows.component + 1)) > 0.01);
    }
}

void setUp(void) {}
void tearDown(void) {}

/* 1 when word is one of the space-separated words of list. */
static int listed(const char *list, const char *word)
{
    const size_t n = strlen(word);
    while (*list != '\0') {
        const size_t len = strcspn(list, " ");
        if (len == n && strncmp(list, word, n) == 0) {
            return 1;
        }
        list += len + (list[len] == ' ');
    }
    return 0;
}

/* Every plant's task is a configuration the controller accepts, with one input per state
 * component; its learner settings keep it valid and apply to exactly the conditions they name. */
static void test_task_presets(void)
{
    static const char *const conditions[] = {"ico", "ico-rl", "ico-mean-rl", "rl-ico-cov", "rl", "ico-search",
                                             "search", "rl-ico"};
    const int32_t n = icoac_sim_plant_count();
    icoac_config_t cfg, before;
    int32_t i, k;
    size_t c;
    for (i = 0; i < n; ++i) {
        const icoac_sim_plant_desc_t *d = plant(i);
        if (d->task == NULL) {
            TEST_ASSERT_EQUAL_INT(ICOAC_SIM_ERR_BAD_PLANT, icoac_sim_plant_task(i, NULL, &cfg));
            continue;
        }
        TEST_ASSERT_TRUE(strlen(d->task->source) > 0 && d->task->n_learners >= 0);
        TEST_ASSERT_EQUAL_INT(ICOAC_SIM_OK, icoac_sim_plant_task(i, NULL, &cfg));
        TEST_ASSERT_EQUAL_INT(d->n_state, cfg.task.n_inputs);
        TEST_ASSERT_EQUAL_INT(ICOAC_OK, icoac_config_check(&cfg));
        for (c = 0; c < sizeof conditions / sizeof conditions[0]; ++c) {
            int named = 0;
            for (k = 0; k < d->task->n_learners; ++k) {
                named += listed(d->task->learners[k].conditions, conditions[c]);
            }
            before = cfg;
            TEST_ASSERT_EQUAL_INT(ICOAC_SIM_OK, icoac_sim_plant_learner(i, conditions[c], &cfg));
            TEST_ASSERT_EQUAL_INT(ICOAC_OK, icoac_config_check(&cfg));
            TEST_ASSERT_TRUE(named <= 1);
            if (named == 0) { /* "ico" or "rl-ico" only inside another name: no match */
                TEST_ASSERT_EQUAL_MEMORY(&before, &cfg, sizeof cfg);
            }
        }
    }
    TEST_ASSERT_EQUAL_INT(ICOAC_SIM_ERR_BAD_PLANT, icoac_sim_plant_task(n, NULL, &cfg));
    TEST_ASSERT_EQUAL_INT(ICOAC_SIM_ERR_BAD_PLANT, icoac_sim_plant_learner(-1, "rl", &cfg));
    TEST_ASSERT_EQUAL_INT(ICOAC_SIM_ERR_BAD_ARGUMENT, icoac_sim_plant_task(0, NULL, NULL));
    TEST_ASSERT_EQUAL_INT(ICOAC_SIM_ERR_BAD_ARGUMENT, icoac_sim_plant_learner(0, NULL, &cfg));
    /* the cart-pole's task is the controller's defaults */
    icoac_config_default(&before);
    TEST_ASSERT_EQUAL_INT(ICOAC_SIM_OK, icoac_sim_plant_task(ICOAC_SIM_CART_POLE, NULL, &cfg));
    TEST_ASSERT_EQUAL_MEMORY(&before, &cfg, sizeof cfg);
    TEST_ASSERT_EQUAL_INT(1, plant(ICOAC_SIM_CART_POLE)->task->paper);
}

/* A task's knobs: their defaults are the task (NULL gives the same configuration), each at another
 * value within its range changes the configuration and keeps it valid, and a knob outside its range
 * or not finite is refused with the configuration left as it was. */
static void test_task_knobs(void)
{
    const int32_t n = icoac_sim_plant_count();
    icoac_config_t cfg, defaults, moved;
    double knob[ICOAC_SIM_MAX_TASK_KNOBS];
    int32_t i, k, with_knobs = 0;
    for (i = 0; i < n; ++i) {
        const icoac_sim_task_t *task = plant(i)->task;
        if (task == NULL) {
            continue;
        }
        TEST_ASSERT_TRUE(task->n_knobs >= 0 && task->n_knobs <= ICOAC_SIM_MAX_TASK_KNOBS);
        with_knobs += task->n_knobs > 0;
        TEST_ASSERT_EQUAL_INT(ICOAC_SIM_OK, icoac_sim_plant_task(i, NULL, &defaults));
        for (k = 0; k < task->n_knobs; ++k) {
            const icoac_sim_param_t *p = &task->knobs[k];
            TEST_ASSERT_TRUE(strlen(p->name) > 0 && strlen(p->doc) > 0 && p->min <= p->value && p->value <= p->max);
            knob[k] = p->value;
        }
        TEST_ASSERT_EQUAL_INT(ICOAC_SIM_OK, icoac_sim_plant_task(i, knob, &cfg));
        TEST_ASSERT_EQUAL_MEMORY(&defaults, &cfg, sizeof cfg);
        for (k = 0; k < task->n_knobs; ++k) {
            const icoac_sim_param_t *p = &task->knobs[k];
            const double bad[3] = {p->max * 2.0 + 1.0, p->min - 1.0, NAN};
            size_t b;
            knob[k] = p->value == p->max ? p->min : 0.5 * (p->value + p->max);
            TEST_ASSERT_EQUAL_INT(ICOAC_SIM_OK, icoac_sim_plant_task(i, knob, &moved));
            TEST_ASSERT_EQUAL_INT(ICOAC_OK, icoac_config_check(&moved));
            TEST_ASSERT_TRUE(memcmp(&moved, &defaults, sizeof moved) != 0);
            for (b = 0; b < 3; ++b) {
                knob[k] = bad[b];
                cfg = moved;
                TEST_ASSERT_EQUAL_INT(ICOAC_SIM_ERR_BAD_PLANT, icoac_sim_plant_task(i, knob, &cfg));
                TEST_ASSERT_EQUAL_MEMORY(&moved, &cfg, sizeof cfg);
            }
            knob[k] = p->value;
        }
    }
    TEST_ASSERT_TRUE(with_knobs >= 2);
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_registry);
    RUN_TEST(test_model_checks);
    RUN_TEST(test_nonfinite_input);
    RUN_TEST(test_step_lanes);
    RUN_TEST(test_input_saturation);
    RUN_TEST(test_failure_limits);
    RUN_TEST(test_grids);
    RUN_TEST(test_trial_start);
    RUN_TEST(test_energy_conserved);
    RUN_TEST(test_task_presets);
    RUN_TEST(test_task_knobs);
    return UNITY_END();
}
