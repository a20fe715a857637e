/* libFuzzer target of the controller API (icoac.h). One source, three executables:
 * fuzz_controller (float library icoac), fuzz_controller_double (icoac_double) and
 * fuzz_controller_fast_exp (icoac_fast_exp, the microcontroller presets' float math).
 *
 * Input format, read front to back (a byte past the end reads as 0):
 *   config  mode byte c. c odd: sizeof(icoac_config_t) raw bytes laid over
 *           icoac_config_default (fewer when the input ends; the nested layout of icoac.h,
 *           padding included). c even: the default with (c >> 1) % 8 mutations, each a field
 *           byte (% 26; indices in struct order, table in fuzz_input.c: 0 mode,
 *           1-4 policy.input_range, 5 policy.clip_inputs, 6 policy.gain, 7 policy.reflex_mode,
 *           8 policy.reflex_force, 9 policy.zone_theta, 10 policy.zone_x, 11 ico.rate,
 *           12 ico.timing, 13 critic.rate, 14 critic.discount, 15 critic.td_clip,
 *           16-19 critic.range, 20 critic.threshold, 21 actor.noise_std, 22 actor.scale,
 *           23 actor.forgetting, 24 actor.reflex, 25 actor.act_with_sample) and a value.
 *   prior   byte p. p % 3: 0 NULL, 1 mean 0 and cov I, 2 that with (p / 3) % 8 mutations,
 *           each a field byte b ((b & 127) % 20: 0-3 mean[i], 4 + 4i + j cov[i][j];
 *           b & 128 also sets cov[j][i]) and a value.
 *   seed    8 bytes, little endian.
 *   ops     until the input ends, at most FZ_MAX_OPS ops and FZ_MAX_STEPS steps. Op byte o:
 *           o & 3: 0 or 1 step, 2 terminal step (ICOAC_INPUT_TERMINAL), 3 icoac_reset.
 *           A step runs ((o >> 2) & 7) + 1 times; o & 0x20 keeps the previous s, else the
 *           4 values s[0..3] follow. Bits 6 and 7 are ignored.
 *   value   real: selector byte k % 40. k < 28: special value (table in fuzz_input.c: 0, -0,
 *           1e-39, 1e-45, REAL_MIN, REAL_MAX, 1e30, 1e-20, NaN, +Inf, -Inf, -1, 1, 0.5,
 *           -1e30, 1e38, -REAL_MAX, 2, 0.25, 2.4, -2.4, 10, 1e-5, -0.25, REAL_TRUE_MIN,
 *           0.999, 1e10, -1e-39); 28-35: int16 (2 bytes) / 32768 * {1e-3, 1e-2, 0.1, 1, 3,
 *           10, 100, 1e4}[k - 28]; 36-39: raw bits, sizeof(icoac_real_t) bytes.
 *           int32 switch: selector % 8: 0, 1, 2, -1, INT32_MAX, INT32_MIN, 3, 7 = 4 raw bytes.
 * tests/fuzz/gen_corpus.py writes the committed corpus in this format.
 *
 * Contract, checked after every call (abort on violation):
 *   init    status = icoac_config_check when that fails, else icoac_prior_check when that
 *           fails, else OK or ICOAC_ERR_NUMERIC; icoac_config_check_field agrees and names a
 *           field exactly when the check fails; the checks accept only documented ranges of
 *           the groups the mode uses (ICO: policy, ico; RL: policy, critic, actor); after OK
 *           the learned state (w, |w|, cov, w_act, v) is finite and holds the prior.
 *   step    returned status = out.status, a known status; non-finite s <=> NONFINITE_INPUT;
 *           the counters count the tick and its rejection.
 *           OK: every real output written (out is NaN-filled before the call) and finite, the
 *           learned state finite, cov exactly symmetric, out.weight_norm = |w|; force and
 *           noise 0 on a terminal step; q 0 in RL; value, td_error, noise, cov_trace 0 in ICO;
 *           with learn = 0 (the no-learning control) w, |w|, cov and v unchanged.
 *           Not OK: every real output 0 but weight_norm = |w|, learned state bytewise
 *           unchanged (the spare kept-unit slot and covariance buffer are scratch, not learned).
 *   reset   OK or ICOAC_ERR_NUMERIC; w, |w|, cov, v unchanged; w_act = w unless acting with a
 *           sample (and always after ICOAC_ERR_NUMERIC); w_act finite after OK.
 */
