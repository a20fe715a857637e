/* SPDX-License-Identifier: Apache-2.0 */
/* libFuzzer target of the controller API (icoac.h). One source, three executables:
 * fuzz_controller (float library icoac), fuzz_controller_double (icoac_double) and
 * fuzz_controller_fast_exp (icoac_fast_exp, the microcontroller presets' float math).
 *
 * Input format, read front to back (a byte past the end reads as 0):
 *   config  mode byte c. c odd: sizeof(icoac_config_t) raw bytes laid over
 *           icoac_config_default (fewer when the input ends; the nested layout of icoac.h,
 *           padding included). c even: the default with (c >> 1) % 8 mutations, each a field
 *           byte (% 79; indices in struct order over every array element of the default maxima,
 *           6 inputs and 6 rules: table in fuzz_input.c) and a value: random task descriptions
 *           (input counts, rule tables, late-signal sources) and critic grids.
 *   prior   byte p. p % 3: 0 NULL, 1 mean 0 and cov I (6 x 6), 2 that with (p / 3) % 8
 *           mutations, each a field byte b ((b & 127) % 42: 0-5 mean[i], 6 + 6i + j cov[i][j];
 *           b & 128 also sets cov[j][i]) and a value.
 *   seed    8 bytes, little endian.
 *   ops     until the input ends, at most FZ_MAX_OPS ops and FZ_MAX_STEPS steps. Op byte o:
 *           o & 3: 0 or 1 step, 2 terminal step (ICOAC_INPUT_TERMINAL), 3 icoac_reset or retune.
 *           A step runs ((o >> 2) & 7) + 1 times; o & 0x20 keeps the previous s, else the
 *           n values s[0..n-1] follow (n = task.n_inputs; s[n..] is NaN, never read); o & 0x40
 *           sets ICOAC_INPUT_LATE; o & 0x80: a value for in.reflex follows (else it is kept,
 *           initially 0). o & 3 == 3: o & 0x40 clear:
 *           icoac_reset (bit 7 ignored); set: icoac_retune with a config section (as above)
 *           laid over the configuration in force (o & 0x80 clear) or over the default
 *           (o & 0x80 set: the config section exactly as at the start).
 *   value   real: selector byte k % 40. k < 28: special value (table in fuzz_input.c: 0, -0,
 *           1e-39, 1e-45, REAL_MIN, REAL_MAX, 1e30, 1e-20, NaN, +Inf, -Inf, -1, 1, 0.5,
 *           -1e30, 1e38, -REAL_MAX, 2, 0.25, 2.4, -2.4, 10, 1e-5, -0.25, REAL_TRUE_MIN,
 *           0.999, 1e10, -1e-39); 28-35: int16 (2 bytes) / 32768 * {1e-3, 1e-2, 0.1, 1, 3,
 *           10, 100, 1e4}[k - 28]; 36-39: raw bits, sizeof(icoac_real_t) bytes.
 *           int32 switch: selector % 8: 0, 1, 2, -1, INT32_MAX, INT32_MIN, 3, 7 = 4 raw bytes.
 * tests/fuzz/gen_corpus.py writes the committed corpus in this format.
 *
 * Contract, checked after every call (abort on violation):
 *   init    status = icoac_config_check when that fails, else icoac_prior_check when that
 *           fails, else OK or ICOAC_ERR_NUMERIC (search mode: or ICOAC_ERR_BAD_PRIOR, when
 *           cov_scale * the prior covariance is not positive definite); a rejected init leaves
 *           the state bytewise untouched; icoac_config_check_field agrees and names a field
 *           exactly when the check fails; the checks accept only
 *           documented ranges of the groups the mode uses (ICO: policy, ico; RL: policy,
 *           critic, actor; search: policy, search); after OK the learned state (w, |w|, cov,
 *           w_act, v) is finite and holds the prior (search: cov = cov_scale * the prior's,
 *           the floor search.floor * its diagonal, no trial recorded).
 *   step    returned status = out.status, a known status; the counters count the tick and its
 *           rejection; the configuration copy in the state never changes. After a terminal step
 *           that returned OK (the trial ended; the state's header word is the ended one), every
 *           step until icoac_reset returns ICOAC_ERR_TRIAL_ENDED, whatever s, with the output
 *           cleared but weight_norm = |w| and the state bytewise unchanged but counters.ticks + 1.
 *           In a trial: never TRIAL_ENDED or CORRUPT_STATE; non-finite s <=> NONFINITE_INPUT; an OK
 *           terminal step ends the trial, any other step leaves the header word as it was.
 *           OK: every real output written (out is NaN-filled before the call) and finite, the
 *           learned state finite, cov exactly symmetric, out.weight_norm = |w|; the trial's
 *           tick count + 1 on a non-terminal RL or search step (ICO does not count); force and
 *           noise 0 on a terminal step; q 0 in RL and search; value, td_error, noise,
 *           cov_trace 0 in ICO; value, td_error, noise 0 and cov_trace = trace(cov) in search;
 *           with learn = 0 (the no-learning control) w, |w|, cov, v, the actor's batch sums
 *           and the search's trial record unchanged. RL: the mean and gradient readings never
 *           change cov; per-trial batches (actor.batch) change w and cov only at a terminal
 *           step; noise 0 from tick actor.explore_ticks of a trial on. Search: w, cov and the
 *           record change only at a terminal step, which records the trial (count + 1) or,
 *           with at least batch - 1 trials recorded (more after a retune to a smaller batch),
 *           updates (count 0, every cov_ii >= its floor); after a terminal step count < batch.
 *           Not OK: every real output 0 but weight_norm = |w|, learned state (batch sums,
 *           trial record and the trial's tick count included) bytewise unchanged (the spare
 *           kept-unit slot, covariance buffer and staged batch shift are scratch, not learned).
 *   reset   OK (a state the library wrote passes its state check); the trial is open again
 *           (header word); w, |w|, cov, v and the search's record unchanged, the actor's batch
 *           sums cleared; w_act = w unless acting with a sample (RL with act_with_sample,
 *           search); w_act finite.
 *   retune  status = icoac_config_check when that fails, else ICOAC_ERR_RETUNE_MODE when the
 *           mode differs from the one in force, else OK. On an error the state is bytewise
 *           unchanged. On OK icoac_get_config returns the new configuration (every field
 *           bitwise), task.input_sign / policy.input_range and (search) the floors search.floor *
 *           (prior variance * search.cov_scale) are re-derived, the shape tag's rule-layout
 *           bit says whether the new rule table is the cart-pole preset's (4 inputs, its 4 rules'
 *           inputs and sides), and every other byte of the state is unchanged: w, |w|, cov, v, w_act, the batch sums, the search's record and
 *           factor, the trial's caches, the RNG, the counters and the header word. The
 *           configuration in force is then the new one for every later check.
 *   end     icoac_get_posterior returns w and cov; icoac_get_config the configuration in force.
 *   Also: a zeroed state and NULL pointers are refused by every entry point.
 */
#include <math.h>
#include <stdint.h>
#include <string.h>

#include "fuzz_check.h"
#include "fuzz_input.h"
#include "icoac/icoac.h"
#include "icoac_state.h" /* private layout of the state (firmware/src) */

#define FZ_MAX_OPS 128
#define FZ_MAX_STEPS 512
#define N ICOAC_MAX_INPUTS /* the library's vectors; a task uses the first task.n_inputs */
/* C will not pass T[N][N] as const T[N][N] implicitly. */
#define CONST_MAT(m) ((const icoac_real_t(*)[N])(m))

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

/* Everything the controller learns; compared bytewise around each call (no padding). The
 * actor's batch sums (actor.batch) and the search's record of the trials of its batch are
 * learned too, but per trial or per batch; trial_ticks is the trial's tick count. */
