/* SPDX-License-Identifier: Apache-2.0 */
/* icoac: PCG32 random numbers and a Gaussian transform, state owned by the caller. */
#ifndef ICOAC_RNG_H
#define ICOAC_RNG_H

#include "icoac_types.h"

#ifdef __cplusplus
extern "C" {
#endif

/* PCG-XSH-RR 64/32 generator (O'Neill 2014) plus one cached Gaussian. */
typedef struct {
    uint64_t state;             /* LCG state */
    uint64_t increment;         /* stream selector, always odd */
    icoac_real_t spare_normal;  /* second value of the last polar-method pair */
    int32_t has_spare;          /* 1 when spare_normal is valid */
} icoac_rng_t;

/* Seed a generator; different (seed, stream) pairs give independent sequences. */
void icoac_rng_seed(icoac_rng_t *rng, uint64_t seed, uint64_t stream);

/* Next 32 uniformly distributed bits. */
uint32_t icoac_rng_next_u32(icoac_rng_t *rng);

/* Uniform real in [0, 1) (24 bits for float, 32 bits for double). */
icoac_real_t icoac_rng_uniform(icoac_rng_t *rng);

/* Standard normal N(0, 1) by the Marsaglia polar method (pairs; one cached). */
icoac_real_t icoac_rng_normal(icoac_rng_t *rng);

/* SplitMix64 finaliser: decorrelates derived seeds (e.g. seed per grid cell). */
uint64_t icoac_mix_seed(uint64_t seed, uint64_t index);

#ifdef __cplusplus
}
#endif

#endif /* ICOAC_RNG_H */
