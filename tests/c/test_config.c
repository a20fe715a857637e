/* SPDX-License-Identifier: Apache-2.0 */
/* Configuration, prior and argument checks; the named bad field; status names; layout
 * functions. */
#include "test_common.h"

#include "icoac_priv.h"
#include "icoac/icoac_version.h"

#define NAN_R ((icoac_real_t)NAN)
#define INF_R ((icoac_real_t)INFINITY)

static void test_defaults_match_spec(void)
{
    icoac_config_t cfg = test_default_config();
    icoac_config_t filled;
    icoac_policy_config_t policy;
    icoac_ico_config_t ico;
    icoac_critic_config_t critic;
    icoac_actor_config_t actor;
    icoac_search_config_t search;
    const double tol = 4.0 * REAL_EPS;
    TEST_ASSERT_EQUAL_INT(ICOAC_MODE_ICO, cfg.mode);
    TEST_ASSERT_EQUAL_INT(ICOAC_REFLEX_UNIT, cfg.policy.reflex_mode);
    TEST_ASSERT_EQUAL_INT(ICOAC_ICO_TIMING_CODE, cfg.ico.timing);
    TEST_ASSERT_EQUAL_INT(1, cfg.policy.clip_inputs);
    assert_close(cfg.policy.input_range[0], 2.4, tol * 2.4);
    assert_close(cfg.policy.input_range[1], 3.5, tol * 3.5);
    assert_close(cfg.policy.input_range[2], 0.2094384, tol);
    assert_close(cfg.policy.input_range[3], 2.0, 0.0);
    assert_close(cfg.policy.gain, 10.0, 0.0);
    assert_close(cfg.policy.reflex_force, 1.0, 0.0);
    /* the cart-pole task: Eq. (4)'s zone as four rules, first match wins */
    TEST_ASSERT_EQUAL_INT(4, cfg.task.n_inputs);
    for (int i = 0; i < ICOAC_MAX_INPUTS; ++i) {
        TEST_ASSERT_EQUAL_INT(1, cfg.task.input_sign[i]); /* the paper's: no sign changed */
    }
    TEST_ASSERT_EQUAL_INT(ICOAC_LATE_RULES, cfg.task.late_source);
    TEST_ASSERT_EQUAL_INT(4, cfg.task.n_rules);
    TEST_ASSERT_EQUAL_INT(ICOAC_IDX_THETA, cfg.task.rule_input[0]);
    TEST_ASSERT_EQUAL_INT(ICOAC_RULE_ABOVE, cfg.task.rule_side[0]);
    assert_close(cfg.task.rule_threshold[0], DEG(11.5), tol);
    assert_close(cfg.task.rule_reflex[0], 1.0, 0.0);
    TEST_ASSERT_EQUAL_INT(ICOAC_IDX_X, cfg.task.rule_input[1]);
    TEST_ASSERT_EQUAL_INT(ICOAC_RULE_BELOW, cfg.task.rule_side[1]);
    assert_close(cfg.task.rule_threshold[1], -2.35, tol * 2.35);
    assert_close(cfg.task.rule_reflex[1], 1.0, 0.0);
    TEST_ASSERT_EQUAL_INT(ICOAC_IDX_THETA, cfg.task.rule_input[2]);
    TEST_ASSERT_EQUAL_INT(ICOAC_RULE_BELOW, cfg.task.rule_side[2]);
    assert_close(cfg.task.rule_threshold[2], -DEG(11.5), tol);
    assert_close(cfg.task.rule_reflex[2], -1.0, 0.0);
    TEST_ASSERT_EQUAL_INT(ICOAC_IDX_X, cfg.task.rule_input[3]);
    TEST_ASSERT_EQUAL_INT(ICOAC_RULE_ABOVE, cfg.task.rule_side[3]);
    assert_close(cfg.task.rule_threshold[3], 2.35, tol * 2.35);
    assert_close(cfg.task.rule_reflex[3], -1.0, 0.0);
    TEST_ASSERT_EQUAL_INT(3, cfg.critic.units[0]);
    TEST_ASSERT_EQUAL_INT(3, cfg.critic.units[1]);
    TEST_ASSERT_EQUAL_INT(6, cfg.critic.units[2]);
    TEST_ASSERT_EQUAL_INT(3, cfg.critic.units[3]);
    assert_close(cfg.ico.rate, 1e-4, tol * 1e-4);
    assert_close(cfg.critic.rate, 0.6, tol);
    assert_close(cfg.critic.discount, 0.95, tol);
    assert_close(cfg.critic.td_clip, 1.0, 0.0);
    assert_close(cfg.critic.range[0], 2.4, tol * 2.4);
    assert_close(cfg.critic.range[1], 3.5, tol * 3.5);
    assert_close(cfg.critic.range[2], 0.2094384, tol);
    assert_close(cfg.critic.range[3], 2.0, 0.0);
    assert_close(cfg.critic.threshold, 0.001, tol * 0.001);
    assert_close(cfg.actor.noise_std, 3.0, 0.0); /* chosen by the learner sweeps (literal: 1) */
    assert_close(cfg.actor.scale, 0.5, 0.0);
    assert_close(cfg.actor.forgetting, 1.0, 0.0);
    TEST_ASSERT_EQUAL_INT(1, cfg.actor.reflex);
    TEST_ASSERT_EQUAL_INT(0, cfg.actor.act_with_sample);
    /* L2-L4, A10 (method.md): the literal critic, per-tick updates and sigma_L = sigma_u (0); the actor
     * reading and its exploration schedule, and the search group, chosen by the learner sweeps */
    TEST_ASSERT_EQUAL_INT(1, cfg.learn);
    TEST_ASSERT_EQUAL_INT(0, cfg.critic.quirks);
    TEST_ASSERT_EQUAL_INT(ICOAC_ACTOR_GRADIENT, cfg.actor.update);
    assert_close(cfg.actor.rate, 0.001, tol * 0.001);
    TEST_ASSERT_TRUE(cfg.actor.likelihood_std == 0); /* 0: sigma_L = sigma_u (literal) */
    TEST_ASSERT_EQUAL_INT(0, cfg.actor.batch);
    TEST_ASSERT_EQUAL_INT(1000, cfg.actor.explore_ticks);
    TEST_ASSERT_EQUAL_INT(8, cfg.search.batch);
    assert_close(cfg.search.elite_fraction, 0.25, 0.0);
    assert_close(cfg.search.step, 0.5, 0.0);
    assert_close(cfg.search.floor, 1.0, 0.0);
    assert_close(cfg.search.cov_scale, 64.0, 0.0);
    /* Each group's default is the configuration default's group (same fill: padding agrees). */
    memset(&filled, 0xA5, sizeof filled);
    memset(&policy, 0xA5, sizeof policy);
    memset(&ico, 0xA5, sizeof ico);
    memset(&critic, 0xA5, sizeof critic);
    memset(&actor, 0xA5, sizeof actor);
    memset(&search, 0xA5, sizeof search);
    icoac_config_default(&filled);
    icoac_policy_config_default(&policy);
    icoac_ico_config_default(&ico);
    icoac_critic_config_default(&critic);
    icoac_actor_config_default(&actor);
    icoac_search_config_default(&search);
    TEST_ASSERT_EQUAL_INT(ICOAC_MODE_ICO, filled.mode);
    TEST_ASSERT_EQUAL_MEMORY(&filled.policy, &policy, sizeof policy);
    TEST_ASSERT_EQUAL_MEMORY(&filled.ico, &ico, sizeof ico);
    TEST_ASSERT_EQUAL_MEMORY(&filled.critic, &critic, sizeof critic);
    TEST_ASSERT_EQUAL_MEMORY(&filled.actor, &actor, sizeof actor);
    TEST_ASSERT_EQUAL_MEMORY(&filled.search, &search, sizeof search);
    /* and the default over a 0xA5 fill equals the default over zeros, field by field */
    TEST_ASSERT_TRUE(memcmp(filled.policy.input_range, cfg.policy.input_range, sizeof cfg.policy.input_range) == 0);
    TEST_ASSERT_TRUE(filled.policy.gain == cfg.policy.gain && filled.task.rule_threshold[3] == cfg.task.rule_threshold[3]);
    TEST_ASSERT_TRUE(memcmp(&filled.task, &cfg.task, sizeof cfg.task) == 0);
    TEST_ASSERT_TRUE(filled.critic.threshold == cfg.critic.threshold && filled.actor.reflex == cfg.actor.reflex);
    TEST_ASSERT_TRUE(filled.actor.likelihood_std == cfg.actor.likelihood_std && filled.search.floor == cfg.search.floor);
    TEST_ASSERT_TRUE(filled.search.batch == cfg.search.batch && filled.actor.explore_ticks == cfg.actor.explore_ticks);
    /* must not crash */
    icoac_config_default(NULL);
    icoac_policy_config_default(NULL);
    icoac_ico_config_default(NULL);
    icoac_critic_config_default(NULL);
    icoac_actor_config_default(NULL);
    icoac_search_config_default(NULL);
}

/* One mutation of the default configuration, the status it must produce and the field
 * icoac_config_check_field must name (NULL when OK). */
typedef void (*mutate_fn)(icoac_config_t *cfg);
typedef struct {
    const char *name;
    mutate_fn mutate;
    icoac_status_t expected;
    const char *field;
} config_case_t;

/* MUT: on the default (ICO) configuration; RLMUT: in RL mode, which validates critic and actor;
 * SMUT: in search mode, which validates the search group. */
#define MUT(fname, body) \
    static void fname(icoac_config_t *c) { body; }
#define RLMUT(fname, body)           \
    static void fname(icoac_config_t *c) \
    {                                \
        c->mode = ICOAC_MODE_RL;     \
        body;                        \
    }
#define SMUT(fname, body)            \
    static void fname(icoac_config_t *c) \
    {                                \
        c->mode = ICOAC_MODE_SEARCH; \
        body;                        \
    }

