/* SPDX-License-Identifier: Apache-2.0 */
/* The optional float exp of the critic (ICOAC_FAST_EXP=1, on for the microcontroller presets):
 * relative error against the double-precision exp over its whole range. */
#include "test_common.h"

#include "icoac_priv.h"

#if !(defined(ICOAC_FAST_EXP) && ICOAC_FAST_EXP)
#error "build this test with ICOAC_FAST_EXP=1"
#endif

static double relative_error(float a)
{
    const double exact = exp((double)a);
    return fabs((double)icoac_priv_exp(a) - exact) / exact;
}

static void test_error_bound_dense_grid(void)
{
    /* 2e6 points over [-87, 88] (2e5 under QEMU, where a double exp is emulated in software). */
    const int points = TEST_ITERATIONS(2000000, 200000);
    double worst = 0.0;
    float worst_at = 0.0f;
    int k;
    for (k = 0; k <= points; ++k) {
        const float a = -87.0f + (float)((double)k * (175.0 / (double)points));
        const double e = relative_error(a);
        if (e > worst) {
            worst = e;
            worst_at = a;
        }
    }
    TEST_PRINTF("fast exp: max relative error %g at %g", worst, (double)worst_at);
    TEST_ASSERT_LESS_THAN_DOUBLE(1e-6, worst);
}

static void test_reduction_boundaries(void)
{
    /* a = (n + 1/2) ln 2 is where the rounding of n switches. */
    int n;
    for (n = -120; n <= 120; ++n) {
        const float mid = (float)(((double)n + 0.5) * 0.69314718055994531);
        TEST_ASSERT_LESS_THAN_DOUBLE(1e-6, relative_error(nextafterf(mid, -INFINITY)));
        TEST_ASSERT_LESS_THAN_DOUBLE(1e-6, relative_error(mid));
        TEST_ASSERT_LESS_THAN_DOUBLE(1e-6, relative_error(nextafterf(mid, INFINITY)));
    }
}

static void test_exact_points_and_limits(void)
{
    TEST_ASSERT_TRUE(icoac_priv_exp(0.0f) == 1.0f);
    TEST_ASSERT_TRUE(icoac_priv_exp(-87.5f) == 0.0f);
    TEST_ASSERT_TRUE(icoac_priv_exp(-1000.0f) == 0.0f);
    TEST_ASSERT_TRUE(isfinite(icoac_priv_exp(1000.0f)));
    TEST_ASSERT_TRUE(icoac_priv_exp(-1.0f) < icoac_priv_exp(-0.999f));
    /* NaN stays NaN and never reaches the float -> int32 conversion (UB under UBSan) */
    TEST_ASSERT_TRUE(isnan(icoac_priv_exp(NAN)));
    TEST_ASSERT_TRUE(icoac_priv_exp(-INFINITY) == 0.0f);
}

void setUp(void)
{
}

void tearDown(void)
{
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_error_bound_dense_grid);
    RUN_TEST(test_reduction_boundaries);
    RUN_TEST(test_exact_points_and_limits);
    return UNITY_END();
}
