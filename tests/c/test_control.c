/* SPDX-License-Identifier: Apache-2.0 */
/* The no-learning control (method.md L1, cfg.learn = 0): the same acting, exploration noise and
 * random stream as learning, with every update off. */
#include "test_common.h"

#include "icoac_priv.h"

/* Ticks of each run: fewer on an emulated core, where QEMU is slow and the four runs' forces
 * (6.4 KB at 400 ticks, about 4 trials) must fit the Cortex-M0+ board's 16 KiB of RAM. */
#define TICKS TEST_ITERATIONS(20000, 400)

static icoac_input_t wandering_input(test_rng_t *rng, uint32_t flags)
{
    return test_input(test_uniform(rng, -2.5, 2.5), test_uniform(rng, -2, 2), test_uniform(rng, -0.22, 0.22),
                      test_uniform(rng, -2, 2), flags);
}

/* A long run of ticks, terminal calls and resets; returns nothing, fills forces. */
static void run(const icoac_config_t *cfg, icoac_state_t *state, const icoac_prior_t *prior, icoac_real_t *forces,
                int n)
{
    test_rng_t rng = {77u};
    int k;
    TEST_ASSERT_EQUAL_INT(ICOAC_OK, icoac_init(cfg, state, prior, 3u));
    for (k = 0; k < n; ++k) {
        icoac_output_t out;
        const uint32_t flags = k % 97 == 96 ? ICOAC_INPUT_TERMINAL : 0u;
        icoac_input_t in = wandering_input(&rng, flags);
        TEST_ASSERT_EQUAL_INT(ICOAC_OK, icoac_step(state, &in, &out));
        forces[k] = out.force;
        if (flags != 0u) {
            TEST_ASSERT_EQUAL_INT(ICOAC_OK, icoac_reset(state));
        }
    }
}

/* Nothing learned changes over a long run, in either mode and with either way of acting, and
 * in RL with each actor reading (the default gradient one, the literal posterior one, the
 * mean one per trial). */
static void test_control_learns_nothing(void)
{
    static icoac_real_t forces[TICKS];
    const icoac_prior_t prior = test_prior(0.1, 0.05, 0.4, 0.1, 0.3);
    int variant;
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
        run(&cfg, &state, &prior, forces, TICKS);
        TEST_ASSERT_EQUAL_INT(ICOAC_OK, icoac_get_posterior(&state, &post));
        TEST_ASSERT_EQUAL_MEMORY(prior.mean, post.mean, sizeof post.mean);
        TEST_ASSERT_EQUAL_MEMORY(prior.cov, post.cov, sizeof post.cov);
        TEST_ASSERT_EQUAL_MEMORY(v0, st->v, sizeof v0);
    }
}

/* RL: the control acts exactly like a run whose learning rates are 0 (the critic rate, and
 * the actor's: the scale alpha of the posterior and mean readings, the rate beta of the
 * gradient reading; the posterior reading still shrinks Sigma_w there, which does not change
 * how the mean acts), tick by tick, with the same noise and exploration schedule, for each
 * reading. And learning does change the forces. */
static void test_control_equals_zero_rates(void)
{
    static icoac_real_t control[TICKS], zero_rates[TICKS], learning[TICKS];
    const icoac_prior_t prior = test_prior(0.1, 0.05, 0.4, 0.1, 0.3);
    int variant;
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
        run(&cfg, &state, &prior, learning, TICKS);
        cfg.learn = 0;
        run(&cfg, &state, &prior, control, TICKS);
        cfg.learn = 1;
        cfg.critic.rate = 0;
        if (cfg.actor.update == ICOAC_ACTOR_GRADIENT) {
            cfg.actor.rate = 0;
        } else {
            cfg.actor.scale = 0;
        }
        run(&cfg, &state, &prior, zero_rates, TICKS);
        TEST_ASSERT_EQUAL_MEMORY(zero_rates, control, sizeof control);
        TEST_ASSERT_TRUE(memcmp(control, learning, sizeof control) != 0);
    }
}

static void test_learn_is_a_flag(void)
{
    icoac_config_t cfg = test_default_config();
    const char *field = 0;
    TEST_ASSERT_EQUAL_INT(1, cfg.learn);
    cfg.learn = 2;
    TEST_ASSERT_EQUAL_INT(ICOAC_ERR_BAD_MODE, icoac_config_check_field(&cfg, &field));
    TEST_ASSERT_EQUAL_STRING("learn", field);
}

void setUp(void) {}
void tearDown(void) {}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_control_learns_nothing);
    RUN_TEST(test_control_equals_zero_rates);
    RUN_TEST(test_learn_is_a_flag);
    return UNITY_END();
}