MUT(m_mode_3, c->mode = 3)
MUT(m_mode_neg, c->mode = -1)
MUT(m_reflex_mode_2, c->policy.reflex_mode = 2)
MUT(m_reflex_mode_neg, c->policy.reflex_mode = -1)
RLMUT(m_rl_reflex_mode_2, c->policy.reflex_mode = 2)
MUT(m_timing_2, c->ico.timing = 2)
MUT(m_timing_neg, c->ico.timing = -1)
MUT(m_clip_2, c->policy.clip_inputs = 2)
MUT(m_clip_neg, c->policy.clip_inputs = -1)
RLMUT(m_rl_reflex_2, c->actor.reflex = 2)
RLMUT(m_sample_2, c->actor.act_with_sample = 2)
MUT(m_range0_zero, c->policy.input_range[0] = 0)
MUT(m_range1_neg, c->policy.input_range[1] = -3.5f)
MUT(m_range2_nan, c->policy.input_range[2] = NAN_R)
MUT(m_range3_inf, c->policy.input_range[3] = INF_R)
RLMUT(m_rl_range3_inf, c->policy.input_range[3] = INF_R)
MUT(m_gain_neg, c->policy.gain = -1.0f)
MUT(m_gain_nan, c->policy.gain = NAN_R)
MUT(m_gain_inf, c->policy.gain = INF_R)
RLMUT(m_rl_gain_nan, c->policy.gain = NAN_R)
MUT(m_reflex_force_neg, c->policy.reflex_force = -0.1f)
MUT(m_reflex_force_nan, c->policy.reflex_force = NAN_R)
MUT(m_threshold0_nan, c->task.rule_threshold[0] = NAN_R)
MUT(m_threshold2_inf, c->task.rule_threshold[2] = INF_R)
MUT(m_reflex1_big, c->task.rule_reflex[1] = 1.5f)
MUT(m_rule_input3_n, c->task.rule_input[3] = 4)
RLMUT(m_rl_rule_side1_2, c->task.rule_side[1] = 2)
MUT(m_rule_input0_neg, c->task.rule_input[0] = -1)
MUT(m_late_source_2, c->task.late_source = 2)
MUT(m_n_inputs_zero, c->task.n_inputs = 0)
MUT(m_n_rules_neg, c->task.n_rules = -1)
MUT(m_input_sign0_zero, c->task.input_sign[0] = 0)
RLMUT(m_rl_input_sign3_2, c->task.input_sign[3] = 2)
MUT(m_n_inputs_6_sign5_unset, { c->task.n_inputs = 6; c->policy.input_range[4] = 1; c->policy.input_range[5] = 1;
                                c->task.input_sign[5] = 0; })
MUT(m_n_inputs_6_ranges_unset, c->task.n_inputs = 6)
RLMUT(m_units2_17, c->critic.units[2] = 17)
RLMUT(m_units0_zero, c->critic.units[0] = 0)
RLMUT(m_units_too_many, { c->critic.units[0] = 16; c->critic.units[1] = 16; })
RLMUT(m_units_rows_too_many, { c->critic.units[0] = 2; c->critic.units[1] = 16; c->critic.units[2] = 6;
                               c->critic.units[3] = 1; })
RLMUT(m_rl_n_inputs_6_critic_unset, { c->task.n_inputs = 6; c->policy.input_range[4] = 1; c->policy.input_range[5] = 1;
                                      c->critic.range[4] = 1; c->critic.range[5] = 1; })
MUT(m_ico_rate_neg, c->ico.rate = -1e-9f)
MUT(m_ico_rate_nan, c->ico.rate = NAN_R)
MUT(m_ico_rate_inf, c->ico.rate = INF_R)
RLMUT(m_critic_rate_neg, c->critic.rate = -0.1f)
RLMUT(m_critic_rate_big, c->critic.rate = 10.5f)
RLMUT(m_critic_rate_nan, c->critic.rate = NAN_R)
RLMUT(m_discount_neg, c->critic.discount = -0.01f)
RLMUT(m_discount_big, c->critic.discount = 1.01f)
RLMUT(m_discount_nan, c->critic.discount = NAN_R)
RLMUT(m_td_clip_zero, c->critic.td_clip = 0)
RLMUT(m_td_clip_nan, c->critic.td_clip = NAN_R)
RLMUT(m_critic_range0_zero, c->critic.range[0] = 0)
RLMUT(m_critic_range2_nan, c->critic.range[2] = NAN_R)
RLMUT(m_critic_range3_neg, c->critic.range[3] = -2.0f)
RLMUT(m_threshold_neg, c->critic.threshold = -0.001f)
RLMUT(m_threshold_one, c->critic.threshold = 1.0f)
RLMUT(m_threshold_nan, c->critic.threshold = NAN_R)
RLMUT(m_noise_zero, c->actor.noise_std = 0)
RLMUT(m_noise_nan, c->actor.noise_std = NAN_R)
RLMUT(m_noise_inf, c->actor.noise_std = INF_R)
RLMUT(m_scale_neg, c->actor.scale = -0.5f)
RLMUT(m_scale_nan, c->actor.scale = NAN_R)
RLMUT(m_forget_zero, c->actor.forgetting = 0)
RLMUT(m_forget_big, c->actor.forgetting = 1.001f)
RLMUT(m_forget_nan, c->actor.forgetting = NAN_R)
/* Values once accepted that then gave NaN/Inf (or a critic overrun) in the tick. Both ends bounded. */
MUT(m_range0_subnormal, c->policy.input_range[0] = (icoac_real_t)1e-39)
MUT(m_range1_tiny, c->policy.input_range[1] = (icoac_real_t)9e-7)
MUT(m_range2_huge, c->policy.input_range[2] = (icoac_real_t)1.1e6)
MUT(m_gain_huge, c->policy.gain = (icoac_real_t)1e30)
MUT(m_reflex_force_huge, c->policy.reflex_force = (icoac_real_t)1e38)
MUT(m_threshold1_big, c->task.rule_threshold[1] = (icoac_real_t)1.1e6)
MUT(m_n_inputs_big, c->task.n_inputs = ICOAC_MAX_INPUTS + 1)
MUT(m_ico_rate_huge, c->ico.rate = (icoac_real_t)1e30)
RLMUT(m_td_clip_subnormal, c->critic.td_clip = (icoac_real_t)1e-39)
RLMUT(m_td_clip_huge, c->critic.td_clip = (icoac_real_t)1e30)
RLMUT(m_critic_range0_subnormal, c->critic.range[0] = (icoac_real_t)1e-39)
RLMUT(m_critic_range1_huge, c->critic.range[1] = (icoac_real_t)1e30)
RLMUT(m_noise_tiny, c->actor.noise_std = (icoac_real_t)1e-20)
RLMUT(m_noise_huge, c->actor.noise_std = (icoac_real_t)1e30)
RLMUT(m_scale_huge, c->actor.scale = (icoac_real_t)1e30)
RLMUT(m_forget_tiny, c->actor.forgetting = (icoac_real_t)1e-30)
RLMUT(m_forget_below_half, c->actor.forgetting = (icoac_real_t)0.49)
MUT(m_threshold3_subnormal, c->task.rule_threshold[3] = (icoac_real_t)(REAL_IS_FLOAT ? 1e-39 : 1e-310))
MUT(m_n_rules_big, c->task.n_rules = ICOAC_MAX_RULES + 1)
MUT(m_gain_subnormal, c->policy.gain = (icoac_real_t)(REAL_IS_FLOAT ? 1e-39 : 1e-310))
RLMUT(m_threshold_subnormal, c->critic.threshold = (icoac_real_t)(REAL_IS_FLOAT ? 1e-39 : 1e-310))
/* The learners' fields (method.md, L2-L4, A10), each bound from both sides. */
RLMUT(m_quirks_2, c->critic.quirks = 2)
RLMUT(m_quirks_neg, c->critic.quirks = -1)
RLMUT(m_update_3, c->actor.update = 3)
RLMUT(m_update_neg, c->actor.update = -1)
RLMUT(m_rate_neg, c->actor.rate = (icoac_real_t)-1e-6)
RLMUT(m_rate_big, c->actor.rate = (icoac_real_t)1001)
RLMUT(m_rate_nan, c->actor.rate = NAN_R)
RLMUT(m_rate_inf, c->actor.rate = INF_R)
RLMUT(m_rate_subnormal, c->actor.rate = (icoac_real_t)(REAL_IS_FLOAT ? 1e-39 : 1e-310))
RLMUT(m_lik_subnormal, c->actor.likelihood_std = (icoac_real_t)(REAL_IS_FLOAT ? 1e-39 : 1e-310))
RLMUT(m_lik_tiny, c->actor.likelihood_std = (icoac_real_t)9e-4)
RLMUT(m_lik_big, c->actor.likelihood_std = (icoac_real_t)1001)
RLMUT(m_lik_nan, c->actor.likelihood_std = NAN_R)
RLMUT(m_lik_inf, c->actor.likelihood_std = INF_R)
RLMUT(m_lik_neg, c->actor.likelihood_std = -1)
RLMUT(m_abatch_2, c->actor.batch = 2)
RLMUT(m_abatch_neg, c->actor.batch = -1)
RLMUT(m_explore_neg, c->actor.explore_ticks = -1)
RLMUT(m_explore_big, c->actor.explore_ticks = ICOAC_EXPLORE_TICKS_MAX + 1)
RLMUT(m_explore_min, c->actor.explore_ticks = INT32_MIN)
SMUT(m_sbatch_zero, c->search.batch = 0)
SMUT(m_sbatch_neg, c->search.batch = -1)
SMUT(m_sbatch_big, c->search.batch = ICOAC_SEARCH_BATCH_MAX + 1)
SMUT(m_elite_zero, c->search.elite_fraction = 0)
SMUT(m_elite_neg, c->search.elite_fraction = (icoac_real_t)-0.5)
SMUT(m_elite_big, c->search.elite_fraction = (icoac_real_t)1.001)
SMUT(m_elite_nan, c->search.elite_fraction = NAN_R)
SMUT(m_elite_subnormal, c->search.elite_fraction = (icoac_real_t)(REAL_IS_FLOAT ? 1e-39 : 1e-310))
SMUT(m_step_zero, c->search.step = 0)
SMUT(m_step_neg, c->search.step = (icoac_real_t)-0.5)
SMUT(m_step_big, c->search.step = (icoac_real_t)1.001)
SMUT(m_step_nan, c->search.step = NAN_R)
SMUT(m_floor_zero, c->search.floor = 0)
SMUT(m_floor_tiny, c->search.floor = (icoac_real_t)9e-7)
SMUT(m_floor_big, c->search.floor = (icoac_real_t)1001)
SMUT(m_floor_nan, c->search.floor = NAN_R)
SMUT(m_floor_inf, c->search.floor = INF_R)
SMUT(m_cov_scale_below_one, c->search.cov_scale = (icoac_real_t)0.999)
SMUT(m_cov_scale_zero, c->search.cov_scale = 0)
SMUT(m_cov_scale_big, c->search.cov_scale = (icoac_real_t)1001)
SMUT(m_cov_scale_nan, c->search.cov_scale = NAN_R)
SMUT(m_cov_scale_inf, c->search.cov_scale = INF_R)
SMUT(m_search_learn_2, c->learn = 2)
SMUT(m_search_gain_nan, c->policy.gain = NAN_R)
/* Several bad fields: the first in struct order (mode, policy, then the mode's groups) is named. */
MUT(m_two_policy_fields, { c->policy.gain = INF_R; c->policy.input_range[2] = NAN_R; })
MUT(m_task_before_policy, { c->policy.input_range[0] = NAN_R; c->task.rule_reflex[3] = 2; })
RLMUT(m_policy_before_critic, { c->critic.rate = NAN_R; c->policy.gain = -1.0f; })
RLMUT(m_critic_before_actor, { c->actor.noise_std = 0; c->critic.threshold = 1.0f; })
SMUT(m_policy_before_search, { c->search.batch = 0; c->policy.gain = INF_R; })
SMUT(m_search_in_order, { c->search.cov_scale = 0; c->search.floor = 0; c->search.step = 0;
                          c->search.elite_fraction = 0; })
