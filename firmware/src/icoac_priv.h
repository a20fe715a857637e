/* SPDX-License-Identifier: Apache-2.0 */
/* Private declarations of the icoac library: numeric helpers and the stages of a tick.
 * Not installed, not part of the API; every name carries the prefix icoac_priv_. */
#ifndef ICOAC_PRIV_H
#define ICOAC_PRIV_H

#include <float.h>
#include <math.h>
#include <string.h>

#include "icoac/icoac.h"
#include "icoac_state.h"

/* Math of the real type. */
#if defined(ICOAC_REAL_DOUBLE) && ICOAC_REAL_DOUBLE
#define ICOAC_PRIV_SQRT sqrt
#define ICOAC_PRIV_LOG log
#define ICOAC_PRIV_FABS fabs
#define ICOAC_PRIV_LIBM_EXP exp
#else
#define ICOAC_PRIV_SQRT sqrtf
#define ICOAC_PRIV_LOG logf
#define ICOAC_PRIV_FABS fabsf
#define ICOAC_PRIV_LIBM_EXP expf
#endif

/* The pointer p as a value the compiler cannot see through: it keeps p in a register instead
 * of folding it into every address computed from it (GCC and clang; elsewhere nothing). */
#if defined(__GNUC__)
#define ICOAC_PRIV_OPAQUE(p) __asm__("" : "+r"(p))
#else
#define ICOAC_PRIV_OPAQUE(p) ((void)0)
#endif

/* Unroll the next loop completely when its trip count is a compile-time constant: the input
 * loops of the kernels' cart-pole instances (GCC 8 and later; elsewhere nothing). */
#if defined(__GNUC__) && !defined(__clang__) && __GNUC__ >= 8
#define ICOAC_PRIV_UNROLL _Pragma("GCC unroll 16")
#else
#define ICOAC_PRIV_UNROLL
#endif

/* Kept out of line: a per-trial path whose frame should not add to the per-tick one. */
#if defined(__GNUC__)
#define ICOAC_PRIV_NOINLINE __attribute__((__noinline__))
#else
#define ICOAC_PRIV_NOINLINE
#endif

/* C99 will not pass T[N][N] to const T[N][N] implicitly. */
#define ICOAC_PRIV_CONST_MAT(m) ((const icoac_real_t(*)[ICOAC_MAX_INPUTS])(m))

/* exp(a) for the critic and ln(a) for the exploration noise. Default: the C library's. With
 * ICOAC_FAST_EXP=1 (float builds; the microcontroller presets turn it on), icoac's own. exp:
 * Cody-Waite reduction a = n ln2 + r, |r| <= ln2/2, a degree-6 Taylor polynomial for e^r and
 * 2^n from the exponent bits.
 * Relative error < 1e-6 on [-87, 88] (tests/c/test_fast_exp.c); 0 below -87, NaN for NaN. */
#if defined(ICOAC_FAST_EXP) && ICOAC_FAST_EXP && !(defined(ICOAC_REAL_DOUBLE) && ICOAC_REAL_DOUBLE)
static inline float icoac_priv_exp(float a)
{
    const float ln2_hi = 0.693145751953125f;
    const float ln2_lo = 1.42860676533018704e-06f;
    const float inv_ln2 = 1.44269504088896341f;
    union {
        float f;
        uint32_t u;
    } scale;
    float n_real;
    float r;
    float p;
    int32_t n;
    if (!(a >= -87.0f)) {
        return a != a ? a : 0.0f; /* NaN stays NaN (the tick's finiteness check reports it) */
    }
    if (a > 88.0f) {
        a = 88.0f;
    }
    n_real = a * inv_ln2;
    n = (int32_t)(n_real < 0.0f ? n_real - 0.5f : n_real + 0.5f);
    n_real = (float)n;
    r = (a - n_real * ln2_hi) - n_real * ln2_lo;
    p = 1.0f + r * (1.0f + r * (0.5f + r * (1.0f / 6.0f + r * (1.0f / 24.0f +
                                       r * (1.0f / 120.0f + r * (1.0f / 720.0f))))));
    scale.u = (uint32_t)(n + 127) << 23;
    return p * scale.f;
}

/* ln(a) for the polar method's s in (0, 1), positive normal a (ICOAC_FAST_EXP=1): a = m 2^e with
 * m in [sqrt(1/2), sqrt(2)), ln m = 2 atanh(t), t = (m - 1)/(m + 1), |t| <= 0.1716, by its odd
 * series to t^9 (truncation < 3e-9 relative); e ln 2 in two parts. Max error a few ulp
 * (tests/c/test_fast_exp.c); not for 0, subnormal, negative or non-finite a. */
