/* SPDX-License-Identifier: Apache-2.0 */
/* icoac: ICO-learning / Bayesian actor-critic controller, one 100 Hz tick per call.
 *
 * Allocation-free C99. The caller owns a configuration (may live in flash), a state struct
 * (everything learned, the configuration in force and per-trial caches) and one input/output
 * pair per tick. Call order: icoac_config_default -> edit -> icoac_config_check -> icoac_init,
 * which copies the configuration into the state; then per tick icoac_step, and icoac_reset at
 * each new trial. The state uses its own copy: editing the caller's configuration afterwards
 * changes nothing until icoac_retune checks and applies it (live tuning).
 */
#ifndef ICOAC_H
#define ICOAC_H

#include "icoac_params.h"
#include "icoac_rng.h"
#include "icoac_types.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Learning condition. ICO->RL is ICOAC_MODE_RL with an ICO-derived prior, ICO->search
 * ICOAC_MODE_SEARCH with one. */
typedef enum {
    ICOAC_MODE_ICO = 0,   /* ICO rule on w (Eq. 2-3) */
    ICOAC_MODE_RL = 1,    /* NGnet critic + Bayesian actor on (mu_w, Sigma_w) (Eq. 6-8) */
    ICOAC_MODE_SEARCH = 2 /* episodic search on (mu_w, Sigma_w): one sample per trial (method.md, L4) */
} icoac_mode_t;

/* How the actor moves mu_w (and Sigma_w) per observation (method.md, L2). */
typedef enum {
    ICOAC_ACTOR_POSTERIOR = 0, /* sequential Bayesian posterior (literal Eq. 6-8): Sigma_w shrinks */
    ICOAC_ACTOR_MEAN = 1,      /* posterior-mean step with Sigma_w held at the prior */
    ICOAC_ACTOR_GRADIENT = 2   /* Gaussian-policy gradient step beta * delta * eps * h / sigma_u^2 */
} icoac_actor_update_t;

/* Task description (method.md, the task): what the controller needs to know about a plant.
 * - inputs: n observations s_0 .. s_{n-1} per tick (task.n_inputs), each scaled to x~_i =
 *   s_i / policy.input_range[i] (clipped to [-1, 1] with policy.clip_inputs); the feature is
 *   z = w^T x~ over the n inputs, the prior and the learned weights are n-vectors.
 * - late signal: the penalty r in {-1, 0} that ICO learns from and the reflex U that acts with
 *   it. With ICOAC_LATE_RULES, a table of task.n_rules rules on the raw inputs, checked in order,
 *   the first match wins: rule k matches when s[rule_input[k]] is above (ICOAC_RULE_ABOVE: >)
 *   or below (ICOAC_RULE_BELOW: <) rule_threshold[k], and gives r = -1, U = rule_reflex[k]; no
 *   match gives r = 0, U = 0. With ICOAC_LATE_SENSOR the plant measures it: a tick whose input
 *   has ICOAC_INPUT_LATE set has r = -1 and U = in.reflex, any other tick r = 0, U = 0 (a bump
 *   switch, a limit switch).
 * - critic (RL mode): critic.units[i] normalized Gaussian units along input i over
 *   [-critic.range[i], critic.range[i]], the grid being their product (method.md, critic).
 * - input signs: task.input_sign[i] (+1 or -1) multiplies the scaled input, x~_i = sign_i *
 *   clip(s_i / range_i), so that a weight w_i >= 0 (all ICO learns) pushes with the sign the
 *   plant's stabilising feedback needs on input i (method.md, input signs; a step beyond the
 *   paper). The features, ICO's weights, the actor's and the search's weights and the prior are
 *   in these signed inputs; the rules and the critic read the raw inputs s_i. +1 everywhere: the
 *   paper's controller.
 * The inputs a task does not use (index n and up) are never read. icoac_task_cartpole gives the
 * cart-pole task, which icoac_config_default installs. */
typedef enum {
    ICOAC_LATE_RULES = 0, /* the rule table on the inputs */
    ICOAC_LATE_SENSOR = 1 /* the input's ICOAC_INPUT_LATE flag and reflex */
} icoac_late_source_t;

typedef enum {
    ICOAC_RULE_BELOW = 0, /* matches when s[input] < threshold */
    ICOAC_RULE_ABOVE = 1  /* matches when s[input] > threshold */
} icoac_rule_side_t;

