/* SPDX-License-Identifier: Apache-2.0 */
/* Double inverted pendulum on a cart, force on the cart, with the parameters of Bogdanov,
 * "Optimal control of a double inverted pendulum on a cart", OGI technical report CSE-04-006,
 * 2004. Frictionless; both links are uniform rods (centre of mass at half length, inertia
 * m L^2 / 12 about it); angles are absolute, from upright, positive toward +x. Equations:
 * Lagrange's equations, derived in docs/plants.md.
 *
 * State (x, x_dot, theta1, theta1_dot, theta2, theta2_dot). */
#include <float.h>
#include <math.h>

#include "icoac_sim/icoac_sim.h"
#include "sim_integrate.h"
#include "sim_trig.h"

enum { GRAVITY, CART_MASS, MASS1, MASS2, LENGTH1, LENGTH2, X_LIMIT, ANGLE_LIMIT, MAX_FORCE, N_PARAMS };

/* Inertia terms: T = 1/2 qdot^T M qdot with q = (x, theta1, theta2),
 * M = [[m, a1 c1, a2 c2], [a1 c1, j1, b c12], [a2 c2, b c12, j2]], V = g (a1 c1 + a2 c2). */
typedef struct {
    double m, a1, a2, j1, j2, b;
} terms_t;

static terms_t terms(const double *p)
{
    terms_t t;
    const double l1 = p[LENGTH1], l2 = p[LENGTH2];
    t.m = p[CART_MASS] + p[MASS1] + p[MASS2];
    t.a1 = (0.5 * p[MASS1] + p[MASS2]) * l1;
    t.a2 = 0.5 * p[MASS2] * l2;
    t.j1 = (p[MASS1] / 3.0 + p[MASS2]) * l1 * l1;
    t.j2 = p[MASS2] * l2 * l2 / 3.0;
    t.b = 0.5 * p[MASS2] * l1 * l2;
    return t;
}

SIM_DERIVATIVES derivatives(const double *p, const double *s, double command, double *ds)
{
    const terms_t t = terms(p);
    const double force = sim_saturate(command, p[MAX_FORCE]);
    double s1, c1, s2, c2, s12, c12;
    sim_sincos(s[2], &s1, &c1);
    sim_sincos(s[4], &s2, &c2);
    sim_sincos(s[2] - s[4], &s12, &c12);
    /* symmetric mass matrix (m00 m01 m02 / m11 m12 / m22) and right-hand side r */
    const double m01 = t.a1 * c1, m02 = t.a2 * c2, m12 = t.b * c12;
    const double r0 = force + t.a1 * s1 * s[3] * s[3] + t.a2 * s2 * s[5] * s[5];
    const double r1 = p[GRAVITY] * t.a1 * s1 - t.b * s12 * s[5] * s[5];
    const double r2 = p[GRAVITY] * t.a2 * s2 + t.b * s12 * s[3] * s[3];
    /* Cramer's rule with the cofactors of the symmetric matrix */
    const double k00 = t.j1 * t.j2 - m12 * m12, k01 = m02 * m12 - m01 * t.j2, k02 = m01 * m12 - m02 * t.j1;
    const double k11 = t.m * t.j2 - m02 * m02, k12 = m01 * m02 - t.m * m12, k22 = t.m * t.j1 - m01 * m01;
    const double det = t.m * k00 + m01 * k01 + m02 * k02;
    ds[0] = s[1];
    ds[1] = (k00 * r0 + k01 * r1 + k02 * r2) / det;
    ds[2] = s[3];
    ds[3] = (k01 * r0 + k11 * r1 + k12 * r2) / det;
    ds[4] = s[5];
    ds[5] = (k02 * r0 + k12 * r1 + k22 * r2) / det;
}

SIM_VECTOR_CLONES static void step(const double *p, double dt, int32_t integrator, double *s,
                                const double *forces, int32_t lanes)
{
    sim_integrate(derivatives, 6, p, dt, integrator, s, forces, lanes);
}

/* Outside the track or either link's angle limit (strict), or not finite; NaN fails. */
SIM_STATE_TEST outside(const double *p, const double *s)
{
    return !((fabs(s[0]) <= p[X_LIMIT]) & (fabs(s[2]) <= p[ANGLE_LIMIT]) & (fabs(s[4]) <= p[ANGLE_LIMIT]) &
             (fabs(s[1]) <= DBL_MAX) & (fabs(s[3]) <= DBL_MAX) & (fabs(s[5]) <= DBL_MAX));
}