typedef struct {
    icoac_real_t w[N];
    icoac_real_t weight_norm;
    icoac_real_t cov[N][N];
    icoac_real_t v[ICOAC_CARTPOLE_CRITIC_UNITS];
    icoac_real_t w_act[N];
    icoac_real_t batch_info[N][N];
    icoac_real_t batch_shift[N];
    icoac_real_t search_w[ICOAC_SEARCH_BATCH_MAX][N];
    uint32_t search_ticks[ICOAC_SEARCH_BATCH_MAX];
    icoac_real_t search_lower[N][N];
    icoac_real_t search_floor[N];
    int32_t search_count;
    uint32_t trial_ticks;
} learned_t;

/* What learned_changed compares besides w, |w|, cov and v. */
#define FZ_W_ACT 1      /* the acting weights */
#define FZ_BATCH 2      /* the actor's batch sums */
#define FZ_RECORD 4     /* the search's record, factor and floor */
#define FZ_TRIAL 8      /* the trial's tick count */

static void learned_take(const icoac_state_t *state, learned_t *l)
{
    const icoac_priv_state_t *st = icoac_priv_state_c(state);
    memset(l, 0, sizeof *l);
    memcpy(l->w, st->w, sizeof l->w);
    l->weight_norm = st->weight_norm;
    memcpy(l->cov, icoac_priv_cov_c(st), sizeof l->cov);
    memcpy(l->v, st->v, sizeof l->v);
    memcpy(l->w_act, st->w_act, sizeof l->w_act);
    memcpy(l->batch_info, st->batch.info, sizeof l->batch_info);
    memcpy(l->batch_shift, st->batch.shift, sizeof l->batch_shift);
    memcpy(l->search_w, st->search.w, sizeof l->search_w);
    memcpy(l->search_ticks, st->search.ticks, sizeof l->search_ticks);
    memcpy(l->search_lower, st->search.lower, sizeof l->search_lower);
    memcpy(l->search_floor, st->search.floor, sizeof l->search_floor);
    l->search_count = st->search.count;
    l->trial_ticks = st->trial_ticks;
}

static int all_zero(const icoac_real_t *p, int n)
{
    int i;
    for (i = 0; i < n; ++i) {
        if (p[i] != ICOAC_R(0.0)) {
            return 0;
        }
    }
    return 1;
}

static icoac_real_t trace4(const icoac_real_t m[N][N])
{
    /* the library's order (entries past the task's inputs are 0) */
    ICOAC_STATIC_ASSERT(N == 6, trace_of_the_default_maxima);
    return ((m[0][0] + m[1][1]) + (m[2][2] + m[3][3])) + (m[4][4] + m[5][5]);
}

/* The task's inputs, bounded to the arrays as the library bounds them. */
static int inputs_of(const icoac_config_t *cfg)
{
    return (uint32_t)cfg->task.n_inputs <= (uint32_t)N ? (int)cfg->task.n_inputs : N;
}

/* The task's rule table has the cart-pole preset's layout: 4 inputs, 4 rules on the preset's
 * inputs and sides (theta above, x below, theta below, x above); any thresholds and reflexes. */
static int cartpole_rule_layout(const icoac_task_config_t *t)
{
    static const int32_t input[4] = {ICOAC_IDX_THETA, ICOAC_IDX_X, ICOAC_IDX_THETA, ICOAC_IDX_X};
    static const int32_t side[4] = {ICOAC_RULE_ABOVE, ICOAC_RULE_BELOW, ICOAC_RULE_BELOW, ICOAC_RULE_ABOVE};
    int k;
    if (t->n_inputs != 4 || t->late_source != ICOAC_LATE_RULES || t->n_rules != 4) {
        return 0;
    }
    for (k = 0; k < 4; ++k) {
        if (t->rule_input[k] != input[k] || t->rule_side[k] != side[k]) {
            return 0;
        }
    }
    return 1;
}

static icoac_counters_t counters_of(const icoac_state_t *state)
{
    icoac_counters_t c;
    FZ_CHECK(icoac_get_counters(state, &c) == ICOAC_OK, "icoac_get_counters failed on an initialised state");
    return c;
}

/* Name of the first non-finite learned field, or NULL. */
static const char *learned_nonfinite(const learned_t *l, int with_w_act)
{
    int i;
    if (!fz_all_finite(l->w, N)) {
        return "w";
    }
    if (!isfinite(l->weight_norm)) {
        return "weight_norm";
    }
    for (i = 0; i < N; ++i) {
        if (!fz_all_finite(l->cov[i], N)) {
            return "cov";
        }
    }
    if (!fz_all_finite(l->v, ICOAC_CARTPOLE_CRITIC_UNITS)) {
        return "v";
    }
    if (with_w_act && !fz_all_finite(l->w_act, N)) {
        return "w_act";
    }
    return 0;
}

/* Name of the first learned field that differs, or NULL (w, |w|, cov, v, and the FZ_* parts
 * in what). */
static const char *learned_changed(const learned_t *a, const learned_t *b, int what)
{
    if (memcmp(a->w, b->w, sizeof a->w) != 0) {
        return "w";
    }
    if (memcmp(&a->weight_norm, &b->weight_norm, sizeof a->weight_norm) != 0) {
        return "weight_norm";
    }
    if (memcmp(a->cov, b->cov, sizeof a->cov) != 0) {
        return "cov";
    }
    if (memcmp(a->v, b->v, sizeof a->v) != 0) {
        return "v";
    }
    if ((what & FZ_W_ACT) && memcmp(a->w_act, b->w_act, sizeof a->w_act) != 0) {
        return "w_act";
    }
    if ((what & FZ_BATCH) && (memcmp(a->batch_info, b->batch_info, sizeof a->batch_info) != 0 ||
                              memcmp(a->batch_shift, b->batch_shift, sizeof a->batch_shift) != 0)) {
        return "actor batch sums";
    }
    if ((what & FZ_RECORD) && (memcmp(a->search_w, b->search_w, sizeof a->search_w) != 0 ||
                               memcmp(a->search_ticks, b->search_ticks, sizeof a->search_ticks) != 0 ||
                               a->search_count != b->search_count)) {
        return "search record";
    }
    if ((what & FZ_RECORD) && (memcmp(a->search_lower, b->search_lower, sizeof a->search_lower) != 0 ||
                               memcmp(a->search_floor, b->search_floor, sizeof a->search_floor) != 0)) {
        return "search factor or floor";
    }
    if ((what & FZ_TRIAL) && a->trial_ticks != b->trial_ticks) {
        return "trial tick count";
    }
    return 0;
}

/* cov[i][j] == cov[j][i] over the leading n x n block (exact; what icoac_prior_check asks of a
 * prior). */
static int cov_symmetric(const icoac_real_t cov[N][N], int n)
{
    int i;
    int j;
    for (i = 0; i < n; ++i) {
        for (j = i + 1; j < n; ++j) {
            if (cov[i][j] != cov[j][i]) {
                return 0;
            }
        }
    }
    return 1;
}

static int known_status(int32_t status)
{
    return strcmp(icoac_status_str((icoac_status_t)status), "unknown status") != 0;
}

static const char *status_name(int32_t status)
{
    return icoac_status_str((icoac_status_t)status);
}

static int finite_positive(icoac_real_t v)
{
    return isfinite(v) && v > ICOAC_R(0.0);
}

static int finite_non_negative(icoac_real_t v)
{
    return isfinite(v) && v >= ICOAC_R(0.0);
}

static int is_flag(int32_t v)
{
    return v == 0 || v == 1;
}

/* Necessary conditions from the documented ranges (icoac.h) of the groups a mode uses (ICO:
 * policy and ico; RL: policy, critic and actor; the others are ignored); the check may be
 * stricter. */
