/* SPDX-License-Identifier: Apache-2.0 */
/* Episodic search (ICOAC_MODE_SEARCH, method.md L4) through the public API, each trial a reset, a
 * few ticks and a terminal tick, with the trial's sampled weights read from the state:
 *   - the update after each batch against a reference written here in double: the elite (the
 *     n_e = max(1, round(rho K)) longest trials, ties to the earlier trial), its mean, its
 *     covariance about the new mean, the step a and the floor f * Sigma0_ii, and the fallback
 *     when that Sigma' is not positive definite (a rank-deficient elite, n_e <= 4, with a step
 *     near 1): the floor added to the whole diagonal;
 *   - a step of 1 with small elites: never a numeric fault, the fallback where Sigma' is
 *     singular, by hand and over many random updates;
 *   - the per-trial draw w = mu + L n through the Cholesky factor of Sigma_w, exactly and in
 *     distribution (sample mean and covariance over many resets);
 *   - Sigma_w symmetric positive definite over 1e6 random updates, steps up to 1;
 *   - init (Sigma0 = c * the prior covariance; a prior whose c Sigma_prior is not positive
 *     definite rejected with the state untouched), the tick's outputs, determinism for a seed,
 *     and learn = 0 (the no-learning control) learning nothing from the same samples. */
#include "test_common.h"

#include "icoac_priv.h"

#define N ICOAC_CARTPOLE_INPUTS /* the cart-pole task's inputs */
#define M ICOAC_MAX_INPUTS      /* the library's vectors: entries past N are 0 */
#define KMAX ICOAC_SEARCH_BATCH_MAX
#define GAIN 10.0

typedef struct {
    double mean[N];
    double cov[N][N];
} gauss_t;

static void step_ok(const icoac_config_t *cfg, icoac_state_t *state, const icoac_input_t *in, icoac_output_t *out)
{
    test_assert_config_in_force(cfg, state);
    memset(out, 0x7F, sizeof *out);
    TEST_ASSERT_EQUAL_INT(ICOAC_OK, icoac_step(state, in, out));
}

static const icoac_priv_state_t *priv(const icoac_state_t *state)
{
    return icoac_priv_state_c(state);
}

static void posterior_of(const icoac_state_t *state, gauss_t *g)
{
    icoac_prior_t post;
    int i, j;
    TEST_ASSERT_EQUAL_INT(ICOAC_OK, icoac_get_posterior(state, &post));
    for (i = 0; i < N; ++i) {
        g->mean[i] = (double)post.mean[i];
        for (j = 0; j < N; ++j) {
            g->cov[i][j] = (double)post.cov[i][j];
        }
    }
}

static void w_act_of(const icoac_state_t *state, double w[N])
{
    int i;
    for (i = 0; i < N; ++i) {
        w[i] = (double)priv(state)->w_act[i];
    }
}

static icoac_input_t random_input(test_rng_t *rng, uint32_t flags)
{
    return test_input(test_uniform(rng, -2.3, 2.3), test_uniform(rng, -3.0, 3.0), test_uniform(rng, -0.2, 0.2),
                      test_uniform(rng, -2.0, 2.0), flags);
}

static icoac_config_t search_config(int batch, double rho, double step, double floor_, double cov_scale)
{
    icoac_config_t cfg = test_default_config();
    cfg.mode = ICOAC_MODE_SEARCH;
    cfg.search.batch = batch;
    cfg.search.elite_fraction = (icoac_real_t)rho;
    cfg.search.step = (icoac_real_t)step;
    cfg.search.floor = (icoac_real_t)floor_;
    cfg.search.cov_scale = (icoac_real_t)cov_scale;
    TEST_ASSERT_EQUAL_INT(ICOAC_OK, icoac_config_check(&cfg));
    return cfg;
}

/* Lower Cholesky factor in double (Cholesky-Banachiewicz); 0 when not positive definite. */
static int cholesky(const double m[N][N], double lower[N][N])
{
    int i, j, k;
    memset(lower, 0, sizeof(double) * N * N);
    for (i = 0; i < N; ++i) {
        for (j = 0; j <= i; ++j) {
            double sum = m[i][j];
            for (k = 0; k < j; ++k) {
                sum -= lower[i][k] * lower[j][k];
            }
            if (i == j) {
                if (!(sum > 0.0)) {
                    return 0;
                }
                lower[i][i] = sqrt(sum);
            } else {
                lower[i][j] = sum / lower[j][j];
            }
        }
    }
    return 1;
}

/* Smallest pivot of the Cholesky factorisation of m in double, each relative to its diagonal
 * entry; the first one <= 0 when m is not positive definite (the factorisation stops there). */
static double min_relative_pivot(const double m[N][N])
{
    double lower[N][N] = {{0}}, smallest = 1.0;
    int i, j, k;
    for (j = 0; j < N; ++j) {
        double diag = m[j][j];
        for (k = 0; k < j; ++k) {
            diag -= lower[j][k] * lower[j][k];
        }
        smallest = diag / m[j][j] < smallest ? diag / m[j][j] : smallest;
        if (!(diag > 0.0)) {
            return smallest;
        }
        lower[j][j] = sqrt(diag);
        for (i = j + 1; i < N; ++i) {
            double sum = m[i][j];
            for (k = 0; k < j; ++k) {
                sum -= lower[i][k] * lower[j][k];
            }
            lower[i][j] = sum / lower[j][j];
        }
    }
    return smallest;
}

static double max_abs_mat(const double m[N][N])
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

/* Below this smallest relative pivot Sigma_w counts as singular up to rounding: its Cholesky
 * factor is not determined to the precision of a draw (a step-1 update can leave such a
 * Sigma_w, see assert_update_is_reference). */
#define SINGULAR_PIVOT (REAL_IS_FLOAT ? 1e-2 : 1e-8)

/* The draw of the coming reset, from a copy of the state's generator: mu + L n, L the double
 * Cholesky factor of the state's Sigma_w; returns a tolerance for comparing it with the
 * library's draw (rounding of L n and of mu). When Sigma_w is singular up to rounding, L is the
 * state's stored factor instead, checked here to be lower triangular with a positive diagonal
 * and to reproduce Sigma_w (L L^T = Sigma_w up to rounding); *singular (when not NULL) counts
 * those draws. */
