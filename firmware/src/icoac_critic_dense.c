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

/* b >= threshold ? kept : otherwise, for b >= 0 and threshold > 0, in integer operations on
 * the bit patterns (a float compare and select would be a branch under -ftrapping-math, the
 * default). Non-negative IEEE-754 values order like their bits as signed integers; NaN counts
 * as kept, so it reaches V and the tick's finiteness check. */
static inline icoac_real_t select_kept(icoac_real_t b, icoac_real_t threshold, icoac_real_t kept,
                                       icoac_real_t otherwise)
{
    real_bits_t bits_b, bits_threshold, bits_kept, bits_otherwise, mask;
    memcpy(&bits_b, &b, sizeof b);
    memcpy(&bits_threshold, &threshold, sizeof threshold);
    memcpy(&bits_kept, &kept, sizeof kept);
    memcpy(&bits_otherwise, &otherwise, sizeof otherwise);
    mask = -(real_bits_t)(bits_b >= bits_threshold);
    bits_kept = (bits_kept & mask) | (bits_otherwise & ~mask);
    memcpy(&kept, &bits_kept, sizeof kept);
    return kept;
}

icoac_real_t icoac_priv_critic_value_dense(const icoac_critic_config_t *critic, const icoac_priv_grid_t *grid,
                                           const icoac_real_t *v, const icoac_real_t s[ICOAC_MAX_INPUTS],
                                           icoac_priv_critic_products_t *products)
{
    const icoac_real_t threshold = icoac_priv_critic_floor(critic);
    const int n = grid->n <= ICOAC_MAX_INPUTS ? (int)grid->n : ICOAC_MAX_INPUTS;
    const int split = grid->split < n ? (int)grid->split : n;
    icoac_real_t g[ICOAC_CRITIC_UNITS_PER_INPUT_MAX];
    icoac_real_t cell_sum[ICOAC_PRIV_BLOCK];
    icoac_real_t value = ICOAC_R(0.0);
    int rows = 1;
    int cells = 1;
    int begin = 0;
    int end = 0;
    int i, c, r, j;
    products->row_product[0] = ICOAC_R(1.0);
    for (i = 0; i < split; ++i) {
        const int count = grid->units[i] <= ICOAC_CRITIC_UNITS_PER_INPUT_MAX ? (int)grid->units[i]
                                                                            : ICOAC_CRITIC_UNITS_PER_INPUT_MAX;
        icoac_priv_critic_factors(s[i], critic->range[i], count, g);
        rows = icoac_priv_critic_expand(products->row_product, 0, g, count, 0, count, rows);
    }
    products->cell_product[0] = ICOAC_R(1.0);
    for (i = split; i < n; ++i) {
        const int count = grid->units[i] <= ICOAC_CRITIC_UNITS_PER_INPUT_MAX ? (int)grid->units[i]
                                                                            : ICOAC_CRITIC_UNITS_PER_INPUT_MAX;
        icoac_priv_critic_factors(s[i], critic->range[i], count, g);
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
        cells = icoac_priv_critic_expand(products->cell_product, 0, g, count, 0, count, cells);
    }
    /* a geometry the configuration check would refuse (a corrupted state) keeps no unit */
    if (cells == 0 || rows * cells > ICOAC_MAX_CRITIC_UNITS) {
        rows = 0;
        end = 0;
    }
    products->rows = (uint8_t)rows;
    products->stride = (uint8_t)cells;
    products->cell_begin = (uint8_t)begin;
    products->cell_end = (uint8_t)end;
    for (j = begin; j < end; ++j) {
        cell_sum[j] = ICOAC_R(0.0);
    }
    for (r = 0; r < rows; ++r) {
        const icoac_real_t row_product = products->row_product[r];
        const icoac_real_t *u = v + r * cells;
        for (j = begin; j < end; ++j) {
            const icoac_real_t unit_b = row_product * products->cell_product[j];
            cell_sum[j] += select_kept(unit_b, threshold, u[j] * unit_b, ICOAC_R(0.0));
        }
    }
    for (j = begin; j < end; ++j) {
        value += cell_sum[j];
    }
    return value;
}

void icoac_priv_critic_update_dense(const icoac_critic_config_t *critic, icoac_real_t *v,
                                    const icoac_priv_critic_products_t *products, icoac_real_t step)
{
    const icoac_real_t threshold = icoac_priv_critic_floor(critic);
    /* the products live in the state between ticks: bounded, whatever they hold */
    const int rows = products->rows;
    const int stride = products->stride;
    const int begin = products->cell_begin;
    const int end = products->cell_end < stride ? (int)products->cell_end : stride;
    int r, j;
    if (rows > ICOAC_PRIV_BLOCK || stride > ICOAC_PRIV_BLOCK || rows * stride > ICOAC_MAX_CRITIC_UNITS) {
        return;
    }
    for (r = 0; r < rows; ++r) {
        const icoac_real_t row_product = products->row_product[r];
        const icoac_real_t row_step = step * row_product;
        icoac_real_t *u = v + r * stride;
        for (j = begin; j < end; ++j) {
            const icoac_real_t cell_product = products->cell_product[j];
            const icoac_real_t unit = u[j];
            const icoac_real_t updated = unit + row_step * cell_product;
            u[j] = select_kept(row_product * cell_product, threshold, updated, unit);
        }
    }
}
