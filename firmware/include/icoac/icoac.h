/* icoac: ICO-learning / Bayesian actor-critic controller, one 100 Hz tick per call.
 *
 * Allocation-free C99. The caller owns a const configuration (may live in flash),
 * a state struct (everything learned plus per-trial caches) and one input/output
 * pair per tick. Call order: icoac_config_default -> edit -> icoac_config_check
 * -> icoac_init, then per tick icoac_step; icoac_reset at each new trial.
 */
#ifndef ICOAC_H
#define ICOAC_H

#include "icoac_rng.h"
#include "icoac_types.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Learning condition. ICO->RL is ICOAC_MODE_RL with an ICO-derived prior. */
typedef enum {
    ICOAC_MODE_ICO = 0, /* ICO rule on w (Eq. 2-3) */
    ICOAC_MODE_RL = 1   /* NGnet critic + Bayesian actor on (mu_w, Sigma_w) (Eq. 6-8) */
} icoac_mode_t;

/* How the reflex U in {-1, 0, +1} enters the force (spec A2). */
typedef enum {
    ICOAC_REFLEX_UNIT = 0,  /* F = G*z + U*reflex_force (literal Eq. 5, 1 N) */
    ICOAC_REFLEX_GAIN = 1   /* F = G*(z + U) (authors' code, 10 N) */
} icoac_reflex_mode_t;

/* When the ICO rule sees the penalty change (spec A4). */
typedef enum {
    ICOAC_ICO_TIMING_CODE = 0,   /* r from the pre-step state, failure states unseen, r_prev persists */
    ICOAC_ICO_TIMING_LITERAL = 1 /* r(t+1) from the post-step state incl. failure, update with x~(t) */
} icoac_ico_timing_t;

/* Valid ranges of the configuration, closed at both ends unless said otherwise; subnormal
 * values are rejected everywhere (a host that flushes them to zero would read 0). Each bound
 * keeps a derived quantity representable in float: 1/range and s*n/range (critic) stay finite
 * and normal, sigma_u^2 stays normal, 1/forgetting stays small. */
#define ICOAC_RANGE_MIN ICOAC_R(1.0e-6)       /* input_range, critic_range (m, m/s, rad, rad/s) */
#define ICOAC_RANGE_MAX ICOAC_R(1.0e6)
#define ICOAC_GAIN_MAX ICOAC_R(1.0e4)         /* gain (N per unit feature), >= 0 */
#define ICOAC_FORCE_MAX ICOAC_R(1.0e4)        /* reflex_force (N), >= 0 */
#define ICOAC_ZONE_MIN ICOAC_R(1.0e-6)        /* zone_theta (rad), zone_x (m) */
#define ICOAC_ZONE_THETA_MAX ICOAC_R(3.14159265358979)
#define ICOAC_ZONE_X_MAX ICOAC_R(1.0e6)
#define ICOAC_ICO_RATE_MAX ICOAC_R(1.0)       /* ico_rate, >= 0 */
#define ICOAC_CRITIC_RATE_MAX ICOAC_R(10.0)   /* critic_rate, >= 0 */
#define ICOAC_TD_CLIP_MIN ICOAC_R(1.0e-6)     /* td_clip */
#define ICOAC_TD_CLIP_MAX ICOAC_R(1.0e3)
#define ICOAC_NOISE_STD_MIN ICOAC_R(1.0e-3)   /* noise_std (N) */
#define ICOAC_NOISE_STD_MAX ICOAC_R(1.0e3)
#define ICOAC_ACTOR_SCALE_MAX ICOAC_R(1.0e3)  /* actor_scale, >= 0 */
#define ICOAC_FORGETTING_MIN ICOAC_R(0.5)     /* forgetting, <= 1 */

/* Configuration. Integer switches are int32_t so the layout is the same on every ABI.
 * Ranges: the ICOAC_*_MIN / _MAX bounds above. */
