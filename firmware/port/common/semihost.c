/* SPDX-License-Identifier: Apache-2.0 */
#include "semihost.h"

#include <stdint.h>

#define SYS_WRITE0 0x04u
#define SYS_EXIT_EXTENDED 0x20u
#define ADP_STOPPED_APPLICATION_EXIT 0x20026u

static uint32_t semihost_call(uint32_t op, uint32_t arg)
{
    register uint32_t r0 __asm__("r0") = op;
    register uint32_t r1 __asm__("r1") = arg;
    __asm__ volatile("bkpt 0xab" : "+r"(r0) : "r"(r1) : "memory");
    return r0;
}

void semihost_write0(const char *s)
{
    (void)semihost_call(SYS_WRITE0, (uint32_t)(uintptr_t)s);
}

void semihost_exit(int code)
{
    /* AArch32 SYS_EXIT takes a reason only (QEMU exits 0 or 1); SYS_EXIT_EXTENDED also takes
     * the status, which QEMU exits with (on mps2-an386 and microbit alike). The host keeps its
     * low 8 bits: a nonzero code that would read as 0 there becomes 255. */
    const uint32_t block[2] = {ADP_STOPPED_APPLICATION_EXIT,
                               (code != 0 && (code & 0xFF) == 0) ? 255u : (uint32_t)code & 0xFFu};
    (void)semihost_call(SYS_EXIT_EXTENDED, (uint32_t)(uintptr_t)block);
    for (;;) {
    }
}
