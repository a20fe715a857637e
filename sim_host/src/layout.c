/* SPDX-License-Identifier: Apache-2.0 */
/* Constants, struct layouts and parameter rows exported for bindings (harness/icoac/core/binding.py reads
 * the tables at import), so that sizes, enum values, statuses, grid geometry, field offsets and
 * every parameter's description are defined once, in C. */
#include <stddef.h>

#include "icoac_sim/icoac_sim.h"

#define CONSTANT(name) {#name, (double)(name)}

static const icoac_sim_constant_t constants[] = {
    CONSTANT(ICOAC_ABI_VERSION),
    CONSTANT(ICOAC_SIM_ABI_VERSION),
    CONSTANT(ICOAC_MAX_INPUTS),
    CONSTANT(ICOAC_MAX_RULES),
    CONSTANT(ICOAC_MAX_CRITIC_UNITS),
    CONSTANT(ICOAC_CARTPOLE_INPUTS),
    CONSTANT(ICOAC_CARTPOLE_CRITIC_UNITS),
    CONSTANT(ICOAC_STATE_SIZE),
    CONSTANT(ICOAC_CRITIC_DENSE), /* the critic kernel of this build: 1 dense, 0 sparse */
    CONSTANT(ICOAC_SIM_MAX_LANES),
    CONSTANT(ICOAC_INPUT_TERMINAL),
    CONSTANT(ICOAC_INPUT_LATE),
    /* switches */
    CONSTANT(ICOAC_LATE_RULES),
    CONSTANT(ICOAC_LATE_SENSOR),
    CONSTANT(ICOAC_RULE_BELOW),
    CONSTANT(ICOAC_RULE_ABOVE),
    CONSTANT(ICOAC_MODE_ICO),
    CONSTANT(ICOAC_MODE_RL),
    CONSTANT(ICOAC_MODE_SEARCH),
    CONSTANT(ICOAC_ACTOR_POSTERIOR),
    CONSTANT(ICOAC_ACTOR_MEAN),
    CONSTANT(ICOAC_ACTOR_GRADIENT),
    CONSTANT(ICOAC_PARAM_ICO), /* the modes column of the parameter table */
    CONSTANT(ICOAC_PARAM_RL),
    CONSTANT(ICOAC_PARAM_SEARCH),
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
    CONSTANT(ICOAC_PRIOR_COV_MAX),
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
    CONSTANT(ICOAC_ERR_BAD_TASK),
    CONSTANT(ICOAC_SIM_OK),
    CONSTANT(ICOAC_SIM_ERR_BAD_PLANT),
    CONSTANT(ICOAC_SIM_ERR_BAD_RUN),
    CONSTANT(ICOAC_SIM_ERR_BAD_ARGUMENT),
    CONSTANT(ICOAC_SIM_ERR_THREAD),
    CONSTANT(ICOAC_SIM_CANCELLED),
    CONSTANT(ICOAC_SIM_ERR_NONFINITE),
    /* cell outcomes and progress counters */
    CONSTANT(ICOAC_SIM_PENDING),
    CONSTANT(ICOAC_SIM_SUCCESS),
    CONSTANT(ICOAC_SIM_FAILED),
    CONSTANT(ICOAC_SIM_ERROR),
    CONSTANT(ICOAC_SIM_PROGRESS_CELLS),
    CONSTANT(ICOAC_SIM_PROGRESS_TRIALS),
    CONSTANT(ICOAC_SIM_PROGRESS_STEPS),
    CONSTANT(ICOAC_SIM_PROGRESS_LEN),
    /* the plant registry */
    CONSTANT(ICOAC_SIM_PI),
    CONSTANT(ICOAC_SIM_DT_MIN),
    CONSTANT(ICOAC_SIM_DT_MAX),
    CONSTANT(ICOAC_SIM_MAX_STATE),
    CONSTANT(ICOAC_SIM_MAX_PARAMS),
    CONSTANT(ICOAC_SIM_MAX_TASK_KNOBS),
    CONSTANT(ICOAC_SIM_CART_POLE),
    CONSTANT(ICOAC_SIM_ZONE_FRACTION),
    CONSTANT(ICOAC_SIM_START_STREAM),
};

