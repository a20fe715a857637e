/* icoac: real-number type, sizes and status codes shared by every header. */
#ifndef ICOAC_TYPES_H
#define ICOAC_TYPES_H

#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

/* Bump when a public struct layout or an enum value changes. */
#define ICOAC_ABI_VERSION 7

/* Real-number type: float by default; define ICOAC_REAL_DOUBLE=1 for double. */
#if defined(ICOAC_REAL_DOUBLE) && ICOAC_REAL_DOUBLE
typedef double icoac_real_t;
#define ICOAC_R(x) (x)
#else
typedef float icoac_real_t;
#define ICOAC_R(x) (x##f)
#endif

/* Observation layout: (x, x_dot, theta, theta_dot). */
#define ICOAC_N_INPUTS 4
#define ICOAC_IDX_X 0
#define ICOAC_IDX_X_DOT 1
#define ICOAC_IDX_THETA 2
#define ICOAC_IDX_THETA_DOT 3

/* Critic grid: 3 x 3 x 6 x 3 normalized Gaussian units. */
#define ICOAC_CRITIC_N_X 3
#define ICOAC_CRITIC_N_X_DOT 3
#define ICOAC_CRITIC_N_THETA 6
#define ICOAC_CRITIC_N_THETA_DOT 3
#define ICOAC_CRITIC_UNITS \
    (ICOAC_CRITIC_N_X * ICOAC_CRITIC_N_X_DOT * ICOAC_CRITIC_N_THETA * ICOAC_CRITIC_N_THETA_DOT)
#define ICOAC_CRITIC_FACTORS \
    (ICOAC_CRITIC_N_X + ICOAC_CRITIC_N_X_DOT + ICOAC_CRITIC_N_THETA + ICOAC_CRITIC_N_THETA_DOT)
/* Unit k = pair * CELLS + cell: pair over (x, x_dot), cell over (theta, theta_dot). */
#define ICOAC_CRITIC_PAIRS (ICOAC_CRITIC_N_X * ICOAC_CRITIC_N_X_DOT)
#define ICOAC_CRITIC_CELLS (ICOAC_CRITIC_N_THETA * ICOAC_CRITIC_N_THETA_DOT)

/* Compile-time assertion usable in C99 and C11. */
#if defined(__STDC_VERSION__) && __STDC_VERSION__ >= 201112L
#define ICOAC_STATIC_ASSERT(cond, name) _Static_assert(cond, #name)
#else
#define ICOAC_STATIC_ASSERT(cond, name) typedef char icoac_static_assert_##name[(cond) ? 1 : -1]
#endif

/* Result of every icoac function. Values are stable across releases. */
typedef enum {
    ICOAC_OK = 0,
    ICOAC_ERR_NULL = 1,             /* a required pointer was NULL */
    ICOAC_ERR_NOT_INITIALISED = 2,  /* state not set up by icoac_init */
    ICOAC_ERR_NONFINITE_INPUT = 3,  /* observation had NaN/Inf: safe output, no learning */
    ICOAC_ERR_NUMERIC = 4,          /* a value derived in this tick was not finite: force 0, nothing learned */
    ICOAC_ERR_TRIAL_ENDED = 5,      /* a tick after a terminal tick without icoac_reset: force 0, nothing learned */
    ICOAC_ERR_CORRUPT_STATE = 6,    /* the state's content is not one the library wrote (corrupted): icoac_init */
    ICOAC_ERR_RETUNE_MODE = 7,      /* icoac_retune cannot change the mode: icoac_init (posterior as the prior) */
    ICOAC_ERR_BAD_MODE = 10,        /* mode, policy.reflex_mode, ico.timing, actor.update or a 0/1 flag out of range */
    ICOAC_ERR_BAD_SCALE = 11,       /* policy.input_range out of range */
    ICOAC_ERR_BAD_GAIN = 12,        /* policy.gain or policy.reflex_force out of range */
    ICOAC_ERR_BAD_ZONE = 13,        /* policy.zone_theta or policy.zone_x out of range */
    ICOAC_ERR_BAD_ICO_RATE = 14,    /* ico.rate out of range */
    ICOAC_ERR_BAD_CRITIC = 15,      /* a critic field out of range */
    ICOAC_ERR_BAD_ACTOR = 16,       /* an actor field out of range */
    ICOAC_ERR_BAD_PRIOR = 17,       /* prior out of range, subnormal, or covariance not symmetric PD */
    ICOAC_ERR_BAD_SEARCH = 18       /* a search field out of range */
} icoac_status_t;

/* Static, human-readable name of a status (never NULL). */
const char *icoac_status_str(icoac_status_t status);

#ifdef __cplusplus
}
#endif

#endif /* ICOAC_TYPES_H */