static inline float icoac_priv_log(float a)
{
    const float ln2_hi = 0.693145751953125f;
    const float ln2_lo = 1.42860676533018704e-06f;
    union {
        float f;
        uint32_t u;
    } m;
    int32_t e;
    float t;
    float t2;
    float series;
    m.f = a;
    e = (int32_t)(m.u >> 23) - 127;
    m.u = (m.u & 0x007FFFFFu) | 0x3F800000u; /* [1, 2) */
    if (m.u > 0x3FB504F3u) {                  /* above sqrt(2): halve */
        m.u -= 0x00800000u;
        ++e;
    }
    t = (m.f - 1.0f) / (m.f + 1.0f);
    t2 = t * t;
    series = t * (2.0f + t2 * (2.0f / 3.0f + t2 * (2.0f / 5.0f + t2 * (2.0f / 7.0f + t2 * (2.0f / 9.0f)))));
    return ((float)e * ln2_hi + series) + (float)e * ln2_lo;
}
#else
#if defined(ICOAC_CRITIC_DENSE) && ICOAC_CRITIC_DENSE && !(defined(ICOAC_REAL_DOUBLE) && ICOAC_REAL_DOUBLE)
/* The float build of a host (the dense kernel): icoac's own e^a, in double with no branch and no
 * table, so that a loop of it over many values vectorises (icoac_step_batch) with the same bits
 * as one call: a = k ln2 + r, |r| <= ln2/2 (k rounded by adding 1.5 * 2^52), e^r by its Taylor
 * series to r^9 (truncation < 7e-12 relative) in Estrin's order, 2^k from the exponent bits, one
 * rounding to float. Within 1 ulp of the C library's expf (tests/c/test_fast_exp.c). a is
 * clamped to [-110, 100] first: 0 below, Inf above float's range, NaN stays NaN. */
static inline float icoac_priv_exp(float a)
{
    const double shift = 6755399441055744.0;
    const double inv_ln2 = 1.4426950408889634074;
    const double ln2 = 0.69314718055994530942;
    union {
        double d;
        uint64_t u;
    } k_bits;
    union {
        double d;
        uint64_t u;
    } scale;
    double x = (double)a;
    double k;
    double r;
    double r2;
    double r4;
    double p;
    x = (x < -110.0) ? -110.0 : x;
    x = (x > 100.0) ? 100.0 : x;
    k = x * inv_ln2;
    k = k + shift;
    k_bits.d = k; /* k in the low bits of the mantissa */
    k = k - shift;
    r = x - k * ln2;
    r2 = r * r;
    r4 = r2 * r2;
    p = ((1.0 + r) + r2 * (0.5 + r * (1.0 / 6.0))) +
        r4 * ((((1.0 / 24.0) + r * (1.0 / 120.0)) + r2 * ((1.0 / 720.0) + r * (1.0 / 5040.0))) +
              r4 * ((1.0 / 40320.0) + r * (1.0 / 362880.0)));
    scale.u = (k_bits.u + 1023u) << 52; /* 2^k: k + 1023 in the exponent field */
    return (float)(p * scale.d);
}
#else
static inline icoac_real_t icoac_priv_exp(icoac_real_t a)
{
    return ICOAC_PRIV_LIBM_EXP(a);
}
#endif

static inline icoac_real_t icoac_priv_log(icoac_real_t a)
{
    return ICOAC_PRIV_LOG(a);
}
#endif

/* a >= b for non-negative, non-NaN a and b. Such IEEE-754 values order like their bit
 * patterns, so this is an integer compare: a soft-float compare costs ~40 instructions on a
 * Cortex-M0+, and the sparse critic makes hundreds per tick. */
static inline int icoac_priv_nonneg_at_least(icoac_real_t a, icoac_real_t b)
{
#if defined(ICOAC_REAL_DOUBLE) && ICOAC_REAL_DOUBLE
    uint64_t bits_a;
    uint64_t bits_b;
#else
    uint32_t bits_a;
    uint32_t bits_b;
#endif
    (void)memcpy(&bits_a, &a, sizeof bits_a);
    (void)memcpy(&bits_b, &b, sizeof bits_b);
    return bits_a >= bits_b;
}

