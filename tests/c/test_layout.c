/* SPDX-License-Identifier: Apache-2.0 */
/* The constant and layout tables icoac_sim exports for bindings (sim_host/src/layout.c):
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
    {"icoac_output_t", sizeof(icoac_output_t)},       {"icoac_sim_plant_t", sizeof(icoac_sim_plant_t)},
    {"icoac_sim_run_t", sizeof(icoac_sim_run_t)},     {"icoac_sim_cell_t", sizeof(icoac_sim_cell_t)},
    {"icoac_sim_axis_t", sizeof(icoac_sim_axis_t)},   {"icoac_sim_param_t", sizeof(icoac_sim_param_t)},
    {"icoac_sim_sweep_t", sizeof(icoac_sim_sweep_t)}, {"icoac_sim_plant_desc_t", sizeof(icoac_sim_plant_desc_t)},
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
    print_error("field %s.%s not in the layout table\n", type, field);
    fail();
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
    print_error("constant %s not in the table\n", name);
    fail();
    return 0.0;
}

static void test_constants_table(void **unused)
{
    int32_t n = -1;
    const icoac_sim_constant_t *constants = icoac_sim_constants(&n);
    int32_t i, j;
    (void)unused;
    assert_non_null(constants);
    assert_true(n > 0);
    assert_ptr_equal(icoac_sim_constants(NULL), constants); /* count may be NULL */
    for (i = 0; i < n; ++i) {
        assert_non_null(constants[i].name);
        assert_true(strlen(constants[i].name) > 0);
        assert_true(isfinite(constants[i].value));
        for (j = 0; j < i; ++j) {
            if (strcmp(constants[i].name, constants[j].name) == 0) {
                print_error("constant %s listed twice\n", constants[i].name);
                fail();
            }
        }
    }
    /* spot checks against the headers */
    assert_true(constant("ICOAC_ABI_VERSION") == ICOAC_ABI_VERSION);
    assert_true(constant("ICOAC_ABI_VERSION") == 8);
    assert_true(constant("ICOAC_SIM_ABI_VERSION") == ICOAC_SIM_ABI_VERSION);
    assert_true(constant("ICOAC_SIM_ABI_VERSION") == 3);
    assert_true(constant("ICOAC_CARTPOLE_INPUTS") == ICOAC_CARTPOLE_INPUTS);
    assert_true(constant("ICOAC_CARTPOLE_CRITIC_UNITS") == ICOAC_CARTPOLE_CRITIC_UNITS);
    assert_true(constant("ICOAC_STATE_SIZE") == ICOAC_STATE_SIZE);
    assert_true(constant("ICOAC_STATE_SIZE") == (double)icoac_sizeof_state());
    assert_true(constant("ICOAC_INPUT_TERMINAL") == ICOAC_INPUT_TERMINAL);
    assert_true(constant("ICOAC_FORCE_MAX") == (double)ICOAC_FORCE_MAX);
    assert_true(constant("ICOAC_MODE_ICO") == ICOAC_MODE_ICO);
    assert_true(constant("ICOAC_MODE_RL") == ICOAC_MODE_RL);
    assert_true(constant("ICOAC_MODE_SEARCH") == ICOAC_MODE_SEARCH);
    assert_true(constant("ICOAC_MODE_SEARCH") == 2);
    assert_true(constant("ICOAC_ACTOR_POSTERIOR") == ICOAC_ACTOR_POSTERIOR);
    assert_true(constant("ICOAC_ACTOR_MEAN") == ICOAC_ACTOR_MEAN);
    assert_true(constant("ICOAC_ACTOR_GRADIENT") == ICOAC_ACTOR_GRADIENT);
    assert_true(constant("ICOAC_SEARCH_BATCH_MAX") == ICOAC_SEARCH_BATCH_MAX);
    assert_true(constant("ICOAC_EXPLORE_TICKS_MAX") == ICOAC_EXPLORE_TICKS_MAX);
    assert_true(constant("ICOAC_ERR_BAD_SEARCH") == ICOAC_ERR_BAD_SEARCH);
    assert_true(constant("ICOAC_ERR_BAD_SEARCH") == 18);
    assert_true(constant("ICOAC_REFLEX_GAIN") == ICOAC_REFLEX_GAIN);
    assert_true(constant("ICOAC_ICO_TIMING_LITERAL") == ICOAC_ICO_TIMING_LITERAL);
    assert_true(constant("ICOAC_ERR_NUMERIC") == ICOAC_ERR_NUMERIC);
    assert_true(constant("ICOAC_ERR_BAD_PRIOR") == ICOAC_ERR_BAD_PRIOR);
    assert_true(constant("ICOAC_SIM_CANCELLED") == ICOAC_SIM_CANCELLED);
    assert_true(constant("ICOAC_SIM_ERROR") == ICOAC_SIM_ERROR);
    assert_true(constant("ICOAC_SIM_PROGRESS_LEN") == ICOAC_SIM_PROGRESS_LEN);
    assert_true(constant("ICOAC_SIM_GRID_CELLS") == ICOAC_SIM_GRID_CELLS);
    assert_true(constant("ICOAC_SIM_GRID_CELLS") == 1225);
    assert_true(constant("ICOAC_SIM_GRID_X_FIRST") == ICOAC_SIM_GRID_X_FIRST);
    assert_true(constant("ICOAC_SIM_GRID_X_STEP") == ICOAC_SIM_GRID_X_STEP);
    assert_true(constant("ICOAC_SIM_GRID_THETA_FIRST_DEG") == ICOAC_SIM_GRID_THETA_FIRST_DEG);
    assert_true(constant("ICOAC_SIM_PI") == ICOAC_SIM_PI);
    assert_true(constant("ICOAC_SIM_MAX_STATE") == ICOAC_SIM_MAX_STATE);
    assert_true(constant("ICOAC_SIM_MAX_PARAMS") == ICOAC_SIM_MAX_PARAMS);
    assert_true(constant("ICOAC_SIM_CART_POLE") == ICOAC_SIM_CART_POLE);
    assert_true(constant("ICOAC_SIM_START_STREAM") == ICOAC_SIM_START_STREAM);
    assert_true(constant("ICOAC_SIM_ERR_NONFINITE") == ICOAC_SIM_ERR_NONFINITE);
}

