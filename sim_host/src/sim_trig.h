/* SPDX-License-Identifier: Apache-2.0 */
/* sin and cos of one argument for the plants, in plain branch-free C so that a loop over a
 * batch's lanes vectorises, with the same bits in the scalar and the vector code (build without
 * floating-point contraction). Reduction by the nearest multiple k of pi/2 in three parts (Cody and
 * Waite), each product exact, the rounding of each subtraction kept; kernels on |r| <= pi/4 from
 * near-minimax fits in r^2 (sim_host/tools/fit_trig.py prints them). Within 1 ulp of the true
 * value for |x| <= 2^20, where k P1 is exact (tests/c/test_trig.c). Beyond that (a plant state has
 * failed its limits long before), and for NaN or an infinity, both are NaN: a diverged angle stays
 * non-finite, which every plant's failure test catches. */
#ifndef SIM_TRIG_H
#define SIM_TRIG_H

#include <math.h>

static inline void sim_sincos(double x, double *sin_x, double *cos_x)
{
    /* pi/2 = P1 + P2 + P3 + P3T: P1 and P2 have 33 significant bits, so k P1 and k P2 are exact
     * for |k| < 2^20 */
    const double two_over_pi = 0x1.45f306dc9c883p-1;
    const double p1 = 0x1.921fb544p+0, p2 = 0x1.0b4611a6p-34, p3 = 0x1.3198a2e037073p-69;
    const double p3_tail = 0x1.129024e088a68p-123;
    const double round_shift = 0x1.8p52; /* x + 1.5 2^52 - 1.5 2^52 rounds x to an integer */
    const double s1 = -0x1.5555555555555p-3, s2 = 0x1.1111111110bb2p-7, s3 = -0x1.a01a019e83aaep-13,
                 s4 = 0x1.71de37968a100p-19, s5 = -0x1.ae600b02b6262p-26, s6 = 0x1.5e0b19f8b1451p-33;
    const double c1 = 0x1.5555555555555p-5, c2 = -0x1.6c16c16c16967p-10, c3 = 0x1.a01a019f4eb01p-16,
                 c4 = -0x1.27e4fa17da09ep-22, c5 = 0x1.1eeb68e93b64cp-29, c6 = -0x1.907da367a37cbp-37;
    const double k = (x * two_over_pi + round_shift) - round_shift;
    /* r = x - k pi/2 as head + tail: every subtraction's rounding error is carried to the tail */
    const double a = x - k * p1; /* exact (Sterbenz) */
    const double b = k * p2, ab = a - b, ab_err = (a - ab) - b;
    const double c = k * p3, abc = ab - c, abc_err = (ab - abc) - c;
    const double tail = ab_err + abc_err - k * p3_tail;
    const double r = abc + tail, r_tail = (abc - r) + tail;
    const double z = r * r;
    /* sin(r + t) = sin r + t cos r ~ r + r^3 S(z) + t (1 - z/2) */
    const double sin_poly = s1 + z * (s2 + z * (s3 + z * (s4 + z * (s5 + z * s6))));
    const double sin_r = r + (r * z * sin_poly + r_tail * (1.0 - 0.5 * z));
    /* cos(r + t) = cos r - t sin r ~ 1 - z/2 + z^2 C(z) - t r, with 1 - z/2 split exactly */
    const double cos_poly = c1 + z * (c2 + z * (c3 + z * (c4 + z * (c5 + z * c6))));
    const double half_z = 0.5 * z, one_minus = 1.0 - half_z;
    const double cos_r = one_minus + (((1.0 - one_minus) - half_z) + (z * z * cos_poly - r * r_tail));
    /* quadrant q = k mod 4, in doubles (no integer conversion, so that it vectorises) */
    const double q = k - 4.0 * ((k * 0.25 - 0.375 + round_shift) - round_shift);
    const int swap = q == 1.0 || q == 3.0;
    const double sin_abs = swap ? cos_r : sin_r, cos_abs = swap ? sin_r : cos_r;
    const int in_range = x >= -0x1p20 && x <= 0x1p20; /* false for NaN */
    *sin_x = in_range ? (q >= 2.0 ? -sin_abs : sin_abs) : (double)NAN;
    *cos_x = in_range ? ((q == 1.0 || q == 2.0) ? -cos_abs : cos_abs) : (double)NAN;
}

/* One of the two, for the plants' energies and the like. */
static inline double sim_sin(double x)
{
    double s, c;
    sim_sincos(x, &s, &c);
    return s;
}

static inline double sim_cos(double x)
{
    double s, c;
    sim_sincos(x, &s, &c);
    return c;
}

#endif /* SIM_TRIG_H */
