/* SPDX-License-Identifier: Apache-2.0 */
/* Frictionless cart-pole (Barto, Sutton & Anderson 1983, with g = +9.8; method.md, plant): the
 * registry's first plant, and the icoac_sim_plant_t entry points of the trial loop. */
#include <math.h>

#include "icoac_sim/icoac_sim.h"
#include "sim_integrate.h"
#include "sim_internal.h"

enum { GRAVITY, CART_MASS, POLE_MASS, HALF_LENGTH, X_LIMIT = SIM_CART_POLE_X_LIMIT, THETA_LIMIT, N_PARAMS };

/* d/dt (x, x_dot, theta, theta_dot) under force: Sutton's equations. */
static void derivatives(const double *p, const double *s, double force, double *ds)
{
    const double inv_total_mass = 1.0 / (p[CART_MASS] + p[POLE_MASS]);
    const double pole_moment = p[POLE_MASS] * p[HALF_LENGTH];
    const double sin_t = sin(s[2]);
    const double cos_t = cos(s[2]);
    const double temp = (force + pole_moment * s[3] * s[3] * sin_t) * inv_total_mass;
    const double theta_acc = (p[GRAVITY] * sin_t - cos_t * temp) /
                             (p[HALF_LENGTH] * (4.0 / 3.0 - p[POLE_MASS] * cos_t * cos_t * inv_total_mass));
    const double x_acc = temp - pole_moment * theta_acc * cos_t * inv_total_mass;
    ds[0] = s[1];
    ds[1] = x_acc;
    ds[2] = s[3];
    ds[3] = theta_acc;
}

void sim_cart_pole_step(const double *p, double dt, int32_t integrator, double *s, double force)
{
    sim_integrate(derivatives, 4, p, dt, integrator, s, force);
}

static int32_t failed(const double *p, const double *s)
{
    return sim_cart_pole_failed(p[X_LIMIT], p[THETA_LIMIT], s);
}

/* Cart plus a uniform rod of half-length l (inertia m l^2 / 3 about its centre), height 0 at
 * the pivot. */
static double energy(const double *p, const double *s)
{
    const double m = p[POLE_MASS], l = p[HALF_LENGTH];
    return 0.5 * (p[CART_MASS] + m) * s[1] * s[1] + m * l * cos(s[2]) * s[1] * s[3] +
           (2.0 / 3.0) * m * l * l * s[3] * s[3] + m * p[GRAVITY] * l * cos(s[2]);
}

static const icoac_sim_param_t params[N_PARAMS] = {
    {"gravity", "m/s^2", 9.8, ICOAC_SIM_PHYS_MIN, ICOAC_SIM_PHYS_MAX},
    {"cart_mass", "kg", 1.0, ICOAC_SIM_PHYS_MIN, ICOAC_SIM_PHYS_MAX},
    {"pole_mass", "kg", 0.1, ICOAC_SIM_PHYS_MIN, ICOAC_SIM_PHYS_MAX},
    {"half_length", "m", 0.5, ICOAC_SIM_PHYS_MIN, ICOAC_SIM_PHYS_MAX},
    {"x_limit", "m", 2.4, ICOAC_SIM_PHYS_MIN, ICOAC_SIM_PHYS_MAX},
    {"theta_limit", "rad", 12.0 * ICOAC_SIM_PI / 180.0, ICOAC_SIM_PHYS_MIN, ICOAC_SIM_THETA_LIMIT_MAX},
};

/* The paper's task: the controller's defaults. */
static const icoac_sim_task_t task = {"the C defaults (the paper's task)", 0, 0, 1, 0, 0};

const icoac_sim_plant_desc_t sim_cart_pole = {
    "cart_pole",
    "frictionless cart-pole, force on the cart",
    "Barto, Sutton & Anderson, IEEE Trans. SMC 13(5), 1983; Florian, 'Correct equations for the "
    "dynamics of the cart-pole system', 2007",
    {"force", "N"},
    4,
    N_PARAMS,
    {{"x", "m"}, {"x_dot", "m/s"}, {"theta", "rad"}, {"theta_dot", "rad/s"}},
    params,
    {2, ICOAC_SIM_GRID_THETAS, ICOAC_SIM_GRID_THETA_FIRST_DEG, 1.0, 1, 0},
    {0, ICOAC_SIM_GRID_XS, ICOAC_SIM_GRID_X_FIRST, ICOAC_SIM_GRID_X_STEP, 0, 0},
    {0.0, 0.0, 0.0, 0.0},
    {0, 1, 0, 1},
    {0, 1, 2, 3},
    sim_cart_pole_step,
    derivatives,
    failed,
    energy,
    &task,
};