SMUT(m_search_batch_first, { c->search.cov_scale = 0; c->search.batch = 0; })
RLMUT(m_actor_new_in_order, { c->actor.explore_ticks = -1; c->actor.batch = 2; c->actor.likelihood_std = -1;
                              c->actor.rate = -1; c->actor.update = 3; })
RLMUT(m_quirks_before_actor, { c->actor.update = 3; c->critic.quirks = 2; })
MUT(m_mode_before_all, { c->mode = 7; c->policy.gain = NAN_R; c->ico.rate = NAN_R; })
/* Boundary values that are valid. */
RLMUT(ok_range_bounds, { c->policy.input_range[0] = (icoac_real_t)1e-6; c->policy.input_range[1] = (icoac_real_t)1e6;
                         c->critic.range[2] = (icoac_real_t)1e-6; c->critic.range[3] = (icoac_real_t)1e6; })
MUT(ok_upper_bounds_ico, { c->policy.gain = (icoac_real_t)1e4; c->policy.reflex_force = (icoac_real_t)1e4;
                           c->ico.rate = 1; })
RLMUT(ok_upper_bounds_rl, { c->policy.gain = (icoac_real_t)1e4; c->policy.reflex_force = (icoac_real_t)1e4;
                            c->critic.td_clip = (icoac_real_t)1e3; c->actor.noise_std = (icoac_real_t)1e3;
                            c->actor.scale = (icoac_real_t)1e3; })
RLMUT(ok_lower_bounds, { c->critic.td_clip = (icoac_real_t)1e-6; c->actor.noise_std = (icoac_real_t)1e-3; })
MUT(ok_mode_search, c->mode = ICOAC_MODE_SEARCH)
RLMUT(ok_rl_learner_lower, { c->critic.quirks = 1; c->actor.update = ICOAC_ACTOR_GRADIENT; c->actor.rate = 0;
                             c->actor.likelihood_std = ICOAC_NOISE_STD_MIN; c->actor.batch = 1;
                             c->actor.explore_ticks = 0; })
RLMUT(ok_rl_learner_upper, { c->actor.update = ICOAC_ACTOR_MEAN; c->actor.rate = ICOAC_ACTOR_RATE_MAX;
                             c->actor.likelihood_std = ICOAC_NOISE_STD_MAX;
                             c->actor.explore_ticks = ICOAC_EXPLORE_TICKS_MAX; })
RLMUT(ok_explore_one, c->actor.explore_ticks = 1)
RLMUT(ok_likelihood_follows_noise, c->actor.likelihood_std = 0)
SMUT(ok_search_lower, { c->search.batch = 1; c->search.elite_fraction = (icoac_real_t)1e-6;
                        c->search.step = (icoac_real_t)1e-6; c->search.floor = ICOAC_SEARCH_FLOOR_MIN;
                        c->search.cov_scale = 1; })
SMUT(ok_search_upper, { c->search.batch = ICOAC_SEARCH_BATCH_MAX; c->search.elite_fraction = 1;
                        c->search.step = 1; c->search.floor = ICOAC_SEARCH_FLOOR_MAX;
                        c->search.cov_scale = ICOAC_SEARCH_COV_SCALE_MAX; })
SMUT(ok_search_no_learning, { c->learn = 0; c->policy.reflex_mode = ICOAC_REFLEX_GAIN; c->policy.clip_inputs = 0; })
MUT(ok_gain_zero, c->policy.gain = 0)
MUT(ok_reflex_force_zero, c->policy.reflex_force = 0)
MUT(ok_ico_rate_zero, c->ico.rate = 0)
RLMUT(ok_discount_zero, c->critic.discount = 0)
RLMUT(ok_discount_one, c->critic.discount = 1)
RLMUT(ok_critic_rate_ten, c->critic.rate = 10)
RLMUT(ok_threshold, c->critic.threshold = 0.999f)
RLMUT(ok_forget, c->actor.forgetting = 0.5f)
RLMUT(ok_scale_zero, c->actor.scale = 0)
RLMUT(ok_rl_gain_literal, { c->policy.reflex_mode = ICOAC_REFLEX_GAIN; c->ico.timing = ICOAC_ICO_TIMING_LITERAL;
                            c->policy.clip_inputs = 0; c->actor.reflex = 0; c->actor.act_with_sample = 1; })
MUT(ok_sensor_ignores_rules, { c->task.late_source = ICOAC_LATE_SENSOR; c->task.rule_input[0] = 99;
                                c->task.rule_threshold[1] = NAN_R; })
MUT(ok_no_rules, { c->task.n_rules = 0; c->task.rule_side[0] = 5; })
MUT(ok_rule_bounds, { c->task.rule_threshold[0] = ICOAC_RULE_THRESHOLD_MAX; c->task.rule_threshold[1] = -ICOAC_RULE_THRESHOLD_MAX;
                      c->task.rule_reflex[2] = 0; c->task.rule_reflex[3] = (icoac_real_t)0.25; })
MUT(ok_one_input, { c->task.n_inputs = 1; c->task.n_rules = 1; c->task.rule_input[0] = 0; })
MUT(ok_input_signs, { c->task.input_sign[0] = -1; c->task.input_sign[3] = -1; c->task.input_sign[4] = 0; })
RLMUT(ok_six_inputs, { c->task.n_inputs = 6; c->policy.input_range[4] = 1; c->policy.input_range[5] = 1;
                       c->critic.range[4] = 1; c->critic.range[5] = 1; c->critic.units[0] = 3; c->critic.units[1] = 3;
                       c->critic.units[2] = 3; c->critic.units[3] = 2; c->critic.units[4] = 2; c->critic.units[5] = 2; })
RLMUT(ok_units_max_per_input, { c->critic.units[0] = 1; c->critic.units[1] = 1; c->critic.units[2] = 16;
                                c->critic.units[3] = 13; })
MUT(ok_ico_gain_literal, { c->policy.reflex_mode = ICOAC_REFLEX_GAIN; c->ico.timing = ICOAC_ICO_TIMING_LITERAL;
                           c->policy.clip_inputs = 0; })

