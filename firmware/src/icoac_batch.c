/* SPDX-License-Identifier: Apache-2.0 */
/* The batch tick (icoac_step_batch): many states, one tick each, in lockstep over
 * structure-of-arrays inputs and outputs. Each lane's result is icoac_step's on that state, bit
 * for bit; the scalar tick is untouched, and this file is left out of the microcontroller builds
 * (CMake ICOAC_BATCH).
 *
 * The caller's icoac_batch_t keeps, per lane, what the tick reads of its state and what only the
 * library's other functions change (configuration, scaling, rules, weights), as arrays indexed
 * [input or rule][lane]: a lane is loaded once, then ticks read nothing of its state but its
 * header. A loaded lane stays valid while only icoac_step_batch ticks its state: the load stamps
 * the state with a token (icoac_state.h, batch_token) that icoac_init, icoac_retune and icoac_reset
 * clear, and records its tick counter, which icoac_step advances; either change reloads it (a
 * tick the batch itself hands to icoac_step re-reads only what that tick can change).
 *
 * The vectorised ticks are the common ones of ICO (both timings) and search mode on a rule-table
 * task: a non-terminal tick with finite inputs and force that learns nothing. They run as one
 * loop over the lanes without data-dependent branches, each value computed with the scalar
 * tick's expression and order of operations (the dot product's pairing, the reflex force added
 * last), so the two agree without fast-math or contraction (-ffp-contract=off, GCC's default in
 * ISO C; -fno-trapping-math, which changes no value, lets GCC if-convert the loop).
 * Every other lane runs icoac_step on its own input: RL mode, a sensor task, terminal ticks, ICO's
 * learning ticks, errors of any kind, states not in a trial. An RL lane's critic exponentials
 * (two per input, icoac_priv_factors_of) are computed first for all such lanes at once, in one
 * vectorised loop, and handed to its tick (icoac_priv_step), which computes the same values
 * itself when called alone. */
#include "icoac_features.h"

#define N ICOAC_MAX_INPUTS
#define R ICOAC_MAX_RULES
#define L ICOAC_BATCH_MAX_LANES

/* The vector loops run over whole groups of this many lanes (an AVX2 vector of floats; measured
 * against 16: as fast at 16 lanes, less work at 8); the lanes past the call's count compute on
 * what their columns hold and are not committed. */
#define GROUP 8
ICOAC_STATIC_ASSERT((L % GROUP) == 0, lanes_in_whole_groups);
/* A call or a group with fewer lanes for the vector pass runs them through icoac_step: the pass
 * over the whole group would cost more. */
#define MIN_VECTOR_LANES ICOAC_BATCH_MIN_VECTOR_LANES

#define BATCH_MAGIC 0x1C0ACBA7u

/* An integer of the real's width: selects between reals and integers of one lane then share
 * vector lanes (no widening inside the loops). */
#if defined(ICOAC_REAL_DOUBLE) && ICOAC_REAL_DOUBLE
typedef int64_t lane_int_t;
#define BATCH_REAL_MAX DBL_MAX
#else
typedef int32_t lane_int_t;
#define BATCH_REAL_MAX FLT_MAX
#endif
#define LANE_TRUE ((lane_int_t)1)
#define LANE_FALSE ((lane_int_t)0)

/* How a loaded lane ticks. */
#define KIND_SCALAR 0u      /* icoac_step */
#define KIND_ICO 1u         /* vector pass, ICO mode, code timing */
#define KIND_ICO_LITERAL 2u /* vector pass, ICO mode, literal timing: also caches the tick */
#define KIND_SEARCH 3u      /* vector pass, search mode */

