/* SPDX-License-Identifier: MIT */
/*
 * bench_support.h: what `coavoid bench predict` and `coavoid bench plan` share: the seeded
 * PRNG that makes a seed give the same airspace or encounters everywhere, and the timing
 * summary (median, min, max of the repeats).
 */
#ifndef COAVOID_APP_BENCH_SUPPORT_H
#define COAVOID_APP_BENCH_SUPPORT_H

#include <stdint.h>
#include <stdlib.h>
#include <time.h>

typedef struct {
    uint64_t state;
} prng_t;

/* splitmix64 (Steele, Lea, Flood 2014): tiny, fast and the same everywhere. */
static inline uint64_t prng_next(prng_t *r)
{
    uint64_t z = (r->state += 0x9e3779b97f4a7c15u);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9u;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebu;
    return z ^ (z >> 31);
}

/* Uniform in [lo, hi). */
static inline double prng_uniform(prng_t *r, double lo, double hi)
{
    double u = (double)(prng_next(r) >> 11) * (1.0 / 9007199254740992.0);
    return lo + (hi - lo) * u;
}

/* Uniform in 0..n-1 (n >= 1). */
static inline uint32_t prng_below(prng_t *r, uint32_t n)
{
    return (uint32_t)(prng_next(r) % n);
}

static inline double bench_elapsed_ms(const struct timespec *start, const struct timespec *end)
{
    return (double)(end->tv_sec - start->tv_sec) * 1e3 +
           (double)(end->tv_nsec - start->tv_nsec) * 1e-6;
}

static inline int bench_compare_doubles(const void *pa, const void *pb)
{
    double a = *(const double *)pa;
    double b = *(const double *)pb;
    return a < b ? -1 : (a > b ? 1 : 0);
}

/* Sorts times[0..r-1] (r >= 1) and gives their median, least and largest. */
static inline void bench_summarise(double *times, uint32_t r, double *median, double *min,
                                   double *max)
{
    qsort(times, r, sizeof *times, bench_compare_doubles);
    *median = r % 2u == 1u ? times[r / 2u] : 0.5 * (times[r / 2u - 1u] + times[r / 2u]);
    *min = times[0];
    *max = times[r - 1u];
}

#endif /* COAVOID_APP_BENCH_SUPPORT_H */
