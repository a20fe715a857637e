/* SPDX-License-Identifier: Apache-2.0 */
/* icoac: real-number type, sizes and status codes shared by every header. */
#ifndef ICOAC_TYPES_H
#define ICOAC_TYPES_H

#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

/* Bump when a public struct layout or an enum value changes. */
#define ICOAC_ABI_VERSION 10

/* Real-number type: float by default; define ICOAC_REAL_DOUBLE=1 for double. */
#if defined(ICOAC_REAL_DOUBLE) && ICOAC_REAL_DOUBLE
typedef double icoac_real_t;
#define ICOAC_R(x) (x)
#else
typedef float icoac_real_t;
#define ICOAC_R(x) (x##f)
#endif

/* The build options of a CMake build or installed package (icoac_build_config.h, generated):
 * it fixes the build maxima below to the library's. */
#if defined(__has_include)
#if __has_include("icoac/icoac_build_config.h")
#include "icoac/icoac_build_config.h"
#endif
#endif

/* Build maxima of the task description (CMake cache variables of the same names, or -D; they
 * change the layout of every public struct, so a library and its callers must agree on them).
 * The defaults fit the shipped plants: the cart-pole (4 inputs, 4 rules, 3 x 3 x 6 x 3 = 162
 * critic units) and a double inverted pendulum on a cart (6 inputs: x, theta1, theta2 and their
 * rates; 6 rules: each of the three positions on both sides; a critic of 3,3,3,2,2,2 = 216 units). */
#ifndef ICOAC_MAX_INPUTS
#define ICOAC_MAX_INPUTS 6 /* inputs n of a task, 4 .. 16 */
#endif
#ifndef ICOAC_MAX_RULES
#define ICOAC_MAX_RULES 6 /* late-signal rules of a task, 4 .. 16 */
#endif
#ifndef ICOAC_MAX_CRITIC_UNITS
#define ICOAC_MAX_CRITIC_UNITS 216 /* critic units (product of the per-input counts), 162 .. 1024 */
#endif

/* The critic's units per input, at most; their product splits into at most
 * ICOAC_CRITIC_BLOCK_MAX blocks of at most ICOAC_CRITIC_BLOCK_MAX units (icoac.h, critic). */
#define ICOAC_CRITIC_UNITS_PER_INPUT_MAX 16
#define ICOAC_CRITIC_BLOCK_MAX 31

/* The cart-pole task (icoac_task_cartpole): inputs (x, x_dot, theta, theta_dot) and its critic
 * grid, 3 x 3 x 6 x 3 normalized Gaussian units. */
#define ICOAC_CARTPOLE_INPUTS 4
#define ICOAC_IDX_X 0
#define ICOAC_IDX_X_DOT 1
#define ICOAC_IDX_THETA 2
#define ICOAC_IDX_THETA_DOT 3
#define ICOAC_CARTPOLE_RULES 4
#define ICOAC_CRITIC_N_X 3
#define ICOAC_CRITIC_N_X_DOT 3
#define ICOAC_CRITIC_N_THETA 6
#define ICOAC_CRITIC_N_THETA_DOT 3
#define ICOAC_CARTPOLE_CRITIC_UNITS \
    (ICOAC_CRITIC_N_X * ICOAC_CRITIC_N_X_DOT * ICOAC_CRITIC_N_THETA * ICOAC_CRITIC_N_THETA_DOT)

/* Compile-time assertion usable in C99 and C11. */
#if defined(__STDC_VERSION__) && __STDC_VERSION__ >= 201112L
#define ICOAC_STATIC_ASSERT(cond, name) _Static_assert(cond, #name)
#else
#define ICOAC_STATIC_ASSERT(cond, name) typedef char icoac_static_assert_##name[(cond) ? 1 : -1]
#endif

#if ICOAC_MAX_INPUTS < ICOAC_CARTPOLE_INPUTS || ICOAC_MAX_INPUTS > 16
#error "ICOAC_MAX_INPUTS must be in [4, 16] (the cart-pole preset has 4 inputs)"
#endif
#if ICOAC_MAX_RULES < ICOAC_CARTPOLE_RULES || ICOAC_MAX_RULES > 16
#error "ICOAC_MAX_RULES must be in [4, 16] (the cart-pole preset has 4 rules)"
#endif
#if ICOAC_MAX_CRITIC_UNITS < ICOAC_CARTPOLE_CRITIC_UNITS || ICOAC_MAX_CRITIC_UNITS > 1024
#error "ICOAC_MAX_CRITIC_UNITS must be in [162, 1024] (the cart-pole preset has 162 units)"
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
    ICOAC_ERR_RETUNE_MODE = 7,      /* icoac_retune cannot change the mode, task.n_inputs or critic.units: icoac_init */
    ICOAC_ERR_BAD_MODE = 10,        /* mode, policy.reflex_mode, ico.timing, actor.update or a 0/1 flag out of range */
    ICOAC_ERR_BAD_SCALE = 11,       /* policy.input_range out of range */
    ICOAC_ERR_BAD_GAIN = 12,        /* policy.gain or policy.reflex_force out of range */
    ICOAC_ERR_BAD_ZONE = 13,        /* task.rule_threshold or task.rule_reflex out of range */
    ICOAC_ERR_BAD_ICO_RATE = 14,    /* ico.rate out of range */
    ICOAC_ERR_BAD_CRITIC = 15,      /* a critic field out of range */
    ICOAC_ERR_BAD_ACTOR = 16,       /* an actor field out of range */
    ICOAC_ERR_BAD_PRIOR = 17,       /* prior out of range, subnormal, or covariance not symmetric PD */
    ICOAC_ERR_BAD_SEARCH = 18,      /* a search field out of range */
    ICOAC_ERR_BAD_TASK = 19         /* task.n_inputs, late_source, n_rules, rule_input or rule_side out of range */
} icoac_status_t;

/* Static, human-readable name of a status (never NULL). */
const char *icoac_status_str(icoac_status_t status);

#ifdef __cplusplus
}
#endif

#endif /* ICOAC_TYPES_H */