/* How the reflex U (in [-1, 1]; the cart-pole's -1, 0, +1) enters the force (method.md, A2). */
typedef enum {
    ICOAC_REFLEX_UNIT = 0,  /* F = G*z + U*reflex_force (literal Eq. 5, 1 N) */
    ICOAC_REFLEX_GAIN = 1   /* F = G*(z + U) (authors' code, 10 N) */
} icoac_reflex_mode_t;

/* When the ICO rule sees the penalty change (method.md, A4). */
typedef enum {
    ICOAC_ICO_TIMING_CODE = 0,   /* r from the pre-step state, failure states unseen, r_prev persists */
    ICOAC_ICO_TIMING_LITERAL = 1 /* r(t+1) from the post-step state incl. failure, update with x~(t) */
} icoac_ico_timing_t;

/* Valid ranges of the configuration, closed at both ends unless said otherwise; subnormal
 * values are rejected everywhere (a host that flushes them to zero would read 0). Each bound
 * keeps a derived quantity representable in float: 1/range and s*n/range (critic) stay finite
 * and normal, sigma_u^2 stays normal, 1/forgetting stays small. */
#define ICOAC_RANGE_MIN ICOAC_R(1.0e-6)       /* policy.input_range, critic.range (m, m/s, rad, rad/s) */
#define ICOAC_RANGE_MAX ICOAC_R(1.0e6)
#define ICOAC_GAIN_MAX ICOAC_R(1.0e4)         /* policy.gain (N per unit feature), >= 0 */
#define ICOAC_FORCE_MAX ICOAC_R(1.0e4)        /* policy.reflex_force (N), >= 0 */
#define ICOAC_RULE_THRESHOLD_MAX ICOAC_R(1.0e6) /* |task.rule_threshold| (the input's unit) */
#define ICOAC_ICO_RATE_MAX ICOAC_R(1.0)       /* ico.rate, >= 0 */
#define ICOAC_CRITIC_RATE_MAX ICOAC_R(10.0)   /* critic.rate, >= 0 */
#define ICOAC_TD_CLIP_MIN ICOAC_R(1.0e-6)     /* critic.td_clip */
#define ICOAC_TD_CLIP_MAX ICOAC_R(1.0e3)
#define ICOAC_NOISE_STD_MIN ICOAC_R(1.0e-3)   /* actor.noise_std (N) */
#define ICOAC_NOISE_STD_MAX ICOAC_R(1.0e3)
#define ICOAC_ACTOR_SCALE_MAX ICOAC_R(1.0e3)  /* actor.scale, >= 0 */
#define ICOAC_FORGETTING_MIN ICOAC_R(0.5)     /* actor.forgetting, <= 1 */
#define ICOAC_ACTOR_RATE_MAX ICOAC_R(1.0e3)   /* actor.rate, >= 0 */
#define ICOAC_EXPLORE_TICKS_MAX 100000000     /* actor.explore_ticks, >= 0 */
#define ICOAC_SEARCH_BATCH_MAX 16             /* search.batch, >= 1: trials per update */
#define ICOAC_SEARCH_FLOOR_MIN ICOAC_R(1.0e-6) /* search.floor */
#define ICOAC_SEARCH_FLOOR_MAX ICOAC_R(1.0e3)
#define ICOAC_SEARCH_COV_SCALE_MAX ICOAC_R(1.0e3) /* search.cov_scale, >= 1 */

/* Configuration, one group per concern; a mode validates and uses only its groups (ICO:
 * task, policy, ico; RL: task, policy, critic, actor; search: task, policy, search). Integer switches are int32_t
 * so the layout is the same on every ABI. Every field's type, unit, range, default, modes and
 * meaning: its row in icoac_params.h, which also makes the members below. Arrays have room for
 * ICOAC_MAX_INPUTS inputs or ICOAC_MAX_RULES rules; only the first task.n_inputs or task.n_rules
 * entries are checked and used. */

/* Task: the plant's inputs and late signal (above). Defaults: the cart-pole (icoac_task_cartpole). */
typedef struct {
    ICOAC_PARAMS_TASK(ICOAC_PARAM_MEMBER)
} icoac_task_config_t;