#include <math.h>
#include <stdint.h>
#include <string.h>

#include "fuzz_check.h"
#include "fuzz_input.h"
#include "icoac/icoac.h"
#include "icoac_state.h" /* private layout of the state (firmware/src) */

#define FZ_MAX_OPS 128
#define FZ_MAX_STEPS 512
#define N ICOAC_N_INPUTS
/* C will not pass T[4][4] as const T[4][4] implicitly. */
#define CONST_MAT(m) ((const icoac_real_t(*)[N])(m))

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

/* Everything the controller learns; compared bytewise around each call (no padding). */
typedef struct {
    icoac_real_t w[N];
    icoac_real_t weight_norm;
    icoac_real_t cov[N][N];
    icoac_real_t v[ICOAC_CRITIC_UNITS];
    icoac_real_t w_act[N];
} learned_t;

static void learned_take(const icoac_state_t *state, learned_t *l)
{
    const icoac_priv_state_t *st = icoac_priv_state_c(state);
    memcpy(l->w, st->w, sizeof l->w);
    l->weight_norm = st->weight_norm;
    memcpy(l->cov, icoac_priv_cov_c(st), sizeof l->cov);
    memcpy(l->v, st->v, sizeof l->v);
    memcpy(l->w_act, st->w_act, sizeof l->w_act);
}

static icoac_counters_t counters_of(const icoac_state_t *state)
{
    icoac_counters_t c;
    FZ_CHECK(icoac_get_counters(state, &c) == ICOAC_OK, "icoac_get_counters failed on an initialised state");
    return c;
}

static int finite_n(const icoac_real_t *p, int n)
{
    int i;
    for (i = 0; i < n; ++i) {
        if (!isfinite(p[i])) {
            return 0;
        }
    }
    return 1;
}

/* Name of the first non-finite learned field, or NULL. */
static const char *learned_nonfinite(const learned_t *l, int with_w_act)
{
    int i;
    if (!finite_n(l->w, N)) {
        return "w";
    }
    if (!isfinite(l->weight_norm)) {
        return "weight_norm";
    }
    for (i = 0; i < N; ++i) {
        if (!finite_n(l->cov[i], N)) {
            return "cov";
        }
    }
    if (!finite_n(l->v, ICOAC_CRITIC_UNITS)) {
        return "v";
    }
    if (with_w_act && !finite_n(l->w_act, N)) {
        return "w_act";
    }
    return 0;
}

/* Name of the first learned field that differs, or NULL (w_act only if with_w_act). */
static const char *learned_changed(const learned_t *a, const learned_t *b, int with_w_act)
{
    if (memcmp(a->w, b->w, sizeof a->w) != 0) {
        return "w";
    }
    if (memcmp(&a->weight_norm, &b->weight_norm, sizeof a->weight_norm) != 0) {
        return "weight_norm";
    }
    if (memcmp(a->cov, b->cov, sizeof a->cov) != 0) {
        return "cov";
    }
    if (memcmp(a->v, b->v, sizeof a->v) != 0) {
        return "v";
    }
    if (with_w_act && memcmp(a->w_act, b->w_act, sizeof a->w_act) != 0) {
        return "w_act";
    }
    return 0;
}

/* cov[i][j] == cov[j][i] (exact; what icoac_prior_check asks of a prior). */
static int cov_symmetric(const icoac_real_t cov[N][N])
{
    int i;
    int j;
    for (i = 0; i < N; ++i) {
        for (j = i + 1; j < N; ++j) {
            if (cov[i][j] != cov[j][i]) {
                return 0;
            }
        }
    }
    return 1;
}

static int known_status(int32_t status)
{
    return strcmp(icoac_status_str((icoac_status_t)status), "unknown status") != 0;
}

static const char *status_name(int32_t status)
{
    return icoac_status_str((icoac_status_t)status);
}

static int finite_positive(icoac_real_t v)
{
    return isfinite(v) && v > ICOAC_R(0.0);
}

