/* SPDX-License-Identifier: Apache-2.0 */
/* libFuzzer target of corrupted controller states: raw bytes in the state's configuration copy,
 * or in the whole state, behind a valid header word, through every entry point of icoac.h.
 * One source, three executables: fuzz_state (float library icoac), fuzz_state_double
 * (icoac_double) and fuzz_state_mcu (float, ICOAC_FAST_EXP and the sparse critic kernel: the
 * microcontroller presets' build, whose kept-unit list the host libraries do not use).
 *
 * The promise under test: no configuration reaching icoac_step or icoac_reset,
 * checked or not, and no state content, corrupted or not, makes the library read or write
 * outside the objects it was given or reach undefined behaviour. ASan and UBSan (every report
 * fatal) watch the library; the state, input, output and every result buffer are heap blocks of
 * their exact size, allocated per input, so a one-byte overrun of any of them is reported.
 *
 * Input format, read front to back (a byte past the end reads as 0):
 *   kind    byte k: k & 1 == 0 raw configuration (A), 1 raw state (B).
 *   setup   mode byte m; a config section (fuzz_controller.c) whose mode is replaced by m % 3
 *           (when icoac_config_check refuses it: the default configuration of that mode); a
 *           prior section (fuzz_controller.c; NULL when icoac_init refuses it); seed, 8 bytes;
 *           warm-up byte w: (w >> 5) + 1 trials of (w & 31) ticks on a fixed in-range
 *           trajectory, each trial but the last ended by a terminal tick and icoac_reset.
 *   A       a config section laid over the state's configuration copy, unchecked: c odd,
 *           sizeof(icoac_config_t) raw bytes (fewer when the input ends); c even, field
 *           mutations of the copy (fz_config_over).
 *   B       byte f: f & 1 header word ICOAC_PRIV_STATE_ENDED, else ICOAC_PRIV_STATE_MAGIC. f & 2:
 *           sizeof(icoac_state_t) raw bytes over the whole state (fewer when the input ends: the
 *           rest stays as the warm-up left it); else (f >> 2) patches. Then the header word.
 *   patch   byte p % 46. 0-42 a named field of icoac_state.h (table state_fields below, in
 *           layout order; gen_corpus.py mirrors it), an element byte (% the field's element
 *           count), then the value: int32 / uint32 as an int32 switch, uint8
 *           a byte, uint64 8 bytes, real a real value (fuzz_controller.c). 43: the header word
 *           (a byte: odd ENDED, even MAGIC). 44: a config section over the configuration copy.
 *           45: raw bytes: offset (2 bytes, little endian, % sizeof(icoac_state_t)), length byte
 *           n, n bytes (clipped at the state's end); the header word is kept.
 *   ops     until the input ends, at most FZ_STATE_MAX_OPS ops and FZ_STATE_MAX_STEPS ticks.
 *           Op byte o, o % 8: 0 tick, 1 terminal tick (ICOAC_INPUT_TERMINAL), each run
 *           ((o >> 3) & 7) + 1 times, on the previous s when o & 0x40, else n real values
 *           follow (n: the setup's task.n_inputs); o & 0x80: ICOAC_INPUT_LATE, and a real value
 *           for in.reflex follows; 2 icoac_reset; 3 icoac_retune with a config section laid over the state's
 *           configuration (icoac_get_config; o & 0x08 set: over the setup configuration
 *           instead); 4 icoac_retune with the setup configuration (valid); 5 icoac_get_posterior,
 *           icoac_get_counters and icoac_get_config; 6 a config section over the configuration
 *           copy (no check); 7 one patch.
 *
 * Contract, checked after every call (abort on violation):
 *   every call  returns a named icoac_status_t; the getters, icoac_reset and icoac_retune
 *           return OK or one of their documented errors only (below).
 *   step    out.status = the return value; out.weight_norm is the state's |w| (bitwise); on
 *           any error every other real output is 0 (so the force). Header ENDED: ICOAC_ERR_TRIAL_ENDED,
 *           the state bytewise unchanged but counters.ticks + 1. Header MAGIC: OK, NUMERIC or
 *           CORRUPT_STATE for a finite s, NONFINITE_INPUT for a non-finite one; counters.ticks + 1,
 *           nonfinite and numeric_faults counting their statuses; the configuration copy never
 *           changes; on an error nothing is committed (the state bytewise unchanged but the
 *           counters and the scratch a tick stages into: the spare covariance buffer, the spare
 *           kept-unit list and the staged batch shift); an OK terminal tick turns the header to
 *           ENDED, any other tick leaves it.
 *   reset   OK or ICOAC_ERR_CORRUPT_STATE. CORRUPT_STATE: the state bytewise unchanged; required when
 *           the state breaks a documented invariant (configuration copy refused by
 *           icoac_config_check, cov_slot, active_slot or rng.has_spare not 0 or 1, a non-finite
 *           w, |w|, covariance in force or spare normal; search: a count outside
 *           [0, 15], a non-finite factor, a prior variance not positive and finite). OK: the
 *           header MAGIC, has_prev 0, trial_ticks 0, batch sums 0, the configuration copy
 *           passes icoac_config_check and is unchanged, the slots 0 or 1, the counters and the
 *           learned values (w, |w|, covariances, critic weights, search record) unchanged,
 *           task.input_sign / policy.input_range re-derived. From then on, until the state is
 *           patched again, every tick with a finite s returns OK or ICOAC_ERR_NUMERIC (TRIAL_ENDED after an
 *           OK terminal tick), and OK with a finite force.
 *   retune  icoac_config_check's status when it refuses the configuration, else
 *           ICOAC_ERR_RETUNE_MODE when its mode is not the copy's, else OK. An error leaves the
 *           state bytewise unchanged; OK sets the copy (icoac_get_config returns the new
 *           configuration), re-derives task.input_sign / policy.input_range and (search) the
 *           floors, and leaves every other byte of the state as it was.
 *   getters OK on any state with a valid header word; the posterior is w and the covariance
 *           in force (cov_buffer[cov_slot & 1]), the counters and the configuration those of
 *           the state; the state bytewise unchanged.
 *   Nothing hangs (libFuzzer -timeout): every loop bound taken from the state is bounded.
 * Known violation (open; corpus repro-rl-spare-normal-huge): icoac_reset accepts any finite
 * rng.spare_normal, so an RL tick can return OK with an infinite force. ICOAC_FUZZ_KNOWN=
 * spare-normal in the environment passes exactly that case, for long runs that look for others.
 */