static int task_documented(const icoac_task_config_t *t)
{
    int k;
    if (t->n_inputs < 1 || t->n_inputs > N || t->n_rules < 0 || t->n_rules > ICOAC_MAX_RULES ||
        (t->late_source != ICOAC_LATE_RULES && t->late_source != ICOAC_LATE_SENSOR)) {
        return 0;
    }
    for (k = 0; k < t->n_inputs; ++k) {
        if (t->input_sign[k] != 1 && t->input_sign[k] != -1) {
            return 0;
        }
    }
    for (k = 0; t->late_source == ICOAC_LATE_RULES && k < t->n_rules; ++k) {
        if (t->rule_input[k] < 0 || t->rule_input[k] >= t->n_inputs || !is_flag(t->rule_side[k]) ||
            !isfinite(t->rule_threshold[k]) || !(fabs((double)t->rule_reflex[k]) <= 1.0)) {
            return 0;
        }
    }
    return 1;
}

static int policy_documented(const icoac_policy_config_t *p, int n)
{
    int i;
    for (i = 0; i < n; ++i) {
        if (!finite_positive(p->input_range[i])) {
            return 0;
        }
    }
    return is_flag(p->clip_inputs) && finite_non_negative(p->gain) &&
           (p->reflex_mode == ICOAC_REFLEX_UNIT || p->reflex_mode == ICOAC_REFLEX_GAIN) &&
           finite_non_negative(p->reflex_force);
}

static int ico_documented(const icoac_ico_config_t *ico)
{
    return finite_non_negative(ico->rate) && ico->rate <= ICOAC_R(1.0) &&
           (ico->timing == ICOAC_ICO_TIMING_CODE || ico->timing == ICOAC_ICO_TIMING_LITERAL);
}

static int critic_documented(const icoac_critic_config_t *c, int n)
{
    long units = 1;
    int i;
    for (i = 0; i < n; ++i) {
        if (!finite_positive(c->range[i]) || c->units[i] < 1 || c->units[i] > ICOAC_CRITIC_UNITS_PER_INPUT_MAX) {
            return 0;
        }
        units *= c->units[i];
    }
    if (units > ICOAC_MAX_CRITIC_UNITS) {
        return 0;
    }
    return finite_non_negative(c->rate) && c->rate <= ICOAC_R(10.0) && finite_non_negative(c->discount) &&
           c->discount <= ICOAC_R(1.0) && finite_positive(c->td_clip) && finite_non_negative(c->threshold) &&
           c->threshold < ICOAC_R(1.0);
}

static int actor_documented(const icoac_actor_config_t *a)
{
    return finite_positive(a->noise_std) && finite_non_negative(a->scale) && finite_positive(a->forgetting) &&
           a->forgetting <= ICOAC_R(1.0) && is_flag(a->reflex) && is_flag(a->act_with_sample) &&
           (a->update == ICOAC_ACTOR_POSTERIOR || a->update == ICOAC_ACTOR_MEAN ||
            a->update == ICOAC_ACTOR_GRADIENT) &&
           finite_non_negative(a->rate) &&
           (a->likelihood_std == ICOAC_R(0.0) || finite_positive(a->likelihood_std)) && /* 0: sigma_u */
           is_flag(a->batch) && a->explore_ticks >= 0;
}

static int search_documented(const icoac_search_config_t *s)
{
    return s->batch >= 1 && s->batch <= ICOAC_SEARCH_BATCH_MAX && finite_positive(s->elite_fraction) &&
           s->elite_fraction <= ICOAC_R(1.0) && finite_positive(s->step) && s->step <= ICOAC_R(1.0) &&
           finite_positive(s->floor) && isfinite(s->cov_scale) && s->cov_scale >= ICOAC_R(1.0);
}

static int config_documented(const icoac_config_t *cfg)
{
    const int n = cfg->task.n_inputs;
    if ((cfg->learn != 0 && cfg->learn != 1) || !task_documented(&cfg->task) || !policy_documented(&cfg->policy, n)) {
        return 0;
    }
    if (cfg->mode == ICOAC_MODE_ICO) {
        return ico_documented(&cfg->ico);
    }
    if (cfg->mode == ICOAC_MODE_SEARCH) {
        return search_documented(&cfg->search);
    }
    return cfg->mode == ICOAC_MODE_RL && critic_documented(&cfg->critic, n) && actor_documented(&cfg->actor) &&
           is_flag(cfg->critic.quirks);
}

/* The fields icoac_config_check_field may name, with their group's status and the mode that
 * checks them. */
typedef struct {
    const char *name;
    int32_t status;
    int32_t mode; /* -1: every mode */
} named_field_t;