static int finite_non_negative(icoac_real_t v)
{
    return isfinite(v) && v >= ICOAC_R(0.0);
}

static int is_flag(int32_t v)
{
    return v == 0 || v == 1;
}

/* Necessary conditions from the documented ranges (icoac.h) of the groups a mode uses (ICO:
 * policy and ico; RL: policy, critic and actor; the others are ignored); the check may be
 * stricter. */
static int policy_documented(const icoac_policy_config_t *p)
{
    int i;
    for (i = 0; i < N; ++i) {
        if (!finite_positive(p->input_range[i])) {
            return 0;
        }
    }
    return is_flag(p->clip_inputs) && finite_non_negative(p->gain) &&
           (p->reflex_mode == ICOAC_REFLEX_UNIT || p->reflex_mode == ICOAC_REFLEX_GAIN) &&
           finite_non_negative(p->reflex_force) && finite_positive(p->zone_theta) && finite_positive(p->zone_x);
}

static int ico_documented(const icoac_ico_config_t *ico)
{
    return finite_non_negative(ico->rate) && ico->rate <= ICOAC_R(1.0) &&
           (ico->timing == ICOAC_ICO_TIMING_CODE || ico->timing == ICOAC_ICO_TIMING_LITERAL);
}

static int critic_documented(const icoac_critic_config_t *c)
{
    int i;
    for (i = 0; i < N; ++i) {
        if (!finite_positive(c->range[i])) {
            return 0;
        }
    }
    return finite_non_negative(c->rate) && c->rate <= ICOAC_R(10.0) && finite_non_negative(c->discount) &&
           c->discount <= ICOAC_R(1.0) && finite_positive(c->td_clip) && finite_non_negative(c->threshold) &&
           c->threshold < ICOAC_R(1.0);
}

static int actor_documented(const icoac_actor_config_t *a)
{
    return finite_positive(a->noise_std) && finite_non_negative(a->scale) && finite_positive(a->forgetting) &&
           a->forgetting <= ICOAC_R(1.0) && is_flag(a->reflex) && is_flag(a->act_with_sample);
}

static int config_documented(const icoac_config_t *cfg)
{
    if (cfg->learn != 0 && cfg->learn != 1) {
        return 0;
    }
    if (cfg->mode == ICOAC_MODE_ICO) {
        return policy_documented(&cfg->policy) && ico_documented(&cfg->ico);
    }
    return cfg->mode == ICOAC_MODE_RL && policy_documented(&cfg->policy) && critic_documented(&cfg->critic) &&
           actor_documented(&cfg->actor);
}

/* The fields icoac_config_check_field may name, with their group's status and the mode that
 * checks them. */
typedef struct {
    const char *name;
    int32_t status;
    int32_t mode; /* -1: every mode */
} named_field_t;

static const named_field_t named_fields[] = {
    {"mode", ICOAC_ERR_BAD_MODE, -1},
    {"learn", ICOAC_ERR_BAD_MODE, -1},
    {"policy.input_range[0]", ICOAC_ERR_BAD_SCALE, -1},
    {"policy.input_range[1]", ICOAC_ERR_BAD_SCALE, -1},
    {"policy.input_range[2]", ICOAC_ERR_BAD_SCALE, -1},
    {"policy.input_range[3]", ICOAC_ERR_BAD_SCALE, -1},
    {"policy.clip_inputs", ICOAC_ERR_BAD_MODE, -1},
    {"policy.gain", ICOAC_ERR_BAD_GAIN, -1},
    {"policy.reflex_mode", ICOAC_ERR_BAD_MODE, -1},
    {"policy.reflex_force", ICOAC_ERR_BAD_GAIN, -1},
    {"policy.zone_theta", ICOAC_ERR_BAD_ZONE, -1},
    {"policy.zone_x", ICOAC_ERR_BAD_ZONE, -1},
    {"ico.rate", ICOAC_ERR_BAD_ICO_RATE, ICOAC_MODE_ICO},
    {"ico.timing", ICOAC_ERR_BAD_MODE, ICOAC_MODE_ICO},
    {"critic.rate", ICOAC_ERR_BAD_CRITIC, ICOAC_MODE_RL},
    {"critic.discount", ICOAC_ERR_BAD_CRITIC, ICOAC_MODE_RL},
    {"critic.td_clip", ICOAC_ERR_BAD_CRITIC, ICOAC_MODE_RL},
    {"critic.range[0]", ICOAC_ERR_BAD_CRITIC, ICOAC_MODE_RL},
    {"critic.range[1]", ICOAC_ERR_BAD_CRITIC, ICOAC_MODE_RL},
    {"critic.range[2]", ICOAC_ERR_BAD_CRITIC, ICOAC_MODE_RL},
    {"critic.range[3]", ICOAC_ERR_BAD_CRITIC, ICOAC_MODE_RL},
    {"critic.threshold", ICOAC_ERR_BAD_CRITIC, ICOAC_MODE_RL},
    {"actor.noise_std", ICOAC_ERR_BAD_ACTOR, ICOAC_MODE_RL},
    {"actor.scale", ICOAC_ERR_BAD_ACTOR, ICOAC_MODE_RL},
    {"actor.forgetting", ICOAC_ERR_BAD_ACTOR, ICOAC_MODE_RL},
    {"actor.reflex", ICOAC_ERR_BAD_MODE, ICOAC_MODE_RL},
    {"actor.act_with_sample", ICOAC_ERR_BAD_MODE, ICOAC_MODE_RL},
};

