/* SPDX-License-Identifier: MIT */
/*
 * evaluation_internal.h: what the harnesses of coavoid::evaluation share and its callers
 * do not need: the error line of evaluation.h, and the timing of a benchmark (the
 * monotonic clock's milliseconds, and the median, least and largest of the repeats). Not
 * part of the library's interface.
 */
#ifndef COAVOID_EVALUATION_INTERNAL_H
#define COAVOID_EVALUATION_INTERNAL_H

#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

#include "evaluation.h"

#if defined(__GNUC__)
#define COAVOID_EVALUATION_PRINTF_LIKE(fmt, args) __attribute__((format(printf, fmt, args)))
#else
#define COAVOID_EVALUATION_PRINTF_LIKE(fmt, args)
#endif

/* Writes the error line into err[size] and returns status, so that every check reads
 * `return coavoid_evaluation_fail(...)`. */
static inline int coavoid_evaluation_fail(char *err, size_t size, int status, const char *fmt, ...)
    COAVOID_EVALUATION_PRINTF_LIKE(4, 5);

static inline int coavoid_evaluation_fail(char *err, size_t size, int status, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(err, size, fmt, ap);
    va_end(ap);
    return status;
}

static inline double coavoid_timing_elapsed_ms(const struct timespec *start,
                                               const struct timespec *end)
{
    return (double)(end->tv_sec - start->tv_sec) * 1e3 +
           (double)(end->tv_nsec - start->tv_nsec) * 1e-6;
}

/* qsort's comparison of doubles, ascending. */
static inline int coavoid_timing_compare(const void *pa, const void *pb)
{
    double a = *(const double *)pa;
    double b = *(const double *)pb;
    return a < b ? -1 : (a > b ? 1 : 0);
}

/* Sorts times[0..r-1] (r >= 1) and gives their median, least and largest. */
static inline void coavoid_timing_summarise(double *times, uint32_t r, double *median, double *min,
                                            double *max)
{
    qsort(times, r, sizeof *times, coavoid_timing_compare);
    *median = r % 2u == 1u ? times[r / 2u] : 0.5 * (times[r / 2u - 1u] + times[r / 2u]);
    *min = times[0];
    *max = times[r - 1u];
}

#endif /* COAVOID_EVALUATION_INTERNAL_H */
