/* SPDX-License-Identifier: Apache-2.0 */
/* Cart-pole plant against an independent evaluation of its equations (method.md, plant);
 * failure test; parameter checks; the paper grid. */
#include "test_common.h"

#include <stdlib.h>

#include "icoac_sim/icoac_sim.h"

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
    icoac_sim_plant_t plant;
    size_t a, f;
    int i;
    icoac_sim_plant_default(&plant);
    plant.integrator = integrator;
    TEST_ASSERT_EQUAL_INT(ICOAC_SIM_OK, icoac_sim_plant_check(&plant));
    for (a = 0; a < sizeof states / sizeof states[0]; ++a) {
        for (f = 0; f < sizeof forces / sizeof forces[0]; ++f) {
            double s[4];
            long double r[4];
            for (i = 0; i < 4; ++i) {
                s[i] = states[a][i];
                r[i] = states[a][i];
            }
            TEST_ASSERT_EQUAL_INT(ICOAC_SIM_OK, icoac_sim_plant_step(&plant, s, forces[f]));
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
    icoac_sim_plant_t plant;
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
    icoac_sim_plant_default(&plant);
    TEST_ASSERT_EQUAL_INT(ICOAC_SIM_OK, icoac_sim_plant_step(&plant, s, 10.0));
    TEST_ASSERT_TRUE(s[1] > 0 && s[3] < 0 && s[0] == 0.0 && s[2] == 0.0); /* Euler: positions use old velocities */
    s[0] = s[1] = s[3] = 0;
    s[2] = 0.1;
    TEST_ASSERT_EQUAL_INT(ICOAC_SIM_OK, icoac_sim_plant_step(&plant, s, 0.0));
    TEST_ASSERT_TRUE(s[3] > 0);
    /* RK4 and Euler differ (the switch is effective) */
    {
        double e[4] = {0.1, 0.2, 0.1, 0.3}, k[4] = {0.1, 0.2, 0.1, 0.3};
        TEST_ASSERT_EQUAL_INT(ICOAC_SIM_OK, icoac_sim_plant_step(&plant, e, 3.0));
        plant.integrator = ICOAC_SIM_RK4;
        TEST_ASSERT_EQUAL_INT(ICOAC_SIM_OK, icoac_sim_plant_step(&plant, k, 3.0));
        TEST_ASSERT_TRUE(fabs(e[0] - k[0]) > 1e-6);
    }
    TEST_ASSERT_EQUAL_INT(ICOAC_SIM_ERR_BAD_ARGUMENT, icoac_sim_plant_step(NULL, s, 0.0));
    TEST_ASSERT_EQUAL_INT(ICOAC_SIM_ERR_BAD_ARGUMENT, icoac_sim_plant_step(&plant, NULL, 0.0));
}

/* The cart-pole's icoac_sim_plant_t entries check what the model API checks: a plant the check
 * refuses, a non-finite state or force, and a step that overflows get a status and leave the
 * state as it was; NULL pointers a status, never a dereference. */
static void test_plant_entries_refuse_bad_input(void)
{
    icoac_sim_plant_t plant;
    const double start[4] = {0.1, -0.2, 0.05, 0.3};
    double s[4];
    int c;
    for (c = 0; c < 6; ++c) {
        icoac_sim_plant_default(&plant);
        switch (c) {
        case 0: plant.dt = NAN; break;
        case 1: plant.gravity = NAN; break;
        case 2: plant.cart_mass = 0.0; plant.pole_mass = 0.0; break; /* masses summing to 0 */
        case 3: plant.integrator = 7; break;
        case 4: plant.x_limit = INFINITY; break;
        default: plant.dt = -0.01; break;
        }
        TEST_ASSERT_EQUAL_INT(ICOAC_SIM_ERR_BAD_PLANT, icoac_sim_plant_check(&plant));
        memcpy(s, start, sizeof s);
        TEST_ASSERT_EQUAL_INT(ICOAC_SIM_ERR_BAD_PLANT, icoac_sim_plant_step(&plant, s, 1.0));
        TEST_ASSERT_EQUAL_MEMORY(start, s, sizeof s);
        TEST_ASSERT_EQUAL_INT(ICOAC_SIM_ERR_BAD_PLANT, icoac_sim_failed(&plant, s));
    }
    icoac_sim_plant_default(&plant);
    memcpy(s, start, sizeof s);
    TEST_ASSERT_EQUAL_INT(ICOAC_SIM_ERR_NONFINITE, icoac_sim_plant_step(&plant, s, NAN));
    TEST_ASSERT_EQUAL_INT(ICOAC_SIM_ERR_NONFINITE, icoac_sim_plant_step(&plant, s, INFINITY));
    TEST_ASSERT_EQUAL_MEMORY(start, s, sizeof s);
    s[3] = NAN;
    TEST_ASSERT_EQUAL_INT(ICOAC_SIM_ERR_NONFINITE, icoac_sim_plant_step(&plant, s, 1.0));
    TEST_ASSERT_EQUAL_INT(1, icoac_sim_failed(&plant, s)); /* a non-finite state has failed */
    /* a step that overflows: refused, the state as it was */
    memcpy(s, start, sizeof s);
    s[3] = 1e300;
    TEST_ASSERT_EQUAL_INT(ICOAC_SIM_ERR_NONFINITE, icoac_sim_plant_step(&plant, s, 1.0));
    TEST_ASSERT_TRUE(s[3] == 1e300 && s[0] == start[0]);
    TEST_ASSERT_EQUAL_INT(ICOAC_SIM_ERR_BAD_ARGUMENT, icoac_sim_failed(NULL, start));
    TEST_ASSERT_EQUAL_INT(ICOAC_SIM_ERR_BAD_ARGUMENT, icoac_sim_failed(&plant, NULL));
    TEST_ASSERT_EQUAL_INT(0, icoac_sim_failed(&plant, start));
}

static void test_failure_strict(void)
{
    icoac_sim_plant_t plant;
    const double lim = 12.0 * TEST_PI / 180.0;
    double s[4];
    int c;
    icoac_sim_plant_default(&plant);
    assert_close(plant.theta_limit, lim, 1e-16);
    assert_close(plant.x_limit, 2.4, 0.0);
#define FAILED(x, th) (s[0] = (x), s[1] = 0.3, s[2] = (th), s[3] = -0.2, icoac_sim_failed(&plant, s))
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
        TEST_ASSERT_EQUAL_INT(1, icoac_sim_failed(&plant, s));
        s[c] = (double)INFINITY;
        TEST_ASSERT_EQUAL_INT(1, icoac_sim_failed(&plant, s));
    }
}

