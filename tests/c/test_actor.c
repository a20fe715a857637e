/* SPDX-License-Identifier: Apache-2.0 */
/* Bayesian actor (method.md): icoac_priv_actor_posterior against the closed-form Gaussian posterior,
 * long-run symmetry / positive definiteness, forgetting, and the Eq. 7-8 wiring in icoac_step. */
#include "test_common.h"

#include "icoac_priv.h"

#define N ICOAC_CARTPOLE_INPUTS /* the cart-pole task's inputs */
#define M ICOAC_MAX_INPUTS      /* the library's vectors: entries past N are 0 */

/* The update writes its candidate posterior over the state's own (mu_w, Sigma_w): the
 * outputs alias what it reads. */
static void actor_update_in_place(const icoac_config_t *cfg, icoac_state_t *state, const icoac_real_t h[M],
                                  icoac_real_t innovation)
{
    icoac_priv_state_t *st = icoac_priv_state(state);
    icoac_priv_actor_posterior(&cfg->actor, st, h, innovation, st->w, icoac_priv_cov(st));
}

/* The state's mean and covariance. */
static icoac_real_t *mean_of(icoac_state_t *state)
{
    return icoac_priv_state(state)->w;
}

static icoac_real_t (*cov_of(icoac_state_t *state))[M]
{
    return icoac_priv_cov(icoac_priv_state(state));
}

typedef struct {
    double mean[N];
    double cov[N][N];
} gauss_t;

/* Posterior of w ~ N(mean, cov) after observing y = h^T w + e, e ~ N(0, r), with
 * innovation y - h^T mean. Textbook form (not Joseph form). */
static void closed_form(const gauss_t *prior, const double h[N], double innovation, double r, gauss_t *post)
{
    double ch[N], s = r;
    int i, j;
    for (i = 0; i < N; ++i) {
        ch[i] = 0;
        for (j = 0; j < N; ++j) {
            ch[i] += prior->cov[i][j] * h[j];
        }
        s += h[i] * ch[i];
    }
    for (i = 0; i < N; ++i) {
        post->mean[i] = prior->mean[i] + ch[i] * innovation / s;
        for (j = 0; j < N; ++j) {
            post->cov[i][j] = prior->cov[i][j] - ch[i] * ch[j] / s;
        }
    }
}

/* Random SPD matrix A A^T + 0.05 I scaled by `scale`, and a random mean. */
static void random_gauss(test_rng_t *rng, double scale, gauss_t *g)
{
    double a[N][N];
    int i, j, k;
    for (i = 0; i < N; ++i) {
        g->mean[i] = test_uniform(rng, -0.5, 0.5);
        for (j = 0; j < N; ++j) {
            a[i][j] = test_uniform(rng, -1, 1);
        }
    }
    for (i = 0; i < N; ++i) {
        for (j = 0; j <= i; ++j) {
            double sum = i == j ? 0.05 : 0.0;
            for (k = 0; k < N; ++k) {
                sum += a[i][k] * a[j][k];
            }
            g->cov[i][j] = g->cov[j][i] = scale * sum;
        }
    }
}

/* Store g in the state (rounded to icoac_real_t) and read the rounded values back into g. */
static void load_state(icoac_state_t *state, gauss_t *g)
{
    icoac_real_t *w = mean_of(state);
    icoac_real_t(*cov)[M] = cov_of(state);
    int i, j;
    for (i = 0; i < N; ++i) {
        w[i] = (icoac_real_t)g->mean[i];
        g->mean[i] = (double)w[i];
        for (j = 0; j < N; ++j) {
            cov[i][j] = (icoac_real_t)g->cov[i][j];
            g->cov[i][j] = (double)cov[i][j];
        }
    }
}

/* RL with the posterior reading (the file's subject; the default reading is the gradient). */
static icoac_state_t rl_state(icoac_config_t *cfg)
{
    icoac_state_t state;
    *cfg = test_default_config();
    cfg->mode = ICOAC_MODE_RL;
    test_literal_reading(cfg);
    TEST_ASSERT_EQUAL_INT(ICOAC_OK, icoac_init(cfg, &state, NULL, 1u));
    return state;
}