#include <math.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "fuzz_check.h"
#include "fuzz_input.h"
#include "icoac/icoac.h"
#include "icoac_state.h" /* private layout of the state (firmware/src) */

#define FZ_STATE_MAX_OPS 512
#define FZ_STATE_MAX_STEPS 2048
#define N ICOAC_MAX_INPUTS /* the library's vectors; a task uses the first task.n_inputs */

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

/* ---- the named fields of icoac_priv_state_t a patch can set ---- */

typedef struct {
    const char *name;
    size_t offset; /* of element 0 */
    size_t size;   /* of one element */
    int count;     /* elements */
    int per;       /* elements per outer block (the two kept-unit lists), else count */
    size_t outer;  /* bytes between outer blocks */
    char kind;     /* 'i' int32, 'u' uint32, 'b' uint8, 'q' uint64, 'r' real */
} state_field_t;

#define FZ_MEMBER_SIZE(member) sizeof(((icoac_priv_state_t *)0)->member)
#define FZ_FIELD(name, member, elem_size, kind) \
    {name, offsetof(icoac_priv_state_t, member), elem_size, (int)(FZ_MEMBER_SIZE(member) / (elem_size)), \
     (int)(FZ_MEMBER_SIZE(member) / (elem_size)), 0, kind}
/* A member of both kept-unit lists: active[0] then active[1]. */
#define FZ_ACTIVE(name, member, elem_size, kind) \
    {name, offsetof(icoac_priv_state_t, active[0].member), elem_size, \
     2 * (int)(FZ_MEMBER_SIZE(active[0].member) / (elem_size)), \
     (int)(FZ_MEMBER_SIZE(active[0].member) / (elem_size)), sizeof(icoac_priv_critic_active_t), kind}

#define R sizeof(icoac_real_t)

static const state_field_t state_fields[] = {
    FZ_FIELD("has_prev", has_prev, 4, 'i'),
    FZ_FIELD("grid.n", grid.n, 1, 'b'),
    FZ_FIELD("grid.split", grid.split, 1, 'b'),
    FZ_FIELD("grid.shape", grid.shape, 1, 'b'),
    FZ_FIELD("inv_range", inv_range, R, 'r'),
    FZ_FIELD("w", w, R, 'r'),
    FZ_FIELD("weight_norm", weight_norm, R, 'r'),
    FZ_FIELD("w_act", w_act, R, 'r'),
    FZ_FIELD("cov_slot", cov_slot, 4, 'i'),
    FZ_FIELD("active_slot", active_slot, 4, 'i'),
    FZ_FIELD("x_prev", x_prev, R, 'r'),
    FZ_FIELD("penalty_prev", penalty_prev, R, 'r'),
    FZ_FIELD("value_prev", value_prev, R, 'r'),
    FZ_FIELD("noise_prev", noise_prev, R, 'r'),
    FZ_FIELD("trial_ticks", trial_ticks, 4, 'u'),
    FZ_FIELD("rng.state", rng.state, 8, 'q'),
    FZ_FIELD("rng.increment", rng.increment, 8, 'q'),
    FZ_FIELD("rng.spare_normal", rng.spare_normal, R, 'r'),
    FZ_FIELD("rng.has_spare", rng.has_spare, 4, 'i'),
    FZ_FIELD("counters", counters, 4, 'u'),
    FZ_FIELD("cov_buffer", cov_buffer, R, 'r'),
    FZ_ACTIVE("active.sparse.product", sparse.product, R, 'r'),
    FZ_ACTIVE("active.sparse.index", sparse.index, 1, 'b'),
    FZ_ACTIVE("active.sparse.cells", sparse.cells, 1, 'b'),
    FZ_ACTIVE("active.sparse.rows", sparse.rows, 1, 'b'),
    FZ_ACTIVE("active.sparse.stride", sparse.stride, 1, 'b'),
    FZ_ACTIVE("active.dense.product", dense.product, R, 'r'),
    FZ_ACTIVE("active.dense.cell_begin", dense.cell_begin, 1, 'b'),
    FZ_ACTIVE("active.dense.cell_end", dense.cell_end, 1, 'b'),
    FZ_ACTIVE("active.dense.rows", dense.rows, 1, 'b'),
    FZ_ACTIVE("active.dense.stride", dense.stride, 1, 'b'),
    FZ_FIELD("v", v, R, 'r'),
    FZ_FIELD("batch.info", batch.info, R, 'r'),
    FZ_FIELD("batch.shift", batch.shift, R, 'r'),
    FZ_FIELD("batch.staged_shift", batch.staged_shift, R, 'r'),
    FZ_FIELD("search.w", search.w, R, 'r'),
    FZ_FIELD("search.ticks", search.ticks, 4, 'u'),
    FZ_FIELD("search.lower", search.lower, R, 'r'),
    FZ_FIELD("search.floor", search.floor, R, 'r'),
    FZ_FIELD("search.prior_var", search.prior_var, R, 'r'),
    FZ_FIELD("search.count", search.count, 4, 'i'),
};

