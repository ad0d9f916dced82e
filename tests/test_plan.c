/* SPDX-License-Identifier: MIT */
/*
 * test_plan.c: the A* planner against exhaustive searches written here, plus the budget,
 * workspace, reordering and edge-case contracts of plan.h.
 *
 * The exhaustive search (layered dynamic programming over every reachable offset vector)
 * shares no code with plan.c and none with the core's cost code: it uses only the geometry
 * conflict tests, and it prices plans itself, exactly, from the contract (docs/scenario-format.md
 * "Costs"): each w_i = fl(fl(v dt) fl(c dt)) taken apart with frexp, the areas as exact
 * rationals, everything summed in the compiler's 128-bit integers (this test runs on
 * 64-bit hosts only). So an error in the engine's duplicate handling, ordering, validity
 * tables, bookkeeping or cost arithmetic shows up as a different status or cost, and a tie
 * between vehicles with different L*dh is broken by effort as the contract says.
 */
#include <check.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "coavoid/coavoid.h"
#include "plan_internal.h" /* coa_plan_test_bound_breaks */
#include "test_support.h"

#ifndef __SIZEOF_INT128__
#error "test_plan's cost oracle needs unsigned __int128 (a 64-bit GCC or Clang host)"
#endif
/* __extension__: 128-bit integers are a GCC and Clang extension, fine in a host test. */
__extension__ typedef unsigned __int128 u128_t;

#define MAXV 10u
#define MAXN 24u

/* The problem holder, sized to this file's limits (the other capacities' defaults are
 * this file's). */
#define FX_MAXV MAXV
#define FX_MAXN MAXN
#include "plan_fixture.h"

/* ------------------------------------------------------------------------------------ */
/* Problems                                                                              */

/* UAVs converging on one point at random times, so that conflicts are common, with
 * obstacles and tracks around that point. dt is 0.5, 1 or 2 s. Two problems in three draw
 * speeds from {10, 20} and climb rates from {1, 2, 3} m/s, so L*dh differs between
 * vehicles by simple ratios and exact ties between different vehicles' manoeuvres are
 * common; the others draw both from intervals. Routes have 1 to 3 legs that turn and
 * climb or descend, some ending inside the window (the reference then continues along the
 * last leg); tracks fly constant velocity or a path whose first point may come after
 * t = 0; initial offsets go up to +-3 and max_offset can equal |initial_offset|. */
/* What the generator produced, so that the tests can check it covers what it claims. */
static struct {
    unsigned dt_half;
    unsigned dt_two;
    unsigned extrapolated;    /* a route that ends inside the window */
    unsigned multi_leg_climb; /* a route of 2 or more legs with a climbing or descending leg */
    unsigned path_late_start; /* a track path whose first point comes after t = 0 */
    unsigned far_offset;      /* |initial_offset| >= 2 */
    unsigned pinned;          /* max_offset == |initial_offset| */
} gen;

static void fx_random(fx_t *f, uint64_t *rng, size_t n, uint32_t horizon, uint32_t max_steep)
{
    static const double dts[3] = {0.5, 1.0, 2.0};
    static const double tie_speed[3] = {10.0, 10.0, 20.0};
    double dt = dts[pick(rng, 3u)];
    double span = dt * (double)horizon; /* seconds in the window */
    bool ties = pick(rng, 3u) != 0u;
    double cx = unif(rng, -10, 10);
    double cy = unif(rng, -10, 10);
    double cz = 100;
    double base = unif(rng, 0, 6.283185307179586);
    size_t i;
    size_t j;
    uint32_t count;

    fx_init(f, dt, horizon);
    gen.dt_half += dt == 0.5 ? 1u : 0u;
    gen.dt_two += dt == 2.0 ? 1u : 0u;
    for (i = 0; i < n; ++i) {
        double speed = ties ? tie_speed[pick(rng, 3u)] : unif(rng, 8, 16);
        double climb = ties ? (double)(1u + pick(rng, 3u)) : unif(rng, 1, 5);
        double dh = climb * dt;
        size_t npts = 2u + pick(rng, 3u);
        double total = speed * span * unif(rng, 0.4, 1.4);
        /* Headings spread around the circle: UAVs flying side by side from t = 0 would
         * mostly be infeasible at once. */
        double th = base + 6.283185307179586 * (double)i / (double)n + unif(rng, -0.6, 0.6);
        /* Not too early: a conflict already at t = 0 proves little. */
        double tm = unif(rng, fmax(dt, 0.35 * span), span - 0.2 * dt);
        double x = 0.0;
        double y = 0.0;
        double z = 0.0;
        double length = 0.0;
        bool climbs = false;
        coa_vec3_t at;
        coa_vec3_t shift;
        coa_vehicle_t *v =
            fx_vehicle(f, (uint16_t)(10u + pick(rng, 5u) * 10u + i), 1u + pick(rng, 3u), speed,
                       climb, 2u + pick(rng, max_steep - 1u), speed * dt * unif(rng, 0.3, 0.6),
                       dh * unif(rng, 0.6, 1.6), V(0, 0, 0), V(1, 0, 0));
        f->route[i][0] = V(0, 0, 0);
        for (j = 1; j < npts; ++j) {
            double len = total / (double)(npts - 1u) * unif(rng, 0.6, 1.4);
            double slope = pick(rng, 3u) == 0u ? 0.0 : unif(rng, -0.25, 0.25);
            th += unif(rng, -0.5, 0.5);
            x += cos(th) * len;
            y += sin(th) * len;
            z += slope * len;
            f->route[i][j] = V(x, y, z);
            length += len;
            climbs = climbs || slope != 0.0;
        }
        v->route_count = npts;
        gen.extrapolated += length < speed * span ? 1u : 0u;
        gen.multi_leg_climb += (npts > 2u && climbs) ? 1u : 0u;
        /* Move the route so that the reference passes near the meeting point at tm. */
        at = coa_reference_at(v, R(tm));
        shift = V(cx + unif(rng, -3, 3) - (double)at.x, cy + unif(rng, -3, 3) - (double)at.y,
                  cz + unif(rng, -4, 4) - (double)at.z);
        for (j = 0; j < npts; ++j) {
            f->route[i][j].x += shift.x;
            f->route[i][j].y += shift.y;
            f->route[i][j].z += shift.z;
        }
        switch (pick(rng, 6u)) {
        case 0u:
            v->initial_offset = pick(rng, 2u) == 0u ? 1 : -1;
            break;
        case 1u:
            v->initial_offset = (int32_t)(2u + pick(rng, 2u)) * (pick(rng, 2u) == 0u ? 1 : -1);
            break;
        default:
            break;
        }
        gen.far_offset += abs(v->initial_offset) >= 2 ? 1u : 0u;
        switch (pick(rng, 5u)) {
        case 0u:
            v->max_offset = abs(v->initial_offset); /* it may never move further out */
            ++gen.pinned;
            break;
        case 1u:
            v->max_offset = abs(v->initial_offset) + (int32_t)(1u + pick(rng, 2u));
            break;
        default:
            break;
        }
    }
    count = pick(rng, 3u);
    for (i = 0; i < count; ++i) {
        double ox = cx + unif(rng, -15, 15);
        double oy = cy + unif(rng, -15, 15);
        double oz = cz + (pick(rng, 2u) == 0u ? 1.0 : -1.0) * unif(rng, 6, 15);
        if (pick(rng, 2u) == 0u) {
            double sx = unif(rng, 3, 10);
            double sy = unif(rng, 3, 10);
            double sz = unif(rng, 2, 6);
            fx_box(f, V(ox - sx, oy - sy, oz - sz), V(ox + sx, oy + sy, oz + sz));
        } else {
            size_t o = f->p.obstacle_count++;
            double rad = unif(rng, 4, 8);
            f->obs[o].kind = COA_OBSTACLE_POLYTOPE;
            for (j = 0; j < FX_POLYV; ++j) {
                f->poly[o][j] = V(ox + unif(rng, -rad, rad), oy + unif(rng, -rad, rad),
                                  oz + unif(rng, -rad, rad));
            }
            f->obs[o].polytope.vertices = f->poly[o];
            f->obs[o].polytope.count = FX_POLYV;
        }
    }
    if (pick(rng, 5u) < 2u) {
        double speed = unif(rng, 10, 20);
        double th = unif(rng, 0, 6.283185307179586);
        double tm = unif(rng, 0.5 * dt, span);
        double vz = unif(rng, -1, 1);
        double bz = cz + unif(rng, -8, 8);
        coa_vec3_t vel = V(speed * cos(th), speed * sin(th), vz);
        coa_track_t *t;
        fx_track(f, V(cx - (double)vel.x * tm, cy - (double)vel.y * tm, bz - vz * tm), vel,
                 unif(rng, 3, 6), unif(rng, 2, 4));
        t = &f->tr[f->p.track_count - 1u];
        if (pick(rng, 2u) == 0u) {
            /* The same encounter as a path that bends a little at each point; its first
             * point can come after t = 0, when the first leg is extended backwards. */
            size_t np = 2u + pick(rng, 2u);
            double tj = unif(rng, -0.5 * span, 0.8 * span);
            gen.path_late_start += tj > 0.0 ? 1u : 0u;
            for (j = 0; j < np; ++j) {
                double d = tj - tm;
                f->trpath[f->p.track_count - 1u][j].t = R(tj);
                f->trpath[f->p.track_count - 1u][j].p =
                    V(cx + (double)vel.x * d + unif(rng, -2, 2),
                      cy + (double)vel.y * d + unif(rng, -2, 2), bz + vz * d + unif(rng, -1, 1));
                tj += dt * unif(rng, 0.5, 2.0);
            }
            t->path = f->trpath[f->p.track_count - 1u];
            t->path_count = np;
        }
    }
    fx_finish(f);
}

/* ------------------------------------------------------------------------------------ */
/* Independent checks                                                                    */

static int32_t limit_of(const coa_vehicle_t *v)
{
    return v->max_offset >= 0 ? v->max_offset : COA_MAX_OFFSET;
}

static coa_sweep_t sweep_of(const fx_t *f, size_t v, uint32_t k, int32_t a, int32_t b)
{
    coa_real_t dh = coa_climb_step(&f->veh[v], f->p.dt);
    coa_sweep_t s;
    s.volume = f->veh[v].volume;
    s.p0 = f->ref[v][k];
    s.p0.z += (coa_real_t)a * dh;
    s.p1 = f->ref[v][k + 1u];
    s.p1.z += (coa_real_t)b * dh;
    return s;
}

/* Rows start at the initial offset, move by actions, respect max_offset. */
static bool rows_well_formed(const fx_t *f, const int32_t *rows, const size_t *which, size_t count)
{
    size_t i;
    uint32_t k;
    for (i = 0; i < count; ++i) {
        const coa_vehicle_t *v = &f->veh[which[i]];
        const int32_t *r = &rows[which[i] * ROW(f)];
        int32_t s = (int32_t)v->steep_factor;
        if (r[0] != v->initial_offset) {
            return false;
        }
        for (k = 0; k <= f->p.horizon; ++k) {
            if (r[k] > limit_of(v) || r[k] < -limit_of(v)) {
                return false;
            }
            if (k < f->p.horizon) {
                int32_t d = r[k + 1u] - r[k];
                if (d != 0 && d != 1 && d != -1 && d != s && d != -s) {
                    return false;
                }
            }
        }
    }
    return true;
}

static bool plan_conflict_free(const fx_t *f, const int32_t *rows, const size_t *which,
                               size_t count)
{
    uint32_t k;
    size_t i;
    size_t j;
    for (k = 0; k < f->p.horizon; ++k) {
        for (i = 0; i < count; ++i) {
            const int32_t *ri = &rows[which[i] * ROW(f)];
            coa_sweep_t si = sweep_of(f, which[i], k, ri[k], ri[k + 1u]);
            if (!fx_static_clear(f, &si, k)) {
                return false;
            }
            for (j = i + 1u; j < count; ++j) {
                const int32_t *rj = &rows[which[j] * ROW(f)];
                coa_sweep_t sj = sweep_of(f, which[j], k, rj[k], rj[k + 1u]);
                if (coa_conflict_volumes(&si, &sj)) {
                    return false;
                }
            }
        }
    }
    return true;
}

/* ------------------------------------------------------------------------------------ */
/* The cost oracle: the contract's costs, exactly, without the core's cost code          */

/* Exact costs of a problem: deviation in units of 2^e / scale m^2, so that vehicle i's
 * step from a to b costs w[i] * area(a, b) units, an integer. */
typedef struct {
    u128_t w[MAXV];
    int e;
    uint32_t scale;
} oracle_t;

static uint32_t gcd32(uint32_t a, uint32_t b)
{
    return b == 0u ? a : gcd32(b, a % b);
}

static void oracle_make(const fx_t *f, oracle_t *o)
{
    uint64_t mant[MAXV];
    int ex[MAXV];
    size_t n = f->p.vehicle_count;
    size_t i;

    o->scale = 1u;
    for (i = 0; i < n; ++i) {
        /* w_i as the contract's formula evaluates in double: fl(fl(v dt) * fl(c dt)). */
        double l = (double)f->veh[i].cruise_speed * (double)f->p.dt;
        double dh = (double)f->veh[i].climb_rate * (double)f->p.dt;
        double w = l * dh;
        double m = frexp(w, &ex[i]); /* w = m 2^ex, 0.5 <= m < 1: m 2^53 is an integer */
        uint32_t two_s = 2u * f->veh[i].steep_factor;
        mant[i] = (uint64_t)ldexp(m, 53);
        REQUIRE(ldexp((double)mant[i], ex[i] - 53) == w);
        ex[i] -= 53;
        while ((mant[i] & 1u) == 0u) {
            mant[i] >>= 1;
            ++ex[i];
        }
        o->e = (i == 0u || ex[i] < o->e) ? ex[i] : o->e;
        /* Every area has denominator 2 or 2|a - b| = 2 s_i. */
        o->scale = o->scale / gcd32(o->scale, two_s) * two_s;
    }
    for (i = 0; i < n; ++i) {
        REQUIRE(ex[i] - o->e < 64);
        o->w[i] = (u128_t)mant[i] << (ex[i] - o->e);
    }
}

/* A(a, b) * scale by the contract's formula, checked to be an integer. */
static u128_t oracle_area(int32_t a, int32_t b, uint32_t scale)
{
    int64_t la = a;
    int64_t lb = b;
    u128_t num;
    u128_t den;
    if (la * lb >= 0) {
        num = (u128_t)(uint64_t)(llabs(la) + llabs(lb)) * scale;
        den = 2u;
    } else {
        num = (u128_t)(uint64_t)(la * la + lb * lb) * scale;
        den = 2u * (u128_t)(uint64_t)llabs(la - lb);
    }
    REQUIRE(num % den == 0u);
    return num / den;
}

static u128_t to_u128(coa_cost_t c)
{
    return ((u128_t)c.hi << 64) | (u128_t)c.lo;
}

/* Decimal, for messages. */
static const char *u128_str(u128_t x, char *buf)
{
    char tmp[40];
    size_t n = 0u;
    size_t i;
    do {
        tmp[n++] = (char)('0' + (int)(x % 10u));
        x /= 10u;
    } while (x != 0u);
    for (i = 0; i < n; ++i) {
        buf[i] = tmp[n - 1u - i];
    }
    buf[n] = '\0';
    return buf;
}

