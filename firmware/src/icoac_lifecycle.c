/* SPDX-License-Identifier: Apache-2.0 */
/* Lifecycle of a controller state: init, live retuning, reset per trial (with the check of a
 * state's content), and the accessors. */
#include "icoac_priv.h"

static void clear_trial(icoac_priv_state_t *st)
{
    st->has_prev = 0;
    st->value_prev = ICOAC_R(0.0);
    st->noise_prev = ICOAC_R(0.0);
    (void)memset(st->x_prev, 0, sizeof st->x_prev);
    icoac_priv_critic_clear(&st->active[0]);
    icoac_priv_critic_clear(&st->active[1]);
    st->trial_ticks = 0u;
    (void)memset(&st->batch, 0, sizeof st->batch);
}

/* 1 when the task's rule table is laid out as the cart-pole preset's: 4 inputs, 4 rules on the
 * preset's inputs and sides (any thresholds and reflexes). */
static int cartpole_rules(const icoac_task_config_t *task)
{
    static const int32_t rule_input[ICOAC_CARTPOLE_RULES] = ICOAC_PRIV_CARTPOLE_RULE_INPUTS;
    static const int32_t rule_side[ICOAC_CARTPOLE_RULES] = ICOAC_PRIV_CARTPOLE_RULE_SIDES;
    int same = task->n_inputs == ICOAC_CARTPOLE_INPUTS && task->late_source == ICOAC_LATE_RULES &&
               task->n_rules == ICOAC_CARTPOLE_RULES;
    int k;
    for (k = 0; same && k < ICOAC_CARTPOLE_RULES; ++k) {
        same = task->rule_input[k] == rule_input[k] && task->rule_side[k] == rule_side[k];
    }
    return same;
}

/* What the tick takes from the configuration in force, derived once (and the state's batch
 * stamp cleared): task.input_sign /
 * policy.input_range (0 past the task's inputs; the sign folded in, so a tick pays nothing for
 * it, and +1 gives 1 / range bit for bit), the critic's geometry, the shape tags and the search's
 * floors. */
static void derive(icoac_priv_state_t *st)
{
    const int n = icoac_priv_inputs(&st->config);
    int i;
    st->batch_token = 0u; /* a batch that loaded the state loads it again */
    for (i = 0; i < ICOAC_MAX_INPUTS; ++i) {
        const icoac_real_t sign = (st->config.task.input_sign[i] < 0) ? ICOAC_R(-1.0) : ICOAC_R(1.0);
        st->inv_range[i] = i < n ? sign / st->config.policy.input_range[i] : ICOAC_R(0.0);
    }
    icoac_priv_critic_grid(&st->config, &st->grid);
    if (cartpole_rules(&st->config.task) != 0) {
        st->grid.shape |= ICOAC_PRIV_SHAPE_CARTPOLE_RULES;
    }
    if (st->config.mode == ICOAC_MODE_SEARCH) {
        icoac_priv_search_floors(&st->config.search, &st->search);
    }
}

/* 1 when the state holds what the library writes: a configuration icoac_config_check accepts,
 * slots 0 or 1, finite weights and covariance, a cached normal the generator can draw (the RL
 * tick's force is finite only for such noise), and (search) a recorded count inside
 * the batch arrays and a positive prior variance. Derived values are not checked: reset derives
 * them again. The 162 critic weights are not either (a per-trial cost the size of a tick's): the
 * library never writes a non-finite one, and a corrupted one makes the ticks that read it
 * ICOAC_ERR_NUMERIC. */
