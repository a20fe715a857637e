/* SPDX-License-Identifier: Apache-2.0 */
/* libFuzzer target of the batch tick (icoac_step_batch) against icoac_step, lane for lane.
 *
 * The promises under test: each lane's status, force and state afterwards (but the batch's
 * stamp) are icoac_step's on a twin state, bit for bit, while the states are reset, retuned or
 * stepped by icoac_step between batch ticks and move between lanes; and whatever bytes the
 * batch's storage or a state holds, a call reads and writes only inside the batch, the states
 * and the call's arrays (ASan and UBSan, every report fatal; every array a heap block of its
 * exact size), returning a named status per lane.
 *
 * Input format, read front to back (a byte past the end reads as 0):
 *   lanes   byte: 1 + byte % 20 lanes.
 *   lane    per lane: mode byte m (m % 3: ICO, RL, search; m & 4: literal ICO timing; m & 8: a
 *           sensor task), a config section (fuzz_controller.c) whose mode, timing and late
 *           source are then set from m (refused by icoac_config_check: the default of that
 *           mode), a prior section and a seed byte; icoac_init of both twins (refused: both
 *           left zero, never initialised).
 *   ops     until the input ends, at most FZ_BATCH_MAX_OPS. Op byte o, o % 8:
 *           0-3 a batch tick: a rotation byte (column c holds lane (c + r) % lanes), then per
 *               lane a flags byte f (f & 3 == 3: terminal; f & 4: ICOAC_INPUT_LATE with a
 *               real reflex) and, when o & 8, n real inputs (else the previous tick's inputs
 *               moved by a small step); 4 icoac_reset of lane (byte % lanes); 5 icoac_retune of
 *               a lane with a config section over its configuration; 6 icoac_step of a lane on
 *               real inputs; 7 raw bytes over the batch's storage (o & 8) or over both twins
 *               of a lane at an offset (2 bytes), n bytes: from then on only the safety
 *               promise is checked, and a batch whose header was overwritten is refused
 *               (ICOAC_ERR_NOT_INITIALISED, no lane written).
 */
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "fuzz_check.h"
#include "fuzz_input.h"
#include "icoac/icoac.h"
#include "icoac_state.h" /* private layout of the state (firmware/src) */

#define FZ_BATCH_MAX_LANES 20
#define FZ_BATCH_MAX_OPS 96
#define N ICOAC_MAX_INPUTS

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

typedef struct {
    icoac_state_t *scalar; /* icoac_step's twin */
    icoac_state_t *batch;  /* the batch's */
    icoac_real_t s[N];     /* the lane's inputs of the last tick */
    int32_t n;             /* its task's inputs (4 when it was refused) */
} fz_lane_t;

static void *alloc_exact(size_t size)
{
    void *p = malloc(size);
    FZ_CHECK(p != NULL, "out of memory");
    return p;
}

/* 1 when two states hold the same bytes but the batch's stamp. */
static int same_state(const icoac_state_t *a, const icoac_state_t *b)
{
    icoac_state_t ca = *a;
    icoac_state_t cb = *b;
    icoac_priv_state(&ca)->batch_token = 0u;
    icoac_priv_state(&cb)->batch_token = 0u;
    return memcmp(&ca, &cb, sizeof ca) == 0;
}

static int named_status(int32_t s)
{
    return (s >= ICOAC_OK && s <= ICOAC_ERR_RETUNE_MODE) || (s >= ICOAC_ERR_BAD_MODE && s <= ICOAC_ERR_BAD_TASK);
}

