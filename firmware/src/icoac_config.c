/* SPDX-License-Identifier: Apache-2.0 */
/* Configuration: defaults (the cart-pole task) and checks of every group, made from the rows of
 * icoac_params.h; the prior check, status names. */
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
    case ICOAC_ERR_BAD_SCALE: return "invalid policy.input_range (out of its range: icoac_params.h)";
    case ICOAC_ERR_BAD_GAIN: return "invalid policy.gain or policy.reflex_force (out of its range: icoac_params.h)";
    case ICOAC_ERR_BAD_ZONE: return "invalid late-signal rule (task.rule_threshold or task.rule_reflex out of its range: icoac_params.h)";
    case ICOAC_ERR_BAD_ICO_RATE: return "invalid ico.rate (out of its range: icoac_params.h)";
    case ICOAC_ERR_BAD_CRITIC: return "invalid critic parameter (out of its range: icoac_params.h)";
    case ICOAC_ERR_BAD_ACTOR: return "invalid actor parameter (out of its range: icoac_params.h)";
    case ICOAC_ERR_BAD_SEARCH: return "invalid search parameter (out of its range: icoac_params.h)";
    case ICOAC_ERR_BAD_TASK: return "invalid task (n_inputs, input_sign, late_source, n_rules, rule_input or rule_side out of its range: icoac_params.h)";
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

/* The task group's input arrays (the input signs): every entry their row's default (icoac_params.h);
 * its sizes and rules are the preset's. */
#define ICOAC_PRIV_TASK_INPUTS_DEFAULT_scalar(v, def)
#define ICOAC_PRIV_TASK_INPUTS_DEFAULT_rules(v, def)
#define ICOAC_PRIV_TASK_INPUTS_DEFAULT_inputs(v, def) \
    for (k = 0; k < ICOAC_MAX_INPUTS; ++k) {           \
        (v)[k] = (def);                                \
    }
#define ICOAC_PRIV_TASK_INPUTS_DEFAULT(group, field, type, dim, check, unit, min, max, def, modes, tier, status, doc) \
    ICOAC_PRIV_TASK_INPUTS_DEFAULT_##dim(task->field, def)

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
    ICOAC_PARAMS_TASK(ICOAC_PRIV_TASK_INPUTS_DEFAULT)
    task->n_inputs = ICOAC_CARTPOLE_INPUTS;
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

/* A row's default (icoac_params.h) on the group struct p; the arrays are the task preset's (the rule
 * table is the task group's, which the preset fills). */
#define ICOAC_PRIV_DEFAULT_scalar(v, def) (v) = (def);
#define ICOAC_PRIV_DEFAULT_inputs(v, def)
#define ICOAC_PRIV_DEFAULT(group, field, type, dim, check, unit, min, max, def, modes, tier, status, doc) \
    ICOAC_PRIV_DEFAULT_##dim(p->field, def)

void icoac_policy_config_default(icoac_policy_config_t *policy)
{
    icoac_policy_config_t *const p = policy;
    int i;
    if (p == NULL) {
        return;
    }
    for (i = 0; i < ICOAC_MAX_INPUTS; ++i) {
        p->input_range[i] = cartpole_range[i];
    }
    ICOAC_PARAMS_POLICY(ICOAC_PRIV_DEFAULT)
}

void icoac_ico_config_default(icoac_ico_config_t *ico)
{
    icoac_ico_config_t *const p = ico;
    if (p == NULL) {
        return;
    }
    ICOAC_PARAMS_ICO(ICOAC_PRIV_DEFAULT)
}

void icoac_critic_config_default(icoac_critic_config_t *critic)
{
    icoac_critic_config_t *const p = critic;
    int i;
    if (p == NULL) {
        return;
    }
    for (i = 0; i < ICOAC_MAX_INPUTS; ++i) {
        p->range[i] = cartpole_range[i];
        p->units[i] = cartpole_units[i];
    }
    ICOAC_PARAMS_CRITIC(ICOAC_PRIV_DEFAULT)
}