#define FZ_STATE_FIELDS ((int)(sizeof state_fields / sizeof state_fields[0]))
#define FZ_PATCH_HEADER FZ_STATE_FIELDS
#define FZ_PATCH_CONFIG (FZ_STATE_FIELDS + 1)
#define FZ_PATCH_RAW (FZ_STATE_FIELDS + 2)
#define FZ_PATCH_KINDS (FZ_STATE_FIELDS + 3)
ICOAC_STATIC_ASSERT(sizeof state_fields / sizeof state_fields[0] == 41, fz_state_field_count);

/* The task's inputs as the library bounds the copy's n_inputs (whatever the copy holds). */
static int inputs_of(const icoac_config_t *cfg)
{
    return (uint32_t)cfg->task.n_inputs <= (uint32_t)N ? (int)cfg->task.n_inputs : N;
}

/* ---- one input's objects: heap blocks of their exact size ---- */

typedef struct {
    icoac_state_t *state;
    icoac_input_t *in;
    icoac_output_t *out;
    icoac_prior_t *posterior;
    icoac_counters_t *counters;
    icoac_config_t *got; /* icoac_get_config's result */
    icoac_config_t *next; /* a configuration given to icoac_retune */
    icoac_config_t setup; /* the valid configuration of icoac_init */
    int validated;        /* icoac_reset returned OK and nothing was patched since */
    int op;
} run_t;

/* The state's bytes before the call being checked, and an expected image. */
static icoac_state_t before;
static icoac_state_t expect;

static const icoac_priv_state_t *st_of(const run_t *run)
{
    return icoac_priv_state_c(run->state);
}

static int known_status(int32_t status)
{
    return strcmp(icoac_status_str((icoac_status_t)status), "unknown status") != 0;
}

static const char *status_name(int32_t status)
{
    return icoac_status_str((icoac_status_t)status);
}

/* a and b the same value: bitwise, or both NaN (a NaN's payload may depend on operand order). */
static int same_real(icoac_real_t a, icoac_real_t b)
{
    return (isnan(a) && isnan(b)) || memcmp(&a, &b, sizeof a) == 0;
}

static int state_unchanged(const run_t *run)
{
    return memcmp(&before, run->state, sizeof before) == 0;
}

/* ---- decoding ---- */

/* Tick j of the warm-up trajectory: inside every zone and input range of the defaults. */
static void warmup_s(int j, icoac_real_t s[N])
{
    s[0] = ICOAC_R(0.05) * (icoac_real_t)(j % 9) - ICOAC_R(0.2);
    s[1] = ICOAC_R(0.1) * (icoac_real_t)(j % 5) - ICOAC_R(0.2);
    s[2] = ICOAC_R(0.01) * (icoac_real_t)(j % 7) - ICOAC_R(0.03);
    s[3] = ICOAC_R(0.05) * (icoac_real_t)(j % 3) - ICOAC_R(0.05);
}

static void patch_field(fz_reader_t *r, icoac_state_t *state, const state_field_t *f)
{
    const int index = fz_u8(r) % f->count;
    unsigned char *p = (unsigned char *)state + f->offset + (size_t)(index / f->per) * f->outer +
                       (size_t)(index % f->per) * f->size;
    switch (f->kind) {
    case 'i':
    case 'u': {
        const int32_t v = fz_i32(r);
        memcpy(p, &v, sizeof v);
        break;
    }
    case 'b':
        *p = fz_u8(r);
        break;
    case 'q': {
        const uint64_t v = fz_u64(r);
        memcpy(p, &v, sizeof v);
        break;
    }
    default: {
        const icoac_real_t v = fz_real(r);
        memcpy(p, &v, sizeof v);
        break;
    }
    }
}

