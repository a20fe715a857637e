/* SPDX-License-Identifier: Apache-2.0 */
/* Helpers of the host simulator's tests (test_plant.c, test_engine.c, test_model_runs.c, ...). */
#ifndef TEST_SIM_COMMON_H
#define TEST_SIM_COMMON_H

#include <string.h>

#include "icoac_sim/icoac_sim.h"

/* The paper's grid, the cart-pole's: 25 angles x 49 positions. */
#define TEST_PAPER_CELLS 1225

/* The cart-pole with its default parameters, dt 0.01 s and Euler. */
static inline icoac_sim_model_t test_cart_pole(void)
{
    icoac_sim_model_t m;
    (void)icoac_sim_model_default(&m, ICOAC_SIM_CART_POLE);
    return m;
}

/* The cart-pole's 4 state components through the model API (whose states hold
 * ICOAC_SIM_MAX_STATE values): one step of s (left as it was on an error), and the failure test
 * (1 or 0, or the status of a refused model). */
static inline int32_t test_cart_pole_step(const icoac_sim_model_t *m, double s[4], double force)
{
    double full[ICOAC_SIM_MAX_STATE] = {0};
    int32_t status;
    memcpy(full, s, 4 * sizeof s[0]);
    status = icoac_sim_model_step(m, full, force);
    memcpy(s, full, 4 * sizeof s[0]);
    return status;
}

static inline int32_t test_cart_pole_failed(const icoac_sim_model_t *m, const double s[4])
{
    double full[ICOAC_SIM_MAX_STATE] = {0};
    int32_t failed = -1;
    int32_t status;
    memcpy(full, s, 4 * sizeof s[0]);
    status = icoac_sim_model_failed(m, full, &failed);
    return status == ICOAC_SIM_OK ? failed : status;
}

/* Index of plant's parameter name in its model's param[], -1 when it has none. */
static inline int test_param(int32_t plant, const char *name)
{
    const icoac_sim_plant_desc_t *d = icoac_sim_plant_info(plant);
    int i;
    for (i = 0; d != 0 && i < d->n_params; ++i) {
        if (strcmp(d->params[i].name, name) == 0) {
            return i;
        }
    }
    return -1;
}

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
