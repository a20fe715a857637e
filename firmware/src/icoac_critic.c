/* Normalized Gaussian critic on the 3x3x6x3 grid (method.md, critic), evaluated separably:
 * a_k = prod_i f_i(k_i) and sum_k a_k = prod_i sum_j f_i(j), so the normalized
 * activation is b_k = prod_i g_i(k_i) with per-dimension normalized factors g.
 * Units with b_k below critic->threshold count as 0 (method.md, A10). This file: the factors and the
 * sparse kernel (the dense one is icoac_critic_dense.c); its value pass lists the units it
 * kept, and the TD update of the next tick walks that list.
 * Layout: k = pair * 18 + cell with pair = a*3 + b over (x, x_dot) and cell = c*3 + d over
 * (theta, theta_dot); b_k is evaluated as (g_x[a] g_xd[b]) * (g_th[c] g_thd[d]).
 * All factors are <= 1, so a pair or cell product below the threshold rules out every unit it
 * belongs to. The surviving cells are sorted by product, largest first; the kept units of a
 * pair are then a leading run of that order, and V sums over them in that order. */
#include "icoac_priv.h"

#include <float.h>

/* Normalized 1-D Gaussian factors of one coordinate. With centres c_j = -R + (2j+1)R/n and
 * width sigma = R/n, (s - c_j)/sigma = d_j = o - 2j with o = s*n/R + n - 1. Relative to the
 * nearest centre j* (distance d), a_{j*+1}/a_{j*} = exp(2d - 2) =: up, a_{j*-1}/a_{j*} =
 * exp(-2d - 2) = e^-4 / up, and each further step out multiplies the ratio by e^-4: one
 * exponential per dimension instead of n. a_{j*} = 1, so far-away states never give 0/0. */
static inline void dimension_factors(icoac_real_t value, icoac_real_t range, int n, icoac_real_t *g)
{
    const icoac_real_t exp_minus_4 = ICOAC_R(0.018315638888734180294);
    const icoac_real_t offset = value * ((icoac_real_t)n / range) + (icoac_real_t)(n - 1);
    icoac_real_t up = ICOAC_R(0.0);
    icoac_real_t down = ICOAC_R(0.0);
    icoac_real_t ratio;
    icoac_real_t distance;
    icoac_real_t total = ICOAC_R(0.0);
    icoac_real_t inv_total;
    int nearest;
    int j;
    if (!(offset > ICOAC_R(0.0))) {
        nearest = 0;
    } else if (offset >= (icoac_real_t)(2 * (n - 1))) {
        nearest = n - 1;
    } else {
        nearest = (int)(offset * ICOAC_R(0.5) + ICOAC_R(0.5));
    }
    distance = offset - (icoac_real_t)(2 * nearest);
    if (nearest < n - 1) {
        up = icoac_priv_exp(ICOAC_R(2.0) * distance - ICOAC_R(2.0));
    }
    if (nearest > 0) {
        /* inside the grid |distance| <= 1, so up >= e^-4 and down = e^-4 / up <= 1 */
        down = nearest < n - 1 ? exp_minus_4 / up : icoac_priv_exp(ICOAC_R(-2.0) * distance - ICOAC_R(2.0));
    }
    /* Both chains run over the whole array and select, so no branch depends on nearest. */
    for (j = 0; j < n; ++j) {
        g[j] = ICOAC_R(1.0);
    }
    ratio = up;
    for (j = 1; j < n; ++j) {
        const int above = j > nearest;
        const icoac_real_t next = g[j - 1] * ratio;
        g[j] = above ? next : g[j];
        ratio = above ? ratio * exp_minus_4 : ratio;
    }
    ratio = down;
    for (j = n - 2; j >= 0; --j) {
        const int below = j < nearest;
        const icoac_real_t next = g[j + 1] * ratio;
        g[j] = below ? next : g[j];
        ratio = below ? ratio * exp_minus_4 : ratio;
    }
    for (j = 0; j < n; ++j) {
        total += g[j];
    }
    inv_total = ICOAC_R(1.0) / total;
    for (j = 0; j < n; ++j) {
        g[j] *= inv_total;
    }
}

void icoac_priv_critic_factors(const icoac_critic_config_t *critic, const icoac_real_t s[ICOAC_N_INPUTS],
                               icoac_real_t factors[ICOAC_CRITIC_FACTORS])
{
    dimension_factors(s[ICOAC_IDX_X], critic->range[ICOAC_IDX_X], ICOAC_CRITIC_N_X, factors);
    factors += ICOAC_CRITIC_N_X;
    dimension_factors(s[ICOAC_IDX_X_DOT], critic->range[ICOAC_IDX_X_DOT], ICOAC_CRITIC_N_X_DOT, factors);
    factors += ICOAC_CRITIC_N_X_DOT;
    dimension_factors(s[ICOAC_IDX_THETA], critic->range[ICOAC_IDX_THETA], ICOAC_CRITIC_N_THETA, factors);
    factors += ICOAC_CRITIC_N_THETA;
    dimension_factors(s[ICOAC_IDX_THETA_DOT], critic->range[ICOAC_IDX_THETA_DOT],
                      ICOAC_CRITIC_N_THETA_DOT, factors);
}

#define ICOAC_CELLS ICOAC_CRITIC_CELLS

/* With threshold 0 the floor is the smallest normal number: b_k below it is 0 under
 * flush-to-zero and adds nothing to V either way. */
