/* SPDX-License-Identifier: Apache-2.0 */
/* icoac_step_batch against icoac_step, lane for lane and bit for bit (force, status, the whole
 * state afterwards but the batch's stamp): every mode and every reading or timing that changes the
 * tick, lanes of mixed configurations and plants, 1 to 64 lanes, each registry plant's task
 * closing the loop through the plant for hundreds of ticks with terminal ticks and resets, while
 * the states move between lanes, are retuned or stepped by icoac_step between batch ticks, and
 * two batches take turns; then the status paths.
 * TEST_BATCH_PLANTS=1 (test_batch, the simulator's float library): the registry's plants and
 * tasks. 0 (test_batch_double): the cart-pole task on a random walk of its inputs instead, which
 * fails like the plant (the simulator has no double build). */
#include "test_common.h"

#ifndef TEST_BATCH_PLANTS
#define TEST_BATCH_PLANTS 1
#endif
#if TEST_BATCH_PLANTS
#include "icoac_sim/icoac_sim.h"
#define STATE_MAX ICOAC_SIM_MAX_STATE
#else
#define STATE_MAX ICOAC_MAX_INPUTS
#endif
#include "icoac_state.h"

#define MAX_LANES 64
#define TICKS 700
#define TRIAL_CAP 250 /* a trial that lasts this long is ended by a terminal tick anyway */

/* A configuration's edit over the plant's task: the reading under test. */
typedef struct {
    const char *name;
    int32_t mode;
    void (*edit)(icoac_config_t *cfg);
    int sensor; /* the late signal from the input's flag (the test raises it from the rules) */
} variant_t;

static void ico_code(icoac_config_t *cfg)
{
    cfg->ico.rate = ICOAC_R(0.01); /* learning ticks often */
}
static void ico_literal(icoac_config_t *cfg)
{
    ico_code(cfg);
    cfg->ico.timing = ICOAC_ICO_TIMING_LITERAL;
}
static void ico_code_unclipped_gain(icoac_config_t *cfg)
{
    ico_code(cfg);
    cfg->policy.clip_inputs = 0;
    cfg->policy.reflex_mode = ICOAC_REFLEX_GAIN;
}
static void ico_literal_unclipped(icoac_config_t *cfg)
{
    ico_literal(cfg);
    cfg->policy.clip_inputs = 0;
}
static void ico_no_learning(icoac_config_t *cfg)
{
    cfg->learn = 0;
    cfg->policy.reflex_force = ICOAC_R(2.5);
}
static void ico_literal_no_learning(icoac_config_t *cfg)
{
    ico_no_learning(cfg);
    cfg->ico.timing = ICOAC_ICO_TIMING_LITERAL;
}
/* The task's first two rules swapped: rule k reads another input than in the other lanes. */
static void rules_swapped(icoac_config_t *cfg)
{
    icoac_task_config_t *task = &cfg->task;
    const int32_t input = task->rule_input[0];
    const int32_t side = task->rule_side[0];
    const icoac_real_t threshold = task->rule_threshold[0];
    const icoac_real_t reflex = task->rule_reflex[0];
    task->rule_input[0] = task->rule_input[1];
    task->rule_side[0] = task->rule_side[1];
    task->rule_threshold[0] = task->rule_threshold[1];
    task->rule_reflex[0] = task->rule_reflex[1];
    task->rule_input[1] = input;
    task->rule_side[1] = side;
    task->rule_threshold[1] = threshold;
    task->rule_reflex[1] = reflex;
}
static void ico_code_rules_swapped(icoac_config_t *cfg)
{
    ico_code(cfg);
    rules_swapped(cfg);
}
static void as_is(icoac_config_t *cfg)
{
    (void)cfg;
}
static void search_small_batch(icoac_config_t *cfg)
{
    cfg->search.batch = 2;
    cfg->policy.reflex_mode = ICOAC_REFLEX_GAIN;
}
static void search_unclipped_no_learning(icoac_config_t *cfg)
{
    cfg->policy.clip_inputs = 0;
    cfg->learn = 0;
}
static void rl_posterior(icoac_config_t *cfg)
{
    cfg->actor.update = ICOAC_ACTOR_POSTERIOR;
    cfg->actor.act_with_sample = 1;
}
static void rl_mean_batch(icoac_config_t *cfg)
{
    cfg->actor.update = ICOAC_ACTOR_MEAN;
    cfg->actor.batch = 1;
    cfg->actor.likelihood_std = ICOAC_R(0.1);
}
static void rl_quirks(icoac_config_t *cfg)
{
    cfg->critic.quirks = 1;
    cfg->actor.reflex = 0;
    cfg->actor.explore_ticks = 0;
}
static void rl_short_exploration(icoac_config_t *cfg)
{
    cfg->actor.explore_ticks = 20;
    cfg->policy.clip_inputs = 0;
}