/* 1 when v is finite. An IEEE-754 value is NaN or Inf exactly when its exponent bits are all
 * ones: an integer test, no float compare (costly in soft float). */
static inline int icoac_priv_finite(icoac_real_t v)
{
#if defined(ICOAC_REAL_DOUBLE) && ICOAC_REAL_DOUBLE
    const uint64_t exponent = 0x7FF0000000000000ull;
    uint64_t bits;
#else
    const uint32_t exponent = 0x7F800000u;
    uint32_t bits;
#endif
    (void)memcpy(&bits, &v, sizeof bits);
    return (bits & exponent) != exponent;
}

/* 1 when v is +-0 or a normal number (or Inf/NaN): not subnormal. Configuration and prior
 * values must be, since hosts that flush subnormals to zero would read them as 0. */
static inline int icoac_priv_zero_or_normal(icoac_real_t v)
{
#if defined(ICOAC_REAL_DOUBLE) && ICOAC_REAL_DOUBLE
    const uint64_t exponent = 0x7FF0000000000000ull;
    const uint64_t magnitude = 0x7FFFFFFFFFFFFFFFull;
    uint64_t bits;
#else
    const uint32_t exponent = 0x7F800000u;
    const uint32_t magnitude = 0x7FFFFFFFu;
    uint32_t bits;
#endif
    (void)memcpy(&bits, &v, sizeof bits);
    return (bits & exponent) != 0u || (bits & magnitude) == 0u;
}

/* 1 when every one of the n values is finite; no branch per value. */
static inline int icoac_priv_all_finite(const icoac_real_t *values, int n)
{
    int finite = 1;
    int i;
    for (i = 0; i < n; ++i) {
        finite &= icoac_priv_finite(values[i]);
    }
    return finite;
}

/* Vectors and matrices have ICOAC_MAX_INPUTS entries per dimension, of which a task uses the
 * first n; the library keeps the others 0 (icoac_init clears them, nothing writes them), so the
 * fixed-size helpers below give the n-entry results. */

/* The task's n, bounded to the arrays whatever the state's copy holds. */
static inline int icoac_priv_inputs(const icoac_config_t *cfg)
{
    return (uint32_t)cfg->task.n_inputs <= (uint32_t)ICOAC_MAX_INPUTS ? (int)cfg->task.n_inputs : ICOAC_MAX_INPUTS;
}

/* dst = src; inline, as newlib-nano's memcpy copies byte by byte. */
static inline void icoac_priv_copy(icoac_real_t dst[ICOAC_MAX_INPUTS], const icoac_real_t src[ICOAC_MAX_INPUTS])
{
    int i;
    for (i = 0; i < ICOAC_MAX_INPUTS; ++i) {
        dst[i] = src[i];
    }
}

/* dst = src over the first n entries (an instance with a compile-time n). */
static inline void icoac_priv_copy_n(icoac_real_t *dst, const icoac_real_t *src, int n)
{
    int i;
    for (i = 0; i < n && i < ICOAC_MAX_INPUTS; ++i) {
        dst[i] = src[i];
    }
}

/* Fixed pairwise order, the same on every target: (a0 b0 + a1 b1) + (a2 b2 + a3 b3), then each
 * further pair (and a last odd term) added in turn, over the first n entries (4 <= n <=
 * ICOAC_MAX_INPUTS; a compile-time n in the instances). Zero entries add +-0, which leaves every
 * nonzero sum unchanged, so a task's n gives the sum over all entries. */
static inline icoac_real_t icoac_priv_dot_n(const icoac_real_t *a, const icoac_real_t *b, int n)
{
    /* cppcheck-suppress uninitvar ; n >= 4 (a task has at least 4 inputs), the first n entries are set */
    icoac_real_t sum = (a[0] * b[0] + a[1] * b[1]) + (a[2] * b[2] + a[3] * b[3]);
    int i;
    for (i = 4; i + 1 < n && i + 1 < ICOAC_MAX_INPUTS; i += 2) {
        sum += a[i] * b[i] + a[i + 1] * b[i + 1];
    }
    if ((n & 1) != 0 && n <= ICOAC_MAX_INPUTS) {
        sum += a[n - 1] * b[n - 1];
    }
    return sum;
}

/* The same over every entry. */
static inline icoac_real_t icoac_priv_dot(const icoac_real_t a[ICOAC_MAX_INPUTS], const icoac_real_t b[ICOAC_MAX_INPUTS])
{
    return icoac_priv_dot_n(a, b, ICOAC_MAX_INPUTS);
}

