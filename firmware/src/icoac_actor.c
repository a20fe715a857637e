/* Bayesian actor (spec 7): rank-1 Gaussian posterior step on (mu_w, Sigma_w),
 * covariance in Joseph form so it stays symmetric positive definite. */
#include "icoac_internal.h"

#define N ICOAC_N_INPUTS

icoac_real_t icoac_trace4(const icoac_real_t m[N][N])
{
    return (m[0][0] + m[1][1]) + (m[2][2] + m[3][3]);
}

/* m = L L^T; returns 0 when m is not positive definite. */
int icoac_cholesky4(const icoac_real_t m[N][N], icoac_real_t lower[N][N])
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
        lower[j][j] = ICOAC_SQRT(diag);
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

void icoac_actor_sample(icoac_state_t *state)
{
    icoac_real_t lower[N][N];
    icoac_real_t normal[N];
    int i;
    int j;
    for (i = 0; i < N; ++i) {
        normal[i] = icoac_rng_normal(&state->rng);
    }
    if (!icoac_cholesky4(ICOAC_CONST_MAT4(state->cov), lower)) {
        icoac_copy4(state->w_act, state->w);
        return;
    }
    for (i = 0; i < N; ++i) {
        icoac_real_t sum = state->w[i];
        for (j = 0; j <= i; ++j) {
            sum += lower[i][j] * normal[j];
        }
        state->w_act[i] = sum;
    }
}

/* Sigma' = A Sigma A^T + sigma_u^2 k k^T with A = I - k h^T (Joseph form), evaluated as
 * A Sigma = Sigma - k (Sigma h)^T and (A Sigma) A^T = A Sigma - (A Sigma h) k^T; the upper
 * triangle is mirrored, so Sigma stays exactly symmetric. */
void icoac_actor_update(const icoac_config_t *cfg, const icoac_state_t *state,
                        const icoac_real_t h[N], icoac_real_t innovation, icoac_real_t w[N],
                        icoac_real_t cov[N][N])
{
    const icoac_real_t noise_var = cfg->noise_std * cfg->noise_std;
    const icoac_real_t (*prior)[N] = ICOAC_CONST_MAT4(state->cov);
    icoac_real_t cov_h[N];
    icoac_real_t gain[N];
    icoac_real_t a_cov[N][N];
    icoac_real_t a_cov_h[N];
    icoac_real_t inv_innovation_var;
    int i;
    int j;

    if (cfg->forgetting < ICOAC_R(1.0)) {
        const icoac_real_t inflate = ICOAC_R(1.0) / cfg->forgetting;
        for (i = 0; i < N; ++i) {
            for (j = 0; j < N; ++j) {
                cov[i][j] = state->cov[i][j] * inflate;
            }
        }
        prior = ICOAC_CONST_MAT4(cov);
    }
    for (i = 0; i < N; ++i) {
        cov_h[i] = icoac_dot4(prior[i], h);
    }
    inv_innovation_var = ICOAC_R(1.0) / (icoac_dot4(h, cov_h) + noise_var);
    for (i = 0; i < N; ++i) {
        gain[i] = cov_h[i] * inv_innovation_var;
        w[i] = state->w[i] + gain[i] * innovation;
    }
    for (i = 0; i < N; ++i) {
        for (j = 0; j < N; ++j) {
            a_cov[i][j] = prior[i][j] - gain[i] * cov_h[j];
        }
    }
    for (i = 0; i < N; ++i) {
        a_cov_h[i] = icoac_dot4(a_cov[i], h);
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