/* Byte coverage of one type by its listed members. */
static void check_type_layout(const icoac_sim_field_t *fields, int32_t n, const type_size_t *type)
{
    unsigned char *covered = calloc(type->size, 1);
    size_t bytes = 0;
    int listed = 0;
    int32_t i;
    size_t b;
    assert_non_null(covered);
    for (i = 0; i < n; ++i) {
        if (strcmp(fields[i].type, type->name) != 0) {
            continue;
        }
        ++listed;
        for (b = fields[i].offset; b < (size_t)fields[i].offset + fields[i].size; ++b) {
            if (covered[b]) {
                print_error("%s.%s overlaps another member at byte %u\n", type->name, fields[i].field, (unsigned)b);
                fail();
            }
            covered[b] = 1;
            ++bytes;
        }
    }
    assert_true(listed > 0);
    /* These structs have no padding with float reals (icoac_sim links the float library), so
     * the members listed must cover every byte: no member is missing from the table. */
    if (REAL_IS_FLOAT && bytes != type->size) {
        print_error("%s: the listed members cover %u of %u bytes\n", type->name, (unsigned)bytes,
                    (unsigned)type->size);
        fail();
    }
    free(covered);
}

static void test_fields_table(void **unused)
{
    int32_t n = -1;
    const icoac_sim_field_t *fields = icoac_sim_fields(&n);
    int32_t i, j;
    size_t t;
    (void)unused;
    assert_non_null(fields);
    assert_true(n > 0);
    assert_ptr_equal(icoac_sim_fields(NULL), fields);
    for (i = 0; i < n; ++i) {
        const type_size_t *type;
        assert_non_null(fields[i].type);
        assert_non_null(fields[i].field);
        assert_true(strlen(fields[i].field) > 0);
        type = find_type(fields[i].type);
        if (type == NULL) {
            print_error("field %s of unknown type %s\n", fields[i].field, fields[i].type);
            fail();
        }
        /* inside its type */
        assert_true(fields[i].size > 0);
        if ((size_t)fields[i].offset + fields[i].size > type->size) {
            print_error("%s.%s: offset %u + size %u > sizeof %u\n", fields[i].type, fields[i].field,
                        (unsigned)fields[i].offset, (unsigned)fields[i].size, (unsigned)type->size);
            fail();
        }
        /* unique (type, field) */
        for (j = 0; j < i; ++j) {
            if (strcmp(fields[i].type, fields[j].type) == 0 && strcmp(fields[i].field, fields[j].field) == 0) {
                print_error("field %s.%s listed twice\n", fields[i].type, fields[i].field);
                fail();
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
        assert_int_equal(f_->offset, offsetof(type, member));                                 \
        assert_int_equal(f_->size, sizeof(((type *)0)->member));                              \
    } while (0)

static void test_fields_spot_checks(void **unused)
{
    (void)unused;
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
    SPOT(icoac_sim_plant_t, integrator);
    SPOT(icoac_sim_run_t, init_velocity_noise);
    SPOT(icoac_sim_cell_t, cov);
    SPOT(icoac_sim_param_t, max);
    SPOT(icoac_sim_sweep_t, degrees);
    SPOT(icoac_sim_plant_desc_t, observed);
    SPOT(icoac_sim_plant_desc_t, energy);
    SPOT(icoac_sim_model_t, param);
    /* the nested layout, as the table names it */
    assert_int_equal(find_field("icoac_config_t", "critic.range")->size, ICOAC_MAX_INPUTS * sizeof(icoac_real_t));
    assert_int_equal(find_field("icoac_config_t", "task.rule_input")->size, ICOAC_MAX_RULES * sizeof(int32_t));
    assert_int_equal(find_field("icoac_config_t", "task.n_inputs")->offset, offsetof(icoac_config_t, task));
    assert_int_equal(find_field("icoac_config_t", "mode")->offset, 0);
    assert_int_equal(find_field("icoac_config_t", "policy.input_range")->offset, offsetof(icoac_config_t, policy));
    assert_true(find_field("icoac_config_t", "ico.rate")->offset >= offsetof(icoac_config_t, ico));
    assert_true(find_field("icoac_config_t", "actor.act_with_sample")->offset <
                offsetof(icoac_config_t, actor) + sizeof(icoac_actor_config_t));
    assert_int_equal(find_field("icoac_config_t", "search.batch")->offset, offsetof(icoac_config_t, search));
    /* the search group is the last: its last member ends the struct (no tail padding with float) */
    assert_true(find_field("icoac_config_t", "search.cov_scale")->offset + sizeof(icoac_real_t) +
                    (REAL_IS_FLOAT ? 0 : sizeof(icoac_real_t) - 1) >=
                sizeof(icoac_config_t));
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_constants_table),
        cmocka_unit_test(test_fields_table),
        cmocka_unit_test(test_fields_spot_checks),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
