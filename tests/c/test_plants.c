/* SPDX-License-Identifier: Apache-2.0 */
/* The plant registry (sim_host/src/plant_registry.c, model.c, plants/): descriptors consistent,
 * the cart-pole through the interface bit for bit the icoac_sim_plant_t functions, parameter
 * checks, named statuses for non-finite input, grids and trial starts, and energy conservation
 * of every plant without input and friction. The dynamics against independently derived
 * equations are in tests/python/test_plants.py. */
#include "test_common.h"

#include <float.h>

#include "icoac_sim/icoac_sim.h"

static const icoac_sim_plant_desc_t *plant(int32_t i)
{
    const icoac_sim_plant_desc_t *d = icoac_sim_plant_info(i);
    assert_non_null(d);
    return d;
}

static void test_registry(void **unused)
{
    const int32_t n = icoac_sim_plant_count();
    int32_t i, j, c;
    (void)unused;
    assert_true(n >= 3);
    assert_string_equal(plant(ICOAC_SIM_CART_POLE)->name, "cart_pole");
    assert_int_equal(icoac_sim_plant_find("furuta"), 1);
    assert_int_equal(icoac_sim_plant_find("double_cart_pole"), 2);
    assert_int_equal(icoac_sim_plant_find("no_such_plant"), -1);
    assert_int_equal(icoac_sim_plant_find(NULL), -1);
    assert_null(icoac_sim_plant_info(-1));
    assert_null(icoac_sim_plant_info(n));
    for (i = 0; i < n; ++i) {
        const icoac_sim_plant_desc_t *d = plant(i);
        icoac_sim_model_t model;
        double s[ICOAC_SIM_MAX_STATE];
        int32_t failed = -1;
        assert_int_equal(icoac_sim_plant_find(d->name), i);
        assert_true(d->n_state >= 2 && d->n_state <= ICOAC_SIM_MAX_STATE);
        assert_true(d->n_params >= 1 && d->n_params <= ICOAC_SIM_MAX_PARAMS);
        assert_true(strlen(d->title) > 0 && strlen(d->source) > 0 && strlen(d->input.name) > 0);
        assert_true(d->step != NULL && d->derivatives != NULL && d->failed != NULL);
        for (c = 0; c < d->n_state; ++c) {
            assert_true(strlen(d->state[c].name) > 0 && strlen(d->state[c].unit) > 0);
            assert_true(d->observed[c] >= -1 && d->observed[c] < d->n_state);
            assert_true(d->drawn[c] == 0 || d->drawn[c] == 1);
        }
        for (j = 0; j < d->n_params; ++j) {
            assert_true(strlen(d->params[j].name) > 0 && d->params[j].min <= d->params[j].max);
            for (c = 0; c < j; ++c) {
                assert_true(strcmp(d->params[j].name, d->params[c].name) != 0);
            }
        }
        assert_true(d->rows.component != d->cols.component);
        assert_true(d->rows.component >= 0 && d->rows.component < d->n_state && !d->drawn[d->rows.component]);
        assert_true(d->cols.component >= 0 && d->cols.component < d->n_state && !d->drawn[d->cols.component]);
        assert_true(d->rows.count >= 1 && d->cols.count >= 1 && d->rows.count * d->cols.count <= 25 * 49);
        /* the defaults are valid and the start state balances */
        assert_int_equal(icoac_sim_model_default(&model, i), ICOAC_SIM_OK);
        assert_int_equal(icoac_sim_model_check(&model), ICOAC_SIM_OK);
        memcpy(s, d->start, sizeof s);
        assert_int_equal(icoac_sim_model_failed(&model, s, &failed), ICOAC_SIM_OK);
        assert_int_equal(failed, 0);
        /* the upright, at rest and without input, is an equilibrium */
        assert_int_equal(icoac_sim_model_step(&model, s, 0.0), ICOAC_SIM_OK);
        for (c = 0; c < d->n_state; ++c) {
            assert_true(s[c] == 0.0);
        }
    }
    assert_int_equal(icoac_sim_model_default(NULL, 0), ICOAC_SIM_ERR_BAD_ARGUMENT);
    {
        icoac_sim_model_t model;
        assert_int_equal(icoac_sim_model_default(&model, n), ICOAC_SIM_ERR_BAD_PLANT);
    }
}

