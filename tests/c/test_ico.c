/* SPDX-License-Identifier: Apache-2.0 */
/* Step tables through icoac_step: input scaling, reflex/penalty (Eq. 4), force (Eq. 5),
 * and the ICO update (Eq. 2-3) in code and literal timing. */
#include "test_common.h"

#include "icoac_features.h"

static double tol_of(double magnitude)
{
    return 8.0 * REAL_EPS * (1.0 + fabs(magnitude));
}

static void init_with_w(const icoac_config_t *cfg, icoac_state_t *state, double w0, double w1, double w2,
                        double w3)
{
    icoac_prior_t p = test_prior(w0, w1, w2, w3, 1.0);
    TEST_ASSERT_EQUAL_INT(ICOAC_OK, icoac_init(cfg, state, &p, 11u));
}

static void get_w(const icoac_state_t *state, double w[4])
{
    icoac_prior_t post;
    int i;
    TEST_ASSERT_EQUAL_INT(ICOAC_OK, icoac_get_posterior(state, &post));
    for (i = 0; i < 4; ++i) {
        w[i] = (double)post.mean[i];
    }
}

/* ---- input scaling: z = e_i^T x~ reads the scaled component i ---- */

typedef struct {
    int component;
    double value;
} scale_row_t;

static const scale_row_t scale_rows[] = {
    {0, 0.0}, {0, 1.2}, {0, -2.0}, {0, 2.4}, {0, 3.0}, {0, -7.5},
    {1, 0.7}, {1, -3.4}, {1, 3.5}, {1, 5.0}, {1, -40.0},
    {2, 0.1}, {2, -0.15}, {2, 0.2094384}, {2, 0.3}, {2, -1.0},
    {3, 1.9}, {3, -0.5}, {3, 2.5}, {3, -9.0},
};

static void run_scaling(int clip)
{
    size_t r;
    for (r = 0; r < sizeof scale_rows / sizeof scale_rows[0]; ++r) {
        icoac_config_t cfg = test_default_config();
        icoac_state_t state;
        icoac_output_t out;
        double s[4] = {0, 0, 0, 0};
        double w[4] = {0, 0, 0, 0};
        icoac_input_t in;
        double expected;
        cfg.policy.clip_inputs = clip;
        cfg.ico.rate = 0; /* keep w fixed even when the row enters the reflex zone */
        s[scale_rows[r].component] = scale_rows[r].value;
        w[scale_rows[r].component] = 1.0;
        init_with_w(&cfg, &state, w[0], w[1], w[2], w[3]);
        in = test_input(s[0], s[1], s[2], s[3], 0);
        TEST_ASSERT_EQUAL_INT(ICOAC_OK, icoac_step(&state, &in, &out));
        expected = test_scale(scale_rows[r].component, (double)in.s[scale_rows[r].component], clip);
        if (clip) {
            TEST_ASSERT_TRUE(fabs(expected) <= 1.0);
        }
        assert_close(out.z, expected, tol_of(expected));
        /* F = G z + U (1 N). */
        assert_close(out.force, 10.0 * expected + (double)out.reflex, tol_of(10.0 * expected));
    }
}

static void test_scaling_clipped(void)
{
    run_scaling(1);
}

static void test_scaling_unclipped(void)
{
    run_scaling(0);
}

static void test_feature_is_dot_product(void)
{
    const double w[4] = {0.5, -0.25, 2.0, 1.0};
    test_rng_t rng = {0x1234567u};
    int k, i;
    for (k = 0; k < 200; ++k) {
        icoac_config_t cfg = test_default_config();
        icoac_state_t state;
        icoac_output_t out;
        icoac_input_t in = test_input(test_uniform(&rng, -3, 3), test_uniform(&rng, -5, 5),
                                      test_uniform(&rng, -0.3, 0.3), test_uniform(&rng, -3, 3), 0);
        double z = 0;
        cfg.policy.clip_inputs = (int32_t)(k & 1);
        cfg.ico.rate = 0;
        init_with_w(&cfg, &state, w[0], w[1], w[2], w[3]);
        TEST_ASSERT_EQUAL_INT(ICOAC_OK, icoac_step(&state, &in, &out));
        for (i = 0; i < 4; ++i) {
            z += w[i] * test_scale(i, (double)in.s[i], cfg.policy.clip_inputs);
        }
        assert_close(out.z, z, tol_of(8.0 * fabs(z) + 4.0));
    }
}

