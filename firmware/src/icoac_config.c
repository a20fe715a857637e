/* Configuration: defaults and checks of every group, the prior check, status names. */
#include "icoac_priv.h"

const char *icoac_status_str(icoac_status_t status)
{
    switch (status) {
    case ICOAC_OK: return "ok";
    case ICOAC_ERR_NULL: return "null pointer";
    case ICOAC_ERR_NOT_INITIALISED: return "state not initialised (call icoac_init)";
    case ICOAC_ERR_NONFINITE_INPUT: return "non-finite observation (ignored, no learning)";
    case ICOAC_ERR_NUMERIC: return "numeric failure: a value derived in this tick was not finite (force 0, nothing learned)";
    case ICOAC_ERR_TRIAL_ENDED: return "trial ended by a terminal tick: call icoac_reset before the next tick";
    case ICOAC_ERR_CORRUPT_STATE: return "state corrupted (not as the library left it): call icoac_init";
    case ICOAC_ERR_RETUNE_MODE: return "icoac_retune cannot change the mode: icoac_init with the posterior as the prior";
    case ICOAC_ERR_BAD_MODE: return "invalid switch (mode, policy.reflex_mode, ico.timing, actor.update or a 0/1 flag)";
    case ICOAC_ERR_BAD_SCALE: return "invalid policy.input_range (must be in [1e-6, 1e6])";
    case ICOAC_ERR_BAD_GAIN: return "invalid policy.gain or policy.reflex_force (must be in [0, 1e4])";
    case ICOAC_ERR_BAD_ZONE: return "invalid policy.zone_theta or policy.zone_x (must be in [1e-6, pi] rad and [1e-6, 1e6] m)";
    case ICOAC_ERR_BAD_ICO_RATE: return "invalid ico.rate (must be in [0, 1])";
    case ICOAC_ERR_BAD_CRITIC: return "invalid critic parameter (rate [0, 10], discount [0, 1], td_clip [1e-6, 1e3], range [1e-6, 1e6], threshold [0, 1))";
    case ICOAC_ERR_BAD_ACTOR: return "invalid actor parameter (noise_std [1e-3, 1e3], scale [0, 1e3], forgetting [0.5, 1], update 0-2, rate [0, 1e3], likelihood_std 0 or [1e-3, 1e3], explore_ticks [0, 1e8])";
    case ICOAC_ERR_BAD_SEARCH: return "invalid search parameter (batch [1, 16], elite_fraction (0, 1], step (0, 1], floor [1e-6, 1e3], cov_scale [1, 1e3])";
    case ICOAC_ERR_BAD_PRIOR: return "invalid prior (|mean| <= 1e6, covariance entries |c| <= 1e12, zero or normal, symmetric positive definite)";
    default: return "unknown status";
    }
}

void icoac_policy_config_default(icoac_policy_config_t *policy)
{
    if (policy == 0) {
        return;
    }
    policy->input_range[ICOAC_IDX_X] = ICOAC_R(2.4);
    policy->input_range[ICOAC_IDX_X_DOT] = ICOAC_R(3.5);
    policy->input_range[ICOAC_IDX_THETA] = ICOAC_R(0.2094384);
    policy->input_range[ICOAC_IDX_THETA_DOT] = ICOAC_R(2.0);
    policy->clip_inputs = 1;
    policy->gain = ICOAC_R(10.0);
    policy->reflex_mode = ICOAC_REFLEX_UNIT;
    policy->reflex_force = ICOAC_R(1.0);
    policy->zone_theta = ICOAC_R(0.20071286397934788); /* 11.5 deg */
    policy->zone_x = ICOAC_R(2.35);
}

void icoac_ico_config_default(icoac_ico_config_t *ico)
{
    if (ico == 0) {
        return;
    }
    ico->rate = ICOAC_R(1.0e-4);
    ico->timing = ICOAC_ICO_TIMING_CODE;
}

void icoac_critic_config_default(icoac_critic_config_t *critic)
{
    if (critic == 0) {
        return;
    }
    critic->rate = ICOAC_R(0.6);
    critic->discount = ICOAC_R(0.95);
    critic->td_clip = ICOAC_R(1.0);
    critic->range[ICOAC_IDX_X] = ICOAC_R(2.4);
    critic->range[ICOAC_IDX_X_DOT] = ICOAC_R(3.5);
    critic->range[ICOAC_IDX_THETA] = ICOAC_R(0.2094384);
    critic->range[ICOAC_IDX_THETA_DOT] = ICOAC_R(2.0);
    critic->threshold = ICOAC_R(0.001);
    critic->quirks = 0;
}