#define FIELD(type, member) {#type, #member, (uint32_t)offsetof(type, member), (uint32_t)sizeof(((type *)0)->member)}

/* A parameter row's member designator in its struct (icoac_params.h, ICOAC_SIM_RUN_PARAMS). */
#define MEMBER_config(f) f
#define MEMBER_task(f) task.f
#define MEMBER_policy(f) policy.f
#define MEMBER_ico(f) ico.f
#define MEMBER_critic(f) critic.f
#define MEMBER_actor(f) actor.f
#define MEMBER_search(f) search.f
#define MEMBER_run(f) f
#define MEMBER(group, field) MEMBER_##group(field)
#define PARAM_FIELD(struct_type, group, field)                                                 \
    {#struct_type, ICOAC_PARAM_PREFIX_##group #field, (uint32_t)offsetof(struct_type, MEMBER(group, field)), \
     (uint32_t)sizeof(((struct_type *)0)->MEMBER(group, field))},
#define CONFIG_FIELD(group, field, type, dim, check, unit, min, max, def, modes, tier, status, doc) \
    PARAM_FIELD(icoac_config_t, group, field)
#define RUN_FIELD(group, field, type, dim, check, unit, min, max, def, modes, tier, status, doc) \
    PARAM_FIELD(icoac_sim_run_t, group, field)

