/* SPDX-License-Identifier: Apache-2.0 */
/* The benchmark trial loop of one cell (method.md, benchmark protocol): trials from a fresh
 * controller until one lasts success_steps or max_trials have failed, as a lane of a block
 * (sim_internal.h) that a worker thread advances in lockstep with the block's other lanes. */
#include <float.h>
#include <math.h>
#include <string.h>

#include "icoac_sim/icoac_sim.h"
#include "sim_integrate.h"
#include "sim_internal.h"

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#if defined(ICOAC_REAL_DOUBLE) && ICOAC_REAL_DOUBLE
#define SIM_REAL_MAX DBL_MAX
#else
#define SIM_REAL_MAX ((double)FLT_MAX)
#endif

/* A plant value as the controller's real. A value outside the real type's range would be an
 * undefined conversion: it is passed as NaN, which the controller rejects. */
static inline icoac_real_t sim_real(double v)
{
    return fabs(v) <= SIM_REAL_MAX ? (icoac_real_t)v : (icoac_real_t)NAN;
}

/* The plant state as the controller's input (sim_real of each value), for a tick outside the
 * block's batch (the terminal tick, a trajectory). With SSE2 and float reals a 4-input task's
 * values go out in one 16-byte store: the compiler vectorizes icoac_step's reads of in->s into
 * one 16-byte load, which cannot be forwarded from four 4-byte stores, and would wait until they
 * retire (measured when every lane's tick came this way: two lanes ran no faster than one). */
void sim_to_input(const double *s, int32_t n, uint32_t flags, icoac_input_t *in)
{
    int32_t i = 0;
#if defined(__SSE2__) && !(defined(ICOAC_REAL_DOUBLE) && ICOAC_REAL_DOUBLE)
    if (n == 4) {
        const __m128d magnitude = _mm_castsi128_pd(_mm_set1_epi64x(0x7FFFFFFFFFFFFFFFll));
        const __m128d limit = _mm_set1_pd(SIM_REAL_MAX);
        const __m128d nan = _mm_set1_pd((double)NAN);
        const __m128d low = _mm_set_pd(s[1], s[0]);
        const __m128d high = _mm_set_pd(s[3], s[2]);
        const __m128d low_ok = _mm_cmple_pd(_mm_and_pd(low, magnitude), limit); /* false for NaN */
        const __m128d high_ok = _mm_cmple_pd(_mm_and_pd(high, magnitude), limit);
        const __m128 low_real = _mm_cvtpd_ps(_mm_or_pd(_mm_and_pd(low_ok, low), _mm_andnot_pd(low_ok, nan)));
        const __m128 high_real = _mm_cvtpd_ps(_mm_or_pd(_mm_and_pd(high_ok, high), _mm_andnot_pd(high_ok, nan)));
        _mm_storeu_ps(in->s, _mm_movelh_ps(low_real, high_real));
        i = 4;
    }
#endif
    for (; i < n; ++i) {
        in->s[i] = sim_real(s[i]);
    }
    in->flags = flags;
    in->reflex = (icoac_real_t)0; /* the late signal comes from the task's rules */
}

static void store_posterior(const icoac_state_t *ctrl, icoac_sim_cell_t *cell)
{
    icoac_prior_t post;
    int i, j;
    (void)icoac_get_posterior(ctrl, &post);
    for (i = 0; i < ICOAC_MAX_INPUTS; ++i) {
        cell->weights[i] = (double)post.mean[i];
        for (j = 0; j < ICOAC_MAX_INPUTS; ++j) {
            cell->cov[i][j] = (double)post.cov[i][j];
        }
    }
}

static void add_progress(volatile int64_t *progress, int index, int64_t amount)
{
    if (progress != 0) {
        (void)__atomic_fetch_add(&progress[index], amount, __ATOMIC_RELAXED);
    }
}

/* The lane's plant state out of the block (one contiguous state), and back. */
static void lane_state(const sim_block_t *block, int32_t lane, int32_t n, double *x)
{
    int32_t i;
    for (i = 0; i < n; ++i) {
        x[i] = block->s[i * block->lanes + lane];
    }
}