/* One patch (format above); the header word stays as it was unless the patch sets it. */
static void patch(fz_reader_t *r, icoac_state_t *state)
{
    icoac_priv_state_t *st = icoac_priv_state(state);
    const uint32_t magic = st->magic;
    const int kind = fz_u8(r) % FZ_PATCH_KINDS;
    if (kind < FZ_STATE_FIELDS) {
        patch_field(r, state, &state_fields[kind]);
    } else if (kind == FZ_PATCH_HEADER) {
        st->magic = (fz_u8(r) & 1u) ? ICOAC_PRIV_STATE_ENDED : ICOAC_PRIV_STATE_MAGIC;
        return;
    } else if (kind == FZ_PATCH_CONFIG) {
        fz_config_over(r, &st->config);
    } else {
        const size_t low = fz_u8(r);
        const size_t offset = (low | (size_t)fz_u8(r) << 8) % sizeof *state;
        size_t n = fz_u8(r);
        if (n > sizeof *state - offset) {
            n = sizeof *state - offset;
        }
        fz_overlay(r, (unsigned char *)state + offset, n);
    }
    st->magic = magic;
}

/* ---- checks of each entry point ---- */

static void check_getters(run_t *run)
{
    const icoac_priv_state_t *st = st_of(run);
    int32_t status;
    memcpy(&before, run->state, sizeof before);
    status = (int32_t)icoac_get_posterior(run->state, run->posterior);
    FZ_CHECK(status == ICOAC_OK, "op %d: icoac_get_posterior returned %d (%s)", run->op, (int)status,
             status_name(status));
    FZ_CHECK(memcmp(run->posterior->mean, st->w, sizeof st->w) == 0 &&
                 memcmp(run->posterior->cov, st->cov_buffer[st->cov_slot & 1], sizeof run->posterior->cov) == 0,
             "op %d: icoac_get_posterior is not w and the covariance in force (cov_slot %d)", run->op,
             (int)st->cov_slot);
    status = (int32_t)icoac_get_counters(run->state, run->counters);
    FZ_CHECK(status == ICOAC_OK && memcmp(run->counters, &st->counters, sizeof st->counters) == 0,
             "op %d: icoac_get_counters returned %d (%s) or other counters", run->op, (int)status,
             status_name(status));
    status = (int32_t)icoac_get_config(run->state, run->got);
    FZ_CHECK(status == ICOAC_OK && fz_config_equal(run->got, &st->config),
             "op %d: icoac_get_config returned %d (%s) or another configuration", run->op, (int)status,
             status_name(status));
    FZ_CHECK(state_unchanged(run), "op %d: a getter changed the state", run->op);
}

/* Every output real 0 but weight_norm, the state's |w|. */
static int output_cleared(const icoac_output_t *out)
{
    return out->force == ICOAC_R(0.0) && out->z == ICOAC_R(0.0) && out->reflex == ICOAC_R(0.0) &&
           out->penalty == ICOAC_R(0.0) && out->q == ICOAC_R(0.0) && out->value == ICOAC_R(0.0) &&
           out->td_error == ICOAC_R(0.0) && out->noise == ICOAC_R(0.0) && out->cov_trace == ICOAC_R(0.0);
}

/* The state bytewise as before the tick but for the counters and the scratch a tick stages into
 * (chosen by the slots before the tick, as the library masks them). */
static int unchanged_but_scratch(const run_t *run)
{
    const icoac_priv_state_t *st = st_of(run);
    icoac_priv_state_t *ex = icoac_priv_state(&expect);
    const int cov_spare = (icoac_priv_state_c(&before)->cov_slot & 1) ^ 1;
    const int active_spare = (icoac_priv_state_c(&before)->active_slot & 1) ^ 1;
    memcpy(&expect, &before, sizeof expect);
    ex->counters = st->counters;
    memcpy(ex->cov_buffer[cov_spare], st->cov_buffer[cov_spare], sizeof ex->cov_buffer[0]);
    memcpy(&ex->active[active_spare], &st->active[active_spare], sizeof ex->active[0]);
    memcpy(ex->batch.staged_shift, st->batch.staged_shift, sizeof ex->batch.staged_shift);
    return memcmp(&expect, run->state, sizeof expect) == 0;
}

/* ICOAC_FUZZ_KNOWN=spare-normal (environment) lets a long run look past one known violation:
 * icoac_reset accepts any finite rng.spare_normal, and the RL tick that draws a huge one as its
 * noise returns ICOAC_OK with a non-finite force. Only that case passes: an OK tick whose noise
 * is not finite, drawn from a spare normal the state held before the tick. Off by default. */
static int known_spare_normal(const run_t *run, const icoac_priv_state_t *was)
{
    static int allowed = -1;
    if (allowed < 0) {
        const char *known = getenv("ICOAC_FUZZ_KNOWN");
        allowed = known != 0 && strstr(known, "spare-normal") != 0;
    }
    return allowed && was->rng.has_spare == 1 && !isfinite(run->out->noise) && isfinite(was->rng.spare_normal);
}