void icoac_actor_config_default(icoac_actor_config_t *actor)
{
    if (actor == 0) {
        return;
    }
    /* sigma_u and the reading below were chosen by the learner sweeps (docs/results.md); the
     * literal values: noise_std 1, update posterior, explore_ticks 0 */
    actor->noise_std = ICOAC_R(3.0);
    actor->scale = ICOAC_R(0.5);
    actor->forgetting = ICOAC_R(1.0);
    actor->reflex = 1;
    actor->act_with_sample = 0;
    actor->update = ICOAC_ACTOR_GRADIENT;
    actor->rate = ICOAC_R(0.001);
    actor->likelihood_std = ICOAC_R(0.0);
    actor->batch = 0;
    actor->explore_ticks = 1000;
}

void icoac_search_config_default(icoac_search_config_t *search)
{
    if (search == 0) {
        return;
    }
    /* chosen by the learner sweeps for ICO->search (docs/results.md) */
    search->batch = 8;
    search->elite_fraction = ICOAC_R(0.25);
    search->step = ICOAC_R(0.5);
    search->floor = ICOAC_R(1.0);
    search->cov_scale = ICOAC_R(64.0);
}

void icoac_config_default(icoac_config_t *cfg)
{
    if (cfg == 0) {
        return;
    }
    cfg->mode = ICOAC_MODE_ICO;
    cfg->learn = 1;
    icoac_policy_config_default(&cfg->policy);
    icoac_ico_config_default(&cfg->ico);
    icoac_critic_config_default(&cfg->critic);
    icoac_actor_config_default(&cfg->actor);
    icoac_search_config_default(&cfg->search);
}

/* lo <= v <= hi and v not subnormal; false for NaN. */
static int within(icoac_real_t v, icoac_real_t lo, icoac_real_t hi)
{
    return v >= lo && v <= hi && icoac_priv_zero_or_normal(v);
}

static int is_flag(int32_t v)
{
    return v == 0 || v == 1;
}

/* The first bad field of a check: its name and its group's status. */
typedef struct {
    const char *field;
    icoac_status_t status;
} bad_field_t;

#define ICOAC_PRIV_FAIL(name, code) \
    do {                            \
        bad->field = (name);        \
        bad->status = (code);       \
        return 0;                   \
    } while (0)

static const char *const input_range_names[ICOAC_N_INPUTS] = {
    "policy.input_range[0]", "policy.input_range[1]", "policy.input_range[2]", "policy.input_range[3]"};
static const char *const critic_range_names[ICOAC_N_INPUTS] = {
    "critic.range[0]", "critic.range[1]", "critic.range[2]", "critic.range[3]"};

static int policy_ok(const icoac_policy_config_t *p, bad_field_t *bad)
{
    int i;
    for (i = 0; i < ICOAC_N_INPUTS; ++i) {
        if (!within(p->input_range[i], ICOAC_RANGE_MIN, ICOAC_RANGE_MAX)) {
            ICOAC_PRIV_FAIL(input_range_names[i], ICOAC_ERR_BAD_SCALE);
        }
    }
    if (!is_flag(p->clip_inputs)) {
        ICOAC_PRIV_FAIL("policy.clip_inputs", ICOAC_ERR_BAD_MODE);
    }
    if (!within(p->gain, ICOAC_R(0.0), ICOAC_GAIN_MAX)) {
        ICOAC_PRIV_FAIL("policy.gain", ICOAC_ERR_BAD_GAIN);
    }
    if (p->reflex_mode != ICOAC_REFLEX_UNIT && p->reflex_mode != ICOAC_REFLEX_GAIN) {
        ICOAC_PRIV_FAIL("policy.reflex_mode", ICOAC_ERR_BAD_MODE);
    }
    if (!within(p->reflex_force, ICOAC_R(0.0), ICOAC_FORCE_MAX)) {
        ICOAC_PRIV_FAIL("policy.reflex_force", ICOAC_ERR_BAD_GAIN);
    }
    if (!within(p->zone_theta, ICOAC_ZONE_MIN, ICOAC_ZONE_THETA_MAX)) {
        ICOAC_PRIV_FAIL("policy.zone_theta", ICOAC_ERR_BAD_ZONE);
    }
    if (!within(p->zone_x, ICOAC_ZONE_MIN, ICOAC_ZONE_X_MAX)) {
        ICOAC_PRIV_FAIL("policy.zone_x", ICOAC_ERR_BAD_ZONE);
    }
    return 1;
}

