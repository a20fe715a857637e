/* SPDX-License-Identifier: Apache-2.0 */
/* Actor (method.md: the Bayesian actor, L2): the posterior, mean and gradient readings of one
 * observation, per tick or summed over a trial (batch, A14), and the per-trial sample of w.
 * Vectors and matrices run over all ICOAC_MAX_INPUTS entries: those past the task's n are 0 and
 * stay 0 (h, w and Sigma_w are 0 there), only the factorizations take n. */
#include "icoac_priv.h"

#define N ICOAC_MAX_INPUTS

/* sigma_L^2: actor.likelihood_std, or sigma_u^2 when it is 0 (the literal reading). */
static inline icoac_real_t likelihood_var(const icoac_actor_config_t *actor)
{
    const icoac_real_t std = actor->likelihood_std > ICOAC_R(0.0) ? actor->likelihood_std : actor->noise_std;
    return std * std;
}

void icoac_priv_actor_sample(icoac_priv_state_t *st)
{
    const int n = icoac_priv_inputs(&st->config);
    icoac_real_t lower[N][N];
    icoac_real_t sample[N];
    int i;
    if (!icoac_priv_cholesky(icoac_priv_cov_c(st), lower, n)) {
        /* the draw is made anyway, so the stream does not depend on the factor */
        for (i = 0; i < n; ++i) {
            (void)icoac_rng_normal(&st->rng);
        }
        icoac_priv_copy(st->w_act, st->w);
        return;
    }
    icoac_priv_sample_lower(&st->rng, st->w, ICOAC_PRIV_CONST_MAT(lower), sample, n);
    icoac_priv_copy(st->w_act, sample);
}

/* Posterior reading: Sigma' = A Sigma A^T + sigma_L^2 k k^T with A = I - k h^T (Joseph form),
 * evaluated as A Sigma = Sigma - k (Sigma h)^T and (A Sigma) A^T = A Sigma - (A Sigma h) k^T.
 * A Sigma is formed one row at a time (row i of the result needs row i of A Sigma only), so the
 * frame holds vectors, no matrix; row i writes the upper triangle of row i of cov, which no
 * later row reads, and the lower triangle is mirrored at the end, so Sigma stays exactly
 * symmetric. With forgetting, Sigma / lambda_f is formed in cov first and read from there. cov
 * must not be the state's Sigma (the tick stages into the spare buffer). Returns 1 when the new
 * off-diagonal entries are finite (each adds v - v, 0 or NaN, to a sum), 0 otherwise; the
 * caller checks the diagonal through the trace. */
static inline int posterior_step(const icoac_actor_config_t *actor, const icoac_priv_state_t *st,
                                 const icoac_real_t h[N], icoac_real_t innovation, icoac_real_t w[N],
                                 icoac_real_t cov[N][N], int n)
{
    const icoac_real_t noise_var = likelihood_var(actor);
    const icoac_real_t (*prior)[N] = icoac_priv_cov_c(st);
    icoac_real_t row[N];
    icoac_real_t cov_h[N];
    icoac_real_t gain[N];
    icoac_real_t inv_innovation_var;
    icoac_real_t off_diagonal = ICOAC_R(0.0);
    int i;
    int j;

    if (actor->forgetting < ICOAC_R(1.0)) {
        const icoac_real_t inflate = ICOAC_R(1.0) / actor->forgetting;
        for (i = 0; i < n; ++i) {
            for (j = 0; j < n; ++j) {
                cov[i][j] = prior[i][j] * inflate;
            }
        }
        prior = ICOAC_PRIV_CONST_MAT(cov);
    }
    for (i = 0; i < n; ++i) {
        cov_h[i] = icoac_priv_dot_n(prior[i], h, n);
    }
    inv_innovation_var = ICOAC_R(1.0) / (icoac_priv_dot_n(h, cov_h, n) + noise_var);
    for (i = 0; i < N; ++i) {
        if (i < n) {
            gain[i] = cov_h[i] * inv_innovation_var;
            w[i] = st->w[i] + gain[i] * innovation;
        } else {
            w[i] = st->w[i];
        }
    }
    for (i = 0; i < n; ++i) {
        icoac_real_t a_cov_h;
        for (j = 0; j < n; ++j) {
            /* cppcheck-suppress uninitvar ; gain[i] is set above for every i < n */
            row[j] = prior[i][j] - gain[i] * cov_h[j];
        }
        a_cov_h = icoac_priv_dot_n(row, h, n);
        for (j = i; j < n; ++j) {
            cov[i][j] = row[j] - a_cov_h * gain[j] + noise_var * gain[i] * gain[j];
        }
    }
    for (i = 0; i < n; ++i) {
        for (j = i + 1; j < n; ++j) {
            cov[j][i] = cov[i][j];
            off_diagonal += cov[i][j] - cov[i][j];
        }
    }
    return icoac_priv_finite(off_diagonal);
}