void icoac_actor_config_default(icoac_actor_config_t *actor)
{
    icoac_actor_config_t *const p = actor;
    if (p == NULL) {
        return;
    }
    ICOAC_PARAMS_ACTOR(ICOAC_PRIV_DEFAULT)
}

void icoac_search_config_default(icoac_search_config_t *search)
{
    icoac_search_config_t *const p = search;
    if (p == NULL) {
        return;
    }
    ICOAC_PARAMS_SEARCH(ICOAC_PRIV_DEFAULT)
}

void icoac_config_default(icoac_config_t *cfg)
{
    icoac_config_t *const p = cfg;
    if (p == NULL) {
        return;
    }
    ICOAC_PARAMS_CONFIG(ICOAC_PRIV_DEFAULT)
    task_cartpole(&p->task);
    icoac_policy_config_default(&p->policy);
    icoac_ico_config_default(&p->ico);
    icoac_critic_config_default(&p->critic);
    icoac_actor_config_default(&p->actor);
    icoac_search_config_default(&p->search);
}

/* lo <= v <= hi and v not subnormal; false for NaN. */
static int within(icoac_real_t v, icoac_real_t lo, icoac_real_t hi)
{
    return v >= lo && v <= hi && icoac_priv_zero_or_normal(v);
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
#define ICOAC_PRIV_NAMES_scalar(group, field)
#define ICOAC_PRIV_NAMES_inputs(group, field) \
    static const char *const names_##group##_##field[16] = NAMES16(ICOAC_PARAM_PREFIX_##group #field);
#define ICOAC_PRIV_NAMES_rules(group, field) ICOAC_PRIV_NAMES_inputs(group, field)
#define ICOAC_PRIV_NAMES(group, field, type, dim, check, unit, min, max, def, modes, tier, status, doc) \
    ICOAC_PRIV_NAMES_##dim(group, field)
ICOAC_PARAMS(ICOAC_PRIV_NAMES)

/* A row's check (icoac_params.h) on the group struct p, in a function that has the task's
 * n_inputs, the rules it checks (n_rules) and an index i; the first bad value fails. */
#define ICOAC_PRIV_OK_real(v, lo, hi) within((v), (lo), (hi))
#define ICOAC_PRIV_OK_real_open_lo(v, lo, hi) (within((v), (lo), (hi)) && ((v) > (lo)))
#define ICOAC_PRIV_OK_real_open_hi(v, lo, hi) (within((v), (lo), (hi)) && ((v) < (hi)))
#define ICOAC_PRIV_OK_real_or_zero(v, lo, hi) (((v) == ICOAC_R(0.0)) || within((v), (lo), (hi)))
#define ICOAC_PRIV_OK_int(v, lo, hi) (((v) >= (lo)) && ((v) <= (hi)))
#define ICOAC_PRIV_OK_flag(v, lo, hi) ICOAC_PRIV_OK_int(v, lo, hi)
#define ICOAC_PRIV_OK_choice(v, lo, hi) ICOAC_PRIV_OK_int(v, lo, hi)
#define ICOAC_PRIV_OK_units(v, lo, hi) ICOAC_PRIV_OK_int(v, lo, hi)
#define ICOAC_PRIV_OK_sign(v, lo, hi) (((v) == (lo)) || ((v) == (hi)))
#define ICOAC_PRIV_OK_index(v, lo, hi) (((v) >= (lo)) && ((v) < n_inputs))
/* The critic's units: their running product within ICOAC_MAX_CRITIC_UNITS (at most 16 times it
 * before this stops it), then their split into blocks. */
#define ICOAC_PRIV_NEXT_units(v)                                  \
    units *= (v)[i];                                              \
    if (units > ICOAC_MAX_CRITIC_UNITS) {                         \
        ICOAC_PRIV_FAIL("critic.units", ICOAC_ERR_BAD_CRITIC);    \
    }
#define ICOAC_PRIV_END_units(v)                                   \
    if (icoac_priv_critic_split((v), n_inputs) == 0) {            \
        ICOAC_PRIV_FAIL("critic.units", ICOAC_ERR_BAD_CRITIC);    \
    }
#define ICOAC_PRIV_NEXT_real(v)
#define ICOAC_PRIV_END_real(v)
#define ICOAC_PRIV_NEXT_index(v)
#define ICOAC_PRIV_END_index(v)
#define ICOAC_PRIV_NEXT_choice(v)
#define ICOAC_PRIV_END_choice(v)
#define ICOAC_PRIV_NEXT_sign(v)
#define ICOAC_PRIV_END_sign(v)

#define ICOAC_PRIV_CHECK_scalar(check, v, group, field, min, max, status) \
    if (!ICOAC_PRIV_OK_##check(v, min, max)) {                            \
        ICOAC_PRIV_FAIL(ICOAC_PARAM_PREFIX_##group #field, status);      \
    }
#define ICOAC_PRIV_CHECK_LOOP(count, check, v, group, field, min, max, status) \
    for (i = 0; i < (count); ++i) {                                            \
        if (!ICOAC_PRIV_OK_##check((v)[i], min, max)) {                        \
            ICOAC_PRIV_FAIL(names_##group##_##field[i], status);               \
        }                                                                      \
        ICOAC_PRIV_NEXT_##check(v)                                             \
    }                                                                          \
    ICOAC_PRIV_END_##check(v)
#define ICOAC_PRIV_CHECK_inputs(check, v, group, field, min, max, status) \
    ICOAC_PRIV_CHECK_LOOP(n_inputs, check, v, group, field, min, max, status)
#define ICOAC_PRIV_CHECK_rules(check, v, group, field, min, max, status) \
    ICOAC_PRIV_CHECK_LOOP(n_rules, check, v, group, field, min, max, status)
#define ICOAC_PRIV_CHECK(group, field, type, dim, check, unit, min, max, def, modes, tier, status, doc) \
    ICOAC_PRIV_CHECK_##dim(check, p->field, group, field, min, max, status)

/* The task group; n_inputs first, as the input signs and the other groups' arrays are checked
 * up to it. The rule table is checked only when it is the late signal's source; in struct order:
 * every rule's input, then every side, threshold, reflex. */
static int task_ok(const icoac_task_config_t *p, bad_field_t *bad)
{
    const int32_t n_inputs = p->n_inputs;
    int32_t n_rules;
    int32_t i;
    ICOAC_PARAMS_TASK_SIZES(ICOAC_PRIV_CHECK)
    if (p->late_source != ICOAC_LATE_RULES) {
        return 1; /* the table is not used */
    }
    n_rules = p->n_rules;
    ICOAC_PARAMS_TASK_RULES(ICOAC_PRIV_CHECK)
    return 1;
}

static int policy_ok(const icoac_policy_config_t *p, int32_t n_inputs, bad_field_t *bad)
{
    int32_t i;
    ICOAC_PARAMS_POLICY(ICOAC_PRIV_CHECK)
    return 1;
}

static int ico_ok(const icoac_ico_config_t *p, bad_field_t *bad)
{
    ICOAC_PARAMS_ICO(ICOAC_PRIV_CHECK)
    return 1;
}

static int critic_ok(const icoac_critic_config_t *p, int32_t n_inputs, bad_field_t *bad)
{
    int32_t units = 1;
    int32_t i;
    ICOAC_PARAMS_CRITIC(ICOAC_PRIV_CHECK)
    return 1;
}

static int actor_ok(const icoac_actor_config_t *p, bad_field_t *bad)
{
    ICOAC_PARAMS_ACTOR(ICOAC_PRIV_CHECK)
    return 1;
}

static int search_ok(const icoac_search_config_t *p, bad_field_t *bad)
{
    ICOAC_PARAMS_SEARCH(ICOAC_PRIV_CHECK)
    return 1;
}

/* The mode, then the groups it uses, in struct order. */
static int config_ok(const icoac_config_t *cfg, bad_field_t *bad)
{
    const icoac_config_t *const p = cfg;
    ICOAC_PARAMS_CONFIG(ICOAC_PRIV_CHECK)
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
