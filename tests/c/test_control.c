/* SPDX-License-Identifier: Apache-2.0 */
/* The no-learning control (method.md L1, cfg.learn = 0): the same acting, exploration noise and
 * random stream as learning, with every update off. */
#include "test_common.h"

#include "icoac_priv.h"

static icoac_input_t wandering_input(test_rng_t *rng, uint32_t flags)
{
    return test_input(test_uniform(rng, -2.5, 2.5), test_uniform(rng, -2, 2), test_uniform(rng, -0.22, 0.22),
                      test_uniform(rng, -2, 2), flags);
}

/* A long run of ticks, terminal calls and resets; returns nothing, fills forces. */
static void run(const icoac_config_t *cfg, icoac_state_t *state, const icoac_prior_t *prior, double *forces,
                int n)
{
    test_rng_t rng = {77u};
    int k;
    assert_int_equal(icoac_init(cfg, state, prior, 3u), ICOAC_OK);
    for (k = 0; k < n; ++k) {
        icoac_output_t out;
        const uint32_t flags = k % 97 == 96 ? ICOAC_INPUT_TERMINAL : 0u;
        icoac_input_t in = wandering_input(&rng, flags);
        assert_int_equal(icoac_step(state, &in, &out), ICOAC_OK);
        forces[k] = (double)out.force;
        if (flags != 0u) {
            assert_int_equal(icoac_reset(state), ICOAC_OK);
        }
    }
}

/* Nothing learned changes over a long run, in either mode and with either way of acting, and
 * in RL with each actor reading (the default gradient one, the literal posterior one, the
 * mean one per trial). */
static void test_control_learns_nothing(void **unused)
{
    static double forces[20000];
    const icoac_prior_t prior = test_prior(0.1, 0.05, 0.4, 0.1, 0.3);
    int variant;
    (void)unused;
    for (variant = 0; variant < 6; ++variant) {
        icoac_config_t cfg = test_default_config();
        icoac_state_t state;
        icoac_priv_state_t *st = icoac_priv_state(&state);
        icoac_real_t v0[ICOAC_CARTPOLE_CRITIC_UNITS];
        icoac_prior_t post;
        cfg.learn = 0;
        cfg.mode = (variant < 2 || variant >= 4) ? ICOAC_MODE_RL : ICOAC_MODE_ICO;
        cfg.actor.act_with_sample = variant == 1;
        cfg.ico.timing = variant == 3 ? ICOAC_ICO_TIMING_LITERAL : ICOAC_ICO_TIMING_CODE;
        if (variant == 4) {
            test_literal_reading(&cfg);
        } else if (variant == 5) {
            cfg.actor.update = ICOAC_ACTOR_MEAN;
            cfg.actor.batch = 1;
        }
        memset(v0, 0, sizeof v0);
        run(&cfg, &state, &prior, forces, 20000);
        assert_int_equal(icoac_get_posterior(&state, &post), ICOAC_OK);
        assert_memory_equal(post.mean, prior.mean, sizeof post.mean);
        assert_memory_equal(post.cov, prior.cov, sizeof post.cov);
        assert_memory_equal(st->v, v0, sizeof v0);
    }
}

/* RL: the control acts exactly like a run whose learning rates are 0 (the critic rate, and
 * the actor's: the scale alpha of the posterior and mean readings, the rate beta of the
 * gradient reading; the posterior reading still shrinks Sigma_w there, which does not change
 * how the mean acts), tick by tick, with the same noise and exploration schedule, for each
 * reading. And learning does change the forces. */
static void test_control_equals_zero_rates(void **unused)
{
    static double control[20000], zero_rates[20000], learning[20000];
    const icoac_prior_t prior = test_prior(0.1, 0.05, 0.4, 0.1, 0.3);
    int variant;
    (void)unused;
    for (variant = 0; variant < 4; ++variant) {
        icoac_config_t cfg = test_default_config();
        icoac_state_t state;
        cfg.mode = ICOAC_MODE_RL;
        switch (variant) {
        case 0: break; /* the defaults: gradient, exploring for the first 1000 ticks of a trial */
        case 1: test_literal_reading(&cfg); break;
        case 2: cfg.actor.update = ICOAC_ACTOR_MEAN; cfg.actor.explore_ticks = 0; break;
        default: cfg.actor.explore_ticks = 40; break; /* shorter than the 97-tick trials */
        }
        run(&cfg, &state, &prior, learning, 20000);
        cfg.learn = 0;
        run(&cfg, &state, &prior, control, 20000);
        cfg.learn = 1;
        cfg.critic.rate = 0;
        if (cfg.actor.update == ICOAC_ACTOR_GRADIENT) {
            cfg.actor.rate = 0;
        } else {
            cfg.actor.scale = 0;
        }
        run(&cfg, &state, &prior, zero_rates, 20000);
        assert_memory_equal(control, zero_rates, sizeof control);
        assert_true(memcmp(control, learning, sizeof control) != 0);
    }
}

static void test_learn_is_a_flag(void **unused)
{
    icoac_config_t cfg = test_default_config();
    const char *field = 0;
    (void)unused;
    assert_int_equal(cfg.learn, 1);
    cfg.learn = 2;
    assert_int_equal(icoac_config_check_field(&cfg, &field), ICOAC_ERR_BAD_MODE);
    assert_string_equal(field, "learn");
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_control_learns_nothing),
        cmocka_unit_test(test_control_equals_zero_rates),
        cmocka_unit_test(test_learn_is_a_flag),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
