/* SPDX-License-Identifier: Apache-2.0 */
/* The constant, layout and parameter tables icoac_sim exports for bindings (sim_host/src/layout.c):
 * non-empty, unique names, every field inside its type, the members of each struct listed
 * without overlap and covering it, and spot checks against this compiler's offsetof. */
#include "test_common.h"

#include <stdlib.h>

#include "icoac_sim/icoac_sim.h"

/* The types the field table may name, with their sizes here. */
typedef struct {
    const char *name;
    size_t size;
} type_size_t;

static const type_size_t types[] = {
    {"icoac_config_t", sizeof(icoac_config_t)},       {"icoac_prior_t", sizeof(icoac_prior_t)},
    {"icoac_counters_t", sizeof(icoac_counters_t)},   {"icoac_input_t", sizeof(icoac_input_t)},
    {"icoac_output_t", sizeof(icoac_output_t)},
    {"icoac_sim_run_t", sizeof(icoac_sim_run_t)},     {"icoac_sim_cell_t", sizeof(icoac_sim_cell_t)},
    {"icoac_sim_axis_t", sizeof(icoac_sim_axis_t)},   {"icoac_sim_param_t", sizeof(icoac_sim_param_t)},
    {"icoac_sim_sweep_t", sizeof(icoac_sim_sweep_t)}, {"icoac_sim_plant_desc_t", sizeof(icoac_sim_plant_desc_t)},
    {"icoac_sim_actuator_t", sizeof(icoac_sim_actuator_t)},
    {"icoac_sim_learner_t", sizeof(icoac_sim_learner_t)}, {"icoac_sim_task_t", sizeof(icoac_sim_task_t)},
    {"icoac_sim_model_t", sizeof(icoac_sim_model_t)},       {"icoac_rng_t", sizeof(icoac_rng_t)},
};

#define N_TYPES (sizeof types / sizeof types[0])

static const type_size_t *find_type(const char *name)
{
    size_t i;
    for (i = 0; i < N_TYPES; ++i) {
        if (strcmp(types[i].name, name) == 0) {
            return &types[i];
        }
    }
    return NULL;
}

static const icoac_sim_field_t *find_field(const char *type, const char *field)
{
    int32_t n = 0;
    const icoac_sim_field_t *fields = icoac_sim_fields(&n);
    int32_t i;
    for (i = 0; i < n; ++i) {
        if (strcmp(fields[i].type, type) == 0 && strcmp(fields[i].field, field) == 0) {
            return &fields[i];
        }
    }
    TEST_PRINTF("field %s.%s not in the layout table", type, field);
    TEST_FAIL();
    return NULL;
}

static double constant(const char *name)
{
    int32_t n = 0;
    const icoac_sim_constant_t *constants = icoac_sim_constants(&n);
    int32_t i;
    for (i = 0; i < n; ++i) {
        if (strcmp(constants[i].name, name) == 0) {
            return constants[i].value;
        }
    }
    TEST_PRINTF("constant %s not in the table", name);
    TEST_FAIL();
    return 0.0;
}

