/* SPDX-License-Identifier: Apache-2.0 */
/* Misuse: a configuration edited after icoac_init, live retuning, unknown switches,
 * non-finite fields, repeated terminal ticks and corrupted state bytes. Each reproducer of the
 * misuse report is a test here; run under ASan and UBSan (preset debug-asan), an access outside
 * the state or an undefined conversion fails it. */
#include "test_common.h"

#if !ICOAC_TEST_ON_TARGET
#include <stdlib.h>
#endif

#include "icoac_priv.h"

#define N ICOAC_CARTPOLE_INPUTS /* the cart-pole task's inputs */
#define M ICOAC_MAX_INPUTS      /* the library's vectors: entries past N are 0 */

static const icoac_priv_state_t *priv(const icoac_state_t *state)
{
    return icoac_priv_state_c(state);
}

static icoac_priv_state_t *priv_mut(icoac_state_t *state)
{
    return icoac_priv_state(state);
}

/* A rejected tick may leave its scratch (the spare kept-unit slot, the spare covariance buffer,
 * the batch's staged shift: never read before a commit) and counts itself; everything else is
 * as it was. */
static void assert_unchanged_but_scratch(const icoac_state_t *state, const icoac_state_t *before)
{
    icoac_state_t expect = *before;
    icoac_priv_state_t *e = icoac_priv_state(&expect);
    const icoac_priv_state_t *s = priv(state);
    const int active_spare = (e->active_slot & 1) ^ 1;
    const int cov_spare = (e->cov_slot & 1) ^ 1;
    e->counters = s->counters;
    memcpy(&e->active[active_spare], &s->active[active_spare], sizeof e->active[active_spare]);
    memcpy(e->cov_buffer[cov_spare], s->cov_buffer[cov_spare], sizeof e->cov_buffer[cov_spare]);
    memcpy(e->batch.staged_shift, s->batch.staged_shift, sizeof e->batch.staged_shift);
    TEST_ASSERT_EQUAL_MEMORY(&expect, state, sizeof expect);
}

#if ICOAC_TEST_ON_TARGET
/* No heap on a bare-metal core (firmware/port links none): the states (at most two at once in a
 * test) come from a static pair, in turn. */
static icoac_state_t *new_state(void)
{
    static icoac_state_t pair[2];
    static unsigned next;
    icoac_state_t *state = &pair[next++ % 2u];
    memset(state, 0, sizeof *state);
    return state;
}

static void free_state(icoac_state_t *state)
{
    (void)state;
}
#else
/* A state in its own heap block of exactly its size, so that ASan sees a one-byte overrun. */
static icoac_state_t *new_state(void)
{
    icoac_state_t *state = malloc(sizeof *state);
    TEST_ASSERT_NOT_NULL(state);
    memset(state, 0, sizeof *state);
    return state;
}

static void free_state(icoac_state_t *state)
{
    free(state);
}
#endif

static icoac_input_t calm(test_rng_t *rng, uint32_t flags)
{
    return test_input(test_uniform(rng, -0.5, 0.5), test_uniform(rng, -0.5, 0.5), test_uniform(rng, -0.05, 0.05),
                      test_uniform(rng, -0.5, 0.5), flags);
}

/* One trial: reset, ticks plain ticks, one terminal tick; the statuses must be OK. */
static void trial(icoac_state_t *state, test_rng_t *rng, int ticks)
{
    icoac_output_t out;
    icoac_input_t in;
    int k;
    TEST_ASSERT_EQUAL_INT(ICOAC_OK, icoac_reset(state));
    for (k = 0; k < ticks; ++k) {
        in = calm(rng, 0u);
        TEST_ASSERT_EQUAL_INT(ICOAC_OK, icoac_step(state, &in, &out));
    }
    in = calm(rng, ICOAC_INPUT_TERMINAL);
    TEST_ASSERT_EQUAL_INT(ICOAC_OK, icoac_step(state, &in, &out));
}

