/* Frictionless cart-pole (method.md, plant): Sutton's equations, explicit Euler or RK4. */
#include <math.h>

#include "icoac_sim/icoac_sim.h"
#include "sim_internal.h"

/* d/dt (x, x_dot, theta, theta_dot) under force. */
static inline void derivatives(const icoac_sim_plant_t *p, const double s[4], double force, double ds[4])
{
    const double inv_total_mass = 1.0 / (p->cart_mass + p->pole_mass);
    const double pole_moment = p->pole_mass * p->half_length;
    const double sin_t = sin(s[2]);
    const double cos_t = cos(s[2]);
    const double temp = (force + pole_moment * s[3] * s[3] * sin_t) * inv_total_mass;
    const double theta_acc = (p->gravity * sin_t - cos_t * temp) /
                             (p->half_length * (4.0 / 3.0 - p->pole_mass * cos_t * cos_t * inv_total_mass));
    const double x_acc = temp - pole_moment * theta_acc * cos_t * inv_total_mass;
    ds[0] = s[1];
    ds[1] = x_acc;
    ds[2] = s[3];
    ds[3] = theta_acc;
}

static void rk4_step(const icoac_sim_plant_t *p, double s[4], double force)
{
    double k1[4], k2[4], k3[4], k4[4], tmp[4];
    const double dt = p->dt;
    int i;
    derivatives(p, s, force, k1);
    for (i = 0; i < 4; ++i) tmp[i] = s[i] + 0.5 * dt * k1[i];
    derivatives(p, tmp, force, k2);
    for (i = 0; i < 4; ++i) tmp[i] = s[i] + 0.5 * dt * k2[i];
    derivatives(p, tmp, force, k3);
    for (i = 0; i < 4; ++i) tmp[i] = s[i] + dt * k3[i];
    derivatives(p, tmp, force, k4);
    for (i = 0; i < 4; ++i) s[i] += dt / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]);
}

int32_t icoac_sim_plant_step(const icoac_sim_plant_t *plant, double state[4], double force)
{
    double ds[4];
    int i;
    if (plant == 0 || state == 0) {
        return ICOAC_SIM_ERR_BAD_ARGUMENT;
    }
    if (plant->integrator == ICOAC_SIM_RK4) {
        rk4_step(plant, state, force);
        return ICOAC_SIM_OK;
    }
    /* Explicit Euler: every right-hand side uses the old state (Sutton order). */
    derivatives(plant, state, force, ds);
    for (i = 0; i < 4; ++i) {
        state[i] += plant->dt * ds[i];
    }
    return ICOAC_SIM_OK;
}

int32_t icoac_sim_failed(const icoac_sim_plant_t *plant, const double s[4])
{
    return sim_failed(plant, s);
}