static double max_abs(const double m[N][N])
{
    double v = 0;
    int i, j;
    for (i = 0; i < N; ++i) {
        for (j = 0; j < N; ++j) {
            v = fabs(m[i][j]) > v ? fabs(m[i][j]) : v;
        }
    }
    return v;
}

static void compare_with_closed_form(const icoac_config_t *cfg, test_rng_t *rng, double h_scale)
{
    icoac_config_t c2;
    icoac_state_t state = rl_state(&c2);
    gauss_t prior, post;
    icoac_real_t h[M] = {0};
    double hd[N], innovation, r, tol;
    int i, j;
    random_gauss(rng, test_uniform(rng, 0.01, 2.0), &prior);
    load_state(&state, &prior);
    for (i = 0; i < N; ++i) {
        h[i] = (icoac_real_t)test_uniform(rng, -h_scale, h_scale);
        hd[i] = (double)h[i];
    }
    innovation = (double)(icoac_real_t)test_uniform(rng, -3, 3);
    /* the likelihood variance is sigma_L^2 (L2), whatever the exploration std sigma_u;
     * sigma_L = sigma_u when likelihood_std is 0 (the literal reading) */
    r = test_likelihood_var(&cfg->actor);
    closed_form(&prior, hd, innovation, r, &post);
    actor_update_in_place(cfg, &state, h, (icoac_real_t)innovation);
    /* float: a few hundred ulps of the largest prior entry (the update subtracts nearly equal terms) */
    tol = (REAL_IS_FLOAT ? 2e-5 : 1e-12) * (1.0 + max_abs(prior.cov));
    for (i = 0; i < N; ++i) {
        assert_close(mean_of(&state)[i], post.mean[i], tol * (1.0 + fabs(innovation)));
        for (j = 0; j < N; ++j) {
            assert_close(cov_of(&state)[i][j], post.cov[i][j], tol);
            TEST_ASSERT_TRUE(cov_of(&state)[i][j] == cov_of(&state)[j][i]);
        }
    }
}

static void test_update_matches_closed_form(void)
{
    icoac_config_t cfg;
    test_rng_t rng = {0xACu};
    int n;
    (void)rl_state(&cfg);
    for (n = 0; n < 400; ++n) {
        /* 0: sigma_L = sigma_u */
        cfg.actor.likelihood_std = (icoac_real_t)(n % 4 == 0 ? 1.0 : (n % 4 == 1 ? 0.5 : (n % 4 == 2 ? 3.0 : 0.0)));
        /* sigma_u differs from sigma_L in most cases: it must not enter the posterior step but
         * through likelihood_std = 0 */
        cfg.actor.noise_std = (icoac_real_t)(n % 5 == 0 ? 1.0 : (n % 5 < 3 ? 0.25 : 7.0));
        compare_with_closed_form(&cfg, &rng, n % 2 ? 10.0 : 1.0);
    }
}

static void test_zero_innovation_keeps_mean(void)
{
    icoac_config_t cfg;
    icoac_state_t state = rl_state(&cfg);
    test_rng_t rng = {3u};
    gauss_t prior;
    icoac_real_t h[M] = {(icoac_real_t)3.0, (icoac_real_t)-7.0, (icoac_real_t)10.0, (icoac_real_t)0.5};
    icoac_real_t mean_before[M] = {0};
    double trace_before;
    random_gauss(&rng, 1.0, &prior);
    load_state(&state, &prior);
    memcpy(mean_before, mean_of(&state), sizeof mean_before);
    trace_before = (double)icoac_priv_trace(ICOAC_PRIV_CONST_MAT(cov_of(&state)));
    actor_update_in_place(&cfg, &state, h, (icoac_real_t)0.0);
    TEST_ASSERT_EQUAL_MEMORY(mean_before, mean_of(&state), sizeof mean_before);
    /* the covariance still shrinks */
    TEST_ASSERT_TRUE((double)icoac_priv_trace(ICOAC_PRIV_CONST_MAT(cov_of(&state))) < trace_before);
}

