/* SPDX-License-Identifier: Apache-2.0 */
/* The plant registry: one entry per plant file in src/plants/ (docs/plants.md). The cart-pole
 * stays first (ICOAC_SIM_CART_POLE). */
#include <string.h>

#include "icoac_sim/icoac_sim.h"

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