/* The tick's per-trial cache: this tick's scaled observation is the next one's previous. */
static inline void icoac_priv_cache_tick(icoac_priv_state_t *st, const icoac_real_t scaled[ICOAC_MAX_INPUTS])
{
    icoac_priv_copy(st->x_prev, scaled);
    st->has_prev = 1;
}

/* The trace over the first n entries (4 <= n <= ICOAC_MAX_INPUTS), in the dot product's order. */
static inline icoac_real_t icoac_priv_trace_n(const icoac_real_t m[ICOAC_MAX_INPUTS][ICOAC_MAX_INPUTS], int n)
{
    icoac_real_t sum = (m[0][0] + m[1][1]) + (m[2][2] + m[3][3]);
    int i;
    for (i = 4; i + 1 < n && i + 1 < ICOAC_MAX_INPUTS; i += 2) {
        sum += m[i][i] + m[i + 1][i + 1];
    }
    if ((n & 1) != 0 && n <= ICOAC_MAX_INPUTS) {
        sum += m[n - 1][n - 1];
    }
    return sum;
}

/* The trace over every entry. */
static inline icoac_real_t icoac_priv_trace(const icoac_real_t m[ICOAC_MAX_INPUTS][ICOAC_MAX_INPUTS])
{
    return icoac_priv_trace_n(m, ICOAC_MAX_INPUTS);
}

/* Stages of a tick. Each tick function stages what it would learn and output, checks that it
 * is finite, and only then commits it; it returns 0 when not, with the state untouched but for
 * its scratch (the spare covariance buffer and the spare kept-unit list, never read before a
 * commit). */

/* A bound on every standard normal the generator draws (the polar method's values stay below
 * about 6 in float): the RL tick relies on |eps| <= ICOAC_PRIV_NORMAL_MAX * sigma_u for a finite
 * force, and icoac_reset refuses a state whose cached normal exceeds it. */
#define ICOAC_PRIV_NORMAL_MAX ICOAC_R(1.0e8)

/* What a mode's tick returns. */
#define ICOAC_PRIV_TICK_NUMERIC 0   /* a staged value was not finite: nothing committed */
#define ICOAC_PRIV_TICK_OK 1        /* committed */
#define ICOAC_PRIV_TICK_CORRUPT 2 /* an unknown switch in the state's configuration: nothing committed */

/* icoac_step, with the critic's exponentials of the input computed by the caller: given holds
 * e^(up's argument) and e^(edge's argument) of input i at given[2i], given[2i + 1]
 * (icoac_priv_factors_of), or is NULL (icoac_step: the tick computes them). icoac_step_batch
 * computes them for many states at once. */
icoac_status_t icoac_priv_step(icoac_state_t *state, const icoac_input_t *in, icoac_output_t *out,
                               const icoac_real_t *given);

/* ICO rule, both timings (icoac_ico.c). */
int icoac_priv_ico_tick(const icoac_config_t *cfg, icoac_priv_state_t *st,
                        const icoac_real_t scaled[ICOAC_MAX_INPUTS], icoac_real_t penalty, int terminal,
                        icoac_output_t *out);

/* Actor-critic tick: critic and actor on the transition into s, then act (icoac_rl.c), for a
 * task of n inputs. given: NULL, or the critic's exponentials of s computed by the caller
 * (icoac_priv_step). */
int icoac_priv_rl_tick(const icoac_config_t *cfg, icoac_priv_state_t *st, const icoac_real_t s[ICOAC_MAX_INPUTS],
                       const icoac_real_t scaled[ICOAC_MAX_INPUTS], int terminal, icoac_output_t *out, int n,
                       const icoac_real_t *given);

/* Critic (method.md, critic): V(s) with the units it kept, and the TD update v_k += step * b_k
 * over such units. Two kernels compute the same units:
 * - sparse (icoac_critic.c), for microcontrollers: a sorted list of the kept cells, walked in
 *   leading runs per row; V sums in that order.
 * - dense (icoac_critic_dense.c), for hosts: every row and the cells of one range, in loops
 *   without data-dependent branches that a compiler vectorizes; V sums per cell over the rows,
 *   then over the cells.
 * The update adds the same step to the same units in both; V differs by the rounding of the
 * sum's order. ICOAC_CRITIC_DENSE=1 (the host build's default, CMake ICOAC_CRITIC_KERNEL)
 * selects the dense kernel in icoac_priv_critic_value / _update; both are always built.
 * Each kernel is one static inline function of the grid's shape (inputs, units per input, the
 * rows / cells split), instantiated twice: with the cart-pole's shape as compile-time constants
 * (unrolled like hard-wired code), and with the shape of the state's configuration, checked
 * against the arrays first; the state's shape tag (ICOAC_PRIV_SHAPE_CARTPOLE_CRITIC) selects one
 * per call. v has ICOAC_PRIV_CRITIC_WEIGHTS entries (the state's). */

