/* Properties of icoac_step / icoac_reset: what persists, when nothing is learned,
 * and how non-finite observations are rejected. */
#include "test_common.h"

#include "icoac_internal.h"

/* A state outside the reflex zone: |x| < 2.3, |theta| < 11 deg, any velocities. */
static icoac_input_t calm_input(test_rng_t *rng)
{
    return test_input(test_uniform(rng, -2.3, 2.3), test_uniform(rng, -6, 6), test_uniform(rng, -DEG(11), DEG(11)),
                      test_uniform(rng, -4, 4), 0);
}

/* A state inside the reflex zone. */
static icoac_input_t zone_input(test_rng_t *rng)
{
    const double sign = test_uniform(rng, 0, 1) < 0.5 ? -1.0 : 1.0;
    if (test_uniform(rng, 0, 1) < 0.5) {
        return test_input(test_uniform(rng, -2.3, 2.3), test_uniform(rng, -6, 6), sign * test_uniform(rng, DEG(11.6), DEG(20)),
                          test_uniform(rng, -4, 4), 0);
    }
    return test_input(sign * test_uniform(rng, 2.36, 3.0), test_uniform(rng, -6, 6), test_uniform(rng, -DEG(11), DEG(11)),
                      test_uniform(rng, -4, 4), 0);
}

static void test_reset_keeps_learning_code_timing(void **unused)
{
    icoac_config_t cfg = test_default_config();
    icoac_state_t state, before;
    icoac_output_t out;
    test_rng_t rng = {99u};
    icoac_input_t in;
    (void)unused;
    assert_int_equal(icoac_init(&cfg, &state, NULL, 5u), ICOAC_OK);
    in = calm_input(&rng);
    assert_int_equal(icoac_step(&cfg, &state, &in, &out), ICOAC_OK);
    in = zone_input(&rng);
    assert_int_equal(icoac_step(&cfg, &state, &in, &out), ICOAC_OK);
    assert_true(out.q == 1);
    assert_true(out.weight_norm > 0);
    before = state;
    assert_int_equal(icoac_reset(&cfg, &state), ICOAC_OK);
    assert_memory_equal(state.w, before.w, sizeof state.w);
    assert_memory_equal(state.cov, before.cov, sizeof state.cov);
    assert_memory_equal(state.v, before.v, sizeof state.v);
    assert_true(state.penalty_prev == -1);
    assert_memory_equal(&state.rng, &before.rng, sizeof state.rng);
    /* r_prev persisted: starting the new trial inside the zone gives no learning */
    in = zone_input(&rng);
    assert_int_equal(icoac_step(&cfg, &state, &in, &out), ICOAC_OK);
    assert_true(out.q == 0);
    assert_memory_equal(state.w, before.w, sizeof state.w);
}

static void test_reset_keeps_learning_rl(void **unused)
{
    icoac_config_t cfg = test_default_config();
    icoac_state_t state, before;
    icoac_output_t out;
    test_rng_t rng = {1234u};
    icoac_input_t in;
    int k, nonzero = 0;
    (void)unused;
    cfg.mode = ICOAC_MODE_RL;
    assert_int_equal(icoac_init(&cfg, &state, NULL, 5u), ICOAC_OK);
    for (k = 0; k < 50; ++k) {
        in = calm_input(&rng);
        if (k % 10 == 9) {
            in.flags = ICOAC_INPUT_TERMINAL;
        }
        assert_int_equal(icoac_step(&cfg, &state, &in, &out), ICOAC_OK);
    }
    for (k = 0; k < ICOAC_CRITIC_UNITS; ++k) {
        nonzero += state.v[k] != 0;
    }
    assert_true(nonzero > 0);
    before = state;
    assert_int_equal(icoac_reset(&cfg, &state), ICOAC_OK);
    assert_memory_equal(state.w, before.w, sizeof state.w);
    assert_memory_equal(state.cov, before.cov, sizeof state.cov);
    assert_memory_equal(state.v, before.v, sizeof state.v);
    assert_int_equal(state.has_prev, 0);
    /* the first tick of a trial has no transition to learn from */
    in = calm_input(&rng);
    assert_int_equal(icoac_step(&cfg, &state, &in, &out), ICOAC_OK);
    assert_true(out.td_error == 0);
    assert_memory_equal(state.w, before.w, sizeof state.w);
    assert_memory_equal(state.v, before.v, sizeof state.v);
}