static void test_forgetting_inflates_first(void)
{
    icoac_config_t cfg;
    icoac_state_t state = rl_state(&cfg);
    test_rng_t rng = {4u};
    gauss_t prior, inflated, post;
    icoac_real_t h[M] = {0};
    double hd[N];
    const double lambda = 0.9;
    int i, j;
    cfg.actor.forgetting = (icoac_real_t)lambda;
    random_gauss(&rng, 0.5, &prior);
    load_state(&state, &prior);
    for (i = 0; i < N; ++i) {
        h[i] = (icoac_real_t)test_uniform(&rng, -10, 10);
        hd[i] = (double)h[i];
    }
    inflated = prior;
    for (i = 0; i < N; ++i) {
        for (j = 0; j < N; ++j) {
            inflated.cov[i][j] = prior.cov[i][j] / (double)cfg.actor.forgetting;
        }
    }
    closed_form(&inflated, hd, 0.7, test_likelihood_var(&cfg.actor), &post);
    actor_update_in_place(&cfg, &state, h, (icoac_real_t)0.7);
    for (i = 0; i < N; ++i) {
        assert_close(mean_of(&state)[i], post.mean[i], REAL_IS_FLOAT ? 1e-4 : 1e-12);
        for (j = 0; j < N; ++j) {
            assert_close(cov_of(&state)[i][j], post.cov[i][j], REAL_IS_FLOAT ? 1e-4 : 1e-12);
        }
    }
    /* with h = 0 (no information) the step is pure inflation: Sigma / lambda */
    load_state(&state, &prior);
    memset(h, 0, sizeof h);
    actor_update_in_place(&cfg, &state, h, (icoac_real_t)0.3);
    for (i = 0; i < N; ++i) {
        TEST_ASSERT_TRUE(mean_of(&state)[i] == (icoac_real_t)prior.mean[i]);
        for (j = 0; j < N; ++j) {
            assert_close(cov_of(&state)[i][j], prior.cov[i][j] / lambda,
                         4.0 * REAL_EPS * (1.0 + fabs(prior.cov[i][j])));
        }
    }
}

/* The RL tick stages the update: it reads (mu_w, Sigma_w) from the state and writes the
 * candidate to a local w and the spare covariance buffer, leaving the state's own posterior
 * as it was. The staged result is bitwise the in-place one, with and without forgetting. */
static void test_update_staged_into_spare(void)
{
    test_rng_t rng = {0x57A6Eu};
    int n, i;
    for (n = 0; n < 200; ++n) {
        icoac_config_t cfg;
        icoac_state_t state = rl_state(&cfg);
        icoac_state_t in_place;
        icoac_state_t before;
        icoac_priv_state_t *st = icoac_priv_state(&state);
        const int spare = st->cov_slot ^ 1;
        gauss_t prior;
        icoac_real_t h[M] = {0};
        icoac_real_t w[M] = {0};
        const icoac_real_t innovation = (icoac_real_t)test_uniform(&rng, -3, 3);
        cfg.actor.forgetting = n % 2 ? ICOAC_R(1.0) : (icoac_real_t)0.95;
        random_gauss(&rng, test_uniform(&rng, 0.01, 2.0), &prior);
        load_state(&state, &prior);
        for (i = 0; i < N; ++i) {
            h[i] = (icoac_real_t)test_uniform(&rng, -10, 10);
        }
        in_place = state;
        before = state;
        icoac_priv_actor_posterior(&cfg.actor, st, h, innovation, w, st->cov_buffer[spare]);
        actor_update_in_place(&cfg, &in_place, h, innovation);
        /* the state's posterior and slot are untouched ... */
        TEST_ASSERT_EQUAL_INT(icoac_priv_state_c(&before)->cov_slot, st->cov_slot);
        TEST_ASSERT_EQUAL_MEMORY(icoac_priv_state_c(&before)->w, st->w, sizeof st->w);
        TEST_ASSERT_EQUAL_MEMORY(icoac_priv_cov_c(icoac_priv_state_c(&before)), icoac_priv_cov_c(st),
                                 sizeof(icoac_real_t) * N * N);
        /* ... and the staged candidate is the in-place result */
        TEST_ASSERT_EQUAL_MEMORY(mean_of(&in_place), w, sizeof w);
        TEST_ASSERT_EQUAL_MEMORY(cov_of(&in_place), st->cov_buffer[spare], sizeof(icoac_real_t) * N * N);
    }
}

