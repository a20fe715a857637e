#include "icoac_internal.h"

/* lo <= v <= hi and v not subnormal; false for NaN. */
static int within(icoac_real_t v, icoac_real_t lo, icoac_real_t hi)
{
    return v >= lo && v <= hi && icoac_zero_or_normal(v);
}

static int is_flag(int32_t v)
{
    return v == 0 || v == 1;
}

const char *icoac_status_str(icoac_status_t status)
{
    switch (status) {
    case ICOAC_OK: return "ok";
    case ICOAC_ERR_NULL: return "null pointer";
    case ICOAC_ERR_NOT_INITIALISED: return "state not initialised (call icoac_init)";
    case ICOAC_ERR_NONFINITE_INPUT: return "non-finite observation (ignored, no learning)";
    case ICOAC_ERR_NUMERIC: return "numeric failure: a value derived in this tick was not finite (force 0, nothing learned)";
    case ICOAC_ERR_BAD_MODE: return "invalid switch (mode, reflex_mode, ico_timing or a 0/1 flag)";
    case ICOAC_ERR_BAD_SCALE: return "invalid input_range (must be in [1e-6, 1e6])";
    case ICOAC_ERR_BAD_GAIN: return "invalid gain or reflex_force (must be in [0, 1e4])";
    case ICOAC_ERR_BAD_ZONE: return "invalid zone_theta or zone_x (must be in [1e-6, pi] rad and [1e-6, 1e6] m)";
    case ICOAC_ERR_BAD_ICO_RATE: return "invalid ico_rate (must be in [0, 1])";
    case ICOAC_ERR_BAD_CRITIC: return "invalid critic parameter (critic_rate [0, 10], discount [0, 1], td_clip [1e-6, 1e3], critic_range [1e-6, 1e6], critic_threshold [0, 1))";
    case ICOAC_ERR_BAD_ACTOR: return "invalid actor parameter (noise_std [1e-3, 1e3], actor_scale [0, 1e3], forgetting [0.5, 1])";
    case ICOAC_ERR_BAD_PRIOR: return "invalid prior (|mean| <= 1e6, covariance entries |c| <= 1e12, zero or normal, symmetric positive definite)";
    default: return "unknown status";
    }
}

void icoac_config_default(icoac_config_t *cfg)
{
    if (cfg == 0) {
        return;
    }
    cfg->mode = ICOAC_MODE_ICO;
    cfg->reflex_mode = ICOAC_REFLEX_UNIT;
    cfg->ico_timing = ICOAC_ICO_TIMING_CODE;
    cfg->clip_inputs = 1;
    cfg->input_range[ICOAC_IDX_X] = ICOAC_R(2.4);
    cfg->input_range[ICOAC_IDX_X_DOT] = ICOAC_R(3.5);
    cfg->input_range[ICOAC_IDX_THETA] = ICOAC_R(0.2094384);
    cfg->input_range[ICOAC_IDX_THETA_DOT] = ICOAC_R(2.0);
    cfg->gain = ICOAC_R(10.0);
    cfg->reflex_force = ICOAC_R(1.0);
    cfg->zone_theta = ICOAC_R(0.20071286397934788); /* 11.5 deg */
    cfg->zone_x = ICOAC_R(2.35);
    cfg->ico_rate = ICOAC_R(1.0e-4);
    cfg->critic_rate = ICOAC_R(0.6);
    cfg->discount = ICOAC_R(0.95);
    cfg->td_clip = ICOAC_R(1.0);
    cfg->critic_range[ICOAC_IDX_X] = ICOAC_R(2.4);
    cfg->critic_range[ICOAC_IDX_X_DOT] = ICOAC_R(3.5);
    cfg->critic_range[ICOAC_IDX_THETA] = ICOAC_R(0.2094384);
    cfg->critic_range[ICOAC_IDX_THETA_DOT] = ICOAC_R(2.0);
    cfg->critic_threshold = ICOAC_R(0.001);
    cfg->noise_std = ICOAC_R(1.0);
    cfg->actor_scale = ICOAC_R(0.5);
    cfg->forgetting = ICOAC_R(1.0);
    cfg->rl_reflex = 1;
    cfg->act_with_sample = 0;
}

icoac_status_t icoac_config_check(const icoac_config_t *cfg)
{
    int i;
    if (cfg == 0) {
        return ICOAC_ERR_NULL;
    }
    if ((cfg->mode != ICOAC_MODE_ICO && cfg->mode != ICOAC_MODE_RL) ||
        (cfg->reflex_mode != ICOAC_REFLEX_UNIT && cfg->reflex_mode != ICOAC_REFLEX_GAIN) ||
        (cfg->ico_timing != ICOAC_ICO_TIMING_CODE && cfg->ico_timing != ICOAC_ICO_TIMING_LITERAL) ||
        !is_flag(cfg->clip_inputs) || !is_flag(cfg->rl_reflex) || !is_flag(cfg->act_with_sample)) {
        return ICOAC_ERR_BAD_MODE;
    }
    for (i = 0; i < ICOAC_N_INPUTS; ++i) {
        if (!within(cfg->input_range[i], ICOAC_RANGE_MIN, ICOAC_RANGE_MAX)) {
            return ICOAC_ERR_BAD_SCALE;
        }
    }
    if (!within(cfg->gain, ICOAC_R(0.0), ICOAC_GAIN_MAX) ||
        !within(cfg->reflex_force, ICOAC_R(0.0), ICOAC_FORCE_MAX)) {
        return ICOAC_ERR_BAD_GAIN;
    }
    if (!within(cfg->zone_theta, ICOAC_ZONE_MIN, ICOAC_ZONE_THETA_MAX) ||
        !within(cfg->zone_x, ICOAC_ZONE_MIN, ICOAC_ZONE_X_MAX)) {
        return ICOAC_ERR_BAD_ZONE;
    }
    if (!within(cfg->ico_rate, ICOAC_R(0.0), ICOAC_ICO_RATE_MAX)) {
        return ICOAC_ERR_BAD_ICO_RATE;
    }
    if (!within(cfg->critic_rate, ICOAC_R(0.0), ICOAC_CRITIC_RATE_MAX) ||
        !within(cfg->discount, ICOAC_R(0.0), ICOAC_R(1.0)) ||
        !within(cfg->td_clip, ICOAC_TD_CLIP_MIN, ICOAC_TD_CLIP_MAX) ||
        !(within(cfg->critic_threshold, ICOAC_R(0.0), ICOAC_R(1.0)) && cfg->critic_threshold < ICOAC_R(1.0))) {
        return ICOAC_ERR_BAD_CRITIC;
    }
    for (i = 0; i < ICOAC_N_INPUTS; ++i) {
        if (!within(cfg->critic_range[i], ICOAC_RANGE_MIN, ICOAC_RANGE_MAX)) {
            return ICOAC_ERR_BAD_CRITIC;
        }
    }
    if (!within(cfg->noise_std, ICOAC_NOISE_STD_MIN, ICOAC_NOISE_STD_MAX) ||
        !within(cfg->actor_scale, ICOAC_R(0.0), ICOAC_ACTOR_SCALE_MAX) ||
        !within(cfg->forgetting, ICOAC_FORGETTING_MIN, ICOAC_R(1.0))) {
        return ICOAC_ERR_BAD_ACTOR;
    }
    return ICOAC_OK;
}