static void test_constants_table(void)
{
    int32_t n = -1;
    const icoac_sim_constant_t *constants = icoac_sim_constants(&n);
    int32_t i, j;
    TEST_ASSERT_NOT_NULL(constants);
    TEST_ASSERT_TRUE(n > 0);
    TEST_ASSERT_EQUAL_PTR(constants, icoac_sim_constants(NULL)); /* count may be NULL */
    for (i = 0; i < n; ++i) {
        TEST_ASSERT_NOT_NULL(constants[i].name);
        TEST_ASSERT_TRUE(strlen(constants[i].name) > 0);
        TEST_ASSERT_TRUE(isfinite(constants[i].value));
        for (j = 0; j < i; ++j) {
            if (strcmp(constants[i].name, constants[j].name) == 0) {
                TEST_PRINTF("constant %s listed twice", constants[i].name);
                TEST_FAIL();
            }
        }
    }
    /* spot checks against the headers */
    TEST_ASSERT_TRUE(constant("ICOAC_ABI_VERSION") == ICOAC_ABI_VERSION);
    TEST_ASSERT_TRUE(constant("ICOAC_ABI_VERSION") == 10);
    TEST_ASSERT_TRUE(constant("ICOAC_SIM_ABI_VERSION") == ICOAC_SIM_ABI_VERSION);
    TEST_ASSERT_TRUE(constant("ICOAC_SIM_ABI_VERSION") == 10);
    TEST_ASSERT_TRUE(constant("ICOAC_CARTPOLE_INPUTS") == ICOAC_CARTPOLE_INPUTS);
    TEST_ASSERT_TRUE(constant("ICOAC_CARTPOLE_CRITIC_UNITS") == ICOAC_CARTPOLE_CRITIC_UNITS);
    TEST_ASSERT_TRUE(constant("ICOAC_STATE_SIZE") == ICOAC_STATE_SIZE);
    TEST_ASSERT_TRUE(constant("ICOAC_STATE_SIZE") == (double)icoac_sizeof_state());
    TEST_ASSERT_TRUE(constant("ICOAC_INPUT_TERMINAL") == ICOAC_INPUT_TERMINAL);
    TEST_ASSERT_TRUE(constant("ICOAC_FORCE_MAX") == (double)ICOAC_FORCE_MAX);
    TEST_ASSERT_TRUE(constant("ICOAC_PRIOR_COV_MAX") == (double)ICOAC_PRIOR_COV_MAX);
    TEST_ASSERT_TRUE(constant("ICOAC_MODE_ICO") == ICOAC_MODE_ICO);
    TEST_ASSERT_TRUE(constant("ICOAC_MODE_RL") == ICOAC_MODE_RL);
    TEST_ASSERT_TRUE(constant("ICOAC_MODE_SEARCH") == ICOAC_MODE_SEARCH);
    TEST_ASSERT_TRUE(constant("ICOAC_MODE_SEARCH") == 2);
    TEST_ASSERT_TRUE(constant("ICOAC_ACTOR_POSTERIOR") == ICOAC_ACTOR_POSTERIOR);
    TEST_ASSERT_TRUE(constant("ICOAC_ACTOR_MEAN") == ICOAC_ACTOR_MEAN);
    TEST_ASSERT_TRUE(constant("ICOAC_ACTOR_GRADIENT") == ICOAC_ACTOR_GRADIENT);
    TEST_ASSERT_TRUE(constant("ICOAC_SEARCH_BATCH_MAX") == ICOAC_SEARCH_BATCH_MAX);
    TEST_ASSERT_TRUE(constant("ICOAC_EXPLORE_TICKS_MAX") == ICOAC_EXPLORE_TICKS_MAX);
    TEST_ASSERT_TRUE(constant("ICOAC_ERR_BAD_SEARCH") == ICOAC_ERR_BAD_SEARCH);
    TEST_ASSERT_TRUE(constant("ICOAC_ERR_BAD_SEARCH") == 18);
    TEST_ASSERT_TRUE(constant("ICOAC_REFLEX_GAIN") == ICOAC_REFLEX_GAIN);
    TEST_ASSERT_TRUE(constant("ICOAC_ICO_TIMING_LITERAL") == ICOAC_ICO_TIMING_LITERAL);
    TEST_ASSERT_TRUE(constant("ICOAC_ERR_NUMERIC") == ICOAC_ERR_NUMERIC);
    TEST_ASSERT_TRUE(constant("ICOAC_ERR_BAD_PRIOR") == ICOAC_ERR_BAD_PRIOR);
    TEST_ASSERT_TRUE(constant("ICOAC_SIM_CANCELLED") == ICOAC_SIM_CANCELLED);
    TEST_ASSERT_TRUE(constant("ICOAC_SIM_ERROR") == ICOAC_SIM_ERROR);
    TEST_ASSERT_TRUE(constant("ICOAC_SIM_PROGRESS_LEN") == ICOAC_SIM_PROGRESS_LEN);
    TEST_ASSERT_TRUE(constant("ICOAC_SIM_PI") == ICOAC_SIM_PI);
    TEST_ASSERT_TRUE(constant("ICOAC_SIM_MAX_STATE") == ICOAC_SIM_MAX_STATE);
    TEST_ASSERT_TRUE(constant("ICOAC_SIM_MAX_PARAMS") == ICOAC_SIM_MAX_PARAMS);
    TEST_ASSERT_TRUE(constant("ICOAC_SIM_CART_POLE") == ICOAC_SIM_CART_POLE);
    TEST_ASSERT_TRUE(constant("ICOAC_SIM_START_STREAM") == ICOAC_SIM_START_STREAM);
    TEST_ASSERT_TRUE(constant("ICOAC_SIM_ERR_NONFINITE") == ICOAC_SIM_ERR_NONFINITE);
}

