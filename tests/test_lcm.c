/*
 * LCM messages: every type round-trips through encode/decode and through the core
 * types; each validation rule refuses its bad message; decoding random, truncated and
 * corrupted bytes never crashes (run under the sanitizers).
 */
#include <check.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#ifdef COAVOID_HAVE_LCM

#include "coavoid_lcm.h"

#include <math.h>

#define T0 INT64_C(1700000000000000) /* a plausible utime */

static coa_lcm_context_t ctx_now(void)
{
    coa_lcm_context_t c;
    c.now_utime = T0;
    c.max_age_us = INT64_C(10000000);
    c.max_future_us = INT64_C(1000000);
    c.epoch_utime = T0 - INT64_C(5000000);
    return c;
}

static uint64_t rng_state;
static uint64_t rng_next(void)
{
    /* splitmix64: fixed seeds, same cases on every machine. */
    uint64_t z = (rng_state += UINT64_C(0x9E3779B97F4A7C15));
    z = (z ^ (z >> 30)) * UINT64_C(0xBF58476D1CE4E5B9);
    z = (z ^ (z >> 27)) * UINT64_C(0x94D049BB133111EB);
    return z ^ (z >> 31);
}

/* ---- valid messages ---- */

static coavoid_intent_t good_intent(void)
{
    coavoid_intent_t m;
    int32_t j;
    memset(&m, 0, sizeof m);
    m.utime = T0;
    m.uav_id = 7;
    m.sequence = 42;
    m.priority = 2;
    m.mode = COAVOID_INTENT_T_MODE_DECOUPLED;
    m.position[0] = 100.0;
    m.position[1] = -50.0;
    m.position[2] = 120.0;
    m.velocity[0] = 20.0;
    m.radius = 30.0;
    m.half_height = 10.0;
    m.plan_utime = T0 - 500000;
    m.step = 1.0;
    m.sample_count = 61;
    for (j = 0; j < m.sample_count; ++j) {
        m.samples[j][0] = 100.0 + 20.0 * j;
        m.samples[j][1] = -50.0;
        m.samples[j][2] = 120.0 + (j % 5);
    }
    m.sigma_horizontal = 5.0;
    m.sigma_vertical = 2.5;
    return m;
}

static coavoid_plan_t good_plan(void)
{
    coavoid_plan_t m;
    int32_t i;
    int32_t k;
    memset(&m, 0, sizeof m);
    m.utime = T0;
    m.coordinator_id = 1;
    m.plan_id = 9;
    m.valid_from_utime = T0;
    m.valid_until_utime = T0 + 5000000;
    m.dt = 1.0;
    m.horizon = 60;
    m.mode = COAVOID_PLAN_T_MODE_CENTRALISED;
    m.status = COAVOID_PLAN_T_STATUS_SOLVED;
    m.deviation = 1234.5;
    m.effort = 6;
    m.nodes_expanded = 999;
    m.vehicle_count = 3;
    m.planned_count = 3;
    for (i = 0; i < 3; ++i) {
        m.uav_ids[i] = 10 + i;
        for (k = 0; k <= m.horizon; ++k) {
            m.offsets[i][k] = (k < 10) ? k * (i - 1) : 9 * (i - 1);
        }
    }
    return m;
}

static coavoid_track_t good_track(void)
{
    coavoid_track_t m;
    int32_t j;
    memset(&m, 0, sizeof m);
    m.utime = T0;
    m.source_id = 3;
    m.sequence = 5;
    m.track_id = 77;
    m.estimate_utime = T0 - 200000;
    m.position[0] = 500.0;
    m.position[1] = 500.0;
    m.position[2] = 150.0;
    m.velocity[0] = -30.0;
    m.velocity[2] = 1.0;
    m.radius = 50.0;
    m.half_height = 20.0;
    m.path_count = 3;
    for (j = 0; j < 3; ++j) {
        m.path_utime[j] = T0 + (int64_t)j * 1000000;
        m.path[j][0] = 500.0 - 30.0 * j;
        m.path[j][1] = 500.0;
        m.path[j][2] = 150.0 + j;
    }
    m.sigma_horizontal = 15.0;
    m.sigma_vertical = 5.0;
    return m;
}

static coavoid_obstacle_map_t good_map(void)
{
    coavoid_obstacle_map_t m;
    int32_t j;
    memset(&m, 0, sizeof m);
    m.utime = T0;
    m.map_id = 2;
    m.version = 4;
    m.box_count = 2;
    m.box_min[0][0] = 0.0;
    m.box_max[0][0] = 100.0;
    m.box_max[0][1] = 100.0;
    m.box_max[0][2] = 80.0;
    m.box_min[1][0] = 300.0;
    m.box_max[1][0] = 400.0;
    m.box_max[1][1] = 50.0;
    m.box_max[1][2] = 200.0;
    m.polytope_count = 1;
    m.vertex_count[0] = 5;
    for (j = 0; j < 5; ++j) {
        m.vertices[0][j][0] = 1000.0 + 50.0 * (j % 2);
        m.vertices[0][j][1] = 50.0 * (j / 2);
        m.vertices[0][j][2] = (j == 4) ? 90.0 : 0.0;
    }
    return m;
}