/* Derive the geometry and the shape tags of a checked configuration (icoac_config_check
 * accepted it). */
void icoac_priv_critic_grid(const icoac_config_t *cfg, icoac_priv_grid_t *grid);
/* The rows x cells split of a grid of n inputs with these unit counts: the first input m from
 * which the counts multiply to at most ICOAC_CRITIC_BLOCK_MAX cells; 0 when the rows do not fit
 * that bound (or a count is not in [1, ICOAC_CRITIC_UNITS_PER_INPUT_MAX]), else m + 1. */
int icoac_priv_critic_split(const int32_t *units, int n);
/* b_k below this floor counts as 0: the threshold, or with threshold 0 the smallest normal number
 * (b_k below it is 0 under flush-to-zero and adds nothing to V either way). */
static inline icoac_real_t icoac_priv_critic_floor(const icoac_critic_config_t *critic)
{
#if defined(ICOAC_REAL_DOUBLE) && ICOAC_REAL_DOUBLE
    const icoac_real_t smallest_normal = DBL_MIN;
#else
    const icoac_real_t smallest_normal = FLT_MIN;
#endif
    return critic->threshold > smallest_normal ? critic->threshold : smallest_normal;
}
/* The normalized 1-D Gaussian factors g_0 .. g_{n-1} of one input (n in [1, 16]). With centres c_j = -R + (2j+1)R/n and
 * width sigma = R/n, (s - c_j)/sigma = d_j = o - 2j with o = s*n/R + n - 1. Relative to the
 * nearest centre j* (distance d), a_{j*+1}/a_{j*} = exp(2d - 2) =: up, a_{j*-1}/a_{j*} =
 * exp(-2d - 2) = e^-4 / up, and each further step out multiplies the ratio by e^-4: one
 * exponential per dimension instead of n. a_{j*} = 1, so far-away states never give 0/0.
 * First the nearest centre j* and the distance d to it: */
static inline int icoac_priv_factor_nearest(icoac_real_t value, icoac_real_t range, int n, icoac_real_t *distance)
{
    const icoac_real_t offset = value * ((icoac_real_t)n / range) + (icoac_real_t)(n - 1);
    int nearest;
    if (!(offset > ICOAC_R(0.0))) {
        nearest = 0;
    } else if (offset >= (icoac_real_t)(2 * (n - 1))) {
        nearest = n - 1;
    } else {
        nearest = (int)(offset * ICOAC_R(0.5) + ICOAC_R(0.5));
    }
    *distance = offset - (icoac_real_t)(2 * nearest);
    return nearest;
}
/* The arguments of the two exponentials: up's, 2d - 2, and the last centre's down, -2d - 2. */
static inline icoac_real_t icoac_priv_factor_up_arg(icoac_real_t distance)
{
    return ICOAC_R(2.0) * distance - ICOAC_R(2.0);
}
static inline icoac_real_t icoac_priv_factor_edge_arg(icoac_real_t distance)
{
    return ICOAC_R(-2.0) * distance - ICOAC_R(2.0);
}
/* given: NULL, or e^(up's argument) and e^(edge's argument) computed by the caller for this value
 * (icoac_step_batch, for many states at once); they are the values this function would take. */