/* Sigma stays exactly symmetric and positive definite over many updates; it matches the
 * information-form accumulation Sigma^-1 = Sigma_0^-1 + sum h h^T / sigma_L^2 (sigma_L = sigma_u
 * = 1 by default). */
static void run_long(double forgetting, int n_updates)
{
    icoac_config_t cfg;
    icoac_state_t state = rl_state(&cfg);
    icoac_real_t lower[M][M] = {{0}};
    test_rng_t rng = {0x5EEDu};
    double info[N][N];
    int n, i, j;
    cfg.actor.forgetting = (icoac_real_t)forgetting;
    for (i = 0; i < N; ++i) {
        for (j = 0; j < N; ++j) {
            info[i][j] = i == j ? 1.0 : 0.0; /* Sigma_0 = I from icoac_init */
        }
    }
    for (n = 0; n < n_updates; ++n) {
        icoac_real_t h[M] = {0};
        double prev_trace = (double)icoac_priv_trace(ICOAC_PRIV_CONST_MAT(cov_of(&state)));
        for (i = 0; i < N; ++i) {
            h[i] = (icoac_real_t)(10.0 * test_uniform(&rng, -1, 1)); /* G x~, |x~| <= 1 */
        }
        actor_update_in_place(&cfg, &state, h, (icoac_real_t)test_uniform(&rng, -3, 3));
        for (i = 0; i < N; ++i) {
            for (j = 0; j < N; ++j) {
                if (cov_of(&state)[i][j] != cov_of(&state)[j][i]) {
                    TEST_PRINTF("update %d: cov not symmetric at (%d, %d)", n, i, j);
                    TEST_FAIL();
                }
                info[i][j] = forgetting * info[i][j] + (double)h[i] * (double)h[j] / test_likelihood_var(&cfg.actor);
            }
        }
        if (!icoac_priv_cholesky(ICOAC_PRIV_CONST_MAT(cov_of(&state)), lower, ICOAC_CARTPOLE_INPUTS)) {
            TEST_PRINTF("update %d: cov not positive definite", n);
            TEST_FAIL();
        }
        if (forgetting == 1.0) {
            /* without forgetting Sigma never grows (up to rounding) */
            TEST_ASSERT_TRUE((double)icoac_priv_trace(ICOAC_PRIV_CONST_MAT(cov_of(&state))) <=
                             prev_trace * (1.0 + 64.0 * REAL_EPS));
        }
    }
    for (i = 0; i < N; ++i) {
        TEST_ASSERT_TRUE(isfinite(mean_of(&state)[i]));
    }
    /* Sigma * info should be I: check the trace and the largest off-diagonal. */
    {
        double tr = 0, off = 0;
        int k;
        for (i = 0; i < N; ++i) {
            for (j = 0; j < N; ++j) {
                double p = 0;
                for (k = 0; k < N; ++k) {
                    p += (double)cov_of(&state)[i][k] * info[k][j];
                }
                if (i == j) {
                    tr += p;
                } else {
                    off = fabs(p) > off ? fabs(p) : off;
                }
            }
        }
        assert_close(tr, 4.0, REAL_IS_FLOAT ? 0.05 : 1e-6);
        assert_close(off, 0.0, REAL_IS_FLOAT ? 0.05 : 1e-6);
    }
}

static void test_long_run_symmetric_pd(void)
{
    run_long(1.0, TEST_ITERATIONS(1000000, 20000)); /* fewer updates on an emulated core (QEMU is slow) */
}

static void test_long_run_with_forgetting(void)
{
    run_long(0.999, TEST_ITERATIONS(100000, 10000)); /* fewer updates on an emulated core (QEMU is slow) */
}