/* The icoac_sim_plant_t entry points: the descriptor's defaults, ranges and step on the
 * struct's parameters. */
void icoac_sim_plant_default(icoac_sim_plant_t *plant)
{
    if (plant == 0) {
        return;
    }
    plant->gravity = params[GRAVITY].value;
    plant->cart_mass = params[CART_MASS].value;
    plant->pole_mass = params[POLE_MASS].value;
    plant->half_length = params[HALF_LENGTH].value;
    plant->dt = SIM_DT_DEFAULT;
    plant->x_limit = params[X_LIMIT].value;
    plant->theta_limit = params[THETA_LIMIT].value;
    plant->integrator = ICOAC_SIM_EULER;
    plant->reserved = 0;
}

int32_t icoac_sim_plant_check(const icoac_sim_plant_t *plant)
{
    icoac_sim_model_t model;
    if (plant == 0) {
        return ICOAC_SIM_ERR_BAD_ARGUMENT;
    }
    (void)icoac_sim_model_from_plant(plant, &model);
    return icoac_sim_model_check(&model);
}

/* The plant's model and the first 4 entries of a model state (the rest 0): the model API checks
 * the plant's parameters, dt, integrator and state as it does for every plant. */
static void as_model(const icoac_sim_plant_t *plant, const double state[4], icoac_sim_model_t *model,
                     double s[ICOAC_SIM_MAX_STATE])
{
    int i;
    (void)icoac_sim_model_from_plant(plant, model);
    for (i = 0; i < ICOAC_SIM_MAX_STATE; ++i) {
        s[i] = i < 4 ? state[i] : 0.0;
    }
}

int32_t icoac_sim_plant_step(const icoac_sim_plant_t *plant, double state[4], double force)
{
    icoac_sim_model_t model;
    double s[ICOAC_SIM_MAX_STATE];
    int32_t status;
    int i;
    if (plant == 0 || state == 0) {
        return ICOAC_SIM_ERR_BAD_ARGUMENT;
    }
    as_model(plant, state, &model, s);
    status = icoac_sim_model_step(&model, s, force);
    if (status == ICOAC_SIM_OK) {
        for (i = 0; i < 4; ++i) {
            state[i] = s[i];
        }
    }
    return status;
}

int32_t icoac_sim_failed(const icoac_sim_plant_t *plant, const double state[4])
{
    icoac_sim_model_t model;
    double s[ICOAC_SIM_MAX_STATE];
    int32_t failed = 1;
    int32_t status;
    if (plant == 0 || state == 0) {
        return ICOAC_SIM_ERR_BAD_ARGUMENT;
    }
    as_model(plant, state, &model, s);
    status = icoac_sim_model_failed(&model, s, &failed);
    return status == ICOAC_SIM_OK ? failed : status;
}

int32_t icoac_sim_model_from_plant(const icoac_sim_plant_t *plant, icoac_sim_model_t *model)
{
    int i;
    if (plant == 0 || model == 0) {
        return ICOAC_SIM_ERR_BAD_ARGUMENT;
    }
    model->plant = ICOAC_SIM_CART_POLE;
    model->integrator = plant->integrator;
    model->dt = plant->dt;
    for (i = 0; i < ICOAC_SIM_MAX_PARAMS; ++i) model->param[i] = 0.0;
    model->param[GRAVITY] = plant->gravity;
    model->param[CART_MASS] = plant->cart_mass;
    model->param[POLE_MASS] = plant->pole_mass;
    model->param[HALF_LENGTH] = plant->half_length;
    model->param[X_LIMIT] = plant->x_limit;
    model->param[THETA_LIMIT] = plant->theta_limit;
    return ICOAC_SIM_OK;
}
