/* SPDX-License-Identifier: Apache-2.0 */
/* The tick contract (design.md): with an accepted configuration and a finite observation,
 * icoac_step returns ICOAC_OK with a finite output and learned state, or an error status with
 * force 0 and the state unchanged but for its counters. Regression tests of the reproducers
 * an outside tester found: the critic scan that ran off its arrays, and OK ticks with a NaN or
 * infinite force. */
#include "test_common.h"

#include <float.h>

#include "icoac_priv.h"

static int finite_real(icoac_real_t v)
{
    return isfinite((double)v) ? 1 : 0;
}

static const icoac_priv_state_t *priv(const icoac_state_t *state)
{
    return icoac_priv_state_c(state);
}

static int state_finite(const icoac_state_t *state)
{
    const icoac_priv_state_t *s = priv(state);
    const icoac_real_t(*cov)[ICOAC_MAX_INPUTS] = icoac_priv_cov_c(s);
    int i, j;
    for (i = 0; i < ICOAC_CARTPOLE_INPUTS; ++i) {
        if (!finite_real(s->w[i]) || !finite_real(s->w_act[i])) {
            return 0;
        }
        for (j = 0; j < ICOAC_CARTPOLE_INPUTS; ++j) {
            if (!finite_real(cov[i][j])) {
                return 0;
            }
        }
    }
    for (i = 0; i < ICOAC_CARTPOLE_CRITIC_UNITS; ++i) {
        if (!finite_real(s->v[i])) {
            return 0;
        }
    }
    return finite_real(s->weight_norm);
}

static int output_finite(const icoac_output_t *o)
{
    return finite_real(o->force) && finite_real(o->z) && finite_real(o->reflex) && finite_real(o->penalty) &&
           finite_real(o->q) && finite_real(o->weight_norm) && finite_real(o->value) &&
           finite_real(o->td_error) && finite_real(o->noise) && finite_real(o->cov_trace);
}

/* Every real of an error output is 0 but |w|, which is the unchanged state's. */
static int output_cleared(const icoac_output_t *o, icoac_real_t weight_norm)
{
    return o->force == 0 && o->z == 0 && o->reflex == 0 && o->penalty == 0 && o->q == 0 &&
           o->weight_norm == weight_norm && o->value == 0 && o->td_error == 0 && o->noise == 0 &&
           o->cov_trace == 0;
}

/* A rejected tick leaves every byte of the state as it was, except the counters and the
 * scratch the tick stages into: the critic's spare kept-unit slot (active[active_slot ^ 1]),
 * the spare covariance buffer (cov_buffer[cov_slot ^ 1]) and the per-trial batch's staged
 * shift (batch.staged_shift). The slots and the batch's sums themselves stay. */
static void assert_rejected_state(const icoac_state_t *state, const icoac_state_t *before)
{
    icoac_state_t expect = *before;
    icoac_priv_state_t *e = icoac_priv_state(&expect);
    const icoac_priv_state_t *s = priv(state);
    const int active_spare = e->active_slot ^ 1;
    const int cov_spare = e->cov_slot ^ 1;
    TEST_ASSERT_TRUE(active_spare == 0 || active_spare == 1);
    TEST_ASSERT_TRUE(cov_spare == 0 || cov_spare == 1);
    e->counters = s->counters;
    memcpy(&e->active[active_spare], &s->active[active_spare], sizeof e->active[active_spare]);
    memcpy(e->cov_buffer[cov_spare], s->cov_buffer[cov_spare], sizeof e->cov_buffer[cov_spare]);
    memcpy(e->batch.staged_shift, s->batch.staged_shift, sizeof e->batch.staged_shift);
    TEST_ASSERT_EQUAL_MEMORY(&expect, state, sizeof expect);
}

