/* SPDX-License-Identifier: MIT */
/*
 * trajectory.c: vehicle and track validation, reference and track sampling, the action
 * lattice and the exact integer step costs (see trajectory.h for the contract).
 */
#include "coavoid/trajectory.h"

#include <float.h>
#include <math.h>

#include "internal.h"

#define INT64_LIMIT ((uint64_t)INT64_MAX)

/* ------------------------------------------------------------------------------------ */
/* Small numeric helpers                                                                 */

static bool real_finite(coa_real_t x)
{
    return isfinite(x) != 0;
}

static bool real_positive(coa_real_t x)
{
    return isfinite(x) != 0 && x > (coa_real_t)0;
}

static bool vec_finite(const coa_vec3_t *p)
{
    return real_finite(p->x) && real_finite(p->y) && real_finite(p->z);
}

static coa_vec3_t vec_lerp(const coa_vec3_t *p0, const coa_vec3_t *p1, coa_real_t u)
{
    /* Anchored at p0 so that u == 0 gives p0 exactly (route corners, path points). */
    coa_vec3_t r;
    r.x = p0->x + u * (p1->x - p0->x);
    r.y = p0->y + u * (p1->y - p0->y);
    r.z = p0->z + u * (p1->z - p0->z);
    return r;
}

static coa_real_t horizontal_length(const coa_vec3_t *p0, const coa_vec3_t *p1)
{
    return real_norm2(p1->x - p0->x, p1->y - p0->y);
}

static uint64_t magnitude(int32_t a)
{
    return a < 0 ? (uint64_t)(-(int64_t)a) : (uint64_t)a;
}

/* floor(num * scale / den) without an intermediate overflow, saturating at INT64_MAX.
 * The planner's costs only ever take the exact branch (scale % den == 0). */
static int64_t mul_div_floor(uint64_t num, uint64_t scale, uint64_t den)
{
    uint64_t q = scale / den;
    uint64_t r = scale % den;
    uint64_t whole;
    uint64_t part;

    if (q != 0u && num > INT64_LIMIT / q) {
        return INT64_MAX;
    }
    whole = num * q;
    if (r == 0u) {
        part = 0u;
    } else if (num <= UINT64_MAX / r) {
        part = num * r / den;
    } else {
        uint64_t rest = num % den;
        if (rest > UINT64_MAX / r || num / den > INT64_LIMIT / r) {
            return INT64_MAX;
        }
        part = (num / den) * r + rest * r / den;
    }
    if (part > INT64_LIMIT - whole) {
        return INT64_MAX;
    }
    return (int64_t)(whole + part);
}

/* ------------------------------------------------------------------------------------ */
/* Vehicles and the reference trajectory                                                 */

int coa_vehicle_check(const coa_vehicle_t *v)
{
    int64_t initial;
    coa_real_t total = (coa_real_t)0;
    size_t i;

    if (v == NULL) {
        return COA_ERR_ARGUMENT;
    }
    if (v->id == 0u || v->priority == 0u) {
        return COA_ERR_ARGUMENT;
    }
    if (!real_positive(v->cruise_speed) || !real_positive(v->climb_rate)) {
        return COA_ERR_ARGUMENT;
    }
    if (v->steep_factor < 2u || v->steep_factor > COA_MAX_STEEP_FACTOR) {
        return COA_ERR_ARGUMENT;
    }
    if (!real_positive(v->volume.radius) || !real_positive(v->volume.half_height)) {
        return COA_ERR_ARGUMENT;
    }
    initial = v->initial_offset < 0 ? -(int64_t)v->initial_offset : (int64_t)v->initial_offset;
    if (initial > COA_MAX_OFFSET) {
        return COA_ERR_ARGUMENT;
    }
    if (v->max_offset >= 0 && initial > (int64_t)v->max_offset) {
        return COA_ERR_ARGUMENT;
    }
    if (v->route == NULL || v->route_count < 2u) {
        return COA_ERR_ARGUMENT;
    }
    for (i = 0; i < v->route_count; ++i) {
        if (!vec_finite(&v->route[i])) {
            return COA_ERR_ARGUMENT;
        }
    }
    /* Finite differences and a finite total length keep every interpolation below finite. */
    for (i = 0; i + 1u < v->route_count; ++i) {
        coa_real_t len = horizontal_length(&v->route[i], &v->route[i + 1u]);
        if (!real_positive(len) || !real_finite(v->route[i + 1u].z - v->route[i].z)) {
            return COA_ERR_ARGUMENT;
        }
        total += len;
        if (!real_finite(total)) {
            return COA_ERR_ARGUMENT;
        }
    }
    return COA_OK;
}

