/* SPDX-License-Identifier: Apache-2.0 */
#include "icoac_priv.h"

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
    /* the increment is odd (icoac_rng_seed); forced so, so that a corrupted one cannot stall the
     * generator on a fixed point (state 0, increment 0) */
    rng->state = old * PCG32_MULTIPLIER + (rng->increment | 1u);
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

/* Marsaglia's polar method: a point (u, v) uniform in the unit disc gives two independent
 * normals u f and v f, f = sqrt(-2 ln(s) / s), s = u^2 + v^2. No sine or cosine (costly in
 * soft float); a point is accepted with probability pi/4, so a pair takes 2.55 uniforms on
 * average and more than 8 tries with probability below 5e-6. */
icoac_real_t icoac_rng_normal(icoac_rng_t *rng)
{
    icoac_real_t u;
    icoac_real_t v;
    icoac_real_t s;
    icoac_real_t f;
    if (rng->has_spare != 0) {
        rng->has_spare = 0;
        return rng->spare_normal;
    }
    do {
        u = ICOAC_R(2.0) * icoac_rng_uniform(rng) - ICOAC_R(1.0);
        v = ICOAC_R(2.0) * icoac_rng_uniform(rng) - ICOAC_R(1.0);
        s = u * u + v * v;
    } while (s >= ICOAC_R(1.0) || s == ICOAC_R(0.0));
    f = ICOAC_PRIV_SQRT(ICOAC_R(-2.0) * icoac_priv_log(s) / s);
    rng->spare_normal = v * f;
    rng->has_spare = 1;
    return u * f;
}

uint64_t icoac_mix_seed(uint64_t seed, uint64_t index)
{
    uint64_t z = seed + (index + 1u) * 0x9E3779B97F4A7C15ULL;
    z = (z ^ (z >> 30u)) * 0xBF58476D1CE4E5B9ULL;
    z = (z ^ (z >> 27u)) * 0x94D049BB133111EBULL;
    return z ^ (z >> 31u);
}
