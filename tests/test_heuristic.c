/* SPDX-License-Identifier: MIT */
/*
 * test_heuristic.c: the planner's exact tables and the joint search's heuristic against
 * brute force on small random problems.
 *
 *   - Each vehicle's cost-to-go table (plan_table.c): every cell of the table the planner
 *     builds (cost, dead or live, action mask) against an exhaustive depth-first search
 *     over every action sequence from that (k, offset) to the horizon.
 *   - The joint search's heuristic (plan_search.c), on 2 and 3 UAVs: a group of all of
 *     them is set up as the centralised front end sets one up, but with no cap and no
 *     bound (coa_plan_test_group_setup). Checked on the set-up: each member's cost-to-go and
 *     cost-from-start tables; each pair table present where the pair can meet, its
 *     corridor every offset live both ways (the full reachable range, as there is no
 *     cap), and every cell equal to the exact cost to go of the two alone. Then every
 *     search state reachable from the root (sample k, the offsets of the members in the
 *     search at k: members before their span wait, members after it have left, as
 *     plan_search.c represents them) gets the exact joint cost-to-go, computed twice:
 *     (A) backwards over the search's own state graph with every move, entry and exit,
 *     and (B) from an exact dynamic programme over every UAV's offset at every sample, all
 *     pairs and steps checked, with the waiting members' pasts and the left members'
 *     futures priced alone. A == B checks that the spans lose nothing. The heuristic must
 *     be admissible (h <= exact, and "dead" only where no plan exists) and consistent
 *     (h(s) <= c(s, s') + h(s') over every valid joint step), compared as the planner
 *     compares costs: packed (deviation, effort), doubled; and it must be what it is
 *     documented to be (own parts plus the largest half-integral matching of the
 *     surcharges, the matching found here by enumeration). Last, the search run on the
 *     uncapped group must find the exact optimum.
 *
 * The oracles use only the public API (reference and track sampling, the geometry conflict
 * tests, coa_deviation_weights, coa_climb_step) and price steps with their own area
 * formula; the planner's internals are only read (tables, group, pair corridors) and
 * called through the test hooks of plan_internal.h.
 */
#include <check.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "coavoid/coavoid.h"
#include "plan_internal.h"
#include "test_support.h"

#ifndef __SIZEOF_INT128__
#error "test_heuristic needs unsigned __int128 (a 64-bit GCC or Clang host)"
#endif
__extension__ typedef unsigned __int128 u128_t;

#define MAXM 3u                      /* UAVs */
#define MAXN 8u                      /* horizon */
#define MAXS 3u                      /* steep factor */
#define ROWW (2u * MAXN * MAXS + 1u) /* widest row */
#define ACTS 5u
#define INF (~(u128_t)0)
#define EFF_BITS PLAN_EFF_BITS /* the planner's packing */

/* The problem holder, sized to these problems. */
#define FX_MAXV MAXM
#define FX_MAXN MAXN
#include "plan_fixture.h"

static u128_t from_cost(coa_cost_t c)
{
    return ((u128_t)c.hi << 64) | (u128_t)c.lo;
}

/* A packed cost for messages: "deviation:effort" in decimal (INF: "inf"). The efforts
 * here stay far below 2^(EFF_BITS - 1), so a low part above it is a difference's negative effort
 * (a surcharge's, say), shown as such. Eight rotating buffers: up to eight per message. */
static const char *pk(u128_t x)
{
    static char buf[8][80];
    static unsigned turn;
    char *b = buf[turn++ % 8u];
    char digits[48];
    size_t n = 0u;
    u128_t dev = x >> EFF_BITS;
    int eff = (int)(x & ((1u << EFF_BITS) - 1u));
    if (x == ~(u128_t)0) {
        return "inf";
    }
    if (eff >= (1 << (EFF_BITS - 1u))) {
        eff -= 1 << EFF_BITS;
        dev += 1u;
    }
    do {
        digits[n++] = (char)('0' + (int)(dev % 10u));
        dev /= 10u;
    } while (dev != 0u);
    {
        size_t i;
        for (i = 0; i < n; ++i) {
            b[i] = digits[n - 1u - i];
        }
        snprintf(&b[n], 80u - n, ":%d", eff);
    }
    return b;
}

/* ------------------------------------------------------------------------------------ */
/* Problems                                                                              */

/* A UAV flying straight at `speed` along heading th, over (cx, cy, cz) at time tm. */
static coa_vehicle_t *fx_flyby(fx_t *f, double speed, double climb, uint32_t steep, double radius,
                               double half, double th, double tm, double cx, double cy, double cz,
                               double slope)
{
    size_t i = f->p.vehicle_count;
    double span = (double)f->p.dt * (double)f->p.horizon;
    double ux = cos(th);
    double uy = sin(th);
    return fx_vehicle(f, (uint16_t)(1u + i), 1u, speed, climb, steep, radius, half,
                      V(cx - ux * speed * tm, cy - uy * speed * tm, cz - slope * speed * tm),
                      V(cx + ux * speed * (span + 1.0), cy + uy * speed * (span + 1.0),
                        cz + slope * speed * (span + 1.0)));
}

/* A level track at `speed` along heading th, over (cx, cy, cz) at time tm. */
static void fx_crossing(fx_t *f, double speed, double th, double tm, double cx, double cy,
                        double cz, double radius, double half)
{
    coa_vec3_t vel = V(speed * cos(th), speed * sin(th), 0.0);
    coa_track_t *t =
        fx_track(f, V(cx - (double)vel.x * tm, cy - (double)vel.y * tm, cz), vel, radius, half);
    t->id = 100u;
}

/* Initial offset and bound of a random vehicle: 0 mostly, up to +-2, sometimes a bound
 * (as low as the initial offset itself). */
static void random_offsets(uint64_t *rng, coa_vehicle_t *v)
{
    switch (pick(rng, 5u)) {
    case 0u:
        v->initial_offset = pick(rng, 2u) == 0u ? 1 : -1;
        break;
    case 1u:
        v->initial_offset = pick(rng, 2u) == 0u ? 2 : -2;
        break;
    default:
        break;
    }
    switch (pick(rng, 4u)) {
    case 0u:
        v->max_offset = abs(v->initial_offset) + (int32_t)pick(rng, 3u);
        break;
    case 1u:
        v->max_offset = abs(v->initial_offset) + 2 + (int32_t)pick(rng, 3u);
        break;
    default:
        break;
    }
}

/* One UAV flying east through a box (a hill, a ceiling or a band across some offsets,
 * over part of the window) and sometimes a crossing track. */
static void fx_single(fx_t *f, uint64_t *rng, uint32_t horizon, uint32_t steep)
{
    double dt = pick(rng, 2u) == 0u ? 1.0 : 0.5;
    double speed = pick(rng, 2u) == 0u ? 10.0 : 20.0;
    double climb = (double)(1u + pick(rng, 3u));
    double dh = climb * dt;
    double span = dt * (double)horizon;
    double cz = 100.0;
    coa_vehicle_t *v;

    fx_init(f, dt, horizon);
    v = fx_flyby(f, speed, climb, steep, speed * dt * unif(rng, 0.2, 0.5), dh * unif(rng, 0.6, 1.6),
                 0.0, 0.0, 0.0, 0.0, cz, 0.0);
    random_offsets(rng, v);
    if (pick(rng, 6u) != 0u) {
        double t0 = unif(rng, -0.2, 0.8) * span;
        double t1 = t0 + unif(rng, 0.1, 0.6) * span;
        double lo;
        double hi;
        switch (pick(rng, 3u)) {
        case 0u: /* a hill: climb over it */
            lo = -1000.0;
            hi = unif(rng, -3.0, 4.0) * dh;
            break;
        case 1u: /* a ceiling */
            lo = unif(rng, -4.0, 3.0) * dh;
            hi = 1000.0;
            break;
        default: /* a band */
            lo = unif(rng, -5.0, 3.0) * dh;
            hi = lo + unif(rng, 0.5, 5.0) * dh;
            break;
        }
        fx_box(f, V(speed * t0, -unif(rng, 1, 20), cz + lo),
               V(speed * t1, unif(rng, 1, 20), cz + hi));
    }
    if (pick(rng, 3u) == 0u) {
        fx_crossing(f, unif(rng, 5, 20), unif(rng, 0.5, 2.6), unif(rng, 0.1, 1.0) * span,
                    speed * unif(rng, 0.1, 1.0) * span, 0.0, cz + unif(rng, -4, 4) * dh,
                    unif(rng, 2, 8), unif(rng, 0.5, 2.0) * dh);
    }
    fx_finish(f);
}