/* A position on the route, kept between calls so that sampling increasing distances is
 * one walk along the route. coa_reference_at and coa_reference_sample both go through
 * ref_walk_to with the same arithmetic, so they agree bit for bit. */
typedef struct {
    size_t leg;        /* the current leg runs from route[leg] to route[leg + 1] */
    coa_real_t start;  /* distance along the route where the current leg starts */
    coa_real_t length; /* the current leg's horizontal length */
} ref_walk_t;

static void ref_walk_init(const coa_vehicle_t *v, ref_walk_t *w)
{
    w->leg = 0;
    w->start = (coa_real_t)0;
    w->length = horizontal_length(&v->route[0], &v->route[1]);
}

/* The reference at horizontal distance d along the route; d must not decrease between
 * calls on one walk. Past the last point the last leg is extended, which keeps its
 * horizontal direction and its slope; a corner reached exactly gives the route point. */
static coa_vec3_t ref_walk_to(const coa_vehicle_t *v, ref_walk_t *w, coa_real_t d)
{
    size_t last_leg = v->route_count - 2u;
    coa_real_t u;

    while (w->leg < last_leg && d >= w->start + w->length) {
        w->start += w->length;
        w->leg += 1u;
        w->length = horizontal_length(&v->route[w->leg], &v->route[w->leg + 1u]);
    }
    u = (d - w->start) / w->length;
    return vec_lerp(&v->route[w->leg], &v->route[w->leg + 1u], u);
}

coa_vec3_t coa_reference_at(const coa_vehicle_t *v, coa_real_t t)
{
    ref_walk_t w;
    ref_walk_init(v, &w);
    return ref_walk_to(v, &w, v->cruise_speed * t);
}

static bool sampling_ok(coa_real_t dt, uint32_t horizon)
{
    return real_positive(dt) && horizon >= 1u && horizon <= COA_MAX_HORIZON;
}

int coa_reference_sample(const coa_vehicle_t *v, coa_real_t dt, uint32_t horizon, coa_vec3_t *out)
{
    ref_walk_t w;
    uint32_t k;

    if (v == NULL || out == NULL || !sampling_ok(dt, horizon)) {
        return COA_ERR_ARGUMENT;
    }
    if (coa_vehicle_check(v) != COA_OK) {
        return COA_ERR_ARGUMENT;
    }
    ref_walk_init(v, &w);
    for (k = 0; k <= horizon; ++k) {
        coa_real_t t = (coa_real_t)k * dt;
        out[k] = ref_walk_to(v, &w, v->cruise_speed * t);
        /* A dt so large that the extrapolation overflows would hand the geometry
         * non-finite points, which its tests take as a precondition. */
        if (!vec_finite(&out[k])) {
            return COA_ERR_ARGUMENT;
        }
    }
    return COA_OK;
}

/* ------------------------------------------------------------------------------------ */
/* Tracks                                                                                */

int coa_track_check(const coa_track_t *tr)
{
    size_t i;

    if (tr == NULL) {
        return COA_ERR_ARGUMENT;
    }
    if (!real_positive(tr->volume.radius) || !real_positive(tr->volume.half_height)) {
        return COA_ERR_ARGUMENT;
    }
    if (!vec_finite(&tr->position) || !vec_finite(&tr->velocity)) {
        return COA_ERR_ARGUMENT;
    }
    if (!real_finite(tr->sigma_horizontal) || tr->sigma_horizontal < (coa_real_t)0 ||
        !real_finite(tr->sigma_vertical) || tr->sigma_vertical < (coa_real_t)0) {
        return COA_ERR_ARGUMENT;
    }
    if (tr->path_count == 0u) {
        return COA_OK;
    }
    if (tr->path == NULL) {
        return COA_ERR_ARGUMENT;
    }
    for (i = 0; i < tr->path_count; ++i) {
        const coa_track_point_t *q = &tr->path[i];
        if (!real_finite(q->t) || !vec_finite(&q->p)) {
            return COA_ERR_ARGUMENT;
        }
        if (i > 0u) {
            const coa_track_point_t *p = &tr->path[i - 1u];
            coa_vec3_t d;
            d.x = q->p.x - p->p.x;
            d.y = q->p.y - p->p.y;
            d.z = q->p.z - p->p.z;
            /* Strictly ascending, with a finite duration and displacement per leg, so the
             * interpolation never divides by zero or overflows. */
            if (!real_positive(q->t - p->t) || !vec_finite(&d)) {
                return COA_ERR_ARGUMENT;
            }
        }
    }
    return COA_OK;
}