/* A cart-pole plant with random valid parameters, dt and integrator. */
static void random_plant(test_rng_t *rng, icoac_sim_plant_t *p)
{
    icoac_sim_plant_default(p);
    p->gravity = test_uniform(rng, 1.0, 20.0);
    p->cart_mass = test_uniform(rng, 0.1, 5.0);
    p->pole_mass = test_uniform(rng, 0.01, 2.0);
    p->half_length = test_uniform(rng, 0.1, 2.0);
    p->dt = test_uniform(rng, 1e-4, 0.05);
    p->x_limit = test_uniform(rng, 0.5, 5.0);
    p->theta_limit = test_uniform(rng, 0.05, 1.5);
    p->integrator = test_rng_u64(rng) & 1u ? ICOAC_SIM_RK4 : ICOAC_SIM_EULER;
}

static void test_cart_pole_bit_for_bit(void **unused)
{
    test_rng_t rng = {0x9E3779B97F4A7C15ULL};
    int k, i;
    (void)unused;
    for (k = 0; k < 20000; ++k) {
        icoac_sim_plant_t p;
        icoac_sim_model_t model;
        double old_s[4], new_s[ICOAC_SIM_MAX_STATE] = {0}, ds[ICOAC_SIM_MAX_STATE];
        double force = test_uniform(&rng, -50.0, 50.0);
        int32_t failed = -1;
        if (k == 0) {
            icoac_sim_plant_default(&p);
        } else {
            random_plant(&rng, &p);
        }
        assert_int_equal(icoac_sim_model_from_plant(&p, &model), ICOAC_SIM_OK);
        assert_int_equal(icoac_sim_model_check(&model), ICOAC_SIM_OK);
        for (i = 0; i < 4; ++i) {
            old_s[i] = new_s[i] = test_uniform(&rng, -3.0, 3.0);
        }
        if (k % 7 == 0) {
            old_s[0] = new_s[0] = p.x_limit; /* on the limits: not failed */
            old_s[2] = new_s[2] = -p.theta_limit;
        }
        assert_int_equal(icoac_sim_model_failed(&model, new_s, &failed), ICOAC_SIM_OK);
        assert_int_equal(failed, icoac_sim_failed(&p, old_s));
        assert_int_equal(icoac_sim_model_derivatives(&model, new_s, force, ds), ICOAC_SIM_OK);
        assert_int_equal(icoac_sim_plant_step(&p, old_s, force), ICOAC_SIM_OK);
        assert_int_equal(icoac_sim_model_step(&model, new_s, force), ICOAC_SIM_OK);
        assert_memory_equal(old_s, new_s, sizeof old_s);
        /* Euler is s + dt ds */
        if (p.integrator == ICOAC_SIM_EULER) {
            assert_true(old_s[1] - new_s[1] == 0.0 && isfinite(ds[1]));
        }
    }
    /* the default plant struct and the registry's defaults agree */
    {
        icoac_sim_plant_t p;
        icoac_sim_model_t a, b;
        icoac_sim_plant_default(&p);
        assert_int_equal(icoac_sim_model_from_plant(&p, &a), ICOAC_SIM_OK);
        assert_int_equal(icoac_sim_model_default(&b, ICOAC_SIM_CART_POLE), ICOAC_SIM_OK);
        assert_memory_equal(&a, &b, sizeof a);
    }
    assert_int_equal(icoac_sim_model_from_plant(NULL, NULL), ICOAC_SIM_ERR_BAD_ARGUMENT);
}

static void test_model_checks(void **unused)
{
    static const double bad[] = {(double)NAN, (double)INFINITY, -(double)INFINITY, 1e-310, -1.0, 2e6};
    int32_t i, j;
    size_t b;
    (void)unused;
    for (i = 0; i < icoac_sim_plant_count(); ++i) {
        const icoac_sim_plant_desc_t *d = plant(i);
        icoac_sim_model_t model;
        for (j = 0; j < ICOAC_SIM_MAX_PARAMS; ++j) {
            for (b = 0; b < sizeof bad / sizeof bad[0]; ++b) {
                assert_int_equal(icoac_sim_model_default(&model, i), ICOAC_SIM_OK);
                model.param[j] = bad[b];
                assert_int_equal(icoac_sim_model_check(&model), ICOAC_SIM_ERR_BAD_PLANT);
            }
            if (j < d->n_params) { /* the bounds themselves are valid */
                model.param[j] = d->params[j].min;
                assert_int_equal(icoac_sim_model_check(&model), ICOAC_SIM_OK);
                model.param[j] = d->params[j].max;
                assert_int_equal(icoac_sim_model_check(&model), ICOAC_SIM_OK);
            } else { /* unused parameters must be 0 */
                model.param[j] = 1.0;
                assert_int_equal(icoac_sim_model_check(&model), ICOAC_SIM_ERR_BAD_PLANT);
            }
        }
        assert_int_equal(icoac_sim_model_default(&model, i), ICOAC_SIM_OK);
        model.dt = 0.0;
        assert_int_equal(icoac_sim_model_check(&model), ICOAC_SIM_ERR_BAD_PLANT);
        model.dt = 0.01;
        model.integrator = 2;
        assert_int_equal(icoac_sim_model_check(&model), ICOAC_SIM_ERR_BAD_PLANT);
        model.integrator = ICOAC_SIM_RK4;
        model.plant = icoac_sim_plant_count();
        assert_int_equal(icoac_sim_model_check(&model), ICOAC_SIM_ERR_BAD_PLANT);
        model.plant = -1;
        assert_int_equal(icoac_sim_model_check(&model), ICOAC_SIM_ERR_BAD_PLANT);
    }
    assert_int_equal(icoac_sim_model_check(NULL), ICOAC_SIM_ERR_BAD_ARGUMENT);
}

