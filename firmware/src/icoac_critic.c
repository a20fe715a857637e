/* Normalized Gaussian critic on the 3x3x6x3 grid (spec 6), evaluated separably:
 * a_k = prod_i f_i(k_i) and sum_k a_k = prod_i sum_j f_i(j), so the normalized
 * activation is b_k = prod_i g_i(k_i) with per-dimension normalized factors g. */
#include "icoac_internal.h"

static const int grid_size[ICOAC_N_INPUTS] = {
    ICOAC_CRITIC_N_X, ICOAC_CRITIC_N_X_DOT, ICOAC_CRITIC_N_THETA, ICOAC_CRITIC_N_THETA_DOT};

/* Normalized 1-D Gaussian factors of one coordinate; the smallest exponent is shifted
 * to 0 before exp, so far-away states never underflow to 0/0. */
static void dimension_factors(icoac_real_t value, icoac_real_t range, int n, icoac_real_t *g)
{
    const icoac_real_t width = range / (icoac_real_t)n; /* sigma = centre spacing / 2 */
    icoac_real_t dist[ICOAC_CRITIC_N_THETA];
    icoac_real_t nearest;
    icoac_real_t total = ICOAC_R(0.0);
    int j;
    for (j = 0; j < n; ++j) {
        const icoac_real_t centre = -range + (icoac_real_t)(2 * j + 1) * width;
        const icoac_real_t d = (value - centre) / width;
        dist[j] = d * d;
    }
    nearest = dist[0];
    for (j = 1; j < n; ++j) {
        nearest = dist[j] < nearest ? dist[j] : nearest;
    }
    for (j = 0; j < n; ++j) {
        g[j] = ICOAC_EXP(ICOAC_R(-0.5) * (dist[j] - nearest));
        total += g[j];
    }
    for (j = 0; j < n; ++j) {
        g[j] /= total;
    }
}

void icoac_critic_factors(const icoac_config_t *cfg, const icoac_real_t s[ICOAC_N_INPUTS],
                          icoac_real_t factors[ICOAC_CRITIC_FACTORS])
{
    int offset = 0;
    int i;
    for (i = 0; i < ICOAC_N_INPUTS; ++i) {
        dimension_factors(s[i], cfg->critic_range[i], grid_size[i], factors + offset);
        offset += grid_size[i];
    }
}

/* Calls visit(k, b_k) over all units in index order k = ((a*3 + b)*6 + c)*3 + d. */
#define ICOAC_FOR_EACH_UNIT(factors, threshold, BODY)                                            \
    do {                                                                                         \
        const icoac_real_t *gx_ = (factors);                                                     \
        const icoac_real_t *gxd_ = gx_ + ICOAC_CRITIC_N_X;                                       \
        const icoac_real_t *gth_ = gxd_ + ICOAC_CRITIC_N_X_DOT;                                  \
        const icoac_real_t *gthd_ = gth_ + ICOAC_CRITIC_N_THETA;                                 \
        int a_, b_, c_, d_, k_ = 0;                                                              \
        for (a_ = 0; a_ < ICOAC_CRITIC_N_X; ++a_) {                                              \
            for (b_ = 0; b_ < ICOAC_CRITIC_N_X_DOT; ++b_) {                                      \
                const icoac_real_t pab_ = gx_[a_] * gxd_[b_];                                    \
                for (c_ = 0; c_ < ICOAC_CRITIC_N_THETA; ++c_) {                                  \
                    const icoac_real_t pabc_ = pab_ * gth_[c_];                                  \
                    for (d_ = 0; d_ < ICOAC_CRITIC_N_THETA_DOT; ++d_, ++k_) {                    \
                        const icoac_real_t unit_b = pabc_ * gthd_[d_];                           \
                        const int unit_k = k_;                                                   \
                        if (unit_b >= (threshold)) {                                             \
                            BODY;                                                                \
                        }                                                                        \
                    }                                                                            \
                }                                                                                \
            }                                                                                    \
        }                                                                                        \
    } while (0)

icoac_real_t icoac_critic_value(const icoac_config_t *cfg, const icoac_real_t v[ICOAC_CRITIC_UNITS],
                                const icoac_real_t factors[ICOAC_CRITIC_FACTORS])
{
    icoac_real_t value = ICOAC_R(0.0);
    ICOAC_FOR_EACH_UNIT(factors, cfg->critic_threshold, value += v[unit_k] * unit_b);
    return value;
}

void icoac_critic_update(const icoac_config_t *cfg, icoac_real_t v[ICOAC_CRITIC_UNITS],
                         const icoac_real_t factors[ICOAC_CRITIC_FACTORS], icoac_real_t step)
{
    ICOAC_FOR_EACH_UNIT(factors, cfg->critic_threshold, v[unit_k] += step * unit_b);
}
