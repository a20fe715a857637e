/* init, reset and the per-tick step (spec section 8). */
#include "icoac_internal.h"

#include <math.h>
#include <string.h>

icoac_status_t icoac_prior_check(const icoac_prior_t *prior)
{
    icoac_real_t lower[ICOAC_N_INPUTS][ICOAC_N_INPUTS];
    int i;
    int j;
    if (prior == 0) {
        return ICOAC_ERR_NULL;
    }
    for (i = 0; i < ICOAC_N_INPUTS; ++i) {
        if (!isfinite(prior->mean[i])) {
            return ICOAC_ERR_BAD_PRIOR;
        }
        for (j = 0; j < ICOAC_N_INPUTS; ++j) {
            if (!isfinite(prior->cov[i][j]) || prior->cov[i][j] != prior->cov[j][i]) {
                return ICOAC_ERR_BAD_PRIOR;
            }
        }
    }
    return icoac_cholesky4(prior->cov, lower) ? ICOAC_OK : ICOAC_ERR_BAD_PRIOR;
}

static void clear_trial(icoac_state_t *state)
{
    state->has_prev = 0;
    state->value_prev = ICOAC_R(0.0);
    state->noise_prev = ICOAC_R(0.0);
    memset(state->x_prev, 0, sizeof state->x_prev);
    state->active[0].pairs = 0u;
    state->active[1].pairs = 0u;
}

icoac_status_t icoac_init(const icoac_config_t *cfg, icoac_state_t *state,
                          const icoac_prior_t *prior, uint64_t seed)
{
    icoac_status_t status;
    int i;
    if (cfg == 0 || state == 0) {
        return ICOAC_ERR_NULL;
    }
    status = icoac_config_check(cfg);
    if (status == ICOAC_OK && prior != 0) {
        status = icoac_prior_check(prior);
    }
    if (status != ICOAC_OK) {
        return status;
    }
    memset(state, 0, sizeof *state);
    if (prior != 0) {
        memcpy(state->w, prior->mean, sizeof state->w);
        memcpy(state->cov, prior->cov, sizeof state->cov);
    } else {
        for (i = 0; i < ICOAC_N_INPUTS; ++i) {
            state->cov[i][i] = ICOAC_R(1.0);
        }
    }
    for (i = 0; i < ICOAC_N_INPUTS; ++i) {
        state->inv_range[i] = ICOAC_R(1.0) / cfg->input_range[i];
    }
    state->weight_norm = ICOAC_SQRT(icoac_dot4(state->w, state->w));
    icoac_rng_seed(&state->rng, seed, 0x1C0ACu);
    state->magic = ICOAC_STATE_MAGIC;
    return icoac_reset(cfg, state);
}

icoac_status_t icoac_reset(const icoac_config_t *cfg, icoac_state_t *state)
{
    if (cfg == 0 || state == 0) {
        return ICOAC_ERR_NULL;
    }
    if (state->magic != ICOAC_STATE_MAGIC) {
        return ICOAC_ERR_NOT_INITIALISED;
    }
    clear_trial(state);
    if (cfg->mode == ICOAC_MODE_RL && cfg->act_with_sample) {
        icoac_actor_sample(state);
    } else {
        icoac_copy4(state->w_act, state->w);
    }
    return ICOAC_OK;
}

/* ICO rule, code timing: act with w_t, then learn from the penalty onset at s_t. */
static void ico_code_timing(const icoac_config_t *cfg, icoac_state_t *state,
                            const icoac_real_t scaled[ICOAC_N_INPUTS], icoac_real_t penalty,
                            icoac_output_t *out)
{
    const icoac_real_t drop = state->penalty_prev - penalty;
    int i;
    out->z = icoac_dot4(state->w, scaled);
    if (drop > ICOAC_R(0.0)) {
        const icoac_real_t step = cfg->ico_rate * drop;
        for (i = 0; i < ICOAC_N_INPUTS; ++i) {
            state->w[i] += step * ICOAC_FABS(scaled[i]);
        }
        state->weight_norm = ICOAC_SQRT(icoac_dot4(state->w, state->w));
        out->q = drop;
    }
    state->penalty_prev = penalty;
}

