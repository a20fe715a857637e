/* SPDX-License-Identifier: Apache-2.0 */
/* Private layout of icoac_state_t; tests and the library include it, callers do not. */
#ifndef ICOAC_STATE_H
#define ICOAC_STATE_H

#include "icoac/icoac.h"

/* The layout is read through a cast of the caller's storage: may_alias tells GCC and clang
 * that it aliases icoac_state_t (other compilers do not exploit the aliasing rule across the
 * library's translation units). */
#if defined(__GNUC__)
#define ICOAC_PRIV_MAY_ALIAS __attribute__((__may_alias__))
#else
#define ICOAC_PRIV_MAY_ALIAS
#endif

/* The header word of an initialised state; it changes with the layout. A terminal tick turns a
 * trial's word into the ended one until icoac_reset: a tick in between is refused. */
#define ICOAC_PRIV_STATE_MAGIC 0x1C0AC071u
#define ICOAC_PRIV_STATE_ENDED 0x1C0AC07Fu

/* Critic blocks (icoac.h, critic): unit k = row * cells + cell with rows, cells <=
 * ICOAC_CRITIC_BLOCK_MAX and rows * cells <= ICOAC_MAX_CRITIC_UNITS, so rows + cells <=
 * ICOAC_CRITIC_BLOCK_MAX + ICOAC_MAX_CRITIC_UNITS / ICOAC_CRITIC_BLOCK_MAX (the sum of two factors of
 * a bounded product is largest at the extremes). A kept-unit list holds the rows' products, then
 * the cells' and a 0 after them, in one array of ICOAC_PRIV_LIST slots; the kernels check a
 * geometry against these bounds before they use it, whatever the state holds. */
#define ICOAC_PRIV_CELL_MASK 31
#define ICOAC_PRIV_LIST ICOAC_STATE_LIST
#define ICOAC_PRIV_LIST_BOUND (ICOAC_CRITIC_BLOCK_MAX + ICOAC_MAX_CRITIC_UNITS / ICOAC_CRITIC_BLOCK_MAX + 1)
#define ICOAC_PRIV_LIST_MAX (2 * ICOAC_CRITIC_BLOCK_MAX + 1)
ICOAC_STATIC_ASSERT(ICOAC_STATE_LIST ==
                        (ICOAC_PRIV_LIST_BOUND < ICOAC_PRIV_LIST_MAX ? ICOAC_PRIV_LIST_BOUND : ICOAC_PRIV_LIST_MAX),
                    list_room_as_bounded);
#define ICOAC_PRIV_CRITIC_WEIGHTS ICOAC_MAX_CRITIC_UNITS
ICOAC_STATIC_ASSERT(ICOAC_CRITIC_BLOCK_MAX <= ICOAC_PRIV_CELL_MASK, block_fits_its_mask);
ICOAC_STATIC_ASSERT(ICOAC_CRITIC_UNITS_PER_INPUT_MAX <= ICOAC_CRITIC_BLOCK_MAX, an_input_fits_a_block);

/* Shape tags of the configuration in force (icoac_priv_grid_t.shape), derived by icoac_init /
 * icoac_retune / icoac_reset: the RL tick runs the critic kernels instantiated for the
 * cart-pole's shape when CARTPOLE_CRITIC is set, the general ones otherwise; the tick's
 * cart-pole instance reads the rule table with the cart-pole's inputs and sides as constants
 * when CARTPOLE_RULES is set (thresholds and reflexes from the configuration copy). Those
 * instances use their compile-time shape, inside every array whatever the state holds, so a
 * corrupted tag stays memory-safe. (The tick's instance itself is chosen on the task's three
 * words in the configuration copy: icoac_step.c; the actor's on the task's n.) */