static coavoid_conflict_report_t good_report(void)
{
    coavoid_conflict_report_t m;
    memset(&m, 0, sizeof m);
    m.utime = T0;
    m.reporter_id = 1;
    m.sequence = 100;
    m.prediction_utime = T0;
    m.dt = 1.0;
    m.horizon = 60;
    m.conflicts_found = 2;
    m.conflict_count = 2;
    m.kind[0] = COAVOID_CONFLICT_REPORT_T_KIND_VEHICLE;
    m.a_id[0] = 10;
    m.b_id[0] = 11;
    m.first_step[0] = 12;
    m.min_horizontal[0] = 3.0;
    m.min_vertical[0] = 1.0;
    m.probability[0] = 1.0;
    m.cluster[0] = 0;
    m.kind[1] = COAVOID_CONFLICT_REPORT_T_KIND_TRACK;
    m.a_id[1] = 12;
    m.b_id[1] = 77;
    m.first_step[1] = 30;
    m.min_horizontal[1] = 40.0;
    m.min_vertical[1] = 5.0;
    m.probability[1] = 0.25;
    m.cluster[1] = 1;
    return m;
}

static coavoid_status_t good_status(void)
{
    coavoid_status_t m;
    memset(&m, 0, sizeof m);
    m.utime = T0;
    m.node_id = 1;
    m.node_kind = COAVOID_STATUS_T_NODE_COORDINATOR;
    m.sequence = 8;
    m.health = COAVOID_STATUS_T_HEALTH_OK;
    m.mode = COAVOID_STATUS_T_MODE_CENTRALISED;
    m.last_plan_utime = T0 - 100000;
    m.last_plan_duration_us = 2500;
    m.nodes_expanded = 321;
    m.outcome = COAVOID_STATUS_T_OUTCOME_SOLVED;
    m.conflicts = 2;
    m.messages_received = 1000;
    m.messages_rejected = 3;
    m.last_reject_code = COA_LCM_ERR_NONFINITE;
    return m;
}

/* Encodes `m` of a generated type, decodes it into a zeroed struct and compares bytes
 * (fixed-size arrays only, so the structs hold no pointers). */