static void test_no_penalty_change_no_learning(void **unused)
{
    int timing;
    (void)unused;
    for (timing = 0; timing <= 1; ++timing) {
        icoac_config_t cfg = test_default_config();
        icoac_state_t state;
        icoac_output_t out;
        icoac_prior_t p = test_prior(0.07, 0.05, 0.3, 0.08, 1.0);
        icoac_prior_t post;
        test_rng_t rng = {777u + (uint64_t)timing};
        icoac_input_t in;
        int k, learned = 0;
        cfg.ico_timing = timing;
        assert_int_equal(icoac_init(&cfg, &state, &p, 5u), ICOAC_OK);
        /* many calm ticks, with resets: r stays 0 */
        for (k = 0; k < 20000; ++k) {
            if (k % 1000 == 999) {
                assert_int_equal(icoac_reset(&cfg, &state), ICOAC_OK);
            }
            in = calm_input(&rng);
            assert_int_equal(icoac_step(&cfg, &state, &in, &out), ICOAC_OK);
            assert_true(out.q == 0);
        }
        assert_int_equal(icoac_get_posterior(&state, &post), ICOAC_OK);
        assert_memory_equal(post.mean, p.mean, sizeof p.mean);
        /* then only in-zone ticks: exactly one onset, hence one update */
        for (k = 0; k < 20000; ++k) {
            in = zone_input(&rng);
            assert_int_equal(icoac_step(&cfg, &state, &in, &out), ICOAC_OK);
            learned += out.q != 0;
        }
        assert_int_equal(learned, 1);
    }
}

/* Run a few ticks so that every learned field is non-trivial. */
static void warm_up(const icoac_config_t *cfg, icoac_state_t *state)
{
    test_rng_t rng = {4242u};
    icoac_output_t out;
    icoac_input_t in;
    int k;
    for (k = 0; k < 30; ++k) {
        /* ends inside the zone so that penalty_prev = -1 (ICO) and x_prev is non-zero */
        in = (k % 7 == 3 || k >= 28) ? zone_input(&rng) : calm_input(&rng);
        assert_int_equal(icoac_step(cfg, state, &in, &out), ICOAC_OK);
    }
}

