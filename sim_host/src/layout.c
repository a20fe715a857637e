/* Constants and struct layouts exported for bindings (harness/_binding.py reads both tables
 * at import), so that sizes, enum values, statuses, grid geometry and field offsets are defined
 * once, in C. */
#include <stddef.h>

#include "icoac_sim/icoac_sim.h"

#define CONSTANT(name) {#name, (double)(name)}

static const icoac_sim_constant_t constants[] = {
    CONSTANT(ICOAC_ABI_VERSION),
    CONSTANT(ICOAC_SIM_ABI_VERSION),
    CONSTANT(ICOAC_N_INPUTS),
    CONSTANT(ICOAC_CRITIC_UNITS),
    CONSTANT(ICOAC_STATE_SIZE),
    CONSTANT(ICOAC_CRITIC_DENSE), /* the critic kernel of this build: 1 dense, 0 sparse */
    CONSTANT(ICOAC_SIM_LANES),
    CONSTANT(ICOAC_INPUT_TERMINAL),
    /* switches */
    CONSTANT(ICOAC_MODE_ICO),
    CONSTANT(ICOAC_MODE_RL),
    CONSTANT(ICOAC_MODE_SEARCH),
    CONSTANT(ICOAC_ACTOR_POSTERIOR),
    CONSTANT(ICOAC_ACTOR_MEAN),
    CONSTANT(ICOAC_ACTOR_GRADIENT),
    CONSTANT(ICOAC_SEARCH_BATCH_MAX),
    CONSTANT(ICOAC_EXPLORE_TICKS_MAX),
    CONSTANT(ICOAC_REFLEX_UNIT),
    CONSTANT(ICOAC_REFLEX_GAIN),
    CONSTANT(ICOAC_ICO_TIMING_CODE),
    CONSTANT(ICOAC_ICO_TIMING_LITERAL),
    CONSTANT(ICOAC_SIM_EULER),
    CONSTANT(ICOAC_SIM_RK4),
    /* the largest configurable force (N): the action bound of the harness's Gymnasium env */
    CONSTANT(ICOAC_FORCE_MAX),
    /* statuses */
    CONSTANT(ICOAC_OK),
    CONSTANT(ICOAC_ERR_NULL),
    CONSTANT(ICOAC_ERR_NOT_INITIALISED),
    CONSTANT(ICOAC_ERR_NONFINITE_INPUT),
    CONSTANT(ICOAC_ERR_NUMERIC),
    CONSTANT(ICOAC_ERR_TRIAL_ENDED),
    CONSTANT(ICOAC_ERR_CORRUPT_STATE),
    CONSTANT(ICOAC_ERR_RETUNE_MODE),
    CONSTANT(ICOAC_ERR_BAD_MODE),
    CONSTANT(ICOAC_ERR_BAD_SCALE),
    CONSTANT(ICOAC_ERR_BAD_GAIN),
    CONSTANT(ICOAC_ERR_BAD_ZONE),
    CONSTANT(ICOAC_ERR_BAD_ICO_RATE),
    CONSTANT(ICOAC_ERR_BAD_CRITIC),
    CONSTANT(ICOAC_ERR_BAD_ACTOR),
    CONSTANT(ICOAC_ERR_BAD_PRIOR),
    CONSTANT(ICOAC_ERR_BAD_SEARCH),
    CONSTANT(ICOAC_SIM_OK),
    CONSTANT(ICOAC_SIM_ERR_BAD_PLANT),
    CONSTANT(ICOAC_SIM_ERR_BAD_RUN),
    CONSTANT(ICOAC_SIM_ERR_BAD_ARGUMENT),
    CONSTANT(ICOAC_SIM_ERR_THREAD),
    CONSTANT(ICOAC_SIM_CANCELLED),
    /* cell outcomes and progress counters */
    CONSTANT(ICOAC_SIM_PENDING),
    CONSTANT(ICOAC_SIM_SUCCESS),
    CONSTANT(ICOAC_SIM_FAILED),
    CONSTANT(ICOAC_SIM_ERROR),
    CONSTANT(ICOAC_SIM_PROGRESS_CELLS),
    CONSTANT(ICOAC_SIM_PROGRESS_TRIALS),
    CONSTANT(ICOAC_SIM_PROGRESS_STEPS),
    CONSTANT(ICOAC_SIM_PROGRESS_LEN),
    /* the paper grid */
    CONSTANT(ICOAC_SIM_GRID_THETAS),
    CONSTANT(ICOAC_SIM_GRID_XS),
    CONSTANT(ICOAC_SIM_GRID_CELLS),
    CONSTANT(ICOAC_SIM_GRID_THETA_FIRST_DEG),
    CONSTANT(ICOAC_SIM_GRID_X_FIRST),
    CONSTANT(ICOAC_SIM_GRID_X_STEP),
    CONSTANT(ICOAC_SIM_PI),
};