/* The private layout of icoac_batch_t: the loaded lanes, then the tick's working rows. */
typedef struct ICOAC_PRIV_MAY_ALIAS {
    icoac_real_t inv_range[N][L]; /* sign / range, 0 past the task's n */
    icoac_real_t w[N][L];         /* ICO: w; search: w_act */
    icoac_real_t threshold[R][L];
    icoac_real_t rule_reflex[R][L];
    lane_int_t rule_input[R][L]; /* the input a rule reads, bounded to the task's */
    lane_int_t above[R][L];      /* ICOAC_RULE_ABOVE: 1 */
    lane_int_t inputs[L];        /* the task's n */
    lane_int_t rules[L];         /* rules in force */
    lane_int_t clip[L];
    lane_int_t learns[L]; /* ICO with learn = 1 */
    icoac_real_t gain[L];
    icoac_real_t reflex_gain[L]; /* gain or reflex_force, by policy.reflex_mode */
    icoac_real_t penalty_prev[L];
    lane_int_t armed[L]; /* a penalty onset learns: code timing; literal timing with a previous tick */
    lane_int_t preset[L]; /* the cart-pole's task with the preset's rule layout (icoac_step's instance) */
    /* the tick's rows */
    icoac_real_t raw[N][L]; /* the inputs */
    icoac_real_t x[N][L];   /* scaled; after the vector pass, the RL lanes' exponentials (exps_of) */
    icoac_real_t penalty[L];
    icoac_real_t force[L];
    lane_int_t vector[L]; /* 1: the vector pass's lane; cleared where its tick needs icoac_step */
    const icoac_state_t *state[L]; /* the state a lane was loaded from (NULL: none) */
    uint32_t token[L];             /* its stamp */
    uint32_t ticks[L];             /* its tick counter */
    icoac_input_t in;              /* the input and output of a lane icoac_step runs, here */
    icoac_output_t out;            /* rather than in a frame under icoac_step's */
    uint8_t kind[L];               /* KIND_* */
    uint32_t magic;
    uint32_t next_token; /* never 0 */
    int32_t rows;        /* inputs of the largest task loaded, at most N: the rows gathered */
} batch_t;

ICOAC_STATIC_ASSERT(sizeof(batch_t) <= sizeof(icoac_batch_t), batch_fits_its_storage);

static batch_t *batch_of(icoac_batch_t *batch)
{
    return (batch_t *)(void *)batch;
}

/* The rows of the vector pass's scaled inputs, free once it has run, as the RL lanes'
 * exponentials of a group: [lane in the group][2 * input + e] (rl_exponentials). */
ICOAC_STATIC_ASSERT((2 * N * GROUP) <= (N * L), exps_fit_in_the_scaled_rows);
static icoac_real_t (*exps_of(batch_t *b))[2 * N]
{
    return (icoac_real_t(*)[2 * N])(void *)b->x;
}

/* 1 when v is finite (icoac_priv_finite as a compare, which vectorises). */
static lane_int_t is_finite(icoac_real_t v)
{
    return (ICOAC_PRIV_FABS(v) <= BATCH_REAL_MAX) ? LANE_TRUE : LANE_FALSE;
}

icoac_status_t icoac_batch_init(icoac_batch_t *batch)
{
    icoac_status_t status = ICOAC_ERR_NULL;
    if (batch != NULL) {
        batch_t *b = batch_of(batch);
        (void)memset(batch, 0, sizeof *batch);
        b->magic = BATCH_MAGIC;
        b->next_token = 1u;
        status = ICOAC_OK;
    }
    return status;
}

/* The kind of tick an initialised state's configuration gives (the instance icoac_step chooses). */
static uint8_t kind_of(const icoac_config_t *cfg)
{
    uint8_t kind = KIND_SCALAR;
    if (cfg->task.late_source == (int32_t)ICOAC_LATE_RULES) {
        if (cfg->mode == (int32_t)ICOAC_MODE_SEARCH) {
            kind = KIND_SEARCH;
        } else if (cfg->mode == (int32_t)ICOAC_MODE_ICO) {
            if (cfg->ico.timing == (int32_t)ICOAC_ICO_TIMING_CODE) {
                kind = KIND_ICO;
            } else if (cfg->ico.timing == (int32_t)ICOAC_ICO_TIMING_LITERAL) {
                kind = KIND_ICO_LITERAL;
            } else {
                /* a corrupted timing: icoac_step reports it */
            }
        } else {
            /* RL mode, or a corrupted mode */
        }
    }
    return kind;
}

