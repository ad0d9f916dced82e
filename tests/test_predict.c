/* SPDX-License-Identifier: MIT */
/*
 * test_predict.c: collision prediction (predict.h) against independent references.
 *
 *   - Deterministic conflicts against the planner's own check (coa_plan_find_conflict on
 *     a problem whose references are the plans' samples), pair by pair, on random fleets.
 *   - The broad phase against all_pairs on random fleets of hundreds of UAVs, bit for bit,
 *     with the work it saves measured.
 *   - coa_conflict_probability against Monte Carlo sampling of the Gaussian model, the
 *     closed form at d = 0, and the deterministic answer at sigma 0.
 *   - Alignment of plans with their own start times and steps, by probes whose least
 *     separation and first conflict are known in closed form.
 *   - Separations against dense sampling; sigma growth; capacity overflow and the pair
 *     set's limit; clusters against a breadth-first search; the workspace and argument
 *     contracts.
 */
#include <check.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "coavoid/coavoid.h"
#include "coavoid/predict.h"
#include "test_support.h"

/* Strict C11 has no PI. */
#define PI 3.14159265358979323846
#define SQRT2 1.41421356237309504880

/* Tolerances for rounding: float coordinates of a few hundred metres carry about 1e-5 m
 * of it, and float inputs move P by about 1e-7. */
#ifdef COA_SINGLE_PRECISION
#define POS_TOL 2e-3  /* m, a resampled position */
#define TIME_TOL 1e-4 /* s */
#define FINE_TOL 1e-3 /* m, a separation */
#define PROB_TOL 1e-6 /* P against mpmath, inputs rounded to float */
#define PROB_REL 1.0
#else
#define POS_TOL 1e-9
#define TIME_TOL 1e-9
#define FINE_TOL 1e-6
#define PROB_TOL 1e-13
#define PROB_REL 1e-9
#endif

/* Two independent standard normals (Box-Muller; u1 in (0, 1] so the log is finite). */
static void normal_pair(uint64_t *s, double *z1, double *z2)
{
    double u1 = ((double)(splitmix(s) >> 11) + 1.0) / 9007199254740992.0;
    double u2 = (double)(splitmix(s) >> 11) / 9007199254740992.0;
    double r = sqrt(-2.0 * log(u1));
    *z1 = r * cos(2.0 * PI * u2);
    *z2 = r * sin(2.0 * PI * u2);
}

static coa_real_t R(double x)
{
    return (coa_real_t)x;
}

static coa_vec3_t V(double x, double y, double z)
{
    coa_vec3_t v;
    v.x = R(x);
    v.y = R(y);
    v.z = R(z);
    return v;
}

/* ------------------------------------------------------------------------------------ */
/* Fleets                                                                                */

#define MAXP 600u
#define MAXS 132u
#define MAXT 16u
#define MAXO 12u
#define MAXC 20000u

typedef struct {
    coa_predict_config_t cfg;
    coa_intent_plan_t plans[MAXP];
    coa_vec3_t samples[MAXP][MAXS];
    coa_track_t tracks[MAXT];
    coa_track_point_t paths[MAXT][3];
    coa_obstacle_t obstacles[MAXO];
    coa_vec3_t hulls[MAXO][8];
    size_t n;
    size_t m;
    size_t o;
} fleet_t;

static fleet_t *fleet_new(void)
{
    fleet_t *f = calloc(1u, sizeof *f);
    ck_assert_ptr_nonnull(f);
    return f;
}

static void config_default(coa_predict_config_t *c, uint32_t horizon, double dt)
{
    memset(c, 0, sizeof *c);
    c->t0 = R(0.0);
    c->dt = R(dt);
    c->horizon = horizon;
    c->threshold = 0.01;
}

static void random_box(uint64_t *s, coa_box_t *b, double side, double zlo, double zhi)
{
    double x = unif(s, -side, side);
    double y = unif(s, -side, side);
    double w = unif(s, 20.0, 80.0);
    double d = unif(s, 20.0, 80.0);
    double z0 = unif(s, zlo, zhi);
    double z1 = z0 + unif(s, 5.0, 60.0);
    b->min = V(x, y, z0);
    b->max = V(x + w, y + d, z1);
}

/* A convex hull of eight jittered corners of a random box. */
static void random_hull(uint64_t *s, coa_vec3_t *h, double side, double zlo, double zhi)
{
    coa_box_t b;
    size_t i;
    random_box(s, &b, side, zlo, zhi);
    for (i = 0; i < 8u; ++i) {
        double x = (i & 1u) ? (double)b.max.x : (double)b.min.x;
        double y = (i & 2u) ? (double)b.max.y : (double)b.min.y;
        double z = (i & 4u) ? (double)b.max.z : (double)b.min.z;
        h[i] = V(x + unif(s, -8.0, 8.0), y + unif(s, -8.0, 8.0), z + unif(s, -4.0, 4.0));
    }
}

static void add_obstacles(fleet_t *f, uint64_t *s, size_t boxes, size_t hulls, double side,
                          double zlo, double zhi)
{
    size_t i;
    for (i = 0; i < boxes + hulls; ++i) {
        coa_obstacle_t *o = &f->obstacles[f->o];
        memset(o, 0, sizeof *o);
        if (i < boxes) {
            o->kind = COA_OBSTACLE_BOX;
            random_box(s, &o->box, side, zlo, zhi);
        } else {
            o->kind = COA_OBSTACLE_POLYTOPE;
            random_hull(s, f->hulls[f->o], side, zlo, zhi);
            o->polytope.vertices = f->hulls[f->o];
            o->polytope.count = 8u;
        }
        f->o += 1u;
    }
}

/* A track: constant velocity, or a three-point path over the horizon. */
static void add_track(fleet_t *f, uint64_t *s, double side, double zlo, double zhi, double speed_lo,
                      double speed_hi, bool with_sigma)
{
    coa_track_t *t = &f->tracks[f->m];
    double heading = unif(s, 0.0, 2.0 * PI);
    double speed = unif(s, speed_lo, speed_hi);
    double span = (double)f->cfg.horizon * (double)f->cfg.dt;

    memset(t, 0, sizeof *t);
    t->id = (uint32_t)(100u + f->m);
    t->volume.radius = R(unif(s, 10.0, 30.0));
    t->volume.half_height = R(unif(s, 5.0, 10.0));
    t->position = V(unif(s, -side, side), unif(s, -side, side), unif(s, zlo, zhi));
    t->velocity = V(speed * cos(heading), speed * sin(heading), unif(s, -1.0, 1.0));
    if (pick(s, 2u) == 0u) {
        size_t j;
        coa_vec3_t p = t->position;
        for (j = 0; j < 3u; ++j) {
            double h = heading + unif(s, -0.8, 0.8);
            f->paths[f->m][j].t = R((double)f->cfg.t0 + span * ((double)j * 0.45 - 0.1));
            f->paths[f->m][j].p = p;
            p = V((double)p.x + 0.45 * span * speed * cos(h),
                  (double)p.y + 0.45 * span * speed * sin(h), (double)p.z + unif(s, -10.0, 10.0));
        }
        t->path = f->paths[f->m];
        t->path_count = 3u;
    }
    if (with_sigma) {
        t->sigma_horizontal = R(unif(s, 5.0, 25.0));
        t->sigma_vertical = R(unif(s, 2.0, 8.0));
    }
    f->m += 1u;
}

/* Small, dense and aligned with the predictor's grid (t0 = config t0, step = dt, N + 1
 * samples), UAVs that wander step by step: the planner's check sees the same samples. */
static void small_fleet(fleet_t *f, uint64_t *s, uint32_t horizon)
{
    size_t i;
    size_t k;
    size_t tracks = pick(s, 3u);

    memset(f, 0, sizeof *f);
    config_default(&f->cfg, horizon, 1.0);
    f->n = 3u + pick(s, 6u);
    for (i = 0; i < f->n; ++i) {
        coa_intent_plan_t *p = &f->plans[i];
        double heading = unif(s, 0.0, 2.0 * PI);
        double speed = unif(s, 3.0, 15.0);
        coa_vec3_t q = V(unif(s, -150.0, 150.0), unif(s, -150.0, 150.0), unif(s, 85.0, 115.0));
        p->id = (uint16_t)(i + 1u);
        p->volume.radius = R(unif(s, 8.0, 20.0));
        p->volume.half_height = R(unif(s, 4.0, 10.0));
        p->t0 = f->cfg.t0;
        p->step = f->cfg.dt;
        p->count = (size_t)horizon + 1u;
        p->samples = f->samples[i];
        for (k = 0; k <= horizon; ++k) {
            f->samples[i][k] = q;
            heading += unif(s, -0.4, 0.4);
            q = V((double)q.x + speed * cos(heading), (double)q.y + speed * sin(heading),
                  (double)q.z + unif(s, -2.0, 2.0));
        }
    }
    for (i = 0; i < tracks; ++i) {
        add_track(f, s, 200.0, 85.0, 115.0, 5.0, 20.0, false);
    }
    add_obstacles(f, s, pick(s, 3u), pick(s, 2u), 150.0, 70.0, 120.0);
}

/* A city-like airspace: UAVs on four layers (60, 90, 120, 150 m), one turn each, one in
 * five climbing or descending to the next layer after it; plans published unaligned
 * (t0 in (-step, 0], step 0.5, 1 or 2 s), some ending early or a single sample; tracks
 * with sigma; buildings and hills. */
static void city_fleet(fleet_t *f, uint64_t seed, size_t n, double side, bool uav_sigma,
                       uint32_t horizon, double dt, double clock)
{
    static const double layers[4] = {60.0, 90.0, 120.0, 150.0};
    static const double steps[3] = {0.5, 1.0, 2.0};
    uint64_t s = seed;
    double span = (double)horizon * dt;
    size_t i;
    size_t j;

    memset(f, 0, sizeof *f);
    config_default(&f->cfg, horizon, dt);
    f->cfg.t0 = R(clock);
    f->n = n;
    for (i = 0; i < n; ++i) {
        coa_intent_plan_t *p = &f->plans[i];
        double step = steps[pick(&s, 3u)];
        double t0 = -unif(&s, 0.0, step);
        double h1 = unif(&s, 0.0, 2.0 * PI);
        double h2 = h1 + unif(&s, -PI / 2.0, PI / 2.0);
        double speed = unif(&s, 8.0, 20.0);
        double turn = unif(&s, 0.0, span);
        uint32_t layer = pick(&s, 4u);
        double z0 = layers[layer];
        double z1 = z0;
        double x0 = unif(&s, -side / 2.0, side / 2.0);
        double y0 = unif(&s, -side / 2.0, side / 2.0);
        size_t count = (size_t)ceil((span - t0) / step) + 1u;
        uint32_t shape = pick(&s, 20u);

        if (pick(&s, 5u) == 0u) {
            z1 = layer == 0u
                     ? layers[1]
                     : (layer == 3u ? layers[2] : layers[layer + (pick(&s, 2u) ? 1u : -1u)]);
        }
        if (shape == 0u) {
            count = 1u; /* hovering */
        } else if (shape < 3u) {
            count = count / 2u + 1u; /* ends early: extrapolated */
        }
        REQUIRE(count <= MAXS);
        p->id = (uint16_t)(i + 1u);
        p->volume.radius = R(25.0);
        p->volume.half_height = R(7.5);
        p->t0 = R(clock + t0);
        p->step = R(step);
        p->count = count;
        p->samples = f->samples[i];
        if (uav_sigma) {
            p->sigma_horizontal = R(unif(&s, 1.0, 5.0));
            p->sigma_vertical = R(unif(&s, 0.5, 2.0));
        }
        for (j = 0; j < count; ++j) {
            double t = t0 + (double)j * step;
            double a = t < turn ? t : turn;
            double b = t < turn ? 0.0 : t - turn;
            double climb = 2.0 * b;
            double z = z1 >= z0 ? fmin(z1, z0 + climb) : fmax(z1, z0 - climb);
            f->samples[i][j] = V(x0 + speed * (a * cos(h1) + b * cos(h2)),
                                 y0 + speed * (a * sin(h1) + b * sin(h2)), z);
        }
    }
    for (i = 0; i < n / 50u + 2u && i < MAXT; ++i) {
        add_track(f, &s, side / 2.0, 50.0, 200.0, 20.0, 50.0, true);
    }
    add_obstacles(f, &s, 6u, 3u, side / 2.0, 0.0, 100.0);
    if (uav_sigma) {
        f->cfg.vehicle_sigma_rate_horizontal = R(0.1);
        f->cfg.vehicle_sigma_rate_vertical = R(0.05);
    }
    f->cfg.track_sigma_rate_horizontal = R(0.5);
    f->cfg.track_sigma_rate_vertical = R(0.1);
}