/* ICO rule, literal timing: learn from r(t+1) - r(t) with x~(t), then act with w_{t+1}. */
static void ico_literal_timing(const icoac_config_t *cfg, icoac_state_t *state,
                               const icoac_real_t scaled[ICOAC_N_INPUTS], icoac_real_t penalty,
                               icoac_output_t *out)
{
    int i;
    if (state->has_prev) {
        const icoac_real_t drop = state->penalty_prev - penalty;
        if (drop > ICOAC_R(0.0)) {
            const icoac_real_t step = cfg->ico_rate * drop;
            for (i = 0; i < ICOAC_N_INPUTS; ++i) {
                state->w[i] += step * ICOAC_FABS(state->x_prev[i]);
            }
            state->weight_norm = ICOAC_SQRT(icoac_dot4(state->w, state->w));
            out->q = drop;
        }
    }
    state->penalty_prev = penalty;
    icoac_copy4(state->x_prev, scaled);
    state->has_prev = 1;
    out->z = icoac_dot4(state->w, scaled);
}

static void ico_tick(const icoac_config_t *cfg, icoac_state_t *state,
                     const icoac_real_t scaled[ICOAC_N_INPUTS], icoac_real_t penalty, int terminal,
                     icoac_output_t *out)
{
    if (cfg->ico_timing == ICOAC_ICO_TIMING_LITERAL) {
        ico_literal_timing(cfg, state, scaled, penalty, out);
    } else if (!terminal) {
        ico_code_timing(cfg, state, scaled, penalty, out);
    }
    if (!terminal) {
        out->force = cfg->gain * out->z + icoac_reflex_force(cfg, out->reflex);
    }
}

/* Actor-critic: learn from the transition s_t -> s (spec 8b steps 5-8), then act on s. */
static void rl_tick(const icoac_config_t *cfg, icoac_state_t *state, const icoac_real_t s[ICOAC_N_INPUTS],
                    const icoac_real_t scaled[ICOAC_N_INPUTS], int terminal, icoac_output_t *out)
{
    icoac_real_t factors[ICOAC_CRITIC_FACTORS];
    icoac_real_t value = ICOAC_R(0.0);
    const int slot_prev = state->active_slot;
    int i;
    if (!terminal) {
        icoac_critic_factors(cfg, s, factors);
        value = icoac_critic_value(cfg, state->v, factors, &state->active[slot_prev ^ 1]);
    }
    if (state->has_prev) {
        const icoac_real_t reward = terminal ? ICOAC_R(-1.0) : ICOAC_R(0.0);
        icoac_real_t delta = reward + cfg->discount * value - state->value_prev;
        icoac_real_t h[ICOAC_N_INPUTS];
        icoac_real_t innovation;
        if (delta > cfg->td_clip) {
            delta = cfg->td_clip;
        } else if (delta < -cfg->td_clip) {
            delta = -cfg->td_clip;
        }
        icoac_critic_update(state->v, &state->active[slot_prev], cfg->critic_rate * delta);
        for (i = 0; i < ICOAC_N_INPUTS; ++i) {
            h[i] = cfg->gain * state->x_prev[i];
        }
        /* u_ob - h^T mu_w, with u_ob = h^T w_act + alpha * delta * eps (Eq. 7-8). */
        innovation = icoac_dot4(h, state->w_act) - icoac_dot4(h, state->w) +
                     cfg->actor_scale * delta * state->noise_prev;
        icoac_actor_update(cfg, state, h, innovation);
        state->weight_norm = ICOAC_SQRT(icoac_dot4(state->w, state->w));
        if (!cfg->act_with_sample) {
            icoac_copy4(state->w_act, state->w);
        }
        out->td_error = delta;
    }
    out->value = value;
    out->cov_trace = icoac_trace4(ICOAC_CONST_MAT4(state->cov));
    if (terminal) {
        state->has_prev = 0;
        return;
    }
    out->z = icoac_dot4(state->w_act, scaled);
    out->noise = cfg->noise_std * icoac_rng_normal(&state->rng);
    out->force = cfg->gain * out->z + out->noise;
    if (cfg->rl_reflex) {
        out->force += icoac_reflex_force(cfg, out->reflex);
    }
    state->active_slot = slot_prev ^ 1;
    icoac_copy4(state->x_prev, scaled);
    state->value_prev = value;
    state->noise_prev = out->noise;
    state->has_prev = 1;
}

