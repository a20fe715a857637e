/* Features of a tick (method.md: input scaling, zone, force; A2): input scaling, the penalty
 * zone with its reflex, and the reflex force. Private; static inline, as they run on every tick
 * of every mode. */
#ifndef ICOAC_FEATURES_H
#define ICOAC_FEATURES_H

#include "icoac_priv.h"

/* Reflex U and penalty r of one observation (Eq. 4). */
typedef struct {
    icoac_real_t reflex;
    icoac_real_t penalty;
} icoac_priv_zone_t;

static inline icoac_real_t icoac_priv_clip_unit(icoac_real_t a)
{
    return a > ICOAC_R(1.0) ? ICOAC_R(1.0) : (a < ICOAC_R(-1.0) ? ICOAC_R(-1.0) : a);
}

/* x~_i = clip(s_i / range_i), with 1 / range_i precomputed by icoac_init. */
static inline void icoac_priv_scale_inputs(const icoac_policy_config_t *policy, const icoac_priv_state_t *st,
                                           const icoac_real_t s[ICOAC_N_INPUTS],
                                           icoac_real_t scaled[ICOAC_N_INPUTS])
{
    int i;
    for (i = 0; i < ICOAC_N_INPUTS; ++i) {
        const icoac_real_t a = s[i] * st->inv_range[i];
        scaled[i] = policy->clip_inputs ? icoac_priv_clip_unit(a) : a;
    }
}

/* Eq. (4); the first branch wins when both apply. */
static inline icoac_priv_zone_t icoac_priv_zone(const icoac_policy_config_t *policy,
                                                const icoac_real_t s[ICOAC_N_INPUTS])
{
    icoac_priv_zone_t zone;
    const icoac_real_t x = s[ICOAC_IDX_X];
    const icoac_real_t theta = s[ICOAC_IDX_THETA];
    zone.reflex = ICOAC_R(0.0);
    zone.penalty = ICOAC_R(0.0);
    if (theta > policy->zone_theta || x < -policy->zone_x) {
        zone.reflex = ICOAC_R(1.0);
        zone.penalty = ICOAC_R(-1.0);
    } else if (theta < -policy->zone_theta || x > policy->zone_x) {
        zone.reflex = ICOAC_R(-1.0);
        zone.penalty = ICOAC_R(-1.0);
    }
    return zone;
}

/* Force of the reflex U (method.md, A2). */
static inline icoac_real_t icoac_priv_reflex_force(const icoac_policy_config_t *policy, icoac_real_t reflex)
{
    return policy->reflex_mode == ICOAC_REFLEX_GAIN ? policy->gain * reflex : policy->reflex_force * reflex;
}

#endif /* ICOAC_FEATURES_H */
