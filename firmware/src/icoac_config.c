/* SPDX-License-Identifier: Apache-2.0 */
/* Configuration: defaults (the cart-pole task) and checks of every group, the prior check,
 * status names. */
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
    case ICOAC_ERR_RETUNE_MODE: return "icoac_retune cannot change the mode, task.n_inputs or critic.units: icoac_init with the posterior as the prior";
    case ICOAC_ERR_BAD_MODE: return "invalid switch (mode, policy.reflex_mode, ico.timing, actor.update or a 0/1 flag)";
    case ICOAC_ERR_BAD_SCALE: return "invalid policy.input_range (must be in [1e-6, 1e6])";
    case ICOAC_ERR_BAD_GAIN: return "invalid policy.gain or policy.reflex_force (must be in [0, 1e4])";
    case ICOAC_ERR_BAD_ZONE: return "invalid late-signal rule (task.rule_threshold: |t| <= 1e6; task.rule_reflex: [-1, 1])";
    case ICOAC_ERR_BAD_ICO_RATE: return "invalid ico.rate (must be in [0, 1])";
    case ICOAC_ERR_BAD_CRITIC: return "invalid critic parameter (rate [0, 10], discount [0, 1], td_clip [1e-6, 1e3], range [1e-6, 1e6], threshold [0, 1))";
    case ICOAC_ERR_BAD_ACTOR: return "invalid actor parameter (noise_std [1e-3, 1e3], scale [0, 1e3], forgetting [0.5, 1], update 0-2, rate [0, 1e3], likelihood_std 0 or [1e-3, 1e3], explore_ticks [0, 1e8])";
    case ICOAC_ERR_BAD_SEARCH: return "invalid search parameter (batch [1, 16], elite_fraction (0, 1], step (0, 1], floor [1e-6, 1e3], cov_scale [1, 1e3])";
    case ICOAC_ERR_BAD_TASK: return "invalid task (n_inputs [1, max], input_sign +1 or -1, late_source 0-1, n_rules [0, max], rule_input [0, n_inputs), rule_side 0-1)";
    case ICOAC_ERR_BAD_PRIOR: return "invalid prior (|mean| <= 1e6, covariance entries |c| <= 1e12, zero or normal, symmetric positive definite)";
    default: return "unknown status";
    }
}

/* The cart-pole task (x, x_dot, theta, theta_dot): its input and critic ranges, its critic grid
 * and its penalty zone, |theta| > 11.5 deg or |x| > 2.35 m; entries past its inputs are 0. */
static const icoac_real_t cartpole_range[ICOAC_MAX_INPUTS] = {ICOAC_R(2.4), ICOAC_R(3.5), ICOAC_R(0.2094384),
                                                              ICOAC_R(2.0)};
static const int32_t cartpole_units[ICOAC_MAX_INPUTS] = {ICOAC_CRITIC_N_X, ICOAC_CRITIC_N_X_DOT, ICOAC_CRITIC_N_THETA,
                                                         ICOAC_CRITIC_N_THETA_DOT};
#define CARTPOLE_ZONE_THETA ICOAC_R(0.20071286397934788) /* 11.5 deg */
#define CARTPOLE_ZONE_X ICOAC_R(2.35)

static void task_cartpole(icoac_task_config_t *task)
{
    /* Eq. (4), first match wins: leaning or pushed past the zone on one side pushes back */
    static const int32_t input[ICOAC_CARTPOLE_RULES] = ICOAC_PRIV_CARTPOLE_RULE_INPUTS;
    static const int32_t side[ICOAC_CARTPOLE_RULES] = ICOAC_PRIV_CARTPOLE_RULE_SIDES;
    static const icoac_real_t threshold[ICOAC_CARTPOLE_RULES] = {CARTPOLE_ZONE_THETA, -CARTPOLE_ZONE_X,
                                                                 -CARTPOLE_ZONE_THETA, CARTPOLE_ZONE_X};
    static const icoac_real_t reflex[ICOAC_CARTPOLE_RULES] = {ICOAC_R(1.0), ICOAC_R(1.0), ICOAC_R(-1.0), ICOAC_R(-1.0)};
    int k;
    (void)memset(task, 0, sizeof *task);
    task->n_inputs = ICOAC_CARTPOLE_INPUTS;
    for (k = 0; k < ICOAC_MAX_INPUTS; ++k) {
        task->input_sign[k] = 1;
    }
    task->late_source = ICOAC_LATE_RULES;
    task->n_rules = ICOAC_CARTPOLE_RULES;
    for (k = 0; k < ICOAC_CARTPOLE_RULES; ++k) {
        task->rule_input[k] = input[k];
        task->rule_side[k] = side[k];
        task->rule_threshold[k] = threshold[k];
        task->rule_reflex[k] = reflex[k];
    }
}