/* m UAVs converging on one point at different times (so that their spans differ), with
 * sometimes a box above or below it and a crossing track. */
static void fx_group(fx_t *f, uint64_t *rng, size_t m, uint32_t horizon, uint32_t max_steep)
{
    double dt = pick(rng, 2u) == 0u ? 1.0 : 0.5;
    double span = dt * (double)horizon;
    double cz = 100.0;
    double base = unif(rng, 0, 6.283185307179586);
    double dhmin = 1e9;
    /* half the problems: everyone over the point at about the same time (three-way
     * encounters), else each at its own time (spans that differ) */
    bool together = pick(rng, 2u) == 0u;
    double common = unif(rng, 0.3, 0.8);
    size_t i;

    fx_init(f, dt, horizon);
    for (i = 0; i < m; ++i) {
        double speed = pick(rng, 2u) == 0u ? 10.0 : 20.0;
        double climb = (double)(1u + pick(rng, 3u));
        double dh = climb * dt;
        double th = base + 6.283185307179586 * (double)i / (double)m + unif(rng, -0.5, 0.5);
        coa_vehicle_t *v =
            fx_flyby(f, speed, climb, 2u + pick(rng, max_steep - 1u),
                     speed * dt * unif(rng, 0.25, 0.6), dh * unif(rng, 0.6, 1.6), th,
                     (together ? common + unif(rng, -0.1, 0.1) : unif(rng, 0.15, 0.95)) * span,
                     unif(rng, -3, 3), unif(rng, -3, 3), cz + unif(rng, -1.5, 1.5) * dh,
                     pick(rng, 3u) == 0u ? unif(rng, -0.1, 0.1) : 0.0);
        random_offsets(rng, v);
        dhmin = dh < dhmin ? dh : dhmin;
    }
    if (pick(rng, 3u) == 0u) {
        double s = pick(rng, 2u) == 0u ? 1.0 : -1.0;
        double near = unif(rng, 1.5, 4.0) * dhmin;
        double a = unif(rng, 3, 25);
        fx_box(f, V(-a, -a, s > 0 ? cz + near : cz - near - 50.0),
               V(a, a, s > 0 ? cz + near + 50.0 : cz - near));
    }
    if (pick(rng, 4u) == 0u) {
        fx_crossing(f, unif(rng, 5, 20), unif(rng, 0, 6.283185307179586),
                    unif(rng, 0.1, 1.0) * span, unif(rng, -5, 5), unif(rng, -5, 5),
                    cz + unif(rng, -3, 3) * dhmin, unif(rng, 2, 6), unif(rng, 0.5, 2.0) * dhmin);
    }
    fx_finish(f);
}

/* ------------------------------------------------------------------------------------ */
/* The oracle: steps, their validity and their exact cost                                */

static const int32_t act_sign[ACTS] = {0, 1, -1, 1, -1};
static const bool act_steep[ACTS] = {false, false, false, true, true};
static const uint32_t act_effort[ACTS] = {0u, 1u, 1u, 3u, 3u};

typedef struct {
    const fx_t *f;
    size_t m;
    uint32_t n;
    int32_t init[MAXM];
    int32_t lim[MAXM];
    uint32_t steep[MAXM];
    coa_real_t dh[MAXM];
    u128_t wunit[MAXM];                 /* W_i * S / (2 s_i) */
    uint8_t ok[MAXM][MAXN][ROWW][ACTS]; /* in the bound, clear of obstacles and tracks */
    u128_t tg[MAXM][MAXN + 1u][ROWW];   /* cost to go alone, packed; INF: dead */
    u128_t fs[MAXM][MAXN + 1u][ROWW];   /* cost from the start alone; INF: none */
} oracle_t;

static int32_t delta(const oracle_t *o, size_t i, uint32_t a)
{
    return act_sign[a] * (act_steep[a] ? (int32_t)o->steep[i] : 1);
}

static int32_t lo_of(const oracle_t *o, size_t i, uint32_t k)
{
    int32_t x = o->init[i] - (int32_t)(k * o->steep[i]);
    return x < -o->lim[i] ? -o->lim[i] : x;
}

static int32_t hi_of(const oracle_t *o, size_t i, uint32_t k)
{
    int32_t x = o->init[i] + (int32_t)(k * o->steep[i]);
    return x > o->lim[i] ? o->lim[i] : x;
}

/* The contract's area A(a, b) times 2s, exactly. */
static uint64_t area2s(int32_t a, int32_t b, uint32_t s)
{
    int64_t x = a;
    int64_t y = b;
    if ((x >= 0 && y >= 0) || (x <= 0 && y <= 0)) {
        return (uint64_t)((llabs(x) + llabs(y)) * (int64_t)s);
    }
    {
        int64_t num = (x * x + y * y) * 2 * (int64_t)s;
        int64_t den = 2 * llabs(x - y);
        REQUIRE(num % den == 0);
        return (uint64_t)(num / den);
    }
}

static u128_t step_cost(const oracle_t *o, size_t i, int32_t a, int32_t b, uint32_t act)
{
    return ((o->wunit[i] * area2s(a, b, o->steep[i])) << EFF_BITS) + act_effort[act];
}

static coa_sweep_t sweep_of(const oracle_t *o, size_t i, uint32_t k, int32_t a, int32_t b)
{
    coa_sweep_t s;
    s.volume = o->f->veh[i].volume;
    s.p0 = o->f->ref[i][k];
    s.p0.z += (coa_real_t)a * o->dh[i];
    s.p1 = o->f->ref[i][k + 1u];
    s.p1.z += (coa_real_t)b * o->dh[i];
    return s;
}

static uint32_t gcd32(uint32_t a, uint32_t b)
{
    while (b != 0u) {
        uint32_t t = a % b;
        a = b;
        b = t;
    }
    return a;
}

/* Validity of every step, and each vehicle's exact cost to go and from the start alone
 * (dynamic programmes over the same steps). */
static void oracle_init(oracle_t *o, const fx_t *f)
{
    uint64_t w[MAXM];
    uint32_t scale = 1u;
    int e;
    size_t i;
    uint32_t k;
    int32_t x;
    uint32_t a;

    memset(o, 0, sizeof *o);
    o->f = f;
    o->m = f->p.vehicle_count;
    o->n = f->p.horizon;
    ck_assert_int_eq(coa_deviation_weights(f->veh, o->m, f->p.dt, w, &e), COA_OK);
    for (i = 0; i < o->m; ++i) {
        uint32_t s2 = 2u * f->veh[i].steep_factor;
        scale = scale / gcd32(scale, s2) * s2;
    }
    for (i = 0; i < o->m; ++i) {
        const coa_vehicle_t *v = &f->veh[i];
        o->init[i] = v->initial_offset;
        o->lim[i] = v->max_offset >= 0 ? v->max_offset : COA_MAX_OFFSET;
        o->steep[i] = v->steep_factor;
        o->dh[i] = coa_climb_step(v, f->p.dt);
        o->wunit[i] = (u128_t)w[i] * (scale / (2u * v->steep_factor));
        for (k = 0; k < o->n; ++k) {
            for (x = lo_of(o, i, k); x <= hi_of(o, i, k); ++x) {
                for (a = 0; a < ACTS; ++a) {
                    int32_t b = x + delta(o, i, a);
                    coa_sweep_t s;
                    if (b < -o->lim[i] || b > o->lim[i]) {
                        continue;
                    }
                    s = sweep_of(o, i, k, x, b);
                    o->ok[i][k][x - lo_of(o, i, k)][a] = fx_static_clear(o->f, &s, k) ? 1u : 0u;
                }
            }
        }
        for (k = 0; k <= o->n; ++k) {
            for (x = 0; x < (int32_t)ROWW; ++x) {
                o->tg[i][k][x] = k == o->n ? 0u : INF;
                o->fs[i][k][x] = INF;
            }
        }
        for (k = o->n; k-- > 0u;) {
            for (x = lo_of(o, i, k); x <= hi_of(o, i, k); ++x) {
                u128_t *c = &o->tg[i][k][x - lo_of(o, i, k)];
                for (a = 0; a < ACTS; ++a) {
                    int32_t b = x + delta(o, i, a);
                    u128_t nx;
                    if (!o->ok[i][k][x - lo_of(o, i, k)][a]) {
                        continue;
                    }
                    nx = o->tg[i][k + 1u][b - lo_of(o, i, k + 1u)];
                    if (nx != INF && step_cost(o, i, x, b, a) + nx < *c) {
                        *c = step_cost(o, i, x, b, a) + nx;
                    }
                }
            }
        }
        o->fs[i][0][0] = 0u;
        for (k = 0; k < o->n; ++k) {
            for (x = lo_of(o, i, k); x <= hi_of(o, i, k); ++x) {
                u128_t here = o->fs[i][k][x - lo_of(o, i, k)];
                if (here == INF) {
                    continue;
                }
                for (a = 0; a < ACTS; ++a) {
                    int32_t b = x + delta(o, i, a);
                    u128_t *c;
                    if (!o->ok[i][k][x - lo_of(o, i, k)][a]) {
                        continue;
                    }
                    c = &o->fs[i][k + 1u][b - lo_of(o, i, k + 1u)];
                    if (here + step_cost(o, i, x, b, a) < *c) {
                        *c = here + step_cost(o, i, x, b, a);
                    }
                }
            }
        }
    }
}