/* What icoac_step may change of a loaded lane's state (the weights, the previous tick's penalty
 * and cache, the tick counter), read again. */
static void refresh_lane(batch_t *b, int32_t l, const icoac_priv_state_t *st)
{
    const uint8_t kind = b->kind[l];
    const icoac_real_t *w = (kind == KIND_SEARCH) ? st->w_act : st->w;
    int i;
    for (i = 0; i < N; ++i) {
        b->w[i][l] = w[i];
    }
    b->penalty_prev[l] = st->penalty_prev;
    b->armed[l] = ((kind != KIND_ICO_LITERAL) || (st->has_prev != 0)) ? LANE_TRUE : LANE_FALSE;
    b->ticks[l] = st->counters.ticks;
}

/* Lane l loaded from st (in a trial), and st stamped with the lane's token. The rules' inputs
 * and sides are those icoac_step's instance reads: the preset's when the cart-pole instance runs
 * with the state's tag, else the table's, bounded to the task's n. */
static void load_lane(batch_t *b, int32_t l, const icoac_state_t *state, icoac_priv_state_t *st)
{
    static const int32_t cartpole_input[ICOAC_CARTPOLE_RULES] = ICOAC_PRIV_CARTPOLE_RULE_INPUTS;
    static const int32_t cartpole_side[ICOAC_CARTPOLE_RULES] = ICOAC_PRIV_CARTPOLE_RULE_SIDES;
    const icoac_config_t *cfg = &st->config;
    const icoac_task_config_t *task = &cfg->task;
    const int n = icoac_priv_inputs(cfg);
    const int rules = icoac_priv_rules(task);
    int cartpole = 0;
    const uint8_t kind = kind_of(cfg);
    int i;
    int k;
    if ((task->n_inputs == ICOAC_CARTPOLE_INPUTS) && (task->late_source == (int32_t)ICOAC_LATE_RULES) &&
        (task->n_rules == ICOAC_CARTPOLE_RULES) && ((st->grid.shape & ICOAC_PRIV_SHAPE_CARTPOLE_RULES) != 0u)) {
        cartpole = 1;
    }
    for (i = 0; i < N; ++i) {
        b->inv_range[i][l] = st->inv_range[i];
    }
    for (k = 0; k < R; ++k) {
        const int32_t input = (cartpole != 0) ? cartpole_input[k & 3] : task->rule_input[k];
        const int32_t side = (cartpole != 0) ? cartpole_side[k & 3] : task->rule_side[k];
        b->rule_input[k][l] = ((uint32_t)input < (uint32_t)n) ? (lane_int_t)input : 0;
        b->above[k][l] = (side == (int32_t)ICOAC_RULE_ABOVE) ? LANE_TRUE : LANE_FALSE;
        b->threshold[k][l] = task->rule_threshold[k];
        b->rule_reflex[k][l] = task->rule_reflex[k];
    }
    b->inputs[l] = (lane_int_t)n;
    b->rules[l] = (lane_int_t)rules;
    b->clip[l] = (cfg->policy.clip_inputs != 0) ? LANE_TRUE : LANE_FALSE;
    b->learns[l] = ((kind != KIND_SEARCH) && (cfg->learn != 0)) ? LANE_TRUE : LANE_FALSE;
    b->gain[l] = cfg->policy.gain;
    b->reflex_gain[l] = (cfg->policy.reflex_mode == (int32_t)ICOAC_REFLEX_GAIN) ? cfg->policy.gain : cfg->policy.reflex_force;
    b->preset[l] = (cartpole != 0) ? LANE_TRUE : LANE_FALSE;
    b->kind[l] = kind;
    b->state[l] = state;
    b->token[l] = b->next_token;
    refresh_lane(b, l, st);
    st->batch_token = b->next_token;
    b->next_token = (b->next_token == UINT32_MAX) ? 1u : (b->next_token + 1u);
    if (n > b->rows) {
        b->rows = n;
    }
}

