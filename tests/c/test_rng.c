/* SPDX-License-Identifier: Apache-2.0 */
/* PCG32 known answers, uniform range, polar-method normals, SplitMix64 seed mixing. */
#include "test_common.h"

#include "icoac/icoac_rng.h"

/* Reference PCG-XSH-RR 64/32 (O'Neill 2014), written from the published description. */
typedef struct {
    uint64_t state, inc;
} ref_pcg_t;

static uint32_t ref_next(ref_pcg_t *g)
{
    uint64_t old = g->state;
    uint32_t xs, rot;
    g->state = old * 6364136223846793005ULL + g->inc;
    xs = (uint32_t)(((old >> 18) ^ old) >> 27);
    rot = (uint32_t)(old >> 59);
    return rot == 0 ? xs : (xs >> rot) | (xs << (32 - rot));
}

static void ref_seed(ref_pcg_t *g, uint64_t seed, uint64_t stream)
{
    g->state = 0;
    g->inc = (stream << 1) | 1u;
    (void)ref_next(g);
    g->state += seed;
    (void)ref_next(g);
}

static void test_pcg32_published_vector(void)
{
    /* pcg32-demo of the PCG reference C library, pcg32_srandom_r(&rng, 42, 54). */
    static const uint32_t expected[6] = {0xa15c02b7u, 0x7b47f409u, 0xba1d3330u,
                                         0x83d2f293u, 0xbfa4784bu, 0xcbed606eu};
    icoac_rng_t rng;
    ref_pcg_t ref;
    int i;
    icoac_rng_seed(&rng, 42u, 54u);
    ref_seed(&ref, 42u, 54u);
    for (i = 0; i < 6; ++i) {
        const uint32_t r = ref_next(&ref);
        TEST_ASSERT_EQUAL_HEX32(expected[i], r); /* the reference implementation itself */
        TEST_ASSERT_EQUAL_HEX32(expected[i], icoac_rng_next_u32(&rng));
    }
}

static void test_pcg32_matches_reference(void)
{
    static const uint64_t seeds[][2] = {
        {0u, 0u}, {1u, 0u}, {0u, 1u}, {42u, 54u}, {0xFFFFFFFFFFFFFFFFULL, 0x7FFFFFFFFFFFFFFFULL},
        {0x853c49e6748fea9bULL, 0xda3e39cb94b95bdbULL}, {123456789u, 0x1C0ACu}};
    size_t s;
    int i;
    for (s = 0; s < sizeof seeds / sizeof seeds[0]; ++s) {
        icoac_rng_t rng;
        ref_pcg_t ref;
        icoac_rng_seed(&rng, seeds[s][0], seeds[s][1]);
        ref_seed(&ref, seeds[s][0], seeds[s][1]);
        TEST_ASSERT_TRUE(rng.increment & 1u);
        for (i = 0; i < 10000; ++i) {
            const uint32_t r = ref_next(&ref);
            const uint32_t got = icoac_rng_next_u32(&rng);
            if (got != r) {
                TEST_PRINTF("seed %u draw %d", (unsigned)s, i);
            }
            TEST_ASSERT_EQUAL_HEX32(r, got);
        }
        TEST_ASSERT_EQUAL_HEX64(ref.state, rng.state);
    }
    /* different streams with the same seed differ */
    {
        icoac_rng_t a, b;
        int same = 0;
        icoac_rng_seed(&a, 7u, 1u);
        icoac_rng_seed(&b, 7u, 2u);
        for (i = 0; i < 100; ++i) {
            same += icoac_rng_next_u32(&a) == icoac_rng_next_u32(&b);
        }
        TEST_ASSERT_LESS_THAN_INT(3, same);
    }
}

static void test_uniform_range(void)
{
    const int n = TEST_ITERATIONS(1000000, 100000); /* fewer under QEMU; 5 SE at either n */
    icoac_rng_t rng, twin;
    double sum = 0, mean, se;
    double lo = 1, hi = 0;
    int i;
    icoac_rng_seed(&rng, 2024u, 3u);
    icoac_rng_seed(&twin, 2024u, 3u);
    for (i = 0; i < n; ++i) {
        const double u = (double)icoac_rng_uniform(&rng);
        const uint32_t bits = icoac_rng_next_u32(&twin);
        /* exact mapping: top 24 bits * 2^-24 (float), 32 bits * 2^-32 (double) */
        const double expect = REAL_IS_FLOAT ? (double)(bits >> 8) / 16777216.0 : (double)bits / 4294967296.0;
        if (u != expect) {
            TEST_PRINTF("draw %d", i);
        }
        TEST_ASSERT_DOUBLE_WITHIN(0.0, expect, u); /* exactly */
        TEST_ASSERT_TRUE(u >= 0.0 && u < 1.0);
        sum += u;
        lo = u < lo ? u : lo;
        hi = u > hi ? u : hi;
    }
    /* the largest possible value is still below 1 */
    TEST_ASSERT_TRUE(REAL_IS_FLOAT ? (float)(16777215.0 / 16777216.0) < 1.0f
                                   : 4294967295.0 * (1.0 / 4294967296.0) < 1.0);
    mean = sum / n;
    se = sqrt(1.0 / 12.0 / n);
    assert_close(mean, 0.5, 5.0 * se);
    TEST_ASSERT_TRUE(lo < 1e-4 && hi > 1.0 - 1e-4);
}