/* ------------------------------------------------------------------------------------ */
/* Running the predictor                                                                 */

typedef struct {
    void *mem;
    size_t bytes;
    coa_predictor_t *pr;
} ws_t;

static void ws_make(ws_t *w, size_t vehicles, size_t tracks, uint32_t horizon, size_t pairs)
{
    w->bytes = coa_predictor_workspace_size(vehicles, tracks, horizon, pairs);
    ck_assert_uint_gt(w->bytes, 0u);
    w->mem = malloc(w->bytes);
    ck_assert_ptr_nonnull(w->mem);
    w->pr = coa_predictor_init(w->mem, w->bytes, vehicles, tracks, horizon, pairs);
    ck_assert_ptr_nonnull(w->pr);
}

static void ws_free(ws_t *w)
{
    free(w->mem);
    w->mem = NULL;
    w->pr = NULL;
}

static int run(ws_t *w, const fleet_t *f, bool all_pairs, coa_conflict_t *out, size_t cap,
               coa_predict_result_t *res)
{
    coa_predict_config_t c = f->cfg;
    c.all_pairs = all_pairs;
    return coa_predict(w->pr, &c, f->plans, f->n, f->obstacles, f->o, f->tracks, f->m, out, cap,
                       res);
}

static bool same_real(coa_real_t a, coa_real_t b)
{
    return memcmp(&a, &b, sizeof a) == 0;
}

static bool same_conflict(const coa_conflict_t *x, const coa_conflict_t *y)
{
    return x->kind == y->kind && x->a == y->a && x->b == y->b && x->first_step == y->first_step &&
           same_real(x->first_time, y->first_time) &&
           same_real(x->min_horizontal, y->min_horizontal) &&
           same_real(x->min_vertical, y->min_vertical) &&
           memcmp(&x->probability, &y->probability, sizeof x->probability) == 0;
}

/* ------------------------------------------------------------------------------------ */
/* The planner's check as the reference                                                  */

static const coa_vec3_t dummy_route[2] = {{0, 0, 0}, {100, 0, 0}};

static void dummy_vehicle(coa_vehicle_t *v, uint16_t id, coa_volume_t volume)
{
    memset(v, 0, sizeof *v);
    v->id = id;
    v->priority = 1u;
    v->cruise_speed = R(10.0);
    v->climb_rate = R(1.0);
    v->steep_factor = 2u;
    v->volume = volume;
    v->route = dummy_route;
    v->route_count = 2u;
    v->max_offset = -1;
}

/* The planner's verdict on one pair: -1 no conflict, else the first conflicting step. */
static long planner_first_step(const fleet_t *f, uint32_t kind, size_t a, size_t b,
                               coa_vec3_t *track_buf)
{
    static int32_t zeros[2u * (MAXS + 1u)];
    coa_vehicle_t veh[2];
    const coa_vec3_t *refs[2];
    const coa_vec3_t *trs[1];
    coa_problem_t p;
    size_t vehicle = 0u;
    uint32_t step = 0u;
    static const size_t which[2] = {0u, 1u};
    int rc;

    memset(&p, 0, sizeof p);
    p.dt = f->cfg.dt;
    p.horizon = f->cfg.horizon;
    p.vehicles = veh;
    p.references = refs;
    dummy_vehicle(&veh[0], 1u, f->plans[a].volume);
    refs[0] = f->plans[a].samples;
    p.vehicle_count = 1u;
    if (kind == 0u) {
        dummy_vehicle(&veh[1], 2u, f->plans[b].volume);
        refs[1] = f->plans[b].samples;
        p.vehicle_count = 2u;
    } else if (kind == 1u) {
        REQUIRE(coa_track_sample(&f->tracks[b], f->cfg.dt, f->cfg.horizon, track_buf) == COA_OK);
        trs[0] = track_buf;
        p.tracks = &f->tracks[b];
        p.track_count = 1u;
        p.track_samples = trs;
    } else {
        p.obstacles = &f->obstacles[b];
        p.obstacle_count = 1u;
    }
    rc = coa_plan_find_conflict(&p, zeros, which, p.vehicle_count, &vehicle, &step);
    REQUIRE(rc == 0 || rc == 1);
    return rc == 1 ? (long)step : -1;
}

START_TEST(deterministic_conflicts_equal_the_planners_check)
{
    fleet_t *f = fleet_new();
    static coa_conflict_t got[2][MAXC];
    static coa_vec3_t track_buf[MAXS + 1u];
    coa_predict_result_t res[2];
    ws_t w;
    uint64_t s = 20240611u;
    size_t seed;
    size_t total = 0u;
    size_t by_kind[3] = {0u, 0u, 0u};

    ws_make(&w, 8u, 2u, 16u, 256u);
    for (seed = 0; seed < 600u; ++seed) {
        size_t mode;
        size_t idx = 0u;
        size_t a;
        size_t b;
        uint32_t kind;

        small_fleet(f, &s, 16u);
        for (mode = 0; mode < 2u; ++mode) {
            REQUIRE(run(&w, f, mode == 1u, got[mode], MAXC, &res[mode]) == COA_OK);
            REQUIRE(!res[mode].overflow);
        }
        /* Every pair, in the output order, against the planner. */
        for (kind = 0; kind < 3u; ++kind) {
            size_t others = kind == 0u ? f->n : (kind == 1u ? f->m : f->o);
            for (a = 0; a < f->n; ++a) {
                for (b = kind == 0u ? a + 1u : 0u; b < others; ++b) {
                    long step = planner_first_step(f, kind, a, b, track_buf);
                    if (step < 0) {
                        continue;
                    }
                    REQUIRE(idx < res[0].conflict_count);
                    REQUIRE(got[0][idx].kind == (coa_conflict_kind_t)kind);
                    REQUIRE(got[0][idx].a == a && got[0][idx].b == b);
                    REQUIRE((long)got[0][idx].first_step == step);
                    REQUIRE(got[0][idx].probability == 1.0);
                    REQUIRE(got[0][idx].first_time == R((double)step));
                    by_kind[kind] += 1u;
                    ++idx;
                }
            }
        }
        REQUIRE(idx == res[0].conflict_count);
        REQUIRE(res[1].conflict_count == res[0].conflict_count);
        for (a = 0; a < idx; ++a) {
            REQUIRE(same_conflict(&got[0][a], &got[1][a]));
        }
        total += idx;
    }
    /* The fleets are dense enough for every kind to conflict often. */
    printf("planner check: %zu conflicts (%zu vehicle, %zu track, %zu obstacle) over 600 fleets\n",
           total, by_kind[0], by_kind[1], by_kind[2]);
    ck_assert_uint_gt(by_kind[0], 400u);
    ck_assert_uint_gt(by_kind[1], 100u);
    ck_assert_uint_gt(by_kind[2], 100u);
    ws_free(&w);
    free(f);
}
END_TEST

/* The least separations reported are the minima of the piecewise-linear motion: never
 * above a dense sampling of it, and within a hair of it. */
START_TEST(separations_are_the_exact_minima)
{
    fleet_t *f = fleet_new();
    static coa_conflict_t got[MAXC];
    coa_predict_result_t res;
    ws_t w;
    uint64_t s = 77u;
    size_t seed;
    size_t checked_box = 0u;

    ws_make(&w, 8u, 2u, 16u, 256u);
    for (seed = 0; seed < 100u; ++seed) {
        size_t i;
        small_fleet(f, &s, 16u);
        REQUIRE(run(&w, f, false, got, MAXC, &res) == COA_OK);
        for (i = 0; i < res.conflict_count; ++i) {
            const coa_conflict_t *c = &got[i];
            const coa_vec3_t *pa = f->plans[c->a].samples;
            static coa_vec3_t pb[MAXS + 1u];
            const coa_box_t *box = NULL;
            double best_h = INFINITY;
            double best_v = INFINITY;
            uint32_t k;
            int j;

            if (c->kind == COA_CONFLICT_VEHICLE) {
                memcpy(pb, f->plans[c->b].samples, sizeof(coa_vec3_t) * (f->cfg.horizon + 1u));
            } else if (c->kind == COA_CONFLICT_TRACK) {
                REQUIRE(coa_track_sample(&f->tracks[c->b], f->cfg.dt, f->cfg.horizon, pb) ==
                        COA_OK);
            } else if (f->obstacles[c->b].kind == COA_OBSTACLE_BOX) {
                box = &f->obstacles[c->b].box;
                ++checked_box;
            } else {
                REQUIRE(c->min_horizontal == R(0.0) && c->min_vertical == R(0.0));
                continue;
            }
            for (k = 0; k < f->cfg.horizon; ++k) {
                for (j = 0; j <= 2000; ++j) {
                    double u = (double)j / 2000.0;
                    double x = (double)pa[k].x + u * ((double)pa[k + 1u].x - (double)pa[k].x);
                    double y = (double)pa[k].y + u * ((double)pa[k + 1u].y - (double)pa[k].y);
                    double z = (double)pa[k].z + u * ((double)pa[k + 1u].z - (double)pa[k].z);
                    double dx;
                    double dy;
                    double dz;
                    if (box == NULL) {
                        dx = x - ((double)pb[k].x + u * ((double)pb[k + 1u].x - (double)pb[k].x));
                        dy = y - ((double)pb[k].y + u * ((double)pb[k + 1u].y - (double)pb[k].y));
                        dz = fabs(z -
                                  ((double)pb[k].z + u * ((double)pb[k + 1u].z - (double)pb[k].z)));
                    } else {
                        dx = fmax(0.0, fmax((double)box->min.x - x, x - (double)box->max.x));
                        dy = fmax(0.0, fmax((double)box->min.y - y, y - (double)box->max.y));
                        dz = fmax(0.0, fmax((double)box->min.z - z, z - (double)box->max.z));
                    }
                    best_h = fmin(best_h, sqrt(dx * dx + dy * dy));
                    best_v = fmin(best_v, dz);
                }
            }
            /* Sampling every 1/2000 of a step of at most ~30 m of relative motion misses
             * the minimum by less than 2 cm (less where it is smooth). */
            REQUIRE((double)c->min_horizontal <= best_h + FINE_TOL);
            REQUIRE((double)c->min_horizontal >= best_h - 0.02);
            REQUIRE((double)c->min_vertical <= best_v + FINE_TOL);
            REQUIRE((double)c->min_vertical >= best_v - 0.02);
        }
    }
    ck_assert_uint_gt(checked_box, 20u);
    ws_free(&w);
    free(f);
}
END_TEST