/* Reproducer: search mode, init, then search.batch = 1000 and 40 trials. Before, the tick used
 * the edited batch as the bound of its trial record and wrote past w[16] / ticks[16], then past
 * the state. Now the caller's edit changes nothing (the state runs on its own copy, bit for bit
 * as a twin that was never edited), and the same value forced into the state's copy is clamped
 * where it is used, then refused by icoac_reset. */
static void test_search_batch_edited_after_init(void)
{
    icoac_config_t cfg = test_default_config();
    icoac_state_t *state = new_state();
    icoac_state_t *twin = new_state();
    test_rng_t rng = {1u}, rng_twin = {1u};
    icoac_output_t out;
    icoac_input_t in;
    int t, k;
    cfg.mode = ICOAC_MODE_SEARCH;
    TEST_ASSERT_EQUAL_INT(ICOAC_OK, icoac_init(&cfg, state, NULL, 3u));
    TEST_ASSERT_EQUAL_INT(ICOAC_OK, icoac_init(&cfg, twin, NULL, 3u));
    cfg.search.batch = 1000;
    for (t = 0; t < 40; ++t) {
        trial(state, &rng, 20);
        trial(twin, &rng_twin, 20);
    }
    TEST_ASSERT_EQUAL_MEMORY(twin, state, sizeof *state);
    /* the same value inside the state (corrupted memory), with a full record: clamped */
    priv_mut(state)->config.search.batch = 1000;
    for (t = 0; t < 40; ++t) {
        priv_mut(state)->magic = ICOAC_PRIV_STATE_MAGIC; /* a new trial without the checks of a reset */
        for (k = 0; k < 20; ++k) {
            in = calm(&rng, 0u);
            TEST_ASSERT_EQUAL_INT(ICOAC_OK, icoac_step(state, &in, &out));
        }
        in = calm(&rng, ICOAC_INPUT_TERMINAL);
        TEST_ASSERT_EQUAL_INT(ICOAC_OK, icoac_step(state, &in, &out));
        TEST_ASSERT_TRUE(priv(state)->search.count >= 0 && priv(state)->search.count < ICOAC_SEARCH_BATCH_MAX);
    }
    TEST_ASSERT_EQUAL_INT(ICOAC_ERR_CORRUPT_STATE, icoac_reset(state));
    free_state(state);
    free_state(twin);
}

/* Reproducer: policy.input_range edited after init kept its init-time 1/range (5979 of 6000
 * ticks differed from a fresh init). Now an edit alone changes nothing, and icoac_retune
 * applies it: the ticks then equal those of a fresh init with the edited configuration. */
static void test_retune_applies_input_range(void)
{
    icoac_config_t cfg = test_default_config();
    icoac_config_t edited;
    icoac_state_t *state = new_state();
    icoac_state_t *fresh = new_state();
    test_rng_t rng = {2u};
    int k, differ = 0;
    TEST_ASSERT_EQUAL_INT(ICOAC_OK, icoac_init(&cfg, state, NULL, 5u));
    edited = cfg;
    edited.policy.input_range[0] = ICOAC_R(1.2);
    edited.policy.input_range[2] = ICOAC_R(0.1);
    TEST_ASSERT_EQUAL_INT(ICOAC_OK, icoac_init(&edited, fresh, NULL, 5u));
    TEST_ASSERT_EQUAL_INT(ICOAC_OK, icoac_retune(state, &edited));
    test_assert_config_in_force(&edited, state);
    for (k = 0; k < 6000; ++k) {
        icoac_output_t out, out_fresh;
        icoac_input_t in = calm(&rng, 0u);
        memset(&out, 0, sizeof out); /* padding too (double build) */
        memset(&out_fresh, 0, sizeof out_fresh);
        TEST_ASSERT_EQUAL_INT(ICOAC_OK, icoac_step(state, &in, &out));
        TEST_ASSERT_EQUAL_INT(ICOAC_OK, icoac_step(fresh, &in, &out_fresh));
        differ += memcmp(&out, &out_fresh, sizeof out) != 0;
    }
    TEST_ASSERT_EQUAL_INT(0, differ);
    free_state(state);
    free_state(fresh);
}

