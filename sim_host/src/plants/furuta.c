/* SPDX-License-Identifier: Apache-2.0 */
/* Furuta (rotary inverted) pendulum driven by a DC motor, with the parameters of the Quanser
 * QUBE-Servo 2 (QUBE-Servo 2 User Manual, system parameters table: motor and rotary pendulum
 * module; the module's masses and lengths are also listed in the QUBE-Servo 3 User Manual,
 * Table 2.2). Equations: Lagrange's equations of the two links, derived in docs/plants.md (the
 * model of Acosta, "Furuta's pendulum: a conservative nonlinear model for theory and practise",
 * Math. Probl. Eng. 2010, article 742894, and of Cazzolato & Prime, "On the dynamics of the Furuta
 * pendulum", J. Control Sci. Eng. 2011, here with thin-rod links).
 *
 * State (theta, theta_dot, alpha, alpha_dot): arm angle about the motor axis, pendulum angle
 * from upright (positive when the pendulum leans the way the arm's tip moves for theta_dot > 0).
 * Input: motor voltage V, saturated at the amplifier's limit (+-10 V); the motor's torque is
 * k_t (V - k_t theta_dot) / R_m (inductance neglected, back-EMF constant = torque constant in SI
 * units). Links are thin uniform rods: the arm pivots at one end, the pendulum at the arm's tip.
 * The viscous damping of both joints is that of Quanser's parameter script for this unit
 * (qube2_rotpen_param.m). The model without damping and limit is the variant
 * --set arm_damping=0 --set pendulum_damping=0 --set max_voltage=1e6 (docs/plants.md). */
#include <float.h>
#include <math.h>

#include "icoac_sim/icoac_sim.h"
#include "sim_integrate.h"
#include "sim_trig.h"

enum {
    GRAVITY, ARM_MASS, ARM_LENGTH, PENDULUM_MASS, PENDULUM_LENGTH, HUB_INERTIA, RESISTANCE,
    TORQUE_CONSTANT, ARM_DAMPING, PENDULUM_DAMPING, ARM_LIMIT, PENDULUM_LIMIT, MAX_VOLTAGE, N_PARAMS
};

/* Inertia terms of the Lagrangian: T = 1/2 (a + b sin^2 alpha) theta_dot^2
 * + c cos alpha theta_dot alpha_dot + 1/2 b alpha_dot^2, V = d cos alpha. */
typedef struct {
    double a, b, c, d;
} terms_t;

static terms_t terms(const double *p)
{
    terms_t t;
    const double lr = p[ARM_LENGTH], lp = p[PENDULUM_LENGTH], mp = p[PENDULUM_MASS];
    t.a = p[HUB_INERTIA] + (p[ARM_MASS] / 3.0 + mp) * lr * lr;
    t.b = mp * lp * lp / 3.0;
    t.c = 0.5 * mp * lr * lp;
    t.d = 0.5 * mp * p[GRAVITY] * lp;
    return t;
}

SIM_DERIVATIVES derivatives(const double *p, const double *s, double voltage, double *ds)
{
    const terms_t t = terms(p);
    double sin_a, cos_a;
    sim_sincos(s[2], &sin_a, &cos_a);
    const double applied = sim_saturate(voltage, p[MAX_VOLTAGE]); /* the amplifier's */
    const double torque = p[TORQUE_CONSTANT] * (applied - p[TORQUE_CONSTANT] * s[1]) / p[RESISTANCE];
    /* mass matrix [[m11, m12], [m12, b]] and right-hand side (r1, r2) */
    const double m11 = t.a + t.b * sin_a * sin_a;
    const double m12 = t.c * cos_a;
    const double r1 = torque - p[ARM_DAMPING] * s[1] - 2.0 * t.b * sin_a * cos_a * s[1] * s[3] +
                      t.c * sin_a * s[3] * s[3];
    const double r2 = -p[PENDULUM_DAMPING] * s[3] + t.b * sin_a * cos_a * s[1] * s[1] + t.d * sin_a;
    const double det = m11 * t.b - m12 * m12;
    ds[0] = s[1];
    ds[1] = (t.b * r1 - m12 * r2) / det;
    ds[2] = s[3];
    ds[3] = (m11 * r2 - m12 * r1) / det;
}

SIM_VECTOR_CLONES static void step(const double *p, double dt, int32_t integrator, double *s,
                                const double *voltages, int32_t lanes)
{
    sim_integrate(derivatives, 4, p, dt, integrator, s, voltages, lanes);
}