/* ------------------------------------------------------------------------------------ */
/* Broad phase                                                                           */

START_TEST(broad_phase_finds_exactly_what_all_pairs_finds)
{
    /* Fleets of hundreds at a few densities; UAVs with and without sigma; clocks not at
     * 0; steps of 1, 0.5 and 2 s; thresholds from 1e-9 (almost nothing pruned) to 0.5. */
    static const struct {
        uint64_t seed;
        size_t n;
        double side;
        bool uav_sigma;
        uint32_t horizon;
        double dt;
        double clock;
        double threshold;
    } cases[] = {
        {1u, 300u, 2500.0, false, 30u, 1.0, 0.0, 0.01},
        {2u, 450u, 3000.0, true, 30u, 1.0, 0.0, 0.01},
        {3u, 600u, 3500.0, false, 30u, 1.0, 0.0, 0.01},
        {4u, 600u, 3000.0, true, 30u, 1.0, 0.0, 0.01},
        {5u, 500u, 3000.0, false, 60u, 0.5, 1000.0, 1e-9},
        {6u, 400u, 2500.0, true, 20u, 2.0, -37.25, 0.5},
        {7u, 600u, 4000.0, true, 60u, 1.0, 12345.5, 1e-4},
        {8u, 350u, 2000.0, false, 30u, 1.0, 3.0, 1.0},
    };
    fleet_t *f = fleet_new();
    static coa_conflict_t got[2][MAXC];
    coa_predict_result_t res[2];
    size_t ci;

    for (ci = 0; ci < sizeof cases / sizeof cases[0]; ++ci) {
        ws_t w;
        size_t i;
        uint64_t all;
        size_t kinds[3] = {0u, 0u, 0u};
        size_t uncertain = 0u;

        city_fleet(f, cases[ci].seed, cases[ci].n, cases[ci].side, cases[ci].uav_sigma,
                   cases[ci].horizon, cases[ci].dt, cases[ci].clock);
        f->cfg.threshold = cases[ci].threshold;
        ws_make(&w, f->n, f->m, cases[ci].horizon, 20000u);
        ck_assert_int_eq(run(&w, f, false, got[0], MAXC, &res[0]), COA_OK);
        ck_assert_int_eq(run(&w, f, true, got[1], MAXC, &res[1]), COA_OK);
        ck_assert(!res[0].overflow && !res[1].overflow);
        ck_assert_uint_eq(res[0].conflicts_found, res[1].conflicts_found);
        ck_assert_uint_eq(res[0].conflict_count, res[1].conflict_count);
        for (i = 0; i < res[0].conflict_count; ++i) {
            REQUIRE(same_conflict(&got[0][i], &got[1][i]));
            kinds[got[0][i].kind] += 1u;
            uncertain += got[0][i].probability < 1.0 ? 1u : 0u;
        }
        all = (uint64_t)f->n * (f->n - 1u) / 2u;
        ck_assert_uint_eq(res[1].pair_tests, all + (uint64_t)f->n * (f->m + f->o));
        ck_assert_uint_eq(res[1].candidate_pairs, 0u);
        ck_assert_uint_eq(res[0].pair_tests, res[0].candidate_pairs);
        printf("broad phase: %zu UAVs, %zu tracks, %zu obstacles%s, N %u: %zu conflicts (%zu "
               "vehicle, %zu track, %zu obstacle; %zu with P < 1), %llu pair tests against %llu "
               "all-pairs (n(n-1)/2 = %llu)\n",
               f->n, f->m, f->o, cases[ci].uav_sigma ? ", UAV sigma" : "", cases[ci].horizon,
               res[0].conflict_count, kinds[0], kinds[1], kinds[2], uncertain,
               (unsigned long long)res[0].pair_tests, (unsigned long long)res[1].pair_tests,
               (unsigned long long)all);
        /* Something to compare, and sparse traffic costs a small fraction of all pairs. */
        ck_assert_uint_gt(kinds[0], 5u);
        ck_assert_uint_gt(kinds[1] + kinds[2], 2u);
        ck_assert_uint_lt(res[0].pair_tests * 20u, all);
        ws_free(&w);
    }
    free(f);
}
END_TEST

START_TEST(broad_phase_grid_handles_degenerate_scenes)
{
    /* The grid's shape comes from the boxes of each step: check it against all-pairs on
     * scenes that bend it: everyone on one line (one row of cells), one UAV far away (a
     * huge, sparse bounding square), a crowd in a small square (cells that hold many),
     * and large track sigmas (boxes wider than several cells). */
    fleet_t *f = fleet_new();
    static coa_conflict_t got[2][MAXC];
    coa_predict_result_t res[2];
    int variant;

    for (variant = 0; variant < 4; ++variant) {
        ws_t w;
        size_t i;
        size_t j;
        city_fleet(f, 40u + (uint64_t)variant, variant == 2 ? 150u : 300u,
                   variant == 2 ? 300.0 : 2500.0, true, 30u, 1.0, 0.0);
        for (i = 0; i < f->n; ++i) {
            for (j = 0; j < f->plans[i].count; ++j) {
                coa_vec3_t *q = &f->samples[i][j];
                if (variant == 0) {
                    q->y = R(0.25 * (double)q->y * 1e-3);
                } else if (variant == 1 && i == 7u) {
                    q->x = R((double)q->x + 4.0e6);
                    q->y = R((double)q->y - 3.0e6);
                }
            }
        }
        if (variant == 3) {
            f->cfg.track_sigma_rate_horizontal = R(20.0);
        }
        ws_make(&w, f->n, f->m, 30u, 40000u);
        ck_assert_int_eq(run(&w, f, false, got[0], MAXC, &res[0]), COA_OK);
        ck_assert_int_eq(run(&w, f, true, got[1], MAXC, &res[1]), COA_OK);
        ck_assert(!res[0].overflow && !res[1].overflow);
        ck_assert_uint_eq(res[0].conflicts_found, res[1].conflicts_found);
        ck_assert_uint_eq(res[0].conflict_count, res[1].conflict_count);
        ck_assert_uint_gt(res[0].conflict_count, 0u);
        for (i = 0; i < res[0].conflict_count; ++i) {
            REQUIRE(same_conflict(&got[0][i], &got[1][i]));
        }
        ws_free(&w);
    }
    free(f);
}
END_TEST

/* ------------------------------------------------------------------------------------ */
/* Probability                                                                           */

START_TEST(probabilities_agree_with_monte_carlo)
{
    /* d, dz, R, H, sigma_h, sigma_v */
    static const double cases[][6] = {
        {0.0, 0.0, 20.0, 10.0, 10.0, 5.0},  {15.0, 5.0, 20.0, 10.0, 8.0, 4.0},
        {20.0, 0.0, 20.0, 10.0, 5.0, 3.0},  {21.0, 12.0, 20.0, 10.0, 6.0, 3.0},
        {40.0, 0.0, 20.0, 10.0, 10.0, 5.0}, {60.0, 3.0, 20.0, 10.0, 15.0, 2.0},
        {5.0, 0.0, 50.0, 15.0, 1.0, 1.0},   {49.0, 0.0, 50.0, 15.0, 1.0, 2.0},
        {51.0, 14.0, 50.0, 15.0, 2.0, 2.0}, {100.0, 8.0, 30.0, 10.0, 40.0, 0.0},
        {25.0, 11.0, 30.0, 10.0, 0.0, 3.0}, {3.0, 0.0, 10.0, 5.0, 50.0, 50.0},
        {35.0, -4.0, 30.0, 10.0, 3.0, 6.0},
    };
    const size_t samples = 200000u;
    uint64_t s = 99u;
    size_t ci;

    for (ci = 0; ci < sizeof cases / sizeof cases[0]; ++ci) {
        const double *c = cases[ci];
        double p = coa_conflict_probability(R(c[0]), R(c[1]), R(c[2]), R(c[3]), R(c[4]), R(c[5]));
        size_t hits = 0u;
        size_t i;
        double pmc;
        double tol;

        for (i = 0; i < samples; ++i) {
            double ex;
            double ey;
            double ez;
            double unused;
            double x;
            normal_pair(&s, &ex, &ey);
            normal_pair(&s, &ez, &unused);
            x = c[0] + c[4] * ex;
            if (x * x + (c[4] * ey) * (c[4] * ey) < c[2] * c[2] && fabs(c[1] + c[5] * ez) < c[3]) {
                ++hits;
            }
        }
        pmc = (double)hits / (double)samples;
        tol = 4.0 * sqrt(p * (1.0 - p) / (double)samples) + 1e-4;
        printf("P(d=%g dz=%g R=%g H=%g sh=%g sv=%g) = %.6f, Monte Carlo %.6f (tolerance %.2g)\n",
               c[0], c[1], c[2], c[3], c[4], c[5], p, pmc, tol);
        ck_assert(p >= 0.0 && p <= 1.0);
        ck_assert_msg(fabs(p - pmc) <= tol, "case %zu: %.9f vs Monte Carlo %.9f", ci, p, pmc);
    }
}
END_TEST

/* P_h = P(|d + e| < R), e ~ N(0, sigma^2 I_2), from mpmath: d, R, sigma, P_h. */
static const double mpmath_ph[][4] = {
    {0.5, 1, 1, 0.35728576972745623084},
    {3, 2, 1, 0.11327924559760774296},
    {1, 3, 1, 0.956284028421364313},
    {20, 20, 4, 0.45990161322628164579},
    {35, 20, 5, 0.00098782376443072170745},
    {12, 20, 5, 0.92473142139048613419},
    {60, 20, 10, 0.000017402248322776218949},
    {80, 20, 10, 4.7708162170470193081e-10},
    {100, 30, 40, 0.015977437969185396958},
    {0.01, 10, 50, 0.019801326301165232338},
    {45, 20, 5, 1.8722942801872037718e-7},
    {5.5, 5, 0.5, 0.14738185775961113937},
    {9.5, 10, 0.5, 0.83505666144705509966},
    {19, 20, 1.05, 0.82263120400118708082},
    {21.5, 20, 1.0, 0.063739827591868474629},
    {40, 50, 1, 1.0 - 7.6e-24},
    {50, 50, 1, 0.49601037767994575408},
    {52.5, 50, 1, 0.006040685022141321731},
    {48, 50, 2, 0.83635408828425743799},
    {103, 100, 1, 0.0013282249644854483998},
    {100.3, 100, 0.1, 0.0013476870805463340812},
    {99.2, 100, 0.2, 0.99996819411950087503},
    {1000.5, 1000, 0.5, 0.15859478392374621566},
    {998, 1000, 1, 0.97722283200434516055},
    {30, 20, 2.2, 2.2149707383238507744e-6},
    {70, 25, 5, 6.6828800545218856684e-20},
    {26, 25, 0.7, 0.074608822017087222259},
};