static inline void icoac_priv_factors_of(icoac_real_t value, icoac_real_t range, int n, const icoac_real_t *given,
                                         icoac_real_t *g)
{
    const icoac_real_t exp_minus_4 = ICOAC_R(0.018315638888734180294);
    icoac_real_t up = ICOAC_R(0.0);
    icoac_real_t down = ICOAC_R(0.0);
    icoac_real_t ratio;
    icoac_real_t distance;
    icoac_real_t total = ICOAC_R(0.0);
    icoac_real_t inv_total;
    const int nearest = icoac_priv_factor_nearest(value, range, n, &distance);
    int j;
    if (nearest < n - 1) {
        up = (given != NULL) ? given[0] : icoac_priv_exp(icoac_priv_factor_up_arg(distance));
    }
    if (nearest > 0) {
        /* inside the grid |distance| <= 1, so up >= e^-4 and down = e^-4 / up <= 1 */
        if (nearest < n - 1) {
            down = exp_minus_4 / up;
        } else {
            down = (given != NULL) ? given[1] : icoac_priv_exp(icoac_priv_factor_edge_arg(distance));
        }
    }
    /* Both chains run over the whole array and select, so no branch depends on nearest. */
    for (j = 0; j < n; ++j) {
        g[j] = ICOAC_R(1.0);
    }
    ratio = up;
    for (j = 1; j < n; ++j) {
        const int above = j > nearest;
        const icoac_real_t next = g[j - 1] * ratio;
        g[j] = above ? next : g[j];
        ratio = above ? ratio * exp_minus_4 : ratio;
    }
    ratio = down;
    for (j = n - 2; j >= 0; --j) {
        const int below = j < nearest;
        /* j + 1 < n <= ICOAC_CRITIC_UNITS_PER_INPUT_MAX (the shape check bounds n): the analyzer,
         * losing that bound, lets n - 2 wrap around */
        const icoac_real_t next = g[j + 1] * ratio; /* NOLINT(clang-analyzer-core.UndefinedBinaryOperatorResult) */
        g[j] = below ? next : g[j];
        ratio = below ? ratio * exp_minus_4 : ratio;
    }
    for (j = 0; j < n; ++j) {
        total += g[j];
    }
    inv_total = ICOAC_R(1.0) / total;
    for (j = 0; j < n; ++j) {
        g[j] *= inv_total;
    }
}

/* The grid of the state's configuration (the general instances): n, split, the units of each
 * input and rows x cells, with n <= ICOAC_MAX_INPUTS, every count in [1, 16], rows and cells <=
 * ICOAC_CRITIC_BLOCK_MAX and rows * cells <= ICOAC_MAX_CRITIC_UNITS; 0 (no unit kept) when the
 * state's copy does not describe such a grid (a corrupted state). */
typedef struct {
    int n;
    int split;
    int rows;
    int cells;
    int units[ICOAC_MAX_INPUTS];
} icoac_priv_shape_t;
int icoac_priv_critic_shape(const icoac_critic_config_t *critic, const icoac_priv_grid_t *grid,
                            icoac_priv_shape_t *shape);
/* The cart-pole's units per input (the compile-time shape of the cart-pole instances). */
#define ICOAC_PRIV_CARTPOLE_UNITS \
    {ICOAC_CRITIC_N_X, ICOAC_CRITIC_N_X_DOT, ICOAC_CRITIC_N_THETA, ICOAC_CRITIC_N_THETA_DOT}
/* The same, with loops of a constant length (unrolled) for the common counts: the kernels' input
 * loops do not unroll, so the count is a constant only inside such a case. */
#if defined(__GNUC__) && defined(ICOAC_CRITIC_DENSE) && ICOAC_CRITIC_DENSE
__attribute__((__always_inline__)) /* hosts: inline in the dense kernel (measured: RL tick -4 %) */
#endif
static inline void icoac_priv_factors(icoac_real_t value, icoac_real_t range, int n, const icoac_real_t *given,
                                      icoac_real_t *g)
{
    switch (n) {
    case 2: icoac_priv_factors_of(value, range, 2, given, g); break;
    case 3: icoac_priv_factors_of(value, range, 3, given, g); break;
    case 6: icoac_priv_factors_of(value, range, 6, given, g); break;
    default: icoac_priv_factors_of(value, range, n, given, g); break;
    }
}
/* The products of the factors g of one input over its index range [begin, end) with each of the
 * entries products so far, in place, row-major (this input fastest), left to right; index (or
 * NULL) = the units' row-major index within the inputs so far. Returns the new number of
 * products; the caller bounds it (entries * (end - begin) <= the array's room). */
