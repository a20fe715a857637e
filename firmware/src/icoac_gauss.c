/* SPDX-License-Identifier: Apache-2.0 */
/* Gaussian helpers shared by the actor and the search: Cholesky factor, SPD inverse, and a
 * draw through the factor. */
#include "icoac_priv.h"

#define N ICOAC_MAX_INPUTS

int icoac_priv_cholesky(const icoac_real_t m[N][N], icoac_real_t lower[N][N], int n)
{
    int i;
    int j;
    int k;
    /* the entries the factor leaves 0; column j reads m's column j on and writes it, so lower
     * may be m itself */
    for (i = 0; i < N; ++i) {
        for (j = 0; j < N; ++j) {
            if ((j > i) || (i >= n)) {
                lower[i][j] = ICOAC_R(0.0);
            }
        }
    }
    for (j = 0; j < n; ++j) {
        icoac_real_t diag = m[j][j];
        for (k = 0; k < j; ++k) {
            diag -= lower[j][k] * lower[j][k];
        }
        if (!(diag > ICOAC_R(0.0))) {
            return 0;
        }
        lower[j][j] = ICOAC_PRIV_SQRT(diag);
        for (i = j + 1; i < n; ++i) {
            icoac_real_t sum = m[i][j];
            for (k = 0; k < j; ++k) {
                sum -= lower[i][k] * lower[j][k];
            }
            lower[i][j] = sum / lower[j][j];
        }
    }
    return 1;
}

/* m = m^-1 from its Cholesky factor, which m holds in its lower triangle; returns 1. Out of
 * line: its frame and the factorization's come one after the other. */
ICOAC_PRIV_NOINLINE static int inverse_from_factor(icoac_real_t m[N][N], int n)
{
    icoac_real_t column[N];
    icoac_real_t diagonal[N]; /* of the inverse: m's holds the factor's until the last column */
    int i;
    int j;
    int k;
    /* the inverse's upper triangle is written above the factor */
    for (k = 0; k < n; ++k) {
        /* L y = e_k, then L^T x = y: x is column k of the inverse */
        for (i = 0; i < n; ++i) {
            icoac_real_t sum = (i == k) ? ICOAC_R(1.0) : ICOAC_R(0.0);
            for (j = 0; j < i; ++j) {
                sum -= m[i][j] * column[j];
            }
            column[i] = sum / m[i][i];
        }
        for (i = n - 1; i >= 0; --i) {
            icoac_real_t sum = column[i];
            for (j = i + 1; j < n; ++j) {
                sum -= m[j][i] * column[j];
            }
            column[i] = sum / m[i][i];
        }
        for (i = 0; i < k; ++i) {
            m[i][k] = column[i];
        }
        /* cppcheck-suppress uninitvar ; both passes above set column[0 .. n-1], and k < n */
        diagonal[k] = column[k];
    }
    /* exactly symmetric */
    for (i = 0; i < n; ++i) {
        m[i][i] = diagonal[i];
        for (j = i + 1; j < n; ++j) {
            m[j][i] = m[i][j];
        }
    }
    return 1;
}

int icoac_priv_spd_inverse(icoac_real_t m[N][N], int n)
{
    return icoac_priv_cholesky(ICOAC_PRIV_CONST_MAT(m), m, n) && inverse_from_factor(m, n);
}

void icoac_priv_sample_lower(icoac_rng_t *rng, const icoac_real_t mean[N], const icoac_real_t lower[N][N],
                             icoac_real_t sample[N], int n)
{
    icoac_real_t normal[N];
    int i;
    int j;
    for (i = 0; i < n; ++i) {
        normal[i] = icoac_rng_normal(rng);
    }
    for (i = 0; i < N; ++i) {
        icoac_real_t sum = mean[i];
        for (j = 0; j <= i && j < n; ++j) {
            sum += lower[i][j] * normal[j];
        }
        sample[i] = i < n ? sum : ICOAC_R(0.0);
    }
}
