/* SPDX-License-Identifier: Apache-2.0 */
/* The engine's integrators for any plant (icoac_sim_integrator_t): a plant file's step calls
 * sim_integrate with its own derivative function, which the compiler then inlines. */
#ifndef SIM_INTEGRATE_H
#define SIM_INTEGRATE_H

#include "icoac_sim/icoac_sim.h"

/* Advance the n values of s by one dt: explicit Euler (every right-hand side from the old state,
 * Sutton's order) or classical RK4. */
static inline void sim_integrate(icoac_sim_derivatives_fn derivatives, int n, const double *p, double dt,
                                 int32_t integrator, double *s, double u)
{
    double k1[ICOAC_SIM_MAX_STATE], k2[ICOAC_SIM_MAX_STATE], k3[ICOAC_SIM_MAX_STATE];
    double k4[ICOAC_SIM_MAX_STATE], tmp[ICOAC_SIM_MAX_STATE];
    int i;
    derivatives(p, s, u, k1);
    if (integrator != ICOAC_SIM_RK4) {
        for (i = 0; i < n; ++i) s[i] += dt * k1[i];
        return;
    }
    for (i = 0; i < n; ++i) tmp[i] = s[i] + 0.5 * dt * k1[i];
    derivatives(p, tmp, u, k2);
    for (i = 0; i < n; ++i) tmp[i] = s[i] + 0.5 * dt * k2[i];
    derivatives(p, tmp, u, k3);
    for (i = 0; i < n; ++i) tmp[i] = s[i] + dt * k3[i];
    derivatives(p, tmp, u, k4);
    for (i = 0; i < n; ++i) s[i] += dt / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]);
}

#endif /* SIM_INTEGRATE_H */
