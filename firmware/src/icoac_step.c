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
        const icoac_real_t m = prior->mean[i];
        if (!(ICOAC_FABS(m) <= ICOAC_PRIOR_MEAN_MAX) || !icoac_zero_or_normal(m)) {
            return ICOAC_ERR_BAD_PRIOR;
        }
        for (j = 0; j < ICOAC_N_INPUTS; ++j) {
            const icoac_real_t c = prior->cov[i][j];
            if (!(ICOAC_FABS(c) <= ICOAC_PRIOR_COV_MAX) || !icoac_zero_or_normal(c) || c != prior->cov[j][i]) {
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

/* The per-tick caches both tick kinds stage and commit together. */
static void commit_trial_cache(icoac_state_t *state, const icoac_real_t scaled[ICOAC_N_INPUTS])
{
    icoac_copy4(state->x_prev, scaled);
    state->has_prev = 1;
}

/* ICO weights after a penalty onset of size drop > 0 (Eq. 2-3), and their norm. */
static icoac_real_t ico_learn(const icoac_config_t *cfg, const icoac_state_t *state,
                              const icoac_real_t trace[ICOAC_N_INPUTS], icoac_real_t drop,
                              icoac_real_t w[ICOAC_N_INPUTS])
{
    const icoac_real_t step = cfg->ico_rate * drop;
    int i;
    for (i = 0; i < ICOAC_N_INPUTS; ++i) {
        w[i] = state->w[i] + step * ICOAC_FABS(trace[i]);
    }
    return ICOAC_SQRT(icoac_dot4(w, w));
}

static void ico_commit(icoac_state_t *state, const icoac_real_t w[ICOAC_N_INPUTS], icoac_real_t norm)
{
    icoac_copy4(state->w, w);
    state->weight_norm = norm;
}

/* ICO rule, code timing: act with w_t, then learn from the penalty onset at s_t. Failure
 * states are not seen. The force and the new weights' norm (finite only if every w_i is) are
 * checked before anything is stored; returns 0, with the state untouched, when one is not. */
static int ico_code_timing(const icoac_config_t *cfg, icoac_state_t *state,
                           const icoac_real_t scaled[ICOAC_N_INPUTS], icoac_real_t penalty, int terminal,
                           icoac_output_t *out)
{
    const icoac_real_t drop = state->penalty_prev - penalty;
    icoac_real_t w[ICOAC_N_INPUTS];
    icoac_real_t norm = ICOAC_R(0.0);
    icoac_real_t z;
    icoac_real_t force;
    if (terminal) {
        return 1;
    }
    z = icoac_dot4(state->w, scaled);
    force = cfg->gain * z + icoac_reflex_force(cfg, out->reflex);
    if (drop > ICOAC_R(0.0)) {
        norm = ico_learn(cfg, state, scaled, drop, w);
    }
    if (!icoac_finite(force) || !icoac_finite(norm)) {
        return 0;
    }
    if (drop > ICOAC_R(0.0)) {
        ico_commit(state, w, norm);
        out->q = drop;
    }
    state->penalty_prev = penalty;
    out->z = z;
    out->force = force;
    return 1;
}

/* ICO rule, literal timing: learn from r(t+1) - r(t) with x~(t), then act with w_{t+1}; a
 * terminal tick learns and outputs no force. Checked like the code timing (z stands for the
 * force on a terminal tick). */
static int ico_literal_timing(const icoac_config_t *cfg, icoac_state_t *state,
                              const icoac_real_t scaled[ICOAC_N_INPUTS], icoac_real_t penalty,
                              int terminal, icoac_output_t *out)
{
    const icoac_real_t drop = state->penalty_prev - penalty;
    const int learn = state->has_prev && drop > ICOAC_R(0.0);
    icoac_real_t w[ICOAC_N_INPUTS];
    icoac_real_t norm = ICOAC_R(0.0);
    icoac_real_t z;
    icoac_real_t force = ICOAC_R(0.0);
    if (learn) {
        norm = ico_learn(cfg, state, state->x_prev, drop, w);
    }
    z = icoac_dot4(learn ? w : state->w, scaled);
    if (!terminal) {
        force = cfg->gain * z + icoac_reflex_force(cfg, out->reflex);
    }
    if (!icoac_finite(terminal ? z : force) || !icoac_finite(norm)) {
        return 0;
    }
    if (learn) {
        ico_commit(state, w, norm);
        out->q = drop;
    }
    state->penalty_prev = penalty;
    commit_trial_cache(state, scaled);
    out->z = z;
    out->force = force;
    return 1;
}

/* delta clipped to +-td_clip. */
static icoac_real_t clip_td(icoac_real_t delta, icoac_real_t td_clip)
{
    return delta > td_clip ? td_clip : (delta < -td_clip ? -td_clip : delta);
}

/* Off-diagonal entries of a symmetric 4x4 matrix finite (its trace covers the diagonal). */
static int off_diagonal_finite(const icoac_real_t m[ICOAC_N_INPUTS][ICOAC_N_INPUTS])
{
    return icoac_all_finite(&m[0][1], 3) && icoac_all_finite(&m[1][2], 2) && icoac_all_finite(&m[2][3], 1);
}

/* Actor-critic tick: learn from the transition s_t -> s (spec 8b steps 5-8), then act on s.
 * V(s), delta, the actor's candidate posterior and the force are staged; the critic and the
 * actor are updated, and the caches advanced, only when they are finite. Returns 0, with the
 * state untouched, otherwise. Checked: V(s), delta, |w| (covers every w_i), the trace of
 * Sigma_w (covers its diagonal) and its off-diagonal, and G z (+ reflex). Not checked, as
 * finite by the configuration's bounds: the noise (|eps| < 1e8 sigma_u), hence the force
 * G z + eps + reflex; and the critic weights, which move by at most critic_rate * td_clip
 * <= 1e4 per tick. */
static int rl_tick(const icoac_config_t *cfg, icoac_state_t *state, const icoac_real_t s[ICOAC_N_INPUTS],
                   const icoac_real_t scaled[ICOAC_N_INPUTS], int terminal, icoac_output_t *out)
{
    icoac_real_t factors[ICOAC_CRITIC_FACTORS];
    icoac_real_t w[ICOAC_N_INPUTS];
    icoac_real_t cov[ICOAC_N_INPUTS][ICOAC_N_INPUTS];
    icoac_real_t checked[5]; /* V(s), delta, |w|, trace of Sigma_w, G z (+ reflex) */
    const int slot_prev = state->active_slot;
    const int learn = state->has_prev;
    const icoac_real_t *w_act = cfg->act_with_sample ? state->w_act : (learn ? w : state->w);
    icoac_real_t z = ICOAC_R(0.0);
    icoac_real_t noise;
    int i;
    checked[0] = ICOAC_R(0.0);
    checked[4] = ICOAC_R(0.0);
    if (!terminal) {
        icoac_critic_factors(cfg, s, factors);
        /* fills the spare slot: the current one stays the eligibility of this update */
        checked[0] = icoac_critic_value(cfg, state->v, factors, &state->active[slot_prev ^ 1]);
    }
    if (learn) {
        const icoac_real_t reward = terminal ? ICOAC_R(-1.0) : ICOAC_R(0.0);
        icoac_real_t h[ICOAC_N_INPUTS];
        icoac_real_t innovation;
        checked[1] = clip_td(reward + cfg->discount * checked[0] - state->value_prev, cfg->td_clip);
        for (i = 0; i < ICOAC_N_INPUTS; ++i) {
            h[i] = cfg->gain * state->x_prev[i];
        }
        /* u_ob - h^T mu_w, with u_ob = h^T w_act + alpha * delta * eps (Eq. 7-8). */
        innovation = icoac_dot4(h, state->w_act) - icoac_dot4(h, state->w) +
                     cfg->actor_scale * checked[1] * state->noise_prev;
        icoac_actor_update(cfg, state, h, innovation, w, cov);
        checked[2] = ICOAC_SQRT(icoac_dot4(w, w));
        checked[3] = icoac_trace4(ICOAC_CONST_MAT4(cov));
        if (!off_diagonal_finite(ICOAC_CONST_MAT4(cov))) {
            return 0;
        }
    } else {
        checked[1] = ICOAC_R(0.0);
        checked[2] = state->weight_norm;
        checked[3] = icoac_trace4(ICOAC_CONST_MAT4(state->cov));
    }
    if (!terminal) {
        z = icoac_dot4(w_act, scaled);
        checked[4] = cfg->gain * z;
    }
    if (!icoac_all_finite(checked, 5)) {
        return 0;
    }
    /* commit */
    if (learn) {
        icoac_critic_update(state->v, &state->active[slot_prev], cfg->critic_rate * checked[1]);
        icoac_copy4(state->w, w);
        for (i = 0; i < ICOAC_N_INPUTS; ++i) {
            icoac_copy4(state->cov[i], cov[i]);
        }
        state->weight_norm = checked[2];
        if (!cfg->act_with_sample) {
            icoac_copy4(state->w_act, w);
        }
        out->td_error = checked[1];
    }
    out->value = checked[0];
    out->cov_trace = checked[3];
    if (terminal) {
        state->has_prev = 0;
        return 1;
    }
    noise = cfg->noise_std * icoac_rng_normal(&state->rng);
    out->z = z;
    out->noise = noise;
    out->force = checked[4] + noise;
    if (cfg->rl_reflex) {
        out->force += icoac_reflex_force(cfg, out->reflex);
    }
    state->active_slot = slot_prev ^ 1;
    state->value_prev = checked[0];
    state->noise_prev = noise;
    commit_trial_cache(state, scaled);
    return 1;
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
    int ok;
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
        ok = rl_tick(cfg, state, in->s, scaled, terminal, out);
    } else if (cfg->ico_timing == ICOAC_ICO_TIMING_LITERAL) {
        ok = ico_literal_timing(cfg, state, scaled, zone.penalty, terminal, out);
    } else {
        ok = ico_code_timing(cfg, state, scaled, zone.penalty, terminal, out);
    }
    if (!ok) {
        state->numeric_fault_count++;
        clear_output(out);
        out->weight_norm = state->weight_norm;
        out->status = ICOAC_ERR_NUMERIC;
        return ICOAC_ERR_NUMERIC;
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