static int ico_ok(const icoac_ico_config_t *ico, bad_field_t *bad)
{
    if (!within(ico->rate, ICOAC_R(0.0), ICOAC_ICO_RATE_MAX)) {
        ICOAC_PRIV_FAIL("ico.rate", ICOAC_ERR_BAD_ICO_RATE);
    }
    if (ico->timing != ICOAC_ICO_TIMING_CODE && ico->timing != ICOAC_ICO_TIMING_LITERAL) {
        ICOAC_PRIV_FAIL("ico.timing", ICOAC_ERR_BAD_MODE);
    }
    return 1;
}

static int critic_ok(const icoac_critic_config_t *c, bad_field_t *bad)
{
    int i;
    if (!within(c->rate, ICOAC_R(0.0), ICOAC_CRITIC_RATE_MAX)) {
        ICOAC_PRIV_FAIL("critic.rate", ICOAC_ERR_BAD_CRITIC);
    }
    if (!within(c->discount, ICOAC_R(0.0), ICOAC_R(1.0))) {
        ICOAC_PRIV_FAIL("critic.discount", ICOAC_ERR_BAD_CRITIC);
    }
    if (!within(c->td_clip, ICOAC_TD_CLIP_MIN, ICOAC_TD_CLIP_MAX)) {
        ICOAC_PRIV_FAIL("critic.td_clip", ICOAC_ERR_BAD_CRITIC);
    }
    for (i = 0; i < ICOAC_N_INPUTS; ++i) {
        if (!within(c->range[i], ICOAC_RANGE_MIN, ICOAC_RANGE_MAX)) {
            ICOAC_PRIV_FAIL(critic_range_names[i], ICOAC_ERR_BAD_CRITIC);
        }
    }
    if (!within(c->threshold, ICOAC_R(0.0), ICOAC_R(1.0)) || !(c->threshold < ICOAC_R(1.0))) {
        ICOAC_PRIV_FAIL("critic.threshold", ICOAC_ERR_BAD_CRITIC);
    }
    if (!is_flag(c->quirks)) {
        ICOAC_PRIV_FAIL("critic.quirks", ICOAC_ERR_BAD_MODE);
    }
    return 1;
}

static int actor_ok(const icoac_actor_config_t *a, bad_field_t *bad)
{
    if (!within(a->noise_std, ICOAC_NOISE_STD_MIN, ICOAC_NOISE_STD_MAX)) {
        ICOAC_PRIV_FAIL("actor.noise_std", ICOAC_ERR_BAD_ACTOR);
    }
    if (!within(a->scale, ICOAC_R(0.0), ICOAC_ACTOR_SCALE_MAX)) {
        ICOAC_PRIV_FAIL("actor.scale", ICOAC_ERR_BAD_ACTOR);
    }
    if (!within(a->forgetting, ICOAC_FORGETTING_MIN, ICOAC_R(1.0))) {
        ICOAC_PRIV_FAIL("actor.forgetting", ICOAC_ERR_BAD_ACTOR);
    }
    if (!is_flag(a->reflex)) {
        ICOAC_PRIV_FAIL("actor.reflex", ICOAC_ERR_BAD_MODE);
    }
    if (!is_flag(a->act_with_sample)) {
        ICOAC_PRIV_FAIL("actor.act_with_sample", ICOAC_ERR_BAD_MODE);
    }
    if (a->update != ICOAC_ACTOR_POSTERIOR && a->update != ICOAC_ACTOR_MEAN && a->update != ICOAC_ACTOR_GRADIENT) {
        ICOAC_PRIV_FAIL("actor.update", ICOAC_ERR_BAD_MODE);
    }
    if (!within(a->rate, ICOAC_R(0.0), ICOAC_ACTOR_RATE_MAX)) {
        ICOAC_PRIV_FAIL("actor.rate", ICOAC_ERR_BAD_ACTOR);
    }
    if (!(a->likelihood_std == ICOAC_R(0.0)) && !within(a->likelihood_std, ICOAC_NOISE_STD_MIN, ICOAC_NOISE_STD_MAX)) {
        ICOAC_PRIV_FAIL("actor.likelihood_std", ICOAC_ERR_BAD_ACTOR);
    }
    if (!is_flag(a->batch)) {
        ICOAC_PRIV_FAIL("actor.batch", ICOAC_ERR_BAD_MODE);
    }
    if (a->explore_ticks < 0 || a->explore_ticks > ICOAC_EXPLORE_TICKS_MAX) {
        ICOAC_PRIV_FAIL("actor.explore_ticks", ICOAC_ERR_BAD_ACTOR);
    }
    return 1;
}

