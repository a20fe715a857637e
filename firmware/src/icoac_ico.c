/* SPDX-License-Identifier: Apache-2.0 */
/* ICO rule (Eq. 2-3) in both timings of A4 (method.md), staged: the new weights, their norm and the
 * force are stored only when finite. */
#include "icoac_features.h"

/* ICO weights after a penalty onset of size drop > 0 (Eq. 2-3), and their norm. */
static icoac_real_t learn_weights(const icoac_config_t *cfg, const icoac_priv_state_t *st,
                                  const icoac_real_t trace[ICOAC_MAX_INPUTS], icoac_real_t drop,
                                  icoac_real_t w[ICOAC_MAX_INPUTS])
{
    const icoac_real_t step = cfg->ico.rate * drop;
    int i;
    for (i = 0; i < ICOAC_MAX_INPUTS; ++i) {
        w[i] = st->w[i] + step * ICOAC_PRIV_FABS(trace[i]);
    }
    return ICOAC_PRIV_SQRT(icoac_priv_dot(w, w));
}

static void commit_weights(icoac_priv_state_t *st, const icoac_real_t w[ICOAC_MAX_INPUTS], icoac_real_t norm)
{
    icoac_priv_copy(st->w, w);
    st->weight_norm = norm;
}

/* ICO rule, code timing: act with w_t, then learn from the penalty onset at s_t. Failure
 * states are not seen. The force and the new weights' norm (finite only if every w_i is) are
 * checked before anything is stored; returns 0, with the state untouched, when one is not. */
static int code_timing(const icoac_config_t *cfg, icoac_priv_state_t *st,
                       const icoac_real_t scaled[ICOAC_MAX_INPUTS], icoac_real_t penalty, int terminal,
                       icoac_output_t *out)
{
    const icoac_real_t drop = cfg->learn ? st->penalty_prev - penalty : ICOAC_R(0.0);
    icoac_real_t z;
    icoac_real_t force;
    if (terminal != 0) {
        out->q = ICOAC_R(0.0);
        out->z = ICOAC_R(0.0);
        out->force = ICOAC_R(0.0);
        return 1;
    }
    z = icoac_priv_dot(st->w, scaled);
    force = cfg->policy.gain * z + icoac_priv_reflex_force(&cfg->policy, out->reflex);
    if (!icoac_priv_finite(force)) {
        return 0;
    }
    if (drop > ICOAC_R(0.0)) {
        /* the new weights live in this branch only: learnt, checked and committed together */
        icoac_real_t w[ICOAC_MAX_INPUTS];
        const icoac_real_t norm = learn_weights(cfg, st, scaled, drop, w);
        if (!icoac_priv_finite(norm)) {
            return 0;
        }
        commit_weights(st, w, norm);
        out->q = drop;
    } else {
        out->q = ICOAC_R(0.0);
    }
    st->penalty_prev = penalty;
    out->z = z;
    out->force = force;
    return 1;
}

/* ICO rule, literal timing: learn from r(t+1) - r(t) with x~(t), then act with w_{t+1}; a
 * terminal tick learns and outputs no force. Checked like the code timing (z stands for the
 * force on a terminal tick). */
static int literal_timing(const icoac_config_t *cfg, icoac_priv_state_t *st,
                          const icoac_real_t scaled[ICOAC_MAX_INPUTS], icoac_real_t penalty,
                          int terminal, icoac_output_t *out)
{
    const icoac_real_t drop = st->penalty_prev - penalty;
    const int learn = cfg->learn && st->has_prev && drop > ICOAC_R(0.0);
    icoac_real_t w[ICOAC_MAX_INPUTS];
    icoac_real_t norm = ICOAC_R(0.0);
    icoac_real_t z;
    icoac_real_t force = ICOAC_R(0.0);
    if (learn != 0) {
        norm = learn_weights(cfg, st, st->x_prev, drop, w);
    }
    z = icoac_priv_dot(learn ? w : st->w, scaled);
    if (!terminal) {
        force = cfg->policy.gain * z + icoac_priv_reflex_force(&cfg->policy, out->reflex);
    }
    if (!icoac_priv_finite(terminal ? z : force) || !icoac_priv_finite(norm)) {
        return 0;
    }
    out->q = ICOAC_R(0.0);
    if (learn != 0) {
        commit_weights(st, w, norm);
        out->q = drop;
    }
    st->penalty_prev = penalty;
    icoac_priv_cache_tick(st, scaled);
    out->z = z;
    out->force = force;
    return 1;
}

/* Writes every output field but reflex, penalty, weight_norm and status. */
int icoac_priv_ico_tick(const icoac_config_t *cfg, icoac_priv_state_t *st,
                        const icoac_real_t scaled[ICOAC_MAX_INPUTS], icoac_real_t penalty, int terminal,
                        icoac_output_t *out)
{
    out->value = ICOAC_R(0.0);
    out->td_error = ICOAC_R(0.0);
    out->noise = ICOAC_R(0.0);
    out->cov_trace = ICOAC_R(0.0);
    if (cfg->ico.timing == ICOAC_ICO_TIMING_CODE) {
        return code_timing(cfg, st, scaled, penalty, terminal, out);
    }
    if (cfg->ico.timing == ICOAC_ICO_TIMING_LITERAL) {
        return literal_timing(cfg, st, scaled, penalty, terminal, out);
    }
    return ICOAC_PRIV_TICK_CORRUPT;
}
