/* SPDX-License-Identifier: Apache-2.0 */
/* icoac port example: replays the recorded closed-loop ICO, RL and search sequences through
 * icoac_step, measures instructions (SysTick under QEMU -icount shift=0) and peak stack
 * (painting), and prints every tick's outputs over semihosting.
 *
 * Output lines:  B <board> / Z config state / C calibration / M <mode> ... / T ... / P ... / END
 */
#include <stdint.h>
#include <string.h>

#include "icoac/icoac.h"
#include "replay.h"
#include "semihost.h"

#ifndef ICOAC_PORT_BOARD_NAME
#define ICOAC_PORT_BOARD_NAME "unknown"
#endif

#define SYST_CSR (*(volatile uint32_t *)0xE000E010u)
#define SYST_RVR (*(volatile uint32_t *)0xE000E014u)
#define SYST_CVR (*(volatile uint32_t *)0xE000E018u)
#define STACK_PAINT 0xC5C5C5C5u

extern uint32_t __stack_bottom[];

static uint32_t t_begin, t_end, t_last, t_max, t_update, n_update;
static uint32_t phase_delay; /* iterations of spin() before a timed loop starts */
static uintptr_t stack_low, stack_low_update, loop_sp;
/* Set for a run that repaints the stack around each update tick: stack_low is then the peak of
 * the other ticks and stack_low_update that of the update ticks (otherwise stack_low is the
 * peak of all ticks). */
static int split_stack;

void port_puts(const char *s)
{
    semihost_write0(s);
}

/* Caller's stack pointer: naked, so no frame of its own. */
__attribute__((naked, noinline)) uintptr_t port_read_sp(void)
{
    __asm__ volatile("mov r0, sp\n\tbx lr");
}

static uint32_t timer_now(void)
{
    return SYST_CVR; /* 24-bit down-counter */
}

static uint32_t timer_elapsed(uint32_t from, uint32_t to)
{
    return (from - to) & 0x00FFFFFFu;
}

/* 2 instructions per iteration (subs + bne); iterations >= 1. */
static void spin(uint32_t iterations)
{
    __asm__ volatile(".syntax unified\n1: subs %0, %0, #1\n\tbne 1b" : "+l"(iterations) : : "cc");
}

/* Paint the stack from its bottom to 16 bytes below the caller's frame. The stores are
 * volatile so that GCC does not turn the loop into a memset call, whose own frame would lie in
 * the painted area (newlib-nano's ARMv6-M memset pushes 20 bytes). */
static void stack_paint(void)
{
    volatile uint32_t *p = __stack_bottom;
    volatile uint32_t *end = (volatile uint32_t *)(port_read_sp() - 16u);
    while (p < end) {
        *p++ = STACK_PAINT;
    }
}

/* Lowest address written since the last paint (sp if nothing below sp was). */
static uintptr_t stack_scan(uintptr_t sp)
{
    uint32_t *p = __stack_bottom;
    while (*p == STACK_PAINT && (uintptr_t)p < sp) {
        ++p;
    }
    return (uintptr_t)p;
}

static void stack_keep_low(uintptr_t *low)
{
    const uintptr_t p = stack_scan(loop_sp);
    if (p < *low) {
        *low = p;
    }
}

void port_ticks_begin(uintptr_t sp)
{
    loop_sp = sp;
    stack_low = sp;
    stack_low_update = sp;
    stack_paint();
    t_max = 0u;
    t_update = 0u;
    n_update = 0u;
    if (phase_delay != 0u) {
        spin(phase_delay); /* shifts every tick against the SysTick counts */
    }
    t_begin = timer_now();
    t_last = t_begin;
}

void port_tick_start(uint32_t kind)
{
    if (split_stack && kind == REPLAY_TICK_UPDATE) {
        stack_keep_low(&stack_low); /* the ticks since the last paint */
        stack_paint();
    }
}

void port_tick_done(uint32_t kind)
{
    uint32_t now = timer_now();
    uint32_t d = timer_elapsed(t_last, now);
    if (kind == REPLAY_TICK_UPDATE) {
        t_update += d;
        ++n_update;
        if (split_stack) {
            stack_keep_low(&stack_low_update);
            stack_paint();
        }
    } else if (d > t_max) {
        t_max = d;
    }
    t_last = now;
}

void port_ticks_end(uintptr_t sp)
{
    t_end = timer_now();
    loop_sp = sp;
    stack_keep_low(&stack_low);
}

static icoac_status_t step_stub(icoac_state_t *state, const icoac_input_t *in, icoac_output_t *out)
{
    (void)state;
    (void)in;
    out->force = 0.0f;
    return ICOAC_OK;
}

static void put_kv(const char *key, uint32_t v)
{
    char buf[48];
    char *p = buf;
    *p++ = ' ';
    p = (char *)memcpy(p, key, strlen(key)) + strlen(key);
    *p++ = '=';
    (void)replay_fmt_u32(p, v);
    port_puts(buf);
}