#define FIELD(type, member) {#type, #member, (uint32_t)offsetof(type, member), (uint32_t)sizeof(((type *)0)->member)}

static const icoac_sim_field_t fields[] = {
    FIELD(icoac_config_t, mode),
    FIELD(icoac_config_t, learn),
    FIELD(icoac_config_t, policy.input_range),
    FIELD(icoac_config_t, policy.clip_inputs),
    FIELD(icoac_config_t, policy.gain),
    FIELD(icoac_config_t, policy.reflex_mode),
    FIELD(icoac_config_t, policy.reflex_force),
    FIELD(icoac_config_t, policy.zone_theta),
    FIELD(icoac_config_t, policy.zone_x),
    FIELD(icoac_config_t, ico.rate),
    FIELD(icoac_config_t, ico.timing),
    FIELD(icoac_config_t, critic.rate),
    FIELD(icoac_config_t, critic.discount),
    FIELD(icoac_config_t, critic.td_clip),
    FIELD(icoac_config_t, critic.range),
    FIELD(icoac_config_t, critic.threshold),
    FIELD(icoac_config_t, critic.quirks),
    FIELD(icoac_config_t, actor.noise_std),
    FIELD(icoac_config_t, actor.scale),
    FIELD(icoac_config_t, actor.forgetting),
    FIELD(icoac_config_t, actor.reflex),
    FIELD(icoac_config_t, actor.act_with_sample),
    FIELD(icoac_config_t, actor.update),
    FIELD(icoac_config_t, actor.rate),
    FIELD(icoac_config_t, actor.likelihood_std),
    FIELD(icoac_config_t, actor.batch),
    FIELD(icoac_config_t, actor.explore_ticks),
    FIELD(icoac_config_t, search.batch),
    FIELD(icoac_config_t, search.elite_fraction),
    FIELD(icoac_config_t, search.step),
    FIELD(icoac_config_t, search.floor),
    FIELD(icoac_config_t, search.cov_scale),
    FIELD(icoac_prior_t, mean),
    FIELD(icoac_prior_t, cov),
    FIELD(icoac_counters_t, ticks),
    FIELD(icoac_counters_t, nonfinite),
    FIELD(icoac_counters_t, numeric_faults),
    FIELD(icoac_input_t, s),
    FIELD(icoac_input_t, flags),
    FIELD(icoac_output_t, force),
    FIELD(icoac_output_t, z),
    FIELD(icoac_output_t, reflex),
    FIELD(icoac_output_t, penalty),
    FIELD(icoac_output_t, q),
    FIELD(icoac_output_t, weight_norm),
    FIELD(icoac_output_t, value),
    FIELD(icoac_output_t, td_error),
    FIELD(icoac_output_t, noise),
    FIELD(icoac_output_t, cov_trace),
    FIELD(icoac_output_t, status),
    FIELD(icoac_sim_plant_t, gravity),
    FIELD(icoac_sim_plant_t, cart_mass),
    FIELD(icoac_sim_plant_t, pole_mass),
    FIELD(icoac_sim_plant_t, half_length),
    FIELD(icoac_sim_plant_t, dt),
    FIELD(icoac_sim_plant_t, x_limit),
    FIELD(icoac_sim_plant_t, theta_limit),
    FIELD(icoac_sim_plant_t, integrator),
    FIELD(icoac_sim_plant_t, reserved),
    FIELD(icoac_sim_run_t, max_trials),
    FIELD(icoac_sim_run_t, success_steps),
    FIELD(icoac_sim_run_t, init_velocity_noise),
    FIELD(icoac_sim_cell_t, x0),
    FIELD(icoac_sim_cell_t, theta0),
    FIELD(icoac_sim_cell_t, seed),
    FIELD(icoac_sim_cell_t, outcome),
    FIELD(icoac_sim_cell_t, status),
    FIELD(icoac_sim_cell_t, trials),
    FIELD(icoac_sim_cell_t, total_steps),
    FIELD(icoac_sim_cell_t, last_trial_steps),
    FIELD(icoac_sim_cell_t, elapsed_time),
    FIELD(icoac_sim_cell_t, weights),
    FIELD(icoac_sim_cell_t, cov),
};

const icoac_sim_constant_t *icoac_sim_constants(int32_t *count)
{
    if (count != 0) {
        *count = (int32_t)(sizeof constants / sizeof constants[0]);
    }
    return constants;
}

const icoac_sim_field_t *icoac_sim_fields(int32_t *count)
{
    if (count != 0) {
        *count = (int32_t)(sizeof fields / sizeof fields[0]);
    }
    return fields;
}
