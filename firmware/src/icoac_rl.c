/* SPDX-License-Identifier: Apache-2.0 */
/* The actor-critic tick (method.md: critic, actor, one tick): the critic's TD error on the
 * transition into s drives the critic and the Bayesian actor, then the actor acts on s with
 * exploration noise. */
#include "icoac_features.h"

/* delta clipped to +-td_clip. */
static icoac_real_t clip_td(icoac_real_t delta, icoac_real_t td_clip)
{
    return delta > td_clip ? td_clip : (delta < -td_clip ? -td_clip : delta);
}

/* Actor-critic tick: learn from the transition s_t -> s (method.md, one tick), then act on s,
 * over the first n inputs (ICOAC_MAX_INPUTS, or a task's n as a compile-time constant: the
 * entries past the task's n are 0 and stay so, so both instances give the same values).
 * V(s), delta, the actor's candidate mu_w and Sigma_w and the force are staged; the critic and
 * the actor are updated, and the caches advanced, only when they are finite. Returns 0, with
 * the state untouched, otherwise. Checked: V(s), delta, |w| (covers every w_i), the trace of
 * Sigma_w (covers its diagonal; the actor step checks its off-diagonal when it changed, and the
 * batch sums), and G z (+ reflex). Not checked, as finite by the configuration's bounds: the noise
 * (|eps| < 1e8 sigma_u), hence the force G z + eps + reflex; and the critic weights, which move
 * by at most critic_rate * td_clip <= 1e4 per tick. Writes every output field but reflex,
 * penalty, weight_norm and status. */