static u128_t tg_at(const oracle_t *o, size_t i, uint32_t k, int32_t x)
{
    return o->tg[i][k][x - lo_of(o, i, k)];
}

static u128_t fs_at(const oracle_t *o, size_t i, uint32_t k, int32_t x)
{
    return o->fs[i][k][x - lo_of(o, i, k)];
}

static void *xcalloc(size_t n, size_t size)
{
    void *p = calloc(n, size);
    ck_assert_ptr_nonnull(p);
    return p;
}

/* A planner on an aligned heap buffer. */
static coa_planner_t *planner_new(const coa_planner_config_t *c, void **buffer)
{
    size_t bytes = coa_planner_workspace_size(c);
    coa_planner_t *pl;
    ck_assert_uint_gt(bytes, 0u);
    *buffer = xcalloc(1u, bytes);
    pl = coa_planner_init(*buffer, bytes, c);
    ck_assert_ptr_nonnull(pl);
    return pl;
}

/* ------------------------------------------------------------------------------------ */
/* 1. Each vehicle's cost-to-go table                                                    */

typedef struct {
    bool found;
    uint64_t dev; /* own units: area * 2s */
    uint32_t eff;
    int32_t path[MAXN + 1u];
} best_t;

/* Every action sequence from (k, x) to the horizon, by brute force. */
static void dfs(const oracle_t *o, uint32_t k, int32_t x, uint64_t dev, uint32_t eff, int32_t *path,
                best_t *b, uint64_t *visits)
{
    uint32_t a;
    ++*visits;
    path[k] = x;
    if (k == o->n) {
        if (!b->found || dev < b->dev || (dev == b->dev && eff < b->eff)) {
            b->found = true;
            b->dev = dev;
            b->eff = eff;
            memcpy(b->path, path, sizeof b->path);
        }
        return;
    }
    for (a = 0; a < ACTS; ++a) {
        int32_t y = x + delta(o, 0u, a);
        if (o->ok[0][k][x - lo_of(o, 0u, k)][a]) {
            dfs(o, k + 1u, y, dev + area2s(x, y, o->steep[0]), eff + act_effort[a], path, b,
                visits);
        }
    }
}

typedef struct {
    unsigned problems;
    unsigned cells;
    unsigned dead;
    unsigned live;
    unsigned dead_roots;
    unsigned initial_conflicts;
    unsigned solved;
    unsigned masked_out; /* actions in the bound left out of a live cell's mask */
    uint64_t visits;
} table_stats_t;

static void check_table(uint64_t seed, table_stats_t *st)
{
    static fx_t f;
    static oracle_t o;
    static best_t best[MAXN + 1u][ROWW];
    uint64_t rng = seed;
    uint32_t horizon = 4u + pick(&rng, 5u);
    uint32_t steep = 2u + pick(&rng, 2u);
    coa_planner_config_t cfg;
    coa_planner_t *pl;
    void *buf;
    int32_t rows[MAXN + 1u];
    coa_plan_result_t res;
    const plan_table_t *t;
    uint32_t k;
    int32_t x;

    fx_single(&f, &rng, horizon, steep);
    oracle_init(&o, &f);
    ck_assert_int_eq(coa_planner_config_of(&f.p, 1u, 1u, &cfg), COA_OK);
    pl = planner_new(&cfg, &buf);
    ck_assert_int_eq(coa_plan_centralised(pl, &f.p, rows, &res), COA_OK);
    t = &pl->to_go[0];
    if (res.searches == 0u) {
        /* A conflict at t = 0: the front end stops before building the table. */
        ck_assert_int_eq(res.status, COA_PLAN_INFEASIBLE);
        coa_plan_table_build(pl, &pl->to_go[0], 0u, NULL, 0u);
        ++st->initial_conflicts;
    }
    ck_assert_uint_eq(t->vehicle, 0u);
    ck_assert_int_eq(t->origin, o.init[0]);
    ck_assert_uint_eq(t->horizon, horizon);
    ++st->problems;

    for (k = horizon + 1u; k-- > 0u;) {
        ck_assert_int_eq(plan_row_lo(t, k), lo_of(&o, 0u, k));
        ck_assert_int_eq(plan_row_hi(t, k), hi_of(&o, 0u, k));
        for (x = lo_of(&o, 0u, k); x <= hi_of(&o, 0u, k); ++x) {
            best_t *b = &best[k][x - lo_of(&o, 0u, k)];
            int32_t path[MAXN + 1u];
            uint64_t cell = plan_table_at(t, k, x);
            u128_t dp = tg_at(&o, 0u, k, x);
            uint32_t mask = 0u;
            uint32_t a;
            b->found = false;
            dfs(&o, k, x, 0u, 0u, path, b, &st->visits);
            ++st->cells;
            /* the oracle's own programme agrees with the brute force */
            REQUIRE((dp == INF) == !b->found);
            REQUIRE(!b->found || dp == (((o.wunit[0] * b->dev) << EFF_BITS) | b->eff));
            if (k < horizon) {
                for (a = 0; a < ACTS; ++a) {
                    int32_t y = x + delta(&o, 0u, a);
                    if (o.ok[0][k][x - lo_of(&o, 0u, k)][a] &&
                        best[k + 1u][y - lo_of(&o, 0u, k + 1u)].found) {
                        mask |= 1u << a;
                    } else if (b->found && y >= -o.lim[0] && y <= o.lim[0]) {
                        ++st->masked_out;
                    }
                }
            }
            if (!b->found) {
                if (!cell_dead(cell) || cell_mask(cell) != 0u) {
                    ck_abort_msg("seed %llu: k=%u offset %d: brute force dead, table %s "
                                 "(dev %llu eff %u mask %#x)",
                                 (unsigned long long)seed, k, x, cell_dead(cell) ? "dead" : "live",
                                 (unsigned long long)cell_dev(cell), cell_eff(cell),
                                 cell_mask(cell));
                }
                ++st->dead;
                continue;
            }
            ++st->live;
            if (cell_dead(cell) || cell_dev(cell) != b->dev || cell_eff(cell) != b->eff ||
                cell_mask(cell) != mask) {
                ck_abort_msg("seed %llu: k=%u offset %d: brute force dev %llu eff %u mask "
                             "%#x, table %s dev %llu eff %u mask %#x",
                             (unsigned long long)seed, k, x, (unsigned long long)b->dev, b->eff,
                             mask, cell_dead(cell) ? "dead" : "live",
                             (unsigned long long)cell_dev(cell), cell_eff(cell), cell_mask(cell));
            }
            if (k < horizon) {
                /* the public cost function prices the brute force's best plan the same */
                double dev;
                uint32_t eff;
                double want = (double)f.veh[0].cruise_speed * (double)f.p.dt *
                              ((double)f.veh[0].climb_rate * (double)f.p.dt) * (double)b->dev /
                              (2.0 * (double)steep);
                ck_assert_int_eq(
                    coa_plan_vehicle_cost(&f.veh[0], f.p.dt, horizon - k, &b->path[k], &dev, &eff),
                    COA_OK);
                REQUIRE(eff == b->eff);
                REQUIRE(fabs(dev - want) <= 1e-9 * (1.0 + want));
            }
        }
    }
    /* The front end's answer is the table's root. */
    {
        const best_t *root = &best[0][0];
        if (!root->found) {
            ++st->dead_roots;
            ck_assert_int_eq(res.status, COA_PLAN_INFEASIBLE);
        } else if (res.searches > 0u) {
            u128_t units = o.wunit[0] * root->dev;
            ck_assert_int_eq(res.status, COA_PLAN_SOLVED);
            ck_assert(from_cost(res.deviation_units) == units);
            ck_assert_uint_eq(res.effort, root->eff);
            ++st->solved;
        }
    }
    free(buf);
}

