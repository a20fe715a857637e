/* SPDX-License-Identifier: Apache-2.0 */
/* Dense critic kernel, the host build's (icoac_priv.h): the units of icoac_critic.c's sparse
 * kernel, found by a mask instead of a sorted list. Unit k = row * cells + cell is kept when
 * b_k = row_product * cell_product >= the floor, the sparse kernel's test on the same product.
 * The loops run over every row and over the cells whose first cell input's unit is above the
 * threshold (one run, the same for every row of a tick), with no data-dependent branch inside: a
 * compiler vectorizes them, cells in SIMD lanes. Nothing is reassociated, so the result is the
 * same with or without vectorization.
 * V = sum over cells of (sum over rows, in row order, of v_k b_k): the sparse kernel's terms
 * in another order. The update adds (step * row_product) * cell_product to the kept units, as
 * the sparse one does. */
#include "icoac_priv.h"

#if defined(ICOAC_REAL_DOUBLE) && ICOAC_REAL_DOUBLE
typedef int64_t real_bits_t;
#else
typedef int32_t real_bits_t;
#endif

/* A value and its bit pattern. A union rather than memcpy: GCC 12's -fanalyzer takes the bits
 * of an integer expression copied by memcpy for uninitialised (a false positive); the object
 * code is the same. */
typedef union {
    icoac_real_t real;
    real_bits_t bits;
} real_view_t;

/* b >= threshold ? kept : otherwise, for b >= 0 and threshold > 0, in integer operations on
 * the bit patterns (a float compare and select would be a branch under -ftrapping-math, the
 * default). Non-negative IEEE-754 values order like their bits as signed integers; NaN counts
 * as kept, so it reaches V and the tick's finiteness check. */
static inline icoac_real_t select_kept(icoac_real_t b, icoac_real_t threshold, icoac_real_t kept,
                                       icoac_real_t otherwise)
{
    real_view_t view_b;
    real_view_t view_threshold;
    real_view_t view_kept;
    real_view_t view_otherwise;
    real_bits_t mask;
    view_b.real = b;
    view_threshold.real = threshold;
    view_kept.real = kept;
    view_otherwise.real = otherwise;
    mask = -(real_bits_t)(view_b.bits >= view_threshold.bits);
    view_kept.bits = (view_kept.bits & mask) | (view_otherwise.bits & ~mask);
    return view_kept.real;
}

/* The dense kernel for the grid of n inputs with these units, split and rows x stride (checked
 * by the caller: rows and stride <= ICOAC_CRITIC_BLOCK_MAX, rows * stride <=
 * ICOAC_MAX_CRITIC_UNITS). */
static inline icoac_real_t dense_value(const icoac_critic_config_t *critic, const icoac_real_t *v,
                                       const icoac_real_t s[ICOAC_MAX_INPUTS], const icoac_real_t *given,
                                       icoac_priv_critic_products_t *products, int n_inputs, const int *units,
                                       int first_cell, int rows, int stride)
{
    /* the callers' bounds, restated for the compiler: 1 <= n <= ICOAC_MAX_INPUTS, split < n */
    const int n = n_inputs < ICOAC_MAX_INPUTS ? n_inputs : ICOAC_MAX_INPUTS;
    const int split = first_cell < n - 1 ? first_cell : n - 1;
    const icoac_real_t threshold = icoac_priv_critic_floor(critic);
    icoac_real_t g[ICOAC_CRITIC_UNITS_PER_INPUT_MAX];
    icoac_real_t cell_sum[ICOAC_CRITIC_BLOCK_MAX];
    icoac_real_t *const row_product = products->product;
    icoac_real_t *const cell_product = products->product + rows;
    icoac_real_t value = ICOAC_R(0.0);
    int entries = 1;
    int begin = 0;
    int end = 0;
    int i;
    int c;
    int r;
    int j;
    row_product[0] = ICOAC_R(1.0);
    ICOAC_PRIV_UNROLL
    for (i = 0; i < split; ++i) {
        icoac_priv_factors(s[i], critic->range[i], units[i], (given != NULL) ? &given[2 * i] : NULL, g);
        entries = icoac_priv_critic_expand_all(row_product, g, units[i], entries);
    }
    cell_product[0] = ICOAC_R(1.0);
    entries = 1;
    ICOAC_PRIV_UNROLL
    for (i = split; i < n; ++i) {
        const int count = units[i];
        icoac_priv_factors(s[i], critic->range[i], count, (given != NULL) ? &given[2 * i] : NULL, g);
        if (i == split) {
            /* Only units of the first cell input with g >= the threshold can be kept (every factor
             * is <= 1); g is unimodal, so they are one run [begin, end) of it. */
            begin = count;
            for (c = 0; c < count; ++c) {
                const int above = icoac_priv_nonneg_at_least(g[c], threshold);
                begin = above && c < begin ? c : begin;
                end = above ? c + 1 : end;
            }
        } else {
            begin *= count;
            end *= count;
        }
        entries = icoac_priv_critic_expand_all(cell_product, g, count, entries);
    }
    products->rows = (uint8_t)rows;
    products->stride = (uint8_t)stride;
    products->cell_begin = (uint8_t)begin;
    products->cell_end = (uint8_t)end;
    for (j = begin; j < end; ++j) {
        cell_sum[j] = ICOAC_R(0.0);
    }
    for (r = 0; r < rows; ++r) {
        const icoac_real_t product_r = row_product[r];
        /* r * stride <= ICOAC_MAX_CRITIC_UNITS (checked by the caller): no int overflow */
        const icoac_real_t *u = v + (r * stride); /* NOLINT(bugprone-implicit-widening-of-multiplication-result) */
        for (j = begin; j < end; ++j) {
            const icoac_real_t unit_b = product_r * cell_product[j];
            cell_sum[j] += select_kept(unit_b, threshold, u[j] * unit_b, ICOAC_R(0.0));
        }
    }
    for (j = begin; j < end; ++j) {
        value += cell_sum[j];
    }
    return value;
}