static const variant_t variants[] = {
    {"ico code", ICOAC_MODE_ICO, ico_code, 0},
    {"ico literal", ICOAC_MODE_ICO, ico_literal, 0},
    {"ico code unclipped, reflex gain", ICOAC_MODE_ICO, ico_code_unclipped_gain, 0},
    {"ico literal unclipped", ICOAC_MODE_ICO, ico_literal_unclipped, 0},
    {"ico no learning", ICOAC_MODE_ICO, ico_no_learning, 0},
    {"ico literal no learning", ICOAC_MODE_ICO, ico_literal_no_learning, 0},
    {"ico code sensor", ICOAC_MODE_ICO, ico_code, 1},
    {"ico literal sensor", ICOAC_MODE_ICO, ico_literal, 1},
    {"ico code, rules swapped", ICOAC_MODE_ICO, ico_code_rules_swapped, 0},
    {"search rules swapped", ICOAC_MODE_SEARCH, rules_swapped, 0},
    {"search", ICOAC_MODE_SEARCH, as_is, 0},
    {"search batch 2, reflex gain", ICOAC_MODE_SEARCH, search_small_batch, 0},
    {"search unclipped, no learning", ICOAC_MODE_SEARCH, search_unclipped_no_learning, 0},
    {"search sensor", ICOAC_MODE_SEARCH, as_is, 1},
    {"rl gradient", ICOAC_MODE_RL, as_is, 0},
    {"rl posterior, sample", ICOAC_MODE_RL, rl_posterior, 0},
    {"rl mean, batch", ICOAC_MODE_RL, rl_mean_batch, 0},
    {"rl quirks, no reflex, explore always", ICOAC_MODE_RL, rl_quirks, 0},
    {"rl short exploration, unclipped", ICOAC_MODE_RL, rl_short_exploration, 0},
    {"rl sensor", ICOAC_MODE_RL, as_is, 1},
};
#define N_VARIANTS ((int)(sizeof variants / sizeof variants[0]))

/* One lane: a plant under two copies of one controller, stepped by icoac_step and by the batch. */
typedef struct {
    icoac_state_t scalar;
    icoac_state_t batch;
    icoac_config_t cfg; /* the task's rules drive a sensor variant's flag */
#if TEST_BATCH_PLANTS
    icoac_sim_model_t model;
    icoac_sim_cell_t cell;
    icoac_rng_t start_rng;
#else
    test_rng_t walk; /* the random walk's steps */
#endif
    int32_t plant_index;
    double plant[STATE_MAX];
    int variant;
    int terminal_next; /* the next tick is terminal */
    int trial_ticks;
} lane_t;

static lane_t lanes[MAX_LANES];
static icoac_state_t *batch_states[MAX_LANES];
static icoac_real_t batch_s[ICOAC_MAX_INPUTS * MAX_LANES];
static uint32_t batch_flags[MAX_LANES];
static icoac_real_t batch_reflex[MAX_LANES];
static icoac_real_t batch_force[MAX_LANES];
static int32_t batch_status[MAX_LANES];
static icoac_batch_t batches[2];
static int batch_turn;  /* which batch ticks: the other one now and then */
static int rotation;    /* column c of the batch holds lane (c + rotation) mod the lanes */

/* The batch of this tick (set up at its first use). */
static icoac_batch_t *work(void)
{
    static int ready;
    if (!ready) {
        TEST_ASSERT_EQUAL_INT(ICOAC_OK, icoac_batch_init(&batches[0]));
        TEST_ASSERT_EQUAL_INT(ICOAC_OK, icoac_batch_init(&batches[1]));
        ready = 1;
    }
    return &batches[batch_turn];
}

/* 1 when two states hold the same bytes but the batch's stamp. */
static int same_state(const icoac_state_t *a, const icoac_state_t *b)
{
    static icoac_state_t ca;
    static icoac_state_t cb;
    ca = *a;
    cb = *b;
    icoac_priv_state(&ca)->batch_token = 0u;
    icoac_priv_state(&cb)->batch_token = 0u;
    return memcmp(&ca, &cb, sizeof ca) == 0;
}

/* The plants that have a task. */
static int32_t task_plants[8];
static int n_task_plants;

static void find_task_plants(void)
{
#if TEST_BATCH_PLANTS
    int32_t p;
    icoac_config_t cfg;
    n_task_plants = 0;
    for (p = 0; p < icoac_sim_plant_count() && n_task_plants < 8; ++p) {
        if (icoac_sim_plant_task(p, 0, &cfg) == ICOAC_SIM_OK) {
            task_plants[n_task_plants++] = p;
        }
    }
    TEST_ASSERT_TRUE_MESSAGE(n_task_plants >= 3, "the registry's plants with a task");
#else
    task_plants[0] = 0; /* the random walk */
    n_task_plants = 1;
#endif
}

/* The task of plant p over icoac_config_default's. */
static void plant_task(int32_t p, icoac_config_t *cfg)
{
#if TEST_BATCH_PLANTS
    TEST_ASSERT_EQUAL_INT(ICOAC_SIM_OK, icoac_sim_plant_task(p, 0, cfg));
#else
    TEST_ASSERT_EQUAL_INT(0, p);
    icoac_config_default(cfg);
#endif
}

/* A task of 6 inputs (the general instance of the tick) with the cart-pole's rule table. */
static void six_input_task(icoac_config_t *cfg)
{
    icoac_config_default(cfg);
    cfg->task.n_inputs = 6;
    cfg->policy.input_range[4] = 1;
    cfg->policy.input_range[5] = 1;
    TEST_ASSERT_EQUAL_INT(ICOAC_OK, icoac_config_check(cfg));
}

/* A prior over the task's n inputs: weights that act (mean 0.05 .. 0.5), a small covariance. */
static icoac_prior_t lane_prior(test_rng_t *rng, int n)
{
    icoac_prior_t prior;
    int i;
    memset(&prior, 0, sizeof prior);
    for (i = 0; i < n; ++i) {
        prior.mean[i] = (icoac_real_t)test_uniform(rng, 0.05, 0.5);
        prior.cov[i][i] = (icoac_real_t)test_uniform(rng, 1e-3, 1e-2);
    }
    return prior;
}