/* One tick under the contract; returns the status. */
static icoac_status_t checked_step(const icoac_config_t *cfg, icoac_state_t *state, const icoac_input_t *in)
{
    const icoac_state_t before = *state;
    icoac_output_t out;
    icoac_status_t status;
    test_assert_config_in_force(cfg, state);
    memset(&out, 0x7F, sizeof out);
    status = icoac_step(state, in, &out);
    TEST_ASSERT_EQUAL_INT(out.status, status);
    TEST_ASSERT_EQUAL_UINT32(priv(&before)->counters.ticks + 1u, priv(state)->counters.ticks);
    if (status == ICOAC_OK) {
        TEST_ASSERT_TRUE(output_finite(&out));
        TEST_ASSERT_TRUE(state_finite(state));
        TEST_ASSERT_TRUE(out.weight_norm == priv(state)->weight_norm);
        TEST_ASSERT_EQUAL_UINT32(priv(&before)->counters.numeric_faults, priv(state)->counters.numeric_faults);
        /* a terminal tick ends the trial until icoac_reset */
        TEST_ASSERT_EQUAL_UINT32((in->flags & ICOAC_INPUT_TERMINAL) != 0u ? ICOAC_PRIV_STATE_ENDED : ICOAC_PRIV_STATE_MAGIC,
                                 priv(state)->magic);
        return status;
    }
    if (status == ICOAC_ERR_TRIAL_ENDED) {
        icoac_state_t expect = before;
        TEST_ASSERT_EQUAL_UINT32(ICOAC_PRIV_STATE_ENDED, priv(&before)->magic);
        TEST_ASSERT_TRUE(output_cleared(&out, priv(state)->weight_norm));
        icoac_priv_state(&expect)->counters = priv(state)->counters;
        TEST_ASSERT_EQUAL_MEMORY(&expect, state, sizeof expect);
        return status;
    }
    TEST_ASSERT_EQUAL_INT(ICOAC_ERR_NUMERIC, status);
    TEST_ASSERT_TRUE(output_cleared(&out, priv(state)->weight_norm));
    TEST_ASSERT_EQUAL_UINT32(priv(&before)->counters.numeric_faults + 1u, priv(state)->counters.numeric_faults);
    TEST_ASSERT_EQUAL_UINT32(priv(&before)->counters.nonfinite, priv(state)->counters.nonfinite);
    assert_rejected_state(state, &before);
    return status;
}

/* Reproducer 1, first half: NaN critic factors (what a subnormal critic_range produced) must
 * not run the kept-unit scans off their arrays. Before the fix they read past the end of
 * cell_product (ASan: stack-buffer-overflow) and wrote through the indices they found. Here
 * NaN in every factor (every input NaN), then only in the (theta, theta_dot) factors, for both
 * kernels: the lists stay inside their arrays, and V is NaN (which the tick rejects) or 0. */
static void check_scan(const icoac_config_t *cfg, const icoac_real_t *v, const icoac_real_t s[ICOAC_MAX_INPUTS])
{
    icoac_priv_critic_list_t list[2]; /* a neighbour to overrun into, as in the state */
    icoac_priv_critic_products_t products[2];
    icoac_priv_grid_t grid;
    icoac_real_t value;
    int i;
    icoac_priv_critic_grid(cfg, &grid);
    memset(list, 0, sizeof list);
    value = icoac_priv_critic_value_sparse(&cfg->critic, &grid, v, s, &list[0]);
    TEST_ASSERT_TRUE(isnan((double)value) || value == ICOAC_R(0.0)); /* as the dense kernel's, below */
    TEST_ASSERT_TRUE(list[0].cells <= list[0].stride && list[0].stride <= ICOAC_CRITIC_BLOCK_MAX);
    for (i = 0; i < list[0].rows; ++i) {
        TEST_ASSERT_TRUE(list[0].index[i] <= list[0].cells);
    }
    for (i = 0; i < list[0].cells; ++i) {
        TEST_ASSERT_TRUE(list[0].index[list[0].rows + i] < list[0].stride);
    }
    TEST_ASSERT_TRUE(list[1].index[0] == 0 && list[1].cells == 0);
    memset(products, 0, sizeof products);
    value = icoac_priv_critic_value_dense(&cfg->critic, &grid, v, s, NULL, &products[0]);
    /* factors computed from NaN are NaN of either sign (IEEE 754 leaves it open): a positive one
     * counts as kept (V NaN, which the tick rejects), a negative one as dropped (V 0) */
    TEST_ASSERT_TRUE(isnan((double)value) || value == ICOAC_R(0.0));
    TEST_ASSERT_TRUE(products[0].cell_begin <= products[0].cell_end);
    TEST_ASSERT_TRUE(products[0].cell_end <= products[0].stride);
    TEST_ASSERT_TRUE(products[1].cell_begin == 0 && products[1].cell_end == 0);
}