/* The update over rows x stride (checked by the caller against the weights); the cell range
 * lives in the state between ticks, so it is bounded to the stride here. */
static inline void dense_update(const icoac_critic_config_t *critic, icoac_real_t *v,
                                const icoac_priv_critic_products_t *products, icoac_real_t step, int rows, int stride)
{
    const icoac_real_t threshold = icoac_priv_critic_floor(critic);
    const icoac_real_t *const cell_product = products->product + rows;
    const int begin = products->cell_begin;
    const int end = ((int)products->cell_end < stride) ? (int)products->cell_end : stride;
    int r;
    int j;
    for (r = 0; r < rows; ++r) {
        const icoac_real_t product_r = products->product[r];
        const icoac_real_t row_step = step * product_r;
        /* r * stride <= ICOAC_MAX_CRITIC_UNITS (checked by the caller): no int overflow */
        icoac_real_t *u = v + (r * stride); /* NOLINT(bugprone-implicit-widening-of-multiplication-result) */
        for (j = begin; j < end; ++j) {
            const icoac_real_t unit = u[j];
            const icoac_real_t updated = unit + row_step * cell_product[j];
            u[j] = select_kept(product_r * cell_product[j], threshold, updated, unit);
        }
    }
}

ICOAC_PRIV_NOINLINE static icoac_real_t dense_value_general(const icoac_critic_config_t *critic,
                                                            const icoac_priv_grid_t *grid, const icoac_real_t *v,
                                                            const icoac_real_t s[ICOAC_MAX_INPUTS],
                                                            const icoac_real_t *given,
                                                            icoac_priv_critic_products_t *products)
{
    icoac_priv_shape_t shape;
    if (!icoac_priv_critic_shape(critic, grid, &shape) || shape.n > ICOAC_MAX_INPUTS || shape.split >= shape.n) {
        /* a geometry the configuration check would refuse (a corrupted state) keeps no unit */
        products->rows = 0u;
        products->stride = 0u;
        products->cell_begin = 0u;
        products->cell_end = 0u;
        return ICOAC_R(0.0);
    }
    return dense_value(critic, v, s, given, products, shape.n, shape.units, shape.split, shape.rows, shape.cells);
}

icoac_real_t icoac_priv_critic_value_dense(const icoac_critic_config_t *critic, const icoac_priv_grid_t *grid,
                                           const icoac_real_t *v, const icoac_real_t s[ICOAC_MAX_INPUTS],
                                           const icoac_real_t *given, icoac_priv_critic_products_t *products)
{
    static const int cartpole_units[ICOAC_CARTPOLE_INPUTS] = ICOAC_PRIV_CARTPOLE_UNITS;
    if ((grid->shape & ICOAC_PRIV_SHAPE_CARTPOLE_CRITIC) != 0u) {
        return dense_value(critic, v, s, given, products, ICOAC_CARTPOLE_INPUTS, cartpole_units, 2,
                           ICOAC_PRIV_CARTPOLE_ROWS, ICOAC_PRIV_CARTPOLE_CELLS);
    }
    return dense_value_general(critic, grid, v, s, given, products);
}

void icoac_priv_critic_update_dense(const icoac_critic_config_t *critic, const icoac_priv_grid_t *grid,
                                    icoac_real_t *v, const icoac_priv_critic_products_t *products,
                                    icoac_real_t step)
{
    /* the products live in the state between ticks: bounded, whatever they hold */
    const int rows = products->rows;
    const int stride = products->stride;
    if ((grid->shape & ICOAC_PRIV_SHAPE_CARTPOLE_CRITIC) != 0u) {
        dense_update(critic, v, products, step, ICOAC_PRIV_CARTPOLE_ROWS, ICOAC_PRIV_CARTPOLE_CELLS);
        return;
    }
    if (rows > ICOAC_CRITIC_BLOCK_MAX || stride > ICOAC_CRITIC_BLOCK_MAX || rows * stride > ICOAC_MAX_CRITIC_UNITS) {
        return;
    }
    dense_update(critic, v, products, step, rows, stride);
}
