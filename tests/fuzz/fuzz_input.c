/* SPDX-License-Identifier: Apache-2.0 */
/* Byte reader, special-value tables and the config / prior sections of the fuzz inputs.
 * tests/fuzz/gen_corpus.py writes inputs in this format: keep the tables in step with it. */
#include "fuzz_input.h"

#include <float.h>
#include <math.h>
#include <string.h>

#if defined(ICOAC_REAL_DOUBLE) && ICOAC_REAL_DOUBLE
#define FZ_REAL_MIN DBL_MIN
#define FZ_REAL_MAX DBL_MAX
#define FZ_REAL_TRUE_MIN DBL_TRUE_MIN
#else
#define FZ_REAL_MIN FLT_MIN
#define FZ_REAL_MAX FLT_MAX
#define FZ_REAL_TRUE_MIN FLT_TRUE_MIN
#endif

/* Special values of icoac_real_t; 1e-39 and 1e-45 are float subnormals. */
static const icoac_real_t real_table[FZ_VALUE_TABLE] = {
    ICOAC_R(0.0), ICOAC_R(-0.0), ICOAC_R(1e-39), ICOAC_R(1e-45), FZ_REAL_MIN, FZ_REAL_MAX,
    ICOAC_R(1e30), ICOAC_R(1e-20), (icoac_real_t)NAN, (icoac_real_t)INFINITY,
    -(icoac_real_t)INFINITY, ICOAC_R(-1.0), ICOAC_R(1.0), ICOAC_R(0.5), ICOAC_R(-1e30),
    ICOAC_R(1e38), -FZ_REAL_MAX, ICOAC_R(2.0), ICOAC_R(0.25), ICOAC_R(2.4), ICOAC_R(-2.4),
    ICOAC_R(10.0), ICOAC_R(1e-5), ICOAC_R(-0.25), FZ_REAL_TRUE_MIN, ICOAC_R(0.999),
    ICOAC_R(1e10), ICOAC_R(-1e-39)};

/* Special doubles; 1e-310 is a double subnormal. */
static const double double_table[FZ_VALUE_TABLE] = {
    0.0, -0.0, 1e-310, DBL_TRUE_MIN, DBL_MIN, DBL_MAX, 1e300, 1e30, (double)NAN, (double)INFINITY,
    -(double)INFINITY, -1.0, 1.0, 0.5, -1e30, 1e-20, -DBL_MAX, 2.0, 0.25, 2.4, -2.4, 9.8, 0.01, 1e-6,
    1e6, 0.1, 1e-39, 3.2};

static const double bounded_scale[FZ_VALUE_BOUNDED] = {1e-3, 1e-2, 0.1, 1.0, 3.0, 10.0, 100.0, 1e4};

static const int64_t i64_table[11] = {0, 1, 2, 3, -1, 300, 1000, 100000, INT64_MAX, INT64_MIN, 10};

void fz_reader_init(fz_reader_t *r, const uint8_t *data, size_t size)
{
    r->data = data;
    r->size = size;
    r->pos = 0;
}

int fz_done(const fz_reader_t *r)
{
    return r->pos >= r->size;
}

uint8_t fz_u8(fz_reader_t *r)
{
    return r->pos < r->size ? r->data[r->pos++] : 0u;
}

/* n <= 8 bytes, little endian. */
static uint64_t read_le(fz_reader_t *r, int n)
{
    uint64_t v = 0;
    int i;
    for (i = 0; i < n; ++i) {
        v |= (uint64_t)fz_u8(r) << (8 * i);
    }
    return v;
}

uint64_t fz_u64(fz_reader_t *r)
{
    return read_le(r, 8);
}

void fz_overlay(fz_reader_t *r, void *dst, size_t n)
{
    const size_t left = r->size - r->pos;
    const size_t take = n < left ? n : left;
    if (take > 0) {
        memcpy(dst, r->data + r->pos, take);
        r->pos += take;
    }
}