static const config_case_t config_cases[] = {
    {"mode=3", m_mode_3, ICOAC_ERR_BAD_MODE, "mode"},
    {"mode=-1", m_mode_neg, ICOAC_ERR_BAD_MODE, "mode"},
    {"policy.reflex_mode=2", m_reflex_mode_2, ICOAC_ERR_BAD_MODE, "policy.reflex_mode"},
    {"policy.reflex_mode=-1", m_reflex_mode_neg, ICOAC_ERR_BAD_MODE, "policy.reflex_mode"},
    {"RL, policy.reflex_mode=2", m_rl_reflex_mode_2, ICOAC_ERR_BAD_MODE, "policy.reflex_mode"},
    {"ico.timing=2", m_timing_2, ICOAC_ERR_BAD_MODE, "ico.timing"},
    {"ico.timing=-1", m_timing_neg, ICOAC_ERR_BAD_MODE, "ico.timing"},
    {"policy.clip_inputs=2", m_clip_2, ICOAC_ERR_BAD_MODE, "policy.clip_inputs"},
    {"policy.clip_inputs=-1", m_clip_neg, ICOAC_ERR_BAD_MODE, "policy.clip_inputs"},
    {"RL, actor.reflex=2", m_rl_reflex_2, ICOAC_ERR_BAD_MODE, "actor.reflex"},
    {"RL, actor.act_with_sample=2", m_sample_2, ICOAC_ERR_BAD_MODE, "actor.act_with_sample"},
    {"policy.input_range[0]=0", m_range0_zero, ICOAC_ERR_BAD_SCALE, "policy.input_range[0]"},
    {"policy.input_range[1]<0", m_range1_neg, ICOAC_ERR_BAD_SCALE, "policy.input_range[1]"},
    {"policy.input_range[2]=NaN", m_range2_nan, ICOAC_ERR_BAD_SCALE, "policy.input_range[2]"},
    {"policy.input_range[3]=Inf", m_range3_inf, ICOAC_ERR_BAD_SCALE, "policy.input_range[3]"},
    {"RL, policy.input_range[3]=Inf", m_rl_range3_inf, ICOAC_ERR_BAD_SCALE, "policy.input_range[3]"},
    {"policy.gain<0", m_gain_neg, ICOAC_ERR_BAD_GAIN, "policy.gain"},
    {"policy.gain=NaN", m_gain_nan, ICOAC_ERR_BAD_GAIN, "policy.gain"},
    {"policy.gain=Inf", m_gain_inf, ICOAC_ERR_BAD_GAIN, "policy.gain"},
    {"RL, policy.gain=NaN", m_rl_gain_nan, ICOAC_ERR_BAD_GAIN, "policy.gain"},
    {"policy.reflex_force<0", m_reflex_force_neg, ICOAC_ERR_BAD_GAIN, "policy.reflex_force"},
    {"policy.reflex_force=NaN", m_reflex_force_nan, ICOAC_ERR_BAD_GAIN, "policy.reflex_force"},
    {"task.rule_threshold[0]=NaN", m_threshold0_nan, ICOAC_ERR_BAD_ZONE, "task.rule_threshold[0]"},
    {"task.rule_threshold[2]=Inf", m_threshold2_inf, ICOAC_ERR_BAD_ZONE, "task.rule_threshold[2]"},
    {"task.rule_reflex[1]=1.5", m_reflex1_big, ICOAC_ERR_BAD_ZONE, "task.rule_reflex[1]"},
    {"task.rule_input[3]=n", m_rule_input3_n, ICOAC_ERR_BAD_TASK, "task.rule_input[3]"},
    {"RL, task.rule_side[1]=2", m_rl_rule_side1_2, ICOAC_ERR_BAD_TASK, "task.rule_side[1]"},
    {"task.rule_input[0]=-1", m_rule_input0_neg, ICOAC_ERR_BAD_TASK, "task.rule_input[0]"},
    {"task.late_source=2", m_late_source_2, ICOAC_ERR_BAD_TASK, "task.late_source"},
    {"task.n_inputs=0", m_n_inputs_zero, ICOAC_ERR_BAD_TASK, "task.n_inputs"},
    {"task.n_rules=-1", m_n_rules_neg, ICOAC_ERR_BAD_TASK, "task.n_rules"},
    {"task.input_sign[0]=0", m_input_sign0_zero, ICOAC_ERR_BAD_TASK, "task.input_sign[0]"},
    {"RL, task.input_sign[3]=2", m_rl_input_sign3_2, ICOAC_ERR_BAD_TASK, "task.input_sign[3]"},
    {"task.n_inputs=6, task.input_sign[5]=0", m_n_inputs_6_sign5_unset, ICOAC_ERR_BAD_TASK, "task.input_sign[5]"},
    {"task.n_inputs=6, ranges 4-5 unset", m_n_inputs_6_ranges_unset, ICOAC_ERR_BAD_SCALE, "policy.input_range[4]"},
    {"RL, critic.units[2]=17", m_units2_17, ICOAC_ERR_BAD_CRITIC, "critic.units[2]"},
    {"RL, critic.units[0]=0", m_units0_zero, ICOAC_ERR_BAD_CRITIC, "critic.units[0]"},
    {"RL, critic.units 16x16x6x3", m_units_too_many, ICOAC_ERR_BAD_CRITIC, "critic.units"},
    {"RL, critic.units 2x16x6x1: 32 rows", m_units_rows_too_many, ICOAC_ERR_BAD_CRITIC, "critic.units"},
    {"RL, task.n_inputs=6, critic.units[4] unset", m_rl_n_inputs_6_critic_unset, ICOAC_ERR_BAD_CRITIC,
     "critic.units[4]"},
    {"ico.rate<0", m_ico_rate_neg, ICOAC_ERR_BAD_ICO_RATE, "ico.rate"},
    {"ico.rate=NaN", m_ico_rate_nan, ICOAC_ERR_BAD_ICO_RATE, "ico.rate"},
    {"ico.rate=Inf", m_ico_rate_inf, ICOAC_ERR_BAD_ICO_RATE, "ico.rate"},
    {"RL, critic.rate<0", m_critic_rate_neg, ICOAC_ERR_BAD_CRITIC, "critic.rate"},
    {"RL, critic.rate>10", m_critic_rate_big, ICOAC_ERR_BAD_CRITIC, "critic.rate"},
    {"RL, critic.rate=NaN", m_critic_rate_nan, ICOAC_ERR_BAD_CRITIC, "critic.rate"},
    {"RL, critic.discount<0", m_discount_neg, ICOAC_ERR_BAD_CRITIC, "critic.discount"},
    {"RL, critic.discount>1", m_discount_big, ICOAC_ERR_BAD_CRITIC, "critic.discount"},
    {"RL, critic.discount=NaN", m_discount_nan, ICOAC_ERR_BAD_CRITIC, "critic.discount"},
    {"RL, critic.td_clip=0", m_td_clip_zero, ICOAC_ERR_BAD_CRITIC, "critic.td_clip"},
    {"RL, critic.td_clip=NaN", m_td_clip_nan, ICOAC_ERR_BAD_CRITIC, "critic.td_clip"},
    {"RL, critic.range[0]=0", m_critic_range0_zero, ICOAC_ERR_BAD_CRITIC, "critic.range[0]"},
    {"RL, critic.range[2]=NaN", m_critic_range2_nan, ICOAC_ERR_BAD_CRITIC, "critic.range[2]"},
    {"RL, critic.range[3]<0", m_critic_range3_neg, ICOAC_ERR_BAD_CRITIC, "critic.range[3]"},
    {"RL, critic.threshold<0", m_threshold_neg, ICOAC_ERR_BAD_CRITIC, "critic.threshold"},
    {"RL, critic.threshold=1", m_threshold_one, ICOAC_ERR_BAD_CRITIC, "critic.threshold"},
    {"RL, critic.threshold=NaN", m_threshold_nan, ICOAC_ERR_BAD_CRITIC, "critic.threshold"},
    {"RL, actor.noise_std=0", m_noise_zero, ICOAC_ERR_BAD_ACTOR, "actor.noise_std"},
    {"RL, actor.noise_std=NaN", m_noise_nan, ICOAC_ERR_BAD_ACTOR, "actor.noise_std"},
    {"RL, actor.noise_std=Inf", m_noise_inf, ICOAC_ERR_BAD_ACTOR, "actor.noise_std"},
    {"RL, actor.scale<0", m_scale_neg, ICOAC_ERR_BAD_ACTOR, "actor.scale"},
    {"RL, actor.scale=NaN", m_scale_nan, ICOAC_ERR_BAD_ACTOR, "actor.scale"},
    {"RL, actor.forgetting=0", m_forget_zero, ICOAC_ERR_BAD_ACTOR, "actor.forgetting"},
    {"RL, actor.forgetting>1", m_forget_big, ICOAC_ERR_BAD_ACTOR, "actor.forgetting"},
    {"RL, actor.forgetting=NaN", m_forget_nan, ICOAC_ERR_BAD_ACTOR, "actor.forgetting"},
    {"policy.input_range[0]=1e-39", m_range0_subnormal, ICOAC_ERR_BAD_SCALE, "policy.input_range[0]"},
    {"policy.input_range[1]=9e-7", m_range1_tiny, ICOAC_ERR_BAD_SCALE, "policy.input_range[1]"},
    {"policy.input_range[2]=1.1e6", m_range2_huge, ICOAC_ERR_BAD_SCALE, "policy.input_range[2]"},
    {"policy.gain=1e30", m_gain_huge, ICOAC_ERR_BAD_GAIN, "policy.gain"},
    {"policy.reflex_force=1e38", m_reflex_force_huge, ICOAC_ERR_BAD_GAIN, "policy.reflex_force"},
    {"task.rule_threshold[1]=1.1e6", m_threshold1_big, ICOAC_ERR_BAD_ZONE, "task.rule_threshold[1]"},
    {"task.n_inputs=max+1", m_n_inputs_big, ICOAC_ERR_BAD_TASK, "task.n_inputs"},
    {"ico.rate=1e30", m_ico_rate_huge, ICOAC_ERR_BAD_ICO_RATE, "ico.rate"},
    {"RL, critic.td_clip=1e-39", m_td_clip_subnormal, ICOAC_ERR_BAD_CRITIC, "critic.td_clip"},
    {"RL, critic.td_clip=1e30", m_td_clip_huge, ICOAC_ERR_BAD_CRITIC, "critic.td_clip"},
    {"RL, critic.range[0]=1e-39", m_critic_range0_subnormal, ICOAC_ERR_BAD_CRITIC, "critic.range[0]"},
    {"RL, critic.range[1]=1e30", m_critic_range1_huge, ICOAC_ERR_BAD_CRITIC, "critic.range[1]"},
    {"RL, actor.noise_std=1e-20", m_noise_tiny, ICOAC_ERR_BAD_ACTOR, "actor.noise_std"},
    {"RL, actor.noise_std=1e30", m_noise_huge, ICOAC_ERR_BAD_ACTOR, "actor.noise_std"},
    {"RL, actor.scale=1e30", m_scale_huge, ICOAC_ERR_BAD_ACTOR, "actor.scale"},
    {"RL, actor.forgetting=1e-30", m_forget_tiny, ICOAC_ERR_BAD_ACTOR, "actor.forgetting"},
    {"RL, actor.forgetting=0.49", m_forget_below_half, ICOAC_ERR_BAD_ACTOR, "actor.forgetting"},
    {"task.rule_threshold[3] subnormal", m_threshold3_subnormal, ICOAC_ERR_BAD_ZONE, "task.rule_threshold[3]"},
    {"task.n_rules=max+1", m_n_rules_big, ICOAC_ERR_BAD_TASK, "task.n_rules"},
    {"policy.gain subnormal", m_gain_subnormal, ICOAC_ERR_BAD_GAIN, "policy.gain"},
    {"RL, critic.threshold subnormal", m_threshold_subnormal, ICOAC_ERR_BAD_CRITIC, "critic.threshold"},
    {"RL, critic.quirks=2", m_quirks_2, ICOAC_ERR_BAD_MODE, "critic.quirks"},
    {"RL, critic.quirks=-1", m_quirks_neg, ICOAC_ERR_BAD_MODE, "critic.quirks"},
    {"RL, actor.update=3", m_update_3, ICOAC_ERR_BAD_MODE, "actor.update"},
    {"RL, actor.update=-1", m_update_neg, ICOAC_ERR_BAD_MODE, "actor.update"},
    {"RL, actor.rate<0", m_rate_neg, ICOAC_ERR_BAD_ACTOR, "actor.rate"},
    {"RL, actor.rate>1e3", m_rate_big, ICOAC_ERR_BAD_ACTOR, "actor.rate"},
    {"RL, actor.rate=NaN", m_rate_nan, ICOAC_ERR_BAD_ACTOR, "actor.rate"},
    {"RL, actor.rate=Inf", m_rate_inf, ICOAC_ERR_BAD_ACTOR, "actor.rate"},
    {"RL, actor.rate subnormal", m_rate_subnormal, ICOAC_ERR_BAD_ACTOR, "actor.rate"},
    {"RL, actor.likelihood_std subnormal", m_lik_subnormal, ICOAC_ERR_BAD_ACTOR, "actor.likelihood_std"},
    {"RL, actor.likelihood_std=9e-4", m_lik_tiny, ICOAC_ERR_BAD_ACTOR, "actor.likelihood_std"},
    {"RL, actor.likelihood_std>1e3", m_lik_big, ICOAC_ERR_BAD_ACTOR, "actor.likelihood_std"},
    {"RL, actor.likelihood_std=NaN", m_lik_nan, ICOAC_ERR_BAD_ACTOR, "actor.likelihood_std"},
    {"RL, actor.likelihood_std=Inf", m_lik_inf, ICOAC_ERR_BAD_ACTOR, "actor.likelihood_std"},
    {"RL, actor.likelihood_std<0", m_lik_neg, ICOAC_ERR_BAD_ACTOR, "actor.likelihood_std"},
    {"RL, actor.batch=2", m_abatch_2, ICOAC_ERR_BAD_MODE, "actor.batch"},
    {"RL, actor.batch=-1", m_abatch_neg, ICOAC_ERR_BAD_MODE, "actor.batch"},
    {"RL, actor.explore_ticks=-1", m_explore_neg, ICOAC_ERR_BAD_ACTOR, "actor.explore_ticks"},
    {"RL, actor.explore_ticks>1e8", m_explore_big, ICOAC_ERR_BAD_ACTOR, "actor.explore_ticks"},
    {"RL, actor.explore_ticks=INT32_MIN", m_explore_min, ICOAC_ERR_BAD_ACTOR, "actor.explore_ticks"},
    {"search, search.batch=0", m_sbatch_zero, ICOAC_ERR_BAD_SEARCH, "search.batch"},
    {"search, search.batch=-1", m_sbatch_neg, ICOAC_ERR_BAD_SEARCH, "search.batch"},
    {"search, search.batch=17", m_sbatch_big, ICOAC_ERR_BAD_SEARCH, "search.batch"},
    {"search, search.elite_fraction=0", m_elite_zero, ICOAC_ERR_BAD_SEARCH, "search.elite_fraction"},
    {"search, search.elite_fraction<0", m_elite_neg, ICOAC_ERR_BAD_SEARCH, "search.elite_fraction"},
    {"search, search.elite_fraction>1", m_elite_big, ICOAC_ERR_BAD_SEARCH, "search.elite_fraction"},
    {"search, search.elite_fraction=NaN", m_elite_nan, ICOAC_ERR_BAD_SEARCH, "search.elite_fraction"},
    {"search, search.elite_fraction subnormal", m_elite_subnormal, ICOAC_ERR_BAD_SEARCH, "search.elite_fraction"},
    {"search, search.step=0", m_step_zero, ICOAC_ERR_BAD_SEARCH, "search.step"},
    {"search, search.step<0", m_step_neg, ICOAC_ERR_BAD_SEARCH, "search.step"},
    {"search, search.step>1", m_step_big, ICOAC_ERR_BAD_SEARCH, "search.step"},
    {"search, search.step=NaN", m_step_nan, ICOAC_ERR_BAD_SEARCH, "search.step"},
    {"search, search.floor=0", m_floor_zero, ICOAC_ERR_BAD_SEARCH, "search.floor"},
    {"search, search.floor=9e-7", m_floor_tiny, ICOAC_ERR_BAD_SEARCH, "search.floor"},
    {"search, search.floor>1e3", m_floor_big, ICOAC_ERR_BAD_SEARCH, "search.floor"},
    {"search, search.floor=NaN", m_floor_nan, ICOAC_ERR_BAD_SEARCH, "search.floor"},
    {"search, search.floor=Inf", m_floor_inf, ICOAC_ERR_BAD_SEARCH, "search.floor"},
    {"search, search.cov_scale=0.999", m_cov_scale_below_one, ICOAC_ERR_BAD_SEARCH, "search.cov_scale"},
    {"search, search.cov_scale=0", m_cov_scale_zero, ICOAC_ERR_BAD_SEARCH, "search.cov_scale"},
    {"search, search.cov_scale>1e3", m_cov_scale_big, ICOAC_ERR_BAD_SEARCH, "search.cov_scale"},
    {"search, search.cov_scale=NaN", m_cov_scale_nan, ICOAC_ERR_BAD_SEARCH, "search.cov_scale"},
    {"search, search.cov_scale=Inf", m_cov_scale_inf, ICOAC_ERR_BAD_SEARCH, "search.cov_scale"},
    {"search, learn=2", m_search_learn_2, ICOAC_ERR_BAD_MODE, "learn"},
    {"search, policy.gain=NaN", m_search_gain_nan, ICOAC_ERR_BAD_GAIN, "policy.gain"},
    {"policy.gain and policy.input_range[2]", m_two_policy_fields, ICOAC_ERR_BAD_SCALE, "policy.input_range[2]"},
    {"policy.input_range[0] and task.rule_reflex[3]", m_task_before_policy, ICOAC_ERR_BAD_ZONE, "task.rule_reflex[3]"},
    {"RL, critic.rate and policy.gain", m_policy_before_critic, ICOAC_ERR_BAD_GAIN, "policy.gain"},
    {"RL, actor.noise_std and critic.threshold", m_critic_before_actor, ICOAC_ERR_BAD_CRITIC, "critic.threshold"},
    {"search, search.batch and policy.gain", m_policy_before_search, ICOAC_ERR_BAD_GAIN, "policy.gain"},
    {"search, four search fields", m_search_in_order, ICOAC_ERR_BAD_SEARCH, "search.elite_fraction"},
    {"search, search.cov_scale and search.batch", m_search_batch_first, ICOAC_ERR_BAD_SEARCH, "search.batch"},
    {"RL, five new actor fields", m_actor_new_in_order, ICOAC_ERR_BAD_MODE, "actor.update"},
    {"RL, actor.update and critic.quirks", m_quirks_before_actor, ICOAC_ERR_BAD_MODE, "critic.quirks"},
    {"mode=7 and more", m_mode_before_all, ICOAC_ERR_BAD_MODE, "mode"},
    {"RL, ranges at their bounds", ok_range_bounds, ICOAC_OK, NULL},
    {"ICO upper bounds", ok_upper_bounds_ico, ICOAC_OK, NULL},
    {"RL upper bounds", ok_upper_bounds_rl, ICOAC_OK, NULL},
    {"RL lower bounds", ok_lower_bounds, ICOAC_OK, NULL},
    {"mode=search", ok_mode_search, ICOAC_OK, NULL},
    {"RL, learner fields at their lower bounds", ok_rl_learner_lower, ICOAC_OK, NULL},
    {"RL, learner fields at their upper bounds", ok_rl_learner_upper, ICOAC_OK, NULL},
    {"RL, actor.explore_ticks=1", ok_explore_one, ICOAC_OK, NULL},
    {"RL, actor.likelihood_std=0 (sigma_u)", ok_likelihood_follows_noise, ICOAC_OK, NULL},
    {"search lower bounds", ok_search_lower, ICOAC_OK, NULL},
    {"search upper bounds", ok_search_upper, ICOAC_OK, NULL},
    {"search, no learning, switches at their alternative", ok_search_no_learning, ICOAC_OK, NULL},
    {"policy.gain=0", ok_gain_zero, ICOAC_OK, NULL},
    {"policy.reflex_force=0", ok_reflex_force_zero, ICOAC_OK, NULL},
    {"ico.rate=0", ok_ico_rate_zero, ICOAC_OK, NULL},
    {"RL, critic.discount=0", ok_discount_zero, ICOAC_OK, NULL},
    {"RL, critic.discount=1", ok_discount_one, ICOAC_OK, NULL},
    {"RL, critic.rate=10", ok_critic_rate_ten, ICOAC_OK, NULL},
    {"RL, critic.threshold=0.999", ok_threshold, ICOAC_OK, NULL},
    {"RL, actor.forgetting=0.5", ok_forget, ICOAC_OK, NULL},
    {"RL, actor.scale=0", ok_scale_zero, ICOAC_OK, NULL},
    {"RL, all switches at their alternative", ok_rl_gain_literal, ICOAC_OK, NULL},
    {"ICO, all switches at their alternative", ok_ico_gain_literal, ICOAC_OK, NULL},
    {"sensor late signal: the rules are not checked", ok_sensor_ignores_rules, ICOAC_OK, NULL},
    {"no rules", ok_no_rules, ICOAC_OK, NULL},
    {"rule thresholds and reflexes at their bounds", ok_rule_bounds, ICOAC_OK, NULL},
    {"one input, one rule", ok_one_input, ICOAC_OK, NULL},
    {"input signs -1 (and an unused one 0)", ok_input_signs, ICOAC_OK, NULL},
    {"RL, six inputs, critic 3x3x3x2x2x2", ok_six_inputs, ICOAC_OK, NULL},
    {"RL, critic 1x1x16x13", ok_units_max_per_input, ICOAC_OK, NULL},
};