/* Field by field: newlib-nano's memset goes byte by byte. */
static void clear_output(icoac_output_t *out)
{
    out->force = ICOAC_R(0.0);
    out->z = ICOAC_R(0.0);
    out->reflex = ICOAC_R(0.0);
    out->penalty = ICOAC_R(0.0);
    out->q = ICOAC_R(0.0);
    out->weight_norm = ICOAC_R(0.0);
    out->value = ICOAC_R(0.0);
    out->td_error = ICOAC_R(0.0);
    out->noise = ICOAC_R(0.0);
    out->cov_trace = ICOAC_R(0.0);
    out->status = ICOAC_OK;
}

icoac_status_t icoac_step(const icoac_config_t *cfg, icoac_state_t *state,
                          const icoac_input_t *in, icoac_output_t *out)
{
    static const icoac_real_t zeros[ICOAC_N_INPUTS] = {ICOAC_R(0.0), ICOAC_R(0.0), ICOAC_R(0.0),
                                                        ICOAC_R(0.0)};
    icoac_real_t scaled[ICOAC_N_INPUTS];
    icoac_zone_t zone;
    int terminal;
    if (out != 0) {
        clear_output(out);
    }
    if (cfg == 0 || state == 0 || in == 0 || out == 0) {
        if (out != 0) {
            out->status = ICOAC_ERR_NULL;
        }
        return ICOAC_ERR_NULL;
    }
    if (state->magic != ICOAC_STATE_MAGIC) {
        out->status = ICOAC_ERR_NOT_INITIALISED;
        return ICOAC_ERR_NOT_INITIALISED;
    }
    state->ticks++;
    /* s_i * 0 is 0 for finite s_i and NaN for NaN or Inf: one test for all four. */
    if (!(icoac_dot4(in->s, zeros) == ICOAC_R(0.0))) {
        state->nonfinite_count++;
        out->weight_norm = state->weight_norm;
        out->status = ICOAC_ERR_NONFINITE_INPUT;
        return ICOAC_ERR_NONFINITE_INPUT;
    }
    terminal = (in->flags & ICOAC_INPUT_TERMINAL) != 0u;
    icoac_scale_inputs(cfg, state, in->s, scaled);
    zone = icoac_zone(cfg, in->s);
    out->reflex = zone.reflex;
    out->penalty = zone.penalty;
    if (cfg->mode == ICOAC_MODE_RL) {
        rl_tick(cfg, state, in->s, scaled, terminal, out);
    } else {
        ico_tick(cfg, state, scaled, zone.penalty, terminal, out);
    }
    out->weight_norm = state->weight_norm;
    out->status = ICOAC_OK;
    return ICOAC_OK;
}

icoac_status_t icoac_get_posterior(const icoac_state_t *state, icoac_prior_t *posterior)
{
    if (state == 0 || posterior == 0) {
        return ICOAC_ERR_NULL;
    }
    if (state->magic != ICOAC_STATE_MAGIC) {
        return ICOAC_ERR_NOT_INITIALISED;
    }
    memcpy(posterior->mean, state->w, sizeof posterior->mean);
    memcpy(posterior->cov, state->cov, sizeof posterior->cov);
    return ICOAC_OK;
}

uint32_t icoac_abi_version(void) { return ICOAC_ABI_VERSION; }
uint32_t icoac_sizeof_real(void) { return (uint32_t)sizeof(icoac_real_t); }
uint32_t icoac_sizeof_config(void) { return (uint32_t)sizeof(icoac_config_t); }
uint32_t icoac_sizeof_state(void) { return (uint32_t)sizeof(icoac_state_t); }
uint32_t icoac_sizeof_input(void) { return (uint32_t)sizeof(icoac_input_t); }
uint32_t icoac_sizeof_output(void) { return (uint32_t)sizeof(icoac_output_t); }
uint32_t icoac_sizeof_prior(void) { return (uint32_t)sizeof(icoac_prior_t); }