/* ---- reflex / penalty (Eq. 4) and force (Eq. 5) ---- */

typedef struct {
    const char *name;
    double x;
    double theta;
    double reflex;
    double penalty;
} zone_row_t;

static const zone_row_t zone_rows[] = {
    {"centre", 0.0, 0.0, 0, 0},
    {"theta +11.4", 0.0, DEG(11.4), 0, 0},
    {"theta -11.4", 0.0, DEG(-11.4), 0, 0},
    {"x +2.34", 2.34, 0.0, 0, 0},
    {"x -2.34", -2.34, 0.0, 0, 0},
    {"theta +11.6", 0.0, DEG(11.6), 1, -1},
    {"theta +12", 0.5, DEG(12.0), 1, -1},
    {"x -2.36", -2.36, 0.0, 1, -1},
    {"x -2.4", -2.4, DEG(-3.0), 1, -1},
    {"theta -11.6", 0.0, DEG(-11.6), -1, -1},
    {"theta -12", -1.0, DEG(-12.0), -1, -1},
    {"x +2.36", 2.36, 0.0, -1, -1},
    {"x +2.4", 2.4, DEG(3.0), -1, -1},
    /* both branches apply: the first (U = +1) wins */
    {"theta +11.6 and x +2.36", 2.36, DEG(11.6), 1, -1},
    {"theta -11.6 and x -2.36", -2.36, DEG(-11.6), 1, -1},
    {"theta +11.4 and x +2.36", 2.36, DEG(11.4), -1, -1},
    {"theta -11.6 and x +2.34", 2.34, DEG(-11.6), -1, -1},
};

static void run_zone_table(int reflex_mode, double reflex_force, const double w[4])
{
    size_t r;
    int i;
    for (r = 0; r < sizeof zone_rows / sizeof zone_rows[0]; ++r) {
        const zone_row_t *row = &zone_rows[r];
        icoac_config_t cfg = test_default_config();
        icoac_state_t state;
        icoac_output_t out;
        icoac_input_t in = test_input(row->x, 0.3, row->theta, -0.4, 0);
        double z = 0, force;
        cfg.policy.reflex_mode = reflex_mode;
        cfg.policy.reflex_force = (icoac_real_t)reflex_force;
        init_with_w(&cfg, &state, w[0], w[1], w[2], w[3]);
        TEST_ASSERT_EQUAL_INT(ICOAC_OK, icoac_step(&state, &in, &out));
        if (out.reflex != row->reflex || out.penalty != row->penalty) {
            TEST_PRINTF("row %s: U = %g r = %g, expected U = %g r = %g", row->name, (double)out.reflex,
                        (double)out.penalty, row->reflex, row->penalty);
            TEST_FAIL();
        }
        for (i = 0; i < 4; ++i) {
            z += w[i] * test_scale(i, (double)in.s[i], 1);
        }
        force = reflex_mode == ICOAC_REFLEX_GAIN ? 10.0 * (z + row->reflex) : 10.0 * z + reflex_force * row->reflex;
        assert_close(out.z, z, tol_of(4.0));
        assert_close(out.force, force, tol_of(40.0));
        TEST_ASSERT_EQUAL_INT(ICOAC_OK, out.status);
    }
}

static void test_zone_table_unit_reflex(void)
{
    const double w0[4] = {0, 0, 0, 0};
    const double w1[4] = {0.075, 0.049, 0.318, 0.085};
    run_zone_table(ICOAC_REFLEX_UNIT, 1.0, w0);
    run_zone_table(ICOAC_REFLEX_UNIT, 1.0, w1);
    run_zone_table(ICOAC_REFLEX_UNIT, 2.5, w1);
}

static void test_zone_table_gain_reflex(void)
{
    const double w0[4] = {0, 0, 0, 0};
    const double w1[4] = {0.075, 0.049, 0.318, 0.085};
    run_zone_table(ICOAC_REFLEX_GAIN, 1.0, w0);
    run_zone_table(ICOAC_REFLEX_GAIN, 1.0, w1);
    /* reflex_force is not used in gain mode */
    run_zone_table(ICOAC_REFLEX_GAIN, 2.5, w1);
}