#define ROUND_TRIP(type, m)                                                        \
    do {                                                                           \
        type back_;                                                                \
        int size_ = type##_encoded_size(&(m));                                     \
        unsigned char *buf_ = malloc((size_t)size_);                               \
        ck_assert_ptr_nonnull(buf_);                                               \
        ck_assert_int_eq(type##_encode(buf_, 0, size_, &(m)), size_);              \
        memset(&back_, 0, sizeof back_);                                           \
        ck_assert_int_eq(type##_decode(buf_, 0, size_, &back_), size_);            \
        ck_assert_int_eq(memcmp(&back_, &(m), sizeof back_), 0);                   \
        type##_decode_cleanup(&back_);                                             \
        free(buf_);                                                                \
    } while (0)

START_TEST(test_round_trip_wire)
{
    coavoid_intent_t i = good_intent();
    coavoid_plan_t p = good_plan();
    coavoid_track_t t = good_track();
    coavoid_obstacle_map_t o = good_map();
    coavoid_conflict_report_t c = good_report();
    coavoid_status_t s = good_status();
    coa_lcm_context_t ctx = ctx_now();
    const char *why = NULL;
    ck_assert_int_eq(coa_lcm_intent_check(&i, &ctx, &why), COA_OK);
    ck_assert_int_eq(coa_lcm_plan_check(&p, &ctx, &why), COA_OK);
    ck_assert_int_eq(coa_lcm_track_check(&t, &ctx, &why), COA_OK);
    ck_assert_int_eq(coa_lcm_obstacle_map_check(&o, &ctx, &why), COA_OK);
    ck_assert_int_eq(coa_lcm_conflict_report_check(&c, &ctx, &why), COA_OK);
    ck_assert_int_eq(coa_lcm_status_check(&s, &ctx, &why), COA_OK);
    ck_assert_str_eq(why, "ok");
    ROUND_TRIP(coavoid_intent_t, i);
    ROUND_TRIP(coavoid_plan_t, p);
    ROUND_TRIP(coavoid_track_t, t);
    ROUND_TRIP(coavoid_obstacle_map_t, o);
    ROUND_TRIP(coavoid_conflict_report_t, c);
    ROUND_TRIP(coavoid_status_t, s);
}
END_TEST

START_TEST(test_round_trip_intent_core)
{
    coavoid_intent_t m = good_intent();
    coavoid_intent_t back;
    coa_lcm_context_t ctx = ctx_now();
    coa_lcm_intent_info_t info;
    coa_intent_plan_t plan;
    coa_vec3_t samples[COAVOID_INTENT_T_MAX_SAMPLES];
    const char *why = NULL;
    ck_assert_int_eq(coa_lcm_intent_to_core(&m, &ctx, NULL, &info, &plan, samples,
                                            COAVOID_INTENT_T_MAX_SAMPLES, &why), COA_OK);
    ck_assert_uint_eq(plan.id, 7u);
    ck_assert_uint_eq(plan.count, 61u);
    ck_assert(fabs((double)plan.t0 - 4.5) < 1e-6);
    ck_assert_uint_eq(info.priority, 2u);
    ck_assert_int_eq(coa_lcm_intent_from_core(&plan, &info, &ctx, &back, &why), COA_OK);
#ifndef COA_SINGLE_PRECISION
    ck_assert_int_eq(memcmp(&back, &m, sizeof m), 0);
#endif
    ck_assert_int_eq(coa_lcm_intent_to_core(&m, &ctx, NULL, &info, &plan, samples, 60, &why),
                     COA_LCM_ERR_CAPACITY);
}
END_TEST

START_TEST(test_round_trip_plan_core)
{
    coavoid_plan_t m = good_plan();
    coavoid_plan_t back;
    coa_lcm_context_t ctx = ctx_now();
    coa_lcm_plan_info_t info;
    coa_plan_result_t result;
    int32_t offsets[COAVOID_PLAN_T_MAX_VEHICLES * COAVOID_PLAN_T_MAX_SAMPLES];
    const char *why = NULL;
    ck_assert_int_eq(coa_lcm_plan_to_core(&m, &ctx, NULL, &info, &result, offsets,
                                          sizeof offsets / sizeof offsets[0], &why), COA_OK);
    ck_assert_int_eq(result.status, COA_PLAN_SOLVED);
    ck_assert_uint_eq(result.planned_count, 3u);
    ck_assert_int_eq(offsets[2 * 61 + 60], 9);
    ck_assert_int_eq(coa_lcm_plan_from_core(&info, &result, offsets, &ctx, &back, &why), COA_OK);
    ck_assert_int_eq(memcmp(&back, &m, sizeof m), 0);
    ck_assert_int_eq(coa_lcm_plan_to_core(&m, &ctx, NULL, &info, &result, offsets, 3 * 61 - 1, &why),
                     COA_LCM_ERR_CAPACITY);
}
END_TEST

START_TEST(test_round_trip_track_core)
{
    coavoid_track_t m = good_track();
    coavoid_track_t back;
    coa_lcm_context_t ctx = ctx_now();
    coa_lcm_track_info_t info;
    coa_track_t track;
    coa_track_point_t path[COAVOID_TRACK_T_MAX_PATH];
    const char *why = NULL;
    ck_assert_int_eq(coa_lcm_track_to_core(&m, &ctx, NULL, &info, &track, path,
                                           COAVOID_TRACK_T_MAX_PATH, &why), COA_OK);
    ck_assert_int_eq(coa_track_check(&track), COA_OK);
    /* Estimated at t = 4.8 s of the core clock: at t = 0 it was 4.8 s * 30 m/s east. */
    ck_assert(fabs((double)track.position.x - (500.0 + 30.0 * 4.8)) < 1e-3);
    ck_assert(fabs((double)path[1].t - 6.0) < 1e-6);
    ck_assert_int_eq(coa_lcm_track_from_core(&track, &info, &ctx, &back, &why), COA_OK);
    ck_assert_int_eq(back.track_id, 77);
    ck_assert_int_eq(back.path_count, 3);
    ck_assert_int_eq((int)(back.path_utime[2] - m.path_utime[2]), 0);
    /* Re-estimated at the epoch: the same straight line. */
    ck_assert(fabs(back.position[0] + back.velocity[0] * 4.8 - m.position[0]) < 1e-3);
}
END_TEST

START_TEST(test_round_trip_map_core)
{
    coavoid_obstacle_map_t m = good_map();
    coavoid_obstacle_map_t back;
    coa_lcm_context_t ctx = ctx_now();
    coa_obstacle_t obstacles[COAVOID_OBSTACLE_MAP_T_MAX_BOXES + COAVOID_OBSTACLE_MAP_T_MAX_POLYTOPES];
    coa_vec3_t vertices[COAVOID_OBSTACLE_MAP_T_MAX_POLYTOPES * COAVOID_OBSTACLE_MAP_T_MAX_VERTICES];
    size_t n = 0;
    size_t i;
    const char *why = NULL;
    ck_assert_int_eq(coa_lcm_obstacle_map_to_core(&m, &ctx, NULL, obstacles, 80, &n, vertices, 512,
                                                  &why), COA_OK);
    ck_assert_uint_eq(n, 3u);
    for (i = 0; i < n; ++i) {
        ck_assert_int_eq(coa_obstacle_check(&obstacles[i]), COA_OK);
    }
    ck_assert_int_eq(coa_lcm_obstacle_map_from_core(obstacles, n, m.utime, 2, 4, &ctx, &back, &why),
                     COA_OK);
    ck_assert_int_eq(memcmp(&back, &m, sizeof m), 0);
    ck_assert_int_eq(coa_lcm_obstacle_map_to_core(&m, &ctx, NULL, obstacles, 2, &n, vertices, 512,
                                                  &why), COA_LCM_ERR_CAPACITY);
    ck_assert_int_eq(coa_lcm_obstacle_map_to_core(&m, &ctx, NULL, obstacles, 80, &n, vertices, 4,
                                                  &why), COA_LCM_ERR_CAPACITY);
}
END_TEST

START_TEST(test_round_trip_report_core)
{
    coavoid_conflict_report_t m = good_report();
    coavoid_conflict_report_t back;
    coa_lcm_context_t ctx = ctx_now();
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
    ck_assert_int_eq(coa_lcm_conflict_report_from_core(c, 2, 2, plan_ids, 3, track_ids, 1, cluster,
                                                       T0, 1, 100, T0, 1.0, 60, &ctx, &back, &why),
                     COA_OK);
    ck_assert_int_eq(memcmp(&back, &m, sizeof m), 0);
}
END_TEST

/* ---- each rule refuses its bad message ---- */

#define EXPECT(type, checker, mutate, code)                           \
    do {                                                              \
        type m_ = good_##checker##_msg();                             \
        const char *why_ = NULL;                                      \
        coa_lcm_context_t ctx_ = ctx_now();                           \
        mutate;                                                       \
        ck_assert_int_eq(coa_lcm_##checker##_check(&m_, &ctx_, &why_), (code)); \
        ck_assert_ptr_nonnull(why_);                                  \
    } while (0)

#define good_intent_msg good_intent
#define good_plan_msg good_plan
#define good_track_msg good_track
#define good_obstacle_map_msg good_map
#define good_conflict_report_msg good_report
#define good_status_msg good_status

START_TEST(test_reject_intent)
{
    EXPECT(coavoid_intent_t, intent, m_.utime = 0, COA_LCM_ERR_TIME);
    EXPECT(coavoid_intent_t, intent, m_.utime = T0 - 20000000, COA_LCM_ERR_TIME);
    EXPECT(coavoid_intent_t, intent, m_.utime = T0 + 2000000, COA_LCM_ERR_TIME);
    EXPECT(coavoid_intent_t, intent, m_.uav_id = 0, COA_LCM_ERR_ID);
    EXPECT(coavoid_intent_t, intent, m_.uav_id = 65536, COA_LCM_ERR_ID);
    EXPECT(coavoid_intent_t, intent, m_.sequence = -1, COA_LCM_ERR_VALUE);
    EXPECT(coavoid_intent_t, intent, m_.priority = 0, COA_LCM_ERR_VALUE);
    EXPECT(coavoid_intent_t, intent, m_.mode = 3, COA_LCM_ERR_ENUM);
    EXPECT(coavoid_intent_t, intent, m_.position[1] = NAN, COA_LCM_ERR_NONFINITE);
    EXPECT(coavoid_intent_t, intent, m_.position[2] = 1e300, COA_LCM_ERR_VALUE);
    EXPECT(coavoid_intent_t, intent, m_.velocity[0] = INFINITY, COA_LCM_ERR_NONFINITE);
    EXPECT(coavoid_intent_t, intent, m_.velocity[0] = 2e4, COA_LCM_ERR_VALUE);
    EXPECT(coavoid_intent_t, intent, m_.radius = 0.0, COA_LCM_ERR_VALUE);
    EXPECT(coavoid_intent_t, intent, m_.half_height = -1.0, COA_LCM_ERR_VALUE);
    EXPECT(coavoid_intent_t, intent, m_.half_height = NAN, COA_LCM_ERR_NONFINITE);
    EXPECT(coavoid_intent_t, intent, m_.plan_utime = 0, COA_LCM_ERR_TIME);
    EXPECT(coavoid_intent_t, intent, m_.plan_utime = T0 + 20000000, COA_LCM_ERR_TIME);
    EXPECT(coavoid_intent_t, intent, m_.step = 0.0, COA_LCM_ERR_VALUE);
    EXPECT(coavoid_intent_t, intent, m_.step = NAN, COA_LCM_ERR_NONFINITE);
    EXPECT(coavoid_intent_t, intent, m_.sample_count = 0, COA_LCM_ERR_COUNT);
    EXPECT(coavoid_intent_t, intent, m_.sample_count = 129, COA_LCM_ERR_COUNT);
    EXPECT(coavoid_intent_t, intent, m_.sample_count = -5, COA_LCM_ERR_COUNT);
    EXPECT(coavoid_intent_t, intent, m_.samples[60][0] = NAN, COA_LCM_ERR_NONFINITE);
    EXPECT(coavoid_intent_t, intent, m_.sigma_horizontal = -0.1, COA_LCM_ERR_VALUE);
    EXPECT(coavoid_intent_t, intent, m_.sigma_vertical = INFINITY, COA_LCM_ERR_NONFINITE);
    /* A sample past sample_count is not part of the message. */
    EXPECT(coavoid_intent_t, intent, m_.samples[61][0] = NAN, COA_OK);
}
END_TEST

START_TEST(test_reject_plan)
{
    EXPECT(coavoid_plan_t, plan, m_.utime = -1, COA_LCM_ERR_TIME);
    EXPECT(coavoid_plan_t, plan, m_.coordinator_id = 0, COA_LCM_ERR_ID);
    EXPECT(coavoid_plan_t, plan, m_.plan_id = -3, COA_LCM_ERR_VALUE);
    EXPECT(coavoid_plan_t, plan, m_.valid_from_utime = 0, COA_LCM_ERR_TIME);
    EXPECT(coavoid_plan_t, plan, m_.valid_until_utime = m_.valid_from_utime, COA_LCM_ERR_TIME);
    EXPECT(coavoid_plan_t, plan, m_.dt = -1.0, COA_LCM_ERR_VALUE);
    EXPECT(coavoid_plan_t, plan, m_.dt = NAN, COA_LCM_ERR_NONFINITE);
    EXPECT(coavoid_plan_t, plan, m_.horizon = 0, COA_LCM_ERR_COUNT);
    EXPECT(coavoid_plan_t, plan, m_.horizon = 128, COA_LCM_ERR_COUNT);
    EXPECT(coavoid_plan_t, plan, m_.mode = 2, COA_LCM_ERR_ENUM);
    EXPECT(coavoid_plan_t, plan, m_.status = 3, COA_LCM_ERR_ENUM);
    EXPECT(coavoid_plan_t, plan, m_.deviation = -1.0, COA_LCM_ERR_VALUE);
    EXPECT(coavoid_plan_t, plan, m_.deviation = NAN, COA_LCM_ERR_NONFINITE);
    EXPECT(coavoid_plan_t, plan, m_.effort = -1, COA_LCM_ERR_VALUE);
    EXPECT(coavoid_plan_t, plan, m_.nodes_expanded = -1, COA_LCM_ERR_VALUE);
    EXPECT(coavoid_plan_t, plan, m_.vehicle_count = 0, COA_LCM_ERR_COUNT);
    EXPECT(coavoid_plan_t, plan, m_.vehicle_count = 33, COA_LCM_ERR_COUNT);
    EXPECT(coavoid_plan_t, plan, m_.planned_count = 2, COA_LCM_ERR_COUNT);
    EXPECT(coavoid_plan_t, plan, m_.planned_count = -1, COA_LCM_ERR_COUNT);
    EXPECT(coavoid_plan_t, plan, m_.uav_ids[2] = 0, COA_LCM_ERR_ID);
    EXPECT(coavoid_plan_t, plan, m_.uav_ids[2] = m_.uav_ids[0], COA_LCM_ERR_ID);
    EXPECT(coavoid_plan_t, plan, m_.offsets[1][5] = 40000, COA_LCM_ERR_VALUE);
    EXPECT(coavoid_plan_t, plan, m_.offsets[1][5] = 11, COA_LCM_ERR_VALUE);
    /* Not solved: fewer rows are plans. */
    EXPECT(coavoid_plan_t, plan, (m_.status = 2, m_.planned_count = 1), COA_OK);
}
END_TEST

START_TEST(test_reject_track)
{
    EXPECT(coavoid_track_t, track, m_.utime = T0 + 5000000, COA_LCM_ERR_TIME);
    EXPECT(coavoid_track_t, track, m_.source_id = -4, COA_LCM_ERR_ID);
    EXPECT(coavoid_track_t, track, m_.sequence = -1, COA_LCM_ERR_VALUE);
    EXPECT(coavoid_track_t, track, m_.track_id = 0, COA_LCM_ERR_ID);
    EXPECT(coavoid_track_t, track, m_.estimate_utime = 0, COA_LCM_ERR_TIME);
    EXPECT(coavoid_track_t, track, m_.position[0] = NAN, COA_LCM_ERR_NONFINITE);
    EXPECT(coavoid_track_t, track, m_.velocity[1] = -1e5, COA_LCM_ERR_VALUE);
    EXPECT(coavoid_track_t, track, m_.radius = -1.0, COA_LCM_ERR_VALUE);
    EXPECT(coavoid_track_t, track, m_.half_height = 1e6, COA_LCM_ERR_VALUE);
    EXPECT(coavoid_track_t, track, m_.path_count = 17, COA_LCM_ERR_COUNT);
    EXPECT(coavoid_track_t, track, m_.path_count = -1, COA_LCM_ERR_COUNT);
    EXPECT(coavoid_track_t, track, m_.path_utime[2] = m_.path_utime[1], COA_LCM_ERR_TIME);
    EXPECT(coavoid_track_t, track, m_.path_utime[0] = -1, COA_LCM_ERR_TIME);
    EXPECT(coavoid_track_t, track, m_.path[1][2] = INFINITY, COA_LCM_ERR_NONFINITE);
    EXPECT(coavoid_track_t, track, m_.sigma_horizontal = NAN, COA_LCM_ERR_NONFINITE);
    EXPECT(coavoid_track_t, track, m_.sigma_vertical = -2.0, COA_LCM_ERR_VALUE);
}
END_TEST

START_TEST(test_reject_obstacle_map)
{
    EXPECT(coavoid_obstacle_map_t, obstacle_map, m_.utime = 0, COA_LCM_ERR_TIME);
    EXPECT(coavoid_obstacle_map_t, obstacle_map, m_.utime = T0 + 5000000, COA_LCM_ERR_TIME);
    /* A latched map may be old. */
    EXPECT(coavoid_obstacle_map_t, obstacle_map, m_.utime = T0 - 3600000000, COA_OK);
    EXPECT(coavoid_obstacle_map_t, obstacle_map, m_.map_id = 70000, COA_LCM_ERR_ID);
    EXPECT(coavoid_obstacle_map_t, obstacle_map, m_.version = -1, COA_LCM_ERR_VALUE);
    EXPECT(coavoid_obstacle_map_t, obstacle_map, m_.box_count = 65, COA_LCM_ERR_COUNT);
    EXPECT(coavoid_obstacle_map_t, obstacle_map, m_.box_count = -1, COA_LCM_ERR_COUNT);
    EXPECT(coavoid_obstacle_map_t, obstacle_map, m_.box_min[1][2] = NAN, COA_LCM_ERR_NONFINITE);
    EXPECT(coavoid_obstacle_map_t, obstacle_map, m_.box_max[0][0] = 1e8, COA_LCM_ERR_VALUE);
    EXPECT(coavoid_obstacle_map_t, obstacle_map, m_.box_min[0][1] = 200.0, COA_LCM_ERR_VALUE);
    EXPECT(coavoid_obstacle_map_t, obstacle_map, m_.polytope_count = 17, COA_LCM_ERR_COUNT);
    EXPECT(coavoid_obstacle_map_t, obstacle_map, m_.vertex_count[0] = 3, COA_LCM_ERR_COUNT);
    EXPECT(coavoid_obstacle_map_t, obstacle_map, m_.vertex_count[0] = 33, COA_LCM_ERR_COUNT);
    EXPECT(coavoid_obstacle_map_t, obstacle_map, m_.vertices[0][4][1] = -INFINITY, COA_LCM_ERR_NONFINITE);
}
END_TEST

START_TEST(test_reject_conflict_report)
{
    EXPECT(coavoid_conflict_report_t, conflict_report, m_.utime = 0, COA_LCM_ERR_TIME);
    EXPECT(coavoid_conflict_report_t, conflict_report, m_.reporter_id = 0, COA_LCM_ERR_ID);
    EXPECT(coavoid_conflict_report_t, conflict_report, m_.sequence = -1, COA_LCM_ERR_VALUE);
    EXPECT(coavoid_conflict_report_t, conflict_report, m_.prediction_utime = 0, COA_LCM_ERR_TIME);
    EXPECT(coavoid_conflict_report_t, conflict_report, m_.dt = 0.0, COA_LCM_ERR_VALUE);
    EXPECT(coavoid_conflict_report_t, conflict_report, m_.horizon = 0, COA_LCM_ERR_COUNT);
    EXPECT(coavoid_conflict_report_t, conflict_report, m_.conflict_count = 65, COA_LCM_ERR_COUNT);
    EXPECT(coavoid_conflict_report_t, conflict_report, m_.conflicts_found = 1, COA_LCM_ERR_COUNT);
    EXPECT(coavoid_conflict_report_t, conflict_report, m_.kind[1] = 3, COA_LCM_ERR_ENUM);
    EXPECT(coavoid_conflict_report_t, conflict_report, m_.a_id[0] = 0, COA_LCM_ERR_ID);
    EXPECT(coavoid_conflict_report_t, conflict_report, m_.b_id[0] = m_.a_id[0], COA_LCM_ERR_ID);
    EXPECT(coavoid_conflict_report_t, conflict_report, m_.b_id[1] = -1, COA_LCM_ERR_ID);
    EXPECT(coavoid_conflict_report_t, conflict_report, m_.first_step[0] = 60, COA_LCM_ERR_VALUE);
    EXPECT(coavoid_conflict_report_t, conflict_report, m_.min_horizontal[0] = NAN, COA_LCM_ERR_NONFINITE);
    EXPECT(coavoid_conflict_report_t, conflict_report, m_.min_vertical[1] = -1.0, COA_LCM_ERR_VALUE);
    EXPECT(coavoid_conflict_report_t, conflict_report, m_.probability[1] = 1.5, COA_LCM_ERR_VALUE);
    EXPECT(coavoid_conflict_report_t, conflict_report, m_.probability[1] = NAN, COA_LCM_ERR_NONFINITE);
    EXPECT(coavoid_conflict_report_t, conflict_report, m_.cluster[0] = -2, COA_LCM_ERR_VALUE);
}
END_TEST

START_TEST(test_reject_status)
{
    EXPECT(coavoid_status_t, status, m_.utime = T0 - 11000000, COA_LCM_ERR_TIME);
    EXPECT(coavoid_status_t, status, m_.node_id = 65536, COA_LCM_ERR_ID);
    EXPECT(coavoid_status_t, status, m_.node_kind = 2, COA_LCM_ERR_ENUM);
    EXPECT(coavoid_status_t, status, m_.sequence = -1, COA_LCM_ERR_VALUE);
    EXPECT(coavoid_status_t, status, m_.health = 3, COA_LCM_ERR_ENUM);
    EXPECT(coavoid_status_t, status, m_.mode = -1, COA_LCM_ERR_ENUM);
    EXPECT(coavoid_status_t, status, m_.outcome = 4, COA_LCM_ERR_ENUM);
    EXPECT(coavoid_status_t, status, m_.last_plan_utime = T0 + 1, COA_LCM_ERR_TIME);
    EXPECT(coavoid_status_t, status, m_.last_plan_duration_us = -1, COA_LCM_ERR_VALUE);
    EXPECT(coavoid_status_t, status, m_.nodes_expanded = -1, COA_LCM_ERR_VALUE);
    EXPECT(coavoid_status_t, status, m_.conflicts = -1, COA_LCM_ERR_VALUE);
    EXPECT(coavoid_status_t, status, m_.messages_rejected = 1001, COA_LCM_ERR_COUNT);
    EXPECT(coavoid_status_t, status, m_.messages_received = -1, COA_LCM_ERR_COUNT);
    EXPECT(coavoid_status_t, status, m_.last_reject_code = 1, COA_LCM_ERR_VALUE);
}
END_TEST

START_TEST(test_sequence_rules)
{
    coa_lcm_sender_t entries[2];
    coa_lcm_sequence_table_t table;
    coa_lcm_context_t ctx = ctx_now();
    coavoid_intent_t m = good_intent();
    coa_lcm_intent_info_t info;
    coa_intent_plan_t plan;
    coa_vec3_t samples[COAVOID_INTENT_T_MAX_SAMPLES];
    coavoid_obstacle_map_t map = good_map();
    coa_obstacle_t obstacles[80];
    coa_vec3_t vertices[512];
    size_t n;
    const char *why = NULL;
    coa_lcm_sequence_init(&table, entries, 2);
    ck_assert_int_eq(coa_lcm_intent_to_core(&m, &ctx, &table, &info, &plan, samples, 128, &why), COA_OK);
    /* The same sequence again, and an older one: refused, nothing recorded. */
    ck_assert_int_eq(coa_lcm_intent_to_core(&m, &ctx, &table, &info, &plan, samples, 128, &why),
                     COA_LCM_ERR_SEQUENCE);
    m.sequence = 41;
    ck_assert_int_eq(coa_lcm_intent_to_core(&m, &ctx, &table, &info, &plan, samples, 128, &why),
                     COA_LCM_ERR_SEQUENCE);
    m.sequence = 43;
    ck_assert_int_eq(coa_lcm_intent_to_core(&m, &ctx, &table, &info, &plan, samples, 128, &why), COA_OK);
    /* An invalid message does not advance the sequence. */
    m.sequence = 100;
    m.radius = NAN;
    ck_assert_int_eq(coa_lcm_intent_to_core(&m, &ctx, &table, &info, &plan, samples, 128, &why),
                     COA_LCM_ERR_NONFINITE);
    m.radius = 30.0;
    m.sequence = 44;
    ck_assert_int_eq(coa_lcm_intent_to_core(&m, &ctx, &table, &info, &plan, samples, 128, &why), COA_OK);
    /* Senders are independent; the table is bounded. */
    m.uav_id = 8;
    m.sequence = 0;
    ck_assert_int_eq(coa_lcm_intent_to_core(&m, &ctx, &table, &info, &plan, samples, 128, &why), COA_OK);
    m.uav_id = 9;
    ck_assert_int_eq(coa_lcm_intent_to_core(&m, &ctx, &table, &info, &plan, samples, 128, &why),
                     COA_LCM_ERR_SENDERS);
    coa_lcm_sequence_forget(&table, 8);
    ck_assert_int_eq(coa_lcm_intent_to_core(&m, &ctx, &table, &info, &plan, samples, 128, &why), COA_OK);
    /* A map may be republished with the same version, never an older one. */
    coa_lcm_sequence_init(&table, entries, 2);
    ck_assert_int_eq(coa_lcm_obstacle_map_to_core(&map, &ctx, &table, obstacles, 80, &n, vertices, 512, &why), COA_OK);
    ck_assert_int_eq(coa_lcm_obstacle_map_to_core(&map, &ctx, &table, obstacles, 80, &n, vertices, 512, &why), COA_OK);
    map.version = 3;
    ck_assert_int_eq(coa_lcm_obstacle_map_to_core(&map, &ctx, &table, obstacles, 80, &n, vertices, 512, &why),
                     COA_LCM_ERR_SEQUENCE);
    ck_assert_str_eq(coa_lcm_error_name(COA_LCM_ERR_SEQUENCE), "sequence went backwards");
}
END_TEST

/* ---- hostile bytes ---- */

/* Decodes buf[0..len) as `type` and, when it decodes, validates and converts it. Either
 * way nothing may crash, leak or read out of bounds. Returns 1 when it decoded. */
#define HOSTILE(type, checker, buf, len)                                                    \
    do {                                                                                    \
        type m_;                                                                            \
        const char *why_ = NULL;                                                            \
        coa_lcm_context_t ctx_ = ctx_now();                                                 \
        memset(&m_, 0, sizeof m_);                                                          \
        if (type##_decode((buf), 0, (int)(len), &m_) >= 0) {                                \
            decoded++;                                                                      \
            if (coa_lcm_##checker##_check(&m_, &ctx_, &why_) == COA_OK) {                    \
                accepted++;                                                                 \
            }                                                                               \
            ck_assert_ptr_nonnull(why_);                                                    \
            type##_decode_cleanup(&m_);                                                     \
        }                                                                                   \
    } while (0)

static void hostile_all(const unsigned char *buf, size_t len, int which, int *decoded_out,
                        int *accepted_out)
{
    int decoded = 0;
    int accepted = 0;
    switch (which) {
    case 0: HOSTILE(coavoid_intent_t, intent, buf, len); break;
    case 1: HOSTILE(coavoid_plan_t, plan, buf, len); break;
    case 2: HOSTILE(coavoid_track_t, track, buf, len); break;
    case 3: HOSTILE(coavoid_obstacle_map_t, obstacle_map, buf, len); break;
    case 4: HOSTILE(coavoid_conflict_report_t, conflict_report, buf, len); break;
    default: HOSTILE(coavoid_status_t, status, buf, len); break;
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
#define ENC(type, fn)                                     \
    do {                                                  \
        type m_ = fn();                                   \
        size = type##_encoded_size(&m_);                  \
        buf = malloc((size_t)size);                       \
        ck_assert_ptr_nonnull(buf);                       \
        ck_assert_int_eq(type##_encode(buf, 0, size, &m_), size); \
    } while (0)
    switch (which) {
    case 0: ENC(coavoid_intent_t, good_intent); break;
    case 1: ENC(coavoid_plan_t, good_plan); break;
    case 2: ENC(coavoid_track_t, good_track); break;
    case 3: ENC(coavoid_obstacle_map_t, good_map); break;
    case 4: ENC(coavoid_conflict_report_t, good_report); break;
    default: ENC(coavoid_status_t, good_status); break;
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
        free(buf);
        free(good);
    }
}
END_TEST

static Suite *lcm_suite(void)
{
    Suite *s = suite_create("lcm");
    TCase *tc = tcase_create("messages");
    tcase_add_test(tc, test_round_trip_wire);
    tcase_add_test(tc, test_round_trip_intent_core);
    tcase_add_test(tc, test_round_trip_plan_core);
    tcase_add_test(tc, test_round_trip_track_core);
    tcase_add_test(tc, test_round_trip_map_core);
    tcase_add_test(tc, test_round_trip_report_core);
    tcase_add_test(tc, test_reject_intent);
    tcase_add_test(tc, test_reject_plan);
    tcase_add_test(tc, test_reject_track);
    tcase_add_test(tc, test_reject_obstacle_map);
    tcase_add_test(tc, test_reject_conflict_report);
    tcase_add_test(tc, test_reject_status);
    tcase_add_test(tc, test_sequence_rules);
    tcase_add_test(tc, test_truncated_bytes);
    tcase_add_test(tc, test_random_bytes);
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

#else /* !COAVOID_HAVE_LCM */

/* Built without LCM (COAVOID_BUILD_LCM=OFF): nothing to test. */
int main(void)
{
    puts("test_lcm: built without LCM, skipped");
    return EXIT_SUCCESS;
}

#endif