START_TEST(table_exact)
{
    table_stats_t st;
    uint64_t seed;
    memset(&st, 0, sizeof st);
    for (seed = 1u; seed <= 400u; ++seed) {
        check_table(0x7ab1e000u + seed * 7919u, &st);
    }
    fprintf(stderr,
            "table_exact: %u problems, %u cells (%u live, %u dead), %u dead roots, %u initial "
            "conflicts, %u solved, %u actions masked out of live cells, %llu DFS visits\n",
            st.problems, st.cells, st.live, st.dead, st.dead_roots, st.initial_conflicts, st.solved,
            st.masked_out, (unsigned long long)st.visits);
    /* the generator must exercise dead states and masks */
    ck_assert_uint_gt(st.dead, 200u);
    ck_assert_uint_gt(st.masked_out, 200u);
    ck_assert_uint_gt(st.dead_roots, 5u);
    ck_assert_uint_gt(st.solved, 200u);
}
END_TEST

/* ------------------------------------------------------------------------------------ */
/* 2. The joint heuristic                                                                */

/* Dense layers of joint states: the offsets of the members of a set at sample k, each
 * within its reachable row. */
typedef struct {
    size_t dims;
    size_t member[MAXM];
    int32_t lo[MAXM];
    size_t width[MAXM];
    size_t stride[MAXM];
    size_t size;
} layer_t;

static void layer_make(const oracle_t *o, uint32_t k, uint32_t set, layer_t *l)
{
    size_t i;
    size_t stride = 1u;
    l->dims = 0u;
    for (i = 0; i < o->m; ++i) {
        if ((set & (1u << i)) != 0u) {
            size_t d = l->dims++;
            l->member[d] = i;
            l->lo[d] = lo_of(o, i, k);
            l->width[d] = (size_t)(hi_of(o, i, k) - lo_of(o, i, k)) + 1u;
            l->stride[d] = stride;
            stride *= l->width[d];
        }
    }
    l->size = stride;
}

/* The index of the offsets off[member] of the layer's members. */
static size_t layer_index(const layer_t *l, const int32_t *off)
{
    size_t idx = 0u;
    size_t d;
    for (d = 0; d < l->dims; ++d) {
        int32_t x = off[l->member[d]] - l->lo[d];
        REQUIRE(x >= 0 && (size_t)x < l->width[d]);
        idx += (size_t)x * l->stride[d];
    }
    return idx;
}

static void layer_decode(const layer_t *l, size_t idx, int32_t *off)
{
    size_t d;
    for (d = 0; d < l->dims; ++d) {
        off[l->member[d]] = l->lo[d] + (int32_t)((idx / l->stride[d]) % l->width[d]);
    }
}

/* Conflicts between two UAVs' steps, computed once: 0 not yet, 1 clear, 2 conflict. */
static uint8_t pair_memo[MAXM * (MAXM - 1u) / 2u][MAXN][ROWW][ACTS][ROWW][ACTS];

static size_t pair_of(size_t i, size_t j)
{
    /* i < j < 3 */
    return i == 0u ? j - 1u : 2u;
}

static bool steps_clear(const oracle_t *o, uint32_t k, size_t i, int32_t xi, uint32_t ai, size_t j,
                        int32_t xj, uint32_t aj)
{
    uint8_t *c;
    if (i > j) {
        size_t ts = i;
        int32_t tx = xi;
        uint32_t ta = ai;
        i = j;
        xi = xj;
        ai = aj;
        j = ts;
        xj = tx;
        aj = ta;
    }
    c = &pair_memo[pair_of(i, j)][k][xi - lo_of(o, i, k)][ai][xj - lo_of(o, j, k)][aj];
    if (*c == 0u) {
        coa_sweep_t a = sweep_of(o, i, k, xi, xi + delta(o, i, ai));
        coa_sweep_t b = sweep_of(o, j, k, xj, xj + delta(o, j, aj));
        *c = coa_conflict_volumes(&a, &b) ? 2u : 1u;
    }
    return *c == 1u;
}

/* The exact joint cost to go of every UAV at every sample, every pair checked at every
 * step: v[k] over the layer of all UAVs. */
typedef struct {
    const oracle_t *o;
    uint32_t k;
    int32_t off[MAXM];
    int32_t to[MAXM];
    uint32_t act[MAXM];
    const layer_t *next_layer;
    const u128_t *next;
    u128_t best;
} dp_ctx_t;

static void dp_rec(dp_ctx_t *c, size_t i, u128_t cost)
{
    const oracle_t *o = c->o;
    uint32_t a;
    if (cost >= c->best) {
        return;
    }
    if (i == o->m || i >= MAXM) { /* o->m <= MAXM: the second says so to the compiler */
        u128_t nx = c->next[layer_index(c->next_layer, c->to)];
        if (nx != INF && cost + nx < c->best) {
            c->best = cost + nx;
        }
        return;
    }
    for (a = 0; a < ACTS; ++a) {
        bool ok = o->ok[i][c->k][c->off[i] - lo_of(o, i, c->k)][a] != 0u;
        size_t j;
        for (j = 0; ok && j < i; ++j) {
            ok = steps_clear(o, c->k, j, c->off[j], c->act[j], i, c->off[i], a);
        }
        if (ok) {
            c->act[i] = a;
            c->to[i] = c->off[i] + delta(o, i, a);
            dp_rec(c, i + 1u, cost + step_cost(o, i, c->off[i], c->to[i], a));
        }
    }
}

static void full_dp(const oracle_t *o, u128_t **v, layer_t *full)
{
    const uint32_t all = (1u << o->m) - 1u;
    dp_ctx_t c;
    uint32_t k;
    size_t idx;

    for (k = 0; k <= o->n; ++k) {
        layer_make(o, k, all, &full[k]);
        v[k] = xcalloc(full[k].size, sizeof(u128_t));
    }
    memset(&c, 0, sizeof c);
    c.o = o;
    for (k = o->n; k-- > 0u;) {
        c.k = k;
        c.next_layer = &full[k + 1u];
        c.next = v[k + 1u];
        for (idx = 0; idx < full[k].size; ++idx) {
            layer_decode(&full[k], idx, c.off);
            c.best = INF;
            dp_rec(&c, 0u, 0u);
            v[k][idx] = c.best;
        }
    }
}

/* The search's state graph. */
typedef struct {
    const oracle_t *o;
    const plan_group_t *g;
    uint32_t k0;
    uint32_t end;
    layer_t layer[MAXN + 2u]; /* over the members in the search at k */
    u128_t *ha[MAXN + 2u];    /* (A) exact cost to go over the search's graph */
    u128_t *hb[MAXN + 2u];    /* (B) the same from the full programme */
    uint8_t *reach[MAXN + 2u];
    uint8_t *hlive[MAXN + 2u]; /* the heuristic says live */
    u128_t *h2[MAXN + 2u];     /* the doubled heuristic */
} graph_t;

static bool in_span(const plan_group_t *g, size_t i, uint32_t k)
{
    return k >= g->first[i] && k <= g->last[i];
}

static uint32_t in_set(const graph_t *gr, uint32_t k)
{
    uint32_t set = 0u;
    size_t i;
    for (i = 0; i < gr->o->m; ++i) {
        set |= in_span(gr->g, i, k) ? 1u << i : 0u;
    }
    return set;
}

/* One step of the search from state (k, off): the members in the search move, those
 * whose span starts at k + 1 enter at any offset they can reach alone, those whose span
 * ended at k leave at their cost to go alone. visit gets every valid step with its exact
 * cost (the planner's g increase). */
typedef struct edge_ctx edge_ctx_t;
struct edge_ctx {
    const graph_t *gr;
    uint32_t k;
    size_t count;
    size_t who[MAXM];
    bool enters[MAXM];
    int32_t from[MAXM];
    int32_t to[MAXM];
    uint32_t act[MAXM];
    void (*visit)(edge_ctx_t *e, size_t next, u128_t cost);
    /* the visitor's own state */
    size_t idx;
    u128_t acc;
    uint64_t edges;
};