START_TEST(probability_closed_forms_and_edges)
{
    static const double ratios[] = {0.01, 0.1, 0.5, 1.0, 2.0, 5.0, 10.0, 19.9, 20.1, 30.0};
    size_t i;
    int j;

    /* d = 0: the Rayleigh CDF, P_h = 1 - exp(-R^2 / (2 sigma^2)); P_v = 1 with sigma_v 0. */
    for (i = 0; i < sizeof ratios / sizeof ratios[0]; ++i) {
        double sigma = 20.0 / ratios[i];
        double want = -expm1(-200.0 / (sigma * sigma));
        double p = coa_conflict_probability(R(0.0), R(0.0), R(20.0), R(1.0), R(sigma), R(0.0));
        ck_assert_msg(fabs(p - want) <= 1e-13, "R/sigma %g: %.17g vs %.17g", ratios[i], p, want);
    }
    /* The vertical part alone: a difference of normal CDFs (here with P_h = 1). */
    for (j = -40; j <= 40; ++j) {
        double dz = 0.5 * (double)j;
        double want = 0.5 * (erfc((dz - 3.0) / (2.0 * SQRT2)) - erfc((dz + 3.0) / (2.0 * SQRT2)));
        double p = coa_conflict_probability(R(0.0), R(dz), R(5.0), R(3.0), R(0.0), R(2.0));
        ck_assert_msg(fabs(p - want) <= 1e-15 + 1e-12 * want, "dz %g", dz);
    }
    /* Far tails are differences of two small numbers, not of two numbers near 1: 19 to 21
     * sigma below the slab is about 1.3e-80, not 0. */
    {
        double p = coa_conflict_probability(R(0.0), R(20.0), R(5.0), R(1.0), R(0.0), R(1.0));
        double want = 0.5 * (erfc(19.0 / SQRT2) - erfc(21.0 / SQRT2));
        ck_assert(p > 0.0);
        ck_assert(fabs(p - want) <= 1e-9 * want);
    }
    /* Against mpmath (40 digits, the Rice integral of the non-central chi-square with two
     * degrees of freedom): the series (R / sigma < 20) and Gauss-Hermite (>= 20), near
     * and far from the edge, deep in the tail and at R / sigma = 1000. */
    for (i = 0; i < sizeof mpmath_ph / sizeof mpmath_ph[0]; ++i) {
        const double *c = mpmath_ph[i];
        double p = coa_conflict_probability(R(c[0]), R(0.0), R(c[1]), R(1.0), R(c[2]), R(0.0));
        ck_assert_msg(fabs(p - c[3]) <= PROB_TOL && fabs(p - c[3]) <= PROB_REL * c[3] + 1e-30,
                      "d %g R %g sigma %g: %.17g vs mpmath %.17g", c[0], c[1], c[2], p, c[3]);
    }
    /* The two methods for P_h meet at R / sigma = 20: either side of it they agree (the
     * true values 2e-10 apart differ by up to 1e-13 where dP/db is largest). */
    for (j = -30; j <= 30; ++j) {
        double c = 0.25 * (double)j;
        double below = coa_conflict_probability(R(20.0 - 1e-10 - c), R(0.0), R(20.0 - 1e-10),
                                                R(1.0), R(1.0), R(0.0));
        double above = coa_conflict_probability(R(20.0 + 1e-10 - c), R(0.0), R(20.0 + 1e-10),
                                                R(1.0), R(1.0), R(0.0));
        ck_assert_msg(fabs(below - above) <= 3e-13, "c %g: %.17g vs %.17g", c, below, above);
    }
    /* Monotone in distance across both methods and the edge. */
    for (i = 0; i < 2u; ++i) {
        double radius = i == 0u ? 5.0 : 80.0;
        double prev = 2.0;
        for (j = 0; j <= 400; ++j) {
            double d = (radius + 30.0) * (double)j / 400.0;
            double p = coa_conflict_probability(R(d), R(0.0), R(radius), R(1.0), R(2.0), R(0.0));
            REQUIRE(p <= prev + 1e-15);
            prev = p;
        }
        ck_assert(prev < 1e-30);
    }
    /* Zero sigma is the deterministic answer, strict at the edge. */
    ck_assert(coa_conflict_probability(R(19.0), R(9.0), R(20.0), R(10.0), R(0.0), R(0.0)) == 1.0);
    ck_assert(coa_conflict_probability(R(20.0), R(0.0), R(20.0), R(10.0), R(0.0), R(0.0)) == 0.0);
    ck_assert(coa_conflict_probability(R(0.0), R(10.0), R(20.0), R(10.0), R(0.0), R(0.0)) == 0.0);
    ck_assert(coa_conflict_probability(R(0.0), R(-10.0), R(20.0), R(10.0), R(0.0), R(0.0)) == 0.0);
    ck_assert(coa_conflict_probability(R(5.0), R(-9.9), R(20.0), R(10.0), R(0.0), R(0.0)) == 1.0);
    /* One axis certain: that factor is its indicator. */
    ck_assert(coa_conflict_probability(R(25.0), R(0.0), R(20.0), R(10.0), R(0.0), R(3.0)) == 0.0);
    ck_assert(coa_conflict_probability(R(0.0), R(11.0), R(20.0), R(10.0), R(4.0), R(0.0)) == 0.0);
    /* Far beyond the edge: exactly 0, quickly; far inside: 1. */
    ck_assert(coa_conflict_probability(R(1e6), R(0.0), R(20.0), R(10.0), R(1.0), R(1.0)) == 0.0);
    ck_assert(coa_conflict_probability(R(0.0), R(0.0), R(1e4), R(1e4), R(1.0), R(1.0)) == 1.0);
    /* Out of range: 1, the safe side. */
    ck_assert(coa_conflict_probability(R(-1.0), R(0.0), R(20.0), R(10.0), R(1.0), R(1.0)) == 1.0);
    ck_assert(coa_conflict_probability(R(NAN), R(0.0), R(20.0), R(10.0), R(1.0), R(1.0)) == 1.0);
    ck_assert(coa_conflict_probability(R(100.0), R(INFINITY), R(20.0), R(10.0), R(1.0), R(1.0)) ==
              1.0);
    ck_assert(coa_conflict_probability(R(100.0), R(0.0), R(0.0), R(10.0), R(1.0), R(1.0)) == 1.0);
    ck_assert(coa_conflict_probability(R(100.0), R(0.0), R(20.0), R(-1.0), R(1.0), R(1.0)) == 1.0);
    ck_assert(coa_conflict_probability(R(100.0), R(0.0), R(20.0), R(10.0), R(-1.0), R(1.0)) == 1.0);
    ck_assert(coa_conflict_probability(R(100.0), R(0.0), R(20.0), R(10.0), R(1.0), R(INFINITY)) ==
              1.0);
}
END_TEST

/* ------------------------------------------------------------------------------------ */
/* Alignment                                                                             */

/* A straight line p(t) = p0 + v t published two ways, probed by hovering UAVs (one-sample
 * plans) whose least separation and first conflict are known in closed form. */
static void line_at(double t, double *x, double *y, double *z)
{
    *x = 100.0 + 10.0 * t;
    *y = -50.0 + 5.0 * t;
    *z = 100.0 + 0.5 * t;
}

static void line_plan(fleet_t *f, size_t i, double t0, double step, size_t count)
{
    coa_intent_plan_t *p = &f->plans[i];
    size_t j;
    memset(p, 0, sizeof *p);
    p->id = (uint16_t)(i + 1u);
    p->volume.radius = R(10.0);
    p->volume.half_height = R(5.0);
    p->t0 = R(t0);
    p->step = R(step);
    p->count = count;
    p->samples = f->samples[i];
    for (j = 0; j < count; ++j) {
        double x;
        double y;
        double z;
        line_at(t0 + step * (double)j, &x, &y, &z);
        f->samples[i][j] = V(x, y, z);
    }
}

static void probe_plan(fleet_t *f, size_t i, double x, double y, double z, double radius,
                       double half_height)
{
    coa_intent_plan_t *p = &f->plans[i];
    memset(p, 0, sizeof *p);
    p->id = (uint16_t)(i + 1u);
    p->volume.radius = R(radius);
    p->volume.half_height = R(half_height);
    p->t0 = R(1000.0); /* a single sample is stationary whenever it was published */
    p->step = R(1.0);
    p->count = 1u;
    p->samples = f->samples[i];
    f->samples[i][0] = V(x, y, z);
}

