/* SPDX-License-Identifier: MIT */
/*
 * internal.h: helpers the core's modules share. Private: not installed, not API.
 *
 * The planner and the predictor both lay out a workspace inside the caller's buffer; the
 * arithmetic that sizes it must report overflow instead of wrapping, identically in both,
 * because each module's size function promises to be exact.
 */
#ifndef COAVOID_CORE_INTERNAL_H
#define COAVOID_CORE_INTERNAL_H

#include <float.h>
#include <math.h>

#include "coavoid/common.h"
#include "coavoid/geometry.h"

#define WS_ALIGN ((size_t)COA_WORKSPACE_ALIGNMENT)

/* An interval of a step's parameter u (geometry.c): empty unless lo < hi, so a single
 * point never counts. */
typedef struct {
    coa_real_t lo;
    coa_real_t hi;
} coa_span_t;

/* coa_conflict_volumes in two halves, for callers that test many pairs of sweeps whose
 * horizontal paths are the same and only their altitudes differ (every offset of two
 * vehicles at one step): the u where the discs come within r_a + r_b, computed once, then
 * per pair the vertical test met with it. coa_conflict_volumes_given(a, b,
 * coa_conflict_horizontal_span(a', b')) is exactly coa_conflict_volumes(a, b) when a', b'
 * have a's and b's x, y and radii (the same arithmetic on the same numbers). */
coa_span_t coa_conflict_horizontal_span(const coa_sweep_t *a, const coa_sweep_t *b);
bool coa_conflict_volumes_given(const coa_sweep_t *a, const coa_sweep_t *b, coa_span_t horizontal);

/* Whether some u of the closed step [0, 1] is in the span: false means no pair of sweeps
 * with these horizontal paths can conflict, whatever their altitudes. */
bool coa_conflict_span_in_step(coa_span_t s);

/* a * b, false when it would overflow size_t. */
static inline bool size_mul(size_t a, size_t b, size_t *out)
{
    if (a != 0u && b > SIZE_MAX / a) {
        return false;
    }
    *out = a * b;
    return true;
}

/* a + b, false when it would overflow size_t. */
static inline bool size_add(size_t a, size_t b, size_t *out)
{
    if (b > SIZE_MAX - a) {
        return false;
    }
    *out = a + b;
    return true;
}

/* a rounded up to the workspace alignment. */
static inline bool size_round(size_t a, size_t *out)
{
    return size_add(a, (WS_ALIGN - a % WS_ALIGN) % WS_ALIGN, out);
}

/* Reserves count * elem bytes at *cursor, rounded up so the next array stays aligned;
 * *at receives the array's offset. False on overflow. */
static inline bool reserve(size_t *cursor, size_t count, size_t elem, size_t *at)
{
    size_t bytes;
    if (!size_mul(count, elem, &bytes) || !size_round(bytes, &bytes)) {
        return false;
    }
    *at = *cursor;
    return size_add(*cursor, bytes, cursor);
}

/* The precision-dependent libm calls, named once for every module. Only correctly rounded
 * operations are used (sqrt and fabs are, by IEEE 754, and frexp and ldexp are exact;
 * hypot is not, and its error differs between libms), so the host and a firmware's libm
 * give the same bits for the same inputs in the same precision. */
#ifdef COA_SINGLE_PRECISION
#define real_sqrt(x) sqrtf(x)
#define real_fabs(x) fabsf(x)
#define real_frexp(x, e) frexpf((x), (e))
#define real_ldexp(x, e) ldexpf((x), (e))
#else
#define real_sqrt(x) sqrt(x)
#define real_fabs(x) fabs(x)
#define real_frexp(x, e) frexp((x), (e))
#define real_ldexp(x, e) ldexp((x), (e))
#endif

/* sqrt(x^2 + y^2), the length of a horizontal vector, rather than hypot (see above).
 * Coordinates in a local ENU frame are far from the range where the squares would
 * overflow or underflow. */
static inline coa_real_t real_norm2(coa_real_t x, coa_real_t y)
{
    return real_sqrt(x * x + y * y);
}

/* Boxes and cheap rejections in front of an exact conflict test are widened by this many
 * ulps of the scene's largest coordinate, so that no rounding in them can reject a step
 * that the exact tests (whose own rounding is a few ulps) would accept. */
#ifdef COA_SINGLE_PRECISION
#define REAL_EPSILON FLT_EPSILON
#else
#define REAL_EPSILON DBL_EPSILON
#endif
#define SLACK_ULPS 64

/* b grown by `slack` on every side (the widening of SLACK_ULPS above). */
static inline coa_box_t box_widened(coa_box_t b, coa_real_t slack)
{
    b.min.x -= slack;
    b.min.y -= slack;
    b.min.z -= slack;
    b.max.x += slack;
    b.max.y += slack;
    b.max.z += slack;
    return b;
}

/* b grown to hold point p (the bounding box of a set of points, one point at a time). */
static inline void box_include(coa_box_t *b, const coa_vec3_t *p)
{
    b->min.x = p->x < b->min.x ? p->x : b->min.x;
    b->min.y = p->y < b->min.y ? p->y : b->min.y;
    b->min.z = p->z < b->min.z ? p->z : b->min.z;
    b->max.x = p->x > b->max.x ? p->x : b->max.x;
    b->max.y = p->y > b->max.y ? p->y : b->max.y;
    b->max.z = p->z > b->max.z ? p->z : b->max.z;
}

/* The largest of m and |p|'s coordinates. */
static inline coa_real_t real_max_abs3(const coa_vec3_t *p, coa_real_t m)
{
    coa_real_t x = real_fabs(p->x);
    coa_real_t y = real_fabs(p->y);
    coa_real_t z = real_fabs(p->z);
    m = x > m ? x : m;
    m = y > m ? y : m;
    return z > m ? z : m;
}

static inline bool real_ok(coa_real_t x)
{
    return isfinite(x) != 0;
}

static inline bool vec_ok(const coa_vec3_t *p)
{
    return real_ok(p->x) && real_ok(p->y) && real_ok(p->z);
}

#endif /* COAVOID_CORE_INTERNAL_H */
