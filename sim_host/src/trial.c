/* SPDX-License-Identifier: Apache-2.0 */
/* The benchmark trial loop of one cell (method.md, benchmark protocol): trials from a fresh
 * controller until one lasts success_steps or max_trials have failed, as a lane
 * (sim_internal.h) that advances one tick per call, so that a worker thread can interleave
 * several cells. */
#include <float.h>
#include <math.h>
#include <string.h>

#include "icoac_sim/icoac_sim.h"
#include "sim_internal.h"

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#if defined(ICOAC_REAL_DOUBLE) && ICOAC_REAL_DOUBLE
#define SIM_REAL_MAX DBL_MAX
#else
#define SIM_REAL_MAX ((double)FLT_MAX)
#endif

/* The plant state as the controller's reals. A value outside the real type's range would be
 * an undefined conversion: it is passed as NaN, which the controller rejects.
 * With SSE2 and float reals a 4-input task's values go out in one 16-byte store. The compiler
 * vectorizes icoac_step's reads of in->s into one 16-byte load, which cannot be forwarded from
 * four 4-byte stores: it then waits until they retire, and that serializes the ticks of the
 * engine's lanes (measured: two lanes in lockstep ran no faster than one). */
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
        in->s[i] = fabs(s[i]) <= SIM_REAL_MAX ? (icoac_real_t)s[i] : (icoac_real_t)NAN;
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

/* One plant step under u; 1 when the plant then failed. The cart-pole's step is called and its
 * test made directly: through the descriptor, the ICO tick of every paper benchmark cost 4 %
 * more. */
static inline int32_t lane_plant_step(const sim_job_t *job, double *s, double u)
{
    const icoac_sim_model_t *model = job->model;
    if (model->plant == ICOAC_SIM_CART_POLE) {
        sim_cart_pole_step(model->param, model->dt, model->integrator, s, u);
        return sim_cart_pole_failed(model->param[SIM_CART_POLE_X_LIMIT], model->param[SIM_CART_POLE_THETA_LIMIT], s);
    }
    job->desc->step(model->param, model->dt, model->integrator, s, u);
    return job->desc->failed(model->param, s);
}

/* The cell's result from the lane; outcome last, with release order: a reader that sees it
 * non-PENDING sees the rest. */
static int finish(const sim_job_t *job, sim_lane_t *lane, int32_t outcome)
{
    icoac_sim_cell_t *cell = lane->cell;
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
static int start_trial(const sim_job_t *job, sim_lane_t *lane)
{
    if (job->cancel != 0 && __atomic_load_n(job->cancel, __ATOMIC_RELAXED) != 0) {
        return SIM_LANE_CANCELLED;
    }
    sim_start_trial(job->desc, lane->cell, job->run->init_velocity_noise, &lane->rng, lane->s);
    lane->steps = 0;
    lane->status = (int32_t)icoac_reset(&lane->ctrl);
    return lane->status == ICOAC_SIM_OK ? SIM_LANE_RUNNING : finish(job, lane, ICOAC_SIM_ERROR);
}

/* A trial ended: it lasted success_steps steps (balanced), or failed. */
static int end_trial(const sim_job_t *job, sim_lane_t *lane, int balanced)
{
    ++lane->trials;
    lane->total += lane->steps;
    add_progress(job->progress, ICOAC_SIM_PROGRESS_TRIALS, 1);
    add_progress(job->progress, ICOAC_SIM_PROGRESS_STEPS, lane->steps);
    if (balanced) {
        return finish(job, lane, ICOAC_SIM_SUCCESS);
    }
    if (lane->trials >= job->run->max_trials) {
        return finish(job, lane, ICOAC_SIM_FAILED);
    }
    return start_trial(job, lane);
}

int32_t sim_lane_init(const sim_job_t *job, sim_lane_t *lane, icoac_sim_cell_t *cell)
{
    const int32_t status = (int32_t)icoac_init(job->cfg, &lane->ctrl, job->prior, icoac_mix_seed(cell->seed, 1u));
    icoac_rng_seed(&lane->rng, cell->seed, ICOAC_SIM_START_STREAM);
    lane->cell = cell;
    lane->trials = 0;
    lane->total = 0;
    lane->steps = 0;
    lane->status = status;
    return status;
}

int sim_lane_start(const sim_job_t *job, sim_lane_t *lane)
{
    return start_trial(job, lane);
}

int sim_lane_tick(const sim_job_t *job, sim_lane_t *lane)
{
    icoac_input_t in;
    icoac_output_t out;
    int32_t failed;
    sim_to_input(lane->s, job->cfg->task.n_inputs, 0u, &in);
    lane->status = (int32_t)icoac_step(&lane->ctrl, &in, &out);
    if (lane->status != ICOAC_SIM_OK) {
        return finish(job, lane, ICOAC_SIM_ERROR);
    }
    failed = lane_plant_step(job, lane->s, (double)out.force);
    ++lane->steps;
    if (failed) {
        /* Let the controller learn from the failure state; it rejects NaN plant states,
         * which end the trial like any failure, but a numeric fault is an error. */
        sim_to_input(lane->s, job->cfg->task.n_inputs, ICOAC_INPUT_TERMINAL, &in);
        if (icoac_step(&lane->ctrl, &in, &out) == ICOAC_ERR_NUMERIC) {
            lane->status = ICOAC_ERR_NUMERIC;
            return finish(job, lane, ICOAC_SIM_ERROR);
        }
        return end_trial(job, lane, 0);
    }
    /* a failure at the last step is a failure */
    return lane->steps >= job->run->success_steps ? end_trial(job, lane, 1) : SIM_LANE_RUNNING;
}

int32_t icoac_sim_run_cell(const icoac_config_t *cfg, const icoac_sim_model_t *model,
                           const icoac_sim_run_t *run, const icoac_prior_t *prior,
                           icoac_sim_cell_t *cell, const volatile int32_t *cancel,
                           volatile int64_t *progress)
{
    sim_lane_t lane;
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
        status = sim_lane_init(&job, &lane, cell);
        if (status == ICOAC_SIM_OK) {
            state = sim_lane_start(&job, &lane);
            while (state == SIM_LANE_RUNNING) {
                state = sim_lane_tick(&job, &lane);
            }
        }
        sim_fpu_restore(fpu_mode);
    }
    return state == SIM_LANE_CANCELLED ? ICOAC_SIM_CANCELLED : status;
}