/* The track at time t. `leg` is the path leg to start searching from; t must not
 * decrease between calls sharing it. Both coa_track_at and coa_track_sample use this, so
 * they agree bit for bit. */
static coa_vec3_t track_eval(const coa_track_t *tr, coa_real_t t, size_t *leg)
{
    const coa_track_point_t *path = tr->path;
    size_t last;
    size_t i;
    coa_real_t u;

    if (tr->path_count == 0u) {
        coa_vec3_t r;
        r.x = tr->position.x + t * tr->velocity.x;
        r.y = tr->position.y + t * tr->velocity.y;
        r.z = tr->position.z + t * tr->velocity.z;
        return r;
    }
    if (tr->path_count == 1u) {
        return path[0].p;
    }
    last = tr->path_count - 1u;
    if (!(t < path[last].t)) {
        /* Anchored at the last point (exact there), moving on with the last leg's velocity. */
        u = (t - path[last].t) / (path[last].t - path[last - 1u].t);
        {
            coa_vec3_t r;
            r.x = path[last].p.x + u * (path[last].p.x - path[last - 1u].p.x);
            r.y = path[last].p.y + u * (path[last].p.y - path[last - 1u].p.y);
            r.z = path[last].p.z + u * (path[last].p.z - path[last - 1u].p.z);
            return r;
        }
    }
    /* Before the first point leg 0 is used with u < 0: the first leg's velocity. */
    i = *leg;
    while (i + 1u < last && t >= path[i + 1u].t) {
        i += 1u;
    }
    *leg = i;
    u = (t - path[i].t) / (path[i + 1u].t - path[i].t);
    return vec_lerp(&path[i].p, &path[i + 1u].p, u);
}

coa_vec3_t coa_track_at(const coa_track_t *tr, coa_real_t t)
{
    size_t leg = 0;
    return track_eval(tr, t, &leg);
}

int coa_track_sample(const coa_track_t *tr, coa_real_t dt, uint32_t horizon, coa_vec3_t *out)
{
    size_t leg = 0;
    uint32_t k;

    if (tr == NULL || out == NULL || !sampling_ok(dt, horizon)) {
        return COA_ERR_ARGUMENT;
    }
    if (coa_track_check(tr) != COA_OK) {
        return COA_ERR_ARGUMENT;
    }
    for (k = 0; k <= horizon; ++k) {
        out[k] = track_eval(tr, (coa_real_t)k * dt, &leg);
        if (!vec_finite(&out[k])) {
            return COA_ERR_ARGUMENT;
        }
    }
    return COA_OK;
}

/* ------------------------------------------------------------------------------------ */
/* Actions                                                                               */

coa_real_t coa_climb_step(const coa_vehicle_t *v, coa_real_t dt)
{
    return v->climb_rate * dt;
}

int32_t coa_action_delta(coa_action_t action, uint32_t steep_factor)
{
    int32_t s = steep_factor > (uint32_t)INT32_MAX ? INT32_MAX : (int32_t)steep_factor;

    switch (action) {
    case COA_ACTION_CLIMB:
        return 1;
    case COA_ACTION_DIVE:
        return -1;
    case COA_ACTION_STEEP_CLIMB:
        return s;
    case COA_ACTION_STEEP_DIVE:
        return -s;
    case COA_ACTION_LEVEL:
    default:
        return 0;
    }
}

uint32_t coa_action_effort(coa_action_t action)
{
    switch (action) {
    case COA_ACTION_CLIMB:
    case COA_ACTION_DIVE:
        return 1u;
    case COA_ACTION_STEEP_CLIMB:
    case COA_ACTION_STEEP_DIVE:
        return 3u;
    case COA_ACTION_LEVEL:
    default:
        return 0u;
    }
}

const char *coa_action_name(coa_action_t action)
{
    switch (action) {
    case COA_ACTION_CLIMB:
        return "climb";
    case COA_ACTION_DIVE:
        return "dive";
    case COA_ACTION_STEEP_CLIMB:
        return "steep_climb";
    case COA_ACTION_STEEP_DIVE:
        return "steep_dive";
    case COA_ACTION_LEVEL:
    default:
        /* An unknown action behaves as level everywhere else, so it is named so. */
        return "level";
    }
}

