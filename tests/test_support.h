/* SPDX-License-Identifier: MIT */
/*
 * test_support.h: helpers the Check suites share (included, not a suite of its own: the
 * tests' glob only picks up test_*.c).
 */
#ifndef COAVOID_TEST_SUPPORT_H
#define COAVOID_TEST_SUPPORT_H

#include <check.h>
#include <stdint.h>

/* An assertion for inner loops: Check logs the place of every ck_assert it passes, which
 * in a loop run millions of times costs more than the code under test. */
#define REQUIRE(cond)                                             \
    do {                                                          \
        if (!(cond)) {                                            \
            ck_abort_msg("%s:%d: %s", __FILE__, __LINE__, #cond); \
        }                                                         \
    } while (0)

/* Deterministic random numbers (splitmix64): fixed seeds, the same on every machine. */
static inline uint64_t splitmix(uint64_t *s)
{
    uint64_t z = (*s += 0x9e3779b97f4a7c15u);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9u;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebu;
    return z ^ (z >> 31);
}

/* Uniform in [lo, hi). */
static inline double unif(uint64_t *s, double lo, double hi)
{
    return lo + (hi - lo) * ((double)(splitmix(s) >> 11) / 9007199254740992.0);
}

/* Uniform in 0..n-1. */
static inline uint32_t pick(uint64_t *s, uint32_t n)
{
    return (uint32_t)(splitmix(s) % n);
}

#endif /* COAVOID_TEST_SUPPORT_H */
