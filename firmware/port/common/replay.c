/* SPDX-License-Identifier: Apache-2.0 */
/* Replay of recorded closed-loop sequences; see replay.h. */
#include "replay.h"

#include <string.h>

#include "recorded_inputs.h"

ICOAC_STATIC_ASSERT(sizeof(icoac_real_t) == sizeof(float), replay_needs_float_build);

char *replay_fmt_u32(char *p, uint32_t v)
{
    char tmp[10];
    int n = 0;
    do {
        tmp[n++] = (char)('0' + (v % 10u));
        v /= 10u;
    } while (v != 0u);
    while (n > 0) {
        *p++ = tmp[--n];
    }
    *p = '\0';
    return p;
}

char *replay_fmt_hex32(char *p, uint32_t v)
{
    static const char digits[] = "0123456789abcdef";
    int i;
    for (i = 7; i >= 0; --i) {
        *p++ = digits[(v >> (4 * i)) & 0xfu];
    }
    *p = '\0';
    return p;
}

char *replay_fmt_real(char *p, float v)
{
    uint32_t bits;
    double d = (double)v;
    double ip;
    uint32_t hi, lo;
    memcpy(&bits, &v, sizeof bits);
    p = replay_fmt_hex32(p, bits);
    *p++ = ':';
    if (d != d) {
        memcpy(p, "nan", 4);
        return p + 3;
    }
    if (d < 0.0) {
        *p++ = '-';
        d = -d;
    }
    if (d >= 4e9) {
        memcpy(p, "big", 4);
        return p + 3;
    }
    d = d * 1e6 + 0.5; /* 6 decimals, rounded half up */
    ip = d / 1e6;
    hi = (uint32_t)ip;
    lo = (uint32_t)(d - (double)hi * 1e6);
    if (lo >= 1000000u) {
        lo -= 1000000u;
        hi += 1u;
    }
    p = replay_fmt_u32(p, hi);
    *p++ = '.';
    {
        char frac[12];
        char *e = replay_fmt_u32(frac, lo);
        size_t n = (size_t)(e - frac);
        while (n < 6u) {
            *p++ = '0';
            ++n;
        }
        memcpy(p, frac, (size_t)(e - frac) + 1u);
        p += e - frac;
    }
    return p;
}

static void print_tick(uint32_t i, const icoac_output_t *out)
{
    char line[256];
    char *p = line;
    const float f[10] = {out->force, out->z, out->reflex, out->penalty, out->q,
                         out->weight_norm, out->value, out->td_error, out->noise, out->cov_trace};
    int k;
    *p++ = 'T';
    *p++ = ' ';
    p = replay_fmt_u32(p, i);
    *p++ = ' ';
    p = replay_fmt_u32(p, (uint32_t)out->status);
    for (k = 0; k < 10; ++k) {
        *p++ = ' ';
        p = replay_fmt_real(p, f[k]);
    }
    *p++ = '\n';
    *p = '\0';
    port_puts(line);
}

static void print_posterior(const icoac_state_t *state)
{
    icoac_prior_t post;
    char line[128];
    int i, j;
    (void)icoac_get_posterior(state, &post);
    for (i = 0; i < ICOAC_CARTPOLE_INPUTS; ++i) {
        char *p = line;
        *p++ = 'P';
        *p++ = ' ';
        p = replay_fmt_real(p, post.mean[i]);
        for (j = i; j < ICOAC_CARTPOLE_INPUTS; ++j) {
            *p++ = ' ';
            p = replay_fmt_real(p, post.cov[i][j]);
        }
        *p++ = '\n';
        *p = '\0';
        port_puts(line);
    }
}

void replay_config(icoac_config_t *cfg, int32_t mode)
{
    icoac_config_default(cfg);
    cfg->mode = mode == REPLAY_RL_LITERAL || mode == REPLAY_RL_BATCH ? ICOAC_MODE_RL : mode;
    if (mode == REPLAY_RL_LITERAL) {
        cfg->actor.update = ICOAC_ACTOR_POSTERIOR;
        cfg->actor.explore_ticks = 0;
        cfg->actor.batch = 0;
    } else if (mode == REPLAY_RL_BATCH) {
        cfg->actor.update = ICOAC_ACTOR_POSTERIOR;
        cfg->actor.batch = 1;
    }
    cfg->search.batch = REPLAY_SEARCH_BATCH; /* as gen_inputs.c; search mode only */
}

uint32_t replay_run(replay_controller_t *ctrl, int32_t mode, replay_step_fn step, int verbose)
{
    const replay_tick_t *seq;
    uint32_t n;
    uint64_t seed;
    const char *section;
    icoac_input_t in;
    icoac_output_t out;
    uint32_t i;
    uint32_t trials = 0u;
    uintptr_t sp;

    if (mode == ICOAC_MODE_SEARCH) {
        seq = replay_search;
        n = REPLAY_SEARCH_N;
        seed = REPLAY_SEARCH_SEED;
        section = "S search\n";
    } else if (mode == ICOAC_MODE_RL || mode == REPLAY_RL_LITERAL || mode == REPLAY_RL_BATCH) {
        seq = replay_rl;
        n = REPLAY_RL_N;
        seed = REPLAY_RL_SEED;
        section = mode == REPLAY_RL_LITERAL ? "S rl_literal\n" : (mode == REPLAY_RL_BATCH ? "S rl_batch\n" : "S rl\n");
    } else {
        seq = replay_ico;
        n = REPLAY_ICO_N;
        seed = REPLAY_ICO_SEED;
        section = "S ico\n";
    }
    replay_config(&ctrl->cfg, mode);
    if (icoac_config_check(&ctrl->cfg) != ICOAC_OK ||
        icoac_init(&ctrl->cfg, &ctrl->state, NULL, seed) != ICOAC_OK) {
        port_puts("E init\n");
        return 0u;
    }
    if (verbose) {
        port_puts(section);
    }
    sp = port_read_sp();
    if (!verbose) {
        port_ticks_begin(sp);
    }
    for (i = 0u; i < n; ++i) {
        const int terminal = (seq[i].flags & REPLAY_FLAG_TERMINAL) != 0u;
        uint32_t kind = REPLAY_TICK_PLAIN;
        if (mode == ICOAC_MODE_SEARCH && terminal && ++trials % (uint32_t)REPLAY_SEARCH_BATCH == 0u) {
            kind = REPLAY_TICK_UPDATE;
        }
        if (!verbose) {
            port_tick_start(kind);
        }
        if ((seq[i].flags & REPLAY_FLAG_RESET) != 0u) {
            (void)icoac_reset(&ctrl->state);
        }
        memcpy(in.s, seq[i].s, sizeof seq[i].s); /* the recorded cart-pole inputs; in.s has room for more */
        in.flags = terminal ? ICOAC_INPUT_TERMINAL : 0u;
        (void)step(&ctrl->state, &in, &out);
        if (verbose) {
            print_tick(i, &out);
        } else {
            port_tick_done(kind);
        }
    }
    if (!verbose) {
        port_ticks_end(sp);
    } else {
        print_posterior(&ctrl->state);
    }
    return n;
}