static void edges_rec(edge_ctx_t *e, size_t c, u128_t cost)
{
    const oracle_t *o = e->gr->o;
    const plan_group_t *g = e->gr->g;
    const uint32_t k = e->k;
    size_t i;
    size_t d;

    if (c == e->count) {
        for (d = 0; d < e->count; ++d) {
            i = e->who[d];
            if (!e->enters[d] && g->last[i] == k) {
                u128_t t = tg_at(o, i, k + 1u, e->to[i]);
                if (t == INF) {
                    return;
                }
                cost += t;
            }
        }
        e->visit(e, layer_index(&e->gr->layer[k + 1u], e->to), cost);
        return;
    }
    i = e->who[c];
    if (i >= MAXM) { /* never: who[] holds members; says so to the compiler's bounds check */
        return;
    }
    if (e->enters[c]) {
        int32_t x;
        for (x = lo_of(o, i, k + 1u); x <= hi_of(o, i, k + 1u); ++x) {
            u128_t f = fs_at(o, i, k + 1u, x);
            if (f != INF) {
                e->to[i] = x;
                edges_rec(e, c + 1u, cost + f);
            }
        }
        return;
    }
    for (e->act[i] = 0u; e->act[i] < ACTS; ++e->act[i]) {
        const uint32_t a = e->act[i];
        bool ok = o->ok[i][k][e->from[i] - lo_of(o, i, k)][a] != 0u;
        for (d = 0; ok && d < c; ++d) {
            size_t j = e->who[d];
            /* every pair of movers, whether or not their spans say they can meet */
            ok = e->enters[d] || steps_clear(o, k, j, e->from[j], e->act[j], i, e->from[i], a);
        }
        if (ok) {
            e->to[i] = e->from[i] + delta(o, i, a);
            edges_rec(e, c + 1u, cost + step_cost(o, i, e->from[i], e->to[i], a));
        }
    }
}

static void edges_of(edge_ctx_t *e, uint32_t k, size_t idx)
{
    const graph_t *gr = e->gr;
    size_t i;
    e->k = k;
    e->idx = idx;
    e->count = 0u;
    for (i = 0; i < MAXM; ++i) {
        e->from[i] = INT32_MIN;
        e->to[i] = INT32_MIN;
    }
    layer_decode(&gr->layer[k], idx, e->from);
    for (i = 0; i < gr->o->m; ++i) {
        if (in_span(gr->g, i, k)) {
            e->who[e->count] = i;
            e->enters[e->count++] = false;
        } else if (gr->g->first[i] == k + 1u) {
            e->who[e->count] = i;
            e->enters[e->count++] = true;
        }
    }
    edges_rec(e, 0u, 0u);
}

static void visit_min(edge_ctx_t *e, size_t next, u128_t cost)
{
    u128_t h = e->gr->ha[e->k + 1u][next];
    if (h != INF && cost + h < e->acc) {
        e->acc = cost + h;
    }
}

static void visit_reach(edge_ctx_t *e, size_t next, u128_t cost)
{
    (void)cost;
    e->gr->reach[e->k + 1u][next] = 1u;
}

typedef struct {
    unsigned problems;
    unsigned skipped_size;
    unsigned states;
    unsigned live_states;
    unsigned dead_by_h;
    unsigned dead_by_own; /* truly dead states the heuristic prices finite */
    unsigned tight;       /* h == exact */
    unsigned positive_matching;
    unsigned waiting_states; /* reachable states with a member waiting */
    unsigned left_states;    /* ... with a member that has left */
    unsigned spans_partial;  /* problems with a member whose span is not 0..N-1 */
    unsigned joint_dearer;   /* optimum above the sum alone */
    unsigned searched;
    unsigned search_budget;
    unsigned pair_tables;
    unsigned pair_cells_positive;
    unsigned triangles; /* live states with three members in the search, all surcharges > 0 */
    uint64_t edges;
    uint64_t full_states;
} joint_stats_t;

/* The consistency check of every step out of a reachable state. */
static const char *fail_seed_msg;
static uint64_t fail_seed;

static void visit_consistent(edge_ctx_t *e, size_t next, u128_t cost)
{
    const graph_t *gr = e->gr;
    const uint32_t k = e->k;
    ++e->edges;
    if (!gr->hlive[k + 1u][next]) {
        return; /* h(s') infinite */
    }
    if (gr->h2[k][e->idx] > 2u * cost + gr->h2[k + 1u][next]) {
        int32_t a[MAXM] = {0, 0, 0};
        int32_t b[MAXM] = {0, 0, 0};
        layer_decode(&gr->layer[k], e->idx, a);
        layer_decode(&gr->layer[k + 1u], next, b);
        ck_abort_msg("%s seed %llu: inconsistent: k=%u (%d,%d,%d) h2=%s -> k=%u (%d,%d,%d) "
                     "h2=%s, 2c=%s (exact cost to go %s -> %s)",
                     fail_seed_msg, (unsigned long long)fail_seed, k, a[0], a[1], a[2],
                     pk(gr->h2[k][e->idx]), k + 1u, b[0], b[1], b[2], pk(gr->h2[k + 1u][next]),
                     pk(2u * cost), pk(gr->hb[k][e->idx]), pk(gr->hb[k + 1u][next]));
    }
}

/* The rows' exact cost, priced by the oracle. */
static u128_t rows_cost(const oracle_t *o, const int32_t *rows)
{
    u128_t sum = 0u;
    size_t i;
    uint32_t k;
    for (i = 0; i < o->m; ++i) {
        const int32_t *r = &rows[i * (o->n + 1u)];
        for (k = 0; k < o->n; ++k) {
            uint32_t a;
            for (a = 0; a < ACTS && r[k] + delta(o, i, a) != r[k + 1u]; ++a) {
            }
            REQUIRE(a < ACTS);
            sum += step_cost(o, i, r[k], r[k + 1u], a);
        }
    }
    return sum;
}

static coa_cost_t to_cost(u128_t x)
{
    coa_cost_t c;
    c.hi = (uint64_t)(x >> 64);
    c.lo = (uint64_t)x;
    return c;
}

/* Pair (i, j)'s table against the exact cost to go of the two alone (every step checked,
 * not only those where the planner says they can meet), from their own costs to go after
 * its last row: equal wherever both offsets are live both ways (cost from the start and
 * to go), dead elsewhere. Returns the cells with a positive surcharge. */
static unsigned check_pair_table(const oracle_t *o, const coa_planner_t *pl, size_t i, size_t j,
                                 uint64_t seed)
{
    static u128_t exact[2][ROWW][ROWW];
    const plan_pair_t *p = &pl->pair[plan_pair_index(i, j, o->m)];
    unsigned positive = 0u;
    uint32_t k = p->last + 1u;
    int32_t x;
    int32_t y;

    for (x = lo_of(o, i, k); x <= hi_of(o, i, k); ++x) {
        for (y = lo_of(o, j, k); y <= hi_of(o, j, k); ++y) {
            u128_t a = tg_at(o, i, k, x);
            u128_t b = tg_at(o, j, k, y);
            exact[k & 1u][x - lo_of(o, i, k)][y - lo_of(o, j, k)] =
                (a == INF || b == INF) ? INF : a + b;
        }
    }
    while (k-- > p->first) {
        for (x = lo_of(o, i, k); x <= hi_of(o, i, k); ++x) {
            for (y = lo_of(o, j, k); y <= hi_of(o, j, k); ++y) {
                u128_t best = INF;
                u128_t ti = tg_at(o, i, k, x);
                u128_t tj = tg_at(o, j, k, y);
                bool live =
                    ti != INF && tj != INF && fs_at(o, i, k, x) != INF && fs_at(o, j, k, y) != INF;
                coa_cost_t sur;
                uint32_t a;
                uint32_t b;
                for (a = 0; a < ACTS; ++a) {
                    int32_t x2 = x + delta(o, i, a);
                    if (!o->ok[i][k][x - lo_of(o, i, k)][a]) {
                        continue;
                    }
                    for (b = 0; b < ACTS; ++b) {
                        int32_t y2 = y + delta(o, j, b);
                        u128_t nx;
                        if (!o->ok[j][k][y - lo_of(o, j, k)][b] ||
                            !steps_clear(o, k, i, x, a, j, y, b)) {
                            continue;
                        }
                        nx = exact[(k + 1u) & 1u][x2 - lo_of(o, i, k + 1u)]
                                  [y2 - lo_of(o, j, k + 1u)];
                        if (nx != INF) {
                            u128_t c = nx + step_cost(o, i, x, x2, a) + step_cost(o, j, y, y2, b);
                            best = c < best ? c : best;
                        }
                    }
                }
                exact[k & 1u][x - lo_of(o, i, k)][y - lo_of(o, j, k)] = best;
                sur = coa_plan_pair_surcharge(pl, i, j, k, x, y, to_cost(live ? ti : 0u),
                                              to_cost(live ? tj : 0u));
                if (!live || best == INF) {
                    if (!plan_cost_dead(sur)) {
                        ck_abort_msg("seed %llu: pair (%zu,%zu) k=%u (%d,%d): table live "
                                     "(surcharge %s), exact %s, offsets live both ways: %d",
                                     (unsigned long long)seed, i, j, k, x, y, pk(from_cost(sur)),
                                     pk(best), (int)live);
                    }
                    continue;
                }
                if (plan_cost_dead(sur) || from_cost(sur) + ti + tj != best) {
                    ck_abort_msg("seed %llu: pair (%zu,%zu) k=%u (%d,%d): table %s, exact %s",
                                 (unsigned long long)seed, i, j, k, x, y,
                                 plan_cost_dead(sur) ? "dead" : pk(from_cost(sur) + ti + tj),
                                 pk(best));
                }
                positive += from_cost(sur) > 0u ? 1u : 0u;
            }
        }
    }
    return positive;
}