/* search.floor and search.cov_scale: the floors follow a retune (floor * cov_scale * prior
 * variance), the learned Sigma_w is kept, and the next update holds Sigma_w's diagonal at the
 * new floors. */
static void test_retune_search_floors(void)
{
    icoac_config_t cfg = test_default_config();
    icoac_config_t tuned;
    icoac_state_t *state = new_state();
    icoac_prior_t prior = test_prior(0.1, 0.2, 1.0, 0.3, 0.5), before, after;
    test_rng_t rng = {3u};
    int i, t;
    cfg.mode = ICOAC_MODE_SEARCH;
    cfg.search.batch = 4;
    cfg.search.floor = ICOAC_R(1e-3);
    TEST_ASSERT_EQUAL_INT(ICOAC_OK, icoac_init(&cfg, state, &prior, 9u));
    TEST_ASSERT_EQUAL_INT(ICOAC_OK, icoac_get_posterior(state, &before));
    tuned = cfg;
    tuned.search.floor = ICOAC_R(2.0);
    tuned.search.cov_scale = ICOAC_R(8.0);
    TEST_ASSERT_EQUAL_INT(ICOAC_OK, icoac_retune(state, &tuned));
    TEST_ASSERT_EQUAL_INT(ICOAC_OK, icoac_get_posterior(state, &after));
    TEST_ASSERT_EQUAL_MEMORY(&after, &before, sizeof before); /* nothing learned is lost */
    for (i = 0; i < N; ++i) {
        TEST_ASSERT_TRUE(priv(state)->search.floor[i] == tuned.search.floor * (prior.cov[i][i] * tuned.search.cov_scale));
    }
    for (t = 0; t < tuned.search.batch; ++t) {
        trial(state, &rng, 5);
    }
    TEST_ASSERT_EQUAL_INT(ICOAC_OK, icoac_get_posterior(state, &after));
    for (i = 0; i < N; ++i) {
        TEST_ASSERT_TRUE(after.cov[i][i] >= priv(state)->search.floor[i]);
    }
    free_state(state);
}

/* Reproducer: RL -> SEARCH without a re-init ran the search with a zero Cholesky factor and
 * explored nothing. A retune cannot change the mode; the state stays as it was. */
static void test_retune_refuses_a_mode_change(void)
{
    icoac_config_t cfg = test_default_config();
    icoac_config_t other;
    icoac_state_t *state = new_state();
    icoac_state_t copy;
    test_rng_t rng = {4u};
    int mode;
    cfg.mode = ICOAC_MODE_RL;
    TEST_ASSERT_EQUAL_INT(ICOAC_OK, icoac_init(&cfg, state, NULL, 1u));
    trial(state, &rng, 30);
    copy = *state;
    for (mode = ICOAC_MODE_ICO; mode <= ICOAC_MODE_SEARCH; ++mode) {
        if (mode == ICOAC_MODE_RL) {
            continue;
        }
        other = cfg;
        other.mode = mode;
        TEST_ASSERT_EQUAL_INT(ICOAC_ERR_RETUNE_MODE, icoac_retune(state, &other));
        TEST_ASSERT_EQUAL_MEMORY(&copy, state, sizeof copy);
    }
    free_state(state);
}

/* Reproducer: mode 99 and ico.timing 7 ran a default branch with status OK. A retune refuses
 * them (state unchanged); forced into the state's copy, the tick refuses them with
 * ICOAC_ERR_CORRUPT_STATE (force 0, state unchanged but counters) and icoac_reset too. The same for
 * an unknown actor.update. */