static const icoac_sim_field_t fields[] = {
    ICOAC_PARAMS(CONFIG_FIELD)
    ICOAC_SIM_RUN_PARAMS(RUN_FIELD)
    FIELD(icoac_prior_t, mean),
    FIELD(icoac_prior_t, cov),
    FIELD(icoac_counters_t, ticks),
    FIELD(icoac_counters_t, nonfinite),
    FIELD(icoac_counters_t, numeric_faults),
    FIELD(icoac_input_t, s),
    FIELD(icoac_input_t, flags),
    FIELD(icoac_input_t, reflex),
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
    FIELD(icoac_rng_t, state),
    FIELD(icoac_rng_t, increment),
    FIELD(icoac_rng_t, spare_normal),
    FIELD(icoac_rng_t, has_spare),
    FIELD(icoac_sim_axis_t, name),
    FIELD(icoac_sim_axis_t, unit),
    FIELD(icoac_sim_param_t, name),
    FIELD(icoac_sim_param_t, unit),
    FIELD(icoac_sim_param_t, value),
    FIELD(icoac_sim_param_t, min),
    FIELD(icoac_sim_param_t, max),
    FIELD(icoac_sim_param_t, tier),
    FIELD(icoac_sim_param_t, doc),
    FIELD(icoac_sim_actuator_t, param),
    FIELD(icoac_sim_actuator_t, reserved),
    FIELD(icoac_sim_actuator_t, limit),
    FIELD(icoac_sim_actuator_t, source),
    FIELD(icoac_sim_sweep_t, component),
    FIELD(icoac_sim_sweep_t, count),
    FIELD(icoac_sim_sweep_t, first),
    FIELD(icoac_sim_sweep_t, step),
    FIELD(icoac_sim_sweep_t, degrees),
    FIELD(icoac_sim_sweep_t, reserved),
    FIELD(icoac_sim_plant_desc_t, name),
    FIELD(icoac_sim_plant_desc_t, title),
    FIELD(icoac_sim_plant_desc_t, source),
    FIELD(icoac_sim_plant_desc_t, input.name),
    FIELD(icoac_sim_plant_desc_t, input.unit),
    FIELD(icoac_sim_plant_desc_t, actuator.param),
    FIELD(icoac_sim_plant_desc_t, actuator.reserved),
    FIELD(icoac_sim_plant_desc_t, actuator.limit),
    FIELD(icoac_sim_plant_desc_t, actuator.source),
    FIELD(icoac_sim_plant_desc_t, n_state),
    FIELD(icoac_sim_plant_desc_t, n_params),
    FIELD(icoac_sim_plant_desc_t, state),
    FIELD(icoac_sim_plant_desc_t, params),
    FIELD(icoac_sim_plant_desc_t, rows.component),
    FIELD(icoac_sim_plant_desc_t, rows.count),
    FIELD(icoac_sim_plant_desc_t, rows.first),
    FIELD(icoac_sim_plant_desc_t, rows.step),
    FIELD(icoac_sim_plant_desc_t, rows.degrees),
    FIELD(icoac_sim_plant_desc_t, rows.reserved),
    FIELD(icoac_sim_plant_desc_t, cols.component),
    FIELD(icoac_sim_plant_desc_t, cols.count),
    FIELD(icoac_sim_plant_desc_t, cols.first),
    FIELD(icoac_sim_plant_desc_t, cols.step),
    FIELD(icoac_sim_plant_desc_t, cols.degrees),
    FIELD(icoac_sim_plant_desc_t, cols.reserved),
    FIELD(icoac_sim_plant_desc_t, start),
    FIELD(icoac_sim_plant_desc_t, drawn),
    FIELD(icoac_sim_plant_desc_t, observed),
    FIELD(icoac_sim_plant_desc_t, step),
    FIELD(icoac_sim_plant_desc_t, derivatives),
    FIELD(icoac_sim_plant_desc_t, failed),
    FIELD(icoac_sim_plant_desc_t, energy),
    FIELD(icoac_sim_plant_desc_t, task),
    FIELD(icoac_sim_learner_t, conditions),
    FIELD(icoac_sim_learner_t, apply),
    FIELD(icoac_sim_task_t, source),
    FIELD(icoac_sim_task_t, apply),
    FIELD(icoac_sim_task_t, n_knobs),
    FIELD(icoac_sim_task_t, reserved),
    FIELD(icoac_sim_task_t, knobs),
    FIELD(icoac_sim_task_t, n_learners),
    FIELD(icoac_sim_task_t, paper),
    FIELD(icoac_sim_task_t, learners),
    FIELD(icoac_sim_task_t, prior_all_finished),
    FIELD(icoac_sim_model_t, plant),
    FIELD(icoac_sim_model_t, integrator),
    FIELD(icoac_sim_model_t, dt),
    FIELD(icoac_sim_model_t, param),
};

#define PARAM_ROW(struct_type, group, field, type, dim, check, unit, min, max, def, modes, tier, status, doc) \
    {#struct_type, ICOAC_PARAM_PREFIX_##group #field, #group, #type, #dim, #check, unit, #tier, doc,           \
     (double)(min), (double)(max), (double)(def), (uint32_t)(modes), (int32_t)(status),                     \
     (uint32_t)offsetof(struct_type, MEMBER(group, field)), (uint32_t)sizeof(((struct_type *)0)->MEMBER(group, field))},
#define CONFIG_ROW(group, field, type, dim, check, unit, min, max, def, modes, tier, status, doc) \
    PARAM_ROW(icoac_config_t, group, field, type, dim, check, unit, min, max, def, modes, tier, status, doc)
#define RUN_ROW(group, field, type, dim, check, unit, min, max, def, modes, tier, status, doc) \
    PARAM_ROW(icoac_sim_run_t, group, field, type, dim, check, unit, min, max, def, modes, tier, status, doc)

static const icoac_sim_param_row_t param_rows[] = {
    ICOAC_PARAMS(CONFIG_ROW)
    ICOAC_SIM_RUN_PARAMS(RUN_ROW)
};

const icoac_sim_param_row_t *icoac_sim_param_table(int32_t *count)
{
    if (count != 0) {
        *count = (int32_t)(sizeof param_rows / sizeof param_rows[0]);
    }
    return param_rows;
}

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
