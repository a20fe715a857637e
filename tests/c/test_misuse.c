/* SPDX-License-Identifier: Apache-2.0 */
/* Misuse: a configuration edited after icoac_init, live retuning, unknown switches,
 * non-finite fields, repeated terminal ticks and corrupted state bytes. Each reproducer of the
 * misuse report is a test here; run under ASan and UBSan (preset debug-asan), an access outside
 * the state or an undefined conversion fails it. */
#include <stdlib.h>

#include "test_common.h"

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
    assert_memory_equal(state, &expect, sizeof expect);
}

/* A state in its own heap block of exactly its size, so that ASan sees a one-byte overrun. */
static icoac_state_t *new_state(void)
{
    icoac_state_t *state = malloc(sizeof *state);
    assert_non_null(state);
    memset(state, 0, sizeof *state);
    return state;
}

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
    assert_int_equal(icoac_reset(state), ICOAC_OK);
    for (k = 0; k < ticks; ++k) {
        in = calm(rng, 0u);
        assert_int_equal(icoac_step(state, &in, &out), ICOAC_OK);
    }
    in = calm(rng, ICOAC_INPUT_TERMINAL);
    assert_int_equal(icoac_step(state, &in, &out), ICOAC_OK);
}

/* Reproducer: search mode, init, then search.batch = 1000 and 40 trials. Before, the tick used
 * the edited batch as the bound of its trial record and wrote past w[16] / ticks[16], then past
 * the state. Now the caller's edit changes nothing (the state runs on its own copy, bit for bit
 * as a twin that was never edited), and the same value forced into the state's copy is clamped
 * where it is used, then refused by icoac_reset. */
static void test_search_batch_edited_after_init(void **unused)
{
    icoac_config_t cfg = test_default_config();
    icoac_state_t *state = new_state();
    icoac_state_t *twin = new_state();
    test_rng_t rng = {1u}, rng_twin = {1u};
    icoac_output_t out;
    icoac_input_t in;
    int t, k;
    (void)unused;
    cfg.mode = ICOAC_MODE_SEARCH;
    assert_int_equal(icoac_init(&cfg, state, NULL, 3u), ICOAC_OK);
    assert_int_equal(icoac_init(&cfg, twin, NULL, 3u), ICOAC_OK);
    cfg.search.batch = 1000;
    for (t = 0; t < 40; ++t) {
        trial(state, &rng, 20);
        trial(twin, &rng_twin, 20);
    }
    assert_memory_equal(state, twin, sizeof *state);
    /* the same value inside the state (corrupted memory), with a full record: clamped */
    priv_mut(state)->config.search.batch = 1000;
    for (t = 0; t < 40; ++t) {
        priv_mut(state)->magic = ICOAC_PRIV_STATE_MAGIC; /* a new trial without the checks of a reset */
        for (k = 0; k < 20; ++k) {
            in = calm(&rng, 0u);
            assert_int_equal(icoac_step(state, &in, &out), ICOAC_OK);
        }
        in = calm(&rng, ICOAC_INPUT_TERMINAL);
        assert_int_equal(icoac_step(state, &in, &out), ICOAC_OK);
        assert_true(priv(state)->search.count >= 0 && priv(state)->search.count < ICOAC_SEARCH_BATCH_MAX);
    }
    assert_int_equal(icoac_reset(state), ICOAC_ERR_CORRUPT_STATE);
    free(state);
    free(twin);
}

/* Reproducer: policy.input_range edited after init kept its init-time 1/range (5979 of 6000
 * ticks differed from a fresh init). Now an edit alone changes nothing, and icoac_retune
 * applies it: the ticks then equal those of a fresh init with the edited configuration. */