static void test_unknown_switches(void)
{
    static const struct {
        int32_t mode;
        size_t offset; /* of the switch in icoac_config_t */
        int32_t value;
    } cases[] = {
        {ICOAC_MODE_ICO, offsetof(icoac_config_t, mode), 99},
        {ICOAC_MODE_ICO, offsetof(icoac_config_t, ico) + offsetof(icoac_ico_config_t, timing), 7},
        {ICOAC_MODE_RL, offsetof(icoac_config_t, mode), -1},
        {ICOAC_MODE_RL, offsetof(icoac_config_t, actor) + offsetof(icoac_actor_config_t, update), 3},
        {ICOAC_MODE_SEARCH, offsetof(icoac_config_t, mode), 3},
    };
    size_t c;
    for (c = 0; c < sizeof cases / sizeof cases[0]; ++c) {
        icoac_config_t cfg = test_default_config();
        icoac_config_t bad;
        icoac_state_t *state = new_state();
        icoac_state_t copy;
        icoac_output_t out;
        icoac_input_t in = test_input(0.1, 0.0, 0.02, 0.0, 0u);
        test_rng_t rng = {5u};
        cfg.mode = cases[c].mode;
        TEST_ASSERT_EQUAL_INT(ICOAC_OK, icoac_init(&cfg, state, NULL, 1u));
        trial(state, &rng, 10);
        TEST_ASSERT_EQUAL_INT(ICOAC_OK, icoac_reset(state));
        TEST_ASSERT_EQUAL_INT(ICOAC_OK, icoac_step(state, &in, &out)); /* a transition to learn from next */
        bad = cfg;
        memcpy((unsigned char *)&bad + cases[c].offset, &cases[c].value, sizeof cases[c].value);
        copy = *state;
        TEST_ASSERT_EQUAL_INT(ICOAC_ERR_BAD_MODE, icoac_retune(state, &bad));
        TEST_ASSERT_EQUAL_MEMORY(&copy, state, sizeof copy);
        memcpy((unsigned char *)&priv_mut(state)->config + cases[c].offset, &cases[c].value, sizeof cases[c].value);
        copy = *state;
        memset(&out, 0x7F, sizeof out);
        TEST_ASSERT_EQUAL_INT(ICOAC_ERR_CORRUPT_STATE, icoac_step(state, &in, &out));
        TEST_ASSERT_EQUAL_INT(ICOAC_ERR_CORRUPT_STATE, out.status);
        TEST_ASSERT_TRUE(out.force == 0);
        assert_unchanged_but_scratch(state, &copy);
        TEST_ASSERT_EQUAL_INT(ICOAC_ERR_CORRUPT_STATE, icoac_reset(state));
        free_state(state);
    }
}

/* Reproducers: actor.noise_std = NaN gave OK with a NaN force; critic.rate = 1e38 for three
 * trials broke the state for good (every later tick NUMERIC, even after a valid configuration
 * and a reset). Both are refused by the check of icoac_retune, the state unchanged; the trials
 * then run on the configuration in force. Corrupted learned values (NaN critic weights, as a
 * 1e38 rate used to leave) make the ticks ICOAC_ERR_NUMERIC and icoac_init restores the state;
 * corrupted actor weights are refused by icoac_reset too. */
