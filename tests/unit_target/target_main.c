/* SPDX-License-Identifier: Apache-2.0 */
/* main of a unit test on a core. The test file's own main is compiled as icoac_unit_test_main;
 * this one paints the RAM between .bss and the stack, runs it, prints the peak stack and
 * returns its failure count (startup.c exits QEMU with it). Unity's characters go out over
 * semihosting a line at a time: one SYS_WRITEC trap per character would be slower. */
#include <stdint.h>

#include "semihost.h"
#include "unity.h"

#define STACK_PAINT 0xC5C5C5C5u
/* Words left unpainted below main's frame. */
#define PAINT_MARGIN_WORDS 64u

extern uint32_t __bss_end[], __stack_top[];
int icoac_unit_test_main(void);
int main(void);

static char line[128];
static unsigned line_len;

void icoac_unit_flush(void)
{
    if (line_len > 0u) {
        line[line_len] = '\0';
        semihost_write0(line);
        line_len = 0u;
    }
}

void icoac_unit_putchar(int c)
{
    line[line_len++] = (char)c;
    if (c == '\n' || line_len == sizeof line - 1u) {
        icoac_unit_flush();
    }
}

int main(void)
{
    volatile uint32_t here = 0u;
    const uintptr_t paint_end = (uintptr_t)&here - PAINT_MARGIN_WORDS * sizeof(uint32_t);
    const uintptr_t ram_for_stack = (uintptr_t)__stack_top - (uintptr_t)__bss_end;
    uint32_t *p;
    int failures;
    for (p = __bss_end; (uintptr_t)p < paint_end; ++p) {
        *p = STACK_PAINT;
    }
    failures = icoac_unit_test_main();
    for (p = __bss_end; (uintptr_t)p < (uintptr_t)__stack_top && *p == STACK_PAINT; ++p) {
    }
    UnityPrint("stack peak ");
    UnityPrintNumberUnsigned((UNITY_UINT)((uintptr_t)__stack_top - (uintptr_t)p));
    UnityPrint(" B of ");
    UnityPrintNumberUnsigned((UNITY_UINT)ram_for_stack);
    UnityPrint(" B above .bss");
    UNITY_PRINT_EOL();
    if (p == __bss_end) {
        /* the stack reached .bss: the run's results are not to be trusted */
        UnityPrint("STACK OVERFLOW");
        UNITY_PRINT_EOL();
        failures += 1;
    }
    icoac_unit_flush();
    return failures;
}