static void check_joint(uint64_t seed, size_t m, joint_stats_t *st, coa_planner_t *pl)
{
    static fx_t f;
    static oracle_t o;
    static graph_t gr;
    static int32_t rows[MAXM * (MAXN + 1u)];
    u128_t *v[MAXN + 1u];
    layer_t full[MAXN + 1u];
    uint64_t rng = seed;
    uint32_t horizon;
    uint32_t steep;
    const plan_group_t *g;
    coa_plan_result_t res;
    edge_ctx_t e;
    uint64_t total = 0u;
    uint32_t k;
    size_t i;
    size_t j;
    size_t idx;
    int rc;

    if (m == 2u) {
        horizon = 4u + pick(&rng, 4u);
        steep = 3u;
    } else {
        horizon = 4u + pick(&rng, 3u);
        steep = pick(&rng, 4u) == 0u ? 3u : 2u;
    }
    fx_group(&f, &rng, m, horizon, steep);
    oracle_init(&o, &f);
    for (k = 0; k <= horizon; ++k) {
        size_t size = 1u;
        for (i = 0; i < m; ++i) {
            size *= (size_t)(hi_of(&o, i, k) - lo_of(&o, i, k)) + 1u;
        }
        total += size;
    }
    if (total > (m == 2u ? 20000u : 90000u)) {
        ++st->skipped_size;
        return;
    }
    fail_seed_msg = m == 2u ? "2 UAVs" : "3 UAVs";
    fail_seed = seed;

    rc = coa_plan_centralised(pl, &f.p, rows, &res);
    ck_assert_int_eq(rc, COA_OK);
    coa_plan_test_group_setup(pl, (1u << m) - 1u);
    g = &pl->group;
    ck_assert_uint_eq(g->count, m);
    ck_assert(!g->capped && !g->bounded && g->fixed_count == 0u);
    ++st->problems;
    st->full_states += total;

    /* The planner's tables against the oracle's (both alone, exact). */
    for (i = 0; i < m; ++i) {
        ck_assert_uint_eq(g->vehicle[i], i);
        ck_assert(g->last[i] < horizon && g->first[i] <= g->last[i]);
        if (g->first[i] > 0u || g->last[i] + 1u < horizon) {
            ++st->spans_partial;
        }
        for (k = 0; k <= horizon; ++k) {
            int32_t x;
            for (x = lo_of(&o, i, k); x <= hi_of(&o, i, k); ++x) {
                uint64_t tc = plan_table_at(&pl->to_go[i], k, x);
                uint64_t fc = plan_table_at(&pl->from_start[i], k, x);
                u128_t tg = tg_at(&o, i, k, x);
                u128_t fs = fs_at(&o, i, k, x);
                u128_t tv = cell_dead(tc) ? INF : from_cost(plan_cell_cost(pl, i, tc));
                u128_t fv = cell_dead(fc) ? INF : from_cost(plan_cell_cost(pl, i, fc));
                /* From the start the table goes over live states only: the oracle's value
                 * where the state is live, dead elsewhere (but at the start itself). */
                u128_t fw = tg != INF ? fs : (k == 0u && x == o.init[i]) ? 0u : INF;
                if (tv != tg || fv != fw) {
                    ck_abort_msg("%s seed %llu: UAV %zu k=%u offset %d: cost to go %s (exact "
                                 "%s), from the start %s (exact %s)",
                                 fail_seed_msg, (unsigned long long)seed, i, k, x, pk(tv), pk(tg),
                                 pk(fv), pk(fw));
                }
            }
        }
    }
    /* Uncapped pair tables: present wherever the pair can meet, over rows from the first
     * sample both are in the search to the last step they can meet, and their corridors
     * are every offset that is live both ways (the full reachable range). */
    for (i = 0; i < m; ++i) {
        for (j = i + 1u; j < m; ++j) {
            size_t pi = plan_pair_index(i, j, m);
            const plan_pair_t *p = &pl->pair[pi];
            if (g->near_first[pi] > g->near_last[pi]) {
                ck_assert(!p->present);
                continue;
            }
            ck_assert(p->present);
            ck_assert_uint_eq(p->first, g->first[i] > g->first[j] ? g->first[i] : g->first[j]);
            ck_assert_uint_eq(p->last, g->near_last[pi]);
            for (k = p->first; k <= p->last; ++k) {
                const int16_t *c = &p->row_lo[4u * (k - p->first)];
                size_t side;
                for (side = 0; side < 2u; ++side) {
                    size_t u = side == 0u ? i : j;
                    int32_t lo = INT16_MAX;
                    int32_t hi = INT16_MIN;
                    int32_t x;
                    for (x = lo_of(&o, u, k); x <= hi_of(&o, u, k); ++x) {
                        if (tg_at(&o, u, k, x) != INF && fs_at(&o, u, k, x) != INF) {
                            lo = x < lo ? x : lo;
                            hi = x > hi ? x : hi;
                        }
                    }
                    ck_assert_int_eq(c[2u * side], lo);
                    ck_assert_int_eq(c[2u * side + 1u], hi);
                }
            }
            st->pair_cells_positive += check_pair_table(&o, pl, i, j, seed);
            ++st->pair_tables;
        }
    }

    /* The exact joint cost to go, all UAVs, all pairs, all steps. */
    full_dp(&o, v, full);

    memset(&gr, 0, sizeof gr);
    gr.o = &o;
    gr.g = g;
    gr.end = g->end;
    gr.k0 = UINT32_MAX;
    for (i = 0; i < m; ++i) {
        gr.k0 = g->first[i] < gr.k0 ? g->first[i] : gr.k0;
    }
    gr.k0 = gr.k0 > 0u ? gr.k0 - 1u : 0u;
    ck_assert_uint_le(gr.end, horizon);
    for (k = gr.k0; k <= gr.end; ++k) {
        layer_make(&o, k, in_set(&gr, k), &gr.layer[k]);
        gr.ha[k] = xcalloc(gr.layer[k].size, sizeof(u128_t));
        gr.hb[k] = xcalloc(gr.layer[k].size, sizeof(u128_t));
        gr.h2[k] = xcalloc(gr.layer[k].size, sizeof(u128_t));
        gr.reach[k] = xcalloc(gr.layer[k].size, 1u);
        gr.hlive[k] = xcalloc(gr.layer[k].size, 1u);
    }
    ck_assert_uint_eq(gr.layer[gr.end].dims, 0u);

    /* (B): from the full programme. Waiting members (before their span) bring their
     * cheapest past alone, left members (after it) take their cost to go alone away. */
    for (k = gr.k0; k <= gr.end; ++k) {
        for (idx = 0; idx < gr.layer[k].size; ++idx) {
            gr.hb[k][idx] = INF;
        }
        for (idx = 0; idx < full[k].size; ++idx) {
            int32_t off[MAXM];
            u128_t val = v[k][idx];
            u128_t less = 0u;
            size_t at;
            if (val == INF) {
                continue;
            }
            layer_decode(&full[k], idx, off);
            for (i = 0; i < m && val != INF; ++i) {
                if (k < g->first[i]) {
                    u128_t p = fs_at(&o, i, k, off[i]);
                    val = p == INF ? INF : val + p;
                } else if (k > g->last[i]) {
                    u128_t t = tg_at(&o, i, k, off[i]);
                    REQUIRE(t != INF); /* the full programme's plan goes on from there */
                    less += t;
                }
            }
            if (val == INF) {
                continue;
            }
            REQUIRE(val >= less);
            val -= less;
            at = layer_index(&gr.layer[k], off);
            gr.hb[k][at] = val < gr.hb[k][at] ? val : gr.hb[k][at];
        }
    }
    /* (A): backwards over the search's graph. */
    memset(&e, 0, sizeof e);
    e.gr = &gr;
    gr.ha[gr.end][0] = 0u;
    for (k = gr.end; k-- > gr.k0;) {
        for (idx = 0; idx < gr.layer[k].size; ++idx) {
            e.visit = visit_min;
            e.acc = INF;
            edges_of(&e, k, idx);
            gr.ha[k][idx] = e.acc;
        }
    }
    /* The search's root, and what it reaches. */
    {
        int32_t off[MAXM];
        size_t root;
        u128_t opt = v[0][layer_index(&full[0], o.init)];
        for (i = 0; i < m; ++i) {
            off[i] = o.init[i];
        }
        root = layer_index(&gr.layer[gr.k0], off);
        gr.reach[gr.k0][root] = 1u;
        /* the search's graph loses nothing: its optimum is the true one */
        ck_assert(gr.ha[gr.k0][root] == opt);
        if (opt != INF) {
            u128_t alone = 0u;
            for (i = 0; i < m; ++i) {
                alone += tg_at(&o, i, 0u, o.init[i]);
            }
            st->joint_dearer += opt > alone ? 1u : 0u;
        }
        for (k = gr.k0; k < gr.end; ++k) {
            for (idx = 0; idx < gr.layer[k].size; ++idx) {
                if (gr.reach[k][idx]) {
                    e.visit = visit_reach;
                    edges_of(&e, k, idx);
                }
            }
        }
        /* Every reachable state: (A) == (B), the heuristic admissible. */
        for (k = gr.k0; k <= gr.end; ++k) {
            for (idx = 0; idx < gr.layer[k].size; ++idx) {
                int16_t o16[PLAN_MAXM];
                int32_t at[MAXM] = {0, 0, 0};
                coa_cost_t h2;
                u128_t exact = gr.hb[k][idx];
                bool live;
                if (!gr.reach[k][idx]) {
                    continue;
                }
                ++st->states;
                layer_decode(&gr.layer[k], idx, at);
                for (i = 0; i < PLAN_MAXM; ++i) {
                    o16[i] = (i < m && in_span(g, i, k)) ? (int16_t)at[i] : PLAN_OUT;
                }
                for (i = 0; i < m; ++i) {
                    st->waiting_states += (k < g->first[i]) ? 1u : 0u;
                    st->left_states += (k > g->last[i]) ? 1u : 0u;
                }
                if (gr.ha[k][idx] != exact) {
                    ck_abort_msg("%s seed %llu: k=%u (%d,%d,%d): exact cost to go over the "
                                 "search's graph %s, over every UAV and step %s",
                                 fail_seed_msg, (unsigned long long)seed, k, at[0], at[1], at[2],
                                 pk(gr.ha[k][idx]), pk(exact));
                }
                live = coa_plan_test_heuristic(pl, k, o16, &h2);
                gr.hlive[k][idx] = live ? 1u : 0u;
                if (!live) {
                    ++st->dead_by_h;
                    if (exact != INF) {
                        ck_abort_msg("%s seed %llu: k=%u (%d,%d,%d): heuristic dead, exact "
                                     "cost to go %s",
                                     fail_seed_msg, (unsigned long long)seed, k, at[0], at[1],
                                     at[2], pk(exact));
                    }
                    continue;
                }
                gr.h2[k][idx] = from_cost(h2);
                if (exact == INF) {
                    ++st->dead_by_own;
                    continue;
                }
                ++st->live_states;
                if (from_cost(h2) > 2u * exact) {
                    ck_abort_msg("%s seed %llu: inadmissible: k=%u (%d,%d,%d): h2=%s, "
                                 "2 * exact=%s",
                                 fail_seed_msg, (unsigned long long)seed, k, at[0], at[1], at[2],
                                 pk(from_cost(h2)), pk(2u * exact));
                }
                st->tight += from_cost(h2) == 2u * exact ? 1u : 0u;
                {
                    /* What the heuristic is documented to be: twice the own costs to go of
                     * the members in the search and the costs alone of those not yet in
                     * it, plus the largest half-integral fractional matching of the
                     * surcharges (the pair tables are exact, checked above), doubled: here
                     * by brute force over y_e = 2 x_e in {0, 1, 2} with at most 2 at each
                     * member. */
                    u128_t own = 0u;
                    u128_t sur[3] = {0u, 0u, 0u};
                    u128_t match = 0u;
                    size_t pa[3] = {0u, 0u, 1u};
                    size_t pb[3] = {1u, 2u, 2u};
                    size_t npairs = m == 3u ? 3u : 1u;
                    unsigned pos = 0u;
                    uint32_t y;
                    for (i = 0; i < m; ++i) {
                        if (in_span(g, i, k)) {
                            own += tg_at(&o, i, k, at[i]);
                        } else if (k < g->first[i]) {
                            own += tg_at(&o, i, 0u, o.init[i]);
                        }
                    }
                    for (j = 0; j < npairs; ++j) {
                        coa_cost_t c;
                        if (!in_span(g, pa[j], k) || !in_span(g, pb[j], k)) {
                            continue;
                        }
                        c = coa_plan_pair_surcharge(pl, pa[j], pb[j], k, at[pa[j]], at[pb[j]],
                                                    to_cost(tg_at(&o, pa[j], k, at[pa[j]])),
                                                    to_cost(tg_at(&o, pb[j], k, at[pb[j]])));
                        REQUIRE(!plan_cost_dead(c)); /* the heuristic said live */
                        sur[j] = from_cost(c);
                        pos += sur[j] > 0u ? 1u : 0u;
                    }
                    for (y = 0; y < 27u; ++y) {
                        uint32_t ye[3] = {y % 3u, (y / 3u) % 3u, y / 9u};
                        uint32_t load[MAXM] = {0u, 0u, 0u};
                        u128_t val = 0u;
                        for (j = 0; j < 3u; ++j) {
                            load[pa[j]] += ye[j];
                            load[pb[j]] += ye[j];
                            val += (u128_t)ye[j] * sur[j];
                        }
                        if (load[0] <= 2u && load[1] <= 2u && load[2] <= 2u && val > match) {
                            match = val;
                        }
                    }
                    if (from_cost(h2) != 2u * own + match) {
                        ck_abort_msg("%s seed %llu: k=%u (%d,%d,%d): h2=%s, expected 2 * own "
                                     "%s + matching %s (surcharges %s %s %s)",
                                     fail_seed_msg, (unsigned long long)seed, k, at[0], at[1],
                                     at[2], pk(from_cost(h2)), pk(own), pk(match), pk(sur[0]),
                                     pk(sur[1]), pk(sur[2]));
                    }
                    st->positive_matching += match > 0u ? 1u : 0u;
                    st->triangles += pos == 3u ? 1u : 0u;
                }
            }
        }
        /* Every step out of a reachable state: consistent. */
        for (k = gr.k0; k < gr.end; ++k) {
            for (idx = 0; idx < gr.layer[k].size; ++idx) {
                if (gr.reach[k][idx] && gr.hlive[k][idx]) {
                    e.visit = visit_consistent;
                    edges_of(&e, k, idx);
                }
            }
        }
        st->edges += e.edges;

        /* The search on the uncapped group finds the optimum. */
        {
            plan_search_out_t out;
            coa_plan_search(pl, &out);
            if (out.status == COA_PLAN_BUDGET_EXHAUSTED) {
                ++st->search_budget;
            } else if (opt == INF) {
                ck_assert_int_eq(out.status, COA_PLAN_INFEASIBLE);
            } else {
                size_t which[MAXM] = {0u, 1u, 2u};
                if (out.status != COA_PLAN_SOLVED) {
                    ck_abort_msg("%s seed %llu: uncapped search status %d, optimum %s",
                                 fail_seed_msg, (unsigned long long)seed, (int)out.status, pk(opt));
                }
                ck_assert_int_eq(coa_plan_find_conflict(&f.p, rows, which, m, NULL, NULL), 0);
                if (rows_cost(&o, rows) != opt) {
                    ck_abort_msg("%s seed %llu: uncapped search's plan costs %s, optimum %s",
                                 fail_seed_msg, (unsigned long long)seed, pk(rows_cost(&o, rows)),
                                 pk(opt));
                }
                ++st->searched;
            }
            coa_plan_search_release(pl);
        }
    }

    for (k = 0; k <= horizon; ++k) {
        free(v[k]);
    }
    for (k = gr.k0; k <= gr.end; ++k) {
        free(gr.ha[k]);
        free(gr.hb[k]);
        free(gr.h2[k]);
        free(gr.reach[k]);
        free(gr.hlive[k]);
    }
}