static double expected_draw(const icoac_state_t *state, double w[N], int *singular)
{
    icoac_rng_t copy = priv(state)->rng;
    gauss_t g;
    double lower[N][N], n[N];
    int i, j, k;
    posterior_of(state, &g);
    if (min_relative_pivot(g.cov) > SINGULAR_PIVOT) {
        TEST_ASSERT_TRUE(cholesky(g.cov, lower));
    } else {
        for (i = 0; i < N; ++i) {
            for (j = 0; j < N; ++j) {
                lower[i][j] = (double)priv(state)->search.lower[i][j];
                TEST_ASSERT_TRUE(j <= i ? (j < i || lower[i][i] > 0.0) : lower[i][j] == 0.0);
            }
        }
        for (i = 0; i < N; ++i) {
            for (j = 0; j < N; ++j) {
                double sum = 0;
                for (k = 0; k < N; ++k) {
                    sum += lower[i][k] * lower[j][k];
                }
                assert_close(sum, g.cov[i][j], (REAL_IS_FLOAT ? 1e-5 : 1e-13) * max_abs_mat(g.cov));
            }
        }
        if (singular != NULL) {
            ++*singular;
        }
    }
    for (i = 0; i < N; ++i) {
        n[i] = (double)icoac_rng_normal(&copy);
    }
    for (i = 0; i < N; ++i) {
        w[i] = g.mean[i];
        for (j = 0; j <= i; ++j) {
            w[i] += lower[i][j] * n[j];
        }
    }
    return (REAL_IS_FLOAT ? 2e-6 : 1e-13) *
           (1.0 + fabs(g.mean[0]) + fabs(g.mean[1]) + fabs(g.mean[2]) + fabs(g.mean[3]) +
            sqrt(max_abs_mat(g.cov)) * (fabs(n[0]) + fabs(n[1]) + fabs(n[2]) + fabs(n[3])));
}

/* A trial: reset (which draws w), `ticks` non-terminal ticks, a terminal tick. */
static icoac_status_t run_trial(const icoac_config_t *cfg, icoac_state_t *state, test_rng_t *rng, int ticks)
{
    icoac_input_t in;
    icoac_output_t out;
    int t;
    TEST_ASSERT_EQUAL_INT(ICOAC_OK, icoac_reset(state));
    for (t = 0; t < ticks; ++t) {
        in = random_input(rng, 0);
        step_ok(cfg, state, &in, &out);
    }
    in = random_input(rng, ICOAC_INPUT_TERMINAL);
    return icoac_step(state, &in, &out);
}

/* The reference update of L4 (method.md, episodic search) in double. */
typedef struct {
    gauss_t next;     /* mu', and Sigma' = (1-a) Sigma + a Cov_elite with Sigma'_ii >= floor_i */
    gauss_t fallback; /* mu', and Sigma' + diag(floor): what a Sigma' not positive definite becomes */
    double pivot;     /* min_relative_pivot(Sigma'): <= 0 when it is not positive definite */
} reference_t;

static void reference_update(const icoac_config_t *cfg, const gauss_t *start, const double floor_[N],
                             double w[KMAX][N], const int ticks[KMAX], reference_t *ref, int elite_out[KMAX])
{
    const int batch = cfg->search.batch;
    const double a = (double)cfg->search.step;
    gauss_t *next = &ref->next;
    /* round(rho K), halves up, evaluated on the configured real values; at least 1 */
    int n_e = (int)(cfg->search.elite_fraction * (icoac_real_t)batch + ICOAC_R(0.5));
    int order[KMAX], taken[KMAX] = {0};
    double mean_e[N] = {0};
    int e, k, i, j;
    n_e = n_e < 1 ? 1 : n_e;
    /* the elite: longest first; a later trial must be strictly longer to go first */
    for (e = 0; e < n_e; ++e) {
        int best = -1;
        for (k = 0; k < batch; ++k) {
            if (!taken[k] && (best < 0 || ticks[k] > ticks[best])) {
                best = k;
            }
        }
        taken[best] = 1;
        order[e] = best;
        elite_out[e] = best;
    }
    for (e = n_e; e < KMAX; ++e) {
        elite_out[e] = -1;
    }
    for (e = 0; e < n_e; ++e) {
        for (i = 0; i < N; ++i) {
            mean_e[i] += w[order[e]][i] / n_e;
        }
    }
    for (i = 0; i < N; ++i) {
        next->mean[i] = (1.0 - a) * start->mean[i] + a * mean_e[i];
    }
    for (i = 0; i < N; ++i) {
        for (j = 0; j < N; ++j) {
            double c = 0;
            for (e = 0; e < n_e; ++e) {
                c += (w[order[e]][i] - next->mean[i]) * (w[order[e]][j] - next->mean[j]);
            }
            next->cov[i][j] = (1.0 - a) * start->cov[i][j] + a * c / n_e;
        }
        if (next->cov[i][i] < floor_[i]) {
            next->cov[i][i] = floor_[i];
        }
    }
    ref->fallback = *next;
    for (i = 0; i < N; ++i) {
        ref->fallback.cov[i][i] += floor_[i];
    }
    ref->pivot = min_relative_pivot(next->cov);
}

static int gauss_within(const gauss_t *got, const gauss_t *want, double mean_tol, double cov_tol)
{
    int i, j;
    for (i = 0; i < N; ++i) {
        if (!(fabs(got->mean[i] - want->mean[i]) <= mean_tol)) {
            return 0;
        }
        for (j = 0; j < N; ++j) {
            if (!(fabs(got->cov[i][j] - want->cov[i][j]) <= cov_tol)) {
                return 0;
            }
        }
    }
    return 1;
}

static void assert_gauss_close(const gauss_t *got, const gauss_t *want, double mean_tol, double cov_tol,
                               const char *what, int n)
{
    int i, j;
    for (i = 0; i < N; ++i) {
        if (!(fabs(got->mean[i] - want->mean[i]) <= mean_tol)) {
            TEST_PRINTF("%s %d: mean[%d] = %g, expected %g (tol %g)", what, n, i, got->mean[i],
                        want->mean[i], mean_tol);
            TEST_FAIL();
        }
        for (j = 0; j < N; ++j) {
            if (!(fabs(got->cov[i][j] - want->cov[i][j]) <= cov_tol)) {
                TEST_PRINTF("%s %d: cov[%d][%d] = %g, expected %g (tol %g)", what, n, i, j,
                            got->cov[i][j], want->cov[i][j], cov_tol);
                TEST_FAIL();
            }
        }
    }
}

/* The library's update `now` against the reference: Sigma' when it is positive definite with a
 * margin (every relative pivot above `band`, and above the library's 1e-4 cut-off); in the band below, where Sigma' is singular up to
 * rounding (in exact arithmetic it is positive semidefinite) and the library's own Cholesky
 * factorisation in icoac_real_t passes or fails by rounding, Sigma' or the fallback
 * Sigma' + diag(floor). Returns 1 when `now` is the fallback. */
static int assert_update_is_reference(const gauss_t *now, const reference_t *ref, double band, double mean_tol,
                                      double cov_tol, const char *what, int n)
{
    /* the library also treats Sigma' as singular when a relative pivot is below 1e-4 */
    band = band > 1.01e-4 ? band : 1.01e-4;
    if (ref->pivot > band || gauss_within(now, &ref->next, mean_tol, cov_tol)) {
        assert_gauss_close(now, &ref->next, mean_tol, cov_tol, what, n);
        return 0;
    }
    assert_gauss_close(now, &ref->fallback, mean_tol, cov_tol, what, n);
    return 1;
}

/* The band of assert_update_is_reference: the rounding of Sigma' in icoac_real_t relative to
 * its smallest diagonal entry, with the cancellation in w - mu' when |w| is large next to the
 * spread. (Over the random updates here the library fell back at relative pivots at most about
 * 1/70 of it.) */