typedef void (*plant_mut)(icoac_sim_plant_t *p);
#define PMUT(name, body) \
    static void name(icoac_sim_plant_t *p) { body; }
PMUT(p_g0, p->gravity = 0)
PMUT(p_gnan, p->gravity = (double)NAN)
PMUT(p_mc, p->cart_mass = -1)
PMUT(p_mp, p->pole_mass = 0)
PMUT(p_l, p->half_length = (double)INFINITY)
PMUT(p_dt0, p->dt = 0)
PMUT(p_dtbig, p->dt = 1.5)
PMUT(p_xl, p->x_limit = 0)
PMUT(p_tl, p->theta_limit = (double)NAN)
PMUT(p_int, p->integrator = 2)
PMUT(p_intneg, p->integrator = -1)
/* Subnormal or absurd values the workers would flush to zero or overflow on. */
PMUT(p_dt_subnormal, p->dt = 1e-310)
PMUT(p_dt_tiny, p->dt = 9e-7)
PMUT(p_g_subnormal, p->gravity = 1e-310)
PMUT(p_g_huge, p->gravity = 1e300)
PMUT(p_mc_subnormal, p->cart_mass = 4.9e-324)
PMUT(p_mp_huge, p->pole_mass = 1e7)
PMUT(p_l_tiny, p->half_length = 1e-9)
PMUT(p_xl_huge, p->x_limit = 1e300)
PMUT(p_tl_big, p->theta_limit = 4.0)

