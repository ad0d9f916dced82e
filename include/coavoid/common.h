/* SPDX-License-Identifier: MIT */
/*
 * coavoid: co-operative collision avoidance for UAVs with vertical manoeuvres.
 *
 * common.h: the types, limits and status codes shared by every core module.
 *
 * The core (geometry, trajectory, plan) is C11 with libm and libccd only: it never
 * allocates, prints, reads a clock or keeps state in globals. The caller owns all
 * memory. Every function that can fail returns a signed status: 0 (COA_OK) on success,
 * a negative COA_ERR_* code otherwise; functions that cannot fail say so by their type.
 *
 * Trust: the core trusts nothing about numbers it is given except what a function's
 * contract states as a precondition; inputs from files or the network are validated by
 * the apps (and later the messaging layer) before they reach the core.
 */
#ifndef COAVOID_COMMON_H
#define COAVOID_COMMON_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

/* Geometry precision. Double by default; define COA_SINGLE_PRECISION for float (firmware
 * on an FPU that only does single precision). Costs never depend on it: they are integers.
 *
 * Same plans in both precisions. Fed the same numbers (so numbers representable in float,
 * as everything a float build receives is), the two builds give the same plan result -
 * status, every offset, deviation, effort, nodes expanded and generated, priority order -
 * whenever the numbers the conflict tests form are exact in float: every sampled position
 * representable (reference legs along the axes whose fractions flown are dyadic, such as
 * legs 2^j m long; tracks by position and velocity at such times), and relative positions
 * and displacements over a step with few significant bits (coordinates on a grid of 1/8 m
 * within a few hundred metres, say). The conflict tests form sums of products of their
 * inputs, with no square root or quotient before the discriminant's, so there an exact
 * touch (no conflict, by the contract) at a step's end or a tangency comes out exact in
 * both, and both decide it as the contract does. Where a position rounds (a leg 17 m
 * long, a leg off the axes, a dt of 0.1) or the products need more bits than float has,
 * a pair within rounding of an exact touch (a few float ulps of the coordinates: 1e-4 m
 * at 1 km) may be decided differently by the two builds, and by neither exactly (double
 * has the same limit, further out), and the plans may then differ. Predictions
 * (predict.h) agree on conflict sets and first steps under the same rule; the real numbers
 * they report (times, least separations, probabilities) differ by rounding, and a pair
 * with uncertainty within rounding of the threshold may be listed by one build only.
 * Other differences: the planner's workspace is 2,112 bytes smaller in float (its fixed
 * header holds 62 sweeps and 32 climb steps of coa_real_t); the polytope test runs
 * libccd's MPR in libccd's own precision (double on the host whatever this is).
 * tests/precision checks this (docs/library.md, "Precision"). */
#ifdef COA_SINGLE_PRECISION
typedef float coa_real_t;
#else
typedef double coa_real_t;
#endif

/* A point or a vector in the local ENU frame: x east, y north, z up (m). */
typedef struct {
    coa_real_t x;
    coa_real_t y;
    coa_real_t z;
} coa_vec3_t;

/* Status codes. 0 is success; every error is negative so `if (rc < 0)` catches them all. */
#define COA_OK 0
#define COA_ERR_ARGUMENT \
    (-1) /* NULL pointer, count out of range, non-finite or out-of-range number */
#define COA_ERR_WORKSPACE (-2) /* workspace missing, too small or built for fewer vehicles/beta */
#define COA_ERR_RANGE (-3)     /* the problem is too large for the integer cost or offset types */

/* Limits of the core. They bound every loop and every fixed array. */
#define COA_MAX_VEHICLES 32u /* co-operative UAVs in one problem */
/* UAVs in one centralised problem: each has a cost-to-go table, and the joint search's
 * fixed arrays (its stack frame, the workspace's header) are sized for it. A build may set
 * it from 2 to 10 (CMake COAVOID_MAX_CENTRALISED; the Cortex-M build's is 6), and the
 * installed package's compile flags carry it. */
#ifndef COA_MAX_CENTRALISED
#define COA_MAX_CENTRALISED 10u
#endif
#define COA_MAX_STEEP_FACTOR 10u /* largest steep_factor; keeps the integer cost scale small */
#define COA_MAX_HORIZON 10000u   /* N: samples k = 0..N */
#define COA_MAX_OFFSET 32767     /* |altitude offset| in climb steps at any sample */

/* The workspace buffer passed to coa_planner_init must be aligned to this many bytes. */
#define COA_WORKSPACE_ALIGNMENT 8u

/* A short English name for a status code, for logs ("ok", "invalid argument", ...).
 * Cost O(1); never NULL. */
const char *coa_status_name(int status);

#ifdef __cplusplus
}
#endif

#endif /* COAVOID_COMMON_H */