SIM_VECTOR_CLONES static void failed(const double *p, const double *s, int32_t lanes, int32_t *out)
{
    sim_test_lanes(outside, 6, p, s, lanes, out);
}

static double energy(const double *p, const double *s)
{
    const terms_t t = terms(p);
    const double c1 = sim_cos(s[2]), c2 = sim_cos(s[4]), c12 = sim_cos(s[2] - s[4]);
    const double v = s[1], w1 = s[3], w2 = s[5];
    const double kinetic = 0.5 * (t.m * v * v + t.j1 * w1 * w1 + t.j2 * w2 * w2) + t.a1 * c1 * v * w1 +
                           t.a2 * c2 * v * w2 + t.b * c12 * w1 * w2;
    return kinetic + p[GRAVITY] * (t.a1 * c1 + t.a2 * c2);
}

static const icoac_sim_param_t params[N_PARAMS] = {
    {"gravity", "m/s^2", 9.8, ICOAC_SIM_PHYS_MIN, ICOAC_SIM_PHYS_MAX, "essential",
     "gravitational acceleration (Bogdanov 2004)"},
    {"cart_mass", "kg", 1.5, ICOAC_SIM_PHYS_MIN, ICOAC_SIM_PHYS_MAX, "essential",
     "m0, mass of the cart (Bogdanov 2004)"},
    {"mass1", "kg", 0.5, ICOAC_SIM_PHYS_MIN, ICOAC_SIM_PHYS_MAX, "essential",
     "mass of the lower link, a uniform rod (Bogdanov 2004)"},
    {"mass2", "kg", 0.75, ICOAC_SIM_PHYS_MIN, ICOAC_SIM_PHYS_MAX, "essential",
     "mass of the upper link, a uniform rod (Bogdanov 2004)"},
    {"length1", "m", 0.5, ICOAC_SIM_PHYS_MIN, ICOAC_SIM_PHYS_MAX, "essential",
     "length of the lower link (Bogdanov 2004)"},
    {"length2", "m", 0.75, ICOAC_SIM_PHYS_MIN, ICOAC_SIM_PHYS_MAX, "essential",
     "length of the upper link (Bogdanov 2004)"},
    {"x_limit", "m", 2.4, ICOAC_SIM_PHYS_MIN, ICOAC_SIM_PHYS_MAX, "advanced",
     "failure when |x| exceeds it (our choice, as the cart-pole's)"},
    {"angle_limit", "rad", 12.0 * ICOAC_SIM_PI / 180.0, ICOAC_SIM_PHYS_MIN, ICOAC_SIM_THETA_LIMIT_MAX, "advanced",
     "failure when |theta1| or |theta2| exceeds it (our choice, as the cart-pole's)"},
    {"max_force", "N", 1.0e6, ICOAC_SIM_PHYS_MIN, ICOAC_SIM_PHYS_MAX, "advanced",
     "|force| applied saturates at it (1e6: practically none)"},
};

/* Its task: six inputs scaled to the track and angle limits and to the velocity ranges (both links
 * alike); the critic over the same ranges, 216 units; six rules, first match wins: the lower link
 * beyond the zone gives the cart-pole's reflex, the cart beyond ICOAC_SIM_ZONE_FRACTION of the
 * track a push of CART_REFLEX times the push back to the centre, the upper link beyond the zone a
 * push of UPPER_REFLEX times its sign; ICO rate 1, gain 10 N. The knobs' values were chosen by its
 * sweep (docs/sweeps-double_cart_pole.md): both reflexes -1 (the signs of the plant's LQR gains on
 * x and theta2: away from the centre; tipping the lower link under the upper). */
enum { CART_VELOCITY_RANGE, LINK_VELOCITY_RANGE, ZONE, UPPER_REFLEX, CART_REFLEX, N_KNOBS };