/* The batch's arguments. */
typedef struct {
    icoac_state_t *const *states;
    const icoac_real_t *s; /* rows of `lanes` values */
    const uint32_t *flags;
    const icoac_real_t *reflex; /* NULL: 0 */
    icoac_real_t *force;
    int32_t *status;
    int32_t lanes;
    int32_t inputs; /* rows of s */
} batch_args_t;

static uint32_t flags_of(const batch_args_t *a, int32_t l)
{
    return (a->flags != NULL) ? a->flags[l] : 0u;
}

/* 1 when lane l's tick runs in the vector pass: its state in a trial and loaded (loaded now if it
 * was not), a vector kind, all its inputs present, not a terminal tick. A lane of icoac_step's
 * kind (RL mode, a sensor task) is loaded too: its next ticks then read only its header. */
static lane_int_t classify(batch_t *b, const batch_args_t *a, int32_t l)
{
    icoac_state_t *const state = a->states[l];
    lane_int_t vector = LANE_FALSE;
    if ((state != NULL) && ((flags_of(a, l) & ICOAC_INPUT_TERMINAL) == 0u)) {
        icoac_priv_state_t *st = icoac_priv_state(state);
        int loaded = 0;
        if ((b->state[l] == state) && (st->batch_token == b->token[l]) && (st->batch_token != 0u) &&
            (st->counters.ticks == b->ticks[l])) {
            loaded = 1;
        }
        /* a lane whose input is missing is not loaded (its state not stamped) */
        if ((st->magic == ICOAC_PRIV_STATE_MAGIC) && (loaded == 0) && (icoac_priv_inputs(&st->config) <= a->inputs)) {
            load_lane(b, l, state, st);
            loaded = 1;
        }
        if ((st->magic == ICOAC_PRIV_STATE_MAGIC) && (loaded != 0) && (b->kind[l] != KIND_SCALAR) &&
            (b->inputs[l] <= (lane_int_t)a->inputs)) {
            vector = LANE_TRUE;
        }
    }
    return vector;
}

/* The vector pass, compiled for each x86 vector width with GCC (the loader picks the machine's);
 * the baseline build elsewhere. */
#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__)
#define BATCH_CLONES __attribute__((target_clones("default", "avx2", "avx512f")))
#else
#define BATCH_CLONES
#endif
/* The inner loops over inputs and rules unrolled, so that GCC vectorises the loop over the lanes
 * around them (it does with this and -fno-trapping-math, firmware/CMakeLists.txt). */
#if defined(__GNUC__) && !defined(__clang__)
#define BATCH_UNROLL _Pragma("GCC unroll 16")
#else
#define BATCH_UNROLL
#endif

/* The tick of the lanes [g, g + GROUP) (icoac_step.c, tick; icoac_ico.c and icoac_search.c, the
 * non-terminal path): inputs checked and scaled, the late signal, the feature, the force. A lane
 * keeps vector = 1 only when its tick commits nothing but what commit_lane writes. One loop over
 * the lanes, whose inner loops over inputs and rules have fixed counts (unrolled); every
 * operation runs unconditionally and selects follow: a conditional one would keep GCC from
 * vectorising the loop. Like icoac_step's tick, one implementation with two instances: any task
 * (n = ICOAC_MAX_INPUTS, rules = ICOAC_MAX_RULES, each lane's own n, rules and rule inputs), and
 * the cart-pole's (preset = 1: every lane of the pass has its 4 inputs and the preset's rule
 * layout, so the rules' inputs and sides are constants). */
