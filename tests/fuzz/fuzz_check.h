/* SPDX-License-Identifier: Apache-2.0 */
/* Contract checks of the fuzz targets: a violated check prints what failed and aborts, so
 * libFuzzer reports it like a crash and saves the input. */
#ifndef ICOAC_FUZZ_CHECK_H
#define ICOAC_FUZZ_CHECK_H

#include "icoac/icoac_types.h"

/* FZ_CHECK(condition, printf format, arguments...): abort with a message unless condition. */
#define FZ_CHECK(cond, ...)                                    \
    do {                                                       \
        if (!(cond)) {                                         \
            fz_fail(__FILE__, __LINE__, #cond, __VA_ARGS__);   \
        }                                                      \
    } while (0)

#if defined(__GNUC__)
#define FZ_NORETURN __attribute__((noreturn, format(printf, 4, 5)))
#else
#define FZ_NORETURN
#endif

void fz_fail(const char *file, int line, const char *cond, const char *fmt, ...) FZ_NORETURN;

/* 1 when the n reals (doubles) at p are all finite. */
int fz_all_finite(const icoac_real_t *p, int n);
int fz_all_finite_double(const double *p, int n);

#if defined(ICOAC_FUZZ_SIM) && ICOAC_FUZZ_SIM
#include "icoac_sim/icoac_sim.h"

/* Runs of the sim targets are kept small: at most this many trials of this many steps, and
 * this many controller ticks in cells and grids per input. */
#define FZ_SIM_MAX_TRIALS 3
#define FZ_SIM_SUCCESS_STEPS 300
#define FZ_SIM_TICK_BUDGET 3600

/* icoac_sim_status_str knows the status. */
int fz_sim_status_known(int32_t status);
/* The run check's verdict on run as decoded (OK or BAD_RUN, OK only for documented runs); then
 * max_trials clamped to FZ_SIM_MAX_TRIALS, success_steps to FZ_SIM_SUCCESS_STEPS, and the check
 * must agree. Returns the verdict. */
int32_t fz_run_clamp(icoac_sim_run_t *run);
/* Charge *budget for n_cells cells of run; 0 when it is spent (the op is then skipped). */
int fz_charge(int64_t *budget, const icoac_sim_run_t *run, int64_t n_cells);
/* A cell after a run that returned OK, with run's limits and time step dt: SUCCESS, FAILED or
 * ERROR with counts that fit it, elapsed_time == dt * total_steps, and unless ERROR status OK
 * and finite weights and cov. */
void fz_check_finished_cell(const icoac_sim_run_t *run, double dt, const icoac_sim_cell_t *cell, const char *what);
#endif

#endif /* ICOAC_FUZZ_CHECK_H */