#define ICOAC_PRIV_SHAPE_CARTPOLE_RULES 1u  /* the rule table of the cart-pole preset: inputs and sides */
#define ICOAC_PRIV_SHAPE_CARTPOLE_CRITIC 2u /* RL with 4 inputs and the 3 x 3 x 6 x 3 grid (rows 9, cells 18) */
/* The cart-pole preset's rules (Eq. 4, first match wins): the input and side of each. */
#define ICOAC_PRIV_CARTPOLE_RULE_INPUTS {ICOAC_IDX_THETA, ICOAC_IDX_X, ICOAC_IDX_THETA, ICOAC_IDX_X}
#define ICOAC_PRIV_CARTPOLE_RULE_SIDES {ICOAC_RULE_ABOVE, ICOAC_RULE_BELOW, ICOAC_RULE_BELOW, ICOAC_RULE_ABOVE}
#define ICOAC_PRIV_CARTPOLE_ROWS (ICOAC_CRITIC_N_X * ICOAC_CRITIC_N_X_DOT)
#define ICOAC_PRIV_CARTPOLE_CELLS (ICOAC_CRITIC_N_THETA * ICOAC_CRITIC_N_THETA_DOT)
ICOAC_STATIC_ASSERT(ICOAC_PRIV_CARTPOLE_ROWS + ICOAC_PRIV_CARTPOLE_CELLS < ICOAC_PRIV_LIST, cartpole_list_fits);

/* The critic's geometry, derived from the configuration: inputs [0, split) index the rows,
 * [split, n) the cells. units is not kept: critic.units of the configuration copy holds it. */
typedef struct {
    uint8_t n;     /* task.n_inputs */
    uint8_t split; /* first cell input, < n */
    uint8_t shape; /* ICOAC_PRIV_SHAPE_* bits */
    uint8_t unused;
} icoac_priv_grid_t;

/* Critic units kept (b_k >= critic.threshold) at one state: the eligibility of the next TD
 * update, in the layout of the critic kernel that found them (icoac_priv.h).
 * Sparse kernel: product[0, rows) are the rows' products, product[rows, rows + cells) the kept
 * cells' products, largest first, then a 0; index[r] (r < rows) is the number of leading cells
 * of the list that row r keeps (0: none), index[rows + i] the listed cell's index. */
typedef struct {
    icoac_real_t product[ICOAC_PRIV_LIST];
    uint8_t index[ICOAC_PRIV_LIST];
    uint8_t cells;  /* cells listed */
    uint8_t rows;   /* rows of the grid */
    uint8_t stride; /* cells of the grid: a row's units */
} icoac_priv_critic_list_t;

/* Dense kernel: product[0, rows) the rows' products, product[rows, rows + stride) every cell's;
 * unit row * stride + cell is kept when their product reaches the threshold. Only cells in
 * [cell_begin, cell_end) can be (the others have a product below it). */
typedef struct {
    icoac_real_t product[ICOAC_PRIV_LIST];
    uint8_t cell_begin;
    uint8_t cell_end; /* <= cell_begin: no unit kept */
    uint8_t rows;
    uint8_t stride;
} icoac_priv_critic_products_t;

typedef union {
    icoac_priv_critic_list_t sparse;
    icoac_priv_critic_products_t dense;
} icoac_priv_critic_active_t;

/* Per-trial sums of the actor's batch granularity (actor.batch), over the explored ticks. */
typedef struct {
    icoac_real_t info[ICOAC_MAX_INPUTS][ICOAC_MAX_INPUTS]; /* sum h h^T / sigma_L^2 (posterior, mean) */
    icoac_real_t shift[ICOAC_MAX_INPUTS];                /* sum h * innovation / sigma_L^2; gradient: sum delta eps h */
    icoac_real_t staged_shift[ICOAC_MAX_INPUTS];         /* scratch: shift after this tick, until its commit */
} icoac_priv_actor_batch_t;

/* Episodic search (ICOAC_MODE_SEARCH): the batch of trials since the last update. */
typedef struct {
    icoac_real_t w[ICOAC_SEARCH_BATCH_MAX][ICOAC_MAX_INPUTS]; /* each trial's sampled weights */
    uint32_t ticks[ICOAC_SEARCH_BATCH_MAX];                 /* its length (the return) */
    icoac_real_t lower[ICOAC_MAX_INPUTS][ICOAC_MAX_INPUTS];     /* Cholesky factor of Sigma_w */
    icoac_real_t floor[ICOAC_MAX_INPUTS];                     /* search.floor * Sigma0_ii */
    icoac_real_t prior_var[ICOAC_MAX_INPUTS];                 /* the prior's variances: Sigma0_ii / cov_scale */
    int32_t count;                                          /* trials recorded, [0, search.batch) */
} icoac_priv_search_t;

/* Everything the controller owns. The small per-tick fields come first: a Cortex-M load or
 * store reaches 1020 bytes past the base, so fields behind the large arrays cost an address
 * computation per access. */
