/* SPDX-License-Identifier: Apache-2.0 */
/* Defaults and checks of the run parameters (their rows: ICOAC_SIM_RUN_PARAMS in icoac_sim.h);
 * the cart-pole's own are in plants/cart_pole.c. */
#include <math.h>

#include "icoac_sim/icoac_sim.h"
#include "sim_internal.h"

#define RUN_DEFAULT(group, field, type, dim, check, unit, min, max, def, modes, tier, status, doc) run->field = (def);

void icoac_sim_run_default(icoac_sim_run_t *run)
{
    if (run == 0) {
        return;
    }
    ICOAC_SIM_RUN_PARAMS(RUN_DEFAULT)
}

/* A run row's check (the kinds of icoac_params.h that run rows use). */
#define RUN_OK_at_least(v, lo, hi) ((v) >= (lo))
#define RUN_OK_int(v, lo, hi) ((v) >= (lo) && (v) <= (hi))
#define RUN_OK_real_or_zero(v, lo, hi) ((v) == 0.0 || ((v) >= (lo) && (v) <= (hi)))

int sim_velocity_noise_valid(double a)
{
    return RUN_OK_real_or_zero(a, ICOAC_SIM_NOISE_MIN, ICOAC_SIM_NOISE_MAX);
}

#define RUN_CHECK(group, field, type, dim, check, unit, min, max, def, modes, tier, status, doc) \
    if (!RUN_OK_##check(run->field, min, max)) {                                              \
        return status;                                                                        \
    }

int32_t icoac_sim_run_check(const icoac_sim_run_t *run)
{
    if (run == 0) {
        return ICOAC_SIM_ERR_BAD_ARGUMENT;
    }
    ICOAC_SIM_RUN_PARAMS(RUN_CHECK)
    return ICOAC_SIM_OK;
}

/* The engine hands the controller the plant's whole state, one input per component: the task
 * must take n_state inputs, and the plant must observe every component in order. */
static int observation_fits(const icoac_sim_plant_desc_t *desc, int32_t n_inputs)
{
    int32_t i;
    if (desc->n_state != n_inputs) {
        return 0;
    }
    for (i = 0; i < n_inputs; ++i) {
        if (desc->observed[i] != i) {
            return 0;
        }
    }
    return 1;
}

int32_t sim_check_all(const icoac_config_t *cfg, const icoac_sim_model_t *model,
                      const icoac_sim_run_t *run)
{
    int32_t status;
    if (cfg == 0 || model == 0) {
        return ICOAC_SIM_ERR_BAD_ARGUMENT;
    }
    status = (int32_t)icoac_config_check(cfg);
    if (status == ICOAC_SIM_OK) {
        status = icoac_sim_model_check(model);
    }
    if (status == ICOAC_SIM_OK && !observation_fits(icoac_sim_plant_info(model->plant), cfg->task.n_inputs)) {
        status = ICOAC_SIM_ERR_BAD_PLANT;
    }
    if (status == ICOAC_SIM_OK && run != 0) {
        status = icoac_sim_run_check(run);
    }
    return status;
}