static void test_zone_edges_are_strict(void)
{
    icoac_config_t cfg = test_default_config();
    icoac_state_t state;
    icoac_output_t out;
    icoac_input_t in;
    /* exactly on the thresholds (as stored in the configuration): not in the zone */
    const double edges[4][2] = {{0, 1}, {0, -1}, {1, 0}, {-1, 0}};
    int e;
    for (e = 0; e < 4; ++e) {
        TEST_ASSERT_EQUAL_INT(ICOAC_OK, icoac_init(&cfg, &state, NULL, 1u));
        in = test_input(0, 0, 0, 0, 0);
        in.s[0] = (icoac_real_t)edges[e][0] * cfg.task.rule_threshold[3]; /* x above 2.35 m */
        in.s[2] = (icoac_real_t)edges[e][1] * cfg.task.rule_threshold[0]; /* theta above 11.5 deg */
        TEST_ASSERT_EQUAL_INT(ICOAC_OK, icoac_step(&state, &in, &out));
        TEST_ASSERT_TRUE(out.reflex == 0 && out.penalty == 0);
    }
}

/* The private feature helpers of the tick (icoac_features.h) on the same tables. */
static void test_feature_helpers(void)
{
    icoac_config_t cfg = test_default_config();
    icoac_state_t state;
    size_t r;
    int clip, i;
    for (r = 0; r < sizeof zone_rows / sizeof zone_rows[0]; ++r) {
        const icoac_real_t s[ICOAC_MAX_INPUTS] = {(icoac_real_t)zone_rows[r].x, ICOAC_R(0.3),
                                                  (icoac_real_t)zone_rows[r].theta, ICOAC_R(-0.4)};
        const icoac_priv_zone_t zone =
            icoac_priv_zone(&cfg.task, icoac_priv_rules(&cfg.task), ICOAC_CARTPOLE_INPUTS, s);
        TEST_ASSERT_TRUE(zone.reflex == zone_rows[r].reflex && zone.penalty == zone_rows[r].penalty);
    }
    cfg.policy.reflex_force = (icoac_real_t)2.5;
    cfg.policy.reflex_mode = ICOAC_REFLEX_UNIT;
    TEST_ASSERT_TRUE(icoac_priv_reflex_force(&cfg.policy, ICOAC_R(-1.0)) == (icoac_real_t)-2.5);
    cfg.policy.reflex_mode = ICOAC_REFLEX_GAIN;
    TEST_ASSERT_TRUE(icoac_priv_reflex_force(&cfg.policy, ICOAC_R(1.0)) == cfg.policy.gain);
    TEST_ASSERT_TRUE(icoac_priv_reflex_force(&cfg.policy, ICOAC_R(0.0)) == 0);
    for (clip = 0; clip <= 1; ++clip) {
        cfg.policy.clip_inputs = clip;
        TEST_ASSERT_EQUAL_INT(ICOAC_OK, icoac_init(&cfg, &state, NULL, 1u));
        for (r = 0; r < sizeof scale_rows / sizeof scale_rows[0]; ++r) {
            icoac_real_t s[ICOAC_MAX_INPUTS] = {ICOAC_R(0.0)};
            icoac_real_t scaled[ICOAC_MAX_INPUTS];
            s[scale_rows[r].component] = (icoac_real_t)scale_rows[r].value;
            icoac_priv_scale_inputs(&cfg.policy, icoac_priv_state_c(&state), ICOAC_CARTPOLE_INPUTS, s, scaled);
            for (i = 0; i < ICOAC_CARTPOLE_INPUTS; ++i) {
                const double expected = test_scale(i, (double)s[i], clip);
                assert_close(scaled[i], expected, tol_of(expected));
            }
        }
    }
}

/* ---- ICO update, code timing ---- */

