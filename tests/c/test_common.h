/* SPDX-License-Identifier: Apache-2.0 */
/* Shared helpers of the Unity tests, on the host and on the Cortex-M targets. */
#ifndef ICOAC_TEST_COMMON_H
#define ICOAC_TEST_COMMON_H

#include <stddef.h>
#include <stdint.h>

#include "unity.h"

/* Failure context is printed with TEST_PRINTF (Unity's own printf, no stdio on the targets). */
#ifndef UNITY_INCLUDE_PRINT_FORMATTED
#error "build Unity with UNITY_INCLUDE_PRINT_FORMATTED (cmake/modules/IcoacUnity.cmake)"
#endif

#include <math.h>
#include <string.h>

/* 1 in a build for an emulated core (tests/target), 0 on the host. */
#ifndef ICOAC_TEST_ON_TARGET
#define ICOAC_TEST_ON_TARGET 0
#endif

/* A loop count of a long test: `host` on the host, `target` on an emulated core, where the test
 * says why it runs fewer (QEMU runs a Cortex-M about 100 times slower than the host). */
#if ICOAC_TEST_ON_TARGET
#define TEST_ITERATIONS(host, target) (target)
#else
#define TEST_ITERATIONS(host, target) (host)
#endif

#include "icoac/icoac.h"

#define TEST_PI 3.14159265358979323846
#define DEG(d) ((d) * TEST_PI / 180.0)

/* 1 when the library under test uses float. */
#define REAL_IS_FLOAT (sizeof(icoac_real_t) == sizeof(float))
/* Machine epsilon of icoac_real_t. */
#define REAL_EPS (REAL_IS_FLOAT ? 1.1920928955078125e-7 : 2.220446049250313e-16)