static void test_critic_scan_bounded_for_nan(void)
{
    icoac_config_t cfg = test_default_config();
    icoac_real_t v[ICOAC_PRIV_CRITIC_WEIGHTS];
    icoac_real_t s[ICOAC_MAX_INPUTS] = {ICOAC_R(0.3), ICOAC_R(-0.2), ICOAC_R(0.05), ICOAC_R(0.1)};
    icoac_real_t all_nan[ICOAC_MAX_INPUTS];
    int i;
    cfg.mode = ICOAC_MODE_RL; /* the mode with a critic geometry */
    for (i = 0; i < ICOAC_PRIV_CRITIC_WEIGHTS; ++i) {
        v[i] = (icoac_real_t)0.5;
    }
    for (i = 0; i < ICOAC_MAX_INPUTS; ++i) {
        all_nan[i] = (icoac_real_t)NAN;
    }
    check_scan(&cfg, v, all_nan);
    s[ICOAC_IDX_THETA] = (icoac_real_t)NAN;
    s[ICOAC_IDX_THETA_DOT] = (icoac_real_t)-NAN;
    check_scan(&cfg, v, s);
    cfg.critic.threshold = 0; /* the smallest-normal floor */
    check_scan(&cfg, v, s);
}

/* Reproducer 1, second half: the configuration is now rejected, and an RL tick at s = 0 from
 * the nearest accepted range is finite. */
static void test_subnormal_critic_range(void)
{
    icoac_config_t cfg = test_default_config();
    icoac_state_t state;
    icoac_input_t in = test_input(0, 0, 0, 0, 0);
    const char *field = NULL;
    cfg.mode = ICOAC_MODE_RL;
    cfg.critic.range[0] = (icoac_real_t)1e-39;
    TEST_ASSERT_EQUAL_INT(ICOAC_ERR_BAD_CRITIC, icoac_config_check_field(&cfg, &field));
    TEST_ASSERT_EQUAL_STRING("critic.range[0]", field);
    TEST_ASSERT_EQUAL_INT(ICOAC_ERR_BAD_CRITIC, icoac_init(&cfg, &state, NULL, 1u));
    cfg.critic.range[0] = ICOAC_RANGE_MIN;
    TEST_ASSERT_EQUAL_INT(ICOAC_OK, icoac_init(&cfg, &state, NULL, 1u));
    TEST_ASSERT_EQUAL_INT(ICOAC_OK, checked_step(&cfg, &state, &in));
    in.s[0] = (icoac_real_t)1e30; /* far outside the narrow grid: s * n / range overflows */
    TEST_ASSERT_EQUAL_INT(ICOAC_OK, checked_step(&cfg, &state, &in));
    in.s[0] = -FLT_MAX;
    TEST_ASSERT_EQUAL_INT(ICOAC_OK, checked_step(&cfg, &state, &in));
}

/* Reproducer 2: unclipped inputs with a huge finite x gave an OK tick with an infinite force
 * (ICO) or NaN weights (RL). Now: a numeric fault, nothing learned, and the controller goes
 * on from the same state when the input is sane again. */
