/* SPDX-License-Identifier: MIT */
/*
 * geometry.c: exact continuous-time conflict tests over one step.
 *
 * Volume-volume and volume-box tests reduce every condition to an interval of the step
 * parameter u and intersect them; the polytope test runs libccd's MPR on the swept volume
 * with a support-call budget, because MPR's own loops only end on tolerance.
 */
#include "coavoid/geometry.h"

#include <math.h>

#include <ccd/ccd.h>

#include "internal.h"

/* MPR works in ccd_real_t whatever coa_real_t is; these follow libccd's precision. */
#ifdef CCD_SINGLE
#define mpr_sqrt(x) sqrtf(x)
#define mpr_fabs(x) fabsf(x)
#define mpr_frexp(x, e) frexpf((x), (e))
#define mpr_ldexp(x, e) ldexpf((x), (e))
/* A float MPR cannot resolve 1e-9 of the scene; stop refining near its own rounding. */
#define COA_MPR_RELATIVE_TOLERANCE 1e-5f
#else
#define mpr_sqrt(x) sqrt(x)
#define mpr_fabs(x) fabs(x)
#define mpr_frexp(x, e) frexp((x), (e))
#define mpr_ldexp(x, e) ldexp((x), (e))
#define COA_MPR_RELATIVE_TOLERANCE 1e-9
#endif

/* ---------------------------------------------------------------------------------- */
/* Intervals of the step parameter u.                                                  */

static coa_span_t span_all(void)
{
    coa_span_t s = {-(coa_real_t)INFINITY, (coa_real_t)INFINITY};
    return s;
}

static coa_span_t span_empty(void)
{
    coa_span_t s = {(coa_real_t)INFINITY, -(coa_real_t)INFINITY};
    return s;
}

static bool span_nonempty(coa_span_t s)
{
    return s.lo < s.hi;
}

static coa_span_t span_meet(coa_span_t a, coa_span_t b)
{
    coa_span_t s;
    s.lo = a.lo > b.lo ? a.lo : b.lo;
    s.hi = a.hi < b.hi ? a.hi : b.hi;
    return s;
}

/* The u with p + u*v in (bmin, bmax) (open) or [bmin, bmax] (closed). Only the numbers
 * differ between the two: which ends belong to the set matters only when v == 0. */
static inline coa_span_t span_linear(coa_real_t p, coa_real_t v, coa_real_t bmin, coa_real_t bmax,
                                     bool closed)
{
    coa_real_t t1;
    coa_real_t t2;
    coa_span_t s;

    if (v == (coa_real_t)0) {
        bool inside = closed ? (bmin <= p && p <= bmax) : (bmin < p && p < bmax);
        return inside ? span_all() : span_empty();
    }
    t1 = (bmin - p) / v;
    t2 = (bmax - p) / v;
    if (t1 <= t2) {
        s.lo = t1;
        s.hi = t2;
    } else {
        s.lo = t2;
        s.hi = t1;
    }
    /* A zero-width closed slab gives lo == hi: one instant, which span_nonempty rejects
     * (union_pieces explains why that loses nothing). */
    return s;
}

/* Outside [2^-DISC_RANGE, 2^DISC_RANGE] span_disc rescales its inputs: within it, the
 * fourth powers it forms stay inside even float's normal range (2^-126 to 2^128). */
#define DISC_RANGE 24

/* The open set of u with |q + u*w| < radius in the plane: a*u^2 + 2*b*u + c < 0 with
 * a = |w|^2, b = q.w, c = |q|^2 - radius^2. Its discriminant b^2 - a*c is written as
 * radius^2*|w|^2 - (q x w)^2 (Lagrange's identity), the squared margin between the radius
 * and the line's closest approach, which does not cancel as b^2 - a*c would when q is far;
 * the roots use the cancellation-free pair t/a, c/t.
 *
 * Every quantity is a sum of products of the inputs, with no square root before the
 * discriminant's: on inputs with few significant bits (coordinates on a grid of 1/8 m,
 * say, near a touch) each one is then exact in float as in double, so an exact touch (a
 * root at exactly u = 0 or 1, a zero discriminant) is found exact in both precisions and
 * the two builds agree on it. A norm by sqrt (or radius * sqrt(a)) would round first. */
