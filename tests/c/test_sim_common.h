/* SPDX-License-Identifier: Apache-2.0 */
/* Helpers of the host simulator's tests (test_engine.c, test_model_runs.c). */
#ifndef TEST_SIM_COMMON_H
#define TEST_SIM_COMMON_H

#include "icoac_sim/icoac_sim.h"

/* The default run with the given caps. */
static inline icoac_sim_run_t test_small_run(int64_t max_trials, int64_t success_steps)
{
    icoac_sim_run_t r;
    icoac_sim_run_default(&r);
    r.max_trials = max_trials;
    r.success_steps = success_steps;
    return r;
}

#endif /* TEST_SIM_COMMON_H */
