/* SPDX-License-Identifier: Apache-2.0 */
/* Private helpers shared by the sim_host sources. */
#ifndef SIM_INTERNAL_H
#define SIM_INTERNAL_H

#include <float.h>
#include <math.h>

#include "icoac_sim/icoac_sim.h"

/* Time step of every default plant and model (s). */
#define SIM_DT_DEFAULT 0.01

/* The cart-pole's step (plants/cart_pole.c), which the trial loop calls without going through
 * the descriptor. */
void sim_cart_pole_step(const double *p, double dt, int32_t integrator, double *s, const double *forces,
                        int32_t lanes);

/* Check the controller configuration, model and (if not NULL) run parameters, and that the
 * controller build takes the plant's observation (params.c). */
int32_t sim_check_all(const icoac_config_t *cfg, const icoac_sim_model_t *model,
                      const icoac_sim_run_t *run);

/* Initial velocity noise a: 0, or in [ICOAC_SIM_NOISE_MIN, ICOAC_SIM_NOISE_MAX] (params.c). */
int sim_velocity_noise_valid(double a);
/* 1 when v is 0 or a normal number in [range->min, range->max] (a plant parameter or task knob). */
int sim_param_valid(double v, const icoac_sim_param_t *range);

/* Uniform in (-a, a) from the plant's own generator, in double. */
static inline double sim_uniform_symmetric(icoac_rng_t *rng, double a)
{
    const double u = (double)icoac_rng_next_u32(rng) * (1.0 / 4294967296.0);
    return a * (2.0 * u - 1.0);
}

/* Start state of a trial of a checked model from cell: the plant's start values, the swept
 * components from the cell, the drawn ones U(-noise, noise) in index order (model.c). */
void sim_start_trial(const icoac_sim_plant_desc_t *desc, const icoac_sim_cell_t *cell, double noise,
                     icoac_rng_t *rng, double s[ICOAC_SIM_MAX_STATE]);

/* The plant state as the controller's input; values outside its real range become NaN. The
 * plant's observation is its first n components, n = task.n_inputs (sim_check_all). */
void sim_to_input(const double *s, int32_t n, uint32_t flags, icoac_input_t *in);

/* What every cell of a run shares: the checked model and its descriptor. */
typedef struct {
    const icoac_config_t *cfg;
    const icoac_sim_model_t *model;
    const icoac_sim_plant_desc_t *desc;
    const icoac_sim_run_t *run;
    const icoac_prior_t *prior;
    const volatile int32_t *cancel;
    volatile int64_t *progress;
} sim_job_t;

/* The cells a worker thread advances in lockstep, one lane each: their plant states as a
 * structure of arrays (component i of lane l at s[i * lanes + l], the layout of the plant's batch
 * step), the plant inputs of the tick, and what the controllers see of the states. Each tick every
 * lane's controller acts, then one plant step advances all lanes and tests them all, then each
 * lane sees its new state: the lanes' dependency chains (controller -> input -> plant -> next
 * observation) overlap, and no cell's result depends on the others. */
typedef struct {
    int32_t lanes; /* <= ICOAC_SIM_MAX_LANES */
    double s[ICOAC_SIM_MAX_STATE * ICOAC_SIM_MAX_LANES];
    double u[ICOAC_SIM_MAX_LANES];
    icoac_real_t in[ICOAC_MAX_INPUTS * ICOAC_SIM_MAX_LANES]; /* the controllers' inputs, laid out as s (sim_real) */
    int32_t failed[ICOAC_SIM_MAX_LANES];                     /* the plant's failure test of each lane's state */
    icoac_batch_t batch;                                     /* the controllers' ticks (icoac_step_batch) */
    icoac_state_t *ctrl[ICOAC_SIM_MAX_LANES];                /* the running lanes' controllers, NULL for the others */
    icoac_real_t force[ICOAC_SIM_MAX_LANES];
    int32_t status[ICOAC_SIM_MAX_LANES];
} sim_block_t;
ICOAC_STATIC_ASSERT(ICOAC_SIM_MAX_LANES <= ICOAC_BATCH_MAX_LANES, a_block_is_one_batch);

/* A cell in progress on lane `lane` of a block (trial.c): its controller and counters. */
typedef struct {
    icoac_state_t ctrl;
    icoac_rng_t rng; /* the plant's: the drawn start components */
    icoac_sim_cell_t *cell;
    int64_t trials; /* finished trials */
    int64_t total;  /* their steps */
    int64_t steps;  /* steps of the trial in progress */
    int64_t reported_trials; /* of trials and total, what the progress counters have */
    int64_t reported_steps;
    int32_t status;
    int32_t lane;   /* its column in the block */
} sim_lane_t;

/* The lane functions' results: the lane runs on, its cell was written (outcome last, with
 * release order), or the run was cancelled at the start of a trial (the cell left as it was). */
#define SIM_LANE_RUNNING 0
#define SIM_LANE_DONE 1
#define SIM_LANE_CANCELLED 2
#define SIM_LANE_RESTING 3 /* a worker's lane without a cell (none is left) */

/* An empty block of `lanes` lanes (1 .. ICOAC_SIM_MAX_LANES). */
void sim_block_init(sim_block_t *block, int32_t lanes);

/* A fresh controller for cell on lane; returns the status of icoac_init (the lane is unusable
 * unless ICOAC_SIM_OK, and the cell untouched). */
int32_t sim_lane_init(const sim_job_t *job, sim_lane_t *lane, icoac_sim_cell_t *cell);
/* The first trial of an initialised lane (its start state written to the block): SIM_LANE_*. */
int sim_lane_start(const sim_job_t *job, sim_block_t *block, sim_lane_t *lane);
/* One tick of the block: every lane whose state[l] is SIM_LANE_RUNNING acts (its controller
 * steps), one plant step advances all lanes, and each lane that acted observes its new state (a
 * failure or the success length ends its trial; the next trial starts, or its cell's result is
 * written). state[l] becomes the lane's SIM_LANE_*; lanes[l] is the lane of column l. Returns how
 * many lanes stopped running this tick (their cells ended, or the run was cancelled). */
int sim_block_tick(const sim_job_t *job, sim_block_t *block, sim_lane_t *lanes, int *state);

/* Flush subnormals to zero on this thread; returns the previous mode for sim_fpu_restore (fpu.c). */
uint32_t sim_fpu_flush_subnormals(void);
void sim_fpu_restore(uint32_t mode);

#endif /* SIM_INTERNAL_H */
