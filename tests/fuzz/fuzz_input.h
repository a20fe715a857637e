/* SPDX-License-Identifier: Apache-2.0 */
/* Decoding of fuzz input bytes, shared by the fuzz targets (format: fuzz_controller.c).
 * The reader yields zero bytes once the input is used up, so every input decodes. */
#ifndef ICOAC_FUZZ_INPUT_H
#define ICOAC_FUZZ_INPUT_H

#include <stddef.h>
#include <stdint.h>

#include "icoac/icoac.h"

typedef struct {
    const uint8_t *data;
    size_t size;
    size_t pos;
} fz_reader_t;

/* Selector ranges of one value: table index, bounded value or raw bits (fuzz_input.c). */
#define FZ_VALUE_TABLE 28   /* selectors 0..27: the special-value table */
#define FZ_VALUE_BOUNDED 8  /* 28..35: int16 / 32768 * scale, scale 1e-3 .. 1e4 */
#define FZ_VALUE_RAW 4      /* 36..39: raw bits of the value, little endian */
#define FZ_VALUE_KINDS (FZ_VALUE_TABLE + FZ_VALUE_BOUNDED + FZ_VALUE_RAW)

/* Config mutation field indices, struct order, an index per array entry (fuzz_input.c): one per
 * scalar row of icoac_params.h, ICOAC_MAX_INPUTS / ICOAC_MAX_RULES per array row (79). */
#define FZ_COUNT_scalar 1
#define FZ_COUNT_inputs ICOAC_MAX_INPUTS
#define FZ_COUNT_rules ICOAC_MAX_RULES
#define FZ_COUNT_ROW(group, field, type, dim, check, unit, min, max, def, modes, tier, status, doc) +FZ_COUNT_##dim
#define FZ_CONFIG_FIELDS (0 ICOAC_PARAMS(FZ_COUNT_ROW))
#define FZ_PRIOR_FIELDS 42  /* 0..5 mean, 6 + 6i + j cov[i][j] (ICOAC_MAX_INPUTS 6) */

void fz_reader_init(fz_reader_t *r, const uint8_t *data, size_t size);
int fz_done(const fz_reader_t *r);
uint8_t fz_u8(fz_reader_t *r);
uint64_t fz_u64(fz_reader_t *r);
/* Copy the next n bytes over dst; fewer when the input ends (the rest of dst is kept). */
void fz_overlay(fz_reader_t *r, void *dst, size_t n);

icoac_real_t fz_real(fz_reader_t *r); /* selector byte (mod FZ_VALUE_KINDS), then its bytes */
double fz_double(fz_reader_t *r);     /* same, with the double table */
int32_t fz_i32(fz_reader_t *r);       /* selector (mod 8): 0, 1, 2, -1, INT32_MAX, INT32_MIN, 3, raw */
int64_t fz_i64(fz_reader_t *r);       /* selector (mod 12): see fuzz_input.c, 11 = raw */

/* Config section: a mode byte c; c odd: the raw bytes of icoac_config_t (the nested layout,
 * padding included) over the default; c even: the default with (c >> 1) % 8 mutations (field
 * byte % FZ_CONFIG_FIELDS, value). */
void fz_config(fz_reader_t *r, icoac_config_t *cfg);
/* The same section laid over *cfg instead of the default (raw bytes or mutations of cfg). */
void fz_config_over(fz_reader_t *r, icoac_config_t *cfg);
/* Every field of a and b bitwise equal (NaN equals the same NaN; padding ignored). */
int fz_config_equal(const icoac_config_t *a, const icoac_config_t *b);

/* Prior section: a byte p; p % 3 == 0: NULL, 1: mean 0 and cov I (6 x 6), 2: that with (p / 3) % 8
 * mutations (field byte b: (b & 127) % 42, b & 128 also sets cov[j][i]; value). */
const icoac_prior_t *fz_prior(fz_reader_t *r, icoac_prior_t *prior);

#if defined(ICOAC_FUZZ_SIM) && ICOAC_FUZZ_SIM
#include "icoac_sim/icoac_sim.h"

/* Run section (fuzz_model.c): a mode byte b; b odd: the raw bytes of
 * icoac_sim_run_t over icoac_sim_run_default; b even: (b >> 1) % 4 mutations, each a field byte
 * (% 3: 0 max_trials, 1 success_steps as int64; 2 init_velocity_noise as double) and a value. */
void fz_run(fz_reader_t *r, icoac_sim_run_t *run);
/* Threads byte of a grid: % 16: 13-14 two threads, 15 -1 (refused), else 1. */
int32_t fz_threads(fz_reader_t *r);
#endif

#endif /* ICOAC_FUZZ_INPUT_H */
