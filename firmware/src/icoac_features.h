/* SPDX-License-Identifier: Apache-2.0 */
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

/* 1 when |a| <= 1 (a not NaN): an integer test of the magnitude's bits, the fast path of a clip. */
static inline int icoac_priv_within_unit(icoac_real_t a)
{
#if defined(ICOAC_REAL_DOUBLE) && ICOAC_REAL_DOUBLE
    uint64_t bits;
    (void)memcpy(&bits, &a, sizeof bits);
    return (bits & 0x7FFFFFFFFFFFFFFFull) <= 0x3FF0000000000000ull;
#else
    uint32_t bits;
    (void)memcpy(&bits, &a, sizeof bits);
    return (bits & 0x7FFFFFFFu) <= 0x3F800000u;
#endif
}

/* x~_i = clip(sign_i * s_i / range_i) for i < n, with sign_i / range_i precomputed by icoac_init (the clip
 * is symmetric: sign_i * clip(s_i / range_i)); 0 past n. */
static inline void icoac_priv_scale_inputs(const icoac_policy_config_t *policy, const icoac_priv_state_t *st, int n,
                                           const icoac_real_t s[ICOAC_MAX_INPUTS],
                                           icoac_real_t scaled[ICOAC_MAX_INPUTS])
{
    int i;
    for (i = 0; i < ICOAC_MAX_INPUTS; ++i) {
        scaled[i] = i < n ? s[i] * st->inv_range[i] : ICOAC_R(0.0);
    }
    if (policy->clip_inputs != 0) {
        for (i = 0; i < n && i < ICOAC_MAX_INPUTS; ++i) {
            if (!icoac_priv_within_unit(scaled[i])) {
                scaled[i] = icoac_priv_clip_unit(scaled[i]);
            }
        }
    }
}

/* The late signal of the rule table (icoac.h, task): the first matching rule of the first
 * `rules` (<= ICOAC_MAX_RULES) gives r = -1 and its reflex; none gives 0, 0. The input indices
 * are bounded to the task's n inputs (1 <= n <= ICOAC_MAX_INPUTS): entries n and up are not read. */
static inline icoac_priv_zone_t icoac_priv_zone_of(const icoac_task_config_t *task, int rules, int n,
                                                   const icoac_real_t s[ICOAC_MAX_INPUTS], const int32_t *rule_input,
                                                   const int32_t *rule_side)
{
    icoac_priv_zone_t zone;
    int k;
    zone.reflex = ICOAC_R(0.0);
    zone.penalty = ICOAC_R(0.0);
    for (k = 0; k < rules; ++k) {
        const uint32_t input = (uint32_t)rule_input[k];
        const icoac_real_t value = s[input < (uint32_t)n ? input : 0u];
        const icoac_real_t threshold = task->rule_threshold[k];
        if (rule_side[k] == ICOAC_RULE_ABOVE ? value > threshold : value < threshold) {
            zone.reflex = task->rule_reflex[k];
            zone.penalty = ICOAC_R(-1.0);
            break;
        }
    }
    return zone;
}

/* The rule table's late signal, the rules' inputs and sides read from the table. */
static inline icoac_priv_zone_t icoac_priv_zone(const icoac_task_config_t *task, int rules, int n,
                                                const icoac_real_t s[ICOAC_MAX_INPUTS])
{
    return icoac_priv_zone_of(task, rules, n, s, task->rule_input, task->rule_side);
}

/* The same for a table laid out as the cart-pole preset's (ICOAC_PRIV_SHAPE_CARTPOLE_RULES): its
 * inputs and sides as constants, its thresholds and reflexes from the table. */
static inline icoac_priv_zone_t icoac_priv_zone_cartpole(const icoac_task_config_t *task,
                                                         const icoac_real_t s[ICOAC_MAX_INPUTS])
{
    static const int32_t rule_input[ICOAC_CARTPOLE_RULES] = ICOAC_PRIV_CARTPOLE_RULE_INPUTS;
    static const int32_t rule_side[ICOAC_CARTPOLE_RULES] = ICOAC_PRIV_CARTPOLE_RULE_SIDES;
    return icoac_priv_zone_of(task, ICOAC_CARTPOLE_RULES, ICOAC_CARTPOLE_INPUTS, s, rule_input, rule_side);
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