static double singular_band(const reference_t *ref, double wmax)
{
    double smallest = ref->next.cov[0][0];
    int i;
    for (i = 1; i < N; ++i) {
        smallest = ref->next.cov[i][i] < smallest ? ref->next.cov[i][i] : smallest;
    }
    return (REAL_IS_FLOAT ? 1e-4 : 1e-10) * (1.0 + wmax / sqrt(smallest));
}

/* Random configurations (the floor often active, steps up to 1), several batches each: between
 * updates mu_w and Sigma_w stay; each trial's w is mu + L n; each update is the reference's,
 * with its fallback where Sigma' is singular. */
static void test_update_matches_reference(void)
{
    static const double rhos[] = {1e-3, 0.1, 0.25, 0.3, 0.5, 0.6, 0.75, 1.0};
    test_rng_t rng = {0x5EA5Cu};
    int n, updates = 0, floored = 0, fallbacks = 0, singular_draws = 0;
    for (n = 0; n < 120; ++n) {
        const int batch = 1 + (int)test_uniform(&rng, 0, KMAX);
        const double rho = rhos[(int)test_uniform(&rng, 0, 8)];
        /* a = 1 in every 5th configuration, with any elite: a rank-deficient one (n_e <= 4)
         * makes Sigma' singular unless the floor repairs it */
        const double step = n % 5 == 4 ? 1.0 : test_uniform(&rng, 0.05, 0.95);
        const double floor_ = n % 3 == 0 ? 1.5 : test_uniform(&rng, 1e-3, 0.5);
        const double cov_scale = 1.0 + (n % 4) * test_uniform(&rng, 0.5, 4.0);
        icoac_config_t cfg = search_config(batch, rho, step, floor_, cov_scale);
        icoac_prior_t p = test_random_prior(&rng, 1.0, test_uniform(&rng, 0.05, 1.0));
        icoac_state_t state;
        double floor_d[N];
        int round, i, j;
        TEST_ASSERT_EQUAL_INT(ICOAC_OK, icoac_init(&cfg, &state, &p, 1000u + (uint64_t)n));
        for (i = 0; i < N; ++i) {
            /* Sigma0 = c * the prior covariance; the floor f * Sigma0_ii */
            for (j = 0; j < N; ++j) {
                TEST_ASSERT_TRUE(icoac_priv_cov_c(priv(&state))[i][j] == p.cov[i][j] * cfg.search.cov_scale);
            }
            floor_d[i] = (double)cfg.search.floor * (double)(p.cov[i][i] * cfg.search.cov_scale);
        }
        for (round = 0; round < 4; ++round) {
            double w[KMAX][N];
            int ticks[KMAX], elite[KMAX];
            gauss_t start, now;
            reference_t want;
            int k;
            posterior_of(&state, &start);
            for (k = 0; k < cfg.search.batch; ++k) {
                double drawn[N], tol;
                /* few distinct lengths: many ties */
                ticks[k] = (int)test_uniform(&rng, 0, 5);
                tol = expected_draw(&state, drawn, &singular_draws);
                TEST_ASSERT_EQUAL_INT(ICOAC_OK, icoac_reset(&state));
                w_act_of(&state, w[k]);
                for (i = 0; i < N; ++i) {
                    assert_close(w[k][i], drawn[i], tol);
                }
                {
                    icoac_input_t in;
                    icoac_output_t out;
                    int t;
                    for (t = 0; t < ticks[k]; ++t) {
                        in = random_input(&rng, 0);
                        step_ok(&cfg, &state, &in, &out);
                    }
                    in = random_input(&rng, ICOAC_INPUT_TERMINAL);
                    step_ok(&cfg, &state, &in, &out);
                }
                posterior_of(&state, &now);
                if (k + 1 < cfg.search.batch) {
                    TEST_ASSERT_EQUAL_MEMORY(&start, &now, sizeof now);
                    TEST_ASSERT_EQUAL_INT(k + 1, priv(&state)->search.count);
                }
            }
            TEST_ASSERT_EQUAL_INT(0, priv(&state)->search.count);
            reference_update(&cfg, &start, floor_d, w, ticks, &want, elite);
            {
                const double scale = 1.0 + max_abs_mat(start.cov) + max_abs_mat(want.fallback.cov);
                double wmax = 1.0;
                for (k = 0; k < cfg.search.batch; ++k) {
                    for (i = 0; i < N; ++i) {
                        wmax = fabs(w[k][i]) > wmax ? fabs(w[k][i]) : wmax;
                    }
                }
                fallbacks += assert_update_is_reference(&now, &want, singular_band(&want, wmax),
                                                        (REAL_IS_FLOAT ? 2e-6 : 1e-13) * wmax,
                                                        (REAL_IS_FLOAT ? 4e-6 : 1e-13) * scale * wmax * wmax,
                                                        "search update", n);
            }
            for (i = 0; i < N; ++i) {
                TEST_ASSERT_TRUE(now.cov[i][i] >= floor_d[i] * (1.0 - 4.0 * REAL_EPS));
                floored += now.cov[i][i] == (double)priv(&state)->search.floor[i];
                for (j = 0; j < N; ++j) {
                    TEST_ASSERT_TRUE(icoac_priv_cov_c(priv(&state))[i][j] == icoac_priv_cov_c(priv(&state))[j][i]);
                }
            }
            ++updates;
        }
    }
    TEST_ASSERT_EQUAL_INT(480, updates);
    TEST_ASSERT_TRUE(floored > 100); /* the floor was exercised */
    TEST_PRINTF("%d of %d updates fell back to Sigma' + diag(floor); %d draws from a singular Sigma_w",
                fallbacks, updates, singular_draws);
    TEST_ASSERT_TRUE(fallbacks > 0); /* and the fallback (test_step_one_small_elites: many of them) */
}

/* `ticks` non-terminal ticks and a terminal one, in the trial drawn at the last reset. */
static icoac_status_t finish_trial(const icoac_config_t *cfg, icoac_state_t *state, test_rng_t *rng, int ticks)
{
    icoac_input_t in;
    icoac_output_t out;
    int t;
    for (t = 0; t < ticks; ++t) {
        in = random_input(rng, 0);
        step_ok(cfg, state, &in, &out);
    }
    in = random_input(rng, ICOAC_INPUT_TERMINAL);
    return icoac_step(state, &in, &out);
}

/* Hand-made batches: the elite is chosen by length, ties to the earlier trial; its size is
 * max(1, round(rho K)). With mu = 0 and a = 1/2, mu' = mean_elite / 2: checked against the
 * expected elite, and (ties) shown to differ from the other way of breaking them. */