static void test_retune_applies_input_range(void **unused)
{
    icoac_config_t cfg = test_default_config();
    icoac_config_t edited;
    icoac_state_t *state = new_state();
    icoac_state_t *fresh = new_state();
    test_rng_t rng = {2u};
    int k, differ = 0;
    (void)unused;
    assert_int_equal(icoac_init(&cfg, state, NULL, 5u), ICOAC_OK);
    edited = cfg;
    edited.policy.input_range[0] = ICOAC_R(1.2);
    edited.policy.input_range[2] = ICOAC_R(0.1);
    assert_int_equal(icoac_init(&edited, fresh, NULL, 5u), ICOAC_OK);
    assert_int_equal(icoac_retune(state, &edited), ICOAC_OK);
    test_assert_config_in_force(&edited, state);
    for (k = 0; k < 6000; ++k) {
        icoac_output_t out, out_fresh;
        icoac_input_t in = calm(&rng, 0u);
        memset(&out, 0, sizeof out); /* padding too (double build) */
        memset(&out_fresh, 0, sizeof out_fresh);
        assert_int_equal(icoac_step(state, &in, &out), ICOAC_OK);
        assert_int_equal(icoac_step(fresh, &in, &out_fresh), ICOAC_OK);
        differ += memcmp(&out, &out_fresh, sizeof out) != 0;
    }
    assert_int_equal(differ, 0);
    free(state);
    free(fresh);
}

/* search.floor and search.cov_scale: the floors follow a retune (floor * cov_scale * prior
 * variance), the learned Sigma_w is kept, and the next update holds Sigma_w's diagonal at the
 * new floors. */
static void test_retune_search_floors(void **unused)
{
    icoac_config_t cfg = test_default_config();
    icoac_config_t tuned;
    icoac_state_t *state = new_state();
    icoac_prior_t prior = test_prior(0.1, 0.2, 1.0, 0.3, 0.5), before, after;
    test_rng_t rng = {3u};
    int i, t;
    (void)unused;
    cfg.mode = ICOAC_MODE_SEARCH;
    cfg.search.batch = 4;
    cfg.search.floor = ICOAC_R(1e-3);
    assert_int_equal(icoac_init(&cfg, state, &prior, 9u), ICOAC_OK);
    assert_int_equal(icoac_get_posterior(state, &before), ICOAC_OK);
    tuned = cfg;
    tuned.search.floor = ICOAC_R(2.0);
    tuned.search.cov_scale = ICOAC_R(8.0);
    assert_int_equal(icoac_retune(state, &tuned), ICOAC_OK);
    assert_int_equal(icoac_get_posterior(state, &after), ICOAC_OK);
    assert_memory_equal(&before, &after, sizeof before); /* nothing learned is lost */
    for (i = 0; i < N; ++i) {
        assert_true(priv(state)->search.floor[i] == tuned.search.floor * (prior.cov[i][i] * tuned.search.cov_scale));
    }
    for (t = 0; t < tuned.search.batch; ++t) {
        trial(state, &rng, 5);
    }
    assert_int_equal(icoac_get_posterior(state, &after), ICOAC_OK);
    for (i = 0; i < N; ++i) {
        assert_true(after.cov[i][i] >= priv(state)->search.floor[i]);
    }
    free(state);
}

/* Reproducer: RL -> SEARCH without a re-init ran the search with a zero Cholesky factor and
 * explored nothing. A retune cannot change the mode; the state stays as it was. */
static void test_retune_refuses_a_mode_change(void **unused)
{
    icoac_config_t cfg = test_default_config();
    icoac_config_t other;
    icoac_state_t *state = new_state();
    icoac_state_t copy;
    test_rng_t rng = {4u};
    int mode;
    (void)unused;
    cfg.mode = ICOAC_MODE_RL;
    assert_int_equal(icoac_init(&cfg, state, NULL, 1u), ICOAC_OK);
    trial(state, &rng, 30);
    copy = *state;
    for (mode = ICOAC_MODE_ICO; mode <= ICOAC_MODE_SEARCH; ++mode) {
        if (mode == ICOAC_MODE_RL) {
            continue;
        }
        other = cfg;
        other.mode = mode;
        assert_int_equal(icoac_retune(state, &other), ICOAC_ERR_RETUNE_MODE);
        assert_memory_equal(state, &copy, sizeof copy);
    }
    free(state);
}

