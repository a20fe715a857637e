/* NGnet critic (method.md, critic): separable evaluation against the direct 4-D formula, the activity
 * threshold and the kept-unit list, for both kernels (sparse: microcontrollers, dense: hosts);
 * the dense kernel against the sparse one; the TD(0) update through icoac_step in RL mode. */
#include "test_common.h"

#include "icoac_priv.h"

#define K ICOAC_CRITIC_UNITS

static const double ranges[4] = {2.4, 3.5, 0.2094384, 2.0};
static const int sizes[4] = {3, 3, 6, 3};

/* b_k(s) from the 4-D definition: a_k = exp(-1/2 sum_i ((s_i - c_ki)/sigma_i)^2), normalised.
 * Computed in log space (shifted by the largest exponent) in long double, so far-out states
 * do not turn into 0/0; the shift cancels in the ratio. */
static void direct_b(const icoac_real_t s_in[4], double b[K])
{
    long double logs[K], top = -1e300L, total = 0;
    int a, bb, c, d, k;
    for (a = 0; a < sizes[0]; ++a) {
        for (bb = 0; bb < sizes[1]; ++bb) {
            for (c = 0; c < sizes[2]; ++c) {
                for (d = 0; d < sizes[3]; ++d) {
                    const int idx[4] = {a, bb, c, d};
                    long double e = 0;
                    int i;
                    k = ((a * 3 + bb) * 6 + c) * 3 + d;
                    for (i = 0; i < 4; ++i) {
                        const long double sigma = (long double)ranges[i] / sizes[i];
                        const long double centre = -(long double)ranges[i] + (2 * idx[i] + 1) * sigma;
                        const long double u = ((long double)s_in[i] - centre) / sigma;
                        e += u * u;
                    }
                    logs[k] = -0.5L * e;
                    top = logs[k] > top ? logs[k] : top;
                }
            }
        }
    }
    for (k = 0; k < K; ++k) {
        total += expl(logs[k] - top);
    }
    for (k = 0; k < K; ++k) {
        b[k] = (double)(expl(logs[k] - top) / total);
    }
}

/* The same with the activity threshold (method.md, critic): b_k < threshold counts as 0. */
static void direct_b_kept(const icoac_real_t s_in[4], double threshold, double b[K])
{
    int k;
    direct_b(s_in, b);
    for (k = 0; k < K; ++k) {
        b[k] = b[k] < threshold ? 0.0 : b[k];
    }
}

/* Too close to the threshold to call, given float rounding of b_k. */
static int near_threshold(double b, double threshold)
{
    return threshold > 0 && fabs(b - threshold) < 1e-5 * threshold;
}

/* The two critic kernels, whichever the build selects for icoac_step. */
enum { SPARSE, DENSE, KERNELS };

static icoac_real_t kernel_value(int kernel, const icoac_critic_config_t *critic, const icoac_real_t *v,
                                 const icoac_real_t *factors, icoac_priv_critic_active_t *active)
{
    return kernel == DENSE ? icoac_priv_critic_value_dense(critic, v, factors, &active->dense)
                           : icoac_priv_critic_value_sparse(critic, v, factors, &active->sparse);
}

static void kernel_update(int kernel, const icoac_critic_config_t *critic, icoac_real_t *v,
                          const icoac_priv_critic_active_t *active, icoac_real_t step)
{
    if (kernel == DENSE) {
        icoac_priv_critic_update_dense(critic, v, &active->dense, step);
    } else {
        icoac_priv_critic_update_sparse(v, &active->sparse, step);
    }
}

/* b_k(s) from a kernel: the value pass finds the kept units, and an update with step 1 on
 * v = 0 writes their b_k into v. */
static void library_b(int kernel, const icoac_critic_config_t *critic, const icoac_real_t s[4], double b[K])
{
    icoac_real_t factors[ICOAC_CRITIC_FACTORS];
    icoac_real_t v[K];
    icoac_priv_critic_active_t active;
    int k;
    memset(v, 0, sizeof v);
    icoac_priv_critic_factors(critic, s, factors);
    assert_true(kernel_value(kernel, critic, v, factors, &active) == 0);
    kernel_update(kernel, critic, v, &active, (icoac_real_t)1.0);
    for (k = 0; k < K; ++k) {
        b[k] = (double)v[k];
    }
}

