/* Lifecycle of a controller state: init, reset per trial, and the accessors. */
#include "icoac_priv.h"

static void clear_trial(icoac_priv_state_t *st)
{
    st->has_prev = 0;
    st->value_prev = ICOAC_R(0.0);
    st->noise_prev = ICOAC_R(0.0);
    memset(st->x_prev, 0, sizeof st->x_prev);
    icoac_priv_critic_clear(&st->active[0]);
    icoac_priv_critic_clear(&st->active[1]);
    st->trial_ticks = 0u;
    memset(&st->batch, 0, sizeof st->batch);
}

icoac_status_t icoac_init(const icoac_config_t *cfg, icoac_state_t *state, const icoac_prior_t *prior,
                          uint64_t seed)
{
    icoac_priv_state_t *st = icoac_priv_state(state);
    icoac_status_t status;
    int i;
    if (cfg == 0 || state == 0) {
        return ICOAC_ERR_NULL;
    }
    status = icoac_config_check(cfg);
    if (status == ICOAC_OK && prior != 0) {
        status = icoac_prior_check(prior);
    }
    if (status == ICOAC_OK && cfg->mode == ICOAC_MODE_SEARCH) {
        icoac_real_t identity[ICOAC_N_INPUTS][ICOAC_N_INPUTS] = {{ICOAC_R(0.0)}};
        for (i = 0; i < ICOAC_N_INPUTS; ++i) {
            identity[i][i] = ICOAC_R(1.0);
        }
        if (!icoac_priv_search_prior_ok(&cfg->search, prior != 0 ? prior->cov : ICOAC_PRIV_CONST_MAT4(identity))) {
            status = ICOAC_ERR_BAD_PRIOR;
        }
    }
    if (status != ICOAC_OK) {
        return status;
    }
    memset(state, 0, sizeof *state);
    if (prior != 0) {
        memcpy(st->w, prior->mean, sizeof st->w);
        memcpy(st->cov_buffer[0], prior->cov, sizeof st->cov_buffer[0]);
    } else {
        for (i = 0; i < ICOAC_N_INPUTS; ++i) {
            st->cov_buffer[0][i][i] = ICOAC_R(1.0);
        }
    }
    for (i = 0; i < ICOAC_N_INPUTS; ++i) {
        st->inv_range[i] = ICOAC_R(1.0) / cfg->policy.input_range[i];
    }
    if (cfg->mode == ICOAC_MODE_SEARCH) {
        icoac_priv_search_init(&cfg->search, st);
    }
    st->weight_norm = ICOAC_PRIV_SQRT(icoac_priv_dot4(st->w, st->w));
    icoac_rng_seed(&st->rng, seed, 0x1C0ACu);
    st->magic = ICOAC_PRIV_STATE_MAGIC;
    return icoac_reset(cfg, state);
}

icoac_status_t icoac_reset(const icoac_config_t *cfg, icoac_state_t *state)
{
    icoac_priv_state_t *st = icoac_priv_state(state);
    if (cfg == 0 || state == 0) {
        return ICOAC_ERR_NULL;
    }
    if (st->magic != ICOAC_PRIV_STATE_MAGIC) {
        return ICOAC_ERR_NOT_INITIALISED;
    }
    clear_trial(st);
    if (cfg->mode == ICOAC_MODE_RL && cfg->actor.act_with_sample) {
        icoac_priv_actor_sample(st);
    } else if (cfg->mode == ICOAC_MODE_SEARCH) {
        icoac_priv_search_sample(st);
    } else {
        icoac_priv_copy4(st->w_act, st->w);
    }
    return ICOAC_OK;
}

icoac_status_t icoac_get_posterior(const icoac_state_t *state, icoac_prior_t *posterior)
{
    const icoac_priv_state_t *st = icoac_priv_state_c(state);
    if (state == 0 || posterior == 0) {
        return ICOAC_ERR_NULL;
    }
    if (st->magic != ICOAC_PRIV_STATE_MAGIC) {
        return ICOAC_ERR_NOT_INITIALISED;
    }
    memcpy(posterior->mean, st->w, sizeof posterior->mean);
    memcpy(posterior->cov, icoac_priv_cov_c(st), sizeof posterior->cov);
    return ICOAC_OK;
}

icoac_status_t icoac_get_counters(const icoac_state_t *state, icoac_counters_t *counters)
{
    const icoac_priv_state_t *st = icoac_priv_state_c(state);
    if (state == 0 || counters == 0) {
        return ICOAC_ERR_NULL;
    }
    if (st->magic != ICOAC_PRIV_STATE_MAGIC) {
        return ICOAC_ERR_NOT_INITIALISED;
    }
    *counters = st->counters;
    return ICOAC_OK;
}

uint32_t icoac_abi_version(void) { return ICOAC_ABI_VERSION; }
uint32_t icoac_sizeof_real(void) { return (uint32_t)sizeof(icoac_real_t); }
uint32_t icoac_sizeof_config(void) { return (uint32_t)sizeof(icoac_config_t); }
uint32_t icoac_sizeof_state(void) { return (uint32_t)sizeof(icoac_state_t); }
uint32_t icoac_sizeof_input(void) { return (uint32_t)sizeof(icoac_input_t); }
uint32_t icoac_sizeof_output(void) { return (uint32_t)sizeof(icoac_output_t); }
uint32_t icoac_sizeof_prior(void) { return (uint32_t)sizeof(icoac_prior_t); }