static uint32_t effort_of_delta(int32_t d)
{
    return d == 0 ? 0u : (d == 1 || d == -1) ? 1u : 3u;
}

static void row_cost(const fx_t *f, size_t v, const int32_t *rows, u128_t *units, uint32_t *effort,
                     double *dev)
{
    const int32_t *r = &rows[v * ROW(f)];
    oracle_t o;
    double l = (double)f->veh[v].cruise_speed * (double)f->p.dt;
    double dh = (double)f->veh[v].climb_rate * (double)f->p.dt;
    uint32_t k;
    oracle_make(f, &o);
    for (k = 0; k < f->p.horizon; ++k) {
        int32_t a = r[k];
        int32_t b = r[k + 1u];
        double area = (int64_t)a * b < 0
                          ? ((double)a * a + (double)b * b) / (2.0 * fabs((double)a - b))
                          : (fabs((double)a) + fabs((double)b)) / 2.0;
        *units += o.w[v] * oracle_area(a, b, o.scale);
        *effort += effort_of_delta(b - a);
        *dev += l * dh * area;
    }
}

/* ------------------------------------------------------------------------------------ */
/* Exhaustive search: layered dynamic programming over offset vectors                    */

#define DP_MAXM 3u
#define DP_MAXR 41u     /* offsets a vehicle can reach, when several move together */
#define DP_MAXSPAN 129u /* the same for one vehicle alone */
#define DP_MAXSTATES (DP_MAXR * DP_MAXR * DP_MAXR)
#define DP_CELLS (DP_MAXR * 5u)

static u128_t dp_dev[2][DP_MAXSTATES];
static uint32_t dp_eff[2][DP_MAXSTATES];
/* The highest effort among the least-deviation paths to a state. */
static uint32_t dp_effmax[2][DP_MAXSTATES];
static unsigned char dp_reach[2][DP_MAXSTATES];
static signed char dp_env[DP_MAXM][DP_MAXSPAN][5];
static signed char dp_pair[DP_MAXM][DP_CELLS][DP_CELLS];

typedef struct {
    bool found;
    u128_t dev;
    uint32_t eff;
    /* Plans of the least deviation differ in effort: the effort tie-break had real work
     * to do. */
    bool tie;
} dp_out_t;

static int32_t delta_of(int a, uint32_t s)
{
    static const int32_t unit[5] = {0, 1, -1, 1, -1};
    return a >= 3 ? unit[a] * (int32_t)s : unit[a];
}

/* The least (deviation units, effort) of the vehicles sv[0..m-1] moving together, with
 * the vehicles fixed[0..nfixed-1] flying their rows of `rows`. */
static dp_out_t dp_solve(const fx_t *f, const size_t *sv, size_t m, const int32_t *rows,
                         const size_t *fixed, size_t nfixed)
{
    const uint32_t horizon = f->p.horizon;
    oracle_t orc;
    int32_t lo[DP_MAXM];
    size_t span[DP_MAXM];
    size_t stride[DP_MAXM];
    u128_t w[DP_MAXM];
    size_t states = 1u;
    size_t start = 0u;
    size_t i;
    size_t idx;
    uint32_t k;
    dp_out_t out = {false, 0u, 0u, false};

    oracle_make(f, &orc);
    ck_assert_uint_le(m, DP_MAXM);
    for (i = 0; i < m; ++i) {
        const coa_vehicle_t *v = &f->veh[sv[i]];
        lo[i] = v->initial_offset - (int32_t)(horizon * v->steep_factor);
        span[i] = 2u * horizon * v->steep_factor + 1u;
        ck_assert_uint_le(span[i], m == 1u ? DP_MAXSPAN : DP_MAXR);
        stride[i] = states;
        states *= span[i];
        start += (size_t)(v->initial_offset - lo[i]) * stride[i];
        w[i] = orc.w[sv[i]];
    }
    memset(dp_reach[0], 0, states);
    dp_reach[0][start] = 1u;
    dp_dev[0][start] = 0;
    dp_eff[0][start] = 0u;
    dp_effmax[0][start] = 0u;

    for (k = 0; k < horizon; ++k) {
        unsigned cur = k & 1u;
        unsigned nxt = cur ^ 1u;
        memset(dp_reach[nxt], 0, states);
        memset(dp_env, 0, sizeof dp_env);
        memset(dp_pair, 0, sizeof dp_pair);
        for (idx = 0; idx < states; ++idx) {
            int32_t o[DP_MAXM];
            size_t cell[DP_MAXM];
            int32_t to[DP_MAXM];
            int a[DP_MAXM];
            size_t combos = 1u;
            size_t c;
            if (!dp_reach[cur][idx]) {
                continue;
            }
            for (i = 0; i < m; ++i) {
                o[i] = lo[i] + (int32_t)((idx / stride[i]) % span[i]);
                combos *= 5u;
            }
            for (c = 0; c < combos; ++c) {
                size_t rest = c;
                bool ok = true;
                size_t nidx = 0u;
                u128_t dev = dp_dev[cur][idx];
                uint32_t eff = dp_eff[cur][idx];
                uint32_t effmax = dp_effmax[cur][idx];
                size_t j;
                for (i = 0; i < m && ok; ++i) {
                    const coa_vehicle_t *v = &f->veh[sv[i]];
                    size_t oc = (size_t)(o[i] - lo[i]);
                    a[i] = (int)(rest % 5u);
                    rest /= 5u;
                    to[i] = o[i] + delta_of(a[i], v->steep_factor);
                    if (to[i] > limit_of(v) || to[i] < -limit_of(v)) {
                        ok = false;
                        break;
                    }
                    cell[i] = oc * 5u + (size_t)a[i];
                    if (dp_env[i][oc][a[i]] == 0) {
                        coa_sweep_t s = sweep_of(f, sv[i], k, o[i], to[i]);
                        bool clear = fx_static_clear(f, &s, k);
                        for (j = 0; clear && j < nfixed; ++j) {
                            const int32_t *r = &rows[fixed[j] * ROW(f)];
                            coa_sweep_t t = sweep_of(f, fixed[j], k, r[k], r[k + 1u]);
                            clear = !coa_conflict_volumes(&s, &t);
                        }
                        dp_env[i][oc][a[i]] = clear ? 1 : 2;
                    }
                    if (dp_env[i][oc][a[i]] != 1) {
                        ok = false;
                        break;
                    }
                    for (j = 0; j < i; ++j) {
                        size_t pi = i + j - 1u; /* (0,1) -> 0, (0,2) -> 1, (1,2) -> 2 */
                        signed char *pc = &dp_pair[pi][cell[j]][cell[i]];
                        if (*pc == 0) {
                            coa_sweep_t s = sweep_of(f, sv[i], k, o[i], to[i]);
                            coa_sweep_t t = sweep_of(f, sv[j], k, o[j], to[j]);
                            *pc = coa_conflict_volumes(&s, &t) ? 2 : 1;
                        }
                        if (*pc != 1) {
                            ok = false;
                            break;
                        }
                    }
                    nidx += (size_t)(to[i] - lo[i]) * stride[i];
                    dev += w[i] * oracle_area(o[i], to[i], orc.scale);
                    eff += effort_of_delta(to[i] - o[i]);
                    effmax += effort_of_delta(to[i] - o[i]);
                }
                if (!ok) {
                    continue;
                }
                if (!dp_reach[nxt][nidx] || dev < dp_dev[nxt][nidx]) {
                    dp_reach[nxt][nidx] = 1u;
                    dp_dev[nxt][nidx] = dev;
                    dp_eff[nxt][nidx] = eff;
                    dp_effmax[nxt][nidx] = effmax;
                } else if (dev == dp_dev[nxt][nidx]) {
                    dp_eff[nxt][nidx] = eff < dp_eff[nxt][nidx] ? eff : dp_eff[nxt][nidx];
                    dp_effmax[nxt][nidx] =
                        effmax > dp_effmax[nxt][nidx] ? effmax : dp_effmax[nxt][nidx];
                }
            }
        }
    }
    {
        unsigned last = horizon & 1u;
        uint32_t effmax = 0u;
        for (idx = 0; idx < states; ++idx) {
            if (!dp_reach[last][idx]) {
                continue;
            }
            if (!out.found || dp_dev[last][idx] < out.dev) {
                out.found = true;
                out.dev = dp_dev[last][idx];
                out.eff = dp_eff[last][idx];
                effmax = dp_effmax[last][idx];
            } else if (dp_dev[last][idx] == out.dev) {
                out.eff = dp_eff[last][idx] < out.eff ? dp_eff[last][idx] : out.eff;
                effmax = dp_effmax[last][idx] > effmax ? dp_effmax[last][idx] : effmax;
            }
        }
        out.tie = out.found && effmax > out.eff;
    }
    return out;
}

/* States (k = 0..N, the goal layer included) a joint search could ever store: it never
 * stores one state twice, so beta above this never interferes. */
static uint32_t state_bound(const fx_t *f, const size_t *sv, size_t m)
{
    uint64_t total = 0u;
    uint32_t k;
    size_t i;
    for (k = 0; k <= f->p.horizon; ++k) {
        uint64_t layer = 1u;
        for (i = 0; i < m; ++i) {
            const coa_vehicle_t *v = &f->veh[sv[i]];
            uint64_t reach = 2u * (uint64_t)k * v->steep_factor + 1u;
            uint64_t lim = 2u * (uint64_t)limit_of(v) + 1u;
            layer *= reach < lim ? reach : lim;
        }
        total += layer;
    }
    return (uint32_t)total;
}

/* ------------------------------------------------------------------------------------ */
/* Planner helpers                                                                       */

typedef struct {
    void *mem;
    coa_planner_t *pl;
    size_t bytes;
} ws_t;

static ws_t ws_make_config(const coa_planner_config_t *c)
{
    ws_t w;
    w.bytes = coa_planner_workspace_size(c);
    ck_assert_uint_gt(w.bytes, 0u);
    w.mem = malloc(w.bytes);
    ck_assert_ptr_nonnull(w.mem);
    w.pl = coa_planner_init(w.mem, w.bytes, c);
    ck_assert_ptr_nonnull(w.pl);
    return w;
}

/* Up to m UAVs searched together, at most beta nodes a joint search. The rest of the
 * config fits every problem this file plans with such a planner (horizons up to MAXN,
 * steep factors up to 3, any offset), so that one planner serves a whole random series. */
static ws_t ws_make(size_t m, uint32_t beta)
{
    const coa_planner_config_t c = {m, beta, MAXN, 3u, -1};
    return ws_make_config(&c);
}

static void ws_free(ws_t *w)
{
    free(w->mem);
    w->mem = NULL;
    w->pl = NULL;
}

static const size_t ALL[MAXV] = {0u, 1u, 2u, 3u, 4u, 5u, 6u, 7u, 8u, 9u};

/* The priority order by its definition: ascending priority, ties by ascending id. */
static void expected_order(const fx_t *f, size_t *order)
{
    size_t n = f->p.vehicle_count;
    size_t i;
    size_t j;
    for (i = 0; i < n; ++i) {
        order[i] = i;
    }
    for (i = 0; i < n; ++i) {
        for (j = i + 1u; j < n; ++j) {
            const coa_vehicle_t *a = &f->veh[order[i]];
            const coa_vehicle_t *b = &f->veh[order[j]];
            if (b->priority < a->priority || (b->priority == a->priority && b->id < a->id)) {
                size_t t = order[i];
                order[i] = order[j];
                order[j] = t;
            }
        }
    }
}

/* A solved result describes exactly the rows it returned. */
static void check_solved_plan(const fx_t *f, const int32_t *rows, const coa_plan_result_t *r)
{
    size_t n = f->p.vehicle_count;
    u128_t units = 0u;
    uint32_t effort = 0u;
    double dev = 0.0;
    size_t i;
    size_t bad_v = 99u;
    uint32_t bad_k = 99u;

    ck_assert(rows_well_formed(f, rows, ALL, n));
    ck_assert(plan_conflict_free(f, rows, ALL, n));
    ck_assert_int_eq(coa_plan_find_conflict(&f->p, rows, ALL, n, &bad_v, &bad_k), 0);
    for (i = 0; i < n; ++i) {
        row_cost(f, i, rows, &units, &effort, &dev);
    }
    ck_assert(units == to_u128(r->deviation_units));
    ck_assert_uint_eq(effort, r->effort);
    ck_assert_double_eq_tol(dev, r->deviation, 1e-9 * (1.0 + dev));
    ck_assert_uint_eq(r->planned_count, n);
    ck_assert_uint_eq(r->failed_vehicle, COA_NO_VEHICLE);
}

/* ------------------------------------------------------------------------------------ */
/* Centralised optimality                                                                */

START_TEST(centralised_matches_exhaustive_search)
{
    static fx_t f;
    static int32_t rows[MAXV * (MAXN + 1u)];
    /* Above every state_bound drawn here (three UAVs, four steps, s = 3: 25025), so that
     * no search can run out of nodes and every answer is a proof. */
    const uint32_t beta = 30000u;
    ws_t w = ws_make(3u, beta);
    uint64_t rng = 0x5eed0001u;
    unsigned solved = 0u;
    unsigned infeasible = 0u;
    unsigned moved = 0u;
    unsigned ties = 0u;
    unsigned joint = 0u;
    unsigned trial;

    for (trial = 0; trial < 600u; ++trial) {
        size_t n = 2u + pick(&rng, 2u);
        uint32_t horizon = 2u + pick(&rng, 4u);
        coa_plan_result_t r;
        dp_out_t best;
        /* Three UAVs over five steps only with s = 2: keeps the exhaustive layer small. */
        fx_random(&f, &rng, n, horizon, (n == 3u && horizon == 5u) ? 2u : 3u);
        ck_assert_uint_lt(state_bound(&f, ALL, n), beta);

        memset(rows, 0x55, sizeof rows);
        ck_assert_int_eq(coa_plan_centralised(w.pl, &f.p, rows, &r), COA_OK);
        best = dp_solve(&f, ALL, n, rows, NULL, 0u);
        ck_assert_msg(r.status == (best.found ? COA_PLAN_SOLVED : COA_PLAN_INFEASIBLE),
                      "trial %u: planner status %d, exhaustive search %s", trial, (int)r.status,
                      best.found ? "found a plan" : "found none");
        ck_assert_uint_eq(r.workspace_bytes, w.bytes);
        ck_assert_uint_eq(r.orders_tried, 1u);
        /* Single UAVs (alone, re-planned around a group) walk their tables and store no
         * node: only a merged group's joint search does. */
        ck_assert_uint_le(r.largest_group, n);
        if (r.largest_group < 2u) {
            ck_assert_uint_eq(r.nodes_generated, 0u);
        }
        if (r.nodes_generated > 0u) {
            ++joint;
        }
        if (best.found) {
            char b1[40];
            char b2[40];
            ck_assert_msg(to_u128(r.deviation_units) == best.dev && r.effort == best.eff,
                          "trial %u: planner (%s, %u), exhaustive (%s, %u)", trial,
                          u128_str(to_u128(r.deviation_units), b1), r.effort,
                          u128_str(best.dev, b2), best.eff);
            check_solved_plan(&f, rows, &r);
            /* Every UAV was planned alone first. */
            ck_assert_uint_ge(r.searches, n);
            ck_assert_uint_ge(r.largest_group, 1u);
            ++solved;
            if (best.tie) {
                ++ties;
            }
            if (best.eff > 0u) {
                ++moved;
            }
        } else {
            ++infeasible;
        }
    }
    /* The generator must produce both outcomes and real manoeuvres, or this proves little. */
    ck_assert_uint_ge(gen.dt_half, 100u);
    ck_assert_uint_ge(gen.dt_two, 100u);
    ck_assert_uint_ge(gen.extrapolated, 200u);
    ck_assert_uint_ge(gen.multi_leg_climb, 200u);
    ck_assert_uint_ge(gen.path_late_start, 20u);
    ck_assert_uint_ge(gen.far_offset, 100u);
    ck_assert_uint_ge(gen.pinned, 100u);
    ck_assert_uint_ge(solved, 150u);
    ck_assert_uint_ge(infeasible, 60u);
    ck_assert_uint_ge(moved, 150u);
    /* ... and least-deviation plans that only the effort tells apart. */
    ck_assert_uint_ge(ties, 40u);
    /* ... and groups that independence detection had to merge and search jointly, or the
     * joint search would go unchecked. */
    ck_assert_uint_ge(joint, 150u);
    ws_free(&w);
}
END_TEST

