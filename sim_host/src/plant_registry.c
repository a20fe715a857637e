/* SPDX-License-Identifier: Apache-2.0 */
/* The plant registry: one entry per plant file in src/plants/ (docs/plants.md). The cart-pole
 * stays first (ICOAC_SIM_CART_POLE). */
#include <string.h>

#include "icoac_sim/icoac_sim.h"
#include "sim_internal.h"

#define SIM_PLANTS(X) X(sim_cart_pole) X(sim_furuta) X(sim_double_cart_pole)

#define SIM_DECLARE(desc) extern const icoac_sim_plant_desc_t desc;
SIM_PLANTS(SIM_DECLARE)
#define SIM_ENTRY(desc) &desc,
static const icoac_sim_plant_desc_t *const registry[] = {SIM_PLANTS(SIM_ENTRY)};

int32_t icoac_sim_plant_count(void)
{
    return (int32_t)(sizeof registry / sizeof registry[0]);
}

const icoac_sim_plant_desc_t *icoac_sim_plant_info(int32_t index)
{
    return index >= 0 && index < icoac_sim_plant_count() ? registry[index] : 0;
}

int32_t icoac_sim_plant_find(const char *name)
{
    int32_t i;
    for (i = 0; name != 0 && i < icoac_sim_plant_count(); ++i) {
        if (strcmp(registry[i]->name, name) == 0) {
            return i;
        }
    }
    return -1;
}

int32_t icoac_sim_plant_task(int32_t index, const double *knob, icoac_config_t *cfg)
{
    const icoac_sim_plant_desc_t *desc = icoac_sim_plant_info(index);
    double value[ICOAC_SIM_MAX_TASK_KNOBS];
    int32_t i;
    if (cfg == 0) {
        return ICOAC_SIM_ERR_BAD_ARGUMENT;
    }
    if (desc == 0 || desc->task == 0 || desc->task->n_knobs < 0 || desc->task->n_knobs > ICOAC_SIM_MAX_TASK_KNOBS) {
        return ICOAC_SIM_ERR_BAD_PLANT;
    }
    for (i = 0; i < desc->task->n_knobs; ++i) {
        value[i] = knob == 0 ? desc->task->knobs[i].value : knob[i];
        if (!sim_param_valid(value[i], &desc->task->knobs[i])) {
            return ICOAC_SIM_ERR_BAD_PLANT;
        }
    }
    icoac_config_default(cfg);
    if (desc->task->apply != 0) {
        desc->task->apply(value, cfg);
    }
    return ICOAC_SIM_OK;
}

/* 1 when word is one of the space-separated words of list. */
static int has_word(const char *list, const char *word)
{
    const size_t n = strlen(word);
    const char *p = list;
    while (n > 0 && (p = strstr(p, word)) != 0) {
        if ((p == list || p[-1] == ' ') && (p[n] == ' ' || p[n] == '\0')) {
            return 1;
        }
        p += n;
    }
    return 0;
}

int32_t icoac_sim_plant_learner(int32_t index, const char *condition, icoac_config_t *cfg)
{
    const icoac_sim_plant_desc_t *desc = icoac_sim_plant_info(index);
    int32_t i;
    if (cfg == 0 || condition == 0) {
        return ICOAC_SIM_ERR_BAD_ARGUMENT;
    }
    if (desc == 0 || desc->task == 0) {
        return ICOAC_SIM_ERR_BAD_PLANT;
    }
    for (i = 0; i < desc->task->n_learners; ++i) {
        if (has_word(desc->task->learners[i].conditions, condition)) {
            desc->task->learners[i].apply(cfg);
            break;
        }
    }
    return ICOAC_SIM_OK;
}