static coa_span_t span_disc(coa_real_t qx, coa_real_t qy, coa_real_t wx, coa_real_t wy,
                            coa_real_t radius)
{
    coa_real_t m;
    coa_real_t a;
    coa_real_t c;
    coa_real_t b;
    coa_real_t cross;
    coa_real_t disc;
    coa_real_t sd;
    coa_real_t t;
    coa_real_t u1;
    coa_real_t u2;
    coa_span_t s;

    /* The roots do not change when every input is scaled by one power of two, and such
     * a scaling rounds nothing (short of underflow): it keeps squares of squares finite
     * whatever the coordinates' range, and costs a comparison in a local frame. It
     * cannot help inputs far smaller than the largest: a product such as radius^2*|w|^2
     * still underflows when radius*|w| is below about 2^-63 of m^2 in float (2^-511 in
     * double), e.g. a 1e-20 m step against a 1 m radius, and the answer then follows
     * the rounding (a conflict may be missed); no local frame comes near that. */
    m = real_fabs(qx) > real_fabs(qy) ? real_fabs(qx) : real_fabs(qy);
    m = real_fabs(wx) > m ? real_fabs(wx) : m;
    m = real_fabs(wy) > m ? real_fabs(wy) : m;
    m = radius > m ? radius : m;
    if (m > real_ldexp((coa_real_t)1, DISC_RANGE) || m < real_ldexp((coa_real_t)1, -DISC_RANGE)) {
        /* Each input by ldexp rather than times 2^-e: for a subnormal m, 2^-e itself
         * overflows (float's 2^-e for m < 2^-127) and the product would be inf or NaN. */
        int e = 0;
        (void)real_frexp(m, &e);
        qx = real_ldexp(qx, -e);
        qy = real_ldexp(qy, -e);
        wx = real_ldexp(wx, -e);
        wy = real_ldexp(wy, -e);
        radius = real_ldexp(radius, -e);
    }
    a = wx * wx + wy * wy;
    c = (qx * qx + qy * qy) - radius * radius;
    if (a == (coa_real_t)0) {
        return c < (coa_real_t)0 ? span_all() : span_empty();
    }
    cross = qx * wy - qy * wx;
    disc = radius * radius * a - cross * cross;
    if (!(disc > (coa_real_t)0)) {
        /* c < 0 (the start inside) makes the true discriminant positive; a computed one
         * that is not has underflowed (|w| so far below radius that radius^2*|w|^2 does)
         * or rounded at a tangency through the start. Inside at the start is a conflict
         * either way: the whole step, which is right for a step that short and errs on
         * the safe side at the tangency. */
        return c < (coa_real_t)0 ? span_all() : span_empty();
    }
    sd = real_sqrt(disc);
    b = qx * wx + qy * wy;
    t = b >= (coa_real_t)0 ? -(b + sd) : sd - b;
    u1 = t / a;
    u2 = c / t;
    if (u1 <= u2) {
        s.lo = u1;
        s.hi = u2;
    } else {
        s.lo = u2;
        s.hi = u1;
    }
    return s;
}

/* Whether some u in the closed step [0, 1] lies in the open interval s. */
static bool span_meets_step(coa_span_t s)
{
    return s.lo < s.hi && s.lo < (coa_real_t)1 && s.hi > (coa_real_t)0;
}

/* ---------------------------------------------------------------------------------- */
/* Closed-form tests.                                                                  */

coa_span_t coa_conflict_horizontal_span(const coa_sweep_t *a, const coa_sweep_t *b)
{
    coa_real_t d0x = a->p0.x - b->p0.x;
    coa_real_t d0y = a->p0.y - b->p0.y;
    coa_real_t vx = (a->p1.x - b->p1.x) - d0x;
    coa_real_t vy = (a->p1.y - b->p1.y) - d0y;
    return span_disc(d0x, d0y, vx, vy, a->volume.radius + b->volume.radius);
}

/* The vertical half of coa_conflict_volumes, met with its horizontal span: the vertical
 * test first because it is the cheap one and rules out most pairs. */