static int search_ok(const icoac_search_config_t *s, bad_field_t *bad)
{
    if (s->batch < 1 || s->batch > ICOAC_SEARCH_BATCH_MAX) {
        ICOAC_PRIV_FAIL("search.batch", ICOAC_ERR_BAD_SEARCH);
    }
    if (!within(s->elite_fraction, ICOAC_R(0.0), ICOAC_R(1.0)) || !(s->elite_fraction > ICOAC_R(0.0))) {
        ICOAC_PRIV_FAIL("search.elite_fraction", ICOAC_ERR_BAD_SEARCH);
    }
    if (!within(s->step, ICOAC_R(0.0), ICOAC_R(1.0)) || !(s->step > ICOAC_R(0.0))) {
        ICOAC_PRIV_FAIL("search.step", ICOAC_ERR_BAD_SEARCH);
    }
    if (!within(s->floor, ICOAC_SEARCH_FLOOR_MIN, ICOAC_SEARCH_FLOOR_MAX)) {
        ICOAC_PRIV_FAIL("search.floor", ICOAC_ERR_BAD_SEARCH);
    }
    if (!within(s->cov_scale, ICOAC_R(1.0), ICOAC_SEARCH_COV_SCALE_MAX)) {
        ICOAC_PRIV_FAIL("search.cov_scale", ICOAC_ERR_BAD_SEARCH);
    }
    return 1;
}

/* The mode, then the groups it uses, in struct order. */
static int config_ok(const icoac_config_t *cfg, bad_field_t *bad)
{
    if (cfg->mode != ICOAC_MODE_ICO && cfg->mode != ICOAC_MODE_RL && cfg->mode != ICOAC_MODE_SEARCH) {
        ICOAC_PRIV_FAIL("mode", ICOAC_ERR_BAD_MODE);
    }
    if (!is_flag(cfg->learn)) {
        ICOAC_PRIV_FAIL("learn", ICOAC_ERR_BAD_MODE);
    }
    if (!policy_ok(&cfg->policy, bad)) {
        return 0;
    }
    if (cfg->mode == ICOAC_MODE_ICO) {
        return ico_ok(&cfg->ico, bad);
    }
    if (cfg->mode == ICOAC_MODE_SEARCH) {
        return search_ok(&cfg->search, bad);
    }
    return critic_ok(&cfg->critic, bad) && actor_ok(&cfg->actor, bad);
}

icoac_status_t icoac_config_check_field(const icoac_config_t *cfg, const char **field)
{
    bad_field_t bad = {0, ICOAC_OK};
    if (field != 0) {
        *field = 0;
    }
    if (cfg == 0) {
        return ICOAC_ERR_NULL;
    }
    if (config_ok(cfg, &bad)) {
        return ICOAC_OK;
    }
    if (field != 0) {
        *field = bad.field;
    }
    return bad.status;
}

icoac_status_t icoac_config_check(const icoac_config_t *cfg)
{
    return icoac_config_check_field(cfg, 0);
}

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
        if (!(ICOAC_PRIV_FABS(m) <= ICOAC_PRIOR_MEAN_MAX) || !icoac_priv_zero_or_normal(m)) {
            return ICOAC_ERR_BAD_PRIOR;
        }
        for (j = 0; j < ICOAC_N_INPUTS; ++j) {
            const icoac_real_t c = prior->cov[i][j];
            if (!(ICOAC_PRIV_FABS(c) <= ICOAC_PRIOR_COV_MAX) || !icoac_priv_zero_or_normal(c) || c != prior->cov[j][i]) {
                return ICOAC_ERR_BAD_PRIOR;
            }
        }
    }
    return icoac_priv_cholesky4(prior->cov, lower) ? ICOAC_OK : ICOAC_ERR_BAD_PRIOR;
}
