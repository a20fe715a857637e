/* SPDX-License-Identifier: Apache-2.0 */
/* The host's float exp of the critic (icoac_priv.h: the dense kernel's float builds): within
 * 1 ulp of the C library's expf on a dense sweep of floats, its limits, and the same bits from a
 * loop the compiler vectorises as from one call at a time (icoac_step_batch relies on it). */
#include "test_common.h"

#include <string.h>

#include "icoac_priv.h"

#if !(defined(ICOAC_CRITIC_DENSE) && ICOAC_CRITIC_DENSE) || (defined(ICOAC_REAL_DOUBLE) && ICOAC_REAL_DOUBLE) || \
    (defined(ICOAC_FAST_EXP) && ICOAC_FAST_EXP)
#error "build this test against the host's float library (dense kernel, libm's log, float reals)"
#endif

static uint32_t bits_of(float f)
{
    uint32_t u;
    (void)memcpy(&u, &f, sizeof u);
    return u;
}

/* ulp distance of two finite floats of the same sign */
static uint32_t ulps(float a, float b)
{
    const uint32_t x = bits_of(a);
    const uint32_t y = bits_of(b);
    return x > y ? x - y : y - x;
}

/* One call, out of line: the scalar code. */
static float (*volatile one_call)(float) = icoac_priv_exp;

static void test_within_one_ulp_of_libm_dense_sweep(void)
{
    /* every 61st float from -110 to -0 and from +0 to 89: about 3.7e7 points */
    const uint32_t ends[2][2] = {{0x80000000u, 0xC2DC0000u}, {0x00000000u, 0x42B20000u}};
    uint32_t worst = 0;
    long differ = 0;
    long points = 0;
    int side;
    for (side = 0; side < 2; ++side) {
        uint32_t u;
        for (u = ends[side][0]; u <= ends[side][1]; u += 61u) {
            float a;
            uint32_t d;
            (void)memcpy(&a, &u, sizeof a);
            d = ulps(icoac_priv_exp(a), expf(a));
            worst = d > worst ? d : worst;
            differ += d != 0u;
            ++points;
        }
    }
    TEST_PRINTF("host exp: %ld points, %ld differ from libm's expf, by at most %u ulp", points, differ,
                (unsigned)worst);
    TEST_ASSERT_LESS_OR_EQUAL_UINT32(1u, worst);
    TEST_ASSERT_LESS_THAN(points / 1000, differ);
}

static void test_limits(void)
{
    TEST_ASSERT_TRUE(icoac_priv_exp(0.0f) == 1.0f);
    TEST_ASSERT_TRUE(icoac_priv_exp(-0.0f) == 1.0f);
    TEST_ASSERT_TRUE(icoac_priv_exp(-104.0f) == 0.0f);
    TEST_ASSERT_TRUE(icoac_priv_exp(-1e30f) == 0.0f);
    TEST_ASSERT_TRUE(icoac_priv_exp(-INFINITY) == 0.0f);
    TEST_ASSERT_TRUE(isinf(icoac_priv_exp(89.0f)) && isinf(icoac_priv_exp(1e30f)) && isinf(icoac_priv_exp(INFINITY)));
    TEST_ASSERT_TRUE(isnan(icoac_priv_exp(NAN)));
    TEST_ASSERT_TRUE(icoac_priv_exp(1.0f) == expf(1.0f));
}

static void test_loop_and_one_call_agree(void)
{
    enum { COUNT = 4096 };
    static float in[COUNT];
    static float out[COUNT];
    int k;
    for (k = 0; k < COUNT; ++k) {
        in[k] = -120.0f + (float)k * (220.0f / (float)COUNT) + (float)(k % 7) * 1e-3f;
    }
    for (k = 0; k < COUNT; ++k) {
        out[k] = icoac_priv_exp(in[k]); /* vectorised at -O3 */
    }
    for (k = 0; k < COUNT; ++k) {
        TEST_ASSERT_EQUAL_HEX32(bits_of(one_call(in[k])), bits_of(out[k]));
    }
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
    RUN_TEST(test_within_one_ulp_of_libm_dense_sweep);
    RUN_TEST(test_limits);
    RUN_TEST(test_loop_and_one_call_agree);
    return UNITY_END();
}