static inline void lanes_pass(batch_t *b, int32_t g, int n, int rules, int preset)
{
    static const int32_t preset_input[ICOAC_CARTPOLE_RULES] = ICOAC_PRIV_CARTPOLE_RULE_INPUTS;
    static const int32_t preset_side[ICOAC_CARTPOLE_RULES] = ICOAC_PRIV_CARTPOLE_RULE_SIDES;
    const int rows_read = (preset != 0) ? 1 : n; /* the rows a rule's input is selected among */
    int32_t l;
    for (l = g; l < (g + GROUP); ++l) {
        icoac_real_t x[N];
        icoac_real_t reflex = ICOAC_R(0.0);
        icoac_real_t penalty = ICOAC_R(0.0);
        icoac_real_t z;
        icoac_real_t force;
        lane_int_t ok = b->vector[l];
        lane_int_t onset;
        int i;
        int k;
        /* x~_i = clip(sign_i s_i / range_i) for i < n, 0 past n; the n inputs finite */
        BATCH_UNROLL
        for (i = 0; i < N; ++i) {
            const icoac_real_t raw = b->raw[i][l];
            const lane_int_t used = ((i < n) && ((lane_int_t)i < b->inputs[l])) ? LANE_TRUE : LANE_FALSE;
            const icoac_real_t product = raw * b->inv_range[i][l];
            const icoac_real_t scaled = (used != 0) ? product : ICOAC_R(0.0);
            const lane_int_t high = (scaled > ICOAC_R(1.0)) ? LANE_TRUE : LANE_FALSE;
            const lane_int_t low = (scaled < ICOAC_R(-1.0)) ? LANE_TRUE : LANE_FALSE;
            const icoac_real_t clipped = (high != 0) ? ICOAC_R(1.0) : ((low != 0) ? ICOAC_R(-1.0) : scaled);
            ok &= (used ^ 1) | is_finite(raw);
            x[i] = (b->clip[l] != 0) ? clipped : scaled;
            b->x[i][l] = x[i];
        }
        /* the first matching rule wins: rules in reverse, each match overriding; a rule's input
         * selected among the rows */
        BATCH_UNROLL
        for (k = rules - 1; k >= 0; --k) {
            const icoac_real_t threshold = b->threshold[k][l];
            const icoac_real_t rule_reflex = b->rule_reflex[k][l];
            const lane_int_t above = (preset != 0) ? ((preset_side[k & 3] == (int32_t)ICOAC_RULE_ABOVE) ? LANE_TRUE : LANE_FALSE) : b->above[k][l];
            const lane_int_t input = b->rule_input[k][l];
            icoac_real_t value = b->raw[(preset != 0) ? preset_input[k & 3] : 0][l];
            lane_int_t greater;
            lane_int_t less;
            lane_int_t match;
            BATCH_UNROLL
            for (i = 1; i < rows_read; ++i) {
                const icoac_real_t row = b->raw[i][l];
                value = (input == (lane_int_t)i) ? row : value;
            }
            greater = (value > threshold) ? LANE_TRUE : LANE_FALSE;
            less = (value < threshold) ? LANE_TRUE : LANE_FALSE;
            match = ((preset != 0) ? LANE_TRUE : (((lane_int_t)k < b->rules[l]) ? LANE_TRUE : LANE_FALSE)) & ((above & greater) | ((above ^ 1) & less));
            reflex = (match != 0) ? rule_reflex : reflex;
            penalty = (match != 0) ? ICOAC_R(-1.0) : penalty;
        }
        /* z = w^T x~ in icoac_priv_dot's order over every entry; F = G z + the reflex force. A
         * penalty onset (drop > 0) of a learning lane is ICO's learning tick: icoac_step's. */
        z = ((b->w[0][l] * x[0]) + (b->w[1][l] * x[1])) + ((b->w[2][l] * x[2]) + (b->w[3][l] * x[3]));
        BATCH_UNROLL
        for (i = 4; (i + 1) < N; i += 2) {
            z += (b->w[i][l] * x[i]) + (b->w[i + 1][l] * x[i + 1]);
        }
#if (ICOAC_MAX_INPUTS & 1) != 0
        z += b->w[N - 1][l] * x[N - 1];
#endif
        force = (b->gain[l] * z) + (b->reflex_gain[l] * reflex);
        onset = ((b->penalty_prev[l] - penalty) > ICOAC_R(0.0)) ? LANE_TRUE : LANE_FALSE;
        b->vector[l] = ok & is_finite(force) & ((b->learns[l] & b->armed[l] & onset) ^ 1);
        b->penalty[l] = penalty;
        b->force[l] = force;
    }
}

