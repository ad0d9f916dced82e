/* SPDX-License-Identifier: MIT */
/*
 * prng.h: the seeded pseudo-random numbers behind every random problem of coavoid (the
 * encounters of src/evaluation/encounter.h, bench predict's airspace) and the simulated
 * network's losses and delays (src/sim/net.c). In coavoid::scenario, the layer both of
 * those libraries build on. splitmix64 (Steele, Lea, Flood
 * 2014): tiny, fast, and the same sequence on every machine for a seed, which is what makes
 * a benchmark or an evaluation repeatable from its seed alone; rand() and random() give
 * no such promise across C libraries. Not for anything that must be unpredictable.
 *
 * Each call is O(1), uses no memory besides the 8-byte state and cannot fail.
 */
#ifndef COAVOID_SCENARIO_PRNG_H
#define COAVOID_SCENARIO_PRNG_H

#include <stdint.h>

/* The whole state: {seed} starts a stream. */
typedef struct {
    uint64_t state;
} coavoid_prng_t;

/* The next 64 random bits. */
static inline uint64_t coavoid_prng_next(coavoid_prng_t *r)
{
    uint64_t z = (r->state += 0x9e3779b97f4a7c15u);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9u;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebu;
    return z ^ (z >> 31);
}

/* Uniform in [lo, hi): the top 53 bits, so every double of [0, 1) on a 2^-53 grid. */
static inline double coavoid_prng_uniform(coavoid_prng_t *r, double lo, double hi)
{
    double u = (double)(coavoid_prng_next(r) >> 11) * (1.0 / 9007199254740992.0);
    return lo + (hi - lo) * u;
}

/* Uniform in 0..n-1 (n >= 1), by the remainder: its bias of at most n / 2^64 is far below
 * anything a benchmark could see, and changing it would change every seed's problems. */
static inline uint32_t coavoid_prng_below(coavoid_prng_t *r, uint32_t n)
{
    return (uint32_t)(coavoid_prng_next(r) % n);
}

#endif /* COAVOID_SCENARIO_PRNG_H */