void icoac_task_cartpole(icoac_config_t *cfg)
{
    int i;
    if (cfg == NULL) {
        return;
    }
    task_cartpole(&cfg->task);
    for (i = 0; i < ICOAC_MAX_INPUTS; ++i) {
        cfg->policy.input_range[i] = cartpole_range[i];
        cfg->critic.range[i] = cartpole_range[i];
        cfg->critic.units[i] = cartpole_units[i];
    }
}

void icoac_policy_config_default(icoac_policy_config_t *policy)
{
    int i;
    if (policy == NULL) {
        return;
    }
    for (i = 0; i < ICOAC_MAX_INPUTS; ++i) {
        policy->input_range[i] = cartpole_range[i];
    }
    policy->clip_inputs = 1;
    policy->gain = ICOAC_R(10.0);
    policy->reflex_mode = ICOAC_REFLEX_UNIT;
    policy->reflex_force = ICOAC_R(1.0);
}

void icoac_ico_config_default(icoac_ico_config_t *ico)
{
    if (ico == NULL) {
        return;
    }
    ico->rate = ICOAC_R(1.0e-4);
    ico->timing = ICOAC_ICO_TIMING_CODE;
}

void icoac_critic_config_default(icoac_critic_config_t *critic)
{
    int i;
    if (critic == NULL) {
        return;
    }
    critic->rate = ICOAC_R(0.6);
    critic->discount = ICOAC_R(0.95);
    critic->td_clip = ICOAC_R(1.0);
    for (i = 0; i < ICOAC_MAX_INPUTS; ++i) {
        critic->range[i] = cartpole_range[i];
        critic->units[i] = cartpole_units[i];
    }
    critic->threshold = ICOAC_R(0.001);
    critic->quirks = 0;
}

