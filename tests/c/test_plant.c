/* SPDX-License-Identifier: Apache-2.0 */
/* The cart-pole (the registry's plant 0) against an independent evaluation of its equations
 * (method.md, plant); its failure test, defaults and parameter checks; the paper grid; run
 * parameters. The model API's checks common to every plant are in test_plants.c. */
#include "test_common.h"

#include <stdlib.h>

#include "test_sim_common.h"

/* The plant equations rearranged: multiply the theta equation through by (m_c + m_p), then
 * x_acc = (F + m_p l (thd^2 sin - th_acc cos)) / (m_c + m_p). Long double. */
static void ref_deriv(const long double s[4], long double force, long double ds[4])
{
    const long double g = 9.8L, mc = 1.0L, mp = 0.1L, l = 0.5L;
    const long double m = mc + mp;
    const long double sn = sinl(s[2]), cs = cosl(s[2]);
    const long double th_acc =
        (m * g * sn - cs * (force + mp * l * s[3] * s[3] * sn)) / (l * (4.0L / 3.0L * m - mp * cs * cs));
    const long double x_acc = (force + mp * l * (s[3] * s[3] * sn - th_acc * cs)) / m;
    ds[0] = s[1];
    ds[1] = x_acc;
    ds[2] = s[3];
    ds[3] = th_acc;
}

static void ref_euler(long double s[4], long double force, long double dt)
{
    long double ds[4];
    int i;
    ref_deriv(s, force, ds);
    for (i = 0; i < 4; ++i) {
        s[i] += dt * ds[i];
    }
}

static void ref_rk4(long double s[4], long double force, long double dt)
{
    long double k[4][4], t[4];
    int i, stage;
    static const long double frac[4] = {0.0L, 0.5L, 0.5L, 1.0L};
    for (stage = 0; stage < 4; ++stage) {
        for (i = 0; i < 4; ++i) {
            t[i] = s[i] + (stage ? frac[stage] * dt * k[stage - 1][i] : 0.0L);
        }
        ref_deriv(t, force, k[stage]);
    }
    for (i = 0; i < 4; ++i) {
        s[i] += dt / 6.0L * (k[0][i] + 2.0L * k[1][i] + 2.0L * k[2][i] + k[3][i]);
    }
}

static const double states[][4] = {
    {0.0, 0.0, 0.0, 0.0},          {0.5, -0.3, 0.1, 0.4},   {-2.0, 1.5, -0.2, -1.7},
    {1.2, 0.0, 0.2094, 3.0},       {0.0, 0.0, 1.3, -5.0},   {-0.7, 2.2, -0.05, 0.0},
};
static const double forces[] = {0.0, 1.0, -10.0, 37.5, -0.25};

static void check_integrator(int integrator)
{
    icoac_sim_model_t model = test_cart_pole();
    size_t a, f;
    int i;
    model.integrator = integrator;
    TEST_ASSERT_EQUAL_INT(ICOAC_SIM_OK, icoac_sim_model_check(&model));
    for (a = 0; a < sizeof states / sizeof states[0]; ++a) {
        for (f = 0; f < sizeof forces / sizeof forces[0]; ++f) {
            double s[4];
            long double r[4];
            for (i = 0; i < 4; ++i) {
                s[i] = states[a][i];
                r[i] = states[a][i];
            }
            TEST_ASSERT_EQUAL_INT(ICOAC_SIM_OK, test_cart_pole_step(&model, s, forces[f]));
            if (integrator == ICOAC_SIM_RK4) {
                ref_rk4(r, forces[f], 0.01L);
            } else {
                ref_euler(r, forces[f], 0.01L);
            }
            for (i = 0; i < 4; ++i) {
                assert_close(s[i], (double)r[i], 1e-12);
            }
        }
    }
}

static void test_euler_step(void)
{
    check_integrator(ICOAC_SIM_EULER);
}

static void test_rk4_step(void)
{
    check_integrator(ICOAC_SIM_RK4);
}