/* field is a known name with this status, of a group cfg's mode checks. */
static int field_matches(const icoac_config_t *cfg, const char *field, int32_t status)
{
    size_t i;
    for (i = 0; i < sizeof named_fields / sizeof named_fields[0]; ++i) {
        const named_field_t *f = &named_fields[i];
        if (strcmp(f->name, field) == 0) {
            return f->status == status && (f->mode < 0 || f->mode == cfg->mode);
        }
    }
    return 0;
}

/* Finite mean, finite exactly symmetric covariance with a positive diagonal. */
static int prior_documented(const icoac_prior_t *prior)
{
    int i;
    for (i = 0; i < N; ++i) {
        if (!isfinite(prior->mean[i]) || !finite_n(prior->cov[i], N) || !(prior->cov[i][i] > ICOAC_R(0.0))) {
            return 0;
        }
    }
    return cov_symmetric(prior->cov);
}

static int output_finite(const icoac_output_t *out)
{
    return isfinite(out->force) && isfinite(out->z) && isfinite(out->reflex) && isfinite(out->penalty) &&
           isfinite(out->q) && isfinite(out->weight_norm) && isfinite(out->value) &&
           isfinite(out->td_error) && isfinite(out->noise) && isfinite(out->cov_trace);
}

/* Every real output 0 but weight_norm, which is the (unchanged) |w|. */
static int output_cleared(const icoac_output_t *out, icoac_real_t weight_norm)
{
    return out->force == ICOAC_R(0.0) && out->z == ICOAC_R(0.0) && out->reflex == ICOAC_R(0.0) &&
           out->penalty == ICOAC_R(0.0) && out->q == ICOAC_R(0.0) && out->weight_norm == weight_norm &&
           out->value == ICOAC_R(0.0) && out->td_error == ICOAC_R(0.0) && out->noise == ICOAC_R(0.0) &&
           out->cov_trace == ICOAC_R(0.0);
}