/* ------------------------------------------------------------------------------------ */
/* Decoupled                                                                             */

/* A sweep standing still at sample 0, at the vehicle's initial offset. */
static coa_sweep_t start_of(const fx_t *f, size_t v)
{
    coa_sweep_t s = sweep_of(f, v, 0u, f->veh[v].initial_offset, f->veh[v].initial_offset);
    s.p1 = s.p0;
    return s;
}

/* Whether anything is already in conflict at t = 0, which no plan and no order can undo. */
static bool conflict_at_start(const fx_t *f)
{
    size_t i;
    size_t j;
    for (i = 0; i < f->p.vehicle_count; ++i) {
        coa_sweep_t a = start_of(f, i);
        for (j = 0; j < f->p.obstacle_count; ++j) {
            if (coa_conflict_obstacle(&a, &f->obs[j]) != 0) {
                return true;
            }
        }
        for (j = 0; j < f->p.track_count; ++j) {
            coa_sweep_t t;
            t.volume = f->tr[j].volume;
            t.p0 = f->trs[j][0];
            t.p1 = t.p0;
            if (coa_conflict_volumes(&a, &t)) {
                return true;
            }
        }
        for (j = 0; j < i; ++j) {
            coa_sweep_t b = start_of(f, j);
            if (coa_conflict_volumes(&a, &b)) {
                return true;
            }
        }
    }
    return false;
}

/* Each planned UAV is optimal given the ones before it; the failing one has no plan. */
static void check_decoupled_attempt(const fx_t *f, const int32_t *rows, const coa_plan_result_t *r)
{
    size_t level;
    for (level = 0; level < r->planned_count; ++level) {
        size_t v = r->order[level];
        u128_t units = 0u;
        uint32_t effort = 0u;
        double dev = 0.0;
        dp_out_t best = dp_solve(f, &r->order[level], 1u, rows, r->order, level);
        ck_assert(best.found);
        row_cost(f, v, rows, &units, &effort, &dev);
        ck_assert(units == best.dev);
        ck_assert_uint_eq(effort, best.eff);
        ck_assert(rows_well_formed(f, rows, &r->order[level], 1u));
    }
    ck_assert(plan_conflict_free(f, rows, r->order, r->planned_count));
    if (r->status == COA_PLAN_SOLVED) {
        check_solved_plan(f, rows, r);
    } else {
        ck_assert_uint_lt(r->planned_count, f->p.vehicle_count);
        ck_assert_uint_eq(r->failed_vehicle, r->order[r->planned_count]);
        ck_assert(!dp_solve(f, &r->failed_vehicle, 1u, rows, r->order, r->planned_count).found);
    }
}

START_TEST(decoupled_each_vehicle_optimal_given_earlier)
{
    static fx_t f;
    static int32_t rows[MAXV * (MAXN + 1u)];
    /* The smallest beta: a decoupled plan reads each UAV's plan off its exact cost-to-go
     * table and stores no search node, so beta can never cut it short. */
    const uint32_t beta = 1u;
    ws_t w = ws_make(1u, beta);
    uint64_t rng = 0x5eed0002u;
    unsigned solved = 0u;
    unsigned failed = 0u;
    unsigned covered = 0u;
    unsigned trial;

    for (trial = 0; trial < 200u; ++trial) {
        size_t n = 2u + pick(&rng, 3u);
        uint32_t horizon = 3u + pick(&rng, 4u);
        size_t prio[MAXV];
        size_t given[MAXV];
        coa_plan_result_t r;
        size_t i;
        fx_random(&f, &rng, n, horizon, 3u);
        expected_order(&f, prio);

        memset(rows, 0x55, sizeof rows);
        ck_assert_int_eq(coa_plan_decoupled(w.pl, &f.p, NULL, 1u, rows, &r), COA_OK);
        ck_assert_uint_eq(r.orders_tried, 1u);
        ck_assert_uint_eq(r.workspace_bytes, w.bytes);
        ck_assert(r.status != COA_PLAN_BUDGET_EXHAUSTED);
        ck_assert_uint_eq(r.nodes_generated, 0u);
        /* One search per UAV planned, the one that failed included. */
        ck_assert_uint_eq(r.searches, r.planned_count + (r.status == COA_PLAN_SOLVED ? 0u : 1u));
        for (i = 0; i < n; ++i) {
            ck_assert_uint_eq(r.order[i], prio[i]);
        }
        check_decoupled_attempt(&f, rows, &r);
        /* One order only: every order is covered just when a proof covers them all. */
        ck_assert(r.all_orders_covered == (r.status == COA_PLAN_INFEASIBLE &&
                                           (r.planned_count == 0u || conflict_at_start(&f))));
        if (r.status == COA_PLAN_SOLVED) {
            ++solved;
        } else {
            ++failed;
            covered += r.all_orders_covered ? 1u : 0u;
        }

        /* An explicit order is followed as given. */
        for (i = 0; i < n; ++i) {
            given[i] = prio[n - 1u - i];
        }
        memset(rows, 0x55, sizeof rows);
        ck_assert_int_eq(coa_plan_decoupled(w.pl, &f.p, given, 1u, rows, &r), COA_OK);
        for (i = 0; i < n; ++i) {
            ck_assert_uint_eq(r.order[i], given[i]);
        }
        check_decoupled_attempt(&f, rows, &r);
    }
    ck_assert_uint_ge(solved, 50u);
    ck_assert_uint_ge(failed, 20u);
    ck_assert_uint_ge(covered, 5u);
    ck_assert_uint_ge(failed - covered, 5u);
    ws_free(&w);
}
END_TEST

static void next_permutation(size_t *a, size_t n)
{
    size_t i = n - 1u;
    size_t j = n - 1u;
    while (i > 0u && a[i - 1u] >= a[i]) {
        --i;
    }
    if (i > 0u) {
        size_t t;
        while (a[j] <= a[i - 1u]) {
            --j;
        }
        t = a[i - 1u];
        a[i - 1u] = a[j];
        a[j] = t;
    }
    for (j = n - 1u; i < j; ++i, --j) {
        size_t t = a[i];
        a[i] = a[j];
        a[j] = t;
    }
}

/* Reordering succeeds exactly when some order works, and otherwise reports the first
 * order's attempt as a single-order call would. */
START_TEST(reordering_finds_an_order_iff_one_exists)
{
    static fx_t f;
    static int32_t rows[MAXV * (MAXN + 1u)];
    static int32_t single[MAXV * (MAXN + 1u)];
    ws_t w = ws_make(1u, 2000u);
    uint64_t rng = 0x5eed0003u;
    unsigned rescued = 0u;
    unsigned hopeless = 0u;
    unsigned at_start = 0u;
    unsigned trial;

    for (trial = 0; trial < 120u; ++trial) {
        size_t n = 3u;
        size_t perm[3] = {0u, 1u, 2u};
        bool works[6];
        bool any = false;
        coa_plan_result_t r;
        coa_plan_result_t first;
        size_t prio[MAXV];
        unsigned p;
        size_t i;

        fx_random(&f, &rng, n, 3u + pick(&rng, 3u), 3u);
        expected_order(&f, prio);
        for (p = 0; p < 6u; ++p) {
            ck_assert_int_eq(coa_plan_decoupled(w.pl, &f.p, perm, 1u, single, &r), COA_OK);
            works[p] = r.status == COA_PLAN_SOLVED;
            any = any || works[p];
            next_permutation(perm, n);
        }
        ck_assert_int_eq(coa_plan_decoupled(w.pl, &f.p, NULL, 1u, single, &first), COA_OK);

        memset(rows, 0x55, sizeof rows);
        ck_assert_int_eq(coa_plan_decoupled(w.pl, &f.p, NULL, 6u, rows, &r), COA_OK);
        ck_assert_uint_le(r.orders_tried, 6u);
        ck_assert_msg((r.status == COA_PLAN_SOLVED) == any,
                      "trial %u: status %d after %u orders; orders that work alone: %d%d%d%d%d%d "
                      "prio %zu%zu%zu failed %zu at %zu",
                      trial, (int)r.status, r.orders_tried, works[0], works[1], works[2], works[3],
                      works[4], works[5], prio[0], prio[1], prio[2], r.failed_vehicle,
                      r.planned_count);
        /* Six orders are all there are: a failure covers every one of them, and a
         * conflict at t = 0 is found without trying a second order. */
        ck_assert(r.all_orders_covered == !any);
        if (conflict_at_start(&f)) {
            ck_assert_uint_eq(r.orders_tried, 1u);
            ++at_start;
        }
        if (any) {
            /* The order it reports works on its own and gives the same plan. */
            check_solved_plan(&f, rows, &r);
            ck_assert_int_eq(coa_plan_decoupled(w.pl, &f.p, r.order, 1u, single, &first), COA_OK);
            ck_assert_int_eq(first.status, COA_PLAN_SOLVED);
            ck_assert_mem_eq(rows, single, n * ROW(&f) * sizeof rows[0]);
            if (r.orders_tried > 1u) {
                ++rescued;
            }
        } else {
            ck_assert_int_eq(r.status, first.status);
            ck_assert_uint_eq(r.planned_count, first.planned_count);
            ck_assert_uint_eq(r.failed_vehicle, first.failed_vehicle);
            for (i = 0; i < n; ++i) {
                ck_assert_uint_eq(r.order[i], prio[i]);
            }
            for (i = 0; i < r.planned_count; ++i) {
                size_t v = r.order[i];
                ck_assert_mem_eq(&rows[v * ROW(&f)], &single[v * ROW(&f)],
                                 ROW(&f) * sizeof rows[0]);
            }
            ck_assert(to_u128(r.deviation_units) == to_u128(first.deviation_units));
            ck_assert_uint_eq(r.effort, first.effort);
            check_decoupled_attempt(&f, rows, &r);
            ++hopeless;
        }
    }
    ck_assert_uint_ge(rescued, 3u);
    ck_assert_uint_ge(hopeless, 3u);
    ck_assert_uint_ge(at_start, 2u);
    ws_free(&w);
}
END_TEST

/* A (priority 1) and B (priority 2) meet at a crossing. B flies between a thin roof and
 * floor of terrain that leave it no vertical room; A passes the crossing inside the same
 * slot unless it climbs over the roof or dives under the floor. A plans first and stays
 * level, so B fails; planned first, B stays level and A goes around. */
static void fx_tunnel(fx_t *f)
{
    fx_init(f, 1.0, 16u);
    fx_vehicle(f, 1u, 1u, 20.0, 4.0, 2u, 10.0, 5.0, V(-200, 0, 100), V(200, 0, 100));
    fx_vehicle(f, 2u, 2u, 10.0, 4.0, 2u, 10.0, 5.0, V(0, -100, 100), V(0, 100, 100));
    fx_box(f, V(-11, -160, 105.5), V(11, 160, 106.5));
    fx_box(f, V(-11, -160, 93.5), V(11, 160, 94.5));
}

START_TEST(reordering_rescues_boxed_in_vehicle)
{
    static fx_t f;
    static int32_t rows[MAXV * (MAXN + 1u)];
    ws_t w = ws_make(2u, 4000u);
    coa_plan_result_t r;
    coa_plan_result_t c;
    uint32_t k;
    int32_t peak = 0;

    fx_tunnel(&f);
    fx_finish(&f);
    ck_assert_int_eq(coa_plan_decoupled(w.pl, &f.p, NULL, 1u, rows, &r), COA_OK);
    ck_assert_int_eq(r.status, COA_PLAN_INFEASIBLE);
    ck_assert_uint_eq(r.failed_vehicle, 1u);
    ck_assert_uint_eq(r.planned_count, 1u);
    ck_assert_uint_eq(r.order[0], 0u);
    ck_assert_uint_eq(r.orders_tried, 1u);
    ck_assert(!r.all_orders_covered); /* the other order was never tried */
    check_decoupled_attempt(&f, rows, &r);

    ck_assert_int_eq(coa_plan_decoupled(w.pl, &f.p, NULL, 2u, rows, &r), COA_OK);
    ck_assert_int_eq(r.status, COA_PLAN_SOLVED);
    ck_assert(!r.all_orders_covered);
    ck_assert_uint_eq(r.orders_tried, 2u);
    ck_assert_uint_eq(r.order[0], 1u);
    ck_assert_uint_eq(r.order[1], 0u);
    check_decoupled_attempt(&f, rows, &r);
    for (k = 0; k <= f.p.horizon; ++k) {
        ck_assert_int_eq(rows[1u * ROW(&f) + k], 0);
        peak = abs(rows[k]) > peak ? abs(rows[k]) : peak;
    }
    ck_assert_int_ge(peak, 3);

    /* The centralised planner finds the same: only A can move. */
    ck_assert_int_eq(coa_plan_centralised(w.pl, &f.p, rows, &c), COA_OK);
    ck_assert_int_eq(c.status, COA_PLAN_SOLVED);
    check_solved_plan(&f, rows, &c);
    ck_assert(to_u128(c.deviation_units) == to_u128(r.deviation_units));
    ws_free(&w);
}
END_TEST

/* The tunnel plus C, held level by max_offset, through the same crossing at the same
 * time: C and B can never both fly, and A must go around whichever of them planned first.
 * Depth-first over the orders (failing vehicle first at the position backtracked to):
 *   [A B C] B fails after A      [A C B] C fails after A      [C A B] B fails (A around C)
 *   [C B A] B fails after C      [B C A] C fails after B      [B A C] C fails (A around B)
 * Nothing works; the report is the first order's attempt, whose A row (level) must be
 * planned again after the last orders left A's row going around. */