START_TEST(plans_with_their_own_times_are_aligned)
{
    /* Predictor grid: t0 = 50, dt = 0.7, N = 10: t in [50, 57]. Plan A starts before the
     * grid with step 0.5 and ends at 55.2 (extrapolated past its end); plan B starts at
     * 50.2 with step 2 (extrapolated before its start) and ends at 54.2. */
    const double t0 = 50.0;
    const double dt = 0.7;
    const uint32_t horizon = 10u;
    const double speed_h = sqrt(125.0);
    const double ux = 10.0 / speed_h;
    const double uy = 5.0 / speed_h;
    double tend = t0 + dt * horizon;
    double ax;
    double ay;
    double az;
    double ex;
    double ey;
    double ez;
    double mx;
    double my;
    double mz;
    fleet_t *f = fleet_new();
    static coa_conflict_t got[2][16];
    coa_predict_result_t res[2];
    ws_t w;
    size_t pub;

    ws_make(&w, 5u, 1u, horizon, 64u);
    line_at(t0, &ax, &ay, &az);
    line_at(tend, &ex, &ey, &ez);
    line_at(53.5, &mx, &my, &mz);
    for (pub = 0; pub < 2u; ++pub) {
        size_t i;
        memset(f, 0, sizeof *f);
        config_default(&f->cfg, horizon, dt);
        f->cfg.t0 = R(t0);
        if (pub == 0u) {
            line_plan(f, 0u, t0 - 0.3, 0.5, 12u);
        } else {
            line_plan(f, 0u, t0 + 0.2, 2.0, 3u);
        }
        /* 1: 40 m behind the grid's first position, 60 m below it (a huge volume: always
         * in conflict, so its separations are reported; the line climbs away from it).
         * 2: 30 m ahead of the last position, 20 m above it. 3: on the line at t = 53.5
         * with 25 m of combined radii: the conflict starts when the line comes within
         * 25 m of it, 25 m / |v_h| before 53.5 (the vertical offset then, 0.5 m/s *
         * 2.2 s, is well inside the half-heights). */
        probe_plan(f, 1u, ax - 40.0 * ux, ay - 40.0 * uy, az - 60.0, 1000.0, 1000.0);
        probe_plan(f, 2u, ex + 30.0 * ux, ey + 30.0 * uy, ez + 20.0, 1000.0, 1000.0);
        probe_plan(f, 3u, mx, my, mz, 15.0, 5.0);
        f->n = 4u;
        /* A track with the predictor's clock: at t it is at (100 + 10 t, -50 + 5 t + 40,
         * 100 + 0.5 t), 40 m north of the line, flying alongside it. */
        memset(&f->tracks[0], 0, sizeof f->tracks[0]);
        f->tracks[0].id = 9u;
        f->tracks[0].volume.radius = R(35.0);
        f->tracks[0].volume.half_height = R(5.0);
        f->tracks[0].position = V(100.0, -10.0, 100.0);
        f->tracks[0].velocity = V(10.0, 5.0, 0.5);
        f->m = 1u;
        ck_assert_int_eq(run(&w, f, false, got[pub], 16u, &res[pub]), COA_OK);
        /* The line against each probe; the probes among themselves (1000 m volumes); the
         * track against the line and each probe. */
        ck_assert_uint_eq(res[pub].conflict_count, 10u);
        for (i = 0; i < 10u; ++i) {
            ck_assert_int_eq(got[pub][i].kind, i < 6u ? COA_CONFLICT_VEHICLE : COA_CONFLICT_TRACK);
        }
    }
    for (pub = 0; pub < 2u; ++pub) {
        const coa_conflict_t *c = got[pub];
        double enter = 53.5 - 25.0 / speed_h;
        /* 0-1, 0-2, 0-3 first; the track's pair with the line at 6. */
        ck_assert_uint_eq(c[0].a, 0u);
        ck_assert_uint_eq(c[0].b, 1u);
        ck_assert(fabs((double)c[0].min_horizontal - 40.0) <= 1e3 * POS_TOL);
        ck_assert(fabs((double)c[0].min_vertical - 60.0) <= 1e3 * POS_TOL);
        ck_assert_uint_eq(c[1].b, 2u);
        ck_assert(fabs((double)c[1].min_horizontal - 30.0) <= 1e3 * POS_TOL);
        ck_assert(fabs((double)c[1].min_vertical - 20.0) <= 1e3 * POS_TOL);
        ck_assert_uint_eq(c[2].b, 3u);
        ck_assert_uint_eq(c[2].first_step, (uint32_t)floor((enter - t0) / dt));
        ck_assert(fabs((double)c[2].first_time - (t0 + dt * floor((enter - t0) / dt))) <= TIME_TOL);
        ck_assert((double)c[2].min_horizontal <= 1e3 * POS_TOL);
        ck_assert_uint_eq(c[6].a, 0u);
        ck_assert_uint_eq(c[6].b, 0u);
        ck_assert(fabs((double)c[6].min_horizontal - 40.0) <= 1e3 * POS_TOL);
        ck_assert(fabs((double)c[6].min_vertical) <= 1e3 * POS_TOL);
        ck_assert_uint_eq(c[6].first_step, 0u);
    }
    /* The two publications give the same answer (positions within 1e-9 m). */
    for (pub = 0; pub < 10u; ++pub) {
        ck_assert_int_eq(got[0][pub].kind, got[1][pub].kind);
        ck_assert_uint_eq(got[0][pub].a, got[1][pub].a);
        ck_assert_uint_eq(got[0][pub].b, got[1][pub].b);
        ck_assert_uint_eq(got[0][pub].first_step, got[1][pub].first_step);
        ck_assert(fabs((double)(got[0][pub].min_horizontal - got[1][pub].min_horizontal)) <=
                  1e3 * POS_TOL);
        ck_assert(fabs((double)(got[0][pub].min_vertical - got[1][pub].min_vertical)) <=
                  1e3 * POS_TOL);
    }
    ws_free(&w);
    free(f);
}
END_TEST

/* Resampling itself, through a pair whose separation is the position: a plan against a
 * hovering probe at the origin with a volume that always conflicts, over a grid of one
 * step, reports min_horizontal = the least distance of the segment between the two
 * resampled positions; one step of zero length pins the position itself. */
START_TEST(resampling_matches_the_line_at_every_grid_time)
{
    fleet_t *f = fleet_new();
    coa_conflict_t got[4];
    coa_predict_result_t res;
    ws_t w;
    int pub;
    int k;

    ws_make(&w, 2u, 0u, 1u, 8u);
    for (pub = 0; pub < 2; ++pub) {
        for (k = -10; k <= 40; ++k) {
            /* A one-step grid from t to t + 1e-300 s is a point for every purpose. */
            double t = 0.37 * (double)k - 1.0;
            double x;
            double y;
            double z;
            memset(f, 0, sizeof *f);
            config_default(&f->cfg, 1u, 1e-300);
#ifdef COA_SINGLE_PRECISION
            f->cfg.dt = R(1e-30);
#endif
            f->cfg.t0 = R(t);
            if (pub == 0) {
                line_plan(f, 0u, -0.3, 0.5, 12u);
            } else {
                line_plan(f, 0u, 0.2, 2.0, 3u);
            }
            probe_plan(f, 1u, 0.0, 0.0, 0.0, 1e6, 1e6);
            f->n = 2u;
            ck_assert_int_eq(run(&w, f, false, got, 4u, &res), COA_OK);
            ck_assert_uint_eq(res.conflict_count, 1u);
            line_at(t, &x, &y, &z);
            ck_assert_msg(fabs((double)got[0].min_horizontal - sqrt(x * x + y * y)) <= POS_TOL,
                          "publication %d at t = %g: %.15g vs %.15g", pub, t,
                          (double)got[0].min_horizontal, sqrt(x * x + y * y));
            ck_assert(fabs((double)got[0].min_vertical - z) <= POS_TOL);
        }
    }
    ws_free(&w);
    free(f);
}
END_TEST

/* ------------------------------------------------------------------------------------ */
/* Probability in the cycle                                                              */

/* Two UAVs pass abreast, their nominal miss 25 m against 20 m of combined radii. */
static void passing_pair(fleet_t *f, double sigma_h0)
{
    memset(f, 0, sizeof *f);
    config_default(&f->cfg, 20u, 1.0);
    f->cfg.threshold = 0.05;
    line_plan(f, 0u, 0.0, 1.0, 21u);
    line_plan(f, 1u, 0.0, 1.0, 21u);
    /* Plan 1 flies the same line shifted 25 m to the side and back in time so the closest
     * approach is at t = 10 (it is a head-on pass). */
    {
        size_t j;
        for (j = 0; j <= 20u; ++j) {
            double x;
            double y;
            double z;
            line_at(20.0 - (double)j, &x, &y, &z);
            f->samples[1][j] = V(x - 25.0 * 5.0 / sqrt(125.0), y + 25.0 * 10.0 / sqrt(125.0),
                                 z - 10.0 + (double)j);
        }
    }
    f->plans[0].sigma_horizontal = R(sigma_h0);
    f->plans[1].sigma_horizontal = R(sigma_h0);
    f->n = 2u;
}

START_TEST(sigma_growth_crosses_the_threshold)
{
    fleet_t *f = fleet_new();
    coa_conflict_t got[4];
    coa_predict_result_t res;
    ws_t w;

    ws_make(&w, 2u, 1u, 20u, 8u);
    /* No sigma: the nominal miss is no conflict. */
    passing_pair(f, 0.0);
    ck_assert_int_eq(run(&w, f, false, got, 4u, &res), COA_OK);
    ck_assert_uint_eq(res.conflicts_found, 0u);
    /* A sigma of 0.5 m that does not grow: 5 m is 7 combined sigmas, P ~ 1e-12. */
    passing_pair(f, 0.5);
    ck_assert_int_eq(run(&w, f, false, got, 4u, &res), COA_OK);
    ck_assert_uint_eq(res.conflicts_found, 0u);
    /* Growth of the tracks' sigma does not touch UAVs. */
    f->cfg.track_sigma_rate_horizontal = R(2.0);
    ck_assert_int_eq(run(&w, f, false, got, 4u, &res), COA_OK);
    ck_assert_uint_eq(res.conflicts_found, 0u);
    /* Growing by 1 m/s of look-ahead: 10 m each at the closest approach, P over 0.05. */
    f->cfg.vehicle_sigma_rate_horizontal = R(1.0);
    ck_assert_int_eq(run(&w, f, false, got, 4u, &res), COA_OK);
    ck_assert_uint_eq(res.conflicts_found, 1u);
    ck_assert_int_eq(got[0].kind, COA_CONFLICT_VEHICLE);
    ck_assert(got[0].probability >= 0.05 && got[0].probability < 1.0);
    ck_assert_uint_le(got[0].first_step, 10u);
    ck_assert(fabs((double)got[0].min_horizontal - 25.0) <= FINE_TOL);
    printf("sigma growth: P = %.6f from step %u\n", got[0].probability, got[0].first_step);
    /* The same pair with zero growth but sigma 0 on one side and growth on... the other
     * kind of thing: UAV rates apply to UAVs only, so this is certain again. */
    passing_pair(f, 0.0);
    f->cfg.track_sigma_rate_horizontal = R(5.0);
    f->cfg.track_sigma_rate_vertical = R(5.0);
    ck_assert_int_eq(run(&w, f, false, got, 4u, &res), COA_OK);
    ck_assert_uint_eq(res.conflicts_found, 0u);
    ws_free(&w);
    free(f);
}
END_TEST

/* Hovering pairs, d = 30 and dz = 4 apart (R = 20, H = 9): P depends on time only through
 * the sigmas, so the reported maximum is known from coa_conflict_probability with the
 * combined sigma sqrt(sa^2 + sb^2) at the instants predict.h names (for a hovering pair,
 * the ends and quarters of every step). */
static double hover_sigma(double s0a, double s0b, double rate, double tau)
{
    double x = s0a + rate * tau;
    double y = s0b + rate * tau;
    return sqrt(x * x + y * y);
}

