/* SPDX-License-Identifier: Apache-2.0 */
/* The actor readings and their switches (method.md, L2, L3, A10, A14) through icoac_step, each
 * against an independent double-precision formula computed here from what the ticks output
 * (the exploration noise eps, the TD error delta) and the observed states:
 *   posterior  S = h^T Sigma h + sigma_L^2, mu += Sigma h iota / S, Sigma -= Sigma h h^T Sigma / S
 *   mean       mu += Sigma0 h iota / (h^T Sigma0 h + sigma_L^2), Sigma stays Sigma0 (bitwise)
 *   gradient   mu += beta delta eps h / sigma_u^2, Sigma stays
 * with iota = alpha delta eps (+ h^T (w_act - mu) when acting with a sample), h = G x~(s_t);
 * per-trial batches (actor.batch) against the accumulated closed form; the exploration schedule
 * (actor.explore_ticks); the critic quirks (critic.quirks). */
#include "test_common.h"

#include "icoac_priv.h"

#define N ICOAC_CARTPOLE_INPUTS /* the cart-pole task's inputs */
#define M ICOAC_MAX_INPUTS      /* the library's vectors: entries past N are 0 */
#define K ICOAC_CARTPOLE_CRITIC_UNITS
#define GAIN 10.0

typedef struct {
    double mean[N];
    double cov[N][N];
} gauss_t;

static const double ranges[4] = {2.4, 3.5, 0.2094384, 2.0};
static const int sizes[4] = {3, 3, 6, 3};

static void step_ok(const icoac_config_t *cfg, icoac_state_t *state, const icoac_input_t *in, icoac_output_t *out)
{
    test_assert_config_in_force(cfg, state);
    memset(out, 0x7F, sizeof *out);
    TEST_ASSERT_EQUAL_INT(ICOAC_OK, icoac_step(state, in, out));
}

static void reset_ok(const icoac_config_t *cfg, icoac_state_t *state)
{
    test_assert_config_in_force(cfg, state);
    TEST_ASSERT_EQUAL_INT(ICOAC_OK, icoac_reset(state));
}

/* h = G x~(s), scaled and clipped as in method.md (input scaling), in double. */
static void h_of(const icoac_input_t *in, double h[N])
{
    int i;
    for (i = 0; i < N; ++i) {
        h[i] = GAIN * test_scale(i, (double)in->s[i], 1);
    }
}

static icoac_input_t random_input(test_rng_t *rng, uint32_t flags)
{
    return test_input(test_uniform(rng, -2.3, 2.3), test_uniform(rng, -4.0, 4.0), test_uniform(rng, -0.2, 0.2),
                      test_uniform(rng, -2.5, 2.5), flags);
}

/* mu_w and Sigma_w through icoac_get_posterior. */
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

/* Random critic weights, so that non-terminal transitions have a TD error too. */
static void random_critic(icoac_state_t *state, test_rng_t *rng, double amplitude)
{
    icoac_priv_state_t *st = icoac_priv_state(state);
    int k;
    for (k = 0; k < K; ++k) {
        st->v[k] = (icoac_real_t)test_uniform(rng, -amplitude, amplitude);
    }
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

static double dot(const double a[N], const double b[N])
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2] + a[3] * b[3];
}

static void mat_vec(const double m[N][N], const double v[N], double out[N])
{
    int i;
    for (i = 0; i < N; ++i) {
        out[i] = dot(m[i], v);
    }
}

/* Inverse of an SPD 4x4 matrix by Gauss-Jordan elimination with partial pivoting (not the
 * library's Cholesky route). */
static void inverse4(const double m[N][N], double inv[N][N])
{
    double a[N][2 * N];
    int i, j, k;
    for (i = 0; i < N; ++i) {
        for (j = 0; j < N; ++j) {
            a[i][j] = m[i][j];
            a[i][N + j] = i == j ? 1.0 : 0.0;
        }
    }
    for (k = 0; k < N; ++k) {
        int pivot = k;
        double p;
        for (i = k + 1; i < N; ++i) {
            if (fabs(a[i][k]) > fabs(a[pivot][k])) {
                pivot = i;
            }
        }
        if (pivot != k) {
            for (j = 0; j < 2 * N; ++j) {
                const double t = a[k][j];
                a[k][j] = a[pivot][j];
                a[pivot][j] = t;
            }
        }
        p = a[k][k];
        TEST_ASSERT_TRUE(p != 0.0);
        for (j = 0; j < 2 * N; ++j) {
            a[k][j] /= p;
        }
        for (i = 0; i < N; ++i) {
            if (i != k) {
                const double f = a[i][k];
                for (j = 0; j < 2 * N; ++j) {
                    a[i][j] -= f * a[k][j];
                }
            }
        }
    }
    for (i = 0; i < N; ++i) {
        for (j = 0; j < N; ++j) {
            inv[i][j] = a[i][N + j];
        }
    }
}