/* Sanity of the reference itself: hand values at the upright and the sign convention. */
static void test_reference_sanity(void)
{
    icoac_sim_model_t model = test_cart_pole();
    double s[4] = {0, 0, 0, 0};
    long double ds[4], r[4] = {0, 0, 0, 0};
    /* upright, F = 1 N: theta_acc = -1/1.1 / (0.5 (4/3 - 0.1/1.1)), x_acc = 1/1.1 - 0.1 * 0.5 * theta_acc / 1.1 */
    ref_deriv(r, 1.0L, ds);
    {
        const double th = -(1.0 / 1.1) / (0.5 * (4.0 / 3.0 - 0.1 / 1.1));
        assert_close((double)ds[3], th, 1e-15);
        assert_close((double)ds[1], 1.0 / 1.1 - 0.05 * th / 1.1, 1e-15);
    }
    /* pushing +x tips the pole toward -x; a pole leaning +x falls further +x */
    TEST_ASSERT_EQUAL_INT(ICOAC_SIM_OK, test_cart_pole_step(&model, s, 10.0));
    TEST_ASSERT_TRUE(s[1] > 0 && s[3] < 0 && s[0] == 0.0 && s[2] == 0.0); /* Euler: positions use old velocities */
    s[0] = s[1] = s[3] = 0;
    s[2] = 0.1;
    TEST_ASSERT_EQUAL_INT(ICOAC_SIM_OK, test_cart_pole_step(&model, s, 0.0));
    TEST_ASSERT_TRUE(s[3] > 0);
    /* RK4 and Euler differ (the switch is effective) */
    {
        double e[4] = {0.1, 0.2, 0.1, 0.3}, k[4] = {0.1, 0.2, 0.1, 0.3};
        TEST_ASSERT_EQUAL_INT(ICOAC_SIM_OK, test_cart_pole_step(&model, e, 3.0));
        model.integrator = ICOAC_SIM_RK4;
        TEST_ASSERT_EQUAL_INT(ICOAC_SIM_OK, test_cart_pole_step(&model, k, 3.0));
        TEST_ASSERT_TRUE(fabs(e[0] - k[0]) > 1e-6);
    }
}

static void test_failure_strict(void)
{
    const icoac_sim_model_t model = test_cart_pole();
    const double lim = 12.0 * TEST_PI / 180.0;
    double s[4];
    int c;
    assert_close(model.param[test_param(ICOAC_SIM_CART_POLE, "theta_limit")], lim, 1e-16);
    assert_close(model.param[test_param(ICOAC_SIM_CART_POLE, "x_limit")], 2.4, 0.0);
#define FAILED(x, th) (s[0] = (x), s[1] = 0.3, s[2] = (th), s[3] = -0.2, test_cart_pole_failed(&model, s))
    TEST_ASSERT_EQUAL_INT(0, FAILED(0.0, 0.0));
    TEST_ASSERT_EQUAL_INT(0, FAILED(2.4, 0.0));
    TEST_ASSERT_EQUAL_INT(0, FAILED(-2.4, 0.0));
    TEST_ASSERT_EQUAL_INT(1, FAILED(2.4 + 1e-12, 0.0));
    TEST_ASSERT_EQUAL_INT(1, FAILED(-2.4 - 1e-12, 0.0));
    TEST_ASSERT_EQUAL_INT(0, FAILED(0.0, lim));
    TEST_ASSERT_EQUAL_INT(0, FAILED(0.0, -lim));
    TEST_ASSERT_EQUAL_INT(0, FAILED(2.4, -lim));
    TEST_ASSERT_EQUAL_INT(1, FAILED(0.0, nextafter(lim, 1.0)));
    TEST_ASSERT_EQUAL_INT(1, FAILED(0.0, -nextafter(lim, 1.0)));
    TEST_ASSERT_EQUAL_INT(1, FAILED(0.0, lim + 1e-12));
    TEST_ASSERT_EQUAL_INT(1, FAILED((double)NAN, 0.0));
    TEST_ASSERT_EQUAL_INT(1, FAILED(0.0, (double)NAN));
    TEST_ASSERT_EQUAL_INT(1, FAILED((double)INFINITY, 0.0));
    TEST_ASSERT_EQUAL_INT(1, FAILED(0.0, -(double)INFINITY));
#undef FAILED
    /* non-finite velocities: the state is not finite (header contract) */
    for (c = 1; c <= 3; c += 2) {
        s[0] = 0.0;
        s[1] = 0.0;
        s[2] = 0.0;
        s[3] = 0.0;
        s[c] = (double)NAN;
        TEST_ASSERT_EQUAL_INT(1, test_cart_pole_failed(&model, s));
        s[c] = (double)INFINITY;
        TEST_ASSERT_EQUAL_INT(1, test_cart_pole_failed(&model, s));
    }
}

