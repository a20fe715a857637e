/* Normalized Gaussian critic on the 3x3x6x3 grid (spec 6), evaluated separably:
 * a_k = prod_i f_i(k_i) and sum_k a_k = prod_i sum_j f_i(j), so the normalized
 * activation is b_k = prod_i g_i(k_i) with per-dimension normalized factors g. */
#include "icoac_internal.h"

/* Normalized 1-D Gaussian factors of one coordinate. With centres c_j = -R + (2j+1)R/n and
 * width sigma = R/n, (s - c_j)/sigma = s*n/R + n - 1 - 2j. The smallest squared distance is
 * subtracted before exp, so far-away states never underflow to 0/0. */
static inline void dimension_factors(icoac_real_t value, icoac_real_t range, int n, icoac_real_t *g)
{
    const icoac_real_t offset = value * ((icoac_real_t)n / range) + (icoac_real_t)(n - 1);
    icoac_real_t dist[ICOAC_CRITIC_N_THETA];
    icoac_real_t nearest;
    icoac_real_t total = ICOAC_R(0.0);
    icoac_real_t inv_total;
    int j;
    for (j = 0; j < n; ++j) {
        const icoac_real_t d = offset - (icoac_real_t)(2 * j);
        dist[j] = d * d;
    }
    nearest = dist[0];
    for (j = 1; j < n; ++j) {
        nearest = dist[j] < nearest ? dist[j] : nearest;
    }
    for (j = 0; j < n; ++j) {
        g[j] = icoac_exp(ICOAC_R(-0.5) * (dist[j] - nearest));
        total += g[j];
    }
    inv_total = ICOAC_R(1.0) / total;
    for (j = 0; j < n; ++j) {
        g[j] *= inv_total;
    }
}

void icoac_critic_factors(const icoac_config_t *cfg, const icoac_real_t s[ICOAC_N_INPUTS],
                          icoac_real_t factors[ICOAC_CRITIC_FACTORS])
{
    dimension_factors(s[ICOAC_IDX_X], cfg->critic_range[ICOAC_IDX_X], ICOAC_CRITIC_N_X, factors);
    factors += ICOAC_CRITIC_N_X;
    dimension_factors(s[ICOAC_IDX_X_DOT], cfg->critic_range[ICOAC_IDX_X_DOT], ICOAC_CRITIC_N_X_DOT, factors);
    factors += ICOAC_CRITIC_N_X_DOT;
    dimension_factors(s[ICOAC_IDX_THETA], cfg->critic_range[ICOAC_IDX_THETA], ICOAC_CRITIC_N_THETA, factors);
    factors += ICOAC_CRITIC_N_THETA;
    dimension_factors(s[ICOAC_IDX_THETA_DOT], cfg->critic_range[ICOAC_IDX_THETA_DOT],
                      ICOAC_CRITIC_N_THETA_DOT, factors);
}

/* Slow path with the activity threshold: visits every unit with b_k >= threshold. */
#define ICOAC_FOR_EACH_UNIT(factors, threshold, BODY)                                            \
    do {                                                                                         \
        const icoac_real_t *gx_ = (factors);                                                     \
        const icoac_real_t *gxd_ = gx_ + ICOAC_CRITIC_N_X;                                       \
        const icoac_real_t *gth_ = gxd_ + ICOAC_CRITIC_N_X_DOT;                                  \
        const icoac_real_t *gthd_ = gth_ + ICOAC_CRITIC_N_THETA;                                 \
        int a_, b_, c_, d_, k_ = 0;                                                              \
        for (a_ = 0; a_ < ICOAC_CRITIC_N_X; ++a_) {                                              \
            for (b_ = 0; b_ < ICOAC_CRITIC_N_X_DOT; ++b_) {                                      \
                for (c_ = 0; c_ < ICOAC_CRITIC_N_THETA; ++c_) {                                  \
                    for (d_ = 0; d_ < ICOAC_CRITIC_N_THETA_DOT; ++d_, ++k_) {                    \
                        const icoac_real_t unit_b = gx_[a_] * gxd_[b_] * gth_[c_] * gthd_[d_];   \
                        const int unit_k = k_;                                                   \
                        if (unit_b >= (threshold)) {                                             \
                            BODY;                                                                \
                        }                                                                        \
                    }                                                                            \
                }                                                                                \
            }                                                                                    \
        }                                                                                        \
    } while (0)