static const named_field_t named_fields[] = {
    {"mode", ICOAC_ERR_BAD_MODE, -1},
    {"learn", ICOAC_ERR_BAD_MODE, -1},
    {"task.n_inputs", ICOAC_ERR_BAD_TASK, -1},
    {"task.input_sign[0]", ICOAC_ERR_BAD_TASK, -1},
    {"task.input_sign[1]", ICOAC_ERR_BAD_TASK, -1},
    {"task.input_sign[2]", ICOAC_ERR_BAD_TASK, -1},
    {"task.input_sign[3]", ICOAC_ERR_BAD_TASK, -1},
    {"task.input_sign[4]", ICOAC_ERR_BAD_TASK, -1},
    {"task.input_sign[5]", ICOAC_ERR_BAD_TASK, -1},
    {"task.late_source", ICOAC_ERR_BAD_TASK, -1},
    {"task.n_rules", ICOAC_ERR_BAD_TASK, -1},
    {"task.rule_input[0]", ICOAC_ERR_BAD_TASK, -1},
    {"task.rule_input[1]", ICOAC_ERR_BAD_TASK, -1},
    {"task.rule_input[2]", ICOAC_ERR_BAD_TASK, -1},
    {"task.rule_input[3]", ICOAC_ERR_BAD_TASK, -1},
    {"task.rule_input[4]", ICOAC_ERR_BAD_TASK, -1},
    {"task.rule_input[5]", ICOAC_ERR_BAD_TASK, -1},
    {"task.rule_side[0]", ICOAC_ERR_BAD_TASK, -1},
    {"task.rule_side[1]", ICOAC_ERR_BAD_TASK, -1},
    {"task.rule_side[2]", ICOAC_ERR_BAD_TASK, -1},
    {"task.rule_side[3]", ICOAC_ERR_BAD_TASK, -1},
    {"task.rule_side[4]", ICOAC_ERR_BAD_TASK, -1},
    {"task.rule_side[5]", ICOAC_ERR_BAD_TASK, -1},
    {"task.rule_threshold[0]", ICOAC_ERR_BAD_ZONE, -1},
    {"task.rule_threshold[1]", ICOAC_ERR_BAD_ZONE, -1},
    {"task.rule_threshold[2]", ICOAC_ERR_BAD_ZONE, -1},
    {"task.rule_threshold[3]", ICOAC_ERR_BAD_ZONE, -1},
    {"task.rule_threshold[4]", ICOAC_ERR_BAD_ZONE, -1},
    {"task.rule_threshold[5]", ICOAC_ERR_BAD_ZONE, -1},
    {"task.rule_reflex[0]", ICOAC_ERR_BAD_ZONE, -1},
    {"task.rule_reflex[1]", ICOAC_ERR_BAD_ZONE, -1},
    {"task.rule_reflex[2]", ICOAC_ERR_BAD_ZONE, -1},
    {"task.rule_reflex[3]", ICOAC_ERR_BAD_ZONE, -1},
    {"task.rule_reflex[4]", ICOAC_ERR_BAD_ZONE, -1},
    {"task.rule_reflex[5]", ICOAC_ERR_BAD_ZONE, -1},
    {"policy.input_range[0]", ICOAC_ERR_BAD_SCALE, -1},
    {"policy.input_range[1]", ICOAC_ERR_BAD_SCALE, -1},
    {"policy.input_range[2]", ICOAC_ERR_BAD_SCALE, -1},
    {"policy.input_range[3]", ICOAC_ERR_BAD_SCALE, -1},
    {"policy.input_range[4]", ICOAC_ERR_BAD_SCALE, -1},
    {"policy.input_range[5]", ICOAC_ERR_BAD_SCALE, -1},
    {"policy.clip_inputs", ICOAC_ERR_BAD_MODE, -1},
    {"policy.gain", ICOAC_ERR_BAD_GAIN, -1},
    {"policy.reflex_mode", ICOAC_ERR_BAD_MODE, -1},
    {"policy.reflex_force", ICOAC_ERR_BAD_GAIN, -1},
    {"ico.rate", ICOAC_ERR_BAD_ICO_RATE, ICOAC_MODE_ICO},
    {"ico.timing", ICOAC_ERR_BAD_MODE, ICOAC_MODE_ICO},
    {"critic.rate", ICOAC_ERR_BAD_CRITIC, ICOAC_MODE_RL},
    {"critic.discount", ICOAC_ERR_BAD_CRITIC, ICOAC_MODE_RL},
    {"critic.td_clip", ICOAC_ERR_BAD_CRITIC, ICOAC_MODE_RL},
    {"critic.range[0]", ICOAC_ERR_BAD_CRITIC, ICOAC_MODE_RL},
    {"critic.range[1]", ICOAC_ERR_BAD_CRITIC, ICOAC_MODE_RL},
    {"critic.range[2]", ICOAC_ERR_BAD_CRITIC, ICOAC_MODE_RL},
    {"critic.range[3]", ICOAC_ERR_BAD_CRITIC, ICOAC_MODE_RL},
    {"critic.range[4]", ICOAC_ERR_BAD_CRITIC, ICOAC_MODE_RL},
    {"critic.range[5]", ICOAC_ERR_BAD_CRITIC, ICOAC_MODE_RL},
    {"critic.units[0]", ICOAC_ERR_BAD_CRITIC, ICOAC_MODE_RL},
    {"critic.units[1]", ICOAC_ERR_BAD_CRITIC, ICOAC_MODE_RL},
    {"critic.units[2]", ICOAC_ERR_BAD_CRITIC, ICOAC_MODE_RL},
    {"critic.units[3]", ICOAC_ERR_BAD_CRITIC, ICOAC_MODE_RL},
    {"critic.units[4]", ICOAC_ERR_BAD_CRITIC, ICOAC_MODE_RL},
    {"critic.units[5]", ICOAC_ERR_BAD_CRITIC, ICOAC_MODE_RL},
    {"critic.units", ICOAC_ERR_BAD_CRITIC, ICOAC_MODE_RL},
    {"critic.threshold", ICOAC_ERR_BAD_CRITIC, ICOAC_MODE_RL},
    {"critic.quirks", ICOAC_ERR_BAD_MODE, ICOAC_MODE_RL},
    {"actor.noise_std", ICOAC_ERR_BAD_ACTOR, ICOAC_MODE_RL},
    {"actor.scale", ICOAC_ERR_BAD_ACTOR, ICOAC_MODE_RL},
    {"actor.forgetting", ICOAC_ERR_BAD_ACTOR, ICOAC_MODE_RL},
    {"actor.reflex", ICOAC_ERR_BAD_MODE, ICOAC_MODE_RL},
    {"actor.act_with_sample", ICOAC_ERR_BAD_MODE, ICOAC_MODE_RL},
    {"actor.update", ICOAC_ERR_BAD_MODE, ICOAC_MODE_RL},
    {"actor.rate", ICOAC_ERR_BAD_ACTOR, ICOAC_MODE_RL},
    {"actor.likelihood_std", ICOAC_ERR_BAD_ACTOR, ICOAC_MODE_RL},
    {"actor.batch", ICOAC_ERR_BAD_MODE, ICOAC_MODE_RL},
    {"actor.explore_ticks", ICOAC_ERR_BAD_ACTOR, ICOAC_MODE_RL},
    {"search.batch", ICOAC_ERR_BAD_SEARCH, ICOAC_MODE_SEARCH},
    {"search.elite_fraction", ICOAC_ERR_BAD_SEARCH, ICOAC_MODE_SEARCH},
    {"search.step", ICOAC_ERR_BAD_SEARCH, ICOAC_MODE_SEARCH},
    {"search.floor", ICOAC_ERR_BAD_SEARCH, ICOAC_MODE_SEARCH},
    {"search.cov_scale", ICOAC_ERR_BAD_SEARCH, ICOAC_MODE_SEARCH},
};

/* field is a known name with this status, of a group cfg's mode checks. */
static int field_matches(const icoac_config_t *cfg, const char *field, int32_t status)
{
    size_t i;
    for (i = 0; i < sizeof named_fields / sizeof named_fields[0]; ++i) {
        const named_field_t *f = &named_fields[i];
        if (strcmp(f->name, field) == 0) {
            return f->status == status && (f->mode < 0 || f->mode == cfg->mode);
        }
    }
    return 0;
}

/* Finite mean, finite exactly symmetric covariance with a positive diagonal (the leading n). */
static int prior_documented(const icoac_prior_t *prior, int n)
{
    int i;
    for (i = 0; i < n; ++i) {
        if (!isfinite(prior->mean[i]) || !fz_all_finite(prior->cov[i], n) || !(prior->cov[i][i] > ICOAC_R(0.0))) {
            return 0;
        }
    }
    return cov_symmetric(prior->cov, n);
}

static int output_finite(const icoac_output_t *out)
{
    return isfinite(out->force) && isfinite(out->z) && isfinite(out->reflex) && isfinite(out->penalty) &&
           isfinite(out->q) && isfinite(out->weight_norm) && isfinite(out->value) &&
           isfinite(out->td_error) && isfinite(out->noise) && isfinite(out->cov_trace);
}

/* Every real output 0 but weight_norm, which is the (unchanged) |w|. */
static int output_cleared(const icoac_output_t *out, icoac_real_t weight_norm)
{
    return out->force == ICOAC_R(0.0) && out->z == ICOAC_R(0.0) && out->reflex == ICOAC_R(0.0) &&
           out->penalty == ICOAC_R(0.0) && out->q == ICOAC_R(0.0) && out->weight_norm == weight_norm &&
           out->value == ICOAC_R(0.0) && out->td_error == ICOAC_R(0.0) && out->noise == ICOAC_R(0.0) &&
           out->cov_trace == ICOAC_R(0.0);
}

/* An OK RL step: q 0; the mean and gradient readings keep cov; a per-trial batch moves w and
 * cov only at the trial's end; no exploration noise from tick explore_ticks of a trial on. */
static void check_rl_step(const icoac_config_t *cfg, const learned_t *before, const learned_t *after,
                          const icoac_output_t *out, int terminal, int op)
{
    const icoac_actor_config_t *a = &cfg->actor;
    FZ_CHECK(out->q == ICOAC_R(0.0), "op %d: RL step with q %g", op, (double)out->q);
    FZ_CHECK(a->update == ICOAC_ACTOR_POSTERIOR || memcmp(before->cov, after->cov, sizeof before->cov) == 0,
             "op %d: actor reading %d changed cov", op, (int)a->update);
    FZ_CHECK(!a->batch || terminal ||
                 (memcmp(before->w, after->w, sizeof before->w) == 0 &&
                  memcmp(before->cov, after->cov, sizeof before->cov) == 0),
             "op %d: a per-trial batch changed w or cov before the trial's end", op);
    FZ_CHECK(!a->batch || !terminal || !cfg->learn ||
                 (all_zero(after->batch_shift, N) && all_zero(&after->batch_info[0][0], N * N)),
             "op %d: the batch sums were not cleared at the trial's end", op);
    FZ_CHECK(a->explore_ticks == 0 || before->trial_ticks < (uint32_t)a->explore_ticks ||
                 out->noise == ICOAC_R(0.0),
             "op %d: noise %g at tick %u of a trial, explore_ticks %d", op, (double)out->noise,
             (unsigned)before->trial_ticks, (int)a->explore_ticks);
    FZ_CHECK(!(a->explore_ticks > 0 && before->trial_ticks > (uint32_t)a->explore_ticks) || a->batch ||
                 memcmp(before->w, after->w, sizeof before->w) == 0,
             "op %d: the actor learned from an unexplored tick (tick %u, explore_ticks %d)", op,
             (unsigned)before->trial_ticks, (int)a->explore_ticks);
}

