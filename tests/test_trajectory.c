/* SPDX-License-Identifier: MIT */
/*
 * test_trajectory.c: the trajectory module against hand-computed values, independent
 * oracles and a brute-force cost-to-go.
 */
#include <check.h>
#include <float.h>
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "coavoid/trajectory.h"

#ifdef COA_SINGLE_PRECISION
#define REAL_MAX FLT_MAX
#define REL_TOL 1e-5 /* float positions are a few ulps of coordinates up to ~1e4 */
#else
#define REAL_MAX DBL_MAX
#define REL_TOL 1e-9
#endif

#define R(x) ((coa_real_t)(x))

/* ------------------------------------------------------------------------------------ */
/* Helpers                                                                               */

static uint64_t rng_state;

static uint64_t rng_next(void)
{
    /* splitmix64: deterministic and good enough for test inputs. */
    uint64_t z = (rng_state += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
}

static double rng_uniform(double lo, double hi)
{
    return lo + (hi - lo) * ((double)(rng_next() >> 11) / 9007199254740992.0);
}

static uint32_t rng_below(uint32_t n)
{
    return (uint32_t)(rng_next() % n);
}

static int near(double got, double want)
{
    return fabs(got - want) <= REL_TOL * (1.0 + fabs(want));
}

#define ck_assert_vec_near(p, ex, ey, ez)                                                 \
    ck_assert_msg(near((double)(p).x, (ex)) && near((double)(p).y, (ey)) &&               \
                      near((double)(p).z, (ez)),                                          \
                  "got (%.12g, %.12g, %.12g), want (%.12g, %.12g, %.12g)", (double)(p).x, \
                  (double)(p).y, (double)(p).z, (double)(ex), (double)(ey), (double)(ez))

static int vec_same(coa_vec3_t a, coa_vec3_t b)
{
    return a.x == b.x && a.y == b.y && a.z == b.z;
}

static coa_vec3_t v3(double x, double y, double z)
{
    coa_vec3_t p;
    p.x = R(x);
    p.y = R(y);
    p.z = R(z);
    return p;
}

static coa_vehicle_t make_vehicle(const coa_vec3_t *route, size_t count, double cruise)
{
    coa_vehicle_t v;
    memset(&v, 0, sizeof v);
    v.id = 7;
    v.priority = 1;
    v.cruise_speed = R(cruise);
    v.climb_rate = R(2.0);
    v.steep_factor = 3;
    v.volume.radius = R(5.0);
    v.volume.half_height = R(2.0);
    v.route = route;
    v.route_count = count;
    v.initial_offset = 0;
    v.max_offset = -1;
    return v;
}

static coa_track_t make_track(void)
{
    coa_track_t tr;
    memset(&tr, 0, sizeof tr);
    tr.id = 900;
    tr.volume.radius = R(10.0);
    tr.volume.half_height = R(5.0);
    tr.position = v3(1, 2, 3);
    tr.velocity = v3(1, -1, 0.5);
    tr.path = NULL;
    tr.path_count = 0;
    tr.sigma_horizontal = R(0);
    tr.sigma_vertical = R(0);
    return tr;
}

/* A(a, b) * scale from the contract's formulas, asserting that it is an integer. */
static int64_t spec_area_scaled(int64_t a, int64_t b, int64_t scale)
{
    int64_t num;
    int64_t den;
    if (a * b >= 0) {
        num = (llabs(a) + llabs(b)) * scale;
        den = 2;
    } else {
        num = (a * a + b * b) * scale;
        den = 2 * llabs(a - b);
    }
    ck_assert_int_eq(num % den, 0);
    return num / den;
}

/* ------------------------------------------------------------------------------------ */
/* Reference trajectory                                                                  */

START_TEST(test_reference_straight_level)
{
    static coa_vec3_t route[2];
    coa_vehicle_t v;
    coa_vec3_t out[9];
    int k;

    route[0] = v3(0, 0, 100);
    route[1] = v3(100, 0, 100);
    v = make_vehicle(route, 2, 10.0);
    ck_assert_int_eq(coa_vehicle_check(&v), COA_OK);

    ck_assert(vec_same(coa_reference_at(&v, R(0)), route[0]));
    ck_assert_vec_near(coa_reference_at(&v, R(3)), 30, 0, 100);
    ck_assert_vec_near(coa_reference_at(&v, R(10)), 100, 0, 100);
    ck_assert_vec_near(coa_reference_at(&v, R(12)), 120, 0, 100);

    /* dt = 1.5 s, 8 steps: x = 15 k, past the end from k = 7. */
    ck_assert_int_eq(coa_reference_sample(&v, R(1.5), 8, out), COA_OK);
    for (k = 0; k <= 8; ++k) {
        ck_assert_vec_near(out[k], 15.0 * k, 0, 100);
    }
}
END_TEST

START_TEST(test_reference_climbing_leg)
{
    static coa_vec3_t route[2];
    coa_vehicle_t v;
    coa_vec3_t p4, p5;

    /* A 3-4-5 leg of horizontal length 50 m climbing 10 m. */
    route[0] = v3(0, 0, 0);
    route[1] = v3(30, 40, 10);
    v = make_vehicle(route, 2, 5.0);
    ck_assert_int_eq(coa_vehicle_check(&v), COA_OK);

    p4 = coa_reference_at(&v, R(4));
    p5 = coa_reference_at(&v, R(5));
    ck_assert_vec_near(p4, 12, 16, 4);
    ck_assert_vec_near(p5, 15, 20, 5);
    /* Horizontal speed is the cruise speed, not the 3D speed. */
    ck_assert(near(hypot((double)(p5.x - p4.x), (double)(p5.y - p4.y)), 5.0));
    ck_assert_vec_near(coa_reference_at(&v, R(10)), 30, 40, 10);
    /* Past the end: same direction, same slope (0.2 m per horizontal m). */
    ck_assert_vec_near(coa_reference_at(&v, R(12)), 36, 48, 12);
    ck_assert_vec_near(coa_reference_at(&v, R(20)), 60, 80, 20);
}
END_TEST

START_TEST(test_reference_multi_leg_corners)
{
    /* Legs: 50 m climbing 10 m, 60 m north climbing 30 m, 30 m west level. At 10 m/s the
     * corners are at t = 5, 11 and 14 s. */
    static coa_vec3_t route[4];
    coa_vehicle_t v;
    coa_vec3_t out[41];
    int k;

    route[0] = v3(0, 0, 0);
    route[1] = v3(30, 40, 10);
    route[2] = v3(30, 100, 40);
    route[3] = v3(0, 100, 40);
    v = make_vehicle(route, 4, 10.0);
    ck_assert_int_eq(coa_vehicle_check(&v), COA_OK);

    ck_assert_vec_near(coa_reference_at(&v, R(2.5)), 15, 20, 5);
    /* Exactly at a corner the route point itself comes back. */
    ck_assert(vec_same(coa_reference_at(&v, R(5)), route[1]));
    ck_assert_vec_near(coa_reference_at(&v, R(8)), 30, 70, 25);
    ck_assert(vec_same(coa_reference_at(&v, R(11)), route[2]));
    ck_assert_vec_near(coa_reference_at(&v, R(12.5)), 15, 100, 40);
    ck_assert_vec_near(coa_reference_at(&v, R(14)), 0, 100, 40);
    ck_assert_vec_near(coa_reference_at(&v, R(16)), -20, 100, 40);
    ck_assert_vec_near(coa_reference_at(&v, R(20)), -60, 100, 40);

    ck_assert_int_eq(coa_reference_sample(&v, R(0.5), 40, out), COA_OK);
    ck_assert(vec_same(out[0], route[0]));
    ck_assert_vec_near(out[5], 15, 20, 5);
    ck_assert(vec_same(out[10], route[1]));
    ck_assert_vec_near(out[11], 30, 45, 12.5);
    ck_assert_vec_near(out[16], 30, 70, 25);
    ck_assert(vec_same(out[22], route[2]));
    ck_assert_vec_near(out[25], 15, 100, 40);
    ck_assert_vec_near(out[28], 0, 100, 40);
    ck_assert_vec_near(out[32], -20, 100, 40);
    ck_assert_vec_near(out[40], -60, 100, 40);
    for (k = 0; k <= 40; ++k) {
        ck_assert(vec_same(out[k], coa_reference_at(&v, (coa_real_t)k * R(0.5))));
    }
}
END_TEST

START_TEST(test_reference_extrapolates_last_slope)
{
    /* The last leg runs north climbing 0.5 m per horizontal m; the first leg is level. */
    static coa_vec3_t route[3];
    coa_vehicle_t v;
    coa_vec3_t out[5];

    route[0] = v3(0, 0, 0);
    route[1] = v3(10, 0, 0);
    route[2] = v3(10, 20, 10);
    v = make_vehicle(route, 3, 5.0);
    ck_assert_vec_near(coa_reference_at(&v, R(6)), 10, 20, 10);
    ck_assert_vec_near(coa_reference_at(&v, R(10)), 10, 40, 20);
    ck_assert_vec_near(coa_reference_at(&v, R(100)), 10, 490, 245);

    /* dt = 2.5 s: d = 0, 12.5, 25, 37.5, 50. */
    ck_assert_int_eq(coa_reference_sample(&v, R(2.5), 4, out), COA_OK);
    ck_assert_vec_near(out[0], 0, 0, 0);
    ck_assert_vec_near(out[1], 10, 2.5, 1.25);
    ck_assert_vec_near(out[2], 10, 15, 7.5);
    ck_assert_vec_near(out[3], 10, 27.5, 13.75);
    ck_assert_vec_near(out[4], 10, 40, 20);
}
END_TEST

/* Independent oracle: which leg holds distance d, and the point there, in long double. */
static size_t oracle_leg(const coa_vec3_t *route, size_t n, long double d, long double *cum_out)
{
    long double cum = 0.0L;
    size_t i;
    for (i = 0; i + 2u < n; ++i) {
        long double len = hypotl((long double)route[i + 1].x - route[i].x,
                                 (long double)route[i + 1].y - route[i].y);
        if (d < cum + len) {
            break;
        }
        cum += len;
    }
    *cum_out = cum;
    return i;
}

START_TEST(test_reference_random_routes)
{
    static coa_vec3_t route[8];
    static coa_vec3_t out[COA_MAX_HORIZON + 1];
    int trial;

    rng_state = 0x5EED0001u;
    for (trial = 0; trial < 300; ++trial) {
        size_t n = 2u + rng_below(7);
        size_t i;
        uint32_t horizon = 1u + rng_below(trial % 10 == 0 ? 3000u : 200u);
        coa_real_t dt = R(rng_uniform(0.05, 2.0));
        coa_vehicle_t v;
        uint32_t k;

        for (i = 0; i < n; ++i) {
            do {
                route[i] =
                    v3(rng_uniform(-1000, 1000), rng_uniform(-1000, 1000), rng_uniform(0, 300));
            } while (i > 0 && hypot((double)(route[i].x - route[i - 1].x),
                                    (double)(route[i].y - route[i - 1].y)) < 1.0);
        }
        v = make_vehicle(route, n, rng_uniform(1, 50));
        ck_assert_int_eq(coa_vehicle_check(&v), COA_OK);
        ck_assert_int_eq(coa_reference_sample(&v, dt, horizon, out), COA_OK);

        for (k = 0; k <= horizon; ++k) {
            coa_real_t t = (coa_real_t)k * dt;
            long double d = (long double)v.cruise_speed * (long double)t;
            long double cum;
            size_t leg = oracle_leg(route, n, d, &cum);
            long double len = hypotl((long double)route[leg + 1].x - route[leg].x,
                                     (long double)route[leg + 1].y - route[leg].y);
            long double u = (d - cum) / len;
            double ex = (double)(route[leg].x + u * ((long double)route[leg + 1].x - route[leg].x));
            double ey = (double)(route[leg].y + u * ((long double)route[leg + 1].y - route[leg].y));
            double ez = (double)(route[leg].z + u * ((long double)route[leg + 1].z - route[leg].z));
            /* Scale the tolerance by the distance covered: float positions far out are
             * only as good as their magnitude. */
            double scale = 1.0 + (double)d;

            ck_assert_msg(vec_same(out[k], coa_reference_at(&v, t)),
                          "trial %d k %u: sample differs from coa_reference_at", trial, k);
            ck_assert_msg(fabs((double)out[k].x - ex) <= REL_TOL * scale * 10 &&
                              fabs((double)out[k].y - ey) <= REL_TOL * scale * 10 &&
                              fabs((double)out[k].z - ez) <= REL_TOL * scale * 10,
                          "trial %d k %u: (%g %g %g) vs oracle (%g %g %g)", trial, k,
                          (double)out[k].x, (double)out[k].y, (double)out[k].z, ex, ey, ez);
            /* Distance along the route: the leg start's arc length plus the horizontal
             * distance from it, which must be cruise_speed * t. */
            {
                double along = (double)cum + hypot((double)(out[k].x - route[leg].x),
                                                   (double)(out[k].y - route[leg].y));
                ck_assert_msg(fabs(along - (double)d) <= REL_TOL * scale * 10,
                              "trial %d k %u: along %g want %g", trial, k, along, (double)d);
            }
            /* Two samples on the same leg are exactly cruise_speed * dt apart horizontally. */
            if (k > 0) {
                long double cum_prev;
                long double d_prev =
                    (long double)v.cruise_speed * (long double)((coa_real_t)(k - 1) * dt);
                if (oracle_leg(route, n, d_prev, &cum_prev) == leg) {
                    double h =
                        hypot((double)(out[k].x - out[k - 1].x), (double)(out[k].y - out[k - 1].y));
                    ck_assert(fabs(h - (double)(d - d_prev)) <= REL_TOL * scale * 10);
                }
            }
        }
    }
}
END_TEST

START_TEST(test_reference_sample_errors)
{
    static coa_vec3_t route[2];
    static coa_vec3_t out[COA_MAX_HORIZON + 2];
    coa_vehicle_t v;
    coa_vehicle_t bad;

    route[0] = v3(0, 0, 0);
    route[1] = v3(100, 0, 0);
    v = make_vehicle(route, 2, 10.0);
    ck_assert_int_eq(coa_reference_sample(&v, R(1), 1, out), COA_OK);
    ck_assert_int_eq(coa_reference_sample(&v, R(1), COA_MAX_HORIZON, out), COA_OK);
    ck_assert_int_eq(coa_reference_sample(NULL, R(1), 10, out), COA_ERR_ARGUMENT);
    ck_assert_int_eq(coa_reference_sample(&v, R(1), 10, NULL), COA_ERR_ARGUMENT);
    ck_assert_int_eq(coa_reference_sample(&v, R(0), 10, out), COA_ERR_ARGUMENT);
    ck_assert_int_eq(coa_reference_sample(&v, R(-1), 10, out), COA_ERR_ARGUMENT);
    ck_assert_int_eq(coa_reference_sample(&v, R(NAN), 10, out), COA_ERR_ARGUMENT);
    ck_assert_int_eq(coa_reference_sample(&v, R(INFINITY), 10, out), COA_ERR_ARGUMENT);
    ck_assert_int_eq(coa_reference_sample(&v, R(1), 0, out), COA_ERR_ARGUMENT);
    ck_assert_int_eq(coa_reference_sample(&v, R(1), COA_MAX_HORIZON + 1u, out), COA_ERR_ARGUMENT);
    bad = v;
    bad.route_count = 1;
    ck_assert_int_eq(coa_reference_sample(&bad, R(1), 10, out), COA_ERR_ARGUMENT);
    /* A finite dt whose samples overflow would hand the geometry infinities. */
    ck_assert_int_eq(coa_reference_sample(&v, R(REAL_MAX / 2), 2, out), COA_ERR_ARGUMENT);
}
END_TEST

/* ------------------------------------------------------------------------------------ */
/* Tracks                                                                                */

START_TEST(test_track_constant_velocity)
{
    coa_track_t tr = make_track();
    coa_vec3_t out[5];
    int k;

    ck_assert_int_eq(coa_track_check(&tr), COA_OK);
    ck_assert(vec_same(coa_track_at(&tr, R(0)), tr.position));
    ck_assert_vec_near(coa_track_at(&tr, R(2)), 3, 0, 4);
    ck_assert_int_eq(coa_track_sample(&tr, R(0.5), 4, out), COA_OK);
    for (k = 0; k <= 4; ++k) {
        ck_assert_vec_near(out[k], 1 + 0.5 * k, 2 - 0.5 * k, 3 + 0.25 * k);
    }
}
END_TEST

START_TEST(test_track_path)
{
    static coa_track_point_t path[3];
    coa_track_t tr = make_track();
    coa_vec3_t out[13];
    int k;

    path[0].t = R(1);
    path[0].p = v3(0, 0, 0);
    path[1].t = R(3);
    path[1].p = v3(4, 2, 0);
    path[2].t = R(4);
    path[2].p = v3(4, 2, 10);
    tr.path = path;
    tr.path_count = 3;
    ck_assert_int_eq(coa_track_check(&tr), COA_OK);

    /* Before the first point: the first leg's velocity (2, 1, 0). */
    ck_assert_vec_near(coa_track_at(&tr, R(0)), -2, -1, 0);
    ck_assert(vec_same(coa_track_at(&tr, R(1)), path[0].p));
    ck_assert_vec_near(coa_track_at(&tr, R(2)), 2, 1, 0);
    ck_assert(vec_same(coa_track_at(&tr, R(3)), path[1].p));
    ck_assert_vec_near(coa_track_at(&tr, R(3.5)), 4, 2, 5);
    ck_assert(vec_same(coa_track_at(&tr, R(4)), path[2].p));
    /* After the last point: the last leg's velocity (0, 0, 10). */
    ck_assert_vec_near(coa_track_at(&tr, R(6)), 4, 2, 30);

    ck_assert_int_eq(coa_track_sample(&tr, R(0.5), 12, out), COA_OK);
    ck_assert_vec_near(out[0], -2, -1, 0);
    ck_assert_vec_near(out[1], -1, -0.5, 0);
    ck_assert_vec_near(out[3], 1, 0.5, 0);
    ck_assert_vec_near(out[7], 4, 2, 5);
    ck_assert_vec_near(out[12], 4, 2, 30);
    for (k = 0; k <= 12; ++k) {
        ck_assert(vec_same(out[k], coa_track_at(&tr, (coa_real_t)k * R(0.5))));
    }
}
END_TEST

START_TEST(test_track_path_two_points_and_single)
{
    static coa_track_point_t path[2];
    coa_track_t tr = make_track();
    coa_vec3_t out[4];
    int k;

    /* A path in the past of t = 0: every sample is an extrapolation after its end. */
    path[0].t = R(-4);
    path[0].p = v3(0, 0, 50);
    path[1].t = R(-2);
    path[1].p = v3(10, 0, 50);
    tr.path = path;
    tr.path_count = 2;
    ck_assert_vec_near(coa_track_at(&tr, R(0)), 20, 0, 50);
    ck_assert_vec_near(coa_track_at(&tr, R(3)), 35, 0, 50);
    ck_assert_vec_near(coa_track_at(&tr, R(-3)), 5, 0, 50);
    ck_assert_vec_near(coa_track_at(&tr, R(-10)), -30, 0, 50);

    /* A single point is stationary whatever the velocity field says. */
    tr.path_count = 1;
    ck_assert_int_eq(coa_track_check(&tr), COA_OK);
    ck_assert(vec_same(coa_track_at(&tr, R(-5)), path[0].p));
    ck_assert(vec_same(coa_track_at(&tr, R(0)), path[0].p));
    ck_assert(vec_same(coa_track_at(&tr, R(100)), path[0].p));
    ck_assert_int_eq(coa_track_sample(&tr, R(1), 3, out), COA_OK);
    for (k = 0; k <= 3; ++k) {
        ck_assert(vec_same(out[k], path[0].p));
    }
}
END_TEST

START_TEST(test_track_random_paths_agree)
{
    static coa_track_point_t path[10];
    static coa_vec3_t out[501];
    int trial;

    rng_state = 0x5EED0002u;
    for (trial = 0; trial < 200; ++trial) {
        coa_track_t tr = make_track();
        size_t n = 1u + rng_below(10);
        size_t i;
        double t = rng_uniform(-20, 20);
        uint32_t horizon = 1u + rng_below(500);
        coa_real_t dt = R(rng_uniform(0.05, 1.0));
        uint32_t k;

        for (i = 0; i < n; ++i) {
            path[i].t = R(t);
            path[i].p = v3(rng_uniform(-500, 500), rng_uniform(-500, 500), rng_uniform(0, 300));
            t += rng_uniform(0.5, 20);
        }
        tr.path = path;
        tr.path_count = n;
        ck_assert_int_eq(coa_track_check(&tr), COA_OK);
        ck_assert_int_eq(coa_track_sample(&tr, dt, horizon, out), COA_OK);
        for (k = 0; k <= horizon; ++k) {
            ck_assert(vec_same(out[k], coa_track_at(&tr, (coa_real_t)k * dt)));
        }
        /* Between two path points the track is on the segment joining them. */
        for (i = 0; i + 1 < n; ++i) {
            coa_real_t tm = R(0.5) * (path[i].t + path[i + 1].t);
            coa_vec3_t p = coa_track_at(&tr, tm);
            double u =
                ((double)tm - (double)path[i].t) / ((double)path[i + 1].t - (double)path[i].t);
            ck_assert(fabs((double)p.x -
                           ((double)path[i].p.x + u * ((double)path[i + 1].p.x - path[i].p.x))) <
                      REL_TOL * 1e3);
            ck_assert(fabs((double)p.z -
                           ((double)path[i].p.z + u * ((double)path[i + 1].p.z - path[i].p.z))) <
                      REL_TOL * 1e3);
        }
    }
}
END_TEST

START_TEST(test_track_sample_errors)
{
    coa_track_t tr = make_track();
    coa_track_t bad = tr;
    coa_vec3_t out[11];

    ck_assert_int_eq(coa_track_sample(NULL, R(1), 10, out), COA_ERR_ARGUMENT);
    ck_assert_int_eq(coa_track_sample(&tr, R(1), 10, NULL), COA_ERR_ARGUMENT);
    ck_assert_int_eq(coa_track_sample(&tr, R(0), 10, out), COA_ERR_ARGUMENT);
    ck_assert_int_eq(coa_track_sample(&tr, R(NAN), 10, out), COA_ERR_ARGUMENT);
    ck_assert_int_eq(coa_track_sample(&tr, R(1), 0, out), COA_ERR_ARGUMENT);
    ck_assert_int_eq(coa_track_sample(&tr, R(1), COA_MAX_HORIZON + 1u, out), COA_ERR_ARGUMENT);
    bad.volume.radius = R(0);
    ck_assert_int_eq(coa_track_sample(&bad, R(1), 10, out), COA_ERR_ARGUMENT);
    ck_assert_int_eq(coa_track_sample(&tr, R(REAL_MAX / 2), 3, out), COA_ERR_ARGUMENT);
    ck_assert_int_eq(coa_track_sample(&tr, R(1), 10, out), COA_OK);
}
END_TEST

/* ------------------------------------------------------------------------------------ */
/* Validation                                                                            */

START_TEST(test_vehicle_check)
{
    static coa_vec3_t route[3];
    static coa_vec3_t flat[3];
    static coa_vec3_t huge[2];
    coa_vehicle_t good;
    coa_vehicle_t v;

    route[0] = v3(0, 0, 10);
    route[1] = v3(100, 0, 20);
    route[2] = v3(100, 50, 20);
    good = make_vehicle(route, 3, 10.0);
    ck_assert_int_eq(coa_vehicle_check(&good), COA_OK);
    ck_assert_int_eq(coa_vehicle_check(NULL), COA_ERR_ARGUMENT);

#define EXPECT_BAD(stmt)                                                                 \
    do {                                                                                 \
        v = good;                                                                        \
        stmt;                                                                            \
        ck_assert_msg(coa_vehicle_check(&v) == COA_ERR_ARGUMENT, "accepted: %s", #stmt); \
    } while (0)
#define EXPECT_OK(stmt)                                                        \
    do {                                                                       \
        v = good;                                                              \
        stmt;                                                                  \
        ck_assert_msg(coa_vehicle_check(&v) == COA_OK, "rejected: %s", #stmt); \
    } while (0)

    EXPECT_BAD(v.id = 0);
    EXPECT_BAD(v.priority = 0);
    EXPECT_OK(v.id = 65535);
    EXPECT_BAD(v.cruise_speed = R(NAN));
    EXPECT_BAD(v.cruise_speed = R(INFINITY));
    EXPECT_BAD(v.cruise_speed = R(0));
    EXPECT_BAD(v.cruise_speed = R(-10));
    EXPECT_BAD(v.climb_rate = R(NAN));
    EXPECT_BAD(v.climb_rate = R(-INFINITY));
    EXPECT_BAD(v.climb_rate = R(0));
    EXPECT_BAD(v.climb_rate = R(-1));
    EXPECT_BAD(v.steep_factor = 0);
    EXPECT_BAD(v.steep_factor = 1);
    EXPECT_BAD(v.steep_factor = 11);
    EXPECT_OK(v.steep_factor = 2);
    EXPECT_OK(v.steep_factor = COA_MAX_STEEP_FACTOR);
    EXPECT_BAD(v.volume.radius = R(0));
    EXPECT_BAD(v.volume.radius = R(-1));
    EXPECT_BAD(v.volume.radius = R(NAN));
    EXPECT_BAD(v.volume.half_height = R(0));
    EXPECT_BAD(v.volume.half_height = R(INFINITY));
    EXPECT_BAD(v.route = NULL);
    EXPECT_BAD(v.route_count = 0);
    EXPECT_BAD(v.route_count = 1);
    EXPECT_OK(v.route_count = 2);

    /* Route points: every coordinate finite; every leg with a horizontal length. */
    memcpy(flat, route, sizeof route);
    flat[1].x = R(NAN);
    EXPECT_BAD(v.route = flat);
    memcpy(flat, route, sizeof route);
    flat[2].z = R(INFINITY);
    EXPECT_BAD(v.route = flat);
    memcpy(flat, route, sizeof route);
    flat[2] = v3(100, 0, 80); /* a vertical leg */
    EXPECT_BAD(v.route = flat);
    memcpy(flat, route, sizeof route);
    flat[1] = flat[0]; /* a repeated point */
    EXPECT_BAD(v.route = flat);
    /* Finite points whose leg length overflows. */
    huge[0] = v3(-(double)REAL_MAX, 0, 0);
    huge[1] = v3((double)REAL_MAX, 0, 0);
    EXPECT_BAD(v.route = huge; v.route_count = 2);

    /* Offsets. */
    EXPECT_OK(v.initial_offset = 5; v.max_offset = 5);
    EXPECT_OK(v.initial_offset = -5; v.max_offset = 5);
    EXPECT_BAD(v.initial_offset = 6; v.max_offset = 5);
    EXPECT_BAD(v.initial_offset = -6; v.max_offset = 5);
    EXPECT_BAD(v.initial_offset = 1; v.max_offset = 0);
    EXPECT_OK(v.initial_offset = 0; v.max_offset = 0);
    EXPECT_OK(v.initial_offset = COA_MAX_OFFSET; v.max_offset = -1);
    EXPECT_OK(v.initial_offset = -COA_MAX_OFFSET; v.max_offset = -1);
    EXPECT_BAD(v.initial_offset = COA_MAX_OFFSET + 1; v.max_offset = -1);
    EXPECT_BAD(v.initial_offset = -COA_MAX_OFFSET - 1; v.max_offset = -1);
    EXPECT_BAD(v.initial_offset = INT32_MIN; v.max_offset = -1);
    EXPECT_BAD(v.initial_offset = COA_MAX_OFFSET + 1; v.max_offset = INT32_MAX);
#undef EXPECT_BAD
#undef EXPECT_OK
}
END_TEST

START_TEST(test_track_check)
{
    static coa_track_point_t path[3];
    static coa_track_point_t bad_path[3];
    coa_track_t good = make_track();
    coa_track_t tr;

    path[0].t = R(0);
    path[0].p = v3(0, 0, 0);
    path[1].t = R(1);
    path[1].p = v3(1, 0, 0);
    path[2].t = R(2);
    path[2].p = v3(2, 0, 0);
    ck_assert_int_eq(coa_track_check(&good), COA_OK);
    ck_assert_int_eq(coa_track_check(NULL), COA_ERR_ARGUMENT);

#define EXPECT_BAD(stmt)                                                                \
    do {                                                                                \
        tr = good;                                                                      \
        stmt;                                                                           \
        ck_assert_msg(coa_track_check(&tr) == COA_ERR_ARGUMENT, "accepted: %s", #stmt); \
    } while (0)
#define EXPECT_OK(stmt)                                                       \
    do {                                                                      \
        tr = good;                                                            \
        stmt;                                                                 \
        ck_assert_msg(coa_track_check(&tr) == COA_OK, "rejected: %s", #stmt); \
    } while (0)

    EXPECT_BAD(tr.volume.radius = R(0));
    EXPECT_BAD(tr.volume.radius = R(-3));
    EXPECT_BAD(tr.volume.radius = R(NAN));
    EXPECT_BAD(tr.volume.half_height = R(0));
    EXPECT_BAD(tr.volume.half_height = R(INFINITY));
    EXPECT_BAD(tr.position.x = R(NAN));
    EXPECT_BAD(tr.position.z = R(-INFINITY));
    EXPECT_BAD(tr.velocity.y = R(NAN));
    EXPECT_BAD(tr.velocity.z = R(INFINITY));
    EXPECT_BAD(tr.sigma_horizontal = R(-1));
    EXPECT_BAD(tr.sigma_vertical = R(-0.001));
    EXPECT_BAD(tr.sigma_horizontal = R(NAN));
    EXPECT_BAD(tr.sigma_vertical = R(INFINITY));
    EXPECT_OK(tr.sigma_horizontal = R(3); tr.sigma_vertical = R(1));
    EXPECT_OK(tr.path = path; tr.path_count = 3);
    EXPECT_OK(tr.path = path; tr.path_count = 1);
    EXPECT_BAD(tr.path = NULL; tr.path_count = 2);

    memcpy(bad_path, path, sizeof path);
    bad_path[2].t = R(1); /* equal times */
    EXPECT_BAD(tr.path = bad_path; tr.path_count = 3);
    memcpy(bad_path, path, sizeof path);
    bad_path[1].t = R(3); /* descending */
    EXPECT_BAD(tr.path = bad_path; tr.path_count = 3);
    memcpy(bad_path, path, sizeof path);
    bad_path[1].t = R(NAN);
    EXPECT_BAD(tr.path = bad_path; tr.path_count = 3);
    memcpy(bad_path, path, sizeof path);
    bad_path[0].t = R(-INFINITY);
    EXPECT_BAD(tr.path = bad_path; tr.path_count = 3);
    memcpy(bad_path, path, sizeof path);
    bad_path[2].p.y = R(NAN);
    EXPECT_BAD(tr.path = bad_path; tr.path_count = 3);
    memcpy(bad_path, path, sizeof path);
    bad_path[0].p.x = R(-(double)REAL_MAX);
    bad_path[1].p.x = R(REAL_MAX); /* a leg whose displacement overflows */
    EXPECT_BAD(tr.path = bad_path; tr.path_count = 3);
#undef EXPECT_BAD
#undef EXPECT_OK
}
END_TEST

/* ------------------------------------------------------------------------------------ */
/* Actions                                                                               */

START_TEST(test_actions)
{
    static const char *const names[5] = {"level", "climb", "dive", "steep_climb", "steep_dive"};
    static const int32_t delta3[5] = {0, 1, -1, 3, -3};
    static const uint32_t effort[5] = {0, 1, 1, 3, 3};
    coa_vehicle_t v;
    int i;

    memset(&v, 0, sizeof v);
    v.climb_rate = R(2.5);
    ck_assert(near((double)coa_climb_step(&v, R(0.4)), 1.0));

    for (i = 0; i < 5; ++i) {
        coa_action_t a = (coa_action_t)i;
        ck_assert_int_eq(coa_action_delta(a, 3), delta3[i]);
        ck_assert_uint_eq(coa_action_effort(a), effort[i]);
        ck_assert_str_eq(coa_action_name(a), names[i]);
        ck_assert_int_eq(coa_action_between(100, 100 + delta3[i], 3), i);
        ck_assert_int_eq(coa_action_between(-7, -7 + delta3[i], 3), i);
    }
    ck_assert_int_eq(coa_action_delta(COA_ACTION_STEEP_CLIMB, 10), 10);
    ck_assert_int_eq(coa_action_delta(COA_ACTION_STEEP_DIVE, 2), -2);
    ck_assert_int_eq(coa_action_delta((coa_action_t)9, 3), 0);
    ck_assert_uint_eq(coa_action_effort((coa_action_t)9), 0);
    ck_assert_ptr_nonnull(coa_action_name((coa_action_t)9));
    ck_assert_int_eq(coa_action_between(0, 2, 3), -1);
    ck_assert_int_eq(coa_action_between(0, -4, 3), -1);
    ck_assert_int_eq(coa_action_between(0, 2, 2), COA_ACTION_STEEP_CLIMB);
    ck_assert_int_eq(coa_action_between(5, -5, 10), COA_ACTION_STEEP_DIVE);
    ck_assert_int_eq(coa_action_between(INT32_MAX, INT32_MIN, 3), -1);
}
END_TEST

/* ------------------------------------------------------------------------------------ */
/* Costs                                                                                 */

START_TEST(test_area_hand_values)
{
    ck_assert_double_eq(coa_area(0, 0), 0.0);
    ck_assert_double_eq(coa_area(0, 1), 0.5);
    ck_assert_double_eq(coa_area(1, 0), 0.5);
    ck_assert_double_eq(coa_area(1, 2), 1.5);
    ck_assert_double_eq(coa_area(2, 0), 1.0);
    ck_assert_double_eq(coa_area(-1, -3), 2.0);
    ck_assert_double_eq(coa_area(0, -3), 1.5);
    ck_assert_double_eq(coa_area(1, -1), 0.5);
    ck_assert_double_eq_tol(coa_area(2, -1), 5.0 / 6.0, 1e-15);
    ck_assert_double_eq_tol(coa_area(3, -1), 10.0 / 8.0, 1e-15);
    ck_assert_double_eq_tol(coa_area(1, -2), 5.0 / 6.0, 1e-15);
    ck_assert_double_eq_tol(coa_area(-2, 1), 5.0 / 6.0, 1e-15);

    ck_assert_int_eq(coa_area_scaled(0, 0, 4), 0);
    ck_assert_int_eq(coa_area_scaled(0, 1, 4), 2);
    ck_assert_int_eq(coa_area_scaled(1, 2, 4), 6);
    ck_assert_int_eq(coa_area_scaled(2, 0, 4), 4);
    ck_assert_int_eq(coa_area_scaled(-1, -3, 4), 8);
    ck_assert_int_eq(coa_area_scaled(1, -1, 4), 2);
    ck_assert_int_eq(coa_area_scaled(2, -1, 6), 5);
    ck_assert_int_eq(coa_area_scaled(3, -1, 8), 10);
    ck_assert_int_eq(coa_area_scaled(1, -2, 6), 5);
    ck_assert_int_eq(coa_area_scaled(2, -1, 5040), 4200);
    ck_assert_int_eq(coa_area_scaled(3, -1, 5040), 6300);
    ck_assert_int_eq(coa_area_scaled(-7, 3, 5040), 58 * 252);

    /* Large offsets: exact, no overflow. */
    ck_assert_int_eq(coa_area_scaled(32767, 32757, 5040), (int64_t)65524 * 2520);
    ck_assert_int_eq(coa_area_scaled(-32767, -32767, 5040), (int64_t)65534 * 2520);
    ck_assert_int_eq(coa_area_scaled(32767, -32767, 131068), (int64_t)2 * 32767 * 32767);
    ck_assert_int_eq(coa_area_scaled(32767, -32767, 131068u * 30u), (int64_t)60 * 32767 * 32767);
    ck_assert_int_eq(coa_area_scaled(INT32_MIN, INT32_MIN, 2), (int64_t)1 << 32);
}
END_TEST

START_TEST(test_area_scaled_matches_spec)
{
    /* Every step the actions allow, for every steep factor, at the largest problem scale. */
    uint32_t s;
    int32_t a;
    int i;

    for (s = 2; s <= COA_MAX_STEEP_FACTOR; ++s) {
        for (a = -40; a <= 40; ++a) {
            for (i = 0; i < 5; ++i) {
                int32_t b = a + coa_action_delta((coa_action_t)i, s);
                int64_t want = spec_area_scaled(a, b, 5040);
                ck_assert_int_eq(coa_area_scaled(a, b, 5040), want);
                ck_assert_int_eq(coa_area_scaled(a, b, 2 * s), spec_area_scaled(a, b, 2 * s));
                ck_assert_double_eq_tol(coa_area(a, b), (double)want / 5040.0, 1e-12);
            }
        }
    }
}
END_TEST

START_TEST(test_area_is_geometric_area)
{
    /* A(a, b) is the area between the straight profile from a to b and zero over one unit
     * step, checked by a fine midpoint sum; then the deviation of a concrete vehicle. */
    int32_t a, b;
    for (a = -6; a <= 6; ++a) {
        for (b = -6; b <= 6; ++b) {
            const int n = 20000;
            double sum = 0.0;
            int j;
            for (j = 0; j < n; ++j) {
                double x = (j + 0.5) / n;
                sum += fabs(a + (b - a) * x);
            }
            sum /= n;
            ck_assert_msg(fabs(sum - coa_area(a, b)) < 1e-6, "A(%d,%d)=%g, integral %g", a, b,
                          coa_area(a, b), sum);
        }
    }
    {
        /* 12 m/s, 3 m/s, dt 0.5 s: L = 6 m, dh = 1.5 m. From +2 to -1 climb steps the
         * profile goes from +3 m to -1.5 m and crosses the reference 4 m along: the area
         * is 4*3/2 + 2*1.5/2 = 7.5 m^2 = L * dh * A(2, -1). */
        static coa_vec3_t route[2];
        coa_vehicle_t v;
        double l, dh;
        route[0] = v3(0, 0, 0);
        route[1] = v3(100, 0, 0);
        v = make_vehicle(route, 2, 12.0);
        v.climb_rate = R(3);
        l = (double)(v.cruise_speed * R(0.5));
        dh = (double)coa_climb_step(&v, R(0.5));
        ck_assert_double_eq_tol(l, 6.0, 1e-12);
        ck_assert_double_eq_tol(dh, 1.5, 1e-12);
        ck_assert_double_eq_tol(l * dh * coa_area(2, -1), 7.5, 1e-12);
        ck_assert_double_eq_tol(l * dh * coa_area(2, 3), 6 * 1.5 * 2.5, 1e-12);
    }
}
END_TEST

START_TEST(test_heuristic_hand_values)
{
    /* s = 2, R = 3: |a| <= 6 is the triangle a^2/4, beyond the trapezoid 3|a| - 9. */
    ck_assert_int_eq(coa_heuristic_scaled(0, 3, 2, 4), 0);
    ck_assert_int_eq(coa_heuristic_scaled(4, 3, 2, 4), 16);
    ck_assert_int_eq(coa_heuristic_scaled(-4, 3, 2, 4), 16);
    ck_assert_int_eq(coa_heuristic_scaled(6, 3, 2, 4), 36);
    ck_assert_int_eq(coa_heuristic_scaled(7, 3, 2, 4), 48);
    ck_assert_int_eq(coa_heuristic_scaled(8, 3, 2, 4), 60);
    ck_assert_int_eq(coa_heuristic_scaled(-8, 3, 2, 5040), 15 * 5040);
    /* s = 3, R = 1, a = 5: 5 - 1.5 = 3.5. a = 1: 1/6. */
    ck_assert_int_eq(coa_heuristic_scaled(5, 1, 3, 6), 21);
    ck_assert_int_eq(coa_heuristic_scaled(1, 1, 3, 6), 1);
    ck_assert_int_eq(coa_heuristic_scaled(1, 1, 3, 5040), 840);
    /* No steps left: nothing to go. */
    ck_assert_int_eq(coa_heuristic_scaled(0, 0, 3, 6), 0);
    ck_assert_int_eq(coa_heuristic_scaled(1000, 0, 3, 6), 0);
    /* Large values stay exact: a^2/(2s) with a = 32767, s = 10, R = 10000. */
    ck_assert_int_eq(coa_heuristic_scaled(32767, 10000, 10, 5040), (int64_t)32767 * 32767 * 252);
    /* R = 100, s = 10, a = 32767: 100*32767 - 10*100^2/2 = 3226700. */
    ck_assert_int_eq(coa_heuristic_scaled(-32767, 100, 10, 5040), (int64_t)3226700 * 5040);
}
END_TEST

#define DP_A 60 /* offsets -DP_A..DP_A */
#define DP_R 6  /* steps left 0..DP_R */
#define DP_Q 15 /* offsets checked: -DP_Q..DP_Q */

START_TEST(test_heuristic_admissible_consistent)
{
    static int64_t cost[DP_R + 1][2 * DP_A + 1];
    uint32_t s;

    for (s = 2; s <= 5; ++s) {
        int which;
        for (which = 0; which < 2; ++which) {
            uint32_t scale = which == 0 ? 2 * s : 5040; /* the least scale, then the largest */
            int r;
            int32_t a;

            /* cost[r][a]: the least sum of A over r steps from offset a, any actions. */
            for (a = -DP_A; a <= DP_A; ++a) {
                cost[0][a + DP_A] = 0;
            }
            for (r = 1; r <= DP_R; ++r) {
                int32_t reach = DP_A - (int32_t)(r * (int)s);
                for (a = -DP_A; a <= DP_A; ++a) {
                    int64_t best = INT64_MAX;
                    int i;
                    if (a < -reach || a > reach) {
                        cost[r][a + DP_A] = -1;
                        continue;
                    }
                    for (i = 0; i < 5; ++i) {
                        int32_t b = a + coa_action_delta((coa_action_t)i, s);
                        int64_t c = spec_area_scaled(a, b, scale) + cost[r - 1][b + DP_A];
                        ck_assert(cost[r - 1][b + DP_A] >= 0);
                        if (c < best) {
                            best = c;
                        }
                    }
                    cost[r][a + DP_A] = best;
                }
            }

            for (r = 0; r <= DP_R; ++r) {
                for (a = -DP_Q; a <= DP_Q; ++a) {
                    int64_t h = coa_heuristic_scaled(a, (uint32_t)r, s, scale);
                    int i;
                    ck_assert(h >= 0);
                    ck_assert_msg(h <= cost[r][a + DP_A],
                                  "not admissible: s %u R %d a %d: H %lld > %lld", s, r, a,
                                  (long long)h, (long long)cost[r][a + DP_A]);
                    if (r == 0) {
                        ck_assert_int_eq(h, 0);
                        continue;
                    }
                    /* Tight where steep steps land exactly on the reference in time. */
                    if (a % (int32_t)s == 0 && abs(a) <= (int32_t)s * r) {
                        ck_assert_int_eq(h, cost[r][a + DP_A]);
                    }
                    for (i = 0; i < 5; ++i) {
                        int32_t b = a + coa_action_delta((coa_action_t)i, s);
                        int64_t step = coa_area_scaled(a, b, scale);
                        int64_t hb = coa_heuristic_scaled(b, (uint32_t)(r - 1), s, scale);
                        ck_assert_msg(h <= step + hb,
                                      "not consistent: s %u R %d a %d b %d: %lld > %lld + %lld", s,
                                      r, a, b, (long long)h, (long long)step, (long long)hb);
                    }
                    /* Exactly the truncated triangle. */
                    {
                        int64_t m = llabs(a);
                        int64_t want2s; /* H * 2s */
                        if (m <= (int64_t)s * r) {
                            want2s = m * m;
                        } else {
                            want2s = (int64_t)s * (2 * r * m - (int64_t)s * r * r);
                        }
                        ck_assert_int_eq(h, want2s * (int64_t)(scale / (2 * s)));
                    }
                }
            }
        }
    }
}
END_TEST

START_TEST(test_area_scale)
{
    static coa_vec3_t route[2];
    coa_vehicle_t vs[9];
    int i;

    route[0] = v3(0, 0, 0);
    route[1] = v3(1, 0, 0);
    for (i = 0; i < 9; ++i) {
        vs[i] = make_vehicle(route, 2, 10.0);
        vs[i].steep_factor = (uint32_t)(i + 2);
    }
    ck_assert_uint_eq(coa_area_scale(vs, 1), 4);      /* s = 2 */
    ck_assert_uint_eq(coa_area_scale(vs, 2), 12);     /* lcm(4, 6) */
    ck_assert_uint_eq(coa_area_scale(vs + 2, 1), 8);  /* s = 4 */
    ck_assert_uint_eq(coa_area_scale(vs, 9), 5040);   /* every s: 2 * lcm(2..10) */
    ck_assert_uint_eq(coa_area_scale(vs + 8, 1), 20); /* s = 10 */
    vs[3].steep_factor = 4;
    vs[4].steep_factor = 6;
    vs[5].steep_factor = 10;
    ck_assert_uint_eq(coa_area_scale(vs + 3, 3), 120); /* lcm(8, 12, 20) */
    vs[4].steep_factor = 4;
    vs[5].steep_factor = 4;
    ck_assert_uint_eq(coa_area_scale(vs + 3, 3), 8); /* repeated factors */
    ck_assert_uint_eq(coa_area_scale(vs, 0), 0);
    ck_assert_uint_eq(coa_area_scale(NULL, 3), 0);
    vs[1].steep_factor = 1;
    ck_assert_uint_eq(coa_area_scale(vs, 3), 0);
    vs[1].steep_factor = 11;
    ck_assert_uint_eq(coa_area_scale(vs, 3), 0);
}
END_TEST

/* Whether w == weight * 2^exponent exactly: ldexp of an integer of at most 64 bits is
 * exact when the integer is (it has at most 53 significant bits for a finite double). */
static int weight_is_exact(double w, uint64_t weight, int exponent)
{
    double m = (double)weight;
    if ((uint64_t)m != weight) {
        return 0; /* more than 53 significant bits: cannot be a double's mantissa */
    }
    return ldexp(m, exponent) == w;
}

static double product_of(const coa_vehicle_t *v, coa_real_t dt)
{
    double l = (double)v->cruise_speed * (double)dt;
    double dh = (double)v->climb_rate * (double)dt;
    return l * dh;
}

START_TEST(test_deviation_weights)
{
    static coa_vec3_t route[2];
    coa_vehicle_t vs[4];
    coa_vehicle_t bad[2];
    uint64_t w[4];
    int e = 99;
    int i;
    int trial;

    route[0] = v3(0, 0, 0);
    route[1] = v3(1, 0, 0);
    for (i = 0; i < 4; ++i) {
        vs[i] = make_vehicle(route, 2, 10.0);
    }
    /* Equal vehicles (L = 5, dh = 1): the weight 5 itself, no factor of two to move. */
    ck_assert_int_eq(coa_deviation_weights(vs, 4, R(0.5), w, &e), COA_OK);
    ck_assert_int_eq(e, 0);
    for (i = 0; i < 4; ++i) {
        ck_assert_uint_eq(w[i], 5u);
    }
    /* Twice L*dh (by speed or by climb rate): twice the weight, exactly. */
    vs[1].cruise_speed = R(20);
    vs[2].climb_rate = R(4);
    ck_assert_int_eq(coa_deviation_weights(vs, 4, R(0.5), w, &e), COA_OK);
    ck_assert_int_eq(e, 0);
    ck_assert_uint_eq(w[0], 5u);
    ck_assert_uint_eq(w[1], 10u);
    ck_assert_uint_eq(w[2], 10u);
    ck_assert_uint_eq(w[3], 5u);
    /* L*dh = 1.5 = 3 * 2^-1 moves the common exponent down: 5 becomes 10. */
    vs[3].cruise_speed = R(3);
    ck_assert_int_eq(coa_deviation_weights(vs, 4, R(0.5), w, &e), COA_OK);
    ck_assert_int_eq(e, -1);
    ck_assert_uint_eq(w[0], 10u);
    ck_assert_uint_eq(w[1], 20u);
    ck_assert_uint_eq(w[2], 20u);
    ck_assert_uint_eq(w[3], 3u);
    /* Common factors of two go to the exponent: 30 and 10 (the review's tie) are 15 and
     * 5 times 2. */
    vs[0].climb_rate = R(3);
    vs[1] = vs[0];
    vs[1].climb_rate = R(1);
    ck_assert_int_eq(coa_deviation_weights(vs, 2, R(1), w, &e), COA_OK);
    ck_assert_int_eq(e, 1);
    ck_assert_uint_eq(w[0], 15u);
    ck_assert_uint_eq(w[1], 5u);
    /* Powers of two far apart are still exact: 2^-30 * 2 against 10 * 2 = 5 * 2^2. */
    vs[1].cruise_speed = R(1.0 / 1073741824.0);
    vs[1].climb_rate = R(2);
    ck_assert_int_eq(coa_deviation_weights(vs, 2, R(1), w, &e), COA_OK);
    ck_assert_int_eq(e, -29);
    ck_assert_uint_eq(w[0], UINT64_C(15) << 30);
    ck_assert_uint_eq(w[1], 1u);
    /* A single vehicle: its odd mantissa. */
    ck_assert_int_eq(coa_deviation_weights(vs + 2, 1, R(0.5), w, &e), COA_OK);
    ck_assert_uint_eq(w[0], 5u);
    ck_assert_int_eq(e, 1);

    /* Random speeds, climb rates and dt: every weight is exactly w_i = W_i 2^E with w_i
     * the contract's double product, and some W_i is odd (E is as large as it can be). */
    rng_state = 0x77e1u;
    for (trial = 0; trial < 2000; ++trial) {
        coa_real_t dt = R(trial % 3 == 0 ? 1.0 : rng_uniform(0.1, 3.0));
        bool odd = false;
        int rc;
        for (i = 0; i < 4; ++i) {
            vs[i].cruise_speed =
                R(trial % 2 == 0 ? (double)(5u + rng_below(20u)) : rng_uniform(5.0, 30.0));
            vs[i].climb_rate =
                R(trial % 2 == 0 ? (double)(1u + rng_below(4u)) : rng_uniform(1.0, 6.0));
        }
        rc = coa_deviation_weights(vs, 4, dt, w, &e);
        ck_assert_int_eq(rc, COA_OK); /* ratios below 2^6: W_i fit in 54 + 6 bits */
        for (i = 0; i < 4; ++i) {
            ck_assert_msg(weight_is_exact(product_of(&vs[i], dt), w[i], e),
                          "trial %d vehicle %d: %.17g != %llu * 2^%d", trial, i,
                          product_of(&vs[i], dt), (unsigned long long)w[i], e);
            odd = odd || (w[i] & 1u) != 0u;
        }
        ck_assert(odd);
    }

    /* Full mantissas 2^13 apart need 53 + 13 bits: refused rather than rounded. */
    vs[0].cruise_speed = R(1.1);
    vs[0].climb_rate = R(1.3);
    vs[1] = vs[0];
    vs[1].cruise_speed = R(1.1 * 8192.0);
    {
        int ex;
        double m = frexp(product_of(&vs[0], R(0.7)), &ex);
        /* Precondition: the mantissa really has (almost) all 53 bits. */
        ck_assert(fmod(ldexp(m, 52), 2.0) != 0.0 || fmod(ldexp(m, 53), 2.0) != 0.0);
        ck_assert_double_eq(product_of(&vs[1], R(0.7)), 8192.0 * product_of(&vs[0], R(0.7)));
    }
    ck_assert_int_eq(coa_deviation_weights(vs, 2, R(0.7), w, &e), COA_ERR_RANGE);
    /* 2^9 apart fits (53 + 9 <= 64). */
    vs[1].cruise_speed = R(1.1 * 512.0);
    ck_assert_int_eq(coa_deviation_weights(vs, 2, R(0.7), w, &e), COA_OK);
    ck_assert_uint_eq(w[1], w[0] << 9);
    ck_assert(weight_is_exact(product_of(&vs[0], R(0.7)), w[0], e));

    /* Errors. */
    vs[0] = make_vehicle(route, 2, 10.0);
    ck_assert_int_eq(coa_deviation_weights(NULL, 1, R(0.5), w, &e), COA_ERR_ARGUMENT);
    ck_assert_int_eq(coa_deviation_weights(vs, 1, R(0.5), NULL, &e), COA_ERR_ARGUMENT);
    ck_assert_int_eq(coa_deviation_weights(vs, 1, R(0.5), w, NULL), COA_ERR_ARGUMENT);
    ck_assert_int_eq(coa_deviation_weights(vs, 0, R(0.5), w, &e), COA_ERR_ARGUMENT);
    ck_assert_int_eq(coa_deviation_weights(vs, 1, R(0), w, &e), COA_ERR_ARGUMENT);
    ck_assert_int_eq(coa_deviation_weights(vs, 1, R(-1), w, &e), COA_ERR_ARGUMENT);
    ck_assert_int_eq(coa_deviation_weights(vs, 1, R(NAN), w, &e), COA_ERR_ARGUMENT);
    ck_assert_int_eq(coa_deviation_weights(vs, 1, R(INFINITY), w, &e), COA_ERR_ARGUMENT);
    bad[0] = vs[0];
    bad[1] = vs[0];
    bad[1].cruise_speed = R(-10);
    ck_assert_int_eq(coa_deviation_weights(bad, 2, R(0.5), w, &e), COA_ERR_ARGUMENT);
    bad[1].climb_rate = R(-2); /* two negatives make a positive product */
    ck_assert_int_eq(coa_deviation_weights(bad, 2, R(0.5), w, &e), COA_ERR_ARGUMENT);
    bad[1] = vs[0];
    bad[1].climb_rate = R(0);
    ck_assert_int_eq(coa_deviation_weights(bad, 2, R(0.5), w, &e), COA_ERR_ARGUMENT);
    bad[1].climb_rate = R(NAN);
    ck_assert_int_eq(coa_deviation_weights(bad, 2, R(0.5), w, &e), COA_ERR_ARGUMENT);
#ifndef COA_SINGLE_PRECISION
    /* Finite speeds whose product overflows (float inputs cannot overflow a double). */
    bad[1] = vs[0];
    bad[1].cruise_speed = R(REAL_MAX);
    bad[1].climb_rate = R(REAL_MAX);
    ck_assert_int_eq(coa_deviation_weights(bad, 2, R(4), w, &e), COA_ERR_ARGUMENT);
    /* A subnormal product is still split exactly, and alone it is fine. */
    bad[1] = vs[0];
    bad[1].cruise_speed = R(1e-160);
    bad[1].climb_rate = R(1e-160);
    ck_assert_int_eq(coa_deviation_weights(bad + 1, 1, R(1), w, &e), COA_OK);
    ck_assert(weight_is_exact(product_of(&bad[1], R(1)), w[0], e));
    ck_assert_int_lt(e, -1022);
    ck_assert_int_eq(coa_deviation_weights(bad, 2, R(1), w, &e), COA_ERR_RANGE);
#endif
}
END_TEST

/* The 128-bit helpers against the compiler's own 128-bit integers (tests run on 64-bit
 * hosts; the core itself must not use them). */
#ifdef __SIZEOF_INT128__
/* __extension__: 128-bit integers are a GCC and Clang extension, fine in a host test. */
__extension__ typedef unsigned __int128 u128_t;

static u128_t to_u128(coa_cost_t c)
{
    return ((u128_t)c.hi << 64) | (u128_t)c.lo;
}

static coa_cost_t from_u128(u128_t x)
{
    coa_cost_t c;
    c.hi = (uint64_t)(x >> 64);
    c.lo = (uint64_t)x;
    return c;
}

START_TEST(test_cost_arithmetic)
{
    static const uint64_t edge[] = {0u,
                                    1u,
                                    2u,
                                    0xffffffffu,
                                    UINT64_C(0x100000000),
                                    UINT64_C(0x1ffffffff),
                                    UINT64_C(0x8000000000000000),
                                    UINT64_MAX - 1u,
                                    UINT64_MAX};
    const size_t ne = sizeof edge / sizeof edge[0];
    size_t i;
    size_t j;
    int trial;

    for (i = 0; i < ne; ++i) {
        for (j = 0; j < ne; ++j) {
            u128_t p = (u128_t)edge[i] * edge[j];
            ck_assert(to_u128(coa_cost_mul(edge[i], edge[j])) == p);
        }
    }
    /* (2^64 - 1)^2 = 2^128 - 2^65 + 1. */
    ck_assert_uint_eq(coa_cost_mul(UINT64_MAX, UINT64_MAX).hi, UINT64_MAX - 1u);
    ck_assert_uint_eq(coa_cost_mul(UINT64_MAX, UINT64_MAX).lo, 1u);
    /* The carry out of the low word. */
    {
        coa_cost_t a = {0u, UINT64_MAX};
        coa_cost_t b = {0u, 1u};
        coa_cost_t c = coa_cost_add(a, b);
        ck_assert_uint_eq(c.hi, 1u);
        ck_assert_uint_eq(c.lo, 0u);
        c = coa_cost_add(from_u128(((u128_t)1 << 127) - 1u), b);
        ck_assert(to_u128(c) == (u128_t)1 << 127);
    }
    rng_state = 0xc057u;
    for (trial = 0; trial < 200000; ++trial) {
        /* Mixed magnitudes, so carries and equal high words both occur often. */
        uint64_t a = rng_next() >> rng_below(64u);
        uint64_t b = rng_next() >> rng_below(64u);
        u128_t x = (u128_t)rng_next() << rng_below(64u) | rng_next();
        u128_t y = (trial % 4 == 0) ? x + (u128_t)(rng_below(3u)) - 1u
                                    : ((u128_t)rng_next() << rng_below(64u) | rng_next());
        int want;
        ck_assert(to_u128(coa_cost_mul(a, b)) == (u128_t)a * b);
        x >>= 1; /* keep the sum below 2^128 (the precondition) */
        y >>= 1;
        ck_assert(to_u128(coa_cost_add(from_u128(x), from_u128(y))) == x + y);
        want = x < y ? -1 : x > y ? 1 : 0;
        ck_assert_int_eq(coa_cost_compare(from_u128(x), from_u128(y)), want);
    }
    ck_assert_int_eq(coa_cost_compare(from_u128(5u), from_u128(5u)), 0);
    ck_assert_int_eq(coa_cost_compare(from_u128((u128_t)1 << 64), from_u128(UINT64_MAX)), 1);
    ck_assert_int_eq(coa_cost_compare(from_u128(UINT64_MAX), from_u128((u128_t)1 << 64)), -1);
}
END_TEST
#endif

static Suite *trajectory_suite(void)
{
    Suite *s = suite_create("trajectory");
    TCase *ref = tcase_create("reference");
    TCase *track = tcase_create("track");
    TCase *check = tcase_create("check");
    TCase *cost = tcase_create("cost");

    tcase_add_test(ref, test_reference_straight_level);
    tcase_add_test(ref, test_reference_climbing_leg);
    tcase_add_test(ref, test_reference_multi_leg_corners);
    tcase_add_test(ref, test_reference_extrapolates_last_slope);
    tcase_add_test(ref, test_reference_random_routes);
    tcase_add_test(ref, test_reference_sample_errors);
    suite_add_tcase(s, ref);

    tcase_add_test(track, test_track_constant_velocity);
    tcase_add_test(track, test_track_path);
    tcase_add_test(track, test_track_path_two_points_and_single);
    tcase_add_test(track, test_track_random_paths_agree);
    tcase_add_test(track, test_track_sample_errors);
    suite_add_tcase(s, track);

    tcase_add_test(check, test_vehicle_check);
    tcase_add_test(check, test_track_check);
    suite_add_tcase(s, check);

    tcase_add_test(cost, test_actions);
    tcase_add_test(cost, test_area_hand_values);
    tcase_add_test(cost, test_area_scaled_matches_spec);
    tcase_add_test(cost, test_area_is_geometric_area);
    tcase_add_test(cost, test_heuristic_hand_values);
    tcase_add_test(cost, test_heuristic_admissible_consistent);
    tcase_add_test(cost, test_area_scale);
    tcase_add_test(cost, test_deviation_weights);
#ifdef __SIZEOF_INT128__
    tcase_add_test(cost, test_cost_arithmetic);
#endif
    suite_add_tcase(s, cost);
    return s;
}

int main(void)
{
    SRunner *sr = srunner_create(trajectory_suite());
    int failed;

    srunner_run_all(sr, CK_NORMAL);
    failed = srunner_ntests_failed(sr);
    srunner_free(sr);
    return failed == 0 ? EXIT_SUCCESS : EXIT_FAILURE;
}