/* Policy: how the state becomes the feature z = w^T x~ and the force (every mode). */
typedef struct {
    ICOAC_PARAMS_POLICY(ICOAC_PARAM_MEMBER)
} icoac_policy_config_t;

/* ICO rule (ICOAC_MODE_ICO). */
typedef struct {
    ICOAC_PARAMS_ICO(ICOAC_PARAM_MEMBER)
} icoac_ico_config_t;

/* Normalized-Gaussian critic (ICOAC_MODE_RL). Unit k of the grid is row-major over the inputs
 * (input n-1 fastest). The library evaluates it as rows x cells: the cells are the units of the
 * last inputs, from the first input m at which their product is <= 31, the rows the units of
 * inputs 0 .. m-1; the rows must be <= 31 too (ICOAC_CRITIC_BLOCK_MAX; the cart-pole: 9 x 18). */
typedef struct {
    ICOAC_PARAMS_CRITIC(ICOAC_PARAM_MEMBER)
} icoac_critic_config_t;

/* Actor and exploration (ICOAC_MODE_RL). Every reading observes u_ob = mu_u + alpha*delta*eps. */
typedef struct {
    ICOAC_PARAMS_ACTOR(ICOAC_PARAM_MEMBER)
} icoac_actor_config_t;

/* Episodic search over N(mu_w, Sigma_w) (ICOAC_MODE_SEARCH, method.md L4): each trial acts with one
 * sample w (F = G w^T x~ + reflex, no noise); after `batch` failed trials the best
 * round(elite_fraction * batch) (at least 1) by length move mu_w and Sigma_w by `step`.
 * Defaults chosen by a sweep for the ICO prior (docs/results.md). */
typedef struct {
    ICOAC_PARAMS_SEARCH(ICOAC_PARAM_MEMBER)
} icoac_search_config_t;

typedef struct {
    ICOAC_PARAMS_CONFIG(ICOAC_PARAM_MEMBER)
    icoac_task_config_t task;
    icoac_policy_config_t policy;
    icoac_ico_config_t ico;
    icoac_critic_config_t critic;
    icoac_actor_config_t actor;
    icoac_search_config_t search;
} icoac_config_t;

/* Gaussian prior / posterior of the feature weights w_0 .. w_{n-1} (the cart-pole: w_x, w_xdot,
 * w_theta, w_thetadot). Only the leading n entries of mean and the leading n x n block of cov
 * are read (n = task.n_inputs); icoac_get_posterior writes 0 to the others. A prior must have
 * |mean_i| <= ICOAC_PRIOR_MEAN_MAX, |cov_ij| <= ICOAC_PRIOR_COV_MAX, no subnormal entry, and an
 * exactly symmetric positive definite covariance. */
#define ICOAC_PRIOR_MEAN_MAX ICOAC_R(1.0e6)
#define ICOAC_PRIOR_COV_MAX ICOAC_R(1.0e12)
typedef struct {
    icoac_real_t mean[ICOAC_MAX_INPUTS];
    icoac_real_t cov[ICOAC_MAX_INPUTS][ICOAC_MAX_INPUTS];
} icoac_prior_t;

/* Controller state: caller-owned storage of ICOAC_STATE_SIZE bytes, 8-byte aligned (it may be
 * a static, a stack or a struct member; no heap). Its layout is private and may change
 * between releases: read it through icoac_get_posterior, icoac_get_counters and
 * icoac_get_config. It holds a copy of the configuration in force. Its size follows the build
 * maxima (an upper bound of the layout, checked at compile time to within 128 bytes, rounded up
 * to 64): reals for the configuration copy, the weight vectors, four n x n matrices (two
 * Sigma_w, the batch's information, the search's factor), the search's recorded trials
 * (ICOAC_SEARCH_BATCH_MAX n-vectors), the critic weights (ICOAC_MAX_CRITIC_UNITS) and two
 * kept-unit lists (ICOAC_STATE_LIST reals and bytes each: a critic block's rows and cells).
 * Default maxima: 2,880 bytes with float, 5,440 with double; cart-pole maxima (4 inputs, 4 rules,
 * 162 units): 2,112 / 3,904. */