START_TEST(reordering_reports_first_order_when_none_works)
{
    static fx_t f;
    static int32_t rows[MAXV * (MAXN + 1u)];
    ws_t w = ws_make(1u, 4000u);
    coa_plan_result_t r;
    coa_vehicle_t *c;
    uint32_t k;

    fx_tunnel(&f);
    c = fx_vehicle(&f, 3u, 3u, 14.142135623730951, 4.0, 2u, 10.0, 5.0, V(100, 100, 100),
                   V(-100, -100, 100));
    c->max_offset = 0;
    fx_finish(&f);

    ck_assert_int_eq(coa_plan_decoupled(w.pl, &f.p, NULL, 100u, rows, &r), COA_OK);
    ck_assert_int_eq(r.status, COA_PLAN_INFEASIBLE);
    ck_assert_uint_eq(r.orders_tried, 6u);
    ck_assert(r.all_orders_covered);
    ck_assert_uint_eq(r.order[0], 0u);
    ck_assert_uint_eq(r.order[1], 1u);
    ck_assert_uint_eq(r.order[2], 2u);
    ck_assert_uint_eq(r.planned_count, 1u);
    ck_assert_uint_eq(r.failed_vehicle, 1u);
    for (k = 0; k <= f.p.horizon; ++k) {
        ck_assert_int_eq(rows[k], 0);
    }
    ck_assert(to_u128(r.deviation_units) == 0u);
    check_decoupled_attempt(&f, rows, &r);

    /* Stopping early reports the same first attempt. */
    ck_assert_int_eq(coa_plan_decoupled(w.pl, &f.p, NULL, 4u, rows, &r), COA_OK);
    ck_assert_int_eq(r.status, COA_PLAN_INFEASIBLE);
    ck_assert_uint_eq(r.orders_tried, 4u);
    ck_assert(!r.all_orders_covered); /* two orders were left */
    ck_assert_uint_eq(r.failed_vehicle, 1u);
    for (k = 0; k <= f.p.horizon; ++k) {
        ck_assert_int_eq(rows[k], 0);
    }
    ws_free(&w);
}
END_TEST

/* ------------------------------------------------------------------------------------ */
/* Budget, workspace, edge cases                                                         */

/* Two identical UAVs head-on at the same altitude. */
static void fx_head_on(fx_t *f, uint32_t horizon, double half)
{
    fx_init(f, 1.0, horizon);
    fx_vehicle(f, 1u, 1u, 10.0, 4.0, 2u, 5.0, half, V(-60, 0, 100), V(60, 0, 100));
    fx_vehicle(f, 2u, 1u, 10.0, 4.0, 2u, 5.0, half, V(60, 0, 100), V(-60, 0, 100));
}

/* Whether (units, effort) is lexicographically at most the result's lower bound... the
 * other way round: whether the result's bound is at most (units, effort). */
static bool bound_at_most(const coa_plan_result_t *r, u128_t units, uint32_t effort)
{
    u128_t b = to_u128(r->bound_units);
    return b < units || (b == units && r->bound_effort <= effort);
}

/* Whether result a costs lexicographically less than b. */
static bool result_cheaper(const coa_plan_result_t *a, const coa_plan_result_t *b)
{
    u128_t x = to_u128(a->deviation_units);
    u128_t y = to_u128(b->deviation_units);
    return x < y || (x == y && a->effort < b->effort);
}

/* The incumbent is the cheapest priority order, not only the first that works: with beta 1
 * no joint search of two or more finishes, so a centralised plan that is not proven
 * optimal is exactly the cheapest of the decoupled plans of every order (all 24 are
 * within the incumbent's reach), and a proven one costs no more. */
START_TEST(incumbent_is_the_cheapest_order)
{
    static fx_t f;
    static int32_t rows[MAXV * (MAXN + 1u)];
    ws_t w = ws_make(4u, 1u);
    uint64_t rng = 0x5eed0033u;
    unsigned improved = 0u; /* the cheapest order is not the first that works */
    unsigned bounded = 0u;
    unsigned trial;

    for (trial = 0; trial < 60u; ++trial) {
        size_t perm[4] = {0u, 1u, 2u, 3u};
        coa_plan_result_t best = {0};
        coa_plan_result_t first;
        coa_plan_result_t r;
        bool any = false;
        unsigned p;

        fx_random(&f, &rng, 4u, 6u + pick(&rng, 4u), 3u);
        for (p = 0; p < 24u; ++p) {
            ck_assert_int_eq(coa_plan_decoupled(w.pl, &f.p, perm, 1u, rows, &r), COA_OK);
            if (r.status == COA_PLAN_SOLVED && (!any || result_cheaper(&r, &best))) {
                best = r;
                any = true;
            }
            next_permutation(perm, 4u);
        }
        ck_assert_int_eq(coa_plan_decoupled(w.pl, &f.p, NULL, 24u, rows, &first), COA_OK);
        ck_assert_int_eq(coa_plan_centralised(w.pl, &f.p, rows, &r), COA_OK);
        if (!any) {
            continue; /* no order works: only a finished joint search can answer */
        }
        ck_assert_int_eq(r.status, COA_PLAN_SOLVED);
        check_solved_plan(&f, rows, &r);
        ck_assert(!result_cheaper(&best, &r));
        if (!r.optimal) {
            ck_assert(!result_cheaper(&r, &best));
            ++bounded;
        }
        improved += result_cheaper(&best, &first) ? 1u : 0u;
    }
    ws_free(&w);
    /* The set must exercise what the test is about. */
    ck_assert_uint_ge(bounded, 20u);
    ck_assert_uint_ge(improved, 10u);
}
END_TEST

/* Head-on, each UAV's plan alone goes through the other and neither can go around the
 * other at its own optimal cost, so independence detection merges the two and only a
 * joint search finds the optimum (which shares the manoeuvre: head_on_is_separated). At a
 * tiny beta that search runs out, and the answer is the incumbent, the priority order's
 * plan, with a lower bound below the optimum. Held within one climb step of their
 * references, no priority order has a plan (one UAV alone flies level, the other cannot
 * get clear of it) while the joint one does (one up, one down): at a tiny beta nothing is
 * found and nothing is proven. */
START_TEST(tiny_beta_answers_the_incumbent)
{
    static fx_t f;
    static int32_t rows[MAXV * (MAXN + 1u)];
    ws_t w;
    coa_plan_result_t r;
    coa_plan_result_t d;
    u128_t optimum;
    uint32_t effort;

    fx_head_on(&f, 12u, 3.0);
    fx_finish(&f);
    w = ws_make(2u, 20000u);
    ck_assert_int_eq(coa_plan_centralised(w.pl, &f.p, rows, &r), COA_OK);
    ck_assert_int_eq(r.status, COA_PLAN_SOLVED);
    ck_assert(r.optimal);
    ck_assert_int_eq(r.limit, COA_PLAN_LIMIT_NONE);
    ck_assert(to_u128(r.bound_units) == to_u128(r.deviation_units));
    ck_assert_uint_eq(r.bound_effort, r.effort);
    ck_assert_double_eq_tol(r.bound_deviation, r.deviation, 1e-9 * r.deviation);
    ck_assert_uint_gt(r.nodes_generated, 3u);
    check_solved_plan(&f, rows, &r);
    optimum = to_u128(r.deviation_units);
    effort = r.effort;
    ck_assert_int_eq(coa_plan_decoupled(w.pl, &f.p, NULL, 1u, rows, &d), COA_OK);
    ck_assert_int_eq(d.status, COA_PLAN_SOLVED);
    ck_assert(to_u128(d.deviation_units) > optimum); /* the joint plan shares the climb */
    ws_free(&w);

    /* Beta 6: the root's expansion stores its children a window beyond its key, and the
     * pool fills at the next one, whose key already bounds the optimum above 0. */
    w = ws_make(2u, 6u);
    ck_assert_int_eq(coa_plan_centralised(w.pl, &f.p, rows, &r), COA_OK);
    ck_assert_int_eq(r.status, COA_PLAN_SOLVED);
    ck_assert(!r.optimal);
    ck_assert_int_eq(r.limit, COA_PLAN_LIMIT_BETA);
    ck_assert_uint_eq(r.largest_group, 2u);
    ck_assert_uint_eq(r.nodes_generated, 6u); /* stopped when the pool was full */
    ck_assert(to_u128(r.deviation_units) == to_u128(d.deviation_units));
    ck_assert_uint_eq(r.effort, d.effort);
    ck_assert(bound_at_most(&r, optimum, effort));
    ck_assert(to_u128(r.bound_units) > 0u);
    check_solved_plan(&f, rows, &r);

    f.veh[0].max_offset = 1;
    f.veh[1].max_offset = 1;
    fx_finish(&f);
    ck_assert_int_eq(coa_plan_centralised(w.pl, &f.p, rows, &r), COA_OK);
    ck_assert_int_eq(r.status, COA_PLAN_BUDGET_EXHAUSTED);
    ck_assert_int_eq(r.limit, COA_PLAN_LIMIT_BETA);
    ck_assert(!r.optimal);
    ck_assert(to_u128(r.deviation_units) == 0u); /* no plan, no costs */
    ck_assert(to_u128(r.bound_units) > 0u);
    ws_free(&w);
    w = ws_make(2u, 20000u);
    ck_assert_int_eq(coa_plan_decoupled(w.pl, &f.p, NULL, 2u, rows, &d), COA_OK);
    ck_assert_int_eq(d.status, COA_PLAN_INFEASIBLE);
    ck_assert(d.all_orders_covered);
    ck_assert_int_eq(coa_plan_centralised(w.pl, &f.p, rows, &r), COA_OK);
    ck_assert_int_eq(r.status, COA_PLAN_SOLVED);
    ck_assert(r.optimal);
    check_solved_plan(&f, rows, &r);
    ws_free(&w);
    fx_head_on(&f, 12u, 3.0);
    fx_finish(&f);

    /* Decoupled: B has to move around A, but it reads that off its table against A's
     * plan and stores no node, so even the smallest beta is enough. */
    w = ws_make(1u, 1u);
    ck_assert_int_eq(coa_plan_decoupled(w.pl, &f.p, NULL, 2u, rows, &r), COA_OK);
    ck_assert_int_eq(r.status, COA_PLAN_SOLVED);
    ck_assert_uint_eq(r.nodes_generated, 0u);
    ck_assert_uint_eq(r.orders_tried, 1u);
    ck_assert_int_gt(r.effort, 0u);
    check_decoupled_attempt(&f, rows, &r);
    ws_free(&w);
}
END_TEST

/* One budgeted call against the unbudgeted result u of the same problem: it spends at
 * most the budget; what it claims holds (a plan is conflict-free, a bound is at most the
 * optimum, OPTIMAL only at the optimum, infeasible only when it is); and a budget that
 * ran out says so. */
static void check_budgeted(const fx_t *f, const int32_t *rows, const coa_plan_result_t *r,
                           const coa_plan_result_t *u, uint64_t budget)
{
    ck_assert_uint_le(r->work, budget);
    if (r->limit != COA_PLAN_LIMIT_WORK) {
        ck_assert_int_eq(r->status, u->status);
    }
    if (r->status == COA_PLAN_INFEASIBLE) {
        ck_assert_int_eq(u->status, COA_PLAN_INFEASIBLE);
        return;
    }
    if (u->status == COA_PLAN_SOLVED && u->optimal) {
        ck_assert(bound_at_most(r, to_u128(u->deviation_units), u->effort));
    }
    if (r->status == COA_PLAN_SOLVED) {
        check_solved_plan(f, rows, r);
        ck_assert(!r->optimal || (to_u128(r->deviation_units) == to_u128(u->deviation_units) &&
                                  r->effort == u->effort));
    } else {
        ck_assert_int_eq(r->status, COA_PLAN_BUDGET_EXHAUSTED);
        ck_assert_int_eq(r->limit, COA_PLAN_LIMIT_WORK);
    }
}

/* The work budget (plan.h, "Work"): random problems of 2-3 UAVs planned without a budget,
 * then with budgets below what they took (each call stays within its budget and claims
 * only what holds), and with four times it (the same answer, the same work). */
START_TEST(work_budget_bounds_every_call)
{
    static fx_t f;
    static int32_t rows[MAXV * (MAXN + 1u)];
    ws_t w = ws_make(3u, 30000u);
    uint64_t rng = 0x5eed0b0du;
    unsigned stopped = 0u;
    unsigned trial;

    ck_assert_int_eq(coa_planner_set_work(NULL, 1u), COA_ERR_ARGUMENT);
    for (trial = 0; trial < 200u; ++trial) {
        size_t n = 2u + pick(&rng, 2u);
        coa_plan_result_t u;
        coa_plan_result_t r;
        uint64_t cuts[3];
        size_t c;
        int mode;
        fx_random(&f, &rng, n, 2u + pick(&rng, 4u), (n == 3u) ? 2u : 3u);
        for (mode = 0; mode < 2; ++mode) {
#define PLAN(res)                                              \
    (mode == 0 ? coa_plan_centralised(w.pl, &f.p, rows, (res)) \
               : coa_plan_decoupled(w.pl, &f.p, NULL, 6u, rows, (res)))
            ck_assert_int_eq(coa_planner_set_work(w.pl, 0u), COA_OK);
            ck_assert_int_eq(PLAN(&u), COA_OK);
            ck_assert_int_eq(u.limit == COA_PLAN_LIMIT_WORK, 0);
            if (u.work == 0u) { /* decided at t = 0 without work */
                ck_assert_int_eq(u.status, COA_PLAN_INFEASIBLE);
                continue;
            }
            cuts[0] = 1u;
            cuts[1] = u.work / 3u + 1u;
            cuts[2] = u.work - 1u;
            for (c = 0; c < 3u; ++c) {
                ck_assert_int_eq(coa_planner_set_work(w.pl, cuts[c]), COA_OK);
                ck_assert_int_eq(PLAN(&r), COA_OK);
                check_budgeted(&f, rows, &r, &u, cuts[c]);
                stopped += r.limit == COA_PLAN_LIMIT_WORK ? 1u : 0u;
            }
            ck_assert_int_eq(coa_planner_set_work(w.pl, 4u * u.work), COA_OK);
            ck_assert_int_eq(PLAN(&r), COA_OK);
            ck_assert_int_eq(r.status, u.status);
            ck_assert_int_eq(r.limit, u.limit);
            ck_assert_uint_eq(r.work, u.work);
            ck_assert(to_u128(r.deviation_units) == to_u128(u.deviation_units));
            ck_assert_uint_eq(r.effort, u.effort);
#undef PLAN
        }
    }
    ck_assert_uint_gt(stopped, 600u);
    ws_free(&w);
}
END_TEST

/* The node pool's bytes per node for a config shape, checked to be a constant: the size
 * is exactly linear in beta (betas that are multiples of 8 leave every array on its
 * 8-byte boundary without padding). */
static size_t node_bytes(size_t m, uint32_t horizon, uint32_t steep, int32_t max_offset)
{
    coa_planner_config_t c = {m, 1000u, horizon, steep, max_offset};
    size_t a = coa_planner_workspace_size(&c);
    size_t b;
    size_t d;
    c.beta = 2000u;
    b = coa_planner_workspace_size(&c);
    c.beta = 3000u;
    d = coa_planner_workspace_size(&c);
    ck_assert_uint_gt(a, 0u);
    ck_assert_uint_gt(b, a);
    ck_assert_uint_eq(d - b, b - a);
    ck_assert_uint_eq((b - a) % 1000u, 0u);
    return (b - a) / 1000u;
}

