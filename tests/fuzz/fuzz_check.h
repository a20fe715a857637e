/* Contract checks of the fuzz targets: a violated check prints what failed and aborts, so
 * libFuzzer reports it like a crash and saves the input. */
#ifndef ICOAC_FUZZ_CHECK_H
#define ICOAC_FUZZ_CHECK_H

#include "icoac/icoac_types.h"

/* FZ_CHECK(condition, printf format, arguments...): abort with a message unless condition. */
#define FZ_CHECK(cond, ...)                                    \
    do {                                                       \
        if (!(cond)) {                                         \
            fz_fail(__FILE__, __LINE__, #cond, __VA_ARGS__);   \
        }                                                      \
    } while (0)

#if defined(__GNUC__)
#define FZ_NORETURN __attribute__((noreturn, format(printf, 4, 5)))
#else
#define FZ_NORETURN
#endif

void fz_fail(const char *file, int line, const char *cond, const char *fmt, ...) FZ_NORETURN;

/* 1 when the n reals (doubles) at p are all finite. */
int fz_all_finite(const icoac_real_t *p, int n);
int fz_all_finite_double(const double *p, int n);

#endif /* ICOAC_FUZZ_CHECK_H */
