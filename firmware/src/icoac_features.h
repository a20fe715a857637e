/* Features of a tick (method.md: input scaling, late signal, force; A2): the task's inputs and
 * their scaling, the late signal (penalty and reflex) of the rule table, and the reflex force. Private; static inline, as they run on every tick
 * of every mode. */
#ifndef ICOAC_FEATURES_H
#define ICOAC_FEATURES_H

#include "icoac_priv.h"

/* Reflex U and penalty r of one observation (Eq. 4; the task's late signal). */
typedef struct {
    icoac_real_t reflex;
    icoac_real_t penalty;
} icoac_priv_zone_t;

static inline icoac_real_t icoac_priv_clip_unit(icoac_real_t a)
{
    return a > ICOAC_R(1.0) ? ICOAC_R(1.0) : (a < ICOAC_R(-1.0) ? ICOAC_R(-1.0) : a);
}

/* The task's n inputs finite (entries n and up are not read). */
static inline int icoac_priv_inputs_finite(int n, const icoac_real_t s[ICOAC_MAX_INPUTS])
{
    int finite = 1;
    int i;
    for (i = 0; i < ICOAC_MAX_INPUTS && i < n; ++i) {
        finite &= icoac_priv_finite(s[i]);
    }
    return finite;
}

/* x~_i = clip(s_i / range_i) for i < n, with 1 / range_i precomputed by icoac_init; 0 past n. */
static inline void icoac_priv_scale_inputs(const icoac_policy_config_t *policy, const icoac_priv_state_t *st, int n,
                                           const icoac_real_t s[ICOAC_MAX_INPUTS],
                                           icoac_real_t scaled[ICOAC_MAX_INPUTS])
{
    int i;
    for (i = 0; i < ICOAC_MAX_INPUTS; ++i) {
        if (i < n) {
            const icoac_real_t a = s[i] * st->inv_range[i];
            scaled[i] = policy->clip_inputs ? icoac_priv_clip_unit(a) : a;
        } else {
            scaled[i] = ICOAC_R(0.0);
        }
    }
}

/* The late signal of the rule table (icoac.h, task): the first matching rule of the first
 * `rules` (<= ICOAC_MAX_RULES) gives r = -1 and its reflex; none gives 0, 0. The input indices
 * are bounded to the task's n inputs (1 <= n <= ICOAC_MAX_INPUTS): entries n and up are not read. */
static inline icoac_priv_zone_t icoac_priv_zone(const icoac_task_config_t *task, int rules, int n,
                                                const icoac_real_t s[ICOAC_MAX_INPUTS])
{
    icoac_priv_zone_t zone;
    int k;
    zone.reflex = ICOAC_R(0.0);
    zone.penalty = ICOAC_R(0.0);
    for (k = 0; k < rules; ++k) {
        const uint32_t input = (uint32_t)task->rule_input[k];
        const icoac_real_t value = s[input < (uint32_t)n ? input : 0u];
        const icoac_real_t threshold = task->rule_threshold[k];
        if (task->rule_side[k] == ICOAC_RULE_ABOVE ? value > threshold : value < threshold) {
            zone.reflex = task->rule_reflex[k];
            zone.penalty = ICOAC_R(-1.0);
            break;
        }
    }
    return zone;
}

/* The table's size, bounded to the arrays whatever the state's copy holds. */
static inline int icoac_priv_rules(const icoac_task_config_t *task)
{
    return (uint32_t)task->n_rules <= (uint32_t)ICOAC_MAX_RULES ? (int)task->n_rules : ICOAC_MAX_RULES;
}

/* Force of the reflex U (method.md, A2). */
static inline icoac_real_t icoac_priv_reflex_force(const icoac_policy_config_t *policy, icoac_real_t reflex)
{
    return policy->reflex_mode == ICOAC_REFLEX_GAIN ? policy->gain * reflex : policy->reflex_force * reflex;
}

#endif /* ICOAC_FEATURES_H */