/* A new trial of the lane's plant (its cell's start; the walk: inside the rules' thresholds). */
static void start_trial(lane_t *lane)
{
#if TEST_BATCH_PLANTS
    TEST_ASSERT_EQUAL_INT(ICOAC_SIM_OK,
                          icoac_sim_model_start(&lane->model, &lane->cell, 0.05, &lane->start_rng, lane->plant));
#else
    static const double half_width[ICOAC_CARTPOLE_INPUTS] = {1.5, 0.5, 0.15, 0.5};
    int i;
    for (i = 0; i < ICOAC_CARTPOLE_INPUTS; ++i) {
        lane->plant[i] = test_uniform(&lane->walk, -half_width[i], half_width[i]);
    }
#endif
    lane->terminal_next = 0;
    lane->trial_ticks = 0;
}

static void setup_lane(lane_t *lane, int32_t plant, int variant, uint64_t seed)
{
    const variant_t *v = &variants[variant];
    test_rng_t rng = {seed * 2654435761u + 17u};
    icoac_prior_t prior;
    memset(lane, 0, sizeof *lane);
    plant_task(plant, &lane->cfg);
    lane->plant_index = plant;
    lane->cfg.mode = v->mode;
    v->edit(&lane->cfg);
    if (v->sensor) {
        lane->cfg.task.late_source = ICOAC_LATE_SENSOR;
    }
    TEST_ASSERT_EQUAL_INT_MESSAGE(ICOAC_OK, icoac_config_check(&lane->cfg), v->name);
    prior = lane_prior(&rng, lane->cfg.task.n_inputs);
    /* ICO: w from the prior or from 0 */
    TEST_ASSERT_EQUAL_INT(ICOAC_OK, icoac_init(&lane->cfg, &lane->scalar, (seed & 1u) ? &prior : NULL, seed));
    TEST_ASSERT_EQUAL_INT(ICOAC_OK, icoac_init(&lane->cfg, &lane->batch, (seed & 1u) ? &prior : NULL, seed));
    TEST_ASSERT_TRUE(same_state(&lane->scalar, &lane->batch));
#if TEST_BATCH_PLANTS
    {
        static icoac_sim_cell_t cells[4096];
        const icoac_sim_plant_desc_t *desc = icoac_sim_plant_info(plant);
        int64_t n_cells;
        TEST_ASSERT_EQUAL_INT(ICOAC_SIM_OK, icoac_sim_model_default(&lane->model, plant));
        TEST_ASSERT_NOT_NULL(desc);
        n_cells = (int64_t)desc->rows.count * desc->cols.count;
        TEST_ASSERT_TRUE(n_cells > 0 && n_cells <= 4096);
        TEST_ASSERT_EQUAL_INT(ICOAC_SIM_OK, icoac_sim_plant_grid(plant, cells, n_cells, seed));
        lane->cell = cells[(seed * 7919u) % (uint64_t)n_cells];
        icoac_rng_seed(&lane->start_rng, seed, ICOAC_SIM_START_STREAM);
    }
#else
    lane->walk.s = seed * 0x9E3779B97F4A7C15ull + 1u;
#endif
    lane->variant = variant;
    start_trial(lane);
}

/* One step of the lane's plant under force; *failed = 1 when it left its limits. The walk:
 * each input moves by a uniform step (the rates pushed by the force), the trial failing past
 * 2.4 m or 12 degrees. */
static void advance_plant(lane_t *lane, double force, int *failed)
{
#if TEST_BATCH_PLANTS
    int32_t plant_failed = 0;
    *failed = icoac_sim_model_step(&lane->model, lane->plant, force) != ICOAC_SIM_OK ||
              icoac_sim_model_failed(&lane->model, lane->plant, &plant_failed) != ICOAC_SIM_OK || plant_failed;
#else
    static const double step[ICOAC_CARTPOLE_INPUTS] = {0.02, 0.05, 0.004, 0.02};
    int i;
    for (i = 0; i < ICOAC_CARTPOLE_INPUTS; ++i) {
        lane->plant[i] += test_uniform(&lane->walk, -step[i], step[i]) + ((i & 1) ? 0.001 * force : 0.0);
    }
    *failed = fabs(lane->plant[0]) > 2.4 || fabs(lane->plant[2]) > DEG(12.0) || !isfinite(lane->plant[1]) ||
              !isfinite(lane->plant[3]);
#endif
}

/* The sensor's late signal of a lane: the task's rule table on the plant state, with a reflex
 * beyond [-1, 1] now and then (the tick clips it). */
static uint32_t sensor_flag(const lane_t *lane, const icoac_real_t *s, icoac_real_t *reflex)
{
    const icoac_task_config_t *task = &lane->cfg.task;
    int k;
    *reflex = (icoac_real_t)0.25;
    for (k = 0; k < task->n_rules; ++k) {
        const icoac_real_t value = s[task->rule_input[k]];
        const icoac_real_t t = task->rule_threshold[k];
        if (task->rule_side[k] == ICOAC_RULE_ABOVE ? value > t : value < t) {
            *reflex = task->rule_reflex[k] * (icoac_real_t)((lane->trial_ticks % 3) == 0 ? 1.5 : 1.0);
            return ICOAC_INPUT_LATE;
        }
    }
    return 0u;
}

/* The lanes' inputs for this tick: rows 0 .. rows-1, NaN in the rows past a lane's task (they
 * must not be read); lane l in column column_of(l). */
static int column_of(int l, int n_lanes)
{
    return (l + n_lanes - (rotation % n_lanes)) % n_lanes;
}