/* An OK search step: no critic or noise outputs, cov_trace the trace of cov; w, cov and the
 * record change only at a terminal step (learning), which records the trial or, with the batch
 * full, updates w and cov with the floor held and empties the record. */
static void check_search_step(const icoac_config_t *cfg, const learned_t *before, const learned_t *after,
                              const icoac_output_t *out, int terminal, int op)
{
    const char *field;
    int i;
    FZ_CHECK(out->q == ICOAC_R(0.0) && out->value == ICOAC_R(0.0) && out->td_error == ICOAC_R(0.0) &&
                 out->noise == ICOAC_R(0.0) && out->cov_trace == trace4(CONST_MAT(after->cov)),
             "op %d: search step with q %g value %g td %g noise %g trace %g (cov trace %g)", op, (double)out->q,
             (double)out->value, (double)out->td_error, (double)out->noise, (double)out->cov_trace,
             (double)trace4(CONST_MAT(after->cov)));
    FZ_CHECK(memcmp(before->w_act, after->w_act, sizeof before->w_act) == 0,
             "op %d: a search step changed the trial's weights", op);
    FZ_CHECK(memcmp(before->search_floor, after->search_floor, sizeof before->search_floor) == 0,
             "op %d: a search step changed the floor", op);
    /* a retune to a smaller batch may leave more trials recorded than the new batch holds, until
     * the batch in progress closes at the next terminal step */
    FZ_CHECK(after->search_count >= 0 && after->search_count < ICOAC_SEARCH_BATCH_MAX &&
                 (after->search_count < cfg->search.batch || after->search_count == before->search_count),
             "op %d: %d trials recorded (%d before), batch %d", op, (int)after->search_count,
             (int)before->search_count, (int)cfg->search.batch);
    if (!terminal || !cfg->learn) {
        field = learned_changed(before, after, FZ_RECORD);
        FZ_CHECK(field == 0, "op %d: a non-learning search step changed the learned %s", op, field);
        return;
    }
    if (before->search_count + 1 < cfg->search.batch) {
        FZ_CHECK(after->search_count == before->search_count + 1 &&
                     memcmp(after->search_w[before->search_count], before->w_act, sizeof before->w_act) == 0 &&
                     after->search_ticks[before->search_count] == before->trial_ticks,
                 "op %d: the trial (%u ticks) was not recorded as trial %d", op, (unsigned)before->trial_ticks,
                 (int)before->search_count);
        FZ_CHECK(memcmp(before->w, after->w, sizeof before->w) == 0 &&
                     memcmp(before->cov, after->cov, sizeof before->cov) == 0,
                 "op %d: the search moved w or cov before its batch was full", op);
        return;
    }
    FZ_CHECK(after->search_count == 0, "op %d: the batch is full, but %d trials remain recorded", op,
             (int)after->search_count);
    for (i = 0; i < inputs_of(cfg); ++i) {
        FZ_CHECK(after->cov[i][i] >= after->search_floor[i], "op %d: cov[%d][%d] = %g below its floor %g", op, i, i,
                 (double)after->cov[i][i], (double)after->search_floor[i]);
        FZ_CHECK(after->search_lower[i][i] > ICOAC_R(0.0), "op %d: Cholesky factor with L[%d][%d] = %g", op, i, i,
                 (double)after->search_lower[i][i]);
    }
}

/* The trial ended by a terminal step that returned OK, until the next icoac_reset: what the
 * harness expects, kept apart from the state's header word (which is checked against it). */
static int trial_ended;

/* The state's bytes, as they were before the call being checked. */
static icoac_state_t state_before;

/* The state bytewise equal to state_before, but for counters.ticks, which counted one tick. */
static int unchanged_but_ticks(const icoac_state_t *state)
{
    icoac_state_t expect;
    memcpy(&expect, &state_before, sizeof expect);
    icoac_priv_state(&expect)->counters.ticks++;
    return memcmp(&expect, state, sizeof expect) == 0;
}

