/* SPDX-License-Identifier: MIT */
/*
 * test_geometry.c: the exact conflict tests against dense time sampling.
 *
 * Sampling cannot decide a case whose answer hinges on an exact boundary, so every random
 * case is judged twice: with the volume shrunk by 1% (a sampled conflict then proves a
 * real one) and inflated by 1% (no sampled conflict then proves there is none, because the
 * sample spacing is chosen so that the motion between samples stays well inside the 1%).
 * Cases that neither proof settles are ambiguous, skipped, and counted so that the suite
 * cannot pass by skipping everything.
 */
#include <check.h>
#include <float.h>
#include <math.h>
#include <string.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>

#include <ccd/ccd.h>

#include "coavoid/geometry.h"

#define SHRINK 0.99
#define INFLATE 1.01
#define MIN_SAMPLES 2000u

/* ---------------------------------------------------------------------------------- */
/* Deterministic randomness (splitmix64).                                              */

typedef struct {
    uint64_t s;
} rng_t;

static uint64_t rng_next(rng_t *r)
{
    uint64_t z = (r->s += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
}

static double rng_unit(rng_t *r)
{
    return (double)(rng_next(r) >> 11) * (1.0 / 9007199254740992.0);
}

static double rng_range(rng_t *r, double lo, double hi)
{
    return lo + (hi - lo) * rng_unit(r);
}

static unsigned rng_int(rng_t *r, unsigned lo, unsigned hi)
{
    return lo + (unsigned)(rng_next(r) % (uint64_t)(hi - lo + 1u));
}

static coa_vec3_t vec(double x, double y, double z)
{
    coa_vec3_t v;
    v.x = (coa_real_t)x;
    v.y = (coa_real_t)y;
    v.z = (coa_real_t)z;
    return v;
}

static coa_vec3_t rng_vec(rng_t *r, double lo, double hi)
{
    double x = rng_range(r, lo, hi);
    double y = rng_range(r, lo, hi);
    double z = rng_range(r, lo, hi);
    return vec(x, y, z);
}

static coa_sweep_t sweep(double r, double h, coa_vec3_t p0, coa_vec3_t p1)
{
    coa_sweep_t s;
    s.volume.radius = (coa_real_t)r;
    s.volume.half_height = (coa_real_t)h;
    s.p0 = p0;
    s.p1 = p1;
    return s;
}

static coa_box_t box(coa_vec3_t lo, coa_vec3_t hi)
{
    coa_box_t b;
    b.min = lo;
    b.max = hi;
    return b;
}

/* ---------------------------------------------------------------------------------- */
/* Instantaneous oracles, all in double.                                               */

typedef struct {
    double x, y, z;
} dvec_t;

static dvec_t at(const coa_sweep_t *s, double u)
{
    dvec_t p;
    p.x = (double)s->p0.x + u * ((double)s->p1.x - (double)s->p0.x);
    p.y = (double)s->p0.y + u * ((double)s->p1.y - (double)s->p0.y);
    p.z = (double)s->p0.z + u * ((double)s->p1.z - (double)s->p0.z);
    return p;
}

/* Samples needed so that the motion between a sample and any instant stays within half
 * of the 1% inflation: |v_xy| / (2n) <= 0.005 r and |v_z| / (2n) <= 0.005 h. */
static unsigned samples_for(double vxy, double vz, double r, double h)
{
    double n = fmax(vxy / (0.01 * r), fabs(vz) / (0.01 * h));
    unsigned m = (unsigned)ceil(n) + 1u;
    return m > MIN_SAMPLES ? m : MIN_SAMPLES;
}

typedef bool (*inst_fn)(const void *ctx, double u, double scale);

/* Whether the instantaneous test holds at any of u = i/n, i = 0..n (both endpoints). */
static bool sampled(inst_fn f, const void *ctx, unsigned n, double scale)
{
    unsigned i;
    for (i = 0; i <= n; ++i) {
        if (f(ctx, (double)i / (double)n, scale)) {
            return true;
        }
    }
    return false;
}

typedef enum { CASE_CONFLICT, CASE_CLEAR, CASE_AMBIGUOUS } verdict_t;

static verdict_t judge(inst_fn f, const void *ctx, unsigned n)
{
    if (sampled(f, ctx, n, SHRINK)) {
        return CASE_CONFLICT;
    }
    if (!sampled(f, ctx, n, INFLATE)) {
        return CASE_CLEAR;
    }
    return CASE_AMBIGUOUS;
}

typedef struct {
    const coa_sweep_t *a;
    const coa_sweep_t *b;
} vol_ctx_t;

static bool vol_inst(const void *ctx, double u, double scale)
{
    const vol_ctx_t *c = (const vol_ctx_t *)ctx;
    dvec_t pa = at(c->a, u);
    dvec_t pb = at(c->b, u);
    double rs = scale * ((double)c->a->volume.radius + (double)c->b->volume.radius);
    double hs = scale * ((double)c->a->volume.half_height + (double)c->b->volume.half_height);
    return hypot(pa.x - pb.x, pa.y - pb.y) < rs && fabs(pa.z - pb.z) < hs;
}

typedef struct {
    const coa_sweep_t *a;
    const coa_box_t *b;
} box_ctx_t;

static double axis_gap(double x, double lo, double hi)
{
    return x < lo ? lo - x : (x > hi ? x - hi : 0.0);
}

static bool box_inst(const void *ctx, double u, double scale)
{
    const box_ctx_t *c = (const box_ctx_t *)ctx;
    dvec_t p = at(c->a, u);
    double r = scale * (double)c->a->volume.radius;
    double h = scale * (double)c->a->volume.half_height;
    double gx = axis_gap(p.x, (double)c->b->min.x, (double)c->b->max.x);
    double gy = axis_gap(p.y, (double)c->b->min.y, (double)c->b->max.y);
    return gx * gx + gy * gy < r * r && p.z > (double)c->b->min.z - h &&
           p.z < (double)c->b->max.z + h;
}

/* The polytope oracle: libccd's GJK (not MPR) between the static cylinder at u and the
 * hull, after a bounding-box rejection that only saves time. */
typedef struct {
    dvec_t c;
    double r, h;
} gjk_cyl_t;

typedef struct {
    const coa_vec3_t *v;
    size_t n;
} gjk_poly_t;

static void gjk_cyl_support(const void *obj, const ccd_vec3_t *d, ccd_vec3_t *out)
{
    const gjk_cyl_t *c = (const gjk_cyl_t *)obj;
    double l = hypot(d->v[0], d->v[1]);
    out->v[0] = c->c.x + (l > 0 ? c->r * d->v[0] / l : 0);
    out->v[1] = c->c.y + (l > 0 ? c->r * d->v[1] / l : 0);
    out->v[2] = c->c.z + (d->v[2] > 0 ? c->h : (d->v[2] < 0 ? -c->h : 0));
}

static void gjk_poly_support(const void *obj, const ccd_vec3_t *d, ccd_vec3_t *out)
{
    const gjk_poly_t *p = (const gjk_poly_t *)obj;
    size_t i, best = 0;
    double bd = -INFINITY;
    for (i = 0; i < p->n; ++i) {
        double dot =
            (double)p->v[i].x * d->v[0] + (double)p->v[i].y * d->v[1] + (double)p->v[i].z * d->v[2];
        if (dot > bd) {
            bd = dot;
            best = i;
        }
    }
    out->v[0] = (double)p->v[best].x;
    out->v[1] = (double)p->v[best].y;
    out->v[2] = (double)p->v[best].z;
}

typedef struct {
    const coa_sweep_t *a;
    const coa_polytope_t *p;
    coa_box_t bounds;
} poly_ctx_t;

static unsigned long gjk_calls;

static bool poly_inst(const void *ctx, double u, double scale)
{
    const poly_ctx_t *c = (const poly_ctx_t *)ctx;
    gjk_cyl_t cyl;
    gjk_poly_t hull;
    ccd_t ccd;

    cyl.c = at(c->a, u);
    cyl.r = scale * (double)c->a->volume.radius;
    cyl.h = scale * (double)c->a->volume.half_height;
    if (cyl.c.x + cyl.r < (double)c->bounds.min.x || cyl.c.x - cyl.r > (double)c->bounds.max.x ||
        cyl.c.y + cyl.r < (double)c->bounds.min.y || cyl.c.y - cyl.r > (double)c->bounds.max.y ||
        cyl.c.z + cyl.h < (double)c->bounds.min.z || cyl.c.z - cyl.h > (double)c->bounds.max.z) {
        return false;
    }
    hull.v = c->p->vertices;
    hull.n = c->p->count;
    CCD_INIT(&ccd);
    ccd.support1 = gjk_cyl_support;
    ccd.support2 = gjk_poly_support;
    ccd.max_iterations = 500;
    gjk_calls++;
    return ccdGJKIntersect(&cyl, &hull, &ccd) != 0;
}

static coa_box_t points_bounds(const coa_vec3_t *v, size_t n)
{
    coa_box_t b;
    size_t i;
    b.min = v[0];
    b.max = v[0];
    for (i = 1; i < n; ++i) {
        b.min.x = v[i].x < b.min.x ? v[i].x : b.min.x;
        b.min.y = v[i].y < b.min.y ? v[i].y : b.min.y;
        b.min.z = v[i].z < b.min.z ? v[i].z : b.min.z;
        b.max.x = v[i].x > b.max.x ? v[i].x : b.max.x;
        b.max.y = v[i].y > b.max.y ? v[i].y : b.max.y;
        b.max.z = v[i].z > b.max.z ? v[i].z : b.max.z;
    }
    return b;
}

static double rel_xy(const coa_sweep_t *a, const coa_sweep_t *b)
{
    double vx = ((double)a->p1.x - (double)a->p0.x) - (b ? (double)b->p1.x - (double)b->p0.x : 0);
    double vy = ((double)a->p1.y - (double)a->p0.y) - (b ? (double)b->p1.y - (double)b->p0.y : 0);
    return hypot(vx, vy);
}

static double rel_z(const coa_sweep_t *a, const coa_sweep_t *b)
{
    return ((double)a->p1.z - (double)a->p0.z) - (b ? (double)b->p1.z - (double)b->p0.z : 0);
}

/* ---------------------------------------------------------------------------------- */
/* Tallies of a random set.                                                            */

typedef struct {
    const char *name;
    unsigned total, conflict, clear, ambiguous;
} tally_t;

static void tally_add(tally_t *t, verdict_t v)
{
    t->total++;
    if (v == CASE_CONFLICT) {
        t->conflict++;
    } else if (v == CASE_CLEAR) {
        t->clear++;
    } else {
        t->ambiguous++;
    }
}

/* Both outcomes must be common and ambiguity rare, or the comparison proves little. */
static void tally_check(const tally_t *t)
{
    printf("%-22s cases %5u  conflict %5u  clear %5u  ambiguous %3u\n", t->name, t->total,
           t->conflict, t->clear, t->ambiguous);
    fflush(stdout);
    ck_assert_uint_ge(t->conflict, t->total / 5u);
    ck_assert_uint_ge(t->clear, t->total / 5u);
    ck_assert_uint_le(t->ambiguous, t->total / 50u);
}

static void print_sweep(const char *what, const coa_sweep_t *s)
{
    fprintf(stderr, "%s: r %.17g h %.17g p0 (%.17g %.17g %.17g) p1 (%.17g %.17g %.17g)\n", what,
            (double)s->volume.radius, (double)s->volume.half_height, (double)s->p0.x,
            (double)s->p0.y, (double)s->p0.z, (double)s->p1.x, (double)s->p1.y, (double)s->p1.z);
}

static void print_box(const coa_box_t *b)
{
    fprintf(stderr, "box: (%.17g %.17g %.17g)-(%.17g %.17g %.17g)\n", (double)b->min.x,
            (double)b->min.y, (double)b->min.z, (double)b->max.x, (double)b->max.y,
            (double)b->max.z);
}

/* ---------------------------------------------------------------------------------- */
/* Random generators: positions near each other and sizes comparable to the motion, so
 * that both outcomes are common.                                                      */

static coa_sweep_t rng_sweep(rng_t *r, double spread, double motion)
{
    double rad = rng_range(r, 0.3, 3.0);
    double hh = rng_range(r, 0.3, 2.0);
    coa_vec3_t p0 = rng_vec(r, -spread, spread);
    coa_vec3_t d = rng_vec(r, -motion, motion);
    unsigned kind = rng_int(r, 0u, 9u);
    if (kind == 0u) { /* level flight */
        d.z = 0;
    } else if (kind == 1u) { /* pure climb or dive */
        d.x = 0;
        d.y = 0;
    } else if (kind == 2u) { /* hover */
        d = vec(0, 0, 0);
    }
    return sweep(
        rad, hh, p0,
        vec((double)p0.x + (double)d.x, (double)p0.y + (double)d.y, (double)p0.z + (double)d.z));
}

static coa_box_t rng_box(rng_t *r)
{
    coa_vec3_t c = rng_vec(r, -3.0, 3.0);
    double e[3];
    unsigned i;
    for (i = 0; i < 3u; ++i) {
        e[i] = rng_int(r, 0u, 6u) == 0u ? 0.0 : rng_range(r, 0.0, 3.0);
    }
    return box(vec((double)c.x - e[0], (double)c.y - e[1], (double)c.z - e[2]),
               vec((double)c.x + e[0], (double)c.y + e[1], (double)c.z + e[2]));
}

/* 4..12 points around a centre; one set in ten is flat (a polygon). */
static size_t rng_points(rng_t *r, coa_vec3_t *v)
{
    size_t n = rng_int(r, 4u, 12u);
    coa_vec3_t c = rng_vec(r, -3.0, 3.0);
    double size = rng_range(r, 0.5, 4.0);
    bool flat = rng_int(r, 0u, 9u) == 0u;
    size_t i;
    for (i = 0; i < n; ++i) {
        double x = rng_range(r, -size, size);
        double y = rng_range(r, -size, size);
        double z = flat ? 0.0 : rng_range(r, -size, size);
        v[i] = vec((double)c.x + x, (double)c.y + y, (double)c.z + z);
    }
    return n;
}

/* ---------------------------------------------------------------------------------- */
/* Random comparisons with dense sampling.                                             */

#define VOLUME_CASES 20000u
#define BOX_CASES 20000u
#define POLY_CASES 10000u
#define BOXPOLY_CASES 5000u

START_TEST(test_volumes_random)
{
    rng_t r = {0x5EEDu};
    tally_t t = {"volumes vs volumes", 0, 0, 0, 0};
    unsigned k;

    for (k = 0; k < VOLUME_CASES; ++k) {
        coa_sweep_t a = rng_sweep(&r, 3.5, 6.0);
        coa_sweep_t b = rng_sweep(&r, 3.5, 6.0);
        vol_ctx_t ctx = {&a, &b};
        unsigned n;
        verdict_t v;
        bool got;
        bool got_swapped;

        if (rng_int(&r, 0u, 9u) == 0u) { /* formation flight: no relative motion */
            coa_real_t dx = a.p1.x - a.p0.x, dy = a.p1.y - a.p0.y, dz = a.p1.z - a.p0.z;
            b.p1 = vec((double)b.p0.x + (double)dx, (double)b.p0.y + (double)dy,
                       (double)b.p0.z + (double)dz);
        }
        n = samples_for(rel_xy(&a, &b), rel_z(&a, &b),
                        (double)a.volume.radius + (double)b.volume.radius,
                        (double)a.volume.half_height + (double)b.volume.half_height);
        v = judge(vol_inst, &ctx, n);
        tally_add(&t, v);
        got = coa_conflict_volumes(&a, &b);
        got_swapped = coa_conflict_volumes(&b, &a);
        if ((v == CASE_CONFLICT && !(got && got_swapped)) ||
            (v == CASE_CLEAR && (got || got_swapped))) {
            fprintf(stderr, "case %u: sampled %s, exact %d/%d\n", k,
                    v == CASE_CONFLICT ? "conflict" : "clear", got, got_swapped);
            print_sweep("a", &a);
            print_sweep("b", &b);
            ck_abort_msg("volume test disagrees with sampling (case %u)", k);
        }
        if (got) { /* the broad phase must never reject what the exact test accepts */
            coa_box_t ba = coa_sweep_bounds(&a), bb = coa_sweep_bounds(&b);
            ck_assert(coa_boxes_touch(&ba, &bb));
        }
        /* The horizontal half: implied by a conflict, and exactly the conflict of b moved to
         * a's altitudes (where the vertical overlap holds throughout). */
        {
            coa_sweep_t level = b;
            bool horizontal = coa_conflict_horizontal(&a, &b);
            level.p0.z = a.p0.z;
            level.p1.z = a.p1.z;
            ck_assert(!got || horizontal);
            ck_assert(horizontal == coa_conflict_horizontal(&b, &a));
            ck_assert(horizontal == coa_conflict_volumes(&a, &level));
        }
    }
    tally_check(&t);
}
END_TEST

START_TEST(test_box_random)
{
    rng_t r = {0xB0B0u};
    tally_t t = {"volume vs box", 0, 0, 0, 0};
    unsigned k;

    for (k = 0; k < BOX_CASES; ++k) {
        coa_box_t b = rng_box(&r);
        coa_sweep_t a = rng_sweep(&r, 3.5, 6.0);
        box_ctx_t ctx = {&a, &b};
        unsigned n = samples_for(rel_xy(&a, NULL), rel_z(&a, NULL), (double)a.volume.radius,
                                 (double)a.volume.half_height);
        verdict_t v = judge(box_inst, &ctx, n);
        bool got = coa_conflict_box(&a, &b);
        coa_obstacle_t ob;

        tally_add(&t, v);
        if ((v == CASE_CONFLICT && !got) || (v == CASE_CLEAR && got)) {
            fprintf(stderr, "case %u: sampled %s, exact %d\n", k,
                    v == CASE_CONFLICT ? "conflict" : "clear", got);
            print_sweep("a", &a);
            print_box(&b);
            ck_abort_msg("box test disagrees with sampling (case %u)", k);
        }
        if (got) {
            coa_box_t ba = coa_sweep_bounds(&a);
            ck_assert(coa_boxes_touch(&ba, &b));
        }
        ob.kind = COA_OBSTACLE_BOX;
        ob.box = b;
        ob.polytope.vertices = NULL;
        ob.polytope.count = 0;
        ck_assert_int_eq(coa_conflict_obstacle(&a, &ob), got ? 1 : 0);
    }
    tally_check(&t);
}
END_TEST

START_TEST(test_polytope_random)
{
    rng_t r = {0x9017u};
    tally_t t = {"volume vs polytope", 0, 0, 0, 0};
    unsigned k;

    gjk_calls = 0;
    for (k = 0; k < POLY_CASES; ++k) {
        coa_vec3_t pts[12];
        coa_polytope_t poly;
        coa_sweep_t a;
        poly_ctx_t ctx;
        unsigned n;
        verdict_t v;
        int got;
        coa_obstacle_t ob;

        poly.vertices = pts;
        poly.count = rng_points(&r, pts);
        a = rng_sweep(&r, 3.5, 6.0);
        ctx.a = &a;
        ctx.p = &poly;
        ctx.bounds = points_bounds(pts, poly.count);
        n = samples_for(rel_xy(&a, NULL), rel_z(&a, NULL), (double)a.volume.radius,
                        (double)a.volume.half_height);
        v = judge(poly_inst, &ctx, n);
        got = coa_conflict_polytope(&a, &poly);
        tally_add(&t, v);
        ck_assert_int_ge(got, 0);
        if ((v == CASE_CONFLICT && got != 1) || (v == CASE_CLEAR && got != 0)) {
            size_t i;
            fprintf(stderr, "case %u: sampled %s, exact %d\n", k,
                    v == CASE_CONFLICT ? "conflict" : "clear", got);
            print_sweep("a", &a);
            for (i = 0; i < poly.count; ++i) {
                fprintf(stderr, "  v %.17g %.17g %.17g\n", (double)pts[i].x, (double)pts[i].y,
                        (double)pts[i].z);
            }
            ck_abort_msg("polytope test disagrees with sampling (case %u)", k);
        }
        ob.kind = COA_OBSTACLE_POLYTOPE;
        ob.box = ctx.bounds;
        ob.polytope = poly;
        ck_assert_int_eq(coa_conflict_obstacle(&a, &ob), got);
    }
    printf("(polytope oracle: %lu GJK calls)\n", gjk_calls);
    tally_check(&t);
}
END_TEST

/* A box given to the polytope test as its eight corners: judged by the box oracle. */
START_TEST(test_box_as_polytope_random)
{
    rng_t r = {0xC0BEu};
    tally_t t = {"box as polytope", 0, 0, 0, 0};
    unsigned k;

    for (k = 0; k < BOXPOLY_CASES; ++k) {
        coa_box_t b = rng_box(&r);
        coa_sweep_t a = rng_sweep(&r, 3.5, 6.0);
        box_ctx_t ctx = {&a, &b};
        coa_vec3_t pts[8];
        coa_polytope_t poly;
        unsigned i, n;
        verdict_t v;
        int got;

        for (i = 0; i < 8u; ++i) {
            pts[i].x = (i & 1u) ? b.max.x : b.min.x;
            pts[i].y = (i & 2u) ? b.max.y : b.min.y;
            pts[i].z = (i & 4u) ? b.max.z : b.min.z;
        }
        poly.vertices = pts;
        poly.count = 8;
        n = samples_for(rel_xy(&a, NULL), rel_z(&a, NULL), (double)a.volume.radius,
                        (double)a.volume.half_height);
        v = judge(box_inst, &ctx, n);
        got = coa_conflict_polytope(&a, &poly);
        tally_add(&t, v);
        if ((v == CASE_CONFLICT && got != 1) || (v == CASE_CLEAR && got != 0)) {
            fprintf(stderr, "case %u: sampled %s, polytope %d\n", k,
                    v == CASE_CONFLICT ? "conflict" : "clear", got);
            print_sweep("a", &a);
            print_box(&b);
            ck_abort_msg("polytope test disagrees with the box oracle (case %u)", k);
        }
    }
    tally_check(&t);
}
END_TEST

/* ---------------------------------------------------------------------------------- */
/* Hand-written cases: exact boundaries that sampling cannot settle.                   */

static bool vols(coa_sweep_t a, coa_sweep_t b)
{
    bool x = coa_conflict_volumes(&a, &b);
    bool y = coa_conflict_volumes(&b, &a);
    ck_assert_int_eq(x, y);
    return x;
}

static coa_sweep_t still(double r, double h, double x, double y, double z)
{
    return sweep(r, h, vec(x, y, z), vec(x, y, z));
}

START_TEST(test_volumes_touching)
{
    coa_sweep_t a = still(1, 1, 0, 0, 0);

    /* Side by side at exactly r_a + r_b, at rest and moving together. */
    ck_assert(!vols(a, still(2, 1, 3, 0, 0)));
    ck_assert(vols(a, still(2, 1, 2.999, 0, 0)));
    ck_assert(
        !vols(sweep(1, 1, vec(0, 0, 0), vec(10, 5, 0)), sweep(2, 1, vec(3, 0, 0), vec(13, 5, 0))));
    /* Passing by at a closest approach of exactly r_a + r_b. */
    ck_assert(!vols(a, sweep(1, 1, vec(-5, 2, 0), vec(5, 2, 0))));
    ck_assert(vols(a, sweep(1, 1, vec(-5, 1.999, 0), vec(5, 1.999, 0))));
    ck_assert(!vols(a, sweep(1, 1, vec(-6, -7, 0), vec(10, 5, 0)))); /* 3x - 4y = 10 */
    ck_assert(vols(a, sweep(1, 1, vec(-6, -6.99, 0), vec(10, 5.01, 0))));
    /* Stacked at exactly h_a + h_b, at rest and flying together. */
    ck_assert(!vols(a, still(1, 0.5, 0, 0, 1.5)));
    ck_assert(vols(a, still(1, 0.5, 0, 0, 1.49)));
    ck_assert(!vols(sweep(1, 1, vec(0, 0, 0), vec(7, -3, 0)),
                    sweep(1, 0.5, vec(0.5, 0, -1.5), vec(7.5, -3, -1.5))));
    /* Approaching and stopping exactly at contact at u = 1, and leaving from it at u = 0. */
    ck_assert(!vols(a, sweep(1, 1, vec(0, 0, 5), vec(0, 0, 2))));
    ck_assert(vols(a, sweep(1, 1, vec(0, 0, 5), vec(0, 0, 1.99))));
    ck_assert(!vols(a, sweep(1, 1, vec(0, 0, 2), vec(0, 0, 5))));
    ck_assert(!vols(a, sweep(1, 1, vec(2, 0, 0), vec(5, 0, 0))));
    ck_assert(!vols(a, sweep(1, 1, vec(5, 0, 0), vec(2, 0, 0))));
    /* Leaving contact inwards is a conflict for every u > 0. */
    ck_assert(vols(a, sweep(1, 1, vec(2, 0, 0), vec(1, 0, 0))));
    ck_assert(vols(a, sweep(1, 1, vec(0, 0, -2), vec(0, 0, -1.5))));
    /* Horizontally in contact while vertically overlapping, and the other way round. */
    ck_assert(!vols(a, sweep(1, 1, vec(2, 0, -5), vec(2, 0, 5))));
    ck_assert(!vols(a, sweep(1, 1, vec(-5, 0, 2), vec(5, 0, 2))));
}
END_TEST

START_TEST(test_volumes_crossing)
{
    coa_sweep_t a = sweep(1, 1, vec(-10, 0, 0), vec(10, 0, 0));
    coa_sweep_t b = sweep(1, 1, vec(0, -10, 0), vec(0, 10, 0));

    /* Only in the middle of the step: both ends are far apart. */
    ck_assert(vols(a, b));
    ck_assert(!vols(still(1, 1, -10, 0, 0), still(1, 1, 0, -10, 0)));
    ck_assert(!vols(still(1, 1, 10, 0, 0), still(1, 1, 0, 10, 0)));
    /* The same paths crossed at different times: closest approach 2.5*sqrt(2) > 2. */
    ck_assert(!vols(a, sweep(1, 1, vec(0, -5, 0), vec(0, 15, 0))));
    /* The same crossing with a vertical separation of exactly h_a + h_b, then less. */
    ck_assert(!vols(a, sweep(1, 1, vec(0, -10, 2), vec(0, 10, 2))));
    ck_assert(vols(a, sweep(1, 1, vec(0, -10, 1.9), vec(0, 10, 1.9))));
    /* Horizontal overlap for u in (0.4, 0.6), vertical for u < 0.1: never both. */
    ck_assert(!vols(still(1, 1, 0, 0, 0), sweep(1, 1, vec(-10, 0, 0), vec(10, 0, -20))));
    /* ... and when the vertical window is moved to overlap the horizontal one. */
    ck_assert(vols(still(1, 1, 0, 0, 0), sweep(1, 1, vec(-10, 0, 10), vec(10, 0, -10))));
    /* A climb through another UAV's level while passing over it. */
    ck_assert(vols(still(1, 1, 0, 0, 0), sweep(1, 1, vec(-1, 0, -10), vec(1, 0, 10))));
}
END_TEST

START_TEST(test_volumes_step_ends)
{
    coa_sweep_t a = still(1, 1, 0, 0, 0);

    /* Overlap only for u < 1/9 (at u = 0) and only for u > 8/9 (at u = 1). */
    ck_assert(vols(a, sweep(1, 1, vec(1, 0, 0), vec(10, 0, 0))));
    ck_assert(vols(a, sweep(1, 1, vec(10, 0, 0), vec(1, 0, 0))));
    ck_assert(vols(a, sweep(1, 1, vec(0, 0, 1), vec(0, 0, 10))));
    ck_assert(vols(a, sweep(1, 1, vec(0, 0, 10), vec(0, 0, -1.9))));
    /* Overlap only before the step (u < 0) or after it (u > 1). */
    ck_assert(!vols(a, sweep(1, 1, vec(3, 0, 0), vec(10, 0, 0))));
    ck_assert(!vols(a, sweep(1, 1, vec(10, 0, 0), vec(3, 0, 0))));
    ck_assert(!vols(a, sweep(1, 1, vec(0, 0, 3), vec(0, 0, 10))));
    ck_assert(!vols(a, sweep(1, 1, vec(10, 0, 0), vec(2.5, 0, 0))));
}
END_TEST

START_TEST(test_volumes_degenerate_motion)
{
    coa_sweep_t a = sweep(1, 1, vec(3, 4, 5), vec(8, -1, 7));

    /* Identical volumes and paths, moving and at rest. */
    ck_assert(vols(a, a));
    ck_assert(vols(still(1, 1, 3, 4, 5), still(1, 1, 3, 4, 5)));
    /* No relative motion: overlapping or apart for the whole step. */
    ck_assert(vols(a, sweep(1, 1, vec(4, 4, 5), vec(9, -1, 7))));
    ck_assert(!vols(a, sweep(1, 1, vec(6, 4, 5), vec(11, -1, 7))));
    ck_assert(!vols(a, sweep(1, 1, vec(3, 4, 8), vec(8, -1, 10))));
    /* No relative horizontal motion with vertical motion, and the converse. */
    ck_assert(vols(a, sweep(1, 1, vec(4, 4, 10), vec(9, -1, 5))));
    ck_assert(!vols(a, sweep(1, 1, vec(6, 4, 10), vec(11, -1, 5))));
    ck_assert(vols(a, sweep(1, 1, vec(-3, 4, 5.5), vec(12, -1, 7.5))));
    ck_assert(!vols(a, sweep(1, 1, vec(-3, 4, 7), vec(12, -1, 9))));
}
END_TEST

static coa_box_t cube10(void)
{
    return box(vec(0, 0, 0), vec(10, 10, 10));
}

static bool boxc(coa_sweep_t a, coa_box_t b)
{
    return coa_conflict_box(&a, &b);
}

START_TEST(test_box_touching)
{
    coa_box_t c = cube10();

    /* Face contact at rest: side, top, bottom. */
    ck_assert(!boxc(still(1, 1, 11, 5, 5), c));
    ck_assert(boxc(still(1, 1, 10.99, 5, 5), c));
    ck_assert(!boxc(still(1, 1, 5, -1, 5), c));
    ck_assert(!boxc(still(1, 1, 5, 5, 11), c));
    ck_assert(boxc(still(1, 1, 5, 5, 10.99), c));
    ck_assert(!boxc(still(1, 1, 5, 5, -1), c));
    /* Edge and corner contact: a vertical edge at distance exactly r = 5 (3-4-5). */
    ck_assert(!boxc(still(5, 1, 13, 14, 5), c));
    ck_assert(boxc(still(5, 1, 12.99, 13.99, 5), c));
    ck_assert(!boxc(still(1, 1, 11, 11, 11), c));
    ck_assert(!boxc(still(1, 1, 10.5, 5, 11), c));
    ck_assert(boxc(still(1, 1, 10.5, 5, 10.5), c));
    /* Sliding along a face in contact, and along the tangent of a rounded corner. */
    ck_assert(!boxc(sweep(1, 1, vec(11, -5, 5), vec(11, 15, 5)), c));
    ck_assert(!boxc(sweep(1, 1, vec(-5, 5, 11), vec(15, 5, 11)), c));
    ck_assert(!boxc(sweep(5, 1, vec(9, 17, 5), vec(17, 11, 5)), c));
    ck_assert(boxc(sweep(5, 1, vec(9, 16.99, 5), vec(17, 10.99, 5)), c));
    /* Arriving at contact at u = 1 and leaving it at u = 0. */
    ck_assert(!boxc(sweep(1, 1, vec(20, 5, 5), vec(11, 5, 5)), c));
    ck_assert(!boxc(sweep(1, 1, vec(5, 5, 11), vec(5, 5, 20)), c));
    ck_assert(boxc(sweep(1, 1, vec(5, 5, 11), vec(5, 5, 5)), c));
}
END_TEST

/* Contact reached or left exactly at a step end by relative motion off the axes, as
 * tests/precision/random_scenarios.py --exact found in planning problems: the answer must
 * be exact, and so the same in float and in double, on inputs with few significant bits.
 * Here |w|^2 = 320 is not a square, so a test that took sqrt(|w|^2) (or the norm of q)
 * before the discriminant rounded the root at u = 1 and reported the touch as a conflict
 * (double) or the conflict one step early (float). The same cases scaled by powers of two,
 * far beyond where fourth powers would overflow or underflow, give the same answers, and
 * so do they scaled into the subnormals (where 2^-e for the inputs' exponent e is not a
 * number of the type: a rescaling by multiplying with it gave inf and NaN, and no
 * conflict even for volumes that overlap throughout). */
#ifdef COA_SINGLE_PRECISION
#define REAL_SUBNORMAL_SCALE ((double)FLT_MIN * 0x1p-8)
#else
#define REAL_SUBNORMAL_SCALE (DBL_MIN * 0x1p-8)
#endif
START_TEST(test_volumes_touching_off_axis)
{
    const double scales[] = {1.0, 0x1p60, 0x1p-60, 0x1p100, 0x1p-100, REAL_SUBNORMAL_SCALE};
    size_t i;

    for (i = 0; i < sizeof scales / sizeof scales[0]; ++i) {
        double k = scales[i];
        coa_sweep_t a = still(5 * k, 2 * k, 0, 0, 0);
        coa_box_t corner = box(vec(-100 * k, -100 * k, -10 * k), vec(0, 0, 10 * k));
        /* q = a - b goes (0, -22) -> (8, -6): |q| = 10 = r_a + r_b only at u = 1. */
        ck_assert(!vols(a, sweep(5 * k, 2 * k, vec(0, 22 * k, 0), vec(-8 * k, 6 * k, 0))));
        /* ... and on from there, inside for u in (0, 0.2). */
        ck_assert(vols(a, sweep(5 * k, 2 * k, vec(-8 * k, 6 * k, 0), vec(-16 * k, -10 * k, 0))));
        /* The same closing speed along y, 9 apart in x: contact (9, 12, 15) at u = 1. */
        ck_assert(!vols(
            still(5 * k, 2.5 * k, 0, 0, 0),
            sweep(10 * k, 2 * k, vec(9 * k, 21 * k, 4.375 * k), vec(9 * k, 12 * k, 4.375 * k))));
        ck_assert(
            vols(still(5 * k, 2.5 * k, 0, 0, 0), sweep(10 * k, 2 * k, vec(9 * k, 12 * k, 4.375 * k),
                                                       vec(9 * k, 3 * k, 4.375 * k))));
        /* A box's rounded corner (its max x, max y edge), reached at u = 1. */
        ck_assert(!boxc(sweep(10 * k, 1 * k, vec(22 * k, 0, 0), vec(6 * k, 8 * k, 0)), corner));
        ck_assert(
            boxc(sweep(10 * k, 1 * k, vec(6 * k, 8 * k, 0), vec(-10 * k, 16 * k, 0)), corner));
    }
}
END_TEST

/* Two volumes that coincide at the start conflict however little they then move. With a
 * displacement whose square is the type's least subnormal, radius^2 * |w|^2 underflows to
 * 0, and the discriminant with it: the disc test reported no conflict. */
#ifdef COA_SINGLE_PRECISION
#define REAL_TINY_STEP 0x1.8p-75
#else
#define REAL_TINY_STEP 0x1.8p-538
#endif
START_TEST(test_volumes_coincident_tiny_step)
{
    coa_sweep_t a = still(0.25, 1, 0, 0, 0);
    coa_real_t w = (coa_real_t)REAL_TINY_STEP;

    ck_assert(w * w > 0);
    ck_assert(vols(a, sweep(0.25, 1, vec(0, 0, 0), vec(REAL_TINY_STEP, 0, 0))));
    ck_assert(vols(a, sweep(0.25, 1, vec(0.125, 0, 0), vec(0.125, REAL_TINY_STEP, 0))));
    /* Apart by more than the radii: still no conflict. */
    ck_assert(!vols(a, sweep(0.25, 1, vec(0.5, 0, 0), vec(0.5, REAL_TINY_STEP, 0))));
}
END_TEST

START_TEST(test_box_motion)
{
    coa_box_t c = cube10();

    /* Straight through: clear at both ends, in conflict in the middle. */
    ck_assert(!boxc(still(1, 1, -5, 5, 5), c));
    ck_assert(!boxc(still(1, 1, 15, 5, 5), c));
    ck_assert(boxc(sweep(1, 1, vec(-5, 5, 5), vec(15, 5, 5)), c));
    ck_assert(boxc(sweep(1, 1, vec(5, 5, 25), vec(5, 5, -15)), c));
    ck_assert(boxc(sweep(1, 1, vec(-5, -5, 5), vec(15, 15, 5)), c));
    /* Only at u = 0 and only at u = 1. */
    ck_assert(boxc(sweep(1, 1, vec(10.5, 5, 5), vec(30, 5, 5)), c));
    ck_assert(boxc(sweep(1, 1, vec(30, 5, 5), vec(10.5, 5, 5)), c));
    /* Only outside the step. */
    ck_assert(!boxc(sweep(1, 1, vec(30, 5, 5), vec(12, 5, 5)), c));
    /* Horizontal overlap for u > 0.7, vertical for u < 0.3: the sweep passes the corner. */
    ck_assert(!boxc(sweep(1, 1, vec(25, 5, 5), vec(5, 5, 25)), c));
    /* Parallel to a face just beyond r, crossing the box's whole z range. */
    ck_assert(!boxc(sweep(1, 1, vec(11.01, 5, 25), vec(11.01, 25, -5)), c));
    /* Inside the box for the whole step. */
    ck_assert(boxc(sweep(1, 1, vec(2, 2, 2), vec(8, 8, 8)), c));
}
END_TEST

START_TEST(test_box_zero_thickness)
{
    coa_box_t floor = box(vec(0, 0, 0), vec(10, 10, 0));
    coa_box_t wall = box(vec(0, 0, 0), vec(0, 10, 10));
    coa_box_t pole = box(vec(0, 0, 0), vec(0, 0, 10));
    coa_box_t point = box(vec(0, 0, 0), vec(0, 0, 0));

    ck_assert(boxc(sweep(1, 1, vec(5, 5, 5), vec(5, 5, -5)), floor));
    ck_assert(!boxc(still(1, 1, 5, 5, 1), floor));
    ck_assert(boxc(still(1, 1, 5, 5, 0.99), floor));
    ck_assert(boxc(still(1, 1, 5, 5, 0), floor));
    ck_assert(!boxc(sweep(1, 1, vec(11, -5, 0), vec(11, 15, 0)), floor));
    ck_assert(boxc(sweep(1, 1, vec(10.9, -5, 0), vec(10.9, 15, 0)), floor));

    ck_assert(boxc(sweep(1, 1, vec(-5, 5, 5), vec(5, 5, 5)), wall));
    ck_assert(!boxc(still(1, 1, -1, 5, 5), wall));
    ck_assert(boxc(still(1, 1, -0.99, 5, 5), wall));
    /* Crossing the wall's plane beside it, within r of its edge only through a corner. */
    ck_assert(!boxc(sweep(1, 1, vec(-5, 11, 5), vec(5, 11, 5)), wall));
    ck_assert(boxc(sweep(1, 1, vec(-5, 10.5, 5), vec(5, 10.5, 5)), wall));

    ck_assert(boxc(sweep(1, 1, vec(-5, 0, 5), vec(5, 0, 5)), pole));
    ck_assert(!boxc(sweep(1, 1, vec(-5, 1, 5), vec(5, 1, 5)), pole));
    ck_assert(boxc(sweep(1, 1, vec(-5, 0.99, 5), vec(5, 0.99, 5)), pole));
    ck_assert(!boxc(sweep(1, 1, vec(-5, 0, 11), vec(5, 0, 11)), pole));

    ck_assert(boxc(sweep(1, 1, vec(-5, 0, 0), vec(5, 0, 0)), point));
    ck_assert(!boxc(sweep(1, 1, vec(-5, 1, 0), vec(5, 1, 0)), point));
    ck_assert(boxc(sweep(1, 1, vec(-5, 0.99, 0), vec(5, 0.99, 0)), point));
    ck_assert(!boxc(sweep(1, 1, vec(-5, -5, 0), vec(11, 7, 0)), point)); /* 3x - 4y = 5 */
    ck_assert(boxc(sweep(1, 1, vec(-5, -4.99, 0), vec(11, 7.01, 0)), point));
    ck_assert(!boxc(still(1, 1, 0, 0, 1), point));
    ck_assert(boxc(still(1, 1, 0, 0, 0.99), point));
}
END_TEST

START_TEST(test_bounds)
{
    coa_sweep_t a = sweep(2, 1, vec(1, 5, -3), vec(-4, 6, 2));
    coa_box_t b = coa_sweep_bounds(&a);
    coa_box_t touching = box(vec(4, 0, 0), vec(9, 9, 9));
    coa_box_t apart = box(vec(4.001, 0, 0), vec(9, 9, 9));
    coa_box_t inside = box(vec(0, 6, 0), vec(0, 6, 0));

    ck_assert(b.min.x == -6 && b.min.y == 3 && b.min.z == -4);
    ck_assert(b.max.x == 3 && b.max.y == 8 && b.max.z == 3);
    b.max.x = 4;
    ck_assert(coa_boxes_touch(&b, &touching));
    ck_assert(coa_boxes_touch(&touching, &b));
    ck_assert(!coa_boxes_touch(&b, &apart));
    ck_assert(!coa_boxes_touch(&apart, &b));
    ck_assert(coa_boxes_touch(&b, &inside));
    ck_assert(coa_boxes_touch(&inside, &inside));
}
END_TEST

/* ---------------------------------------------------------------------------------- */
/* Polytopes.                                                                          */

static void cube_points(coa_vec3_t *pts, double lo, double hi, double shift)
{
    unsigned i;
    for (i = 0; i < 8u; ++i) {
        pts[i] = vec(((i & 1u) ? hi : lo) + shift, ((i & 2u) ? hi : lo) + shift,
                     ((i & 4u) ? hi : lo) + shift);
    }
}

static int polyc(coa_sweep_t a, const coa_vec3_t *pts, size_t n)
{
    coa_polytope_t p;
    p.vertices = pts;
    p.count = n;
    return coa_conflict_polytope(&a, &p);
}

START_TEST(test_polytope_arguments)
{
    coa_vec3_t pts[COA_POLYTOPE_MAX_VERTICES + 1u];
    coa_sweep_t a = sweep(1, 1, vec(-5, 5, 5), vec(15, 5, 5));
    coa_polytope_t p;
    coa_obstacle_t ob;
    size_t i;

    for (i = 0; i < COA_POLYTOPE_MAX_VERTICES + 1u; ++i) {
        pts[i] = vec((double)(i % 2u) * 10.0, (double)((i / 2u) % 2u) * 10.0,
                     (double)((i / 4u) % 2u) * 10.0);
    }
    p.vertices = pts;
    p.count = 8;
    ck_assert_int_eq(coa_conflict_polytope(&a, &p), 1);
    ck_assert_int_eq(coa_conflict_polytope(NULL, &p), COA_ERR_ARGUMENT);
    ck_assert_int_eq(coa_conflict_polytope(&a, NULL), COA_ERR_ARGUMENT);
    p.vertices = NULL;
    ck_assert_int_eq(coa_conflict_polytope(&a, &p), COA_ERR_ARGUMENT);
    p.vertices = pts;
    p.count = 3;
    ck_assert_int_eq(coa_conflict_polytope(&a, &p), COA_ERR_ARGUMENT);
    p.count = 0;
    ck_assert_int_eq(coa_conflict_polytope(&a, &p), COA_ERR_ARGUMENT);
    p.count = COA_POLYTOPE_MAX_VERTICES + 1u;
    ck_assert_int_eq(coa_conflict_polytope(&a, &p), COA_ERR_ARGUMENT);
    p.count = COA_POLYTOPE_MAX_VERTICES;
    ck_assert_int_eq(coa_conflict_polytope(&a, &p), 1);

    /* Non-finite numbers anywhere, even where a broad phase would reject the pair. */
    p.count = 8;
    pts[3].y = (coa_real_t)NAN;
    ck_assert_int_eq(coa_conflict_polytope(&a, &p), COA_ERR_ARGUMENT);
    pts[3].y = (coa_real_t)INFINITY;
    ck_assert_int_eq(coa_conflict_polytope(&a, &p), COA_ERR_ARGUMENT);
    pts[3].y = 10;
    pts[7].z = -(coa_real_t)INFINITY;
    ck_assert_int_eq(coa_conflict_polytope(&a, &p), COA_ERR_ARGUMENT);
    pts[7].z = 10;
    ck_assert_int_eq(coa_conflict_polytope(&a, &p), 1);
    a.p1.x = (coa_real_t)INFINITY;
    ck_assert_int_eq(coa_conflict_polytope(&a, &p), COA_ERR_ARGUMENT);
    a.p1.x = 15;
    a.p0.z = (coa_real_t)NAN;
    ck_assert_int_eq(coa_conflict_polytope(&a, &p), COA_ERR_ARGUMENT);
    a.p0.z = 5;
    a.volume.radius = (coa_real_t)NAN;
    ck_assert_int_eq(coa_conflict_polytope(&a, &p), COA_ERR_ARGUMENT);
    a.volume.radius = 1;
    a.volume.half_height = (coa_real_t)INFINITY;
    ck_assert_int_eq(coa_conflict_polytope(&a, &p), COA_ERR_ARGUMENT);
    a.volume.half_height = 1;
    a.volume.radius = 0;
    ck_assert_int_eq(coa_conflict_polytope(&a, &p), COA_ERR_ARGUMENT);
    a.volume.radius = 1;
    a.volume.half_height = -1;
    ck_assert_int_eq(coa_conflict_polytope(&a, &p), COA_ERR_ARGUMENT);
    a.volume.half_height = 1;
#ifndef COA_SINGLE_PRECISION
    {
        /* A scene of 1e-10 m beside coordinates of 1e300 m: no frame holds both. */
        coa_vec3_t far_pts[8];
        coa_sweep_t tiny = still(1e-10, 1e-10, 1e300, 0, 0);
        cube_points(far_pts, 0, 1e-10, 0);
        for (i = 0; i < 8u; ++i) {
            far_pts[i].x += 1e300;
        }
        ck_assert_int_eq(polyc(tiny, far_pts, 8), COA_ERR_ARGUMENT);
        /* Coordinates of 1e6 m and a scene of micrometres are still resolved. */
        tiny = still(1e-6, 1e-6, 1e6 + 1.5e-6, 0, 5e-7);
        cube_points(far_pts, 0, 1e-6, 0);
        for (i = 0; i < 8u; ++i) {
            far_pts[i].x += 1e6;
        }
        ck_assert_int_eq(polyc(tiny, far_pts, 8), 1);
        tiny.p0.x = tiny.p1.x = 1e6 + 2.5e-6;
        ck_assert_int_eq(polyc(tiny, far_pts, 8), 0);
    }
#endif
    pts[0].x = (coa_real_t)NAN;
    a.p0 = vec(1000, 1000, 1000);
    a.p1 = a.p0;
    ck_assert_int_eq(coa_conflict_polytope(&a, &p), COA_ERR_ARGUMENT);
    pts[0].x = 0;
    ck_assert_int_eq(coa_conflict_polytope(&a, &p), 0);

    /* Dispatch: NULL, an unknown kind, and the polytope's own errors. */
    ob.kind = COA_OBSTACLE_POLYTOPE;
    ob.box = cube10();
    ob.polytope = p;
    a = sweep(1, 1, vec(-5, 5, 5), vec(15, 5, 5));
    ck_assert_int_eq(coa_conflict_obstacle(&a, &ob), 1);
    ck_assert_int_eq(coa_conflict_obstacle(NULL, &ob), COA_ERR_ARGUMENT);
    ck_assert_int_eq(coa_conflict_obstacle(&a, NULL), COA_ERR_ARGUMENT);
    ob.polytope.count = 2;
    ck_assert_int_eq(coa_conflict_obstacle(&a, &ob), COA_ERR_ARGUMENT);
    ob.kind = COA_OBSTACLE_BOX;
    ck_assert_int_eq(coa_conflict_obstacle(&a, &ob), 1);
    ob.kind = (coa_obstacle_kind_t)7;
    ck_assert_int_eq(coa_conflict_obstacle(&a, &ob), COA_ERR_ARGUMENT);
}
END_TEST

START_TEST(test_polytope_cases)
{
    coa_vec3_t cube[8];
    coa_vec3_t tet[4] = {{0, 0, 0}, {4, 0, 0}, {0, 4, 0}, {0, 0, 4}};
    coa_vec3_t square[4] = {{0, 0, 0}, {10, 0, 0}, {10, 10, 0}, {0, 10, 0}};

    cube_points(cube, 0, 10, 0);
    /* Near contact on either side of a face, an edge and a vertex. */
    ck_assert_int_eq(polyc(still(1, 1, 11.01, 5, 5), cube, 8), 0);
    ck_assert_int_eq(polyc(still(1, 1, 10.99, 5, 5), cube, 8), 1);
    ck_assert_int_eq(polyc(still(1, 1, 5, 5, 11.01), cube, 8), 0);
    ck_assert_int_eq(polyc(still(1, 1, 5, 5, 10.99), cube, 8), 1);
    ck_assert_int_eq(polyc(still(5, 1, 13.01, 14.01, 5), cube, 8), 0);
    ck_assert_int_eq(polyc(still(5, 1, 12.99, 13.99, 5), cube, 8), 1);
    ck_assert_int_eq(polyc(still(1, 1, 11.01, 11.01, 11.01), cube, 8), 0);
    ck_assert_int_eq(polyc(still(1, 1, 10.5, 10.5, 10.99), cube, 8), 1);
    /* Only in the middle of the step, only at u = 0, only at u = 1, never. */
    ck_assert_int_eq(polyc(sweep(1, 1, vec(-5, 5, 5), vec(15, 5, 5)), cube, 8), 1);
    ck_assert_int_eq(polyc(sweep(1, 1, vec(-5, -5, 15), vec(15, 15, -5)), cube, 8), 1);
    ck_assert_int_eq(polyc(sweep(1, 1, vec(10.5, 5, 5), vec(30, 5, 5)), cube, 8), 1);
    ck_assert_int_eq(polyc(sweep(1, 1, vec(30, 5, 5), vec(10.5, 5, 5)), cube, 8), 1);
    ck_assert_int_eq(polyc(sweep(1, 1, vec(30, 5, 5), vec(11.5, 5, 5)), cube, 8), 0);
    /* The swept volume, not its bounding box: the path passes a corner diagonally. */
    ck_assert_int_eq(polyc(sweep(1, 1, vec(25, 5, 5), vec(5, 5, 25)), cube, 8), 0);
    ck_assert_int_eq(polyc(sweep(1, 1, vec(15, 5, 5), vec(5, 5, 15)), cube, 8), 1);
    /* Inside for the whole step; the sweep's midpoint at the polytope's centre. */
    ck_assert_int_eq(polyc(sweep(1, 1, vec(2, 2, 2), vec(8, 8, 8)), cube, 8), 1);
    ck_assert_int_eq(polyc(still(1, 1, 5, 5, 5), cube, 8), 1);
    /* A tetrahedron: near its slanted face x + y + z = 4 (normal (1,1,1)/sqrt(3)). */
    ck_assert_int_eq(polyc(still(0.5, 0.5, 2.2, 2.2, 2.2), tet, 4), 0);
    ck_assert_int_eq(polyc(still(0.5, 0.5, 1.6, 1.6, 1.6), tet, 4), 1);
    ck_assert_int_eq(polyc(sweep(0.5, 0.5, vec(5, 5, 5), vec(-5, -5, -5)), tet, 4), 1);
    /* A flat polytope (coplanar points): crossed and passed. */
    ck_assert_int_eq(polyc(sweep(1, 1, vec(5, 5, 5), vec(5, 5, -5)), square, 4), 1);
    ck_assert_int_eq(polyc(still(1, 1, 5, 5, 1.01), square, 4), 0);
    ck_assert_int_eq(polyc(sweep(1, 1, vec(11.01, -5, 0), vec(11.01, 15, 0)), square, 4), 0);
    ck_assert_int_eq(polyc(sweep(1, 1, vec(10.9, -5, 0), vec(10.9, 15, 0)), square, 4), 1);
}
END_TEST

/* Far from the origin the test still resolves centimetres: everything is moved to the
 * sweep's midpoint before MPR sees it. */
START_TEST(test_polytope_far_away)
{
#ifdef COA_SINGLE_PRECISION
    const double far[] = {1e3, -2e3};
#else
    const double far[] = {1e6, -3e7};
#endif
    size_t k;

    for (k = 0; k < sizeof far / sizeof far[0]; ++k) {
        double s = far[k];
        coa_vec3_t cube[8];
        cube_points(cube, 0, 10, s);
        ck_assert_int_eq(polyc(still(1, 1, s + 11.01, s + 5, s + 5), cube, 8), 0);
        ck_assert_int_eq(polyc(still(1, 1, s + 10.99, s + 5, s + 5), cube, 8), 1);
        ck_assert_int_eq(
            polyc(sweep(1, 1, vec(s - 5, s + 5, s + 5), vec(s + 15, s + 5, s + 5)), cube, 8), 1);
        ck_assert_int_eq(
            polyc(sweep(1, 1, vec(s + 25, s + 5, s + 5), vec(s + 5, s + 5, s + 25)), cube, 8), 0);
    }
}
END_TEST

/* Whole scenes from the tiny to the huge, and a small volume deep inside a huge polytope:
 * MPR's arithmetic reaches the fourth power of the coordinates and its zero tests are
 * absolute, so this only works because the scene is normalised first. */
START_TEST(test_polytope_extreme_scales)
{
#ifdef COA_SINGLE_PRECISION
    const double scales[] = {1e-30, 1e-3, 1e3, 1e30};
#else
    const double scales[] = {1e-200, 1e-3, 1e3, 1e100, 1e200, 1e300};
#endif
    size_t k;

    for (k = 0; k < sizeof scales / sizeof scales[0]; ++k) {
        double s = scales[k];
        coa_vec3_t cube[8];
        cube_points(cube, 0, 10 * s, 0);
        ck_assert_int_eq(polyc(still(s, s, 11.01 * s, 5 * s, 5 * s), cube, 8), 0);
        ck_assert_int_eq(polyc(still(s, s, 10.99 * s, 5 * s, 5 * s), cube, 8), 1);
        ck_assert_int_eq(
            polyc(sweep(s, s, vec(-5 * s, 5 * s, 5 * s), vec(15 * s, 5 * s, 5 * s)), cube, 8), 1);
        ck_assert_int_eq(
            polyc(sweep(s, s, vec(25 * s, 5 * s, 5 * s), vec(5 * s, 5 * s, 25 * s)), cube, 8), 0);
        cube_points(cube, -s, s, 0);
        ck_assert_int_eq(polyc(still(1, 1, 0.99 * s, 0, 0), cube, 8), 1);
        ck_assert_int_eq(polyc(still(1, 1, 1.01 * s, 0.3 * s, 0), cube, 8), s > 100 ? 0 : 1);
    }
}
END_TEST

/* A vast polytope against a small volume near its face: a scene where MPR has the most
 * refining to do. The answers must still be right and come back (the budget bounds it). */
START_TEST(test_polytope_scale_contrast)
{
    coa_vec3_t big[8];
    cube_points(big, -1e5, 1e5, 0);
    ck_assert_int_eq(polyc(still(0.5, 0.5, 1e5 + 0.6, 3, -7), big, 8), 0);
    ck_assert_int_eq(polyc(still(0.5, 0.5, 1e5 + 0.4, 3, -7), big, 8), 1);
    ck_assert_int_eq(polyc(sweep(0.5, 0.5, vec(1e5 + 0.6, -3, 7), vec(1e5 + 0.6, 4, -7)), big, 8),
                     0);
}
END_TEST

/* MPR is at its hardest when the origin is within rounding of the Minkowski difference's
 * boundary, which is where its loops would spin without the support-call budget. Walk a
 * volume out from inside random polytopes along a ray and bisect the answer's flip 60
 * times, down to the last bit: every call must come back, and the flip must sit where
 * GJK puts the contact. (The ray starts inside a convex set, so the answer is 1 then 0.) */
START_TEST(test_polytope_near_contact)
{
    rng_t r = {0xC0DEu};
    unsigned k;

    for (k = 0; k < 300u; ++k) {
        coa_vec3_t pts[12];
        size_t n = rng_points(&r, pts);
        coa_box_t bb = points_bounds(pts, n);
        double c[3] = {0, 0, 0};
        double e[3];
        double len, lo = 0, hi, size, rad, hh;
        coa_polytope_t poly;
        coa_sweep_t probe;
        poly_ctx_t ctx;
        unsigned i;
        int b;

        for (i = 0; i < n; ++i) {
            c[0] += (double)pts[i].x / (double)n;
            c[1] += (double)pts[i].y / (double)n;
            c[2] += (double)pts[i].z / (double)n;
        }
        do {
            e[0] = rng_range(&r, -1, 1);
            e[1] = rng_range(&r, -1, 1);
            e[2] = rng_range(&r, -1, 1);
            len = sqrt(e[0] * e[0] + e[1] * e[1] + e[2] * e[2]);
        } while (len < 0.1);
        size = fmax((double)(bb.max.x - bb.min.x), (double)(bb.max.y - bb.min.y));
        size = fmax(size, (double)(bb.max.z - bb.min.z));
        rad = rng_range(&r, 0.05, 1.0) * size;
        hh = rng_range(&r, 0.05, 1.0) * size;
        hi = 2 * size + rad + hh;
        poly.vertices = pts;
        poly.count = n;
        for (b = 0; b < 60; ++b) {
            double t = 0.5 * (lo + hi);
            int got;
            probe =
                still(rad, hh, c[0] + t * e[0] / len, c[1] + t * e[1] / len, c[2] + t * e[2] / len);
            got = coa_conflict_polytope(&probe, &poly);
            ck_assert(got == 0 || got == 1);
            if (got) {
                lo = t;
            } else {
                hi = t;
            }
        }
        ck_assert(lo > 0);
        ctx.p = &poly;
        ctx.bounds = bb;
        ctx.a = &probe;
        probe =
            still(rad, hh, c[0] + (lo - 1e-3 * size) * e[0] / len,
                  c[1] + (lo - 1e-3 * size) * e[1] / len, c[2] + (lo - 1e-3 * size) * e[2] / len);
        ck_assert_msg(poly_inst(&ctx, 0, 1.0), "case %u: GJK finds no contact inside", k);
        probe =
            still(rad, hh, c[0] + (lo + 1e-3 * size) * e[0] / len,
                  c[1] + (lo + 1e-3 * size) * e[1] / len, c[2] + (lo + 1e-3 * size) * e[2] / len);
        ck_assert_msg(!poly_inst(&ctx, 0, 1.0), "case %u: GJK finds contact outside", k);
    }
}
END_TEST

/* The obstacle check the planner and the predictor both rely on before any test runs. */
START_TEST(test_obstacle_check)
{
    coa_vec3_t pts[5] = {vec(0, 0, 0), vec(1, 0, 0), vec(0, 1, 0), vec(0, 0, 1), vec(1, 1, 1)};
    coa_obstacle_t o;

    memset(&o, 0, sizeof o);
    o.kind = COA_OBSTACLE_BOX;
    o.box.min = vec(0, 0, 0);
    o.box.max = vec(1, 2, 3);
    ck_assert_int_eq(coa_obstacle_check(&o), COA_OK);
    o.box.max = vec(1, 0, 3); /* zero thickness is a box */
    ck_assert_int_eq(coa_obstacle_check(&o), COA_OK);
    o.box.max = vec(1, -0.5, 3); /* inverted on y */
    ck_assert_int_eq(coa_obstacle_check(&o), COA_ERR_ARGUMENT);
    o.box.max = vec(1, 2, (double)INFINITY);
    ck_assert_int_eq(coa_obstacle_check(&o), COA_ERR_ARGUMENT);

    o.kind = COA_OBSTACLE_POLYTOPE;
    o.polytope.vertices = pts;
    o.polytope.count = 5u;
    ck_assert_int_eq(coa_obstacle_check(&o), COA_OK);
    o.polytope.count = 3u;
    ck_assert_int_eq(coa_obstacle_check(&o), COA_ERR_ARGUMENT);
    o.polytope.count = COA_POLYTOPE_MAX_VERTICES + 1u;
    ck_assert_int_eq(coa_obstacle_check(&o), COA_ERR_ARGUMENT);
    o.polytope.count = 5u;
    pts[4] = vec((double)NAN, 0, 0);
    ck_assert_int_eq(coa_obstacle_check(&o), COA_ERR_ARGUMENT);
    o.polytope.vertices = NULL;
    ck_assert_int_eq(coa_obstacle_check(&o), COA_ERR_ARGUMENT);

    o.kind = (coa_obstacle_kind_t)7;
    ck_assert_int_eq(coa_obstacle_check(&o), COA_ERR_ARGUMENT);
    ck_assert_int_eq(coa_obstacle_check(NULL), COA_ERR_ARGUMENT);
}
END_TEST

static Suite *geometry_suite(void)
{
    Suite *s = suite_create("geometry");
    TCase *hand = tcase_create("hand");
    TCase *random = tcase_create("random");

    tcase_add_test(hand, test_volumes_touching);
    tcase_add_test(hand, test_obstacle_check);
    tcase_add_test(hand, test_volumes_touching_off_axis);
    tcase_add_test(hand, test_volumes_coincident_tiny_step);
    tcase_add_test(hand, test_volumes_crossing);
    tcase_add_test(hand, test_volumes_step_ends);
    tcase_add_test(hand, test_volumes_degenerate_motion);
    tcase_add_test(hand, test_box_touching);
    tcase_add_test(hand, test_box_motion);
    tcase_add_test(hand, test_box_zero_thickness);
    tcase_add_test(hand, test_bounds);
    tcase_add_test(hand, test_polytope_arguments);
    tcase_add_test(hand, test_polytope_cases);
    tcase_add_test(hand, test_polytope_far_away);
    tcase_add_test(hand, test_polytope_scale_contrast);
    tcase_add_test(hand, test_polytope_extreme_scales);
    tcase_add_test(hand, test_polytope_near_contact);
    suite_add_tcase(s, hand);

    tcase_set_timeout(random, 300);
    tcase_add_test(random, test_volumes_random);
    tcase_add_test(random, test_box_random);
    tcase_add_test(random, test_polytope_random);
    tcase_add_test(random, test_box_as_polytope_random);
    suite_add_tcase(s, random);
    return s;
}

int main(void)
{
    SRunner *sr = srunner_create(geometry_suite());
    int failed;

    srunner_run_all(sr, CK_NORMAL);
    failed = srunner_ntests_failed(sr);
    srunner_free(sr);
    return failed == 0 ? EXIT_SUCCESS : EXIT_FAILURE;
}