static void test_elite_choice(void)
{
    typedef struct {
        int batch;
        double rho;
        int ticks[6];
        int elite[6]; /* trial indices, -1 past the elite */
        int other[6]; /* the elite with the tie broken the other way, or {-1} */
    } elite_case_t;
    static const elite_case_t cases[] = {
        {4, 0.25, {5, 9, 9, 2}, {1, -1}, {2, -1}},
        {4, 0.5, {5, 9, 9, 2}, {1, 2, -1}, {-1}},
        {4, 0.75, {5, 9, 9, 2}, {1, 2, 0, -1}, {-1}},
        {4, 1.0, {5, 9, 9, 2}, {1, 2, 0, 3, -1}, {-1}},
        {5, 0.5, {3, 3, 3, 3, 3}, {0, 1, 2, -1}, {2, 3, 4, -1}}, /* round(2.5) = 3; all tied */
        {6, 1e-3, {0, 1, 2, 3, 4, 4}, {4, -1}, {5, -1}},          /* at least one */
        {3, 0.5, {7, 0, 7}, {0, 2, -1}, {-1}},                    /* round(1.5) = 2 */
        {6, 0.3, {1, 6, 2, 6, 6, 0}, {1, 3, -1}, {3, 4, -1}},     /* round(1.8) = 2 */
        {2, 0.5, {0, 0}, {0, -1}, {1, -1}},                       /* empty trials tie too */
    };
    size_t c;
    for (c = 0; c < sizeof cases / sizeof cases[0]; ++c) {
        const elite_case_t *ec = &cases[c];
        icoac_config_t cfg = search_config(ec->batch, ec->rho, 0.5, 1e-3, 1.0);
        icoac_state_t state;
        test_rng_t rng = {c + 1u};
        double w[KMAX][N], want[N] = {0}, other[N] = {0}, diff = 0;
        gauss_t now;
        int k, i, n_e = 0, n_o = 0;
        TEST_ASSERT_EQUAL_INT(ICOAC_OK, icoac_init(&cfg, &state, NULL, 50u + c));
        for (k = 0; k < ec->batch; ++k) {
            TEST_ASSERT_EQUAL_INT(ICOAC_OK, icoac_reset(&state));
            w_act_of(&state, w[k]);
            TEST_ASSERT_EQUAL_INT(ICOAC_OK, finish_trial(&cfg, &state, &rng, ec->ticks[k]));
        }
        while (n_e < 6 && ec->elite[n_e] >= 0) {
            ++n_e;
        }
        while (n_o < 6 && ec->other[n_o] >= 0) {
            ++n_o;
        }
        for (k = 0; k < n_e; ++k) {
            for (i = 0; i < N; ++i) {
                want[i] += 0.5 * w[ec->elite[k]][i] / n_e;
            }
        }
        for (k = 0; k < n_o; ++k) {
            for (i = 0; i < N; ++i) {
                other[i] += 0.5 * w[ec->other[k]][i] / n_o;
            }
        }
        posterior_of(&state, &now);
        for (i = 0; i < N; ++i) {
            assert_close(now.mean[i], want[i], REAL_IS_FLOAT ? 1e-6 : 1e-14);
            diff += fabs(want[i] - other[i]);
        }
        if (n_o > 0) {
            TEST_ASSERT_TRUE(diff > 1e-2); /* the other tie-break would have been seen */
        }
    }
}

/* Sigma_w after an update, checked in double: exactly symmetric, finite, each diagonal entry at
 * least its floor; positive definite for the library's own Cholesky factorisation, whose factor
 * is stored (lower triangular, positive diagonal, L L^T = Sigma_w up to rounding); and, with
 * `margin` = 0, positive definite in double, else positive semidefinite up to rounding
 * (Sigma_w + margin max|Sigma_w| I positive definite in double). */
static void assert_sigma_spd(const icoac_state_t *state, double margin, const char *what, int n)
{
    const icoac_priv_state_t *st = priv(state);
    const icoac_real_t(*cov)[M] = icoac_priv_cov_c(st);
    icoac_real_t lower_r[M][M] = {{0}};
    double m[N][N], l[N][N];
    int i, j, q;
    for (i = 0; i < N; ++i) {
        for (j = 0; j < N; ++j) {
            m[i][j] = (double)cov[i][j];
            if (!isfinite(m[i][j]) || cov[i][j] != cov[j][i] || (i == j && !(cov[i][i] >= st->search.floor[i]))) {
                TEST_PRINTF("%s %d: cov[%d][%d] = %g (floor %g), not finite, symmetric or above the floor", what,
                            n, i, j, m[i][j], (double)st->search.floor[i]);
                TEST_FAIL();
            }
        }
    }
    if (!icoac_priv_cholesky(cov, lower_r, ICOAC_CARTPOLE_INPUTS)) {
        TEST_PRINTF("%s %d: cov not positive definite", what, n);
        TEST_FAIL();
    }
    for (i = 0; i < N; ++i) {
        TEST_ASSERT_TRUE(st->search.lower[i][i] > 0);
        for (j = 0; j < N; ++j) {
            double sum = 0;
            for (q = 0; q < N; ++q) {
                sum += (double)st->search.lower[i][q] * (double)st->search.lower[j][q];
            }
            assert_close(sum, m[i][j], (REAL_IS_FLOAT ? 1e-5 : 1e-13) * max_abs_mat(m));
            TEST_ASSERT_TRUE(j <= i || st->search.lower[i][j] == 0);
        }
    }
    for (i = 0; i < N; ++i) {
        m[i][i] += margin * max_abs_mat(m);
    }
    if (!cholesky(m, l)) {
        TEST_PRINTF("%s %d: cov not positive definite in double (margin %g)", what, n, margin);
        TEST_FAIL();
    }
}

/* Rounding margin of assert_sigma_spd for a Sigma_w that may be singular up to rounding. */
#define PSD_MARGIN (REAL_IS_FLOAT ? 1e-5 : 1e-13)

/* One trial with the given acting weights (written over the reset's draw) and length. */
static void trial_with(const icoac_config_t *cfg, icoac_state_t *state, const double w[N], int ticks)
{
    test_rng_t rng = {(uint64_t)ticks + 1u};
    int i;
    TEST_ASSERT_EQUAL_INT(ICOAC_OK, icoac_reset(state));
    for (i = 0; i < N; ++i) {
        icoac_priv_state(state)->w_act[i] = (icoac_real_t)w[i];
    }
    TEST_ASSERT_EQUAL_INT(ICOAC_OK, finish_trial(cfg, state, &rng, ticks));
}

/* A step of 1 with a rank-deficient elite (L4): Sigma' = Cov_elite (floored) is singular
 * unless the diagonal floor repairs it; then the floor is added to the whole diagonal instead
 * of failing with ICOAC_ERR_NUMERIC (what it did before).
 *   By hand: K = 2 = n_e, mu = 0, Sigma0 = I, floor 0.1; the elite +-d gives mu' = 0 and
 *   Cov_elite = d d^T. d = (1, 1, 1, 1) and (1, 1, 0.1, 0.1): two or more entries above the
 *   floor, Sigma' singular (an exact zero pivot), the fallback d d^T (floored) + 0.1 I;
 *   d = (1, 0.1, 0.1, 0.1): one entry above the floor, the floored Sigma' is positive definite
 *   and kept.
 *   Random: K = 4, rho = 0.5 (n_e = 2), f = 0.1; K = 8, rho = 0.25 (n_e = 2), f = 1, c = 64 (the
 *   default search group but a = 1); K = 3, rho = 1; K = 16, rho = 0.25 (n_e = 4): 20000
 *   updates each from random priors, every terminal tick OK, every update the reference's
 *   (assert_update_is_reference: Sigma' where it is positive definite, the fallback where the
 *   library's Cholesky factorisation of it fails), Sigma_w positive definite after each, the
 *   fallback taken often and never where Sigma' is clearly positive definite. */