START_TEST(workspace_size_is_exact)
{
    /* Head-on below: 2 UAVs, 12 steps, steep factor 2, unbounded; beta too small for it. */
    const coa_planner_config_t c2 = {2u, 20u, 12u, 2u, -1};
    const coa_planner_config_t c1 = {1u, 20u, 12u, 2u, -1};
    /* A bounded config, and configs that each need more in one field. */
    const coa_planner_config_t cb = {2u, 20u, 12u, 2u, 5};
    const coa_planner_config_t more[6] = {
        {3u, 20u, 12u, 2u, 5}, {2u, 21u, 12u, 2u, 5}, {2u, 20u, 13u, 2u, 5},
        {2u, 20u, 12u, 3u, 5}, {2u, 20u, 12u, 2u, 6}, {2u, 20u, 12u, 2u, -1},
    };
    size_t bytes = coa_planner_workspace_size(&c2);
    size_t bytes1 = coa_planner_workspace_size(&c1);
    size_t bytesb = coa_planner_workspace_size(&cb);
    coa_planner_config_t c;
    unsigned char *mem;
    unsigned char *guard;
    coa_planner_t *pl;
    static fx_t f;
    static int32_t rows[MAXV * (MAXN + 1u)];
    coa_plan_result_t r;
    size_t per_node;
    size_t m;
    size_t i;

    ck_assert_uint_gt(bytes, 0u);
    ck_assert_uint_gt(bytes, bytes1);
    ck_assert_uint_gt(bytes, bytesb);
    c = c2;
    c.beta = 21u;
    ck_assert_uint_gt(coa_planner_workspace_size(&c), bytes);

    /* Every field out of its range is refused. */
    ck_assert_uint_eq(coa_planner_workspace_size(NULL), 0u);
    c = c2;
    c.vehicles = 0u;
    ck_assert_uint_eq(coa_planner_workspace_size(&c), 0u);
    c.vehicles = COA_MAX_CENTRALISED + 1u;
    ck_assert_uint_eq(coa_planner_workspace_size(&c), 0u);
    c.vehicles = COA_MAX_CENTRALISED;
    ck_assert_uint_gt(coa_planner_workspace_size(&c), 0u);
    c = c2;
    c.beta = 0u;
    ck_assert_uint_eq(coa_planner_workspace_size(&c), 0u);
    c.beta = UINT32_C(1) << 30; /* a pool of 1 + beta nodes past 2^30 */
    ck_assert_uint_eq(coa_planner_workspace_size(&c), 0u);
    c.beta = UINT32_MAX;
    ck_assert_uint_eq(coa_planner_workspace_size(&c), 0u);
    c = c2;
    c.horizon = 0u;
    ck_assert_uint_eq(coa_planner_workspace_size(&c), 0u);
    c.horizon = COA_MAX_HORIZON + 1u;
    ck_assert_uint_eq(coa_planner_workspace_size(&c), 0u);
    c.horizon = COA_MAX_HORIZON;
    ck_assert_uint_gt(coa_planner_workspace_size(&c), 0u);
    c = c2;
    c.steep_factor = 1u;
    ck_assert_uint_eq(coa_planner_workspace_size(&c), 0u);
    c.steep_factor = COA_MAX_STEEP_FACTOR + 1u;
    ck_assert_uint_eq(coa_planner_workspace_size(&c), 0u);
    c.steep_factor = COA_MAX_STEEP_FACTOR;
    ck_assert_uint_gt(coa_planner_workspace_size(&c), 0u);
    /* Any negative bound is unbounded, and so is COA_MAX_OFFSET itself. */
    c = c2;
    c.max_offset = INT32_MIN;
    ck_assert_uint_eq(coa_planner_workspace_size(&c), bytes);
    c.max_offset = COA_MAX_OFFSET;
    ck_assert_uint_eq(coa_planner_workspace_size(&c), bytes);

    /* The tables (plan.h, "Memory"): a single-UAV planner is its header and one table of
     * T = sum over k of min(2 k s + 1, 2 L + 1) cells of 8 bytes, so the size differs
     * between horizons by the cells alone: 1,225 for N = 24 and s = 2, 6 for N = 1; with
     * L = 3, 1 + 5 + 23 * 7 = 167; a bound beyond reach (2 L + 1 = 2 N s + 1) changes
     * nothing. */
    {
        coa_planner_config_t a = {1u, 20u, 1u, 2u, -1};
        coa_planner_config_t b = {1u, 20u, 24u, 2u, -1};
        ck_assert_uint_eq(coa_planner_workspace_size(&b) - coa_planner_workspace_size(&a),
                          8u * (1225u - 6u));
        a.max_offset = 3;
        b.max_offset = 3;
        ck_assert_uint_eq(coa_planner_workspace_size(&b) - coa_planner_workspace_size(&a),
                          8u * (167u - 6u));
        b.max_offset = 48;
        a.max_offset = -1;
        ck_assert_uint_eq(coa_planner_workspace_size(&b) - coa_planner_workspace_size(&a),
                          8u * (1225u - 6u));
    }
    /* A single-UAV planner never searches jointly: it has no node pool, and beta does not
     * change its size. */
    c = c1;
    c.beta = 1u;
    ck_assert_uint_eq(coa_planner_workspace_size(&c), bytes1);
    c.beta = (UINT32_C(1) << 30) - 1u;
    ck_assert_uint_eq(coa_planner_workspace_size(&c), bytes1);
    /* The node pool: linear in beta, its bytes per node independent of the horizon, the
     * steep factor and the offset bound, and one int16 offset more per UAV searched
     * together (the composite search's pool grew by 5^n a node). */
    per_node = node_bytes(2u, 12u, 2u, -1);
    for (m = 2u; m <= COA_MAX_CENTRALISED; ++m) {
        size_t here = node_bytes(m, 12u, 2u, -1);
        ck_assert_uint_eq(node_bytes(m, 24u, 3u, 5), here);
        ck_assert_uint_eq(node_bytes(m, 1u, COA_MAX_STEEP_FACTOR, 0), here);
        ck_assert_uint_eq(here, per_node + (m - 2u) * sizeof(int16_t));
    }

    /* 16 spare bytes: 8 for a misaligned start, 8 of guard after the workspace. */
    mem = malloc(bytes + 16u);
    ck_assert_ptr_nonnull(mem);
    ck_assert_ptr_null(coa_planner_init(NULL, bytes, &c2));
    ck_assert_ptr_null(coa_planner_init(mem, bytes - 1u, &c2));
    ck_assert_ptr_null(coa_planner_init(mem + 1, bytes, &c2));
    ck_assert_ptr_null(coa_planner_init(mem + 4, bytes, &c2));
    ck_assert_ptr_null(coa_planner_init(mem, bytes, NULL));
    c = c2;
    c.vehicles = 0u;
    ck_assert_ptr_null(coa_planner_init(mem, bytes, &c));
    /* A size exact for one config is one byte short (at least) for any config that needs
     * more in any field. */
    ck_assert_ptr_nonnull(coa_planner_init(mem, bytesb, &cb));
    ck_assert_ptr_null(coa_planner_init(mem, bytesb - 1u, &cb));
    for (i = 0; i < 6u; ++i) {
        ck_assert_uint_gt(coa_planner_workspace_size(&more[i]), bytesb);
        ck_assert_ptr_null(coa_planner_init(mem, bytesb, &more[i]));
    }

    guard = mem + bytes;
    memset(guard, 0xA5, 16u);
    pl = coa_planner_init(mem, bytes, &c2);
    ck_assert_ptr_eq((void *)pl, (void *)mem);

    /* Run it to its budget (the joint search fills its whole pool) and then solve: it
     * never writes past its size. */
    fx_head_on(&f, 12u, 3.0);
    fx_finish(&f);
    ck_assert_int_eq(coa_plan_centralised(pl, &f.p, rows, &r), COA_OK);
    ck_assert_int_eq(r.limit, COA_PLAN_LIMIT_BETA);
    ck_assert_uint_eq(r.nodes_generated, c2.beta);
    ck_assert_uint_eq(r.workspace_bytes, bytes);
    ck_assert_int_eq(coa_plan_decoupled(pl, &f.p, NULL, 2u, rows, &r), COA_OK);
    ck_assert_int_eq(r.status, COA_PLAN_SOLVED);
    ck_assert_uint_eq(r.workspace_bytes, bytes);
    for (i = 0; i < 16u; ++i) {
        ck_assert_uint_eq(guard[i], 0xA5u);
    }

    /* A planner for one vehicle refuses a centralised search of two. */
    pl = coa_planner_init(mem, bytes1, &c1);
    ck_assert_ptr_nonnull(pl);
    ck_assert_int_eq(coa_plan_centralised(pl, &f.p, rows, &r), COA_ERR_WORKSPACE);
    ck_assert_int_eq(coa_plan_decoupled(pl, &f.p, NULL, 1u, rows, &r), COA_OK);
    ck_assert_int_eq(coa_plan_decoupled(pl, &f.p, NULL, 0u, rows, &r), COA_ERR_ARGUMENT);
    ck_assert_int_eq(coa_plan_centralised(NULL, &f.p, rows, &r), COA_ERR_ARGUMENT);
    ck_assert_int_eq(coa_plan_centralised(pl, &f.p, NULL, &r), COA_ERR_ARGUMENT);
    ck_assert_int_eq(coa_plan_centralised(pl, NULL, rows, &r), COA_ERR_ARGUMENT);
    /* A buffer that is not a planner. */
    memset(mem, 0, 64u);
    ck_assert_int_eq(coa_plan_decoupled((coa_planner_t *)(void *)mem, &f.p, NULL, 1u, rows, &r),
                     COA_ERR_WORKSPACE);
    free(mem);
}
END_TEST

/* coa_planner_max_beta inverts the size function: the beta it gives fits, one more does
 * not, and a buffer of exactly the size for beta gives beta back. config->beta plays no
 * part. A single-UAV planner's size does not depend on beta, so there any beta fits once
 * the header and the table do. */
/* result.workspace_touched_bytes: every byte the planner writes in its workspace is
 * counted (a buffer filled with a pattern before init keeps it outside the count), the
 * count only grows, and small problems in a large workspace leave most of it untouched. */
START_TEST(touched_bytes_cover_every_write)
{
    static fx_t f;
    static int32_t rows[MAXV * (MAXN + 1u)];
    const coa_planner_config_t c = {4u, 200000u, MAXN, 3u, -1};
    const size_t bytes = coa_planner_workspace_size(&c);
    unsigned char *mem = malloc(bytes);
    uint64_t rng = 0x70c4edu;
    size_t last = 0u;
    unsigned trial;
    coa_planner_t *pl;

    ck_assert_ptr_nonnull(mem);
    memset(mem, 0xA5, bytes);
    pl = coa_planner_init(mem, bytes, &c);
    ck_assert_ptr_nonnull(pl);
    for (trial = 0; trial < 60u; ++trial) {
        const size_t n = 2u + trial % 3u;
        coa_plan_result_t r;
        size_t changed = 0u;
        size_t i;
        fx_random(&f, &rng, n, 4u + pick(&rng, 8u), 3u);
        if (trial % 2u == 0u) {
            ck_assert_int_eq(coa_plan_centralised(pl, &f.p, rows, &r), COA_OK);
        } else {
            ck_assert_int_eq(coa_plan_decoupled(pl, &f.p, NULL, 6u, rows, &r), COA_OK);
        }
        for (i = 0; i < bytes; ++i) {
            changed += mem[i] != 0xA5u ? 1u : 0u;
        }
        ck_assert_uint_le(changed, r.workspace_touched_bytes);
        ck_assert_uint_ge(r.workspace_touched_bytes, last);
        ck_assert_uint_le(r.workspace_touched_bytes, bytes);
        last = r.workspace_touched_bytes;
    }
    ck_assert_uint_lt(last * 4u, bytes);
    free(mem);
}
END_TEST

START_TEST(max_beta_inverts_workspace_size)
{
    static const uint32_t betas[] = {1u, 2u, 3u, 24u, 100u, 255u, 1000u, 4097u, 100000u};
    /* Two shapes: beta's inverse must not depend on the tables. */
    static const coa_planner_config_t shapes[2] = {{1u, 0u, 12u, 2u, -1}, {1u, 0u, 24u, 3u, 5}};
    const uint32_t top = (UINT32_C(1) << 30) - 1u; /* the node pool's limit */
    size_t sh;
    size_t n;
    size_t i;

    for (sh = 0; sh < 2u; ++sh) {
        for (n = 1u; n <= COA_MAX_CENTRALISED; ++n) {
            coa_planner_config_t c = shapes[sh];
            coa_planner_config_t q;
            size_t floor_bytes;
            c.vehicles = n;
            c.beta = top;
            ck_assert_uint_gt(coa_planner_workspace_size(&c), 0u);
            c.beta = top + 1u;
            ck_assert_uint_eq(coa_planner_workspace_size(&c), 0u);
            c.beta = 1u;
            floor_bytes = coa_planner_workspace_size(&c);
            for (i = 0; i < sizeof betas / sizeof betas[0]; ++i) {
                size_t bytes;
                uint32_t got;
                c.beta = betas[i];
                bytes = coa_planner_workspace_size(&c);
                ck_assert_uint_gt(bytes, 0u);
                /* Whatever beta the config carries. */
                q = c;
                q.beta = 77u;
                if (n == 1u) {
                    ck_assert_uint_eq(bytes, floor_bytes);
                    ck_assert_uint_eq(coa_planner_max_beta(&q, bytes), top);
                    ck_assert_uint_eq(coa_planner_max_beta(&q, bytes - 1u), 0u);
                    continue;
                }
                ck_assert_uint_eq(coa_planner_max_beta(&q, bytes), betas[i]);
                ck_assert_uint_eq(coa_planner_max_beta(&q, bytes - 1u), betas[i] - 1u);
                /* Between two sizes: the smaller beta, which fits. */
                got = coa_planner_max_beta(&q, bytes + 7u);
                ck_assert_uint_ge(got, betas[i]);
                q.beta = got;
                ck_assert_uint_le(coa_planner_workspace_size(&q), bytes + 7u);
                q.beta = got + 1u;
                ck_assert_uint_gt(coa_planner_workspace_size(&q), bytes + 7u);
            }
            /* Room beyond the pool's limit: the limit, not more. */
            ck_assert_uint_eq(coa_planner_max_beta(&c, SIZE_MAX), top);
            /* Less than the workspace for beta = 1: nothing fits. */
            ck_assert_uint_eq(coa_planner_max_beta(&c, floor_bytes - 1u), 0u);
            ck_assert_uint_eq(coa_planner_max_beta(&c, 0u), 0u);
        }
    }
    {
        coa_planner_config_t c = shapes[0];
        ck_assert_uint_eq(coa_planner_max_beta(NULL, SIZE_MAX), 0u);
        c.vehicles = 0u;
        ck_assert_uint_eq(coa_planner_max_beta(&c, SIZE_MAX), 0u);
        c.vehicles = COA_MAX_CENTRALISED + 1u;
        ck_assert_uint_eq(coa_planner_max_beta(&c, SIZE_MAX), 0u);
        c.vehicles = 2u;
        c.horizon = 0u;
        ck_assert_uint_eq(coa_planner_max_beta(&c, SIZE_MAX), 0u);
        c.horizon = 12u;
        c.steep_factor = COA_MAX_STEEP_FACTOR + 1u;
        ck_assert_uint_eq(coa_planner_max_beta(&c, SIZE_MAX), 0u);
    }
}
END_TEST