/* Non-finite state or input, or a step that overflows: a named status, the state untouched. */
static void test_nonfinite_input(void **unused)
{
    int32_t i, c;
    (void)unused;
    for (i = 0; i < icoac_sim_plant_count(); ++i) {
        const icoac_sim_plant_desc_t *d = plant(i);
        icoac_sim_model_t model;
        double s[ICOAC_SIM_MAX_STATE] = {0}, before[ICOAC_SIM_MAX_STATE], ds[ICOAC_SIM_MAX_STATE], e = 0.0;
        int32_t failed = 0;
        assert_int_equal(icoac_sim_model_default(&model, i), ICOAC_SIM_OK);
        for (c = 0; c < d->n_state; ++c) {
            s[c] = 0.01 * (c + 1);
        }
        memcpy(before, s, sizeof s);
        assert_int_equal(icoac_sim_model_step(&model, s, (double)NAN), ICOAC_SIM_ERR_NONFINITE);
        assert_int_equal(icoac_sim_model_step(&model, s, (double)INFINITY), ICOAC_SIM_ERR_NONFINITE);
        assert_int_equal(icoac_sim_model_derivatives(&model, s, (double)NAN, ds), ICOAC_SIM_ERR_NONFINITE);
        assert_int_equal(icoac_sim_model_step(&model, s, DBL_MAX), ICOAC_SIM_ERR_NONFINITE); /* overflows */
        assert_memory_equal(s, before, sizeof s);
        for (c = 0; c < d->n_state; ++c) {
            s[c] = (double)NAN;
            assert_int_equal(icoac_sim_model_step(&model, s, 0.0), ICOAC_SIM_ERR_NONFINITE);
            assert_int_equal(icoac_sim_model_energy(&model, s, &e), ICOAC_SIM_ERR_NONFINITE);
            assert_int_equal(icoac_sim_model_failed(&model, s, &failed), ICOAC_SIM_OK);
            assert_int_equal(failed, 1);
            s[c] = (double)INFINITY;
            assert_int_equal(icoac_sim_model_failed(&model, s, &failed), ICOAC_SIM_OK);
            assert_int_equal(failed, 1);
            assert_true(isnan(s[c] - s[c]));
            s[c] = before[c];
        }
        assert_int_equal(icoac_sim_model_step(&model, NULL, 0.0), ICOAC_SIM_ERR_BAD_ARGUMENT);
        assert_int_equal(icoac_sim_model_failed(&model, s, NULL), ICOAC_SIM_ERR_BAD_ARGUMENT);
        assert_int_equal(icoac_sim_model_energy(&model, s, NULL), ICOAC_SIM_ERR_BAD_ARGUMENT);
        assert_int_equal(icoac_sim_model_derivatives(&model, s, 0.0, NULL), ICOAC_SIM_ERR_BAD_ARGUMENT);
        model.dt = (double)NAN;
        assert_int_equal(icoac_sim_model_step(&model, s, 0.0), ICOAC_SIM_ERR_BAD_PLANT);
        assert_memory_equal(s, before, sizeof s);
    }
    assert_non_null(icoac_sim_status_str(ICOAC_SIM_ERR_NONFINITE));
    assert_true(strstr(icoac_sim_status_str(ICOAC_SIM_ERR_NONFINITE), "not finite") != NULL);
}

