/* SPDX-License-Identifier: MIT */
/*
 * LCM messages: every type round-trips through encode/decode and through the core
 * types; each validation rule refuses its bad message; an accepted intent is one the
 * planner accepts and plans with the positions its sender computed, bit for bit;
 * decoding random, truncated and corrupted bytes never crashes (run under the
 * sanitizers); receive counters for the status message.
 */
#include <check.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "auth.h"
#include "coavoid_lcm.h"
#include "lcm_examples.h"
#include "test_support.h"

#include <math.h>

static uint64_t rng_state;
static uint64_t rng_next(void)
{
    return splitmix(&rng_state);
}

/* Encodes `m` of a generated type, decodes it into a zeroed struct and compares bytes
 * (fixed-size arrays only, so the structs hold no pointers). */
#define ROUND_TRIP(type, m)                                             \
    do {                                                                \
        type back_;                                                     \
        int size_ = type##_encoded_size(&(m));                          \
        unsigned char *buf_ = malloc((size_t)size_);                    \
        ck_assert_ptr_nonnull(buf_);                                    \
        ck_assert_int_eq(type##_encode(buf_, 0, size_, &(m)), size_);   \
        memset(&back_, 0, sizeof back_);                                \
        ck_assert_int_eq(type##_decode(buf_, 0, size_, &back_), size_); \
        ck_assert_int_eq(memcmp(&back_, &(m), sizeof back_), 0);        \
        type##_decode_cleanup(&back_);                                  \
        free(buf_);                                                     \
    } while (0)

START_TEST(test_round_trip_wire)
{
    coavoid_intent_t i = good_intent();
    coavoid_plan_t p = good_plan();
    coavoid_track_t t = good_track();
    coavoid_obstacle_map_t o = good_map();
    coavoid_conflict_report_t c = good_report();
    coavoid_status_t s = good_status();
    coavoid_lcm_context_t ctx = ctx_now();
    const char *why = NULL;
    ck_assert_int_eq(coavoid_lcm_intent_check(&i, &ctx, &why), COA_OK);
    ck_assert_int_eq(coavoid_lcm_plan_check(&p, &ctx, &why), COA_OK);
    ck_assert_int_eq(coavoid_lcm_track_check(&t, &ctx, &why), COA_OK);
    ck_assert_int_eq(coavoid_lcm_obstacle_map_check(&o, &ctx, &why), COA_OK);
    ck_assert_int_eq(coavoid_lcm_conflict_report_check(&c, &ctx, &why), COA_OK);
    ck_assert_int_eq(coavoid_lcm_status_check(&s, &ctx, &why), COA_OK);
    ck_assert_str_eq(why, "ok");
    ROUND_TRIP(coavoid_intent_t, i);
    ROUND_TRIP(coavoid_plan_t, p);
    ROUND_TRIP(coavoid_track_t, t);
    ROUND_TRIP(coavoid_obstacle_map_t, o);
    ROUND_TRIP(coavoid_conflict_report_t, c);
    ROUND_TRIP(coavoid_status_t, s);
}
END_TEST

/* The core's views of an intent, as a receiver holds them. */
typedef struct {
    coavoid_lcm_intent_info_t info;
    coa_vehicle_t vehicle;
    coa_intent_plan_t plan;
    coavoid_lcm_intent_arrays_t arrays;
} intent_view_t;

static int intent_view(const coavoid_intent_t *m, intent_view_t *v, const char **why)
{
    coavoid_lcm_context_t ctx = ctx_now();
    memset(v, 0, sizeof *v);
    return coavoid_lcm_intent_to_core(m, &ctx, NULL, &v->info, &v->vehicle, &v->plan, &v->arrays,
                                      why);
}

/* Bits, not values: -0.0 == 0.0 and the test is about the last bit. */
static bool same_vec(coa_vec3_t a, coa_vec3_t b)
{
    return memcmp(&a.x, &b.x, sizeof a.x) == 0 && memcmp(&a.y, &b.y, sizeof a.y) == 0 &&
           memcmp(&a.z, &b.z, sizeof a.z) == 0;
}

static coa_vec3_t vec_from(const double v[3])
{
    coa_vec3_t r;
    r.x = (coa_real_t)v[0];
    r.y = (coa_real_t)v[1];
    r.z = (coa_real_t)v[2];
    return r;
}

/* A one-vehicle planning problem over an intent's reference, as a coordinator builds it. */
static coa_problem_t intent_problem(const intent_view_t *v, const coa_vec3_t *const *references)
{
    coa_problem_t p;
    memset(&p, 0, sizeof p);
    p.dt = v->info.step;
    p.horizon = (uint32_t)(v->plan.count - 1u);
    p.vehicles = &v->vehicle;
    p.vehicle_count = 1u;
    p.references = references;
    return p;
}

START_TEST(test_round_trip_intent_core)
{
    coavoid_intent_t m = good_intent();
    coavoid_intent_t back;
    coavoid_lcm_context_t ctx = ctx_now();
    intent_view_t *v = malloc(sizeof *v);
    intent_view_t *w = malloc(sizeof *w);
    coa_real_t dh;
    coa_vehicle_t unbounded;
    int32_t j;
    const char *why = NULL;
    ck_assert_ptr_nonnull(v);
    ck_assert_ptr_nonnull(w);
    ck_assert_int_eq(intent_view(&m, v, &why), COA_OK);
    ck_assert_str_eq(why, "ok");

    /* The vehicle a coordinator re-plans: every performance field, the reference as its
     * route, and the offset it flies now. */
    ck_assert_uint_eq(v->vehicle.id, 7u);
    ck_assert_uint_eq(v->vehicle.priority, 2u);
    ck_assert(v->vehicle.cruise_speed == (coa_real_t)18.0);
    ck_assert(v->vehicle.climb_rate == (coa_real_t)1.8);
    ck_assert_uint_eq(v->vehicle.steep_factor, 3u);
    ck_assert(v->vehicle.volume.radius == (coa_real_t)30.0);
    ck_assert(v->vehicle.volume.half_height == (coa_real_t)10.0);
    ck_assert_int_eq(v->vehicle.max_offset, 40);
    ck_assert_int_eq(v->vehicle.initial_offset, -2);
    ck_assert_ptr_eq(v->vehicle.route, v->arrays.reference);
    ck_assert_uint_eq(v->vehicle.route_count, 31u);
    ck_assert_int_eq(coa_vehicle_check(&v->vehicle), COA_OK);

    ck_assert(v->info.utime == m.utime);
    ck_assert(v->info.sequence == 42);
    ck_assert_int_eq(v->info.mode, COAVOID_INTENT_T_MODE_DECOUPLED);
    ck_assert(same_vec(v->info.position, vec_from(m.position)));
    ck_assert(same_vec(v->info.velocity, vec_from(m.velocity)));
    ck_assert(v->info.plan_utime == m.plan_utime);
    ck_assert(v->info.step == (coa_real_t)0.9);
    ck_assert(v->info.sigma_horizontal == (coa_real_t)5.0);
    ck_assert(v->info.sigma_vertical == (coa_real_t)2.5);
    ck_assert_int_eq(v->info.rank, 3);

    ck_assert_uint_eq(v->plan.id, 7u);
    ck_assert_uint_eq(v->plan.count, 31u);
    ck_assert_ptr_eq(v->plan.samples, v->arrays.samples);
    ck_assert(fabs((double)v->plan.t0 - 4.5) < 1e-6);
    ck_assert(v->plan.step == v->info.step);
    ck_assert(v->plan.volume.radius == v->vehicle.volume.radius);
    ck_assert(v->plan.sigma_vertical == (coa_real_t)2.5);

    /* Positions as the planner computes them (plan.c, vehicle_sweep): the reference in
     * core precision, plus the offset times the climb step of the problem's dt. */
    dh = coa_climb_step(&v->vehicle, v->info.step);
    ck_assert(dh == (coa_real_t)1.8 * (coa_real_t)0.9);
    for (j = 0; j < m.sample_count; ++j) {
        coa_vec3_t ref = vec_from(m.reference[j]);
        coa_vec3_t expect = ref;
        expect.z = ref.z + (coa_real_t)m.offsets[j] * dh;
        ck_assert(same_vec(v->arrays.reference[j], ref));
        ck_assert_int_eq(v->arrays.offsets[j], m.offsets[j]);
        ck_assert(same_vec(v->arrays.samples[j], expect));
    }
    /* And back: the sender's message, bit for bit in double; in float, a message that
     * gives the same core views again. */
    ck_assert_int_eq(coavoid_lcm_intent_from_core(&v->vehicle, &v->info, v->arrays.reference,
                                                  v->arrays.offsets, v->plan.count, &ctx, &back,
                                                  &why),
                     COA_OK);
#ifndef COA_SINGLE_PRECISION
    ck_assert_int_eq(memcmp(&back, &m, sizeof m), 0);
#endif
    ck_assert_int_eq(intent_view(&back, w, &why), COA_OK);
    ck_assert_int_eq(memcmp(&w->arrays, &v->arrays, sizeof w->arrays), 0);
    /* Field by field: struct padding is not part of the promise. */
    ck_assert(w->info.utime == v->info.utime && w->info.sequence == v->info.sequence);
    ck_assert(w->info.mode == v->info.mode && w->info.plan_utime == v->info.plan_utime);
    ck_assert(same_vec(w->info.position, v->info.position));
    ck_assert(same_vec(w->info.velocity, v->info.velocity));
    ck_assert(w->info.step == v->info.step);
    ck_assert(w->info.sigma_horizontal == v->info.sigma_horizontal);
    ck_assert(w->info.sigma_vertical == v->info.sigma_vertical);
    ck_assert(w->info.rank == v->info.rank);
    ck_assert(w->vehicle.id == v->vehicle.id && w->vehicle.priority == v->vehicle.priority);
    ck_assert(w->vehicle.cruise_speed == v->vehicle.cruise_speed);
    ck_assert(w->vehicle.climb_rate == v->vehicle.climb_rate);
    ck_assert(w->vehicle.steep_factor == v->vehicle.steep_factor);
    ck_assert(w->vehicle.volume.radius == v->vehicle.volume.radius);
    ck_assert(w->vehicle.volume.half_height == v->vehicle.volume.half_height);
    ck_assert(w->vehicle.route_count == v->vehicle.route_count);
    ck_assert(w->vehicle.initial_offset == v->vehicle.initial_offset);
    ck_assert(w->vehicle.max_offset == v->vehicle.max_offset);

    /* An unbounded vehicle publishes max_offset -1 whatever negative number it holds. */
    unbounded = v->vehicle;
    unbounded.max_offset = -5;
    ck_assert_int_eq(coavoid_lcm_intent_from_core(&unbounded, &v->info, v->arrays.reference,
                                                  v->arrays.offsets, v->plan.count, &ctx, &back,
                                                  &why),
                     COA_OK);
    ck_assert_int_eq(back.max_offset, -1);

    /* What from_core and to_core refuse themselves. */
    ck_assert_int_eq(coavoid_lcm_intent_from_core(&v->vehicle, &v->info, v->arrays.reference,
                                                  v->arrays.offsets, 1, &ctx, &back, &why),
                     COAVOID_LCM_ERR_COUNT);
    ck_assert_int_eq(coavoid_lcm_intent_from_core(&v->vehicle, &v->info, v->arrays.reference,
                                                  v->arrays.offsets, 42, &ctx, &back, &why),
                     COAVOID_LCM_ERR_COUNT);
    ck_assert_int_eq(coavoid_lcm_intent_from_core(&v->vehicle, &v->info, NULL, v->arrays.offsets,
                                                  31, &ctx, &back, &why),
                     COA_ERR_ARGUMENT);
    unbounded.id = 0;
    ck_assert_int_eq(coavoid_lcm_intent_from_core(&unbounded, &v->info, v->arrays.reference,
                                                  v->arrays.offsets, v->plan.count, &ctx, &back,
                                                  &why),
                     COAVOID_LCM_ERR_ID);
    ck_assert_int_eq(
        coavoid_lcm_intent_to_core(&m, &ctx, NULL, &v->info, &v->vehicle, &v->plan, NULL, &why),
        COA_ERR_ARGUMENT);
    free(v);
    free(w);
}
END_TEST

typedef struct {
    void *mem;
    coa_planner_t *planner;
} workspace_t;

/* A planner for one UAV that takes any intent a coordinator can receive: the longest
 * horizon a message holds, the steepest steep factor and no offset bound. The intents a
 * test plans differ in all three, and one workspace serves them all. */
static workspace_t workspace(uint32_t beta)
{
    const coa_planner_config_t config = {1u, beta, COAVOID_INTENT_T_MAX_SAMPLES - 1u,
                                         COA_MAX_STEEP_FACTOR, -1};
    workspace_t ws;
    size_t bytes = coa_planner_workspace_size(&config);
    ck_assert_uint_gt(bytes, 0u);
    ws.mem = malloc(bytes);
    ck_assert_ptr_nonnull(ws.mem);
    ws.planner = coa_planner_init(ws.mem, bytes, &config);
    ck_assert_ptr_nonnull(ws.planner);
    return ws;
}

/* The next coa_real_t up or down. */
static coa_real_t real_next(coa_real_t x, int up)
{
#ifdef COA_SINGLE_PRECISION
    return nextafterf(x, up ? INFINITY : -INFINITY);
#else
    return nextafter(x, up ? INFINITY : -INFINITY);
#endif
}

START_TEST(test_plan_from_intent)
{
    coavoid_intent_t m = good_intent();
    coavoid_intent_t replanned;
    coavoid_lcm_context_t ctx = ctx_now();
    intent_view_t *v = malloc(sizeof *v);
    workspace_t ws = workspace(2000u);
    int32_t offsets[COAVOID_INTENT_T_MAX_SAMPLES];
    const coa_vec3_t *references[1];
    coa_problem_t problem;
    coa_plan_result_t result;
    coa_obstacle_t slabs[2];
    coa_real_t z;
    coa_real_t h;
    size_t k;
    const char *why = NULL;
    ck_assert_ptr_nonnull(v);

    /* A coordinator re-plans the UAV from its intent alone. Free airspace: it returns to
     * its reference from the offset it flies now, and the new plan is publishable. */
    ck_assert_int_eq(intent_view(&m, v, &why), COA_OK);
    references[0] = v->arrays.reference;
    problem = intent_problem(v, references);
    ck_assert_int_eq(coa_problem_check(&problem), COA_OK);
    ck_assert_int_eq(coa_plan_centralised(ws.planner, &problem, offsets, &result), COA_OK);
    ck_assert_int_eq(result.status, COA_PLAN_SOLVED);
    ck_assert_int_eq(offsets[0], -2);
    ck_assert_int_eq(offsets[30], 0);
    ck_assert(result.deviation > 0.0);
    ck_assert_int_eq(coavoid_lcm_intent_from_core(&v->vehicle, &v->info, v->arrays.reference,
                                                  offsets, v->plan.count, &ctx, &replanned, &why),
                     COA_OK);

    /* The positions the receiver computed are the planner's to the last bit. The UAV flies
     * level at offset -5 over a level reference between two slabs that touch its
     * protected volume exactly, above and below: touching is no conflict, and any other
     * altitude, one ulp up or down, is one. So the plan exists only if the planner puts
     * the UAV exactly where arrays.samples says. */
    m.sample_count = 21;
    m.max_offset = -1;
    for (k = 0; k < 21u; ++k) {
        m.reference[k][2] = 100.3;
        m.offsets[k] = -5;
    }
    ck_assert_int_eq(intent_view(&m, v, &why), COA_OK);
    z = v->arrays.samples[0].z;
    h = v->vehicle.volume.half_height;
    for (k = 0; k < 21u; ++k) {
        ck_assert(v->arrays.samples[k].z == z);
    }
    /* The test has teeth: the altitude as a sender might compute it its own way, in
     * double, is off by an ulp in either precision. */
    ck_assert(z != (coa_real_t)(100.3 + -5.0 * 1.8 * 0.9));
    ck_assert((z - h) + h == z); /* the slabs' faces are exact */
    ck_assert((z + h) - h == z);
    memset(slabs, 0, sizeof slabs);
    slabs[0].kind = COA_OBSTACLE_BOX;
    slabs[0].box.min.x = (coa_real_t)-1e5;
    slabs[0].box.min.y = (coa_real_t)-1e5;
    slabs[0].box.min.z = z - h - (coa_real_t)50;
    slabs[0].box.max.x = (coa_real_t)1e5;
    slabs[0].box.max.y = (coa_real_t)1e5;
    slabs[0].box.max.z = z - h;
    slabs[1] = slabs[0];
    slabs[1].box.min.z = z + h;
    slabs[1].box.max.z = z + h + (coa_real_t)50;
    problem = intent_problem(v, references);
    problem.obstacles = slabs;
    problem.obstacle_count = 2u;
    ck_assert_int_eq(
        coa_plan_find_conflict(&problem, v->arrays.offsets, (const size_t[]){0u}, 1u, NULL, NULL),
        0);
    ck_assert_int_eq(coa_plan_centralised(ws.planner, &problem, offsets, &result), COA_OK);
    ck_assert_int_eq(result.status, COA_PLAN_SOLVED);
    ck_assert_uint_eq(result.nodes_expanded, 20u);
    for (k = 0; k < 21u; ++k) {
        ck_assert_int_eq(offsets[k], -5);
    }
    /* Each slab one ulp closer: now it is a conflict from t = 0. */
    slabs[0].box.max.z = real_next(z - h, 1);
    ck_assert_int_eq(
        coa_plan_find_conflict(&problem, v->arrays.offsets, (const size_t[]){0u}, 1u, NULL, NULL),
        1);
    ck_assert_int_eq(coa_plan_centralised(ws.planner, &problem, offsets, &result), COA_OK);
    ck_assert_int_eq(result.status, COA_PLAN_INFEASIBLE);
    ck_assert_uint_eq(result.nodes_expanded, 0u);
    slabs[0].box.max.z = z - h;
    slabs[1].box.min.z = real_next(z + h, 0);
    ck_assert_int_eq(
        coa_plan_find_conflict(&problem, v->arrays.offsets, (const size_t[]){0u}, 1u, NULL, NULL),
        1);
    free(ws.mem);
    free(v);
}
END_TEST

/* What every accepted intent must give a receiver: a vehicle coa_vehicle_check accepts, a
 * problem coa_problem_check accepts, and finite positions. REQUIRE: it runs in loops. */
static void require_usable_intent(const coavoid_intent_t *m)
{
    static intent_view_t v;
    const coa_vec3_t *references[1];
    coa_problem_t problem;
    size_t k;
    const char *why = NULL;
    REQUIRE(intent_view(m, &v, &why) == COA_OK);
    REQUIRE(coa_vehicle_check(&v.vehicle) == COA_OK);
    references[0] = v.arrays.reference;
    problem = intent_problem(&v, references);
    REQUIRE(coa_problem_check(&problem) == COA_OK);
    for (k = 0; k < v.plan.count; ++k) {
        REQUIRE(isfinite(v.arrays.samples[k].z));
    }
}

/* A random magnitude 10^[-320, 8), sometimes negative, sometimes exactly 0. */
static double wild(void)
{
    double x = pow(10.0, unif(&rng_state, -320.0, 8.0));
    uint32_t r = pick(&rng_state, 16u);
    return r == 0u ? 0.0 : (r == 1u ? -x : x);
}

/* The check's promise, pushed to the numbers where double and the core's precision part:
 * speeds, step and volume of any magnitude, and reference legs of any length. Whatever it
 * accepts, a coordinator can plan. */
START_TEST(test_accepted_intent_is_plannable)
{
    int i;
    int accepted = 0;
    int refused = 0;
    rng_state = UINT64_C(0xC0A1D);
    for (i = 0; i < 4000; ++i) {
        coavoid_intent_t m = good_intent();
        coavoid_lcm_context_t ctx = ctx_now();
        int changes = 1 + (int)pick(&rng_state, 3u);
        int c;
        const char *why = NULL;
        for (c = 0; c < changes; ++c) {
            int32_t j = 1 + (int32_t)pick(&rng_state, 30u); /* a leg of the 31 samples */
            switch (pick(&rng_state, 6u)) {
            case 0:
                m.cruise_speed = wild();
                break;
            case 1:
                m.climb_rate = wild();
                break;
            case 2:
                m.step = wild();
                break;
            case 3:
                m.radius = wild();
                break;
            case 4:
                m.half_height = wild();
                break;
            default:
                m.reference[j][0] = m.reference[j - 1][0] + wild();
                m.reference[j][1] = m.reference[j - 1][1] + (pick(&rng_state, 2u) ? wild() : 0.0);
                break;
            }
        }
        if (coavoid_lcm_intent_check(&m, &ctx, &why) == COA_OK) {
            require_usable_intent(&m);
            accepted++;
        } else {
            refused++;
        }
    }
    ck_assert_int_gt(accepted, 150);
    ck_assert_int_gt(refused, 400);
}
END_TEST

/* Collects rows[order[0..n)] into c; returns the last call's status, *whole its output. */
static int collect_rows(coavoid_lcm_plan_rows_t *c, const coavoid_plan_t *rows, const int *order,
                        size_t n, const coavoid_plan_t **whole, coavoid_lcm_plan_info_t *info,
                        coa_plan_result_t *result, int32_t *offsets, size_t capacity)
{
    coavoid_lcm_context_t ctx = ctx_now();
    int rc = COA_OK;
    size_t i;
    for (i = 0; i < n && rc == COA_OK; ++i) {
        ck_assert_ptr_null(i > 0 ? *whole : NULL);
        rc = coavoid_lcm_plan_collect(c, &rows[order[i]], &ctx, whole, info, result, offsets,
                                      capacity, NULL);
    }
    return rc;
}

START_TEST(test_round_trip_plan_core)
{
    coavoid_plan_t rows[4];
    coavoid_plan_t back;
    coavoid_lcm_context_t ctx = ctx_now();
    coavoid_lcm_plan_info_t info;
    coa_plan_result_t result;
    static int32_t offsets[COAVOID_PLAN_T_MAX_VEHICLES * COAVOID_PLAN_T_MAX_SAMPLES];
    const size_t cap = sizeof offsets / sizeof offsets[0];
    static coavoid_lcm_plan_slot_t slots[2];
    coavoid_lcm_plan_rows_t c;
    const coavoid_plan_t *whole = NULL;
    const char *why = NULL;
    size_t i;
    for (i = 0; i < 3; ++i) {
        rows[i] = good_plan_row((int32_t)i);
    }
    /* Rows in any order, one twice: the plan is whole with the third UAV's. */
    coavoid_lcm_plan_rows_init(&c, slots, 2);
    ck_assert_int_eq(
        collect_rows(&c, rows, (const int[]){2, 0, 0}, 3, &whole, &info, &result, offsets, cap),
        COA_OK);
    ck_assert_ptr_null(whole);
    ck_assert_int_eq(
        collect_rows(&c, rows, (const int[]){1}, 1, &whole, &info, &result, offsets, cap), COA_OK);
    ck_assert_ptr_nonnull(whole);
    ck_assert_int_eq((int)whole->plan_id, 9);
    ck_assert_int_eq(result.status, COA_PLAN_SOLVED);
    ck_assert_uint_eq(result.planned_count, 3u);
    ck_assert_uint_eq(info.vehicle_count, 3u);
    ck_assert_int_eq(offsets[2 * 41 + 40], 9);
    ck_assert_int_eq(offsets[0 * 41 + 5], -5);
    /* And back: each UAV's message, bit for bit. */
    for (i = 0; i < 3; ++i) {
        ck_assert_int_eq(coavoid_lcm_plan_from_core(&info, &result, offsets, i, &ctx, &back, &why),
                         COA_OK);
        ck_assert_int_eq(memcmp(&back, &rows[i], sizeof back), 0);
    }
    ck_assert_int_eq(coavoid_lcm_plan_from_core(&info, &result, offsets, 3, &ctx, &back, &why),
                     COAVOID_LCM_ERR_COUNT);
    /* The slot was freed: the same rows again make the plan again. */
    ck_assert_int_eq(
        collect_rows(&c, rows, (const int[]){0, 1, 2}, 3, &whole, &info, &result, offsets, cap),
        COA_OK);
    ck_assert_ptr_nonnull(whole);
    /* Too small an array for the whole plan. */
    ck_assert_int_eq(
        collect_rows(&c, rows, (const int[]){0}, 1, &whole, &info, &result, offsets, 3 * 41 - 1),
        COAVOID_LCM_ERR_CAPACITY);
    /* A row that says something else of its plan than the rows before it: refused, and
     * the plan is still whole with the right row. */
    coavoid_lcm_plan_rows_init(&c, slots, 2);
    rows[3] = rows[1];
    rows[3].deviation = 1.0;
    ck_assert_int_eq(
        collect_rows(&c, rows, (const int[]){0, 3}, 2, &whole, &info, &result, offsets, cap),
        COAVOID_LCM_ERR_VALUE);
    ck_assert_int_eq(
        collect_rows(&c, rows, (const int[]){2, 1}, 2, &whole, &info, &result, offsets, cap),
        COA_OK);
    ck_assert_ptr_nonnull(whole);
    /* With the slots full, a new plan drops the oldest unfinished one: it never completes. */
    coavoid_lcm_plan_rows_init(&c, slots, 1);
    rows[3] = good_plan_row(0);
    rows[3].plan_id = 10;
    ck_assert_int_eq(
        collect_rows(&c, rows, (const int[]){0, 3, 1, 2}, 4, &whole, &info, &result, offsets, cap),
        COA_OK);
    ck_assert_ptr_null(whole);
    /* A failed plan is whole too: a message for each UAV, without rows. */
    coavoid_lcm_plan_rows_init(&c, slots, 2);
    for (i = 0; i < 3; ++i) {
        rows[i].status = COAVOID_PLAN_T_STATUS_INFEASIBLE;
        rows[i].planned_count = 0;
        memset(rows[i].offsets, 0, sizeof rows[i].offsets);
    }
    ck_assert_int_eq(
        collect_rows(&c, rows, (const int[]){0, 1, 2}, 3, &whole, &info, &result, offsets, cap),
        COA_OK);
    ck_assert_ptr_nonnull(whole);
    ck_assert_int_eq(result.status, COA_PLAN_INFEASIBLE);
    ck_assert_uint_eq(result.planned_count, 0u);
    ck_assert_int_eq(
        coavoid_lcm_plan_collect(NULL, &rows[0], &ctx, &whole, &info, &result, offsets, cap, &why),
        COA_ERR_ARGUMENT);
}
END_TEST

START_TEST(test_round_trip_track_core)
{
    coavoid_track_t m = good_track();
    coavoid_track_t back;
    coavoid_lcm_context_t ctx = ctx_now();
    coavoid_lcm_track_info_t info;
    coa_track_t track;
    coa_track_point_t path[COAVOID_TRACK_T_MAX_PATH];
    const char *why = NULL;
    ck_assert_int_eq(coavoid_lcm_track_to_core(&m, &ctx, NULL, &info, &track, path,
                                               COAVOID_TRACK_T_MAX_PATH, &why),
                     COA_OK);
    ck_assert_int_eq(coa_track_check(&track), COA_OK);
    /* Estimated at t = 4.8 s of the core clock: at t = 0 it was 4.8 s * 30 m/s east. */
    ck_assert(fabs((double)track.position.x - (500.0 + 30.0 * 4.8)) < 1e-3);
    ck_assert(fabs((double)path[1].t - 6.0) < 1e-6);
    ck_assert_int_eq(coavoid_lcm_track_from_core(&track, &info, &ctx, &back, &why), COA_OK);
    ck_assert_int_eq(back.track_id, 77);
    ck_assert_int_eq(back.path_count, 3);
    ck_assert_int_eq((int)(back.path_utime[2] - m.path_utime[2]), 0);
    /* Re-estimated at the epoch: the same straight line. */
    ck_assert(fabs(back.position[0] + back.velocity[0] * 4.8 - m.position[0]) < 1e-3);
}
END_TEST

START_TEST(test_round_trip_map_core)
{
    coavoid_obstacle_map_t tiles[2] = {good_map(), good_map_tile1()};
    coavoid_obstacle_map_t back;
    coavoid_lcm_context_t ctx = ctx_now();
    coa_obstacle_t obstacles[COAVOID_LCM_MAP_MAX_OBSTACLES];
    coa_obstacle_t again[COAVOID_LCM_MAP_MAX_OBSTACLES];
    coa_vec3_t vertices[512];
    coa_vec3_t vertices2[512];
    size_t n = 0;
    size_t m = 0;
    size_t count = 0;
    size_t i;
    const char *why = NULL;
    ck_assert_int_eq(
        coavoid_lcm_obstacle_map_to_core(tiles, 2, &ctx, obstacles, 80, &n, vertices, 512, &why),
        COA_OK);
    /* Every box, then every polytope, in tile order. */
    ck_assert_uint_eq(n, 4u);
    for (i = 0; i < n; ++i) {
        ck_assert_int_eq(coa_obstacle_check(&obstacles[i]), COA_OK);
        ck_assert_int_eq(obstacles[i].kind, i < 3 ? COA_OBSTACLE_BOX : COA_OBSTACLE_POLYTOPE);
    }
    ck_assert(obstacles[2].box.min.x == (coa_real_t)500.0);
    /* Back: the four fit one tile, which gives the same obstacles. */
    ck_assert_int_eq(coavoid_lcm_obstacle_map_tiles(obstacles, n, &count, &why), COA_OK);
    ck_assert_uint_eq(count, 1u);
    ck_assert_int_eq(
        coavoid_lcm_obstacle_map_from_core(obstacles, n, T0, 2, 4, 0, &ctx, &back, &why), COA_OK);
    ck_assert_int_eq(back.tile_count, 1);
    ck_assert_int_eq(back.box_count, 3);
    ck_assert_int_eq(
        coavoid_lcm_obstacle_map_to_core(&back, 1, &ctx, again, 80, &m, vertices2, 512, &why),
        COA_OK);
    ck_assert_uint_eq(m, n);
    ck_assert_int_eq(memcmp(vertices, vertices2, 5 * sizeof vertices[0]), 0);
    ck_assert_int_eq(
        coavoid_lcm_obstacle_map_from_core(obstacles, n, T0, 2, 4, 1, &ctx, &back, &why),
        COAVOID_LCM_ERR_COUNT);
    /* Not one whole version: a tile missing, out of order, of another version or map. */
    ck_assert_int_eq(
        coavoid_lcm_obstacle_map_to_core(tiles, 1, &ctx, obstacles, 80, &n, vertices, 512, &why),
        COAVOID_LCM_ERR_COUNT);
    back = tiles[0];
    tiles[0] = tiles[1];
    tiles[1] = back;
    ck_assert_int_eq(
        coavoid_lcm_obstacle_map_to_core(tiles, 2, &ctx, obstacles, 80, &n, vertices, 512, &why),
        COAVOID_LCM_ERR_COUNT);
    tiles[1] = tiles[0];
    tiles[0] = back;
    tiles[1].version = 5;
    ck_assert_int_eq(
        coavoid_lcm_obstacle_map_to_core(tiles, 2, &ctx, obstacles, 80, &n, vertices, 512, &why),
        COAVOID_LCM_ERR_COUNT);
    tiles[1].version = 4;
    tiles[1].map_id = 3;
    ck_assert_int_eq(
        coavoid_lcm_obstacle_map_to_core(tiles, 2, &ctx, obstacles, 80, &n, vertices, 512, &why),
        COAVOID_LCM_ERR_COUNT);
    tiles[1].map_id = 2;
    /* The caller's arrays. */
    ck_assert_int_eq(
        coavoid_lcm_obstacle_map_to_core(tiles, 2, &ctx, obstacles, 3, &n, vertices, 512, &why),
        COAVOID_LCM_ERR_CAPACITY);
    ck_assert_int_eq(
        coavoid_lcm_obstacle_map_to_core(tiles, 2, &ctx, obstacles, 80, &n, vertices, 4, &why),
        COAVOID_LCM_ERR_CAPACITY);
    tiles[1].box_count = 11;
    ck_assert_int_eq(
        coavoid_lcm_obstacle_map_to_core(tiles, 2, &ctx, obstacles, 80, &n, vertices, 512, &why),
        COAVOID_LCM_ERR_COUNT);
}
END_TEST

/* The tiling: today's whole capacity (64 boxes, 16 polytopes of 32 vertices) in at most
 * MAX_TILES tiles, each within one datagram; beyond it, refused. */
START_TEST(test_map_tiles)
{
    static coa_obstacle_t obstacles[COAVOID_LCM_MAP_MAX_OBSTACLES + 1u];
    static coa_vec3_t points[32];
    static coavoid_obstacle_map_t tiles[COAVOID_OBSTACLE_MAP_T_MAX_TILES];
    static coa_obstacle_t back[COAVOID_LCM_MAP_MAX_OBSTACLES];
    static coa_vec3_t vertices[512];
    coavoid_lcm_context_t ctx = ctx_now();
    size_t count = 0;
    size_t n = 0;
    size_t i;
    const char *why = NULL;
    for (i = 0; i < 32u; ++i) {
        points[i].x = (coa_real_t)(i % 2u) * 10;
        points[i].y = (coa_real_t)((i / 2u) % 2u) * 10;
        points[i].z = (coa_real_t)i;
    }
    /* Boxes and polytopes interleaved, as a scenario may list them. */
    for (i = 0; i < 80u; ++i) {
        coa_obstacle_t *o = &obstacles[i];
        memset(o, 0, sizeof *o);
        if (i % 5u == 4u) {
            o->kind = COA_OBSTACLE_POLYTOPE;
            o->polytope.vertices = points;
            o->polytope.count = 32u;
        } else {
            o->kind = COA_OBSTACLE_BOX;
            o->box.min.x = (coa_real_t)i;
            o->box.max.x = (coa_real_t)i + 1;
            o->box.max.y = 1;
            o->box.max.z = 1;
        }
    }
    ck_assert_int_eq(coavoid_lcm_obstacle_map_tiles(obstacles, 80, &count, &why), COA_OK);
    ck_assert_uint_eq(count, 16u);
    for (i = 0; i < count; ++i) {
        ck_assert_int_eq(
            coavoid_lcm_obstacle_map_from_core(obstacles, 80, T0, 2, 1, i, &ctx, &tiles[i], &why),
            COA_OK);
        ck_assert_int_le(coavoid_obstacle_map_t_encoded_size(&tiles[i]),
                         COAVOID_LCM_MAX_DATAGRAM_BYTES);
    }
    ck_assert_int_eq(
        coavoid_lcm_obstacle_map_to_core(tiles, count, &ctx, back, 80, &n, vertices, 512, &why),
        COA_OK);
    /* The boxes, then the polytopes, each in the list's order. */
    ck_assert_uint_eq(n, 80u);
    ck_assert(back[0].box.min.x == 0 && back[4].box.min.x == 5 && back[63].box.min.x == 78);
    ck_assert_int_eq(back[64].kind, COA_OBSTACLE_POLYTOPE);
    /* One box more, or one polytope more, is more than a map holds. */
    obstacles[80] = obstacles[0];
    ck_assert_int_eq(coavoid_lcm_obstacle_map_tiles(obstacles, 81, &count, &why),
                     COAVOID_LCM_ERR_COUNT);
    obstacles[80] = obstacles[4];
    ck_assert_int_eq(coavoid_lcm_obstacle_map_tiles(obstacles, 81, &count, &why),
                     COAVOID_LCM_ERR_COUNT);
    ck_assert_int_eq(coavoid_lcm_obstacle_map_tiles(&obstacles[4], 77, &count, &why),
                     COAVOID_LCM_ERR_COUNT);
    /* Small polytopes share a tile, four to a tile. */
    for (i = 0; i < 5u; ++i) {
        obstacles[i] = obstacles[4];
        obstacles[i].polytope.count = 8u;
    }
    ck_assert_int_eq(coavoid_lcm_obstacle_map_tiles(obstacles, 5, &count, &why), COA_OK);
    ck_assert_uint_eq(count, 2u);
    /* A polytope beyond a tile's vertices, an unknown kind. */
    obstacles[0].polytope.count = 33u;
    ck_assert_int_eq(coavoid_lcm_obstacle_map_tiles(obstacles, 1, &count, &why),
                     COAVOID_LCM_ERR_COUNT);
    obstacles[0].kind = (coa_obstacle_kind_t)7;
    ck_assert_int_eq(coavoid_lcm_obstacle_map_tiles(obstacles, 1, &count, &why),
                     COAVOID_LCM_ERR_ENUM);
    /* No obstacles: one empty tile. */
    ck_assert_int_eq(coavoid_lcm_obstacle_map_tiles(NULL, 0, &count, &why), COA_OK);
    ck_assert_uint_eq(count, 1u);
}
END_TEST

/* Every type's encoded size, the same for every message of it (fixed-size arrays), fits
 * one datagram: the examples are of the largest size there is. */
START_TEST(test_datagram_sizes)
{
    coavoid_intent_t intent = good_intent();
    coavoid_plan_t plan = good_plan();
    coavoid_track_t track = good_track();
    coavoid_obstacle_map_t map = good_map();
    coavoid_conflict_report_t report = good_report();
    coavoid_status_t status = good_status();
    ck_assert_int_eq(coavoid_intent_t_encoded_size(&intent), 1398);
    ck_assert_int_eq(coavoid_plan_t_encoded_size(&plan), 474);
    ck_assert_int_eq(coavoid_track_t_encoded_size(&track), 728);
    ck_assert_int_eq(coavoid_obstacle_map_t_encoded_size(&map), 1400);
    ck_assert_int_eq(coavoid_conflict_report_t_encoded_size(&report), 1378);
    ck_assert_int_eq(coavoid_status_t_encoded_size(&status), 192);
    ck_assert_int_le(coavoid_intent_t_encoded_size(&intent), COAVOID_LCM_MAX_DATAGRAM_BYTES);
    ck_assert_int_le(coavoid_obstacle_map_t_encoded_size(&map), COAVOID_LCM_MAX_DATAGRAM_BYTES);
    ck_assert_int_le(coavoid_conflict_report_t_encoded_size(&report),
                     COAVOID_LCM_MAX_DATAGRAM_BYTES);
}
END_TEST

START_TEST(test_round_trip_report_core)
{
    coavoid_conflict_report_t m = good_report();
    coavoid_conflict_report_t back;
    coavoid_lcm_context_t ctx = ctx_now();
    coa_conflict_t c[2];
    uint16_t plan_ids[3] = {10, 11, 12};
    uint32_t track_ids[1] = {77};
    uint32_t cluster[3] = {0, 0, 1};
    const char *why = NULL;
    memset(c, 0, sizeof c);
    c[0].kind = COA_CONFLICT_VEHICLE;
    c[0].a = 0;
    c[0].b = 1;
    c[0].first_step = 12;
    c[0].min_horizontal = 3.0;
    c[0].min_vertical = 1.0;
    c[0].probability = 1.0;
    c[1].kind = COA_CONFLICT_TRACK;
    c[1].a = 2;
    c[1].b = 0;
    c[1].first_step = 30;
    c[1].min_horizontal = 40.0;
    c[1].min_vertical = 5.0;
    c[1].probability = 0.25;
    ck_assert_int_eq(coavoid_lcm_conflict_report_from_core(c, 2, 2, plan_ids, 3, track_ids, 1,
                                                           cluster, T0, 1, 100, T0, 1.0, 60, &ctx,
                                                           &back, &why),
                     COA_OK);
    ck_assert_int_eq(memcmp(&back, &m, sizeof m), 0);
}
END_TEST

/* ---- each rule refuses its bad message ---- */

#define EXPECT(type, checker, mutate, code)                                         \
    do {                                                                            \
        type m_ = good_##checker##_msg();                                           \
        const char *why_ = NULL;                                                    \
        coavoid_lcm_context_t ctx_ = ctx_now();                                     \
        mutate;                                                                     \
        ck_assert_int_eq(coavoid_lcm_##checker##_check(&m_, &ctx_, &why_), (code)); \
        ck_assert_ptr_nonnull(why_);                                                \
    } while (0)

#define good_intent_msg good_intent
#define good_plan_msg good_plan
#define good_track_msg good_track
#define good_obstacle_map_msg good_map
#define good_conflict_report_msg good_report
#define good_status_msg good_status

/* An intent mutation refused with `code`, by the rule whose reason contains `field`: many
 * rules share COAVOID_LCM_ERR_VALUE, and the reason shows which one fired. */
#define EXPECT_INTENT(mutate, code, field)                                                   \
    do {                                                                                     \
        coavoid_intent_t m_ = good_intent();                                                 \
        const char *why_ = NULL;                                                             \
        coavoid_lcm_context_t ctx_ = ctx_now();                                              \
        mutate;                                                                              \
        ck_assert_int_eq(coavoid_lcm_intent_check(&m_, &ctx_, &why_), (code));               \
        ck_assert_ptr_nonnull(why_);                                                         \
        ck_assert_msg(strstr(why_, (field)) != NULL, "reason \"%s\" does not name %s", why_, \
                      (field));                                                              \
    } while (0)

START_TEST(test_reject_intent)
{
    EXPECT_INTENT(m_.utime = 0, COAVOID_LCM_ERR_TIME, "utime");
    EXPECT_INTENT(m_.utime = T0 - 20000000, COAVOID_LCM_ERR_TIME, "utime");
    EXPECT_INTENT(m_.utime = T0 + 2000000, COAVOID_LCM_ERR_TIME, "utime");
    EXPECT_INTENT(m_.uav_id = 0, COAVOID_LCM_ERR_ID, "uav_id");
    EXPECT_INTENT(m_.uav_id = 65536, COAVOID_LCM_ERR_ID, "uav_id");
    EXPECT_INTENT(m_.sequence = -1, COAVOID_LCM_ERR_VALUE, "sequence");
    EXPECT_INTENT(m_.priority = 0, COAVOID_LCM_ERR_VALUE, "priority");
    EXPECT_INTENT(m_.mode = 3, COAVOID_LCM_ERR_ENUM, "mode");
    EXPECT_INTENT(m_.position[1] = NAN, COAVOID_LCM_ERR_NONFINITE, "position");
    EXPECT_INTENT(m_.position[2] = 1e300, COAVOID_LCM_ERR_VALUE, "position");
    EXPECT_INTENT(m_.velocity[0] = INFINITY, COAVOID_LCM_ERR_NONFINITE, "velocity");
    EXPECT_INTENT(m_.velocity[0] = 2e4, COAVOID_LCM_ERR_VALUE, "velocity");
    EXPECT_INTENT(m_.radius = 0.0, COAVOID_LCM_ERR_VALUE, "radius");
    EXPECT_INTENT(m_.half_height = -1.0, COAVOID_LCM_ERR_VALUE, "half_height");
    EXPECT_INTENT(m_.half_height = NAN, COAVOID_LCM_ERR_NONFINITE, "half_height");

    /* Performance. */
    EXPECT_INTENT(m_.cruise_speed = 0.0, COAVOID_LCM_ERR_VALUE, "cruise_speed");
    EXPECT_INTENT(m_.cruise_speed = -18.0, COAVOID_LCM_ERR_VALUE, "cruise_speed");
    EXPECT_INTENT(m_.cruise_speed = NAN, COAVOID_LCM_ERR_NONFINITE, "cruise_speed");
    EXPECT_INTENT(m_.cruise_speed = 1.0001e4, COAVOID_LCM_ERR_VALUE, "cruise_speed");
    EXPECT_INTENT(m_.climb_rate = 0.0, COAVOID_LCM_ERR_VALUE, "climb_rate");
    EXPECT_INTENT(m_.climb_rate = -1.7, COAVOID_LCM_ERR_VALUE, "climb_rate");
    EXPECT_INTENT(m_.climb_rate = NAN, COAVOID_LCM_ERR_NONFINITE, "climb_rate");
    EXPECT_INTENT(m_.climb_rate = -INFINITY, COAVOID_LCM_ERR_NONFINITE, "climb_rate");
    EXPECT_INTENT(m_.climb_rate = 1.0001e4, COAVOID_LCM_ERR_VALUE, "climb_rate");
    EXPECT_INTENT(m_.steep_factor = 1, COAVOID_LCM_ERR_VALUE, "steep_factor");
    EXPECT_INTENT(m_.steep_factor = 11, COAVOID_LCM_ERR_VALUE, "steep_factor");
    EXPECT_INTENT(m_.max_offset = -2, COAVOID_LCM_ERR_VALUE, "max_offset");
    EXPECT_INTENT(m_.max_offset = 32768, COAVOID_LCM_ERR_VALUE, "max_offset");
    /* The bounds themselves are accepted. */
    EXPECT_INTENT((m_.cruise_speed = 1e4, m_.climb_rate = 1e4), COA_OK, "ok");
    EXPECT_INTENT((m_.steep_factor = 10, memset(m_.offsets, 0, sizeof m_.offsets)), COA_OK, "ok");
    EXPECT_INTENT(m_.steep_factor = 2, COAVOID_LCM_ERR_VALUE, "no action");
    EXPECT_INTENT(m_.max_offset = 32767, COA_OK, "ok");
    EXPECT_INTENT(m_.max_offset = -1, COA_OK, "ok");
    /* Positive in double but nothing in the core: two tiny factors whose product (the
     * climb step, the planner's deviation weight) is 0 in either precision; and a volume
     * that is 0 once in float. */
    EXPECT_INTENT((m_.climb_rate = 1e-200, m_.step = 1e-200), COAVOID_LCM_ERR_VALUE,
                  "core's precision");
    EXPECT_INTENT((m_.cruise_speed = 1e-200, m_.climb_rate = 1e-200), COAVOID_LCM_ERR_VALUE,
                  "core's precision");
#ifdef COA_SINGLE_PRECISION
    EXPECT_INTENT(m_.radius = 1e-300, COAVOID_LCM_ERR_VALUE, "core's precision");
    EXPECT_INTENT(m_.cruise_speed = 1e-50, COAVOID_LCM_ERR_VALUE, "core's precision");
#else
    EXPECT_INTENT(m_.radius = 1e-300, COA_OK, "ok");
    EXPECT_INTENT(m_.cruise_speed = 1e-50, COA_OK, "ok");
#endif

    /* The plan's time and step. */
    EXPECT_INTENT(m_.plan_utime = 0, COAVOID_LCM_ERR_TIME, "plan_utime");
    EXPECT_INTENT(m_.plan_utime = T0 + 20000000, COAVOID_LCM_ERR_TIME, "plan_utime");
    EXPECT_INTENT(m_.step = 0.0, COAVOID_LCM_ERR_VALUE, "step");
    EXPECT_INTENT(m_.step = NAN, COAVOID_LCM_ERR_NONFINITE, "step");
    EXPECT_INTENT(m_.step = 3601.0, COAVOID_LCM_ERR_VALUE, "step");

    /* Sample count. */
    EXPECT_INTENT(m_.sample_count = 1, COAVOID_LCM_ERR_COUNT, "sample_count");
    EXPECT_INTENT(m_.sample_count = 42, COAVOID_LCM_ERR_COUNT, "sample_count");
    EXPECT_INTENT(m_.sample_count = 0, COAVOID_LCM_ERR_COUNT, "sample_count");
    EXPECT_INTENT(m_.sample_count = -5, COAVOID_LCM_ERR_COUNT, "sample_count");
    EXPECT_INTENT(m_.sample_count = 2, COA_OK, "ok");

    /* The reference. */
    EXPECT_INTENT(m_.reference[30][0] = NAN, COAVOID_LCM_ERR_NONFINITE, "reference point");
    EXPECT_INTENT(m_.reference[0][2] = INFINITY, COAVOID_LCM_ERR_NONFINITE, "reference point");
    EXPECT_INTENT(m_.reference[10][1] = -2e7, COAVOID_LCM_ERR_VALUE, "reference point");
    EXPECT_INTENT(
        (m_.reference[5][0] = m_.reference[4][0], m_.reference[5][1] = m_.reference[4][1]),
        COAVOID_LCM_ERR_VALUE, "horizontal separation");
    /* Only z differs: a vertical leg, which no cruise speed flies. */
    EXPECT_INTENT((m_.reference[5][0] = m_.reference[4][0], m_.reference[5][1] = m_.reference[4][1],
                   m_.reference[5][2] += 50.0),
                  COAVOID_LCM_ERR_VALUE, "horizontal separation");
    /* Different numbers, but the horizontal length squares to 0 (in float they are equal
     * once converted). */
    EXPECT_INTENT((m_.reference[4][0] = 0.0, m_.reference[4][1] = 0.0, m_.reference[5][0] = 1e-200,
                   m_.reference[5][1] = 0.0),
                  COAVOID_LCM_ERR_VALUE, "horizontal separation");
    /* A point past sample_count is not part of the message. */
    EXPECT_INTENT(m_.reference[31][0] = NAN, COA_OK, "ok");
    EXPECT_INTENT(m_.offsets[31] = 99999, COA_OK, "ok");

    /* Offsets. The good intent's offsets reach -5. */
    EXPECT_INTENT(m_.max_offset = 4, COAVOID_LCM_ERR_VALUE, "offset beyond max_offset");
    EXPECT_INTENT(m_.max_offset = 5, COA_OK, "ok");
    EXPECT_INTENT((m_.max_offset = -1, m_.offsets[0] = 32768, m_.offsets[1] = 32768),
                  COAVOID_LCM_ERR_VALUE, "offset beyond max_offset");
    EXPECT_INTENT((m_.max_offset = -1, m_.offsets[0] = -32768), COAVOID_LCM_ERR_VALUE,
                  "offset beyond max_offset");
    /* +3 is a steep climb for steep factor 3, no action for 2; +2 is none for 3. */
    EXPECT_INTENT(m_.steep_factor = 2, COAVOID_LCM_ERR_VALUE, "no action");
    EXPECT_INTENT(m_.offsets[1] = m_.offsets[0] + 2, COAVOID_LCM_ERR_VALUE, "no action");
    EXPECT_INTENT(m_.offsets[30] = m_.offsets[29] - 4, COAVOID_LCM_ERR_VALUE, "no action");

    /* A planned position out of range although its reference point is in range: offset 3
     * at sample 6 climbs 3 * 1e4 * 0.9 m above 9.99e6 m; offset -5 at sample 1 dives
     * 45 km below -9.99e6 m. */
    ck_assert_int_eq(good_intent().offsets[6], 3);
    ck_assert_int_eq(good_intent().offsets[1], -5);
    EXPECT_INTENT((m_.climb_rate = 1e4, m_.reference[6][2] = 9.99e6), COAVOID_LCM_ERR_VALUE,
                  "planned position out of range");
    EXPECT_INTENT((m_.climb_rate = 1e4, m_.reference[1][2] = -9.99e6), COAVOID_LCM_ERR_VALUE,
                  "planned position out of range");
    EXPECT_INTENT((m_.climb_rate = 1e4, m_.reference[6][2] = 9.97e6), COA_OK, "ok");

    EXPECT_INTENT(m_.sigma_horizontal = -0.1, COAVOID_LCM_ERR_VALUE, "sigma_horizontal");
    EXPECT_INTENT(m_.sigma_vertical = INFINITY, COAVOID_LCM_ERR_NONFINITE, "sigma_vertical");
    EXPECT_INTENT(m_.rank = -1, COAVOID_LCM_ERR_VALUE, "rank");
    EXPECT_INTENT(m_.rank = COAVOID_INTENT_T_MAX_RANK + 1, COAVOID_LCM_ERR_VALUE, "rank");
    EXPECT_INTENT(m_.rank = COAVOID_INTENT_T_MAX_RANK, COA_OK, "ok");
}
END_TEST

START_TEST(test_reject_plan)
{
    EXPECT(coavoid_plan_t, plan, m_.utime = -1, COAVOID_LCM_ERR_TIME);
    EXPECT(coavoid_plan_t, plan, m_.coordinator_id = 0, COAVOID_LCM_ERR_ID);
    EXPECT(coavoid_plan_t, plan, m_.plan_id = -3, COAVOID_LCM_ERR_VALUE);
    EXPECT(coavoid_plan_t, plan, m_.valid_from_utime = 0, COAVOID_LCM_ERR_TIME);
    EXPECT(coavoid_plan_t, plan, m_.valid_until_utime = m_.valid_from_utime, COAVOID_LCM_ERR_TIME);
    EXPECT(coavoid_plan_t, plan, m_.dt = -1.0, COAVOID_LCM_ERR_VALUE);
    EXPECT(coavoid_plan_t, plan, m_.dt = NAN, COAVOID_LCM_ERR_NONFINITE);
    EXPECT(coavoid_plan_t, plan, m_.horizon = 0, COAVOID_LCM_ERR_COUNT);
    EXPECT(coavoid_plan_t, plan, m_.horizon = 41, COAVOID_LCM_ERR_COUNT);
    EXPECT(coavoid_plan_t, plan, m_.mode = 2, COAVOID_LCM_ERR_ENUM);
    EXPECT(coavoid_plan_t, plan, m_.status = 4, COAVOID_LCM_ERR_ENUM);
    /* Abandoned: no rows, so no offsets in any message. */
    EXPECT(coavoid_plan_t, plan, m_.status = COAVOID_PLAN_T_STATUS_ABANDONED,
           COAVOID_LCM_ERR_COUNT);
    EXPECT(coavoid_plan_t, plan,
           (m_.status = COAVOID_PLAN_T_STATUS_ABANDONED, m_.planned_count = 0),
           COAVOID_LCM_ERR_VALUE);
    EXPECT(coavoid_plan_t, plan,
           (m_.status = COAVOID_PLAN_T_STATUS_ABANDONED, m_.planned_count = 0,
            memset(m_.offsets, 0, sizeof m_.offsets)),
           COA_OK);
    EXPECT(coavoid_plan_t, plan, m_.deviation = -1.0, COAVOID_LCM_ERR_VALUE);
    EXPECT(coavoid_plan_t, plan, m_.deviation = NAN, COAVOID_LCM_ERR_NONFINITE);
    EXPECT(coavoid_plan_t, plan, m_.effort = -1, COAVOID_LCM_ERR_VALUE);
    EXPECT(coavoid_plan_t, plan, m_.nodes_expanded = -1, COAVOID_LCM_ERR_VALUE);
    EXPECT(coavoid_plan_t, plan, m_.vehicle_count = 0, COAVOID_LCM_ERR_COUNT);
    EXPECT(coavoid_plan_t, plan, m_.vehicle_count = 33, COAVOID_LCM_ERR_COUNT);
    EXPECT(coavoid_plan_t, plan, m_.planned_count = 2, COAVOID_LCM_ERR_COUNT);
    EXPECT(coavoid_plan_t, plan, m_.planned_count = -1, COAVOID_LCM_ERR_COUNT);
    EXPECT(coavoid_plan_t, plan, m_.uav_ids[2] = 0, COAVOID_LCM_ERR_ID);
    EXPECT(coavoid_plan_t, plan, m_.uav_ids[2] = m_.uav_ids[0], COAVOID_LCM_ERR_ID);
    /* The row: a listed UAV's, within bounds, steps some action makes. */
    EXPECT(coavoid_plan_t, plan, m_.row_uav_id = 13, COAVOID_LCM_ERR_ID);
    EXPECT(coavoid_plan_t, plan, m_.row_uav_id = 0, COAVOID_LCM_ERR_ID);
    EXPECT(coavoid_plan_t, plan, (m_.vehicle_count = 1, m_.planned_count = 1), COAVOID_LCM_ERR_ID);
    EXPECT(coavoid_plan_t, plan, m_.row_uav_id = 12, COA_OK);
    EXPECT(coavoid_plan_t, plan, m_.offsets[5] = 40000, COAVOID_LCM_ERR_VALUE);
    EXPECT(coavoid_plan_t, plan, m_.offsets[5] = 11, COAVOID_LCM_ERR_VALUE);
    /* Past the horizon, nothing. */
    EXPECT(coavoid_plan_t, plan, m_.horizon = 20, COAVOID_LCM_ERR_VALUE);
    EXPECT(coavoid_plan_t, plan,
           (m_.horizon = 20, memset(&m_.offsets[21], 0, 20 * sizeof(int32_t))), COA_OK);
    /* Not solved: fewer rows are plans; a UAV without one gets no offsets. */
    EXPECT(coavoid_plan_t, plan, (m_.status = 2, m_.planned_count = 2), COA_OK);
    EXPECT(coavoid_plan_t, plan, (m_.status = 2, m_.planned_count = 1), COAVOID_LCM_ERR_VALUE);
    EXPECT(coavoid_plan_t, plan,
           (m_.status = 2, m_.planned_count = 1, memset(m_.offsets, 0, sizeof m_.offsets)), COA_OK);
}
END_TEST

START_TEST(test_reject_track)
{
    EXPECT(coavoid_track_t, track, m_.utime = T0 + 5000000, COAVOID_LCM_ERR_TIME);
    EXPECT(coavoid_track_t, track, m_.source_id = -4, COAVOID_LCM_ERR_ID);
    EXPECT(coavoid_track_t, track, m_.sequence = -1, COAVOID_LCM_ERR_VALUE);
    EXPECT(coavoid_track_t, track, m_.track_id = 0, COAVOID_LCM_ERR_ID);
    EXPECT(coavoid_track_t, track, m_.estimate_utime = 0, COAVOID_LCM_ERR_TIME);
    EXPECT(coavoid_track_t, track, m_.position[0] = NAN, COAVOID_LCM_ERR_NONFINITE);
    EXPECT(coavoid_track_t, track, m_.velocity[1] = -1e5, COAVOID_LCM_ERR_VALUE);
    EXPECT(coavoid_track_t, track, m_.radius = -1.0, COAVOID_LCM_ERR_VALUE);
    EXPECT(coavoid_track_t, track, m_.half_height = 1e6, COAVOID_LCM_ERR_VALUE);
    EXPECT(coavoid_track_t, track, m_.path_count = 17, COAVOID_LCM_ERR_COUNT);
    EXPECT(coavoid_track_t, track, m_.path_count = -1, COAVOID_LCM_ERR_COUNT);
    EXPECT(coavoid_track_t, track, m_.path_utime[2] = m_.path_utime[1], COAVOID_LCM_ERR_TIME);
    EXPECT(coavoid_track_t, track, m_.path_utime[0] = -1, COAVOID_LCM_ERR_TIME);
    EXPECT(coavoid_track_t, track, m_.path[1][2] = INFINITY, COAVOID_LCM_ERR_NONFINITE);
    EXPECT(coavoid_track_t, track, m_.sigma_horizontal = NAN, COAVOID_LCM_ERR_NONFINITE);
    EXPECT(coavoid_track_t, track, m_.sigma_vertical = -2.0, COAVOID_LCM_ERR_VALUE);
}
END_TEST

START_TEST(test_reject_obstacle_map)
{
    EXPECT(coavoid_obstacle_map_t, obstacle_map, m_.utime = 0, COAVOID_LCM_ERR_TIME);
    EXPECT(coavoid_obstacle_map_t, obstacle_map, m_.utime = T0 + 5000000, COAVOID_LCM_ERR_TIME);
    /* A latched map may be old. */
    EXPECT(coavoid_obstacle_map_t, obstacle_map, m_.utime = T0 - 3600000000, COA_OK);
    EXPECT(coavoid_obstacle_map_t, obstacle_map, m_.map_id = 70000, COAVOID_LCM_ERR_ID);
    EXPECT(coavoid_obstacle_map_t, obstacle_map, m_.version = -1, COAVOID_LCM_ERR_VALUE);
    EXPECT(coavoid_obstacle_map_t, obstacle_map, m_.box_count = 11, COAVOID_LCM_ERR_COUNT);
    EXPECT(coavoid_obstacle_map_t, obstacle_map, m_.box_count = -1, COAVOID_LCM_ERR_COUNT);
    EXPECT(coavoid_obstacle_map_t, obstacle_map, m_.box_min[1][2] = NAN, COAVOID_LCM_ERR_NONFINITE);
    EXPECT(coavoid_obstacle_map_t, obstacle_map, m_.box_max[0][0] = 1e8, COAVOID_LCM_ERR_VALUE);
    EXPECT(coavoid_obstacle_map_t, obstacle_map, m_.box_min[0][1] = 200.0, COAVOID_LCM_ERR_VALUE);
    EXPECT(coavoid_obstacle_map_t, obstacle_map, m_.polytope_count = 5, COAVOID_LCM_ERR_COUNT);
    EXPECT(coavoid_obstacle_map_t, obstacle_map, m_.vertex_count[0] = 3, COAVOID_LCM_ERR_COUNT);
    EXPECT(coavoid_obstacle_map_t, obstacle_map, m_.vertex_count[0] = 33, COAVOID_LCM_ERR_COUNT);
    EXPECT(coavoid_obstacle_map_t, obstacle_map, m_.vertices[4][1] = -INFINITY,
           COAVOID_LCM_ERR_NONFINITE);
    /* The tile's polytopes share MAX_VERTICES. */
    EXPECT(coavoid_obstacle_map_t, obstacle_map, (m_.polytope_count = 2, m_.vertex_count[1] = 27),
           COA_OK);
    EXPECT(coavoid_obstacle_map_t, obstacle_map, (m_.polytope_count = 2, m_.vertex_count[1] = 28),
           COAVOID_LCM_ERR_COUNT);
    EXPECT(coavoid_obstacle_map_t, obstacle_map,
           (m_.polytope_count = 2, m_.vertex_count[1] = 27, m_.vertices[31][0] = NAN),
           COAVOID_LCM_ERR_NONFINITE);
    /* Tiles: index below count, count 1..MAX_TILES. */
    EXPECT(coavoid_obstacle_map_t, obstacle_map, m_.tile_index = 2, COAVOID_LCM_ERR_COUNT);
    EXPECT(coavoid_obstacle_map_t, obstacle_map, m_.tile_index = -1, COAVOID_LCM_ERR_COUNT);
    EXPECT(coavoid_obstacle_map_t, obstacle_map, m_.tile_count = 0, COAVOID_LCM_ERR_COUNT);
    EXPECT(coavoid_obstacle_map_t, obstacle_map, m_.tile_count = 17, COAVOID_LCM_ERR_COUNT);
    EXPECT(coavoid_obstacle_map_t, obstacle_map, (m_.tile_count = 16, m_.tile_index = 15), COA_OK);
}
END_TEST

START_TEST(test_reject_conflict_report)
{
    EXPECT(coavoid_conflict_report_t, conflict_report, m_.utime = 0, COAVOID_LCM_ERR_TIME);
    EXPECT(coavoid_conflict_report_t, conflict_report, m_.reporter_id = 0, COAVOID_LCM_ERR_ID);
    EXPECT(coavoid_conflict_report_t, conflict_report, m_.sequence = -1, COAVOID_LCM_ERR_VALUE);
    EXPECT(coavoid_conflict_report_t, conflict_report, m_.prediction_utime = 0,
           COAVOID_LCM_ERR_TIME);
    EXPECT(coavoid_conflict_report_t, conflict_report, m_.dt = 0.0, COAVOID_LCM_ERR_VALUE);
    EXPECT(coavoid_conflict_report_t, conflict_report, m_.horizon = 0, COAVOID_LCM_ERR_COUNT);
    EXPECT(coavoid_conflict_report_t, conflict_report, m_.conflict_count = 31,
           COAVOID_LCM_ERR_COUNT);
    EXPECT(coavoid_conflict_report_t, conflict_report, m_.conflicts_found = 1,
           COAVOID_LCM_ERR_COUNT);
    EXPECT(coavoid_conflict_report_t, conflict_report, m_.kind[1] = 3, COAVOID_LCM_ERR_ENUM);
    EXPECT(coavoid_conflict_report_t, conflict_report, m_.a_id[0] = 0, COAVOID_LCM_ERR_ID);
    EXPECT(coavoid_conflict_report_t, conflict_report, m_.b_id[0] = m_.a_id[0], COAVOID_LCM_ERR_ID);
    EXPECT(coavoid_conflict_report_t, conflict_report, m_.b_id[1] = -1, COAVOID_LCM_ERR_ID);
    EXPECT(coavoid_conflict_report_t, conflict_report, m_.first_step[0] = 60,
           COAVOID_LCM_ERR_VALUE);
    EXPECT(coavoid_conflict_report_t, conflict_report, m_.min_horizontal[0] = NAN,
           COAVOID_LCM_ERR_NONFINITE);
    EXPECT(coavoid_conflict_report_t, conflict_report, m_.min_vertical[1] = -1.0,
           COAVOID_LCM_ERR_VALUE);
    EXPECT(coavoid_conflict_report_t, conflict_report, m_.probability[1] = 1.5,
           COAVOID_LCM_ERR_VALUE);
    EXPECT(coavoid_conflict_report_t, conflict_report, m_.probability[1] = NAN,
           COAVOID_LCM_ERR_NONFINITE);
    EXPECT(coavoid_conflict_report_t, conflict_report, m_.cluster[0] = -2, COAVOID_LCM_ERR_VALUE);
}
END_TEST

START_TEST(test_reject_status)
{
    EXPECT(coavoid_status_t, status, m_.utime = T0 - 11000000, COAVOID_LCM_ERR_TIME);
    EXPECT(coavoid_status_t, status, m_.node_id = 65536, COAVOID_LCM_ERR_ID);
    EXPECT(coavoid_status_t, status, m_.node_kind = 2, COAVOID_LCM_ERR_ENUM);
    EXPECT(coavoid_status_t, status, m_.sequence = -1, COAVOID_LCM_ERR_VALUE);
    EXPECT(coavoid_status_t, status, m_.health = 3, COAVOID_LCM_ERR_ENUM);
    EXPECT(coavoid_status_t, status, m_.mode = -1, COAVOID_LCM_ERR_ENUM);
    EXPECT(coavoid_status_t, status, m_.outcome = 4, COAVOID_LCM_ERR_ENUM);
    EXPECT(coavoid_status_t, status, m_.last_plan_utime = T0 + 1, COAVOID_LCM_ERR_TIME);
    EXPECT(coavoid_status_t, status, m_.last_plan_duration_us = -1, COAVOID_LCM_ERR_VALUE);
    EXPECT(coavoid_status_t, status, m_.nodes_expanded = -1, COAVOID_LCM_ERR_VALUE);
    EXPECT(coavoid_status_t, status, m_.conflicts = -1, COAVOID_LCM_ERR_VALUE);
    EXPECT(coavoid_status_t, status, m_.messages_rejected = 1001, COAVOID_LCM_ERR_COUNT);
    EXPECT(coavoid_status_t, status, m_.messages_received = -1, COAVOID_LCM_ERR_COUNT);
    EXPECT(coavoid_status_t, status, m_.last_reject_code = 1, COAVOID_LCM_ERR_VALUE);
    EXPECT(coavoid_status_t, status, m_.messages_dropped = -1, COAVOID_LCM_ERR_COUNT);
    EXPECT(coavoid_status_t, status, m_.inbox_rate = -1, COAVOID_LCM_ERR_COUNT);
    /* reasons: known bits only, none exactly when OK, a fatal one exactly when FAULT. */
    EXPECT(coavoid_status_t, status, m_.reasons = COAVOID_STATUS_T_REASON_NO_MAP,
           COAVOID_LCM_ERR_VALUE);
    EXPECT(coavoid_status_t, status, (m_.health = COAVOID_STATUS_T_HEALTH_DEGRADED, m_.reasons = 0),
           COAVOID_LCM_ERR_VALUE);
    EXPECT(coavoid_status_t, status,
           (m_.health = COAVOID_STATUS_T_HEALTH_DEGRADED, m_.reasons = 2048),
           COAVOID_LCM_ERR_VALUE);
    EXPECT(coavoid_status_t, status,
           (m_.health = COAVOID_STATUS_T_HEALTH_DEGRADED,
            m_.reasons = COAVOID_STATUS_T_REASON_INBOX_FLOOD),
           COA_OK);
    EXPECT(coavoid_status_t, status,
           (m_.health = COAVOID_STATUS_T_HEALTH_DEGRADED,
            m_.reasons = COAVOID_STATUS_T_REASON_DUPLICATE_ID),
           COAVOID_LCM_ERR_VALUE);
    EXPECT(coavoid_status_t, status,
           (m_.health = COAVOID_STATUS_T_HEALTH_FAULT, m_.reasons = COAVOID_STATUS_T_REASON_NO_MAP),
           COAVOID_LCM_ERR_VALUE);
    EXPECT(coavoid_status_t, status,
           (m_.health = COAVOID_STATUS_T_HEALTH_FAULT,
            m_.reasons = COAVOID_STATUS_T_REASON_INTERNAL_ERROR | COAVOID_STATUS_T_REASON_NO_MAP),
           COA_OK);
    EXPECT(coavoid_status_t, status,
           (m_.health = COAVOID_STATUS_T_HEALTH_DEGRADED,
            m_.reasons = COAVOID_STATUS_T_REASON_NO_PLAN | COAVOID_STATUS_T_REASON_STALE_PEERS),
           COA_OK);
}
END_TEST

START_TEST(test_sequence_rules)
{
    coavoid_lcm_sender_t entries[2];
    coavoid_lcm_sequence_table_t table;
    coavoid_lcm_context_t ctx = ctx_now();
    coavoid_intent_t m = good_intent();
    intent_view_t *v = malloc(sizeof *v);
    coavoid_obstacle_map_t map = good_map();
    const char *why = NULL;
    ck_assert_ptr_nonnull(v);
#define INTENT_IN() \
    coavoid_lcm_intent_to_core(&m, &ctx, &table, &v->info, &v->vehicle, &v->plan, &v->arrays, &why)
    coavoid_lcm_sequence_init(&table, entries, 2);
    ck_assert_int_eq(INTENT_IN(), COA_OK);
    /* The same sequence again, and an older one: refused, nothing recorded. */
    ck_assert_int_eq(INTENT_IN(), COAVOID_LCM_ERR_SEQUENCE);
    m.sequence = 41;
    ck_assert_int_eq(INTENT_IN(), COAVOID_LCM_ERR_SEQUENCE);
    m.sequence = 43;
    ck_assert_int_eq(INTENT_IN(), COA_OK);
    /* An invalid message does not advance the sequence. */
    m.sequence = 100;
    m.steep_factor = 2;
    ck_assert_int_eq(INTENT_IN(), COAVOID_LCM_ERR_VALUE);
    m.steep_factor = 3;
    m.sequence = 44;
    ck_assert_int_eq(INTENT_IN(), COA_OK);
    /* Senders are independent; the table is bounded. */
    m.uav_id = 8;
    m.sequence = 0;
    ck_assert_int_eq(INTENT_IN(), COA_OK);
    m.uav_id = 9;
    ck_assert_int_eq(INTENT_IN(), COAVOID_LCM_ERR_SENDERS);
    coavoid_lcm_sequence_forget(&table, 8);
    ck_assert_int_eq(INTENT_IN(), COA_OK);
#undef INTENT_IN
    free(v);
    /* A map may be republished with the same version, never an older one. */
    coavoid_lcm_sequence_init(&table, entries, 2);
    ck_assert_int_eq(coavoid_lcm_obstacle_map_accept(&map, &ctx, &table, &why), COA_OK);
    ck_assert_int_eq(coavoid_lcm_obstacle_map_accept(&map, &ctx, &table, &why), COA_OK);
    map.version = 3;
    ck_assert_int_eq(coavoid_lcm_obstacle_map_accept(&map, &ctx, &table, &why),
                     COAVOID_LCM_ERR_SEQUENCE);
    ck_assert_str_eq(coavoid_lcm_error_name(COAVOID_LCM_ERR_SEQUENCE), "sequence went backwards");
}
END_TEST

/* ---- counting what arrives ---- */

START_TEST(test_rx_count)
{
    coavoid_lcm_rx_stats_t rx;
    coavoid_status_t st = good_status();
    coavoid_lcm_context_t ctx = ctx_now();
    const char *why = "untouched";
    coavoid_intent_t bad = good_intent();
    int rc;
    coavoid_lcm_rx_init(&rx);
    ck_assert(rx.received == 0 && rx.rejected == 0);
    ck_assert_int_eq(rx.last_reject_code, 0);
    ck_assert_str_eq(rx.last_reason, "none");

    coavoid_lcm_rx_count(&rx, COA_OK, "ok");
    ck_assert(rx.received == 1 && rx.rejected == 0);
    ck_assert_str_eq(rx.last_reason, "none");
    /* A refusal as a node meets it: the check's code and its reason string. */
    bad.climb_rate = NAN;
    rc = coavoid_lcm_intent_check(&bad, &ctx, &why); /* before reading why: argument order */
    coavoid_lcm_rx_count(&rx, rc, why);
    ck_assert(rx.received == 2 && rx.rejected == 1);
    ck_assert_int_eq(rx.last_reject_code, COAVOID_LCM_ERR_NONFINITE);
    ck_assert_ptr_eq(rx.last_reason, why);
    ck_assert_ptr_nonnull(strstr(rx.last_reason, "climb_rate"));
    /* An acceptance leaves the last refusal as it was. */
    coavoid_lcm_rx_count(&rx, COA_OK, "ok");
    ck_assert(rx.received == 3 && rx.rejected == 1);
    ck_assert_int_eq(rx.last_reject_code, COAVOID_LCM_ERR_NONFINITE);
    /* No reason given: the code's name. */
    coavoid_lcm_rx_count(&rx, COAVOID_LCM_ERR_DECODE, NULL);
    ck_assert(rx.received == 4 && rx.rejected == 2);
    ck_assert_int_eq(rx.last_reject_code, COAVOID_LCM_ERR_DECODE);
    ck_assert_str_eq(rx.last_reason, "message does not decode");
    /* A decoder's byte count is a success, not a positive reject code (which would make
     * the status message itself refused). */
    coavoid_lcm_rx_count(&rx, 3791, NULL);
    ck_assert(rx.received == 5 && rx.rejected == 2);
    ck_assert_int_eq(rx.last_reject_code, COAVOID_LCM_ERR_DECODE);

    /* What the status message carries passes the status check. */
    st.messages_received = rx.received;
    st.messages_rejected = rx.rejected;
    st.last_reject_code = rx.last_reject_code;
    ck_assert_int_eq(coavoid_lcm_status_check(&st, &ctx, &why), COA_OK);

    /* Saturation: neither counter wraps, and rejected never passes received. */
    rx.received = INT64_MAX - 1;
    rx.rejected = INT64_MAX - 2;
    coavoid_lcm_rx_count(&rx, COAVOID_LCM_ERR_TIME, "t");
    ck_assert(rx.received == INT64_MAX && rx.rejected == INT64_MAX - 1);
    coavoid_lcm_rx_count(&rx, COAVOID_LCM_ERR_ID, "i");
    ck_assert(rx.received == INT64_MAX && rx.rejected == INT64_MAX);
    coavoid_lcm_rx_count(&rx, COAVOID_LCM_ERR_COUNT, "c");
    ck_assert(rx.received == INT64_MAX && rx.rejected == INT64_MAX);
    ck_assert_int_eq(rx.last_reject_code, COAVOID_LCM_ERR_COUNT);
    ck_assert_str_eq(rx.last_reason, "c");
    coavoid_lcm_rx_count(&rx, COA_OK, NULL);
    ck_assert(rx.received == INT64_MAX && rx.rejected == INT64_MAX);
    st.messages_received = rx.received;
    st.messages_rejected = rx.rejected;
    st.last_reject_code = rx.last_reject_code;
    ck_assert_int_eq(coavoid_lcm_status_check(&st, &ctx, &why), COA_OK);

    /* NULL is harmless. */
    coavoid_lcm_rx_init(NULL);
    coavoid_lcm_rx_count(NULL, COAVOID_LCM_ERR_TIME, "t");
}
END_TEST

/* ---- hostile bytes ---- */

/* Decodes buf[0..len) as `type` and, when it decodes, validates it and runs `usable` on
 * what the check accepted. Either way nothing may crash, leak or read out of bounds. */
#define HOSTILE(type, checker, buf, len, usable)                              \
    do {                                                                      \
        type m_;                                                              \
        const char *why_ = NULL;                                              \
        coavoid_lcm_context_t ctx_ = ctx_now();                               \
        memset(&m_, 0, sizeof m_);                                            \
        if (type##_decode((buf), 0, (int)(len), &m_) >= 0) {                  \
            decoded++;                                                        \
            if (coavoid_lcm_##checker##_check(&m_, &ctx_, &why_) == COA_OK) { \
                accepted++;                                                   \
                usable;                                                       \
            }                                                                 \
            REQUIRE(why_ != NULL);                                            \
            type##_decode_cleanup(&m_);                                       \
        }                                                                     \
    } while (0)

static void hostile_all(const unsigned char *buf, size_t len, int which, int *decoded_out,
                        int *accepted_out)
{
    int decoded = 0;
    int accepted = 0;
    switch (which) {
    /* An intent a receiver accepts is one its planner can take. */
    case 0:
        HOSTILE(coavoid_intent_t, intent, buf, len, require_usable_intent(&m_));
        break;
    case 1:
        HOSTILE(coavoid_plan_t, plan, buf, len, (void)0);
        break;
    case 2:
        HOSTILE(coavoid_track_t, track, buf, len, (void)0);
        break;
    case 3:
        HOSTILE(coavoid_obstacle_map_t, obstacle_map, buf, len, (void)0);
        break;
    case 4:
        HOSTILE(coavoid_conflict_report_t, conflict_report, buf, len, (void)0);
        break;
    default:
        HOSTILE(coavoid_status_t, status, buf, len, (void)0);
        break;
    }
    *decoded_out += decoded;
    *accepted_out += accepted;
}

/* A valid encoding of type `which` into a fresh heap buffer of exactly its size (so
 * ASan catches any read past it). */
static unsigned char *encode_good(int which, size_t *len)
{
    unsigned char *buf = NULL;
    int size = 0;
#define ENC(type, fn)                                             \
    do {                                                          \
        type m_ = fn();                                           \
        size = type##_encoded_size(&m_);                          \
        buf = malloc((size_t)size);                               \
        ck_assert_ptr_nonnull(buf);                               \
        ck_assert_int_eq(type##_encode(buf, 0, size, &m_), size); \
    } while (0)
    switch (which) {
    case 0:
        ENC(coavoid_intent_t, good_intent);
        break;
    case 1:
        ENC(coavoid_plan_t, good_plan);
        break;
    case 2:
        ENC(coavoid_track_t, good_track);
        break;
    case 3:
        ENC(coavoid_obstacle_map_t, good_map);
        break;
    case 4:
        ENC(coavoid_conflict_report_t, good_report);
        break;
    default:
        ENC(coavoid_status_t, good_status);
        break;
    }
#undef ENC
    *len = (size_t)size;
    return buf;
}

START_TEST(test_truncated_bytes)
{
    int which;
    for (which = 0; which < 6; ++which) {
        size_t len;
        size_t cut;
        int decoded = 0;
        int accepted = 0;
        unsigned char *good = encode_good(which, &len);
        for (cut = 0; cut < len; ++cut) {
            /* An exact-size copy, so a read past the cut is an ASan error. */
            unsigned char *part = malloc(cut > 0u ? cut : 1u);
            ck_assert_ptr_nonnull(part);
            memcpy(part, good, cut);
            hostile_all(part, cut, which, &decoded, &accepted);
            free(part);
        }
        /* Every proper prefix is refused by the decoder itself. */
        ck_assert_int_eq(decoded, 0);
        hostile_all(good, len, which, &decoded, &accepted);
        ck_assert_int_eq(decoded, 1);
        ck_assert_int_eq(accepted, 1);
        free(good);
    }
}
END_TEST

START_TEST(test_random_bytes)
{
    int which;
    rng_state = UINT64_C(0x1234567);
    for (which = 0; which < 6; ++which) {
        size_t len;
        int i;
        int decoded = 0;
        int accepted = 0;
        unsigned char *good = encode_good(which, &len);
        unsigned char *buf = malloc(len);
        ck_assert_ptr_nonnull(buf);
        for (i = 0; i < 2000; ++i) {
            size_t j;
            size_t n = (size_t)(rng_next() % (len + 1u));
            uint64_t mode = rng_next() % 3u;
            if (mode == 0u) {
                /* Pure noise: the fingerprint refuses nearly all of it. */
                for (j = 0; j < len; ++j) {
                    buf[j] = (unsigned char)rng_next();
                }
                n = len;
            } else {
                /* A valid message with random bytes flipped and a random length: past the
                 * fingerprint, so the decoder and every check see hostile fields. */
                size_t flips = 1u + (size_t)(rng_next() % 16u);
                memcpy(buf, good, len);
                for (j = 0; j < flips; ++j) {
                    size_t at = 8u + (size_t)(rng_next() % (len - 8u));
                    buf[at] = (unsigned char)rng_next();
                }
                if (mode == 1u) {
                    n = len;
                }
            }
            hostile_all(buf, n, which, &decoded, &accepted);
        }
        /* The flipped cases of full length decode (fixed sizes): the checks ran on them. */
        ck_assert_int_gt(decoded, 100);
        /* Both ways: some corrupted messages pass their check (a flip in a field's slack;
         * for intents, require_usable_intent then ran on them), and some are refused. */
        ck_assert_int_gt(accepted, 20);
        ck_assert_int_gt(decoded - accepted, 5);
        free(buf);
        free(good);
    }
}
END_TEST

/* ---- signed messages (auth.h) ---- */

/* A signer and a trust list that knows it as `role` for `node`, key id 7, with a fleet key
 * they share. */
static void auth_pair(coavoid_auth_signer_t *signer, coavoid_auth_trust_t *trust,
                      coavoid_auth_role_t role, uint16_t node)
{
    coavoid_auth_key_t key;
    memset(&key, 0, sizeof key);
    memset(signer, 0, sizeof *signer);
    key.key_id = 7;
    key.role = role;
    key.node_id = node;
    ck_assert_int_eq(coavoid_auth_keypair(key.public_key, signer->secret_key), COA_OK);
    signer->key_id = 7;
    coavoid_auth_trust_init(trust);
    ck_assert_int_eq(coavoid_auth_trust_add(trust, &key), COA_OK);
    ck_assert_int_eq(coavoid_auth_trust_add(trust, &key), COA_ERR_ARGUMENT); /* repeated */
    unsigned char fleet[COAVOID_AUTH_FLEET_KEY_BYTES];
    ck_assert_int_eq(coavoid_auth_fleet_key(fleet), COA_OK);
    ck_assert_int_eq(coavoid_auth_trust_set_fleet_key(trust, fleet), COA_OK);
    coavoid_auth_signer_use_fleet(signer, trust);
}

/* The good status, signed at `now` into buf; its size. */
static int signed_status(coavoid_auth_signer_t *signer, int64_t now, unsigned char *buf, int cap)
{
    coavoid_status_t m = good_status();
    coavoid_auth_next(signer, now, &m.auth.key_id, &m.auth.timestamp_us, &m.auth.sequence);
    int size = coavoid_status_t_encode(buf, 0, cap, &m);
    ck_assert_int_gt(size, 0);
    ck_assert_int_eq(coavoid_auth_sign(signer, buf, (size_t)size), COA_OK);
    return size;
}

/* A signed datagram verifies with its key, and any changed byte before the tag (the
 * fingerprint, a field, the key id, the time, the signature) makes it fail; any changed
 * byte at all fails the fleet tag; unsigned and unknown keys are told apart. */
START_TEST(test_auth_sign_verify)
{
    coavoid_auth_signer_t signer;
    coavoid_auth_trust_t trust;
    auth_pair(&signer, &trust, COAVOID_AUTH_COORDINATOR, 1);
    unsigned char buf[512];
    const int size = signed_status(&signer, T0, buf, (int)sizeof buf);
    ck_assert_int_eq(size, coavoid_status_t_encoded_size(&(coavoid_status_t){0}));
    size_t key = 99;
    ck_assert_int_eq(coavoid_auth_verify(&trust, buf, (size_t)size, &key), COA_OK);
    ck_assert_uint_eq(key, 0);
    ck_assert_int_eq(coavoid_auth_tag_check(&trust, buf, (size_t)size), COA_OK);
    for (int at = 0; at < size; at++) {
        buf[at] ^= 0x01;
        int rc = coavoid_auth_verify(&trust, buf, (size_t)size, &key);
        ck_assert_msg(rc == COAVOID_AUTH_ERR_SIGNATURE || rc == COAVOID_AUTH_ERR_KEY ||
                          rc == COAVOID_AUTH_ERR_UNSIGNED || at >= size - 8,
                      "byte %d changed, verify %d", at, rc);
        ck_assert_int_eq(coavoid_auth_tag_check(&trust, buf, (size_t)size), COAVOID_AUTH_ERR_TAG);
        buf[at] ^= 0x01;
    }
    coavoid_status_t m = good_status(); /* unsigned: key_id 0 */
    unsigned char plain[512];
    int n = coavoid_status_t_encode(plain, 0, (int)sizeof plain, &m);
    ck_assert_int_eq(coavoid_auth_verify(&trust, plain, (size_t)n, &key),
                     COAVOID_AUTH_ERR_UNSIGNED);
    ck_assert_int_eq(coavoid_auth_verify(&trust, plain, 10, &key), COAVOID_AUTH_ERR_UNSIGNED);
    signer.key_id = 8; /* a key the receiver does not know */
    n = signed_status(&signer, T0, plain, (int)sizeof plain);
    ck_assert_int_eq(coavoid_auth_verify(&trust, plain, (size_t)n, &key), COAVOID_AUTH_ERR_KEY);
}
END_TEST

/* Roles: a key speaks only for its role and node. Freshness: a copy or a replay is
 * refused, as is a time outside the window; a restarted sender (a later clock, its
 * sequence from 0) is accepted at once. */
START_TEST(test_auth_roles_and_freshness)
{
    coavoid_auth_signer_t signer;
    coavoid_auth_trust_t trust;
    auth_pair(&signer, &trust, COAVOID_AUTH_VEHICLE, 3);
    ck_assert_int_eq(coavoid_auth_may_send(&trust, 0, COAVOID_AUTH_VEHICLE, 3), COA_OK);
    ck_assert_int_eq(coavoid_auth_may_send(&trust, 0, COAVOID_AUTH_VEHICLE, 4),
                     COAVOID_AUTH_ERR_ROLE);
    ck_assert_int_eq(coavoid_auth_may_send(&trust, 0, COAVOID_AUTH_COORDINATOR, 0),
                     COAVOID_AUTH_ERR_ROLE);
    ck_assert_int_eq(coavoid_auth_may_send(&trust, 1, COAVOID_AUTH_VEHICLE, 3),
                     COAVOID_AUTH_ERR_ROLE);
    const int64_t window = 2000000;
    const size_t st = COAVOID_AUTH_STREAM_STATUS;
    ck_assert_int_eq(coavoid_auth_fresh(&trust, 0, st, T0, 0, T0, window, window), COA_OK);
    ck_assert_int_eq(coavoid_auth_fresh(&trust, 0, st, T0, 0, T0, window, window),
                     COAVOID_AUTH_ERR_REPLAY);
    ck_assert_int_eq(coavoid_auth_fresh(&trust, 0, st, T0, 1, T0, window, window), COA_OK);
    ck_assert_int_eq(coavoid_auth_fresh(&trust, 0, st, T0 - 5, 9, T0, window, window),
                     COAVOID_AUTH_ERR_REPLAY);
    ck_assert_int_eq(coavoid_auth_fresh(&trust, 0, st, T0 + 3 * window, 0, T0, window, window),
                     COAVOID_AUTH_ERR_CLOCK);
    ck_assert_int_eq(coavoid_auth_fresh(&trust, 0, st, T0 - 3 * window, 0, T0, window, window),
                     COAVOID_AUTH_ERR_CLOCK);
    ck_assert_int_eq(coavoid_auth_fresh(&trust, 0, st, T0 + 10, 0, T0 + 10, window, window),
                     COA_OK);
    /* The window is lopsided: old messages up to max_age, but little ahead (a replay from a
     * clock running ahead must not outrank the sender's next messages). */
    ck_assert_int_eq(
        coavoid_auth_fresh(&trust, 0, st, T0 + 100 + window / 2, 0, T0 + 100, window, window / 4),
        COAVOID_AUTH_ERR_CLOCK);
    /* Streams are apart: an intent sent before that heartbeat but delivered after it is
     * not a replay; a bad stream or key is never fresh. */
    ck_assert_int_eq(coavoid_auth_fresh(&trust, 0, COAVOID_AUTH_STREAM_INTENT, T0 + 5, 0, T0 + 10,
                                        window, window),
                     COA_OK);
    ck_assert_int_eq(
        coavoid_auth_fresh(&trust, 0, COAVOID_AUTH_STREAMS, T0 + 20, 0, T0, window, window),
        COAVOID_AUTH_ERR_REPLAY);
    ck_assert_int_eq(coavoid_auth_fresh(&trust, 1, st, T0 + 20, 0, T0, window, window),
                     COAVOID_AUTH_ERR_REPLAY);
    /* The receiver's rule in one call: the role for the message's own id (out of range:
     * none), then freshness. */
    const size_t in = COAVOID_AUTH_STREAM_INTENT;
    ck_assert_int_eq(coavoid_auth_accept(&trust, 0, in, COAVOID_AUTH_VEHICLE, 0, T0 + 50, 0,
                                         T0 + 50, window, window),
                     COAVOID_AUTH_ERR_ROLE);
    ck_assert_int_eq(coavoid_auth_accept(&trust, 0, in, COAVOID_AUTH_VEHICLE, 65539, T0 + 50, 0,
                                         T0 + 50, window, window),
                     COAVOID_AUTH_ERR_ROLE);
    ck_assert_int_eq(coavoid_auth_accept(&trust, 0, in, COAVOID_AUTH_VEHICLE, 3, T0 + 50, 0,
                                         T0 + 50, window, window),
                     COA_OK);
    ck_assert_int_eq(coavoid_auth_accept(&trust, 0, in, COAVOID_AUTH_VEHICLE, 3, T0 + 50, 0,
                                         T0 + 50, window, window),
                     COAVOID_AUTH_ERR_REPLAY);
    /* The signer's numbers: the clock, then a sequence while it stands still. */
    int32_t id;
    int64_t ts, seq;
    coavoid_auth_next(&signer, T0, &id, &ts, &seq);
    ck_assert(id == 7 && ts == T0 && seq == 0);
    coavoid_auth_next(&signer, T0, &id, &ts, &seq);
    ck_assert(ts == T0 && seq == 1);
    coavoid_auth_next(&signer, T0 + 1, &id, &ts, &seq);
    ck_assert(ts == T0 + 1 && seq == 0);
}
END_TEST

/* The checks before any cryptography (coavoid_auth_precheck): what the tail alone
 * refuses is refused with the reason the full check would give, without marking anything
 * (a datagram that passes it is still fresh for coavoid_auth_accept); a forged signature
 * under a fresh tail passes it and fails only at the signature. */
START_TEST(test_auth_precheck)
{
    coavoid_auth_signer_t signer;
    coavoid_auth_trust_t trust;
    auth_pair(&signer, &trust, COAVOID_AUTH_VEHICLE, 3);
    unsigned char buf[512];
    const int size = signed_status(&signer, T0, buf, (int)sizeof buf);
    const int64_t window = 2000000;
    coavoid_auth_expect_t ex = {COAVOID_AUTH_STREAM_STATUS, COAVOID_AUTH_VEHICLE, T0, window,
                                window};
    size_t key = 99;
    ck_assert_int_eq(coavoid_auth_precheck(&trust, buf, (size_t)size, &ex, &key), COA_OK);
    ck_assert_uint_eq(key, 0);
    /* Nothing marked: the same tail passes again, and is then accepted once. */
    ck_assert_int_eq(coavoid_auth_precheck(&trust, buf, (size_t)size, &ex, &key), COA_OK);
    ck_assert_int_eq(coavoid_auth_accept(&trust, 0, ex.stream, COAVOID_AUTH_VEHICLE, 3, T0, 0, T0,
                                         window, window),
                     COA_OK);
    /* A copy of what was accepted: a replay, before its signature is looked at. */
    ck_assert_int_eq(coavoid_auth_precheck(&trust, buf, (size_t)size, &ex, &key),
                     COAVOID_AUTH_ERR_REPLAY);
    /* The next one passes. With its signature broken (an outsider's fresh stamp) it fails
     * at the fleet tag; without a fleet key in the trust list only at the signature. */
    const int next = signed_status(&signer, T0 + 1, buf, (int)sizeof buf);
    ck_assert_int_eq(coavoid_auth_precheck(&trust, buf, (size_t)next, &ex, &key), COA_OK);
    buf[next - 9] ^= 0x40;
    ck_assert_int_eq(coavoid_auth_precheck(&trust, buf, (size_t)next, &ex, &key),
                     COAVOID_AUTH_ERR_TAG);
    trust.has_fleet_key = false;
    ck_assert_int_eq(coavoid_auth_precheck(&trust, buf, (size_t)next, &ex, &key), COA_OK);
    ck_assert_int_eq(coavoid_auth_verify(&trust, buf, (size_t)next, &key),
                     COAVOID_AUTH_ERR_SIGNATURE);
    trust.has_fleet_key = true;
    /* A member without the fleet key: its tag is zero, and refused as an outsider's. */
    buf[next - 9] ^= 0x40;
    signer.has_fleet_key = false;
    ck_assert_int_eq(coavoid_auth_sign(&signer, buf, (size_t)next), COA_OK);
    for (int at = next - 8; at < next; at++) {
        ck_assert_uint_eq(buf[at], 0);
    }
    ck_assert_int_eq(coavoid_auth_precheck(&trust, buf, (size_t)next, &ex, &key),
                     COAVOID_AUTH_ERR_TAG);
    ck_assert_int_eq(coavoid_auth_verify(&trust, buf, (size_t)next, &key), COA_OK);
    signer.has_fleet_key = true;
    ck_assert_int_eq(coavoid_auth_sign(&signer, buf, (size_t)next), COA_OK);
    /* Out of the window, another role, another channel's stream from a clean slate. */
    ex.now = T0 + 10 * window;
    ck_assert_int_eq(coavoid_auth_precheck(&trust, buf, (size_t)next, &ex, &key),
                     COAVOID_AUTH_ERR_CLOCK);
    ex.now = T0;
    ex.role = COAVOID_AUTH_COORDINATOR;
    ck_assert_int_eq(coavoid_auth_precheck(&trust, buf, (size_t)next, &ex, &key),
                     COAVOID_AUTH_ERR_ROLE);
    ex.role = COAVOID_AUTH_ANY_ROLE;
    ck_assert_int_eq(coavoid_auth_precheck(&trust, buf, (size_t)next, &ex, &key), COA_OK);
    ex.stream = COAVOID_AUTH_STREAMS;
    ck_assert_int_eq(coavoid_auth_precheck(&trust, buf, (size_t)next, &ex, &key),
                     COAVOID_AUTH_ERR_REPLAY);
    ex.stream = COAVOID_AUTH_STREAM_STATUS;
    /* Unsigned, too short, an unknown key. */
    coavoid_status_t m = good_status();
    unsigned char plain[512];
    int n = coavoid_status_t_encode(plain, 0, (int)sizeof plain, &m);
    ck_assert_int_eq(coavoid_auth_precheck(&trust, plain, (size_t)n, &ex, &key),
                     COAVOID_AUTH_ERR_UNSIGNED);
    ck_assert_int_eq(coavoid_auth_precheck(&trust, plain, 10, &ex, &key),
                     COAVOID_AUTH_ERR_UNSIGNED);
    signer.key_id = 8;
    n = signed_status(&signer, T0 + 2, plain, (int)sizeof plain);
    ck_assert_int_eq(coavoid_auth_precheck(&trust, plain, (size_t)n, &ex, &key),
                     COAVOID_AUTH_ERR_KEY);
    ck_assert_int_eq(coavoid_auth_precheck(NULL, plain, (size_t)n, &ex, &key),
                     COAVOID_AUTH_ERR_UNSIGNED);
}
END_TEST

/* Stamping works on the datagram alone: the numbers land where LCM decodes them, the
 * signature verifies, and seeded keys are repeatable. */
START_TEST(test_auth_stamp)
{
    coavoid_auth_signer_t signer;
    coavoid_auth_trust_t trust;
    auth_pair(&signer, &trust, COAVOID_AUTH_VEHICLE, 3);
    coavoid_status_t m = good_status();
    unsigned char buf[512];
    const int size = coavoid_status_t_encode(buf, 0, (int)sizeof buf, &m);
    ck_assert_int_gt(size, 0);
    ck_assert_int_eq(coavoid_auth_stamp(&signer, T0 + 7, buf, (size_t)size), COA_OK);
    ck_assert_int_eq(coavoid_auth_stamp(&signer, T0 + 7, buf, (size_t)size), COA_OK);
    coavoid_status_t back;
    ck_assert_int_eq(coavoid_status_t_decode(buf, 0, size, &back), size);
    ck_assert(back.auth.key_id == 7 && back.auth.timestamp_us == T0 + 7 && back.auth.sequence == 1);
    size_t key = 99;
    ck_assert_int_eq(coavoid_auth_verify(&trust, buf, (size_t)size, &key), COA_OK);
    ck_assert_int_eq(coavoid_auth_stamp(&signer, T0, buf, 20), COA_ERR_ARGUMENT);
    ck_assert(signer.last_timestamp == T0 + 7 && signer.sequence == 1);
    unsigned char seed[COAVOID_AUTH_SEED_BYTES] = {1, 2, 3};
    unsigned char pk1[COAVOID_AUTH_PUBLIC_BYTES], pk2[COAVOID_AUTH_PUBLIC_BYTES];
    unsigned char sk1[COAVOID_AUTH_SECRET_BYTES], sk2[COAVOID_AUTH_SECRET_BYTES];
    ck_assert_int_eq(coavoid_auth_keypair_seed(seed, pk1, sk1), COA_OK);
    ck_assert_int_eq(coavoid_auth_keypair_seed(seed, pk2, sk2), COA_OK);
    ck_assert(memcmp(pk1, pk2, sizeof pk1) == 0 && memcmp(sk1, sk2, sizeof sk1) == 0);
    seed[0] = 9;
    ck_assert_int_eq(coavoid_auth_keypair_seed(seed, pk2, sk2), COA_OK);
    ck_assert(memcmp(pk1, pk2, sizeof pk1) != 0);
}
END_TEST

/* Keys as text: a trust file's lines and a secret key file round-trip; a bad line is
 * refused with its number and why, whatever else the file holds. */
START_TEST(test_auth_key_files)
{
    coavoid_auth_signer_t signer;
    coavoid_auth_trust_t trust;
    auth_pair(&signer, &trust, COAVOID_AUTH_VEHICLE, 3);
    char text[4 * COAVOID_AUTH_LINE_MAX] = "# the fleet\n\n";
    char key_line[COAVOID_AUTH_LINE_MAX], line[COAVOID_AUTH_LINE_MAX];
    ck_assert_int_eq(coavoid_auth_key_line(&trust.keys[0], key_line, sizeof key_line), COA_OK);
    strcat(text, key_line);
    coavoid_auth_trust_t back;
    char err[128] = "";
    ck_assert_int_eq(coavoid_auth_trust_parse(&back, text, strlen(text), err, sizeof err), COA_OK);
    ck_assert_uint_eq(back.count, 1);
    ck_assert_int_eq(memcmp(&back.keys[0], &trust.keys[0], sizeof back.keys[0]), 0);
    ck_assert_int_eq(coavoid_auth_signer_line(&signer, line, sizeof line), COA_OK);
    coavoid_auth_signer_t read;
    ck_assert_int_eq(coavoid_auth_signer_parse(&read, line, strlen(line), err, sizeof err), COA_OK);
    ck_assert(read.key_id == signer.key_id &&
              memcmp(read.secret_key, signer.secret_key, sizeof read.secret_key) == 0);
    /* The fleet line round-trips; a second one, or a bad one, is refused. */
    ck_assert(!back.has_fleet_key);
    char fleet_text[3 * COAVOID_AUTH_LINE_MAX];
    ck_assert_int_eq(coavoid_auth_fleet_line(trust.fleet_key, line, sizeof line), COA_OK);
    snprintf(fleet_text, sizeof fleet_text, "%s%s", key_line, line);
    ck_assert_int_eq(
        coavoid_auth_trust_parse(&back, fleet_text, strlen(fleet_text), err, sizeof err), COA_OK);
    ck_assert(back.has_fleet_key && back.count == 1 &&
              memcmp(back.fleet_key, trust.fleet_key, sizeof back.fleet_key) == 0);
    strcat(fleet_text, line);
    ck_assert_int_eq(
        coavoid_auth_trust_parse(&back, fleet_text, strlen(fleet_text), err, sizeof err),
        COA_ERR_ARGUMENT);
    ck_assert_str_eq(err, "line 3: a second fleet line");
    ck_assert_int_eq(coavoid_auth_fleet_line(trust.fleet_key, line, 20), COA_ERR_ARGUMENT);
    const char *bad[][2] = {
        {"7 pilot 3 00", "line 1: ROLE must be coordinator, world or vehicle"},
        {"# ok\n7 vehicle 3 00ff", "line 2: PUBLIC_KEY_HEX must be 64 hex digits"},
        {"0 vehicle 3 00", "line 1: KEY_ID must be in 1..2147483647 and NODE_ID in 1..65535"},
        {"7 vehicle 70000 00", "line 1: KEY_ID must be in 1..2147483647 and NODE_ID in 1..65535"},
        {"7 vehicle 3", "line 1: expected KEY_ID ROLE NODE_ID PUBLIC_KEY_HEX"},
        {"fleet 00ff", "line 1: expected fleet FLEET_KEY_HEX (32 hex digits)"},
        {"fleet", "line 1: expected KEY_ID ROLE NODE_ID PUBLIC_KEY_HEX"},
    };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        ck_assert_int_eq(
            coavoid_auth_trust_parse(&back, bad[i][0], strlen(bad[i][0]), err, sizeof err),
            COA_ERR_ARGUMENT);
        ck_assert_str_eq(err, bad[i][1]);
    }
    strcat(text, key_line); /* the same key twice */
    ck_assert_int_eq(coavoid_auth_trust_parse(&back, text, strlen(text), err, sizeof err),
                     COA_ERR_ARGUMENT);
    ck_assert_str_eq(err, "line 4: KEY_ID repeated, or more than 128 keys");
    char long_line[400];
    memset(long_line, '1', sizeof long_line - 1u);
    long_line[sizeof long_line - 1u] = '\0';
    ck_assert_int_eq(coavoid_auth_trust_parse(&back, long_line, strlen(long_line), err, sizeof err),
                     COA_ERR_ARGUMENT);
    ck_assert_str_eq(err, "line 1: longer than 255 characters");
    ck_assert_int_eq(
        coavoid_auth_signer_parse(&read, "coavoid-secret-key 7 abc", 24, err, sizeof err),
        COA_ERR_ARGUMENT);
    ck_assert_str_eq(err, "line 1: SECRET_KEY_HEX must be 128 hex digits");
}
END_TEST

/* An agreement on a plan: every field checked; who may sign each kind. */
START_TEST(test_agreement_check)
{
    coavoid_lcm_context_t ctx = ctx_now();
    const char *why = NULL;
    coavoid_agreement_t m = good_agreement();
    ck_assert_int_eq(coavoid_lcm_agreement_check(&m, &ctx, &why), COA_OK);
    m.kind = 5;
    ck_assert_int_eq(coavoid_lcm_agreement_check(&m, &ctx, &why), COAVOID_LCM_ERR_ENUM);
    m = good_agreement();
    m.node_id = 0;
    ck_assert_int_eq(coavoid_lcm_agreement_check(&m, &ctx, &why), COAVOID_LCM_ERR_ID);
    m = good_agreement();
    m.coordinator_id = 65536;
    ck_assert_int_eq(coavoid_lcm_agreement_check(&m, &ctx, &why), COAVOID_LCM_ERR_ID);
    /* A COMMIT names its coordinator as its sender. */
    m = good_agreement();
    m.kind = COAVOID_AGREEMENT_T_KIND_COMMIT;
    ck_assert_int_eq(coavoid_lcm_agreement_check(&m, &ctx, &why), COAVOID_LCM_ERR_ID);
    m.node_id = m.coordinator_id;
    ck_assert_int_eq(coavoid_lcm_agreement_check(&m, &ctx, &why), COA_OK);
    m = good_agreement();
    m.plan_id = -1;
    ck_assert_int_eq(coavoid_lcm_agreement_check(&m, &ctx, &why), COAVOID_LCM_ERR_VALUE);
    m = good_agreement();
    m.valid_from_utime = 0;
    ck_assert_int_eq(coavoid_lcm_agreement_check(&m, &ctx, &why), COAVOID_LCM_ERR_VALUE);
    m = good_agreement();
    m.utime = 0;
    ck_assert_int_lt(coavoid_lcm_agreement_check(&m, &ctx, &why), 0);
    ck_assert_int_eq(coavoid_lcm_agreement_role(COAVOID_AGREEMENT_T_KIND_ACCEPT),
                     COAVOID_AUTH_VEHICLE);
    ck_assert_int_eq(coavoid_lcm_agreement_role(COAVOID_AGREEMENT_T_KIND_SWITCHED),
                     COAVOID_AUTH_VEHICLE);
    ck_assert_int_eq(coavoid_lcm_agreement_role(COAVOID_AGREEMENT_T_KIND_ABORT),
                     COAVOID_AUTH_COORDINATOR);
}
END_TEST

static Suite *lcm_suite(void)
{
    Suite *s = suite_create("lcm");
    TCase *tc = tcase_create("messages");
    tcase_add_test(tc, test_round_trip_wire);
    tcase_add_test(tc, test_round_trip_intent_core);
    tcase_add_test(tc, test_plan_from_intent);
    tcase_add_test(tc, test_accepted_intent_is_plannable);
    tcase_add_test(tc, test_round_trip_plan_core);
    tcase_add_test(tc, test_round_trip_track_core);
    tcase_add_test(tc, test_round_trip_map_core);
    tcase_add_test(tc, test_map_tiles);
    tcase_add_test(tc, test_datagram_sizes);
    tcase_add_test(tc, test_round_trip_report_core);
    tcase_add_test(tc, test_reject_intent);
    tcase_add_test(tc, test_reject_plan);
    tcase_add_test(tc, test_reject_track);
    tcase_add_test(tc, test_reject_obstacle_map);
    tcase_add_test(tc, test_reject_conflict_report);
    tcase_add_test(tc, test_reject_status);
    tcase_add_test(tc, test_sequence_rules);
    tcase_add_test(tc, test_rx_count);
    tcase_add_test(tc, test_truncated_bytes);
    tcase_add_test(tc, test_random_bytes);
    tcase_add_test(tc, test_auth_sign_verify);
    tcase_add_test(tc, test_auth_roles_and_freshness);
    tcase_add_test(tc, test_auth_precheck);
    tcase_add_test(tc, test_auth_stamp);
    tcase_add_test(tc, test_auth_key_files);
    tcase_add_test(tc, test_agreement_check);
    suite_add_tcase(s, tc);
    return s;
}

int main(void)
{
    SRunner *sr = srunner_create(lcm_suite());
    int failed;
    srunner_run_all(sr, CK_NORMAL);
    failed = srunner_ntests_failed(sr);
    srunner_free(sr);
    return failed == 0 ? EXIT_SUCCESS : EXIT_FAILURE;
}