/* int16 / 32768 * scale for a bounded selector k. */
static double bounded(fz_reader_t *r, int k)
{
    const int16_t q = (int16_t)(uint16_t)read_le(r, 2);
    return (double)q / 32768.0 * bounded_scale[k - FZ_VALUE_TABLE];
}

icoac_real_t fz_real(fz_reader_t *r)
{
    const int k = fz_u8(r) % FZ_VALUE_KINDS;
    icoac_real_t v;
    if (k < FZ_VALUE_TABLE) {
        return real_table[k];
    }
    if (k < FZ_VALUE_TABLE + FZ_VALUE_BOUNDED) {
        return (icoac_real_t)bounded(r, k);
    }
#if defined(ICOAC_REAL_DOUBLE) && ICOAC_REAL_DOUBLE
    {
        const uint64_t bits = read_le(r, 8);
        memcpy(&v, &bits, sizeof v);
    }
#else
    {
        const uint32_t bits = (uint32_t)read_le(r, 4);
        memcpy(&v, &bits, sizeof v);
    }
#endif
    return v;
}

double fz_double(fz_reader_t *r)
{
    const int k = fz_u8(r) % FZ_VALUE_KINDS;
    double v;
    uint64_t bits;
    if (k < FZ_VALUE_TABLE) {
        return double_table[k];
    }
    if (k < FZ_VALUE_TABLE + FZ_VALUE_BOUNDED) {
        return bounded(r, k);
    }
    bits = read_le(r, 8);
    memcpy(&v, &bits, sizeof v);
    return v;
}

int32_t fz_i32(fz_reader_t *r)
{
    static const int32_t table[7] = {0, 1, 2, -1, INT32_MAX, INT32_MIN, 3};
    const int k = fz_u8(r) % 8;
    return k < 7 ? table[k] : (int32_t)(uint32_t)read_le(r, 4);
}

int64_t fz_i64(fz_reader_t *r)
{
    const int k = fz_u8(r) % 12;
    return k < 11 ? i64_table[k] : (int64_t)read_le(r, 8);
}

/* Config fields by index, in struct order (the order icoac_config_check walks them), every
 * array element of the default maxima (6 inputs, 6 rules): the member's offset and whether it is
 * an int32 (switch or count) or a real; made from the rows of icoac_params.h (0 mode, 1 learn,
 * 2 task.n_inputs, 3-8 task.input_sign[0..5], ..., 11-16 task.rule_input[0..5], ...,
 * 78 search.cov_scale). */
typedef struct {
    size_t offset;
    int is_int;
} config_field_t;

#define FZ_MEMBER_config(f) f
#define FZ_MEMBER_task(f) task.f
#define FZ_MEMBER_policy(f) policy.f
#define FZ_MEMBER_ico(f) ico.f
#define FZ_MEMBER_critic(f) critic.f
#define FZ_MEMBER_actor(f) actor.f
#define FZ_MEMBER_search(f) search.f
#define FZ_IS_INT_int32_t 1
#define FZ_IS_INT_icoac_real_t 0
#define FZ_ELEM(member, is_int) {offsetof(icoac_config_t, member), is_int},
#define FZ_ELEMS_scalar(member, is_int) FZ_ELEM(member, is_int)
#define FZ_ELEMS_inputs(member, is_int)                                                                  \
    FZ_ELEM(member[0], is_int) FZ_ELEM(member[1], is_int) FZ_ELEM(member[2], is_int)                    \
    FZ_ELEM(member[3], is_int) FZ_ELEM(member[4], is_int) FZ_ELEM(member[5], is_int)