static void make_inputs(int n_lanes, int rows)
{
    int l;
    int i;
    for (l = 0; l < n_lanes; ++l) {
        lane_t *lane = &lanes[l];
        const int c = column_of(l, n_lanes);
        icoac_real_t s[ICOAC_MAX_INPUTS];
        for (i = 0; i < rows; ++i) {
            s[i] = i < lane->cfg.task.n_inputs ? (icoac_real_t)lane->plant[i] : (icoac_real_t)NAN;
            batch_s[i * n_lanes + c] = s[i];
        }
        batch_flags[c] = lane->terminal_next ? ICOAC_INPUT_TERMINAL : 0u;
        batch_reflex[c] = (icoac_real_t)NAN; /* read only with ICOAC_INPUT_LATE */
        if (variants[lane->variant].sensor) {
            batch_flags[c] |= sensor_flag(lane, s, &batch_reflex[c]);
        }
        batch_states[c] = &lane->batch;
    }
}

/* Column c's input as icoac_step takes it. */
static icoac_input_t lane_input(int n_lanes, int rows, int c)
{
    icoac_input_t in;
    int i;
    for (i = 0; i < ICOAC_MAX_INPUTS; ++i) {
        in.s[i] = i < rows ? batch_s[i * n_lanes + c] : (icoac_real_t)NAN;
    }
    in.flags = batch_flags[c];
    in.reflex = batch_reflex[c];
    return in;
}

/* Between batch ticks, now and then, what a caller may do to a lane's state outside the batch,
 * done to both copies: a retune (another gain), or a tick of icoac_step on the state's input. */
static void outside_the_batch(int n_lanes, int rows, int tick)
{
    int l;
    for (l = 0; l < n_lanes; ++l) {
        lane_t *lane = &lanes[l];
        if ((tick + 3 * l) % 53 == 7 && !lane->terminal_next) {
            icoac_config_t cfg;
            TEST_ASSERT_EQUAL_INT(ICOAC_OK, icoac_get_config(&lane->scalar, &cfg));
            cfg.policy.gain = cfg.policy.gain * (icoac_real_t)((tick & 1) ? 0.75 : 1.25);
            TEST_ASSERT_EQUAL_INT(icoac_retune(&lane->scalar, &cfg), icoac_retune(&lane->batch, &cfg));
        } else if ((tick + 5 * l) % 41 == 5 && !lane->terminal_next) {
            const icoac_input_t in = lane_input(n_lanes, rows, column_of(l, n_lanes));
            icoac_output_t a;
            icoac_output_t b;
            TEST_ASSERT_EQUAL_INT(icoac_step(&lane->scalar, &in, &a), icoac_step(&lane->batch, &in, &b));
        }
    }
}

/* One tick of every lane both ways, compared; then the plants advance (a terminal tick: a reset
 * and a new trial). */
static void tick_and_compare(int n_lanes, int rows, int tick)
{
    icoac_status_t expected_result = ICOAC_OK;
    icoac_status_t result;
    int c;
    rotation = tick / 37;
    batch_turn = (tick % 29) == 11;
    make_inputs(n_lanes, rows);
    outside_the_batch(n_lanes, rows, tick);
    result = icoac_step_batch(work(), batch_states, n_lanes, batch_s, rows, batch_flags, batch_reflex, batch_force,
                              batch_status);
    for (c = 0; c < n_lanes; ++c) {
        const int l = (c + rotation) % n_lanes;
        lane_t *lane = &lanes[l];
        const icoac_input_t in = lane_input(n_lanes, rows, c);
        icoac_output_t out;
        const icoac_status_t status = icoac_step(&lane->scalar, &in, &out);
        if (batch_status[c] != (int32_t)status || memcmp(&batch_force[c], &out.force, sizeof out.force) != 0 ||
            !same_state(&lane->scalar, &lane->batch)) {
            TEST_PRINTF("tick %d lane %d of %d (%s, plant %d): status %d / %d, force %.9g / %.9g", tick, l, n_lanes,
                        variants[lane->variant].name, (int)lane->plant_index, (int)batch_status[c], (int)status,
                        (double)batch_force[c], (double)out.force);
        }
        TEST_ASSERT_EQUAL_INT((int)status, (int)batch_status[c]);
        TEST_ASSERT_EQUAL_MEMORY(&out.force, &batch_force[c], sizeof out.force);
        TEST_ASSERT_TRUE(same_state(&lane->scalar, &lane->batch));
        if (expected_result == ICOAC_OK) {
            expected_result = status;
        }
        if (lane->terminal_next) {
            TEST_ASSERT_EQUAL_INT(ICOAC_OK, icoac_reset(&lane->scalar));
            TEST_ASSERT_EQUAL_INT(ICOAC_OK, icoac_reset(&lane->batch));
            start_trial(lane);
        } else {
            int failed = 0;
            ++lane->trial_ticks;
            advance_plant(lane, (double)out.force, &failed);
            lane->terminal_next = failed || lane->trial_ticks >= TRIAL_CAP;
        }
    }
    TEST_ASSERT_EQUAL_INT((int)expected_result, (int)result);
}

/* n_lanes lanes; plant < 0: lane l runs plant l mod the plants, else that plant; lane l's
 * variant is (l + offset) mod the variants, or `only` when >= 0. */