/* A cart-pole model with one value changed: a parameter by name, or dt / the integrator. */
typedef struct {
    const char *param; /* NULL: dt or integrator below */
    double value;
    double dt;
    int32_t integrator;
} plant_change_t;

static icoac_sim_model_t changed(const plant_change_t *c)
{
    icoac_sim_model_t m = test_cart_pole();
    if (c->param != NULL) {
        const int k = test_param(ICOAC_SIM_CART_POLE, c->param);
        TEST_ASSERT_TRUE(k >= 0);
        m.param[k] = c->value;
    } else {
        m.dt = c->dt;
        m.integrator = c->integrator;
    }
    return m;
}

static void test_plant_and_run_checks(void)
{
    static const plant_change_t bad[] = {
        {"gravity", 0.0, 0, 0}, {"gravity", (double)NAN, 0, 0}, {"cart_mass", -1.0, 0, 0},
        {"pole_mass", 0.0, 0, 0}, {"half_length", (double)INFINITY, 0, 0}, {NULL, 0, 0.0, 0},
        {NULL, 0, 1.5, 0}, {"x_limit", 0.0, 0, 0}, {"theta_limit", (double)NAN, 0, 0}, {NULL, 0, 0.01, 2},
        {NULL, 0, 0.01, -1},
        /* subnormal or absurd values the workers would flush to zero or overflow on */
        {NULL, 0, 1e-310, 0}, {NULL, 0, 9e-7, 0}, {"gravity", 1e-310, 0, 0}, {"gravity", 1e300, 0, 0},
        {"cart_mass", 4.9e-324, 0, 0}, {"pole_mass", 1e7, 0, 0}, {"half_length", 1e-9, 0, 0},
        {"x_limit", 1e300, 0, 0}, {"theta_limit", 4.0, 0, 0}};
    static const plant_change_t on_bounds[] = {
        {NULL, 0, ICOAC_SIM_DT_MIN, 0}, {"gravity", ICOAC_SIM_PHYS_MAX, 0, 0},
        {"theta_limit", ICOAC_SIM_THETA_LIMIT_MAX, 0, 0}};
    const icoac_sim_model_t model = test_cart_pole();
    icoac_sim_run_t run;
    size_t i;
    assert_close(model.param[test_param(ICOAC_SIM_CART_POLE, "gravity")], 9.8, 0);
    assert_close(model.param[test_param(ICOAC_SIM_CART_POLE, "cart_mass")], 1.0, 0);
    assert_close(model.param[test_param(ICOAC_SIM_CART_POLE, "pole_mass")], 0.1, 0);
    assert_close(model.param[test_param(ICOAC_SIM_CART_POLE, "half_length")], 0.5, 0);
    assert_close(model.dt, 0.01, 0);
    TEST_ASSERT_EQUAL_INT(ICOAC_SIM_EULER, model.integrator);
    for (i = 0; i < sizeof bad / sizeof bad[0]; ++i) {
        const icoac_sim_model_t m = changed(&bad[i]);
        TEST_ASSERT_EQUAL_INT(ICOAC_SIM_ERR_BAD_PLANT, icoac_sim_model_check(&m));
    }
    for (i = 0; i < sizeof on_bounds / sizeof on_bounds[0]; ++i) {
        const icoac_sim_model_t m = changed(&on_bounds[i]);
        TEST_ASSERT_EQUAL_INT(ICOAC_SIM_OK, icoac_sim_model_check(&m));
    }
    icoac_sim_run_default(&run);
    TEST_ASSERT_TRUE(run.max_trials == 100000 && run.success_steps == 100000);
    assert_close(run.init_velocity_noise, 1e-4, 0);
    TEST_ASSERT_EQUAL_INT(ICOAC_SIM_OK, icoac_sim_run_check(&run));
    run.max_trials = 0;
    TEST_ASSERT_EQUAL_INT(ICOAC_SIM_ERR_BAD_RUN, icoac_sim_run_check(&run));
    icoac_sim_run_default(&run);
    run.success_steps = -1;
    TEST_ASSERT_EQUAL_INT(ICOAC_SIM_ERR_BAD_RUN, icoac_sim_run_check(&run));
    icoac_sim_run_default(&run);
    run.init_velocity_noise = -1e-4;
    TEST_ASSERT_EQUAL_INT(ICOAC_SIM_ERR_BAD_RUN, icoac_sim_run_check(&run));
    run.init_velocity_noise = (double)NAN;
    TEST_ASSERT_EQUAL_INT(ICOAC_SIM_ERR_BAD_RUN, icoac_sim_run_check(&run));
    run.init_velocity_noise = 1e-310; /* subnormal */
    TEST_ASSERT_EQUAL_INT(ICOAC_SIM_ERR_BAD_RUN, icoac_sim_run_check(&run));
    run.init_velocity_noise = 1e4;
    TEST_ASSERT_EQUAL_INT(ICOAC_SIM_ERR_BAD_RUN, icoac_sim_run_check(&run));
    run.init_velocity_noise = 0.0;
    TEST_ASSERT_EQUAL_INT(ICOAC_SIM_OK, icoac_sim_run_check(&run));
    TEST_ASSERT_TRUE(run.lanes == 16);
    run.lanes = 0;
    TEST_ASSERT_EQUAL_INT(ICOAC_SIM_ERR_BAD_RUN, icoac_sim_run_check(&run));
    run.lanes = ICOAC_SIM_MAX_LANES + 1;
    TEST_ASSERT_EQUAL_INT(ICOAC_SIM_ERR_BAD_RUN, icoac_sim_run_check(&run));
    run.lanes = ICOAC_SIM_MAX_LANES;
    TEST_ASSERT_EQUAL_INT(ICOAC_SIM_OK, icoac_sim_run_check(&run));
    run.lanes = 1;
    TEST_ASSERT_EQUAL_INT(ICOAC_SIM_OK, icoac_sim_run_check(&run));
    TEST_ASSERT_EQUAL_INT(ICOAC_SIM_ERR_BAD_ARGUMENT, icoac_sim_run_check(NULL));
}