#define ICOAC_STATE_LIST_BOUND (32 + ICOAC_MAX_CRITIC_UNITS / 31)
#define ICOAC_STATE_LIST (ICOAC_STATE_LIST_BOUND < 63 ? ICOAC_STATE_LIST_BOUND : 63)
#define ICOAC_STATE_REALS                                                                                \
    (4 * ICOAC_MAX_INPUTS * ICOAC_MAX_INPUTS + 26 * ICOAC_MAX_INPUTS + 2 * ICOAC_MAX_RULES + ICOAC_MAX_CRITIC_UNITS + \
     2 * ICOAC_STATE_LIST + 32)
#define ICOAC_STATE_WORDS (2 * ICOAC_MAX_RULES + 2 * ICOAC_MAX_INPUTS + 41)
#define ICOAC_STATE_SIZE                                                                                  \
    (((int)sizeof(icoac_real_t) * ICOAC_STATE_REALS + 4 * ICOAC_STATE_WORDS + 2 * ICOAC_STATE_LIST + 63) / 64 * 64)
typedef struct {
    uint64_t opaque[ICOAC_STATE_SIZE / 8];
} icoac_state_t;

/* Counters since icoac_init (each wraps at 2^32). */
typedef struct {
    uint32_t ticks;          /* icoac_step calls on an initialised state */
    uint32_t nonfinite;      /* ticks rejected with ICOAC_ERR_NONFINITE_INPUT */
    uint32_t numeric_faults; /* ticks rejected with ICOAC_ERR_NUMERIC */
} icoac_counters_t;