static void check_step(const icoac_config_t *cfg, icoac_state_t *state, const icoac_input_t *in, int op)
{
    learned_t before;
    learned_t after;
    icoac_output_t out;
    icoac_counters_t counted;
    icoac_counters_t counted_after;
    const char *field;
    int32_t status;
    const int terminal = (in->flags & ICOAC_INPUT_TERMINAL) != 0u;
    const uint32_t magic = icoac_priv_state_c(state)->magic;
    int finite_in = 1;
    int i;
    FZ_CHECK(magic == (trial_ended ? ICOAC_PRIV_STATE_ENDED : ICOAC_PRIV_STATE_MAGIC),
             "op %d: header word 0x%08x, trial ended %d", op, (unsigned)magic, trial_ended);
    memcpy(&state_before, state, sizeof state_before);
    learned_take(state, &before);
    counted = counters_of(state);
    memset(&out, 0xff, sizeof out); /* NaN in every real: each must be written */
    status = (int32_t)icoac_step(state, in, &out);
    learned_take(state, &after);
    counted_after = counters_of(state);
    /* the task's inputs, and the sensor's reflex on a late tick: what the tick reads */
    for (i = 0; i < inputs_of(cfg); ++i) {
        finite_in = finite_in && isfinite(in->s[i]);
    }
    if (cfg->task.late_source == ICOAC_LATE_SENSOR && (in->flags & ICOAC_INPUT_LATE) != 0u) {
        finite_in = finite_in && isfinite(in->reflex);
    }
    FZ_CHECK(memcmp(&icoac_priv_state_c(state)->config, &icoac_priv_state_c(&state_before)->config,
                    sizeof(icoac_config_t)) == 0,
             "op %d: icoac_step (status %d) changed the state's configuration copy", op, (int)status);
    if (trial_ended) {
        /* every tick after an ended trial is refused until icoac_reset, whatever s */
        FZ_CHECK(status == ICOAC_ERR_TRIAL_ENDED, "op %d: a step after the trial's terminal step returned %d (%s)", op,
                 (int)status, status_name(status));
        FZ_CHECK(unchanged_but_ticks(state), "op %d: ICOAC_ERR_TRIAL_ENDED changed the state beyond counters.ticks", op);
    } else {
        FZ_CHECK(status != ICOAC_ERR_TRIAL_ENDED && status != ICOAC_ERR_CORRUPT_STATE,
                 "op %d: icoac_step in a trial of a state the library wrote returned %d (%s)", op, (int)status,
                 status_name(status));
        FZ_CHECK(finite_in == (status != ICOAC_ERR_NONFINITE_INPUT),
                 "op %d: s = (%g, %g, %g, %g) gave status %d (%s)", op, (double)in->s[0], (double)in->s[1],
                 (double)in->s[2], (double)in->s[3], (int)status, status_name(status));
        trial_ended = terminal && status == ICOAC_OK;
        FZ_CHECK(icoac_priv_state_c(state)->magic == (trial_ended ? ICOAC_PRIV_STATE_ENDED : ICOAC_PRIV_STATE_MAGIC),
                 "op %d: status %d (%s), terminal %d: header word 0x%08x", op, (int)status, status_name(status),
                 terminal, (unsigned)icoac_priv_state_c(state)->magic);
    }
    FZ_CHECK(counted_after.ticks == counted.ticks + 1u &&
                 counted_after.nonfinite == counted.nonfinite + (status == ICOAC_ERR_NONFINITE_INPUT ? 1u : 0u) &&
                 counted_after.numeric_faults == counted.numeric_faults + (status == ICOAC_ERR_NUMERIC ? 1u : 0u),
             "op %d: status %d, counters %u/%u/%u -> %u/%u/%u", op, (int)status, (unsigned)counted.ticks,
             (unsigned)counted.nonfinite, (unsigned)counted.numeric_faults, (unsigned)counted_after.ticks,
             (unsigned)counted_after.nonfinite, (unsigned)counted_after.numeric_faults);
    FZ_CHECK(status == out.status, "op %d: icoac_step returned %d, out.status %d", op, (int)status,
             (int)out.status);
    FZ_CHECK(known_status(status), "op %d: icoac_step returned unknown status %d", op, (int)status);
    if (status == ICOAC_OK) {
        FZ_CHECK(output_finite(&out),
                 "op %d: ICOAC_OK with a non-finite output: force %g z %g reflex %g penalty %g q %g "
                 "|w| %g value %g td %g noise %g trace %g; s = (%g, %g, %g, %g)",
                 op, (double)out.force, (double)out.z, (double)out.reflex, (double)out.penalty,
                 (double)out.q, (double)out.weight_norm, (double)out.value, (double)out.td_error,
                 (double)out.noise, (double)out.cov_trace, (double)in->s[0], (double)in->s[1],
                 (double)in->s[2], (double)in->s[3]);
        field = learned_nonfinite(&after, 1);
        FZ_CHECK(field == 0, "op %d: ICOAC_OK left a non-finite learned %s (w = %g %g %g %g, |w| %g)", op,
                 field, (double)after.w[0], (double)after.w[1], (double)after.w[2], (double)after.w[3],
                 (double)after.weight_norm);
        FZ_CHECK(cov_symmetric(CONST_MAT(after.cov), N), "op %d: covariance not exactly symmetric", op);
        FZ_CHECK(out.penalty == ICOAC_R(0.0) || out.penalty == ICOAC_R(-1.0), "op %d: penalty %g", op,
                 (double)out.penalty);
        FZ_CHECK(out.reflex >= ICOAC_R(-1.0) && out.reflex <= ICOAC_R(1.0) &&
                     (out.penalty != ICOAC_R(0.0) || out.reflex == ICOAC_R(0.0)),
                 "op %d: reflex %g with penalty %g", op, (double)out.reflex, (double)out.penalty);
        field = cfg->learn ? 0 : learned_changed(&before, &after, FZ_BATCH | FZ_RECORD);
        FZ_CHECK(field == 0, "op %d: learn = 0, but the tick changed the learned %s", op, field);
        FZ_CHECK(!terminal || (out.force == ICOAC_R(0.0) && out.noise == ICOAC_R(0.0)),
                 "op %d: terminal step with force %g noise %g", op, (double)out.force, (double)out.noise);
        FZ_CHECK(out.weight_norm == after.weight_norm, "op %d: out.weight_norm %g, state |w| %g", op,
                 (double)out.weight_norm, (double)after.weight_norm);
        /* RL and search count the non-terminal ticks of a trial; ICO does not count */
        FZ_CHECK(after.trial_ticks == before.trial_ticks + (terminal || cfg->mode == ICOAC_MODE_ICO ? 0u : 1u),
                 "op %d: trial tick count %u -> %u (terminal %d, mode %d)", op, (unsigned)before.trial_ticks,
                 (unsigned)after.trial_ticks, terminal, (int)cfg->mode);
        if (cfg->mode == ICOAC_MODE_RL) {
            check_rl_step(cfg, &before, &after, &out, terminal, op);
        } else if (cfg->mode == ICOAC_MODE_SEARCH) {
            check_search_step(cfg, &before, &after, &out, terminal, op);
        } else {
            FZ_CHECK(out.value == ICOAC_R(0.0) && out.td_error == ICOAC_R(0.0) && out.noise == ICOAC_R(0.0) &&
                         out.cov_trace == ICOAC_R(0.0),
                     "op %d: ICO step with value %g td %g noise %g trace %g", op, (double)out.value,
                     (double)out.td_error, (double)out.noise, (double)out.cov_trace);
        }
    } else {
        FZ_CHECK(output_cleared(&out, after.weight_norm),
                 "op %d: status %d (%s) with an output not cleared: force %g z %g reflex %g penalty %g q %g "
                 "|w| %g (state %g) value %g td %g noise %g trace %g",
                 op, (int)status, status_name(status), (double)out.force, (double)out.z, (double)out.reflex,
                 (double)out.penalty, (double)out.q, (double)out.weight_norm, (double)after.weight_norm,
                 (double)out.value, (double)out.td_error, (double)out.noise, (double)out.cov_trace);
        field = learned_changed(&before, &after, FZ_W_ACT | FZ_BATCH | FZ_RECORD | FZ_TRIAL);
        FZ_CHECK(field == 0, "op %d: status %d (%s) changed the learned %s", op, (int)status,
                 status_name(status), field);
    }
}

static void check_reset(const icoac_config_t *cfg, icoac_state_t *state, int op)
{
    const int sampled = (cfg->mode == ICOAC_MODE_RL && cfg->actor.act_with_sample) || cfg->mode == ICOAC_MODE_SEARCH;
    learned_t before;
    learned_t after;
    const char *field;
    int32_t status;
    memcpy(&state_before, state, sizeof state_before);
    learned_take(state, &before);
    status = (int32_t)icoac_reset(state);
    learned_take(state, &after);
    /* a state the library wrote passes the reset's state check; no other error exists */
    FZ_CHECK(status == ICOAC_OK, "op %d: icoac_reset returned %d (%s)", op, (int)status, status_name(status));
    trial_ended = 0;
    FZ_CHECK(icoac_priv_state_c(state)->magic == ICOAC_PRIV_STATE_MAGIC && icoac_priv_state_c(state)->has_prev == 0,
             "op %d: icoac_reset left header word 0x%08x, has_prev %d", op, (unsigned)icoac_priv_state_c(state)->magic,
             (int)icoac_priv_state_c(state)->has_prev);
    FZ_CHECK(memcmp(&icoac_priv_state_c(state)->config, &icoac_priv_state_c(&state_before)->config,
                    sizeof(icoac_config_t)) == 0 &&
                 memcmp(&icoac_priv_state_c(state)->counters, &icoac_priv_state_c(&state_before)->counters,
                        sizeof(icoac_counters_t)) == 0,
             "op %d: icoac_reset changed the configuration copy or the counters", op);
    /* a batch not ended by a terminal step is dropped */
    field = learned_changed(&before, &after, FZ_RECORD);
    FZ_CHECK(field == 0, "op %d: icoac_reset changed the learned %s", op, field);
    FZ_CHECK(all_zero(after.batch_shift, N) && all_zero(&after.batch_info[0][0], N * N) && after.trial_ticks == 0u,
             "op %d: icoac_reset kept the trial's batch sums or tick count (%u)", op, (unsigned)after.trial_ticks);
    FZ_CHECK(fz_all_finite(after.w_act, N), "op %d: icoac_reset OK with a non-finite w_act", op);
    if (!sampled) {
        FZ_CHECK(memcmp(after.w_act, after.w, sizeof after.w) == 0, "op %d: icoac_reset left w_act != w", op);
    }
}

/* icoac_retune(state, next): the status of its checks; on an error the state bytewise unchanged;
 * on OK the new configuration in force and nothing but what it derives changed. Returns 1 when
 * next is the configuration in force now. */