static int cmp_u64(const void *a, const void *b)
{
    const uint64_t x = *(const uint64_t *)a, y = *(const uint64_t *)b;
    return x < y ? -1 : (x > y);
}

static void test_paper_grid(void)
{
    static icoac_sim_cell_t cells[TEST_PAPER_CELLS];
    static icoac_sim_cell_t other[TEST_PAPER_CELLS];
    static uint64_t seeds[TEST_PAPER_CELLS];
    const icoac_sim_plant_desc_t *d = icoac_sim_plant_info(ICOAC_SIM_CART_POLE);
    int row, col, i, differ = 0;
    TEST_ASSERT_EQUAL_INT(25, d->rows.count);
    TEST_ASSERT_EQUAL_INT(49, d->cols.count);
    memset(cells, 0x33, sizeof cells);
    TEST_ASSERT_EQUAL_INT(ICOAC_SIM_OK, icoac_sim_plant_grid(ICOAC_SIM_CART_POLE, cells, 1225, 42u));
    for (row = 0; row < 25; ++row) {
        for (col = 0; col < 49; ++col) {
            const icoac_sim_cell_t *c = &cells[row * 49 + col];
            assert_close(c->theta0, (double)(-12 + row) / 180.0 * TEST_PI, 1e-15);
            assert_close(c->x0, -2.4 + 0.1 * col, 1e-12);
            TEST_ASSERT_EQUAL_INT(ICOAC_SIM_PENDING, c->outcome);
            TEST_ASSERT_EQUAL_INT64(0, c->trials);
            TEST_ASSERT_EQUAL_INT64(0, c->total_steps);
        }
    }
    /* the corners and centre exactly on the documented values */
    TEST_ASSERT_TRUE(cells[0].x0 == -2.4 && cells[0].theta0 == -12.0 * TEST_PI / 180.0);
    assert_close(cells[1224].x0, 2.4, 1e-12);
    assert_close(cells[1224].theta0, 12.0 * TEST_PI / 180.0, 1e-15);
    assert_close(cells[12 * 49 + 24].x0, 0.0, 1e-12);
    TEST_ASSERT_TRUE(cells[12 * 49 + 24].theta0 == 0.0);
    for (i = 0; i < 1225; ++i) {
        seeds[i] = cells[i].seed;
    }
    qsort(seeds, 1225, sizeof seeds[0], cmp_u64);
    for (i = 1; i < 1225; ++i) {
        TEST_ASSERT_TRUE(seeds[i] != seeds[i - 1]);
    }
    /* the grid seed drives the cell seeds, and reproducibly */
    TEST_ASSERT_EQUAL_INT(ICOAC_SIM_OK, icoac_sim_plant_grid(ICOAC_SIM_CART_POLE, other, 1225, 42u));
    TEST_ASSERT_EQUAL_MEMORY(cells, other, sizeof cells);
    TEST_ASSERT_EQUAL_INT(ICOAC_SIM_OK, icoac_sim_plant_grid(ICOAC_SIM_CART_POLE, other, 1225, 43u));
    for (i = 0; i < 1225; ++i) {
        differ += other[i].seed != cells[i].seed;
    }
    TEST_ASSERT_EQUAL_INT(1225, differ);
    TEST_ASSERT_EQUAL_INT(ICOAC_SIM_ERR_BAD_ARGUMENT, icoac_sim_plant_grid(ICOAC_SIM_CART_POLE, cells, 1224, 42u));
    TEST_ASSERT_EQUAL_INT(ICOAC_SIM_ERR_BAD_ARGUMENT, icoac_sim_plant_grid(ICOAC_SIM_CART_POLE, NULL, 1225, 42u));
}