static void assert_gauss_close(const gauss_t *got, const gauss_t *want, double mean_tol, double cov_tol,
                               const char *what, int n)
{
    int i, j;
    for (i = 0; i < N; ++i) {
        if (!(fabs(got->mean[i] - want->mean[i]) <= mean_tol)) {
            TEST_PRINTF("%s, case %d: mean[%d] = %g, expected %g (tol %g)", what, n, i, got->mean[i],
                        want->mean[i], mean_tol);
            TEST_FAIL();
        }
        for (j = 0; j < N; ++j) {
            if (!(fabs(got->cov[i][j] - want->cov[i][j]) <= cov_tol)) {
                TEST_PRINTF("%s, case %d: cov[%d][%d] = %g, expected %g (tol %g)", what, n, i, j,
                            got->cov[i][j], want->cov[i][j], cov_tol);
                TEST_FAIL();
            }
        }
    }
}

/* One reading's step from (mu, Sigma) for an observation (h, delta, eps, offset = h^T (w_act -
 * mu)): the formulas of L2 (method.md) in double. */
static void reading_step(const icoac_actor_config_t *a, const gauss_t *prior, const double h[N], double delta,
                         double eps, double offset, gauss_t *post)
{
    const double sigma_l2 = test_likelihood_var(a); /* likelihood_std, or sigma_u when 0 */
    const double sigma_u2 = (double)a->noise_std * (double)a->noise_std;
    const double iota = offset + (double)a->scale * delta * eps;
    double ch[N], s;
    int i, j;
    *post = *prior;
    mat_vec(prior->cov, h, ch);
    s = dot(h, ch) + sigma_l2;
    switch (a->update) {
    case ICOAC_ACTOR_POSTERIOR:
        for (i = 0; i < N; ++i) {
            post->mean[i] = prior->mean[i] + ch[i] * iota / s;
            for (j = 0; j < N; ++j) {
                post->cov[i][j] = prior->cov[i][j] - ch[i] * ch[j] / s;
            }
        }
        break;
    case ICOAC_ACTOR_MEAN:
        for (i = 0; i < N; ++i) {
            post->mean[i] = prior->mean[i] + ch[i] * iota / s;
        }
        break;
    default:
        for (i = 0; i < N; ++i) {
            post->mean[i] = prior->mean[i] + (double)a->rate * delta * eps * h[i] / sigma_u2;
        }
        break;
    }
}

static const char *const reading_names[3] = {"posterior", "mean", "gradient"};

/* One step of each reading, from a random prior and random settings, with sigma_L != sigma_u
 * (a quarter of the cases with likelihood_std 0: sigma_L = sigma_u), acting with mu_w or a
 * sample, on a terminal (delta = -1) or a non-terminal transition (delta from random critic
 * weights): the posterior and step against the formula, and Sigma_w bitwise the prior for mean
 * and gradient. */