static bool conflict_vertical(const coa_sweep_t *a, const coa_sweep_t *b,
                              const coa_span_t *horizontal)
{
    coa_real_t d0z = a->p0.z - b->p0.z;
    coa_real_t vz = (a->p1.z - b->p1.z) - d0z;
    coa_real_t hsum = a->volume.half_height + b->volume.half_height;
    coa_span_t vert = span_linear(d0z, vz, -hsum, hsum, false);
    if (!span_meets_step(vert)) {
        return false;
    }
    return span_meets_step(
        span_meet(horizontal != NULL ? *horizontal : coa_conflict_horizontal_span(a, b), vert));
}

bool coa_conflict_volumes(const coa_sweep_t *a, const coa_sweep_t *b)
{
    return conflict_vertical(a, b, NULL);
}

bool coa_conflict_volumes_given(const coa_sweep_t *a, const coa_sweep_t *b, coa_span_t horizontal)
{
    return conflict_vertical(a, b, &horizontal);
}

bool coa_conflict_span_in_step(coa_span_t s)
{
    return span_meets_step(s);
}

bool coa_conflict_horizontal(const coa_sweep_t *a, const coa_sweep_t *b)
{
    return span_meets_step(coa_conflict_horizontal_span(a, b));
}

/* The open rounded rectangle {distance to the closed rectangle < r} is convex, so its
 * u-set is one open interval: the inf and sup over the pieces that cover it (two open
 * slabs crossed with closed strips, four open corner discs). Pieces that are a single
 * instant are dropped; that is safe because the whole set is open, so any such instant
 * has a neighbourhood covered by pieces of positive length, which give the same inf/sup. */
static coa_span_t union_pieces(const coa_span_t *pieces, size_t n)
{
    coa_span_t u = span_empty();
    size_t i;

    for (i = 0; i < n; ++i) {
        if (!span_nonempty(pieces[i])) {
            continue;
        }
        if (pieces[i].lo < u.lo) {
            u.lo = pieces[i].lo;
        }
        if (pieces[i].hi > u.hi) {
            u.hi = pieces[i].hi;
        }
    }
    return u;
}

bool coa_conflict_box(const coa_sweep_t *a, const coa_box_t *box)
{
    coa_real_t r = a->volume.radius;
    coa_real_t h = a->volume.half_height;
    coa_real_t px = a->p0.x;
    coa_real_t py = a->p0.y;
    coa_real_t vx = a->p1.x - a->p0.x;
    coa_real_t vy = a->p1.y - a->p0.y;
    coa_real_t vz = a->p1.z - a->p0.z;
    coa_span_t vert;
    coa_span_t pieces[6];
    coa_span_t horiz;

    vert = span_linear(a->p0.z, vz, box->min.z - h, box->max.z + h, false);
    if (!span_meets_step(vert)) {
        return false;
    }
    pieces[0] = span_meet(span_linear(px, vx, box->min.x - r, box->max.x + r, false),
                          span_linear(py, vy, box->min.y, box->max.y, true));
    pieces[1] = span_meet(span_linear(px, vx, box->min.x, box->max.x, true),
                          span_linear(py, vy, box->min.y - r, box->max.y + r, false));
    pieces[2] = span_disc(px - box->min.x, py - box->min.y, vx, vy, r);
    pieces[3] = span_disc(px - box->max.x, py - box->min.y, vx, vy, r);
    pieces[4] = span_disc(px - box->min.x, py - box->max.y, vx, vy, r);
    pieces[5] = span_disc(px - box->max.x, py - box->max.y, vx, vy, r);
    horiz = union_pieces(pieces, sizeof pieces / sizeof pieces[0]);
    return span_meets_step(span_meet(horiz, vert));
}

coa_box_t coa_sweep_bounds(const coa_sweep_t *a)
{
    coa_box_t b;
    coa_real_t r = a->volume.radius;
    coa_real_t h = a->volume.half_height;

    b.min.x = (a->p0.x < a->p1.x ? a->p0.x : a->p1.x) - r;
    b.min.y = (a->p0.y < a->p1.y ? a->p0.y : a->p1.y) - r;
    b.min.z = (a->p0.z < a->p1.z ? a->p0.z : a->p1.z) - h;
    b.max.x = (a->p0.x > a->p1.x ? a->p0.x : a->p1.x) + r;
    b.max.y = (a->p0.y > a->p1.y ? a->p0.y : a->p1.y) + r;
    b.max.z = (a->p0.z > a->p1.z ? a->p0.z : a->p1.z) + h;
    return b;
}