static void test_nonfinite_fields_and_recovery(void)
{
    icoac_config_t cfg = test_default_config();
    icoac_config_t bad;
    icoac_state_t *state = new_state();
    icoac_state_t copy;
    icoac_output_t out;
    icoac_input_t in;
    test_rng_t rng = {6u};
    int t, k, numeric = 0;
    cfg.mode = ICOAC_MODE_RL;
    TEST_ASSERT_EQUAL_INT(ICOAC_OK, icoac_init(&cfg, state, NULL, 2u));
    copy = *state;
    bad = cfg;
    bad.actor.noise_std = (icoac_real_t)NAN;
    TEST_ASSERT_EQUAL_INT(ICOAC_ERR_BAD_ACTOR, icoac_retune(state, &bad));
    bad = cfg;
    bad.critic.rate = ICOAC_R(1e38);
    TEST_ASSERT_EQUAL_INT(ICOAC_ERR_BAD_CRITIC, icoac_retune(state, &bad));
    TEST_ASSERT_EQUAL_MEMORY(&copy, state, sizeof copy);
    for (t = 0; t < 3; ++t) {
        trial(state, &rng, 50);
    }
    /* corrupted learned values: the ticks fail, init restores */
    for (k = 0; k < ICOAC_CARTPOLE_CRITIC_UNITS; ++k) {
        priv_mut(state)->v[k] = k % 2 ? (icoac_real_t)NAN : (icoac_real_t)INFINITY;
    }
    TEST_ASSERT_EQUAL_INT(ICOAC_OK, icoac_reset(state));
    for (k = 0; k < 200; ++k) {
        in = calm(&rng, 0u);
        numeric += icoac_step(state, &in, &out) == ICOAC_ERR_NUMERIC;
    }
    TEST_ASSERT_TRUE(numeric > 0);
    priv_mut(state)->w[2] = (icoac_real_t)NAN;
    TEST_ASSERT_EQUAL_INT(ICOAC_ERR_CORRUPT_STATE, icoac_reset(state));
    TEST_ASSERT_EQUAL_INT(ICOAC_OK, icoac_init(&cfg, state, NULL, 2u));
    for (t = 0; t < 3; ++t) {
        trial(state, &rng, 50);
    }
    free_state(state);
}

/* Reproducer: elite_fraction 1e30 or NaN was an undefined float-to-int conversion. Forced into
 * the state's copy (a retune refuses it), a closing batch converts nothing out of range
 * (UBSan's float-cast-overflow) and the elite stays within the batch. */
static void test_corrupted_elite_fraction(void)
{
    const icoac_real_t values[] = {ICOAC_R(1e30), (icoac_real_t)NAN, ICOAC_R(-1e30), (icoac_real_t)INFINITY};
    size_t v;
    for (v = 0; v < sizeof values / sizeof values[0]; ++v) {
        icoac_config_t cfg = test_default_config();
        icoac_config_t bad;
        icoac_state_t *state = new_state();
        test_rng_t rng = {7u};
        icoac_output_t out;
        icoac_input_t in;
        int t, k;
        cfg.mode = ICOAC_MODE_SEARCH;
        cfg.search.batch = 4;
        TEST_ASSERT_EQUAL_INT(ICOAC_OK, icoac_init(&cfg, state, NULL, 4u));
        bad = cfg;
        bad.search.elite_fraction = values[v];
        TEST_ASSERT_EQUAL_INT(ICOAC_ERR_BAD_SEARCH, icoac_retune(state, &bad));
        priv_mut(state)->config.search.elite_fraction = values[v];
        for (t = 0; t < 2 * cfg.search.batch; ++t) {
            for (k = 0; k < 5 + t; ++k) {
                in = calm(&rng, 0u);
                TEST_ASSERT_EQUAL_INT(ICOAC_OK, icoac_step(state, &in, &out));
            }
            in = calm(&rng, ICOAC_INPUT_TERMINAL);
            TEST_ASSERT_EQUAL_INT(ICOAC_OK, icoac_step(state, &in, &out));
            priv_mut(state)->magic = ICOAC_PRIV_STATE_MAGIC;
            priv_mut(state)->trial_ticks = 0u;
        }
        TEST_ASSERT_EQUAL_INT(ICOAC_ERR_CORRUPT_STATE, icoac_reset(state));
        free_state(state);
    }
}

/* Reproducer: a corrupted state whose magic word survived made icoac_get_posterior read far
 * outside the state (through cov_slot). The slot is masked wherever it is read; icoac_reset
 * refuses the state. */
