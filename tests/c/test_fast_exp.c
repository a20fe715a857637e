/* SPDX-License-Identifier: Apache-2.0 */
/* The optional float exp of the critic (ICOAC_FAST_EXP=1, on for the microcontroller presets):
 * relative error against the double-precision exp over its whole range. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include "icoac_priv.h"

#if !(defined(ICOAC_FAST_EXP) && ICOAC_FAST_EXP)
#error "build this test with ICOAC_FAST_EXP=1"
#endif

static double relative_error(float a)
{
    const double exact = exp((double)a);
    return fabs((double)icoac_priv_exp(a) - exact) / exact;
}

static void test_error_bound_dense_grid(void **state)
{
    double worst = 0.0;
    float worst_at = 0.0f;
    int k;
    (void)state;
    /* 2e6 points over [-87, 88], plus every float of [-1, 1] near the reduction boundaries. */
    for (k = 0; k <= 2000000; ++k) {
        const float a = -87.0f + (float)((double)k * (175.0 / 2000000.0));
        const double e = relative_error(a);
        if (e > worst) {
            worst = e;
            worst_at = a;
        }
    }
    print_message("fast exp: max relative error %.3g at %g\n", worst, (double)worst_at);
    assert_true(worst < 1e-6);
}

static void test_reduction_boundaries(void **state)
{
    /* a = (n + 1/2) ln 2 is where the rounding of n switches. */
    int n;
    (void)state;
    for (n = -120; n <= 120; ++n) {
        const float mid = (float)(((double)n + 0.5) * 0.69314718055994531);
        assert_true(relative_error(nextafterf(mid, -INFINITY)) < 1e-6);
        assert_true(relative_error(mid) < 1e-6);
        assert_true(relative_error(nextafterf(mid, INFINITY)) < 1e-6);
    }
}

static void test_exact_points_and_limits(void **state)
{
    (void)state;
    assert_true(icoac_priv_exp(0.0f) == 1.0f);
    assert_true(icoac_priv_exp(-87.5f) == 0.0f);
    assert_true(icoac_priv_exp(-1000.0f) == 0.0f);
    assert_true(isfinite(icoac_priv_exp(1000.0f)));
    assert_true(icoac_priv_exp(-1.0f) < icoac_priv_exp(-0.999f));
    /* NaN stays NaN and never reaches the float -> int32 conversion (UB under UBSan) */
    assert_true(isnan(icoac_priv_exp(NAN)));
    assert_true(icoac_priv_exp(-INFINITY) == 0.0f);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_error_bound_dense_grid),
        cmocka_unit_test(test_reduction_boundaries),
        cmocka_unit_test(test_exact_points_and_limits),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