static int32_t check_step(run_t *run)
{
    const icoac_priv_state_t *st = st_of(run);
    const icoac_priv_state_t *was = icoac_priv_state_c(&before);
    const int terminal = (run->in->flags & ICOAC_INPUT_TERMINAL) != 0u;
    /* what the tick reads: the copy's n inputs, and a sensor's reflex on a late tick */
    const icoac_config_t *copy = &st->config;
    const int finite_in = fz_all_finite(run->in->s, inputs_of(copy)) &&
                          (copy->task.late_source == ICOAC_LATE_RULES || (run->in->flags & ICOAC_INPUT_LATE) == 0u ||
                           isfinite(run->in->reflex));
    int32_t status;
    int ended;
    memcpy(&before, run->state, sizeof before);
    ended = was->magic == ICOAC_PRIV_STATE_ENDED;
    memset(run->out, 0xff, sizeof *run->out); /* NaN in every real: each must be written */
    status = (int32_t)icoac_step(run->state, run->in, run->out);
    FZ_CHECK(known_status(status), "op %d: icoac_step returned unknown status %d", run->op, (int)status);
    FZ_CHECK(run->out->status == status, "op %d: icoac_step returned %d, out.status %d", run->op, (int)status,
             (int)run->out->status);
    FZ_CHECK(memcmp(&run->out->weight_norm, &st->weight_norm, sizeof st->weight_norm) == 0,
             "op %d: status %d: out.weight_norm %g, the state's |w| %g", run->op, (int)status,
             (double)run->out->weight_norm, (double)st->weight_norm);
    FZ_CHECK(status == ICOAC_OK || output_cleared(run->out),
             "op %d: status %d (%s) with force %g z %g reflex %g penalty %g q %g value %g td %g noise %g trace %g",
             run->op, (int)status, status_name(status), (double)run->out->force, (double)run->out->z,
             (double)run->out->reflex, (double)run->out->penalty, (double)run->out->q, (double)run->out->value,
             (double)run->out->td_error, (double)run->out->noise, (double)run->out->cov_trace);
    if (ended) {
        memcpy(&expect, &before, sizeof expect);
        icoac_priv_state(&expect)->counters.ticks++;
        FZ_CHECK(status == ICOAC_ERR_TRIAL_ENDED, "op %d: a tick on an ended trial returned %d (%s)", run->op,
                 (int)status, status_name(status));
        FZ_CHECK(memcmp(&expect, run->state, sizeof expect) == 0,
                 "op %d: ICOAC_ERR_TRIAL_ENDED changed the state beyond counters.ticks", run->op);
        return status;
    }
    FZ_CHECK(finite_in ? (status == ICOAC_OK || status == ICOAC_ERR_NUMERIC || status == ICOAC_ERR_CORRUPT_STATE)
                       : status == ICOAC_ERR_NONFINITE_INPUT,
             "op %d: a tick with %s s = (%g, %g, %g, %g) returned %d (%s)", run->op, finite_in ? "finite" : "non-finite",
             (double)run->in->s[0], (double)run->in->s[1], (double)run->in->s[2], (double)run->in->s[3], (int)status,
             status_name(status));
    FZ_CHECK(st->counters.ticks == was->counters.ticks + 1u &&
                 st->counters.nonfinite == was->counters.nonfinite + (status == ICOAC_ERR_NONFINITE_INPUT ? 1u : 0u) &&
                 st->counters.numeric_faults ==
                     was->counters.numeric_faults + (status == ICOAC_ERR_NUMERIC ? 1u : 0u),
             "op %d: status %d, counters %u/%u/%u -> %u/%u/%u", run->op, (int)status, (unsigned)was->counters.ticks,
             (unsigned)was->counters.nonfinite, (unsigned)was->counters.numeric_faults, (unsigned)st->counters.ticks,
             (unsigned)st->counters.nonfinite, (unsigned)st->counters.numeric_faults);
    FZ_CHECK(memcmp(&st->config, &was->config, sizeof st->config) == 0,
             "op %d: icoac_step changed the configuration copy", run->op);
    FZ_CHECK(st->magic == (terminal && status == ICOAC_OK ? ICOAC_PRIV_STATE_ENDED : ICOAC_PRIV_STATE_MAGIC),
             "op %d: status %d, terminal %d: header word 0x%08x", run->op, (int)status, terminal,
             (unsigned)st->magic);
    if (status != ICOAC_OK) {
        FZ_CHECK(unchanged_but_scratch(run), "op %d: icoac_step returned %d (%s) and committed to the state", run->op,
                 (int)status, status_name(status));
    }
    if (run->validated && finite_in) {
        /* a state icoac_reset accepted, not patched since */
        FZ_CHECK(status == ICOAC_OK || status == ICOAC_ERR_NUMERIC,
                 "op %d: a tick on a state icoac_reset accepted returned %d (%s)", run->op, (int)status,
                 status_name(status));
        FZ_CHECK(status != ICOAC_OK || isfinite(run->out->force) || known_spare_normal(run, was),
                 "op %d: ICOAC_OK with force %g (z %g noise %g reflex %g) on a state icoac_reset accepted; "
                 "s = (%g, %g, %g, %g)",
                 run->op, (double)run->out->force, (double)run->out->z, (double)run->out->noise,
                 (double)run->out->reflex, (double)run->in->s[0], (double)run->in->s[1], (double)run->in->s[2],
                 (double)run->in->s[3]);
    }
    return status;
}

