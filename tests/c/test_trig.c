/* SPDX-License-Identifier: Apache-2.0 */
/* The plants' sin and cos (sim_host/src/sim_trig.h): within 1 ulp of the long-double libm over
 * dense sweeps of the plants' angles and beyond, and the same bits from a loop over a batch (which
 * the compiler vectorises) as from one call at a time. */
#include "test_common.h"

#include <float.h>

#include "sim_trig.h"

/* |got - want| in units of the last place of want (a double). */
static double ulp_error(double got, long double want)
{
    int e;
    (void)frexpl(want, &e);
    return (double)(fabsl((long double)got - want) / ldexpl(1.0L, (e - 53) < -1074 ? -1074 : e - 53));
}

static uint64_t rng_state = 0x9E3779B97F4A7C15ULL;
static double uniform01(void)
{
    rng_state ^= rng_state << 13;
    rng_state ^= rng_state >> 7;
    rng_state ^= rng_state << 17;
    return (double)(rng_state >> 11) * 0x1p-53;
}

/* Worst error of sin and cos over n arguments from make(i, n). */
static void sweep(const char *name, double (*make)(long, long), long n)
{
    double worst = 0.0;
    long i;
    for (i = 0; i < n; ++i) {
        const double x = make(i, n);
        double s, c;
        sim_sincos(x, &s, &c);
        {
            const double es = ulp_error(s, sinl((long double)x)), ec = ulp_error(c, cosl((long double)x));
            worst = es > worst ? es : worst;
            worst = ec > worst ? ec : worst;
        }
    }
    TEST_PRINTF("%s: %d arguments, worst %d/1000 ulp", name, (int)n, (int)(1000.0 * worst));
    TEST_ASSERT_TRUE(worst < 1.0);
}

static double over_pi(long i, long n) { return -TEST_PI + 2.0 * TEST_PI * (double)i / (double)(n - 1); }
static double over_4pi(long i, long n) { return 4.0 * over_pi(i, n); }
static double random_100(long i, long n) { (void)i; (void)n; return 200.0 * uniform01() - 100.0; }
static double random_2e20(long i, long n) { (void)i; (void)n; return (2.0 * uniform01() - 1.0) * 0x1p20; }
static double tiny(long i, long n)
{
    (void)n;
    return ldexp(0.5 + uniform01(), -(int)(uniform01() * 1020.0)) * (i % 2 ? -1.0 : 1.0);
}
/* Within a few thousand ulps of k pi/2, where the reduction cancels most bits. */
static double near_half_pi(long i, long n)
{
    const double k = (double)(i % 129 - 64);
    const double at = k * (TEST_PI / 2.0);
    (void)n;
    return at + (uniform01() - 0.5) * 4096.0 * (at == 0.0 ? DBL_MIN : fabs(at) * DBL_EPSILON);
}

static void test_within_one_ulp(void)
{
    sweep("[-pi, pi]", over_pi, 2000000);
    sweep("[-4 pi, 4 pi]", over_4pi, 1000000);
    sweep("random in [-100, 100]", random_100, 1000000);
    sweep("random in [-2^20, 2^20]", random_2e20, 300000);
    sweep("tiny", tiny, 300000);
    sweep("near k pi/2", near_half_pi, 300000);
}

static void test_exact_points_and_symmetry(void)
{
    double s, c;
    sim_sincos(0.0, &s, &c);
    TEST_ASSERT_TRUE(s == 0.0 && c == 1.0);
    sim_sincos(-0.0, &s, &c);
    TEST_ASSERT_TRUE(s == 0.0 && c == 1.0);
    {
        long i;
        for (i = 0; i < 100000; ++i) {
            const double x = 20.0 * uniform01() - 10.0;
            double s2, c2;
            sim_sincos(x, &s, &c);
            sim_sincos(-x, &s2, &c2);
            TEST_ASSERT_TRUE(s2 == -s && c2 == c); /* odd and even, bit for bit */
            TEST_ASSERT_TRUE(fabs(s) <= 1.0 && fabs(c) <= 1.0);
        }
    }
    sim_sincos((double)NAN, &s, &c);
    TEST_ASSERT_TRUE(isnan(s) && isnan(c));
    sim_sincos((double)INFINITY, &s, &c);
    TEST_ASSERT_TRUE(isnan(s) && isnan(c)); /* a diverged angle stays non-finite */
    sim_sincos(-0x1p20, &s, &c);
    TEST_ASSERT_TRUE(isfinite(s) && isfinite(c)); /* the documented range's ends */
    sim_sincos(nextafter(0x1p20, 1e300), &s, &c);
    TEST_ASSERT_TRUE(isnan(s) && isnan(c)); /* beyond it, NaN rather than a wrong value */
    sim_sincos(-1e300, &s, &c);
    TEST_ASSERT_TRUE(isnan(s) && isnan(c));
}

/* One call at a time, kept out of any loop the compiler could vectorise. */
static void __attribute__((noinline)) one_call(double x, double *s, double *c)
{
    sim_sincos(x, s, c);
}

static void __attribute__((noinline)) batch(const double *restrict x, double *restrict s, double *restrict c,
                                            int n)
{
    int i;
    for (i = 0; i < n; ++i) {
        sim_sincos(x[i], &s[i], &c[i]);
    }
}

static void test_batch_equals_one_call(void)
{
    enum { N = 4099 };
    static double x[N], s[N], c[N];
    int round, i;
    for (round = 0; round < 64; ++round) {
        const double scale = round % 3 == 0 ? 3.3 : round % 3 == 1 ? 120.0 : 0x1p20;
        for (i = 0; i < N; ++i) {
            x[i] = (2.0 * uniform01() - 1.0) * scale;
        }
        batch(x, s, c, N);
        for (i = 0; i < N; ++i) {
            double s1, c1;
            one_call(x[i], &s1, &c1);
            TEST_ASSERT_EQUAL_MEMORY(&s1, &s[i], sizeof s1);
            TEST_ASSERT_EQUAL_MEMORY(&c1, &c[i], sizeof c1);
        }
    }
}

void setUp(void) {}
void tearDown(void) {}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_within_one_ulp);
    RUN_TEST(test_exact_points_and_symmetry);
    RUN_TEST(test_batch_equals_one_call);
    return UNITY_END();
}
