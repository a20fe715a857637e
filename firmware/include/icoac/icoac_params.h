/* SPDX-License-Identifier: Apache-2.0 */
/* The controller's parameters, each described once: one row per field of icoac_config_t, one
 * list per group, in struct order. From these rows come the structs' members (icoac.h), the
 * defaults, the checks and the names they report (icoac_config.c), and the host's parameter
 * table (icoac_sim_params, which the harness, its command line and docs/design.md read).
 *
 * ICOAC_PARAM(group, field, type, dim, check, unit, min, max, def, modes, tier, status, doc):
 * - group, field: the member cfg->group.field (group `config`: cfg->field);
 * - type: icoac_real_t or int32_t (the run's rows: int64_t, double); dim: scalar, inputs (ICOAC_MAX_INPUTS entries, the first
 *   task.n_inputs checked and used) or rules (ICOAC_MAX_RULES, the first task.n_rules);
 * - check, with min and max (C constants of the field's type):
 *   real: min <= v <= max, v zero or normal; real_open_lo: min < v <= max; real_open_hi:
 *   min <= v < max; real_or_zero: v == 0 or min <= v <= max; int, flag (0/1), choice (an enum
 *   of values min..max): min <= v <= max; sign: v == min or v == max; at_least: min <= v (max:
 *   the type's); index: min <= v < task.n_inputs; units: int, and the units' product fits the
 *   critic (ICOAC_MAX_CRITIC_UNITS, blocks of ICOAC_CRITIC_BLOCK_MAX);
 * - unit: the field's unit ("" for none; "input" for the unit of the input it applies to);
 * - def: the default of a scalar, and of every entry of the task group's input arrays (the other
 *   arrays and the task's sizes and rules: the task preset, icoac_task_cartpole);
 * - modes: the modes that read it (ICOAC_PARAM_ICO | ICOAC_PARAM_RL | ICOAC_PARAM_SEARCH);
 * - tier: essential (a user tunes it) or advanced (a reading of the method, a guard rail);
 * - status: the icoac_status_t of a value the check refuses; doc: one line for humans.
 * A new parameter is a row here, plus the code that reads it. */
#ifndef ICOAC_PARAMS_H
#define ICOAC_PARAMS_H

/* The modes column: a bit per icoac_mode_t value. */
#define ICOAC_PARAM_ICO 1u
#define ICOAC_PARAM_RL 2u
#define ICOAC_PARAM_SEARCH 4u
#define ICOAC_PARAM_ALL 7u

/* The designator prefix of each group ("policy.gain"; the top level has none). */
#define ICOAC_PARAM_PREFIX_config ""
#define ICOAC_PARAM_PREFIX_task "task."
#define ICOAC_PARAM_PREFIX_policy "policy."
#define ICOAC_PARAM_PREFIX_ico "ico."
#define ICOAC_PARAM_PREFIX_critic "critic."
#define ICOAC_PARAM_PREFIX_actor "actor."
#define ICOAC_PARAM_PREFIX_search "search."

/* The array length of each dim. */
#define ICOAC_PARAM_DIM_scalar
#define ICOAC_PARAM_DIM_inputs [ICOAC_MAX_INPUTS]
#define ICOAC_PARAM_DIM_rules [ICOAC_MAX_RULES]

/* clang-format off */
#define ICOAC_PARAMS_CONFIG(X) \
    X(config, mode, int32_t, scalar, choice, "", ICOAC_MODE_ICO, ICOAC_MODE_SEARCH, ICOAC_MODE_ICO, ICOAC_PARAM_ALL, essential, ICOAC_ERR_BAD_MODE, \
      "learning condition: ico, rl (NGnet critic + Bayesian actor) or search (episodic search)") \
    X(config, learn, int32_t, scalar, flag, "", 0, 1, 1, ICOAC_PARAM_ALL, essential, ICOAC_ERR_BAD_MODE, \
      "1: learn; 0: every update off (w, Sigma_w, v fixed), the no-learning control")

/* The task: its sizes, input signs and late-signal source, then its rule table (checked only
 * when it is the source). */
