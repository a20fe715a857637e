/* SPDX-License-Identifier: Apache-2.0 */
/* Denormal handling of the host engine. Balanced trials decay toward 0 for up to 1000 s and
 * would spend most of their time in subnormal floats, which x86 handles ~100x slower. The
 * engine flushes subnormals to zero (FTZ/DAZ) while it runs and restores the caller's mode.
 * This changes only values below 1e-38 (float) / 1e-308 (double); it is not fast-math. */
#include "sim_internal.h"

#if defined(__SSE2__)
#include <xmmintrin.h>

#define SIM_MXCSR_FTZ_DAZ 0x8040u

uint32_t sim_fpu_flush_subnormals(void)
{
    const uint32_t old = (uint32_t)_mm_getcsr();
    _mm_setcsr(old | SIM_MXCSR_FTZ_DAZ);
    return old;
}

void sim_fpu_restore(uint32_t mode)
{
    _mm_setcsr(mode);
}
#else
uint32_t sim_fpu_flush_subnormals(void)
{
    return 0u;
}

void sim_fpu_restore(uint32_t mode)
{
    (void)mode;
}
#endif