static void run_joint(size_t m, unsigned count, uint64_t salt)
{
    joint_stats_t st;
    coa_planner_config_t cfg;
    coa_planner_t *pl;
    void *buf;
    unsigned s;

    memset(&st, 0, sizeof st);
    cfg.vehicles = m;
    cfg.beta = UINT32_C(1) << 17; /* also the pair arena: every pair table fits */
    cfg.horizon = MAXN;
    cfg.steep_factor = MAXS;
    cfg.max_offset = -1;
    pl = planner_new(&cfg, &buf);
    for (s = 1u; s <= count; ++s) {
        memset(pair_memo, 0, sizeof pair_memo);
        check_joint(salt + (uint64_t)s * 104729u, m, &st, pl);
    }
    free(buf);
    fprintf(stderr,
            "joint (%zu UAVs): %u problems (%u too large skipped), %llu full states; %u "
            "reachable search states (%u live, %u dead by the heuristic, %u dead priced "
            "finite), %u tight, %u with a positive matching, %u/%u member-states waiting/left, "
            "%u problems with partial spans, %u dearer than alone, %u live states with three "
            "positive surcharges; %u pair tables exact (%u cells with a positive surcharge); "
            "%llu steps checked for consistency; %u uncapped searches optimal, %u out of "
            "budget\n",
            m, st.problems, st.skipped_size, (unsigned long long)st.full_states, st.states,
            st.live_states, st.dead_by_h, st.dead_by_own, st.tight, st.positive_matching,
            st.waiting_states, st.left_states, st.spans_partial, st.joint_dearer, st.triangles,
            st.pair_tables, st.pair_cells_positive, (unsigned long long)st.edges, st.searched,
            st.search_budget);
    /* the generator must exercise what the test is about */
    ck_assert_uint_gt(st.positive_matching, 20u);
    ck_assert_uint_gt(st.waiting_states, 20u);
    ck_assert_uint_gt(st.left_states, 20u);
    ck_assert_uint_gt(st.joint_dearer, 5u);
    ck_assert_uint_gt(st.dead_by_h + st.dead_by_own, 5u);
}