#define ICOAC_PARAMS_TASK(X) ICOAC_PARAMS_TASK_SIZES(X) ICOAC_PARAMS_TASK_RULES(X)
#define ICOAC_PARAMS_TASK_SIZES(X) \
    X(task, n_inputs, int32_t, scalar, int, "", 1, ICOAC_MAX_INPUTS, ICOAC_CARTPOLE_INPUTS, ICOAC_PARAM_ALL, essential, ICOAC_ERR_BAD_TASK, \
      "inputs n of the task: observations s_0 .. s_{n-1} per tick") \
    X(task, input_sign, int32_t, inputs, sign, "", -1, 1, 1, ICOAC_PARAM_ALL, essential, ICOAC_ERR_BAD_TASK, \
      "sign of the scaled input i: the sign ICO's growing w_i pushes input i with (method.md, L8)") \
    X(task, late_source, int32_t, scalar, choice, "", ICOAC_LATE_RULES, ICOAC_LATE_SENSOR, ICOAC_LATE_RULES, ICOAC_PARAM_ALL, advanced, ICOAC_ERR_BAD_TASK, \
      "late signal from the rule table (rules) or the plant's sensor flag (sensor)") \
    X(task, n_rules, int32_t, scalar, int, "", 0, ICOAC_MAX_RULES, ICOAC_CARTPOLE_RULES, ICOAC_PARAM_ALL, essential, ICOAC_ERR_BAD_TASK, \
      "rules in the late-signal table, checked in order, the first match wins")
#define ICOAC_PARAMS_TASK_RULES(X) \
    X(task, rule_input, int32_t, rules, index, "", 0, ICOAC_MAX_INPUTS - 1, 0, ICOAC_PARAM_ALL, essential, ICOAC_ERR_BAD_TASK, \
      "input a rule tests, below task.n_inputs") \
    X(task, rule_side, int32_t, rules, choice, "", ICOAC_RULE_BELOW, ICOAC_RULE_ABOVE, ICOAC_RULE_BELOW, ICOAC_PARAM_ALL, essential, ICOAC_ERR_BAD_TASK, \
      "a rule matches when its input is below or above its threshold") \
    X(task, rule_threshold, icoac_real_t, rules, real, "input", -ICOAC_RULE_THRESHOLD_MAX, ICOAC_RULE_THRESHOLD_MAX, ICOAC_R(0.0), ICOAC_PARAM_ALL, essential, ICOAC_ERR_BAD_ZONE, \
      "threshold of a rule, in its input's unit") \
    X(task, rule_reflex, icoac_real_t, rules, real, "", ICOAC_R(-1.0), ICOAC_R(1.0), ICOAC_R(0.0), ICOAC_PARAM_ALL, essential, ICOAC_ERR_BAD_ZONE, \
      "reflex U of a rule's match (penalty r = -1)")

#define ICOAC_PARAMS_POLICY(X) \
    X(policy, input_range, icoac_real_t, inputs, real, "input", ICOAC_RANGE_MIN, ICOAC_RANGE_MAX, ICOAC_R(1.0), ICOAC_PARAM_ALL, essential, ICOAC_ERR_BAD_SCALE, \
      "input i is scaled to x~_i = task.input_sign[i] * s_i / input_range[i]") \
    X(policy, clip_inputs, int32_t, scalar, flag, "", 0, 1, 1, ICOAC_PARAM_ALL, advanced, ICOAC_ERR_BAD_MODE, \
      "1: clip the scaled inputs to [-1, 1]") \
    X(policy, gain, icoac_real_t, scalar, real, "N", ICOAC_R(0.0), ICOAC_GAIN_MAX, ICOAC_R(10.0), ICOAC_PARAM_ALL, essential, ICOAC_ERR_BAD_GAIN, \
      "G: force per unit of the feature z = w^T x~") \
    X(policy, reflex_mode, int32_t, scalar, choice, "", ICOAC_REFLEX_UNIT, ICOAC_REFLEX_GAIN, ICOAC_REFLEX_UNIT, ICOAC_PARAM_ALL, advanced, ICOAC_ERR_BAD_MODE, \
      "reflex force U * reflex_force (unit, Eq. 5) or G * U (gain, the authors' code)") \
    X(policy, reflex_force, icoac_real_t, scalar, real, "N", ICOAC_R(0.0), ICOAC_FORCE_MAX, ICOAC_R(1.0), ICOAC_PARAM_ALL, essential, ICOAC_ERR_BAD_GAIN, \
      "force per unit reflex U with reflex_mode unit")