static void test_unclipped_huge_input(void)
{
    int mode;
    for (mode = ICOAC_MODE_ICO; mode <= ICOAC_MODE_RL; ++mode) {
        icoac_config_t cfg = test_default_config();
        icoac_state_t state;
        icoac_state_t twin;
        icoac_input_t calm = test_input(0.1, 0, 0.01, 0, 0);
        /* finite, but x / input_range overflows; in the penalty zone, so ICO learns from it */
        icoac_input_t huge = test_input(REAL_IS_FLOAT ? 3e38 : 1e303, 0, 0.3, 0, 0);
        cfg.mode = mode;
        cfg.policy.clip_inputs = 0;
        cfg.policy.input_range[0] = ICOAC_RANGE_MIN;
        TEST_ASSERT_EQUAL_INT(ICOAC_OK, icoac_init(&cfg, &state, NULL, 3u));
        TEST_ASSERT_EQUAL_INT(ICOAC_OK, checked_step(&cfg, &state, &calm));
        twin = state;
        TEST_ASSERT_EQUAL_INT(ICOAC_ERR_NUMERIC, checked_step(&cfg, &state, &huge));
        TEST_ASSERT_EQUAL_INT(ICOAC_OK, checked_step(&cfg, &state, &calm));
        TEST_ASSERT_EQUAL_INT(ICOAC_OK, checked_step(&cfg, &twin, &calm));
        TEST_ASSERT_EQUAL_MEMORY(priv(&twin)->w, priv(&state)->w, sizeof priv(&state)->w);
        TEST_ASSERT_EQUAL_MEMORY(priv(&twin)->v, priv(&state)->v, sizeof priv(&state)->v);
        TEST_ASSERT_EQUAL_MEMORY(icoac_priv_cov_c(priv(&twin)), icoac_priv_cov_c(priv(&state)),
                                 sizeof(icoac_real_t) * ICOAC_CARTPOLE_INPUTS * ICOAC_CARTPOLE_INPUTS);
    }
}

/* Reproducer 3: priors the check accepted but whose derived values overflowed (|w|^2 of a mean
 * of 1e30: OK ticks with an infinite |w|), or which a host that flushes subnormals reads
 * differently (a subnormal diagonal becomes 0, a subnormal asymmetry disappears). Now rejected;
 * the largest accepted covariance, inflated by forgetting (posterior reading, the literal one),
 * gives numeric faults. */
static void test_prior_bounds(void)
{
    icoac_config_t cfg = test_default_config();
    icoac_state_t state;
    icoac_prior_t prior = test_prior(1e30, 0.1, 0.5, 0.1, 1.0);
    icoac_input_t in = test_input(1.0, 0.5, 0.1, 0.2, 0);
    int k;
    int faults = 0;
    TEST_ASSERT_EQUAL_INT(ICOAC_ERR_BAD_PRIOR, icoac_prior_check(&prior, ICOAC_CARTPOLE_INPUTS));
    prior = test_prior(0, 0, 0, 0, 1.0);
    prior.cov[1][1] = (icoac_real_t)1e-39; /* subnormal in float, tiny in double: below 1e-12 of the rest */
    TEST_ASSERT_EQUAL_INT(REAL_IS_FLOAT ? ICOAC_ERR_BAD_PRIOR : ICOAC_OK, icoac_prior_check(&prior, ICOAC_CARTPOLE_INPUTS));
    prior = test_prior(0, 0, 0, 0, 1.0);
    prior.cov[3][0] = (icoac_real_t)(REAL_IS_FLOAT ? -1e-39 : -1e-310);
    TEST_ASSERT_EQUAL_INT(ICOAC_ERR_BAD_PRIOR, icoac_prior_check(&prior, ICOAC_CARTPOLE_INPUTS));
    prior.cov[0][3] = prior.cov[3][0]; /* symmetric now, but still subnormal */
    TEST_ASSERT_EQUAL_INT(ICOAC_ERR_BAD_PRIOR, icoac_prior_check(&prior, ICOAC_CARTPOLE_INPUTS));
    prior = test_prior(ICOAC_PRIOR_MEAN_MAX, 0, 0, 0, 1.1 * (double)ICOAC_PRIOR_COV_MAX);
    TEST_ASSERT_EQUAL_INT(ICOAC_ERR_BAD_PRIOR, icoac_prior_check(&prior, ICOAC_CARTPOLE_INPUTS));

    prior = test_prior(ICOAC_PRIOR_MEAN_MAX, 0.1, 0.5, 0.1, (double)ICOAC_PRIOR_COV_MAX);
    cfg.mode = ICOAC_MODE_RL;
    test_literal_reading(&cfg);
    cfg.actor.forgetting = ICOAC_FORGETTING_MIN;
    TEST_ASSERT_EQUAL_INT(ICOAC_OK, icoac_prior_check(&prior, ICOAC_CARTPOLE_INPUTS));
    TEST_ASSERT_EQUAL_INT(ICOAC_OK, icoac_init(&cfg, &state, &prior, 5u));
    for (k = 0; k < (REAL_IS_FLOAT ? 200 : 1200); ++k) {
        faults += checked_step(&cfg, &state, &in) == ICOAC_ERR_NUMERIC;
    }
    TEST_ASSERT_TRUE(faults > 0);
    TEST_ASSERT_EQUAL_UINT32((uint32_t)faults, priv(&state)->counters.numeric_faults);
}