static void run_lanes(int n_lanes, int plant, int offset, int only, int ticks)
{
    int rows = 1;
    int l;
    int t;
    for (l = 0; l < n_lanes; ++l) {
        const int32_t p = plant >= 0 ? task_plants[plant] : task_plants[l % n_task_plants];
        const int v = only >= 0 ? only : (l + offset) % N_VARIANTS;
        setup_lane(&lanes[l], p, v, 1000u * (uint64_t)(n_lanes + 1) + (uint64_t)l + 31u * (uint64_t)offset);
        if (lanes[l].cfg.task.n_inputs > rows) {
            rows = lanes[l].cfg.task.n_inputs;
        }
    }
    for (t = 0; t < ticks; ++t) {
        tick_and_compare(n_lanes, rows, t);
    }
}

static const int lane_counts[] = {1, 2, 7, 8, 17, 64};
#define N_LANE_COUNTS ((int)(sizeof lane_counts / sizeof lane_counts[0]))

/* Every variant alone on each plant, in batches of each size. */
static void test_each_variant_each_plant(void)
{
    int p;
    int v;
    int c;
    find_task_plants();
    for (p = 0; p < n_task_plants; ++p) {
        for (v = 0; v < N_VARIANTS; ++v) {
            for (c = 0; c < N_LANE_COUNTS; ++c) {
                if (lane_counts[c] <= 8 || v % 6 == 0) {
                    run_lanes(lane_counts[c], p, 0, v, TICKS);
                }
            }
        }
    }
}

/* Lanes of mixed modes, readings and plants (tasks of 4 and 6 inputs) in one batch. */
static void test_mixed_lanes(void)
{
    int c;
    int offset;
    find_task_plants();
    for (c = 0; c < N_LANE_COUNTS; ++c) {
        for (offset = 0; offset < 3; ++offset) {
            run_lanes(lane_counts[c], -1, offset * 5, -1, TICKS);
        }
    }
}

/* ---- status paths ---------------------------------------------------------------------------- */

/* Eight lanes of the cart-pole task (ICO, search, RL by turns) at a central state. */
static void status_setup(int n_lanes)
{
    static const int modes[3] = {ICOAC_MODE_ICO, ICOAC_MODE_SEARCH, ICOAC_MODE_RL};
    int l;
    for (l = 0; l < n_lanes; ++l) {
        lane_t *lane = &lanes[l];
        memset(lane, 0, sizeof *lane);
        icoac_config_default(&lane->cfg);
        lane->cfg.mode = modes[l % 3];
        TEST_ASSERT_EQUAL_INT(ICOAC_OK, icoac_init(&lane->cfg, &lane->scalar, NULL, 5u + (uint64_t)l));
        TEST_ASSERT_EQUAL_INT(ICOAC_OK, icoac_init(&lane->cfg, &lane->batch, NULL, 5u + (uint64_t)l));
        lane->plant[0] = 0.1 * l;
        lane->plant[2] = 0.01 * l;
        batch_states[l] = &lane->batch;
    }
}

static void status_inputs(int n_lanes)
{
    int l;
    int i;
    for (l = 0; l < n_lanes; ++l) {
        for (i = 0; i < ICOAC_CARTPOLE_INPUTS; ++i) {
            batch_s[i * n_lanes + l] = (icoac_real_t)lanes[l].plant[i];
        }
        batch_flags[l] = 0u;
        batch_reflex[l] = 0;
        batch_force[l] = (icoac_real_t)-7;
        batch_status[l] = -7;
    }
}

/* The batch's lanes against icoac_step on the scalar copies; returns the batch's result. */
static icoac_status_t status_tick(int n_lanes, const icoac_status_t *expected)
{
    icoac_status_t result =
        icoac_step_batch(work(), batch_states, n_lanes, batch_s, ICOAC_CARTPOLE_INPUTS, batch_flags, batch_reflex,
                         batch_force, batch_status);
    int l;
    for (l = 0; l < n_lanes; ++l) {
        icoac_input_t in = lane_input(n_lanes, ICOAC_CARTPOLE_INPUTS, l);
        icoac_output_t out;
        const icoac_status_t status = icoac_step(&lanes[l].scalar, &in, &out);
        TEST_ASSERT_EQUAL_INT((int)expected[l], (int)status);
        TEST_ASSERT_EQUAL_INT((int)expected[l], (int)batch_status[l]);
        TEST_ASSERT_EQUAL_MEMORY(&out.force, &batch_force[l], sizeof out.force);
        TEST_ASSERT_TRUE(same_state(&lanes[l].scalar, &lanes[l].batch));
    }
    return result;
}

static void expect_all(icoac_status_t *expected, int n_lanes, icoac_status_t status)
{
    int l;
    for (l = 0; l < n_lanes; ++l) {
        expected[l] = status;
    }
}

/* A NaN in one lane: that lane ICOAC_ERR_NONFINITE_INPUT (its nonfinite counter up), the others
 * their tick; an infinite reflex in a sensor lane likewise. */
