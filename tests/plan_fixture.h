/* SPDX-License-Identifier: MIT */
/*
 * plan_fixture.h: a planner problem held in fixed arrays, and the calls that fill it, for
 * the suites that build problems (test_plan, test_plan_oracle, test_heuristic). Included,
 * not a suite of its own (the tests' glob only picks up test_*.c), so everything here is
 * static inline: a suite that leaves a helper unused does not trip -Werror.
 *
 * Use: fx_init, then fx_vehicle / fx_box / fx_track (or fill the arrays directly: a
 * polytope in obs and poly, a track's path in trpath), adjust the vehicles, and fx_finish
 * samples the references and tracks and checks the problem. A suite may call fx_finish
 * again after adding to or changing a finished problem.
 */
#ifndef COAVOID_PLAN_FIXTURE_H
#define COAVOID_PLAN_FIXTURE_H

#include <check.h>
#include <stdint.h>
#include <string.h>

#include "coavoid/coavoid.h"

/* Capacities. A suite may define any of them before including this header, so that
 * fx_vehicle's check holds the suite's problems to the suite's own limit (and its arrays
 * sized from MAXV and MAXN fit every problem). The defaults are the largest any suite
 * needs, test_plan's. Every fx_t of the suites is static, so its size (about 10 kB at
 * these defaults, in double precision) never lands on a sanitized stack. */
#ifndef FX_MAXV
#define FX_MAXV 10u /* vehicles */
#endif
#ifndef FX_MAXN
#define FX_MAXN 24u /* horizon: references and track samples hold FX_MAXN + 1 rows */
#endif
#ifndef FX_MAXPTS
#define FX_MAXPTS 4u /* route points of a vehicle */
#endif
#ifndef FX_MAXOBS
#define FX_MAXOBS 4u /* obstacles */
#endif
#ifndef FX_MAXTR
#define FX_MAXTR 2u /* tracks */
#endif
#ifndef FX_MAXTRPTS
#define FX_MAXTRPTS 3u /* path points of a track */
#endif
#define FX_POLYV 8u /* vertices of a polytope obstacle */

/* Samples in one row of a plan (offsets at k = 0..N). */
#define ROW(f) ((size_t)(f)->p.horizon + 1u)

static inline coa_real_t R(double x)
{
    return (coa_real_t)x;
}

static inline coa_vec3_t V(double x, double y, double z)
{
    coa_vec3_t v;
    v.x = R(x);
    v.y = R(y);
    v.z = R(z);
    return v;
}

typedef struct {
    coa_vehicle_t veh[FX_MAXV];
    coa_vec3_t route[FX_MAXV][FX_MAXPTS];
    coa_vec3_t ref[FX_MAXV][FX_MAXN + 1u];
    const coa_vec3_t *refp[FX_MAXV];
    coa_obstacle_t obs[FX_MAXOBS];
    coa_vec3_t poly[FX_MAXOBS][FX_POLYV];
    coa_track_t tr[FX_MAXTR];
    coa_track_point_t trpath[FX_MAXTR][FX_MAXTRPTS];
    coa_vec3_t trs[FX_MAXTR][FX_MAXN + 1u];
    const coa_vec3_t *trp[FX_MAXTR];
    coa_problem_t p;
} fx_t;

/* An empty problem: no vehicles, obstacles or tracks yet. */
static inline void fx_init(fx_t *f, double dt, uint32_t horizon)
{
    memset(f, 0, sizeof *f);
    f->p.dt = R(dt);
    f->p.horizon = horizon;
    f->p.vehicles = f->veh;
    f->p.references = f->refp;
    f->p.obstacles = f->obs;
    f->p.tracks = f->tr;
    f->p.track_samples = f->trp;
}

/* A vehicle on the straight route start -> end, level at offset 0 and unbounded; the
 * caller may lengthen the route (route[i], route_count) or set the offsets after. */
static inline coa_vehicle_t *fx_vehicle(fx_t *f, uint16_t id, uint32_t priority, double speed,
                                        double climb, uint32_t steep, double radius, double half,
                                        coa_vec3_t start, coa_vec3_t end)
{
    size_t i = f->p.vehicle_count++;
    coa_vehicle_t *v = &f->veh[i];
    ck_assert_uint_lt(i, FX_MAXV);
    f->route[i][0] = start;
    f->route[i][1] = end;
    v->id = id;
    v->priority = priority;
    v->cruise_speed = R(speed);
    v->climb_rate = R(climb);
    v->steep_factor = steep;
    v->volume.radius = R(radius);
    v->volume.half_height = R(half);
    v->route = f->route[i];
    v->route_count = 2u;
    v->initial_offset = 0;
    v->max_offset = -1;
    return v;
}

static inline void fx_box(fx_t *f, coa_vec3_t min, coa_vec3_t max)
{
    coa_obstacle_t *o = &f->obs[f->p.obstacle_count++];
    o->kind = COA_OBSTACLE_BOX;
    o->box.min = min;
    o->box.max = max;
}

/* A track at constant velocity, numbered 101, 102, ... in the order added; returned so
 * that a suite can give it its own id or a path. */
static inline coa_track_t *fx_track(fx_t *f, coa_vec3_t pos, coa_vec3_t vel, double radius,
                                    double half)
{
    coa_track_t *t = &f->tr[f->p.track_count++];
    t->id = (uint32_t)(100u + f->p.track_count);
    t->volume.radius = R(radius);
    t->volume.half_height = R(half);
    t->position = pos;
    t->velocity = vel;
    return t;
}

/* Samples every reference and track over the horizon and checks the problem. */
static inline void fx_finish(fx_t *f)
{
    size_t i;
    for (i = 0; i < f->p.vehicle_count; ++i) {
        ck_assert_int_eq(coa_reference_sample(&f->veh[i], f->p.dt, f->p.horizon, f->ref[i]),
                         COA_OK);
        f->refp[i] = f->ref[i];
    }
    for (i = 0; i < f->p.track_count; ++i) {
        ck_assert_int_eq(coa_track_sample(&f->tr[i], f->p.dt, f->p.horizon, f->trs[i]), COA_OK);
        f->trp[i] = f->trs[i];
    }
    ck_assert_int_eq(coa_problem_check(&f->p), COA_OK);
}

/* Whether one step's sweep s (over samples k -> k + 1) is clear of the problem's obstacles
 * and tracks, by the public conflict tests: the suites' own oracles use it instead of the
 * planner's tables. The polytope test may only answer clear or conflict here. */
static inline bool fx_static_clear(const fx_t *f, const coa_sweep_t *s, uint32_t k)
{
    size_t j;
    for (j = 0; j < f->p.obstacle_count; ++j) {
        int rc = coa_conflict_obstacle(s, &f->obs[j]);
        ck_assert_msg(rc == 0 || rc == 1, "coa_conflict_obstacle returned %d", rc);
        if (rc != 0) {
            return false;
        }
    }
    for (j = 0; j < f->p.track_count; ++j) {
        coa_sweep_t t;
        t.volume = f->tr[j].volume;
        t.p0 = f->trs[j][k];
        t.p1 = f->trs[j][k + 1u];
        if (coa_conflict_volumes(s, &t)) {
            return false;
        }
    }
    return true;
}

#endif /* COAVOID_PLAN_FIXTURE_H */