static void test_sim_sizes_and_strings(void)
{
    static const int32_t statuses[] = {ICOAC_SIM_OK, ICOAC_SIM_ERR_BAD_PLANT, ICOAC_SIM_ERR_BAD_RUN,
                                       ICOAC_SIM_ERR_BAD_ARGUMENT, ICOAC_SIM_ERR_THREAD, ICOAC_SIM_CANCELLED,
                                       ICOAC_ERR_BAD_PRIOR, 12345};
    size_t i;
    TEST_ASSERT_EQUAL_UINT32(ICOAC_SIM_ABI_VERSION, icoac_sim_abi_version());
    TEST_ASSERT_EQUAL_size_t(sizeof(icoac_sim_run_t), icoac_sim_sizeof_run());
    TEST_ASSERT_EQUAL_size_t(sizeof(icoac_sim_cell_t), icoac_sim_sizeof_cell());
    for (i = 0; i < sizeof statuses / sizeof statuses[0]; ++i) {
        TEST_ASSERT_NOT_NULL(icoac_sim_status_str(statuses[i]));
    }
    TEST_ASSERT_EQUAL_STRING(icoac_status_str(ICOAC_ERR_BAD_PRIOR), icoac_sim_status_str(ICOAC_ERR_BAD_PRIOR));
}

void setUp(void) {}
void tearDown(void) {}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_euler_step);
    RUN_TEST(test_rk4_step);
    RUN_TEST(test_reference_sanity);
    RUN_TEST(test_failure_strict);
    RUN_TEST(test_plant_and_run_checks);
    RUN_TEST(test_paper_grid);
    RUN_TEST(test_sim_sizes_and_strings);
    return UNITY_END();
}