static void test_corrupted_slots(void)
{
    const int32_t slots[] = {0x7FFFFFFF, -1, 2, (int32_t)0x80000000u};
    size_t s;
    for (s = 0; s < sizeof slots / sizeof slots[0]; ++s) {
        icoac_config_t cfg = test_default_config();
        icoac_state_t *state = new_state();
        icoac_prior_t post;
        icoac_output_t out;
        icoac_input_t in;
        test_rng_t rng = {8u};
        int k;
        cfg.mode = ICOAC_MODE_RL;
        test_literal_reading(&cfg); /* the posterior reading flips the covariance slot */
        TEST_ASSERT_EQUAL_INT(ICOAC_OK, icoac_init(&cfg, state, NULL, 1u));
        priv_mut(state)->cov_slot = slots[s];
        priv_mut(state)->active_slot = slots[s];
        TEST_ASSERT_EQUAL_INT(ICOAC_OK, icoac_get_posterior(state, &post));
        TEST_ASSERT_EQUAL_MEMORY(priv(state)->cov_buffer[slots[s] & 1], post.cov, sizeof post.cov);
        for (k = 0; k < 50; ++k) {
            in = calm(&rng, 0u);
            TEST_ASSERT_EQUAL_INT(ICOAC_OK, icoac_step(state, &in, &out));
        }
        priv_mut(state)->cov_slot = slots[s];
        TEST_ASSERT_EQUAL_INT(ICOAC_ERR_CORRUPT_STATE, icoac_reset(state));
        free_state(state);
    }
}

/* Reproducer: a repeated TERMINAL tick recorded the same search trial again (1000 repeats moved
 * mu_w far). Every tick after a terminal tick is refused with ICOAC_ERR_TRIAL_ENDED, the state
 * unchanged but for its tick counter, until icoac_reset; in every mode. */
static void test_repeated_terminal(void)
{
    int mode;
    for (mode = ICOAC_MODE_ICO; mode <= ICOAC_MODE_SEARCH; ++mode) {
        icoac_config_t cfg = test_default_config();
        icoac_state_t *state = new_state();
        icoac_state_t copy;
        icoac_output_t out;
        icoac_input_t in;
        icoac_counters_t counters;
        test_rng_t rng = {9u};
        int k;
        cfg.mode = mode;
        cfg.search.batch = 2;
        TEST_ASSERT_EQUAL_INT(ICOAC_OK, icoac_init(&cfg, state, NULL, 1u));
        trial(state, &rng, 30);
        copy = *state;
        for (k = 0; k < 1000; ++k) {
            in = calm(&rng, k % 2 == 0 ? ICOAC_INPUT_TERMINAL : 0u);
            memset(&out, 0x7F, sizeof out);
            TEST_ASSERT_EQUAL_INT(ICOAC_ERR_TRIAL_ENDED, icoac_step(state, &in, &out));
            TEST_ASSERT_EQUAL_INT(ICOAC_ERR_TRIAL_ENDED, out.status);
            TEST_ASSERT_TRUE(out.force == 0 && out.weight_norm == priv(state)->weight_norm);
        }
        TEST_ASSERT_EQUAL_INT(ICOAC_OK, icoac_get_counters(state, &counters));
        TEST_ASSERT_EQUAL_UINT32(priv(&copy)->counters.ticks + 1000u, counters.ticks);
        icoac_priv_state(&copy)->counters = counters;
        TEST_ASSERT_EQUAL_MEMORY(&copy, state, sizeof copy);
        trial(state, &rng, 30); /* a reset opens the next trial */
        free_state(state);
    }
}

/* The sparse kernel's update (the microcontrollers') on a kept-unit list of arbitrary bytes
 * writes only inside the state's weights: the heap block below holds exactly
 * ICOAC_PRIV_CRITIC_WEIGHTS reals (a static array on a bare-metal core, which has no heap). */
static void test_corrupted_kept_unit_list(void)
{
    test_rng_t rng = {10u};
#if ICOAC_TEST_ON_TARGET
    static icoac_real_t v[ICOAC_PRIV_CRITIC_WEIGHTS];
#else
    icoac_real_t *v = malloc(sizeof(icoac_real_t) * ICOAC_PRIV_CRITIC_WEIGHTS);
#endif
    int n;
    TEST_ASSERT_NOT_NULL(v);
    for (n = 0; n < 2000; ++n) {
        icoac_priv_critic_list_t list;
        unsigned char *bytes = (unsigned char *)&list;
        size_t i;
        for (i = 0; i < sizeof list; ++i) {
            bytes[i] = (unsigned char)(test_rng_u64(&rng) >> 56);
        }
        for (i = 0; i < ICOAC_PRIV_CRITIC_WEIGHTS; ++i) {
            v[i] = ICOAC_R(0.0);
        }
        icoac_priv_critic_update_sparse(v, &list, ICOAC_R(1.0));
    }
#if !ICOAC_TEST_ON_TARGET
    free(v);
#endif
}