#define ICOAC_PARAMS_ICO(X) \
    X(ico, rate, icoac_real_t, scalar, real, "", ICOAC_R(0.0), ICOAC_ICO_RATE_MAX, ICOAC_R(1.0e-4), ICOAC_PARAM_ICO, essential, ICOAC_ERR_BAD_ICO_RATE, \
      "mu: the ICO learning rate") \
    X(ico, timing, int32_t, scalar, choice, "", ICOAC_ICO_TIMING_CODE, ICOAC_ICO_TIMING_LITERAL, ICOAC_ICO_TIMING_CODE, ICOAC_PARAM_ICO, advanced, ICOAC_ERR_BAD_MODE, \
      "when the rule sees the penalty: code (pre-step state) or literal (post-step, Eq. 2-3)")

#define ICOAC_PARAMS_CRITIC(X) \
    X(critic, rate, icoac_real_t, scalar, real, "", ICOAC_R(0.0), ICOAC_CRITIC_RATE_MAX, ICOAC_R(0.6), ICOAC_PARAM_RL, essential, ICOAC_ERR_BAD_CRITIC, \
      "eta_c: the critic's learning rate") \
    X(critic, discount, icoac_real_t, scalar, real, "", ICOAC_R(0.0), ICOAC_R(1.0), ICOAC_R(0.95), ICOAC_PARAM_RL, essential, ICOAC_ERR_BAD_CRITIC, \
      "gamma: discount per tick") \
    X(critic, td_clip, icoac_real_t, scalar, real, "", ICOAC_TD_CLIP_MIN, ICOAC_TD_CLIP_MAX, ICOAC_R(1.0), ICOAC_PARAM_RL, advanced, ICOAC_ERR_BAD_CRITIC, \
      "limit of |delta|, the TD error") \
    X(critic, range, icoac_real_t, inputs, real, "input", ICOAC_RANGE_MIN, ICOAC_RANGE_MAX, ICOAC_R(1.0), ICOAC_PARAM_RL, essential, ICOAC_ERR_BAD_CRITIC, \
      "half-width of the critic's grid along input i") \
    X(critic, units, int32_t, inputs, units, "", 1, ICOAC_CRITIC_UNITS_PER_INPUT_MAX, 1, ICOAC_PARAM_RL, essential, ICOAC_ERR_BAD_CRITIC, \
      "Gaussian units along input i; their product at most ICOAC_MAX_CRITIC_UNITS, in blocks") \
    X(critic, threshold, icoac_real_t, scalar, real_open_hi, "", ICOAC_R(0.0), ICOAC_R(1.0), ICOAC_R(0.001), ICOAC_PARAM_RL, advanced, ICOAC_ERR_BAD_CRITIC, \
      "normalized activations below it are dropped (0: dense)") \
    X(critic, quirks, int32_t, scalar, flag, "", 0, 1, 0, ICOAC_PARAM_RL, advanced, ICOAC_ERR_BAD_MODE, \
      "1: the authors' code (A10): TD update on b(s_t+1), V_old = 0 at a reset")