START_TEST(initial_conflict_is_infeasible_without_expanding)
{
    static fx_t f;
    static int32_t rows[MAXV * (MAXN + 1u)];
    ws_t w = ws_make(2u, 1000u);
    coa_plan_result_t r;

    /* Two UAVs overlapping at t = 0, diverging at once. */
    fx_init(&f, 1.0, 6u);
    fx_vehicle(&f, 1u, 1u, 10.0, 4.0, 2u, 5.0, 3.0, V(0, 0, 100), V(100, 0, 100));
    fx_vehicle(&f, 2u, 2u, 10.0, 4.0, 2u, 5.0, 3.0, V(2, 0, 101), V(-100, 0, 101));
    fx_finish(&f);
    ck_assert_int_eq(coa_plan_centralised(w.pl, &f.p, rows, &r), COA_OK);
    ck_assert_int_eq(r.status, COA_PLAN_INFEASIBLE);
    ck_assert_uint_eq(r.nodes_expanded, 0u);
    ck_assert_uint_eq(r.nodes_generated, 0u);
    ck_assert_uint_eq(r.searches, 0u); /* not even the UAVs alone */
    ck_assert_uint_eq(r.largest_group, 0u);
    ck_assert_int_eq(coa_plan_decoupled(w.pl, &f.p, NULL, 1u, rows, &r), COA_OK);
    ck_assert_int_eq(r.status, COA_PLAN_INFEASIBLE);
    ck_assert_uint_eq(r.planned_count, 1u);
    ck_assert_uint_eq(r.failed_vehicle, 1u);
    ck_assert_uint_eq(r.nodes_expanded, 6u); /* vehicle 0 alone: one expansion a step */
    ck_assert_uint_eq(r.nodes_generated, 0u);

    /* One UAV starting inside a box; a track sitting on the other at t = 0. */
    fx_init(&f, 1.0, 6u);
    fx_vehicle(&f, 1u, 1u, 10.0, 4.0, 2u, 5.0, 3.0, V(0, 0, 100), V(100, 0, 100));
    fx_box(&f, V(-3, -3, 90), V(3, 3, 98));
    fx_finish(&f);
    ck_assert_int_eq(coa_plan_centralised(w.pl, &f.p, rows, &r), COA_OK);
    ck_assert_int_eq(r.status, COA_PLAN_INFEASIBLE);
    ck_assert_uint_eq(r.nodes_expanded, 0u);
    fx_init(&f, 1.0, 6u);
    fx_vehicle(&f, 1u, 1u, 10.0, 4.0, 2u, 5.0, 3.0, V(0, 0, 100), V(100, 0, 100));
    fx_track(&f, V(-3, 3, 104), V(0, -30, 0), 3.0, 2.0);
    fx_finish(&f);
    ck_assert_int_eq(coa_plan_centralised(w.pl, &f.p, rows, &r), COA_OK);
    ck_assert_int_eq(r.status, COA_PLAN_INFEASIBLE);
    ck_assert_uint_eq(r.nodes_expanded, 0u);
    ws_free(&w);
}
END_TEST

START_TEST(max_offset_is_respected)
{
    static fx_t f;
    static int32_t rows[MAXV * (MAXN + 1u)];
    ws_t w = ws_make(2u, 20000u);
    coa_plan_result_t r;
    uint32_t k;
    int32_t peak0 = 0;
    int32_t peak1 = 0;

    /* Separation needs 10 m vertically, dh = 4 m: the offsets must differ by 3. */
    fx_head_on(&f, 12u, 5.0);
    fx_finish(&f);
    ck_assert_int_eq(coa_plan_centralised(w.pl, &f.p, rows, &r), COA_OK);
    ck_assert_int_eq(r.status, COA_PLAN_SOLVED);
    for (k = 0; k <= f.p.horizon; ++k) {
        peak1 = abs(rows[ROW(&f) + k]) > peak1 ? abs(rows[ROW(&f) + k]) : peak1;
    }
    ck_assert_int_gt(peak1, 0); /* unbounded, both share the manoeuvre */

    f.veh[1].max_offset = 0;
    ck_assert_int_eq(coa_plan_centralised(w.pl, &f.p, rows, &r), COA_OK);
    ck_assert_int_eq(r.status, COA_PLAN_SOLVED);
    check_solved_plan(&f, rows, &r);
    for (k = 0; k <= f.p.horizon; ++k) {
        ck_assert_int_eq(rows[ROW(&f) + k], 0);
        peak0 = abs(rows[k]) > peak0 ? abs(rows[k]) : peak0;
    }
    ck_assert_int_ge(peak0, 3);

    f.veh[0].max_offset = 2;
    ck_assert_int_eq(coa_plan_centralised(w.pl, &f.p, rows, &r), COA_OK);
    ck_assert_int_eq(r.status, COA_PLAN_INFEASIBLE);
    ck_assert_int_eq(coa_plan_decoupled(w.pl, &f.p, NULL, 2u, rows, &r), COA_OK);
    ck_assert_int_eq(r.status, COA_PLAN_INFEASIBLE);

    f.veh[0].max_offset = 2;
    f.veh[1].max_offset = 1;
    ck_assert_int_eq(coa_plan_centralised(w.pl, &f.p, rows, &r), COA_OK);
    ck_assert_int_eq(r.status, COA_PLAN_SOLVED);
    check_solved_plan(&f, rows, &r);
    ws_free(&w);
}
END_TEST

START_TEST(head_on_is_separated)
{
    static fx_t f;
    static int32_t rows[MAXV * (MAXN + 1u)];
    ws_t w = ws_make(2u, 20000u);
    coa_plan_result_t r;
    uint32_t k;
    int mode;

    fx_head_on(&f, 12u, 3.0);
    fx_finish(&f);
    ck_assert_int_eq(coa_plan_find_conflict(&f.p, (int32_t[26]){0}, ALL, 2u, NULL, NULL), 1);
    for (mode = 0; mode < 2; ++mode) {
        if (mode == 0) {
            ck_assert_int_eq(coa_plan_centralised(w.pl, &f.p, rows, &r), COA_OK);
        } else {
            ck_assert_int_eq(coa_plan_decoupled(w.pl, &f.p, NULL, 1u, rows, &r), COA_OK);
        }
        ck_assert_int_eq(r.status, COA_PLAN_SOLVED);
        check_solved_plan(&f, rows, &r);
        ck_assert_int_gt(r.effort, 0u);
        /* They meet at t = 6: there they must be vertically apart by the two half-heights
         * (dh = 4 m, 6 m needed), which moving the same way could not give. */
        k = 6u;
        ck_assert_int_ge(abs(rows[k] - rows[ROW(&f) + k]) * 4, 6);
    }
    /* Centralised shares the manoeuvre: the vertical gap must grow from 0 at t = 5 to
     * 1.5 climb steps by t = 5.5, so 3 steps at t = 6: one UAV climbs 1, the other dives 2
     * steeply (area 1 + 2 climb-step-steps of L dh = 40 m^2; effort 1+1 + 3+3). */
    ck_assert_int_eq(coa_plan_centralised(w.pl, &f.p, rows, &r), COA_OK);
    ck_assert_int_eq(abs(rows[6] - rows[ROW(&f) + 6u]), 3);
    ck_assert_int_lt(rows[6] * rows[ROW(&f) + 6u], 0);
    ck_assert_double_eq_tol(r.deviation, 120.0, 1e-9);
    ck_assert_uint_eq(r.effort, 8u);
    ws_free(&w);
}
END_TEST

/* Whether every sample of the listed rows keeps its UAV's volume at or above `floor`:
 * computed here in double from the references, not by the planner's rule. */
static bool rows_above(const fx_t *f, const int32_t *rows, size_t count, double floor)
{
    size_t i;
    uint32_t k;
    for (i = 0; i < count; ++i) {
        const coa_vehicle_t *v = &f->veh[i];
        const double dh = (double)v->climb_rate * (double)f->p.dt;
        for (k = 0; k <= f->p.horizon; ++k) {
            const double z = (double)f->ref[i][k].z + (double)rows[i * ROW(f) + k] * dh;
            if (z - (double)v->volume.half_height < floor) {
                return false;
            }
        }
    }
    return true;
}

/* One UAV (bottom at 97 m) that a box in its way lets pass only below (its top at 94 m,
 * two climb steps down: bottom 89 m) or, when the box ends at 130 m, far above. A floor
 * at 90 m forbids the descent: every planner climbs over when it can, and answers
 * infeasible when it cannot, never below the floor. */
static void floor_under_a_box(double box_top)
{
    static fx_t f;
    static int32_t rows[MAXV * (MAXN + 1u)];
    ws_t w = ws_make(2u, 20000u);
    coa_plan_result_t r;
    int mode;

    fx_init(&f, 1.0, 12u);
    fx_vehicle(&f, 1u, 1u, 10.0, 4.0, 2u, 5.0, 3.0, V(-60, 0, 100), V(60, 0, 100));
    fx_box(&f, V(-10, -50, 97), V(10, 50, box_top));
    fx_finish(&f);
    ck_assert_int_eq(coa_plan_centralised(w.pl, &f.p, rows, &r), COA_OK);
    ck_assert_int_eq(r.status, COA_PLAN_SOLVED);
    ck_assert(!rows_above(&f, rows, 1u, 90.0)); /* without a floor it dives */
    f.p.has_floor = true;
    f.p.floor_z = R(90.0);
    ck_assert_int_eq(coa_plan_find_conflict(&f.p, rows, ALL, 1u, NULL, NULL), 1);
    for (mode = 0; mode < 3; ++mode) {
        if (mode == 0) {
            ck_assert_int_eq(coa_plan_centralised(w.pl, &f.p, rows, &r), COA_OK);
        } else {
            ck_assert_int_eq(coa_plan_decoupled(w.pl, &f.p, NULL, mode == 1 ? 1u : 4u, rows, &r),
                             COA_OK);
        }
        if (box_top > 500.0) {
            ck_assert_int_eq(r.status, COA_PLAN_INFEASIBLE);
            continue;
        }
        ck_assert_int_eq(r.status, COA_PLAN_SOLVED);
        check_solved_plan(&f, rows, &r);
        ck_assert(rows_above(&f, rows, 1u, 90.0));
        ck_assert_int_ge(rows[6], 9); /* over the box: bottom at 130 m or above */
    }
    ws_free(&w);
}

/* A floor is never crossed (plan.h, "Floor"): by a single UAV's table, centralised and
 * decoupled; by the joint search of a head-on pair, which without it shares the manoeuvre
 * (one climbs, one dives) and with it at their bottoms must climb both or one alone; and
 * a UAV already below it at t = 0 is an initial conflict. */
START_TEST(floor_is_never_crossed)
{
    static fx_t f;
    static int32_t rows[MAXV * (MAXN + 1u)];
    ws_t w = ws_make(2u, 20000u);
    coa_plan_result_t r;
    int mode;

    floor_under_a_box(130.0);
    floor_under_a_box(1000.0);

    fx_head_on(&f, 12u, 3.0);
    fx_finish(&f);
    ck_assert_int_eq(coa_plan_centralised(w.pl, &f.p, rows, &r), COA_OK);
    ck_assert_int_eq(r.status, COA_PLAN_SOLVED);
    ck_assert_uint_eq(r.largest_group, 2u);
    ck_assert(!rows_above(&f, rows, 2u, 97.0));
    f.p.has_floor = true;
    f.p.floor_z = R(97.0); /* both bottoms: touching it is clear, one step down is not */
    for (mode = 0; mode < 2; ++mode) {
        if (mode == 0) {
            ck_assert_int_eq(coa_plan_centralised(w.pl, &f.p, rows, &r), COA_OK);
            ck_assert_uint_eq(r.largest_group, 2u);
        } else {
            ck_assert_int_eq(coa_plan_decoupled(w.pl, &f.p, NULL, 1u, rows, &r), COA_OK);
        }
        ck_assert_int_eq(r.status, COA_PLAN_SOLVED);
        check_solved_plan(&f, rows, &r);
        ck_assert(rows_above(&f, rows, 2u, 97.0));
    }

    f.p.floor_z = R(97.5); /* above both bottoms at t = 0 */
    ck_assert_int_eq(coa_plan_centralised(w.pl, &f.p, rows, &r), COA_OK);
    ck_assert_int_eq(r.status, COA_PLAN_INFEASIBLE);
    ck_assert_uint_eq(r.nodes_expanded, 0u);
    ck_assert_int_eq(coa_plan_decoupled(w.pl, &f.p, NULL, 2u, rows, &r), COA_OK);
    ck_assert_int_eq(r.status, COA_PLAN_INFEASIBLE);
    ck_assert(r.all_orders_covered);
    f.p.floor_z = R(NAN);
    ck_assert_int_eq(coa_problem_check(&f.p), COA_ERR_ARGUMENT);
    ws_free(&w);
}
END_TEST

