/* SPDX-License-Identifier: Apache-2.0 */
/* Episodic search over N(mu_w, Sigma_w) (method.md, L4): each trial acts with one sample of w, like
 * the ICO policy and without exploration noise; each failed trial's length is its return; every
 * search.batch trials the elite moves mu_w and Sigma_w (cross-entropy step with a floor). */
#include "icoac_features.h"

#define N ICOAC_MAX_INPUTS

/* floor_i = f * (c * prior variance_i), the arithmetic of Sigma0's diagonal. */
static icoac_real_t floor_of(const icoac_search_config_t *search, icoac_real_t prior_var)
{
    return search->floor * (prior_var * search->cov_scale);
}

/* Sigma0 = c * cov, its floors and its Cholesky factor; 0 when not finite or not PD. */
static int scaled_prior(const icoac_search_config_t *search, const icoac_real_t cov[N][N], icoac_real_t sigma0[N][N],
                        icoac_real_t floor[N], icoac_real_t lower[N][N], int n)
{
    int i;
    int j;
    for (i = 0; i < N; ++i) {
        floor[i] = floor_of(search, cov[i][i]);
        for (j = 0; j < N; ++j) {
            sigma0[i][j] = cov[i][j] * search->cov_scale;
        }
    }
    return icoac_priv_all_finite(&sigma0[0][0], N * N) && icoac_priv_all_finite(floor, N) &&
           icoac_priv_cholesky(ICOAC_PRIV_CONST_MAT(sigma0), lower, n);
}

int icoac_priv_search_prior_ok(const icoac_search_config_t *search, const icoac_real_t cov[N][N], int n)
{
    icoac_real_t sigma0[N][N]; /* factored in place */
    icoac_real_t floor[N];
    return scaled_prior(search, cov, sigma0, floor, sigma0, n);
}

void icoac_priv_search_init(const icoac_search_config_t *search, icoac_priv_state_t *st)
{
    icoac_real_t (*cov)[N] = icoac_priv_cov(st);
    int i;
    st->search.count = 0;
    for (i = 0; i < N; ++i) {
        st->search.prior_var[i] = cov[i][i];
    }
    (void)scaled_prior(search, ICOAC_PRIV_CONST_MAT(cov), cov, st->search.floor, st->search.lower,
                       icoac_priv_inputs(&st->config));
}

void icoac_priv_search_floors(const icoac_search_config_t *search, icoac_priv_search_t *recorded)
{
    int i;
    for (i = 0; i < N; ++i) {
        recorded->floor[i] = floor_of(search, recorded->prior_var[i]);
    }
}

void icoac_priv_search_sample(icoac_priv_state_t *st)
{
    icoac_real_t sample[N];
    icoac_priv_sample_lower(&st->rng, st->w, ICOAC_PRIV_CONST_MAT(st->search.lower), sample,
                            icoac_priv_inputs(&st->config));
    icoac_priv_copy(st->w_act, sample);
}

/* The batch being closed: the recorded trials 0..count-1, then the trial ending now. */
typedef struct {
    const icoac_priv_search_t *recorded;
    int count; /* recorded trials */
    const icoac_real_t *last_w;
    uint32_t last_ticks;
    int size;
} closing_batch_t;

static const icoac_real_t *trial_w(const closing_batch_t *b, int k)
{
    return k < b->count ? b->recorded->w[k] : b->last_w;
}

static uint32_t trial_ticks(const closing_batch_t *b, int k)
{
    return k < b->count ? b->recorded->ticks[k] : b->last_ticks;
}

/* The n_elite longest trials, longest first; ties go to the earlier trial. Returns how many were
 * chosen: n_elite, as a closing batch holds at least that many trials (if it held fewer, the
 * loop would stop when every trial is taken, rather than shift by -1). */
static int choose_elite(const closing_batch_t *b, int n_elite, uint8_t elite[ICOAC_SEARCH_BATCH_MAX])
{
    uint32_t taken = 0u;
    int e;
    int k;
    for (e = 0; e < n_elite; ++e) {
        int best = -1;
        for (k = 0; k < b->size; ++k) {
            if ((((taken >> (uint32_t)k) & 1u) == 0u) && ((best < 0) || (trial_ticks(b, k) > trial_ticks(b, best)))) {
                best = k;
            }
        }
        if (best < 0) {
            break; /* every trial taken */
        }
        taken |= 1u << (uint32_t)best;
        elite[e] = (uint8_t)best;
    }
    return e;
}

