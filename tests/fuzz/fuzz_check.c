/* SPDX-License-Identifier: Apache-2.0 */
/* Failure report of FZ_CHECK, and the checks' shared helpers. */
#include "fuzz_check.h"

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

void fz_fail(const char *file, int line, const char *cond, const char *fmt, ...)
{
    va_list args;
    fprintf(stderr, "\n==== icoac fuzz: CONTRACT VIOLATION at %s:%d\n==== check: %s\n==== ", file, line, cond);
    va_start(args, fmt);
    vfprintf(stderr, fmt, args);
    va_end(args);
    fprintf(stderr, "\n");
    fflush(stderr);
    abort();
}

int fz_all_finite(const icoac_real_t *p, int n)
{
    int i;
    for (i = 0; i < n; ++i) {
        if (!isfinite(p[i])) {
            return 0;
        }
    }
    return 1;
}

int fz_all_finite_double(const double *p, int n)
{
    int i;
    for (i = 0; i < n; ++i) {
        if (!isfinite(p[i])) {
            return 0;
        }
    }
    return 1;
}

#if defined(ICOAC_FUZZ_SIM) && ICOAC_FUZZ_SIM
int fz_sim_status_known(int32_t status)
{
    return strcmp(icoac_sim_status_str(status), "unknown status") != 0;
}

static int run_documented(const icoac_sim_run_t *run)
{
    return run->max_trials >= 1 && run->success_steps >= 1 && isfinite(run->init_velocity_noise) &&
           run->init_velocity_noise >= 0.0;
}

int32_t fz_run_clamp(icoac_sim_run_t *run)
{
    const int32_t status = icoac_sim_run_check(run);
    int32_t clamped_status;
    FZ_CHECK(status == ICOAC_SIM_OK || status == ICOAC_SIM_ERR_BAD_RUN, "run_check returned %d", (int)status);
    FZ_CHECK(status != ICOAC_SIM_OK || run_documented(run), "run_check accepted trials %lld steps %lld noise %g",
             (long long)run->max_trials, (long long)run->success_steps, run->init_velocity_noise);
    if (run->max_trials > FZ_SIM_MAX_TRIALS) {
        run->max_trials = FZ_SIM_MAX_TRIALS;
    }
    if (run->success_steps > FZ_SIM_SUCCESS_STEPS) {
        run->success_steps = FZ_SIM_SUCCESS_STEPS;
    }
    clamped_status = icoac_sim_run_check(run);
    FZ_CHECK(clamped_status == status, "run_check: %d before clamping max_trials / success_steps, %d after",
             (int)status, (int)clamped_status);
    return status;
}

int fz_charge(int64_t *budget, const icoac_sim_run_t *run, int64_t n_cells)
{
    const int64_t trials = run->max_trials > 0 ? run->max_trials : 1;
    const int64_t steps = run->success_steps > 0 ? run->success_steps : 1;
    const int64_t cost = n_cells * trials * steps;
    if (cost > *budget) {
        return 0;
    }
    *budget -= cost;
    return 1;
}

static int finite_cell_posterior(const icoac_sim_cell_t *cell)
{
    return fz_all_finite_double(cell->weights, ICOAC_MAX_INPUTS) &&
           fz_all_finite_double(&cell->cov[0][0], ICOAC_MAX_INPUTS * ICOAC_MAX_INPUTS);
}

void fz_check_finished_cell(const icoac_sim_run_t *run, double dt, const icoac_sim_cell_t *cell, const char *what)
{
    const int32_t outcome = cell->outcome;
    FZ_CHECK(outcome == ICOAC_SIM_SUCCESS || outcome == ICOAC_SIM_FAILED || outcome == ICOAC_SIM_ERROR,
             "%s: outcome %d after the run", what, (int)outcome);
    FZ_CHECK(fz_sim_status_known(cell->status), "%s: unknown cell status %d", what, (int)cell->status);
    FZ_CHECK(cell->trials >= 0 && cell->trials <= run->max_trials && cell->last_trial_steps >= 0 &&
                 cell->last_trial_steps <= run->success_steps && cell->total_steps >= cell->last_trial_steps &&
                 cell->total_steps <= cell->trials * run->success_steps,
             "%s: counts trials %lld total %lld last %lld (max_trials %lld, success_steps %lld)", what,
             (long long)cell->trials, (long long)cell->total_steps, (long long)cell->last_trial_steps,
             (long long)run->max_trials, (long long)run->success_steps);
    FZ_CHECK(cell->elapsed_time == dt * (double)cell->total_steps, "%s: elapsed_time %g, dt * total_steps %g", what,
             cell->elapsed_time, dt * (double)cell->total_steps);
    if (outcome == ICOAC_SIM_ERROR) {
        FZ_CHECK(cell->status != ICOAC_SIM_OK, "%s: ERROR cell with status OK", what);
        return;
    }
    FZ_CHECK(cell->status == ICOAC_SIM_OK, "%s: outcome %d with status %d (%s)", what, (int)outcome,
             (int)cell->status, icoac_sim_status_str(cell->status));
    FZ_CHECK(finite_cell_posterior(cell), "%s: outcome %d with non-finite weights (%g %g %g %g) or cov", what,
             (int)outcome, cell->weights[0], cell->weights[1], cell->weights[2], cell->weights[3]);
    if (outcome == ICOAC_SIM_SUCCESS) {
        FZ_CHECK(cell->trials >= 1 && cell->last_trial_steps == run->success_steps,
                 "%s: SUCCESS after %lld trials, last %lld steps", what, (long long)cell->trials,
                 (long long)cell->last_trial_steps);
    } else {
        /* a trial that fails at its last step is a failure: last_trial_steps may equal the cap */
        FZ_CHECK(cell->trials == run->max_trials && cell->last_trial_steps >= 1 &&
                     cell->last_trial_steps <= run->success_steps,
                 "%s: FAILED after %lld trials, last %lld steps", what, (long long)cell->trials,
                 (long long)cell->last_trial_steps);
    }
}
#endif