#define N_CONFIG_CASES (sizeof config_cases / sizeof config_cases[0])

static int starts_with(const char *s, const char *prefix)
{
    return s != NULL && strncmp(s, prefix, strlen(prefix)) == 0;
}

static void test_bad_configs_rejected_state_untouched(void)
{
    size_t n;
    int seen[ICOAC_ERR_BAD_TASK + 1] = {0};
    int s;
    for (n = 0; n < N_CONFIG_CASES; ++n) {
        const config_case_t *c = &config_cases[n];
        icoac_config_t cfg = test_default_config();
        icoac_state_t state;
        icoac_state_t sentinel;
        icoac_status_t got;
        c->mutate(&cfg);
        got = icoac_config_check(&cfg);
        TEST_ASSERT_EQUAL_INT_MESSAGE(c->expected, got, c->name); /* icoac_config_check */
        memset(&state, 0xA5, sizeof state);
        memset(&sentinel, 0xA5, sizeof sentinel);
        got = icoac_init(&cfg, &state, NULL, 7u);
        TEST_ASSERT_EQUAL_INT_MESSAGE(c->expected, got, c->name); /* icoac_init */
        if (c->expected != ICOAC_OK) {
            TEST_ASSERT_EQUAL_MEMORY_MESSAGE(&sentinel, &state, sizeof state, c->name); /* state untouched */
        } else {
            TEST_ASSERT_EQUAL_UINT32(ICOAC_PRIV_STATE_MAGIC, icoac_priv_state_c(&state)->magic);
        }
        seen[c->expected] = 1;
    }
    /* Every named configuration status is exercised. */
    for (s = ICOAC_ERR_BAD_MODE; s <= ICOAC_ERR_BAD_ACTOR; ++s) {
        TEST_ASSERT_TRUE(seen[s]);
    }
    TEST_ASSERT_TRUE(seen[ICOAC_ERR_BAD_SEARCH]);
    TEST_ASSERT_TRUE(seen[ICOAC_ERR_BAD_TASK]);
}

/* icoac_config_check_field names the first bad field of every case, agrees with
 * icoac_config_check, and writes NULL when the configuration is OK. */
static void test_config_cases_name_their_field(void)
{
    size_t n;
    for (n = 0; n < N_CONFIG_CASES; ++n) {
        const config_case_t *c = &config_cases[n];
        icoac_config_t cfg = test_default_config();
        const char *field = "not written";
        icoac_status_t got;
        c->mutate(&cfg);
        got = icoac_config_check_field(&cfg, &field);
        TEST_ASSERT_EQUAL_INT(c->expected, got);
        TEST_ASSERT_EQUAL_INT(icoac_config_check(&cfg), got);
        TEST_ASSERT_EQUAL_INT(got, icoac_config_check_field(&cfg, NULL)); /* field may be NULL */
        if (c->field == NULL) {
            TEST_ASSERT_NULL_MESSAGE(field, c->name);
        } else {
            TEST_ASSERT_EQUAL_STRING_MESSAGE(c->field, field, c->name);
            /* a static string: the same pointer each time, unchanged by the configuration */
            {
                const char *again = NULL;
                TEST_ASSERT_EQUAL_INT(got, icoac_config_check_field(&cfg, &again));
                TEST_ASSERT_EQUAL_PTR(field, again);
            }
        }
    }
    {
        const char *field = "not written";
        TEST_ASSERT_EQUAL_INT(ICOAC_ERR_NULL, icoac_config_check_field(NULL, &field));
        TEST_ASSERT_NULL(field);
        TEST_ASSERT_EQUAL_INT(ICOAC_ERR_NULL, icoac_config_check_field(NULL, NULL));
    }
}

/* Every field of the configuration, in struct order, with the group that validates it: the
 * policy in every mode, ico in ICO mode only, critic and actor in RL mode only, search in
 * search mode only; and a value that is invalid in that field (NaN for a real). */
typedef enum { G_POLICY, G_ICO, G_RL, G_SEARCH, G_UNUSED } group_t;
typedef struct {
    const char *name;
    size_t offset;
    size_t size;
    int is_int;
    group_t group;
    icoac_status_t status;
    int32_t bad_int; /* for an int field */
} config_field_t;