static double b_tol(void)
{
    return REAL_IS_FLOAT ? 2e-6 : 1e-12;
}

static void random_state(test_rng_t *rng, int far, icoac_real_t s[4])
{
    int i;
    for (i = 0; i < 4; ++i) {
        const double scale = far ? (i == 2 ? 20.0 : 15.0) : 1.3;
        s[i] = (icoac_real_t)test_uniform(rng, -scale * ranges[i], scale * ranges[i]);
    }
}

/* The integer comparison behind the threshold agrees with >= on non-negative reals. */
static void test_nonneg_at_least(void **unused)
{
    const icoac_real_t special[] = {(icoac_real_t)0.0, (icoac_real_t)1e-45, (icoac_real_t)1e-40,
                                    (icoac_real_t)1e-38, (icoac_real_t)0.001, (icoac_real_t)0.5,
                                    (icoac_real_t)1.0, (icoac_real_t)3e38, (icoac_real_t)INFINITY};
    const int n_special = (int)(sizeof special / sizeof special[0]);
    test_rng_t rng = {77u};
    int i, j;
    (void)unused;
    for (i = 0; i < n_special; ++i) {
        for (j = 0; j < n_special; ++j) {
            assert_int_equal(icoac_priv_nonneg_at_least(special[i], special[j]), special[i] >= special[j]);
        }
    }
    for (i = 0; i < 100000; ++i) {
        const icoac_real_t a = (icoac_real_t)pow(10.0, test_uniform(&rng, -40, 3));
        const icoac_real_t b = i % 3 == 0 ? a : (icoac_real_t)pow(10.0, test_uniform(&rng, -40, 3));
        assert_int_equal(icoac_priv_nonneg_at_least(a, b), a >= b);
    }
}

static void test_grid_centres(void **unused)
{
    /* the centres listed in method.md: x {-1.6, 0, 1.6}; theta +-2, +-6, +-10 deg (to 4 digits) */
    const double x_c[3] = {-1.6, 0.0, 1.6};
    const double th_c[6] = {-10, -6, -2, 2, 6, 10};
    int j;
    (void)unused;
    for (j = 0; j < 3; ++j) {
        assert_close(-2.4 + (2 * j + 1) * 2.4 / 3, x_c[j], 1e-12);
    }
    for (j = 0; j < 6; ++j) {
        assert_close(-0.2094384 + (2 * j + 1) * 0.2094384 / 6, DEG(th_c[j]), 1e-5);
    }
}

static void test_separable_equals_direct(void **unused)
{
    icoac_config_t cfg = test_default_config();
    test_rng_t rng = {0xC0FFEEu};
    double bl[K], bd[K];
    int n, k;
    (void)unused;
    cfg.critic.threshold = 0; /* every unit */
    for (n = 0; n < 2 * 400; ++n) {
        const int kernel = n / 400;
        icoac_real_t s[4];
        double sum = 0;
        random_state(&rng, n % 400 >= 200, s);
        if (n % 400 == 0) {
            s[0] = s[1] = s[2] = s[3] = 0; /* between centres in theta */
        } else if (n % 400 == 1) {
            s[0] = (icoac_real_t)1.6; /* on a centre in x */
            s[1] = (icoac_real_t)-1e6;
            s[2] = (icoac_real_t)100.0;
            s[3] = (icoac_real_t)-1e4;
        }
        library_b(kernel, &cfg.critic, s, bl);
        direct_b(s, bd);
        for (k = 0; k < K; ++k) {
            if (!(fabs(bl[k] - bd[k]) <= b_tol())) {
                print_error("kernel %d state %d (%g, %g, %g, %g) unit %d: %.10g vs %.10g\n", kernel, n, (double)s[0],
                            (double)s[1], (double)s[2], (double)s[3], k, bl[k], bd[k]);
                fail();
            }
            assert_true(bl[k] >= 0.0);
            sum += bl[k];
        }
        assert_close(sum, 1.0, REAL_IS_FLOAT ? 1e-5 : 1e-12);
    }
}