static void check_step(const icoac_config_t *cfg, icoac_state_t *state, const icoac_input_t *in, int op)
{
    learned_t before;
    learned_t after;
    icoac_output_t out;
    icoac_counters_t counted;
    icoac_counters_t counted_after;
    const char *field;
    int32_t status;
    int finite_in = 1;
    int i;
    learned_take(state, &before);
    counted = counters_of(state);
    memset(&out, 0xff, sizeof out); /* NaN in every real: each must be written */
    status = (int32_t)icoac_step(cfg, state, in, &out);
    learned_take(state, &after);
    counted_after = counters_of(state);
    for (i = 0; i < N; ++i) {
        finite_in = finite_in && isfinite(in->s[i]);
    }
    FZ_CHECK(counted_after.ticks == counted.ticks + 1u &&
                 counted_after.nonfinite == counted.nonfinite + (status == ICOAC_ERR_NONFINITE_INPUT ? 1u : 0u) &&
                 counted_after.numeric_faults == counted.numeric_faults + (status == ICOAC_ERR_NUMERIC ? 1u : 0u),
             "op %d: status %d, counters %u/%u/%u -> %u/%u/%u", op, (int)status, (unsigned)counted.ticks,
             (unsigned)counted.nonfinite, (unsigned)counted.numeric_faults, (unsigned)counted_after.ticks,
             (unsigned)counted_after.nonfinite, (unsigned)counted_after.numeric_faults);
    FZ_CHECK(status == out.status, "op %d: icoac_step returned %d, out.status %d", op, (int)status,
             (int)out.status);
    FZ_CHECK(known_status(status), "op %d: icoac_step returned unknown status %d", op, (int)status);
    FZ_CHECK(finite_in == (status != ICOAC_ERR_NONFINITE_INPUT),
             "op %d: s = (%g, %g, %g, %g) gave status %d (%s)", op, (double)in->s[0], (double)in->s[1],
             (double)in->s[2], (double)in->s[3], (int)status, status_name(status));
    if (status == ICOAC_OK) {
        FZ_CHECK(output_finite(&out),
                 "op %d: ICOAC_OK with a non-finite output: force %g z %g reflex %g penalty %g q %g "
                 "|w| %g value %g td %g noise %g trace %g; s = (%g, %g, %g, %g)",
                 op, (double)out.force, (double)out.z, (double)out.reflex, (double)out.penalty,
                 (double)out.q, (double)out.weight_norm, (double)out.value, (double)out.td_error,
                 (double)out.noise, (double)out.cov_trace, (double)in->s[0], (double)in->s[1],
                 (double)in->s[2], (double)in->s[3]);
        field = learned_nonfinite(&after, 1);
        FZ_CHECK(field == 0, "op %d: ICOAC_OK left a non-finite learned %s (w = %g %g %g %g, |w| %g)", op,
                 field, (double)after.w[0], (double)after.w[1], (double)after.w[2], (double)after.w[3],
                 (double)after.weight_norm);
        FZ_CHECK(cov_symmetric(CONST_MAT(after.cov)), "op %d: covariance not exactly symmetric", op);
        field = cfg->learn ? 0 : learned_changed(&before, &after, 0);
        FZ_CHECK(field == 0, "op %d: learn = 0, but the tick changed the learned %s", op, field);
        FZ_CHECK((in->flags & ICOAC_INPUT_TERMINAL) == 0u || (out.force == ICOAC_R(0.0) && out.noise == ICOAC_R(0.0)),
                 "op %d: terminal step with force %g noise %g", op, (double)out.force, (double)out.noise);
        FZ_CHECK(out.weight_norm == after.weight_norm, "op %d: out.weight_norm %g, state |w| %g", op,
                 (double)out.weight_norm, (double)after.weight_norm);
        if (cfg->mode == ICOAC_MODE_RL) {
            FZ_CHECK(out.q == ICOAC_R(0.0), "op %d: RL step with q %g", op, (double)out.q);
        } else {
            FZ_CHECK(out.value == ICOAC_R(0.0) && out.td_error == ICOAC_R(0.0) && out.noise == ICOAC_R(0.0) &&
                         out.cov_trace == ICOAC_R(0.0),
                     "op %d: ICO step with value %g td %g noise %g trace %g", op, (double)out.value,
                     (double)out.td_error, (double)out.noise, (double)out.cov_trace);
        }
    } else {
        FZ_CHECK(output_cleared(&out, after.weight_norm),
                 "op %d: status %d (%s) with an output not cleared: force %g z %g reflex %g penalty %g q %g "
                 "|w| %g (state %g) value %g td %g noise %g trace %g",
                 op, (int)status, status_name(status), (double)out.force, (double)out.z, (double)out.reflex,
                 (double)out.penalty, (double)out.q, (double)out.weight_norm, (double)after.weight_norm,
                 (double)out.value, (double)out.td_error, (double)out.noise, (double)out.cov_trace);
        field = learned_changed(&before, &after, 1);
        FZ_CHECK(field == 0, "op %d: status %d (%s) changed the learned %s", op, (int)status,
                 status_name(status), field);
    }
}