static void test_single_step_each_reading(void)
{
    test_rng_t rng = {0x5EAD1u};
    int n, moved = 0;
    for (n = 0; n < 600; ++n) {
        const int reading = n % 3;
        const int sample = (n / 3) % 2;
        const int terminal = (n / 6) % 2;
        icoac_config_t cfg = test_default_config();
        icoac_state_t state;
        icoac_prior_t p = test_random_prior(&rng, 0.5, test_uniform(&rng, 0.02, 1.5));
        icoac_input_t s1 = random_input(&rng, 0);
        icoac_input_t s2 = random_input(&rng, terminal ? ICOAC_INPUT_TERMINAL : 0u);
        icoac_output_t out1, out2;
        gauss_t before, after, want;
        double h[N], w_act[N], offset = 0, mean_tol, cov_tol, step_size = 0;
        int i;
        cfg.mode = ICOAC_MODE_RL;
        cfg.actor.update = reading;
        cfg.actor.act_with_sample = sample;
        cfg.actor.likelihood_std = (icoac_real_t)test_uniform(&rng, 0.3, 3.0);
        cfg.actor.noise_std = (icoac_real_t)test_uniform(&rng, 0.3, 3.0);
        cfg.actor.scale = (icoac_real_t)test_uniform(&rng, 0.1, 2.0);
        cfg.actor.rate = (icoac_real_t)test_uniform(&rng, 1e-3, 0.3);
        if ((n / 12) % 4 == 3) {
            cfg.actor.likelihood_std = 0;
        }
        TEST_ASSERT_EQUAL_INT(ICOAC_OK, icoac_init(&cfg, &state, &p, (uint64_t)n + 1u));
        random_critic(&state, &rng, 0.5);
        posterior_of(&state, &before);
        for (i = 0; i < N; ++i) {
            w_act[i] = (double)icoac_priv_state_c(&state)->w_act[i];
        }
        h_of(&s1, h);
        step_ok(&cfg, &state, &s1, &out1);
        TEST_ASSERT_TRUE(out1.noise != 0);
        step_ok(&cfg, &state, &s2, &out2);
        if (terminal) {
            /* r = -1, V(terminal) = 0: delta = clip(-1 - V(s_t)), |V| <= 0.5 */
            TEST_ASSERT_TRUE(out2.td_error <= -0.5f && out2.td_error >= -1.0f);
        } else {
            TEST_ASSERT_TRUE(out2.td_error != 0);
        }
        posterior_of(&state, &after);
        if (sample) {
            double d[N];
            for (i = 0; i < N; ++i) {
                d[i] = w_act[i] - before.mean[i];
            }
            offset = dot(h, d);
            TEST_ASSERT_TRUE(offset != 0);
        }
        reading_step(&cfg.actor, &before, h, (double)out2.td_error, (double)out1.noise, offset, &want);
        for (i = 0; i < N; ++i) {
            step_size = fabs(want.mean[i] - before.mean[i]) > step_size ? fabs(want.mean[i] - before.mean[i]) : step_size;
        }
        moved += step_size > 1e-3;
        mean_tol = (REAL_IS_FLOAT ? 2e-5 : 1e-12) * (1.0 + step_size + max_abs_mat(before.cov));
        cov_tol = (REAL_IS_FLOAT ? 2e-5 : 1e-12) * (1.0 + max_abs_mat(before.cov));
        assert_gauss_close(&after, &want, mean_tol, cov_tol, reading_names[reading], n);
        if (reading != ICOAC_ACTOR_POSTERIOR) {
            icoac_prior_t post;
            TEST_ASSERT_EQUAL_INT(ICOAC_OK, icoac_get_posterior(&state, &post));
            TEST_ASSERT_EQUAL_MEMORY(p.cov, post.cov, sizeof p.cov);
        }
    }
    TEST_ASSERT_TRUE(moved > 400); /* the steps are not vanishingly small */
}

/* The readings differ: one observation, three readings, three different means (and only the
 * posterior moves Sigma_w). Guards the formula test against a reading switch that is ignored. */
static void test_readings_differ(void)
{
    test_rng_t rng = {0xD1FFu};
    icoac_prior_t p = test_random_prior(&rng, 0.5, 0.5);
    icoac_input_t s1 = test_input(0.5, -0.3, 0.05, 0.4, 0);
    icoac_input_t s2 = test_input(0.6, -0.3, 0.3, 0.4, ICOAC_INPUT_TERMINAL);
    gauss_t got[3];
    int reading, i;
    for (reading = 0; reading < 3; ++reading) {
        icoac_config_t cfg = test_default_config();
        icoac_state_t state;
        icoac_output_t out;
        cfg.mode = ICOAC_MODE_RL;
        cfg.actor.update = reading;
        cfg.actor.rate = (icoac_real_t)0.05;
        cfg.actor.likelihood_std = (icoac_real_t)2.0;
        TEST_ASSERT_EQUAL_INT(ICOAC_OK, icoac_init(&cfg, &state, &p, 9u));
        step_ok(&cfg, &state, &s1, &out);
        step_ok(&cfg, &state, &s2, &out);
        posterior_of(&state, &got[reading]);
    }
    for (i = 0; i < N; ++i) {
        TEST_ASSERT_TRUE(got[0].mean[i] != got[2].mean[i] && got[1].mean[i] != got[2].mean[i]);
    }
    /* on the first step Sigma is Sigma0, so the posterior and mean readings take the same
     * mean step; only the posterior moves Sigma (mean and gradient keep the prior) */
    for (i = 0; i < N; ++i) {
        assert_close(got[0].mean[i], got[1].mean[i], REAL_IS_FLOAT ? 1e-6 : 1e-14);
    }
    TEST_ASSERT_TRUE(memcmp(got[0].cov, got[1].cov, sizeof got[0].cov) != 0);
    TEST_ASSERT_TRUE(memcmp(got[1].cov, got[2].cov, sizeof got[1].cov) == 0);
}