/* Reproducer: mode 99 and ico.timing 7 ran a default branch with status OK. A retune refuses
 * them (state unchanged); forced into the state's copy, the tick refuses them with
 * ICOAC_ERR_CORRUPT_STATE (force 0, state unchanged but counters) and icoac_reset too. The same for
 * an unknown actor.update. */
static void test_unknown_switches(void **unused)
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
    (void)unused;
    for (c = 0; c < sizeof cases / sizeof cases[0]; ++c) {
        icoac_config_t cfg = test_default_config();
        icoac_config_t bad;
        icoac_state_t *state = new_state();
        icoac_state_t copy;
        icoac_output_t out;
        icoac_input_t in = test_input(0.1, 0.0, 0.02, 0.0, 0u);
        test_rng_t rng = {5u};
        cfg.mode = cases[c].mode;
        assert_int_equal(icoac_init(&cfg, state, NULL, 1u), ICOAC_OK);
        trial(state, &rng, 10);
        assert_int_equal(icoac_reset(state), ICOAC_OK);
        assert_int_equal(icoac_step(state, &in, &out), ICOAC_OK); /* a transition to learn from next */
        bad = cfg;
        memcpy((unsigned char *)&bad + cases[c].offset, &cases[c].value, sizeof cases[c].value);
        copy = *state;
        assert_int_equal(icoac_retune(state, &bad), ICOAC_ERR_BAD_MODE);
        assert_memory_equal(state, &copy, sizeof copy);
        memcpy((unsigned char *)&priv_mut(state)->config + cases[c].offset, &cases[c].value, sizeof cases[c].value);
        copy = *state;
        memset(&out, 0x7F, sizeof out);
        assert_int_equal(icoac_step(state, &in, &out), ICOAC_ERR_CORRUPT_STATE);
        assert_int_equal(out.status, ICOAC_ERR_CORRUPT_STATE);
        assert_true(out.force == 0);
        assert_unchanged_but_scratch(state, &copy);
        assert_int_equal(icoac_reset(state), ICOAC_ERR_CORRUPT_STATE);
        free(state);
    }
}

/* Reproducers: actor.noise_std = NaN gave OK with a NaN force; critic.rate = 1e38 for three
 * trials broke the state for good (every later tick NUMERIC, even after a valid configuration
 * and a reset). Both are refused by the check of icoac_retune, the state unchanged; the trials
 * then run on the configuration in force. Corrupted learned values (NaN critic weights, as a
 * 1e38 rate used to leave) make the ticks ICOAC_ERR_NUMERIC and icoac_init restores the state;
 * corrupted actor weights are refused by icoac_reset too. */
static void test_nonfinite_fields_and_recovery(void **unused)
{
    icoac_config_t cfg = test_default_config();
    icoac_config_t bad;
    icoac_state_t *state = new_state();
    icoac_state_t copy;
    icoac_output_t out;
    icoac_input_t in;
    test_rng_t rng = {6u};
    int t, k, numeric = 0;
    (void)unused;
    cfg.mode = ICOAC_MODE_RL;
    assert_int_equal(icoac_init(&cfg, state, NULL, 2u), ICOAC_OK);
    copy = *state;
    bad = cfg;
    bad.actor.noise_std = (icoac_real_t)NAN;
    assert_int_equal(icoac_retune(state, &bad), ICOAC_ERR_BAD_ACTOR);
    bad = cfg;
    bad.critic.rate = ICOAC_R(1e38);
    assert_int_equal(icoac_retune(state, &bad), ICOAC_ERR_BAD_CRITIC);
    assert_memory_equal(state, &copy, sizeof copy);
    for (t = 0; t < 3; ++t) {
        trial(state, &rng, 50);
    }
    /* corrupted learned values: the ticks fail, init restores */
    for (k = 0; k < ICOAC_CARTPOLE_CRITIC_UNITS; ++k) {
        priv_mut(state)->v[k] = k % 2 ? (icoac_real_t)NAN : (icoac_real_t)INFINITY;
    }
    assert_int_equal(icoac_reset(state), ICOAC_OK);
    for (k = 0; k < 200; ++k) {
        in = calm(&rng, 0u);
        numeric += icoac_step(state, &in, &out) == ICOAC_ERR_NUMERIC;
    }
    assert_true(numeric > 0);
    priv_mut(state)->w[2] = (icoac_real_t)NAN;
    assert_int_equal(icoac_reset(state), ICOAC_ERR_CORRUPT_STATE);
    assert_int_equal(icoac_init(&cfg, state, NULL, 2u), ICOAC_OK);
    for (t = 0; t < 3; ++t) {
        trial(state, &rng, 50);
    }
    free(state);
}