static void test_step_one_small_elites(void)
{
    static const double hand[3][N] = {{1, 1, 1, 1}, {1, 1, 0.1, 0.1}, {1, 0.1, 0.1, 0.1}};
    typedef struct {
        int batch;
        double rho, floor_, cov_scale;
    } step_one_case_t;
    static const step_one_case_t cases[] = {{4, 0.5, 0.1, 1.0}, {8, 0.25, 1.0, 64.0}, {3, 1.0, 0.01, 1.0},
                                            {16, 0.25, 0.1, 1.0}};
    size_t h, c;
    for (h = 0; h < 3; ++h) {
        const icoac_config_t cfg = search_config(2, 1.0, 1.0, 0.1, 1.0);
        icoac_state_t state;
        double plus[N], minus[N];
        gauss_t now;
        int i, j, above = 0;
        TEST_ASSERT_EQUAL_INT(ICOAC_OK, icoac_init(&cfg, &state, NULL, 5u + h));
        for (i = 0; i < N; ++i) {
            plus[i] = (double)(icoac_real_t)hand[h][i];
            minus[i] = -plus[i];
            above += plus[i] * plus[i] > 0.1;
        }
        trial_with(&cfg, &state, plus, 3);
        trial_with(&cfg, &state, minus, 2); /* the update: OK, no numeric fault */
        TEST_ASSERT_EQUAL_INT(0, priv(&state)->search.count);
        posterior_of(&state, &now);
        for (i = 0; i < N; ++i) {
            TEST_ASSERT_TRUE(now.mean[i] == 0.0);
            for (j = 0; j < N; ++j) {
                double want = plus[i] * plus[j];
                if (i == j) {
                    want = want < 0.1 ? (double)(icoac_real_t)0.1 : want;
                    want += above >= 2 ? (double)(icoac_real_t)0.1 : 0.0; /* the fallback */
                }
                assert_close(now.cov[i][j], want, REAL_IS_FLOAT ? 1e-6 : 1e-15);
            }
        }
        assert_sigma_spd(&state, 0.0, "by hand", (int)h);
        {
            /* the next draws go through the new factor */
            double drawn[N], w[N], tol = expected_draw(&state, drawn, NULL);
            TEST_ASSERT_EQUAL_INT(ICOAC_OK, icoac_reset(&state));
            w_act_of(&state, w);
            for (i = 0; i < N; ++i) {
                assert_close(w[i], drawn[i], tol);
            }
        }
    }
    for (c = 0; c < sizeof cases / sizeof cases[0]; ++c) {
        const step_one_case_t *sc = &cases[c];
        const icoac_config_t cfg = search_config(sc->batch, sc->rho, 1.0, sc->floor_, sc->cov_scale);
        test_rng_t rng = {0x57E91u + c};
        icoac_state_t state;
        double floor_d[N];
        int u, k, i, fallbacks = 0, clear = 0;
        const int updates = TEST_ITERATIONS(20000, 1000); /* fewer on an emulated core (QEMU is slow) */
        for (u = 0; u < updates; ++u) {
            double w[KMAX][N], wmax = 1.0;
            int ticks[KMAX], elite[KMAX];
            gauss_t start, now;
            reference_t want;
            if (u % 250 == 0) {
                /* a fresh prior now and then: mu_w random-walks at a = 1 */
                icoac_prior_t p = test_random_prior(&rng, 1.0, test_uniform(&rng, 0.05, 1.0));
                TEST_ASSERT_EQUAL_INT(ICOAC_OK, icoac_init(&cfg, &state, u % 500 ? &p : NULL, 9u + (uint64_t)u));
                for (i = 0; i < N; ++i) {
                    floor_d[i] = (double)priv(&state)->search.floor[i];
                }
            }
            posterior_of(&state, &start);
            for (k = 0; k < sc->batch; ++k) {
                ticks[k] = (int)(test_rng_u64(&rng) % 4u);
                TEST_ASSERT_EQUAL_INT(ICOAC_OK, icoac_reset(&state));
                w_act_of(&state, w[k]);
                if (finish_trial(&cfg, &state, &rng, ticks[k]) != ICOAC_OK) {
                    TEST_PRINTF("case %u, update %d: terminal tick not OK", (unsigned)c, u);
                    TEST_FAIL();
                }
                for (i = 0; i < N; ++i) {
                    wmax = fabs(w[k][i]) > wmax ? fabs(w[k][i]) : wmax;
                }
            }
            posterior_of(&state, &now);
            reference_update(&cfg, &start, floor_d, w, ticks, &want, elite);
            {
                const double scale = 1.0 + max_abs_mat(start.cov) + max_abs_mat(want.fallback.cov);
                const double band = singular_band(&want, wmax);
                clear += want.pivot > band;
                fallbacks += assert_update_is_reference(&now, &want, band, (REAL_IS_FLOAT ? 2e-6 : 1e-13) * wmax,
                                                        (REAL_IS_FLOAT ? 4e-6 : 1e-13) * scale * wmax * wmax,
                                                        "step 1 update", u);
            }
            assert_sigma_spd(&state, PSD_MARGIN, "step 1 update", u);
        }
        TEST_PRINTF("K %d, rho %g: %d of %d updates fell back, %d with Sigma' clearly positive definite",
                    sc->batch, sc->rho, fallbacks, updates, clear);
        TEST_ASSERT_TRUE(fallbacks > updates / 50);
        TEST_ASSERT_TRUE(clear > updates / 2);
    }
}

/* A prior the check accepts (and icoac_init in the other modes) whose Sigma0 = c Sigma_prior is
 * not positive definite for this c (a nearly singular prior, its Cholesky pivot lost to the
 * rounding of c Sigma): search-mode icoac_init rejects it with ICOAC_ERR_BAD_PRIOR before it
 * clears the state, so the state is untouched, byte for byte, whether it was never initialised
 * (a fill) or held a learning controller; with c = 1 the same prior is accepted. */