/* mean and gradient over a long run through icoac_step (random states, failures, resets):
 * Sigma_w and the output's trace stay bitwise at the prior, and every tick's step is the
 * reading's formula from the state it started from; mu_w travels. The posterior reading
 * with the same run shrinks Sigma_w, so Sigma_w is not merely never written. */
static void run_keeps_prior(int reading, int n_ticks)
{
    test_rng_t rng = {0x10E6u + (uint64_t)reading};
    icoac_config_t cfg = test_default_config();
    icoac_state_t state;
    icoac_prior_t p = test_random_prior(&rng, 0.5, 0.3);
    const icoac_real_t trace = (p.cov[0][0] + p.cov[1][1]) + (p.cov[2][2] + p.cov[3][3]);
    icoac_input_t prev;
    icoac_output_t out, prev_out;
    gauss_t before, after, want;
    double h[N], travelled = 0;
    int k, i, have_prev = 0, checked = 0;
    cfg.mode = ICOAC_MODE_RL;
    cfg.actor.update = reading;
    cfg.actor.rate = (icoac_real_t)0.002;
    cfg.actor.likelihood_std = (icoac_real_t)3.0;
    TEST_ASSERT_EQUAL_INT(ICOAC_OK, icoac_init(&cfg, &state, &p, 77u));
    memset(&prev, 0, sizeof prev);
    memset(&prev_out, 0, sizeof prev_out);
    for (k = 0; k < n_ticks; ++k) {
        const int terminal = k % 53 == 52;
        icoac_input_t in = random_input(&rng, terminal ? ICOAC_INPUT_TERMINAL : 0u);
        icoac_prior_t post;
        posterior_of(&state, &before);
        step_ok(&cfg, &state, &in, &out);
        TEST_ASSERT_EQUAL_INT(ICOAC_OK, icoac_get_posterior(&state, &post));
        if (reading == ICOAC_ACTOR_POSTERIOR) {
            if (k == n_ticks - 1) {
                TEST_ASSERT_TRUE(out.cov_trace < trace * 0.5f);
            }
        } else {
            if (memcmp(post.cov, p.cov, sizeof p.cov) != 0 || memcmp(&out.cov_trace, &trace, sizeof trace) != 0) {
                TEST_PRINTF("%s, tick %d: Sigma_w or its trace left the prior", reading_names[reading], k);
                TEST_FAIL();
            }
            if (have_prev && k % 7 == 0) {
                double scale = 1.0;
                h_of(&prev, h);
                reading_step(&cfg.actor, &before, h, (double)out.td_error, (double)prev_out.noise, 0.0, &want);
                posterior_of(&state, &after);
                for (i = 0; i < N; ++i) {
                    scale += fabs(after.mean[i]) + fabs(want.mean[i] - before.mean[i]);
                }
                assert_gauss_close(&after, &want, (REAL_IS_FLOAT ? 2e-6 : 1e-13) * scale, 0.0, reading_names[reading], k);
                ++checked;
            }
        }
        have_prev = !terminal;
        prev = in;
        prev_out = out;
        if (terminal) {
            reset_ok(&cfg, &state);
        }
    }
    posterior_of(&state, &after);
    for (i = 0; i < N; ++i) {
        travelled += fabs(after.mean[i] - (double)p.mean[i]);
    }
    TEST_ASSERT_TRUE(travelled > 1e-3);
    TEST_ASSERT_TRUE(reading == ICOAC_ACTOR_POSTERIOR || checked > n_ticks / 10);
}

