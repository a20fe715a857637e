/* SPDX-License-Identifier: Apache-2.0 */
/* The Fig. 1g trajectory recorder: one trial with learning on, every tick stored. */
#include <math.h>
#include <string.h>

#include "icoac_sim/icoac_sim.h"
#include "sim_internal.h"

int32_t icoac_sim_trajectory(const icoac_config_t *cfg, const icoac_sim_model_t *model,
                             const icoac_prior_t *prior, double x0, double theta0,
                             double init_velocity_noise, uint64_t seed, int64_t max_steps,
                             double *states, double *forces, int64_t *n_steps)
{
    const icoac_sim_plant_desc_t *desc;
    icoac_state_t ctrl;
    icoac_rng_t rng;
    icoac_sim_cell_t cell;
    icoac_input_t in;
    icoac_output_t out;
    double s[ICOAC_SIM_MAX_STATE];
    size_t row;
    int64_t k;
    int32_t failed = 0;
    uint32_t fpu_mode;
    int32_t status = sim_check_all(cfg, model, 0);
    if (status != ICOAC_SIM_OK) {
        return status;
    }
    if (states == 0 || forces == 0 || n_steps == 0 || max_steps < 1 || !isfinite(x0) ||
        !isfinite(theta0) || !sim_velocity_noise_valid(init_velocity_noise)) {
        return ICOAC_SIM_ERR_BAD_ARGUMENT;
    }
    status = (int32_t)icoac_init(cfg, &ctrl, prior, icoac_mix_seed(seed, 1u));
    if (status != ICOAC_SIM_OK) {
        return status;
    }
    desc = icoac_sim_plant_info(model->plant);
    row = (size_t)desc->n_state;
    fpu_mode = sim_fpu_flush_subnormals();
    memset(&cell, 0, sizeof cell);
    cell.x0 = x0;
    cell.theta0 = theta0;
    icoac_rng_seed(&rng, seed, ICOAC_SIM_START_STREAM);
    sim_start_trial(desc, &cell, init_velocity_noise, &rng, s);
    memcpy(states, s, row * sizeof s[0]);
    *n_steps = 0;
    for (k = 0; k < max_steps; ++k) {
        sim_to_input(s, cfg->task.n_inputs, 0u, &in);
        status = (int32_t)icoac_step(&ctrl, &in, &out);
        if (status != ICOAC_SIM_OK) {
            break;
        }
        forces[k] = (double)out.force;
        desc->step(model->param, model->dt, model->integrator, s, &forces[k], 1);
        memcpy(states + row * (size_t)(k + 1), s, row * sizeof s[0]);
        *n_steps = k + 1;
        desc->failed(model->param, s, 1, &failed);
        if (failed != 0) {
            break;
        }
    }
    sim_fpu_restore(fpu_mode);
    return status;
}
