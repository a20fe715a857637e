#include "icoac/icoac_rng.h"

#include <math.h>

#define PCG32_MULTIPLIER 6364136223846793005ULL

void icoac_rng_seed(icoac_rng_t *rng, uint64_t seed, uint64_t stream)
{
    rng->state = 0u;
    rng->increment = (stream << 1u) | 1u;
    (void)icoac_rng_next_u32(rng);
    rng->state += seed;
    (void)icoac_rng_next_u32(rng);
    rng->spare_normal = ICOAC_R(0.0);
    rng->has_spare = 0;
}

uint32_t icoac_rng_next_u32(icoac_rng_t *rng)
{
    const uint64_t old = rng->state;
    const uint32_t xorshifted = (uint32_t)(((old >> 18u) ^ old) >> 27u);
    const uint32_t rot = (uint32_t)(old >> 59u);
    rng->state = old * PCG32_MULTIPLIER + rng->increment;
    return (xorshifted >> rot) | (xorshifted << ((0u - rot) & 31u));
}

icoac_real_t icoac_rng_uniform(icoac_rng_t *rng)
{
#if defined(ICOAC_REAL_DOUBLE) && ICOAC_REAL_DOUBLE
    return (double)icoac_rng_next_u32(rng) * (1.0 / 4294967296.0);
#else
    return (float)(icoac_rng_next_u32(rng) >> 8u) * (1.0f / 16777216.0f);
#endif
}

icoac_real_t icoac_rng_normal(icoac_rng_t *rng)
{
    const icoac_real_t two_pi = ICOAC_R(6.28318530717958647692);
    icoac_real_t u1;
    icoac_real_t u2;
    icoac_real_t radius;
    icoac_real_t angle;

    if (rng->has_spare) {
        rng->has_spare = 0;
        return rng->spare_normal;
    }
    /* u1 in (0, 1]: log never sees zero. */
    u1 = ICOAC_R(1.0) - icoac_rng_uniform(rng);
    u2 = icoac_rng_uniform(rng);
    radius = ICOAC_SQRT(ICOAC_R(-2.0) * ICOAC_LOG(u1));
    angle = two_pi * u2;
#if defined(ICOAC_REAL_DOUBLE) && ICOAC_REAL_DOUBLE
    rng->spare_normal = radius * sin(angle);
#else
    rng->spare_normal = radius * sinf(angle);
#endif
    rng->has_spare = 1;
    return radius * ICOAC_COS(angle);
}

uint64_t icoac_mix_seed(uint64_t seed, uint64_t index)
{
    uint64_t z = seed + (index + 1u) * 0x9E3779B97F4A7C15ULL;
    z = (z ^ (z >> 30u)) * 0xBF58476D1CE4E5B9ULL;
    z = (z ^ (z >> 27u)) * 0x94D049BB133111EBULL;
    return z ^ (z >> 31u);
}