static int state_ok(const icoac_priv_state_t *st)
{
    const icoac_priv_search_t *search = &st->search;
    const int n = icoac_priv_inputs(&st->config);
    int i;
    if (icoac_config_check(&st->config) != ICOAC_OK || (st->cov_slot & ~1) != 0 || (st->active_slot & ~1) != 0 ||
        (st->rng.has_spare & ~1) != 0 || !(ICOAC_PRIV_FABS(st->rng.spare_normal) <= ICOAC_PRIV_NORMAL_MAX)) {
        return 0;
    }
    if (!icoac_priv_all_finite(st->w, ICOAC_MAX_INPUTS) || !icoac_priv_finite(st->weight_norm) ||
        !icoac_priv_all_finite(&icoac_priv_cov_c(st)[0][0], ICOAC_MAX_INPUTS * ICOAC_MAX_INPUTS)) {
        return 0;
    }
    if (st->config.mode != ICOAC_MODE_SEARCH) {
        return 1;
    }
    if (search->count < 0 || search->count >= ICOAC_SEARCH_BATCH_MAX ||
        !icoac_priv_all_finite(&search->lower[0][0], ICOAC_MAX_INPUTS * ICOAC_MAX_INPUTS)) {
        return 0;
    }
    for (i = 0; i < n; ++i) {
        if (!(search->prior_var[i] > ICOAC_R(0.0)) || !icoac_priv_finite(search->prior_var[i])) {
            return 0;
        }
    }
    return 1;
}

/* icoac_init but its icoac_reset: out of line, so that its frame (the staged prior) is released
 * before the reset's. */
ICOAC_PRIV_NOINLINE static icoac_status_t init_state(const icoac_config_t *cfg, icoac_state_t *state,
                                                     const icoac_prior_t *prior, uint64_t seed)
{
    icoac_priv_state_t *st = icoac_priv_state(state);
    icoac_status_t status;
    icoac_real_t mean[ICOAC_MAX_INPUTS] = {ICOAC_R(0.0)};
    icoac_real_t cov[ICOAC_MAX_INPUTS][ICOAC_MAX_INPUTS] = {{ICOAC_R(0.0)}};
    int n;
    int i;
    int j;
    if ((cfg == NULL) || (state == NULL)) {
        return ICOAC_ERR_NULL;
    }
    status = icoac_config_check(cfg);
    if (status != ICOAC_OK) {
        return status;
    }
    n = (int)cfg->task.n_inputs;
    if (prior != NULL) {
        status = icoac_prior_check(prior, cfg->task.n_inputs);
    }
    /* the prior's leading n entries (N(0, I) without one), 0 past them */
    for (i = 0; i < n; ++i) {
        mean[i] = (prior != NULL) ? prior->mean[i] : ICOAC_R(0.0);
        for (j = 0; j < n; ++j) {
            cov[i][j] = (prior != NULL) ? prior->cov[i][j] : ((i == j) ? ICOAC_R(1.0) : ICOAC_R(0.0));
        }
    }
    if (status == ICOAC_OK && cfg->mode == ICOAC_MODE_SEARCH &&
        !icoac_priv_search_prior_ok(&cfg->search, ICOAC_PRIV_CONST_MAT(cov), n)) {
        status = ICOAC_ERR_BAD_PRIOR;
    }
    if (status != ICOAC_OK) {
        return status;
    }
    (void)memset(state, 0, sizeof *state);
    st->config = *cfg;
    (void)memcpy(st->w, mean, sizeof st->w);
    (void)memcpy(st->cov_buffer[0], cov, sizeof st->cov_buffer[0]);
    if (cfg->mode == ICOAC_MODE_SEARCH) {
        icoac_priv_search_init(&st->config.search, st);
    }
    st->weight_norm = ICOAC_PRIV_SQRT(icoac_priv_dot(st->w, st->w));
    icoac_rng_seed(&st->rng, seed, 0x1C0ACu);
    st->magic = ICOAC_PRIV_STATE_MAGIC;
    return ICOAC_OK;
}

icoac_status_t icoac_init(const icoac_config_t *cfg, icoac_state_t *state, const icoac_prior_t *prior,
                          uint64_t seed)
{
    const icoac_status_t status = init_state(cfg, state, prior, seed);
    return status != ICOAC_OK ? status : icoac_reset(state);
}