static inline int icoac_priv_critic_expand_of(icoac_real_t *product, uint8_t *index, const icoac_real_t *g,
                                              int count, int begin, int end, int entries)
{
    const int width = end > begin ? end - begin : 0;
    int e;
    int j;
    /* from the back, so that each entry is read before its slots are written */
    for (e = entries - 1; e >= 0; --e) {
        const icoac_real_t p = product[e];
        const int first = e * width - begin;
        if (index != NULL) {
            const int base = (int)index[e] * count;
            for (j = end - 1; j >= begin; --j) {
                index[first + j] = (uint8_t)(base + j);
            }
        }
        for (j = end - 1; j >= begin; --j) {
            product[first + j] = p * g[j];
        }
    }
    return entries * width;
}
/* The same, with the common counts as constants (see icoac_priv_factors). */
static inline int icoac_priv_critic_expand(icoac_real_t *product, uint8_t *index, const icoac_real_t *g, int count,
                                           int begin, int end, int entries)
{
    switch (count) {
    case 3: return icoac_priv_critic_expand_of(product, index, g, 3, begin, end, entries);
    case 6: return icoac_priv_critic_expand_of(product, index, g, 6, begin, end, entries);
    default: return icoac_priv_critic_expand_of(product, index, g, count, begin, end, entries);
    }
}
/* Every unit of an input: its whole index range, no index. */
static inline int icoac_priv_critic_expand_all(icoac_real_t *product, const icoac_real_t *g, int count, int entries)
{
    switch (count) {
    case 3: return icoac_priv_critic_expand_of(product, 0, g, 3, 0, 3, entries);
    case 6: return icoac_priv_critic_expand_of(product, 0, g, 6, 0, 6, entries);
    default: return icoac_priv_critic_expand_of(product, 0, g, count, 0, count, entries);
    }
}
icoac_real_t icoac_priv_critic_value_sparse(const icoac_critic_config_t *critic, const icoac_priv_grid_t *grid,
                                            const icoac_real_t *v, const icoac_real_t s[ICOAC_MAX_INPUTS],
                                            icoac_priv_critic_list_t *list);
/* The update of a list of the general instance: its rows and stride are checked against the
 * weights, its counts and cell indices against the list (nothing is updated when they do not
 * describe a list the value pass could write). */
void icoac_priv_critic_update_sparse(icoac_real_t *v, const icoac_priv_critic_list_t *list, icoac_real_t step);
void icoac_priv_critic_update_sparse_shaped(const icoac_priv_grid_t *grid, icoac_real_t *v,
                                            const icoac_priv_critic_list_t *list, icoac_real_t step);
icoac_real_t icoac_priv_critic_value_dense(const icoac_critic_config_t *critic, const icoac_priv_grid_t *grid,
                                           const icoac_real_t *v, const icoac_real_t s[ICOAC_MAX_INPUTS],
                                           const icoac_real_t *given, icoac_priv_critic_products_t *products);
void icoac_priv_critic_update_dense(const icoac_critic_config_t *critic, const icoac_priv_grid_t *grid,
                                    icoac_real_t *v, const icoac_priv_critic_products_t *products,
                                    icoac_real_t step);

/* No unit kept: the empty eligibility of a trial's start. */
static inline void icoac_priv_critic_clear(icoac_priv_critic_active_t *active)
{
#if defined(ICOAC_CRITIC_DENSE) && ICOAC_CRITIC_DENSE
    active->dense.cell_begin = 0u;
    active->dense.cell_end = 0u;
#else
    (void)memset(active->sparse.index, 0, sizeof active->sparse.index);
    active->sparse.cells = 0u;
#endif
}

static inline icoac_real_t icoac_priv_critic_value(const icoac_critic_config_t *critic, const icoac_priv_grid_t *grid,
                                                   const icoac_real_t *v, const icoac_real_t s[ICOAC_MAX_INPUTS],
                                                   const icoac_real_t *given, icoac_priv_critic_active_t *active)
{
#if defined(ICOAC_CRITIC_DENSE) && ICOAC_CRITIC_DENSE
    return icoac_priv_critic_value_dense(critic, grid, v, s, given, &active->dense);
#else
    (void)given; /* the dense kernel's: hosts */
    return icoac_priv_critic_value_sparse(critic, grid, v, s, &active->sparse);
#endif
}

static inline void icoac_priv_critic_update(const icoac_critic_config_t *critic, const icoac_priv_grid_t *grid,
                                            icoac_real_t *v, const icoac_priv_critic_active_t *active,
                                            icoac_real_t step)
{
#if defined(ICOAC_CRITIC_DENSE) && ICOAC_CRITIC_DENSE
    icoac_priv_critic_update_dense(critic, grid, v, &active->dense, step);
#else
    (void)critic;
    icoac_priv_critic_update_sparse_shaped(grid, v, &active->sparse, step);
#endif
}