static void test_rejected_prior_leaves_state(void)
{
    static const double scales[] = {3.0, 1.1, 7.0, 1000.0};
    test_rng_t rng = {0xBAD9u};
    int tries, found = 0;
    for (tries = 0; tries < 100000 && found < 8; ++tries) {
        icoac_prior_t p;
        double v[3][N];
        const double eps = pow(10.0, -test_uniform(&rng, REAL_IS_FLOAT ? 5.0 : 12.0, REAL_IS_FLOAT ? 9.0 : 17.0));
        size_t c;
        int i, j, r;
        memset(&p, 0, sizeof p);
        /* rank 3 plus eps I */
        for (r = 0; r < 3; ++r) {
            for (i = 0; i < N; ++i) {
                v[r][i] = test_uniform(&rng, -1.0, 1.0);
            }
        }
        for (i = 0; i < N; ++i) {
            p.mean[i] = (icoac_real_t)test_uniform(&rng, -1.0, 1.0);
            for (j = 0; j <= i; ++j) {
                double sum = i == j ? eps : 0.0;
                for (r = 0; r < 3; ++r) {
                    sum += v[r][i] * v[r][j];
                }
                p.cov[i][j] = p.cov[j][i] = (icoac_real_t)sum;
            }
        }
        if (icoac_prior_check(&p, ICOAC_CARTPOLE_INPUTS) != ICOAC_OK) {
            continue;
        }
        for (c = 0; c < sizeof scales / sizeof scales[0]; ++c) {
            icoac_config_t cfg = search_config(4, 0.5, 0.5, 0.1, scales[c]);
            icoac_real_t scaled[M][M] = {{0}}, lower[M][M] = {{0}};
            icoac_state_t state, sentinel;
            int mode;
            for (i = 0; i < N; ++i) {
                for (j = 0; j < N; ++j) {
                    scaled[i][j] = p.cov[i][j] * cfg.search.cov_scale; /* Sigma0 as icoac_init forms it */
                }
            }
            if (icoac_priv_cholesky(ICOAC_PRIV_CONST_MAT(scaled), lower, ICOAC_CARTPOLE_INPUTS)) {
                continue;
            }
            ++found;
            /* a never-initialised state */
            memset(&state, 0xA5, sizeof state);
            memset(&sentinel, 0xA5, sizeof sentinel);
            TEST_ASSERT_EQUAL_INT(ICOAC_ERR_BAD_PRIOR, icoac_init(&cfg, &state, &p, 3u));
            TEST_ASSERT_EQUAL_MEMORY(&sentinel, &state, sizeof state);
            /* a running controller: a search one with a trial recorded */
            {
                icoac_config_t running = search_config(4, 0.5, 0.5, 0.1, 2.0);
                test_rng_t in = {7u};
                TEST_ASSERT_EQUAL_INT(ICOAC_OK, icoac_init(&running, &state, NULL, 4u));
                TEST_ASSERT_EQUAL_INT(ICOAC_OK, run_trial(&running, &state, &in, 5));
                sentinel = state;
                TEST_ASSERT_EQUAL_INT(ICOAC_ERR_BAD_PRIOR, icoac_init(&cfg, &state, &p, 3u));
                TEST_ASSERT_EQUAL_MEMORY(&sentinel, &state, sizeof state);
                TEST_ASSERT_EQUAL_INT(ICOAC_OK, run_trial(&running, &state, &in, 5)); /* and it still runs */
            }
            /* the prior itself is accepted: by the other modes, and by search with c = 1 */
            for (mode = ICOAC_MODE_ICO; mode <= ICOAC_MODE_RL; ++mode) {
                icoac_config_t other = cfg;
                other.mode = mode;
                TEST_ASSERT_EQUAL_INT(ICOAC_OK, icoac_init(&other, &state, &p, 3u));
            }
            cfg.search.cov_scale = 1;
            TEST_ASSERT_EQUAL_INT(ICOAC_OK, icoac_init(&cfg, &state, &p, 3u));
        }
    }
    TEST_ASSERT_TRUE(found >= 8);
}

/* Over many resets, the trials' w have mean mu_w and covariance Sigma_w (sample statistics
 * within 5 standard errors), for Sigma0 = c * a correlated prior and again for the Sigma_w of
 * an update; every draw is mu + L n exactly (the first one too, drawn by icoac_init). */
static void check_sample_statistics(const icoac_config_t *cfg, icoac_state_t *state, int n_samples)
{
    gauss_t g;
    double sum[N] = {0}, sum2[N][N] = {{0}};
    int n, i, j;
    test_assert_config_in_force(cfg, state);
    posterior_of(state, &g);
    for (n = 0; n < n_samples; ++n) {
        double w[N], drawn[N], tol = 0;
        if (n % 997 == 0) {
            tol = expected_draw(state, drawn, NULL);
        }
        TEST_ASSERT_EQUAL_INT(ICOAC_OK, icoac_reset(state));
        w_act_of(state, w);
        if (n % 997 == 0) {
            for (i = 0; i < N; ++i) {
                assert_close(w[i], drawn[i], tol);
            }
        }
        for (i = 0; i < N; ++i) {
            sum[i] += w[i] - g.mean[i];
            for (j = 0; j < N; ++j) {
                sum2[i][j] += (w[i] - g.mean[i]) * (w[j] - g.mean[j]);
            }
        }
    }
    for (i = 0; i < N; ++i) {
        const double mean_dev = sum[i] / n_samples;
        assert_close(mean_dev, 0.0, 5.0 * sqrt(g.cov[i][i] / n_samples));
        for (j = 0; j < N; ++j) {
            /* about the known mean: var of (w_i - mu_i)(w_j - mu_j) is S_ii S_jj + S_ij^2 */
            const double se = sqrt((g.cov[i][i] * g.cov[j][j] + g.cov[i][j] * g.cov[i][j]) / n_samples);
            assert_close(sum2[i][j] / n_samples, g.cov[i][j], 5.0 * se);
        }
    }
}

/* Draws of each statistics check: fewer on an emulated core (QEMU is slow); the tolerances
 * follow the count. */
#define SAMPLES TEST_ITERATIONS(200000, 20000)

static void test_samples_through_cholesky(void)
{
    test_rng_t rng = {0xC401u};
    icoac_config_t cfg = search_config(8, 0.5, 0.6, 1e-3, 3.0);
    icoac_config_t frozen;
    icoac_state_t state;
    icoac_prior_t p = test_random_prior(&rng, 1.0, 0.5);
    gauss_t g;
    int i, j, k;
    TEST_ASSERT_EQUAL_INT(ICOAC_OK, icoac_init(&cfg, &state, &p, 7u));
    posterior_of(&state, &g);
    for (i = 0; i < N; ++i) {
        TEST_ASSERT_TRUE(g.mean[i] == (double)p.mean[i]);
        for (j = 0; j < N; ++j) {
            TEST_ASSERT_TRUE(g.cov[i][j] == (double)(p.cov[i][j] * cfg.search.cov_scale)); /* Sigma0 = c Sigma_prior */
        }
    }
    /* the first trial's w, drawn by icoac_init: four normals from the seeded generator */
    {
        icoac_rng_t gen;
        double lower[N][N], n[N], w[N];
        icoac_rng_seed(&gen, 7u, 0x1C0ACu);
        for (i = 0; i < N; ++i) {
            n[i] = (double)icoac_rng_normal(&gen);
        }
        /* the generator is where the four draws leave it: the stream is the controller's */
        TEST_ASSERT_TRUE(gen.state == priv(&state)->rng.state && gen.increment == priv(&state)->rng.increment &&
                         gen.has_spare == priv(&state)->rng.has_spare);
        TEST_ASSERT_TRUE(cholesky(g.cov, lower));
        w_act_of(&state, w);
        for (i = 0; i < N; ++i) {
            double want = g.mean[i];
            for (j = 0; j <= i; ++j) {
                want += lower[i][j] * n[j];
            }
            assert_close(w[i], want, (REAL_IS_FLOAT ? 2e-6 : 1e-13) * (1.0 + fabs(want)));
        }
    }
    check_sample_statistics(&cfg, &state, SAMPLES);
    /* one update (a correlated elite covariance), then the same statistics without learning */
    for (k = 0; k < cfg.search.batch; ++k) {
        TEST_ASSERT_EQUAL_INT(ICOAC_OK, run_trial(&cfg, &state, &rng, k % 5));
    }
    frozen = cfg;
    frozen.learn = 0;
    TEST_ASSERT_EQUAL_INT(ICOAC_OK, icoac_retune(&state, &frozen));
    posterior_of(&state, &g);
    TEST_ASSERT_TRUE(fabs(g.cov[0][1] - (double)p.cov[0][1] * 3.0) > 1e-3); /* Sigma_w moved */
    check_sample_statistics(&frozen, &state, SAMPLES);
}

