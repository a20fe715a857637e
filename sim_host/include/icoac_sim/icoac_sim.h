/* SPDX-License-Identifier: Apache-2.0 */
/* icoac_sim: a registry of plants, the benchmark trial loop and the grid runner for the icoac
 * controller. Host-only C11; exported as a shared library for the Python harness. */
#ifndef ICOAC_SIM_H
#define ICOAC_SIM_H

#include <stdint.h>

#include "icoac/icoac.h"

#ifdef __cplusplus
extern "C" {
#endif

#define ICOAC_SIM_ABI_VERSION 10

/* Status of sim functions: values below 100 are icoac_status_t, passed through. */
typedef enum {
    ICOAC_SIM_OK = 0,
    ICOAC_SIM_ERR_BAD_PLANT = 100,    /* plant parameter not finite / out of range */
    ICOAC_SIM_ERR_BAD_RUN = 101,      /* run parameter out of range */
    ICOAC_SIM_ERR_BAD_ARGUMENT = 102, /* NULL pointer, zero length or bad cell */
    ICOAC_SIM_ERR_THREAD = 103,       /* a worker thread could not be started */
    ICOAC_SIM_CANCELLED = 104,        /* the cancel flag was raised; finished cells are kept */
    ICOAC_SIM_ERR_NONFINITE = 105     /* plant state or input not finite, or made so by a step */
} icoac_sim_status_t;

typedef enum {
    ICOAC_SIM_EULER = 0, /* explicit Euler, Sutton's update order (method.md, A1) */
    ICOAC_SIM_RK4 = 1    /* classical Runge-Kutta, same dt */
} icoac_sim_integrator_t;

#define ICOAC_SIM_PI 3.14159265358979323846

/* The most cells a thread of icoac_sim_run_grid advances in lockstep (the run's `lanes`): each
 * lane's controller tick, then one plant step for all of them, vectorised over the lanes (no
 * cell's result depends on it). */
#define ICOAC_SIM_MAX_LANES 64

/* Valid plant and run ranges (closed): no subnormal or absurd value reaches the integrator,
 * whose worker threads flush subnormals to zero. */
#define ICOAC_SIM_PHYS_MIN 1.0e-6   /* the shipped plants' physical parameters: gravity, masses, lengths */
#define ICOAC_SIM_PHYS_MAX 1.0e6
#define ICOAC_SIM_DT_MIN 1.0e-6     /* dt (s) */
#define ICOAC_SIM_DT_MAX 1.0
#define ICOAC_SIM_THETA_LIMIT_MAX ICOAC_SIM_PI /* an angle limit (rad), >= 1e-6 */
#define ICOAC_SIM_NOISE_MIN 1.0e-12 /* init_velocity_noise: 0 or in [1e-12, 1e3] (m/s, rad/s) */
#define ICOAC_SIM_NOISE_MAX 1.0e3

/* Benchmark protocol of one cell (method.md): one row per field, as the controller's
 * (icoac_params.h, the same columns); its members, default, check and exported rows come from it. */
#define ICOAC_PARAM_PREFIX_run ""
/* clang-format off */
#define ICOAC_SIM_RUN_PARAMS(X) \
    X(run, max_trials, int64_t, scalar, at_least, "trial", 1, INT64_MAX, 100000, ICOAC_PARAM_ALL, essential, ICOAC_SIM_ERR_BAD_RUN, \
      "trials before a cell counts as failed") \
    X(run, success_steps, int64_t, scalar, at_least, "tick", 1, INT64_MAX, 100000, ICOAC_PARAM_ALL, essential, ICOAC_SIM_ERR_BAD_RUN, \
      "ticks of one trial that make a success (1e5: 1000 s)") \
    X(run, init_velocity_noise, double, scalar, real_or_zero, "state", ICOAC_SIM_NOISE_MIN, ICOAC_SIM_NOISE_MAX, 1.0e-4, ICOAC_PARAM_ALL, advanced, ICOAC_SIM_ERR_BAD_RUN, \
      "a: the drawn start components (the cart-pole's velocities) ~ U(-a, a); 0: none") \
    X(run, lanes, int64_t, scalar, int, "cell", 1, ICOAC_SIM_MAX_LANES, 16, ICOAC_PARAM_ALL, advanced, ICOAC_SIM_ERR_BAD_RUN, \
      "cells a grid thread runs in lockstep, its plant steps vectorised over them (no result depends on it)")
/* clang-format on */
typedef struct {
    ICOAC_SIM_RUN_PARAMS(ICOAC_PARAM_MEMBER)
} icoac_sim_run_t;

typedef enum {
    ICOAC_SIM_PENDING = 0, /* not run yet (or cancelled mid-run) */
    ICOAC_SIM_SUCCESS = 1, /* a trial lasted success_steps */
    ICOAC_SIM_FAILED = 2,  /* max_trials trials, none successful */
    ICOAC_SIM_ERROR = 3    /* the controller reported an error (e.g. ICOAC_ERR_NUMERIC); see status */
} icoac_sim_outcome_t;

/* One cell: the caller fills x0, theta0, seed; the run fills the rest. x0 is the start of the
 * plant grid's column component and theta0 that of its row component, in the plant's units
 * (icoac_sim_plant_grid; the cart-pole's x and theta). */
typedef struct {
    double x0;                  /* m (the cart-pole's x; a plant's column component) */
    double theta0;              /* rad (the cart-pole's theta; a plant's row component) */
    uint64_t seed;              /* drives initial velocities and exploration */
    int32_t outcome;            /* icoac_sim_outcome_t */
    int32_t status;             /* icoac_status_t / icoac_sim_status_t of the run */
    int64_t trials;             /* trials run, the successful one included */
    int64_t total_steps;        /* steps over all trials */
    int64_t last_trial_steps;   /* length of the final trial */
    double elapsed_time;        /* s: dt * total_steps */
    double weights[ICOAC_MAX_INPUTS];                   /* final w (ICO) or mu_w (RL); task.n_inputs used, 0 after */
    double cov[ICOAC_MAX_INPUTS][ICOAC_MAX_INPUTS];     /* final Sigma_w (RL); the leading n x n block */
} icoac_sim_cell_t;

/* Indices of the progress array given to icoac_sim_run_grid. A thread adds a cell's trials and
 * steps every 64 trials of it, at its end and at a cancel: a reader sees them with that lag. */
#define ICOAC_SIM_PROGRESS_CELLS 0  /* cells finished */
#define ICOAC_SIM_PROGRESS_TRIALS 1 /* trials finished */
#define ICOAC_SIM_PROGRESS_STEPS 2  /* plant steps of those trials */
#define ICOAC_SIM_PROGRESS_LEN 3

const char *icoac_sim_status_str(int32_t status);
uint32_t icoac_sim_abi_version(void);
uint32_t icoac_sim_sizeof_run(void);
uint32_t icoac_sim_sizeof_cell(void);

void icoac_sim_run_default(icoac_sim_run_t *run);
int32_t icoac_sim_run_check(const icoac_sim_run_t *run);

/* Constants and struct layouts for bindings, so that C is their single source. */
typedef struct {
    const char *name; /* the C macro or enum name, e.g. "ICOAC_MODE_RL" */
    double value;
} icoac_sim_constant_t;

typedef struct {
    const char *type;  /* "icoac_config_t", ... */
    const char *field; /* member designator, e.g. "policy.gain" or "cov" */
    uint32_t offset;   /* offsetof(type, field) */
    uint32_t size;     /* sizeof the member */
} icoac_sim_field_t;

/* One parameter of the controller (a row of icoac_params.h) or of a run (ICOAC_SIM_RUN_PARAMS),
 * with its place in its struct: what bindings, the command line and the docs know of it. */
typedef struct {
    const char *type;   /* its struct: "icoac_config_t" or "icoac_sim_run_t" */
    const char *name;   /* member designator, e.g. "policy.gain", "max_trials" */
    const char *group;  /* "config" (the top level), "task", ..., "search"; "run" */
    const char *ctype;  /* "icoac_real_t", "int32_t", "int64_t", "double" */
    const char *dim;    /* "scalar", "inputs" (ICOAC_MAX_INPUTS entries) or "rules" (ICOAC_MAX_RULES) */
    const char *check;  /* real, real_open_lo, real_open_hi, real_or_zero, int, at_least, flag, choice, sign, index, units */
    const char *unit;
    const char *tier;   /* "essential" or "advanced" */
    const char *doc;    /* one line */
    double min;
    double max;
    double def;         /* default of a scalar (arrays: the task preset's) */
    uint32_t modes;     /* ICOAC_PARAM_ICO | ICOAC_PARAM_RL | ICOAC_PARAM_SEARCH */
    int32_t status;     /* status of a value the check refuses */
    uint32_t offset;    /* offsetof(type, name) */
    uint32_t size;      /* sizeof the member */
} icoac_sim_param_row_t;

/* Static tables; *count receives their length. */
const icoac_sim_constant_t *icoac_sim_constants(int32_t *count);
const icoac_sim_field_t *icoac_sim_fields(int32_t *count);
const icoac_sim_param_row_t *icoac_sim_param_table(int32_t *count);

/* ---- Plant registry (docs/plants.md) -------------------------------------------------------
 * Every plant is a descriptor: its state, parameters, dynamics, failure test, grid of initial
 * conditions and controller task. The cart-pole is the registry's first plant. */
#define ICOAC_SIM_MAX_STATE 6   /* state components of any plant */
#define ICOAC_SIM_MAX_PARAMS 16 /* parameters of any plant */
#define ICOAC_SIM_MAX_TASK_KNOBS 8 /* knobs of any plant's task */
#define ICOAC_SIM_CART_POLE 0   /* registry index of the cart-pole */

/* A named, unit-carrying quantity: a state component or the plant's input. */
typedef struct {
    const char *name; /* "x", "theta_dot", "voltage" */
    const char *unit; /* "m", "rad/s", "V" */
} icoac_sim_axis_t;

/* One plant parameter: valid values are 0 or normal numbers in [min, max]. What bindings, the
 * command line and the docs know of it (as of a controller parameter, icoac_params.h). */
typedef struct {
    const char *name;
    const char *unit;
    double value; /* default */
    double min;
    double max;
    const char *tier; /* "essential" (the physics) or "advanced" (the failure limits) */
    const char *doc;  /* one line */
} icoac_sim_param_t;

/* A swept start coordinate: value i (0 <= i < count) is first + step * i, converted by
 * * PI / 180 when degrees is 1 (first and step are then in degrees). */
typedef struct {
    int32_t component; /* state index */
    int32_t count;
    double first;
    double step;
    int32_t degrees;
    int32_t reserved; /* 0 */
} icoac_sim_sweep_t;

/* A plant's actuator: the parameter at which its input saturates, and the limit of a real
 * actuator of this plant, which a comparison with bounded-action learners (PPO, SAC) holds every
 * method to (`--limited`; docs/results.md). */
typedef struct {
    int32_t param;      /* index in the plant's params of the saturation limit; -1: none */
    int32_t reserved;   /* 0 */
    double limit;       /* a real actuator's limit, in that parameter's unit and range (none: 0) */
    const char *source; /* where that limit comes from, one line (none: NULL) */
} icoac_sim_actuator_t;

/* One integration step of the plant's ODE for lanes states at once (a lockstep batch of cells),
 * lane l advanced by dt under input u[l] with the integrator (icoac_sim_integrator_t); p holds
 * the parameter block. s is a structure of arrays: component i of lane l at s[i * lanes + l]
 * (one lane: the state in order). Each lane gets the arithmetic of a batch of one, bit for bit. */
typedef void (*icoac_sim_step_fn)(const double *p, double dt, int32_t integrator, double *s, const double *u,
                                  int32_t lanes);
/* ds = ds/dt at state s under input u. */
typedef void (*icoac_sim_derivatives_fn)(const double *p, const double *s, double u, double *ds);
/* failed[l] = 1 when lane l of the lanes states of s (the step's layout; one lane: the state in
 * order) is outside the plant's limits or not finite, else 0. */
typedef void (*icoac_sim_failed_fn)(const double *p, const double *s, int32_t lanes, int32_t *failed);
/* Total mechanical energy (J) of s. */
typedef double (*icoac_sim_energy_fn)(const double *p, const double *s);

/* The cart-pole's penalty zone along its track, 2.35 of 2.4 m, as a fraction of that range: the
 * shipped plants' tasks scale their own zone by it. */
#define ICOAC_SIM_ZONE_FRACTION (2.35 / 2.4)

/* Settings of some of the harness's learning conditions on a plant, over the condition's own
 * (harness/icoac/core/registry.py names the conditions). */
typedef struct {
    const char *conditions;             /* their names, space-separated: "rl rl-ico-cov" */
    void (*apply)(icoac_config_t *cfg); /* writes the settings */
} icoac_sim_learner_t;

/* The controller task a plant is benchmarked with (docs/plants.md): its inputs' ranges, rule
 * table, critic grid and learner settings, chosen for this plant. The task is written from its
 * knobs: named values (a reflex zone, a velocity range...) whose defaults are the task's choice
 * and which a sweep of the task varies. */
typedef struct {
    const char *source; /* where the settings come from, one line */
    /* writes the task from knob[n_knobs] over icoac_config_default's; NULL: those are it */
    void (*apply)(const double *knob, icoac_config_t *cfg);
    int32_t n_knobs;                /* <= ICOAC_SIM_MAX_TASK_KNOBS */
    int32_t reserved;               /* 0 */
    const icoac_sim_param_t *knobs; /* n_knobs entries: name, unit, the task's value, range, tier, doc */
    int32_t n_learners;
    int32_t paper; /* 1: the paper's plant and task, so that its published results apply */
    const icoac_sim_learner_t *learners; /* n_learners entries; a condition in at most one */
    /* NULL, or why the ICO prior averages every finished ICO cell of this plant, not only the
     * successful ones (ICO balances too few of them for a prior) */
    const char *prior_all_finished;
} icoac_sim_task_t;

typedef struct {
    const char *name;   /* registry key, e.g. "furuta" */
    const char *title;  /* one line for humans */
    const char *source; /* where the equations and default parameters come from */
    icoac_sim_axis_t input;
    icoac_sim_actuator_t actuator;
    int32_t n_state;    /* <= ICOAC_SIM_MAX_STATE */
    int32_t n_params;   /* <= ICOAC_SIM_MAX_PARAMS */
    icoac_sim_axis_t state[ICOAC_SIM_MAX_STATE];
    const icoac_sim_param_t *params; /* n_params entries */
    /* Grid of initial conditions: rows sweep one component (a cell's theta0), columns another
     * (its x0); the other components start at start[], and those with drawn[i] = 1 then get
     * U(-a, a), a = the run's init_velocity_noise, drawn in index order. */
    icoac_sim_sweep_t rows;
    icoac_sim_sweep_t cols;
    double start[ICOAC_SIM_MAX_STATE];
    int32_t drawn[ICOAC_SIM_MAX_STATE];
    /* Controller input i reads state component observed[i] (n_state entries, -1: none). */
    int32_t observed[ICOAC_SIM_MAX_STATE];
    icoac_sim_step_fn step;
    icoac_sim_derivatives_fn derivatives;
    icoac_sim_failed_fn failed;
    icoac_sim_energy_fn energy; /* NULL when the plant has none */
    const icoac_sim_task_t *task; /* NULL: the plant has no task yet, and the harness refuses it */
} icoac_sim_plant_desc_t;

/* A registry plant with its parameter block and the engine's integration options. */
typedef struct {
    int32_t plant;      /* registry index */
    int32_t integrator; /* icoac_sim_integrator_t */
    double dt;          /* s, [1e-6, 1] */
    double param[ICOAC_SIM_MAX_PARAMS]; /* the descriptor's parameters in its order; the rest 0 */
} icoac_sim_model_t;

/* Plants in the registry; the descriptor of plant i (NULL when out of range); the index of the
 * plant named name (-1 when none is). */
int32_t icoac_sim_plant_count(void);
const icoac_sim_plant_desc_t *icoac_sim_plant_info(int32_t index);
int32_t icoac_sim_plant_find(const char *name);

/* icoac_config_default, then the task of plant index (icoac_sim_task_t) written from knob (its
 * task's n_knobs values in order; NULL: their defaults). ICOAC_SIM_ERR_BAD_PLANT for an unknown
 * plant, one without a task, or a knob that is not finite or outside its range (cfg left as it
 * was). */
int32_t icoac_sim_plant_task(int32_t index, const double *knob, icoac_config_t *cfg);
/* The plant's settings of the learning condition named condition over cfg, when its task has
 * some (else cfg is left as it was); ICOAC_SIM_ERR_BAD_PLANT as icoac_sim_plant_task. */
int32_t icoac_sim_plant_learner(int32_t index, const char *condition, icoac_config_t *cfg);

/* Model of plant index with its default parameters, dt 0.01 s and Euler. */
int32_t icoac_sim_model_default(icoac_sim_model_t *model, int32_t index);
/* ICOAC_SIM_ERR_BAD_PLANT for an unknown plant, a parameter outside its range, a bad dt or
 * integrator, or a nonzero unused parameter. */
int32_t icoac_sim_model_check(const icoac_sim_model_t *model);

/* State arrays hold ICOAC_SIM_MAX_STATE values, of which the plant's n_state are read/written.
 * Bad input gets a status, the state left as it was: ICOAC_SIM_ERR_BAD_PLANT (model),
 * ICOAC_SIM_ERR_NONFINITE (state or u not finite, or the step made them so). */
int32_t icoac_sim_model_step(const icoac_sim_model_t *model, double state[ICOAC_SIM_MAX_STATE], double u);
int32_t icoac_sim_model_derivatives(const icoac_sim_model_t *model, const double state[ICOAC_SIM_MAX_STATE],
                                    double u, double ds[ICOAC_SIM_MAX_STATE]);
/* *failed = 1 when the state is outside the plant's limits or not finite, else 0. */
int32_t icoac_sim_model_failed(const icoac_sim_model_t *model, const double state[ICOAC_SIM_MAX_STATE],
                               int32_t *failed);
/* Steps lanes states (states: lanes rows of ICOAC_SIM_MAX_STATE values) one period each, lane i
 * under u[i], for a policy evaluated outside the controller on many cells at once. A lane whose
 * ended[i] is nonzero is left alone; a lane that fails the plant's test, or whose state or input
 * is not finite or would become so (its state then kept), gets ended[i] = 1. Statuses:
 * ICOAC_SIM_ERR_BAD_PLANT (model), ICOAC_SIM_ERR_BAD_ARGUMENT (lanes < 0, or a NULL array). */
int32_t icoac_sim_model_step_lanes(const icoac_sim_model_t *model, double *states, const double *u,
                                   int32_t *ended, int64_t lanes);
/* ICOAC_SIM_ERR_BAD_ARGUMENT when the plant has no energy function. */
int32_t icoac_sim_model_energy(const icoac_sim_model_t *model, const double state[ICOAC_SIM_MAX_STATE],
                               double *energy);

/* The plant's grid (rows.count * cols.count cells, row-major): theta0 = the row value, x0 = the
 * column value, seed = icoac_mix_seed(seed, cell index), outcome PENDING. The cart-pole's is the
 * paper's grid: row i is theta0 = (-12 + i) deg, column j is x0 = -2.4 + 0.1 j m. */
int32_t icoac_sim_plant_grid(int32_t index, icoac_sim_cell_t *cells, int64_t n_cells, uint64_t seed);
/* Start state of a trial from cell: start[], the swept components from the cell, the drawn ones
 * U(-noise, noise) from rng (the trial loop's start). The engine seeds that rng
 * with icoac_rng_seed(&rng, cell seed, ICOAC_SIM_START_STREAM). */
#define ICOAC_SIM_START_STREAM 2u
int32_t icoac_sim_model_start(const icoac_sim_model_t *model, const icoac_sim_cell_t *cell, double noise,
                              icoac_rng_t *rng, double state[ICOAC_SIM_MAX_STATE]);

/* The benchmark (method.md) on a registry plant. Trials start by icoac_sim_model_start; the
 * controller's task reads all the plant's n_state components (task.n_inputs = n_state; the plant
 * observes its state in order), and a task of another size is refused with
 * ICOAC_SIM_ERR_BAD_PLANT. */

/* One independent run of a cell from a fresh controller (prior NULL: icoac_init default). */
int32_t icoac_sim_run_cell(const icoac_config_t *cfg, const icoac_sim_model_t *model,
                           const icoac_sim_run_t *run, const icoac_prior_t *prior,
                           icoac_sim_cell_t *cell, const volatile int32_t *cancel,
                           volatile int64_t *progress);

/* Run every PENDING cell on n_threads threads (0: all cores). Finished cells are final,
 * so a cancelled grid resumes by calling again. cancel and progress may be NULL;
 * progress has ICOAC_SIM_PROGRESS_LEN counters, updated atomically. */
int32_t icoac_sim_run_grid(const icoac_config_t *cfg, const icoac_sim_model_t *model,
                           const icoac_sim_run_t *run, const icoac_prior_t *prior,
                           icoac_sim_cell_t *cells, int64_t n_cells, int32_t n_threads,
                           const volatile int32_t *cancel, volatile int64_t *progress);

/* One trial from (x0, theta0) with the controller initialised from prior (learning on),
 * recording up to max_steps ticks: states holds (max_steps + 1) rows of the plant's n_state
 * values (the start included), forces max_steps inputs. *n_steps receives the ticks run (fewer
 * if the plant failed). */
int32_t icoac_sim_trajectory(const icoac_config_t *cfg, const icoac_sim_model_t *model,
                             const icoac_prior_t *prior, double x0, double theta0,
                             double init_velocity_noise, uint64_t seed, int64_t max_steps,
                             double *states, double *forces, int64_t *n_steps);

#ifdef __cplusplus
}
#endif

#endif /* ICOAC_SIM_H */