static void set_lane_state(sim_block_t *block, int32_t lane, int32_t n, const double *x)
{
    int32_t i;
    for (i = 0; i < n; ++i) {
        block->s[i * block->lanes + lane] = x[i];
    }
}

/* The lane's plant state as its controller's input, in the block (sim_real of each value). */
static void set_lane_input(sim_block_t *block, int32_t lane, int32_t n, const double *x)
{
    int32_t i;
    for (i = 0; i < n; ++i) {
        block->in[i * block->lanes + lane] = sim_real(x[i]);
    }
}

void sim_block_init(sim_block_t *block, int32_t lanes)
{
    (void)memset(block, 0, sizeof *block);
    block->lanes = lanes;
    (void)icoac_batch_init(&block->batch);
}

/* The lane's finished trials and their steps not yet in the progress counters, added. The
 * counters are shared by every thread: a lane adds to them every SIM_PROGRESS_TRIALS trials, at
 * its cell's end and at a cancel, not at every trial (measured: adding at every one of the ICO
 * grid's short trials, two threads fighting over the counters' cache line took 23 % longer). */
#define SIM_PROGRESS_TRIALS 64
static void report(const sim_job_t *job, sim_lane_t *lane)
{
    add_progress(job->progress, ICOAC_SIM_PROGRESS_TRIALS, lane->trials - lane->reported_trials);
    add_progress(job->progress, ICOAC_SIM_PROGRESS_STEPS, lane->total - lane->reported_steps);
    lane->reported_trials = lane->trials;
    lane->reported_steps = lane->total;
}

/* The cell's result from the lane; outcome last, with release order: a reader that sees it
 * non-PENDING sees the rest. */
static int finish(const sim_job_t *job, sim_lane_t *lane, int32_t outcome)
{
    icoac_sim_cell_t *cell = lane->cell;
    report(job, lane);
    cell->trials = lane->trials;
    cell->total_steps = lane->total;
    cell->last_trial_steps = outcome == ICOAC_SIM_ERROR ? 0 : lane->steps;
    cell->elapsed_time = job->model->dt * (double)lane->total;
    store_posterior(&lane->ctrl, cell);
    cell->status = lane->status;
    __atomic_store_n(&cell->outcome, outcome, __ATOMIC_RELEASE);
    add_progress(job->progress, ICOAC_SIM_PROGRESS_CELLS, 1);
    return SIM_LANE_DONE;
}

/* A new trial from the cell's start (a cancel request is honoured here, between trials). */
static int start_trial(const sim_job_t *job, sim_block_t *block, sim_lane_t *lane)
{
    double x[ICOAC_SIM_MAX_STATE];
    if (job->cancel != 0 && __atomic_load_n(job->cancel, __ATOMIC_RELAXED) != 0) {
        report(job, lane);
        return SIM_LANE_CANCELLED;
    }
    sim_start_trial(job->desc, lane->cell, job->run->init_velocity_noise, &lane->rng, x);
    set_lane_state(block, lane->lane, job->desc->n_state, x);
    set_lane_input(block, lane->lane, job->cfg->task.n_inputs, x);
    lane->steps = 0;
    lane->status = (int32_t)icoac_reset(&lane->ctrl);
    return lane->status == ICOAC_SIM_OK ? SIM_LANE_RUNNING : finish(job, lane, ICOAC_SIM_ERROR);
}

/* A trial ended: it lasted success_steps steps (balanced), or failed. */
static int end_trial(const sim_job_t *job, sim_block_t *block, sim_lane_t *lane, int balanced)
{
    ++lane->trials;
    lane->total += lane->steps;
    if (lane->trials - lane->reported_trials >= SIM_PROGRESS_TRIALS) {
        report(job, lane);
    }
    if (balanced) {
        return finish(job, lane, ICOAC_SIM_SUCCESS);
    }
    if (lane->trials >= job->run->max_trials) {
        return finish(job, lane, ICOAC_SIM_FAILED);
    }
    return start_trial(job, block, lane);
}