static void check_reset(const icoac_config_t *cfg, icoac_state_t *state, int op)
{
    const int sampled = cfg->mode == ICOAC_MODE_RL && cfg->actor.act_with_sample;
    learned_t before;
    learned_t after;
    const char *field;
    int32_t status;
    learned_take(state, &before);
    status = (int32_t)icoac_reset(cfg, state);
    learned_take(state, &after);
    FZ_CHECK(status == ICOAC_OK || status == ICOAC_ERR_NUMERIC, "op %d: icoac_reset returned %d (%s)", op,
             (int)status, status_name(status));
    field = learned_changed(&before, &after, 0);
    FZ_CHECK(field == 0, "op %d: icoac_reset changed the learned %s", op, field);
    if (status == ICOAC_OK) {
        FZ_CHECK(finite_n(after.w_act, N), "op %d: icoac_reset OK with a non-finite w_act", op);
    }
    if (!sampled || status == ICOAC_ERR_NUMERIC) {
        FZ_CHECK(memcmp(after.w_act, after.w, sizeof after.w) == 0,
                 "op %d: icoac_reset (%s, sampled %d) left w_act != w", op, status_name(status), sampled);
    }
}

/* An uninitialised (zeroed) state and NULL pointers are refused with a zero force. */
static void check_refusals(const icoac_config_t *cfg)
{
    icoac_state_t blank;
    icoac_input_t in;
    icoac_output_t out;
    icoac_prior_t posterior;
    int32_t status;
    memset(&blank, 0, sizeof blank);
    memset(&in, 0, sizeof in);
    memset(&out, 0xff, sizeof out);
    status = (int32_t)icoac_step(cfg, &blank, &in, &out);
    FZ_CHECK(status == ICOAC_ERR_NOT_INITIALISED && out.status == status && out.force == ICOAC_R(0.0),
             "icoac_step on a zeroed state: %d / out.status %d / force %g", (int)status, (int)out.status,
             (double)out.force);
    FZ_CHECK(icoac_reset(cfg, &blank) == ICOAC_ERR_NOT_INITIALISED, "icoac_reset on a zeroed state");
    FZ_CHECK(icoac_get_posterior(&blank, &posterior) == ICOAC_ERR_NOT_INITIALISED,
             "icoac_get_posterior on a zeroed state");
    {
        icoac_counters_t counters;
        FZ_CHECK(icoac_get_counters(&blank, &counters) == ICOAC_ERR_NOT_INITIALISED,
                 "icoac_get_counters on a zeroed state");
    }
    memset(&out, 0xff, sizeof out);
    status = (int32_t)icoac_step(0, &blank, &in, &out);
    FZ_CHECK(status == ICOAC_ERR_NULL && out.status == status && out.force == ICOAC_R(0.0),
             "icoac_step(NULL config): %d", (int)status);
    FZ_CHECK(icoac_config_check(0) == ICOAC_ERR_NULL && icoac_prior_check(0) == ICOAC_ERR_NULL &&
                 icoac_init(cfg, 0, 0, 0u) == ICOAC_ERR_NULL,
             "NULL argument not refused with ICOAC_ERR_NULL");
}