void icoac_priv_actor_posterior(const icoac_actor_config_t *actor, const icoac_priv_state_t *st,
                                const icoac_real_t h[N], icoac_real_t innovation, icoac_real_t w[N],
                                icoac_real_t cov[N][N])
{
    icoac_real_t staged[N][N];
    int i;
    (void)posterior_step(actor, st, h, innovation, w, staged, N);
    for (i = 0; i < N; ++i) {
        icoac_priv_copy(cov[i], staged[i]);
    }
}

/* Mean reading: mu += Sigma0 h innovation / (h^T Sigma0 h + sigma_L^2), Sigma_w unchanged; over
 * the first n entries. */
static inline void mean_step(const icoac_actor_config_t *actor, const icoac_priv_state_t *st,
                             const icoac_real_t h[N], icoac_real_t innovation, icoac_real_t w[N], int n)
{
    const icoac_real_t (*prior)[N] = icoac_priv_cov_c(st);
    icoac_real_t cov_h[N];
    icoac_real_t step;
    int i;
    for (i = 0; i < n; ++i) {
        cov_h[i] = icoac_priv_dot_n(prior[i], h, n);
    }
    step = innovation / (icoac_priv_dot_n(h, cov_h, n) + likelihood_var(actor));
    for (i = 0; i < n; ++i) {
        w[i] = st->w[i] + cov_h[i] * step;
    }
}

/* sum += h h^T / sigma_L^2 (out of line: its frame is not nested in its callers') */
ICOAC_PRIV_NOINLINE static void add_info(const icoac_actor_config_t *actor, const icoac_real_t h[N],
                                         icoac_real_t sum[N][N])
{
    const icoac_real_t inv_var = ICOAC_R(1.0) / likelihood_var(actor);
    int i;
    int j;
    for (i = 0; i < N; ++i) {
        for (j = 0; j < N; ++j) {
            sum[i][j] += h[i] * h[j] * inv_var;
        }
    }
}

/* The steps of the batch's closed form, each out of line: no value of one is live across the
 * factorizations, so batch_end's frame holds pointers only. */
/* cov = Sigma (/ lambda_f on the posterior reading with forgetting) */
ICOAC_PRIV_NOINLINE static void batch_prior(const icoac_actor_config_t *actor, const icoac_priv_state_t *st,
                                            icoac_real_t cov[N][N])
{
    /* one loop over the N * N entries, not unrolled into a frame of spilled values */
    icoac_real_t *const entry = &cov[0][0];
    int k;
    (void)memcpy(cov, icoac_priv_cov_c(st), sizeof st->cov_buffer[0]);
    if (actor->update == ICOAC_ACTOR_POSTERIOR && actor->forgetting < ICOAC_R(1.0)) {
        const icoac_real_t inflate = ICOAC_R(1.0) / actor->forgetting;
        for (k = 0; k < (N * N); ++k) {
            entry[k] *= inflate;
        }
    }
}

/* precision (Sigma^-1 in place) += the trial's information */
ICOAC_PRIV_NOINLINE static void batch_precision(const icoac_priv_state_t *st, icoac_real_t precision[N][N])
{
    int i;
    int j;
    for (i = 0; i < N; ++i) {
        for (j = 0; j < N; ++j) {
            precision[i][j] += st->batch.info[i][j];
        }
    }
}

/* w = mu + P^-1 shift; the posterior reading's return of batch_end, or 0 */
ICOAC_PRIV_NOINLINE static int batch_mean(const icoac_actor_config_t *actor, const icoac_priv_state_t *st,
                                          const icoac_real_t shift[N], icoac_real_t w[N],
                                          const icoac_real_t cov[N][N])
{
    int i;
    for (i = 0; i < N; ++i) {
        w[i] = st->w[i] + icoac_priv_dot(cov[i], shift);
    }
    if (actor->update != ICOAC_ACTOR_POSTERIOR) {
        return 0;
    }
    for (i = 0; (i + 1) < N; ++i) {
        if (!icoac_priv_all_finite(&cov[i][i + 1], N - 1 - i)) {
            return -1; /* an off-diagonal entry (the caller checks the diagonal) */
        }
    }
    return 1;
}

/* The batch's closed form at a trial's end: with precision P = Sigma^-1 + sum h h^T / sigma_L^2,
 * mu' = mu + P^-1 sum h innovation / sigma_L^2, Sigma' = P^-1 (posterior; the mean reading keeps
 * Sigma); the gradient reading moves mu by beta / sigma_u^2 * sum delta eps h. The sums are the
 * state's plus this tick's observation (h_last, or NULL) and shift, staged by the caller. P is
 * formed and inverted in cov (in place: no matrix in a frame). */
ICOAC_PRIV_NOINLINE static int batch_end(const icoac_actor_config_t *actor, const icoac_priv_state_t *st,
                                          const icoac_real_t *h_last, const icoac_real_t shift[N],
                                          icoac_real_t w[N], icoac_real_t cov[N][N])
{
    const int n = icoac_priv_inputs(&st->config);
    int i;
    if (actor->update != ICOAC_ACTOR_POSTERIOR && actor->update != ICOAC_ACTOR_MEAN &&
        actor->update != ICOAC_ACTOR_GRADIENT) {
        return -2;
    }
    if (actor->update == ICOAC_ACTOR_GRADIENT) {
        const icoac_real_t step = actor->rate / (actor->noise_std * actor->noise_std);
        for (i = 0; i < N; ++i) {
            w[i] = st->w[i] + step * shift[i];
        }
        return 0;
    }
    batch_prior(actor, st, cov);
    if (!icoac_priv_spd_inverse(cov, n)) {
        return -1;
    }
    batch_precision(st, cov);
    if (h_last != NULL) {
        add_info(actor, h_last, cov); /* and this tick's observation */
    }
    if (!icoac_priv_spd_inverse(cov, n)) {
        return -1;
    }
    return batch_mean(actor, st, shift, w, ICOAC_PRIV_CONST_MAT(cov));
}