int coa_action_between(int32_t a, int32_t b, uint32_t steep_factor)
{
    int64_t d = (int64_t)b - (int64_t)a;

    /* Checked in generation order, so that a degenerate steep factor (0 or 1) still maps
     * to the cheapest action. */
    if (d == 0) {
        return (int)COA_ACTION_LEVEL;
    }
    if (d == 1) {
        return (int)COA_ACTION_CLIMB;
    }
    if (d == -1) {
        return (int)COA_ACTION_DIVE;
    }
    if (d == (int64_t)steep_factor) {
        return (int)COA_ACTION_STEEP_CLIMB;
    }
    if (d == -(int64_t)steep_factor) {
        return (int)COA_ACTION_STEEP_DIVE;
    }
    return -1;
}

/* ------------------------------------------------------------------------------------ */
/* Costs                                                                                 */

static bool crosses(int32_t a, int32_t b)
{
    return (a < 0 && b > 0) || (a > 0 && b < 0);
}

double coa_area(int32_t a, int32_t b)
{
    double fa = (double)a;
    double fb = (double)b;

    if (crosses(a, b)) {
        return (fa * fa + fb * fb) / (2.0 * fabs(fa - fb));
    }
    return (fabs(fa) + fabs(fb)) / 2.0;
}

int64_t coa_area_scaled(int32_t a, int32_t b, uint32_t scale)
{
    uint64_t ma = magnitude(a);
    uint64_t mb = magnitude(b);

    if (crosses(a, b)) {
        /* |a - b| = |a| + |b| when the signs differ; a^2 + b^2 <= 2^63 fits. */
        return mul_div_floor(ma * ma + mb * mb, scale, 2u * (ma + mb));
    }
    return mul_div_floor(ma + mb, scale, 2u);
}

int64_t coa_heuristic_scaled(int32_t a, uint32_t steps_left, uint32_t steep_factor, uint32_t scale)
{
    uint64_t m = magnitude(a);
    uint64_t r = steps_left;
    /* Climb and dive shrink the offset by 1 a step whatever s is, so a degenerate steep
     * factor must not make the bound claim less shrinkage than that. */
    uint64_t s = steep_factor < 1u ? 1u : steep_factor;
    uint64_t sr = s * r;

    if (m == 0u || r == 0u) {
        return 0;
    }
    if (m <= sr) {
        /* The profile reaches the reference within the horizon: the triangle a^2 / (2s). */
        return mul_div_floor(m * m, scale, 2u * s);
    }
    /* The horizon ends first: R|a| - sR^2/2 = R(2|a| - sR)/2. Here sR < |a| <= 2^31, so
     * R < 2^31 and the product stays below 2^63. */
    return mul_div_floor(r * (2u * m - sr), scale, 2u);
}

static uint32_t gcd_u32(uint32_t a, uint32_t b)
{
    /* Euclid on values <= 2 * lcm(2..COA_MAX_STEEP_FACTOR): a handful of iterations. */
    while (b != 0u) {
        uint32_t t = a % b;
        a = b;
        b = t;
    }
    return a;
}

uint32_t coa_area_scale(const coa_vehicle_t *vehicles, size_t n)
{
    uint32_t scale = 1u;
    size_t i;

    if (vehicles == NULL || n == 0u) {
        return 0u;
    }
    for (i = 0; i < n; ++i) {
        uint32_t s = vehicles[i].steep_factor;
        uint32_t step;
        if (s < 2u || s > COA_MAX_STEEP_FACTOR) {
            return 0u;
        }
        step = 2u * s;
        /* Bounded by 2 * lcm(2..10) = 5040, so no overflow. */
        scale = scale / gcd_u32(scale, step) * step;
    }
    return scale;
}

/* The bit reading below is only right for IEEE 754 binary64 stored in the byte order of
 * uint64_t, as on x86, ARM EABI and every target the core is built for. */
_Static_assert(sizeof(double) == sizeof(uint64_t) && DBL_MANT_DIG == 53 && DBL_MAX_EXP == 1024 &&
                   DBL_MIN_EXP == -1021,
               "coa_deviation_weights needs IEEE 754 binary64 doubles");

/* A positive finite double as mant * 2^e exactly, mant odd. Read from the bits rather
 * than with frexp so no libm rounding mode or implementation can enter: binary64 is a
 * 52-bit fraction, an 11-bit biased exponent and, unless subnormal, an implicit 1. */
