/* SPDX-License-Identifier: Apache-2.0 */
/* Frictionless cart-pole (Barto, Sutton & Anderson 1983, with g = +9.8; method.md, plant): the
 * registry's first plant, the paper's. */
#include <float.h>
#include <math.h>

#include "icoac_sim/icoac_sim.h"
#include "sim_integrate.h"
#include "sim_trig.h"
#include "sim_internal.h"

enum { GRAVITY, CART_MASS, POLE_MASS, HALF_LENGTH, X_LIMIT, THETA_LIMIT, MAX_FORCE, N_PARAMS };

/* d/dt (x, x_dot, theta, theta_dot) under force (saturated at max_force): Sutton's equations. */
SIM_DERIVATIVES derivatives(const double *p, const double *s, double command, double *ds)
{
    const double force = sim_saturate(command, p[MAX_FORCE]);
    const double inv_total_mass = 1.0 / (p[CART_MASS] + p[POLE_MASS]);
    const double pole_moment = p[POLE_MASS] * p[HALF_LENGTH];
    double sin_t, cos_t;
    sim_sincos(s[2], &sin_t, &cos_t);
    const double temp = (force + pole_moment * s[3] * s[3] * sin_t) * inv_total_mass;
    const double theta_acc = (p[GRAVITY] * sin_t - cos_t * temp) /
                             (p[HALF_LENGTH] * (4.0 / 3.0 - p[POLE_MASS] * cos_t * cos_t * inv_total_mass));
    const double x_acc = temp - pole_moment * theta_acc * cos_t * inv_total_mass;
    ds[0] = s[1];
    ds[1] = x_acc;
    ds[2] = s[3];
    ds[3] = theta_acc;
}

SIM_VECTOR_CLONES void sim_cart_pole_step(const double *p, double dt, int32_t integrator, double *s,
                                       const double *forces, int32_t lanes)
{
    sim_integrate(derivatives, 4, p, dt, integrator, s, forces, lanes);
}

/* Strict limits (method.md). Non-finite velocities fail too (icoac_sim_model_failed's contract:
 * "or not finite"); otherwise the next tick would hand them to the controller, which rejects the
 * observation, and the cell would end as ICOAC_SIM_ERROR instead of a failed trial. */
SIM_STATE_TEST outside(const double *p, const double *s)
{
    return !((s[0] >= -p[X_LIMIT]) & (s[0] <= p[X_LIMIT]) & (s[2] >= -p[THETA_LIMIT]) & (s[2] <= p[THETA_LIMIT]) &
             (fabs(s[1]) <= DBL_MAX) & (fabs(s[3]) <= DBL_MAX));
}

SIM_VECTOR_CLONES static void failed(const double *p, const double *s, int32_t lanes, int32_t *out)
{
    sim_test_lanes(outside, 4, p, s, lanes, out);
}

/* Cart plus a uniform rod of half-length l (inertia m l^2 / 3 about its centre), height 0 at
 * the pivot. */
static double energy(const double *p, const double *s)
{
    const double m = p[POLE_MASS], l = p[HALF_LENGTH];
    const double cos_t = sim_cos(s[2]);
    return 0.5 * (p[CART_MASS] + m) * s[1] * s[1] + m * l * cos_t * s[1] * s[3] +
           (2.0 / 3.0) * m * l * l * s[3] * s[3] + m * p[GRAVITY] * l * cos_t;
}

static const icoac_sim_param_t params[N_PARAMS] = {
    {"gravity", "m/s^2", 9.8, ICOAC_SIM_PHYS_MIN, ICOAC_SIM_PHYS_MAX, "essential",
     "gravitational acceleration"},
    {"cart_mass", "kg", 1.0, ICOAC_SIM_PHYS_MIN, ICOAC_SIM_PHYS_MAX, "essential",
     "mass of the cart"},
    {"pole_mass", "kg", 0.1, ICOAC_SIM_PHYS_MIN, ICOAC_SIM_PHYS_MAX, "essential",
     "mass of the pole, a uniform rod"},
    {"half_length", "m", 0.5, ICOAC_SIM_PHYS_MIN, ICOAC_SIM_PHYS_MAX, "essential",
     "half the pole's length (pivot to centre of mass)"},
    {"x_limit", "m", 2.4, ICOAC_SIM_PHYS_MIN, ICOAC_SIM_PHYS_MAX, "advanced",
     "failure when |x| exceeds it"},
    {"theta_limit", "rad", 12.0 * ICOAC_SIM_PI / 180.0, ICOAC_SIM_PHYS_MIN, ICOAC_SIM_THETA_LIMIT_MAX, "advanced",
     "failure when |theta| exceeds it"},
    {"max_force", "N", 1.0e6, ICOAC_SIM_PHYS_MIN, ICOAC_SIM_PHYS_MAX, "advanced",
     "|force| applied saturates at it (1e6: practically none, the paper's plant; 10: Barto et al.'s)"},
};

/* The paper's task: the controller's defaults. */
static const icoac_sim_task_t task = {"the C defaults (the paper's task)", 0, 0, 0, 0, 0, 1, 0, 0};

const icoac_sim_plant_desc_t sim_cart_pole = {
    "cart_pole",
    "frictionless cart-pole, force on the cart",
    "Barto, Sutton & Anderson, IEEE Trans. SMC 13(5), 1983; Florian, 'Correct equations for the "
    "dynamics of the cart-pole system', 2007",
    {"force", "N"},
    {MAX_FORCE, 0, 10.0, "Barto, Sutton & Anderson 1983: the cart is pushed with +-10 N"},
    4,
    N_PARAMS,
    {{"x", "m"}, {"x_dot", "m/s"}, {"theta", "rad"}, {"theta_dot", "rad/s"}},
    params,
    {2, 25, -12.0, 1.0, 1, 0}, /* the paper's grid: theta0 = -12, -11, ..., 12 deg */
    {0, 49, -2.4, 0.1, 0, 0},  /* x0 = -2.4, -2.3, ..., 2.4 m */
    {0.0, 0.0, 0.0, 0.0},
    {0, 1, 0, 1},
    {0, 1, 2, 3},
    sim_cart_pole_step,
    derivatives,
    failed,
    energy,
    &task,
};