static void test_mean_and_gradient_keep_sigma(void)
{
    /* fewer ticks on an emulated core (QEMU is slow) */
    run_keeps_prior(ICOAC_ACTOR_MEAN, TEST_ITERATIONS(200000, 10000));
    run_keeps_prior(ICOAC_ACTOR_GRADIENT, TEST_ITERATIONS(200000, 10000));
    run_keeps_prior(ICOAC_ACTOR_POSTERIOR, 2000);
}

/* actor.batch: over a trial the acting weights, mu_w and Sigma_w stay; at its terminal tick
 * the closed form of L2 / A14 (method.md) over the trial's observations (h_t, eps_t, delta_t),
 * recorded here from the ticks: P = Sigma^-1 + sum h h^T / sigma_L^2 (Sigma / lambda_f with
 * forgetting), mu' = mu + P^-1 sum h iota / sigma_L^2, Sigma' = P^-1 (posterior) or Sigma
 * (mean); gradient: mu' = mu + beta / sigma_u^2 sum delta eps h. With explore_ticks N only the
 * transitions whose first tick explored (t < N) count. A trial cut by a reset (no terminal
 * tick) changes nothing, and its sums do not leak into the next trial. sigma_L is drawn apart
 * from sigma_u, or is sigma_u (likelihood_std 0) in a few cases. */
typedef struct {
    int reading;
    int explore;
    int sample;
    double forgetting;
} batch_case_t;

#define MAX_TRIAL 40

