/* Private helpers of the icoac library; not installed, not part of the API. */
#ifndef ICOAC_INTERNAL_H
#define ICOAC_INTERNAL_H

#include <math.h>

#include "icoac/icoac.h"

/* C99 will not pass T[4][4] to const T[4][4] implicitly. */
#define ICOAC_CONST_MAT4(m) ((const icoac_real_t(*)[ICOAC_N_INPUTS])(m))

#define ICOAC_STATE_MAGIC 0x1C0AC001u

/* Reflex U and penalty r of one observation (Eq. 4). */
typedef struct {
    icoac_real_t reflex;
    icoac_real_t penalty;
} icoac_zone_t;

/* Hot-path helpers: static inline so every tick is one straight-line function. */
static inline icoac_real_t icoac_clip_unit(icoac_real_t a)
{
    return a > ICOAC_R(1.0) ? ICOAC_R(1.0) : (a < ICOAC_R(-1.0) ? ICOAC_R(-1.0) : a);
}

/* x~_i = clip(s_i / range_i), with 1 / range_i precomputed by icoac_init. */
static inline void icoac_scale_inputs(const icoac_config_t *cfg, const icoac_state_t *state,
                                      const icoac_real_t s[ICOAC_N_INPUTS],
                                      icoac_real_t scaled[ICOAC_N_INPUTS])
{
    int i;
    for (i = 0; i < ICOAC_N_INPUTS; ++i) {
        const icoac_real_t a = s[i] * state->inv_range[i];
        scaled[i] = cfg->clip_inputs ? icoac_clip_unit(a) : a;
    }
}

/* Eq. (4); the first branch wins when both apply. */
static inline icoac_zone_t icoac_zone(const icoac_config_t *cfg, const icoac_real_t s[ICOAC_N_INPUTS])
{
    icoac_zone_t zone;
    const icoac_real_t x = s[ICOAC_IDX_X];
    const icoac_real_t theta = s[ICOAC_IDX_THETA];
    zone.reflex = ICOAC_R(0.0);
    zone.penalty = ICOAC_R(0.0);
    if (theta > cfg->zone_theta || x < -cfg->zone_x) {
        zone.reflex = ICOAC_R(1.0);
        zone.penalty = ICOAC_R(-1.0);
    } else if (theta < -cfg->zone_theta || x > cfg->zone_x) {
        zone.reflex = ICOAC_R(-1.0);
        zone.penalty = ICOAC_R(-1.0);
    }
    return zone;
}

/* Force of the reflex U (spec A2). */
static inline icoac_real_t icoac_reflex_force(const icoac_config_t *cfg, icoac_real_t reflex)
{
    return cfg->reflex_mode == ICOAC_REFLEX_GAIN ? cfg->gain * reflex : cfg->reflex_force * reflex;
}

/* Fixed pairwise order: the same result on every target. */
static inline icoac_real_t icoac_dot4(const icoac_real_t a[ICOAC_N_INPUTS],
                                      const icoac_real_t b[ICOAC_N_INPUTS])
{
    return (a[0] * b[0] + a[1] * b[1]) + (a[2] * b[2] + a[3] * b[3]);
}

/* Critic (icoac_critic.c). */
void icoac_critic_factors(const icoac_config_t *cfg, const icoac_real_t s[ICOAC_N_INPUTS],
                          icoac_real_t factors[ICOAC_CRITIC_FACTORS]);
icoac_real_t icoac_critic_value(const icoac_config_t *cfg, const icoac_real_t v[ICOAC_CRITIC_UNITS],
                                const icoac_real_t factors[ICOAC_CRITIC_FACTORS]);
void icoac_critic_update(const icoac_config_t *cfg, icoac_real_t v[ICOAC_CRITIC_UNITS],
                         const icoac_real_t factors[ICOAC_CRITIC_FACTORS], icoac_real_t step);

/* Actor (icoac_actor.c). */
void icoac_actor_update(const icoac_config_t *cfg, icoac_state_t *state,
                        const icoac_real_t h[ICOAC_N_INPUTS], icoac_real_t innovation);
void icoac_actor_sample(icoac_state_t *state);
icoac_real_t icoac_trace4(const icoac_real_t m[ICOAC_N_INPUTS][ICOAC_N_INPUTS]);
int icoac_cholesky4(const icoac_real_t m[ICOAC_N_INPUTS][ICOAC_N_INPUTS],
                    icoac_real_t lower[ICOAC_N_INPUTS][ICOAC_N_INPUTS]);

#endif /* ICOAC_INTERNAL_H */