int32_t sim_lane_init(const sim_job_t *job, sim_lane_t *lane, icoac_sim_cell_t *cell)
{
    const int32_t status = (int32_t)icoac_init(job->cfg, &lane->ctrl, job->prior, icoac_mix_seed(cell->seed, 1u));
    icoac_rng_seed(&lane->rng, cell->seed, ICOAC_SIM_START_STREAM);
    lane->cell = cell;
    lane->trials = 0;
    lane->total = 0;
    lane->steps = 0;
    lane->reported_trials = 0;
    lane->reported_steps = 0;
    lane->status = status;
    return status;
}

int sim_lane_start(const sim_job_t *job, sim_block_t *block, sim_lane_t *lane)
{
    return start_trial(job, block, lane);
}

/* Lane l's controller input out of the block, for icoac_step. A 4-input task's floats go out in
 * one 16-byte store with SSE2, as in sim_to_input (icoac_step reads them with one load). */
static inline void lane_input(const sim_block_t *block, int32_t l, int32_t n_inputs, icoac_input_t *in)
{
    const int32_t lanes = block->lanes;
    int32_t i = 0;
#if defined(__SSE2__) && !(defined(ICOAC_REAL_DOUBLE) && ICOAC_REAL_DOUBLE)
    if (n_inputs == 4) {
        _mm_storeu_ps(in->s, _mm_setr_ps(block->in[l], block->in[lanes + l], block->in[2 * lanes + l],
                                         block->in[3 * lanes + l]));
        i = 4;
    }
#endif
    for (; i < ICOAC_MAX_INPUTS; ++i) {
        in->s[i] = i < n_inputs ? block->in[i * lanes + l] : (icoac_real_t)0;
    }
    in->flags = 0u;
    in->reflex = (icoac_real_t)0;
}

/* Every running lane's controller ticks on its input, and its force becomes the lane's plant
 * input, or a lane whose controller reported an error ends (its cell's result written): state[l]
 * becomes its SIM_LANE_*. Returns how many lanes ended. One icoac_step_batch for the lanes; a
 * configuration whose ticks have no vector path there (RL mode, a sensor task: icoac_batch.c),
 * or a block of too few lanes for it, steps each lane with icoac_step instead, which spares the
 * batch's bookkeeping. */
static int block_act(const sim_job_t *job, sim_block_t *block, sim_lane_t *lanes, int *state)
{
    const icoac_config_t *cfg = job->cfg;
    const int32_t n = block->lanes;
    int32_t l;
    int ended = 0;
    if (cfg->mode == ICOAC_MODE_RL || cfg->task.late_source != ICOAC_LATE_RULES || n < ICOAC_BATCH_MIN_VECTOR_LANES) {
        for (l = 0; l < n; ++l) {
            if (state[l] == SIM_LANE_RUNNING) {
                icoac_input_t in;
                icoac_output_t out;
                lane_input(block, l, cfg->task.n_inputs, &in);
                block->status[l] = (int32_t)icoac_step(&lanes[l].ctrl, &in, &out);
                block->force[l] = out.force;
            }
        }
    } else {
        for (l = 0; l < n; ++l) {
            block->ctrl[l] = state[l] == SIM_LANE_RUNNING ? &lanes[l].ctrl : 0;
        }
        (void)icoac_step_batch(&block->batch, block->ctrl, n, block->in, cfg->task.n_inputs, 0, 0, block->force,
                               block->status);
    }
    for (l = 0; l < n; ++l) {
        if (state[l] == SIM_LANE_RUNNING) {
            lanes[l].status = block->status[l];
            if (block->status[l] != ICOAC_SIM_OK) {
                state[l] = finish(job, &lanes[l], ICOAC_SIM_ERROR);
                ++ended;
            }
            block->u[l] = (double)block->force[l];
        }
    }
    return ended;
}

/* The controllers' inputs from the plant states (sim_real of each of count values). */
SIM_VECTOR_CLONES static void block_inputs(const double *restrict s, int32_t count, icoac_real_t *restrict in)
{
    int32_t i;
    for (i = 0; i < count; ++i) {
        in[i] = sim_real(s[i]);
    }
}

/* The plant step of every lane, then each lane's failure test and next input, all in loops over
 * the lanes. The cart-pole's step is called directly: through the descriptor, the ICO tick of
 * every paper benchmark cost more (when a block held two lanes). */