static void test_plant_and_run_checks(void)
{
    static const plant_mut muts[] = {p_g0, p_gnan, p_mc, p_mp, p_l, p_dt0, p_dtbig, p_xl, p_tl, p_int, p_intneg,
                                     p_dt_subnormal, p_dt_tiny, p_g_subnormal, p_g_huge, p_mc_subnormal,
                                     p_mp_huge, p_l_tiny, p_xl_huge, p_tl_big};
    icoac_sim_plant_t plant;
    icoac_sim_run_t run;
    size_t i;
    icoac_sim_plant_default(&plant);
    assert_close(plant.gravity, 9.8, 0);
    assert_close(plant.cart_mass, 1.0, 0);
    assert_close(plant.pole_mass, 0.1, 0);
    assert_close(plant.half_length, 0.5, 0);
    assert_close(plant.dt, 0.01, 0);
    TEST_ASSERT_EQUAL_INT(ICOAC_SIM_EULER, plant.integrator);
    for (i = 0; i < sizeof muts / sizeof muts[0]; ++i) {
        icoac_sim_plant_default(&plant);
        muts[i](&plant);
        TEST_ASSERT_EQUAL_INT(ICOAC_SIM_ERR_BAD_PLANT, icoac_sim_plant_check(&plant));
    }
    TEST_ASSERT_EQUAL_INT(ICOAC_SIM_ERR_BAD_ARGUMENT, icoac_sim_plant_check(NULL));
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
    TEST_ASSERT_EQUAL_INT(ICOAC_SIM_ERR_BAD_ARGUMENT, icoac_sim_run_check(NULL));
    /* the bounds themselves are valid */
    icoac_sim_plant_default(&plant);
    plant.dt = ICOAC_SIM_DT_MIN;
    plant.gravity = ICOAC_SIM_PHYS_MAX;
    plant.theta_limit = ICOAC_SIM_THETA_LIMIT_MAX;
    TEST_ASSERT_EQUAL_INT(ICOAC_SIM_OK, icoac_sim_plant_check(&plant));
}

static int cmp_u64(const void *a, const void *b)
{
    const uint64_t x = *(const uint64_t *)a, y = *(const uint64_t *)b;
    return x < y ? -1 : (x > y);
}

static void test_paper_grid(void)
{
    static icoac_sim_cell_t cells[ICOAC_SIM_GRID_CELLS];
    static icoac_sim_cell_t other[ICOAC_SIM_GRID_CELLS];
    static uint64_t seeds[ICOAC_SIM_GRID_CELLS];
    int row, col, i, differ = 0;
    TEST_ASSERT_EQUAL_INT(1225, ICOAC_SIM_GRID_CELLS);
    TEST_ASSERT_EQUAL_INT(25, ICOAC_SIM_GRID_THETAS);
    TEST_ASSERT_EQUAL_INT(49, ICOAC_SIM_GRID_XS);
    memset(cells, 0x33, sizeof cells);
    TEST_ASSERT_EQUAL_INT(ICOAC_SIM_OK, icoac_sim_paper_grid(cells, 1225, 42u));
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
    TEST_ASSERT_EQUAL_INT(ICOAC_SIM_OK, icoac_sim_paper_grid(other, 1225, 42u));
    TEST_ASSERT_EQUAL_MEMORY(cells, other, sizeof cells);
    TEST_ASSERT_EQUAL_INT(ICOAC_SIM_OK, icoac_sim_paper_grid(other, 1225, 43u));
    for (i = 0; i < 1225; ++i) {
        differ += other[i].seed != cells[i].seed;
    }
    TEST_ASSERT_EQUAL_INT(1225, differ);
    TEST_ASSERT_EQUAL_INT(ICOAC_SIM_ERR_BAD_ARGUMENT, icoac_sim_paper_grid(cells, 1224, 42u));
    TEST_ASSERT_EQUAL_INT(ICOAC_SIM_ERR_BAD_ARGUMENT, icoac_sim_paper_grid(NULL, 1225, 42u));
}

static void test_sim_sizes_and_strings(void)
{
    static const int32_t statuses[] = {ICOAC_SIM_OK, ICOAC_SIM_ERR_BAD_PLANT, ICOAC_SIM_ERR_BAD_RUN,
                                       ICOAC_SIM_ERR_BAD_ARGUMENT, ICOAC_SIM_ERR_THREAD, ICOAC_SIM_CANCELLED,
                                       ICOAC_ERR_BAD_PRIOR, 12345};
    size_t i;
    TEST_ASSERT_EQUAL_UINT32(ICOAC_SIM_ABI_VERSION, icoac_sim_abi_version());
    TEST_ASSERT_EQUAL_size_t(sizeof(icoac_sim_plant_t), icoac_sim_sizeof_plant());
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
    RUN_TEST(test_plant_entries_refuse_bad_input);
    RUN_TEST(test_failure_strict);
    RUN_TEST(test_plant_and_run_checks);
    RUN_TEST(test_paper_grid);
    RUN_TEST(test_sim_sizes_and_strings);
    return UNITY_END();
}
