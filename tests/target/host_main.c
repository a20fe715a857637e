/* SPDX-License-Identifier: Apache-2.0 */
/* Host reference for the target example: same replay code, same inputs, host icoac. */
#include <stdio.h>

#include "replay.h"

void port_puts(const char *s) { fputs(s, stdout); }
void port_ticks_begin(uintptr_t sp) { (void)sp; }
void port_ticks_end(uintptr_t sp) { (void)sp; }
void port_tick_start(uint32_t kind) { (void)kind; }
void port_tick_done(uint32_t kind) { (void)kind; }
uintptr_t port_read_sp(void) { return 0u; }

int main(void)
{
    replay_controller_t ctrl;
    if (replay_run(&ctrl, ICOAC_MODE_ICO, icoac_step, 1) == 0u ||
        replay_run(&ctrl, ICOAC_MODE_RL, icoac_step, 1) == 0u ||
        replay_run(&ctrl, REPLAY_RL_BATCH, icoac_step, 1) == 0u ||
        replay_run(&ctrl, ICOAC_MODE_SEARCH, icoac_step, 1) == 0u) {
        return 1;
    }
    port_puts("END\n");
    return 0;
}
