/* SPDX-License-Identifier: Apache-2.0 */
/* The benchmark on registry plants other than the cart-pole (icoac_sim_run_cell,
 * icoac_sim_run_grid, icoac_sim_trajectory; the cart-pole's runs are in test_engine.c): a Furuta
 * pendulum grid runs its own dynamics and failure test, the 6-state double pendulum runs with a
 * task of 6 inputs, and a task of another size is refused. */
#include "test_common.h"

#include "test_sim_common.h"

static icoac_sim_model_t model_of(int32_t index)
{
    icoac_sim_model_t model;
    TEST_ASSERT_EQUAL_INT(ICOAC_SIM_OK, icoac_sim_model_default(&model, index));
    return model;
}

/* A Furuta grid with the controller's zero policy and no learning: every trial follows the
 * plant's own dynamics from the cell's start, and fails by the plant's own limits. The same cell
 * replayed by hand (model start, steps, failure test) gives the trial lengths. */
static void test_furuta_grid(void)
{
    const int32_t furuta = icoac_sim_plant_find("furuta");
    const icoac_sim_run_t run = test_small_run(3, 2000);
    const icoac_sim_model_t model = model_of(furuta);
    const icoac_sim_plant_desc_t *desc = icoac_sim_plant_info(furuta);
    const int64_t n = (int64_t)desc->rows.count * desc->cols.count;
    static icoac_sim_cell_t cells[25 * 49], again[25 * 49];
    icoac_config_t cfg = test_default_config();
    const int64_t picks[3] = {0, n / 2 + 3, n - 1};
    int p;
    TEST_ASSERT_TRUE(furuta > 0);
    cfg.learn = 0;
    cfg.policy.gain = ICOAC_R(0.0);
    cfg.policy.reflex_mode = ICOAC_REFLEX_GAIN; /* F = G (z + U) = 0 */
    TEST_ASSERT_EQUAL_INT(ICOAC_SIM_OK, icoac_sim_plant_grid(furuta, cells, n, 3u));
    memcpy(again, cells, sizeof cells);
    TEST_ASSERT_EQUAL_INT(ICOAC_SIM_OK, icoac_sim_run_grid(&cfg, &model, &run, NULL, cells, n, 2, NULL, NULL));
    TEST_ASSERT_EQUAL_INT(ICOAC_SIM_OK, icoac_sim_run_grid(&cfg, &model, &run, NULL, again, n, 1, NULL, NULL));
    TEST_ASSERT_EQUAL_MEMORY(again, cells, (size_t)n * sizeof cells[0]);
    for (p = 0; p < 3; ++p) {
        const icoac_sim_cell_t *cell = &cells[picks[p]];
        icoac_rng_t rng;
        int64_t total = 0;
        int64_t trial;
        int64_t steps = 0;
        TEST_ASSERT_EQUAL_INT(ICOAC_SIM_FAILED, cell->outcome);
        TEST_ASSERT_EQUAL_INT64(run.max_trials, cell->trials);
        icoac_rng_seed(&rng, cell->seed, ICOAC_SIM_START_STREAM);
        for (trial = 0; trial < run.max_trials; ++trial) {
            double s[ICOAC_SIM_MAX_STATE];
            int32_t failed = 0;
            TEST_ASSERT_EQUAL_INT(ICOAC_SIM_OK, icoac_sim_model_start(&model, cell, run.init_velocity_noise, &rng, s));
            for (steps = 0; !failed && steps < run.success_steps;) {
                TEST_ASSERT_EQUAL_INT(ICOAC_SIM_OK, icoac_sim_model_step(&model, s, 0.0));
                ++steps;
                TEST_ASSERT_EQUAL_INT(ICOAC_SIM_OK, icoac_sim_model_failed(&model, s, &failed));
            }
            TEST_ASSERT_TRUE(failed);
            total += steps;
        }
        TEST_ASSERT_EQUAL_INT64(total, cell->total_steps);
        TEST_ASSERT_EQUAL_INT64(steps, cell->last_trial_steps);
        TEST_ASSERT_TRUE(cell->elapsed_time == model.dt * (double)total);
    }
}