/* Eq. 7-8 through icoac_step with the posterior reading: u_ob - h^T mu = alpha * delta * eps,
 * h = G x~(s_t), likelihood variance sigma_L^2; likelihood_std 0 (the default) takes sigma_L =
 * sigma_u (the literal reading), for sigma_u = 1 and for another sigma_u, and an explicit
 * sigma_L != sigma_u is used as given. */
static void test_step_wiring(void)
{
    static const double cases[][2] = {{1.0, 0.0}, {0.5, 0.0}, {2.0, 0.0}, {0.5, 2.0}}; /* sigma_u, likelihood_std */
    size_t c;
    for (c = 0; c < sizeof cases / sizeof cases[0]; ++c) {
        icoac_config_t cfg = test_default_config();
        icoac_state_t state;
        icoac_output_t out;
        icoac_prior_t p = test_prior(0.1, 0.05, 0.3, 0.1, 0.5);
        icoac_input_t s1 = test_input(0.4, -0.2, 0.08, 0.6, 0);
        icoac_input_t s2 = test_input(0.41, -0.2, 0.25, 0.6, ICOAC_INPUT_TERMINAL);
        gauss_t prior, post, other;
        icoac_prior_t posterior;
        double hd[N], z = 0, eps, r, diff = 0;
        int i, j;
        int32_t slot;
        cfg.mode = ICOAC_MODE_RL;
        test_literal_reading(&cfg);
        cfg.actor.noise_std = (icoac_real_t)cases[c][0];
        cfg.actor.likelihood_std = (icoac_real_t)cases[c][1];
        TEST_ASSERT_EQUAL_INT(ICOAC_OK, icoac_config_check(&cfg));
        r = cases[c][1] != 0.0 ? cases[c][1] * cases[c][1] : cases[c][0] * cases[c][0];
        p.cov[0][2] = p.cov[2][0] = (icoac_real_t)0.1;
        TEST_ASSERT_EQUAL_INT(ICOAC_OK, icoac_init(&cfg, &state, &p, 2024u));
        for (i = 0; i < N; ++i) {
            prior.mean[i] = (double)p.mean[i];
            for (j = 0; j < N; ++j) {
                prior.cov[i][j] = (double)p.cov[i][j];
            }
            hd[i] = 10.0 * test_scale(i, (double)s1.s[i], 1);
            z += prior.mean[i] * test_scale(i, (double)s1.s[i], 1);
        }
        TEST_ASSERT_EQUAL_INT(ICOAC_OK, icoac_step(&state, &s1, &out));
        eps = (double)out.noise;
        TEST_ASSERT_TRUE(eps != 0.0);
        assert_close(out.z, z, 1e-5);
        assert_close(out.force, 10.0 * z + eps, 1e-4); /* no reflex at s1 */
        slot = icoac_priv_state_c(&state)->cov_slot;
        TEST_ASSERT_EQUAL_INT(ICOAC_OK, icoac_step(&state, &s2, &out));
        assert_close(out.td_error, -1.0, 0.0);
        /* the learning tick committed the staged covariance by flipping the slot */
        TEST_ASSERT_EQUAL_INT(slot ^ 1, icoac_priv_state_c(&state)->cov_slot);
        TEST_ASSERT_EQUAL_INT(ICOAC_OK, icoac_get_posterior(&state, &posterior));
        TEST_ASSERT_EQUAL_MEMORY(cov_of(&state), posterior.cov, sizeof posterior.cov);
        TEST_ASSERT_EQUAL_MEMORY(mean_of(&state), posterior.mean, sizeof posterior.mean);
        closed_form(&prior, hd, 0.5 * -1.0 * eps, r, &post);
        for (i = 0; i < N; ++i) {
            assert_close(mean_of(&state)[i], post.mean[i], REAL_IS_FLOAT ? 1e-5 : 1e-12);
            for (j = 0; j < N; ++j) {
                assert_close(cov_of(&state)[i][j], post.cov[i][j], REAL_IS_FLOAT ? 1e-5 : 1e-12);
            }
        }
        assert_close(out.cov_trace, post.cov[0][0] + post.cov[1][1] + post.cov[2][2] + post.cov[3][3],
                     REAL_IS_FLOAT ? 1e-5 : 1e-12);
        /* the variance matters here: with sigma_L^2 = 1 the step would differ unless r is 1 */
        closed_form(&prior, hd, 0.5 * -1.0 * eps, 1.0, &other);
        for (i = 0; i < N; ++i) {
            diff += fabs(other.cov[i][i] - post.cov[i][i]);
        }
        TEST_ASSERT_TRUE(r == 1.0 ? diff == 0.0 : diff > 1e-3);
    }
}