static void test_nonfinite_lane(void)
{
    icoac_status_t expected[8];
    int lane_with_nan;
    for (lane_with_nan = 0; lane_with_nan < 8; lane_with_nan += 3) {
        icoac_counters_t counters;
        status_setup(8);
        status_inputs(8);
        batch_s[2 * 8 + lane_with_nan] = (icoac_real_t)NAN;
        expect_all(expected, 8, ICOAC_OK);
        expected[lane_with_nan] = ICOAC_ERR_NONFINITE_INPUT;
        TEST_ASSERT_EQUAL_INT(ICOAC_ERR_NONFINITE_INPUT, status_tick(8, expected));
        TEST_ASSERT_TRUE(batch_force[lane_with_nan] == 0);
        TEST_ASSERT_EQUAL_INT(ICOAC_OK, icoac_get_counters(&lanes[lane_with_nan].batch, &counters));
        TEST_ASSERT_EQUAL_UINT32(1u, counters.nonfinite);
    }
    /* an infinite input, which the clip would make finite */
    status_setup(8);
    status_inputs(8);
    batch_s[1 * 8 + 3] = (icoac_real_t)-INFINITY; /* x_dot: no rule reads it, no onset */
    expect_all(expected, 8, ICOAC_OK);
    expected[3] = ICOAC_ERR_NONFINITE_INPUT;
    TEST_ASSERT_EQUAL_INT(1, lanes[3].cfg.policy.clip_inputs);
    TEST_ASSERT_EQUAL_INT(ICOAC_ERR_NONFINITE_INPUT, status_tick(8, expected));
    /* a sensor lane's infinite reflex */
    status_setup(4);
    lanes[1].cfg.task.late_source = ICOAC_LATE_SENSOR;
    TEST_ASSERT_EQUAL_INT(ICOAC_OK, icoac_init(&lanes[1].cfg, &lanes[1].scalar, NULL, 6u));
    TEST_ASSERT_EQUAL_INT(ICOAC_OK, icoac_init(&lanes[1].cfg, &lanes[1].batch, NULL, 6u));
    status_inputs(4);
    batch_flags[1] = ICOAC_INPUT_LATE;
    batch_reflex[1] = (icoac_real_t)INFINITY;
    expect_all(expected, 4, ICOAC_OK);
    expected[1] = ICOAC_ERR_NONFINITE_INPUT;
    TEST_ASSERT_EQUAL_INT(ICOAC_ERR_NONFINITE_INPUT, status_tick(4, expected));
}

/* A state never set up, a trial ended by a terminal tick, a numeric fault, a corrupted mode: each
 * its own status in its lane, the other lanes their tick; the batch returns the first failed
 * lane's status. */
static void test_state_faults_per_lane(void)
{
    icoac_status_t expected[8];
    icoac_prior_t huge;
    icoac_state_t before;
    int i;
    status_setup(8);
    memset(&lanes[1].scalar, 0, sizeof lanes[1].scalar); /* never initialised */
    memset(&lanes[1].batch, 0, sizeof lanes[1].batch);
    /* lane 3 (ICO): weights and inputs that overflow the force */
    memset(&huge, 0, sizeof huge);
    for (i = 0; i < ICOAC_CARTPOLE_INPUTS; ++i) {
        huge.mean[i] = (icoac_real_t)1e6;
        huge.cov[i][i] = 1;
    }
    lanes[3].cfg.policy.clip_inputs = 0;
    lanes[3].cfg.policy.gain = (icoac_real_t)1e4;
    lanes[3].cfg.policy.input_range[0] = (icoac_real_t)1e-6;
    TEST_ASSERT_EQUAL_INT(ICOAC_OK, icoac_init(&lanes[3].cfg, &lanes[3].scalar, &huge, 8u));
    TEST_ASSERT_EQUAL_INT(ICOAC_OK, icoac_init(&lanes[3].cfg, &lanes[3].batch, &huge, 8u));
    lanes[3].plant[0] = REAL_IS_FLOAT ? 1e30 : 1e300; /* finite, and 1e6 times it is not */
    /* lane 4 (search): a corrupted mode */
    ((icoac_priv_state_t *)(void *)&lanes[4].scalar)->config.mode = 9;
    ((icoac_priv_state_t *)(void *)&lanes[4].batch)->config.mode = 9;
    /* lane 6 (ICO): a trial ended */
    status_inputs(8);
    batch_flags[6] = ICOAC_INPUT_TERMINAL;
    expect_all(expected, 8, ICOAC_OK);
    expected[1] = ICOAC_ERR_NOT_INITIALISED;
    expected[3] = ICOAC_ERR_NUMERIC;
    expected[4] = ICOAC_ERR_CORRUPT_STATE;
    memcpy(&before, &lanes[1].batch, sizeof before);
    TEST_ASSERT_EQUAL_INT(ICOAC_ERR_NOT_INITIALISED, status_tick(8, expected));
    TEST_ASSERT_EQUAL_MEMORY(&before, &lanes[1].batch, sizeof before);
    status_inputs(8);
    expected[6] = ICOAC_ERR_TRIAL_ENDED;
    TEST_ASSERT_EQUAL_INT(ICOAC_ERR_NOT_INITIALISED, status_tick(8, expected));
    /* a NULL state in a lane: ICOAC_ERR_NULL there, force 0 */
    status_setup(3);
    status_inputs(3);
    batch_states[1] = NULL;
    TEST_ASSERT_EQUAL_INT(ICOAC_ERR_NULL, icoac_step_batch(work(), batch_states, 3, batch_s, ICOAC_CARTPOLE_INPUTS,
                                                           batch_flags, NULL, batch_force, batch_status));
    TEST_ASSERT_EQUAL_INT(ICOAC_OK, batch_status[0]);
    TEST_ASSERT_EQUAL_INT(ICOAC_ERR_NULL, batch_status[1]);
    TEST_ASSERT_EQUAL_INT(ICOAC_OK, batch_status[2]);
    TEST_ASSERT_TRUE(batch_force[1] == 0);
}

/* A corrupted rule input (past the task's inputs; the tick reads input 0 instead) on a task of 6
 * inputs, the tick's general instance: the same tick both ways. */