/* Flags of icoac_input_t. */
#define ICOAC_INPUT_TERMINAL 1u /* s is a failure state: learn from it, output no action; ends a trial
                                   (batch updates and the search's trial record happen here) */
#define ICOAC_INPUT_LATE 2u     /* task.late_source ICOAC_LATE_SENSOR: the late signal is on (r = -1, U = reflex) */

/* One tick's observation: the task's n inputs (the cart-pole: x m, x_dot m/s, theta rad,
 * theta_dot rad/s, theta > 0 leaning toward +x); entries n and up are not read. */
typedef struct {
    icoac_real_t s[ICOAC_MAX_INPUTS];
    uint32_t flags;      /* ICOAC_INPUT_* */
    icoac_real_t reflex; /* U in [-1, 1] of a tick with ICOAC_INPUT_LATE (sensor late signal); else not read */
} icoac_input_t;

/* One tick's action and diagnostics. */
typedef struct {
    icoac_real_t force;       /* F (N), to apply until the next tick; 0 on error or terminal */
    icoac_real_t z;           /* feature w^T x~ */
    icoac_real_t reflex;      /* U in [-1, 1] (the cart-pole: -1, 0, 1) */
    icoac_real_t penalty;     /* r in {-1, 0} */
    icoac_real_t q;           /* ICO learning signal in {0, 1} */
    icoac_real_t weight_norm; /* |w| after this tick */
    icoac_real_t value;       /* V(s) (RL) */
    icoac_real_t td_error;    /* clipped delta of the transition into s (RL) */
    icoac_real_t noise;       /* exploration noise eps (N) (RL) */
    icoac_real_t cov_trace;   /* trace of Sigma_w (RL, search) */
    int32_t status;           /* icoac_status_t of this tick */
} icoac_output_t;

/* Defaults of every group, ICO mode: the paper's values, and the learner sweeps' choices for the
 * actor and the search (docs/method.md lists each with its source). */
void icoac_config_default(icoac_config_t *cfg);
/* The cart-pole task: its four inputs, its rule table (theta > 11.5 deg or x < -2.35 m: U = +1;
 * theta < -11.5 deg or x > 2.35 m: U = -1; the first match wins) and its input ranges and
 * critic grid in policy and critic. The task group of icoac_config_default. */
void icoac_task_cartpole(icoac_config_t *cfg);
void icoac_policy_config_default(icoac_policy_config_t *policy);
void icoac_ico_config_default(icoac_ico_config_t *ico);
void icoac_critic_config_default(icoac_critic_config_t *critic);
void icoac_actor_config_default(icoac_actor_config_t *actor);
void icoac_search_config_default(icoac_search_config_t *search);

/* Validate the mode and the groups it uses; ICOAC_OK or the status of the first bad field's
 * group. icoac_config_check_field also names that field ("critic.range[0]", a static string;
 * NULL when OK); field may be NULL. */
icoac_status_t icoac_config_check(const icoac_config_t *cfg);
icoac_status_t icoac_config_check_field(const icoac_config_t *cfg, const char **field);

/* Validate a prior's leading n_inputs entries (the bounds at icoac_prior_t); n_inputs out of
 * [1, ICOAC_MAX_INPUTS]: ICOAC_ERR_BAD_TASK. */
icoac_status_t icoac_prior_check(const icoac_prior_t *prior, int32_t n_inputs);

/* Check cfg and prior, then clear state and keep a copy of cfg in it (the caller's cfg is not
 * read again). prior NULL: mean 0, covariance I. In ICO mode the prior mean is the initial w.
 * seed drives exploration noise. Restores everything: the way out of any error. */
icoac_status_t icoac_init(const icoac_config_t *cfg, icoac_state_t *state,
                          const icoac_prior_t *prior, uint64_t seed);

/* Live tuning: check cfg and make it the configuration in force, keeping everything learned
 * (w, mu_w and Sigma_w, critic weights, the search's recorded trials) and the trial in
 * progress. Re-derives what icoac_init derived from the configuration: 1/policy.input_range
 * and, in search mode, the floors search.floor * search.cov_scale * prior variance, to which
 * Sigma_w's diagonal is raised (the initial Sigma0 = cov_scale * prior covariance is icoac_init's
 * alone; a new search.batch takes effect when the batch in progress is closed, at the first
 * terminal tick with at least batch - 1 trials recorded). The mode, task.n_inputs and
 * critic.units cannot change (ICOAC_ERR_RETUNE_MODE: icoac_init with icoac_get_posterior's
 * result as the prior); the rest of the task (its rules, its late-signal source) can. On any
 * error the state is unchanged. */
icoac_status_t icoac_retune(icoac_state_t *state, const icoac_config_t *cfg);

/* Start a new trial: forget the previous tick, keep everything learned. A per-trial batch
 * (actor.batch) not ended by a terminal tick is dropped. Search mode draws the trial's w.
 * Checks the state first (ICOAC_ERR_CORRUPT_STATE, state unchanged, when its configuration copy,
 * its indices or its learned values are not what the library writes: a corrupted state). */
icoac_status_t icoac_reset(icoac_state_t *state);

/* One tick: learn from the transition into in->s, then act on it. The return value is the
 * tick's status; out->status holds the same value, for hosts that log the output.
 * Contract: with a state that icoac_init, icoac_retune and icoac_step left, and a finite in->s,
 * either ICOAC_OK with a finite output and a finite learned state (w, Sigma_w, v), or an error
 * status with force 0 and everything the state holds (learned values, caches, RNG) unchanged
 * but for its counters:
 * - ICOAC_ERR_NONFINITE_INPUT for a NaN/Inf observation;
 * - ICOAC_ERR_NUMERIC when a value the tick derived (force, new weights, covariance or its
 *   trace, critic value or TD error) was not finite;
 * - ICOAC_ERR_TRIAL_ENDED after a terminal tick (ICOAC_INPUT_TERMINAL) that returned ICOAC_OK:
 *   every tick is refused until icoac_reset, so a repeated terminal tick cannot record a trial
 *   twice (a terminal tick that failed leaves the trial open).
 * Whatever bytes the state holds (corrupted memory), a tick reads and writes only inside
 * state, in and out, with no undefined behaviour; a corrupted mode, ico.timing or actor.update
 * gives ICOAC_ERR_CORRUPT_STATE, and icoac_reset checks the rest (every other field of the copy,
 * the slots, the learned values but the critic weights). */
icoac_status_t icoac_step(icoac_state_t *state, const icoac_input_t *in, icoac_output_t *out);

/* The batch tick (a host's simulation engine; built with CMake's ICOAC_BATCH, on by default for
 * the host and left out of the microcontroller presets): up to ICOAC_BATCH_MAX_LANES states, one
 * tick each, in lockstep.
 * icoac_batch_t is caller-owned storage, 8-byte aligned, set up by icoac_batch_init. It keeps
 * what a tick reads of each lane's state, loaded at the lane's first tick and again whenever
 * icoac_init, icoac_retune, icoac_reset or icoac_step has changed that state (the load stamps
 * the state; those functions clear the stamp or advance its tick counter), so the lanes' common
 * ticks read nothing of their states but a header. A state is ticked by one batch, or by
 * icoac_step, at a time; any state can move between lanes or leave the batch between calls. A
 * state whose bytes were changed by other means than the library's functions (corrupted memory)
 * is not loaded again until one of those functions runs on it: its lane stays inside the batch,
 * the state and the call's arrays, but may tick as loaded rather than as icoac_step would. */
#define ICOAC_BATCH_MAX_LANES 64
#define ICOAC_BATCH_MIN_VECTOR_LANES 4 /* a call of fewer lanes runs icoac_step for each */
#define ICOAC_BATCH_SIZE                                                                                 \
    (((((4 * ICOAC_MAX_INPUTS) + (4 * ICOAC_MAX_RULES) + 12) * ICOAC_BATCH_MAX_LANES * (int)sizeof(icoac_real_t)) + \
      (ICOAC_BATCH_MAX_LANES * 17) + (int)sizeof(icoac_input_t) + (int)sizeof(icoac_output_t) + 12 + 63) / 64 * 64)
typedef struct {
    uint64_t opaque[ICOAC_BATCH_SIZE / 8];
} icoac_batch_t;

/* An empty batch (ICOAC_ERR_NULL when batch is NULL). */
icoac_status_t icoac_batch_init(icoac_batch_t *batch);

/* One tick of `lanes` states in lockstep. Lane l (0 <= l < lanes) steps states[l] as
 * icoac_step(states[l], &in, &out) would, bit for bit (force, status, the state afterwards), with
 * in.s[i] = s[i * lanes + l] for i < inputs, in.flags = flags[l] (flags NULL: 0) and in.reflex =
 * reflex[l] (reflex NULL: 0), and writes force[l] = out.force and status[l] = the lane's status.
 * The other fields of icoac_output_t are not produced: a caller that wants them calls
 * icoac_step. A lane's bad input or state gives that lane its status and changes no other lane;
 * states[l] NULL gives ICOAC_ERR_NULL, and a state in a trial whose task has more than `inputs`
 * inputs ICOAC_ERR_NULL (its input is missing), force 0 and no change. The states must be
 * distinct. Returns ICOAC_OK when every lane's status is, else the first failed lane's status;
 * with nothing read or written, ICOAC_ERR_NULL when batch, states, s, force or status is NULL,
 * lanes is outside [0, ICOAC_BATCH_MAX_LANES] or inputs outside [1, ICOAC_MAX_INPUTS], and
 * ICOAC_ERR_NOT_INITIALISED for a batch icoac_batch_init did not set up. The common ticks of ICO
 * and search mode on a rule-table task run vectorised across the lanes; RL mode, sensor tasks,
 * terminal ticks, learning ticks and errors run icoac_step per lane (firmware/src/icoac_batch.c). */
icoac_status_t icoac_step_batch(icoac_batch_t *batch, icoac_state_t *const states[], int32_t lanes,
                                const icoac_real_t *s, int32_t inputs, const uint32_t *flags,
                                const icoac_real_t *reflex, icoac_real_t *force, int32_t *status);

/* Current weights (ICO w or actor mean mu_w) and covariance Sigma_w. */
icoac_status_t icoac_get_posterior(const icoac_state_t *state, icoac_prior_t *posterior);

/* The state's counters. */
icoac_status_t icoac_get_counters(const icoac_state_t *state, icoac_counters_t *counters);

/* The configuration in force (icoac_init's or the last icoac_retune's). */
icoac_status_t icoac_get_config(const icoac_state_t *state, icoac_config_t *cfg);

/* Release version of the library, "MAJOR.MINOR.PATCH" (icoac_version.h: the same at compile time). */
const char *icoac_version(void);

/* Layout checks for bindings (field offsets: icoac_sim's layout table on the host). */
uint32_t icoac_abi_version(void);
uint32_t icoac_sizeof_real(void);
uint32_t icoac_sizeof_config(void);
uint32_t icoac_sizeof_state(void);
uint32_t icoac_sizeof_input(void);
uint32_t icoac_sizeof_output(void);
uint32_t icoac_sizeof_prior(void);

#ifdef __cplusplus
}
#endif

#endif /* ICOAC_H */