void icoac_actor_config_default(icoac_actor_config_t *actor)
{
    if (actor == NULL) {
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
    if (search == NULL) {
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
    if (cfg == NULL) {
        return;
    }
    cfg->mode = ICOAC_MODE_ICO;
    cfg->learn = 1;
    task_cartpole(&cfg->task);
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

/* The names of an array's first 16 entries (both maxima are at most 16). */
#define NAMES16(a)                                                                                          \
    {a "[0]", a "[1]", a "[2]", a "[3]", a "[4]", a "[5]", a "[6]", a "[7]", a "[8]", a "[9]", a "[10]", \
     a "[11]", a "[12]", a "[13]", a "[14]", a "[15]"}
static const char *const input_range_names[16] = NAMES16("policy.input_range");
static const char *const critic_range_names[16] = NAMES16("critic.range");
static const char *const critic_units_names[16] = NAMES16("critic.units");
static const char *const rule_input_names[16] = NAMES16("task.rule_input");
static const char *const rule_side_names[16] = NAMES16("task.rule_side");
static const char *const rule_threshold_names[16] = NAMES16("task.rule_threshold");
static const char *const rule_reflex_names[16] = NAMES16("task.rule_reflex");

/* task.n_inputs, then the input signs, +1 or -1 each; one exit. */
static int inputs_ok(const icoac_task_config_t *t, bad_field_t *bad)
{
    static const char *const sign_names[16] = NAMES16("task.input_sign");
    const char *field = NULL;
    int k;
    if ((t->n_inputs < 1) || (t->n_inputs > ICOAC_MAX_INPUTS)) {
        field = "task.n_inputs";
    } else {
        for (k = t->n_inputs - 1; k >= 0; --k) {
            if ((t->input_sign[k] != 1) && (t->input_sign[k] != -1)) {
                field = sign_names[k]; /* the loop runs down: the first bad sign is the last found */
            }
        }
    }
    if (field != NULL) {
        bad->field = field;
        bad->status = ICOAC_ERR_BAD_TASK;
    }
    return (field == NULL) ? 1 : 0;
}

/* The task group; n_inputs first, as the other groups' arrays are checked up to it. */
static int task_ok(const icoac_task_config_t *t, bad_field_t *bad)
{
    int k;
    if (inputs_ok(t, bad) == 0) {
        return 0;
    }
    if (t->late_source != ICOAC_LATE_RULES && t->late_source != ICOAC_LATE_SENSOR) {
        ICOAC_PRIV_FAIL("task.late_source", ICOAC_ERR_BAD_TASK);
    }
    if (t->n_rules < 0 || t->n_rules > ICOAC_MAX_RULES) {
        ICOAC_PRIV_FAIL("task.n_rules", ICOAC_ERR_BAD_TASK);
    }
    if (t->late_source != ICOAC_LATE_RULES) {
        return 1; /* the table is not used */
    }
    /* in struct order: every rule's input, then every side, threshold, reflex */
    for (k = 0; k < t->n_rules; ++k) {
        if (t->rule_input[k] < 0 || t->rule_input[k] >= t->n_inputs) {
            ICOAC_PRIV_FAIL(rule_input_names[k], ICOAC_ERR_BAD_TASK);
        }
    }
    for (k = 0; k < t->n_rules; ++k) {
        if (t->rule_side[k] != ICOAC_RULE_BELOW && t->rule_side[k] != ICOAC_RULE_ABOVE) {
            ICOAC_PRIV_FAIL(rule_side_names[k], ICOAC_ERR_BAD_TASK);
        }
    }
    for (k = 0; k < t->n_rules; ++k) {
        if (!within(t->rule_threshold[k], -ICOAC_RULE_THRESHOLD_MAX, ICOAC_RULE_THRESHOLD_MAX)) {
            ICOAC_PRIV_FAIL(rule_threshold_names[k], ICOAC_ERR_BAD_ZONE);
        }
    }
    for (k = 0; k < t->n_rules; ++k) {
        if (!within(t->rule_reflex[k], ICOAC_R(-1.0), ICOAC_R(1.0))) {
            ICOAC_PRIV_FAIL(rule_reflex_names[k], ICOAC_ERR_BAD_ZONE);
        }
    }
    return 1;
}

static int policy_ok(const icoac_policy_config_t *p, int n, bad_field_t *bad)
{
    int i;
    for (i = 0; i < n; ++i) {
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

static int critic_ok(const icoac_critic_config_t *c, int n, bad_field_t *bad)
{
    int32_t units = 1;
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
    for (i = 0; i < n; ++i) {
        if (!within(c->range[i], ICOAC_RANGE_MIN, ICOAC_RANGE_MAX)) {
            ICOAC_PRIV_FAIL(critic_range_names[i], ICOAC_ERR_BAD_CRITIC);
        }
    }
    for (i = 0; i < n; ++i) {
        if (c->units[i] < 1 || c->units[i] > ICOAC_CRITIC_UNITS_PER_INPUT_MAX) {
            ICOAC_PRIV_FAIL(critic_units_names[i], ICOAC_ERR_BAD_CRITIC);
        }
        units *= c->units[i]; /* at most 16 times the maximum before the check stops it */
        if (units > ICOAC_MAX_CRITIC_UNITS) {
            ICOAC_PRIV_FAIL("critic.units", ICOAC_ERR_BAD_CRITIC);
        }
    }
    if (icoac_priv_critic_split(c->units, n) == 0) {
        ICOAC_PRIV_FAIL("critic.units", ICOAC_ERR_BAD_CRITIC);
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
    if (!task_ok(&cfg->task, bad) || !policy_ok(&cfg->policy, cfg->task.n_inputs, bad)) {
        return 0;
    }
    if (cfg->mode == ICOAC_MODE_ICO) {
        return ico_ok(&cfg->ico, bad);
    }
    if (cfg->mode == ICOAC_MODE_SEARCH) {
        return search_ok(&cfg->search, bad);
    }
    return critic_ok(&cfg->critic, cfg->task.n_inputs, bad) && actor_ok(&cfg->actor, bad);
}

icoac_status_t icoac_config_check_field(const icoac_config_t *cfg, const char **field)
{
    bad_field_t bad = {0, ICOAC_OK};
    if (field != NULL) {
        *field = NULL;
    }
    if (cfg == NULL) {
        return ICOAC_ERR_NULL;
    }
    if (config_ok(cfg, &bad) != 0) {
        return ICOAC_OK;
    }
    if (field != NULL) {
        *field = bad.field;
    }
    return bad.status;
}

icoac_status_t icoac_config_check(const icoac_config_t *cfg)
{
    return icoac_config_check_field(cfg, 0);
}

icoac_status_t icoac_prior_check(const icoac_prior_t *prior, int32_t n_inputs)
{
    icoac_real_t lower[ICOAC_MAX_INPUTS][ICOAC_MAX_INPUTS];
    const int n = (int)n_inputs;
    int i;
    int j;
    if (prior == NULL) {
        return ICOAC_ERR_NULL;
    }
    if (n_inputs < 1 || n_inputs > ICOAC_MAX_INPUTS) {
        return ICOAC_ERR_BAD_TASK;
    }
    for (i = 0; i < n; ++i) {
        const icoac_real_t m = prior->mean[i];
        if (!(ICOAC_PRIV_FABS(m) <= ICOAC_PRIOR_MEAN_MAX) || !icoac_priv_zero_or_normal(m)) {
            return ICOAC_ERR_BAD_PRIOR;
        }
        for (j = 0; j < n; ++j) {
            const icoac_real_t c = prior->cov[i][j];
            if (!(ICOAC_PRIV_FABS(c) <= ICOAC_PRIOR_COV_MAX) || !icoac_priv_zero_or_normal(c) || c != prior->cov[j][i]) {
                return ICOAC_ERR_BAD_PRIOR;
            }
        }
    }
    return icoac_priv_cholesky(prior->cov, lower, n) ? ICOAC_OK : ICOAC_ERR_BAD_PRIOR;
}