/* Byte coverage of one type by its listed members. */
static void check_type_layout(const icoac_sim_field_t *fields, int32_t n, const type_size_t *type)
{
    unsigned char *covered = calloc(type->size, 1);
    size_t bytes = 0;
    int listed = 0;
    int32_t i;
    size_t b;
    TEST_ASSERT_NOT_NULL(covered);
    for (i = 0; i < n; ++i) {
        if (strcmp(fields[i].type, type->name) != 0) {
            continue;
        }
        ++listed;
        for (b = fields[i].offset; b < (size_t)fields[i].offset + fields[i].size; ++b) {
            if (covered[b]) {
                TEST_PRINTF("%s.%s overlaps another member at byte %u", type->name, fields[i].field, (unsigned)b);
                TEST_FAIL();
            }
            covered[b] = 1;
            ++bytes;
        }
    }
    TEST_ASSERT_TRUE(listed > 0);
    /* These structs have no padding with float reals (icoac_sim links the float library), so
     * the members listed must cover every byte: no member is missing from the table. */
    if (REAL_IS_FLOAT && bytes != type->size) {
        TEST_PRINTF("%s: the listed members cover %u of %u bytes", type->name, (unsigned)bytes,
                    (unsigned)type->size);
        TEST_FAIL();
    }
    free(covered);
}

static void test_fields_table(void)
{
    int32_t n = -1;
    const icoac_sim_field_t *fields = icoac_sim_fields(&n);
    int32_t i, j;
    size_t t;
    TEST_ASSERT_NOT_NULL(fields);
    TEST_ASSERT_TRUE(n > 0);
    TEST_ASSERT_EQUAL_PTR(fields, icoac_sim_fields(NULL));
    for (i = 0; i < n; ++i) {
        const type_size_t *type;
        TEST_ASSERT_NOT_NULL(fields[i].type);
        TEST_ASSERT_NOT_NULL(fields[i].field);
        TEST_ASSERT_TRUE(strlen(fields[i].field) > 0);
        type = find_type(fields[i].type);
        if (type == NULL) {
            TEST_PRINTF("field %s of unknown type %s", fields[i].field, fields[i].type);
            TEST_FAIL();
        }
        /* inside its type */
        TEST_ASSERT_TRUE(fields[i].size > 0);
        if ((size_t)fields[i].offset + fields[i].size > type->size) {
            TEST_PRINTF("%s.%s: offset %u + size %u > sizeof %u", fields[i].type, fields[i].field,
                        (unsigned)fields[i].offset, (unsigned)fields[i].size, (unsigned)type->size);
            TEST_FAIL();
        }
        /* unique (type, field) */
        for (j = 0; j < i; ++j) {
            if (strcmp(fields[i].type, fields[j].type) == 0 && strcmp(fields[i].field, fields[j].field) == 0) {
                TEST_PRINTF("field %s.%s listed twice", fields[i].type, fields[i].field);
                TEST_FAIL();
            }
        }
    }
    for (t = 0; t < N_TYPES; ++t) {
        check_type_layout(fields, n, &types[t]);
    }
}