/* Outside the arm or pendulum limit (strict), or not finite; NaN fails. */
SIM_STATE_TEST outside(const double *p, const double *s)
{
    return !((fabs(s[0]) <= p[ARM_LIMIT]) & (fabs(s[2]) <= p[PENDULUM_LIMIT]) & (fabs(s[1]) <= DBL_MAX) &
             (fabs(s[3]) <= DBL_MAX));
}

SIM_VECTOR_CLONES static void failed(const double *p, const double *s, int32_t lanes, int32_t *out)
{
    sim_test_lanes(outside, 4, p, s, lanes, out);
}

static double energy(const double *p, const double *s)
{
    const terms_t t = terms(p);
    double sin_a, cos_a;
    sim_sincos(s[2], &sin_a, &cos_a);
    return 0.5 * (t.a + t.b * sin_a * sin_a) * s[1] * s[1] + t.c * cos_a * s[1] * s[3] +
           0.5 * t.b * s[3] * s[3] + t.d * cos_a;
}

static const icoac_sim_param_t params[N_PARAMS] = {
    {"gravity", "m/s^2", 9.81, ICOAC_SIM_PHYS_MIN, ICOAC_SIM_PHYS_MAX, "essential",
     "gravitational acceleration"},
    {"arm_mass", "kg", 0.095, ICOAC_SIM_PHYS_MIN, ICOAC_SIM_PHYS_MAX, "essential",
     "m_r, mass of the rotary arm, a thin rod (QUBE-Servo 2 rotary pendulum module)"},
    {"arm_length", "m", 0.085, ICOAC_SIM_PHYS_MIN, ICOAC_SIM_PHYS_MAX, "essential",
     "L_r, length of the arm, motor axis to pendulum pivot (same module)"},
    {"pendulum_mass", "kg", 0.024, ICOAC_SIM_PHYS_MIN, ICOAC_SIM_PHYS_MAX, "essential",
     "m_p, mass of the pendulum, a thin rod (same module)"},
    {"pendulum_length", "m", 0.129, ICOAC_SIM_PHYS_MIN, ICOAC_SIM_PHYS_MAX, "essential",
     "L_p, length of the pendulum (same module)"},
    {"hub_inertia", "kg m^2", 4.6e-6, 0.0, ICOAC_SIM_PHYS_MAX, "essential",
     "J_h, about the motor axis: motor rotor 4.0e-6 + module hub 0.6e-6 (QUBE-Servo 2)"},
    {"resistance", "ohm", 8.4, ICOAC_SIM_PHYS_MIN, ICOAC_SIM_PHYS_MAX, "essential",
     "R_m, motor terminal resistance (QUBE-Servo 2)"},
    {"torque_constant", "N m/A", 0.042, 0.0, ICOAC_SIM_PHYS_MAX, "essential",
     "k_t, motor torque constant = back-EMF constant in SI units (QUBE-Servo 2)"},
    {"arm_damping", "N m s/rad", 0.0015, 0.0, ICOAC_SIM_PHYS_MAX, "advanced",
     "D_r, viscous damping of the arm (Quanser's qube2_rotpen_param.m; 0: frictionless)"},
    {"pendulum_damping", "N m s/rad", 0.0005, 0.0, ICOAC_SIM_PHYS_MAX, "advanced",
     "D_p, viscous damping of the pendulum (the same script; 0: frictionless)"},
    {"arm_limit", "rad", 0.5 * ICOAC_SIM_PI, ICOAC_SIM_PHYS_MIN, ICOAC_SIM_PHYS_MAX, "advanced",
     "failure when |theta| exceeds it (our choice)"},
    {"pendulum_limit", "rad", 12.0 * ICOAC_SIM_PI / 180.0, ICOAC_SIM_PHYS_MIN, ICOAC_SIM_THETA_LIMIT_MAX, "advanced",
     "failure when |alpha| exceeds it (our choice, as the cart-pole's)"},
    {"max_voltage", "V", 10.0, ICOAC_SIM_PHYS_MIN, ICOAC_SIM_PHYS_MAX, "advanced",
     "|V| applied saturates at it (the unit's amplifier: 10 V; 1e6: practically none)"},
};

/* Its task: inputs (arm angle, arm velocity, pendulum angle up to its limit, pendulum velocity)
 * and critic over the same ranges, the cart-pole's rule table and critic units, the reflex zone at
 * ICOAC_SIM_ZONE_FRACTION of the arm range and at ZONE of the pendulum, ICO rate 0.01, gain 1 V;
 * the knobs' values were chosen by its sweep (docs/sweeps-furuta.md). */
