/* Normalized Gaussian critic on a grid of critic.units[i] units along each input i (method.md,
 * critic), evaluated separably: a_k = prod_i f_i(k_i) and sum_k a_k = prod_i sum_j f_i(j), so the
 * normalized activation is b_k = prod_i g_i(k_i) with per-input normalized factors g.
 * Units with b_k below critic->threshold count as 0 (method.md, A10). This file: the grid's
 * geometry, the factors and the sparse kernel (the dense one is icoac_critic_dense.c); its value
 * pass lists the units it kept, and the TD update of the next tick walks that list.
 * Layout: k = row * cells + cell, row-major over the row inputs [0, split) and the cell inputs
 * [split, n) (the cart-pole: rows over (x, x_dot), cells over (theta, theta_dot)); b_k is
 * evaluated as (row product) * (cell product), each a left-to-right product of its factors.
 * All factors are <= 1, so a row or cell product below the threshold rules out every unit it
 * belongs to. The surviving cells are sorted by product, largest first; the kept units of a row
 * are then a leading run of that order, and V sums over them in that order. */
#include "icoac_priv.h"

#include <float.h>

int icoac_priv_critic_split(const int32_t *units, int n)
{
    int cells = 1;
    int rows = 1;
    int m = n;
    int i;
    for (i = 0; i < n; ++i) {
        if (units[i] < 1 || units[i] > ICOAC_CRITIC_UNITS_PER_INPUT_MAX) {
            return 0;
        }
    }
    while (m > 0 && cells * units[m - 1] <= ICOAC_CRITIC_BLOCK_MAX) {
        cells *= units[m - 1];
        --m;
    }
    for (i = 0; i < m; ++i) {
        rows *= units[i];
        if (rows > ICOAC_CRITIC_BLOCK_MAX) {
            return 0;
        }
    }
    return m + 1;
}

void icoac_priv_critic_grid(const icoac_config_t *cfg, icoac_priv_grid_t *grid)
{
    const int n = icoac_priv_inputs(cfg);
    const int split = icoac_priv_critic_split(cfg->critic.units, n) - 1;
    int i;
    memset(grid, 0, sizeof *grid);
    if (cfg->mode != ICOAC_MODE_RL) {
        return; /* no critic: its group is not checked, nothing derived from it */
    }
    grid->n = (uint8_t)n;
    grid->split = (uint8_t)(split > 0 ? split : 0);
    for (i = 0; i < n; ++i) {
        grid->units[i] = (uint8_t)cfg->critic.units[i];
    }
}

/* Normalized 1-D Gaussian factors of one input. With centres c_j = -R + (2j+1)R/n and
 * width sigma = R/n, (s - c_j)/sigma = d_j = o - 2j with o = s*n/R + n - 1. Relative to the
 * nearest centre j* (distance d), a_{j*+1}/a_{j*} = exp(2d - 2) =: up, a_{j*-1}/a_{j*} =
 * exp(-2d - 2) = e^-4 / up, and each further step out multiplies the ratio by e^-4: one
 * exponential per dimension instead of n. a_{j*} = 1, so far-away states never give 0/0. */
static inline void factors_of(icoac_real_t value, icoac_real_t range, int n, icoac_real_t *g)
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

/* The common counts get loops of a constant length (unrolled), the others the general ones. */
void icoac_priv_critic_factors(icoac_real_t value, icoac_real_t range, int n, icoac_real_t *g)
{
    switch (n) {
    case 2: factors_of(value, range, 2, g); break;
    case 3: factors_of(value, range, 3, g); break;
    case 6: factors_of(value, range, 6, g); break;
    default: factors_of(value, range, n, g); break;
    }
}

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

/* A unit count from the state's geometry, bounded to the factor array. */
static inline int bounded_units(uint8_t units)
{
    return units <= ICOAC_CRITIC_UNITS_PER_INPUT_MAX ? (int)units : ICOAC_CRITIC_UNITS_PER_INPUT_MAX;
}

/* The kept cells' products and indices, sorted by product (largest first, ties in cell order),
 * then a 0 sentinel; the list's stride and rows; the row products in row_product. */
