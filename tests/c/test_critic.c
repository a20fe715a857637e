/* SPDX-License-Identifier: Apache-2.0 */
/* NGnet critic (method.md, critic): separable evaluation against the direct n-D formula (long
 * double) on the cart-pole's grid and on other task grids (6 inputs, 1, 3, 5), the activity
 * threshold and the kept-unit list, for both kernels (sparse: microcontrollers, dense: hosts);
 * the dense kernel against the sparse one; the TD(0) update through icoac_step in RL mode. */
#include "test_common.h"

#include "icoac_priv.h"

/* The critic grids under test: the cart-pole's, a double pendulum's (6 inputs), one input, a
 * lopsided one whose rows are a single 16-unit input, and five 2-unit inputs. */
typedef struct {
    int n;
    int sizes[6];
    double ranges[6];
} grid_t;

static const grid_t grids[] = {
    {4, {3, 3, 6, 3, 0, 0}, {2.4, 3.5, 0.2094384, 2.0, 0, 0}},
    {6, {3, 3, 3, 2, 2, 2}, {2.4, 0.3, 0.35, 3.5, 2.0, 2.5}},
    {1, {7, 0, 0, 0, 0, 0}, {1.5, 0, 0, 0, 0, 0}},
    {3, {16, 13, 1, 0, 0, 0}, {1.0, 20.0, 0.5, 0, 0, 0}},
    {5, {2, 2, 2, 2, 2, 0}, {1.0, 2.0, 3.0, 4.0, 5.0, 0}},
};
#define N_GRIDS ((int)(sizeof grids / sizeof grids[0]))
#define CARTPOLE 0

/* Room for any grid: the library's weight array. */
#define KMAX ICOAC_PRIV_CRITIC_WEIGHTS

/* The activations of the two sides of a comparison and a unit list, shared by the tests (they
 * run one after another), so that the test fits the Cortex-M0+ board's 16 KiB of RAM. */
static double bl[KMAX], bd[KMAX];
static int listed[KMAX];
#define K ICOAC_CARTPOLE_CRITIC_UNITS

static int units_of(const grid_t *g)
{
    int k = 1, i;
    for (i = 0; i < g->n; ++i) {
        k *= g->sizes[i];
    }
    return k;
}

/* The configuration of a grid: RL mode, its inputs, ranges and counts. */
static icoac_config_t grid_config(const grid_t *g)
{
    icoac_config_t cfg = test_default_config();
    int i;
    cfg.mode = ICOAC_MODE_RL;
    cfg.task.n_inputs = g->n;
    cfg.task.n_rules = 0;
    for (i = 0; i < ICOAC_MAX_INPUTS; ++i) {
        cfg.policy.input_range[i] = (icoac_real_t)1.0;
        cfg.critic.range[i] = i < g->n ? (icoac_real_t)g->ranges[i] : (icoac_real_t)1.0;
        cfg.critic.units[i] = i < g->n ? g->sizes[i] : 1;
    }
    TEST_ASSERT_EQUAL_INT(ICOAC_OK, icoac_config_check(&cfg));
    return cfg;
}

static icoac_priv_grid_t grid_geometry(const icoac_config_t *cfg)
{
    icoac_priv_grid_t geometry;
    icoac_priv_critic_grid(cfg, &geometry);
    return geometry;
}

/* ((s_i - c_ij) / sigma_i)^2 of input i's unit j, less its smallest over j (a factor common to
 * every unit, which the normalisation cancels: it keeps far-out inputs from swamping the others'
 * digits in the sum). */
static long double distance2(const grid_t *g, const icoac_real_t *s_in, int i, int j)
{
    const long double sigma = (long double)g->ranges[i] / g->sizes[i];
    long double smallest = 1e300L, d = 0;
    int jj;
    for (jj = 0; jj < g->sizes[i]; ++jj) {
        const long double centre = -(long double)g->ranges[i] + (2 * jj + 1) * sigma;
        const long double u = ((long double)s_in[i] - centre) / sigma;
        smallest = u * u < smallest ? u * u : smallest;
        d = jj == j ? u * u : d;
    }
    return d - smallest;
}

/* b_k(s) from the n-D definition: a_k = exp(-1/2 sum_i ((s_i - c_ki)/sigma_i)^2), normalised,
 * k row-major over the inputs. Computed in log space (shifted by the largest exponent) in long
 * double, so far-out states do not turn into 0/0; the shifts cancel in the ratio. */