static inline int rl_tick(const icoac_config_t *cfg, icoac_priv_state_t *st, const icoac_real_t s[ICOAC_MAX_INPUTS],
                          const icoac_real_t scaled[ICOAC_MAX_INPUTS], int terminal, icoac_output_t *out, int n,
                          const icoac_real_t *given)
{
    icoac_real_t w[ICOAC_MAX_INPUTS];
    icoac_real_t h[ICOAC_MAX_INPUTS];
    icoac_real_t (*cov)[ICOAC_MAX_INPUTS] = icoac_priv_cov_spare(st);
    /* Staged and checked. Named values, not an array: a compiler vectorizes the check of an
     * array into one load of what was just stored value by value, which x86 cannot forward
     * from the stores (it waits until they retire: measured, about 10 ns a tick). */
    icoac_real_t value = ICOAC_R(0.0); /* V(s) */
    icoac_real_t delta = ICOAC_R(0.0);
    icoac_real_t norm = st->weight_norm; /* |w| */
    icoac_real_t trace;                  /* of Sigma_w */
    icoac_real_t policy_force = ICOAC_R(0.0); /* G z */
    const int slot_prev = st->active_slot & 1;
    const int learn = st->has_prev;         /* a transition into s exists: delta is defined */
    const int update = learn && cfg->learn; /* ... and the critic and actor learn from it */
    /* the transition's first tick explored (L3): its noise is the actor's observation */
    const uint32_t explore_ticks = (uint32_t)cfg->actor.explore_ticks;
    const int observed = explore_ticks == 0u || st->trial_ticks <= explore_ticks;
    const icoac_real_t *w_act = cfg->actor.act_with_sample ? st->w_act : (update ? w : st->w);
    int cov_changed = 0;
    icoac_real_t z = ICOAC_R(0.0);
    icoac_real_t noise = ICOAC_R(0.0);
    int i;
    if (!terminal || cfg->critic.quirks) {
        /* fills the spare slot: the current one stays the eligibility of this update */
        value = icoac_priv_critic_value(&cfg->critic, &st->grid, st->v, s, given, &st->active[slot_prev ^ 1]);
        if (terminal != 0) {
            value = ICOAC_R(0.0); /* quirks: only the kept units of s_t+1 were wanted */
        }
    }
    if (learn != 0) {
        const icoac_real_t reward = terminal ? ICOAC_R(-1.0) : ICOAC_R(0.0);
        delta = clip_td(reward + cfg->critic.discount * value - st->value_prev, cfg->critic.td_clip);
    }
    if (update != 0) {
        for (i = 0; i < ICOAC_MAX_INPUTS; ++i) {
            h[i] = i < n ? cfg->policy.gain * st->x_prev[i] : ICOAC_R(0.0);
        }
        cov_changed = icoac_priv_actor_step(&cfg->actor, st, h, delta, observed, terminal, w, cov, n);
        if (cov_changed < 0) {
            return cov_changed == -1 ? ICOAC_PRIV_TICK_NUMERIC : ICOAC_PRIV_TICK_CORRUPT;
        }
        norm = ICOAC_PRIV_SQRT(icoac_priv_dot_n(w, w, n));
        if (cov_changed != 0) {
            trace = icoac_priv_trace_n(ICOAC_PRIV_CONST_MAT(cov), n); /* the actor checked the rest */
        } else {
            trace = icoac_priv_trace_n(icoac_priv_cov_c(st), n);
        }
    } else {
        trace = icoac_priv_trace_n(icoac_priv_cov_c(st), n);
    }
    if (!terminal) {
        z = icoac_priv_dot_n(w_act, scaled, n);
        policy_force = cfg->policy.gain * z;
    }
    if (!(icoac_priv_finite(value) & icoac_priv_finite(delta) & icoac_priv_finite(norm) & icoac_priv_finite(trace) &
          icoac_priv_finite(policy_force))) {
        return 0;
    }
    /* commit */
    if (update != 0) {
        icoac_priv_critic_update(&cfg->critic, &st->grid, st->v,
                                 &st->active[cfg->critic.quirks ? slot_prev ^ 1 : slot_prev], cfg->critic.rate * delta);
        icoac_priv_copy_n(st->w, w, n);
        st->cov_slot = (st->cov_slot & 1) ^ cov_changed;
        st->weight_norm = norm;
        if (!cfg->actor.act_with_sample) {
            icoac_priv_copy_n(st->w_act, w, n);
        }
        if (cfg->actor.batch != 0) {
            icoac_priv_actor_commit_batch(&cfg->actor, st, h, observed, terminal);
        }
    }
    out->q = ICOAC_R(0.0);
    out->td_error = delta;
    out->value = value;
    out->cov_trace = trace;
    if (terminal != 0) {
        out->z = ICOAC_R(0.0);
        out->noise = ICOAC_R(0.0);
        out->force = ICOAC_R(0.0);
        st->has_prev = 0;
        return 1;
    }
    if (explore_ticks == 0u || st->trial_ticks < explore_ticks) {
        noise = cfg->actor.noise_std * icoac_rng_normal(&st->rng);
    }
    out->z = z;
    out->noise = noise;
    out->force = policy_force + noise;
    if (cfg->actor.reflex != 0) {
        out->force += icoac_priv_reflex_force(&cfg->policy, out->reflex);
    }
    st->active_slot = slot_prev ^ 1;
    /* quirks: V_old = 0 at a reset, so the trial's first delta is gamma V(s_1) */
    st->value_prev = (cfg->critic.quirks && !st->has_prev) ? ICOAC_R(0.0) : value;
    st->noise_prev = noise;
    st->trial_ticks++;
    icoac_priv_copy_n(st->x_prev, scaled, n);
    st->has_prev = 1;
    return 1;
}

int icoac_priv_rl_tick(const icoac_config_t *cfg, icoac_priv_state_t *st, const icoac_real_t s[ICOAC_MAX_INPUTS],
                       const icoac_real_t scaled[ICOAC_MAX_INPUTS], int terminal, icoac_output_t *out, int n,
                       const icoac_real_t *given)
{
    if (n == ICOAC_CARTPOLE_INPUTS) {
        return rl_tick(cfg, st, s, scaled, terminal, out, ICOAC_CARTPOLE_INPUTS, given);
    }
    return rl_tick(cfg, st, s, scaled, terminal, out, ICOAC_MAX_INPUTS, given);
}