START_TEST(probability_is_the_combined_sigma_maximum)
{
    fleet_t *f = fleet_new();
    coa_conflict_t got[4];
    coa_predict_result_t res;
    ws_t w;
    double want;
    double p_start;
    double p_end;
    int j;

    ws_make(&w, 2u, 1u, 10u, 8u);
    memset(f, 0, sizeof *f);
    config_default(&f->cfg, 10u, 2.0);
    probe_plan(f, 0u, 0.0, 0.0, 100.0, 12.0, 5.0);
    probe_plan(f, 1u, 30.0, 0.0, 104.0, 8.0, 4.0);
    f->plans[0].sigma_horizontal = R(6.0);
    f->plans[1].sigma_horizontal = R(8.0);
    f->plans[0].sigma_vertical = R(3.0);
    f->n = 2u;
    /* No growth: the same P at every instant, from the first step. */
    want = coa_conflict_probability(R(30.0), R(4.0), R(20.0), R(9.0), R(10.0), R(3.0));
    ck_assert_int_eq(run(&w, f, false, got, 4u, &res), COA_OK);
    ck_assert_uint_eq(res.conflicts_found, 1u);
    ck_assert_msg(got[0].probability == want, "%.17g vs %.17g", got[0].probability, want);
    ck_assert_uint_eq(got[0].first_step, 0u);
    /* Horizontal growth 0.5 m/s on both: sigma_h goes from 10 to sqrt(16^2 + 18^2) = 24
     * over the 20 s, across the sigma (about 18) where P_h(30; 20, sigma) peaks, so the
     * maximum is inside the horizon, at one of the quarter instants. */
    f->cfg.vehicle_sigma_rate_horizontal = R(0.5);
    want = 0.0;
    for (j = 0; j <= 40; ++j) {
        double p = coa_conflict_probability(R(30.0), R(4.0), R(20.0), R(9.0),
                                            R(hover_sigma(6.0, 8.0, 0.5, 0.5 * (double)j)), R(3.0));
        want = p > want ? p : want;
    }
    p_start = coa_conflict_probability(R(30.0), R(4.0), R(20.0), R(9.0), R(10.0), R(3.0));
    p_end = coa_conflict_probability(R(30.0), R(4.0), R(20.0), R(9.0),
                                     R(hover_sigma(6.0, 8.0, 0.5, 20.0)), R(3.0));
    ck_assert(want > p_start + 0.01 && want > p_end + 0.01);
    ck_assert_int_eq(run(&w, f, false, got, 4u, &res), COA_OK);
    ck_assert_uint_eq(res.conflicts_found, 1u);
    ck_assert_msg(got[0].probability == want, "%.17g vs %.17g", got[0].probability, want);
    /* Other growth rates put the peak on each kind of instant in turn (step ends and each
     * quarter): the reported P is always the largest over exactly those instants. */
    {
        bool hit[4] = {false, false, false, false};
        int r;
        for (r = 0; r < 24; ++r) {
            double rate = 0.45 + 0.025 * (double)r;
            int arg = 0;
            want = 0.0;
            for (j = 0; j <= 40; ++j) {
                double p = coa_conflict_probability(
                    R(30.0), R(4.0), R(20.0), R(9.0),
                    R(hover_sigma(6.0, 8.0, (double)R(rate), 0.5 * (double)j)), R(3.0));
                if (p > want) {
                    want = p;
                    arg = j;
                }
            }
            hit[arg % 4] = true;
            f->cfg.vehicle_sigma_rate_horizontal = R(rate);
            ck_assert_int_eq(run(&w, f, false, got, 4u, &res), COA_OK);
            ck_assert_uint_eq(res.conflicts_found, 1u);
            ck_assert_msg(got[0].probability == want, "rate %g: %.17g vs %.17g", rate,
                          got[0].probability, want);
        }
        ck_assert(hit[0] && hit[1] && hit[2] && hit[3]);
        f->cfg.vehicle_sigma_rate_horizontal = R(0.5);
        want = 0.0;
        for (j = 0; j <= 40; ++j) {
            double p =
                coa_conflict_probability(R(30.0), R(4.0), R(20.0), R(9.0),
                                         R(hover_sigma(6.0, 8.0, 0.5, 0.5 * (double)j)), R(3.0));
            want = p > want ? p : want;
        }
    }
    /* A threshold just above the maximum: not reported; just below: reported, from the
     * step holding the peak. */
    f->cfg.threshold = want * (1.0 + 1e-9);
    ck_assert_int_eq(run(&w, f, false, got, 4u, &res), COA_OK);
    ck_assert_uint_eq(res.conflicts_found, 0u);
    f->cfg.threshold = want * (1.0 - 1e-9);
    ck_assert_int_eq(run(&w, f, false, got, 4u, &res), COA_OK);
    ck_assert_uint_eq(res.conflicts_found, 1u);
    ck_assert_uint_gt(got[0].first_step, 0u);
    ck_assert_uint_lt(got[0].first_step, 9u);
    ck_assert(got[0].probability == want);
    ws_free(&w);
    free(f);
}
END_TEST

/* Where P peaks sharply at the closest approach and that falls a third or two thirds
 * into a step (no quarter, no sample), the reported P is the one at the closest approach:
 * the instants of least horizontal and of least vertical separation are evaluated. */
static void straight_plan(fleet_t *f, size_t i, double x0, double y0, double z0, double vx,
                          double vz, double radius, double half_height)
{
    coa_intent_plan_t *p = &f->plans[i];
    size_t j;
    memset(p, 0, sizeof *p);
    p->id = (uint16_t)(i + 1u);
    p->volume.radius = R(radius);
    p->volume.half_height = R(half_height);
    p->t0 = R(0.0);
    p->step = R(1.0);
    p->count = 41u;
    p->samples = f->samples[i];
    for (j = 0; j < 41u; ++j) {
        f->samples[i][j] = V(x0 + vx * (double)j, y0, z0 + vz * (double)j);
    }
}

START_TEST(probability_is_taken_at_the_closest_approach)
{
    fleet_t *f = fleet_new();
    coa_conflict_t got[4];
    coa_predict_result_t res;
    ws_t w;
    double want;

    ws_make(&w, 2u, 0u, 20u, 8u);
    /* Head-on, 21 m apart across the track against 20 m of radii, closest at t = 20 s:
     * a third into the step [19.5, 21] of dt = 1.5 s. */
    memset(f, 0, sizeof *f);
    config_default(&f->cfg, 20u, 1.5);
    straight_plan(f, 0u, -200.0, 0.0, 100.0, 10.0, 0.0, 10.0, 5.0);
    straight_plan(f, 1u, 200.0, 21.0, 100.0, -10.0, 0.0, 10.0, 5.0);
    f->plans[0].sigma_horizontal = R(0.5);
    f->plans[1].sigma_horizontal = R(0.5);
    f->n = 2u;
    want = coa_conflict_probability(R(21.0), R(0.0), R(20.0), R(10.0), R(sqrt(0.5)), R(0.0));
    ck_assert_int_eq(run(&w, f, false, got, 4u, &res), COA_OK);
    ck_assert_uint_eq(res.conflicts_found, 1u);
    ck_assert_uint_eq(got[0].first_step, 13u);
    ck_assert_msg(fabs(got[0].probability - want) <= 1e-9, "%.17g vs %.17g", got[0].probability,
                  want);
    /* One above the other 10 m apart (certain horizontally: 10 < 20), the second
     * descending at 3 m/s through the first's altitude at t = 10 s, two thirds into the
     * step [9, 10.5]: half-heights of 1 m against a vertical sigma of 1 m. */
    memset(f, 0, sizeof *f);
    config_default(&f->cfg, 20u, 1.5);
    straight_plan(f, 0u, 0.0, 0.0, 100.0, 0.0, 0.0, 10.0, 1.0);
    straight_plan(f, 1u, 0.0, 10.0, 130.0, 0.0, -3.0, 10.0, 1.0);
    f->plans[0].sigma_vertical = R(1.0);
    f->n = 2u;
    want = coa_conflict_probability(R(10.0), R(0.0), R(20.0), R(2.0), R(0.0), R(1.0));
    ck_assert_int_eq(run(&w, f, false, got, 4u, &res), COA_OK);
    ck_assert_uint_eq(res.conflicts_found, 1u);
    ck_assert_msg(fabs(got[0].probability - want) <= 1e-9, "%.17g vs %.17g", got[0].probability,
                  want);
    ck_assert(fabs((double)got[0].min_vertical) <= POS_TOL);
    ws_free(&w);
    free(f);
}
END_TEST

/* ------------------------------------------------------------------------------------ */
/* Capacity, workspace, arguments                                                        */

/* Five UAVs hovering on one spot, a track through it and a box around it. */
static void pileup(fleet_t *f, size_t n)
{
    size_t i;
    memset(f, 0, sizeof *f);
    config_default(&f->cfg, 6u, 1.0);
    for (i = 0; i < n; ++i) {
        probe_plan(f, i, 3.0 * (double)i, 0.0, 100.0, 10.0, 5.0);
    }
    f->n = n;
    memset(&f->tracks[0], 0, sizeof f->tracks[0]);
    f->tracks[0].id = 1u;
    f->tracks[0].volume.radius = R(10.0);
    f->tracks[0].volume.half_height = R(5.0);
    f->tracks[0].position = V(-30.0, 0.0, 100.0);
    f->tracks[0].velocity = V(10.0, 0.0, 0.0);
    f->m = 1u;
    memset(&f->obstacles[0], 0, sizeof f->obstacles[0]);
    f->obstacles[0].kind = COA_OBSTACLE_BOX;
    f->obstacles[0].box.min = V(-1.0, -1.0, 88.0);
    f->obstacles[0].box.max = V(1.0, 1.0, 96.0);
    f->o = 1u;
}

START_TEST(capacity_overflow_is_reported)
{
    fleet_t *f = fleet_new();
    coa_conflict_t all[64];
    coa_conflict_t some[64];
    coa_predict_result_t res;
    coa_predict_result_t part;
    ws_t w;
    size_t cap;
    size_t i;

    ws_make(&w, 5u, 1u, 6u, 64u);
    pileup(f, 5u);
    ck_assert_int_eq(run(&w, f, false, all, 64u, &res), COA_OK);
    /* 10 vehicle pairs, 5 track pairs, and the box reaches the UAVs within 10 m of it
     * (x = 0, 3, 6, 9; not 12). */
    ck_assert_uint_eq(res.conflicts_found, 10u + 5u + 4u);
    ck_assert_uint_eq(res.conflict_count, res.conflicts_found);
    ck_assert(!res.overflow);
    /* The documented order: kind, then (a, b). */
    for (i = 1; i < res.conflict_count; ++i) {
        const coa_conflict_t *p = &all[i - 1u];
        const coa_conflict_t *c = &all[i];
        ck_assert(p->kind < c->kind ||
                  (p->kind == c->kind && (p->a < c->a || (p->a == c->a && p->b < c->b))));
    }
    for (cap = 0; cap < res.conflicts_found; ++cap) {
        memset(some, 0xA5, sizeof some);
        ck_assert_int_eq(run(&w, f, cap % 2u == 1u, cap == 0u ? NULL : some, cap, &part), COA_OK);
        ck_assert_uint_eq(part.conflict_count, cap);
        ck_assert_uint_eq(part.conflicts_found, res.conflicts_found);
        ck_assert(part.overflow);
        for (i = 0; i < cap; ++i) {
            ck_assert(same_conflict(&some[i], &all[i]));
        }
        /* Nothing written past the capacity. */
        ck_assert_uint_eq(((unsigned char *)&some[cap])[0], 0xA5u);
    }
    ws_free(&w);
    free(f);
}
END_TEST

