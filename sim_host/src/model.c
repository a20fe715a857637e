/* SPDX-License-Identifier: Apache-2.0 */
/* The registry plants as models (parameter block + integration options): defaults, checks,
 * step, derivatives, failure test, energy, grid and trial start, each rejecting bad input with
 * a status. */
#include <math.h>
#include <string.h>

#include "icoac_sim/icoac_sim.h"
#include "sim_internal.h"

int32_t icoac_sim_model_default(icoac_sim_model_t *model, int32_t index)
{
    const icoac_sim_plant_desc_t *desc = icoac_sim_plant_info(index);
    int32_t i;
    if (model == 0) {
        return ICOAC_SIM_ERR_BAD_ARGUMENT;
    }
    if (desc == 0) {
        return ICOAC_SIM_ERR_BAD_PLANT;
    }
    memset(model, 0, sizeof *model);
    model->plant = index;
    model->integrator = ICOAC_SIM_EULER;
    model->dt = SIM_DT_DEFAULT;
    for (i = 0; i < desc->n_params; ++i) {
        model->param[i] = desc->params[i].value;
    }
    return ICOAC_SIM_OK;
}

/* 0 or a normal number in [min, max]: no subnormal reaches the engine, whose threads flush them. */
int sim_param_valid(double v, const icoac_sim_param_t *range)
{
    return (v == 0.0 || isnormal(v)) && v >= range->min && v <= range->max;
}

int32_t icoac_sim_model_check(const icoac_sim_model_t *model)
{
    const icoac_sim_plant_desc_t *desc = model == 0 ? 0 : icoac_sim_plant_info(model->plant);
    int32_t i;
    if (model == 0) {
        return ICOAC_SIM_ERR_BAD_ARGUMENT;
    }
    if (desc == 0 || !(model->dt >= ICOAC_SIM_DT_MIN && model->dt <= ICOAC_SIM_DT_MAX) ||
        (model->integrator != ICOAC_SIM_EULER && model->integrator != ICOAC_SIM_RK4)) {
        return ICOAC_SIM_ERR_BAD_PLANT;
    }
    for (i = 0; i < ICOAC_SIM_MAX_PARAMS; ++i) {
        if (i < desc->n_params ? !sim_param_valid(model->param[i], &desc->params[i]) : model->param[i] != 0.0) {
            return ICOAC_SIM_ERR_BAD_PLANT;
        }
    }
    return ICOAC_SIM_OK;
}

static int all_finite(const double *v, int32_t n)
{
    int32_t i;
    for (i = 0; i < n; ++i) {
        if (!isfinite(v[i])) {
            return 0;
        }
    }
    return 1;
}

/* The descriptor of a valid model and non-NULL state (NULL and *status set otherwise). */
static const icoac_sim_plant_desc_t *checked(const icoac_sim_model_t *model, const double *state,
                                             int32_t *status)
{
    *status = icoac_sim_model_check(model);
    if (*status == ICOAC_SIM_OK && state == 0) {
        *status = ICOAC_SIM_ERR_BAD_ARGUMENT;
    }
    return *status == ICOAC_SIM_OK ? icoac_sim_plant_info(model->plant) : 0;
}

int32_t icoac_sim_model_step(const icoac_sim_model_t *model, double state[ICOAC_SIM_MAX_STATE], double u)
{
    double s[ICOAC_SIM_MAX_STATE];
    int32_t status;
    const icoac_sim_plant_desc_t *desc = checked(model, state, &status);
    if (desc == 0) {
        return status;
    }
    if (!all_finite(state, desc->n_state) || !isfinite(u)) {
        return ICOAC_SIM_ERR_NONFINITE;
    }
    memcpy(s, state, (size_t)desc->n_state * sizeof s[0]);
    desc->step(model->param, model->dt, model->integrator, s, &u, 1);
    if (!all_finite(s, desc->n_state)) {
        return ICOAC_SIM_ERR_NONFINITE;
    }
    memcpy(state, s, (size_t)desc->n_state * sizeof s[0]);
    return ICOAC_SIM_OK;
}

int32_t icoac_sim_model_derivatives(const icoac_sim_model_t *model, const double state[ICOAC_SIM_MAX_STATE],
                                    double u, double ds[ICOAC_SIM_MAX_STATE])
{
    double d[ICOAC_SIM_MAX_STATE];
    int32_t status;
    const icoac_sim_plant_desc_t *desc = checked(model, state, &status);
    if (desc == 0) {
        return status;
    }
    if (ds == 0) {
        return ICOAC_SIM_ERR_BAD_ARGUMENT;
    }
    if (!all_finite(state, desc->n_state) || !isfinite(u)) {
        return ICOAC_SIM_ERR_NONFINITE;
    }
    desc->derivatives(model->param, state, u, d);
    if (!all_finite(d, desc->n_state)) {
        return ICOAC_SIM_ERR_NONFINITE;
    }
    memcpy(ds, d, (size_t)desc->n_state * sizeof d[0]);
    return ICOAC_SIM_OK;
}