static void run_batch_case(const batch_case_t *bc, int n_case)
{
    test_rng_t rng = {0xBA7C4u + (uint64_t)n_case * 7919u};
    icoac_config_t cfg = test_default_config();
    icoac_state_t state;
    icoac_prior_t p = test_random_prior(&rng, 0.5, test_uniform(&rng, 0.1, 1.0));
    int trial;
    cfg.mode = ICOAC_MODE_RL;
    cfg.actor.batch = 1;
    cfg.actor.update = bc->reading;
    cfg.actor.explore_ticks = bc->explore;
    cfg.actor.act_with_sample = bc->sample;
    cfg.actor.forgetting = (icoac_real_t)bc->forgetting;
    cfg.actor.likelihood_std = (icoac_real_t)test_uniform(&rng, 2.0, 4.0);
    cfg.actor.noise_std = (icoac_real_t)test_uniform(&rng, 0.5, 2.0);
    cfg.actor.rate = (icoac_real_t)test_uniform(&rng, 1e-3, 0.05);
    cfg.actor.scale = (icoac_real_t)test_uniform(&rng, 0.2, 1.0);
    if (n_case % 5 == 0 || n_case == 6) {
        cfg.actor.likelihood_std = 0; /* sigma_L = sigma_u */
    }
    TEST_ASSERT_EQUAL_INT(ICOAC_OK, icoac_init(&cfg, &state, &p, 100u + (uint64_t)n_case));
    for (trial = 0; trial < 6; ++trial) {
        const int cut = trial == 2; /* ended by a reset, not a failure */
        const int length = 12 + (int)test_uniform(&rng, 0, 14);
        double hs[MAX_TRIAL][N], eps[MAX_TRIAL], delta[MAX_TRIAL], w_act[N];
        gauss_t start, now, want;
        double info[N][N], shift[N], prec[N][N], inv[N][N];
        double lambda_inv = bc->forgetting < 1.0 ? 1.0 / (double)cfg.actor.forgetting : 1.0;
        const double sigma_l2 = test_likelihood_var(&cfg.actor);
        int t, i, j, observed = 0;
        reset_ok(&cfg, &state);
        random_critic(&state, &rng, 0.5);
        posterior_of(&state, &start);
        for (i = 0; i < N; ++i) {
            w_act[i] = (double)icoac_priv_state_c(&state)->w_act[i];
        }
        for (t = 0; t <= length; ++t) {
            const int terminal = t == length;
            icoac_input_t in = random_input(&rng, terminal ? ICOAC_INPUT_TERMINAL : 0u);
            icoac_output_t out;
            if (terminal && cut) {
                break;
            }
            step_ok(&cfg, &state, &in, &out);
            if (t > 0) {
                delta[t - 1] = (double)out.td_error;
            }
            if (!terminal) {
                h_of(&in, hs[t]);
                eps[t] = (double)out.noise;
                TEST_ASSERT_TRUE((bc->explore == 0 || t < bc->explore) ? out.noise != 0 : out.noise == 0);
                /* frozen during the trial: mu_w, Sigma_w and the acting weights */
                posterior_of(&state, &now);
                TEST_ASSERT_EQUAL_MEMORY(&start, &now, sizeof now);
                for (i = 0; i < N; ++i) {
                    TEST_ASSERT_TRUE((double)icoac_priv_state_c(&state)->w_act[i] == w_act[i]);
                }
            }
        }
        posterior_of(&state, &now);
        if (cut) {
            TEST_ASSERT_EQUAL_MEMORY(&start, &now, sizeof now);
            continue;
        }
        /* the closed form over the observed transitions t -> t+1, t = 0 .. length-1 */
        memset(info, 0, sizeof info);
        memset(shift, 0, sizeof shift);
        for (t = 0; t < length; ++t) {
            double d[N], offset = 0;
            if (bc->explore != 0 && t >= bc->explore) {
                continue;
            }
            ++observed;
            for (i = 0; i < N; ++i) {
                d[i] = w_act[i] - start.mean[i];
            }
            offset = bc->sample ? dot(hs[t], d) : 0.0;
            for (i = 0; i < N; ++i) {
                if (bc->reading == ICOAC_ACTOR_GRADIENT) {
                    shift[i] += delta[t] * eps[t] * hs[t][i];
                } else {
                    shift[i] += hs[t][i] * (offset + (double)cfg.actor.scale * delta[t] * eps[t]) / sigma_l2;
                    for (j = 0; j < N; ++j) {
                        info[i][j] += hs[t][i] * hs[t][j] / sigma_l2;
                    }
                }
            }
        }
        TEST_ASSERT_TRUE(observed > 0);
        want = start;
        if (bc->reading == ICOAC_ACTOR_GRADIENT) {
            const double sigma_u2 = (double)cfg.actor.noise_std * (double)cfg.actor.noise_std;
            for (i = 0; i < N; ++i) {
                want.mean[i] = start.mean[i] + (double)cfg.actor.rate / sigma_u2 * shift[i];
            }
        } else {
            double scaled[N][N], dmu[N];
            if (bc->reading == ICOAC_ACTOR_MEAN) {
                lambda_inv = 1.0; /* forgetting belongs to the posterior reading */
            }
            for (i = 0; i < N; ++i) {
                for (j = 0; j < N; ++j) {
                    scaled[i][j] = start.cov[i][j] * lambda_inv;
                }
            }
            inverse4(scaled, prec);
            for (i = 0; i < N; ++i) {
                for (j = 0; j < N; ++j) {
                    prec[i][j] += info[i][j];
                }
            }
            inverse4(prec, inv);
            mat_vec(inv, shift, dmu);
            for (i = 0; i < N; ++i) {
                want.mean[i] = start.mean[i] + dmu[i];
                for (j = 0; j < N; ++j) {
                    want.cov[i][j] = bc->reading == ICOAC_ACTOR_POSTERIOR ? inv[i][j] : start.cov[i][j];
                }
            }
        }
        {
            double step = 0, tol_m, tol_c;
            for (i = 0; i < N; ++i) {
                step = fabs(want.mean[i] - start.mean[i]) > step ? fabs(want.mean[i] - start.mean[i]) : step;
            }
            TEST_ASSERT_TRUE(step > 1e-4); /* the batch moved mu_w */
            tol_m = (REAL_IS_FLOAT ? 1e-4 : 1e-9) * (step + 1e-2 * (1.0 + max_abs_mat(start.cov)));
            tol_c = (REAL_IS_FLOAT ? 1e-4 : 1e-9) * max_abs_mat(want.cov);
            /* the case number names the batch case (reading, explore, sample, forgetting) */
            assert_gauss_close(&now, &want, tol_m, tol_c, reading_names[bc->reading], n_case);
            if (bc->reading != ICOAC_ACTOR_POSTERIOR) {
                TEST_ASSERT_EQUAL_MEMORY(start.cov, now.cov, sizeof now.cov);
            }
        }
    }
}

