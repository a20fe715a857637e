/* SPDX-License-Identifier: Apache-2.0 */
/* The engine's integrators for any plant (icoac_sim_integrator_t): a plant file's step calls
 * sim_integrate with its own derivative function (declared SIM_DERIVATIVES, so that it is inlined
 * into the loop over the batch's lanes, which the compiler then vectorises). */
#ifndef SIM_INTEGRATE_H
#define SIM_INTEGRATE_H

#include "icoac_sim/icoac_sim.h"

#define SIM_DERIVATIVES static inline __attribute__((always_inline)) void
/* A plant's failure test of one state (1: outside its limits or not finite), inlined into
 * sim_test_lanes's loop; written with & rather than && and as !(inside), so that the loop has no
 * branch and NaN fails. */
#define SIM_STATE_TEST static inline __attribute__((always_inline)) int32_t
/* A loop over a block's lanes (a plant's step, the engine's failure test and inputs), compiled
 * for each vector width; the loader picks the machine's. Not with clang:
 * clang 14 gives the clones' resolver of a static function external linkage, so that two plants'
 * `step`s clash at link time; its builds run the baseline (SSE2) code. */
#if defined(__clang__)
#define SIM_VECTOR_CLONES
#else
#define SIM_VECTOR_CLONES __attribute__((target_clones("default", "avx2", "avx512f")))
#endif

/* An actuator's saturation at +-limit (a plant's max_force or max_voltage), inside its
 * derivatives; NaN passes through, for the step's finiteness check to report. */
static inline double sim_saturate(double u, double limit)
{
    return u > limit ? limit : (u < -limit ? -limit : u);
}

/* failed[l] = test(p, lane l's state) for each of the lanes states of s (the step's layout), n
 * components each: a plant's `failed`, declared SIM_VECTOR_CLONES, calls it with its own test. */
static inline __attribute__((always_inline)) void sim_test_lanes(int32_t (*test)(const double *, const double *), int n,
                                                                 const double *p, const double *restrict s,
                                                                 int32_t lanes, int32_t *restrict failed)
{
    int32_t l;
    int i;
    for (l = 0; l < lanes; ++l) {
        double x[ICOAC_SIM_MAX_STATE];
        for (i = 0; i < n; ++i) x[i] = s[i * lanes + l];
        failed[l] = test(p, x);
    }
}

/* Advance each of the lanes states of s (component i of lane l at s[i * lanes + l]) by one dt
 * under its own input u[l]: explicit Euler (every right-hand side from the old state, Sutton's
 * order) or classical RK4. */
static inline __attribute__((always_inline)) void sim_integrate(icoac_sim_derivatives_fn derivatives, int n,
                                                                const double *p, double dt, int32_t integrator,
                                                                double *restrict s, const double *restrict u,
                                                                int32_t lanes)
{
    int32_t l;
    int i;
    if (integrator != ICOAC_SIM_RK4) {
        for (l = 0; l < lanes; ++l) {
            double x[ICOAC_SIM_MAX_STATE], k1[ICOAC_SIM_MAX_STATE];
            for (i = 0; i < n; ++i) x[i] = s[i * lanes + l];
            derivatives(p, x, u[l], k1);
            for (i = 0; i < n; ++i) s[i * lanes + l] = x[i] + dt * k1[i];
        }
        return;
    }
    for (l = 0; l < lanes; ++l) {
        double x[ICOAC_SIM_MAX_STATE], tmp[ICOAC_SIM_MAX_STATE];
        double k1[ICOAC_SIM_MAX_STATE], k2[ICOAC_SIM_MAX_STATE], k3[ICOAC_SIM_MAX_STATE], k4[ICOAC_SIM_MAX_STATE];
        for (i = 0; i < n; ++i) x[i] = s[i * lanes + l];
        derivatives(p, x, u[l], k1);
        for (i = 0; i < n; ++i) tmp[i] = x[i] + 0.5 * dt * k1[i];
        derivatives(p, tmp, u[l], k2);
        for (i = 0; i < n; ++i) tmp[i] = x[i] + 0.5 * dt * k2[i];
        derivatives(p, tmp, u[l], k3);
        for (i = 0; i < n; ++i) tmp[i] = x[i] + dt * k3[i];
        derivatives(p, tmp, u[l], k4);
        for (i = 0; i < n; ++i) s[i * lanes + l] = x[i] + dt / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]);
    }
}

#endif /* SIM_INTEGRATE_H */
