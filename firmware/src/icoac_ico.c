/* Input scaling, reflex/penalty zone and the ICO rule's building blocks (spec 4-5). */
#include "icoac_internal.h"

static icoac_real_t clip_unit(icoac_real_t a)
{
    if (a > ICOAC_R(1.0)) {
        return ICOAC_R(1.0);
    }
    if (a < ICOAC_R(-1.0)) {
        return ICOAC_R(-1.0);
    }
    return a;
}

void icoac_scale_inputs(const icoac_config_t *cfg, const icoac_real_t s[ICOAC_N_INPUTS],
                        icoac_real_t scaled[ICOAC_N_INPUTS])
{
    int i;
    for (i = 0; i < ICOAC_N_INPUTS; ++i) {
        const icoac_real_t a = s[i] / cfg->input_range[i];
        scaled[i] = cfg->clip_inputs ? clip_unit(a) : a;
    }
}

icoac_zone_t icoac_zone(const icoac_config_t *cfg, const icoac_real_t s[ICOAC_N_INPUTS])
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

icoac_real_t icoac_reflex_force(const icoac_config_t *cfg, icoac_real_t reflex)
{
    return cfg->reflex_mode == ICOAC_REFLEX_GAIN ? cfg->gain * reflex : cfg->reflex_force * reflex;
}

icoac_real_t icoac_dot4(const icoac_real_t a[ICOAC_N_INPUTS], const icoac_real_t b[ICOAC_N_INPUTS])
{
    /* Fixed pairwise order: the same result on every target. */
    return (a[0] * b[0] + a[1] * b[1]) + (a[2] * b[2] + a[3] * b[3]);
}