BATCH_CLONES static void group_pass(batch_t *b, int32_t g)
{
    lanes_pass(b, g, N, R, 0);
}

BATCH_CLONES static void group_pass_cartpole(batch_t *b, int32_t g)
{
    lanes_pass(b, g, ICOAC_CARTPOLE_INPUTS, ICOAC_CARTPOLE_RULES, 1);
}

/* What lane l's scalar tick would have stored, stored (in its state and in the lane). */
static void commit_lane(batch_t *b, const batch_args_t *a, int32_t l)
{
    icoac_state_t *const state = a->states[l];
    icoac_priv_state_t *st = icoac_priv_state(state);
    const uint8_t kind = b->kind[l];
    int i;
    st->counters.ticks++;
    b->ticks[l] = st->counters.ticks;
    if (kind == KIND_SEARCH) {
        st->trial_ticks++;
    } else {
        st->penalty_prev = b->penalty[l];
        b->penalty_prev[l] = b->penalty[l];
        if (kind == KIND_ICO_LITERAL) {
            for (i = 0; i < N; ++i) {
                st->x_prev[i] = b->x[i][l];
            }
            st->has_prev = 1;
            b->armed[l] = 1;
        }
    }
    a->force[l] = b->force[l];
    a->status[l] = (int32_t)ICOAC_OK;
}

/* Lane l through icoac_step, on the input the lane was given (given: its critic's exponentials
 * or NULL, icoac_priv_step). A state in a trial whose task has more inputs than the call's rows
 * gets ICOAC_ERR_NULL: its input is missing. */
static void scalar_lane(batch_t *b, const batch_args_t *a, int32_t l, const icoac_real_t *given)
{
    icoac_state_t *const state = a->states[l];
    icoac_input_t *in = &b->in;
    int i;
    a->force[l] = ICOAC_R(0.0);
    a->status[l] = (int32_t)ICOAC_ERR_NULL;
    if ((state != NULL) && ((icoac_priv_state_c(state)->magic != ICOAC_PRIV_STATE_MAGIC) ||
                            (icoac_priv_inputs(&icoac_priv_state_c(state)->config) <= a->inputs))) {
        for (i = 0; i < N; ++i) {
            in->s[i] = (i < a->inputs) ? a->s[((size_t)i * (size_t)a->lanes) + (size_t)l] : ICOAC_R(0.0);
        }
        in->flags = flags_of(a, l);
        in->reflex = (a->reflex != NULL) ? a->reflex[l] : ICOAC_R(0.0);
        a->status[l] = (int32_t)icoac_priv_step(state, in, &b->out, given);
        a->force[l] = b->out.force;
        /* a lane loaded from this state stays so: icoac_step changed none of its configuration */
        if ((b->state[l] == state) && (icoac_priv_state_c(state)->batch_token == b->token[l]) && (b->token[l] != 0u)) {
            if (b->kind[l] == KIND_SCALAR) {
                b->ticks[l] = icoac_priv_state_c(state)->counters.ticks;
            } else {
                refresh_lane(b, l, icoac_priv_state_c(state));
            }
        }
    }
}

/* The call's inputs as the rows of the group of lanes [g, g + GROUP); zeros past the inputs
 * given and past the lanes. */