/* icoac_init against the checks; returns 1 when the state is initialised. */
static int check_init(const icoac_config_t *cfg, icoac_state_t *state, const icoac_prior_t *prior, uint64_t seed)
{
    const int32_t config_status = (int32_t)icoac_config_check(cfg);
    int32_t prior_status = ICOAC_OK;
    learned_t l;
    const char *field;
    const char *bad_field = "not written";
    int32_t status;
    int i;
    FZ_CHECK(known_status(config_status), "icoac_config_check returned unknown status %d", (int)config_status);
    FZ_CHECK((int32_t)icoac_config_check_field(cfg, &bad_field) == config_status,
             "icoac_config_check_field disagrees with icoac_config_check (%d)", (int)config_status);
    FZ_CHECK((config_status == ICOAC_OK) == (bad_field == 0) &&
                 (bad_field == 0 || field_matches(cfg, bad_field, config_status)),
             "icoac_config_check_field: status %d (%s) with field %s (mode %d)", (int)config_status,
             status_name(config_status), bad_field != 0 ? bad_field : "NULL", (int)cfg->mode);
    FZ_CHECK(config_status != ICOAC_OK || config_documented(cfg),
             "icoac_config_check accepted a configuration outside the documented ranges");
    if (prior != 0) {
        prior_status = (int32_t)icoac_prior_check(prior);
        FZ_CHECK(prior_status == ICOAC_OK || prior_status == ICOAC_ERR_BAD_PRIOR,
                 "icoac_prior_check returned %d", (int)prior_status);
        FZ_CHECK(prior_status != ICOAC_OK || prior_documented(prior),
                 "icoac_prior_check accepted a non-finite or asymmetric prior");
    }
    memset(state, 0, sizeof *state);
    status = (int32_t)icoac_init(cfg, state, prior, seed);
    if (config_status != ICOAC_OK) {
        FZ_CHECK(status == config_status, "icoac_init returned %d, icoac_config_check %d", (int)status,
                 (int)config_status);
        return 0;
    }
    if (prior_status != ICOAC_OK) {
        FZ_CHECK(status == prior_status, "icoac_init returned %d, icoac_prior_check %d", (int)status,
                 (int)prior_status);
        return 0;
    }
    FZ_CHECK(status == ICOAC_OK || status == ICOAC_ERR_NUMERIC, "icoac_init returned %d (%s) for a valid setup",
             (int)status, status_name(status));
    learned_take(state, &l);
    field = learned_nonfinite(&l, status == ICOAC_OK);
    FZ_CHECK(field == 0, "icoac_init (%s) left a non-finite learned %s (w = %g %g %g %g)", status_name(status),
             field, (double)l.w[0], (double)l.w[1], (double)l.w[2], (double)l.w[3]);
    for (i = 0; i < N; ++i) {
        int j;
        FZ_CHECK(l.w[i] == (prior != 0 ? prior->mean[i] : ICOAC_R(0.0)), "icoac_init: w[%d] is not the prior mean",
                 i);
        for (j = 0; j < N; ++j) {
            const icoac_real_t expect = prior != 0 ? prior->cov[i][j] : (i == j ? ICOAC_R(1.0) : ICOAC_R(0.0));
            FZ_CHECK(l.cov[i][j] == expect, "icoac_init: cov[%d][%d] is not the prior's", i, j);
        }
    }
    return 1;
}

static void check_posterior(const icoac_state_t *state)
{
    icoac_prior_t posterior;
    FZ_CHECK(icoac_get_posterior(state, &posterior) == ICOAC_OK, "icoac_get_posterior failed");
    FZ_CHECK(memcmp(posterior.mean, icoac_priv_state_c(state)->w, sizeof posterior.mean) == 0 &&
                 memcmp(posterior.cov, icoac_priv_cov_c(icoac_priv_state_c(state)), sizeof posterior.cov) == 0,
             "icoac_get_posterior differs from the state");
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    fz_reader_t r;
    icoac_config_t cfg;
    icoac_prior_t prior_storage;
    const icoac_prior_t *prior;
    icoac_state_t state; /* on the stack: ASan reports overruns past it */
    icoac_input_t in;
    uint64_t seed;
    int ops;
    int steps = 0;
    int i;

    fz_reader_init(&r, data, size);
    fz_config(&r, &cfg);
    prior = fz_prior(&r, &prior_storage);
    seed = fz_u64(&r);
    check_refusals(&cfg);
    if (!check_init(&cfg, &state, prior, seed)) {
        return 0;
    }
    memset(&in, 0, sizeof in);
    for (ops = 0; ops < FZ_MAX_OPS && steps < FZ_MAX_STEPS && !fz_done(&r); ++ops) {
        const uint8_t op = fz_u8(&r);
        int repeat;
        if ((op & 3u) == 3u) {
            check_reset(&cfg, &state, ops);
            continue;
        }
        if ((op & 0x20u) == 0u) {
            for (i = 0; i < N; ++i) {
                in.s[i] = fz_real(&r);
            }
        }
        in.flags = (op & 3u) == 2u ? ICOAC_INPUT_TERMINAL : 0u;
        for (repeat = ((op >> 2) & 7) + 1; repeat > 0 && steps < FZ_MAX_STEPS; --repeat, ++steps) {
            check_step(&cfg, &state, &in, ops);
        }
    }
    check_posterior(&state);
    return 0;
}
