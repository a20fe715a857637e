/* SPDX-License-Identifier: Apache-2.0 */
/* A firmware project's use of icoac: configure, initialise, a few 100 Hz ticks, the version. */
#include <stdio.h>
#include <string.h>

#include "icoac/icoac.h"
#include "icoac/icoac_version.h"

static icoac_config_t cfg;
static icoac_state_t state;

int main(void)
{
    icoac_input_t in;
    icoac_output_t out;
    int k;

    icoac_config_default(&cfg);
    if (icoac_init(&cfg, &state, NULL, 1u) != ICOAC_OK) {
        return 1;
    }
    memset(&in, 0, sizeof in);
    for (k = 0; k < 5; ++k) {
        in.s[ICOAC_IDX_THETA] = 0.06f * (float)k; /* the pole falls past the reflex zone */
        if (icoac_step(&state, &in, &out) != ICOAC_OK) {
            return 2;
        }
        printf("tick %d force %.3f\n", k, (double)out.force);
    }
    printf("icoac %s (header %s, ABI %u), maxima %d inputs %d rules %d critic units, state %u bytes\n", icoac_version(),
           ICOAC_VERSION_STRING, (unsigned)icoac_abi_version(), ICOAC_MAX_INPUTS, ICOAC_MAX_RULES, ICOAC_MAX_CRITIC_UNITS,
           (unsigned)sizeof state);
    return strcmp(icoac_version(), ICOAC_VERSION_STRING) == 0 ? 0 : 3;
}
