/* The benchmark trial loop of one cell (spec 8-9): trials from a fresh controller until one
 * lasts success_steps or max_trials have failed. */
#include <float.h>
#include <math.h>
#include <string.h>

#include "icoac_sim/icoac_sim.h"
#include "sim_internal.h"

#if defined(ICOAC_REAL_DOUBLE) && ICOAC_REAL_DOUBLE
#define SIM_REAL_MAX DBL_MAX
#else
#define SIM_REAL_MAX ((double)FLT_MAX)
#endif

/* Uniform in (-a, a) from the plant's own generator, in double. */
static double uniform_symmetric(icoac_rng_t *rng, double a)
{
    const double u = (double)icoac_rng_next_u32(rng) * (1.0 / 4294967296.0);
    return a * (2.0 * u - 1.0);
}

void sim_start_trial(const icoac_sim_cell_t *cell, double noise, icoac_rng_t *rng, double s[4])
{
    s[0] = cell->x0;
    s[1] = uniform_symmetric(rng, noise);
    s[2] = cell->theta0;
    s[3] = uniform_symmetric(rng, noise);
}

/* The plant state as the controller's reals. A value outside the real type's range would be
 * an undefined conversion: it is passed as NaN, which the controller rejects. */
void sim_to_input(const double s[4], uint32_t flags, icoac_input_t *in)
{
    int i;
    for (i = 0; i < ICOAC_N_INPUTS; ++i) {
        in->s[i] = fabs(s[i]) <= SIM_REAL_MAX ? (icoac_real_t)s[i] : (icoac_real_t)NAN;
    }
    in->flags = flags;
}

static void store_posterior(const icoac_state_t *ctrl, icoac_sim_cell_t *cell)
{
    icoac_prior_t post;
    int i, j;
    (void)icoac_get_posterior(ctrl, &post);
    for (i = 0; i < ICOAC_N_INPUTS; ++i) {
        cell->weights[i] = (double)post.mean[i];
        for (j = 0; j < ICOAC_N_INPUTS; ++j) {
            cell->cov[i][j] = (double)post.cov[i][j];
        }
    }
}

/* One trial; returns the steps run, or -1 on a controller error. *balanced is 1 when the trial
 * lasted success_steps steps without failing (a failure at the last step is a failure). */
static int64_t run_trial(const icoac_config_t *cfg, const icoac_sim_plant_t *plant,
                         const icoac_sim_run_t *run, icoac_state_t *ctrl, const icoac_sim_cell_t *cell,
                         icoac_rng_t *rng, int32_t *status, int *balanced)
{
    double s[4];
    icoac_input_t in;
    icoac_output_t out;
    int64_t steps = 0;
    *balanced = 0;
    sim_start_trial(cell, run->init_velocity_noise, rng, s);
    *status = (int32_t)icoac_reset(cfg, ctrl);
    while (*status == ICOAC_SIM_OK && steps < run->success_steps) {
        sim_to_input(s, 0u, &in);
        *status = (int32_t)icoac_step(cfg, ctrl, &in, &out);
        if (*status != ICOAC_SIM_OK) {
            break;
        }
        icoac_sim_plant_step(plant, s, (double)out.force);
        ++steps;
        if (sim_failed(plant, s)) {
            /* Let the controller learn from the failure state; it rejects NaN plant states,
             * which end the trial like any failure, but a numeric fault is an error. */
            sim_to_input(s, ICOAC_INPUT_TERMINAL, &in);
            if (icoac_step(cfg, ctrl, &in, &out) == ICOAC_ERR_NUMERIC) {
                *status = ICOAC_ERR_NUMERIC;
                return -1;
            }
            return steps;
        }
    }
    if (*status != ICOAC_SIM_OK) {
        return -1;
    }
    *balanced = 1;
    return steps;
}

static int cancelled(const volatile int32_t *cancel)
{
    return cancel != 0 && __atomic_load_n(cancel, __ATOMIC_RELAXED) != 0;
}

static void add_progress(volatile int64_t *progress, int index, int64_t amount)
{
    if (progress != 0) {
        (void)__atomic_fetch_add(&progress[index], amount, __ATOMIC_RELAXED);
    }
}

int32_t sim_run_cell_checked(const icoac_config_t *cfg, const icoac_sim_plant_t *plant,
                             const icoac_sim_run_t *run, const icoac_prior_t *prior,
                             icoac_sim_cell_t *cell, const volatile int32_t *cancel,
                             volatile int64_t *progress)
{
    icoac_state_t ctrl;
    icoac_rng_t rng;
    int32_t status;
    int64_t trials = 0;
    int64_t total = 0;
    int64_t steps = 0;
    int balanced = 0;

    status = (int32_t)icoac_init(cfg, &ctrl, prior, icoac_mix_seed(cell->seed, 1u));
    if (status != ICOAC_SIM_OK) {
        return status;
    }
    icoac_rng_seed(&rng, cell->seed, 2u);
    while (trials < run->max_trials) {
        if (cancelled(cancel)) {
            return ICOAC_SIM_CANCELLED;
        }
        steps = run_trial(cfg, plant, run, &ctrl, cell, &rng, &status, &balanced);
        if (steps < 0) {
            break;
        }
        ++trials;
        total += steps;
        add_progress(progress, ICOAC_SIM_PROGRESS_TRIALS, 1);
        add_progress(progress, ICOAC_SIM_PROGRESS_STEPS, steps);
        if (balanced) {
            break;
        }
    }
    cell->trials = trials;
    cell->total_steps = total;
    cell->last_trial_steps = steps < 0 ? 0 : steps;
    cell->elapsed_time = plant->dt * (double)total;
    store_posterior(&ctrl, cell);
    cell->status = status;
    /* Outcome last, with release order: a reader that sees it non-PENDING sees the rest. */
    __atomic_store_n(&cell->outcome,
                     steps < 0 ? ICOAC_SIM_ERROR : (balanced ? ICOAC_SIM_SUCCESS : ICOAC_SIM_FAILED),
                     __ATOMIC_RELEASE);
    add_progress(progress, ICOAC_SIM_PROGRESS_CELLS, 1);
    return ICOAC_SIM_OK;
}

int32_t icoac_sim_run_cell(const icoac_config_t *cfg, const icoac_sim_plant_t *plant,
                           const icoac_sim_run_t *run, const icoac_prior_t *prior,
                           icoac_sim_cell_t *cell, const volatile int32_t *cancel,
                           volatile int64_t *progress)
{
    uint32_t fpu_mode;
    int32_t status = sim_check_all(cfg, plant, run);
    if (status != ICOAC_SIM_OK) {
        return status;
    }
    if (run == 0 || cell == 0 || !isfinite(cell->x0) || !isfinite(cell->theta0)) {
        return ICOAC_SIM_ERR_BAD_ARGUMENT;
    }
    fpu_mode = sim_fpu_flush_subnormals();
    status = sim_run_cell_checked(cfg, plant, run, prior, cell, cancel, progress);
    sim_fpu_restore(fpu_mode);
    return status;
}