/* Random bytes in a state with a valid header, then every entry point: nothing outside the
 * state (ASan), no undefined behaviour (UBSan), a named status from each, force 0 on error, and
 * icoac_reset either refuses the state unchanged or leaves one that ticks. */
static void test_random_state_bytes(void)
{
    test_rng_t rng = {11u};
    int n;
    for (n = 0; n < TEST_ITERATIONS(3000, 300); ++n) { /* fewer on an emulated core (QEMU is slow) */
        icoac_state_t *state = new_state();
        icoac_state_t copy;
        icoac_config_t cfg = test_default_config();
        icoac_prior_t post;
        icoac_counters_t counters;
        icoac_output_t out;
        icoac_input_t in = test_input(0.2, -0.1, 0.03, 0.2, n % 3 == 0 ? ICOAC_INPUT_TERMINAL : 0u);
        unsigned char *bytes = (unsigned char *)state;
        icoac_status_t status;
        size_t i;
        int k;
        for (i = 0; i < sizeof *state; ++i) {
            bytes[i] = (unsigned char)(test_rng_u64(&rng) >> 56);
        }
        if (n % 2 == 0) { /* a plausible configuration copy, so that the ticks go deeper */
            cfg.mode = n % 3;
            priv_mut(state)->config = cfg;
        }
        priv_mut(state)->magic = n % 5 == 0 ? ICOAC_PRIV_STATE_ENDED : ICOAC_PRIV_STATE_MAGIC;
        TEST_ASSERT_EQUAL_INT(ICOAC_OK, icoac_get_posterior(state, &post));
        TEST_ASSERT_EQUAL_INT(ICOAC_OK, icoac_get_counters(state, &counters));
        for (k = 0; k < 5; ++k) {
            status = icoac_step(state, &in, &out);
            TEST_ASSERT_EQUAL_INT(status, out.status);
            TEST_ASSERT_TRUE(status == ICOAC_OK || out.force == 0);
            TEST_ASSERT_TRUE(status == ICOAC_OK || status == ICOAC_ERR_NUMERIC || status == ICOAC_ERR_CORRUPT_STATE ||
                             status == ICOAC_ERR_TRIAL_ENDED || status == ICOAC_ERR_NONFINITE_INPUT);
        }
        copy = *state;
        status = icoac_reset(state);
        TEST_ASSERT_TRUE(status == ICOAC_OK || status == ICOAC_ERR_CORRUPT_STATE);
        if (status == ICOAC_ERR_CORRUPT_STATE) {
            TEST_ASSERT_EQUAL_MEMORY(&copy, state, sizeof copy);
        } else {
            in.flags = 0u;
            status = icoac_step(state, &in, &out);
            TEST_ASSERT_TRUE(status == ICOAC_OK || status == ICOAC_ERR_NUMERIC);
        }
        free_state(state);
    }
}

void setUp(void) {}
void tearDown(void) {}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_search_batch_edited_after_init);
    RUN_TEST(test_retune_applies_input_range);
    RUN_TEST(test_retune_search_floors);
    RUN_TEST(test_retune_refuses_a_mode_change);
    RUN_TEST(test_unknown_switches);
    RUN_TEST(test_nonfinite_fields_and_recovery);
    RUN_TEST(test_corrupted_elite_fraction);
    RUN_TEST(test_corrupted_slots);
    RUN_TEST(test_repeated_terminal);
    RUN_TEST(test_corrupted_kept_unit_list);
    RUN_TEST(test_random_state_bytes);
    return UNITY_END();
}