/* Elite size n_e = max(1, round(rho K)), at most K; the value is bounded before its conversion,
 * so a corrupted rho (NaN, huge) converts nothing out of range. */
static int elite_size(const icoac_search_config_t *search, int batch)
{
    const icoac_real_t n = search->elite_fraction * (icoac_real_t)batch + ICOAC_R(0.5);
    if (!(n >= ICOAC_R(1.0))) {
        return 1;
    }
    return n >= (icoac_real_t)batch ? batch : (int)n;
}

/* Each coordinate's variance given the earlier ones (the squared Cholesky pivot) at least this
 * fraction of its variance: below it (correlations beyond 0.99995) Sigma' counts as singular. */
#define SEARCH_MIN_PIVOT_FRACTION ICOAC_R(1.0e-4)

/* lower = the Cholesky factor of cov, and every pivot a fair fraction of its diagonal entry. */
static int well_conditioned(const icoac_real_t cov[N][N], icoac_real_t lower[N][N], int n)
{
    int j;
    if (!icoac_priv_cholesky(cov, lower, n)) {
        return 0;
    }
    for (j = 0; j < n; ++j) {
        if (!(lower[j][j] * lower[j][j] >= SEARCH_MIN_PIVOT_FRACTION * cov[j][j])) {
            return 0;
        }
    }
    return 1;
}

/* The update after a full batch, staged into w and cov: mu' = (1-a) mu + a mean_elite;
 * Sigma' = (1-a) Sigma + a Cov_elite about mu' (upper triangle mirrored), then
 * Sigma'_ii >= floor_i. Returns 0 when a value is not finite. */
static int search_update(const icoac_search_config_t *search, const icoac_priv_state_t *st, const closing_batch_t *b,
                         int elite_size_wanted, icoac_real_t w[N], icoac_real_t cov[N][N])
{
    const icoac_real_t (*sigma)[N] = icoac_priv_cov_c(st);
    const icoac_real_t a = search->step;
    uint8_t elite[ICOAC_SEARCH_BATCH_MAX];
    const int n_elite = choose_elite(b, elite_size_wanted, elite);
    const icoac_real_t inv_n = ICOAC_R(1.0) / (icoac_real_t)n_elite;
    int e;
    int i;
    int j;
    for (i = 0; i < N; ++i) {
        icoac_real_t sum = ICOAC_R(0.0);
        for (e = 0; e < n_elite; ++e) {
            sum += trial_w(b, elite[e])[i];
        }
        w[i] = (ICOAC_R(1.0) - a) * st->w[i] + a * (sum * inv_n);
    }
    for (i = 0; i < N; ++i) {
        for (j = i; j < N; ++j) {
            icoac_real_t sum = ICOAC_R(0.0);
            icoac_real_t value;
            for (e = 0; e < n_elite; ++e) {
                const icoac_real_t *we = trial_w(b, elite[e]);
                sum += (we[i] - w[i]) * (we[j] - w[j]);
            }
            value = (ICOAC_R(1.0) - a) * sigma[i][j] + a * (sum * inv_n);
            if (i == j && !(value >= st->search.floor[i])) {
                value = st->search.floor[i];
            }
            cov[i][j] = value;
            cov[j][i] = value;
        }
    }
    if (!icoac_priv_all_finite(w, N) || !icoac_priv_all_finite(&cov[0][0], N * N)) {
        return 0;
    }
    return 1;
}

/* Sigma' (staged in cov) factored, L L^T = Sigma', with every pivot a fair fraction of its
 * variance (else with the floors added to the diagonal); 0 when it is not positive definite. */
static int factor_update(const icoac_priv_state_t *st, icoac_real_t cov[N][N], icoac_real_t lower[N][N])
{
    int i;
    if (!well_conditioned(ICOAC_PRIV_CONST_MAT(cov), lower, icoac_priv_inputs(&st->config))) {
        /* A rank-deficient elite (n_e <= n) with a step near 1 leaves Sigma' singular or nearly
         * so, which a diagonal floor need not repair: add the floor to the diagonal instead, a
         * positive definite bound below Sigma' (Sigma' is positive semidefinite up to rounding). */
        for (i = 0; i < N; ++i) {
            cov[i][i] += st->search.floor[i];
        }
        if (!icoac_priv_cholesky(ICOAC_PRIV_CONST_MAT(cov), lower, icoac_priv_inputs(&st->config))) {
            return 0;
        }
    }
    return icoac_priv_all_finite(&lower[0][0], N * N);
}