static int sorted_cells(const icoac_critic_config_t *critic, const icoac_priv_grid_t *grid,
                        const icoac_real_t s[ICOAC_MAX_INPUTS], icoac_real_t threshold,
                        icoac_priv_critic_list_t *list)
{
    icoac_real_t g[ICOAC_CRITIC_UNITS_PER_INPUT_MAX];
    const int n = grid->n <= ICOAC_MAX_INPUTS ? (int)grid->n : ICOAC_MAX_INPUTS;
    const int split = grid->split < n ? (int)grid->split : n;
    int rows = 1;
    int stride = 1;
    int entries = 1;
    int cells = 0;
    int i;
    int k;
    list->row_product[0] = ICOAC_R(1.0);
    for (i = 0; i < split; ++i) {
        const int count = bounded_units(grid->units[i]);
        icoac_priv_critic_factors(s[i], critic->range[i], count, g);
        rows = icoac_priv_critic_expand(list->row_product, 0, g, count, 0, count, rows);
    }
    list->cell_product[0] = ICOAC_R(1.0);
    list->cell[0] = 0u;
    for (i = split; i < n; ++i) {
        const int count = bounded_units(grid->units[i]);
        int begin;
        int end;
        icoac_priv_critic_factors(s[i], critic->range[i], count, g);
        kept_range(g, count, threshold, &begin, &end);
        entries = icoac_priv_critic_expand(list->cell_product, list->cell, g, count, begin, end, entries);
        stride *= count;
    }
    /* a geometry the configuration check would refuse (a corrupted state) keeps no unit */
    if (stride > ICOAC_PRIV_CELL_MASK || rows * stride > ICOAC_MAX_CRITIC_UNITS) {
        rows = 0;
        entries = 0;
    }
    for (k = 0; k < entries; ++k) {
        const icoac_real_t product = list->cell_product[k];
        const uint8_t cell = list->cell[k];
        int j = cells;
        if (!icoac_priv_nonneg_at_least(product, threshold)) {
            continue;
        }
        while (j > 0 && !icoac_priv_nonneg_at_least(list->cell_product[j - 1], product)) {
            list->cell_product[j] = list->cell_product[j - 1];
            list->cell[j] = list->cell[j - 1];
            --j;
        }
        list->cell_product[j] = product;
        list->cell[j] = cell;
        ++cells;
    }
    /* sentinel: at most 31 cells are listed; with a row product in [threshold, 1] it ends every
     * scan of the list (threshold >= the smallest normal) */
    list->cell_product[cells] = ICOAC_R(0.0);
    list->rows = (uint8_t)rows;
    list->stride = (uint8_t)stride;
    return cells;
}

icoac_real_t icoac_priv_critic_value_sparse(const icoac_critic_config_t *critic, const icoac_priv_grid_t *grid,
                                            const icoac_real_t *v, const icoac_real_t s[ICOAC_MAX_INPUTS],
                                            icoac_priv_critic_list_t *list)
{
    const icoac_real_t threshold = icoac_priv_critic_floor(critic);
    const int cells = sorted_cells(critic, grid, s, threshold, list);
    const int rows = list->rows;
    const int stride = list->stride;
    icoac_real_t value = ICOAC_R(0.0);
    int r;
    for (r = 0; r < rows; ++r) {
        const icoac_real_t row_product = list->row_product[r];
        const icoac_real_t *u = v + r * stride;
        const icoac_real_t *product = list->cell_product;
        const uint8_t *cell = list->cell;
        icoac_real_t unit_b;
        list->row_cells[r] = 0u;
        /* threshold <= row_product <= 1 as bit patterns: false for NaN, Inf and negative
         * values, so row_product * 0 = 0 and the sentinel ends the scan below */
        if (!icoac_priv_nonneg_at_least(row_product, threshold) ||
            !icoac_priv_nonneg_at_least(ICOAC_R(1.0), row_product)) {
            continue;
        }
        unit_b = row_product * *product;
        while (icoac_priv_nonneg_at_least(unit_b, threshold)) {
            value += u[*cell++] * unit_b;
            unit_b = row_product * *++product;
        }
        list->row_cells[r] = (uint8_t)(cell - list->cell);
    }
    list->cells = (uint8_t)cells;
    return value;
}

/* v_k += step * b_k over the units listed by icoac_priv_critic_value_sparse. The list lives in
 * the state between ticks, so what it holds is bounded here: rows and stride must describe a
 * grid of at most ICOAC_MAX_CRITIC_UNITS units (else nothing is updated), and a count or a cell
 * index is masked (the list's arrays and the weights have room for a masked value:
 * icoac_state.h). A list the value pass wrote passes unchanged. */
void icoac_priv_critic_update_sparse(icoac_real_t *v, const icoac_priv_critic_list_t *list, icoac_real_t step)
{
    const int rows = list->rows;
    const int stride = list->stride;
    int r;
    if (rows > ICOAC_PRIV_BLOCK || stride > ICOAC_PRIV_CELL_MASK || rows * stride > ICOAC_MAX_CRITIC_UNITS) {
        return;
    }
    for (r = 0; r < rows; ++r) {
        const icoac_real_t row_step = step * list->row_product[r];
        const uint8_t *cell = list->cell;
        const uint8_t *const end = cell + (list->row_cells[r] & ICOAC_PRIV_CELL_MASK);
        const icoac_real_t *product = list->cell_product;
        icoac_real_t *u = v + r * stride;
        ICOAC_PRIV_OPAQUE(u);
        while (cell != end) {
            u[*cell++ & ICOAC_PRIV_CELL_MASK] += row_step * *product++;
        }
    }
}