static void check_value(icoac_config_t cfg, unsigned seed, int kernel)
{
    test_rng_t rng = {seed};
    icoac_real_t v[K], factors[ICOAC_CRITIC_FACTORS], s[4];
    icoac_priv_critic_active_t active;
    double bd[K];
    int n, k;
    for (n = 0; n < 200; ++n) {
        double expected = 0, slack = 0;
        for (k = 0; k < K; ++k) {
            v[k] = (icoac_real_t)test_uniform(&rng, -1, 1);
        }
        random_state(&rng, n & 1, s);
        icoac_priv_critic_factors(&cfg.critic, s, factors);
        direct_b_kept(s, (double)cfg.critic.threshold, bd);
        for (k = 0; k < K; ++k) {
            expected += (double)v[k] * bd[k];
            slack += near_threshold(bd[k], (double)cfg.critic.threshold) ? fabs((double)v[k]) * bd[k] : 0;
        }
        assert_close(kernel_value(kernel, &cfg.critic, v, factors, &active), expected,
                     slack + (REAL_IS_FLOAT ? 1e-5 : 1e-12));
    }
}

static void test_value_is_weighted_sum(void **unused)
{
    icoac_config_t cfg = test_default_config();
    int kernel;
    (void)unused;
    for (kernel = SPARSE; kernel < KERNELS; ++kernel) {
        cfg.critic.threshold = (icoac_real_t)0.001; /* the default */
        check_value(cfg, 31u, kernel);
        cfg.critic.threshold = 0;
        check_value(cfg, 32u, kernel);
        cfg.critic.threshold = (icoac_real_t)0.05;
        check_value(cfg, 33u, kernel);
    }
}

static void test_threshold_drops_small_activations(void **unused)
{
    icoac_config_t cfg = test_default_config();
    test_rng_t rng = {8u};
    double bl[K], bd[K];
    int n, k, dropped = 0, kept = 0;
    (void)unused;
    assert_true(cfg.critic.threshold == (icoac_real_t)0.001); /* the authors' cut-off is the default */
    for (n = 0; n < 2 * 200; ++n) {
        icoac_real_t s[4];
        random_state(&rng, n % 200 >= 150, s);
        library_b(n / 200, &cfg.critic, s, bl);
        direct_b(s, bd);
        for (k = 0; k < K; ++k) {
            if (near_threshold(bd[k], 0.001)) {
                continue;
            }
            if (bd[k] < 0.001) {
                assert_true(bl[k] == 0.0);
                ++dropped;
            } else {
                assert_close(bl[k], bd[k], b_tol());
                ++kept;
            }
        }
    }
    assert_true(dropped > 0 && kept > 0);
}

/* The sparse kernel's kept-unit list: pairs in order with their leading cells, cells sorted by product with a
 * zero sentinel, and exactly the units with b_k >= threshold. */
static void test_kept_unit_list(void **unused)
{
    icoac_config_t cfg = test_default_config();
    test_rng_t rng = {12u};
    icoac_real_t factors[ICOAC_CRITIC_FACTORS], v[K], s[4];
    icoac_priv_critic_list_t active;
    int n, i, p, total_kept = 0;
    (void)unused;
    memset(v, 0, sizeof v);
    for (n = 0; n < 300; ++n) {
        double bd[K];
        int listed[K];
        random_state(&rng, n % 3 == 2, s);
        icoac_priv_critic_factors(&cfg.critic, s, factors);
        (void)icoac_priv_critic_value_sparse(&cfg.critic, v, factors, &active);
        direct_b(s, bd);
        assert_true(active.cells <= ICOAC_CRITIC_CELLS);
        assert_true(active.cell_product[active.cells] == 0);
        for (i = 1; i < active.cells; ++i) {
            assert_true(active.cell_product[i - 1] >= active.cell_product[i]);
        }
        for (i = 0; i < active.cells; ++i) {
            assert_true(active.cell[i] < ICOAC_CRITIC_CELLS);
        }
        memset(listed, 0, sizeof listed);
        for (p = 0; p < ICOAC_CRITIC_PAIRS; ++p) {
            assert_true(active.pair_cells[p] <= active.cells);
            for (i = 0; i < active.pair_cells[p]; ++i) {
                const int k = p * ICOAC_CRITIC_CELLS + active.cell[i];
                assert_true(listed[k] == 0);
                listed[k] = 1;
            }
        }
        for (i = 0; i < K; ++i) {
            if (!near_threshold(bd[i], 0.001)) {
                assert_int_equal(listed[i], bd[i] >= 0.001);
            }
            total_kept += listed[i];
        }
    }
    assert_true(total_kept > 0 && total_kept < 300 * K / 2); /* the threshold does prune */

    /* threshold 0: a state inside the grid keeps all 162 units */
    cfg.critic.threshold = 0;
    s[0] = (icoac_real_t)0.3;
    s[1] = (icoac_real_t)-0.2;
    s[2] = (icoac_real_t)0.01;
    s[3] = (icoac_real_t)0.1;
    icoac_priv_critic_factors(&cfg.critic, s, factors);
    (void)icoac_priv_critic_value_sparse(&cfg.critic, v, factors, &active);
    assert_int_equal(active.cells, ICOAC_CRITIC_CELLS);
    for (p = 0; p < ICOAC_CRITIC_PAIRS; ++p) {
        assert_int_equal(active.pair_cells[p], ICOAC_CRITIC_CELLS);
    }
}