/* act_with_sample: at each reset the acting weights are mu + L n, L L^T = Sigma, n ~ N(0, I)
 * drawn from the controller's generator (method.md, Bayesian actor: acting with a sample). */
static void test_posterior_sample_per_trial(void)
{
    icoac_config_t cfg = test_default_config();
    icoac_state_t state;
    const icoac_priv_state_t *st = icoac_priv_state_c(&state);
    icoac_prior_t p = test_prior(0.1, -0.2, 0.3, 0.05, 0.0);
    double cov[N][N], lower[N][N];
    int i, j, k, trial;
    cfg.mode = ICOAC_MODE_RL;
    cfg.actor.act_with_sample = 1;
    /* a full SPD covariance */
    {
        const double m[N][N] = {{0.5, 0.1, 0.0, 0.05}, {0.1, 0.4, 0.02, 0.0},
                                {0.0, 0.02, 0.3, 0.01}, {0.05, 0.0, 0.01, 0.2}};
        for (i = 0; i < N; ++i) {
            for (j = 0; j < N; ++j) {
                p.cov[i][j] = (icoac_real_t)m[i][j];
                cov[i][j] = (double)p.cov[i][j];
            }
        }
    }
    /* Cholesky-Banachiewicz in double, independent of icoac_priv_cholesky */
    memset(lower, 0, sizeof lower);
    for (i = 0; i < N; ++i) {
        for (j = 0; j <= i; ++j) {
            double sum = cov[i][j];
            for (k = 0; k < j; ++k) {
                sum -= lower[i][k] * lower[j][k];
            }
            lower[i][j] = i == j ? sqrt(sum) : sum / lower[j][j];
        }
    }
    TEST_ASSERT_EQUAL_INT(ICOAC_OK, icoac_init(&cfg, &state, &p, 31u));
    /* the sample drawn by icoac_init is reproducible from the seed */
    {
        icoac_state_t fresh;
        TEST_ASSERT_EQUAL_INT(ICOAC_OK, icoac_init(&cfg, &fresh, &p, 31u));
        TEST_ASSERT_EQUAL_MEMORY(st->w_act, icoac_priv_state_c(&fresh)->w_act, sizeof st->w_act);
    }
    /* direct check: draw the normals from a copy of the generator, then reset */
    for (trial = 0; trial < 5; ++trial) {
        icoac_rng_t copy = st->rng;
        double n[N];
        for (i = 0; i < N; ++i) {
            n[i] = (double)icoac_rng_normal(&copy);
        }
        TEST_ASSERT_EQUAL_INT(ICOAC_OK, icoac_reset(&state));
        for (i = 0; i < N; ++i) {
            double expect = (double)mean_of(&state)[i];
            for (j = 0; j <= i; ++j) {
                expect += lower[i][j] * n[j];
            }
            assert_close(st->w_act[i], expect, REAL_IS_FLOAT ? 1e-6 : 1e-13);
        }
        TEST_ASSERT_TRUE(memcmp(st->w_act, st->w, sizeof st->w) != 0);
    }
}

void setUp(void) {}
void tearDown(void) {}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_update_matches_closed_form);
    RUN_TEST(test_zero_innovation_keeps_mean);
    RUN_TEST(test_forgetting_inflates_first);
    RUN_TEST(test_update_staged_into_spare);
    RUN_TEST(test_long_run_symmetric_pd);
    RUN_TEST(test_long_run_with_forgetting);
    RUN_TEST(test_step_wiring);
    RUN_TEST(test_posterior_sample_per_trial);
    return UNITY_END();
}