int32_t icoac_sim_model_failed(const icoac_sim_model_t *model, const double state[ICOAC_SIM_MAX_STATE],
                               int32_t *failed)
{
    int32_t status;
    const icoac_sim_plant_desc_t *desc = checked(model, state, &status);
    if (desc == 0) {
        return status;
    }
    if (failed == 0) {
        return ICOAC_SIM_ERR_BAD_ARGUMENT;
    }
    desc->failed(model->param, state, 1, failed);
    return ICOAC_SIM_OK;
}

int32_t icoac_sim_model_step_lanes(const icoac_sim_model_t *model, double *states, const double *u,
                                   int32_t *ended, int64_t lanes)
{
    int64_t lane;
    int32_t status = icoac_sim_model_check(model);
    if (status != ICOAC_SIM_OK) {
        return status;
    }
    if (lanes < 0 || (lanes > 0 && (states == 0 || u == 0 || ended == 0))) {
        return ICOAC_SIM_ERR_BAD_ARGUMENT;
    }
    for (lane = 0; lane < lanes; ++lane) {
        double *s = states + lane * ICOAC_SIM_MAX_STATE;
        int32_t failed = 1;
        if (ended[lane] != 0) {
            continue;
        }
        if (icoac_sim_model_step(model, s, u[lane]) == ICOAC_SIM_OK) {
            (void)icoac_sim_model_failed(model, s, &failed);
        }
        ended[lane] = failed != 0 ? 1 : 0;
    }
    return ICOAC_SIM_OK;
}

int32_t icoac_sim_model_energy(const icoac_sim_model_t *model, const double state[ICOAC_SIM_MAX_STATE],
                               double *energy)
{
    double e;
    int32_t status;
    const icoac_sim_plant_desc_t *desc = checked(model, state, &status);
    if (desc == 0) {
        return status;
    }
    if (energy == 0 || desc->energy == 0) {
        return ICOAC_SIM_ERR_BAD_ARGUMENT;
    }
    if (!all_finite(state, desc->n_state)) {
        return ICOAC_SIM_ERR_NONFINITE;
    }
    e = desc->energy(model->param, state);
    if (!isfinite(e)) {
        return ICOAC_SIM_ERR_NONFINITE;
    }
    *energy = e;
    return ICOAC_SIM_OK;
}

/* Value i of a swept coordinate (the paper grid's expressions for the cart-pole). */
static double sweep_value(const icoac_sim_sweep_t *sweep, int64_t i)
{
    const double v = sweep->first + sweep->step * (double)i;
    return sweep->degrees ? v * ICOAC_SIM_PI / 180.0 : v;
}

int32_t icoac_sim_plant_grid(int32_t index, icoac_sim_cell_t *cells, int64_t n_cells, uint64_t seed)
{
    const icoac_sim_plant_desc_t *desc = icoac_sim_plant_info(index);
    int64_t i;
    if (desc == 0) {
        return ICOAC_SIM_ERR_BAD_PLANT;
    }
    if (cells == 0 || n_cells != (int64_t)desc->rows.count * desc->cols.count) {
        return ICOAC_SIM_ERR_BAD_ARGUMENT;
    }
    memset(cells, 0, (size_t)n_cells * sizeof *cells);
    for (i = 0; i < n_cells; ++i) {
        cells[i].theta0 = sweep_value(&desc->rows, i / desc->cols.count);
        cells[i].x0 = sweep_value(&desc->cols, i % desc->cols.count);
        cells[i].seed = icoac_mix_seed(seed, (uint64_t)i);
        cells[i].outcome = ICOAC_SIM_PENDING;
    }
    return ICOAC_SIM_OK;
}

void sim_start_trial(const icoac_sim_plant_desc_t *desc, const icoac_sim_cell_t *cell, double noise,
                     icoac_rng_t *rng, double s[ICOAC_SIM_MAX_STATE])
{
    int32_t i;
    for (i = 0; i < desc->n_state; ++i) {
        s[i] = desc->start[i];
    }
    s[desc->rows.component] = cell->theta0;
    s[desc->cols.component] = cell->x0;
    for (i = 0; i < desc->n_state; ++i) {
        if (desc->drawn[i]) {
            s[i] = sim_uniform_symmetric(rng, noise);
        }
    }
}

int32_t icoac_sim_model_start(const icoac_sim_model_t *model, const icoac_sim_cell_t *cell, double noise,
                              icoac_rng_t *rng, double state[ICOAC_SIM_MAX_STATE])
{
    int32_t status;
    const icoac_sim_plant_desc_t *desc = checked(model, state, &status);
    if (desc == 0) {
        return status;
    }
    if (cell == 0 || rng == 0 || !isfinite(cell->x0) || !isfinite(cell->theta0) ||
        !sim_velocity_noise_valid(noise)) {
        return ICOAC_SIM_ERR_BAD_ARGUMENT;
    }
    sim_start_trial(desc, cell, noise, rng, state);
    return ICOAC_SIM_OK;
}