/* A state icoac_reset must refuse: the invariants the library documents for its state. */
static const char *must_refuse(const icoac_priv_state_t *st)
{
    int i;
    if (icoac_config_check(&st->config) != ICOAC_OK) {
        return "configuration copy";
    }
    if ((st->cov_slot != 0 && st->cov_slot != 1) || (st->active_slot != 0 && st->active_slot != 1) ||
        (st->rng.has_spare != 0 && st->rng.has_spare != 1)) {
        return "slot or has_spare";
    }
    /* the critic weights are not checked (icoac_lifecycle.c): a non-finite one makes the ticks
     * that read it ICOAC_ERR_NUMERIC */
    if (!fz_all_finite(st->w, N) || !isfinite(st->weight_norm) || !fz_all_finite(&st->cov_buffer[st->cov_slot][0][0], N * N) ||
        !isfinite(st->rng.spare_normal)) {
        return "learned value";
    }
    if (st->config.mode != ICOAC_MODE_SEARCH) {
        return 0;
    }
    if (st->search.count < 0 || st->search.count >= ICOAC_SEARCH_BATCH_MAX ||
        !fz_all_finite(&st->search.lower[0][0], N * N)) {
        return "search count or factor";
    }
    for (i = 0; i < inputs_of(&st->config); ++i) {
        if (!(st->search.prior_var[i] > ICOAC_R(0.0)) || !isfinite(st->search.prior_var[i])) {
            return "search prior variance";
        }
    }
    return 0;
}

static int32_t check_reset(run_t *run)
{
    const icoac_priv_state_t *st = st_of(run);
    const icoac_priv_state_t *was = icoac_priv_state_c(&before);
    const char *bad;
    int32_t status;
    int i;
    memcpy(&before, run->state, sizeof before);
    bad = must_refuse(was);
    status = (int32_t)icoac_reset(run->state);
    FZ_CHECK(status == ICOAC_OK || status == ICOAC_ERR_CORRUPT_STATE, "op %d: icoac_reset returned %d (%s)", run->op,
             (int)status, status_name(status));
    if (status == ICOAC_ERR_CORRUPT_STATE) {
        FZ_CHECK(state_unchanged(run), "op %d: icoac_reset returned ICOAC_ERR_CORRUPT_STATE and changed the state",
                 run->op);
        run->validated = 0;
        return status;
    }
    FZ_CHECK(bad == 0, "op %d: icoac_reset accepted a state with a bad %s", run->op, bad);
    /* what the library's invariants promise from now on */
    FZ_CHECK(icoac_config_check(&st->config) == ICOAC_OK &&
                 memcmp(&st->config, &was->config, sizeof st->config) == 0,
             "op %d: icoac_reset OK with a configuration copy refused or changed", run->op);
    FZ_CHECK(st->magic == ICOAC_PRIV_STATE_MAGIC && st->has_prev == 0 && st->trial_ticks == 0u &&
                 (st->cov_slot == 0 || st->cov_slot == 1) && (st->active_slot == 0 || st->active_slot == 1) &&
                 (st->rng.has_spare == 0 || st->rng.has_spare == 1),
             "op %d: icoac_reset OK left header 0x%08x has_prev %d trial_ticks %u slots %d/%d has_spare %d", run->op,
             (unsigned)st->magic, (int)st->has_prev, (unsigned)st->trial_ticks, (int)st->cov_slot,
             (int)st->active_slot, (int)st->rng.has_spare);
    {
        static const icoac_priv_actor_batch_t zero_batch;
        FZ_CHECK(memcmp(st->batch.info, zero_batch.info, sizeof zero_batch.info) == 0 &&
                     memcmp(st->batch.shift, zero_batch.shift, sizeof zero_batch.shift) == 0,
                 "op %d: icoac_reset OK kept the batch sums", run->op);
    }
    FZ_CHECK(st->config.mode != ICOAC_MODE_SEARCH || (st->search.count >= 0 && st->search.count < ICOAC_SEARCH_BATCH_MAX),
             "op %d: icoac_reset OK with %d search trials recorded", run->op, (int)st->search.count);
    FZ_CHECK(memcmp(st->w, was->w, sizeof st->w) == 0 && memcmp(&st->weight_norm, &was->weight_norm, sizeof st->weight_norm) == 0 &&
                 memcmp(st->cov_buffer, was->cov_buffer, sizeof st->cov_buffer) == 0 &&
                 memcmp(st->v, was->v, sizeof st->v) == 0 && memcmp(&st->counters, &was->counters, sizeof st->counters) == 0 &&
                 memcmp(st->search.w, was->search.w, sizeof st->search.w) == 0 &&
                 memcmp(st->search.ticks, was->search.ticks, sizeof st->search.ticks) == 0 &&
                 st->search.count == was->search.count &&
                 memcmp(st->search.lower, was->search.lower, sizeof st->search.lower) == 0,
             "op %d: icoac_reset OK changed a learned value or the counters", run->op);
    for (i = 0; i < N; ++i) {
        const icoac_real_t sign = st->config.task.input_sign[i] < 0 ? ICOAC_R(-1.0) : ICOAC_R(1.0);
        const icoac_real_t inv =
            i < st->config.task.n_inputs ? sign / st->config.policy.input_range[i] : ICOAC_R(0.0);
        FZ_CHECK(memcmp(&st->inv_range[i], &inv, sizeof inv) == 0, "op %d: icoac_reset: inv_range[%d] = %g, %g/%g",
                 run->op, i, (double)st->inv_range[i], (double)sign, (double)st->config.policy.input_range[i]);
    }
    run->validated = 1;
    return status;
}