/* Reproducer: elite_fraction 1e30 or NaN was an undefined float-to-int conversion. Forced into
 * the state's copy (a retune refuses it), a closing batch converts nothing out of range
 * (UBSan's float-cast-overflow) and the elite stays within the batch. */
static void test_corrupted_elite_fraction(void **unused)
{
    const icoac_real_t values[] = {ICOAC_R(1e30), (icoac_real_t)NAN, ICOAC_R(-1e30), (icoac_real_t)INFINITY};
    size_t v;
    (void)unused;
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
        assert_int_equal(icoac_init(&cfg, state, NULL, 4u), ICOAC_OK);
        bad = cfg;
        bad.search.elite_fraction = values[v];
        assert_int_equal(icoac_retune(state, &bad), ICOAC_ERR_BAD_SEARCH);
        priv_mut(state)->config.search.elite_fraction = values[v];
        for (t = 0; t < 2 * cfg.search.batch; ++t) {
            for (k = 0; k < 5 + t; ++k) {
                in = calm(&rng, 0u);
                assert_int_equal(icoac_step(state, &in, &out), ICOAC_OK);
            }
            in = calm(&rng, ICOAC_INPUT_TERMINAL);
            assert_int_equal(icoac_step(state, &in, &out), ICOAC_OK);
            priv_mut(state)->magic = ICOAC_PRIV_STATE_MAGIC;
            priv_mut(state)->trial_ticks = 0u;
        }
        assert_int_equal(icoac_reset(state), ICOAC_ERR_CORRUPT_STATE);
        free(state);
    }
}

/* Reproducer: a corrupted state whose magic word survived made icoac_get_posterior read far
 * outside the state (through cov_slot). The slot is masked wherever it is read; icoac_reset
 * refuses the state. */
static void test_corrupted_slots(void **unused)
{
    const int32_t slots[] = {0x7FFFFFFF, -1, 2, (int32_t)0x80000000u};
    size_t s;
    (void)unused;
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
        assert_int_equal(icoac_init(&cfg, state, NULL, 1u), ICOAC_OK);
        priv_mut(state)->cov_slot = slots[s];
        priv_mut(state)->active_slot = slots[s];
        assert_int_equal(icoac_get_posterior(state, &post), ICOAC_OK);
        assert_memory_equal(post.cov, priv(state)->cov_buffer[slots[s] & 1], sizeof post.cov);
        for (k = 0; k < 50; ++k) {
            in = calm(&rng, 0u);
            assert_int_equal(icoac_step(state, &in, &out), ICOAC_OK);
        }
        priv_mut(state)->cov_slot = slots[s];
        assert_int_equal(icoac_reset(state), ICOAC_ERR_CORRUPT_STATE);
        free(state);
    }
}

/* Reproducer: a repeated TERMINAL tick recorded the same search trial again (1000 repeats moved
 * mu_w far). Every tick after a terminal tick is refused with ICOAC_ERR_TRIAL_ENDED, the state
 * unchanged but for its tick counter, until icoac_reset; in every mode. */