static void test_nonfinite_inputs(void **unused)
{
    const double bad[3] = {(double)NAN, (double)INFINITY, -(double)INFINITY};
    int variant;
    (void)unused;
    for (variant = 0; variant < 4; ++variant) {
        icoac_config_t cfg = test_default_config();
        int comp, b;
        if (variant == 1) {
            cfg.ico_timing = ICOAC_ICO_TIMING_LITERAL;
        } else if (variant >= 2) {
            cfg.mode = ICOAC_MODE_RL;
            cfg.act_with_sample = variant == 3;
        }
        for (comp = 0; comp < ICOAC_N_INPUTS; ++comp) {
            for (b = 0; b < 3; ++b) {
                uint32_t flags;
                for (flags = 0; flags <= ICOAC_INPUT_TERMINAL; ++flags) {
                    icoac_state_t state, twin, snapshot;
                    icoac_output_t out, out_twin;
                    icoac_input_t in = test_input(0.1, -0.2, 0.05, 0.3, flags);
                    icoac_input_t next = test_input(-0.4, 0.2, -0.03, 0.1, 0);
                    icoac_prior_t p = test_prior(0.1, 0.05, 0.3, 0.1, 0.5);
                    assert_int_equal(icoac_init(&cfg, &state, &p, 9u), ICOAC_OK);
                    warm_up(&cfg, &state);
                    if (cfg.mode == ICOAC_MODE_ICO) {
                        assert_true(state.penalty_prev == -1);
                    }
                    twin = state;
                    snapshot = state;
                    in.s[comp] = (icoac_real_t)bad[b];
                    memset(&out, 0x7F, sizeof out);
                    assert_int_equal(icoac_step(&cfg, &state, &in, &out), ICOAC_ERR_NONFINITE_INPUT);
                    assert_int_equal(out.status, ICOAC_ERR_NONFINITE_INPUT);
                    assert_true(out.force == 0);
                    assert_true(out.q == 0);
                    assert_int_equal(state.ticks, snapshot.ticks + 1u);
                    assert_int_equal(state.nonfinite_count, snapshot.nonfinite_count + 1u);
                    /* everything else byte-identical: w, cov, v, penalty_prev, x_prev, rng, ... */
                    snapshot.ticks = state.ticks;
                    snapshot.nonfinite_count = state.nonfinite_count;
                    assert_memory_equal(&state, &snapshot, sizeof state);
                    /* and the next valid tick behaves as if the bad one never happened
                     * (same fill for both: icoac_step does not write struct padding) */
                    memset(&out, 0, sizeof out);
                    memset(&out_twin, 0, sizeof out_twin);
                    assert_int_equal(icoac_step(&cfg, &state, &next, &out), ICOAC_OK);
                    assert_int_equal(icoac_step(&cfg, &twin, &next, &out_twin), ICOAC_OK);
                    assert_memory_equal(&out, &out_twin, sizeof out);
                    assert_memory_equal(state.w, twin.w, sizeof state.w);
                    assert_memory_equal(state.v, twin.v, sizeof state.v);
                }
            }
        }
    }
}

static void test_output_status_and_counters(void **unused)
{
    icoac_config_t cfg = test_default_config();
    icoac_state_t state;
    icoac_output_t out;
    test_rng_t rng = {5u};
    icoac_input_t in;
    int k;
    (void)unused;
    assert_int_equal(icoac_init(&cfg, &state, NULL, 1u), ICOAC_OK);
    for (k = 0; k < 10; ++k) {
        in = calm_input(&rng);
        assert_int_equal(icoac_step(&cfg, &state, &in, &out), ICOAC_OK);
        assert_int_equal(out.status, ICOAC_OK);
    }
    assert_int_equal(state.ticks, 10u);
    assert_int_equal(state.nonfinite_count, 0u);
}

/* Every output field is cleared on entry, so an error leaves no stale value: fill the struct,
 * call with an uninitialised state, and check every real before status (fields added later
 * are covered as well). */
static void test_output_cleared_on_error(void **unused)
{
    icoac_config_t cfg = test_default_config();
    icoac_state_t state;
    icoac_output_t out;
    icoac_input_t in = test_input(0.1, 0.0, 0.02, 0.0, 0);
    const icoac_real_t *reals = (const icoac_real_t *)(const void *)&out;
    const size_t n_reals = offsetof(icoac_output_t, status) / sizeof(icoac_real_t);
    size_t i;
    (void)unused;
    memset(&state, 0, sizeof state);
    memset(&out, 0x7F, sizeof out);
    assert_int_equal(icoac_step(&cfg, &state, &in, &out), ICOAC_ERR_NOT_INITIALISED);
    assert_int_equal(out.status, ICOAC_ERR_NOT_INITIALISED);
    assert_true(n_reals >= 10u);
    for (i = 0; i < n_reals; ++i) {
        assert_true(reals[i] == 0);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_reset_keeps_learning_code_timing),
        cmocka_unit_test(test_reset_keeps_learning_rl),
        cmocka_unit_test(test_no_penalty_change_no_learning),
        cmocka_unit_test(test_nonfinite_inputs),
        cmocka_unit_test(test_output_status_and_counters),
        cmocka_unit_test(test_output_cleared_on_error),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
