/* Grid runner: independent cells shared out to worker threads through an atomic counter. */
#include <math.h>
#include <pthread.h>
#include <unistd.h>

#include "icoac_sim/icoac_sim.h"
#include "sim_internal.h"

#define SIM_MAX_THREADS 256

typedef struct {
    const icoac_config_t *cfg;
    const icoac_sim_plant_t *plant;
    const icoac_sim_run_t *run;
    const icoac_prior_t *prior;
    icoac_sim_cell_t *cells;
    int64_t n_cells;
    const volatile int32_t *cancel;
    volatile int64_t *progress;
    int64_t next_cell;       /* atomic */
    int32_t cancelled;       /* atomic */
} grid_job_t;

static void *worker(void *arg)
{
    grid_job_t *job = (grid_job_t *)arg;
    (void)sim_fpu_flush_subnormals(); /* a fresh thread: nothing to restore */
    for (;;) {
        const int64_t i = __atomic_fetch_add(&job->next_cell, 1, __ATOMIC_RELAXED);
        int32_t status;
        if (i >= job->n_cells) {
            break;
        }
        if (job->cells[i].outcome != ICOAC_SIM_PENDING) {
            continue;
        }
        status = sim_run_cell_checked(job->cfg, job->plant, job->run, job->prior, &job->cells[i],
                                      job->cancel, job->progress);
        if (status == ICOAC_SIM_CANCELLED) {
            __atomic_store_n(&job->cancelled, 1, __ATOMIC_RELAXED);
            break;
        }
        if (status != ICOAC_SIM_OK) {
            job->cells[i].status = status;
            __atomic_store_n(&job->cells[i].outcome, ICOAC_SIM_ERROR, __ATOMIC_RELEASE);
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

int32_t icoac_sim_run_grid(const icoac_config_t *cfg, const icoac_sim_plant_t *plant,
                           const icoac_sim_run_t *run, const icoac_prior_t *prior,
                           icoac_sim_cell_t *cells, int64_t n_cells, int32_t n_threads,
                           const volatile int32_t *cancel, volatile int64_t *progress)
{
    pthread_t threads[SIM_MAX_THREADS];
    grid_job_t job;
    int32_t status = sim_check_all(cfg, plant, run);
    int32_t n;
    int32_t started = 0;
    int32_t t;
    int64_t i;
    if (status != ICOAC_SIM_OK) {
        return status;
    }
    if (cells == 0 || n_cells < 1 || n_threads < 0) {
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
    job.cfg = cfg;
    job.plant = plant;
    job.run = run;
    job.prior = prior;
    job.cells = cells;
    job.n_cells = n_cells;
    job.cancel = cancel;
    job.progress = progress;
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