static void test_batch_matches_closed_form(void)
{
    static const batch_case_t cases[] = {
        {ICOAC_ACTOR_POSTERIOR, 0, 0, 1.0}, {ICOAC_ACTOR_MEAN, 0, 0, 1.0},     {ICOAC_ACTOR_GRADIENT, 0, 0, 1.0},
        {ICOAC_ACTOR_POSTERIOR, 7, 0, 1.0}, {ICOAC_ACTOR_MEAN, 7, 0, 1.0},     {ICOAC_ACTOR_GRADIENT, 7, 0, 1.0},
        {ICOAC_ACTOR_POSTERIOR, 0, 1, 1.0}, {ICOAC_ACTOR_MEAN, 5, 1, 1.0},     {ICOAC_ACTOR_GRADIENT, 0, 1, 1.0},
        {ICOAC_ACTOR_POSTERIOR, 0, 0, 0.9}, {ICOAC_ACTOR_MEAN, 0, 0, 0.9},     {ICOAC_ACTOR_POSTERIOR, 4, 1, 0.95},
    };
    size_t n;
    for (n = 0; n < sizeof cases / sizeof cases[0]; ++n) {
        run_batch_case(&cases[n], (int)n);
    }
}

/* explore_ticks N: out.noise is exactly 0 from tick N of each trial on (and not before), the
 * actor learns nothing from a transition whose first tick did not explore, while the critic
 * keeps learning; the count starts again at each reset. */
static void test_explore_schedule(void)
{
    const int n_explore = 5;
    int reading;
    for (reading = 0; reading < 3; ++reading) {
        test_rng_t rng = {0xE9u + (uint64_t)reading};
        icoac_config_t cfg = test_default_config();
        icoac_state_t state;
        icoac_prior_t p = test_random_prior(&rng, 0.5, 0.3);
        int trial, critic_moved = 0, actor_moved = 0;
        cfg.mode = ICOAC_MODE_RL;
        cfg.actor.update = reading;
        cfg.actor.explore_ticks = n_explore;
        cfg.actor.rate = (icoac_real_t)0.05;
        TEST_ASSERT_EQUAL_INT(ICOAC_OK, icoac_init(&cfg, &state, &p, 5u));
        random_critic(&state, &rng, 0.5);
        for (trial = 0; trial < 8; ++trial) {
            const int length = 12 + trial;
            int t;
            reset_ok(&cfg, &state);
            for (t = 0; t <= length; ++t) {
                const int terminal = t == length;
                icoac_input_t in = random_input(&rng, terminal ? ICOAC_INPUT_TERMINAL : 0u);
                icoac_output_t out;
                icoac_real_t v_before[K];
                gauss_t before, after;
                memcpy(v_before, icoac_priv_state_c(&state)->v, sizeof v_before);
                posterior_of(&state, &before);
                step_ok(&cfg, &state, &in, &out);
                posterior_of(&state, &after);
                if (t < n_explore && !terminal) {
                    TEST_ASSERT_TRUE(out.noise != 0);
                } else {
                    TEST_ASSERT_TRUE(out.noise == 0);
                }
                if (t > n_explore) {
                    /* transition (t-1 -> t) started at an unexplored tick */
                    TEST_ASSERT_EQUAL_MEMORY(&before, &after, sizeof after);
                }
                if (t > 0 && t <= n_explore && memcmp(&after.mean, &before.mean, sizeof after.mean) != 0) {
                    ++actor_moved;
                }
                if (t > n_explore && memcmp(icoac_priv_state_c(&state)->v, v_before, sizeof v_before) != 0) {
                    TEST_ASSERT_TRUE(out.td_error != 0);
                    ++critic_moved;
                }
            }
        }
        /* every explored transition moved mu_w; the critic learned after the schedule's end */
        TEST_ASSERT_EQUAL_INT(8 * n_explore, actor_moved);
        TEST_ASSERT_TRUE(critic_moved >= 8 * 6);
    }
}

/* b_k(s) from the 4-D definition (method.md, critic), in long double (log space), no threshold. */
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

static double direct_value(const double v[K], const icoac_real_t s[4])
{
    double b[K], sum = 0;
    int k;
    direct_b(s, b);
    for (k = 0; k < K; ++k) {
        sum += v[k] * b[k];
    }
    return sum;
}

/* v_after - v_before = eta * delta * b(s) for every unit; 0 when some unit disagrees. */
static int critic_step_is(const double before[K], const icoac_real_t after[K], double eta_delta, const icoac_real_t s[4])
{
    double b[K];
    int k;
    direct_b(s, b);
    for (k = 0; k < K; ++k) {
        const double want = before[k] + eta_delta * b[k];
        if (!(fabs((double)after[k] - want) <= (REAL_IS_FLOAT ? 3e-7 : 1e-14) * (1.0 + fabs(want)))) {
            return 0;
        }
    }
    return 1;
}