static int check_retune(const icoac_config_t *in_force, icoac_state_t *state, const icoac_config_t *next, int op)
{
    const int32_t config_status = (int32_t)icoac_config_check(next);
    const icoac_priv_state_t *st = icoac_priv_state_c(state);
    icoac_state_t expect;
    icoac_priv_state_t *ex = icoac_priv_state(&expect);
    icoac_config_t got;
    int32_t status;
    int i;
    memcpy(&state_before, state, sizeof state_before);
    status = (int32_t)icoac_retune(state, next);
    if (config_status != ICOAC_OK) {
        FZ_CHECK(status == config_status, "op %d: icoac_retune returned %d, icoac_config_check %d", op, (int)status,
                 (int)config_status);
    } else if (next->mode != in_force->mode || next->task.n_inputs != in_force->task.n_inputs ||
               memcmp(next->critic.units, in_force->critic.units, sizeof next->critic.units) != 0) {
        FZ_CHECK(status == ICOAC_ERR_RETUNE_MODE,
                 "op %d: icoac_retune from mode %d to %d (or of the inputs or critic grid) returned %d (%s)", op,
                 (int)in_force->mode, (int)next->mode, (int)status, status_name(status));
    } else {
        FZ_CHECK(status == ICOAC_OK, "op %d: icoac_retune of a valid configuration returned %d (%s)", op, (int)status,
                 status_name(status));
    }
    if (status != ICOAC_OK) {
        FZ_CHECK(memcmp(&state_before, state, sizeof state_before) == 0,
                 "op %d: icoac_retune returned %d (%s) and changed the state", op, (int)status, status_name(status));
        return 0;
    }
    FZ_CHECK(icoac_get_config(state, &got) == ICOAC_OK && fz_config_equal(&got, next),
             "op %d: icoac_get_config after icoac_retune is not the new configuration", op);
    for (i = 0; i < N; ++i) {
        const icoac_real_t sign = next->task.input_sign[i] < 0 ? ICOAC_R(-1.0) : ICOAC_R(1.0);
        const icoac_real_t inv = i < next->task.n_inputs ? sign / next->policy.input_range[i] : ICOAC_R(0.0);
        FZ_CHECK(memcmp(&st->inv_range[i], &inv, sizeof inv) == 0, "op %d: icoac_retune: inv_range[%d] = %g, %g/%g", op,
                 i, (double)st->inv_range[i], (double)sign, (double)next->policy.input_range[i]);
        if (next->mode == ICOAC_MODE_SEARCH) {
            const icoac_real_t floor = next->search.floor * (st->search.prior_var[i] * next->search.cov_scale);
            FZ_CHECK(memcmp(&st->search.floor[i], &floor, sizeof floor) == 0,
                     "op %d: icoac_retune: search floor[%d] = %g, expected %g", op, i, (double)st->search.floor[i],
                     (double)floor);
        }
    }
    /* every other byte as it was: the learned values, the trial in progress, RNG, counters */
    memcpy(&expect, &state_before, sizeof expect);
    memcpy(&ex->config, &st->config, sizeof ex->config);
    memcpy(ex->inv_range, st->inv_range, sizeof ex->inv_range);
    memcpy(ex->search.floor, st->search.floor, sizeof ex->search.floor);
    FZ_CHECK((st->grid.shape & ICOAC_PRIV_SHAPE_CARTPOLE_RULES) ==
                 (cartpole_rule_layout(&next->task) ? ICOAC_PRIV_SHAPE_CARTPOLE_RULES : 0u),
             "op %d: icoac_retune: rule-layout tag %u for a table of the preset's layout: %d", op,
             (unsigned)(st->grid.shape & ICOAC_PRIV_SHAPE_CARTPOLE_RULES), cartpole_rule_layout(&next->task));
    ex->grid.shape = (uint8_t)((ex->grid.shape & ~ICOAC_PRIV_SHAPE_CARTPOLE_RULES) |
                               (st->grid.shape & ICOAC_PRIV_SHAPE_CARTPOLE_RULES));
    FZ_CHECK(memcmp(&ex->grid, &st->grid, sizeof ex->grid) == 0, "op %d: icoac_retune changed the critic geometry", op);
    FZ_CHECK(memcmp(&expect, state, sizeof expect) == 0,
             "op %d: icoac_retune changed more than the configuration and what it derives", op);
    return 1;
}

/* An uninitialised (zeroed) state and NULL pointers are refused with a zero force. */
static void check_refusals(const icoac_config_t *cfg)
{
    icoac_state_t blank;
    icoac_input_t in;
    icoac_output_t out;
    icoac_prior_t posterior;
    int32_t status;
    memset(&blank, 0, sizeof blank);
    memset(&in, 0, sizeof in);
    memset(&out, 0xff, sizeof out);
    status = (int32_t)icoac_step(&blank, &in, &out);
    FZ_CHECK(status == ICOAC_ERR_NOT_INITIALISED && out.status == status && out.force == ICOAC_R(0.0),
             "icoac_step on a zeroed state: %d / out.status %d / force %g", (int)status, (int)out.status,
             (double)out.force);
    FZ_CHECK(icoac_reset(&blank) == ICOAC_ERR_NOT_INITIALISED, "icoac_reset on a zeroed state");
    FZ_CHECK(icoac_retune(&blank, cfg) == ICOAC_ERR_NOT_INITIALISED, "icoac_retune on a zeroed state");
    {
        icoac_config_t got;
        FZ_CHECK(icoac_get_config(&blank, &got) == ICOAC_ERR_NOT_INITIALISED, "icoac_get_config on a zeroed state");
        FZ_CHECK(icoac_get_config(0, &got) == ICOAC_ERR_NULL && icoac_get_config(&blank, 0) == ICOAC_ERR_NULL &&
                     icoac_retune(0, cfg) == ICOAC_ERR_NULL && icoac_retune(&blank, 0) == ICOAC_ERR_NULL &&
                     icoac_reset(0) == ICOAC_ERR_NULL,
                 "NULL argument of icoac_get_config, icoac_retune or icoac_reset not refused with ICOAC_ERR_NULL");
    }
    FZ_CHECK(icoac_get_posterior(&blank, &posterior) == ICOAC_ERR_NOT_INITIALISED,
             "icoac_get_posterior on a zeroed state");
    {
        icoac_counters_t counters;
        FZ_CHECK(icoac_get_counters(&blank, &counters) == ICOAC_ERR_NOT_INITIALISED,
                 "icoac_get_counters on a zeroed state");
    }
    memset(&out, 0xff, sizeof out);
    status = (int32_t)icoac_step(0, &in, &out);
    FZ_CHECK(status == ICOAC_ERR_NULL && out.status == status && out.force == ICOAC_R(0.0),
             "icoac_step(NULL state): %d", (int)status);
    FZ_CHECK(icoac_config_check(0) == ICOAC_ERR_NULL && icoac_prior_check(0, ICOAC_CARTPOLE_INPUTS) == ICOAC_ERR_NULL &&
                 icoac_init(cfg, 0, 0, 0u) == ICOAC_ERR_NULL,
             "NULL argument not refused with ICOAC_ERR_NULL");
}

/* Every byte of the state is `fill`. */
static int untouched(const icoac_state_t *state, unsigned char fill)
{
    const unsigned char *bytes = (const unsigned char *)state;
    size_t i;
    for (i = 0; i < sizeof *state; ++i) {
        if (bytes[i] != fill) {
            return 0;
        }
    }
    return 1;
}