START_TEST(pair_set_limit_is_an_error_not_a_drop)
{
    fleet_t *f = fleet_new();
    coa_conflict_t got[64];
    coa_conflict_t ref[64];
    coa_predict_result_t res;
    coa_predict_result_t ref_res;
    ws_t w;
    size_t i;
    size_t limit;

    /* Five UAVs in one spot: 10 vehicle + 5 track candidates from the sweep, then 4
     * obstacle candidates (the fifth UAV's reach misses the box): 19. The limit counts
     * distinct pairs, not overlaps: these boxes overlap at every one of the six steps. */
    for (limit = 10u; limit <= 18u; limit += 8u) {
        /* 10: the sweep runs out; 18: the obstacles do. */
        pileup(f, 5u);
        ws_make(&w, 5u, 1u, 6u, limit);
        res.conflicts_found = 99u;
        ck_assert_int_eq(run(&w, f, false, got, 64u, &res), COA_ERR_WORKSPACE);
        ck_assert_uint_eq(res.conflicts_found, 0u); /* cleared */
        /* all_pairs needs no pair set. */
        ck_assert_int_eq(run(&w, f, true, ref, 64u, &ref_res), COA_OK);
        /* After the error the set is empty again (a key left in it would hide its pair
         * from the next call): a fleet that fits gives the reference. */
        pileup(f, 3u);
        ck_assert_int_eq(run(&w, f, false, got, 64u, &res), COA_OK);
        ck_assert_int_eq(run(&w, f, true, ref, 64u, &ref_res), COA_OK);
        ck_assert_uint_eq(res.candidate_pairs, 3u + 3u + 3u);
        ck_assert_uint_eq(res.conflicts_found, ref_res.conflicts_found);
        ck_assert_uint_eq(res.conflicts_found, 9u);
        for (i = 0; i < res.conflict_count; ++i) {
            ck_assert(same_conflict(&got[i], &ref[i]));
        }
        ws_free(&w);
    }
    /* Exactly enough. */
    pileup(f, 5u);
    ws_make(&w, 5u, 1u, 6u, 19u);
    ck_assert_int_eq(run(&w, f, false, got, 64u, &res), COA_OK);
    ck_assert_uint_eq(res.candidate_pairs, 19u);
    ws_free(&w);
    free(f);
}
END_TEST

START_TEST(workspace_size_is_exact)
{
    size_t bytes = coa_predictor_workspace_size(10u, 2u, 60u, 100u);
    unsigned char *mem;
    unsigned char *guard;
    coa_predictor_t *pr;
    fleet_t *f = fleet_new();
    coa_conflict_t got[64];
    coa_predict_result_t res;
    uint64_t s = 5u;

    ck_assert_uint_gt(bytes, 0u);
    ck_assert_uint_gt(coa_predictor_workspace_size(11u, 2u, 60u, 100u), bytes);
    ck_assert_uint_gt(coa_predictor_workspace_size(10u, 3u, 60u, 100u), bytes);
    ck_assert_uint_gt(coa_predictor_workspace_size(10u, 2u, 61u, 100u), bytes);
    ck_assert_uint_gt(coa_predictor_workspace_size(10u, 2u, 60u, 101u), bytes);
    ck_assert_uint_gt(coa_predictor_workspace_size(10u, 0u, 60u, 100u), 0u);
    ck_assert_uint_eq(coa_predictor_workspace_size(0u, 2u, 60u, 100u), 0u);
    ck_assert_uint_eq(coa_predictor_workspace_size(10u, 2u, 0u, 100u), 0u);
    ck_assert_uint_eq(coa_predictor_workspace_size(10u, 2u, 60u, 0u), 0u);
    ck_assert_uint_eq(coa_predictor_workspace_size(10u, 2u, COA_MAX_HORIZON + 1u, 100u), 0u);
    ck_assert_uint_eq(coa_predictor_workspace_size(SIZE_MAX / 8u, 2u, 60u, 100u), 0u);
    ck_assert_uint_eq(coa_predictor_workspace_size(10u, SIZE_MAX, 60u, 100u), 0u);
    ck_assert_uint_eq(coa_predictor_workspace_size(10u, 2u, 60u, SIZE_MAX / 2u), 0u);
    /* Sizes as predict.h states them (double): a mover 24 (N + 1) + 124 bytes, a plan 48
     * more, a pair 12 bytes plus its table slots (2P rounded up to a power of two). Two
     * at a time, so the 4-byte entries keep their arrays' 8-byte rounding. */
#ifndef COA_SINGLE_PRECISION
    ck_assert_uint_eq(coa_predictor_workspace_size(12u, 2u, 60u, 100u) - bytes,
                      2u * (24u * 61u + 124u + 48u));
    ck_assert_uint_eq(coa_predictor_workspace_size(10u, 4u, 60u, 100u) - bytes,
                      2u * (24u * 61u + 124u));
    ck_assert_uint_eq(coa_predictor_workspace_size(10u, 2u, 60u, 110u) - bytes, 10u * 12u);
    ck_assert_uint_eq(coa_predictor_workspace_size(10u, 2u, 60u, 130u) - bytes,
                      30u * 12u + 256u * 8u);
#endif

    mem = malloc(bytes + 16u);
    ck_assert_ptr_nonnull(mem);
    ck_assert_ptr_null(coa_predictor_init(NULL, bytes, 10u, 2u, 60u, 100u));
    ck_assert_ptr_null(coa_predictor_init(mem, bytes - 1u, 10u, 2u, 60u, 100u));
    ck_assert_ptr_null(coa_predictor_init(mem + 4, bytes, 10u, 2u, 60u, 100u));
    ck_assert_ptr_null(coa_predictor_init(mem, bytes, 0u, 2u, 60u, 100u));
    ck_assert_ptr_null(coa_predictor_init(mem, bytes, 11u, 2u, 60u, 100u));
    ck_assert_ptr_null(coa_predictor_init(mem, bytes, 10u, 2u, 61u, 100u));
    guard = mem + bytes;
    memset(guard, 0x5A, 16u);
    pr = coa_predictor_init(mem, bytes, 10u, 2u, 60u, 100u);
    ck_assert_ptr_eq((void *)pr, (void *)mem);
    /* Full to its limits, it never writes past its size. */
    small_fleet(f, &s, 60u);
    while (f->n < 10u) {
        f->plans[f->n] = f->plans[0];
        f->n += 1u;
    }
    while (f->m < 2u) {
        add_track(f, &s, 100.0, 90.0, 110.0, 5.0, 10.0, true);
    }
    ck_assert_int_eq(coa_predict(pr, &f->cfg, f->plans, f->n, f->obstacles, f->o, f->tracks, f->m,
                                 got, 64u, &res),
                     COA_OK);
    ck_assert_uint_gt(res.conflicts_found, 0u);
    {
        size_t i;
        for (i = 0; i < 16u; ++i) {
            ck_assert_uint_eq(guard[i], 0x5Au);
        }
    }
    /* Counts past the limits. */
    ck_assert_int_eq(coa_predict(pr, &f->cfg, f->plans, 11u, f->obstacles, f->o, f->tracks, f->m,
                                 got, 64u, &res),
                     COA_ERR_ARGUMENT);
    ck_assert_int_eq(
        coa_predict(pr, &f->cfg, f->plans, f->n, f->obstacles, f->o, f->tracks, 3u, got, 64u, &res),
        COA_ERR_ARGUMENT);
    f->cfg.horizon = 61u;
    ck_assert_int_eq(coa_predict(pr, &f->cfg, f->plans, f->n, f->obstacles, f->o, f->tracks, f->m,
                                 got, 64u, &res),
                     COA_ERR_ARGUMENT);
    f->cfg.horizon = 60u;
    /* Not a predictor. */
    memset(mem, 0, 8u);
    ck_assert_int_eq(coa_predict(pr, &f->cfg, f->plans, f->n, f->obstacles, f->o, f->tracks, f->m,
                                 got, 64u, &res),
                     COA_ERR_WORKSPACE);
    free(mem);
    free(f);
}
END_TEST