/* SysTick counts of 2 * iterations instructions (calibration). */
static uint32_t calibrate(uint32_t iterations)
{
    uint32_t t0, t1;
    t0 = timer_now();
    spin(iterations);
    t1 = timer_now();
    return timer_elapsed(t0, t1);
}

typedef icoac_status_t (*reset_fn)(icoac_state_t *state);

static icoac_status_t reset_stub(icoac_state_t *state)
{
    (void)state;
    return ICOAC_OK;
}

/* SysTick counts of n calls of fn on ctrl (through a volatile pointer: the same call for the
 * stub and icoac_reset). */
static uint32_t time_resets(replay_controller_t *ctrl, reset_fn fn, uint32_t n)
{
    reset_fn volatile call = fn;
    uint32_t t0, i;
    t0 = timer_now();
    for (i = 0u; i < n; ++i) {
        (void)call(&ctrl->state);
    }
    return timer_elapsed(t0, timer_now());
}

#define SEARCH_PHASES 5u /* timed search runs, shifted by 1/5 SysTick count each */
#define SEARCH_RESETS 64u

/* Line "M <name> ...": SysTick counts of the whole tick loop (total: icoac_step, base: the
 * stub), of its slowest tick (max, base_max; update ticks excluded), and the painted peak
 * stack below the loop's frame. Search mode adds the update ticks: their number per run,
 * summed SysTick counts (update, update_base; also part of total and base), the peak stack of
 * the update ticks alone (stack_update; stack is then that of the other ticks) from a run that
 * repaints the stack around each update tick, and the counts of SEARCH_RESETS calls of
 * icoac_reset (reset) and of a stub (reset_base) on the state the replay left. The search is
 * timed in `phases` pairs of runs (stub, icoac_step), each started 1/phases of a SysTick count
 * later than the one before: the sums over the phases resolve an update tick to about 2/phases
 * counts instead of 2. total, base, update and update_base are sums over the phases, max and
 * base_max maxima. */
static int measure(replay_controller_t *ctrl, int32_t mode, const char *name, uint32_t count_insns)
{
    const uint32_t phases = mode == ICOAC_MODE_SEARCH ? SEARCH_PHASES : 1u;
    uint32_t n = 0u, base = 0u, base_max = 0u, base_update = 0u, total = 0u, max = 0u, update = 0u;
    uint32_t stack, stack_update = 0u, r;
    for (r = 0u; r < phases; ++r) {
        /* r / phases of a count of count_insns instructions, 2 instructions per iteration */
        phase_delay = (r * count_insns + phases) / (2u * phases);
        n = replay_run(ctrl, mode, step_stub, 0);
        base += timer_elapsed(t_begin, t_end);
        base_max = t_max > base_max ? t_max : base_max;
        base_update += t_update;
        n = replay_run(ctrl, mode, icoac_step, 0);
        total += timer_elapsed(t_begin, t_end);
        max = t_max > max ? t_max : max;
        update += t_update;
    }
    phase_delay = 0u;
    stack = (uint32_t)(loop_sp - stack_low); /* bytes below the tick loop's frame */
    port_puts("M ");
    port_puts(name);
    put_kv("ticks", n);
    put_kv("systick_total", total);
    put_kv("systick_base", base);
    put_kv("systick_max", max);
    put_kv("systick_base_max", base_max);
    if (mode == ICOAC_MODE_SEARCH) {
        put_kv("phases", phases);
        put_kv("updates", n_update);
        put_kv("systick_update", update);
        put_kv("systick_update_base", base_update);
        split_stack = 1;
        n = n == 0u ? 0u : replay_run(ctrl, mode, icoac_step, 0);
        split_stack = 0;
        stack = (uint32_t)(loop_sp - stack_low);
        stack_update = (uint32_t)(loop_sp - stack_low_update);
        put_kv("resets", SEARCH_RESETS);
        put_kv("systick_reset", time_resets(ctrl, icoac_reset, SEARCH_RESETS));
        put_kv("systick_reset_base", time_resets(ctrl, reset_stub, SEARCH_RESETS));
    }
    put_kv("stack", stack);
    if (mode == ICOAC_MODE_SEARCH) {
        put_kv("stack_update", stack_update);
    }
    port_puts("\n");
    return n == 0u;
}

/* For one call: paint every word below sp (the caller's own stack pointer) and, after the call,
 * the bytes below sp it wrote. Macros, so that no frame of their own lies below sp. */
#define PAINT_BELOW(sp)                                                                            \
    do {                                                                                           \
        volatile uint32_t *p_ = __stack_bottom;                                                    \
        while ((uintptr_t)p_ < (sp)) {                                                             \
            *p_++ = STACK_PAINT;                                                                   \
        }                                                                                          \
    } while (0)
#define WRITTEN_BELOW(sp, bytes)                                                                   \
    do {                                                                                           \
        const volatile uint32_t *p_ = __stack_bottom;                                              \
        while (*p_ == STACK_PAINT && (uintptr_t)p_ < (sp)) {                                       \
            ++p_;                                                                                  \
        }                                                                                          \
        (bytes) = (uint32_t)((sp) - (uintptr_t)p_);                                                \
    } while (0)