static void test_corrupted_rule_input(void)
{
    icoac_status_t expected[3] = {ICOAC_OK, ICOAC_OK, ICOAC_OK};
    int l;
    int t;
    status_setup(3);
    for (l = 0; l < 3; ++l) {
        six_input_task(&lanes[l].cfg);
        lanes[l].cfg.mode = l == 1 ? ICOAC_MODE_SEARCH : ICOAC_MODE_ICO;
        lanes[l].cfg.learn = l == 2 ? 1 : 0; /* lane 0 stays on the vector path */
        TEST_ASSERT_EQUAL_INT(ICOAC_OK, icoac_init(&lanes[l].cfg, &lanes[l].scalar, NULL, 3u));
        TEST_ASSERT_EQUAL_INT(ICOAC_OK, icoac_init(&lanes[l].cfg, &lanes[l].batch, NULL, 3u));
        ((icoac_priv_state_t *)(void *)&lanes[l].scalar)->config.task.rule_input[0] = 7;
        ((icoac_priv_state_t *)(void *)&lanes[l].batch)->config.task.rule_input[0] = 7;
    }
    for (t = 0; t < 2; ++t) {
        for (l = 0; l < 3; ++l) {
            int i;
            for (i = 0; i < 6; ++i) {
                /* input 0 beyond the first rule's threshold (11.5 degrees, read on input 0 now) on
                 * one tick, not on the other, and inside every other rule */
                batch_s[i * 3 + l] = (icoac_real_t)(i == 0 ? (t == 0 ? 0.5 : -0.01) : 0.01 * (i + l));
            }
            batch_flags[l] = 0u;
            batch_reflex[l] = 0;
        }
        TEST_ASSERT_EQUAL_INT(ICOAC_OK, icoac_step_batch(work(), batch_states, 3, batch_s, 6, batch_flags, batch_reflex,
                                                         batch_force, batch_status));
        for (l = 0; l < 3; ++l) {
            icoac_input_t in = lane_input(3, 6, l);
            icoac_output_t out;
            TEST_ASSERT_EQUAL_INT((int)expected[l], (int)icoac_step(&lanes[l].scalar, &in, &out));
            TEST_ASSERT_EQUAL_MEMORY(&out.force, &batch_force[l], sizeof out.force);
            TEST_ASSERT_TRUE(same_state(&lanes[l].scalar, &lanes[l].batch));
        }
    }
}

/* A lane whose task has more inputs than the batch holds: ICOAC_ERR_NULL, its state unchanged,
 * the other lanes stepped. */
static void test_missing_inputs_lane(void)
{
    static const int lane_count[2] = {3, 12}; /* icoac_step per lane; a chunk with a vector pass */
    int c;
    for (c = 0; c < 2; ++c) {
        const int n_lanes = lane_count[c];
        icoac_state_t before;
        int l;
        status_setup(n_lanes);
        six_input_task(&lanes[2].cfg);
        TEST_ASSERT_EQUAL_INT(6, lanes[2].cfg.task.n_inputs);
        TEST_ASSERT_EQUAL_INT(ICOAC_OK, icoac_init(&lanes[2].cfg, &lanes[2].batch, NULL, 3u));
        memcpy(&before, &lanes[2].batch, sizeof before);
        status_inputs(n_lanes);
        TEST_ASSERT_EQUAL_INT(ICOAC_ERR_NULL, icoac_step_batch(work(), batch_states, n_lanes, batch_s,
                                                               ICOAC_CARTPOLE_INPUTS, batch_flags, NULL, batch_force,
                                                               batch_status));
        for (l = 0; l < n_lanes; ++l) {
            TEST_ASSERT_EQUAL_INT(l == 2 ? ICOAC_ERR_NULL : ICOAC_OK, batch_status[l]);
        }
        TEST_ASSERT_TRUE(batch_force[2] == 0);
        TEST_ASSERT_EQUAL_MEMORY(&before, &lanes[2].batch, sizeof before);
    }
}

/* A sensor lane with ICOAC_INPUT_LATE and no reflex array: as icoac_step with reflex 0. */
static void test_flags_null_read_zero(void)
{
    icoac_status_t expected[6];
    status_setup(6);
    status_inputs(6);
    expect_all(expected, 6, ICOAC_OK);
    TEST_ASSERT_EQUAL_INT(ICOAC_OK, icoac_step_batch(work(), batch_states, 6, batch_s, ICOAC_CARTPOLE_INPUTS, NULL, NULL,
                                                     batch_force, batch_status));
    (void)expected;
    {
        int l;
        for (l = 0; l < 6; ++l) {
            icoac_input_t in = lane_input(6, ICOAC_CARTPOLE_INPUTS, l);
            icoac_output_t out;
            in.flags = 0u;
            in.reflex = 0;
            TEST_ASSERT_EQUAL_INT(ICOAC_OK, icoac_step(&lanes[l].scalar, &in, &out));
            TEST_ASSERT_EQUAL_MEMORY(&out.force, &batch_force[l], sizeof out.force);
            TEST_ASSERT_TRUE(same_state(&lanes[l].scalar, &lanes[l].batch));
        }
    }
}