static void setup_lane(fz_reader_t *r, fz_lane_t *lane)
{
    static const int32_t modes[3] = {ICOAC_MODE_ICO, ICOAC_MODE_RL, ICOAC_MODE_SEARCH};
    const uint8_t m = fz_u8(r);
    icoac_config_t cfg;
    icoac_prior_t prior_storage;
    const icoac_prior_t *prior;
    uint64_t seed;
    fz_config(r, &cfg);
    cfg.mode = modes[m % 3u];
    cfg.ico.timing = (m & 4u) ? ICOAC_ICO_TIMING_LITERAL : ICOAC_ICO_TIMING_CODE;
    cfg.task.late_source = (m & 8u) ? ICOAC_LATE_SENSOR : ICOAC_LATE_RULES;
    if (icoac_config_check(&cfg) != ICOAC_OK) {
        icoac_config_default(&cfg);
        cfg.mode = modes[m % 3u];
    }
    prior = fz_prior(r, &prior_storage);
    seed = fz_u8(r);
    memset(lane->scalar, 0, sizeof *lane->scalar);
    memset(lane->batch, 0, sizeof *lane->batch);
    lane->n = ICOAC_CARTPOLE_INPUTS;
    if (icoac_init(&cfg, lane->scalar, prior, seed) == ICOAC_OK) {
        FZ_CHECK(icoac_init(&cfg, lane->batch, prior, seed) == ICOAC_OK, "init of the twin");
        lane->n = cfg.task.n_inputs;
    } else {
        memset(lane->scalar, 0, sizeof *lane->scalar);
    }
    memset(lane->s, 0, sizeof lane->s);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    fz_reader_t r;
    fz_lane_t lanes[FZ_BATCH_MAX_LANES];
    icoac_batch_t *batch = alloc_exact(sizeof *batch);
    icoac_state_t **states;
    icoac_real_t *s;
    uint32_t *flags;
    icoac_real_t *reflex;
    icoac_real_t *force;
    int32_t *status;
    int n_lanes;
    int faithful = 1; /* no raw bytes laid over a state or the batch yet: compare bit for bit */
    int ops;
    int l;

    fz_reader_init(&r, data, size);
    n_lanes = 1 + fz_u8(&r) % FZ_BATCH_MAX_LANES;
    states = alloc_exact(sizeof *states * (size_t)n_lanes);
    s = alloc_exact(sizeof *s * (size_t)(N * n_lanes));
    flags = alloc_exact(sizeof *flags * (size_t)n_lanes);
    reflex = alloc_exact(sizeof *reflex * (size_t)n_lanes);
    force = alloc_exact(sizeof *force * (size_t)n_lanes);
    status = alloc_exact(sizeof *status * (size_t)n_lanes);
    FZ_CHECK(icoac_batch_init(batch) == ICOAC_OK, "icoac_batch_init");
    for (l = 0; l < n_lanes; ++l) {
        lanes[l].scalar = alloc_exact(sizeof *lanes[l].scalar);
        lanes[l].batch = alloc_exact(sizeof *lanes[l].batch);
        setup_lane(&r, &lanes[l]);
    }
    for (ops = 0; ops < FZ_BATCH_MAX_OPS && !fz_done(&r); ++ops) {
        const uint8_t o = fz_u8(&r);
        const int op = o % 8u;
        if (op <= 3) {
            const int rotation = fz_u8(&r) % n_lanes;
            int c;
            int i;
            icoac_status_t result;
            for (c = 0; c < n_lanes; ++c) {
                fz_lane_t *lane = &lanes[(c + rotation) % n_lanes];
                const uint8_t f = fz_u8(&r);
                for (i = 0; i < N; ++i) {
                    lane->s[i] = (o & 8u) ? fz_real(&r) : lane->s[i] + (icoac_real_t)0.01 * (icoac_real_t)(f & 7u);
                    s[i * n_lanes + c] = lane->s[i];
                }
                flags[c] = ((f & 3u) == 3u ? ICOAC_INPUT_TERMINAL : 0u) | ((f & 4u) ? ICOAC_INPUT_LATE : 0u);
                reflex[c] = (f & 4u) ? fz_real(&r) : (icoac_real_t)0;
                states[c] = lane->batch;
            }
            for (c = 0; c < n_lanes; ++c) {
                force[c] = (icoac_real_t)-7;
                status[c] = -7;
            }
            result = icoac_step_batch(batch, states, n_lanes, s, N, flags, reflex, force, status);
            FZ_CHECK(named_status((int32_t)result), "batch result %d", (int)result);
            if (status[0] == -7) {
                /* the call refused the batch (its bytes overwritten): nothing written */
                FZ_CHECK(!faithful && result == ICOAC_ERR_NOT_INITIALISED, "lane 0 not written, result %d",
                         (int)result);
                for (c = 0; c < n_lanes; ++c) {
                    FZ_CHECK(status[c] == -7 && force[c] == (icoac_real_t)-7, "lane %d written by a refused call", c);
                }
                continue;
            }
            for (c = 0; c < n_lanes; ++c) {
                fz_lane_t *lane = &lanes[(c + rotation) % n_lanes];
                icoac_input_t in;
                icoac_output_t out;
                icoac_status_t expected;
                FZ_CHECK(named_status(status[c]), "lane %d status %d", c, (int)status[c]);
                for (i = 0; i < N; ++i) {
                    in.s[i] = s[i * n_lanes + c];
                }
                in.flags = flags[c];
                in.reflex = reflex[c];
                expected = icoac_step(lane->scalar, &in, &out);
                if (faithful) {
                    FZ_CHECK(status[c] == (int32_t)expected, "lane %d: status %d, icoac_step %d", c, (int)status[c],
                             (int)expected);
                    FZ_CHECK(memcmp(&force[c], &out.force, sizeof out.force) == 0, "lane %d: force %g, icoac_step %g",
                             c, (double)force[c], (double)out.force);
                    FZ_CHECK(same_state(lane->scalar, lane->batch), "lane %d: state differs from icoac_step's", c);
                } else if (status[c] != ICOAC_OK) {
                    FZ_CHECK(force[c] == 0, "lane %d: force %g with status %d", c, (double)force[c], (int)status[c]);
                }
            }
        } else if (op == 7) {
            const size_t offset = (size_t)fz_u8(&r) | ((size_t)fz_u8(&r) << 8);
            const size_t length = fz_u8(&r);
            faithful = 0;
            if (o & 8u) {
                const size_t at = offset % sizeof *batch;
                fz_overlay(&r, (uint8_t *)batch + at, length < sizeof *batch - at ? length : sizeof *batch - at);
            } else {
                fz_lane_t *lane = &lanes[fz_u8(&r) % n_lanes];
                const size_t at = offset % sizeof *lane->batch;
                const size_t n = length < sizeof *lane->batch - at ? length : sizeof *lane->batch - at;
                fz_overlay(&r, (uint8_t *)lane->batch + at, n);
                memcpy((uint8_t *)lane->scalar + at, (uint8_t *)lane->batch + at, n);
            }
        } else {
            fz_lane_t *lane = &lanes[fz_u8(&r) % n_lanes];
            if (op == 4) {
                const icoac_status_t a = icoac_reset(lane->scalar);
                FZ_CHECK(a == icoac_reset(lane->batch) || !faithful, "reset: the twins disagree");
            } else if (op == 5) {
                icoac_config_t cfg;
                icoac_status_t a;
                if (icoac_get_config(lane->scalar, &cfg) != ICOAC_OK) {
                    icoac_config_default(&cfg);
                }
                fz_config_over(&r, &cfg);
                a = icoac_retune(lane->scalar, &cfg);
                FZ_CHECK(a == icoac_retune(lane->batch, &cfg) || !faithful, "retune: the twins disagree");
            } else {
                icoac_input_t in;
                icoac_output_t a;
                icoac_output_t b;
                int i;
                for (i = 0; i < N; ++i) {
                    in.s[i] = lane->s[i] = fz_real(&r);
                }
                in.flags = 0u;
                in.reflex = 0;
                FZ_CHECK(icoac_step(lane->scalar, &in, &a) == icoac_step(lane->batch, &in, &b) || !faithful,
                         "icoac_step: the twins disagree");
            }
            if (faithful) {
                FZ_CHECK(same_state(lane->scalar, lane->batch), "the twins differ after an op outside the batch");
            }
        }
    }
    for (l = 0; l < n_lanes; ++l) {
        free(lanes[l].scalar);
        free(lanes[l].batch);
    }
    free(states);
    free(s);
    free(flags);
    free(reflex);
    free(force);
    free(status);
    free(batch);
    return 0;
}