/* The batch's shift after one more observation, and a value that is finite only when the
 * sums stay finite (the new trace of the information plus |shift|^2 bound every entry). */
ICOAC_PRIV_NOINLINE static icoac_real_t batch_shift(const icoac_actor_config_t *actor,
                                                    const icoac_priv_state_t *st, const icoac_real_t h[N],
                                                    icoac_real_t observation, icoac_real_t shift[N])
{
    icoac_real_t trace = ICOAC_R(0.0);
    icoac_real_t scale = ICOAC_R(1.0);
    int i;
    if (actor->update != ICOAC_ACTOR_GRADIENT) {
        scale = ICOAC_R(1.0) / likelihood_var(actor);
        trace = icoac_priv_trace(st->batch.info) + icoac_priv_dot(h, h) * scale;
    }
    for (i = 0; i < N; ++i) {
        shift[i] = st->batch.shift[i] + h[i] * (observation * scale);
    }
    return trace + icoac_priv_dot(shift, shift);
}

/* icoac_priv_actor_step over the first n entries (a compile-time n in each instance). */
static inline int actor_step(const icoac_actor_config_t *actor, icoac_priv_state_t *st, const icoac_real_t h[N],
                             icoac_real_t delta, int observed, int trial_end, icoac_real_t w[N], icoac_real_t cov[N][N],
                             int n)
{
    /* u_ob - h^T mu_w, with u_ob = h^T w_act + alpha * delta * eps (Eq. 7-8); acting with mu_w,
     * w_act is mu_w bit for bit and the first term is exactly 0 */
    icoac_real_t innovation = actor->scale * delta * st->noise_prev;
    if (actor->act_with_sample != 0) {
        innovation += icoac_priv_dot_n(h, st->w_act, n) - icoac_priv_dot_n(h, st->w, n);
    }
    if (actor->batch != 0) {
        icoac_real_t *shift = st->batch.staged_shift;
        icoac_priv_copy(shift, st->batch.shift);
        if (observed != 0) {
            const icoac_real_t observation =
                actor->update == ICOAC_ACTOR_GRADIENT ? delta * st->noise_prev : innovation;
            if (!icoac_priv_finite(batch_shift(actor, st, h, observation, shift))) {
                return -1;
            }
        }
        if (!trial_end) {
            icoac_priv_copy(w, st->w);
            return 0;
        }
        return batch_end(actor, st, observed ? h : NULL, shift, w, cov);
    }
    if (!observed) {
        icoac_priv_copy_n(w, st->w, n);
        return 0;
    }
    switch (actor->update) {
    case ICOAC_ACTOR_MEAN:
        mean_step(actor, st, h, innovation, w, n);
        return 0;
    case ICOAC_ACTOR_GRADIENT: {
        const icoac_real_t step = actor->rate * delta * st->noise_prev / (actor->noise_std * actor->noise_std);
        int i;
        for (i = 0; i < n; ++i) {
            w[i] = st->w[i] + step * h[i];
        }
        return 0;
    }
    case ICOAC_ACTOR_POSTERIOR:
        return posterior_step(actor, st, h, innovation, w, cov, n) ? 1 : -1;
    default:
        return -2;
    }
}

int icoac_priv_actor_step(const icoac_actor_config_t *actor, icoac_priv_state_t *st, const icoac_real_t h[N],
                          icoac_real_t delta, int observed, int trial_end, icoac_real_t w[N],
                          icoac_real_t cov[N][N], int n)
{
    if (n == ICOAC_CARTPOLE_INPUTS) {
        return actor_step(actor, st, h, delta, observed, trial_end, w, cov, ICOAC_CARTPOLE_INPUTS);
    }
    return actor_step(actor, st, h, delta, observed, trial_end, w, cov, N);
}

void icoac_priv_actor_commit_batch(const icoac_actor_config_t *actor, icoac_priv_state_t *st,
                                   const icoac_real_t h[N], int observed, int trial_end)
{
    int i;
    int j;
    if (trial_end != 0) {
        for (i = 0; i < N; ++i) {
            for (j = 0; j < N; ++j) {
                st->batch.info[i][j] = ICOAC_R(0.0);
            }
            st->batch.shift[i] = ICOAC_R(0.0);
        }
        return;
    }
    if (observed && actor->update != ICOAC_ACTOR_GRADIENT) {
        add_info(actor, h, st->batch.info);
    }
    icoac_priv_copy(st->batch.shift, st->batch.staged_shift);
}