START_TEST(problem_check_and_helpers)
{
    static fx_t f;
    static coa_vec3_t big[9][COA_MAX_HORIZON + 1u];
    static coa_vehicle_t many[9];
    static const coa_vec3_t *bigp[9];
    static const coa_vec3_t route[2] = {{0, 0, 100}, {100, 0, 100}};
    coa_problem_t p;
    size_t order[MAXV];
    double dev;
    uint32_t eff;
    size_t i;
    size_t bad_v = 99u;
    uint32_t bad_k = 99u;
    int32_t offs[5] = {0, 1, 3, 2, 2};

    ck_assert_int_eq(coa_problem_check(NULL), COA_ERR_ARGUMENT);
    fx_head_on(&f, 12u, 3.0);
    fx_finish(&f);
    f.refp[1] = NULL;
    ck_assert_int_eq(coa_problem_check(&f.p), COA_ERR_ARGUMENT);
    f.refp[1] = f.ref[1];
    f.ref[1][3].x = R(NAN);
    ck_assert_int_eq(coa_problem_check(&f.p), COA_ERR_ARGUMENT);
    f.ref[1][3].x = R(0);
    f.veh[1].id = 1u;
    ck_assert_int_eq(coa_problem_check(&f.p), COA_ERR_ARGUMENT);
    f.veh[1].id = 2u;
    fx_box(&f, V(0, 0, 0), V(-1, 1, 1));
    ck_assert_int_eq(coa_problem_check(&f.p), COA_ERR_ARGUMENT);
    f.p.obstacle_count = 0u;
    ck_assert_int_eq(coa_problem_check(&f.p), COA_OK);

    /* The conflict finder names the first conflicting step. */
    {
        int32_t zero[2 * 13] = {0};
        ck_assert_int_eq(coa_plan_find_conflict(&f.p, zero, ALL, 2u, &bad_v, &bad_k), 1);
        ck_assert_uint_eq(bad_v, 0u);
        ck_assert_uint_eq(bad_k, 5u); /* 120 m apart closing at 20 m/s: 10 m at t = 5.5 */
        ck_assert_int_eq(coa_plan_find_conflict(&f.p, zero, ALL, 1u, &bad_v, &bad_k), 0);
        ck_assert_int_eq(coa_plan_find_conflict(&f.p, zero, (size_t[]){0u, 0u}, 2u, NULL, NULL),
                         COA_ERR_ARGUMENT);
        ck_assert_int_eq(coa_plan_find_conflict(&f.p, zero, (size_t[]){0u, 5u}, 2u, NULL, NULL),
                         COA_ERR_ARGUMENT);
    }

    /* Nine UAVs with steep factors 2..10 over the longest horizon, unbounded: S = 5040,
     * and the worst case 2 N sum W S B is far beyond int64 but well inside the 128-bit
     * costs (< 2^112 by the core's limits). */
    for (i = 0; i < 9u; ++i) {
        many[i] = f.veh[0];
        many[i].id = (uint16_t)(i + 1u);
        many[i].route = route;
        many[i].steep_factor = (uint32_t)(2u + i);
        many[i].max_offset = -1;
        ck_assert_int_eq(coa_reference_sample(&many[i], R(1.0), COA_MAX_HORIZON, big[i]), COA_OK);
        bigp[i] = big[i];
    }
    memset(&p, 0, sizeof p);
    p.dt = R(1.0);
    p.horizon = COA_MAX_HORIZON;
    p.vehicles = many;
    p.vehicle_count = 9u;
    p.references = bigp;
    ck_assert_int_eq(coa_problem_check(&p), COA_OK);
    /* Weights that would need more than 64 bits to be exact are refused, not rounded:
     * L*dh = 1.1 * 1.3 (an odd mantissa of 47 bits from floats, about 53 from doubles)
     * against 2^20 times it. */
    many[0].cruise_speed = R(1.1);
    many[0].climb_rate = R(1.3);
    many[1].cruise_speed = R(1.1 * 1048576.0);
    many[1].climb_rate = R(1.3);
    ck_assert_int_eq(coa_problem_check(&p), COA_ERR_RANGE);
    {
        static int32_t big_rows[9 * (COA_MAX_HORIZON + 1u)];
        coa_plan_result_t r;
        coa_planner_config_t c;
        ws_t w;
        /* A planner that takes the problem, so that only the weights can refuse it: its
         * offsets bounded to 1 (unbounded, the table of steep factor 10 over 10,000 steps
         * would take gigabytes), which the range check does not depend on. */
        for (i = 0; i < 9u; ++i) {
            many[i].max_offset = 1;
        }
        ck_assert_int_eq(coa_planner_config_of(&p, 1u, 10u, &c), COA_OK);
        w = ws_make_config(&c);
        ck_assert_int_eq(coa_plan_decoupled(w.pl, &p, NULL, 1u, big_rows, &r), COA_ERR_RANGE);
        ck_assert_int_eq(r.status, COA_PLAN_INFEASIBLE); /* cleared */
        ck_assert_uint_eq(r.orders_tried, 0u);
        ck_assert_uint_eq(r.searches, 0u);
        ws_free(&w);
        for (i = 0; i < 9u; ++i) {
            many[i].max_offset = -1;
        }
    }
    many[1].cruise_speed = R(1.1 * 512.0);
    ck_assert_int_eq(coa_problem_check(&p), COA_OK);
    for (i = 0; i < 9u; ++i) {
        many[i].cruise_speed = f.veh[0].cruise_speed;
        many[i].climb_rate = f.veh[0].climb_rate;
    }

    /* Priority order: ascending priority, ties by id. */
    many[0].priority = 3u;
    many[1].priority = 1u;
    many[2].priority = 1u;
    many[2].id = 1u;
    many[3].priority = 2u;
    ck_assert_int_eq(coa_priority_order(many, 4u, order), COA_OK);
    ck_assert_uint_eq(order[0], 2u);
    ck_assert_uint_eq(order[1], 1u);
    ck_assert_uint_eq(order[2], 3u);
    ck_assert_uint_eq(order[3], 0u);
    ck_assert_int_eq(coa_priority_order(many, 0u, order), COA_ERR_ARGUMENT);
    ck_assert_int_eq(coa_priority_order(NULL, 2u, order), COA_ERR_ARGUMENT);

    /* Vehicle cost: L = 10, dh = 4 (steep factor 2): areas 0.5, 2, 2.5, 2. */
    ck_assert_int_eq(coa_plan_vehicle_cost(&f.veh[0], R(1.0), 4u, offs, &dev, &eff), COA_OK);
    ck_assert_double_eq_tol(dev, 40.0 * 7.0, 1e-9);
    ck_assert_uint_eq(eff, 1u + 3u + 1u + 0u);
    offs[2] = 4;
    ck_assert_int_eq(coa_plan_vehicle_cost(&f.veh[0], R(1.0), 4u, offs, &dev, &eff),
                     COA_ERR_ARGUMENT);
    offs[2] = 3;
    offs[1] = -1; /* 0 -> -1 -> 3 is not an action either */
    ck_assert_int_eq(coa_plan_vehicle_cost(&f.veh[0], R(1.0), 4u, offs, &dev, &eff),
                     COA_ERR_ARGUMENT);
    ck_assert_int_eq(coa_plan_vehicle_cost(NULL, R(1.0), 4u, offs, &dev, &eff), COA_ERR_ARGUMENT);
}
END_TEST

/* ------------------------------------------------------------------------------------ */
/* Regressions: each case below broke an earlier version of the planner.              */

/* Two UAVs crossing at right angles with the same speed and steep factor 3, climb rates 3
 * and 1 (L*dh = 30 and 10). Separating them costs 60 m^2 either way: UAV 1 one climb step
 * for two steps ([0, 1, 1, 0], areas 1/2 + 1 + 1/2, effort 2) or UAV 2 three ([0, -3, -3,
 * 0] by steep actions, effort 6). The exact tie must go to the lower effort; the rounded
 * weights 2^20 and 349525 once made UAV 2's manoeuvre look cheaper (6 * 349525 <
 * 2 * 2^20) and won. */
START_TEST(tie_between_vehicles_goes_to_lower_effort)
{
    static fx_t f;
    static int32_t rows[MAXV * (MAXN + 1u)];
    ws_t w = ws_make(2u, 20000u);
    coa_plan_result_t r;
    dp_out_t best;
    uint32_t k;

    fx_init(&f, 1.0, 3u);
    fx_vehicle(&f, 1u, 1u, 10.0, 3.0, 3u, 2.5, 1.4, V(-15, 0, 100), V(100, 0, 100));
    fx_vehicle(&f, 2u, 2u, 10.0, 1.0, 3u, 2.5, 1.4, V(0, -15, 100), V(0, 100, 100));
    fx_finish(&f);
    ck_assert_int_eq(coa_plan_find_conflict(&f.p, (int32_t[8]){0}, ALL, 2u, NULL, NULL), 1);

    ck_assert_int_eq(coa_plan_centralised(w.pl, &f.p, rows, &r), COA_OK);
    ck_assert_int_eq(r.status, COA_PLAN_SOLVED);
    ck_assert_double_eq_tol(r.deviation, 60.0, 1e-12);
    ck_assert_uint_eq(r.effort, 2u);
    for (k = 0; k <= 3u; ++k) {
        ck_assert_int_eq(rows[ROW(&f) + k], 0);
        ck_assert_int_eq(abs(rows[k]), (k == 1u || k == 2u) ? 1 : 0);
    }
    /* w = 30 = 15 * 2 and 10 = 5 * 2, S = 6: (3 + 6 + 3) * 15 units of 2/6 m^2. */
    ck_assert(to_u128(r.deviation_units) == 180u);
    best = dp_solve(&f, ALL, 2u, rows, NULL, 0u);
    ck_assert(best.found && best.tie);
    ck_assert(best.dev == 180u);
    ck_assert_uint_eq(best.eff, 2u);
    check_solved_plan(&f, rows, &r);
    ws_free(&w);
}
END_TEST

/* A single UAV never needs a search node: alone (centralised) or in turn (decoupled), its
 * plan is read off its exact cost-to-go table in N expansions, so the smallest beta plans
 * any number of UAVs whose plans never meet. (The old planner needed beta = N here, and
 * ran out with N - 1.) */
START_TEST(single_vehicle_plans_need_no_budget)
{
    static fx_t f;
    static int32_t rows[MAXV * (MAXN + 1u)];
    coa_plan_result_t r;
    ws_t w = ws_make(2u, 1u);
    uint32_t n;

    for (n = 1u; n <= 7u; n += 3u) {
        fx_init(&f, 1.0, n);
        fx_vehicle(&f, 1u, 1u, 10.0, 2.0, 2u, 5.0, 2.0, V(0, 0, 100), V(100, 0, 100));
        fx_finish(&f);
        ck_assert_int_eq(coa_plan_centralised(w.pl, &f.p, rows, &r), COA_OK);
        ck_assert_int_eq(r.status, COA_PLAN_SOLVED);
        ck_assert_uint_eq(r.nodes_expanded, n);
        ck_assert_uint_eq(r.nodes_generated, 0u);
        ck_assert_uint_eq(r.searches, 1u);
        ck_assert_uint_eq(r.largest_group, 1u);
        ck_assert_uint_eq(r.effort, 0u);
        ck_assert_int_eq(coa_plan_decoupled(w.pl, &f.p, NULL, 1u, rows, &r), COA_OK);
        ck_assert_int_eq(r.status, COA_PLAN_SOLVED);
        ck_assert_uint_eq(r.nodes_expanded, n);
        ck_assert_uint_eq(r.nodes_generated, 0u);
        ck_assert_uint_eq(r.searches, 1u);
        /* A second UAV far away: one more table each, still no node. */
        fx_vehicle(&f, 2u, 2u, 10.0, 2.0, 2u, 5.0, 2.0, V(0, 500, 100), V(100, 500, 100));
        fx_finish(&f);
        ck_assert_int_eq(coa_plan_decoupled(w.pl, &f.p, NULL, 1u, rows, &r), COA_OK);
        ck_assert_int_eq(r.status, COA_PLAN_SOLVED);
        ck_assert_uint_eq(r.nodes_expanded, 2u * n);
        ck_assert_uint_eq(r.nodes_generated, 0u);
        ck_assert_uint_eq(r.searches, 2u);
        ck_assert_int_eq(coa_plan_centralised(w.pl, &f.p, rows, &r), COA_OK);
        ck_assert_int_eq(r.status, COA_PLAN_SOLVED);
        ck_assert_uint_eq(r.nodes_expanded, 2u * n);
        ck_assert_uint_eq(r.nodes_generated, 0u);
        ck_assert_uint_eq(r.searches, 2u);
        ck_assert_uint_eq(r.largest_group, 1u); /* never searched together */
        check_solved_plan(&f, rows, &r);
    }
    ws_free(&w);
}
END_TEST

/* A goal on top of the open list is taken even when the pool is full. Head-on needs a
 * joint search (tiny_beta_is_budget_exhausted). Over a range of betas, each run either
 * runs out with exactly beta nodes stored (running out of room is the only way to run
 * out) or finds the same optimum with at most beta stored; and some run solves it with
 * all beta stored: the goal was the last node the pool took, and it was still taken. */
START_TEST(goal_on_top_is_taken_at_the_budget)
{
    static fx_t f;
    static int32_t rows[MAXV * (MAXN + 1u)];
    coa_plan_result_t r;
    u128_t optimum;
    uint32_t effort;
    uint32_t beta;
    unsigned exhausted = 0u;
    unsigned full_and_solved = 0u;
    ws_t w = ws_make(2u, 20000u);

    fx_head_on(&f, 12u, 3.0);
    fx_finish(&f);
    ck_assert_int_eq(coa_plan_centralised(w.pl, &f.p, rows, &r), COA_OK);
    ck_assert_int_eq(r.status, COA_PLAN_SOLVED);
    optimum = to_u128(r.deviation_units);
    effort = r.effort;
    ws_free(&w);

    for (beta = 1u; beta <= 64u; ++beta) {
        w = ws_make(2u, beta);
        ck_assert_int_eq(coa_plan_centralised(w.pl, &f.p, rows, &r), COA_OK);
        ck_assert_uint_eq(r.largest_group, 2u);
        if (r.limit == COA_PLAN_LIMIT_BETA) {
            /* The answer is then the incumbent, with a bound below the optimum. */
            ck_assert_uint_eq(r.nodes_generated, beta);
            ck_assert_int_eq(r.status, COA_PLAN_SOLVED);
            ck_assert(!r.optimal && to_u128(r.deviation_units) > optimum);
            ck_assert(bound_at_most(&r, optimum, effort));
            check_solved_plan(&f, rows, &r);
            ++exhausted;
        } else {
            ck_assert(r.optimal);
            ck_assert_int_eq(r.status, COA_PLAN_SOLVED);
            ck_assert_uint_le(r.nodes_generated, beta);
            ck_assert(to_u128(r.deviation_units) == optimum);
            ck_assert_uint_eq(r.effort, effort);
            check_solved_plan(&f, rows, &r);
            full_and_solved += r.nodes_generated == beta ? 1u : 0u;
        }
        ws_free(&w);
    }
    ck_assert_uint_gt(exhausted, 0u);
    ck_assert_uint_gt(full_and_solved, 0u);
}
END_TEST

/* Ten UAVs in separate lanes that never meet, except that two of them (3 and 7 in
 * priority order) already overlap at t = 0. No order can work, and the planner must say
 * so after one attempt instead of walking through up to 10! orders. */
START_TEST(conflict_at_start_rules_out_every_order)
{
    static fx_t f;
    static int32_t rows[MAXV * (MAXN + 1u)];
    ws_t w = ws_make(1u, 100u);
    coa_plan_result_t r;
    uint32_t max_orders[3] = {1u, 100000u, UINT32_MAX};
    size_t i;
    int variant;
    unsigned m;

    for (variant = 0; variant < 3; ++variant) {
        fx_init(&f, 1.0, 6u);
        for (i = 0; i < 10u; ++i) {
            double y = 1000.0 * (double)i;
            fx_vehicle(&f, (uint16_t)(i + 1u), (uint32_t)(i + 1u), 10.0, 2.0, 2u, 5.0, 2.0,
                       V(0, y, 100), V(100, y, 100));
        }
        if (variant == 0) {
            /* 7 starts 4 m from 3, the same lane as 3, crossing it. */
            f.route[7][0] = V(4, 3000, 101);
            f.route[7][1] = V(4, 3100, 101);
        } else if (variant == 1) {
            /* 7 starts inside a box. */
            fx_box(&f, V(-3, 6997, 90), V(3, 7003, 99));
        } else {
            /* A track sits on 7 at t = 0 (and passes over 3 later, which is fine). */
            fx_track(&f, V(0, 7003, 102), V(0, 0, 50), 3.0, 2.0);
        }
        fx_finish(&f);
        ck_assert(conflict_at_start(&f));
        for (m = 0; m < 3u; ++m) {
            memset(rows, 0x55, sizeof rows);
            ck_assert_int_eq(coa_plan_decoupled(w.pl, &f.p, NULL, max_orders[m], rows, &r), COA_OK);
            ck_assert_int_eq(r.status, COA_PLAN_INFEASIBLE);
            ck_assert(r.all_orders_covered);
            ck_assert_uint_eq(r.orders_tried, 1u);
            ck_assert_uint_eq(r.planned_count, 7u);
            ck_assert_uint_eq(r.failed_vehicle, 7u);
            ck_assert_uint_eq(r.nodes_expanded, 7u * 6u); /* the seven before it, free */
            check_decoupled_attempt(&f, rows, &r);
        }
    }
    ws_free(&w);
}
END_TEST

/* A proof that no plan exists ends the call whatever beta is. A (priority 1) is free;
 * then either B flies into a wall, which it cannot survive even alone (tried first in the
 * second order), or B and C overlap at t = 0. Decoupled, no beta can cut a plan short
 * any more (each UAV's plan is read off its table), so even beta = 1 leaves the proofs
 * to decide, where the old planner's first attempt ran out of beta on A and this test
 * checked that the proof outranked that. Centralised, a UAV with no plan even alone is
 * infeasible before any joint search, so a beta too small for the search that two
 * other UAVs' encounter needs does not matter either. */