static void test_repeated_terminal(void **unused)
{
    int mode;
    (void)unused;
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
        assert_int_equal(icoac_init(&cfg, state, NULL, 1u), ICOAC_OK);
        trial(state, &rng, 30);
        copy = *state;
        for (k = 0; k < 1000; ++k) {
            in = calm(&rng, k % 2 == 0 ? ICOAC_INPUT_TERMINAL : 0u);
            memset(&out, 0x7F, sizeof out);
            assert_int_equal(icoac_step(state, &in, &out), ICOAC_ERR_TRIAL_ENDED);
            assert_int_equal(out.status, ICOAC_ERR_TRIAL_ENDED);
            assert_true(out.force == 0 && out.weight_norm == priv(state)->weight_norm);
        }
        assert_int_equal(icoac_get_counters(state, &counters), ICOAC_OK);
        assert_int_equal(counters.ticks, priv(&copy)->counters.ticks + 1000u);
        icoac_priv_state(&copy)->counters = counters;
        assert_memory_equal(state, &copy, sizeof copy);
        trial(state, &rng, 30); /* a reset opens the next trial */
        free(state);
    }
}

/* The sparse kernel's update (the microcontrollers') on a kept-unit list of arbitrary bytes
 * writes only inside the state's weights: the heap block below holds exactly
 * ICOAC_PRIV_CRITIC_WEIGHTS reals. */
static void test_corrupted_kept_unit_list(void **unused)
{
    test_rng_t rng = {10u};
    icoac_real_t *v = malloc(sizeof(icoac_real_t) * ICOAC_PRIV_CRITIC_WEIGHTS);
    int n;
    (void)unused;
    assert_non_null(v);
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
    free(v);
}

/* Random bytes in a state with a valid header, then every entry point: nothing outside the
 * state (ASan), no undefined behaviour (UBSan), a named status from each, force 0 on error, and
 * icoac_reset either refuses the state unchanged or leaves one that ticks. */
static void test_random_state_bytes(void **unused)
{
    test_rng_t rng = {11u};
    int n;
    (void)unused;
    for (n = 0; n < 3000; ++n) {
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
        assert_int_equal(icoac_get_posterior(state, &post), ICOAC_OK);
        assert_int_equal(icoac_get_counters(state, &counters), ICOAC_OK);
        for (k = 0; k < 5; ++k) {
            status = icoac_step(state, &in, &out);
            assert_int_equal(out.status, status);
            assert_true(status == ICOAC_OK || out.force == 0);
            assert_true(status == ICOAC_OK || status == ICOAC_ERR_NUMERIC || status == ICOAC_ERR_CORRUPT_STATE ||
                        status == ICOAC_ERR_TRIAL_ENDED || status == ICOAC_ERR_NONFINITE_INPUT);
        }
        copy = *state;
        status = icoac_reset(state);
        assert_true(status == ICOAC_OK || status == ICOAC_ERR_CORRUPT_STATE);
        if (status == ICOAC_ERR_CORRUPT_STATE) {
            assert_memory_equal(state, &copy, sizeof copy);
        } else {
            in.flags = 0u;
            status = icoac_step(state, &in, &out);
            assert_true(status == ICOAC_OK || status == ICOAC_ERR_NUMERIC);
        }
        free(state);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_search_batch_edited_after_init),
        cmocka_unit_test(test_retune_applies_input_range),
        cmocka_unit_test(test_retune_search_floors),
        cmocka_unit_test(test_retune_refuses_a_mode_change),
        cmocka_unit_test(test_unknown_switches),
        cmocka_unit_test(test_nonfinite_fields_and_recovery),
        cmocka_unit_test(test_corrupted_elite_fraction),
        cmocka_unit_test(test_corrupted_slots),
        cmocka_unit_test(test_repeated_terminal),
        cmocka_unit_test(test_corrupted_kept_unit_list),
        cmocka_unit_test(test_random_state_bytes),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