static void check_retune(run_t *run, const icoac_config_t *next)
{
    const icoac_priv_state_t *st = st_of(run);
    const icoac_priv_state_t *was = icoac_priv_state_c(&before);
    icoac_priv_state_t *ex = icoac_priv_state(&expect);
    int32_t config_status;
    int32_t status;
    int i;
    memcpy(&before, run->state, sizeof before);
    config_status = (int32_t)icoac_config_check(next);
    status = (int32_t)icoac_retune(run->state, next);
    if (config_status != ICOAC_OK) {
        FZ_CHECK(status == config_status, "op %d: icoac_retune returned %d, icoac_config_check %d", run->op,
                 (int)status, (int)config_status);
    } else if (next->mode != was->config.mode || next->task.n_inputs != was->config.task.n_inputs ||
               memcmp(next->critic.units, was->config.critic.units, sizeof next->critic.units) != 0) {
        FZ_CHECK(status == ICOAC_ERR_RETUNE_MODE,
                 "op %d: icoac_retune from mode %d to %d (or of the inputs or critic grid) returned %d (%s)", run->op,
                 (int)was->config.mode, (int)next->mode, (int)status, status_name(status));
    } else {
        FZ_CHECK(status == ICOAC_OK, "op %d: icoac_retune of a valid configuration of mode %d returned %d (%s)",
                 run->op, (int)next->mode, (int)status, status_name(status));
    }
    if (status != ICOAC_OK) {
        FZ_CHECK(state_unchanged(run), "op %d: icoac_retune returned %d (%s) and changed the state", run->op,
                 (int)status, status_name(status));
        return;
    }
    FZ_CHECK(icoac_get_config(run->state, run->got) == ICOAC_OK && fz_config_equal(run->got, next),
             "op %d: icoac_get_config after icoac_retune is not the new configuration", run->op);
    for (i = 0; i < N; ++i) {
        const icoac_real_t sign = next->task.input_sign[i] < 0 ? ICOAC_R(-1.0) : ICOAC_R(1.0);
        const icoac_real_t inv = i < next->task.n_inputs ? sign / next->policy.input_range[i] : ICOAC_R(0.0);
        FZ_CHECK(same_real(st->inv_range[i], inv), "op %d: icoac_retune: inv_range[%d] = %g, %g/%g", run->op, i,
                 (double)st->inv_range[i], (double)sign, (double)next->policy.input_range[i]);
        if (next->mode == ICOAC_MODE_SEARCH) {
            const icoac_real_t floor = next->search.floor * (was->search.prior_var[i] * next->search.cov_scale);
            FZ_CHECK(same_real(st->search.floor[i], floor), "op %d: icoac_retune: search floor[%d] = %g, expected %g",
                     run->op, i, (double)st->search.floor[i], (double)floor);
        }
    }
    memcpy(&expect, &before, sizeof expect);
    memcpy(&ex->config, &st->config, sizeof ex->config);
    memcpy(ex->inv_range, st->inv_range, sizeof ex->inv_range);
    memcpy(ex->search.floor, st->search.floor, sizeof ex->search.floor);
    memcpy(&ex->grid, &st->grid, sizeof ex->grid); /* derived again from the same grid and mode */
    ex->batch_token = 0u; /* a batch that had loaded the state loads it again */
    FZ_CHECK(memcmp(&expect, run->state, sizeof expect) == 0,
             "op %d: icoac_retune changed more than the configuration and what it derives", run->op);
}

/* ---- setup ---- */

/* A valid initialised state of the input's mode, then its warm-up; returns 0 when the setup
 * cannot be made (a rounding-lost search prior and no fallback: never with a NULL prior). */
