/* SPDX-License-Identifier: Apache-2.0 */
/* The plain-C speed reference of the closed-loop ICO tick (docs/results.md, Speed): what a
 * competent scalar implementation of the same workload costs, to put icoac_bench's figures in
 * proportion. Nothing of icoac is used or linked, and nothing uses its numbers but that
 * comparison. The workload is icoac_bench's balanced ICO cell: the cart-pole task (inputs scaled
 * by 2.4 m, 3.5 m/s, 12 deg, 2 rad/s; the four penalty rules |theta| > 11.5 deg, |x| > 2.35 m
 * with their reflexes), float controller, gain 10 N, ICO rate 1e-4 learning at a penalty
 * onset, the learned weights (0.094, 0.066, 0.365, 0.080); the frictionless cart-pole in double,
 * explicit Euler, dt 0.01 s, libm's sin and cos. Cells run one after another, ticks one after
 * another: no lockstep, no vectors. Subnormals are flushed as in icoac's engine.
 * Usage: reference_tick [ticks per cell]; prints ns per tick. */
#define _POSIX_C_SOURCE 199309L
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <time.h>
#if defined(__SSE2__)
#include <xmmintrin.h>
#endif

typedef struct {
    float w[4];
    float penalty_prev;
} ico_t;

static const float range[4] = {2.4f, 3.5f, 0.2094384f, 2.0f};

/* One controller tick: the force for state s, learning on a penalty onset. */
static float ico_tick(ico_t *c, const double s[4])
{
    float x[4], z = 0.0f, reflex = 0.0f, penalty = 0.0f, drop;
    const float theta = (float)s[2], cart = (float)s[0];
    int i;
    for (i = 0; i < 4; ++i) {
        x[i] = (float)s[i] / range[i];
        z += c->w[i] * x[i];
    }
    if (theta > 0.20071286f || cart < -2.35f) {
        reflex = 1.0f;
        penalty = -1.0f;
    } else if (theta < -0.20071286f || cart > 2.35f) {
        reflex = -1.0f;
        penalty = -1.0f;
    }
    drop = c->penalty_prev - penalty;
    if (drop > 0.0f) {
        for (i = 0; i < 4; ++i) {
            c->w[i] += 1.0e-4f * drop * fabsf(x[i]);
        }
    }
    c->penalty_prev = penalty;
    return 10.0f * z + reflex;
}

/* One Euler step of the frictionless cart-pole (Barto, Sutton & Anderson 1983). */
static void cart_pole(double s[4], double force)
{
    const double sin_t = sin(s[2]), cos_t = cos(s[2]);
    const double temp = (force + 0.05 * s[3] * s[3] * sin_t) / 1.1;
    const double theta_acc = (9.8 * sin_t - cos_t * temp) / (0.5 * (4.0 / 3.0 - 0.1 * cos_t * cos_t / 1.1));
    const double x_acc = temp - 0.05 * theta_acc * cos_t / 1.1;
    const double ds[4] = {s[1], x_acc, s[3], theta_acc};
    int i;
    for (i = 0; i < 4; ++i) {
        s[i] += 0.01 * ds[i];
    }
}

static double now_seconds(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

int main(int argc, char **argv)
{
    char *end = NULL;
    const long ticks = argc > 1 ? strtol(argv[1], &end, 10) : 5000000L;
    long done = 0, k;
    int cell;
    double t0, sink = 0.0;
    if (argc > 2 || (argc == 2 && (*argv[1] == '\0' || *end != '\0' || ticks < 16))) {
        fprintf(stderr, "usage: reference_tick [TICKS]  (an integer >= 16; default 5000000)\n");
        return 2;
    }
#if defined(__SSE2__)
    _mm_setcsr(_mm_getcsr() | 0x8040); /* flush to zero, denormals are zero */
#endif
    t0 = now_seconds();
    for (cell = 0; cell < 16; ++cell) {
        ico_t c = {{0.094f, 0.066f, 0.365f, 0.080f}, 0.0f};
        double s[4] = {-0.5, 0.0, -4.0 * 3.14159265358979323846 / 180.0, 0.0};
        s[1] = 1e-5 * (double)cell; /* each cell its own start */
        for (k = 0; k < ticks / 16; ++k) {
            cart_pole(s, (double)ico_tick(&c, s));
            if (!(fabs(s[0]) <= 2.4 && fabs(s[2]) <= 0.20943951)) {
                break; /* the bench's cell stays up; a fall would end the trial */
            }
        }
        done += k;
        sink += s[0];
    }
    printf("reference ICO tick (plain C, scalar, libm): %.1f ns  [%ld ticks, %g]\n",
           1e9 * (now_seconds() - t0) / (double)done, done, sink);
    return 0;
}