/* The host kernel against the microcontroller kernel: on random states (inside and far outside
 * the grid), weights and steps, over thresholds 0, the default and 0.05, both keep the same
 * units, so a sequence of updates with the same steps leaves both weight vectors equal bit for
 * bit; V differs only by the rounding of the sum's order (relative to sum |v_k b_k|). */
static void test_dense_matches_sparse(void **unused)
{
    const icoac_real_t thresholds[3] = {(icoac_real_t)0.0, (icoac_real_t)0.001, (icoac_real_t)0.05};
    icoac_config_t cfg = test_default_config();
    test_rng_t rng = {0xD15Eu};
    icoac_real_t v_sparse[K], v_dense[K], factors[ICOAC_CRITIC_FACTORS], s[4];
    icoac_priv_critic_active_t sparse, dense;
    double max_rel = 0;
    int t, n, k;
    (void)unused;
    for (t = 0; t < 3; ++t) {
        cfg.critic.threshold = thresholds[t];
        for (k = 0; k < K; ++k) {
            v_sparse[k] = v_dense[k] = (icoac_real_t)test_uniform(&rng, -2, 2);
        }
        for (n = 0; n < 3000; ++n) {
            double bd[K], magnitude = 0;
            icoac_real_t value_sparse, value_dense, step;
            random_state(&rng, n % 10 == 9, s);
            icoac_priv_critic_factors(&cfg.critic, s, factors);
            value_sparse = kernel_value(SPARSE, &cfg.critic, v_sparse, factors, &sparse);
            value_dense = kernel_value(DENSE, &cfg.critic, v_dense, factors, &dense);
            direct_b(s, bd);
            for (k = 0; k < K; ++k) {
                magnitude += fabs((double)v_sparse[k]) * bd[k];
            }
            assert_close(value_dense, value_sparse, (REAL_IS_FLOAT ? 2e-6 : 1e-14) * magnitude + 1e-30);
            if (magnitude > 0) {
                max_rel = fmax(max_rel, fabs((double)value_dense - (double)value_sparse) / magnitude);
            }
            step = (icoac_real_t)test_uniform(&rng, -0.05, 0.05);
            kernel_update(SPARSE, &cfg.critic, v_sparse, &sparse, step);
            kernel_update(DENSE, &cfg.critic, v_dense, &dense, step);
            assert_memory_equal(v_dense, v_sparse, sizeof v_sparse);
        }
    }
    assert_true(max_rel > 0); /* the orders do differ: the comparison is not vacuous */
}

static void step_ok(const icoac_config_t *cfg, icoac_state_t *state, const icoac_input_t *in, icoac_output_t *out)
{
    test_assert_config_in_force(cfg, state);
    assert_int_equal(icoac_step(state, in, out), ICOAC_OK);
}