#define SPOT(type, member)                                                                    \
    do {                                                                                      \
        const icoac_sim_field_t *f_ = find_field(#type, #member);                             \
        TEST_ASSERT_EQUAL_size_t(offsetof(type, member), f_->offset);                                 \
        TEST_ASSERT_EQUAL_size_t(sizeof(((type *)0)->member), f_->size);                              \
    } while (0)

static void test_fields_spot_checks(void)
{
    SPOT(icoac_config_t, mode);
    SPOT(icoac_config_t, policy.input_range);
    SPOT(icoac_config_t, policy.gain);
    SPOT(icoac_config_t, task.n_inputs);
    SPOT(icoac_config_t, task.rule_threshold);
    SPOT(icoac_config_t, task.rule_reflex);
    SPOT(icoac_config_t, critic.units);
    SPOT(icoac_input_t, reflex);
    SPOT(icoac_config_t, ico.rate);
    SPOT(icoac_config_t, ico.timing);
    SPOT(icoac_config_t, critic.range);
    SPOT(icoac_config_t, critic.threshold);
    SPOT(icoac_config_t, actor.noise_std);
    SPOT(icoac_config_t, actor.act_with_sample);
    SPOT(icoac_config_t, critic.quirks);
    SPOT(icoac_config_t, actor.update);
    SPOT(icoac_config_t, actor.rate);
    SPOT(icoac_config_t, actor.likelihood_std);
    SPOT(icoac_config_t, actor.batch);
    SPOT(icoac_config_t, actor.explore_ticks);
    SPOT(icoac_config_t, search.batch);
    SPOT(icoac_config_t, search.elite_fraction);
    SPOT(icoac_config_t, search.step);
    SPOT(icoac_config_t, search.floor);
    SPOT(icoac_config_t, search.cov_scale);
    SPOT(icoac_prior_t, cov);
    SPOT(icoac_counters_t, numeric_faults);
    SPOT(icoac_input_t, flags);
    SPOT(icoac_output_t, weight_norm);
    SPOT(icoac_output_t, status);
    SPOT(icoac_sim_run_t, init_velocity_noise);
    SPOT(icoac_sim_cell_t, cov);
    SPOT(icoac_sim_param_t, max);
    SPOT(icoac_sim_param_t, doc);
    SPOT(icoac_sim_sweep_t, degrees);
    SPOT(icoac_sim_actuator_t, limit);
    SPOT(icoac_sim_plant_desc_t, observed);
    SPOT(icoac_sim_plant_desc_t, energy);
    SPOT(icoac_sim_plant_desc_t, task);
    SPOT(icoac_sim_task_t, prior_all_finished);
    SPOT(icoac_sim_model_t, param);
    /* the nested layout, as the table names it */
    TEST_ASSERT_EQUAL_size_t(ICOAC_MAX_INPUTS * sizeof(icoac_real_t), find_field("icoac_config_t", "critic.range")->size);
    TEST_ASSERT_EQUAL_size_t(ICOAC_MAX_RULES * sizeof(int32_t), find_field("icoac_config_t", "task.rule_input")->size);
    TEST_ASSERT_EQUAL_size_t(offsetof(icoac_config_t, task), find_field("icoac_config_t", "task.n_inputs")->offset);
    TEST_ASSERT_EQUAL_UINT32(0, find_field("icoac_config_t", "mode")->offset);
    TEST_ASSERT_EQUAL_size_t(offsetof(icoac_config_t, policy), find_field("icoac_config_t", "policy.input_range")->offset);
    TEST_ASSERT_TRUE(find_field("icoac_config_t", "ico.rate")->offset >= offsetof(icoac_config_t, ico));
    TEST_ASSERT_TRUE(find_field("icoac_config_t", "actor.act_with_sample")->offset <
                     offsetof(icoac_config_t, actor) + sizeof(icoac_actor_config_t));
    TEST_ASSERT_EQUAL_size_t(offsetof(icoac_config_t, search), find_field("icoac_config_t", "search.batch")->offset);
    /* the search group is the last: its last member ends the struct (no tail padding with float) */
    TEST_ASSERT_TRUE(find_field("icoac_config_t", "search.cov_scale")->offset + sizeof(icoac_real_t) +
                    (REAL_IS_FLOAT ? 0 : sizeof(icoac_real_t) - 1) >=
                sizeof(icoac_config_t));
}

void setUp(void) {}
void tearDown(void) {}

/* The parameter table: every row is a field of the layout table at the same place, names are
 * unique, the columns are filled, and each scalar's default is what the default functions write. */
static void test_param_table(void)
{
    int32_t n = 0;
    const icoac_sim_param_row_t *rows = icoac_sim_param_table(&n);
    icoac_config_t cfg;
    icoac_sim_run_t run;
    int32_t config_rows = 0;
    int32_t i;
    int32_t j;
    icoac_config_default(&cfg);
    icoac_sim_run_default(&run);
    TEST_ASSERT_TRUE(n > 0);
    for (i = 0; i < n; ++i) {
        const icoac_sim_param_row_t *r = &rows[i];
        const icoac_sim_field_t *f = find_field(r->type, r->name);
        const unsigned char *base = strcmp(r->type, "icoac_config_t") == 0 ? (const unsigned char *)&cfg
                                                                           : (const unsigned char *)&run;
        TEST_ASSERT_EQUAL_UINT32(f->offset, r->offset);
        TEST_ASSERT_EQUAL_UINT32(f->size, r->size);
        TEST_ASSERT_TRUE(r->group[0] != '\0' && r->ctype[0] != '\0' && r->check[0] != '\0' && r->doc[0] != '\0');
        TEST_ASSERT_TRUE(strcmp(r->tier, "essential") == 0 || strcmp(r->tier, "advanced") == 0);
        TEST_ASSERT_TRUE(r->modes != 0u && (r->modes & ~(uint32_t)ICOAC_PARAM_ALL) == 0u);
        TEST_ASSERT_TRUE(r->min <= r->max);
        for (j = 0; j < i; ++j) {
            TEST_ASSERT_TRUE_MESSAGE(strcmp(rows[j].name, r->name) != 0 || strcmp(rows[j].type, r->type) != 0, r->name);
        }
        if (strcmp(r->type, "icoac_config_t") == 0) {
            ++config_rows;
        }
        if (strcmp(r->dim, "scalar") == 0) {
            double value;
            if (strcmp(r->ctype, "icoac_real_t") == 0) {
                icoac_real_t v;
                memcpy(&v, base + r->offset, sizeof v);
                value = (double)v;
            } else if (strcmp(r->ctype, "double") == 0) {
                memcpy(&value, base + r->offset, sizeof value);
            } else if (strcmp(r->ctype, "int64_t") == 0) {
                int64_t v;
                memcpy(&v, base + r->offset, sizeof v);
                value = (double)v;
            } else {
                int32_t v;
                memcpy(&v, base + r->offset, sizeof v);
                value = (double)v;
            }
            TEST_ASSERT_TRUE_MESSAGE(value == r->def, r->name);
        }
    }
    /* every member of icoac_config_t is a row (the layout table lists them from the rows too:
     * count them against the struct's bytes, with float reals there is no padding) */
    {
        size_t bytes = 0;
        for (i = 0; i < n; ++i) {
            if (strcmp(rows[i].type, "icoac_config_t") == 0) {
                bytes += rows[i].size;
            }
        }
        TEST_ASSERT_TRUE(config_rows > 0);
        TEST_ASSERT_TRUE(sizeof(icoac_config_t) - bytes < sizeof(icoac_real_t) * 2);
    }
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_constants_table);
    RUN_TEST(test_fields_table);
    RUN_TEST(test_fields_spot_checks);
    RUN_TEST(test_param_table);
    return UNITY_END();
}