/* A trajectory of the Furuta pendulum: rows of its four components, from the cell's start. */
static void test_furuta_trajectory(void)
{
    const int32_t furuta = icoac_sim_plant_find("furuta");
    const icoac_sim_model_t model = model_of(furuta);
    icoac_config_t cfg = test_default_config();
    double states[51 * 4], forces[50];
    int64_t steps = -1;
    int64_t k;
    TEST_ASSERT_EQUAL_INT(ICOAC_SIM_OK,
                          icoac_sim_trajectory(&cfg, &model, NULL, 0.4, -0.05, 0.0, 1u, 50, states, forces, &steps));
    TEST_ASSERT_TRUE(steps >= 1 && steps <= 50);
    TEST_ASSERT_TRUE(states[0] == 0.4 && states[1] == 0.0 && states[2] == -0.05 && states[3] == 0.0);
    for (k = 0; k < steps; ++k) {
        double s[ICOAC_SIM_MAX_STATE] = {0.0};
        memcpy(s, states + 4 * k, 4 * sizeof s[0]);
        TEST_ASSERT_EQUAL_INT(ICOAC_SIM_OK, icoac_sim_model_step(&model, s, forces[k]));
        TEST_ASSERT_EQUAL_MEMORY(states + 4 * (k + 1), s, 4 * sizeof s[0]);
    }
}

/* The double pendulum with a task of its 6 inputs (the cart-pole's rules on x and theta1): the
 * trajectory is the model's steps under the recorded forces, and a grid's cells end with weights
 * on all six inputs (the engine feeds the controller every state component). */
static void test_double_pendulum_six_inputs(void)
{
    const icoac_sim_model_t model = model_of(icoac_sim_plant_find("double_cart_pole"));
    const icoac_sim_run_t run = test_small_run(20, 200);
    icoac_config_t cfg = test_default_config();
    icoac_sim_cell_t cells[2];
    double states[31 * 6], forces[30];
    int64_t steps = -1;
    int64_t k;
    int i;
    cfg.task.n_inputs = 6;
    for (i = 4; i < 6; ++i) {
        cfg.policy.input_range[i] = ICOAC_R(1.0);
        cfg.critic.range[i] = ICOAC_R(1.0);
        cfg.critic.units[i] = 1;
    }
    TEST_ASSERT_EQUAL_INT(ICOAC_OK, icoac_config_check(&cfg));
    TEST_ASSERT_EQUAL_INT(ICOAC_SIM_OK,
                          icoac_sim_trajectory(&cfg, &model, NULL, 0.2, 0.1, 0.0, 3u, 30, states, forces, &steps));
    TEST_ASSERT_TRUE(steps >= 1 && steps <= 30);
    TEST_ASSERT_TRUE(states[0] == 0.2 && states[2] == 0.1 && states[4] == 0.0);
    for (k = 0; k < steps; ++k) {
        double s[ICOAC_SIM_MAX_STATE] = {0.0};
        memcpy(s, states + 6 * k, 6 * sizeof s[0]);
        TEST_ASSERT_EQUAL_INT(ICOAC_SIM_OK, icoac_sim_model_step(&model, s, forces[k]));
        TEST_ASSERT_EQUAL_MEMORY(states + 6 * (k + 1), s, 6 * sizeof s[0]);
    }
    memset(cells, 0, sizeof cells);
    cells[1].x0 = -0.5; /* near upright: the links fall slowly enough for the reflex to teach ICO */
    cells[1].theta0 = -0.05;
    cells[0].seed = 1u;
    cells[1].seed = 2u;
    TEST_ASSERT_EQUAL_INT(ICOAC_SIM_OK, icoac_sim_run_grid(&cfg, &model, &run, NULL, cells, 2, 1, NULL, NULL));
    for (i = 0; i < 2; ++i) {
        TEST_ASSERT_EQUAL_INT(ICOAC_OK, cells[i].status);
        TEST_ASSERT_TRUE(cells[i].outcome == ICOAC_SIM_SUCCESS || cells[i].outcome == ICOAC_SIM_FAILED);
        TEST_ASSERT_TRUE(cells[i].weights[4] != 0.0 || cells[i].weights[5] != 0.0); /* theta2 reached ICO */
    }
}

/* Refused: a task whose input count is not the plant's (the cart-pole's 4-input task on the
 * 6-state double pendulum), a model outside its ranges, NULL; the cells are left as they were. */
