/* SPDX-License-Identifier: Apache-2.0 */
/* Grid runner: independent cells shared out to worker threads through an atomic counter; each
 * thread advances the run's `lanes` of them in lockstep, a block (sim_internal.h). */
#include <math.h>
#include <pthread.h>
#include <unistd.h>

#include "icoac_sim/icoac_sim.h"
#include "sim_internal.h"

#define SIM_MAX_THREADS 256

typedef struct {
    sim_job_t sim;
    icoac_sim_cell_t *cells;
    int64_t n_cells;
    int64_t next_cell;       /* atomic */
    int32_t cancelled;       /* atomic */
} grid_job_t;

/* The next pending cell started on lane: SIM_LANE_RUNNING, SIM_LANE_DONE when no cell is left,
 * or SIM_LANE_CANCELLED. A cell whose controller cannot be initialised gets its status and the
 * outcome ICOAC_SIM_ERROR. */
static int take_cell(grid_job_t *job, sim_block_t *block, sim_lane_t *lane)
{
    for (;;) {
        const int64_t i = __atomic_fetch_add(&job->next_cell, 1, __ATOMIC_RELAXED);
        int32_t status;
        int state;
        if (i >= job->n_cells) {
            return SIM_LANE_DONE;
        }
        if (job->cells[i].outcome != ICOAC_SIM_PENDING) {
            continue;
        }
        status = sim_lane_init(&job->sim, lane, &job->cells[i]);
        if (status != ICOAC_SIM_OK) {
            job->cells[i].status = status;
            __atomic_store_n(&job->cells[i].outcome, ICOAC_SIM_ERROR, __ATOMIC_RELEASE);
            continue;
        }
        state = sim_lane_start(&job->sim, block, lane);
        if (state != SIM_LANE_DONE) {
            return state;
        }
    }
}

/* What a worker knows of its lanes. */
typedef struct {
    sim_block_t block;
    sim_lane_t lane[ICOAC_SIM_MAX_LANES];
    int state[ICOAC_SIM_MAX_LANES]; /* SIM_LANE_RUNNING (a cell) or SIM_LANE_RESTING (none left) */
    int active;                     /* lanes running */
} worker_lanes_t;

/* Lane l stopped running (state DONE: its cell ended, or it has none yet) or the run was
 * cancelled: the lane takes the next cell, or rests (its column zero) when none is left. 0 when
 * the thread must stop. */
static int refill(grid_job_t *job, worker_lanes_t *w, int l)
{
    int32_t i;
    int state = w->state[l];
    if (state == SIM_LANE_DONE) {
        state = take_cell(job, &w->block, &w->lane[l]);
    }
    if (state == SIM_LANE_CANCELLED) {
        __atomic_store_n(&job->cancelled, 1, __ATOMIC_RELAXED);
        return 0;
    }
    w->state[l] = state == SIM_LANE_DONE ? SIM_LANE_RESTING : state;
    if (state == SIM_LANE_DONE) {
        --w->active;
        for (i = 0; i < ICOAC_SIM_MAX_STATE; ++i) {
            w->block.s[i * w->block.lanes + l] = 0.0;
        }
        w->block.u[l] = 0.0;
    }
    return 1;
}

/* The run's `lanes` cells in lockstep, a block tick at a time (sim_block_tick); a lane whose cell
 * ended takes the next one after the tick. On a cancel the thread stops, and the cells of its
 * other lanes stay PENDING (nothing of them was written). */
static void *worker(void *arg)
{
    grid_job_t *job = (grid_job_t *)arg;
    static const worker_lanes_t empty;
    worker_lanes_t w = empty;
    int l;
    const int lanes = (int)job->sim.run->lanes; /* checked: 1 .. ICOAC_SIM_MAX_LANES */
    (void)sim_fpu_flush_subnormals();           /* a fresh thread: nothing to restore */
    sim_block_init(&w.block, lanes);
    w.active = lanes;
    for (l = 0; l < lanes; ++l) {
        w.lane[l].lane = l;
        w.state[l] = SIM_LANE_DONE;
        if (!refill(job, &w, l)) {
            return 0;
        }
    }
    while (w.active > 0) {
        if (sim_block_tick(&job->sim, &w.block, w.lane, w.state) > 0) {
            for (l = 0; l < lanes; ++l) {
                if (w.state[l] != SIM_LANE_RUNNING && w.state[l] != SIM_LANE_RESTING && !refill(job, &w, l)) {
                    return 0;
                }
            }
        }
    }
    return 0;
}

static int32_t thread_count(int32_t requested, int64_t n_cells)
{
    long n = requested > 0 ? (long)requested : sysconf(_SC_NPROCESSORS_ONLN);
    if (n < 1) {
        n = 1;
    }
    if (n > SIM_MAX_THREADS) {
        n = SIM_MAX_THREADS;
    }
    if ((int64_t)n > n_cells) {
        n = (long)n_cells;
    }
    return (int32_t)n;
}

int32_t icoac_sim_run_grid(const icoac_config_t *cfg, const icoac_sim_model_t *model,
                           const icoac_sim_run_t *run, const icoac_prior_t *prior,
                           icoac_sim_cell_t *cells, int64_t n_cells, int32_t n_threads,
                           const volatile int32_t *cancel, volatile int64_t *progress)
{
    pthread_t threads[SIM_MAX_THREADS];
    grid_job_t job;
    int32_t status = sim_check_all(cfg, model, run);
    int32_t n;
    int32_t started = 0;
    int32_t t;
    int64_t i;
    if (status != ICOAC_SIM_OK) {
        return status;
    }
    if (run == 0 || cells == 0 || n_cells < 1 || n_threads < 0) {
        return ICOAC_SIM_ERR_BAD_ARGUMENT;
    }
    for (i = 0; i < n_cells; ++i) {
        if (!isfinite(cells[i].x0) || !isfinite(cells[i].theta0)) {
            return ICOAC_SIM_ERR_BAD_ARGUMENT;
        }
    }
    if (prior != 0) {
        /* Validate the prior once, before any cell runs. */
        icoac_state_t probe;
        status = (int32_t)icoac_init(cfg, &probe, prior, 0u);
        if (status != ICOAC_SIM_OK) {
            return status;
        }
    }
    job.sim.cfg = cfg;
    job.sim.model = model;
    job.sim.desc = icoac_sim_plant_info(model->plant);
    job.sim.run = run;
    job.sim.prior = prior;
    job.sim.cancel = cancel;
    job.sim.progress = progress;
    job.cells = cells;
    job.n_cells = n_cells;
    job.next_cell = 0;
    job.cancelled = 0;
    n = thread_count(n_threads, n_cells);
    for (t = 0; t < n; ++t) {
        if (pthread_create(&threads[t], 0, worker, &job) != 0) {
            break;
        }
        ++started;
    }
    if (started == 0) {
        return ICOAC_SIM_ERR_THREAD;
    }
    for (t = 0; t < started; ++t) {
        (void)pthread_join(threads[t], 0);
    }
    return job.cancelled ? ICOAC_SIM_CANCELLED : ICOAC_SIM_OK;
}