enum { ARM_RANGE, ARM_VELOCITY_RANGE, PENDULUM_VELOCITY_RANGE, ZONE, N_KNOBS };

static const icoac_sim_param_t knobs[N_KNOBS] = {
    {"arm_range", "rad", 1.0, ICOAC_SIM_PHYS_MIN, ICOAC_SIM_PHYS_MAX, "advanced",
     "task: the arm angle scaled to it (and the critic's grid over it)"},
    {"arm_velocity_range", "rad/s", 2.3, ICOAC_SIM_PHYS_MIN, ICOAC_SIM_PHYS_MAX, "advanced",
     "task: the arm velocity scaled to it"},
    {"pendulum_velocity_range", "rad/s", 0.6, ICOAC_SIM_PHYS_MIN, ICOAC_SIM_PHYS_MAX, "advanced",
     "task: the pendulum velocity scaled to it"},
    {"zone_deg", "deg", 8.0, ICOAC_SIM_PHYS_MIN, 90.0, "advanced",
     "task: the pendulum's reflex zone starts at this angle"},
};

static void task_settings(const double *knob, icoac_config_t *cfg)
{
    const double range[4] = {knob[ARM_RANGE], knob[ARM_VELOCITY_RANGE], params[PENDULUM_LIMIT].value,
                             knob[PENDULUM_VELOCITY_RANGE]};
    const double zone_arm = ICOAC_SIM_ZONE_FRACTION * range[0], zone_pendulum = knob[ZONE] * (ICOAC_SIM_PI / 180.0);
    const double threshold[4] = {zone_pendulum, -zone_arm, -zone_pendulum, zone_arm}; /* the rules' order */
    int i;
    for (i = 0; i < 4; ++i) {
        cfg->policy.input_range[i] = (icoac_real_t)range[i];
        cfg->critic.range[i] = (icoac_real_t)range[i];
        cfg->task.rule_threshold[i] = (icoac_real_t)threshold[i];
    }
    cfg->ico.rate = (icoac_real_t)0.01;
    cfg->policy.gain = (icoac_real_t)1.0;
}

/* Learner settings by its learner sweeps (docs/sweeps-furuta.md): ICO->RL takes RL alone's
 * (mean) reading; the prior's decomposition takes those of the learner whose prior mean it shares. */
static void ico_mean_learners(icoac_config_t *cfg)
{
    cfg->actor.update = ICOAC_ACTOR_MEAN;
    cfg->actor.likelihood_std = (icoac_real_t)0.1;
    cfg->actor.scale = (icoac_real_t)0.1;
    cfg->actor.noise_std = (icoac_real_t)1.0;
}

static void zero_mean_learners(icoac_config_t *cfg)
{
    cfg->actor.noise_std = (icoac_real_t)3.0; /* V */
}

static const icoac_sim_learner_t learners[2] = {{"ico-rl ico-mean-rl", ico_mean_learners},
                                                {"rl rl-ico-cov", zero_mean_learners}};

static const icoac_sim_task_t task = {
    "its sweep (docs/sweeps-furuta.md): input scaling, reflex zone, ICO rate, gain", task_settings, N_KNOBS, 0, knobs, 2,
    0, learners, 0};

const icoac_sim_plant_desc_t sim_furuta = {
    "furuta",
    "Furuta pendulum (Quanser QUBE-Servo 2), motor voltage on the arm",
    "Quanser QUBE-Servo 2 User Manual (system parameters); Acosta, Math. Probl. Eng. 2010, "
    "article 742894; Cazzolato & Prime, J. Control Sci. Eng. 2011",
    {"voltage", "V"},
    {MAX_VOLTAGE, 0, 10.0, "Quanser QUBE-Servo 2 User Manual: the amplifier's +-10 V (the default)"},
    4,
    N_PARAMS,
    {{"theta", "rad"}, {"theta_dot", "rad/s"}, {"alpha", "rad"}, {"alpha_dot", "rad/s"}},
    params,
    {2, 25, -12.0, 1.0, 1, 0},  /* alpha0: -12..12 deg */
    {0, 49, -90.0, 3.75, 1, 0}, /* theta0: -90..90 deg */
    {0.0, 0.0, 0.0, 0.0},
    {0, 1, 0, 1},
    {0, 1, 2, 3},
    step,
    derivatives,
    failed,
    energy,
    &task,
};