static void test_td_update_through_step(void **unused)
{
    icoac_config_t cfg = test_default_config();
    icoac_state_t state;
    const icoac_priv_state_t *priv = icoac_priv_state_c(&state);
    icoac_output_t out;
    icoac_input_t st = test_input(0.3, -0.4, 0.05, 0.2, 0);
    icoac_input_t fail_in = test_input(0.31, -0.4, 0.22, 0.2, ICOAC_INPUT_TERMINAL);
    icoac_input_t sa = test_input(0.25, -0.3, 0.06, 0.1, 0);
    icoac_input_t sb = test_input(0.2, -0.35, 0.07, 0.15, 0);
    double b_t[K], b_a[K], b_b[K], v1[K];
    double va = 0, vb = 0, delta;
    int k;
    (void)unused;
    cfg.mode = ICOAC_MODE_RL;
    assert_int_equal(icoac_init(&cfg, &state, NULL, 77u), ICOAC_OK);

    /* tick 1: non-terminal s_t, v = 0, nothing to learn yet */
    step_ok(&cfg, &state, &st, &out);
    assert_true(out.value == 0 && out.td_error == 0);
    for (k = 0; k < K; ++k) {
        assert_true(priv->v[k] == 0);
    }
    /* tick 2: terminal: delta = -1 + 0 - V(s_t) = -1, v += eta * delta * b(s_t) */
    step_ok(&cfg, &state, &fail_in, &out);
    assert_close(out.td_error, -1.0, 0.0);
    assert_true(out.force == 0);
    direct_b_kept(st.s, 0.001, b_t);
    for (k = 0; k < K; ++k) {
        assert_close(priv->v[k], -0.6 * b_t[k], b_tol());
        v1[k] = (double)priv->v[k];
    }

    /* a non-terminal transition s_a -> s_b: delta = gamma V(s_b) - V(s_a) */
    assert_int_equal(icoac_reset(&state), ICOAC_OK);
    direct_b_kept(sa.s, 0.001, b_a);
    direct_b_kept(sb.s, 0.001, b_b);
    for (k = 0; k < K; ++k) {
        va += v1[k] * b_a[k];
        vb += v1[k] * b_b[k];
    }
    assert_true(va < -0.01); /* close to s_t: clearly negative */
    step_ok(&cfg, &state, &sa, &out);
    assert_close(out.value, va, REAL_IS_FLOAT ? 1e-6 : 1e-12);
    step_ok(&cfg, &state, &sb, &out);
    assert_close(out.value, vb, REAL_IS_FLOAT ? 1e-6 : 1e-12);
    delta = 0.95 * vb - va;
    assert_true(fabs(delta) < 1.0);
    assert_close(out.td_error, delta, REAL_IS_FLOAT ? 2e-6 : 1e-12);
    for (k = 0; k < K; ++k) {
        assert_close(priv->v[k], v1[k] + 0.6 * delta * b_a[k], REAL_IS_FLOAT ? 2e-6 : 1e-12);
    }
}

static void test_td_clip(void **unused)
{
    icoac_config_t cfg = test_default_config();
    icoac_state_t state;
    const icoac_priv_state_t *priv = icoac_priv_state_c(&state);
    icoac_output_t out;
    icoac_input_t st = test_input(-1.0, 0.4, -0.1, 0.5, 0);
    icoac_input_t fail_in = test_input(-2.41, 0.4, -0.1, 0.5, ICOAC_INPUT_TERMINAL);
    double b_t[K];
    int k;
    (void)unused;
    cfg.mode = ICOAC_MODE_RL;
    cfg.critic.td_clip = (icoac_real_t)0.25;
    cfg.critic.rate = (icoac_real_t)0.5;
    assert_int_equal(icoac_init(&cfg, &state, NULL, 1u), ICOAC_OK);
    step_ok(&cfg, &state, &st, &out);
    step_ok(&cfg, &state, &fail_in, &out);
    assert_close(out.td_error, -0.25, 0.0);
    direct_b_kept(st.s, 0.001, b_t);
    for (k = 0; k < K; ++k) {
        assert_close(priv->v[k], -0.5 * 0.25 * b_t[k], b_tol());
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_nonneg_at_least),
        cmocka_unit_test(test_grid_centres),
        cmocka_unit_test(test_separable_equals_direct),
        cmocka_unit_test(test_value_is_weighted_sum),
        cmocka_unit_test(test_threshold_drops_small_activations),
        cmocka_unit_test(test_kept_unit_list),
        cmocka_unit_test(test_dense_matches_sparse),
        cmocka_unit_test(test_td_update_through_step),
        cmocka_unit_test(test_td_clip),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