typedef struct ICOAC_PRIV_MAY_ALIAS {
    uint32_t magic;                                   /* set by icoac_init; ENDED after a terminal tick */
    int32_t has_prev;                                 /* a previous tick of this trial is cached */
    uint32_t batch_token;                             /* the stamp of the icoac_step_batch lane this state is
                                                         loaded in (icoac_batch.c); 0: none. init, retune
                                                         and reset clear it */
    icoac_config_t config;                            /* in force: checked by icoac_init / icoac_retune,
                                                         checked again by icoac_reset */
    icoac_priv_grid_t grid;                           /* the critic's geometry, derived */
    icoac_real_t inv_range[ICOAC_MAX_INPUTS];           /* task.input_sign / policy.input_range (0 past n), derived by icoac_init */
    icoac_real_t w[ICOAC_MAX_INPUTS];                   /* ICO weights, or actor mean mu_w */
    icoac_real_t weight_norm;                         /* |w|, refreshed when w changes */
    icoac_real_t w_act[ICOAC_MAX_INPUTS];               /* weights used to act (mu_w or a sample) */
    int32_t cov_slot;                                 /* index of Sigma_w in cov_buffer (read & 1) */
    int32_t active_slot;                              /* index of s_t's entry in active (read & 1) */
    icoac_real_t x_prev[ICOAC_MAX_INPUTS];              /* scaled observation of the previous tick */
    icoac_real_t penalty_prev;                        /* r of the previous ICO observation */
    icoac_real_t value_prev;                          /* V(s_t) */
    icoac_real_t noise_prev;                          /* exploration noise eps_t (N) */
    uint32_t trial_ticks;                             /* RL and search: non-terminal ticks of this trial so far (wraps at 2^32) */
    icoac_rng_t rng;                                  /* exploration noise; search: the samples */
    icoac_counters_t counters;
    icoac_real_t cov_buffer[2][ICOAC_MAX_INPUTS][ICOAC_MAX_INPUTS]; /* Sigma_w, and the spare the RL tick stages into */
    icoac_priv_critic_active_t active[2];             /* kept critic units of s_t and of s */
    icoac_real_t v[ICOAC_PRIV_CRITIC_WEIGHTS];        /* critic weights: the grid's units */
    icoac_priv_actor_batch_t batch;                   /* RL, actor.batch: this trial's sums */
    icoac_priv_search_t search;                       /* search mode */
} icoac_priv_state_t;

ICOAC_STATIC_ASSERT(sizeof(icoac_priv_state_t) <= sizeof(icoac_state_t), state_fits_its_storage);
ICOAC_STATIC_ASSERT(sizeof(icoac_priv_state_t) + 128 > sizeof(icoac_state_t), state_storage_not_oversized);
ICOAC_STATIC_ASSERT(sizeof(icoac_state_t) == (size_t)ICOAC_STATE_SIZE, state_size_as_documented);

/* The layout of a caller's state. */
static inline icoac_priv_state_t *icoac_priv_state(icoac_state_t *state)
{
    return (icoac_priv_state_t *)(void *)state;
}

static inline const icoac_priv_state_t *icoac_priv_state_c(const icoac_state_t *state)
{
    return (const icoac_priv_state_t *)(const void *)state;
}

/* The actor covariance Sigma_w, and the spare buffer a tick stages a new one into. The slot is
 * masked, so any state content indexes inside the buffer. */
static inline icoac_real_t (*icoac_priv_cov(icoac_priv_state_t *st))[ICOAC_MAX_INPUTS]
{
    return st->cov_buffer[st->cov_slot & 1];
}

static inline const icoac_real_t (*icoac_priv_cov_c(const icoac_priv_state_t *st))[ICOAC_MAX_INPUTS]
{
    return (const icoac_real_t(*)[ICOAC_MAX_INPUTS])st->cov_buffer[st->cov_slot & 1];
}

static inline icoac_real_t (*icoac_priv_cov_spare(icoac_priv_state_t *st))[ICOAC_MAX_INPUTS]
{
    return st->cov_buffer[(st->cov_slot & 1) ^ 1];
}

/* The state's trial has started and not ended. */
static inline int icoac_priv_initialised(const icoac_priv_state_t *st)
{
    return st->magic == ICOAC_PRIV_STATE_MAGIC || st->magic == ICOAC_PRIV_STATE_ENDED;
}

#endif /* ICOAC_STATE_H */
