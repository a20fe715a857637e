/* SPDX-License-Identifier: Apache-2.0 */
/* The tick dispatcher (method.md, one tick): input check, features, then the mode's tick. */
#include "icoac_features.h"

/* Field by field: newlib-nano's memset goes byte by byte. */
static void clear_output(icoac_output_t *out)
{
    out->force = ICOAC_R(0.0);
    out->z = ICOAC_R(0.0);
    out->reflex = ICOAC_R(0.0);
    out->penalty = ICOAC_R(0.0);
    out->q = ICOAC_R(0.0);
    out->weight_norm = ICOAC_R(0.0);
    out->value = ICOAC_R(0.0);
    out->td_error = ICOAC_R(0.0);
    out->noise = ICOAC_R(0.0);
    out->cov_trace = ICOAC_R(0.0);
    out->status = ICOAC_OK;
}

/* An error status: the output cleared but for |w| and the status. (On success the mode's
 * tick writes every field it does not share with the dispatcher.) */
static icoac_status_t rejected(const icoac_priv_state_t *st, icoac_output_t *out, icoac_status_t status)
{
    clear_output(out);
    out->weight_norm = st->weight_norm;
    out->status = (int32_t)status;
    return status;
}

/* The late signal of a sensor (icoac.h, task): r = -1 and U = in->reflex, clipped to [-1, 1], on
 * a tick with ICOAC_INPUT_LATE; 0, 0 otherwise. A NaN or Inf reflex stays so (a non-finite input). */
ICOAC_PRIV_NOINLINE static icoac_priv_zone_t sensor_zone(const icoac_input_t *in)
{
    icoac_priv_zone_t zone;
    zone.reflex = ICOAC_R(0.0);
    zone.penalty = ICOAC_R(0.0);
    if ((in->flags & ICOAC_INPUT_LATE) != 0u) {
        zone.reflex = icoac_priv_finite(in->reflex) ? icoac_priv_clip_unit(in->reflex) : in->reflex;
        zone.penalty = ICOAC_R(-1.0);
    }
    return zone;
}

/* The slow path of a state that is not in a trial: ended by a terminal tick, or never set up. */
ICOAC_PRIV_NOINLINE static icoac_status_t not_in_trial(icoac_priv_state_t *st, icoac_output_t *out)
{
    if (st->magic == ICOAC_PRIV_STATE_ENDED) {
        st->counters.ticks++;
        return rejected(st, out, ICOAC_ERR_TRIAL_ENDED);
    }
    clear_output(out);
    out->status = ICOAC_ERR_NOT_INITIALISED;
    return ICOAC_ERR_NOT_INITIALISED;
}

/* A tick on an initialised state in a trial, for a task of n inputs whose late signal is the
 * first `rules` rules of its table (sensor: 0, the input's flag instead). One implementation,
 * instantiated for the cart-pole's task (compile-time n and rules: unrolled; with
 * cartpole_rules, the rules' inputs and sides as constants when the state's tag says the table
 * has the preset's layout) and for the configuration's (bounded to the arrays); icoac_step
 * selects one per tick. */
static inline icoac_status_t tick(icoac_priv_state_t *st, const icoac_input_t *in, icoac_output_t *out, int n,
                                  int rules, int sensor, int cartpole_rules, const icoac_real_t *given)
{
    const icoac_config_t *cfg = &st->config;
    const icoac_real_t *const inputs = in->s; /* entries n and up are not read */
    icoac_real_t scaled[ICOAC_MAX_INPUTS];
    icoac_priv_zone_t zone;
    int terminal;
    int ok;
    st->counters.ticks++;
    if (!icoac_priv_inputs_finite(n, inputs)) {
        st->counters.nonfinite++;
        return rejected(st, out, ICOAC_ERR_NONFINITE_INPUT);
    }
    terminal = (in->flags & ICOAC_INPUT_TERMINAL) != 0u;
    icoac_priv_scale_inputs(&cfg->policy, st, n, inputs, scaled);
    if (!sensor) {
        zone = cartpole_rules && (st->grid.shape & ICOAC_PRIV_SHAPE_CARTPOLE_RULES) != 0u
                   ? icoac_priv_zone_cartpole(&cfg->task, inputs)
                   : icoac_priv_zone(&cfg->task, rules, n, inputs);
    } else {
        zone = sensor_zone(in);
        if (!icoac_priv_finite(zone.reflex)) {
            st->counters.nonfinite++;
            return rejected(st, out, ICOAC_ERR_NONFINITE_INPUT);
        }
    }
    out->reflex = zone.reflex;
    out->penalty = zone.penalty;
    if (cfg->mode == ICOAC_MODE_RL) {
        ok = icoac_priv_rl_tick(cfg, st, inputs, scaled, terminal, out, n, given);
    } else if (cfg->mode == ICOAC_MODE_SEARCH) {
        ok = icoac_priv_search_tick(cfg, st, scaled, terminal, out);
    } else if (cfg->mode == ICOAC_MODE_ICO) {
        ok = icoac_priv_ico_tick(cfg, st, scaled, zone.penalty, terminal, out);
    } else {
        ok = ICOAC_PRIV_TICK_CORRUPT;
    }
    if (ok != ICOAC_PRIV_TICK_OK) {
        if (ok == ICOAC_PRIV_TICK_CORRUPT) {
            return rejected(st, out, ICOAC_ERR_CORRUPT_STATE);
        }
        st->counters.numeric_faults++;
        return rejected(st, out, ICOAC_ERR_NUMERIC);
    }
    if (terminal != 0) {
        st->magic = ICOAC_PRIV_STATE_ENDED;
    }
    out->weight_norm = st->weight_norm;
    out->status = ICOAC_OK;
    return ICOAC_OK;
}

/* The general instance: the configuration's task. */
ICOAC_PRIV_NOINLINE static icoac_status_t tick_general(icoac_priv_state_t *st, const icoac_input_t *in,
                                                       icoac_output_t *out, const icoac_real_t *given)
{
    const icoac_task_config_t *task = &st->config.task;
    const int sensor = task->late_source != ICOAC_LATE_RULES;
    return tick(st, in, out, icoac_priv_inputs(&st->config), sensor ? 0 : icoac_priv_rules(task), sensor, 0, given);
}

icoac_status_t icoac_step(icoac_state_t *state, const icoac_input_t *in, icoac_output_t *out)
{
    return icoac_priv_step(state, in, out, NULL); /* a tail call: no frame of its own */
}

icoac_status_t icoac_priv_step(icoac_state_t *state, const icoac_input_t *in, icoac_output_t *out,
                               const icoac_real_t *given)
{
    icoac_priv_state_t *st = icoac_priv_state(state);
    if ((state == NULL) || (in == NULL) || (out == NULL)) {
        if (out != NULL) {
            clear_output(out);
            out->status = ICOAC_ERR_NULL;
        }
        return ICOAC_ERR_NULL;
    }
    if (st->magic != ICOAC_PRIV_STATE_MAGIC) {
        return not_in_trial(st, out);
    }
    /* the cart-pole's task: tested on the configuration copy itself (three words), so the
     * instance reads exactly the inputs and rules the copy names, whatever else the state holds */
    if (st->config.task.n_inputs == ICOAC_CARTPOLE_INPUTS && st->config.task.late_source == ICOAC_LATE_RULES &&
        st->config.task.n_rules == ICOAC_CARTPOLE_RULES) {
        return tick(st, in, out, ICOAC_CARTPOLE_INPUTS, ICOAC_CARTPOLE_RULES, 0, 1, given);
    }
    return tick_general(st, in, out, given);
}