START_TEST(bad_config_and_plans_are_refused)
{
    fleet_t *f = fleet_new();
    coa_conflict_t got[64];
    coa_predict_result_t res;
    ws_t w;
    uint64_t s = 11u;
    coa_predict_config_t good;
    coa_intent_plan_t plan0;
    coa_vec3_t sample0;
    coa_track_t track0;
    coa_obstacle_t obs0;
    size_t i;
    coa_real_t nan = R(NAN);
    coa_real_t inf = R(INFINITY);

#define EXPECT_ARG()                                                           \
    do {                                                                       \
        res.conflicts_found = 7u;                                              \
        ck_assert_int_eq(run(&w, f, false, got, 64u, &res), COA_ERR_ARGUMENT); \
        ck_assert_uint_eq(res.conflicts_found, 0u);                            \
    } while (0)

    ws_make(&w, 8u, 2u, 16u, 256u);
    do {
        small_fleet(f, &s, 16u);
    } while (f->m == 0u || f->o == 0u);
    ck_assert_int_eq(run(&w, f, false, got, 64u, &res), COA_OK);
    good = f->cfg;
    plan0 = f->plans[0];
    sample0 = f->samples[0][3];
    track0 = f->tracks[0];
    obs0 = f->obstacles[0];

    /* Config. */
    f->cfg.t0 = nan;
    EXPECT_ARG();
    f->cfg = good;
    f->cfg.dt = R(0.0);
    EXPECT_ARG();
    f->cfg.dt = R(-1.0);
    EXPECT_ARG();
    f->cfg.dt = inf;
    EXPECT_ARG();
    f->cfg = good;
    f->cfg.horizon = 0u;
    EXPECT_ARG();
    f->cfg = good;
    f->cfg.vehicle_sigma_rate_horizontal = R(-0.1);
    EXPECT_ARG();
    f->cfg = good;
    f->cfg.vehicle_sigma_rate_vertical = nan;
    EXPECT_ARG();
    f->cfg = good;
    f->cfg.track_sigma_rate_horizontal = inf;
    EXPECT_ARG();
    f->cfg = good;
    f->cfg.track_sigma_rate_vertical = R(-1.0);
    EXPECT_ARG();
    f->cfg = good;
    f->cfg.threshold = 0.0;
    EXPECT_ARG();
    f->cfg.threshold = 1.0 + 1e-12;
    EXPECT_ARG();
    f->cfg.threshold = NAN;
    EXPECT_ARG();
    f->cfg.threshold = 1.0; /* allowed */
    ck_assert_int_eq(run(&w, f, false, got, 64u, &res), COA_OK);
    f->cfg = good;
#ifndef COA_SINGLE_PRECISION
    f->cfg.t0 = R(1e308); /* the grid's end overflows */
    f->cfg.dt = R(1e307);
    EXPECT_ARG();
    f->cfg = good;
#endif
    /* Plans. */
    f->plans[0].count = 0u;
    EXPECT_ARG();
    f->plans[0] = plan0;
    f->plans[0].samples = NULL;
    EXPECT_ARG();
    f->plans[0] = plan0;
    f->plans[0].step = R(0.0);
    EXPECT_ARG();
    f->plans[0].step = nan;
    EXPECT_ARG();
    f->plans[0] = plan0;
    f->plans[0].t0 = inf;
    EXPECT_ARG();
    f->plans[0] = plan0;
    f->plans[0].volume.radius = R(0.0);
    EXPECT_ARG();
    f->plans[0] = plan0;
    f->plans[0].volume.half_height = R(-1.0);
    EXPECT_ARG();
    f->plans[0] = plan0;
    f->plans[0].sigma_horizontal = R(-1.0);
    EXPECT_ARG();
    f->plans[0] = plan0;
    f->plans[0].sigma_vertical = inf;
    EXPECT_ARG();
    f->plans[0] = plan0;
    f->samples[0][3].y = nan;
    EXPECT_ARG();
    f->samples[0][3] = sample0;
    /* A sigma that overflows at the horizon. */
#ifndef COA_SINGLE_PRECISION
    f->plans[0].sigma_horizontal = R(1e308);
    EXPECT_ARG();
    f->plans[0] = plan0;
#endif
    /* Tracks and obstacles. */
    f->tracks[0].volume.radius = R(-1.0);
    EXPECT_ARG();
    f->tracks[0] = track0;
    f->tracks[0].sigma_vertical = R(-1.0);
    EXPECT_ARG();
    f->tracks[0] = track0;
    f->obstacles[0].kind = (coa_obstacle_kind_t)7;
    EXPECT_ARG();
    f->obstacles[0] = obs0;
    f->obstacles[0].kind = COA_OBSTACLE_BOX;
    f->obstacles[0].box.min.x = R(10.0);
    f->obstacles[0].box.max.x = R(0.0);
    EXPECT_ARG();
    f->obstacles[0].kind = COA_OBSTACLE_POLYTOPE;
    f->obstacles[0].polytope.vertices = f->hulls[0];
    f->obstacles[0].polytope.count = 3u;
    EXPECT_ARG();
    f->obstacles[0] = obs0;
    /* Pointers. */
    ck_assert_int_eq(coa_predict(NULL, &f->cfg, f->plans, f->n, f->obstacles, f->o, f->tracks, f->m,
                                 got, 64u, &res),
                     COA_ERR_ARGUMENT);
    ck_assert_int_eq(coa_predict(w.pr, NULL, f->plans, f->n, f->obstacles, f->o, f->tracks, f->m,
                                 got, 64u, &res),
                     COA_ERR_ARGUMENT);
    ck_assert_int_eq(
        coa_predict(w.pr, &f->cfg, NULL, f->n, f->obstacles, f->o, f->tracks, f->m, got, 64u, &res),
        COA_ERR_ARGUMENT);
    ck_assert_int_eq(
        coa_predict(w.pr, &f->cfg, f->plans, f->n, NULL, f->o, f->tracks, f->m, got, 64u, &res),
        COA_ERR_ARGUMENT);
    ck_assert_int_eq(
        coa_predict(w.pr, &f->cfg, f->plans, f->n, f->obstacles, f->o, NULL, f->m, got, 64u, &res),
        COA_ERR_ARGUMENT);
    ck_assert_int_eq(coa_predict(w.pr, &f->cfg, f->plans, f->n, f->obstacles, f->o, f->tracks, f->m,
                                 NULL, 64u, &res),
                     COA_ERR_ARGUMENT);
    ck_assert_int_eq(coa_predict(w.pr, &f->cfg, f->plans, f->n, f->obstacles, f->o, f->tracks, f->m,
                                 got, 64u, NULL),
                     COA_ERR_ARGUMENT);
    /* Nothing at all is fine. */
    ck_assert_int_eq(coa_predict(w.pr, &f->cfg, NULL, 0u, NULL, 0u, NULL, 0u, NULL, 0u, &res),
                     COA_OK);
    ck_assert_uint_eq(res.conflicts_found, 0u);
    /* And the good input still works. */
    for (i = 0; i < 2u; ++i) {
        ck_assert_int_eq(run(&w, f, i == 1u, got, 64u, &res), COA_OK);
    }
#undef EXPECT_ARG
    ws_free(&w);
    free(f);
}
END_TEST

/* ------------------------------------------------------------------------------------ */
/* Clusters                                                                              */

static coa_conflict_t edge(coa_conflict_kind_t kind, uint32_t a, uint32_t b)
{
    coa_conflict_t c;
    memset(&c, 0, sizeof c);
    c.kind = kind;
    c.a = a;
    c.b = b;
    return c;
}

START_TEST(clusters_are_connected_components)
{
    coa_conflict_t c[8];
    uint32_t cl[9];
    size_t count = 99u;
    uint64_t s = 3u;
    size_t round;

    /* {0, 3, 5} (via 3), {1, 2}, {6} alone with a track, {7} with an obstacle, 4 and 8
     * free; 2's obstacle conflict does not split or merge anything. */
    c[0] = edge(COA_CONFLICT_VEHICLE, 3u, 5u);
    c[1] = edge(COA_CONFLICT_VEHICLE, 1u, 2u);
    c[2] = edge(COA_CONFLICT_VEHICLE, 0u, 3u);
    c[3] = edge(COA_CONFLICT_TRACK, 6u, 0u);
    c[4] = edge(COA_CONFLICT_OBSTACLE, 7u, 3u);
    c[5] = edge(COA_CONFLICT_OBSTACLE, 2u, 100u);
    ck_assert_int_eq(coa_predict_clusters(c, 6u, 9u, cl, &count), COA_OK);
    ck_assert_uint_eq(count, 4u);
    ck_assert_uint_eq(cl[0], 0u);
    ck_assert_uint_eq(cl[3], 0u);
    ck_assert_uint_eq(cl[5], 0u);
    ck_assert_uint_eq(cl[1], 1u);
    ck_assert_uint_eq(cl[2], 1u);
    ck_assert_uint_eq(cl[6], 2u);
    ck_assert_uint_eq(cl[7], 3u);
    ck_assert_uint_eq(cl[4], COA_NO_CLUSTER);
    ck_assert_uint_eq(cl[8], COA_NO_CLUSTER);

    /* Errors leave cluster[] alone. */
    memset(cl, 0x11, sizeof cl);
    c[6] = edge(COA_CONFLICT_VEHICLE, 2u, 9u);
    ck_assert_int_eq(coa_predict_clusters(c, 7u, 9u, cl, &count), COA_ERR_ARGUMENT);
    c[6] = edge(COA_CONFLICT_TRACK, 9u, 0u);
    ck_assert_int_eq(coa_predict_clusters(c, 7u, 9u, cl, &count), COA_ERR_ARGUMENT);
    c[6] = edge((coa_conflict_kind_t)3, 1u, 2u);
    ck_assert_int_eq(coa_predict_clusters(c, 7u, 9u, cl, &count), COA_ERR_ARGUMENT);
    ck_assert_uint_eq(cl[0], 0x11111111u);
    ck_assert_int_eq(coa_predict_clusters(NULL, 1u, 9u, cl, &count), COA_ERR_ARGUMENT);
    ck_assert_int_eq(coa_predict_clusters(c, 6u, 9u, NULL, &count), COA_ERR_ARGUMENT);
    ck_assert_int_eq(coa_predict_clusters(c, 6u, 9u, cl, NULL), COA_ERR_ARGUMENT);
    ck_assert_int_eq(coa_predict_clusters(NULL, 0u, 0u, NULL, &count), COA_OK);
    ck_assert_uint_eq(count, 0u);

    /* Random graphs against a breadth-first search (labels by smallest member). */
    for (round = 0; round < 300u; ++round) {
        static coa_conflict_t e[400];
        static uint32_t got[200];
        static uint32_t want[200];
        static uint32_t queue[200];
        static bool involved[200];
        size_t n = 1u + pick(&s, 200u);
        size_t m = pick(&s, (uint32_t)(2u * n + 1u));
        size_t labels = 0u;
        size_t i;
        size_t j;

        memset(involved, 0, sizeof involved);
        for (i = 0; i < m; ++i) {
            uint32_t kind = pick(&s, 4u) == 0u ? 1u + pick(&s, 2u) : 0u;
            uint32_t a = pick(&s, (uint32_t)n);
            uint32_t b = kind == 0u ? pick(&s, (uint32_t)n) : pick(&s, 1000u);
            if (kind == 0u && a == b) {
                b = (a + 1u) % (uint32_t)n;
            }
            if (kind == 0u && a > b) {
                uint32_t t = a;
                a = b;
                b = t;
            }
            e[i] = edge((coa_conflict_kind_t)kind, a, b);
            involved[a] = true;
            if (kind == 0u) {
                involved[b] = true;
            }
        }
        for (i = 0; i < n; ++i) {
            want[i] = COA_NO_CLUSTER;
        }
        for (i = 0; i < n; ++i) {
            size_t head = 0u;
            size_t tail = 0u;
            if (!involved[i] || want[i] != COA_NO_CLUSTER) {
                continue;
            }
            want[i] = (uint32_t)labels;
            queue[tail++] = (uint32_t)i;
            while (head < tail) {
                uint32_t u = queue[head++];
                for (j = 0; j < m; ++j) {
                    uint32_t v;
                    if (e[j].kind != COA_CONFLICT_VEHICLE || (e[j].a != u && e[j].b != u)) {
                        continue;
                    }
                    v = e[j].a == u ? e[j].b : e[j].a;
                    if (want[v] == COA_NO_CLUSTER) {
                        want[v] = (uint32_t)labels;
                        queue[tail++] = v;
                    }
                }
            }
            ++labels;
        }
        REQUIRE(coa_predict_clusters(e, m, n, got, &count) == COA_OK);
        REQUIRE(count == labels);
        for (i = 0; i < n; ++i) {
            REQUIRE(got[i] == want[i]);
        }
    }
}
END_TEST

/* ------------------------------------------------------------------------------------ */

static Suite *predict_suite(void)
{
    Suite *s = suite_create("predict");
    TCase *tc = tcase_create("predict");
    tcase_set_timeout(tc, 300);
    tcase_add_test(tc, workspace_size_is_exact);
    tcase_add_test(tc, bad_config_and_plans_are_refused);
    tcase_add_test(tc, probability_closed_forms_and_edges);
    tcase_add_test(tc, probabilities_agree_with_monte_carlo);
    tcase_add_test(tc, plans_with_their_own_times_are_aligned);
    tcase_add_test(tc, resampling_matches_the_line_at_every_grid_time);
    tcase_add_test(tc, sigma_growth_crosses_the_threshold);
    tcase_add_test(tc, probability_is_the_combined_sigma_maximum);
    tcase_add_test(tc, probability_is_taken_at_the_closest_approach);
    tcase_add_test(tc, capacity_overflow_is_reported);
    tcase_add_test(tc, pair_set_limit_is_an_error_not_a_drop);
    tcase_add_test(tc, clusters_are_connected_components);
    tcase_add_test(tc, deterministic_conflicts_equal_the_planners_check);
    tcase_add_test(tc, separations_are_the_exact_minima);
    tcase_add_test(tc, broad_phase_finds_exactly_what_all_pairs_finds);
    tcase_add_test(tc, broad_phase_grid_handles_degenerate_scenes);
    suite_add_tcase(s, tc);
    return s;
}

int main(void)
{
    SRunner *sr = srunner_create(predict_suite());
    int failed;
    srunner_run_all(sr, CK_NORMAL);
    failed = srunner_ntests_failed(sr);
    srunner_free(sr);
    return failed == 0 ? EXIT_SUCCESS : EXIT_FAILURE;
}