/* |actual - expected| <= tol, a non-finite actual fails; the message names the expression. */
#define assert_close(actual, expected, tol)                                                        \
    do {                                                                                           \
        const double assert_close_actual_ = (double)(actual);                                      \
        TEST_ASSERT_TRUE_MESSAGE(isfinite(assert_close_actual_), #actual " is not finite");        \
        TEST_ASSERT_DOUBLE_WITHIN_MESSAGE((double)(tol), (double)(expected), assert_close_actual_, \
                                          #actual);                                                \
    } while (0)

/* Deterministic test-side random numbers (xorshift64*), independent of the library RNG. */
typedef struct {
    uint64_t s;
} test_rng_t;

static inline uint64_t test_rng_u64(test_rng_t *r)
{
    r->s ^= r->s >> 12;
    r->s ^= r->s << 25;
    r->s ^= r->s >> 27;
    return r->s * 2685821657736338717ULL;
}

/* Uniform in [lo, hi). */
static inline double test_uniform(test_rng_t *r, double lo, double hi)
{
    return lo + (hi - lo) * ((double)(test_rng_u64(r) >> 11) * (1.0 / 9007199254740992.0));
}

/* A random prior N(m, s (A A^T + 0.05 I)) with m uniform in (-mean_half_width, mean_half_width),
 * exactly symmetric and accepted by icoac_prior_check. */
static inline icoac_prior_t test_random_prior(test_rng_t *rng, double mean_half_width, double scale)
{
    icoac_prior_t p;
    double a[ICOAC_CARTPOLE_INPUTS][ICOAC_CARTPOLE_INPUTS];
    int i, j, k;
    memset(&p, 0, sizeof p);
    for (i = 0; i < ICOAC_CARTPOLE_INPUTS; ++i) {
        p.mean[i] = (icoac_real_t)test_uniform(rng, -mean_half_width, mean_half_width);
        for (j = 0; j < ICOAC_CARTPOLE_INPUTS; ++j) {
            a[i][j] = test_uniform(rng, -1, 1);
        }
    }
    for (i = 0; i < ICOAC_CARTPOLE_INPUTS; ++i) {
        for (j = 0; j <= i; ++j) {
            double sum = i == j ? 0.05 : 0.0;
            for (k = 0; k < ICOAC_CARTPOLE_INPUTS; ++k) {
                sum += a[i][k] * a[j][k];
            }
            p.cov[i][j] = p.cov[j][i] = (icoac_real_t)(scale * sum);
        }
    }
    TEST_ASSERT_EQUAL_INT(ICOAC_OK, icoac_prior_check(&p, ICOAC_CARTPOLE_INPUTS));
    return p;
}

/* Configuration with paper defaults and a checked status. */
/* cfg is the configuration in force in state: the tests pass the one they initialised or last
 * retuned the state with (the state keeps its own copy; editing cfg alone changes nothing). */
static inline void test_assert_config_in_force(const icoac_config_t *cfg, const icoac_state_t *state)
{
    icoac_config_t in_force;
    TEST_ASSERT_EQUAL_INT(ICOAC_OK, icoac_get_config(state, &in_force));
    TEST_ASSERT_EQUAL_MEMORY(cfg, &in_force, sizeof in_force);
}

static inline icoac_config_t test_default_config(void)
{
    icoac_config_t cfg;
    memset(&cfg, 0, sizeof cfg);
    icoac_config_default(&cfg);
    TEST_ASSERT_EQUAL_INT(ICOAC_OK, icoac_config_check(&cfg));
    return cfg;
}

/* The paper's literal reading of the actor (harness configuration `literal`): the posterior
 * update with sigma_L = sigma_u (likelihood_std 0), per tick, exploring at every tick, the
 * literal critic. The defaults chose the gradient reading and an exploration schedule instead. */
static inline void test_literal_reading(icoac_config_t *cfg)
{
    cfg->actor.update = ICOAC_ACTOR_POSTERIOR;
    cfg->actor.noise_std = 1;
    cfg->actor.scale = (icoac_real_t)0.5;
    cfg->actor.likelihood_std = 0;
    cfg->actor.batch = 0;
    cfg->actor.explore_ticks = 0;
    cfg->critic.quirks = 0;
}

/* sigma_L^2 of the posterior and mean readings: actor.likelihood_std squared, or sigma_u^2
 * (actor.noise_std) when it is 0. */
static inline double test_likelihood_var(const icoac_actor_config_t *actor)
{
    const double std = actor->likelihood_std != 0 ? (double)actor->likelihood_std : (double)actor->noise_std;
    return std * std;
}

/* Prior with the given mean and covariance c * I. */
static inline icoac_prior_t test_prior(double w0, double w1, double w2, double w3, double c)
{
    icoac_prior_t p;
    int i;
    memset(&p, 0, sizeof p);
    p.mean[0] = (icoac_real_t)w0;
    p.mean[1] = (icoac_real_t)w1;
    p.mean[2] = (icoac_real_t)w2;
    p.mean[3] = (icoac_real_t)w3;
    for (i = 0; i < ICOAC_CARTPOLE_INPUTS; ++i) {
        p.cov[i][i] = (icoac_real_t)c;
    }
    return p;
}

static inline icoac_input_t test_input(double x, double xd, double th, double thd, uint32_t flags)
{
    icoac_input_t in;
    memset(&in, 0, sizeof in);
    in.s[0] = (icoac_real_t)x;
    in.s[1] = (icoac_real_t)xd;
    in.s[2] = (icoac_real_t)th;
    in.s[3] = (icoac_real_t)thd;
    in.flags = flags;
    return in;
}

/* Paper scaling (method.md, input scaling), written independently of the library, on the stored input. */
static inline double test_scale(int i, double value, int clip)
{
    static const double range[ICOAC_CARTPOLE_INPUTS] = {2.4, 3.5, 0.2094384, 2.0};
    double a = value / range[i];
    if (clip) {
        a = a > 1.0 ? 1.0 : (a < -1.0 ? -1.0 : a);
    }
    return a;
}

#endif /* ICOAC_TEST_COMMON_H */