#define ICOAC_PARAMS_ACTOR(X) \
    X(actor, noise_std, icoac_real_t, scalar, real, "N", ICOAC_NOISE_STD_MIN, ICOAC_NOISE_STD_MAX, ICOAC_R(3.0), ICOAC_PARAM_RL, essential, ICOAC_ERR_BAD_ACTOR, \
      "sigma_u: exploration noise (literal: 1)") \
    X(actor, scale, icoac_real_t, scalar, real, "", ICOAC_R(0.0), ICOAC_ACTOR_SCALE_MAX, ICOAC_R(0.5), ICOAC_PARAM_RL, advanced, ICOAC_ERR_BAD_ACTOR, \
      "alpha: the observed action is mu_u + alpha * delta * eps") \
    X(actor, forgetting, icoac_real_t, scalar, real, "", ICOAC_FORGETTING_MIN, ICOAC_R(1.0), ICOAC_R(1.0), ICOAC_PARAM_RL, advanced, ICOAC_ERR_BAD_ACTOR, \
      "lambda_f of the posterior reading (1: none)") \
    X(actor, reflex, int32_t, scalar, flag, "", 0, 1, 1, ICOAC_PARAM_RL, advanced, ICOAC_ERR_BAD_MODE, \
      "1: the reflex is added to the executed force") \
    X(actor, act_with_sample, int32_t, scalar, flag, "", 0, 1, 0, ICOAC_PARAM_RL, advanced, ICOAC_ERR_BAD_MODE, \
      "1: act with a posterior sample of w per trial; 0: with mu_w") \
    X(actor, update, int32_t, scalar, choice, "", ICOAC_ACTOR_POSTERIOR, ICOAC_ACTOR_GRADIENT, ICOAC_ACTOR_GRADIENT, ICOAC_PARAM_RL, essential, ICOAC_ERR_BAD_MODE, \
      "the actor's reading: posterior (Eq. 6-8, literal), mean or gradient") \
    X(actor, rate, icoac_real_t, scalar, real, "", ICOAC_R(0.0), ICOAC_ACTOR_RATE_MAX, ICOAC_R(0.001), ICOAC_PARAM_RL, essential, ICOAC_ERR_BAD_ACTOR, \
      "beta: step of the gradient reading") \
    X(actor, likelihood_std, icoac_real_t, scalar, real_or_zero, "N", ICOAC_NOISE_STD_MIN, ICOAC_NOISE_STD_MAX, ICOAC_R(0.0), ICOAC_PARAM_RL, advanced, ICOAC_ERR_BAD_ACTOR, \
      "sigma_L of the posterior and mean readings; 0: sigma_u (literal)") \
    X(actor, batch, int32_t, scalar, flag, "", 0, 1, 0, ICOAC_PARAM_RL, advanced, ICOAC_ERR_BAD_MODE, \
      "1: accumulate over a trial, one update at its terminal tick (A14)") \
    X(actor, explore_ticks, int32_t, scalar, int, "tick", 0, ICOAC_EXPLORE_TICKS_MAX, 1000, ICOAC_PARAM_RL, essential, ICOAC_ERR_BAD_ACTOR, \
      "no exploration and no actor update from this tick of a trial on; 0: always (literal)")

#define ICOAC_PARAMS_SEARCH(X) \
    X(search, batch, int32_t, scalar, int, "trial", 1, ICOAC_SEARCH_BATCH_MAX, 8, ICOAC_PARAM_SEARCH, essential, ICOAC_ERR_BAD_SEARCH, \
      "K: trials per update") \
    X(search, elite_fraction, icoac_real_t, scalar, real_open_lo, "", ICOAC_R(0.0), ICOAC_R(1.0), ICOAC_R(0.25), ICOAC_PARAM_SEARCH, essential, ICOAC_ERR_BAD_SEARCH, \
      "rho: the best max(1, round(rho K)) trials by length move the search") \
    X(search, step, icoac_real_t, scalar, real_open_lo, "", ICOAC_R(0.0), ICOAC_R(1.0), ICOAC_R(0.5), ICOAC_PARAM_SEARCH, essential, ICOAC_ERR_BAD_SEARCH, \
      "a: step of mu_w and Sigma_w toward the elite") \
    X(search, floor, icoac_real_t, scalar, real, "", ICOAC_SEARCH_FLOOR_MIN, ICOAC_SEARCH_FLOOR_MAX, ICOAC_R(1.0), ICOAC_PARAM_SEARCH, advanced, ICOAC_ERR_BAD_SEARCH, \
      "f: Sigma_ii >= f * Sigma0_ii after each update") \
    X(search, cov_scale, icoac_real_t, scalar, real, "", ICOAC_R(1.0), ICOAC_SEARCH_COV_SCALE_MAX, ICOAC_R(64.0), ICOAC_PARAM_SEARCH, essential, ICOAC_ERR_BAD_SEARCH, \
      "c: Sigma0 = c * the prior covariance")

/* Every row, in the order of icoac_config_t. */
#define ICOAC_PARAMS(X) \
    ICOAC_PARAMS_CONFIG(X) ICOAC_PARAMS_TASK(X) ICOAC_PARAMS_POLICY(X) ICOAC_PARAMS_ICO(X) \
    ICOAC_PARAMS_CRITIC(X) ICOAC_PARAMS_ACTOR(X) ICOAC_PARAMS_SEARCH(X)
/* clang-format on */

/* A row as a struct member: `type field[dim];`. */
#define ICOAC_PARAM_MEMBER(group, field, type, dim, check, unit, min, max, def, modes, tier, status, doc) \
    type field ICOAC_PARAM_DIM_##dim;

#endif /* ICOAC_PARAMS_H */