/* Sigma_w stays exactly symmetric and positive definite (and above its floor) over 1e6 updates
 * with random returns, for several settings of (K, rho, a, f, c), the defaults (old and new)
 * among them, steps up to 1; every tick OK; the stored factor is that of Sigma_w. A step near 1
 * with an elite of 2 to 4 trials makes Sigma' singular (a = 1 at once; a >= 0.7 lets its
 * smallest eigenvalue decay off the axes, where the diagonal floor does not reach): the
 * fallback (the floor added to the diagonal) keeps it positive definite where it used to fail
 * with ICOAC_ERR_NUMERIC. Those settings (`singular`) can also keep a Sigma' that is singular
 * only up to rounding, which the library's Cholesky factorisation passes: positive semidefinite
 * up to rounding in double there, positive definite in double for the others. */
static void test_spd_over_many_updates(void)
{
    typedef struct {
        int batch;
        double rho, step, floor_, cov_scale;
        int updates, singular;
    } spd_case_t;
    static const spd_case_t cases[] = {
        {1, 1.0, 0.5, 0.1, 1.0, 150000, 0},      {2, 0.5, 0.95, 1e-3, 1.0, 150000, 0},
        {2, 0.5, 0.05, 1e-2, 10.0, 100000, 0},   {3, 0.3, 0.7, 1e-6, 1.0, 100000, 0},
        {4, 0.5, 0.5, 0.1, 4.0, 80000, 0},       {16, 0.5, 0.5, 1e-4, 1.0, 20000, 0},
        {2, 1.0, 0.3, 1000.0, 1000.0, 50000, 0}, {4, 0.5, 0.5, 0.1, 1.0, 50000, 0}, /* the old defaults */
        {8, 0.25, 0.5, 1.0, 64.0, 50000, 0},     /* the defaults */
        {4, 0.5, 1.0, 0.1, 1.0, 100000, 1},      {8, 0.25, 1.0, 1.0, 64.0, 50000, 1},
        {3, 1.0, 0.9, 1e-2, 1.0, 50000, 1},      {16, 0.25, 0.8, 1e-3, 1.0, 20000, 1},
        {2, 1.0, 1.0, 1e-6, 1.0, 30000, 1},
    };
    size_t c;
    long total = 0;
    for (c = 0; c < sizeof cases / sizeof cases[0]; ++c) {
        const spd_case_t *sc = &cases[c];
        icoac_config_t cfg = search_config(sc->batch, sc->rho, sc->step, sc->floor_, sc->cov_scale);
        test_rng_t rng = {0x5BDu + c};
        icoac_prior_t p = test_random_prior(&rng, 1.0, 0.3);
        icoac_state_t state;
        const icoac_priv_state_t *st = priv(&state);
        int u, k, i, j;
        TEST_ASSERT_EQUAL_INT(ICOAC_OK, icoac_init(&cfg, &state, &p, 3u + c));
        /* 1/50 of the updates on an emulated core (QEMU is slow) */
        for (u = 0; u < TEST_ITERATIONS(sc->updates, sc->updates / 50); ++u) {
            const icoac_real_t(*cov)[M];
            icoac_real_t lower[M][M] = {{0}};
            for (k = 0; k < sc->batch; ++k) {
                icoac_input_t in;
                icoac_output_t out;
                int t, ticks = (int)(test_rng_u64(&rng) % 4u);
                TEST_ASSERT_EQUAL_INT(ICOAC_OK, icoac_reset(&state));
                for (t = 0; t < ticks; ++t) {
                    in = test_input(0.1, 0.0, 0.01, 0.0, 0);
                    step_ok(&cfg, &state, &in, &out);
                }
                in = test_input(0.1, 0.0, 0.3, 0.0, ICOAC_INPUT_TERMINAL);
                if (icoac_step(&state, &in, &out) != ICOAC_OK) {
                    TEST_PRINTF("case %u, update %d: terminal tick -> %d", (unsigned)c, u, (int)out.status);
                    TEST_FAIL();
                }
            }
            cov = icoac_priv_cov_c(st);
            for (i = 0; i < N; ++i) {
                if (!(cov[i][i] >= st->search.floor[i]) || !isfinite((double)cov[i][i])) {
                    TEST_PRINTF("case %u, update %d: cov[%d][%d] = %g, floor %g", (unsigned)c, u, i, i,
                                (double)cov[i][i], (double)st->search.floor[i]);
                    TEST_FAIL();
                }
                for (j = i + 1; j < N; ++j) {
                    if (cov[i][j] != cov[j][i]) {
                        TEST_PRINTF("case %u, update %d: cov not symmetric at (%d, %d)", (unsigned)c, u, i, j);
                        TEST_FAIL();
                    }
                }
            }
            if (!icoac_priv_cholesky(cov, lower, ICOAC_CARTPOLE_INPUTS)) {
                TEST_PRINTF("case %u, update %d: cov not positive definite", (unsigned)c, u);
                TEST_FAIL();
            }
            if (u % TEST_ITERATIONS(5000, 100) == 0) {
                /* independent check in double, and the stored factor L L^T = Sigma_w */
                assert_sigma_spd(&state, sc->singular ? PSD_MARGIN : 0.0, "spd case", (int)c);
            }
            ++total;
        }
    }
    TEST_ASSERT_EQUAL_INT64(TEST_ITERATIONS(1000000, 20000), total);
}

/* Same seed, same observations: the same samples, outputs and state, bytewise; another seed
 * draws other samples. */
static void test_deterministic_for_a_seed(void)
{
    icoac_config_t cfg = search_config(3, 0.5, 0.5, 0.1, 2.0);
    test_rng_t rng_p = {77u};
    icoac_prior_t p = test_random_prior(&rng_p, 1.0, 0.5);
    icoac_state_t a, b, other;
    test_rng_t inputs = {0xD5u};
    int trial;
    TEST_ASSERT_EQUAL_INT(ICOAC_OK, icoac_init(&cfg, &a, &p, 42u));
    TEST_ASSERT_EQUAL_INT(ICOAC_OK, icoac_init(&cfg, &b, &p, 42u));
    TEST_ASSERT_EQUAL_INT(ICOAC_OK, icoac_init(&cfg, &other, &p, 43u));
    TEST_ASSERT_EQUAL_MEMORY(&b, &a, sizeof a);
    TEST_ASSERT_TRUE(memcmp(priv(&a)->w_act, priv(&other)->w_act, sizeof priv(&a)->w_act) != 0);
    for (trial = 0; trial < 60; ++trial) {
        const int ticks = (int)test_uniform(&inputs, 0, 30);
        int t;
        TEST_ASSERT_EQUAL_INT(ICOAC_OK, icoac_reset(&a));
        TEST_ASSERT_EQUAL_INT(ICOAC_OK, icoac_reset(&b));
        for (t = 0; t <= ticks; ++t) {
            icoac_input_t in = random_input(&inputs, t == ticks ? ICOAC_INPUT_TERMINAL : 0u);
            icoac_output_t oa, ob;
            step_ok(&cfg, &a, &in, &oa);
            step_ok(&cfg, &b, &in, &ob);
            TEST_ASSERT_EQUAL_MEMORY(&ob, &oa, sizeof oa);
        }
    }
    TEST_ASSERT_EQUAL_MEMORY(&b, &a, sizeof a);
}