static const icoac_sim_param_t knobs[N_KNOBS] = {
    {"cart_velocity_range", "m/s", 30.0, ICOAC_SIM_PHYS_MIN, ICOAC_SIM_PHYS_MAX, "advanced",
     "task: the cart velocity scaled to it"},
    {"link_velocity_range", "rad/s", 4.0, ICOAC_SIM_PHYS_MIN, ICOAC_SIM_PHYS_MAX, "advanced",
     "task: both links' angular velocities scaled to it"},
    {"zone_deg", "deg", 10.0, ICOAC_SIM_PHYS_MIN, 90.0, "advanced",
     "task: the links' reflex zones start at this angle"},
    {"upper_reflex", "", -1.0, -1.0, 1.0, "advanced",
     "task: the upper link's reflex, times its sign (+1: push under it; -1: tip the lower link under it)"},
    {"cart_reflex", "", -1.0, -1.0, 1.0, "advanced",
     "task: the cart's reflex near the track's end (+1: push back to the centre; -1: away)"},
};

static void task_settings(const double *knob, icoac_config_t *cfg)
{
    const double limit = params[ANGLE_LIMIT].value, z = knob[ZONE] * (ICOAC_SIM_PI / 180.0);
    const double zx = ICOAC_SIM_ZONE_FRACTION * params[X_LIMIT].value;
    const double v = knob[LINK_VELOCITY_RANGE], up = knob[UPPER_REFLEX], cart = knob[CART_REFLEX];
    const double range[6] = {params[X_LIMIT].value, knob[CART_VELOCITY_RANGE], limit, v, limit, v};
    const int32_t units[6] = {2, 2, 3, 3, 3, 2};
    const int32_t input[6] = {2, 0, 2, 0, 4, 4};
    const int32_t side[6] = {ICOAC_RULE_ABOVE, ICOAC_RULE_BELOW, ICOAC_RULE_BELOW,
                             ICOAC_RULE_ABOVE, ICOAC_RULE_ABOVE, ICOAC_RULE_BELOW};
    const double threshold[6] = {z, -zx, -z, zx, z, -z};
    const double reflex[6] = {1.0, cart, -1.0, -cart, up, -up};
    int i;
    cfg->task.n_inputs = 6;
    cfg->task.n_rules = 6;
    for (i = 0; i < 6; ++i) {
        cfg->task.rule_input[i] = input[i];
        cfg->task.rule_side[i] = side[i];
        cfg->task.rule_threshold[i] = (icoac_real_t)threshold[i];
        cfg->task.rule_reflex[i] = (icoac_real_t)reflex[i];
        cfg->policy.input_range[i] = (icoac_real_t)range[i];
        cfg->critic.range[i] = (icoac_real_t)range[i];
        cfg->critic.units[i] = units[i];
    }
    cfg->ico.rate = (icoac_real_t)1.0;
    cfg->policy.gain = (icoac_real_t)10.0;
}

/* No setting of either actor-critic learner balances a cell (its learner sweeps), so both keep
 * their defaults. */
static const icoac_sim_task_t task = {
    "its sweep (docs/sweeps-double_cart_pole.md): velocity scaling, reflex zone and the upper link's "
    "reflex sign, ICO rate, gain",
    task_settings, N_KNOBS, 0, knobs, 0, 0, 0,
    "ICO balances at most 1 of its cells at the default caps (no prior of 2 or more successful cells "
    "in any frame), but it learns weights in every cell: the ICO prior averages them, balanced or not"};

const icoac_sim_plant_desc_t sim_double_cart_pole = {
    "double_cart_pole",
    "double inverted pendulum on a cart, force on the cart",
    "Bogdanov, 'Optimal control of a double inverted pendulum on a cart', OGI School of Science & "
    "Engineering, OHSU, technical report CSE-04-006, 2004",
    {"force", "N"},
    {MAX_FORCE, 0, 25.0, "none published for this cart: the cart-pole's force per weight (10 N to "
                         "1.1 kg x 9.8 m/s^2) at this plant's 2.75 kg"},
    6,
    N_PARAMS,
    {{"x", "m"}, {"x_dot", "m/s"}, {"theta1", "rad"}, {"theta1_dot", "rad/s"}, {"theta2", "rad"},
     {"theta2_dot", "rad/s"}},
    params,
    {2, 25, -12.0, 1.0, 1, 0}, /* theta1_0: -12..12 deg */
    {0, 49, -2.4, 0.1, 0, 0},  /* x0: -2.4..2.4 m */
    {0.0, 0.0, 0.0, 0.0, 0.0, 0.0},
    {0, 1, 0, 1, 0, 1},
    {0, 1, 2, 3, 4, 5},
    step,
    derivatives,
    failed,
    energy,
    &task,
};