static void test_refused(void)
{
    const icoac_sim_run_t run = test_small_run(2, 10);
    icoac_config_t cfg = test_default_config();
    icoac_sim_model_t model = model_of(icoac_sim_plant_find("double_cart_pole"));
    icoac_sim_cell_t cells[2], before[2];
    double states[8], forces[1];
    int64_t steps = 0;
    memset(cells, 0, sizeof cells);
    cells[1].x0 = 0.1;
    memcpy(before, cells, sizeof cells);
    TEST_ASSERT_EQUAL_INT(ICOAC_SIM_ERR_BAD_PLANT,
                          icoac_sim_run_grid(&cfg, &model, &run, NULL, cells, 2, 1, NULL, NULL));
    TEST_ASSERT_EQUAL_INT(ICOAC_SIM_ERR_BAD_PLANT, icoac_sim_run_cell(&cfg, &model, &run, NULL, cells, NULL, NULL));
    TEST_ASSERT_EQUAL_INT(ICOAC_SIM_ERR_BAD_PLANT,
                          icoac_sim_trajectory(&cfg, &model, NULL, 0.0, 0.0, 0.0, 1u, 1, states, forces, &steps));
    model = model_of(icoac_sim_plant_find("furuta"));
    model.param[0] = -1.0;
    TEST_ASSERT_EQUAL_INT(ICOAC_SIM_ERR_BAD_PLANT,
                          icoac_sim_run_grid(&cfg, &model, &run, NULL, cells, 2, 1, NULL, NULL));
    model.param[0] = 9.81;
    model.dt = 0.0;
    TEST_ASSERT_EQUAL_INT(ICOAC_SIM_ERR_BAD_PLANT, icoac_sim_run_cell(&cfg, &model, &run, NULL, cells, NULL, NULL));
    TEST_ASSERT_EQUAL_INT(ICOAC_SIM_ERR_BAD_ARGUMENT,
                          icoac_sim_run_grid(&cfg, NULL, &run, NULL, cells, 2, 1, NULL, NULL));
    TEST_ASSERT_EQUAL_INT(ICOAC_SIM_ERR_BAD_ARGUMENT, icoac_sim_run_cell(NULL, &model, &run, NULL, cells, NULL, NULL));
    TEST_ASSERT_EQUAL_INT(ICOAC_SIM_ERR_BAD_ARGUMENT, icoac_sim_run_grid(&cfg, NULL, &run, NULL, cells, 2, 1, NULL, NULL));
    TEST_ASSERT_EQUAL_MEMORY(before, cells, sizeof cells);
}

/* A NULL run is refused like any NULL argument, the cells left as they were (found by fuzz_model:
 * the grid runner passed the checks without a run, and its first trial start read through the
 * NULL pointer). */
static void test_grid_null_run(void)
{
    icoac_config_t cfg = test_default_config();
    const icoac_sim_model_t model = model_of(icoac_sim_plant_find("furuta"));
    const icoac_sim_model_t cart_pole = model_of(ICOAC_SIM_CART_POLE);
    icoac_sim_cell_t cells[2], before[2];
    memset(cells, 0, sizeof cells);
    cells[1].x0 = 0.1;
    memcpy(before, cells, sizeof cells);
    TEST_ASSERT_EQUAL_INT(ICOAC_SIM_ERR_BAD_ARGUMENT,
                          icoac_sim_run_grid(&cfg, &model, NULL, NULL, cells, 2, 1, NULL, NULL));
    TEST_ASSERT_EQUAL_INT(ICOAC_SIM_ERR_BAD_ARGUMENT, icoac_sim_run_grid(&cfg, &cart_pole, NULL, NULL, cells, 2, 2, NULL, NULL));
    TEST_ASSERT_EQUAL_INT(ICOAC_SIM_ERR_BAD_ARGUMENT, icoac_sim_run_cell(&cfg, &model, NULL, NULL, cells, NULL, NULL));
    TEST_ASSERT_EQUAL_MEMORY(before, cells, sizeof cells);
}

void setUp(void) {}
void tearDown(void) {}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_furuta_grid);
    RUN_TEST(test_furuta_trajectory);
    RUN_TEST(test_double_pendulum_six_inputs);
    RUN_TEST(test_refused);
    RUN_TEST(test_grid_null_run);
    return UNITY_END();
}