/* Each plant's failure test: inside on its limits, outside just beyond any of them. */
static void test_failure_limits(void **unused)
{
    /* {plant, component, parameter of its limit} */
    static const int32_t limits[][3] = {{0, 0, 4}, {0, 2, 5}, {1, 0, 10}, {1, 2, 11}, {2, 0, 6}, {2, 2, 7}, {2, 4, 7}};
    size_t k;
    (void)unused;
    for (k = 0; k < sizeof limits / sizeof limits[0]; ++k) {
        icoac_sim_model_t model;
        double s[ICOAC_SIM_MAX_STATE] = {0};
        const int32_t c = limits[k][1];
        double lim;
        int32_t failed = -1;
        assert_int_equal(icoac_sim_model_default(&model, limits[k][0]), ICOAC_SIM_OK);
        lim = model.param[limits[k][2]];
        assert_true(strstr(plant(limits[k][0])->params[limits[k][2]].name, "limit") != NULL);
        s[c] = lim;
        assert_int_equal(icoac_sim_model_failed(&model, s, &failed), ICOAC_SIM_OK);
        assert_int_equal(failed, 0);
        s[c] = -lim;
        assert_int_equal(icoac_sim_model_failed(&model, s, &failed), ICOAC_SIM_OK);
        assert_int_equal(failed, 0);
        s[c] = nextafter(lim, 1e9);
        assert_int_equal(icoac_sim_model_failed(&model, s, &failed), ICOAC_SIM_OK);
        assert_int_equal(failed, 1);
        s[c] = -nextafter(lim, 1e9);
        assert_int_equal(icoac_sim_model_failed(&model, s, &failed), ICOAC_SIM_OK);
        assert_int_equal(failed, 1);
    }
}

static void test_grids(void **unused)
{
    static icoac_sim_cell_t paper[ICOAC_SIM_GRID_CELLS], cells[ICOAC_SIM_GRID_CELLS];
    int32_t i;
    (void)unused;
    assert_int_equal(icoac_sim_paper_grid(paper, ICOAC_SIM_GRID_CELLS, 7u), ICOAC_SIM_OK);
    assert_int_equal(icoac_sim_plant_grid(ICOAC_SIM_CART_POLE, cells, ICOAC_SIM_GRID_CELLS, 7u), ICOAC_SIM_OK);
    assert_memory_equal(paper, cells, sizeof cells);
    for (i = 1; i < icoac_sim_plant_count(); ++i) {
        const icoac_sim_plant_desc_t *d = plant(i);
        const int64_t n = (int64_t)d->rows.count * d->cols.count;
        const double to_rad = ICOAC_SIM_PI / 180.0;
        const double row_last = d->rows.first + d->rows.step * (d->rows.count - 1);
        const double col_last = d->cols.first + d->cols.step * (d->cols.count - 1);
        assert_int_equal(icoac_sim_plant_grid(i, cells, n, 7u), ICOAC_SIM_OK);
        assert_close(cells[0].theta0, d->rows.first * (d->rows.degrees ? to_rad : 1.0), 1e-15);
        assert_close(cells[0].x0, d->cols.first * (d->cols.degrees ? to_rad : 1.0), 1e-15);
        assert_close(cells[n - 1].theta0, row_last * (d->rows.degrees ? to_rad : 1.0), 1e-12);
        assert_close(cells[n - 1].x0, col_last * (d->cols.degrees ? to_rad : 1.0), 1e-12);
        assert_int_equal(cells[n - 1].outcome, ICOAC_SIM_PENDING);
        assert_true(cells[1].seed != cells[0].seed && cells[0].seed == paper[0].seed);
        assert_int_equal(icoac_sim_plant_grid(i, cells, n - 1, 7u), ICOAC_SIM_ERR_BAD_ARGUMENT);
    }
    assert_int_equal(icoac_sim_plant_grid(-1, cells, 1, 7u), ICOAC_SIM_ERR_BAD_PLANT);
    assert_int_equal(icoac_sim_plant_grid(0, NULL, ICOAC_SIM_GRID_CELLS, 7u), ICOAC_SIM_ERR_BAD_ARGUMENT);
}

/* The cart-pole's start through the interface is the trial loop's (the state a one-step
 * trajectory records first); the other plants take the cell's coordinates and draw the rest. */