coa_box_t coa_obstacle_bounds(const coa_obstacle_t *o)
{
    coa_box_t b;
    size_t v;

    if (o->kind == COA_OBSTACLE_BOX) {
        return o->box;
    }
    b.min = o->polytope.vertices[0];
    b.max = o->polytope.vertices[0];
    for (v = 1; v < o->polytope.count; ++v) {
        box_include(&b, &o->polytope.vertices[v]);
    }
    return b;
}

bool coa_boxes_touch(const coa_box_t *a, const coa_box_t *b)
{
    return a->min.x <= b->max.x && b->min.x <= a->max.x && a->min.y <= b->max.y &&
           b->min.y <= a->max.y && a->min.z <= b->max.z && b->min.z <= a->max.z;
}

/* ---------------------------------------------------------------------------------- */
/* Swept volume against a convex polytope: bounded MPR.                                */

/* Shared by both MPR objects. libccd hands callbacks const pointers, so the mutable
 * budget lives behind a pointer rather than in the objects themselves. */
typedef struct {
    unsigned long calls; /* polytope support evaluations so far (the O(count) ones) */
    bool exhausted;      /* the budget ran out or a direction was not finite */
} coa_mpr_budget_t;

/* MPR's zero tests are absolute (CCD_EPS) and its arithmetic reaches the fourth power of
 * the coordinates (the squared length of a cross product). So MPR sees the scene moved
 * to the sweep's midpoint and scaled to unit size, by powers of two so that scaling
 * itself rounds nothing: x -> (x * pre - mid) * post. `pre` only keeps the subtraction
 * from overflowing when raw coordinates are near the top of the range. */
typedef struct {
    ccd_real_t pre;
    ccd_vec3_t mid; /* the sweep's midpoint, times pre */
    ccd_real_t post;
} coa_mpr_frame_t;

typedef struct {
    ccd_vec3_t half; /* p1 - midpoint in the frame; p0 - midpoint is its negative */
    ccd_real_t radius;
    ccd_real_t half_height;
    coa_mpr_budget_t *budget;
} coa_mpr_sweep_t;

typedef struct {
    const coa_vec3_t *vertices;
    size_t count;
    coa_mpr_frame_t frame;
    ccd_vec3_t centre; /* vertex mean, in the frame */
    coa_mpr_budget_t *budget;
} coa_mpr_poly_t;

/* Beyond every support point of either object in the unit frame (|coordinate| <= 1). */
#define COA_MPR_FAR ((ccd_real_t)8)

static bool mpr_vec_finite(const ccd_vec3_t *v)
{
    return isfinite(v->v[0]) && isfinite(v->v[1]) && isfinite(v->v[2]);
}

/* Once the budget is spent, both supports answer the point at distance COA_MPR_FAR
 * opposite the requested direction. The Minkowski-difference support s1(d) - s2(-d) then
 * has a strictly negative dot with d even if only one side has switched yet, which every
 * MPR exit test reads as "origin outside": discovery and refinement return at their next
 * check. A non-finite direction (a degenerate portal) ends the test the same way. */
static bool support_stop(coa_mpr_budget_t *budget, const ccd_vec3_t *dir, ccd_vec3_t *out)
{
    ccd_real_t len;

    if (!budget->exhausted && mpr_vec_finite(dir)) {
        return false;
    }
    budget->exhausted = true;
    out->v[0] = 0;
    out->v[1] = 0;
    out->v[2] = 0;
    if (!mpr_vec_finite(dir)) {
        return true;
    }
    len = mpr_sqrt(dir->v[0] * dir->v[0] + dir->v[1] * dir->v[1] + dir->v[2] * dir->v[2]);
    if (len > 0 && isfinite(len)) {
        out->v[0] = -COA_MPR_FAR * (dir->v[0] / len);
        out->v[1] = -COA_MPR_FAR * (dir->v[1] / len);
        out->v[2] = -COA_MPR_FAR * (dir->v[2] / len);
    }
    return true;
}