/* icoac_init against the checks; returns 1 when the state is initialised. */
static int check_init(const icoac_config_t *cfg, icoac_state_t *state, const icoac_prior_t *prior, uint64_t seed)
{
    const int32_t config_status = (int32_t)icoac_config_check(cfg);
    int32_t prior_status = ICOAC_OK;
    learned_t l;
    const char *field;
    const char *bad_field = "not written";
    int32_t status;
    int i;
    FZ_CHECK(known_status(config_status), "icoac_config_check returned unknown status %d", (int)config_status);
    FZ_CHECK((int32_t)icoac_config_check_field(cfg, &bad_field) == config_status,
             "icoac_config_check_field disagrees with icoac_config_check (%d)", (int)config_status);
    FZ_CHECK((config_status == ICOAC_OK) == (bad_field == 0) &&
                 (bad_field == 0 || field_matches(cfg, bad_field, config_status)),
             "icoac_config_check_field: status %d (%s) with field %s (mode %d)", (int)config_status,
             status_name(config_status), bad_field != 0 ? bad_field : "NULL", (int)cfg->mode);
    FZ_CHECK(config_status != ICOAC_OK || config_documented(cfg),
             "icoac_config_check accepted a configuration outside the documented ranges");
    if (prior != 0) {
        prior_status = (int32_t)icoac_prior_check(prior, cfg->task.n_inputs);
        /* a prior is checked over the task's inputs: ICOAC_ERR_BAD_TASK when their count is invalid */
        FZ_CHECK(prior_status == ICOAC_OK || prior_status == ICOAC_ERR_BAD_PRIOR ||
                     (prior_status == ICOAC_ERR_BAD_TASK && (cfg->task.n_inputs < 1 || cfg->task.n_inputs > N)),
                 "icoac_prior_check returned %d (task.n_inputs %d)", (int)prior_status, (int)cfg->task.n_inputs);
        FZ_CHECK(prior_status != ICOAC_OK || prior_documented(prior, cfg->task.n_inputs),
                 "icoac_prior_check accepted a non-finite or asymmetric prior");
    }
    /* a fill the rejected inits must leave as it is */
    memset(state, 0x5A, sizeof *state);
    status = (int32_t)icoac_init(cfg, state, prior, seed);
    FZ_CHECK(status == ICOAC_OK || status == ICOAC_ERR_NUMERIC || untouched(state, 0x5A),
             "icoac_init returned %d (%s) and wrote to the state", (int)status, status_name(status));
    if (config_status != ICOAC_OK) {
        FZ_CHECK(status == config_status, "icoac_init returned %d, icoac_config_check %d", (int)status,
                 (int)config_status);
        return 0;
    }
    if (prior_status != ICOAC_OK) {
        FZ_CHECK(status == prior_status, "icoac_init returned %d, icoac_prior_check %d", (int)status,
                 (int)prior_status);
        return 0;
    }
    if (status == ICOAC_ERR_BAD_PRIOR && cfg->mode == ICOAC_MODE_SEARCH) {
        /* cov_scale * the prior covariance lost positive definiteness in rounding */
        return 0;
    }
    /* icoac_init ends with icoac_reset, whose state check a fresh state passes */
    FZ_CHECK(status == ICOAC_OK, "icoac_init returned %d (%s) for a valid setup", (int)status, status_name(status));
    learned_take(state, &l);
    field = learned_nonfinite(&l, status == ICOAC_OK);
    FZ_CHECK(field == 0, "icoac_init (%s) left a non-finite learned %s (w = %g %g %g %g)", status_name(status),
             field, (double)l.w[0], (double)l.w[1], (double)l.w[2], (double)l.w[3]);
    /* the prior's leading n x n block, 0 past it */
    for (i = 0; i < N; ++i) {
        const int in_task = i < cfg->task.n_inputs;
        int j;
        FZ_CHECK(l.w[i] == (prior != 0 && in_task ? prior->mean[i] : ICOAC_R(0.0)),
                 "icoac_init: w[%d] is not the prior mean", i);
        for (j = 0; j < N; ++j) {
            icoac_real_t expect = prior != 0 ? prior->cov[i][j] : (i == j ? ICOAC_R(1.0) : ICOAC_R(0.0));
            if (!in_task || j >= cfg->task.n_inputs) {
                expect = ICOAC_R(0.0);
            }
            if (cfg->mode == ICOAC_MODE_SEARCH) {
                expect *= cfg->search.cov_scale; /* Sigma0 = c * the prior covariance */
            }
            FZ_CHECK(l.cov[i][j] == expect, "icoac_init: cov[%d][%d] = %g is not the prior's (%g)", i, j,
                     (double)l.cov[i][j], (double)expect);
        }
        if (cfg->mode == ICOAC_MODE_SEARCH && in_task) {
            FZ_CHECK(l.search_floor[i] == cfg->search.floor * l.cov[i][i] && l.search_lower[i][i] > ICOAC_R(0.0),
                     "icoac_init: search floor[%d] %g (expected %g), factor %g", i, (double)l.search_floor[i],
                     (double)(cfg->search.floor * l.cov[i][i]), (double)l.search_lower[i][i]);
        }
    }
    FZ_CHECK(l.search_count == 0 && l.trial_ticks == 0u && all_zero(l.batch_shift, N) &&
                 all_zero(&l.batch_info[0][0], N * N),
             "icoac_init: a trial record (%d), tick count (%u) or batch sums not empty", (int)l.search_count,
             (unsigned)l.trial_ticks);
    return 1;
}

static void check_posterior(const icoac_state_t *state)
{
    icoac_prior_t posterior;
    FZ_CHECK(icoac_get_posterior(state, &posterior) == ICOAC_OK, "icoac_get_posterior failed");
    FZ_CHECK(memcmp(posterior.mean, icoac_priv_state_c(state)->w, sizeof posterior.mean) == 0 &&
                 memcmp(posterior.cov, icoac_priv_cov_c(icoac_priv_state_c(state)), sizeof posterior.cov) == 0,
             "icoac_get_posterior differs from the state");
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    fz_reader_t r;
    icoac_config_t cfg; /* the configuration in force: icoac_init's, then the last retune's */
    icoac_config_t next;
    icoac_config_t got;
    icoac_prior_t prior_storage;
    const icoac_prior_t *prior;
    icoac_state_t state; /* on the stack: ASan reports overruns past it */
    icoac_input_t in;
    uint64_t seed;
    int ops;
    int steps = 0;
    int i;

    fz_reader_init(&r, data, size);
    fz_config(&r, &cfg);
    prior = fz_prior(&r, &prior_storage);
    seed = fz_u64(&r);
    check_refusals(&cfg);
    trial_ended = 0;
    if (!check_init(&cfg, &state, prior, seed)) {
        return 0;
    }
    FZ_CHECK(icoac_get_config(&state, &got) == ICOAC_OK && fz_config_equal(&got, &cfg),
             "icoac_get_config after icoac_init is not the configuration given");
    memset(&in, 0, sizeof in);
    for (ops = 0; ops < FZ_MAX_OPS && steps < FZ_MAX_STEPS && !fz_done(&r); ++ops) {
        const uint8_t op = fz_u8(&r);
        int repeat;
        if ((op & 3u) == 3u) {
            if ((op & 0x40u) == 0u) {
                check_reset(&cfg, &state, ops);
                continue;
            }
            if (op & 0x80u) {
                fz_config(&r, &next);
            } else {
                next = cfg;
                fz_config_over(&r, &next);
            }
            if (check_retune(&cfg, &state, &next, ops)) {
                cfg = next;
            }
            continue;
        }
        if ((op & 0x20u) == 0u) {
            /* the task's n inputs; NaN past them, which the tick must not read */
            for (i = 0; i < N; ++i) {
                in.s[i] = i < inputs_of(&cfg) ? fz_real(&r) : (icoac_real_t)NAN;
            }
        }
        if (op & 0x80u) {
            in.reflex = fz_real(&r);
        }
        in.flags = ((op & 3u) == 2u ? ICOAC_INPUT_TERMINAL : 0u) | ((op & 0x40u) ? ICOAC_INPUT_LATE : 0u);
        for (repeat = ((op >> 2) & 7) + 1; repeat > 0 && steps < FZ_MAX_STEPS; --repeat, ++steps) {
            check_step(&cfg, &state, &in, ops);
        }
    }
    check_posterior(&state);
    FZ_CHECK(icoac_get_config(&state, &got) == ICOAC_OK && fz_config_equal(&got, &cfg),
             "icoac_get_config is not the configuration in force");
    return 0;
}
