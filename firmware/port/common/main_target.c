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

static uint32_t t_begin, t_end, t_last, t_max;
static uintptr_t stack_low, loop_sp;

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

/* The paint stores are volatile so that GCC does not turn the loop into a memset call, whose own
 * frame would lie in the painted area (newlib-nano's ARMv6-M memset pushes 20 bytes and would
 * restore a clobbered r4). */
void port_ticks_begin(uintptr_t sp)
{
    volatile uint32_t *p = __stack_bottom;
    volatile uint32_t *end = (volatile uint32_t *)(port_read_sp() - 16u);
    (void)sp;
    while (p < end) {
        *p++ = STACK_PAINT;
    }
    t_max = 0u;
    t_begin = timer_now();
    t_last = t_begin;
}

void port_tick_start(uint32_t kind)
{
    (void)kind;
}

void port_tick_done(uint32_t kind)
{
    uint32_t now = timer_now();
    uint32_t d = timer_elapsed(t_last, now);
    (void)kind;
    if (d > t_max) {
        t_max = d;
    }
    t_last = now;
}

void port_ticks_end(uintptr_t sp)
{
    uint32_t *p = __stack_bottom;
    t_end = timer_now();
    loop_sp = sp;
    while (*p == STACK_PAINT && (uintptr_t)p < sp) {
        ++p;
    }
    stack_low = (uintptr_t)p;
}

static icoac_status_t step_stub(const icoac_config_t *cfg, icoac_state_t *state,
                                const icoac_input_t *in, icoac_output_t *out)
{
    (void)cfg;
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

/* 2 instructions per iteration (subs + bne) for the SysTick calibration. */
static uint32_t calibrate(uint32_t iterations)
{
    uint32_t t0, t1;
    t0 = timer_now();
    __asm__ volatile(".syntax unified\n1: subs %0, %0, #1\n\tbne 1b" : "+l"(iterations) : : "cc");
    t1 = timer_now();
    return timer_elapsed(t0, t1);
}

static int measure(replay_controller_t *ctrl, int32_t mode, const char *name)
{
    uint32_t n, base, base_max, total, stack;
    n = replay_run(ctrl, mode, step_stub, 0);
    base = timer_elapsed(t_begin, t_end);
    base_max = t_max;
    n = replay_run(ctrl, mode, icoac_step, 0);
    total = timer_elapsed(t_begin, t_end);
    stack = (uint32_t)(loop_sp - stack_low); /* bytes below the tick loop's frame */
    port_puts("M ");
    port_puts(name);
    put_kv("ticks", n);
    put_kv("systick_total", total);
    put_kv("systick_base", base);
    put_kv("systick_max", t_max);
    put_kv("systick_base_max", base_max);
    put_kv("stack", stack);
    port_puts("\n");
    return n == 0u;
}

int main(void)
{
    /* In main's frame, above the tick loop's: the painted stack measures the tick alone. */
    replay_controller_t ctrl;
    uint32_t c1, c2;
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
    if (measure(&ctrl, ICOAC_MODE_ICO, "ico") || measure(&ctrl, ICOAC_MODE_RL, "rl")) {
        return 1;
    }
    if (replay_run(&ctrl, ICOAC_MODE_ICO, icoac_step, 1) == 0u ||
        replay_run(&ctrl, ICOAC_MODE_RL, icoac_step, 1) == 0u ||
        replay_run(&ctrl, ICOAC_MODE_SEARCH, icoac_step, 1) == 0u) {
        return 1;
    }
    port_puts("END\n");
    return 0;
}