static void sweep_support(const void *obj, const ccd_vec3_t *dir, ccd_vec3_t *out)
{
    const coa_mpr_sweep_t *s = (const coa_mpr_sweep_t *)obj;
    ccd_real_t dx = dir->v[0];
    ccd_real_t dy = dir->v[1];
    ccd_real_t dz = dir->v[2];
    ccd_real_t along = dx * s->half.v[0] + dy * s->half.v[1] + dz * s->half.v[2];
    ccd_real_t sign = along > 0 ? (ccd_real_t)1 : (ccd_real_t)-1;
    ccd_real_t lxy;

    if (support_stop(s->budget, dir, out)) {
        return;
    }
    out->v[0] = sign * s->half.v[0];
    out->v[1] = sign * s->half.v[1];
    out->v[2] = sign * s->half.v[2];
    lxy = mpr_sqrt(dx * dx + dy * dy);
    if (lxy > 0) {
        out->v[0] += s->radius * (dx / lxy);
        out->v[1] += s->radius * (dy / lxy);
    }
    if (dz > 0) {
        out->v[2] += s->half_height;
    } else if (dz < 0) {
        out->v[2] -= s->half_height;
    }
}

static void sweep_centre(const void *obj, ccd_vec3_t *out)
{
    (void)obj;
    out->v[0] = 0;
    out->v[1] = 0;
    out->v[2] = 0;
}

static void frame_point(const coa_mpr_frame_t *f, const coa_vec3_t *p, ccd_vec3_t *out)
{
    out->v[0] = ((ccd_real_t)p->x * f->pre - f->mid.v[0]) * f->post;
    out->v[1] = ((ccd_real_t)p->y * f->pre - f->mid.v[1]) * f->post;
    out->v[2] = ((ccd_real_t)p->z * f->pre - f->mid.v[2]) * f->post;
}

static void poly_support(const void *obj, const ccd_vec3_t *dir, ccd_vec3_t *out)
{
    const coa_mpr_poly_t *p = (const coa_mpr_poly_t *)obj;
    ccd_vec3_t v;
    ccd_real_t best;
    ccd_real_t dot;
    size_t i;

    p->budget->calls++;
    if (p->budget->calls > COA_MPR_MAX_SUPPORT_CALLS) {
        p->budget->exhausted = true;
    }
    if (support_stop(p->budget, dir, out)) {
        return;
    }
    frame_point(&p->frame, &p->vertices[0], out);
    best = out->v[0] * dir->v[0] + out->v[1] * dir->v[1] + out->v[2] * dir->v[2];
    for (i = 1; i < p->count; ++i) {
        frame_point(&p->frame, &p->vertices[i], &v);
        dot = v.v[0] * dir->v[0] + v.v[1] * dir->v[1] + v.v[2] * dir->v[2];
        if (dot > best) {
            best = dot;
            *out = v;
        }
    }
}

static void poly_centre(const void *obj, ccd_vec3_t *out)
{
    const coa_mpr_poly_t *p = (const coa_mpr_poly_t *)obj;
    *out = p->centre;
}

static bool vec_finite(const coa_vec3_t *v)
{
    return isfinite(v->x) && isfinite(v->y) && isfinite(v->z);
}

static ccd_real_t mpr_max(ccd_real_t a, ccd_real_t b)
{
    return a > b ? a : b;
}

static ccd_real_t vec_max_abs(const coa_vec3_t *v)
{
    return mpr_max(mpr_fabs((ccd_real_t)v->x),
                   mpr_max(mpr_fabs((ccd_real_t)v->y), mpr_fabs((ccd_real_t)v->z)));
}

static ccd_real_t mpr_vec_max_abs(const ccd_vec3_t *v)
{
    return mpr_max(mpr_fabs(v->v[0]), mpr_max(mpr_fabs(v->v[1]), mpr_fabs(v->v[2])));
}

/* 2^-e for the exponent e of m > 0 (m = f * 2^e, 0.5 <= f < 1); infinite when m is too
 * small for that to be represented. */
