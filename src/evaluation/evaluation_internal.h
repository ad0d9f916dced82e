/* SPDX-License-Identifier: MIT */
/*
 * evaluation_internal.h: what the harnesses of coavoid::evaluation share and their callers
 * do not need: the timing of a benchmark (the monotonic clock's milliseconds, and the
 * median, least and largest of the repeats) and the printf check of the encounters'
 * writer. Not part of the library's interface.
 */
#ifndef COAVOID_EVALUATION_INTERNAL_H
#define COAVOID_EVALUATION_INTERNAL_H

#include <stdbool.h>
#include <stdint.h>
#include <stdlib.h>
#include <time.h>

#if defined(__GNUC__)
#define COAVOID_EVALUATION_PRINTF_LIKE(fmt, args) __attribute__((format(printf, fmt, args)))
#else
#define COAVOID_EVALUATION_PRINTF_LIKE(fmt, args)
#endif

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

/* A centralised plan's deviation over its proven lower bound (bound > 0): 1 when it is
 * proven optimal, whose bound is its cost. */
static inline double coavoid_bound_ratio(bool optimal, double deviation, double bound)
{
    return optimal ? 1.0 : deviation / bound;
}

#endif /* COAVOID_EVALUATION_INTERNAL_H */