/* Actor (icoac_actor.c). The step reads mu_w, Sigma_w and the batch sums from st and stages
 * the candidate mu_w in w, Sigma_w in cov (the spare buffer) and the batch's shift in its
 * scratch; h = G x~(t); observed: the transition's tick explored (L3); trial_end: a terminal
 * tick. Returns 1 when cov holds a new Sigma_w, 0 when Sigma_w stays, -1 when the batch sums
 * or its closed form failed, -2 for an unknown actor.update (a corrupted state). n: the task's
 * inputs; the per-tick readings stage w and cov over the first n entries only (the batch's closed
 * form over all). icoac_priv_actor_commit_batch follows the tick's checks. */
int icoac_priv_actor_step(const icoac_actor_config_t *actor, icoac_priv_state_t *st,
                          const icoac_real_t h[ICOAC_MAX_INPUTS], icoac_real_t delta, int observed, int trial_end,
                          icoac_real_t w[ICOAC_MAX_INPUTS], icoac_real_t cov[ICOAC_MAX_INPUTS][ICOAC_MAX_INPUTS], int n);
void icoac_priv_actor_commit_batch(const icoac_actor_config_t *actor, icoac_priv_state_t *st,
                                   const icoac_real_t h[ICOAC_MAX_INPUTS], int observed, int trial_end);
/* The posterior reading's step for innovation (in place allowed: w, cov may be st's own). */
void icoac_priv_actor_posterior(const icoac_actor_config_t *actor, const icoac_priv_state_t *st,
                                const icoac_real_t h[ICOAC_MAX_INPUTS], icoac_real_t innovation,
                                icoac_real_t w[ICOAC_MAX_INPUTS], icoac_real_t cov[ICOAC_MAX_INPUTS][ICOAC_MAX_INPUTS]);
/* w_act = mu_w + L n (L L^T = Sigma_w), or mu_w when Sigma_w is not positive definite. Always
 * finite: |L_ij| <= sqrt(Sigma_ii) <= sqrt(REAL_MAX) and the polar normals are below 1e8. */
void icoac_priv_actor_sample(icoac_priv_state_t *st);

/* Episodic search (icoac_search.c): the tick, the trial's draw, and the setup at init. */
int icoac_priv_search_tick(const icoac_config_t *cfg, icoac_priv_state_t *st,
                           const icoac_real_t scaled[ICOAC_MAX_INPUTS], int terminal, icoac_output_t *out);
void icoac_priv_search_sample(icoac_priv_state_t *st);
/* Sigma0 = search.cov_scale * cov finite and positive definite (checked before icoac_init
 * clears the state), then the setup of a cleared state holding the prior. */
int icoac_priv_search_prior_ok(const icoac_search_config_t *search,
                               const icoac_real_t cov[ICOAC_MAX_INPUTS][ICOAC_MAX_INPUTS], int n);
void icoac_priv_search_init(const icoac_search_config_t *search, icoac_priv_state_t *st);
/* The floors search.floor * Sigma0_ii of the recorded prior variances (icoac_retune, icoac_reset). */
void icoac_priv_search_floors(const icoac_search_config_t *search, icoac_priv_search_t *recorded);

/* Gaussian helpers (icoac_gauss.c), on the leading n x n block (n in [1, ICOAC_MAX_INPUTS]);
 * the entries of the outputs past n are 0. */
/* m = L L^T (lower may be m: factored in place); returns 0 when m is not positive definite,
 * lower then unspecified. */
int icoac_priv_cholesky(const icoac_real_t m[ICOAC_MAX_INPUTS][ICOAC_MAX_INPUTS],
                        icoac_real_t lower[ICOAC_MAX_INPUTS][ICOAC_MAX_INPUTS], int n);
/* m = m^-1 in place (exactly symmetric) through the Cholesky factor; 0 when m is not PD, m
 * then unspecified. */
int icoac_priv_spd_inverse(icoac_real_t m[ICOAC_MAX_INPUTS][ICOAC_MAX_INPUTS], int n);
/* sample = mean + L z, z n standard normals drawn from rng. */
void icoac_priv_sample_lower(icoac_rng_t *rng, const icoac_real_t mean[ICOAC_MAX_INPUTS],
                             const icoac_real_t lower[ICOAC_MAX_INPUTS][ICOAC_MAX_INPUTS],
                             icoac_real_t sample[ICOAC_MAX_INPUTS], int n);

#endif /* ICOAC_PRIV_H */