typedef struct {
    int32_t mode;                               /* icoac_mode_t */
    int32_t reflex_mode;                        /* icoac_reflex_mode_t */
    int32_t ico_timing;                         /* icoac_ico_timing_t */
    int32_t clip_inputs;                        /* 1: clip scaled inputs to [-1, 1]; 0: no clip */
    icoac_real_t input_range[ICOAC_N_INPUTS];   /* (m, m/s, rad, rad/s) maps to +-1; [1e-6, 1e6]. 2.4, 3.5, 0.2094384, 2.0 */
    icoac_real_t gain;                          /* G (N per unit feature), [0, 1e4]. 10 */
    icoac_real_t reflex_force;                  /* N per unit U in ICOAC_REFLEX_UNIT, [0, 1e4]. 1 */
    icoac_real_t zone_theta;                    /* reflex/penalty angle (rad), [1e-6, pi]. 11.5 deg = 0.20071286 */
    icoac_real_t zone_x;                        /* reflex/penalty cart position (m), [1e-6, 1e6]. 2.35 */
    icoac_real_t ico_rate;                      /* mu, [0, 1]. 1e-4 */
    /* RL (ICOAC_MODE_RL) */
    icoac_real_t critic_rate;                   /* eta_c, [0, 10]. 0.6 */
    icoac_real_t discount;                      /* gamma per tick, [0, 1]. 0.95 */
    icoac_real_t td_clip;                       /* |delta| limit, [1e-6, 1e3]. 1 */
    icoac_real_t critic_range[ICOAC_N_INPUTS];  /* critic grid half-widths (SI), [1e-6, 1e6]. 2.4, 3.5, 0.2094, 2.0 */
    icoac_real_t critic_threshold;              /* drop normalized activations below this, [0, 1). 0.001 (code); 0 = dense */
    icoac_real_t noise_std;                     /* sigma_u (N), [1e-3, 1e3]. 1 */
    icoac_real_t actor_scale;                   /* alpha, [0, 1e3]. 0.5 */
    icoac_real_t forgetting;                    /* lambda_f, [0.5, 1]. 1 (none) */
    int32_t rl_reflex;                          /* 1: reflex added to the executed force in RL; 0: off */
    int32_t act_with_sample;                    /* 1: act with a posterior sample of w per trial; 0: with mu_w */
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

/* Critic units kept (b_k >= critic_threshold) at one state: the eligibility of the next TD
 * update. Pair p keeps the units of its first pair_cells[p] cells, in the listed cell order.
 * Part of the state. */
typedef struct {
    icoac_real_t pair_product[ICOAC_CRITIC_PAIRS]; /* g_x * g_xdot of each listed pair */
    icoac_real_t cell_product[ICOAC_CRITIC_CELLS + 1]; /* g_theta * g_thetadot, largest first; 0 */
    uint8_t pair[ICOAC_CRITIC_PAIRS];              /* a*3 + b */
    uint8_t pair_cells[ICOAC_CRITIC_PAIRS];        /* leading cells kept by each pair */
    uint8_t cell[ICOAC_CRITIC_CELLS];              /* c*3 + d */
    uint8_t pairs;                                 /* pairs listed */
    uint8_t cells;                                 /* cells listed */
} icoac_critic_active_t;

/* Everything the controller owns. Treat as opaque; read it through the output struct. */
typedef struct {
    uint32_t magic;                                 /* set by icoac_init */
    int32_t has_prev;                               /* a previous tick of this trial is cached */
    icoac_real_t inv_range[ICOAC_N_INPUTS];         /* 1 / input_range, derived by icoac_init */
    icoac_real_t w[ICOAC_N_INPUTS];                 /* ICO weights, or actor mean mu_w */
    icoac_real_t weight_norm;                       /* |w|, refreshed when w changes */
    icoac_real_t cov[ICOAC_N_INPUTS][ICOAC_N_INPUTS]; /* actor covariance Sigma_w */
    icoac_real_t w_act[ICOAC_N_INPUTS];             /* weights used to act (mu_w or a sample) */
    icoac_real_t v[ICOAC_CRITIC_UNITS];             /* critic weights */
    icoac_critic_active_t active[2];                /* kept critic units of s_t and of s */
    int32_t active_slot;                            /* index of s_t's entry in active */
    icoac_real_t x_prev[ICOAC_N_INPUTS];            /* scaled observation of the previous tick */
    icoac_real_t penalty_prev;                      /* r of the previous ICO observation */
    icoac_real_t value_prev;                        /* V(s_t) */
    icoac_real_t noise_prev;                        /* exploration noise eps_t (N) */
    icoac_rng_t rng;                                /* exploration noise */
    uint32_t ticks;                                 /* icoac_step calls since init (wraps) */
    uint32_t nonfinite_count;                       /* rejected observations since init */
    uint32_t numeric_fault_count;                   /* ticks rejected with ICOAC_ERR_NUMERIC since init */
} icoac_state_t;

/* Flags of icoac_input_t. */
#define ICOAC_INPUT_TERMINAL 1u /* s is a failure state: learn from it, output no action */

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
    icoac_real_t cov_trace;   /* trace of Sigma_w (RL) */
    int32_t status;           /* icoac_status_t of this tick */
} icoac_output_t;

/* Paper defaults (spec section 2), ICO mode. */
void icoac_config_default(icoac_config_t *cfg);

/* Validate every field; ICOAC_OK or the status naming the first bad group. */
icoac_status_t icoac_config_check(const icoac_config_t *cfg);

/* Validate a prior (the bounds at icoac_prior_t). */
icoac_status_t icoac_prior_check(const icoac_prior_t *prior);

/* Check cfg and prior, then clear state. prior NULL: mean 0, covariance I.
 * In ICO mode the prior mean is the initial w. seed drives exploration noise. */
icoac_status_t icoac_init(const icoac_config_t *cfg, icoac_state_t *state,
                          const icoac_prior_t *prior, uint64_t seed);

/* Start a new trial: forget the previous tick, keep everything learned. */
icoac_status_t icoac_reset(const icoac_config_t *cfg, icoac_state_t *state);

/* One tick: learn from the transition into in->s, then act on it. The return value and
 * out->status are the same. Contract: with a configuration icoac_config_check accepts and a
 * finite in->s, either ICOAC_OK with a finite output and a finite learned state (w, Sigma_w,
 * v), or an error status with force 0 and the state unchanged but for its tick counters:
 * ICOAC_ERR_NONFINITE_INPUT for a NaN/Inf observation, ICOAC_ERR_NUMERIC when a value the tick
 * derived (force, new weights, covariance or its trace, critic value or TD error) was not finite. */
icoac_status_t icoac_step(const icoac_config_t *cfg, icoac_state_t *state,
                          const icoac_input_t *in, icoac_output_t *out);

/* Current weights (ICO w or actor mean mu_w) and covariance; either pointer may be NULL. */
icoac_status_t icoac_get_posterior(const icoac_state_t *state, icoac_prior_t *posterior);

/* Layout checks for bindings. */
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