static void test_trial_start(void **unused)
{
    icoac_config_t cfg;
    icoac_sim_plant_t p;
    icoac_sim_model_t model;
    icoac_sim_cell_t cell;
    icoac_rng_t rng;
    double states[2 * 4], forces[1], s[ICOAC_SIM_MAX_STATE];
    int64_t n_steps = 0;
    int32_t i, c;
    (void)unused;
    icoac_config_default(&cfg);
    icoac_sim_plant_default(&p);
    memset(&cell, 0, sizeof cell);
    cell.x0 = 0.7;
    cell.theta0 = -0.1;
    assert_int_equal(icoac_sim_trajectory(&cfg, &p, NULL, cell.x0, cell.theta0, 0.05, 99u, 1, states, forces,
                                          &n_steps),
                     ICOAC_SIM_OK);
    assert_int_equal(icoac_sim_model_default(&model, ICOAC_SIM_CART_POLE), ICOAC_SIM_OK);
    icoac_rng_seed(&rng, 99u, 2u);
    assert_int_equal(icoac_sim_model_start(&model, &cell, 0.05, &rng, s), ICOAC_SIM_OK);
    assert_memory_equal(s, states, 4 * sizeof s[0]);
    for (i = 1; i < icoac_sim_plant_count(); ++i) {
        const icoac_sim_plant_desc_t *d = plant(i);
        assert_int_equal(icoac_sim_model_default(&model, i), ICOAC_SIM_OK);
        assert_int_equal(icoac_sim_model_start(&model, &cell, 0.05, &rng, s), ICOAC_SIM_OK);
        for (c = 0; c < d->n_state; ++c) {
            if (c == d->rows.component) {
                assert_true(s[c] == cell.theta0);
            } else if (c == d->cols.component) {
                assert_true(s[c] == cell.x0);
            } else if (d->drawn[c]) {
                assert_true(fabs(s[c]) < 0.05 && s[c] != 0.0);
            } else {
                assert_true(s[c] == d->start[c]);
            }
        }
        assert_int_equal(icoac_sim_model_start(&model, &cell, -1.0, &rng, s), ICOAC_SIM_ERR_BAD_ARGUMENT);
        cell.x0 = (double)NAN;
        assert_int_equal(icoac_sim_model_start(&model, &cell, 0.05, &rng, s), ICOAC_SIM_ERR_BAD_ARGUMENT);
        cell.x0 = 0.7;
    }
}

/* No input, no friction (the Furuta motor disconnected: torque constant 0), RK4 at 1 ms for
 * 20 s from a tilted start: the energy stays within 1e-6 of its scale. */
static void test_energy_conserved(void **unused)
{
    int32_t i, c, k;
    (void)unused;
    for (i = 0; i < icoac_sim_plant_count(); ++i) {
        const icoac_sim_plant_desc_t *d = plant(i);
        icoac_sim_model_t model;
        double s[ICOAC_SIM_MAX_STATE] = {0}, e0 = 0.0, e = 0.0, scale, drift = 0.0;
        assert_int_equal(icoac_sim_model_default(&model, i), ICOAC_SIM_OK);
        for (c = 0; c < d->n_params; ++c) {
            if (strcmp(d->params[c].name, "torque_constant") == 0) {
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
        assert_int_equal(icoac_sim_model_energy(&model, s, &e0), ICOAC_SIM_OK);
        /* the potential energy of the upright at rest sets the scale */
        {
            double up[ICOAC_SIM_MAX_STATE] = {0}, e_up = 0.0;
            assert_int_equal(icoac_sim_model_energy(&model, up, &e_up), ICOAC_SIM_OK);
            scale = fabs(e_up);
            assert_true(scale > 0.0);
        }
        for (k = 0; k < 20000; ++k) {
            assert_int_equal(icoac_sim_model_step(&model, s, 0.0), ICOAC_SIM_OK);
            if (k % 100 == 99) {
                assert_int_equal(icoac_sim_model_energy(&model, s, &e), ICOAC_SIM_OK);
                drift = fmax(drift, fabs(e - e0));
            }
        }
        print_message("%s: energy drift %.3g of %.3g\n", d->name, drift, scale);
        if (!(drift <= 1e-6 * scale)) {
            print_error("%s: energy drift %.3g, scale %.3g\n", d->name, drift, scale);
            fail();
        }
        /* and it moved: a real test */
        assert_true(fabs(s[d->rows.component] - 0.3 / (d->rows.component + 1)) > 0.01);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_registry),
        cmocka_unit_test(test_cart_pole_bit_for_bit),
        cmocka_unit_test(test_model_checks),
        cmocka_unit_test(test_nonfinite_input),
        cmocka_unit_test(test_failure_limits),
        cmocka_unit_test(test_grids),
        cmocka_unit_test(test_trial_start),
        cmocka_unit_test(test_energy_conserved),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