static ccd_real_t inverse_power_of_two(ccd_real_t m)
{
    int e = 0;
    (void)mpr_frexp(m, &e);
    return mpr_ldexp((ccd_real_t)1, -e);
}

/* The inputs checked, the polytope's bounding box, and the largest coordinate magnitude of
 * the scene (sweep and vertices). COA_OK or COA_ERR_ARGUMENT. */
static int polytope_scene(const coa_sweep_t *a, const coa_polytope_t *poly, coa_box_t *poly_box,
                          ccd_real_t *m)
{
    size_t i;
    if (a == NULL || poly == NULL || poly->vertices == NULL || poly->count < 4u ||
        poly->count > COA_POLYTOPE_MAX_VERTICES) {
        return COA_ERR_ARGUMENT;
    }
    if (!vec_finite(&a->p0) || !vec_finite(&a->p1) || !isfinite(a->volume.radius) ||
        !isfinite(a->volume.half_height) || !(a->volume.radius > (coa_real_t)0) ||
        !(a->volume.half_height > (coa_real_t)0)) {
        return COA_ERR_ARGUMENT;
    }
    poly_box->min = poly->vertices[0];
    poly_box->max = poly->vertices[0];
    *m = mpr_max(vec_max_abs(&a->p0), vec_max_abs(&a->p1));
    *m = mpr_max(*m, mpr_max((ccd_real_t)a->volume.radius, (ccd_real_t)a->volume.half_height));
    for (i = 0; i < poly->count; ++i) {
        const coa_vec3_t *p = &poly->vertices[i];
        if (!vec_finite(p)) {
            return COA_ERR_ARGUMENT;
        }
        box_include(poly_box, p);
        *m = mpr_max(*m, vec_max_abs(p));
    }
    return COA_OK;
}

/* The MPR frame: the sweep about its midpoint, pre-scaled when raw coordinates pass 1 in
 * magnitude, then post-scaled to unit size; the hull's centre in it. COA_OK, or
 * COA_ERR_ARGUMENT when the sizes are too far apart for one floating-point frame (below
 * 2^-1000 of the coordinates): no answer would mean anything. */
static int polytope_frame(const coa_sweep_t *a, const coa_polytope_t *poly, ccd_real_t m,
                          coa_mpr_sweep_t *sweep, coa_mpr_poly_t *hull)
{
    ccd_real_t pre = m > (ccd_real_t)1 ? inverse_power_of_two(m) : (ccd_real_t)1;
    ccd_vec3_t v;
    size_t i;
    sweep->half.v[0] = ((ccd_real_t)a->p1.x * pre - (ccd_real_t)a->p0.x * pre) / 2;
    sweep->half.v[1] = ((ccd_real_t)a->p1.y * pre - (ccd_real_t)a->p0.y * pre) / 2;
    sweep->half.v[2] = ((ccd_real_t)a->p1.z * pre - (ccd_real_t)a->p0.z * pre) / 2;
    hull->frame.pre = pre;
    hull->frame.mid.v[0] = (ccd_real_t)a->p0.x * pre + sweep->half.v[0];
    hull->frame.mid.v[1] = (ccd_real_t)a->p0.y * pre + sweep->half.v[1];
    hull->frame.mid.v[2] = (ccd_real_t)a->p0.z * pre + sweep->half.v[2];
    sweep->radius = (ccd_real_t)a->volume.radius * pre;
    sweep->half_height = (ccd_real_t)a->volume.half_height * pre;
    /* The scene's size about the midpoint, before post-scaling. */
    hull->frame.post = 1;
    m = mpr_max(mpr_fabs(sweep->half.v[0]), mpr_fabs(sweep->half.v[1])) + sweep->radius;
    m = mpr_max(m, mpr_fabs(sweep->half.v[2]) + sweep->half_height);
    for (i = 0; i < poly->count; ++i) {
        frame_point(&hull->frame, &poly->vertices[i], &v);
        m = mpr_max(m, mpr_vec_max_abs(&v));
    }
    hull->frame.post = inverse_power_of_two(m);
    if (!(m > 0) || !isfinite(m) || !(hull->frame.post > 0) || !isfinite(hull->frame.post)) {
        return COA_ERR_ARGUMENT;
    }
    sweep->half.v[0] *= hull->frame.post;
    sweep->half.v[1] *= hull->frame.post;
    sweep->half.v[2] *= hull->frame.post;
    sweep->radius *= hull->frame.post;
    sweep->half_height *= hull->frame.post;
    hull->vertices = poly->vertices;
    hull->count = poly->count;
    hull->centre.v[0] = 0;
    hull->centre.v[1] = 0;
    hull->centre.v[2] = 0;
    for (i = 0; i < poly->count; ++i) {
        frame_point(&hull->frame, &poly->vertices[i], &v);
        hull->centre.v[0] += v.v[0];
        hull->centre.v[1] += v.v[1];
        hull->centre.v[2] += v.v[2];
    }
    hull->centre.v[0] /= (ccd_real_t)poly->count;
    hull->centre.v[1] /= (ccd_real_t)poly->count;
    hull->centre.v[2] /= (ccd_real_t)poly->count;
    return COA_OK;
}