icoac_status_t icoac_retune(icoac_state_t *state, const icoac_config_t *cfg)
{
    icoac_priv_state_t *st = icoac_priv_state(state);
    icoac_status_t status;
    if ((cfg == NULL) || (state == NULL)) {
        return ICOAC_ERR_NULL;
    }
    if (!icoac_priv_initialised(st)) {
        return ICOAC_ERR_NOT_INITIALISED;
    }
    status = icoac_config_check(cfg);
    if (status != ICOAC_OK) {
        return status;
    }
    if (cfg->mode != st->config.mode || cfg->task.n_inputs != st->config.task.n_inputs ||
        memcmp(cfg->critic.units, st->config.critic.units, sizeof cfg->critic.units) != 0) {
        return ICOAC_ERR_RETUNE_MODE;
    }
    st->config = *cfg;
    derive(st);
    return ICOAC_OK;
}

icoac_status_t icoac_reset(icoac_state_t *state)
{
    icoac_priv_state_t *st = icoac_priv_state(state);
    if (state == NULL) {
        return ICOAC_ERR_NULL;
    }
    if (!icoac_priv_initialised(st)) {
        return ICOAC_ERR_NOT_INITIALISED;
    }
    if (!state_ok(st)) {
        return ICOAC_ERR_CORRUPT_STATE;
    }
    derive(st);
    clear_trial(st);
    st->magic = ICOAC_PRIV_STATE_MAGIC;
    if (st->config.mode == ICOAC_MODE_RL && st->config.actor.act_with_sample) {
        icoac_priv_actor_sample(st);
    } else if (st->config.mode == ICOAC_MODE_SEARCH) {
        icoac_priv_search_sample(st);
    } else {
        icoac_priv_copy(st->w_act, st->w);
    }
    return ICOAC_OK;
}

icoac_status_t icoac_get_posterior(const icoac_state_t *state, icoac_prior_t *posterior)
{
    const icoac_priv_state_t *st = icoac_priv_state_c(state);
    if ((state == NULL) || (posterior == NULL)) {
        return ICOAC_ERR_NULL;
    }
    if (!icoac_priv_initialised(st)) {
        return ICOAC_ERR_NOT_INITIALISED;
    }
    (void)memcpy(posterior->mean, st->w, sizeof posterior->mean);
    (void)memcpy(posterior->cov, icoac_priv_cov_c(st), sizeof posterior->cov);
    return ICOAC_OK;
}

icoac_status_t icoac_get_counters(const icoac_state_t *state, icoac_counters_t *counters)
{
    const icoac_priv_state_t *st = icoac_priv_state_c(state);
    if ((state == NULL) || (counters == NULL)) {
        return ICOAC_ERR_NULL;
    }
    if (!icoac_priv_initialised(st)) {
        return ICOAC_ERR_NOT_INITIALISED;
    }
    *counters = st->counters;
    return ICOAC_OK;
}

icoac_status_t icoac_get_config(const icoac_state_t *state, icoac_config_t *cfg)
{
    const icoac_priv_state_t *st = icoac_priv_state_c(state);
    if ((state == NULL) || (cfg == NULL)) {
        return ICOAC_ERR_NULL;
    }
    if (!icoac_priv_initialised(st)) {
        return ICOAC_ERR_NOT_INITIALISED;
    }
    *cfg = st->config;
    return ICOAC_OK;
}

uint32_t icoac_abi_version(void) { return ICOAC_ABI_VERSION; }
uint32_t icoac_sizeof_real(void) { return (uint32_t)sizeof(icoac_real_t); }
uint32_t icoac_sizeof_config(void) { return (uint32_t)sizeof(icoac_config_t); }
uint32_t icoac_sizeof_state(void) { return (uint32_t)sizeof(icoac_state_t); }
uint32_t icoac_sizeof_input(void) { return (uint32_t)sizeof(icoac_input_t); }
uint32_t icoac_sizeof_output(void) { return (uint32_t)sizeof(icoac_output_t); }
uint32_t icoac_sizeof_prior(void) { return (uint32_t)sizeof(icoac_prior_t); }