/* learn = 0 (the no-learning control of a search condition): over many full batches mu_w,
 * Sigma_w, the factor and the record stay bitwise; the trials still draw their w, the same
 * ones as a learning twin with the same seed until its first update, other ones after it. */
static void test_no_learning_control(void)
{
    icoac_config_t learning = search_config(4, 0.5, 0.5, 0.1, 2.0);
    icoac_config_t control = learning;
    test_rng_t rng_p = {5u};
    icoac_prior_t p = test_random_prior(&rng_p, 1.0, 0.5);
    icoac_state_t c_state, l_state;
    icoac_state_t start;
    test_rng_t in_c = {9u}, in_l = {9u};
    int trial, distinct = 0;
    control.learn = 0;
    TEST_ASSERT_EQUAL_INT(ICOAC_OK, icoac_init(&control, &c_state, &p, 11u));
    TEST_ASSERT_EQUAL_INT(ICOAC_OK, icoac_init(&learning, &l_state, &p, 11u));
    start = c_state;
    for (trial = 0; trial < 40; ++trial) {
        double wc[N], wl[N], w_prev[N];
        const int ticks = trial % 6;
        w_act_of(&c_state, w_prev);
        TEST_ASSERT_EQUAL_INT(ICOAC_OK, icoac_reset(&c_state));
        TEST_ASSERT_EQUAL_INT(ICOAC_OK, icoac_reset(&l_state));
        w_act_of(&c_state, wc);
        w_act_of(&l_state, wl);
        distinct += memcmp(wc, w_prev, sizeof wc) != 0;
        if (trial < learning.search.batch) {
            TEST_ASSERT_EQUAL_MEMORY(wl, wc, sizeof wc); /* the same draws before the first update */
        } else {
            TEST_ASSERT_TRUE(memcmp(wc, wl, sizeof wc) != 0);
        }
        TEST_ASSERT_EQUAL_INT(ICOAC_OK, finish_trial(&control, &c_state, &in_c, ticks));
        TEST_ASSERT_EQUAL_INT(ICOAC_OK, finish_trial(&learning, &l_state, &in_l, ticks));
        TEST_ASSERT_EQUAL_MEMORY(priv(&start)->w, priv(&c_state)->w, sizeof priv(&start)->w);
        TEST_ASSERT_EQUAL_MEMORY(icoac_priv_cov_c(priv(&start)), icoac_priv_cov_c(priv(&c_state)),
                                 sizeof(icoac_real_t) * N * N);
        TEST_ASSERT_EQUAL_MEMORY(&priv(&start)->search, &priv(&c_state)->search, sizeof priv(&start)->search);
        TEST_ASSERT_TRUE(priv(&c_state)->weight_norm == priv(&start)->weight_norm);
    }
    TEST_ASSERT_EQUAL_INT(40, distinct);
    /* the learning twin did learn */
    TEST_ASSERT_TRUE(memcmp(priv(&l_state)->w, priv(&start)->w, sizeof priv(&start)->w) != 0);
}

/* A search tick acts like the ICO policy with the trial's w: F = G w^T x~ + reflex, no noise;
 * no critic outputs; the covariance's trace; a terminal tick outputs no force. */
static void test_tick_outputs(void)
{
    icoac_config_t cfg = search_config(2, 0.5, 0.5, 0.1, 1.0);
    icoac_state_t state;
    test_rng_t rng = {31u};
    icoac_prior_t p = test_random_prior(&rng, 1.0, 0.5);
    int k, i;
    TEST_ASSERT_EQUAL_INT(ICOAC_OK, icoac_init(&cfg, &state, &p, 8u));
    for (k = 0; k < 400; ++k) {
        const int terminal = k % 20 == 19;
        icoac_input_t in = random_input(&rng, terminal ? ICOAC_INPUT_TERMINAL : 0u);
        icoac_output_t out;
        gauss_t g;
        double w[N], z = 0, reflex = 0;
        if (k % 40 == 0) {
            in.s[2] = (icoac_real_t)(k % 80 == 0 ? 0.205 : -0.205); /* in the reflex zone */
        }
        w_act_of(&state, w);
        posterior_of(&state, &g);
        step_ok(&cfg, &state, &in, &out);
        for (i = 0; i < N; ++i) {
            z += w[i] * test_scale(i, (double)in.s[i], 1);
        }
        if (fabs((double)in.s[2]) > 0.20071286397934788 || fabs((double)in.s[0]) > 2.35) {
            reflex = (double)out.reflex;
            TEST_ASSERT_TRUE(reflex != 0);
        }
        TEST_ASSERT_TRUE(out.noise == 0 && out.value == 0 && out.td_error == 0 && out.q == 0);
        if (terminal) {
            TEST_ASSERT_TRUE(out.force == 0 && out.z == 0);
            TEST_ASSERT_EQUAL_INT(ICOAC_OK, icoac_reset(&state));
        } else {
            assert_close(out.z, z, (REAL_IS_FLOAT ? 1e-5 : 1e-13) * (1.0 + fabs(z)));
            assert_close(out.force, GAIN * z + reflex, (REAL_IS_FLOAT ? 1e-4 : 1e-12) * (1.0 + fabs(GAIN * z)));
        }
        posterior_of(&state, &g);
        assert_close(out.cov_trace, g.cov[0][0] + g.cov[1][1] + g.cov[2][2] + g.cov[3][3],
                     REAL_IS_FLOAT ? 1e-5 : 1e-13);
        assert_close(out.weight_norm, sqrt(g.mean[0] * g.mean[0] + g.mean[1] * g.mean[1] + g.mean[2] * g.mean[2] +
                                          g.mean[3] * g.mean[3]),
                     REAL_IS_FLOAT ? 1e-5 : 1e-13);
    }
}

void setUp(void) {}
void tearDown(void) {}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_update_matches_reference);
    RUN_TEST(test_elite_choice);
    RUN_TEST(test_step_one_small_elites);
    RUN_TEST(test_rejected_prior_leaves_state);
    RUN_TEST(test_samples_through_cholesky);
    RUN_TEST(test_spd_over_many_updates);
    RUN_TEST(test_deterministic_for_a_seed);
    RUN_TEST(test_no_learning_control);
    RUN_TEST(test_tick_outputs);
    return UNITY_END();
}
