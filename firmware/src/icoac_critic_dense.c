/* Dense critic kernel, the host build's (icoac_priv.h): the units of icoac_critic.c's sparse
 * kernel, found by a mask instead of a sorted list. Unit k = pair * 18 + cell is kept when
 * b_k = pair_product * cell_product >= the floor, the sparse kernel's test on the same product.
 * The loops run over every pair and over the cells of the theta units above the threshold (one
 * run, the same for every pair of a tick), with no data-dependent branch inside: a compiler
 * vectorizes them, cells in SIMD lanes. Nothing is reassociated, so the result is the same with
 * or without vectorization.
 * V = sum over cells of (sum over pairs, in pair order, of v_k b_k): the sparse kernel's terms
 * in another order. The update adds (step * pair_product) * cell_product to the kept units, as
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

icoac_real_t icoac_priv_critic_value_dense(const icoac_critic_config_t *critic,
                                           const icoac_real_t v[ICOAC_CRITIC_UNITS],
                                           const icoac_real_t factors[ICOAC_CRITIC_FACTORS],
                                           icoac_priv_critic_products_t *products)
{
    const icoac_real_t threshold = icoac_priv_critic_floor(critic);
    const icoac_real_t *gx = factors;
    const icoac_real_t *gxd = gx + ICOAC_CRITIC_N_X;
    const icoac_real_t *gth = gxd + ICOAC_CRITIC_N_X_DOT;
    const icoac_real_t *gthd = gth + ICOAC_CRITIC_N_THETA;
    icoac_real_t cell_sum[ICOAC_CRITIC_CELLS];
    icoac_real_t value = ICOAC_R(0.0);
    int begin = ICOAC_CRITIC_N_THETA;
    int end = 0;
    int a, b, c, d, p, j;
    for (a = 0; a < ICOAC_CRITIC_N_X; ++a) {
        for (b = 0; b < ICOAC_CRITIC_N_X_DOT; ++b) {
            products->pair_product[a * ICOAC_CRITIC_N_X_DOT + b] = gx[a] * gxd[b];
        }
    }
    /* Only theta units with g_theta >= the threshold can keep a unit (every factor is <= 1);
     * g_theta is unimodal, so they are one run [begin, end), cells 3 begin .. 3 end. */
    for (c = 0; c < ICOAC_CRITIC_N_THETA; ++c) {
        const int above = icoac_priv_nonneg_at_least(gth[c], threshold);
        begin = above && c < begin ? c : begin;
        end = above ? c + 1 : end;
    }
    for (c = 0; c < ICOAC_CRITIC_N_THETA; ++c) {
        for (d = 0; d < ICOAC_CRITIC_N_THETA_DOT; ++d) {
            products->cell_product[c * ICOAC_CRITIC_N_THETA_DOT + d] = gth[c] * gthd[d];
        }
    }
    begin *= ICOAC_CRITIC_N_THETA_DOT;
    end *= ICOAC_CRITIC_N_THETA_DOT;
    products->cell_begin = (uint8_t)begin;
    products->cell_end = (uint8_t)end;
    for (j = begin; j < end; ++j) {
        cell_sum[j] = ICOAC_R(0.0);
    }
    for (p = 0; p < ICOAC_CRITIC_PAIRS; ++p) {
        const icoac_real_t pair_product = products->pair_product[p];
        const icoac_real_t *u = v + p * ICOAC_CRITIC_CELLS;
        for (j = begin; j < end; ++j) {
            const icoac_real_t unit_b = pair_product * products->cell_product[j];
            cell_sum[j] += select_kept(unit_b, threshold, u[j] * unit_b, ICOAC_R(0.0));
        }
    }
    for (j = begin; j < end; ++j) {
        value += cell_sum[j];
    }
    return value;
}

void icoac_priv_critic_update_dense(const icoac_critic_config_t *critic, icoac_real_t v[ICOAC_CRITIC_UNITS],
                                    const icoac_priv_critic_products_t *products, icoac_real_t step)
{
    const icoac_real_t threshold = icoac_priv_critic_floor(critic);
    /* the range lives in the state between ticks: bounded, whatever it holds */
    const int begin = products->cell_begin;
    const int end = products->cell_end < ICOAC_CRITIC_CELLS ? (int)products->cell_end : ICOAC_CRITIC_CELLS;
    int p, j;
    for (p = 0; p < ICOAC_CRITIC_PAIRS; ++p) {
        const icoac_real_t pair_product = products->pair_product[p];
        const icoac_real_t pair_step = step * pair_product;
        icoac_real_t *u = v + p * ICOAC_CRITIC_CELLS;
        for (j = begin; j < end; ++j) {
            const icoac_real_t cell_product = products->cell_product[j];
            const icoac_real_t unit = u[j];
            const icoac_real_t updated = unit + pair_step * cell_product;
            u[j] = select_kept(pair_product * cell_product, threshold, updated, unit);
        }
    }
}
