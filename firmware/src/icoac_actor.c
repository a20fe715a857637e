/* Bayesian actor (spec 7): rank-1 Gaussian posterior step on (mu_w, Sigma_w),
 * covariance in Joseph form so it stays symmetric positive definite. */
#include "icoac_priv.h"

#define N ICOAC_N_INPUTS

icoac_real_t icoac_priv_trace4(const icoac_real_t m[N][N])
{
    return (m[0][0] + m[1][1]) + (m[2][2] + m[3][3]);
}

/* m = L L^T; returns 0 when m is not positive definite. */
int icoac_priv_cholesky4(const icoac_real_t m[N][N], icoac_real_t lower[N][N])
{
    int i;
    int j;
    int k;
    for (i = 0; i < N; ++i) {
        for (j = 0; j < N; ++j) {
            lower[i][j] = ICOAC_R(0.0);
        }
    }
    for (j = 0; j < N; ++j) {
        icoac_real_t diag = m[j][j];
        for (k = 0; k < j; ++k) {
            diag -= lower[j][k] * lower[j][k];
        }
        if (!(diag > ICOAC_R(0.0))) {
            return 0;
        }
        lower[j][j] = ICOAC_PRIV_SQRT(diag);
        for (i = j + 1; i < N; ++i) {
            icoac_real_t sum = m[i][j];
            for (k = 0; k < j; ++k) {
                sum -= lower[i][k] * lower[j][k];
            }
            lower[i][j] = sum / lower[j][j];
        }
    }
    return 1;
}

void icoac_priv_actor_sample(icoac_priv_state_t *st)
{
    icoac_real_t lower[N][N];
    icoac_real_t normal[N];
    int i;
    int j;
    for (i = 0; i < N; ++i) {
        normal[i] = icoac_rng_normal(&st->rng);
    }
    if (!icoac_priv_cholesky4(icoac_priv_cov_c(st), lower)) {
        icoac_priv_copy4(st->w_act, st->w);
        return;
    }
    for (i = 0; i < N; ++i) {
        icoac_real_t sum = st->w[i];
        for (j = 0; j <= i; ++j) {
            sum += lower[i][j] * normal[j];
        }
        st->w_act[i] = sum;
    }
}

/* Sigma' = A Sigma A^T + sigma_u^2 k k^T with A = I - k h^T (Joseph form), evaluated as
 * A Sigma = Sigma - k (Sigma h)^T and (A Sigma) A^T = A Sigma - (A Sigma h) k^T; the upper
 * triangle is mirrored, so Sigma stays exactly symmetric. */
void icoac_priv_actor_update(const icoac_actor_config_t *actor, const icoac_priv_state_t *st,
                             const icoac_real_t h[N], icoac_real_t innovation, icoac_real_t w[N],
                             icoac_real_t cov[N][N])
{
    const icoac_real_t noise_var = actor->noise_std * actor->noise_std;
    const icoac_real_t (*prior)[N] = icoac_priv_cov_c(st);
    icoac_real_t cov_h[N];
    icoac_real_t gain[N];
    icoac_real_t a_cov[N][N];
    icoac_real_t a_cov_h[N];
    icoac_real_t inv_innovation_var;
    int i;
    int j;

    if (actor->forgetting < ICOAC_R(1.0)) {
        const icoac_real_t inflate = ICOAC_R(1.0) / actor->forgetting;
        for (i = 0; i < N; ++i) {
            for (j = 0; j < N; ++j) {
                cov[i][j] = prior[i][j] * inflate;
            }
        }
        prior = ICOAC_PRIV_CONST_MAT4(cov);
    }
    for (i = 0; i < N; ++i) {
        cov_h[i] = icoac_priv_dot4(prior[i], h);
    }
    inv_innovation_var = ICOAC_R(1.0) / (icoac_priv_dot4(h, cov_h) + noise_var);
    for (i = 0; i < N; ++i) {
        gain[i] = cov_h[i] * inv_innovation_var;
        w[i] = st->w[i] + gain[i] * innovation;
    }
    for (i = 0; i < N; ++i) {
        for (j = 0; j < N; ++j) {
            a_cov[i][j] = prior[i][j] - gain[i] * cov_h[j];
        }
    }
    for (i = 0; i < N; ++i) {
        a_cov_h[i] = icoac_priv_dot4(a_cov[i], h);
    }
    /* written last: cov may be the prior it was computed from */
    for (i = 0; i < N; ++i) {
        for (j = i; j < N; ++j) {
            const icoac_real_t value = a_cov[i][j] - a_cov_h[i] * gain[j] + noise_var * gain[i] * gain[j];
            cov[i][j] = value;
            cov[j][i] = value;
        }
    }
}
