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

/* How the reflex U in {-1, 0, +1} enters the force (method.md, A2). */
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
#define ICOAC_ZONE_MIN ICOAC_R(1.0e-6)        /* policy.zone_theta (rad), policy.zone_x (m) */
#define ICOAC_ZONE_THETA_MAX ICOAC_R(3.14159265358979)
#define ICOAC_ZONE_X_MAX ICOAC_R(1.0e6)
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
 * policy, ico; RL: policy, critic, actor; search: policy, search). Integer switches are int32_t so the layout is the
 * same on every ABI. Ranges: the ICOAC_*_MIN / _MAX bounds above (search: its own group). */

/* Policy: how the state becomes the feature z = w^T x~ and the force (every mode). */
typedef struct {
    icoac_real_t input_range[ICOAC_N_INPUTS]; /* (m, m/s, rad, rad/s) maps to +-1; [1e-6, 1e6]. 2.4, 3.5, 0.2094384, 2.0 */
    int32_t clip_inputs;                      /* 1: clip scaled inputs to [-1, 1]; 0: no clip */
    icoac_real_t gain;                        /* G (N per unit feature), [0, 1e4]. 10 */
    int32_t reflex_mode;                      /* icoac_reflex_mode_t */
    icoac_real_t reflex_force;                /* N per unit U in ICOAC_REFLEX_UNIT, [0, 1e4]. 1 */
    icoac_real_t zone_theta;                  /* reflex/penalty angle (rad), [1e-6, pi]. 11.5 deg = 0.20071286 */
    icoac_real_t zone_x;                      /* reflex/penalty cart position (m), [1e-6, 1e6]. 2.35 */
} icoac_policy_config_t;

/* ICO rule (ICOAC_MODE_ICO). */
typedef struct {
    icoac_real_t rate; /* mu, [0, 1]. 1e-4 */
    int32_t timing;    /* icoac_ico_timing_t */
} icoac_ico_config_t;

/* Normalized-Gaussian critic (ICOAC_MODE_RL). */
typedef struct {
    icoac_real_t rate;                  /* eta_c, [0, 10]. 0.6 */
    icoac_real_t discount;              /* gamma per tick, [0, 1]. 0.95 */
    icoac_real_t td_clip;               /* |delta| limit, [1e-6, 1e3]. 1 */
    icoac_real_t range[ICOAC_N_INPUTS]; /* grid half-widths (SI), [1e-6, 1e6]. 2.4, 3.5, 0.2094, 2.0 */
    icoac_real_t threshold;             /* drop normalized activations below this, [0, 1). 0.001 (code); 0 = dense */
    int32_t quirks;                     /* 1: the authors' code (A10): TD update on b(s_t+1), V_old = 0 at a
                                           reset; 0: TD(0) on b(s_t), V(s_0) (default) */
} icoac_critic_config_t;

/* Actor and exploration (ICOAC_MODE_RL). Every reading observes u_ob = mu_u + alpha*delta*eps. */
typedef struct {
    icoac_real_t noise_std;      /* sigma_u (N), [1e-3, 1e3]. 3 (chosen by a sweep; literal: 1) */
    icoac_real_t scale;          /* alpha, [0, 1e3]. 0.5 */
    icoac_real_t forgetting;     /* lambda_f, [0.5, 1]. 1 (none); posterior reading only */
    int32_t reflex;              /* 1: reflex added to the executed force; 0: off */
    int32_t act_with_sample;     /* 1: act with a posterior sample of w per trial; 0: with mu_w */
    int32_t update;              /* icoac_actor_update_t. gradient (chosen by a sweep; literal: posterior) */
    icoac_real_t rate;           /* beta of the gradient reading, [0, 1e3]. 0.001 */
    icoac_real_t likelihood_std; /* sigma_L (N) of the posterior and mean readings, [1e-3, 1e3], or 0: sigma_u
                                    (literal). 0 */
    int32_t batch;               /* 1: accumulate over a trial, one update at its terminal tick (A14); 0: per tick */
    int32_t explore_ticks;       /* N: eps = 0 and no actor update from tick N of a trial on; 0: always explore
                                    (literal). 1000 (10 s) */
} icoac_actor_config_t;