START_TEST(proof_for_every_order_outranks_budget)
{
    static fx_t f;
    static int32_t rows[MAXV * (MAXN + 1u)];
    ws_t w = ws_make(1u, 1u);
    coa_plan_result_t r;
    int variant;

    for (variant = 0; variant < 2; ++variant) {
        fx_init(&f, 1.0, 6u);
        fx_vehicle(&f, 1u, 1u, 10.0, 2.0, 2u, 3.0, 2.0, V(0, 0, 100), V(100, 0, 100));
        fx_vehicle(&f, 2u, 2u, 10.0, 2.0, 2u, 3.0, 2.0, V(0, 500, 100), V(100, 500, 100));
        if (variant == 0) {
            /* B's first step ends inside a wall taller than any offset it can reach. */
            fx_box(&f, V(11, 400, 0), V(20, 600, 300));
        } else {
            fx_vehicle(&f, 3u, 3u, 10.0, 2.0, 2u, 3.0, 2.0, V(2, 501, 101), V(2, 601, 101));
        }
        fx_finish(&f);
        ck_assert(conflict_at_start(&f) == (variant == 1));
        ck_assert_int_eq(coa_plan_decoupled(w.pl, &f.p, NULL, 100u, rows, &r), COA_OK);
        ck_assert_int_eq(r.status, COA_PLAN_INFEASIBLE);
        ck_assert(r.all_orders_covered);
        ck_assert_uint_eq(r.orders_tried, variant == 0 ? 2u : 1u);
        ck_assert_uint_eq(r.nodes_generated, 0u);
        /* The report is the first order's attempt: A planned, then B (variant 0) or C
         * (variant 1, against B) failed. */
        ck_assert_uint_eq(r.order[0], 0u);
        ck_assert_uint_eq(r.planned_count, variant == 0 ? 1u : 2u);
        ck_assert_uint_eq(r.failed_vehicle, variant == 0 ? 1u : 2u);
        check_decoupled_attempt(&f, rows, &r);
        /* One order: the same failure, covering every order only through the t = 0 proof. */
        ck_assert_int_eq(coa_plan_decoupled(w.pl, &f.p, (const size_t[]){0u, 1u, 2u}, 1u, rows, &r),
                         COA_OK);
        ck_assert_int_eq(r.status, COA_PLAN_INFEASIBLE);
        ck_assert(r.all_orders_covered == (variant == 1));
    }
    ws_free(&w);

    /* Head-on, which needs more than one node of joint search, plus B into its wall. */
    w = ws_make(3u, 1u);
    fx_head_on(&f, 12u, 3.0);
    fx_vehicle(&f, 3u, 2u, 10.0, 2.0, 2u, 3.0, 2.0, V(0, 500, 100), V(100, 500, 100));
    fx_box(&f, V(11, 400, 0), V(20, 600, 300));
    fx_finish(&f);
    ck_assert_int_eq(coa_plan_centralised(w.pl, &f.p, rows, &r), COA_OK);
    ck_assert_int_eq(r.status, COA_PLAN_INFEASIBLE);
    ck_assert_uint_eq(r.nodes_generated, 0u);
    /* Without the wall, beta is what stops the joint search; the priority order's plan
     * is the answer. */
    f.p.obstacle_count = 0u;
    ck_assert_int_eq(coa_plan_centralised(w.pl, &f.p, rows, &r), COA_OK);
    ck_assert_int_eq(r.status, COA_PLAN_SOLVED);
    ck_assert_int_eq(r.limit, COA_PLAN_LIMIT_BETA);
    ck_assert(!r.optimal);
    ck_assert_uint_eq(r.nodes_generated, 1u);
    ws_free(&w);
}
END_TEST

/* coa_planner_config_of fits a problem exactly, and a planner takes a problem just when it
 * fits its config (plan.h, coa_planner_config_t): centralised, at most `vehicles` UAVs;
 * a horizon at most the config's; each UAV's table no larger than the config's. Beyond
 * that it refuses with COA_ERR_WORKSPACE and a cleared result; within it, it plans as a
 * planner with room to spare does. */
/* n UAVs converging on the origin from headings spread around the circle (jittered),
 * each reaching it within a step of t = 4 s, at altitudes 2 m apart: every pair meets, so
 * independence detection merges them into one group. 10 m/s, 2 m/s climb, 1 s steps. */
static void fx_converging(fx_t *f, uint64_t *rng, size_t n, uint32_t horizon)
{
    size_t i;
    fx_init(f, 1.0, horizon);
    for (i = 0; i < n; ++i) {
        double th = 6.283185307179586 * (double)i / (double)n + unif(rng, -0.2, 0.2);
        double before = 10.0 * unif(rng, 3.5, 4.5); /* m flown to the origin */
        double z = 100.0 + 2.0 * (double)i;
        fx_vehicle(f, (uint16_t)(i + 1u), 1u, 10.0, 2.0, 2u, 4.0, 2.0,
                   V(-before * cos(th), -before * sin(th), z),
                   V((100.0 - before) * cos(th), (100.0 - before) * sin(th), z));
    }
    fx_finish(f);
}

/* Groups of 7 to 10 UAVs (their matchings within two sides, plan_internal.h): random
 * encounters planned centrally within a work budget answer within it, a plan with its
 * bound or infeasible proven, never worse than the priority order's plan, and the search's
 * branch bounds never exceed a child's f. */
START_TEST(large_groups_answer_within_the_budget)
{
    static fx_t f;
    static int32_t rows[MAXV * (MAXN + 1u)];
    static int32_t order_rows[MAXV * (MAXN + 1u)];
    const uint64_t budget = 2000000u;
    ws_t w = ws_make(MAXV, 20000u);
    uint64_t rng = 0x1a7e6e0fu;
    unsigned large = 0u;
    unsigned solved = 0u;
    unsigned trial;

    for (trial = 0; trial < 40u; ++trial) {
        const size_t n = 7u + trial % 4u;
        coa_plan_result_t r;
        coa_plan_result_t d;
        fx_converging(&f, &rng, n, 8u);
        ck_assert_int_eq(coa_planner_set_work(w.pl, 0u), COA_OK);
        ck_assert_int_eq(coa_plan_decoupled(w.pl, &f.p, NULL, 1u, order_rows, &d), COA_OK);
        ck_assert_int_eq(coa_planner_set_work(w.pl, budget), COA_OK);
        ck_assert_int_eq(coa_plan_centralised(w.pl, &f.p, rows, &r), COA_OK);
        ck_assert_uint_le(r.work, budget);
        large += r.largest_group >= 7u ? 1u : 0u;
        if (d.status == COA_PLAN_SOLVED) {
            ck_assert_int_eq(r.status, COA_PLAN_SOLVED);
            ck_assert(
                to_u128(r.deviation_units) < to_u128(d.deviation_units) ||
                (to_u128(r.deviation_units) == to_u128(d.deviation_units) && r.effort <= d.effort));
        }
        if (r.status == COA_PLAN_SOLVED) {
            check_solved_plan(&f, rows, &r);
            ck_assert(bound_at_most(&r, to_u128(r.deviation_units), r.effort));
            ++solved;
        }
    }
    ck_assert_uint_ge(large, 5u);
    ck_assert_uint_ge(solved, 30u);
    ck_assert_uint_eq(coa_plan_test_bound_breaks(w.pl), 0u);
    ws_free(&w);
}
END_TEST

START_TEST(planner_takes_problems_within_its_config)
{
    static fx_t f;
    static int32_t rows[MAXV * (MAXN + 1u)];
    static int32_t roomy_rows[MAXV * (MAXN + 1u)];
    coa_planner_config_t c;
    coa_planner_config_t exact;
    coa_plan_result_t r;
    coa_plan_result_t roomy;
    ws_t w;
    size_t i;

    /* A: steep factor 2, offsets within 2; B: steep factor 3, within 5. */
    fx_head_on(&f, 12u, 3.0);
    f.veh[0].max_offset = 2;
    f.veh[1].steep_factor = 3u;
    f.veh[1].max_offset = 5;
    fx_finish(&f);
    ck_assert_int_eq(coa_planner_config_of(&f.p, 2u, 20000u, &exact), COA_OK);
    ck_assert_uint_eq(exact.vehicles, 2u);
    ck_assert_uint_eq(exact.beta, 20000u);
    ck_assert_uint_eq(exact.horizon, 12u);
    ck_assert_uint_eq(exact.steep_factor, 3u);
    ck_assert_int_eq(exact.max_offset, 5);
    /* One unbounded UAV makes the config unbounded, wherever it is. */
    f.veh[0].max_offset = -1;
    ck_assert_int_eq(coa_planner_config_of(&f.p, 2u, 20000u, &c), COA_OK);
    ck_assert_int_lt(c.max_offset, 0);
    f.veh[0].max_offset = 2;
    f.veh[1].max_offset = -1;
    ck_assert_int_eq(coa_planner_config_of(&f.p, 2u, 20000u, &c), COA_OK);
    ck_assert_int_lt(c.max_offset, 0);
    f.veh[1].max_offset = 5;
    /* What it refuses. */
    ck_assert_int_eq(coa_planner_config_of(NULL, 2u, 100u, &c), COA_ERR_ARGUMENT);
    ck_assert_int_eq(coa_planner_config_of(&f.p, 2u, 100u, NULL), COA_ERR_ARGUMENT);
    ck_assert_int_eq(coa_planner_config_of(&f.p, 0u, 100u, &c), COA_ERR_ARGUMENT);
    ck_assert_int_eq(coa_planner_config_of(&f.p, COA_MAX_CENTRALISED + 1u, 100u, &c),
                     COA_ERR_ARGUMENT);
    ck_assert_int_eq(coa_planner_config_of(&f.p, 2u, 0u, &c), COA_ERR_ARGUMENT);
    f.p.vehicle_count = 0u;
    ck_assert_int_eq(coa_planner_config_of(&f.p, 2u, 100u, &c), COA_ERR_ARGUMENT);
    f.p.vehicle_count = 2u;

    /* The exact config plans as a roomy planner does. */
    w = ws_make(2u, 20000u);
    ck_assert_int_eq(coa_plan_centralised(w.pl, &f.p, roomy_rows, &roomy), COA_OK);
    ck_assert_int_eq(roomy.status, COA_PLAN_SOLVED);
    ws_free(&w);
    w = ws_make_config(&exact);
    ck_assert_int_eq(coa_plan_centralised(w.pl, &f.p, rows, &r), COA_OK);
    ck_assert_int_eq(r.status, COA_PLAN_SOLVED);
    ck_assert(to_u128(r.deviation_units) == to_u128(roomy.deviation_units));
    ck_assert_uint_eq(r.effort, roomy.effort);
    ck_assert_mem_eq(rows, roomy_rows, 2u * ROW(&f) * sizeof rows[0]);
    check_solved_plan(&f, rows, &r);
    ck_assert_int_eq(coa_plan_decoupled(w.pl, &f.p, NULL, 1u, rows, &r), COA_OK);
    ws_free(&w);

    /* One short in any field: refused, and the result cleared. Decoupled needs room for
     * one UAV only. */
    for (i = 0; i < 4u; ++i) {
        coa_planner_config_t d = exact;
        int want_decoupled = COA_ERR_WORKSPACE;
        switch (i) {
        case 0u:
            d.vehicles = 1u;
            want_decoupled = COA_OK;
            break;
        case 1u:
            d.horizon = 11u;
            break;
        case 2u:
            d.steep_factor = 2u; /* B's table: 1 + 7 + 11 * 11 cells, not 1 + 5 + 9 + 10 * 11 */
            break;
        default:
            d.max_offset = 4; /* B's table: 1 + 7 + 11 * 9 cells */
            break;
        }
        w = ws_make_config(&d);
        ck_assert_int_eq(coa_plan_centralised(w.pl, &f.p, rows, &r), COA_ERR_WORKSPACE);
        ck_assert_int_eq(r.status, COA_PLAN_INFEASIBLE);
        ck_assert_uint_eq(r.workspace_bytes, 0u);
        ck_assert_uint_eq(r.orders_tried, 0u);
        ck_assert_uint_eq(r.searches, 0u);
        ck_assert_int_eq(coa_plan_decoupled(w.pl, &f.p, NULL, 1u, rows, &r), want_decoupled);
        if (want_decoupled != COA_OK) {
            ck_assert_uint_eq(r.orders_tried, 0u);
        }
        ws_free(&w);
    }

    /* What must fit is each table, not each field: B (steep factor 3, within 5) has fewer
     * cells (129) than a UAV of steep factor 2 unbounded (13 * 25), so a config of steep
     * factor 2, unbounded, takes it although its steep factor is larger. */
    c.vehicles = 2u;
    c.beta = 20000u;
    c.horizon = 12u;
    c.steep_factor = 2u;
    c.max_offset = -1;
    w = ws_make_config(&c);
    ck_assert_int_eq(coa_plan_centralised(w.pl, &f.p, rows, &r), COA_OK);
    ck_assert_int_eq(r.status, COA_PLAN_SOLVED);
    ck_assert(to_u128(r.deviation_units) == to_u128(roomy.deviation_units));
    ws_free(&w);
}
END_TEST

static Suite *plan_suite(void)
{
    Suite *s = suite_create("plan");
    TCase *tc = tcase_create("plan");
    tcase_set_timeout(tc, 300);
    tcase_add_test(tc, workspace_size_is_exact);
    tcase_add_test(tc, max_beta_inverts_workspace_size);
    tcase_add_test(tc, planner_takes_problems_within_its_config);
    tcase_add_test(tc, initial_conflict_is_infeasible_without_expanding);
    tcase_add_test(tc, tiny_beta_answers_the_incumbent);
    tcase_add_test(tc, incumbent_is_the_cheapest_order);
    tcase_add_test(tc, work_budget_bounds_every_call);
    tcase_add_test(tc, max_offset_is_respected);
    tcase_add_test(tc, head_on_is_separated);
    tcase_add_test(tc, floor_is_never_crossed);
    tcase_add_test(tc, problem_check_and_helpers);
    tcase_add_test(tc, tie_between_vehicles_goes_to_lower_effort);
    tcase_add_test(tc, single_vehicle_plans_need_no_budget);
    tcase_add_test(tc, goal_on_top_is_taken_at_the_budget);
    tcase_add_test(tc, conflict_at_start_rules_out_every_order);
    tcase_add_test(tc, proof_for_every_order_outranks_budget);
    tcase_add_test(tc, reordering_rescues_boxed_in_vehicle);
    tcase_add_test(tc, reordering_reports_first_order_when_none_works);
    tcase_add_test(tc, centralised_matches_exhaustive_search);
    tcase_add_test(tc, large_groups_answer_within_the_budget);
    tcase_add_test(tc, touched_bytes_cover_every_write);
    tcase_add_test(tc, decoupled_each_vehicle_optimal_given_earlier);
    tcase_add_test(tc, reordering_finds_an_order_iff_one_exists);
    suite_add_tcase(s, tc);
    return s;
}

int main(void)
{
    SRunner *sr = srunner_create(plan_suite());
    int failed;
    srunner_run_all(sr, CK_NORMAL);
    failed = srunner_ntests_failed(sr);
    srunner_free(sr);
    return failed == 0 ? EXIT_SUCCESS : EXIT_FAILURE;
}