static void test_reflex_null_reads_zero(void)
{
    icoac_status_t expected[2] = {ICOAC_OK, ICOAC_OK};
    int l;
    status_setup(2);
    for (l = 0; l < 2; ++l) {
        lanes[l].cfg.task.late_source = ICOAC_LATE_SENSOR;
        lanes[l].cfg.policy.reflex_force = 3;
        TEST_ASSERT_EQUAL_INT(ICOAC_OK, icoac_init(&lanes[l].cfg, &lanes[l].scalar, NULL, 6u));
        TEST_ASSERT_EQUAL_INT(ICOAC_OK, icoac_init(&lanes[l].cfg, &lanes[l].batch, NULL, 6u));
    }
    status_inputs(2);
    batch_flags[0] = ICOAC_INPUT_LATE;
    TEST_ASSERT_EQUAL_INT(ICOAC_OK, icoac_step_batch(work(), batch_states, 2, batch_s, ICOAC_CARTPOLE_INPUTS, batch_flags,
                                                     NULL, batch_force, batch_status));
    /* the scalar copies with reflex 0 */
    for (l = 0; l < 2; ++l) {
        icoac_input_t in = lane_input(2, ICOAC_CARTPOLE_INPUTS, l);
        icoac_output_t out;
        in.reflex = 0;
        TEST_ASSERT_EQUAL_INT((int)expected[l], (int)icoac_step(&lanes[l].scalar, &in, &out));
        TEST_ASSERT_EQUAL_MEMORY(&out.force, &batch_force[l], sizeof out.force);
        TEST_ASSERT_TRUE(same_state(&lanes[l].scalar, &lanes[l].batch));
    }
}

/* Bad arguments: ICOAC_ERR_NULL with nothing written or stepped; no lanes: nothing done. */
static void test_bad_arguments(void)
{
    icoac_state_t before;
    int l;
    status_setup(4);
    status_inputs(4);
    memcpy(&before, &lanes[0].batch, sizeof before);
#define EXPECT_REFUSED(call)                                                   \
    do {                                                                       \
        TEST_ASSERT_EQUAL_INT(ICOAC_ERR_NULL, (call));                         \
        for (l = 0; l < 4; ++l) {                                              \
            TEST_ASSERT_EQUAL_INT(-7, batch_status[l]);                        \
            TEST_ASSERT_TRUE(batch_force[l] == (icoac_real_t)-7);              \
        }                                                                      \
        TEST_ASSERT_EQUAL_MEMORY(&before, &lanes[0].batch, sizeof before);     \
    } while (0)
    EXPECT_REFUSED(icoac_step_batch(NULL, batch_states, 4, batch_s, 4, batch_flags, NULL, batch_force, batch_status));
    EXPECT_REFUSED(icoac_step_batch(work(), NULL, 4, batch_s, 4, batch_flags, NULL, batch_force, batch_status));
    EXPECT_REFUSED(icoac_step_batch(work(), batch_states, 4, NULL, 4, batch_flags, NULL, batch_force, batch_status));
    EXPECT_REFUSED(icoac_step_batch(work(), batch_states, 4, batch_s, 4, batch_flags, NULL, NULL, batch_status));
    EXPECT_REFUSED(icoac_step_batch(work(), batch_states, 4, batch_s, 4, batch_flags, NULL, batch_force, NULL));
    EXPECT_REFUSED(icoac_step_batch(work(), batch_states, -1, batch_s, 4, batch_flags, NULL, batch_force, batch_status));
    EXPECT_REFUSED(icoac_step_batch(work(), batch_states, 4, batch_s, 0, batch_flags, NULL, batch_force, batch_status));
    EXPECT_REFUSED(icoac_step_batch(work(), batch_states, 4, batch_s, ICOAC_MAX_INPUTS + 1, batch_flags, NULL, batch_force,
                                    batch_status));
    EXPECT_REFUSED(icoac_step_batch(work(), batch_states, ICOAC_BATCH_MAX_LANES + 1, batch_s, 4, batch_flags, NULL,
                                    batch_force, batch_status));
    {
        /* a batch icoac_batch_init did not set up */
        static icoac_batch_t garbage;
        memset(&garbage, 0xA5, sizeof garbage);
        TEST_ASSERT_EQUAL_INT(ICOAC_ERR_NOT_INITIALISED, icoac_step_batch(&garbage, batch_states, 4, batch_s, 4, batch_flags,
                                                                          NULL, batch_force, batch_status));
        for (l = 0; l < 4; ++l) {
            TEST_ASSERT_EQUAL_INT(-7, batch_status[l]);
        }
        TEST_ASSERT_EQUAL_MEMORY(&before, &lanes[0].batch, sizeof before);
        TEST_ASSERT_EQUAL_INT(ICOAC_ERR_NULL, icoac_batch_init(NULL));
    }
    /* no lanes: OK, nothing stepped */
    TEST_ASSERT_EQUAL_INT(ICOAC_OK,
                          icoac_step_batch(work(), batch_states, 0, batch_s, 4, batch_flags, NULL, batch_force, batch_status));
    for (l = 0; l < 4; ++l) {
        TEST_ASSERT_EQUAL_INT(-7, batch_status[l]);
    }
    TEST_ASSERT_EQUAL_MEMORY(&before, &lanes[0].batch, sizeof before);
#undef EXPECT_REFUSED
}

void setUp(void)
{
}

void tearDown(void)
{
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_each_variant_each_plant);
    RUN_TEST(test_mixed_lanes);
    RUN_TEST(test_nonfinite_lane);
    RUN_TEST(test_state_faults_per_lane);
    RUN_TEST(test_corrupted_rule_input);
    RUN_TEST(test_missing_inputs_lane);
    RUN_TEST(test_reflex_null_reads_zero);
    RUN_TEST(test_flags_null_read_zero);
    RUN_TEST(test_bad_arguments);
    return UNITY_END();
}