/* critic.quirks (A10): the trial's first TD error is gamma V(s_1) (V_old = 0 at a reset) and
 * the TD update uses b(s_t+1) (the terminal failure state included); without quirks the first
 * TD error is gamma V(s_1) - V(s_0) and the update uses b(s_t). Dense critic (threshold 0), so
 * b is the plain normalized activation. */
static void test_critic_quirks(void)
{
    int quirks;
    for (quirks = 0; quirks <= 1; ++quirks) {
        test_rng_t rng = {0x9A1u};
        icoac_config_t cfg = test_default_config();
        icoac_state_t state;
        const icoac_priv_state_t *st = icoac_priv_state_c(&state);
        const double gamma = 0.9, eta = 0.3;
        int trial;
        cfg.mode = ICOAC_MODE_RL;
        cfg.critic.quirks = quirks;
        cfg.critic.threshold = 0;
        cfg.critic.discount = (icoac_real_t)gamma;
        cfg.critic.rate = (icoac_real_t)eta;
        TEST_ASSERT_EQUAL_INT(ICOAC_OK, icoac_init(&cfg, &state, NULL, 3u));
        random_critic(&state, &rng, 0.4);
        for (trial = 0; trial < 4; ++trial) {
            icoac_input_t s[5];
            double v_prev_value = 0; /* V(s_t) as the tick of s_t computed it */
            int t;
            reset_ok(&cfg, &state);
            for (t = 0; t < 4; ++t) {
                s[t] = random_input(&rng, 0);
            }
            s[4] = test_input(0.1, 0.2, 0.25, 0.3, ICOAC_INPUT_TERMINAL); /* theta beyond 12 deg */
            for (t = 0; t < 5; ++t) {
                double v[K], v_now, v_t, want_delta;
                icoac_output_t out;
                int k;
                for (k = 0; k < K; ++k) {
                    v[k] = (double)st->v[k];
                }
                step_ok(&cfg, &state, &s[t], &out);
                /* V(s) with the weights before this tick's update; 0 at the terminal state */
                v_now = t < 4 ? direct_value(v, s[t].s) : 0.0;
                assert_close(out.value, v_now, REAL_IS_FLOAT ? 2e-6 : 1e-13);
                if (t == 0) {
                    TEST_ASSERT_TRUE(out.td_error == 0);
                    for (k = 0; k < K; ++k) {
                        TEST_ASSERT_TRUE((double)st->v[k] == v[k]); /* no transition: nothing learned */
                    }
                    v_prev_value = v_now;
                    continue;
                }
                v_t = (quirks && t == 1) ? 0.0 : v_prev_value;
                want_delta = (t < 4 ? 0.0 : -1.0) + gamma * v_now - v_t;
                want_delta = want_delta > 1 ? 1 : (want_delta < -1 ? -1 : want_delta);
                if (quirks && t == 1) {
                    assert_close(out.td_error, gamma * (double)out.value, REAL_IS_FLOAT ? 1e-6 : 1e-14);
                }
                assert_close(out.td_error, want_delta, REAL_IS_FLOAT ? 3e-6 : 1e-13);
                TEST_ASSERT_TRUE(fabs((double)out.td_error) > 1e-3);
                /* the unit activations of the update: b(s_t+1) with quirks, b(s_t) without */
                if (!critic_step_is(v, st->v, eta * (double)out.td_error, quirks ? s[t].s : s[t - 1].s)) {
                    TEST_PRINTF("quirks %d, trial %d, tick %d: the TD update is not eta delta b(%s)", quirks, trial,
                                t, quirks ? "s_t+1" : "s_t");
                    TEST_FAIL();
                }
                TEST_ASSERT_FALSE(critic_step_is(v, st->v, eta * (double)out.td_error, quirks ? s[t - 1].s : s[t].s));
                v_prev_value = v_now;
            }
        }
    }
}

void setUp(void) {}
void tearDown(void) {}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_single_step_each_reading);
    RUN_TEST(test_readings_differ);
    RUN_TEST(test_mean_and_gradient_keep_sigma);
    RUN_TEST(test_batch_matches_closed_form);
    RUN_TEST(test_explore_schedule);
    RUN_TEST(test_critic_quirks);
    return UNITY_END();
}
