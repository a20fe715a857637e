/* Defaults and checks of the plant and run parameters (ranges in icoac_sim.h). */
#include <math.h>

#include "icoac_sim/icoac_sim.h"
#include "sim_internal.h"

void icoac_sim_plant_default(icoac_sim_plant_t *plant)
{
    if (plant == 0) {
        return;
    }
    plant->gravity = 9.8;
    plant->cart_mass = 1.0;
    plant->pole_mass = 0.1;
    plant->half_length = 0.5;
    plant->dt = 0.01;
    plant->x_limit = 2.4;
    plant->theta_limit = 12.0 * ICOAC_SIM_PI / 180.0;
    plant->integrator = ICOAC_SIM_EULER;
    plant->reserved = 0;
}

/* lo <= v <= hi; false for NaN. */
static int within(double v, double lo, double hi)
{
    return v >= lo && v <= hi;
}

int32_t icoac_sim_plant_check(const icoac_sim_plant_t *plant)
{
    if (plant == 0) {
        return ICOAC_SIM_ERR_BAD_ARGUMENT;
    }
    if (!within(plant->gravity, ICOAC_SIM_PHYS_MIN, ICOAC_SIM_PHYS_MAX) ||
        !within(plant->cart_mass, ICOAC_SIM_PHYS_MIN, ICOAC_SIM_PHYS_MAX) ||
        !within(plant->pole_mass, ICOAC_SIM_PHYS_MIN, ICOAC_SIM_PHYS_MAX) ||
        !within(plant->half_length, ICOAC_SIM_PHYS_MIN, ICOAC_SIM_PHYS_MAX) ||
        !within(plant->dt, ICOAC_SIM_DT_MIN, ICOAC_SIM_DT_MAX) ||
        !within(plant->x_limit, ICOAC_SIM_PHYS_MIN, ICOAC_SIM_PHYS_MAX) ||
        !within(plant->theta_limit, ICOAC_SIM_PHYS_MIN, ICOAC_SIM_THETA_LIMIT_MAX) ||
        (plant->integrator != ICOAC_SIM_EULER && plant->integrator != ICOAC_SIM_RK4)) {
        return ICOAC_SIM_ERR_BAD_PLANT;
    }
    return ICOAC_SIM_OK;
}

void icoac_sim_run_default(icoac_sim_run_t *run)
{
    if (run == 0) {
        return;
    }
    run->max_trials = 100000;
    run->success_steps = 100000;
    run->init_velocity_noise = 1.0e-4;
}

int sim_velocity_noise_valid(double a)
{
    return a == 0.0 || (a >= ICOAC_SIM_NOISE_MIN && a <= ICOAC_SIM_NOISE_MAX);
}

int32_t icoac_sim_run_check(const icoac_sim_run_t *run)
{
    if (run == 0) {
        return ICOAC_SIM_ERR_BAD_ARGUMENT;
    }
    if (run->max_trials < 1 || run->success_steps < 1 || !sim_velocity_noise_valid(run->init_velocity_noise)) {
        return ICOAC_SIM_ERR_BAD_RUN;
    }
    return ICOAC_SIM_OK;
}

int32_t sim_check_all(const icoac_config_t *cfg, const icoac_sim_plant_t *plant,
                      const icoac_sim_run_t *run)
{
    int32_t status;
    if (cfg == 0 || plant == 0) {
        return ICOAC_SIM_ERR_BAD_ARGUMENT;
    }
    status = (int32_t)icoac_config_check(cfg);
    /* the plant is the cart-pole: the controller's task must read its four state variables */
    if (status == ICOAC_SIM_OK && cfg->task.n_inputs != ICOAC_CARTPOLE_INPUTS) {
        status = ICOAC_SIM_ERR_BAD_ARGUMENT;
    }
    if (status == ICOAC_SIM_OK) {
        status = icoac_sim_plant_check(plant);
    }
    if (status == ICOAC_SIM_OK && run != 0) {
        status = icoac_sim_run_check(run);
    }
    return status;
}
