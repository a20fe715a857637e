/* SPDX-License-Identifier: Apache-2.0 */
/* Status names and layout checks of the sim API. */
#include "icoac_sim/icoac_sim.h"

const char *icoac_sim_status_str(int32_t status)
{
    switch (status) {
    case ICOAC_SIM_ERR_BAD_PLANT: return "invalid plant (unknown plant; a parameter outside its range, an unused one not 0; dt outside [1e-6, 1] s; integrator not 0 or 1), or a task whose inputs are not the plant's state";
    case ICOAC_SIM_ERR_BAD_RUN: return "invalid run parameter (max_trials >= 1, success_steps >= 1, init_velocity_noise 0 or in [1e-12, 1e3], lanes in [1, 64])";
    case ICOAC_SIM_ERR_BAD_ARGUMENT: return "invalid argument (NULL pointer, empty or wrong-sized array, non-finite cell)";
    case ICOAC_SIM_ERR_THREAD: return "could not start a worker thread";
    case ICOAC_SIM_CANCELLED: return "cancelled (finished cells are kept)";
    case ICOAC_SIM_ERR_NONFINITE: return "plant state or input not finite, or made non-finite by the step (the state is left as it was)";
    default: return icoac_status_str((icoac_status_t)status);
    }
}

uint32_t icoac_sim_abi_version(void) { return ICOAC_SIM_ABI_VERSION; }
uint32_t icoac_sim_sizeof_run(void) { return (uint32_t)sizeof(icoac_sim_run_t); }
uint32_t icoac_sim_sizeof_cell(void) { return (uint32_t)sizeof(icoac_sim_cell_t); }