START_TEST(joint_two)
{
    run_joint(2u, 300u, 0x2000000u);
}
END_TEST

START_TEST(joint_three)
{
    run_joint(3u, 80u, 0x3000000u);
}
END_TEST

/* The best sum over every set of disjoint edges (each counted twice) and triangles (each
 * edge once) among the members of mask: the matching by exhaustive recursion, with no
 * shortcut, for the direct formulas up to four members and the subset pass beyond. */
static coa_cost_t matching_brute(const coa_cost_t *s, size_t m, uint32_t mask)
{
    coa_cost_t best = {0u, 0u};
    size_t i = 0u;
    size_t j;
    size_t l;
    if (mask == 0u) {
        return best;
    }
    while ((mask & (1u << i)) == 0u) {
        ++i;
    }
    best = matching_brute(s, m, mask & ~(1u << i)); /* i alone */
    for (j = i + 1u; j < m; ++j) {
        coa_cost_t v;
        if ((mask & (1u << j)) == 0u) {
            continue;
        }
        v = plan_cost_add(plan_cost_twice(s[plan_pair_index(i, j, m)]),
                          matching_brute(s, m, mask & ~(1u << i) & ~(1u << j)));
        best = plan_cost_compare(v, best) > 0 ? v : best;
        for (l = j + 1u; l < m; ++l) {
            if ((mask & (1u << l)) == 0u) {
                continue;
            }
            v = plan_cost_add(
                plan_cost_add(s[plan_pair_index(i, j, m)], s[plan_pair_index(i, l, m)]),
                plan_cost_add(s[plan_pair_index(j, l, m)],
                              matching_brute(s, m, mask & ~(1u << i) & ~(1u << j) & ~(1u << l))));
            best = plan_cost_compare(v, best) > 0 ? v : best;
        }
    }
    return best;
}

/* The heuristic's matching for 2..6 members, every mask, random surcharges (zeros, small
 * ties and values near 2^64 so that the 128-bit carries matter) against brute force. */
START_TEST(matching_exact)
{
    uint64_t rng = 0x6d617463u;
    size_t trial;
    for (trial = 0; trial < 3000u; ++trial) {
        const size_t m = 2u + (size_t)(trial % 5u);
        coa_cost_t sur[PLAN_PAIRS];
        uint32_t mask;
        size_t p;
        for (p = 0; p < m * (m - 1u) / 2u; ++p) {
            uint64_t r = splitmix(&rng);
            sur[p].hi = (r & 3u) == 0u ? (r >> 40) : 0u;
            sur[p].lo = (r & 12u) == 0u ? 0u : ((r & 16u) != 0u ? r : (r >> 58));
        }
        for (mask = 0u; mask < (1u << m); ++mask) {
            coa_cost_t got = coa_plan_test_matching(sur, m, mask);
            coa_cost_t want = matching_brute(sur, m, mask);
            ck_assert_msg(plan_cost_compare(got, want) == 0,
                          "m %zu mask %x: got %llx:%llx, want %llx:%llx", m, (unsigned)mask,
                          (unsigned long long)got.hi, (unsigned long long)got.lo,
                          (unsigned long long)want.hi, (unsigned long long)want.lo);
        }
    }
}
END_TEST

/* The planner's step area (plan_area, the library's formula without its divisions where
 * a step does not cross the reference) against coa_area_scaled, on every step of every
 * steep factor near the reference, where the crossing cases are, and at the offset
 * bound. */
START_TEST(area_exact)
{
    uint32_t s;
    for (s = 1u; s <= COA_MAX_STEEP_FACTOR; ++s) {
        int32_t a;
        for (a = -40; a <= 40; ++a) {
            int32_t d;
            for (d = -(int32_t)s; d <= (int32_t)s; ++d) {
                int32_t far = a < 0 ? -COA_MAX_OFFSET - a : COA_MAX_OFFSET - a;
                ck_assert_uint_eq(plan_area(a, a + d, s),
                                  (uint64_t)coa_area_scaled(a, a + d, 2u * s));
                if (far + d >= -COA_MAX_OFFSET && far + d <= COA_MAX_OFFSET) {
                    ck_assert_uint_eq(plan_area(far, far + d, s),
                                      (uint64_t)coa_area_scaled(far, far + d, 2u * s));
                }
            }
        }
    }
}
END_TEST

static Suite *suite(void)
{
    Suite *s = suite_create("heuristic");
    TCase *tc = tcase_create("brute force");
    /* Seconds each: Check's default of 4 is for unit tests, not brute force on a loaded
     * 2-core machine under the sanitizers. */
    tcase_set_timeout(tc, 300);
    tcase_add_test(tc, table_exact);
    tcase_add_test(tc, joint_two);
    tcase_add_test(tc, joint_three);
    tcase_add_test(tc, matching_exact);
    tcase_add_test(tc, area_exact);
    suite_add_tcase(s, tc);
    return s;
}

int main(void)
{
    SRunner *sr = srunner_create(suite());
    int failed;
    srunner_run_all(sr, CK_NORMAL);
    failed = srunner_ntests_failed(sr);
    srunner_free(sr);
    return failed == 0 ? EXIT_SUCCESS : EXIT_FAILURE;
}
