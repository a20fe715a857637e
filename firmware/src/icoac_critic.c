/* SPDX-License-Identifier: Apache-2.0 */
/* Normalized Gaussian critic on a grid of critic.units[i] units along each input i (method.md,
 * critic), evaluated separably: a_k = prod_i f_i(k_i) and sum_k a_k = prod_i sum_j f_i(j), so the
 * normalized activation is b_k = prod_i g_i(k_i) with per-input normalized factors g.
 * Units with b_k below critic->threshold count as 0 (method.md, A10). This file: the grid's
 * geometry and the sparse kernel (the factors are icoac_priv.h's, the dense kernel is
 * icoac_critic_dense.c); its value pass lists the units it kept, and the TD update of the next
 * tick walks that list.
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
    static const int32_t cartpole_units[ICOAC_CARTPOLE_INPUTS] = ICOAC_PRIV_CARTPOLE_UNITS;
    const int n = icoac_priv_inputs(cfg);
    const int split = icoac_priv_critic_split(cfg->critic.units, n) - 1;
    int cartpole_grid = n == ICOAC_CARTPOLE_INPUTS;
    int i;
    (void)memset(grid, 0, sizeof *grid);
    if (cfg->mode != ICOAC_MODE_RL) {
        return; /* no critic: its group is not checked, nothing derived from it */
    }
    grid->n = (uint8_t)n;
    grid->split = (uint8_t)(split > 0 ? split : 0);
    for (i = 0; cartpole_grid && i < ICOAC_CARTPOLE_INPUTS; ++i) {
        cartpole_grid = cfg->critic.units[i] == cartpole_units[i];
    }
    if (cartpole_grid != 0) {
        grid->shape |= ICOAC_PRIV_SHAPE_CARTPOLE_CRITIC;
    }
}