static void test_ico_code_timing(void)
{
    icoac_config_t cfg = test_default_config();
    icoac_state_t state;
    icoac_output_t out;
    icoac_input_t in;
    const double w0[4] = {0.01, 0.02, 0.03, 0.04};
    double w[4], xs[4], expect_w[4], z;
    int i;
    init_with_w(&cfg, &state, w0[0], w0[1], w0[2], w0[3]);

    /* tick 1: outside the zone, r = 0 -> 0: no learning */
    in = test_input(0.5, 0.2, 0.05, -0.3, 0);
    TEST_ASSERT_EQUAL_INT(ICOAC_OK, icoac_step(&state, &in, &out));
    TEST_ASSERT_TRUE(out.q == 0 && out.penalty == 0);
    get_w(&state, w);
    for (i = 0; i < 4; ++i) {
        TEST_ASSERT_TRUE(w[i] == (double)(icoac_real_t)w0[i]);
    }

    /* tick 2: enters the zone (theta > 11.5 deg), r 0 -> -1: q = 1, w += mu |x~| */
    in = test_input(-1.0, 4.0, 0.205, -1.0, 0);
    TEST_ASSERT_EQUAL_INT(ICOAC_OK, icoac_step(&state, &in, &out));
    TEST_ASSERT_TRUE(out.q == 1 && out.penalty == -1 && out.reflex == 1);
    z = 0;
    for (i = 0; i < 4; ++i) {
        xs[i] = test_scale(i, (double)in.s[i], 1);
        z += w0[i] * xs[i];
        expect_w[i] = w0[i] + 1e-4 * fabs(xs[i]);
    }
    assert_close(xs[1], 1.0, 0.0); /* x_dot clipped */
    /* the output of this tick still uses the old w */
    assert_close(out.z, z, tol_of(1.0) * 1e-1);
    assert_close(out.force, 10.0 * z + 1.0, tol_of(10.0));
    get_w(&state, w);
    for (i = 0; i < 4; ++i) {
        assert_close(w[i], expect_w[i], 4.0 * REAL_EPS * 0.05);
        TEST_ASSERT_TRUE(w[i] > w0[i]);
    }
    assert_close(out.weight_norm,
                 sqrt(expect_w[0] * expect_w[0] + expect_w[1] * expect_w[1] + expect_w[2] * expect_w[2] +
                      expect_w[3] * expect_w[3]),
                 tol_of(0.1));

    /* tick 3: still in the zone (other side, other state): no more learning, acts with the new w */
    in = test_input(2.37, -0.5, -0.1, 0.7, 0);
    TEST_ASSERT_EQUAL_INT(ICOAC_OK, icoac_step(&state, &in, &out));
    TEST_ASSERT_TRUE(out.q == 0 && out.penalty == -1 && out.reflex == -1);
    z = 0;
    for (i = 0; i < 4; ++i) {
        z += expect_w[i] * test_scale(i, (double)in.s[i], 1);
    }
    assert_close(out.force, 10.0 * z - 1.0, tol_of(10.0));
    {
        double w3[4];
        get_w(&state, w3);
        TEST_ASSERT_EQUAL_MEMORY(w, w3, sizeof w);
    }

    /* tick 4: leaves the zone, r -1 -> 0: q = 0 */
    in = test_input(0.0, 0.0, 0.0, 0.0, 0);
    TEST_ASSERT_EQUAL_INT(ICOAC_OK, icoac_step(&state, &in, &out));
    TEST_ASSERT_TRUE(out.q == 0 && out.penalty == 0);
    {
        double w4[4];
        get_w(&state, w4);
        TEST_ASSERT_EQUAL_MEMORY(w, w4, sizeof w);
    }

    /* tick 5: enters again (x < -2.35): learns again with this tick's x~ */
    in = test_input(-2.36, 0.35, -0.02, 0.1, 0);
    TEST_ASSERT_EQUAL_INT(ICOAC_OK, icoac_step(&state, &in, &out));
    TEST_ASSERT_TRUE(out.q == 1 && out.reflex == 1);
    {
        double w5[4];
        get_w(&state, w5);
        for (i = 0; i < 4; ++i) {
            assert_close(w5[i], w[i] + 1e-4 * fabs(test_scale(i, (double)in.s[i], 1)), 4.0 * REAL_EPS * 0.05);
        }
    }
}