static void direct_b(const grid_t *g, const icoac_real_t *s_in, double *b)
{
    static long double logs[KMAX];
    long double top = -1e300L, total = 0;
    const int units = units_of(g);
    int k, i;
    for (k = 0; k < units; ++k) {
        long double e = 0;
        int rest = k;
        for (i = g->n - 1; i >= 0; --i) {
            e += distance2(g, s_in, i, rest % g->sizes[i]);
            rest /= g->sizes[i];
        }
        logs[k] = -0.5L * e;
        top = logs[k] > top ? logs[k] : top;
    }
    for (k = 0; k < units; ++k) {
        total += expl(logs[k] - top);
    }
    for (k = 0; k < units; ++k) {
        b[k] = (double)(expl(logs[k] - top) / total);
    }
}

/* The same with the activity threshold (method.md, critic): b_k < threshold counts as 0. */
static void direct_b_kept(const grid_t *g, const icoac_real_t *s_in, double threshold, double *b)
{
    int k;
    direct_b(g, s_in, b);
    for (k = 0; k < units_of(g); ++k) {
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

static icoac_real_t kernel_value(int kernel, const icoac_config_t *cfg, const icoac_real_t *v, const icoac_real_t *s,
                                 icoac_priv_critic_active_t *active)
{
    const icoac_priv_grid_t geometry = grid_geometry(cfg);
    return kernel == DENSE ? icoac_priv_critic_value_dense(&cfg->critic, &geometry, v, s, NULL, &active->dense)
                           : icoac_priv_critic_value_sparse(&cfg->critic, &geometry, v, s, &active->sparse);
}

/* Through the state's shape tag, as the tick does (the cart-pole's grid takes the cart-pole
 * instance, the others the general one). */
static void kernel_update(int kernel, const icoac_config_t *cfg, icoac_real_t *v,
                          const icoac_priv_critic_active_t *active, icoac_real_t step)
{
    const icoac_priv_grid_t geometry = grid_geometry(cfg);
    if (kernel == DENSE) {
        icoac_priv_critic_update_dense(&cfg->critic, &geometry, v, &active->dense, step);
    } else {
        icoac_priv_critic_update_sparse_shaped(&geometry, v, &active->sparse, step);
    }
}

/* b_k(s) from a kernel: the value pass finds the kept units, and an update with step 1 on
 * v = 0 writes their b_k into v; the room past the grid's units stays 0. */
static void library_b(int kernel, const icoac_config_t *cfg, const icoac_real_t *s, double *b)
{
    icoac_real_t v[KMAX];
    icoac_priv_critic_active_t active;
    int k;
    memset(v, 0, sizeof v);
    TEST_ASSERT_TRUE(kernel_value(kernel, cfg, v, s, &active) == 0);
    kernel_update(kernel, cfg, v, &active, (icoac_real_t)1.0);
    for (k = 0; k < KMAX; ++k) {
        b[k] = (double)v[k];
    }
}

static double b_tol(void)
{
    return REAL_IS_FLOAT ? 2e-6 : 1e-12;
}

/* A state of a grid's inputs (0 past them): inside the grid, or far out. */
static void random_state(const grid_t *g, test_rng_t *rng, int far, icoac_real_t s[ICOAC_MAX_INPUTS])
{
    int i;
    for (i = 0; i < ICOAC_MAX_INPUTS; ++i) {
        const double scale = far ? (i == 2 ? 20.0 : 15.0) : 1.3;
        s[i] = i < g->n ? (icoac_real_t)test_uniform(rng, -scale * g->ranges[i], scale * g->ranges[i]) : 0;
    }
}

/* The integer comparison behind the threshold agrees with >= on non-negative reals. */
static void test_nonneg_at_least(void)
{
    const icoac_real_t special[] = {(icoac_real_t)0.0, (icoac_real_t)1e-45, (icoac_real_t)1e-40,
                                    (icoac_real_t)1e-38, (icoac_real_t)0.001, (icoac_real_t)0.5,
                                    (icoac_real_t)1.0, (icoac_real_t)3e38, (icoac_real_t)INFINITY};
    const int n_special = (int)(sizeof special / sizeof special[0]);
    test_rng_t rng = {77u};
    int i, j;
    for (i = 0; i < n_special; ++i) {
        for (j = 0; j < n_special; ++j) {
            TEST_ASSERT_EQUAL_INT(special[i] >= special[j], icoac_priv_nonneg_at_least(special[i], special[j]));
        }
    }
    for (i = 0; i < 100000; ++i) {
        const icoac_real_t a = (icoac_real_t)pow(10.0, test_uniform(&rng, -40, 3));
        const icoac_real_t b = i % 3 == 0 ? a : (icoac_real_t)pow(10.0, test_uniform(&rng, -40, 3));
        TEST_ASSERT_EQUAL_INT(a >= b, icoac_priv_nonneg_at_least(a, b));
    }
}

static void test_grid_centres(void)
{
    /* the centres listed in method.md: x {-1.6, 0, 1.6}; theta +-2, +-6, +-10 deg (to 4 digits) */
    const double x_c[3] = {-1.6, 0.0, 1.6};
    const double th_c[6] = {-10, -6, -2, 2, 6, 10};
    int j;
    for (j = 0; j < 3; ++j) {
        assert_close(-2.4 + (2 * j + 1) * 2.4 / 3, x_c[j], 1e-12);
    }
    for (j = 0; j < 6; ++j) {
        assert_close(-0.2094384 + (2 * j + 1) * 0.2094384 / 6, DEG(th_c[j]), 1e-5);
    }
}

/* Random states per grid (and kernel, in test_separable_equals_direct): fewer on an emulated core
 * (QEMU is slow). */
#define STATES TEST_ITERATIONS(200, 40)

/* Every kernel on every grid equals the n-D definition, with threshold 0 (every unit). */
static void test_separable_equals_direct(void)
{
    test_rng_t rng = {0xC0FFEEu};
    int gi, n, k;
    for (gi = 0; gi < N_GRIDS; ++gi) {
        const grid_t *g = &grids[gi];
        icoac_config_t cfg = grid_config(g);
        const int units = units_of(g);
        cfg.critic.threshold = 0; /* every unit */
        for (n = 0; n < 2 * STATES; ++n) {
            const int kernel = n / STATES;
            icoac_real_t s[ICOAC_MAX_INPUTS];
            double sum = 0;
            random_state(g, &rng, n % STATES >= STATES / 2, s);
            if (n % STATES == 0) {
                memset(s, 0, sizeof s); /* between or on centres */
            } else if (n % STATES == 1) {
                s[0] = (icoac_real_t)(g->ranges[0] * (1.0 - 1.0 / g->sizes[0])); /* on the last centre */
                s[g->n - 1] = (icoac_real_t)-1e6;
            }
            library_b(kernel, &cfg, s, bl);
            direct_b(g, s, bd);
            for (k = 0; k < units; ++k) {
                if (!(fabs(bl[k] - bd[k]) <= b_tol())) {
                    TEST_PRINTF("grid %d kernel %d state %d unit %d: %g vs %g at (%g, %g, %g, %g)", gi, kernel, n, k,
                                bl[k], bd[k], (double)s[0], (double)s[1], (double)s[2], (double)s[3]);
                    TEST_FAIL();
                }
                TEST_ASSERT_TRUE(bl[k] >= 0.0);
                sum += bl[k];
            }
            for (k = units; k < KMAX; ++k) {
                TEST_ASSERT_TRUE(bl[k] == 0.0); /* nothing past the grid's units */
            }
            assert_close(sum, 1.0, REAL_IS_FLOAT ? 1e-5 : 1e-12);
        }
    }
}

static void check_value(const grid_t *g, icoac_real_t threshold, unsigned seed, int kernel)
{
    icoac_config_t cfg = grid_config(g);
    test_rng_t rng = {seed};
    const int units = units_of(g);
    icoac_real_t v[KMAX], s[ICOAC_MAX_INPUTS];
    icoac_priv_critic_active_t active;
    int n, k;
    cfg.critic.threshold = threshold;
    for (n = 0; n < STATES / 2; ++n) {
        double expected = 0, slack = 0;
        for (k = 0; k < KMAX; ++k) {
            v[k] = k < units ? (icoac_real_t)test_uniform(&rng, -1, 1) : (icoac_real_t)NAN; /* past the grid: unread */
        }
        random_state(g, &rng, n & 1, s);
        direct_b_kept(g, s, (double)threshold, bd);
        for (k = 0; k < units; ++k) {
            expected += (double)v[k] * bd[k];
            slack += near_threshold(bd[k], (double)threshold) ? fabs((double)v[k]) * bd[k] : 0;
        }
        assert_close(kernel_value(kernel, &cfg, v, s, &active), expected, slack + (REAL_IS_FLOAT ? 1e-5 : 1e-12));
    }
}

static void test_value_is_weighted_sum(void)
{
    int gi, kernel;
    for (gi = 0; gi < N_GRIDS; ++gi) {
        for (kernel = SPARSE; kernel < KERNELS; ++kernel) {
            check_value(&grids[gi], (icoac_real_t)0.001, 31u, kernel); /* the default */
            check_value(&grids[gi], 0, 32u, kernel);
            check_value(&grids[gi], (icoac_real_t)0.05, 33u, kernel);
        }
    }
}

static void test_threshold_drops_small_activations(void)
{
    test_rng_t rng = {8u};
    int gi, n, k, dropped = 0, kept = 0;
    for (gi = 0; gi < N_GRIDS; ++gi) {
        const grid_t *g = &grids[gi];
        const icoac_config_t cfg = grid_config(g);
        TEST_ASSERT_TRUE(cfg.critic.threshold == (icoac_real_t)0.001); /* the authors' cut-off is the default */
        for (n = 0; n < STATES; ++n) {
            icoac_real_t s[ICOAC_MAX_INPUTS];
            random_state(g, &rng, n % (STATES / 2) >= STATES * 3 / 8, s);
            library_b(n / (STATES / 2), &cfg, s, bl);
            direct_b(g, s, bd);
            for (k = 0; k < units_of(g); ++k) {
                if (near_threshold(bd[k], 0.001)) {
                    continue;
                }
                if (bd[k] < 0.001) {
                    TEST_ASSERT_TRUE(bl[k] == 0.0);
                    ++dropped;
                } else {
                    assert_close(bl[k], bd[k], b_tol());
                    ++kept;
                }
            }
        }
    }
    TEST_ASSERT_TRUE(dropped > 0 && kept > 0);
}

/* The sparse kernel's kept-unit list: rows in order with their leading cells, cells sorted by
 * product with a zero sentinel, and exactly the units with b_k >= threshold. */
static void test_kept_unit_list(void)
{
    test_rng_t rng = {12u};
    icoac_real_t v[KMAX], s[ICOAC_MAX_INPUTS];
    icoac_priv_critic_active_t active;
    int gi, n, i, r, total_kept = 0, total_units = 0, all_kept_grids = 0;
    memset(v, 0, sizeof v);
    for (gi = 0; gi < N_GRIDS; ++gi) {
        const grid_t *g = &grids[gi];
        icoac_config_t cfg = grid_config(g);
        const icoac_priv_critic_list_t *list = &active.sparse;
        const int units = units_of(g);
        for (n = 0; n < STATES; ++n) {
            random_state(g, &rng, n % 3 == 2, s);
            (void)kernel_value(SPARSE, &cfg, v, s, &active);
            direct_b(g, s, bd);
            TEST_ASSERT_EQUAL_INT(units, list->rows * list->stride);
            TEST_ASSERT_TRUE(list->stride <= ICOAC_CRITIC_BLOCK_MAX && list->rows <= ICOAC_CRITIC_BLOCK_MAX);
            TEST_ASSERT_TRUE(list->cells <= list->stride);
            TEST_ASSERT_TRUE(list->rows + list->cells < ICOAC_PRIV_LIST);
            TEST_ASSERT_TRUE(list->product[list->rows + list->cells] == 0);
            for (i = 1; i < list->cells; ++i) {
                TEST_ASSERT_TRUE(list->product[list->rows + i - 1] >= list->product[list->rows + i]);
            }
            for (i = 0; i < list->cells; ++i) {
                TEST_ASSERT_TRUE(list->index[list->rows + i] < list->stride);
            }
            memset(listed, 0, sizeof listed);
            for (r = 0; r < list->rows; ++r) {
                TEST_ASSERT_TRUE(list->index[r] <= list->cells);
                for (i = 0; i < list->index[r]; ++i) {
                    const int k = r * list->stride + list->index[list->rows + i];
                    TEST_ASSERT_TRUE(listed[k] == 0);
                    listed[k] = 1;
                }
            }
            for (i = 0; i < units; ++i) {
                if (!near_threshold(bd[i], 0.001)) {
                    TEST_ASSERT_EQUAL_INT(bd[i] >= 0.001, listed[i]);
                }
                total_kept += listed[i];
            }
            total_units += units;
        }
        /* threshold 0: a state at the grid's centre keeps every unit, where every b_k is well
         * above the smallest normal number (the floor) */
        cfg.critic.threshold = 0;
        memset(s, 0, sizeof s);
        (void)kernel_value(SPARSE, &cfg, v, s, &active);
        direct_b(g, s, bd);
        for (i = 0; i < units && bd[i] > 1e-30; ++i) {
        }
        if (i == units) {
            TEST_ASSERT_EQUAL_INT(list->stride, list->cells);
            for (r = 0; r < list->rows; ++r) {
                TEST_ASSERT_EQUAL_INT(list->stride, list->index[r]);
            }
            ++all_kept_grids;
        }
    }
    TEST_ASSERT_TRUE(all_kept_grids >= 2); /* the cart-pole's and the double pendulum's at least */
    TEST_ASSERT_TRUE(total_kept > 0 && total_kept < total_units / 2); /* the threshold does prune */
    /* the cart-pole's blocks: (x, x_dot) rows by (theta, theta_dot) cells */
    {
        icoac_config_t cfg = grid_config(&grids[CARTPOLE]);
        (void)kernel_value(SPARSE, &cfg, v, s, &active);
        TEST_ASSERT_EQUAL_INT(ICOAC_CRITIC_N_X * ICOAC_CRITIC_N_X_DOT, active.sparse.rows);
        TEST_ASSERT_EQUAL_INT(ICOAC_CRITIC_N_THETA * ICOAC_CRITIC_N_THETA_DOT, active.sparse.stride);
    }
}

/* The host kernel against the microcontroller kernel: on random states (inside and far outside
 * the grid), weights and steps, over thresholds 0, the default and 0.05, both keep the same
 * units, so a sequence of updates with the same steps leaves both weight vectors equal bit for
 * bit; V differs only by the rounding of the sum's order (relative to sum |v_k b_k|). */
static void test_dense_matches_sparse(void)
{
    const icoac_real_t thresholds[3] = {(icoac_real_t)0.0, (icoac_real_t)0.001, (icoac_real_t)0.05};
    test_rng_t rng = {0xD15Eu};
    icoac_real_t v_sparse[KMAX], v_dense[KMAX], s[ICOAC_MAX_INPUTS];
    icoac_priv_critic_active_t sparse, dense;
    double max_rel = 0;
    int gi, t, n, k;
    for (gi = 0; gi < N_GRIDS; ++gi) {
        const grid_t *g = &grids[gi];
        icoac_config_t cfg = grid_config(g);
        for (t = 0; t < 3; ++t) {
            cfg.critic.threshold = thresholds[t];
            for (k = 0; k < KMAX; ++k) {
                v_sparse[k] = v_dense[k] = (icoac_real_t)test_uniform(&rng, -2, 2);
            }
            /* fewer states on an emulated core (QEMU is slow) */
            for (n = 0; n < TEST_ITERATIONS(1000, 100); ++n) {
                double magnitude = 0;
                icoac_real_t value_sparse, value_dense, step;
                random_state(g, &rng, n % 10 == 9, s);
                value_sparse = kernel_value(SPARSE, &cfg, v_sparse, s, &sparse);
                value_dense = kernel_value(DENSE, &cfg, v_dense, s, &dense);
                direct_b(g, s, bd);
                for (k = 0; k < units_of(g); ++k) {
                    magnitude += fabs((double)v_sparse[k]) * bd[k];
                }
                assert_close(value_dense, value_sparse, (REAL_IS_FLOAT ? 2e-6 : 1e-14) * magnitude + 1e-30);
                if (magnitude > 0) {
                    max_rel = fmax(max_rel, fabs((double)value_dense - (double)value_sparse) / magnitude);
                }
                step = (icoac_real_t)test_uniform(&rng, -0.05, 0.05);
                kernel_update(SPARSE, &cfg, v_sparse, &sparse, step);
                kernel_update(DENSE, &cfg, v_dense, &dense, step);
                TEST_ASSERT_EQUAL_MEMORY(v_sparse, v_dense, sizeof v_sparse);
            }
        }
    }
    TEST_ASSERT_TRUE(max_rel > 0); /* the orders do differ: the comparison is not vacuous */
}

static void step_ok(const icoac_config_t *cfg, icoac_state_t *state, const icoac_input_t *in, icoac_output_t *out)
{
    test_assert_config_in_force(cfg, state);
    TEST_ASSERT_EQUAL_INT(ICOAC_OK, icoac_step(state, in, out));
}

static void test_td_update_through_step(void)
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
    const grid_t *g = &grids[CARTPOLE];
    double va = 0, vb = 0, delta;
    int k;
    cfg.mode = ICOAC_MODE_RL;
    TEST_ASSERT_EQUAL_INT(ICOAC_OK, icoac_init(&cfg, &state, NULL, 77u));

    /* tick 1: non-terminal s_t, v = 0, nothing to learn yet */
    step_ok(&cfg, &state, &st, &out);
    TEST_ASSERT_TRUE(out.value == 0 && out.td_error == 0);
    for (k = 0; k < K; ++k) {
        TEST_ASSERT_TRUE(priv->v[k] == 0);
    }
    /* tick 2: terminal: delta = -1 + 0 - V(s_t) = -1, v += eta * delta * b(s_t) */
    step_ok(&cfg, &state, &fail_in, &out);
    assert_close(out.td_error, -1.0, 0.0);
    TEST_ASSERT_TRUE(out.force == 0);
    direct_b_kept(g, st.s, 0.001, b_t);
    for (k = 0; k < K; ++k) {
        assert_close(priv->v[k], -0.6 * b_t[k], b_tol());
        v1[k] = (double)priv->v[k];
    }

    /* a non-terminal transition s_a -> s_b: delta = gamma V(s_b) - V(s_a) */
    TEST_ASSERT_EQUAL_INT(ICOAC_OK, icoac_reset(&state));
    direct_b_kept(g, sa.s, 0.001, b_a);
    direct_b_kept(g, sb.s, 0.001, b_b);
    for (k = 0; k < K; ++k) {
        va += v1[k] * b_a[k];
        vb += v1[k] * b_b[k];
    }
    TEST_ASSERT_TRUE(va < -0.01); /* close to s_t: clearly negative */
    step_ok(&cfg, &state, &sa, &out);
    assert_close(out.value, va, REAL_IS_FLOAT ? 1e-6 : 1e-12);
    step_ok(&cfg, &state, &sb, &out);
    assert_close(out.value, vb, REAL_IS_FLOAT ? 1e-6 : 1e-12);
    delta = 0.95 * vb - va;
    TEST_ASSERT_TRUE(fabs(delta) < 1.0);
    assert_close(out.td_error, delta, REAL_IS_FLOAT ? 2e-6 : 1e-12);
    for (k = 0; k < K; ++k) {
        assert_close(priv->v[k], v1[k] + 0.6 * delta * b_a[k], REAL_IS_FLOAT ? 2e-6 : 1e-12);
    }
}

static void test_td_clip(void)
{
    icoac_config_t cfg = test_default_config();
    icoac_state_t state;
    const icoac_priv_state_t *priv = icoac_priv_state_c(&state);
    icoac_output_t out;
    icoac_input_t st = test_input(-1.0, 0.4, -0.1, 0.5, 0);
    icoac_input_t fail_in = test_input(-2.41, 0.4, -0.1, 0.5, ICOAC_INPUT_TERMINAL);
    double b_t[K];
    int k;
    cfg.mode = ICOAC_MODE_RL;
    cfg.critic.td_clip = (icoac_real_t)0.25;
    cfg.critic.rate = (icoac_real_t)0.5;
    TEST_ASSERT_EQUAL_INT(ICOAC_OK, icoac_init(&cfg, &state, NULL, 1u));
    step_ok(&cfg, &state, &st, &out);
    step_ok(&cfg, &state, &fail_in, &out);
    assert_close(out.td_error, -0.25, 0.0);
    direct_b_kept(&grids[CARTPOLE], st.s, 0.001, b_t);
    for (k = 0; k < K; ++k) {
        assert_close(priv->v[k], -0.5 * 0.25 * b_t[k], b_tol());
    }
}

void setUp(void) {}
void tearDown(void) {}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_nonneg_at_least);
    RUN_TEST(test_grid_centres);
    RUN_TEST(test_separable_equals_direct);
    RUN_TEST(test_value_is_weighted_sum);
    RUN_TEST(test_threshold_drops_small_activations);
    RUN_TEST(test_kept_unit_list);
    RUN_TEST(test_dense_matches_sparse);
    RUN_TEST(test_td_update_through_step);
    RUN_TEST(test_td_clip);
    return UNITY_END();
}
