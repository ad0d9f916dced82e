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
 * on an FPU that only does single precision). Costs never depend on it: they are integers. */
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
#define COA_ERR_ARGUMENT (-1)  /* NULL pointer, count out of range, non-finite or out-of-range number */
#define COA_ERR_WORKSPACE (-2) /* workspace missing, too small or built for fewer vehicles/beta */
#define COA_ERR_RANGE (-3)     /* the problem is too large for the integer cost or offset types */

/* Limits of the core. They bound every loop and every fixed array. */
#define COA_MAX_VEHICLES 32u       /* co-operative UAVs in one problem */
#define COA_MAX_CENTRALISED 6u     /* UAVs in one composite (centralised) search: 5^6 children a node */
#define COA_MAX_STEEP_FACTOR 10u   /* largest steep_factor; keeps the integer cost scale small */
#define COA_MAX_HORIZON 10000u     /* N: samples k = 0..N */
#define COA_MAX_OFFSET 32767       /* |altitude offset| in climb steps at any sample */

/* The workspace buffer passed to coa_planner_init must be aligned to this many bytes. */
#define COA_WORKSPACE_ALIGNMENT 8u

/* A short English name for a status code, for logs ("ok", "invalid argument", ...).
 * Cost O(1); never NULL. */
const char *coa_status_name(int status);

#ifdef __cplusplus
}
#endif

#endif /* COAVOID_COMMON_H */