static void gather_inputs(batch_t *b, const batch_args_t *a, int32_t g)
{
    int32_t i;
    int32_t l;
    for (i = 0; i < b->rows; ++i) {
        const icoac_real_t *row = &a->s[(size_t)i * (size_t)a->lanes];
        const int32_t given = (i < a->inputs) ? a->lanes : 0;
        if ((g + GROUP) <= given) {
            (void)memcpy(&b->raw[i][g], &row[g], sizeof(icoac_real_t) * (size_t)GROUP);
        } else {
            for (l = g; l < (g + GROUP); ++l) {
                b->raw[i][l] = (l < given) ? row[l] : ICOAC_R(0.0);
            }
        }
    }
}

/* Lanes [0, lanes) classified, the vector lanes' ticks run and committed; the others keep
 * vector = 0 for scalar_lane. Out of line, like scalar_lane: the frames of the two do not add up. */
ICOAC_PRIV_NOINLINE static void vector_lanes(batch_t *b, const batch_args_t *a)
{
    const int32_t width = ((a->lanes + (GROUP - 1)) / GROUP) * GROUP;
    int32_t g;
    int32_t l;
    b->rows = (b->rows < 0) ? 0 : ((b->rows > N) ? N : b->rows); /* a corrupted batch stays inside its arrays */
    for (g = 0; g < width; g += GROUP) {
        int32_t count = 0;
        int32_t presets = 0;
        for (l = g; l < (g + GROUP); ++l) {
            b->vector[l] = (l < a->lanes) ? classify(b, a, l) : LANE_FALSE;
            count += (int32_t)b->vector[l];
            presets += (int32_t)(b->vector[l] & b->preset[l]);
        }
        if (count < MIN_VECTOR_LANES) {
            for (l = g; l < (g + GROUP); ++l) {
                b->vector[l] = LANE_FALSE;
            }
        } else {
            gather_inputs(b, a, g);
            if (presets == count) {
                group_pass_cartpole(b, g);
            } else {
                group_pass(b, g);
            }
            for (l = g; (l < (g + GROUP)) && (l < a->lanes); ++l) {
                if (b->vector[l] != 0) {
                    commit_lane(b, a, l);
                }
            }
        }
    }
}

/* e^a of every entry (icoac_priv_exp: the same bits as one call), in a loop the compiler
 * vectorises. */
BATCH_CLONES static void exp_all(icoac_real_t *values, int32_t count)
{
    int32_t k;
    for (k = 0; k < count; ++k) {
        values[k] = icoac_priv_exp(values[k]);
    }
}

/* The critic's exponentials: per RL lane l of [g, g + GROUP) whose tick will reach its critic
 * with the units this reads (the state in a trial, in RL mode, its input present), the arguments
 * its tick would give icoac_priv_exp for input i (icoac_priv_factors_of) at exps[l - g][2i + e],
 * e = 0 for up's, 1 for the edge's, then e^ of all at once. Returns the mask of such lanes (bit
 * l - g), or 0 when there are too few of them for the vector loop. Out of line: its frame is not
 * under the lanes' ticks. */