static void test_normal_statistics(void)
{
    const int n = TEST_ITERATIONS(1000000, 100000); /* fewer under QEMU; 5 SE at either n */
    const double p1 = 0.68268949213708585; /* P(|Z| < 1) = erf(1/sqrt 2) */
    icoac_rng_t rng;
    double s1 = 0, s2 = 0, s4 = 0;
    long within = 0;
    int i;
    assert_close(p1, erf(1.0 / sqrt(2.0)), 1e-15);
    icoac_rng_seed(&rng, 99u, 17u);
    for (i = 0; i < n; ++i) {
        const double z = (double)icoac_rng_normal(&rng);
        TEST_ASSERT_TRUE(isfinite(z));
        s1 += z;
        s2 += z * z;
        s4 += z * z * z * z;
        within += fabs(z) < 1.0;
    }
    {
        const double mean = s1 / n;
        const double var = s2 / n - mean * mean;
        const double kurt = s4 / n;
        const double frac = (double)within / n;
        /* 5 standard errors: SE(mean) = 1/sqrt(n); SE(var) = sqrt(2/n); SE(E z^4) = sqrt((105-9)/n);
         * SE(frac) = sqrt(p(1-p)/n) */
        assert_close(mean, 0.0, 5.0 / sqrt((double)n));
        assert_close(var, 1.0, 5.0 * sqrt(2.0 / n));
        assert_close(kurt, 3.0, 5.0 * sqrt(96.0 / n));
        assert_close(frac, p1, 5.0 * sqrt(p1 * (1 - p1) / n));
    }
}

/* Polar-method pairs: from uniforms (u1, u2), u = 2 u1 - 1, v = 2 u2 - 1, points with
 * s = u^2 + v^2 outside (0, 1) are rejected; an accepted point gives u f and v f with
 * f = sqrt(-2 ln s / s). The twin generator replays the uniforms. */
static void test_normal_polar_pairs(void)
{
    icoac_rng_t rng, twin;
    int i, rejected = 0;
    icoac_rng_seed(&rng, 5u, 6u);
    icoac_rng_seed(&twin, 5u, 6u);
    for (i = 0; i < 2000; ++i) {
        const double z1 = (double)icoac_rng_normal(&rng);
        const double z2 = (double)icoac_rng_normal(&rng);
        double u, v, s, f, tol;
        for (;;) {
            u = 2.0 * (double)icoac_rng_uniform(&twin) - 1.0;
            v = 2.0 * (double)icoac_rng_uniform(&twin) - 1.0;
            s = u * u + v * v;
            if (s < 1.0 && s > 0.0) {
                break;
            }
            ++rejected;
        }
        f = sqrt(-2.0 * log(s) / s);
        tol = REAL_IS_FLOAT ? 2e-5 * (1.0 + f) : 1e-12 * (1.0 + f);
        assert_close(z1, u * f, tol);
        assert_close(z2, v * f, tol);
        /* the pair consumed exactly the twin's uniforms, rejections included */
        TEST_ASSERT_EQUAL_HEX64(twin.state, rng.state);
    }
    /* acceptance pi/4: about 0.27 rejections per pair */
    TEST_ASSERT_GREATER_THAN_INT(400, rejected);
    TEST_ASSERT_LESS_THAN_INT(700, rejected);
}

/* SplitMix64 (Steele, Lea, Flood 2014): the i-th output of a generator seeded with `seed`. */
static uint64_t ref_splitmix(uint64_t seed, uint64_t index)
{
    uint64_t x = seed, z = 0;
    uint64_t k;
    for (k = 0; k <= index; ++k) {
        x += 0x9E3779B97F4A7C15ULL;
        z = x;
        z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
        z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
        z ^= z >> 31;
    }
    return z;
}

static void test_mix_seed(void)
{
    uint64_t i;
    /* published first output of SplitMix64 seeded with 0 */
    TEST_ASSERT_EQUAL_HEX64(0xE220A8397B1DCDAFULL, ref_splitmix(0u, 0u));
    TEST_ASSERT_EQUAL_HEX64(0xE220A8397B1DCDAFULL, icoac_mix_seed(0u, 0u));
    for (i = 0; i < 50; ++i) {
        TEST_ASSERT_EQUAL_HEX64(ref_splitmix(12345u, i), icoac_mix_seed(12345u, i));
        TEST_ASSERT_EQUAL_HEX64(ref_splitmix(0xDEADBEEFULL, i), icoac_mix_seed(0xDEADBEEFULL, i));
        TEST_ASSERT_TRUE(icoac_mix_seed(1u, i) != icoac_mix_seed(2u, i));
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
    RUN_TEST(test_pcg32_published_vector);
    RUN_TEST(test_pcg32_matches_reference);
    RUN_TEST(test_uniform_range);
    RUN_TEST(test_normal_statistics);
    RUN_TEST(test_normal_polar_pairs);
    RUN_TEST(test_mix_seed);
    return UNITY_END();
}