int coa_conflict_polytope(const coa_sweep_t *a, const coa_polytope_t *poly)
{
    coa_box_t sweep_box;
    coa_box_t poly_box;
    coa_mpr_budget_t budget;
    coa_mpr_sweep_t sweep;
    coa_mpr_poly_t hull;
    ccd_t ccd;
    ccd_real_t m;
    int hit;

    if (polytope_scene(a, poly, &poly_box, &m) != COA_OK) {
        return COA_ERR_ARGUMENT;
    }
    sweep_box = coa_sweep_bounds(a);
    if (!coa_boxes_touch(&sweep_box, &poly_box)) {
        return 0;
    }
    if (polytope_frame(a, poly, m, &sweep, &hull) != COA_OK) {
        return COA_ERR_ARGUMENT;
    }
    budget.calls = 0;
    budget.exhausted = false;
    sweep.budget = &budget;
    hull.budget = &budget;

    CCD_INIT(&ccd);
    ccd.support1 = sweep_support;
    ccd.support2 = poly_support;
    ccd.center1 = sweep_centre;
    ccd.center2 = poly_centre;
    ccd.max_iterations = COA_MPR_MAX_SUPPORT_CALLS;
    ccd.mpr_tolerance = COA_MPR_RELATIVE_TOLERANCE; /* the frame has unit size */

    hit = ccdMPRIntersect(&sweep, &hull, &ccd);
    if (budget.exhausted) {
        return 1;
    }
    return hit ? 1 : 0;
}

int coa_obstacle_check(const coa_obstacle_t *obstacle)
{
    size_t i;
    if (obstacle == NULL) {
        return COA_ERR_ARGUMENT;
    }
    if (obstacle->kind == COA_OBSTACLE_BOX) {
        const coa_box_t *b = &obstacle->box;
        return (vec_finite(&b->min) && vec_finite(&b->max) && b->min.x <= b->max.x &&
                b->min.y <= b->max.y && b->min.z <= b->max.z)
                   ? COA_OK
                   : COA_ERR_ARGUMENT;
    }
    if (obstacle->kind != COA_OBSTACLE_POLYTOPE || obstacle->polytope.vertices == NULL ||
        obstacle->polytope.count < 4u || obstacle->polytope.count > COA_POLYTOPE_MAX_VERTICES) {
        return COA_ERR_ARGUMENT;
    }
    for (i = 0; i < obstacle->polytope.count; ++i) {
        if (!vec_finite(&obstacle->polytope.vertices[i])) {
            return COA_ERR_ARGUMENT;
        }
    }
    return COA_OK;
}

int coa_conflict_obstacle(const coa_sweep_t *a, const coa_obstacle_t *obstacle)
{
    if (a == NULL || obstacle == NULL) {
        return COA_ERR_ARGUMENT;
    }
    switch (obstacle->kind) {
    case COA_OBSTACLE_BOX:
        return coa_conflict_box(a, &obstacle->box) ? 1 : 0;
    case COA_OBSTACLE_POLYTOPE:
        return coa_conflict_polytope(a, &obstacle->polytope);
    default:
        return COA_ERR_ARGUMENT;
    }
}