static void split_double(double x, uint64_t *mant, int *e_out)
{
    union {
        double d;
        uint64_t u;
    } bits;
    uint64_t field;
    uint64_t m;
    int e;

    bits.d = x;
    field = (bits.u >> 52) & UINT64_C(0x7ff);
    m = bits.u & ((UINT64_C(1) << 52) - 1u);
    if (field == 0u) {
        e = -1074; /* subnormal: no implicit bit */
    } else {
        m |= UINT64_C(1) << 52;
        e = (int)field - 1075;
    }
    /* x > 0, so m != 0 and this ends within 53 steps. */
    while ((m & 1u) == 0u) {
        m >>= 1;
        ++e;
    }
    *mant = m;
    *e_out = e;
}

/* w = fl(fl(v * dt) * fl(c * dt)) in double, or false when a factor or the product is not
 * finite and positive. Both passes below go through here, so they see the same w. */
static bool vehicle_weight(const coa_vehicle_t *v, double step, double *w)
{
    double l = (double)v->cruise_speed * step;
    double dh = (double)v->climb_rate * step;
    double p = l * dh;
    /* Each factor must be positive on its own: two negative speeds multiply to a positive
     * product. */
    if (!(isfinite(l) && l > 0.0 && isfinite(dh) && dh > 0.0 && isfinite(p) && p > 0.0)) {
        return false;
    }
    *w = p;
    return true;
}

int coa_deviation_weights(const coa_vehicle_t *vehicles, size_t n, coa_real_t dt, uint64_t *weights,
                          int *exponent)
{
    double step = (double)dt;
    int low = 0;
    size_t i;

    if (vehicles == NULL || weights == NULL || exponent == NULL || n == 0u ||
        !(isfinite(step) && step > 0.0)) {
        return COA_ERR_ARGUMENT;
    }
    /* The common exponent is the smallest of the weights' own (odd mantissa) exponents:
     * every weight is then an integer multiple of 2^low, and the one that sets it is odd,
     * so no common factor of two is left. */
    for (i = 0; i < n; ++i) {
        double w;
        uint64_t m;
        int e;
        if (!vehicle_weight(&vehicles[i], step, &w)) {
            return COA_ERR_ARGUMENT;
        }
        split_double(w, &m, &e);
        if (i == 0u || e < low) {
            low = e;
        }
    }
    for (i = 0; i < n; ++i) {
        double w = 0.0;
        uint64_t m;
        int e;
        int shift;
        (void)vehicle_weight(&vehicles[i], step, &w);
        split_double(w, &m, &e);
        shift = e - low;
        if (shift >= 64 || m > (UINT64_MAX >> shift)) {
            return COA_ERR_RANGE;
        }
        weights[i] = m << shift;
    }
    *exponent = low;
    return COA_OK;
}

coa_cost_t coa_cost_add(coa_cost_t a, coa_cost_t b)
{
    coa_cost_t r;
    r.lo = a.lo + b.lo;
    r.hi = a.hi + b.hi + (r.lo < a.lo ? 1u : 0u);
    return r;
}

coa_cost_t coa_cost_mul(uint64_t a, uint64_t b)
{
    /* Schoolbook on 32-bit halves: every partial product fits 64 bits, and so does the
     * middle column (at most 3 * (2^32 - 1)), which a 32-bit core does with UMULL. */
    const uint64_t mask = UINT64_C(0xffffffff);
    uint64_t a0 = a & mask;
    uint64_t a1 = a >> 32;
    uint64_t b0 = b & mask;
    uint64_t b1 = b >> 32;
    uint64_t p00 = a0 * b0;
    uint64_t p01 = a0 * b1;
    uint64_t p10 = a1 * b0;
    uint64_t p11 = a1 * b1;
    uint64_t mid = (p00 >> 32) + (p01 & mask) + (p10 & mask);
    coa_cost_t r;
    r.lo = (mid << 32) | (p00 & mask);
    r.hi = p11 + (p01 >> 32) + (p10 >> 32) + (mid >> 32);
    return r;
}

int coa_cost_compare(coa_cost_t a, coa_cost_t b)
{
    if (a.hi != b.hi) {
        return a.hi < b.hi ? -1 : 1;
    }
    if (a.lo != b.lo) {
        return a.lo < b.lo ? -1 : 1;
    }
    return 0;
}