static void keep_max(uint32_t *peak, uint32_t v)
{
    if (v > *peak) {
        *peak = v;
    }
}

/* The public calls but icoac_step (the tick loops measure it), painted one at a time, in the
 * configuration of each replay (icoac_init without and with a prior). Line "M calls <fn>=<peak
 * bytes below the caller's sp> ...", the largest over the configurations. */
static int measure_calls(replay_controller_t *ctrl)
{
    static const int32_t modes[] = {ICOAC_MODE_ICO, ICOAC_MODE_RL, REPLAY_RL_LITERAL, REPLAY_RL_BATCH,
                                    ICOAC_MODE_SEARCH};
    static icoac_prior_t prior; /* out of the frame: the caller's data, not the call's stack */
    uint32_t check = 0u, init = 0u, init_prior = 0u, reset = 0u, retune = 0u, posterior = 0u, bytes;
    const uintptr_t sp = port_read_sp();
    int bad = 0;
    uint32_t m;
    for (m = 0u; m < sizeof modes / sizeof modes[0]; ++m) {
        replay_config(&ctrl->cfg, modes[m]);
        PAINT_BELOW(sp);
        bad |= icoac_config_check(&ctrl->cfg) != ICOAC_OK;
        WRITTEN_BELOW(sp, bytes);
        keep_max(&check, bytes);
        PAINT_BELOW(sp);
        bad |= icoac_init(&ctrl->cfg, &ctrl->state, NULL, 1u) != ICOAC_OK;
        WRITTEN_BELOW(sp, bytes);
        keep_max(&init, bytes);
        PAINT_BELOW(sp);
        bad |= icoac_get_posterior(&ctrl->state, &prior) != ICOAC_OK;
        WRITTEN_BELOW(sp, bytes);
        keep_max(&posterior, bytes);
        PAINT_BELOW(sp);
        bad |= icoac_init(&ctrl->cfg, &ctrl->state, &prior, 2u) != ICOAC_OK;
        WRITTEN_BELOW(sp, bytes);
        keep_max(&init_prior, bytes);
        PAINT_BELOW(sp);
        bad |= icoac_reset(&ctrl->state) != ICOAC_OK;
        WRITTEN_BELOW(sp, bytes);
        keep_max(&reset, bytes);
        PAINT_BELOW(sp);
        bad |= icoac_retune(&ctrl->state, &ctrl->cfg) != ICOAC_OK;
        WRITTEN_BELOW(sp, bytes);
        keep_max(&retune, bytes);
    }
    port_puts("M calls");
    put_kv("icoac_config_check", check);
    put_kv("icoac_init", init > init_prior ? init : init_prior);
    put_kv("icoac_reset", reset);
    put_kv("icoac_retune", retune);
    put_kv("icoac_get_posterior", posterior);
    port_puts("\n");
    return bad;
}

int main(void)
{
    /* In main's frame, above the tick loop's: the painted stack measures the tick alone. */
    replay_controller_t ctrl;
    uint32_t c1, c2, count_insns;
    SYST_RVR = 0x00FFFFFFu;
    SYST_CVR = 0u;
    SYST_CSR = 5u; /* enable, processor clock, no interrupt */

    port_puts("B " ICOAC_PORT_BOARD_NAME "\n");
    port_puts("Z");
    put_kv("config", icoac_sizeof_config());
    put_kv("state", icoac_sizeof_state());
    put_kv("real", icoac_sizeof_real());
    port_puts("\n");
    c1 = calibrate(20000u);
    c2 = calibrate(120000u);
    port_puts("C");
    put_kv("insns", 200000u); /* (120000 - 20000) iterations x 2 instructions */
    put_kv("systick", c2 - c1);
    port_puts("\n");
    count_insns = (200000u + (c2 - c1) / 2u) / (c2 - c1); /* instructions per count, rounded */
    if (measure(&ctrl, ICOAC_MODE_ICO, "ico", count_insns) || measure(&ctrl, ICOAC_MODE_RL, "rl", count_insns) ||
        measure(&ctrl, REPLAY_RL_LITERAL, "rl_literal", count_insns) ||
        measure(&ctrl, REPLAY_RL_BATCH, "rl_batch", count_insns) ||
        measure(&ctrl, ICOAC_MODE_SEARCH, "search", count_insns) || measure_calls(&ctrl)) {
        return 1;
    }
    if (replay_run(&ctrl, ICOAC_MODE_ICO, icoac_step, 1) == 0u ||
        replay_run(&ctrl, ICOAC_MODE_RL, icoac_step, 1) == 0u ||
        replay_run(&ctrl, REPLAY_RL_BATCH, icoac_step, 1) == 0u ||
        replay_run(&ctrl, ICOAC_MODE_SEARCH, icoac_step, 1) == 0u) {
        return 1;
    }
    port_puts("END\n");
    return 0;
}