/* Forgetting inflates Sigma_w by 1/lambda per tick (posterior reading, exploring at every
 * tick); at s = 0 no observation informs it, so it overflows after ~128 ticks at lambda = 0.5.
 * Every tick is OK and finite until then, every later one a numeric fault. */
static void test_forgetting_overflow_is_a_fault(void)
{
    icoac_config_t cfg = test_default_config();
    icoac_state_t state;
    icoac_input_t in = test_input(0, 0, 0, 0, 0);
    int k;
    int first_fault = -1;
    cfg.mode = ICOAC_MODE_RL;
    test_literal_reading(&cfg);
    cfg.actor.forgetting = ICOAC_FORGETTING_MIN;
    TEST_ASSERT_EQUAL_INT(ICOAC_OK, icoac_init(&cfg, &state, NULL, 11u));
    for (k = 0; k < (REAL_IS_FLOAT ? 400 : 2200); ++k) {
        const icoac_status_t status = checked_step(&cfg, &state, &in);
        if (status != ICOAC_OK && first_fault < 0) {
            first_fault = k;
        }
        if (first_fault >= 0) {
            TEST_ASSERT_EQUAL_INT(ICOAC_ERR_NUMERIC, status);
        }
    }
    TEST_ASSERT_TRUE(first_fault > 100);
    TEST_ASSERT_EQUAL_UINT32((uint32_t)((REAL_IS_FLOAT ? 400 : 2200) - first_fault), priv(&state)->counters.numeric_faults);
}

/* Random walks over accepted extreme configurations and extreme finite inputs: every tick
 * keeps the contract (checked_step asserts it). RL runs cycle through the three actor readings
 * (sigma_L = sigma_u or the largest sigma_L), per tick or per trial, with or without an
 * exploration schedule. */