/* Code timing never observes terminal (failure) states. */
static void test_ico_code_timing_ignores_terminal(void)
{
    icoac_config_t cfg = test_default_config();
    icoac_state_t state;
    icoac_output_t out;
    icoac_input_t in;
    double w[4];
    int i;
    init_with_w(&cfg, &state, 0.1, 0.1, 0.1, 0.1);
    in = test_input(0.1, 0.1, 0.1, 0.1, 0);
    TEST_ASSERT_EQUAL_INT(ICOAC_OK, icoac_step(&state, &in, &out));
    in = test_input(0.1, 0.1, 0.25, 0.1, ICOAC_INPUT_TERMINAL);
    TEST_ASSERT_EQUAL_INT(ICOAC_OK, icoac_step(&state, &in, &out));
    TEST_ASSERT_TRUE(out.q == 0);
    TEST_ASSERT_TRUE(out.force == 0);
    get_w(&state, w);
    for (i = 0; i < 4; ++i) {
        TEST_ASSERT_TRUE(w[i] == (double)(icoac_real_t)0.1);
    }
    /* r_prev is still 0: the next in-zone observation learns */
    TEST_ASSERT_EQUAL_INT(ICOAC_OK, icoac_reset(&state));
    in = test_input(0.1, 0.1, 0.205, 0.1, 0);
    TEST_ASSERT_EQUAL_INT(ICOAC_OK, icoac_step(&state, &in, &out));
    TEST_ASSERT_TRUE(out.q == 1);
}

/* ---- ICO update, literal timing ---- */

static void test_ico_literal_timing(void)
{
    icoac_config_t cfg = test_default_config();
    icoac_state_t state;
    icoac_output_t out;
    icoac_input_t a, b, c;
    const double w0[4] = {0.01, 0.02, 0.03, 0.04};
    double w[4], expect_w[4], z;
    int i;
    cfg.ico.timing = ICOAC_ICO_TIMING_LITERAL;
    init_with_w(&cfg, &state, w0[0], w0[1], w0[2], w0[3]);

    a = test_input(0.5, -0.2, 0.15, 1.5, 0); /* outside the zone */
    TEST_ASSERT_EQUAL_INT(ICOAC_OK, icoac_step(&state, &a, &out));
    TEST_ASSERT_TRUE(out.q == 0);

    /* observes the zone: update with the previous tick's x~(a), then act with the new w */
    b = test_input(0.6, -0.1, 0.203, 1.4, 0);
    TEST_ASSERT_EQUAL_INT(ICOAC_OK, icoac_step(&state, &b, &out));
    TEST_ASSERT_TRUE(out.q == 1 && out.penalty == -1);
    z = 0;
    for (i = 0; i < 4; ++i) {
        expect_w[i] = w0[i] + 1e-4 * fabs(test_scale(i, (double)a.s[i], 1));
        z += expect_w[i] * test_scale(i, (double)b.s[i], 1);
    }
    get_w(&state, w);
    for (i = 0; i < 4; ++i) {
        assert_close(w[i], expect_w[i], 4.0 * REAL_EPS * 0.05);
    }
    assert_close(out.z, z, tol_of(0.1));
    assert_close(out.force, 10.0 * z + 1.0, tol_of(10.0));

    /* staying in the zone: no more learning */
    c = test_input(0.7, -0.1, 0.207, 1.3, 0);
    TEST_ASSERT_EQUAL_INT(ICOAC_OK, icoac_step(&state, &c, &out));
    TEST_ASSERT_TRUE(out.q == 0);
    {
        double w2[4];
        get_w(&state, w2);
        TEST_ASSERT_EQUAL_MEMORY(w, w2, sizeof w);
    }
}

static void test_ico_literal_timing_terminal(void)
{
    icoac_config_t cfg = test_default_config();
    icoac_state_t state;
    icoac_output_t out;
    icoac_input_t a, f;
    double w[4];
    int i;
    cfg.ico.timing = ICOAC_ICO_TIMING_LITERAL;
    init_with_w(&cfg, &state, 0, 0, 0, 0);
    a = test_input(-0.3, 0.8, -0.19, -1.7, 0);
    TEST_ASSERT_EQUAL_INT(ICOAC_OK, icoac_step(&state, &a, &out));
    TEST_ASSERT_TRUE(out.q == 0);
    /* jump straight to a failure state (theta < -12 deg), flagged terminal: learned from, no action */
    f = test_input(-0.29, 0.8, -0.215, -1.7, ICOAC_INPUT_TERMINAL);
    TEST_ASSERT_EQUAL_INT(ICOAC_OK, icoac_step(&state, &f, &out));
    TEST_ASSERT_TRUE(out.q == 1);
    TEST_ASSERT_TRUE(out.force == 0);
    get_w(&state, w);
    for (i = 0; i < 4; ++i) {
        assert_close(w[i], 1e-4 * fabs(test_scale(i, (double)a.s[i], 1)), 4.0 * REAL_EPS * 1e-4);
    }
    /* after a reset the first tick has no previous observation: no update even if r changes */
    TEST_ASSERT_EQUAL_INT(ICOAC_OK, icoac_reset(&state));
    a = test_input(0.0, 0.0, 0.0, 0.0, 0);
    TEST_ASSERT_EQUAL_INT(ICOAC_OK, icoac_step(&state, &a, &out));
    TEST_ASSERT_TRUE(out.q == 0);
}