icoac_real_t icoac_priv_critic_floor(const icoac_critic_config_t *critic)
{
#if defined(ICOAC_REAL_DOUBLE) && ICOAC_REAL_DOUBLE
    const icoac_real_t smallest_normal = DBL_MIN;
#else
    const icoac_real_t smallest_normal = FLT_MIN;
#endif
    return critic->threshold > smallest_normal ? critic->threshold : smallest_normal;
}

/* First and one-past-last index of the factors >= threshold (factors are unimodal). */
static inline void kept_range(const icoac_real_t *g, int n, icoac_real_t threshold, int *begin, int *end)
{
    int j = 0;
    while (j < n && !icoac_priv_nonneg_at_least(g[j], threshold)) {
        ++j;
    }
    *begin = j;
    while (j < n && icoac_priv_nonneg_at_least(g[j], threshold)) {
        ++j;
    }
    *end = j;
}

/* Cells with g_th g_thd >= threshold, sorted by product (largest first, ties in cell order). */
static int sorted_cells(const icoac_real_t *gth, const icoac_real_t *gthd, icoac_real_t threshold,
                        icoac_priv_critic_list_t *active)
{
    int cells = 0;
    int c_begin, c_end, d_begin, d_end;
    int c;
    int d;
    kept_range(gth, ICOAC_CRITIC_N_THETA, threshold, &c_begin, &c_end);
    kept_range(gthd, ICOAC_CRITIC_N_THETA_DOT, threshold, &d_begin, &d_end);
    for (c = c_begin; c < c_end; ++c) {
        for (d = d_begin; d < d_end; ++d) {
            const icoac_real_t product = gth[c] * gthd[d];
            int i = cells;
            if (!icoac_priv_nonneg_at_least(product, threshold)) {
                continue;
            }
            while (i > 0 && !icoac_priv_nonneg_at_least(active->cell_product[i - 1], product)) {
                active->cell_product[i] = active->cell_product[i - 1];
                active->cell[i] = active->cell[i - 1];
                --i;
            }
            active->cell_product[i] = product;
            active->cell[i] = (uint8_t)(c * ICOAC_CRITIC_N_THETA_DOT + d);
            ++cells;
        }
    }
    /* sentinel: at most 6 x 3 cells pass, so it always fits; with a pair product in
     * [threshold, 1] it ends every scan of the list (threshold >= the smallest normal) */
    active->cell_product[cells] = ICOAC_R(0.0);
    return cells;
}

icoac_real_t icoac_priv_critic_value_sparse(const icoac_critic_config_t *critic,
                                            const icoac_real_t v[ICOAC_CRITIC_UNITS],
                                            const icoac_real_t factors[ICOAC_CRITIC_FACTORS],
                                            icoac_priv_critic_list_t *active)
{
    const icoac_real_t threshold = icoac_priv_critic_floor(critic);
    const icoac_real_t *gx = factors;
    const icoac_real_t *gxd = gx + ICOAC_CRITIC_N_X;
    const icoac_real_t *gth = gxd + ICOAC_CRITIC_N_X_DOT;
    const icoac_real_t *gthd = gth + ICOAC_CRITIC_N_THETA;
    const int cells = sorted_cells(gth, gthd, threshold, active);
    icoac_real_t value = ICOAC_R(0.0);
    int a;
    int b;
    for (a = 0; a < ICOAC_CRITIC_N_X; ++a) {
        for (b = 0; b < ICOAC_CRITIC_N_X_DOT; ++b) {
            const icoac_real_t pair_product = gx[a] * gxd[b];
            const int pair = a * ICOAC_CRITIC_N_X_DOT + b;
            const icoac_real_t *u = v + pair * ICOAC_CELLS;
            const icoac_real_t *product = active->cell_product;
            const uint8_t *cell = active->cell;
            icoac_real_t unit_b;
            active->pair_product[pair] = pair_product;
            active->pair_cells[pair] = 0u;
            /* threshold <= pair_product <= 1 as bit patterns: false for NaN, Inf and negative
             * values, so pair_product * 0 = 0 and the sentinel ends the scan below */
            if (!icoac_priv_nonneg_at_least(pair_product, threshold) ||
                !icoac_priv_nonneg_at_least(ICOAC_R(1.0), pair_product)) {
                continue;
            }
            unit_b = pair_product * *product;
            while (icoac_priv_nonneg_at_least(unit_b, threshold)) {
                value += u[*cell++] * unit_b;
                unit_b = pair_product * *++product;
            }
            active->pair_cells[pair] = (uint8_t)(cell - active->cell);
        }
    }
    active->cells = (uint8_t)cells;
    return value;
}

/* v_k += step * b_k over the units listed by icoac_priv_critic_value_sparse. The list lives in
 * the state between ticks, so what it holds is bounded here without a test: the pairs are the
 * loop's, and a count or a cell index is masked (the list's arrays and the weights have room for
 * a masked value: icoac_state.h). A list the value pass wrote is unchanged by the masks. */
void icoac_priv_critic_update_sparse(icoac_real_t v[ICOAC_CRITIC_UNITS], const icoac_priv_critic_list_t *active,
                                     icoac_real_t step)
{
    int p;
    for (p = 0; p < ICOAC_CRITIC_PAIRS; ++p) {
        const icoac_real_t pair_step = step * active->pair_product[p];
        const uint8_t *cell = active->cell;
        const uint8_t *const end = cell + (active->pair_cells[p] & ICOAC_PRIV_CELL_MASK);
        const icoac_real_t *product = active->cell_product;
        icoac_real_t *u = v + p * ICOAC_CELLS;
        ICOAC_PRIV_OPAQUE(u);
        while (cell != end) {
            u[*cell++ & ICOAC_PRIV_CELL_MASK] += pair_step * *product++;
        }
    }
}
