/* Private helpers shared by the sim_host sources. */
#ifndef SIM_INTERNAL_H
#define SIM_INTERNAL_H

#include <math.h>

#include "icoac_sim/icoac_sim.h"

/* Failure test of spec 3 with strict limits; written so that NaN counts as failure.
 * Non-finite velocities fail too (icoac_sim_failed contract: "or not finite"); otherwise the
 * next tick hands them to the controller, which rejects the observation and the cell ends
 * as ICOAC_SIM_ERROR instead of a failed trial. */
static inline int32_t sim_failed(const icoac_sim_plant_t *plant, const double s[ICOAC_N_INPUTS])
{
    return !(s[0] >= -plant->x_limit && s[0] <= plant->x_limit && s[2] >= -plant->theta_limit &&
             s[2] <= plant->theta_limit && isfinite(s[1]) && isfinite(s[3]));
}

/* Check the controller configuration, plant and (if not NULL) run parameters (params.c). */
int32_t sim_check_all(const icoac_config_t *cfg, const icoac_sim_plant_t *plant,
                      const icoac_sim_run_t *run);

/* Initial velocity noise a: 0, or in [ICOAC_SIM_NOISE_MIN, ICOAC_SIM_NOISE_MAX] (params.c). */
int sim_velocity_noise_valid(double a);

/* Start state of a trial from cell (x0, theta0) with velocities U(-noise, noise) (trial.c). */
void sim_start_trial(const icoac_sim_cell_t *cell, double noise, icoac_rng_t *rng, double s[ICOAC_N_INPUTS]);

/* The plant state as the controller's input; values outside its real range become NaN. */
void sim_to_input(const double s[ICOAC_N_INPUTS], uint32_t flags, icoac_input_t *in);

/* icoac_sim_run_cell without the argument checks (trial.c). */
int32_t sim_run_cell_checked(const icoac_config_t *cfg, const icoac_sim_plant_t *plant,
                             const icoac_sim_run_t *run, const icoac_prior_t *prior,
                             icoac_sim_cell_t *cell, const volatile int32_t *cancel,
                             volatile int64_t *progress);

/* Flush subnormals to zero on this thread; returns the previous mode for sim_fpu_restore (fpu.c). */
uint32_t sim_fpu_flush_subnormals(void);
void sim_fpu_restore(uint32_t mode);

#endif /* SIM_INTERNAL_H */