/* Code timing with a failure jump gives no learning, literal timing does (method.md, A4). */
static void test_jump_over_zone(void)
{
    int timing;
    for (timing = 0; timing <= 1; ++timing) {
        icoac_config_t cfg = test_default_config();
        icoac_state_t state;
        icoac_output_t out;
        icoac_input_t a = test_input(0.0, 0.0, DEG(11.0), 1.0, 0);
        icoac_input_t f = test_input(0.0, 0.0, DEG(12.5), 1.0, ICOAC_INPUT_TERMINAL);
        cfg.ico.timing = timing;
        TEST_ASSERT_EQUAL_INT(ICOAC_OK, icoac_init(&cfg, &state, NULL, 1u));
        TEST_ASSERT_EQUAL_INT(ICOAC_OK, icoac_step(&state, &a, &out));
        TEST_ASSERT_EQUAL_INT(ICOAC_OK, icoac_step(&state, &f, &out));
        TEST_ASSERT_TRUE(out.q == (timing == ICOAC_ICO_TIMING_LITERAL ? 1 : 0));
        TEST_ASSERT_TRUE((out.weight_norm > 0) == (timing == ICOAC_ICO_TIMING_LITERAL));
    }
}

void setUp(void) {}
void tearDown(void) {}

/* ---- input signs (task.input_sign, method.md: input signs) ---- */

/* A task whose input i has sign -1 behaves, tick for tick and bit for bit, as the same task with
 * sign +1 fed -s_i, in every mode: the features, the learning and the force read sign_i * s_i.
 * The late signal comes from a sensor and the critic has one unit along each flipped input (a
 * constant factor), so nothing reads the raw flipped inputs. */
static void run_signs(int32_t mode, int32_t timing)
{
    static const int32_t sign[4] = {-1, 1, -1, 1};
    icoac_config_t signed_cfg = test_default_config();
    icoac_config_t mirror_cfg;
    icoac_state_t signed_state, mirror_state;
    icoac_prior_t prior = test_prior(0.3, 0.1, 0.7, 0.2, 0.5);
    test_rng_t rng = {0x51617u};
    int trial, k, i;
    signed_cfg.mode = mode;
    signed_cfg.ico.timing = timing;
    signed_cfg.ico.rate = (icoac_real_t)0.01;
    signed_cfg.search.batch = 2;
    signed_cfg.task.late_source = ICOAC_LATE_SENSOR;
    signed_cfg.critic.units[0] = 1;
    signed_cfg.critic.units[2] = 1;
    mirror_cfg = signed_cfg;
    for (i = 0; i < 4; ++i) {
        signed_cfg.task.input_sign[i] = sign[i];
    }
    TEST_ASSERT_EQUAL_INT(ICOAC_OK, icoac_init(&signed_cfg, &signed_state, &prior, 5u));
    TEST_ASSERT_EQUAL_INT(ICOAC_OK, icoac_init(&mirror_cfg, &mirror_state, &prior, 5u));
    for (trial = 0; trial < 6; ++trial) {
        for (k = 0; k < 60; ++k) {
            const uint32_t late = (k % 7 == 3 || k % 7 == 4) ? ICOAC_INPUT_LATE : 0u;
            const uint32_t flags = late | (k == 59 ? ICOAC_INPUT_TERMINAL : 0u);
            icoac_input_t in = test_input(test_uniform(&rng, -3, 3), test_uniform(&rng, -5, 5),
                                          test_uniform(&rng, -0.3, 0.3), test_uniform(&rng, -3, 3), flags);
            icoac_input_t mirrored = in;
            icoac_output_t a, b;
            memset(&a, 0, sizeof a); /* the padding of a double build compares equal */
            memset(&b, 0, sizeof b);
            in.reflex = (icoac_real_t)test_uniform(&rng, -1, 1);
            mirrored.reflex = in.reflex;
            for (i = 0; i < 4; ++i) {
                mirrored.s[i] = sign[i] < 0 ? -in.s[i] : in.s[i];
            }
            TEST_ASSERT_EQUAL_INT(ICOAC_OK, icoac_step(&signed_state, &in, &a));
            TEST_ASSERT_EQUAL_INT(ICOAC_OK, icoac_step(&mirror_state, &mirrored, &b));
            TEST_ASSERT_EQUAL_MEMORY(&b, &a, sizeof a);
        }
        TEST_ASSERT_EQUAL_INT(ICOAC_OK, icoac_reset(&signed_state));
        TEST_ASSERT_EQUAL_INT(ICOAC_OK, icoac_reset(&mirror_state));
    }
    {
        icoac_prior_t pa, pb;
        TEST_ASSERT_EQUAL_INT(ICOAC_OK, icoac_get_posterior(&signed_state, &pa));
        TEST_ASSERT_EQUAL_INT(ICOAC_OK, icoac_get_posterior(&mirror_state, &pb));
        TEST_ASSERT_EQUAL_MEMORY(&pb, &pa, sizeof pa);
        TEST_ASSERT_TRUE(memcmp(&pa, &prior, sizeof pa) != 0); /* it learned */
    }
}