static int setup(fz_reader_t *r, run_t *run)
{
    const int mode = fz_u8(r) % 3;
    icoac_prior_t prior_storage;
    const icoac_prior_t *prior;
    uint64_t seed;
    uint8_t warmup;
    int32_t status;
    int trials;
    int trial;
    int j;
    fz_config(r, &run->setup);
    run->setup.mode = mode;
    if (icoac_config_check(&run->setup) != ICOAC_OK) {
        icoac_config_default(&run->setup);
        run->setup.mode = mode;
    }
    prior = fz_prior(r, &prior_storage);
    seed = fz_u64(r);
    status = (int32_t)icoac_init(&run->setup, run->state, prior, seed);
    if (status != ICOAC_OK) {
        status = (int32_t)icoac_init(&run->setup, run->state, 0, seed);
    }
    FZ_CHECK(status == ICOAC_OK, "icoac_init of a valid configuration (mode %d) returned %d (%s)", mode, (int)status,
             status_name(status));
    warmup = fz_u8(r);
    trials = (warmup >> 5) + 1;
    for (trial = 0; trial < trials; ++trial) {
        for (j = 0; j < (warmup & 31); ++j) {
            warmup_s(j + 7 * trial, run->in->s);
            run->in->flags = 0u;
            status = (int32_t)icoac_step(run->state, run->in, run->out);
            FZ_CHECK(status == ICOAC_OK || status == ICOAC_ERR_NUMERIC, "warm-up tick %d of trial %d returned %d (%s)",
                     j, trial, (int)status, status_name(status));
        }
        if (trial + 1 < trials) {
            run->in->flags = ICOAC_INPUT_TERMINAL;
            status = (int32_t)icoac_step(run->state, run->in, run->out);
            FZ_CHECK(status == ICOAC_OK || status == ICOAC_ERR_NUMERIC, "warm-up terminal tick returned %d (%s)",
                     (int)status, status_name(status));
            status = (int32_t)icoac_reset(run->state);
            FZ_CHECK(status == ICOAC_OK, "warm-up reset returned %d (%s)", (int)status, status_name(status));
        }
    }
    return 1;
}

static void *alloc_exact(size_t n)
{
    void *p = malloc(n);
    FZ_CHECK(p != 0, "out of memory (%zu bytes)", n);
    return p;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    fz_reader_t r;
    run_t run;
    int ops;
    int steps = 0;
    uint8_t kind;
    int i;

    memset(&run, 0, sizeof run);
    run.state = alloc_exact(sizeof *run.state);
    run.in = alloc_exact(sizeof *run.in);
    run.out = alloc_exact(sizeof *run.out);
    run.posterior = alloc_exact(sizeof *run.posterior);
    run.counters = alloc_exact(sizeof *run.counters);
    run.got = alloc_exact(sizeof *run.got);
    run.next = alloc_exact(sizeof *run.next);
    memset(run.in, 0, sizeof *run.in);
    run.op = -1;

    fz_reader_init(&r, data, size);
    kind = fz_u8(&r);
    if (setup(&r, &run)) {
        icoac_priv_state_t *st = icoac_priv_state(run.state);
        if ((kind & 1u) == 0u) {
            fz_config_over(&r, &st->config); /* A: raw configuration bytes, no check */
        } else {
            const uint8_t f = fz_u8(&r); /* B: raw state bytes behind a valid header */
            if (f & 2u) {
                fz_overlay(&r, run.state, sizeof *run.state);
            } else {
                for (i = f >> 2; i > 0; --i) {
                    patch(&r, run.state);
                }
            }
            st->magic = (f & 1u) ? ICOAC_PRIV_STATE_ENDED : ICOAC_PRIV_STATE_MAGIC;
        }
        for (ops = 0; ops < FZ_STATE_MAX_OPS && steps < FZ_STATE_MAX_STEPS && !fz_done(&r); ++ops) {
            const uint8_t op = fz_u8(&r);
            run.op = ops;
            switch (op % 8) {
            case 0:
            case 1: {
                int repeat;
                if ((op & 0x40u) == 0u) {
                    /* the setup task's n inputs (the rest keep their values) */
                    for (i = 0; i < inputs_of(&run.setup); ++i) {
                        run.in->s[i] = fz_real(&r);
                    }
                }
                if (op & 0x80u) {
                    run.in->reflex = fz_real(&r);
                }
                run.in->flags = ((op % 8) == 1 ? ICOAC_INPUT_TERMINAL : 0u) | ((op & 0x80u) ? ICOAC_INPUT_LATE : 0u);
                for (repeat = ((op >> 3) & 7) + 1; repeat > 0 && steps < FZ_STATE_MAX_STEPS; --repeat, ++steps) {
                    (void)check_step(&run);
                }
                break;
            }
            case 2:
                (void)check_reset(&run);
                break;
            case 3:
                if (op & 0x08u) {
                    *run.next = run.setup;
                } else {
                    FZ_CHECK(icoac_get_config(run.state, run.next) == ICOAC_OK, "op %d: icoac_get_config failed", ops);
                }
                fz_config_over(&r, run.next);
                check_retune(&run, run.next);
                break;
            case 4:
                *run.next = run.setup;
                check_retune(&run, run.next);
                break;
            case 5:
                check_getters(&run);
                break;
            case 6:
                fz_config_over(&r, &icoac_priv_state(run.state)->config);
                run.validated = 0;
                break;
            default:
                patch(&r, run.state);
                run.validated = 0;
                break;
            }
        }
        check_getters(&run);
    }
    free(run.next);
    free(run.got);
    free(run.counters);
    free(run.posterior);
    free(run.out);
    free(run.in);
    free(run.state);
    return 0;
}