#define MEMBER_SIZE(member) sizeof(((icoac_config_t *)0)->member)
#define REAL_FIELD(member, group, status) \
    {#member, offsetof(icoac_config_t, member), MEMBER_SIZE(member), 0, group, status, 0}
#define INT_FIELD_BAD(member, group, status, bad) \
    {#member, offsetof(icoac_config_t, member), MEMBER_SIZE(member), 1, group, status, bad}
/* 7 is out of range of every switch and 0/1 flag */
#define INT_FIELD(member, group, status) INT_FIELD_BAD(member, group, status, 7)

/* The table lists the default maxima's entries (6 inputs, 6 rules). */
ICOAC_STATIC_ASSERT(ICOAC_MAX_INPUTS == 6 && ICOAC_MAX_RULES == 6, field_table_lists_the_default_maxima);
static const config_field_t config_fields[] = {
    INT_FIELD(learn, G_POLICY, ICOAC_ERR_BAD_MODE), /* checked in every mode, like the policy */
    /* the task: checked in every mode; entries past the cart-pole's 4 inputs and 4 rules unused */
    INT_FIELD(task.n_inputs, G_POLICY, ICOAC_ERR_BAD_TASK),
    INT_FIELD_BAD(task.input_sign[0], G_POLICY, ICOAC_ERR_BAD_TASK, 0),
    INT_FIELD(task.input_sign[1], G_POLICY, ICOAC_ERR_BAD_TASK),
    INT_FIELD_BAD(task.input_sign[2], G_POLICY, ICOAC_ERR_BAD_TASK, -2),
    INT_FIELD(task.input_sign[3], G_POLICY, ICOAC_ERR_BAD_TASK),
    INT_FIELD(task.input_sign[4], G_UNUSED, ICOAC_OK),
    INT_FIELD(task.input_sign[5], G_UNUSED, ICOAC_OK),
    INT_FIELD(task.late_source, G_POLICY, ICOAC_ERR_BAD_TASK),
    INT_FIELD(task.n_rules, G_POLICY, ICOAC_ERR_BAD_TASK),
    INT_FIELD(task.rule_input[0], G_POLICY, ICOAC_ERR_BAD_TASK),
    INT_FIELD(task.rule_input[1], G_POLICY, ICOAC_ERR_BAD_TASK),
    INT_FIELD(task.rule_input[2], G_POLICY, ICOAC_ERR_BAD_TASK),
    INT_FIELD(task.rule_input[3], G_POLICY, ICOAC_ERR_BAD_TASK),
    INT_FIELD(task.rule_input[4], G_UNUSED, ICOAC_OK),
    INT_FIELD(task.rule_input[5], G_UNUSED, ICOAC_OK),
    INT_FIELD(task.rule_side[0], G_POLICY, ICOAC_ERR_BAD_TASK),
    INT_FIELD(task.rule_side[1], G_POLICY, ICOAC_ERR_BAD_TASK),
    INT_FIELD(task.rule_side[2], G_POLICY, ICOAC_ERR_BAD_TASK),
    INT_FIELD(task.rule_side[3], G_POLICY, ICOAC_ERR_BAD_TASK),
    INT_FIELD(task.rule_side[4], G_UNUSED, ICOAC_OK),
    INT_FIELD(task.rule_side[5], G_UNUSED, ICOAC_OK),
    REAL_FIELD(task.rule_threshold[0], G_POLICY, ICOAC_ERR_BAD_ZONE),
    REAL_FIELD(task.rule_threshold[1], G_POLICY, ICOAC_ERR_BAD_ZONE),
    REAL_FIELD(task.rule_threshold[2], G_POLICY, ICOAC_ERR_BAD_ZONE),
    REAL_FIELD(task.rule_threshold[3], G_POLICY, ICOAC_ERR_BAD_ZONE),
    REAL_FIELD(task.rule_threshold[4], G_UNUSED, ICOAC_OK),
    REAL_FIELD(task.rule_threshold[5], G_UNUSED, ICOAC_OK),
    REAL_FIELD(task.rule_reflex[0], G_POLICY, ICOAC_ERR_BAD_ZONE),
    REAL_FIELD(task.rule_reflex[1], G_POLICY, ICOAC_ERR_BAD_ZONE),
    REAL_FIELD(task.rule_reflex[2], G_POLICY, ICOAC_ERR_BAD_ZONE),
    REAL_FIELD(task.rule_reflex[3], G_POLICY, ICOAC_ERR_BAD_ZONE),
    REAL_FIELD(task.rule_reflex[4], G_UNUSED, ICOAC_OK),
    REAL_FIELD(task.rule_reflex[5], G_UNUSED, ICOAC_OK),
    REAL_FIELD(policy.input_range[0], G_POLICY, ICOAC_ERR_BAD_SCALE),
    REAL_FIELD(policy.input_range[1], G_POLICY, ICOAC_ERR_BAD_SCALE),
    REAL_FIELD(policy.input_range[2], G_POLICY, ICOAC_ERR_BAD_SCALE),
    REAL_FIELD(policy.input_range[3], G_POLICY, ICOAC_ERR_BAD_SCALE),
    REAL_FIELD(policy.input_range[4], G_UNUSED, ICOAC_OK),
    REAL_FIELD(policy.input_range[5], G_UNUSED, ICOAC_OK),
    INT_FIELD(policy.clip_inputs, G_POLICY, ICOAC_ERR_BAD_MODE),
    REAL_FIELD(policy.gain, G_POLICY, ICOAC_ERR_BAD_GAIN),
    INT_FIELD(policy.reflex_mode, G_POLICY, ICOAC_ERR_BAD_MODE),
    REAL_FIELD(policy.reflex_force, G_POLICY, ICOAC_ERR_BAD_GAIN),
    REAL_FIELD(ico.rate, G_ICO, ICOAC_ERR_BAD_ICO_RATE),
    INT_FIELD(ico.timing, G_ICO, ICOAC_ERR_BAD_MODE),
    REAL_FIELD(critic.rate, G_RL, ICOAC_ERR_BAD_CRITIC),
    REAL_FIELD(critic.discount, G_RL, ICOAC_ERR_BAD_CRITIC),
    REAL_FIELD(critic.td_clip, G_RL, ICOAC_ERR_BAD_CRITIC),
    REAL_FIELD(critic.range[0], G_RL, ICOAC_ERR_BAD_CRITIC),
    REAL_FIELD(critic.range[1], G_RL, ICOAC_ERR_BAD_CRITIC),
    REAL_FIELD(critic.range[2], G_RL, ICOAC_ERR_BAD_CRITIC),
    REAL_FIELD(critic.range[3], G_RL, ICOAC_ERR_BAD_CRITIC),
    REAL_FIELD(critic.range[4], G_UNUSED, ICOAC_OK),
    REAL_FIELD(critic.range[5], G_UNUSED, ICOAC_OK),
    INT_FIELD_BAD(critic.units[0], G_RL, ICOAC_ERR_BAD_CRITIC, 17),
    INT_FIELD_BAD(critic.units[1], G_RL, ICOAC_ERR_BAD_CRITIC, 0),
    INT_FIELD_BAD(critic.units[2], G_RL, ICOAC_ERR_BAD_CRITIC, -1),
    INT_FIELD_BAD(critic.units[3], G_RL, ICOAC_ERR_BAD_CRITIC, 17),
    INT_FIELD(critic.units[4], G_UNUSED, ICOAC_OK),
    INT_FIELD(critic.units[5], G_UNUSED, ICOAC_OK),
    REAL_FIELD(critic.threshold, G_RL, ICOAC_ERR_BAD_CRITIC),
    INT_FIELD(critic.quirks, G_RL, ICOAC_ERR_BAD_MODE),
    REAL_FIELD(actor.noise_std, G_RL, ICOAC_ERR_BAD_ACTOR),
    REAL_FIELD(actor.scale, G_RL, ICOAC_ERR_BAD_ACTOR),
    REAL_FIELD(actor.forgetting, G_RL, ICOAC_ERR_BAD_ACTOR),
    INT_FIELD(actor.reflex, G_RL, ICOAC_ERR_BAD_MODE),
    INT_FIELD(actor.act_with_sample, G_RL, ICOAC_ERR_BAD_MODE),
    INT_FIELD(actor.update, G_RL, ICOAC_ERR_BAD_MODE),
    REAL_FIELD(actor.rate, G_RL, ICOAC_ERR_BAD_ACTOR),
    REAL_FIELD(actor.likelihood_std, G_RL, ICOAC_ERR_BAD_ACTOR),
    INT_FIELD(actor.batch, G_RL, ICOAC_ERR_BAD_MODE),
    INT_FIELD_BAD(actor.explore_ticks, G_RL, ICOAC_ERR_BAD_ACTOR, -1), /* 7 ticks is valid */
    INT_FIELD_BAD(search.batch, G_SEARCH, ICOAC_ERR_BAD_SEARCH, ICOAC_SEARCH_BATCH_MAX + 1),
    REAL_FIELD(search.elite_fraction, G_SEARCH, ICOAC_ERR_BAD_SEARCH),
    REAL_FIELD(search.step, G_SEARCH, ICOAC_ERR_BAD_SEARCH),
    REAL_FIELD(search.floor, G_SEARCH, ICOAC_ERR_BAD_SEARCH),
    REAL_FIELD(search.cov_scale, G_SEARCH, ICOAC_ERR_BAD_SEARCH),
};

#define N_CONFIG_FIELDS ((int)(sizeof config_fields / sizeof config_fields[0]))

/* The modes, and the first value past them. */
#define N_MODES (ICOAC_MODE_SEARCH + 1)

/* NaN for a real, the field's bad value for a switch or count. */
static void spoil(icoac_config_t *cfg, const config_field_t *f)
{
    unsigned char *bytes = (unsigned char *)cfg;
    if (f->is_int) {
        memcpy(bytes + f->offset, &f->bad_int, sizeof f->bad_int);
    } else {
        const icoac_real_t bad = NAN_R;
        memcpy(bytes + f->offset, &bad, sizeof bad);
    }
}

static int validated(const config_field_t *f, int32_t mode)
{
    switch (f->group) {
    case G_POLICY: return 1;
    case G_ICO: return mode == ICOAC_MODE_ICO;
    case G_RL: return mode == ICOAC_MODE_RL;
    case G_SEARCH: return mode == ICOAC_MODE_SEARCH;
    default: return 0;
    }
}

/* The table above lists every member of icoac_config_t: with `mode` it covers each byte that
 * is not padding, in struct order, without overlap (a new field the table misses fails here). */
static void test_field_table_covers_config(void)
{
    size_t end = sizeof(int32_t); /* mode, at offset 0 */
    size_t covered = sizeof(int32_t);
    int i;
    TEST_ASSERT_EQUAL_size_t(0, offsetof(icoac_config_t, mode));
    for (i = 0; i < N_CONFIG_FIELDS; ++i) {
        const config_field_t *f = &config_fields[i];
        TEST_ASSERT_EQUAL_size_t(f->is_int ? sizeof(int32_t) : sizeof(icoac_real_t), f->size);
        if (f->offset < end) {
            TEST_PRINTF("%s at %u overlaps the field before (end %u)", f->name, (unsigned)f->offset, (unsigned)end);
            TEST_FAIL();
        }
        /* a gap is alignment padding only: shorter than the member's alignment */
        if (f->offset - end >= f->size) {
            TEST_PRINTF("%u bytes before %s are not listed", (unsigned)(f->offset - end), f->name);
            TEST_FAIL();
        }
        end = f->offset + f->size;
        covered += f->size;
    }
    TEST_ASSERT_TRUE(sizeof(icoac_config_t) - end < sizeof(icoac_real_t));
    if (REAL_IS_FLOAT) {
        TEST_ASSERT_EQUAL_size_t(sizeof(icoac_config_t), covered); /* no padding with float reals */
    }
}

/* One bad field at a time: named with its group's status where the mode uses the group,
 * ignored (OK, and a working controller) where it does not. */
static void test_each_field_named_or_ignored(void)
{
    int32_t mode;
    int i;
    for (mode = ICOAC_MODE_ICO; mode < N_MODES; ++mode) {
        for (i = 0; i < N_CONFIG_FIELDS; ++i) {
            const config_field_t *f = &config_fields[i];
            icoac_config_t cfg = test_default_config();
            const char *field = "not written";
            icoac_status_t got;
            cfg.mode = mode;
            spoil(&cfg, f);
            got = icoac_config_check_field(&cfg, &field);
            if (validated(f, mode)) {
                if (got != f->status || field == NULL || strcmp(field, f->name) != 0) {
                    TEST_PRINTF("mode %d, bad %s: status %d field %s", (int)mode, f->name, (int)got,
                                field ? field : "NULL");
                    TEST_FAIL();
                }
            } else {
                icoac_state_t state;
                icoac_output_t out;
                icoac_input_t in = test_input(0.1, -0.2, 0.05, 0.3, 0);
                if (got != ICOAC_OK || field != NULL) {
                    TEST_PRINTF("mode %d ignores %s, but: status %d field %s", (int)mode, f->name, (int)got,
                                field ? field : "NULL");
                    TEST_FAIL();
                }
                TEST_ASSERT_EQUAL_INT(ICOAC_OK, icoac_init(&cfg, &state, NULL, 3u));
                TEST_ASSERT_EQUAL_INT(ICOAC_OK, icoac_step(&state, &in, &out));
                TEST_ASSERT_EQUAL_INT(ICOAC_OK, icoac_step(&state, &in, &out));
                TEST_ASSERT_TRUE(isfinite((double)out.force));
            }
        }
    }
}

/* Spoiling the fields from the last to the first, each check names the one just spoiled: the
 * check walks the mode, the policy, then the mode's groups, in struct order. */
static void test_check_order_is_struct_order(void)
{
    int32_t mode;
    int i;
    for (mode = ICOAC_MODE_ICO; mode < N_MODES; ++mode) {
        icoac_config_t cfg = test_default_config();
        const char *field = NULL;
        cfg.mode = mode;
        for (i = N_CONFIG_FIELDS - 1; i >= 0; --i) {
            const config_field_t *f = &config_fields[i];
            if (!validated(f, mode)) {
                continue;
            }
            spoil(&cfg, f);
            TEST_ASSERT_EQUAL_INT(f->status, icoac_config_check_field(&cfg, &field));
            TEST_ASSERT_NOT_NULL(field);
            TEST_ASSERT_EQUAL_STRING(f->name, field);
        }
        cfg.mode = N_MODES;
        TEST_ASSERT_EQUAL_INT(ICOAC_ERR_BAD_MODE, icoac_config_check_field(&cfg, &field));
        TEST_ASSERT_EQUAL_STRING("mode", field);
        cfg.mode = -1;
        TEST_ASSERT_EQUAL_INT(ICOAC_ERR_BAD_MODE, icoac_config_check_field(&cfg, &field));
        TEST_ASSERT_EQUAL_STRING("mode", field);
    }
}

/* A mode ignores the groups it does not use, even when every field of them is bad: ICO runs
 * with a spoilt critic, actor and search, RL with a spoilt ico and search group (new with
 * the one-file-per-stage restructuring), search with a spoilt ico, critic and actor. The
 * controller behaves exactly as with valid unused groups. */
static void test_unused_groups_ignored(void)
{
    int32_t mode;
    for (mode = ICOAC_MODE_ICO; mode < N_MODES; ++mode) {
        icoac_config_t cfg = test_default_config();
        icoac_config_t clean;
        icoac_state_t state, twin;
        test_rng_t rng = {(uint64_t)mode + 17u};
        const char *field = "not written";
        int i, k;
        cfg.mode = mode;
        clean = cfg;
        for (i = 0; i < N_CONFIG_FIELDS; ++i) {
            if (!validated(&config_fields[i], mode)) {
                spoil(&cfg, &config_fields[i]);
            }
        }
        TEST_ASSERT_EQUAL_INT(ICOAC_OK, icoac_config_check_field(&cfg, &field));
        TEST_ASSERT_NULL(field);
        TEST_ASSERT_EQUAL_INT(ICOAC_OK, icoac_init(&cfg, &state, NULL, 21u));
        TEST_ASSERT_EQUAL_INT(ICOAC_OK, icoac_init(&clean, &twin, NULL, 21u));
        for (k = 0; k < 300; ++k) {
            icoac_output_t out, out_twin;
            icoac_input_t in = test_input(test_uniform(&rng, -2.5, 2.5), test_uniform(&rng, -3, 3),
                                          test_uniform(&rng, -0.25, 0.25), test_uniform(&rng, -3, 3),
                                          k % 40 == 39 ? ICOAC_INPUT_TERMINAL : 0u);
            memset(&out, 0, sizeof out);
            memset(&out_twin, 0, sizeof out_twin);
            TEST_ASSERT_EQUAL_INT(ICOAC_OK, icoac_step(&state, &in, &out));
            TEST_ASSERT_EQUAL_INT(ICOAC_OK, icoac_step(&twin, &in, &out_twin));
            TEST_ASSERT_EQUAL_MEMORY(&out_twin, &out, sizeof out);
            if (k % 40 == 39) {
                TEST_ASSERT_EQUAL_INT(ICOAC_OK, icoac_reset(&state));
                TEST_ASSERT_EQUAL_INT(ICOAC_OK, icoac_reset(&twin));
            }
        }
        /* the same state but for the unused groups of the configuration it keeps */
        icoac_priv_state(&state)->config = clean;
        TEST_ASSERT_EQUAL_MEMORY(&twin, &state, sizeof state);
    }
    /* the case table's rejections of a mode's own group, in every other mode */
    {
        size_t n;
        int32_t other;
        int tried = 0;
        for (n = 0; n < N_CONFIG_CASES; ++n) {
            const config_case_t *c = &config_cases[n];
            int32_t owner;
            if (starts_with(c->field, "critic.") || starts_with(c->field, "actor.")) {
                owner = ICOAC_MODE_RL;
            } else if (starts_with(c->field, "ico.")) {
                owner = ICOAC_MODE_ICO;
            } else if (starts_with(c->field, "search.")) {
                owner = ICOAC_MODE_SEARCH;
            } else {
                continue;
            }
            for (other = ICOAC_MODE_ICO; other < N_MODES; ++other) {
                icoac_config_t cfg = test_default_config();
                icoac_state_t state;
                const char *field = "not written";
                if (other == owner) {
                    continue;
                }
                c->mutate(&cfg);
                cfg.mode = other;
                if (icoac_config_check_field(&cfg, &field) != ICOAC_OK || field != NULL) {
                    TEST_PRINTF("case %s in mode %d: not ignored (field %s)", c->name, (int)other,
                                field ? field : "NULL");
                    TEST_FAIL();
                }
                TEST_ASSERT_EQUAL_INT(ICOAC_OK, icoac_init(&cfg, &state, NULL, 1u));
                ++tried;
            }
        }
        TEST_ASSERT_TRUE(tried > 100);
    }
}

static void expect_bad_prior(const icoac_prior_t *prior, const char *name)
{
    icoac_config_t cfg = test_default_config();
    icoac_state_t state;
    icoac_state_t sentinel;
    icoac_status_t got;
    int mode;
    TEST_ASSERT_EQUAL_INT(ICOAC_ERR_BAD_PRIOR, icoac_prior_check(prior, ICOAC_CARTPOLE_INPUTS));
    for (mode = ICOAC_MODE_ICO; mode < N_MODES; ++mode) {
        cfg.mode = mode;
        memset(&state, 0x5A, sizeof state);
        memset(&sentinel, 0x5A, sizeof sentinel);
        got = icoac_init(&cfg, &state, prior, 1u);
        TEST_ASSERT_EQUAL_INT_MESSAGE(ICOAC_ERR_BAD_PRIOR, got, name);
        TEST_ASSERT_EQUAL_MEMORY(&sentinel, &state, sizeof state);
    }
}

static void test_bad_priors(void)
{
    icoac_prior_t p;
    /* Non-symmetric (but with a PD symmetric part). */
    p = test_prior(0, 0, 0, 0, 1.0);
    p.cov[0][1] = (icoac_real_t)0.1;
    expect_bad_prior(&p, "non-symmetric");
    /* Symmetric, indefinite: eigenvalues of [[1,2],[2,1]] are 3 and -1. */
    p = test_prior(0, 0, 0, 0, 1.0);
    p.cov[1][2] = p.cov[2][1] = (icoac_real_t)2.0;
    expect_bad_prior(&p, "indefinite");
    /* Positive semi-definite, singular. */
    p = test_prior(0, 0, 0, 0, 1.0);
    p.cov[3][3] = 0;
    expect_bad_prior(&p, "singular");
    /* Negative diagonal. */
    p = test_prior(0, 0, 0, 0, 1.0);
    p.cov[0][0] = -1;
    expect_bad_prior(&p, "negative diagonal");
    /* Non-finite mean. */
    p = test_prior(0, (double)NAN, 0, 0, 1.0);
    expect_bad_prior(&p, "NaN mean");
    p = test_prior(0, 0, 0, (double)INFINITY, 1.0);
    expect_bad_prior(&p, "Inf mean");
    /* Non-finite covariance entries, symmetric. */
    p = test_prior(0, 0, 0, 0, 1.0);
    p.cov[2][3] = p.cov[3][2] = NAN_R;
    expect_bad_prior(&p, "NaN cov");
    p = test_prior(0, 0, 0, 0, 1.0);
    p.cov[1][1] = INF_R;
    expect_bad_prior(&p, "Inf cov");
}

static void test_init_prior_copied(void)
{
    icoac_config_t cfg = test_default_config();
    icoac_state_t state;
    icoac_prior_t p = test_prior(0.1, -0.2, 0.3, -0.4, 2.0);
    icoac_prior_t post;
    int i, j;
    p.cov[0][3] = p.cov[3][0] = (icoac_real_t)0.5;
    TEST_ASSERT_EQUAL_INT(ICOAC_OK, icoac_prior_check(&p, ICOAC_CARTPOLE_INPUTS));
    TEST_ASSERT_EQUAL_INT(ICOAC_OK, icoac_init(&cfg, &state, &p, 3u));
    TEST_ASSERT_EQUAL_INT(ICOAC_OK, icoac_get_posterior(&state, &post));
    TEST_ASSERT_EQUAL_MEMORY(p.mean, post.mean, sizeof p.mean);
    TEST_ASSERT_EQUAL_MEMORY(p.cov, post.cov, sizeof p.cov);
    /* NULL prior: mean 0, covariance I. */
    TEST_ASSERT_EQUAL_INT(ICOAC_OK, icoac_init(&cfg, &state, NULL, 3u));
    TEST_ASSERT_EQUAL_INT(ICOAC_OK, icoac_get_posterior(&state, &post));
    for (i = 0; i < ICOAC_CARTPOLE_INPUTS; ++i) {
        TEST_ASSERT_TRUE(post.mean[i] == 0);
        for (j = 0; j < ICOAC_CARTPOLE_INPUTS; ++j) {
            TEST_ASSERT_TRUE(post.cov[i][j] == (i == j ? 1 : 0));
        }
    }
    {
        const icoac_priv_state_t *st = icoac_priv_state_c(&state);
        for (i = 0; i < ICOAC_CARTPOLE_CRITIC_UNITS; ++i) {
            TEST_ASSERT_TRUE(st->v[i] == 0);
        }
        TEST_ASSERT_TRUE(st->penalty_prev == 0);
        TEST_ASSERT_EQUAL_INT(0, st->cov_slot);
        TEST_ASSERT_EQUAL_MEMORY(post.cov, icoac_priv_cov_c(st), sizeof post.cov);
    }
}

static void test_null_pointers(void)
{
    icoac_config_t cfg = test_default_config();
    icoac_state_t state;
    icoac_input_t in = test_input(0, 0, 0, 0, 0);
    icoac_output_t out;
    icoac_prior_t post;
    icoac_counters_t counters;
    TEST_ASSERT_EQUAL_INT(ICOAC_ERR_NULL, icoac_config_check(NULL));
    TEST_ASSERT_EQUAL_INT(ICOAC_ERR_NULL, icoac_prior_check(NULL, ICOAC_CARTPOLE_INPUTS));
    TEST_ASSERT_EQUAL_INT(ICOAC_ERR_NULL, icoac_init(NULL, &state, NULL, 0u));
    TEST_ASSERT_EQUAL_INT(ICOAC_ERR_NULL, icoac_init(&cfg, NULL, NULL, 0u));
    TEST_ASSERT_EQUAL_INT(ICOAC_OK, icoac_init(&cfg, &state, NULL, 0u));
    TEST_ASSERT_EQUAL_INT(ICOAC_ERR_NULL, icoac_reset(NULL));
    TEST_ASSERT_EQUAL_INT(ICOAC_ERR_NULL, icoac_retune(NULL, &cfg));
    TEST_ASSERT_EQUAL_INT(ICOAC_ERR_NULL, icoac_retune(&state, NULL));
    memset(&out, 0x7F, sizeof out);
    TEST_ASSERT_EQUAL_INT(ICOAC_ERR_NULL, icoac_step(NULL, &in, &out));
    TEST_ASSERT_EQUAL_INT(ICOAC_ERR_NULL, out.status);
    TEST_ASSERT_TRUE(out.force == 0);
    memset(&out, 0x7F, sizeof out);
    TEST_ASSERT_EQUAL_INT(ICOAC_ERR_NULL, icoac_step(&state, NULL, &out));
    TEST_ASSERT_EQUAL_INT(ICOAC_ERR_NULL, out.status);
    TEST_ASSERT_TRUE(out.force == 0);
    TEST_ASSERT_EQUAL_INT(ICOAC_ERR_NULL, icoac_step(&state, &in, NULL));
    TEST_ASSERT_EQUAL_INT(ICOAC_ERR_NULL, icoac_get_posterior(NULL, &post));
    TEST_ASSERT_EQUAL_INT(ICOAC_ERR_NULL, icoac_get_posterior(&state, NULL));
    TEST_ASSERT_EQUAL_INT(ICOAC_ERR_NULL, icoac_get_counters(NULL, &counters));
    TEST_ASSERT_EQUAL_INT(ICOAC_ERR_NULL, icoac_get_counters(&state, NULL));
    /* None of the rejected calls counted a tick. */
    memset(&counters, 0xA5, sizeof counters);
    TEST_ASSERT_EQUAL_INT(ICOAC_OK, icoac_get_counters(&state, &counters));
    TEST_ASSERT_EQUAL_UINT32(0, counters.ticks);
    TEST_ASSERT_EQUAL_UINT32(0, counters.nonfinite);
    TEST_ASSERT_EQUAL_UINT32(0, counters.numeric_faults);
}

static void test_not_initialised(void)
{
    icoac_state_t state;
    icoac_state_t copy;
    icoac_input_t in = test_input(0.1, 0, 0.05, 0, 0);
    icoac_output_t out;
    icoac_prior_t post;
    icoac_counters_t counters;
    memset(&state, 0, sizeof state);
    memset(&out, 0x7F, sizeof out);
    copy = state;
    TEST_ASSERT_EQUAL_INT(ICOAC_ERR_NOT_INITIALISED, icoac_step(&state, &in, &out));
    TEST_ASSERT_EQUAL_INT(ICOAC_ERR_NOT_INITIALISED, out.status);
    TEST_ASSERT_TRUE(out.force == 0);
    TEST_ASSERT_EQUAL_INT(ICOAC_ERR_NOT_INITIALISED, icoac_reset(&state));
    TEST_ASSERT_EQUAL_INT(ICOAC_ERR_NOT_INITIALISED, icoac_get_posterior(&state, &post));
    TEST_ASSERT_EQUAL_INT(ICOAC_ERR_NOT_INITIALISED, icoac_get_counters(&state, &counters));
    TEST_ASSERT_EQUAL_MEMORY(&copy, &state, sizeof state);
    /* Garbage is not mistaken for an initialised state. */
    memset(&state, 0xA5, sizeof state);
    copy = state;
    TEST_ASSERT_EQUAL_INT(ICOAC_ERR_NOT_INITIALISED, icoac_step(&state, &in, &out));
    TEST_ASSERT_EQUAL_INT(ICOAC_ERR_NOT_INITIALISED, icoac_get_counters(&state, &counters));
    TEST_ASSERT_EQUAL_MEMORY(&copy, &state, sizeof state);
}

static void test_status_strings(void)
{
    static const icoac_status_t all[] = {
        ICOAC_OK, ICOAC_ERR_NULL, ICOAC_ERR_NOT_INITIALISED, ICOAC_ERR_NONFINITE_INPUT, ICOAC_ERR_NUMERIC,
        ICOAC_ERR_TRIAL_ENDED, ICOAC_ERR_CORRUPT_STATE, ICOAC_ERR_RETUNE_MODE, ICOAC_ERR_BAD_MODE, ICOAC_ERR_BAD_SCALE, ICOAC_ERR_BAD_GAIN, ICOAC_ERR_BAD_ZONE,
        ICOAC_ERR_BAD_ICO_RATE, ICOAC_ERR_BAD_CRITIC, ICOAC_ERR_BAD_ACTOR, ICOAC_ERR_BAD_PRIOR,
        ICOAC_ERR_BAD_SEARCH};
    const size_t n = sizeof all / sizeof all[0];
    const char *unknown;
    size_t i, j;
    int raw;
    unknown = icoac_status_str((icoac_status_t)999);
    TEST_ASSERT_NOT_NULL(unknown);
    for (i = 0; i < n; ++i) {
        const char *s = icoac_status_str(all[i]);
        TEST_ASSERT_NOT_NULL(s);
        TEST_ASSERT_TRUE(strlen(s) > 0);
        /* Named statuses have their own text, distinct from each other and from "unknown". */
        TEST_ASSERT_TRUE_MESSAGE(strcmp(s, unknown) != 0, s);
        for (j = 0; j < i; ++j) {
            TEST_ASSERT_TRUE_MESSAGE(strcmp(s, icoac_status_str(all[j])) != 0, s);
        }
    }
    for (raw = -5; raw < 200; ++raw) {
        TEST_ASSERT_NOT_NULL(icoac_status_str((icoac_status_t)raw));
    }
}

/* The library's version is the header's, MAJOR.MINOR.PATCH of its three numbers. */
static void test_version(void)
{
    const char *v = icoac_version();
    char expected[32];
    int major = ICOAC_VERSION_MAJOR, minor = ICOAC_VERSION_MINOR, patch = ICOAC_VERSION_PATCH;
    int parts[3];
    int p, k = 0;
    TEST_ASSERT_NOT_NULL(v);
    TEST_ASSERT_EQUAL_STRING(ICOAC_VERSION_STRING, v);
    parts[0] = major;
    parts[1] = minor;
    parts[2] = patch;
    /* the expected text written digit by digit (no stdio on the cores) */
    for (p = 0; p < 3; ++p) {
        char digits[12];
        int d = 0, x = parts[p];
        TEST_ASSERT_TRUE(x >= 0);
        do {
            digits[d++] = (char)('0' + x % 10);
            x /= 10;
        } while (x > 0);
        while (d > 0) {
            expected[k++] = digits[--d];
        }
        expected[k++] = p < 2 ? '.' : '\0';
    }
    TEST_ASSERT_EQUAL_STRING(expected, v);
}

static void test_sizeof_functions(void)
{
    TEST_ASSERT_EQUAL_UINT32(ICOAC_ABI_VERSION, icoac_abi_version());
    TEST_ASSERT_EQUAL_INT(10, ICOAC_ABI_VERSION);
    TEST_ASSERT_EQUAL_INT(19, ICOAC_ERR_BAD_TASK);
    TEST_ASSERT_EQUAL_INT(18, ICOAC_ERR_BAD_SEARCH);
    TEST_ASSERT_EQUAL_INT(2, ICOAC_MODE_SEARCH);
    TEST_ASSERT_EQUAL_INT(0, ICOAC_ACTOR_POSTERIOR);
    TEST_ASSERT_EQUAL_INT(1, ICOAC_ACTOR_MEAN);
    TEST_ASSERT_EQUAL_INT(2, ICOAC_ACTOR_GRADIENT);
    TEST_ASSERT_EQUAL_size_t(sizeof(icoac_real_t), icoac_sizeof_real());
    TEST_ASSERT_EQUAL_UINT32(REAL_IS_FLOAT ? 4 : 8, icoac_sizeof_real());
    TEST_ASSERT_EQUAL_size_t(sizeof(icoac_config_t), icoac_sizeof_config());
    TEST_ASSERT_EQUAL_size_t(sizeof(icoac_state_t), icoac_sizeof_state());
    TEST_ASSERT_EQUAL_size_t(sizeof(icoac_input_t), icoac_sizeof_input());
    TEST_ASSERT_EQUAL_size_t(sizeof(icoac_output_t), icoac_sizeof_output());
    TEST_ASSERT_EQUAL_size_t(sizeof(icoac_prior_t), icoac_sizeof_prior());
    /* The caller's storage is the documented size, 8-byte aligned, and holds the private layout. */
    TEST_ASSERT_EQUAL_size_t(ICOAC_STATE_SIZE, sizeof(icoac_state_t));
    TEST_ASSERT_TRUE(_Alignof(icoac_state_t) >= 8);
    TEST_ASSERT_TRUE(sizeof(icoac_priv_state_t) <= sizeof(icoac_state_t));
    TEST_ASSERT_TRUE(_Alignof(icoac_priv_state_t) <= _Alignof(icoac_state_t));
}

void setUp(void) {}
void tearDown(void) {}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_defaults_match_spec);
    RUN_TEST(test_bad_configs_rejected_state_untouched);
    RUN_TEST(test_config_cases_name_their_field);
    RUN_TEST(test_field_table_covers_config);
    RUN_TEST(test_each_field_named_or_ignored);
    RUN_TEST(test_check_order_is_struct_order);
    RUN_TEST(test_unused_groups_ignored);
    RUN_TEST(test_bad_priors);
    RUN_TEST(test_init_prior_copied);
    RUN_TEST(test_null_pointers);
    RUN_TEST(test_not_initialised);
    RUN_TEST(test_status_strings);
    RUN_TEST(test_version);
    RUN_TEST(test_sizeof_functions);
    return UNITY_END();
}