/* x clamped to [lo, hi]. */
static int clamp_int(int32_t x, int lo, int hi)
{
    return x < lo ? lo : (x > hi ? hi : (int)x);
}

/* The closing batch's mean and Sigma' staged (into batch.staged_shift and the spare buffer). */
ICOAC_PRIV_NOINLINE static int stage_batch(const icoac_config_t *cfg, icoac_priv_state_t *st, int batch, int count)
{
    closing_batch_t b;
    b.recorded = &st->search;
    b.count = count;
    b.last_w = st->w_act;
    b.last_ticks = st->trial_ticks;
    b.size = count + 1;
    return search_update(&cfg->search, st, &b, elite_size(&cfg->search, batch), st->batch.staged_shift,
                         icoac_priv_cov_spare(st));
}

/* The staged mean (batch.staged_shift, a tick's scratch, unused by the search otherwise) and
 * Sigma' (the spare buffer) factored and committed, or nothing when Sigma' is not positive
 * definite. */
ICOAC_PRIV_NOINLINE static int commit_batch(icoac_priv_state_t *st)
{
    icoac_priv_search_t *recorded = &st->search;
    const icoac_real_t *w = st->batch.staged_shift;
    icoac_real_t lower[N][N];
    int i;
    int j;
    if (!factor_update(st, icoac_priv_cov_spare(st), lower)) {
        return 0;
    }
    icoac_priv_copy(st->w, w);
    st->cov_slot = (st->cov_slot & 1) ^ 1;
    for (i = 0; i < N; ++i) {
        for (j = 0; j < N; ++j) {
            recorded->lower[i][j] = lower[i][j];
        }
    }
    st->weight_norm = ICOAC_PRIV_SQRT(icoac_priv_dot(w, w));
    recorded->count = 0;
    return 1;
}

/* A terminal tick ends the trial: record (w_act, length); a full batch updates (staged: on a
 * failure nothing is recorded and 0 is returned). The batch closes when at least batch - 1
 * trials are recorded (more after a retune to a smaller batch). Count and batch are clamped to
 * the arrays, whatever the state holds. The update's two stages are kept out of line, one after
 * the other: a trial that only records pays no frame for them, and their frames do not add up. */
static int end_trial(const icoac_config_t *cfg, icoac_priv_state_t *st)
{
    icoac_priv_search_t *recorded = &st->search;
    const int batch = clamp_int(cfg->search.batch, 1, ICOAC_SEARCH_BATCH_MAX);
    const int count = clamp_int(recorded->count, 0, ICOAC_SEARCH_BATCH_MAX - 1);
    if (!cfg->learn) {
        return 1;
    }
    if (count + 1 < batch) {
        icoac_priv_copy(recorded->w[count], st->w_act);
        recorded->ticks[count] = st->trial_ticks;
        recorded->count = count + 1;
        return 1;
    }
    return stage_batch(cfg, st, batch, count) && commit_batch(st);
}

/* Writes every output field but reflex, penalty, weight_norm and status. */
int icoac_priv_search_tick(const icoac_config_t *cfg, icoac_priv_state_t *st,
                           const icoac_real_t scaled[ICOAC_MAX_INPUTS], int terminal, icoac_output_t *out)
{
    icoac_real_t z;
    icoac_real_t force;
    out->q = ICOAC_R(0.0);
    out->value = ICOAC_R(0.0);
    out->td_error = ICOAC_R(0.0);
    out->noise = ICOAC_R(0.0);
    if (terminal != 0) {
        if (!end_trial(cfg, st)) {
            return 0;
        }
        out->z = ICOAC_R(0.0);
        out->force = ICOAC_R(0.0);
        out->cov_trace = icoac_priv_trace(icoac_priv_cov_c(st));
        return 1;
    }
    z = icoac_priv_dot(st->w_act, scaled);
    force = cfg->policy.gain * z + icoac_priv_reflex_force(&cfg->policy, out->reflex);
    if (!icoac_priv_finite(force)) {
        return 0;
    }
    out->z = z;
    out->force = force;
    out->cov_trace = icoac_priv_trace(icoac_priv_cov_c(st));
    st->trial_ticks++;
    return 1;
}