#define FZ_ELEMS_rules(member, is_int) FZ_ELEMS_inputs(member, is_int)
#define FZ_ELEMS(member, dim, is_int) FZ_ELEMS_##dim(member, is_int)
#define FZ_ROW(group, field, type, dim, check, unit, min, max, def, modes, tier, status, doc) \
    FZ_ELEMS(FZ_MEMBER_##group(field), dim, FZ_IS_INT_##type)

ICOAC_STATIC_ASSERT(ICOAC_MAX_INPUTS == 6 && ICOAC_MAX_RULES == 6, fz_tables_of_the_default_maxima);

static const config_field_t config_fields[] = {ICOAC_PARAMS(FZ_ROW)};

ICOAC_STATIC_ASSERT(sizeof config_fields / sizeof config_fields[0] == FZ_CONFIG_FIELDS, fz_config_field_count);

void fz_config(fz_reader_t *r, icoac_config_t *cfg)
{
    icoac_config_default(cfg);
    fz_config_over(r, cfg);
}

void fz_config_over(fz_reader_t *r, icoac_config_t *cfg)
{
    const uint8_t c = fz_u8(r);
    int n;
    if (c & 1u) {
        fz_overlay(r, cfg, sizeof *cfg);
        return;
    }
    for (n = (c >> 1) % 8; n > 0; --n) {
        const config_field_t *f = &config_fields[fz_u8(r) % FZ_CONFIG_FIELDS];
        unsigned char *member = (unsigned char *)cfg + f->offset;
        if (f->is_int) {
            const int32_t v = fz_i32(r);
            memcpy(member, &v, sizeof v);
        } else {
            const icoac_real_t v = fz_real(r);
            memcpy(member, &v, sizeof v);
        }
    }
}

const icoac_prior_t *fz_prior(fz_reader_t *r, icoac_prior_t *prior)
{
    const uint8_t p = fz_u8(r);
    int i;
    int n;
    if (p % 3 == 0) {
        return 0;
    }
    memset(prior, 0, sizeof *prior);
    for (i = 0; i < ICOAC_MAX_INPUTS; ++i) {
        prior->cov[i][i] = ICOAC_R(1.0);
    }
    if (p % 3 == 1) {
        return prior;
    }
    for (n = (p / 3) % 8; n > 0; --n) {
        const uint8_t b = fz_u8(r);
        const int field = (b & 0x7f) % FZ_PRIOR_FIELDS;
        const icoac_real_t v = fz_real(r);
        if (field < ICOAC_MAX_INPUTS) {
            prior->mean[field] = v;
        } else {
            const int row = (field - ICOAC_MAX_INPUTS) / ICOAC_MAX_INPUTS;
            const int col = (field - ICOAC_MAX_INPUTS) % ICOAC_MAX_INPUTS;
            prior->cov[row][col] = v;
            if (b & 0x80) {
                prior->cov[col][row] = v;
            }
        }
    }
    return prior;
}

int fz_config_equal(const icoac_config_t *a, const icoac_config_t *b)
{
    size_t i;
    for (i = 0; i < FZ_CONFIG_FIELDS; ++i) {
        const size_t size = config_fields[i].is_int ? sizeof(int32_t) : sizeof(icoac_real_t);
        if (memcmp((const unsigned char *)a + config_fields[i].offset, (const unsigned char *)b + config_fields[i].offset,
                   size) != 0) {
            return 0;
        }
    }
    return 1;
}

#if defined(ICOAC_FUZZ_SIM) && ICOAC_FUZZ_SIM
void fz_run(fz_reader_t *r, icoac_sim_run_t *run)
{
    const uint8_t mode = fz_u8(r);
    int n;
    icoac_sim_run_default(run);
    if (mode & 1u) {
        fz_overlay(r, run, sizeof *run);
        return;
    }
    for (n = (mode >> 1) % 4; n > 0; --n) {
        const int field = fz_u8(r) % 3;
        if (field == 0) {
            run->max_trials = fz_i64(r);
        } else if (field == 1) {
            run->success_steps = fz_i64(r);
        } else {
            run->init_velocity_noise = fz_double(r);
        }
    }
}

int32_t fz_threads(fz_reader_t *r)
{
    const uint8_t b = fz_u8(r) % 16;
    return b == 15 ? -1 : (b >= 13 ? 2 : 1);
}
#endif
