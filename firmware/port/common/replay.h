/* SPDX-License-Identifier: Apache-2.0 */
/* Replay of recorded closed-loop observation sequences through icoac_step.
 *
 * Shared by the target example (main_target.c) and the host reference build
 * (tests/target/host_main.c), so both run the same code on the same inputs.
 */
#ifndef ICOAC_PORT_REPLAY_H
#define ICOAC_PORT_REPLAY_H

#include <stdint.h>

#include "icoac/icoac.h"

#define REPLAY_FLAG_TERMINAL 1u /* pass ICOAC_INPUT_TERMINAL */
#define REPLAY_FLAG_RESET 2u    /* call icoac_reset before this tick (new trial) */

typedef struct {
    float s[ICOAC_CARTPOLE_INPUTS]; /* observation as the host controller saw it */
    uint8_t flags;           /* REPLAY_FLAG_* */
} replay_tick_t;

typedef icoac_status_t (*replay_step_fn)(icoac_state_t *state, const icoac_input_t *in, icoac_output_t *out);

/* Kind of a tick, passed to the per-tick hooks of a non-verbose run. */
#define REPLAY_TICK_PLAIN 0u  /* every tick but the next kind (trial starts included) */
#define REPLAY_TICK_UPDATE 1u /* search: the terminal tick that closes a batch of
                                 REPLAY_SEARCH_BATCH trials and runs the update */

/* Provided by the platform (target: semihosting; host: stdout). */
void port_puts(const char *s);
/* Called right before and after the tick loop with the stack pointer of the loop's frame
 * (0 on the host). The target paints the stack and reads its timer here. */
void port_ticks_begin(uintptr_t sp);
void port_ticks_end(uintptr_t sp);
/* Called before every tick of a non-verbose run (before its icoac_reset, if any) and after it
 * (timing of the slowest tick and of the update ticks; stack of the update ticks). */
void port_tick_start(uint32_t kind);
void port_tick_done(uint32_t kind);
uintptr_t port_read_sp(void);

/* One controller instance, owned by the caller (the library keeps no state of its own). */
typedef struct {
    icoac_config_t cfg;
    icoac_state_t state;
} replay_controller_t;

/* Not a controller mode: the RL sequence with the paper's literal actor reading (posterior
 * update, exploration always on, per tick), whatever the defaults are. */
#define REPLAY_RL_LITERAL 0x100
/* Not a controller mode either: the RL sequence with the batch granularity (actor.batch = 1,
 * posterior reading): the closed form at each trial's end, the deepest path of a tick. */
#define REPLAY_RL_BATCH 0x101

/* The configuration replay_run uses for mode (ICOAC_MODE_*, REPLAY_RL_LITERAL, REPLAY_RL_BATCH). */
void replay_config(icoac_config_t *cfg, int32_t mode);

/* Run sequence mode (ICOAC_MODE_ICO / ICOAC_MODE_RL / ICOAC_MODE_SEARCH / REPLAY_RL_LITERAL /
 * REPLAY_RL_BATCH)
 * with step on ctrl (re-initialised; default configuration but search.batch =
 * REPLAY_SEARCH_BATCH); print each tick and then the posterior when verbose. Returns the
 * number of ticks, or 0 on an init error. */
uint32_t replay_run(replay_controller_t *ctrl, int32_t mode, replay_step_fn step, int verbose);

/* Formatting helpers (no printf: newlib's float printf allocates). */
char *replay_fmt_u32(char *p, uint32_t v);
char *replay_fmt_hex32(char *p, uint32_t v);
char *replay_fmt_real(char *p, float v); /* hex bits, ':', decimal with 6 digits */

#endif