/* Episodic search over N(mu_w, Sigma_w) (ICOAC_MODE_SEARCH, method.md L4): each trial acts with one
 * sample w (F = G w^T x~ + reflex, no noise); after `batch` failed trials the best
 * round(elite_fraction * batch) (at least 1) by length move mu_w and Sigma_w by `step`.
 * Defaults chosen by a sweep for the ICO prior (docs/results.md). */
typedef struct {
    int32_t batch;               /* K, trials per update, [1, ICOAC_SEARCH_BATCH_MAX]. 8 */
    icoac_real_t elite_fraction; /* rho, (0, 1]; n_e = max(1, round half up(rho K)). 0.25 */
    icoac_real_t step;           /* a, (0, 1]. 0.5 */
    icoac_real_t floor;          /* f: Sigma_ii >= f * Sigma0_ii after each update, [1e-6, 1e3]. 1 */
    icoac_real_t cov_scale;      /* c: Sigma0 = c * prior covariance, [1, 1e3]. 64 */
} icoac_search_config_t;

typedef struct {
    int32_t mode;                 /* icoac_mode_t */
    int32_t learn;                /* 1: learn (default); 0: every update off (w, Sigma_w, v fixed): the
                                     no-learning control of a condition, or a fixed-w evaluation.
                                     Acting, exploration noise and its random stream are unchanged */
    icoac_policy_config_t policy;
    icoac_ico_config_t ico;
    icoac_critic_config_t critic;
    icoac_actor_config_t actor;
    icoac_search_config_t search;
} icoac_config_t;

/* Gaussian prior / posterior of the feature weights, (w_x, w_xdot, w_theta, w_thetadot).
 * A prior must have |mean_i| <= ICOAC_PRIOR_MEAN_MAX, |cov_ij| <= ICOAC_PRIOR_COV_MAX, no
 * subnormal entry, and an exactly symmetric positive definite covariance. */
#define ICOAC_PRIOR_MEAN_MAX ICOAC_R(1.0e6)
#define ICOAC_PRIOR_COV_MAX ICOAC_R(1.0e12)
typedef struct {
    icoac_real_t mean[ICOAC_N_INPUTS];
    icoac_real_t cov[ICOAC_N_INPUTS][ICOAC_N_INPUTS];
} icoac_prior_t;

/* Controller state: caller-owned storage of ICOAC_STATE_SIZE bytes, 8-byte aligned (it may be
 * a static, a stack or a struct member; no heap). Its layout is private and may change
 * between releases: read it through icoac_get_posterior, icoac_get_counters and
 * icoac_get_config. It holds a copy of the configuration in force. The size has room for
 * later learners. */
#if defined(ICOAC_REAL_DOUBLE) && ICOAC_REAL_DOUBLE
#define ICOAC_STATE_SIZE 4096
#else
#define ICOAC_STATE_SIZE 2048
#endif
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

/* One tick's observation, SI units, theta > 0 leans toward +x. */
typedef struct {
    icoac_real_t s[ICOAC_N_INPUTS]; /* (x m, x_dot m/s, theta rad, theta_dot rad/s) */
    uint32_t flags;                 /* ICOAC_INPUT_* */
} icoac_input_t;

/* One tick's action and diagnostics. */
typedef struct {
    icoac_real_t force;       /* F (N), to apply until the next tick; 0 on error or terminal */
    icoac_real_t z;           /* feature w^T x~ */
    icoac_real_t reflex;      /* U in {-1, 0, 1} */
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

/* Validate a prior (the bounds at icoac_prior_t). */
icoac_status_t icoac_prior_check(const icoac_prior_t *prior);

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
 * terminal tick with at least batch - 1 trials recorded). The mode cannot change
 * (ICOAC_ERR_RETUNE_MODE: icoac_init with icoac_get_posterior's result as the prior). On any
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

/* Current weights (ICO w or actor mean mu_w) and covariance Sigma_w. */
icoac_status_t icoac_get_posterior(const icoac_state_t *state, icoac_prior_t *posterior);

/* The state's counters. */
icoac_status_t icoac_get_counters(const icoac_state_t *state, icoac_counters_t *counters);

/* The configuration in force (icoac_init's or the last icoac_retune's). */
icoac_status_t icoac_get_config(const icoac_state_t *state, icoac_config_t *cfg);

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