static void block_step(const sim_job_t *job, sim_block_t *block)
{
    const icoac_sim_model_t *model = job->model;
    const double *p = model->param;
    const int32_t lanes = block->lanes;
    const int32_t n_inputs = job->cfg->task.n_inputs;
    if (model->plant == ICOAC_SIM_CART_POLE) {
        sim_cart_pole_step(p, model->dt, model->integrator, block->s, block->u, lanes);
    } else {
        job->desc->step(p, model->dt, model->integrator, block->s, block->u, lanes);
    }
    job->desc->failed(p, block->s, lanes, block->failed);
    block_inputs(block->s, n_inputs * lanes, block->in); /* the inputs' layout is the states' */
}

/* After the plant step of a lane that acted: a failure or the success length ends the trial, and
 * then the next trial starts or the cell's result is written: SIM_LANE_*. */
static inline int lane_observe(const sim_job_t *job, sim_block_t *block, sim_lane_t *lane)
{
    ++lane->steps;
    if (block->failed[lane->lane]) {
        /* Let the controller learn from the failure state; it rejects NaN plant states,
         * which end the trial like any failure, but a numeric fault is an error. */
        double x[ICOAC_SIM_MAX_STATE];
        icoac_input_t in;
        icoac_output_t out;
        lane_state(block, lane->lane, job->desc->n_state, x);
        sim_to_input(x, job->cfg->task.n_inputs, ICOAC_INPUT_TERMINAL, &in);
        if (icoac_step(&lane->ctrl, &in, &out) == ICOAC_ERR_NUMERIC) {
            lane->status = ICOAC_ERR_NUMERIC;
            return finish(job, lane, ICOAC_SIM_ERROR);
        }
        return end_trial(job, block, lane, 0);
    }
    /* a failure at the last step is a failure */
    return lane->steps >= job->run->success_steps ? end_trial(job, block, lane, 1) : SIM_LANE_RUNNING;
}

int sim_block_tick(const sim_job_t *job, sim_block_t *block, sim_lane_t *lanes, int *state)
{
    int acted[ICOAC_SIM_MAX_LANES];
    int32_t l;
    int ended = block_act(job, block, lanes, state);
    for (l = 0; l < block->lanes; ++l) {
        acted[l] = state[l] == SIM_LANE_RUNNING;
    }
    block_step(job, block);
    for (l = 0; l < block->lanes; ++l) {
        if (acted[l]) {
            state[l] = lane_observe(job, block, &lanes[l]);
            ended += state[l] != SIM_LANE_RUNNING;
        }
    }
    return ended;
}

int32_t icoac_sim_run_cell(const icoac_config_t *cfg, const icoac_sim_model_t *model,
                           const icoac_sim_run_t *run, const icoac_prior_t *prior,
                           icoac_sim_cell_t *cell, const volatile int32_t *cancel,
                           volatile int64_t *progress)
{
    sim_lane_t lane;
    sim_block_t block;
    uint32_t fpu_mode;
    int state = SIM_LANE_RUNNING;
    int32_t status = sim_check_all(cfg, model, run);
    if (status != ICOAC_SIM_OK) {
        return status;
    }
    if (run == 0 || cell == 0 || !isfinite(cell->x0) || !isfinite(cell->theta0)) {
        return ICOAC_SIM_ERR_BAD_ARGUMENT;
    }
    {
        const sim_job_t job = {cfg, model, icoac_sim_plant_info(model->plant), run, prior, cancel, progress};
        fpu_mode = sim_fpu_flush_subnormals();
        sim_block_init(&block, 1);
        lane.lane = 0;
        status = sim_lane_init(&job, &lane, cell);
        if (status == ICOAC_SIM_OK) {
            state = sim_lane_start(&job, &block, &lane);
            while (state == SIM_LANE_RUNNING) {
                (void)sim_block_tick(&job, &block, &lane, &state);
            }
        }
        sim_fpu_restore(fpu_mode);
    }
    return state == SIM_LANE_CANCELLED ? ICOAC_SIM_CANCELLED : status;
}