static void test_signs_ico_code(void)
{
    run_signs(ICOAC_MODE_ICO, ICOAC_ICO_TIMING_CODE);
}

static void test_signs_ico_literal(void)
{
    run_signs(ICOAC_MODE_ICO, ICOAC_ICO_TIMING_LITERAL);
}

static void test_signs_rl(void)
{
    run_signs(ICOAC_MODE_RL, ICOAC_ICO_TIMING_CODE);
}

static void test_signs_search(void)
{
    run_signs(ICOAC_MODE_SEARCH, ICOAC_ICO_TIMING_CODE);
}

/* A sign flips the input's contribution to the feature: z = sum_i w_i sign_i x~_i. */
static void test_sign_flips_the_feature(void)
{
    icoac_config_t cfg = test_default_config();
    icoac_state_t state;
    icoac_output_t out;
    const icoac_input_t in = test_input(1.2, 0.7, 0.1, -0.5, 0);
    double z = 0;
    int i;
    cfg.ico.rate = 0;
    cfg.task.input_sign[1] = -1;
    cfg.task.input_sign[2] = -1;
    init_with_w(&cfg, &state, 0.5, 0.25, 2.0, 1.0);
    TEST_ASSERT_EQUAL_INT(ICOAC_OK, icoac_step(&state, &in, &out));
    {
        const double w[4] = {0.5, 0.25, 2.0, 1.0};
        const double sgn[4] = {1, -1, -1, 1};
        for (i = 0; i < 4; ++i) {
            z += w[i] * sgn[i] * test_scale(i, (double)in.s[i], 1);
        }
    }
    assert_close(out.z, z, tol_of(8.0));
    assert_close(out.force, 10.0 * z, tol_of(80.0));
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_scaling_clipped);
    RUN_TEST(test_scaling_unclipped);
    RUN_TEST(test_feature_is_dot_product);
    RUN_TEST(test_zone_table_unit_reflex);
    RUN_TEST(test_zone_table_gain_reflex);
    RUN_TEST(test_zone_edges_are_strict);
    RUN_TEST(test_feature_helpers);
    RUN_TEST(test_ico_code_timing);
    RUN_TEST(test_ico_code_timing_ignores_terminal);
    RUN_TEST(test_ico_literal_timing);
    RUN_TEST(test_ico_literal_timing_terminal);
    RUN_TEST(test_jump_over_zone);
    RUN_TEST(test_signs_ico_code);
    RUN_TEST(test_signs_ico_literal);
    RUN_TEST(test_signs_rl);
    RUN_TEST(test_signs_search);
    RUN_TEST(test_sign_flips_the_feature);
    return UNITY_END();
}