ICOAC_PRIV_NOINLINE static uint32_t rl_exponentials(const batch_args_t *a, int32_t g, icoac_real_t exps[GROUP][2 * N])
{
    static const int32_t cartpole_units[ICOAC_CARTPOLE_INPUTS] = ICOAC_PRIV_CARTPOLE_UNITS;
    uint32_t mask = 0u;
    int32_t count = 0;
    int32_t l;
    int i;
    for (l = g; l < (g + GROUP); ++l) {
        const icoac_priv_state_t *st = (l < a->lanes && a->states[l] != NULL) ? icoac_priv_state_c(a->states[l]) : NULL;
        for (i = 0; i < (2 * N); ++i) {
            exps[l - g][i] = ICOAC_R(0.0);
        }
        if ((st != NULL) && (st->magic == ICOAC_PRIV_STATE_MAGIC) && (st->config.mode == (int32_t)ICOAC_MODE_RL) &&
            (icoac_priv_inputs(&st->config) <= a->inputs)) {
            const int cartpole = (st->grid.shape & ICOAC_PRIV_SHAPE_CARTPOLE_CRITIC) != 0u;
            const int n = cartpole ? ICOAC_CARTPOLE_INPUTS : ((st->grid.n <= N) ? (int)st->grid.n : N);
            for (i = 0; i < n; ++i) {
                /* the count the critic's kernel reads: the preset's with the state's tag, else the
                 * configuration's, which its shape check bounds (any other: not used) */
                const int32_t units = cartpole ? cartpole_units[i] : st->config.critic.units[i];
                if ((units >= 1) && (units <= ICOAC_CRITIC_UNITS_PER_INPUT_MAX)) {
                    icoac_real_t distance;
                    /* the input scalar_lane hands its tick */
                    const icoac_real_t s = (i < a->inputs) ? a->s[((size_t)i * (size_t)a->lanes) + (size_t)l] : ICOAC_R(0.0);
                    (void)icoac_priv_factor_nearest(s, st->config.critic.range[i], (int)units, &distance);
                    exps[l - g][2 * i] = icoac_priv_factor_up_arg(distance);
                    exps[l - g][(2 * i) + 1] = icoac_priv_factor_edge_arg(distance);
                }
            }
            mask |= 1u << (uint32_t)(l - g);
            ++count;
        }
    }
    if (count < MIN_VECTOR_LANES) {
        return 0u;
    }
    exp_all(&exps[0][0], 2 * N * GROUP);
    return mask;
}

/* The lanes of [g, g + GROUP) that the vector pass left (vector = 0) through icoac_step, each RL
 * lane with its critic's exponentials when the group has enough of them. Out of line: its frame
 * and icoac_step's are not the caller's. */
ICOAC_PRIV_NOINLINE static void scalar_lanes(batch_t *b, const batch_args_t *a, int32_t g)
{
    icoac_real_t (*const exps)[2 * N] = exps_of(b);
    const uint32_t given = rl_exponentials(a, g, exps);
    int32_t l;
    for (l = g; (l < (g + GROUP)) && (l < a->lanes); ++l) {
        if ((a->lanes < MIN_VECTOR_LANES) || (b->vector[l] == 0)) {
            scalar_lane(b, a, l, (((given >> (uint32_t)(l - g)) & 1u) != 0u) ? exps[l - g] : NULL);
        }
    }
}

icoac_status_t icoac_step_batch(icoac_batch_t *batch, icoac_state_t *const states[], int32_t lanes,
                                const icoac_real_t *s, int32_t inputs, const uint32_t *flags,
                                const icoac_real_t *reflex, icoac_real_t *force, int32_t *status)
{
    batch_t *b = batch_of(batch);
    const batch_args_t a = {states, s, flags, reflex, force, status, lanes, inputs};
    icoac_status_t first = ICOAC_ERR_NULL;
    int32_t l;
    if ((batch != NULL) && (states != NULL) && (s != NULL) && (force != NULL) && (status != NULL) && (lanes >= 0) &&
        (lanes <= L) && (inputs >= 1) && (inputs <= N)) {
        first = ICOAC_ERR_NOT_INITIALISED;
    }
    if ((first == ICOAC_ERR_NOT_INITIALISED) && (b->magic == BATCH_MAGIC)) {
        first = ICOAC_OK;
        if (lanes >= MIN_VECTOR_LANES) {
            vector_lanes(b, &a);
        }
        for (l = 0; l < lanes; l += GROUP) {
            scalar_lanes(b, &a, l);
        }
        for (l = 0; l < lanes; ++l) {
            if ((first == ICOAC_OK) && (status[l] != (int32_t)ICOAC_OK)) {
                first = (icoac_status_t)status[l];
            }
        }
    }
    return first;
}