/* Units are stored with theta_dot fastest: k = ((a*3 + b)*6 + c)*3 + d. The fast paths
 * walk the 54 (a, b, c) prefixes and handle the 3 theta_dot units of each inline. */
#define ICOAC_PREFIXES (ICOAC_CRITIC_N_X * ICOAC_CRITIC_N_X_DOT * ICOAC_CRITIC_N_THETA)
ICOAC_STATIC_ASSERT(ICOAC_CRITIC_N_THETA_DOT == 3, fast_path_expects_three_theta_dot_units);

icoac_real_t icoac_critic_value(const icoac_config_t *cfg, const icoac_real_t v[ICOAC_CRITIC_UNITS],
                                const icoac_real_t factors[ICOAC_CRITIC_FACTORS])
{
    const icoac_real_t *gx = factors;
    const icoac_real_t *gxd = gx + ICOAC_CRITIC_N_X;
    const icoac_real_t *gth = gxd + ICOAC_CRITIC_N_X_DOT;
    const icoac_real_t *gthd = gth + ICOAC_CRITIC_N_THETA;
    icoac_real_t value = ICOAC_R(0.0);
    int a;
    int b;
    int c;
    if (cfg->critic_threshold > ICOAC_R(0.0)) {
        ICOAC_FOR_EACH_UNIT(factors, cfg->critic_threshold, value += v[unit_k] * unit_b);
        return value;
    }
    for (a = 0; a < ICOAC_CRITIC_N_X; ++a) {
        for (b = 0; b < ICOAC_CRITIC_N_X_DOT; ++b) {
            const icoac_real_t pab = gx[a] * gxd[b];
            for (c = 0; c < ICOAC_CRITIC_N_THETA; ++c) {
                const icoac_real_t *u = v + ((a * ICOAC_CRITIC_N_X_DOT + b) * ICOAC_CRITIC_N_THETA + c) *
                                                ICOAC_CRITIC_N_THETA_DOT;
                value += (pab * gth[c]) * ((u[0] * gthd[0] + u[1] * gthd[1]) + u[2] * gthd[2]);
            }
        }
    }
    return value;
}

void icoac_critic_update(const icoac_config_t *cfg, icoac_real_t v[ICOAC_CRITIC_UNITS],
                         const icoac_real_t factors[ICOAC_CRITIC_FACTORS], icoac_real_t step)
{
    const icoac_real_t *gx = factors;
    const icoac_real_t *gxd = gx + ICOAC_CRITIC_N_X;
    const icoac_real_t *gth = gxd + ICOAC_CRITIC_N_X_DOT;
    const icoac_real_t *gthd = gth + ICOAC_CRITIC_N_THETA;
    int a;
    int b;
    int c;
    if (cfg->critic_threshold > ICOAC_R(0.0)) {
        ICOAC_FOR_EACH_UNIT(factors, cfg->critic_threshold, v[unit_k] += step * unit_b);
        return;
    }
    for (a = 0; a < ICOAC_CRITIC_N_X; ++a) {
        for (b = 0; b < ICOAC_CRITIC_N_X_DOT; ++b) {
            const icoac_real_t pab = step * gx[a] * gxd[b];
            for (c = 0; c < ICOAC_CRITIC_N_THETA; ++c) {
                const icoac_real_t pabc = pab * gth[c];
                icoac_real_t *u = v + ((a * ICOAC_CRITIC_N_X_DOT + b) * ICOAC_CRITIC_N_THETA + c) *
                                          ICOAC_CRITIC_N_THETA_DOT;
                u[0] += pabc * gthd[0];
                u[1] += pabc * gthd[1];
                u[2] += pabc * gthd[2];
            }
        }
    }
}