static void test_contract_random_extremes(void)
{
    static const double extremes[] = {0.0, -0.0, 1e-39, -1e-39, 1e-6, 0.5, -1.0, 3.0, 1e6, -1e12, 1e30, -3e38};
    const int n_extremes = (int)(sizeof extremes / sizeof extremes[0]);
    test_rng_t rng = {0xC0FFEEu};
    int run;
    for (run = 0; run < 200; ++run) {
        icoac_config_t cfg = test_default_config();
        icoac_state_t state;
        int k;
        cfg.mode = run % 2;
        cfg.policy.clip_inputs = (run / 2) % 2;
        cfg.actor.act_with_sample = (run / 4) % 2;
        cfg.ico.timing = (run / 8) % 2;
        cfg.policy.gain = ICOAC_GAIN_MAX;
        cfg.ico.rate = ICOAC_ICO_RATE_MAX;
        cfg.actor.noise_std = run % 3 ? ICOAC_NOISE_STD_MIN : ICOAC_NOISE_STD_MAX;
        cfg.actor.scale = ICOAC_ACTOR_SCALE_MAX;
        cfg.critic.td_clip = ICOAC_TD_CLIP_MAX;
        cfg.critic.rate = ICOAC_CRITIC_RATE_MAX;
        cfg.actor.forgetting = run % 5 ? ICOAC_R(1.0) : ICOAC_FORGETTING_MIN;
        cfg.policy.input_range[run % 4] = ICOAC_RANGE_MIN;
        cfg.critic.range[(run + 1) % 4] = ICOAC_RANGE_MIN;
        cfg.critic.threshold = run % 7 ? cfg.critic.threshold : ICOAC_R(0.0);
        cfg.actor.update = (run / 16) % 3;
        cfg.actor.batch = (run / 48) % 2;
        cfg.actor.explore_ticks = run % 11 < 4 ? 0 : (run % 11 < 8 ? 3 : 1000);
        cfg.actor.likelihood_std = run % 13 ? ICOAC_R(0.0) : ICOAC_NOISE_STD_MAX;
        TEST_ASSERT_EQUAL_INT(ICOAC_OK, icoac_init(&cfg, &state, NULL, (uint64_t)run));
        /* every configuration, fewer ticks each on an emulated core (QEMU is slow) */
        for (k = 0; k < TEST_ITERATIONS(300, 30); ++k) {
            icoac_input_t in;
            int i;
            for (i = 0; i < ICOAC_CARTPOLE_INPUTS; ++i) {
                const int pick = (int)(test_rng_u64(&rng) % (uint64_t)(n_extremes + 4));
                in.s[i] = (icoac_real_t)(pick < n_extremes ? extremes[pick] : test_uniform(&rng, -3, 3));
            }
            in.flags = test_rng_u64(&rng) % 20u == 0u ? ICOAC_INPUT_TERMINAL : 0u;
            (void)checked_step(&cfg, &state, &in);
            if (test_rng_u64(&rng) % 50u == 0u) {
                TEST_ASSERT_EQUAL_INT(ICOAC_OK, icoac_reset(&state));
                TEST_ASSERT_TRUE(state_finite(&state));
            }
        }
    }
}

/* The finiteness check itself, on every class of value. */
static void test_all_finite(void)
{
    icoac_real_t values[4] = {ICOAC_R(0.0), ICOAC_R(-0.0), ICOAC_R(1.0), ICOAC_R(-3.0e38)};
    TEST_ASSERT_TRUE(icoac_priv_all_finite(values, 4));
    values[2] = (icoac_real_t)1e-39; /* subnormal (float) is finite */
    TEST_ASSERT_TRUE(icoac_priv_all_finite(values, 4));
    values[1] = (icoac_real_t)INFINITY;
    TEST_ASSERT_FALSE(icoac_priv_all_finite(values, 4));
    values[1] = (icoac_real_t)-INFINITY;
    TEST_ASSERT_FALSE(icoac_priv_all_finite(values, 4));
    values[1] = (icoac_real_t)NAN;
    TEST_ASSERT_FALSE(icoac_priv_all_finite(values, 4));
    values[1] = -(icoac_real_t)NAN;
    TEST_ASSERT_FALSE(icoac_priv_all_finite(values, 4));
    TEST_ASSERT_TRUE(icoac_priv_all_finite(values, 1));
}

void setUp(void) {}
void tearDown(void) {}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_critic_scan_bounded_for_nan);
    RUN_TEST(test_subnormal_critic_range);
    RUN_TEST(test_unclipped_huge_input);
    RUN_TEST(test_prior_bounds);
    RUN_TEST(test_forgetting_overflow_is_a_fault);
    RUN_TEST(test_contract_random_extremes);
    RUN_TEST(test_all_finite);
    return UNITY_END();
}