int icoac_priv_critic_shape(const icoac_critic_config_t *critic, const icoac_priv_grid_t *grid,
                            icoac_priv_shape_t *shape)
{
    const int n = ((int)grid->n <= ICOAC_MAX_INPUTS) ? (int)grid->n : ICOAC_MAX_INPUTS;
    const int split = grid->split;
    int rows = 1;
    int cells = 1;
    int i;
    if (split >= n) {
        return 0;
    }
    for (i = 0; i < n; ++i) {
        const int32_t count = critic->units[i];
        if (count < 1 || count > ICOAC_CRITIC_UNITS_PER_INPUT_MAX) {
            return 0;
        }
        shape->units[i] = (int)count;
        if (i < split) {
            rows *= (int)count;
        } else {
            cells *= (int)count;
        }
        if (rows > ICOAC_CRITIC_BLOCK_MAX || cells > ICOAC_CRITIC_BLOCK_MAX) {
            return 0;
        }
    }
    if (rows * cells > ICOAC_MAX_CRITIC_UNITS) {
        return 0;
    }
    shape->n = n;
    shape->split = split;
    shape->rows = rows;
    shape->cells = cells;
    return 1;
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

/* The sparse kernel (see the file's head) for the grid of n inputs with these units, split and
 * rows x stride: fills the list and returns V(s). The caller has checked the shape (rows and
 * stride <= ICOAC_CRITIC_BLOCK_MAX, rows * stride <= ICOAC_MAX_CRITIC_UNITS), so every product,
 * the sentinel and every weight read stay inside their arrays. */
static inline icoac_real_t sparse_value(const icoac_critic_config_t *critic, const icoac_real_t *v,
                                        const icoac_real_t s[ICOAC_MAX_INPUTS], icoac_priv_critic_list_t *list,
                                        int n_inputs, const int *units, int first_cell, int rows, int stride)
{
    /* the callers' bounds, restated for the compiler: 1 <= n <= ICOAC_MAX_INPUTS, split < n */
    const int n = n_inputs < ICOAC_MAX_INPUTS ? n_inputs : ICOAC_MAX_INPUTS;
    const int split = first_cell < n - 1 ? first_cell : n - 1;
    const icoac_real_t threshold = icoac_priv_critic_floor(critic);
    icoac_real_t g[ICOAC_CRITIC_UNITS_PER_INPUT_MAX];
    icoac_real_t *const row_product = list->product;
    icoac_real_t *const cell_product = list->product + rows;
    uint8_t *const row_cells = list->index;
    uint8_t *const cell_index = list->index + rows;
    icoac_real_t value = ICOAC_R(0.0);
    int entries = 1;
    int cells = 0;
    int prefix_first;
    int i;
    int k;
    int r;
    row_product[0] = ICOAC_R(1.0);
    ICOAC_PRIV_UNROLL
    for (i = 0; i < split; ++i) {
        /* units[i] is set for i < n (icoac_priv_critic_shape, or the cart-pole's constant): the
         * analyzer loses split < n through the shape's copy and calls it uninitialised */
        icoac_priv_factors(s[i], critic->range[i], units[i], NULL, g); /* NOLINT(clang-analyzer-core.CallAndMessage) */
        entries = icoac_priv_critic_expand_all(row_product, g, units[i], entries);
    }
    /* The cell inputs but the last: the products and indices of their kept units, expanded at
     * the end of the cells' room (stride + 1 slots), since their count is at most
     * stride / units[n - 1]. */
    prefix_first = stride + 1 - stride / units[n - 1];
    cell_product[prefix_first] = ICOAC_R(1.0);
    cell_index[prefix_first] = 0u;
    entries = 1;
    ICOAC_PRIV_UNROLL
    for (i = split; i < n - 1; ++i) {
        int begin;
        int end;
        icoac_priv_factors(s[i], critic->range[i], units[i], NULL, g);
        kept_range(g, units[i], threshold, &begin, &end);
        entries = icoac_priv_critic_expand(cell_product + prefix_first, cell_index + prefix_first, g, units[i], begin,
                                           end, entries);
    }
    /* The last input's kept units times each of them: the kept cells, sorted by product (largest
     * first, ties in cell order) into the front of the room. After e entries at most e * units
     * cells are listed, below the entries still to read. */
    {
        const int count = units[n - 1];
        int begin;
        int end;
        int e;
        icoac_priv_factors(s[n - 1], critic->range[n - 1], count, NULL, g);
        kept_range(g, count, threshold, &begin, &end);
        for (e = 0; e < entries; ++e) {
            const icoac_real_t p = cell_product[prefix_first + e];
            const int base = (int)cell_index[prefix_first + e] * count;
            for (k = begin; k < end; ++k) {
                const icoac_real_t product = p * g[k];
                int j = cells;
                if (!icoac_priv_nonneg_at_least(product, threshold)) {
                    continue;
                }
                while (j > 0 && !icoac_priv_nonneg_at_least(cell_product[j - 1], product)) {
                    cell_product[j] = cell_product[j - 1];
                    cell_index[j] = cell_index[j - 1];
                    --j;
                }
                cell_product[j] = product;
                cell_index[j] = (uint8_t)(base + k);
                ++cells;
            }
        }
    }
    /* sentinel: cells <= stride, so it fits; with a row product in [threshold, 1] it ends every
     * scan of the list (threshold >= the smallest normal) */
    cell_product[cells] = ICOAC_R(0.0);
    for (r = 0; r < rows; ++r) {
        const icoac_real_t product_r = row_product[r];
        /* r * stride <= ICOAC_MAX_CRITIC_UNITS (checked by the caller): no int overflow */
        const icoac_real_t *u = v + (r * stride); /* NOLINT(bugprone-implicit-widening-of-multiplication-result) */
        const icoac_real_t *product = cell_product;
        const uint8_t *cell = cell_index;
        icoac_real_t unit_b;
        row_cells[r] = 0u;
        /* threshold <= product_r <= 1 as bit patterns: false for NaN, Inf and negative
         * values, so product_r * 0 = 0 and the sentinel ends the scan below */
        if (!icoac_priv_nonneg_at_least(product_r, threshold) ||
            !icoac_priv_nonneg_at_least(ICOAC_R(1.0), product_r)) {
            continue;
        }
        ICOAC_PRIV_OPAQUE(u); /* the row's weights in a register: one add per unit's address */
        unit_b = product_r * *product;
        while (icoac_priv_nonneg_at_least(unit_b, threshold) != 0) {
            value += u[*cell++] * unit_b;
            unit_b = product_r * *++product;
        }
        row_cells[r] = (uint8_t)(cell - cell_index);
    }
    list->cells = (uint8_t)cells;
    list->rows = (uint8_t)rows;
    list->stride = (uint8_t)stride;
    return value;
}

/* v_k += step * b_k over the units of a list of rows x stride (checked by the caller against
 * the weights). The list lives in the state between ticks, so its counts and cell indices are
 * checked here (nothing is updated past a bad one); a list the value pass wrote passes. */
static inline void sparse_update(icoac_real_t *v, const icoac_priv_critic_list_t *list, icoac_real_t step, int rows,
                                 int stride)
{
    const icoac_real_t *const cell_product = list->product + rows;
    const uint8_t *const cell_index = list->index + rows;
    const int cells = list->cells;
    int r;
    int i;
    if (cells > stride) {
        return;
    }
    for (i = 0; i < cells; ++i) {
        if ((int)cell_index[i] >= stride) {
            return;
        }
    }
    for (r = 0; r < rows; ++r) {
        const int kept = list->index[r];
        const icoac_real_t row_step = step * list->product[r];
        const uint8_t *cell = cell_index;
        const uint8_t *const end = cell + kept;
        const icoac_real_t *product = cell_product;
        /* r * stride <= ICOAC_MAX_CRITIC_UNITS (checked by the caller): no int overflow */
        icoac_real_t *u = v + (r * stride); /* NOLINT(bugprone-implicit-widening-of-multiplication-result) */
        if (kept > cells) {
            return;
        }
        ICOAC_PRIV_OPAQUE(u);
        while (cell != end) {
            u[*cell++] += row_step * *product++;
        }
    }
}

/* The general instances: the shape of the state's configuration, checked. */
ICOAC_PRIV_NOINLINE static icoac_real_t sparse_value_general(const icoac_critic_config_t *critic,
                                                             const icoac_priv_grid_t *grid, const icoac_real_t *v,
                                                             const icoac_real_t s[ICOAC_MAX_INPUTS],
                                                             icoac_priv_critic_list_t *list)
{
    icoac_priv_shape_t shape;
    if (!icoac_priv_critic_shape(critic, grid, &shape) || shape.n > ICOAC_MAX_INPUTS || shape.split >= shape.n) {
        /* a geometry the configuration check would refuse (a corrupted state) keeps no unit */
        list->product[0] = ICOAC_R(0.0);
        list->cells = 0u;
        list->rows = 0u;
        list->stride = 0u;
        return ICOAC_R(0.0);
    }
    return sparse_value(critic, v, s, list, shape.n, shape.units, shape.split, shape.rows, shape.cells);
}

/* The cart-pole's instance. Inline in the dispatch below where the call of the general instance
 * is a tail call (the dispatch's frame is released first); out of line on ARMv6-M (Cortex-M0/M0+),
 * whose calls into another section are never tail calls, so that the general instance's frame
 * is not nested under this one's. */
#if defined(__ARM_ARCH_6M__)
ICOAC_PRIV_NOINLINE
#endif
static icoac_real_t value_cartpole(const icoac_critic_config_t *critic, const icoac_real_t *v,
                                   const icoac_real_t s[ICOAC_MAX_INPUTS], icoac_priv_critic_list_t *list)
{
    static const int cartpole_units[ICOAC_CARTPOLE_INPUTS] = ICOAC_PRIV_CARTPOLE_UNITS;
    return sparse_value(critic, v, s, list, ICOAC_CARTPOLE_INPUTS, cartpole_units, 2, ICOAC_PRIV_CARTPOLE_ROWS,
                        ICOAC_PRIV_CARTPOLE_CELLS);
}

icoac_real_t icoac_priv_critic_value_sparse(const icoac_critic_config_t *critic, const icoac_priv_grid_t *grid,
                                            const icoac_real_t *v, const icoac_real_t s[ICOAC_MAX_INPUTS],
                                            icoac_priv_critic_list_t *list)
{
    if ((grid->shape & ICOAC_PRIV_SHAPE_CARTPOLE_CRITIC) != 0u) {
        return value_cartpole(critic, v, s, list);
    }
    return sparse_value_general(critic, grid, v, s, list);
}

void icoac_priv_critic_update_sparse(icoac_real_t *v, const icoac_priv_critic_list_t *list, icoac_real_t step)
{
    const int rows = list->rows;
    const int stride = list->stride;
    if (rows > ICOAC_CRITIC_BLOCK_MAX || stride > ICOAC_CRITIC_BLOCK_MAX || rows * stride > ICOAC_MAX_CRITIC_UNITS) {
        return;
    }
    sparse_update(v, list, step, rows, stride);
}

void icoac_priv_critic_update_sparse_shaped(const icoac_priv_grid_t *grid, icoac_real_t *v,
                                            const icoac_priv_critic_list_t *list, icoac_real_t step)
{
    if ((grid->shape & ICOAC_PRIV_SHAPE_CARTPOLE_CRITIC) != 0u) {
        sparse_update(v, list, step, ICOAC_PRIV_CARTPOLE_ROWS, ICOAC_PRIV_CARTPOLE_CELLS);
        return;
    }
    icoac_priv_critic_update_sparse(v, list, step);
}
