/* SPDX-License-Identifier: MIT */
/*
 * lcm_examples.h: one valid message of each type, as of a receiver's clock T0, and that
 * receiver's validation context: what the message tests (test_lcm.c) change one field at a
 * time, and what the message fuzzer (fuzz/fuzz_messages.c) mutates.
 */
#ifndef COAVOID_TESTS_LCM_EXAMPLES_H
#define COAVOID_TESTS_LCM_EXAMPLES_H

#include <string.h>

#include "coavoid_lcm.h"

#define T0 INT64_C(1700000000000000) /* a plausible utime */

static inline coavoid_lcm_context_t ctx_now(void)
{
    coavoid_lcm_context_t c;
    c.now_utime = T0;
    c.max_age_us = INT64_C(10000000);
    c.max_future_us = INT64_C(1000000);
    c.epoch_utime = T0 - INT64_C(5000000);
    return c;
}

/* ---- valid messages ---- */

/* The good intent's offsets step through every action (steep factor 3) and return: net 0
 * every ten steps, -2, -5, -5, -4, -1, 2, 3, 3, 0, -1, -2, ... so in -5..3. */
static const int32_t ACTION_CYCLE[10] = {-3, 0, 1, 3, 3, 1, 0, -3, -1, -1};

static inline coavoid_intent_t good_intent(void)
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
    /* Numbers with no short binary expansion (1.8 * 0.9, 0.3 * j), so that computing a
     * position any other way than the planner does shows in the last bit. */
    m.cruise_speed = 18.0;
    m.climb_rate = 1.8;
    m.steep_factor = 3;
    m.max_offset = 40;
    m.plan_utime = T0 - 500000;
    m.step = 0.9;
    m.sample_count = 31; /* room past it: what is not part of the message */
    for (j = 0; j < m.sample_count; ++j) {
        m.reference[j][0] = 100.0 + 16.2 * j;
        m.reference[j][1] = -50.0 + 0.1 * j;
        m.reference[j][2] = 120.0 + 0.3 * j;
        m.offsets[j] = (j == 0) ? -2 : m.offsets[j - 1] + ACTION_CYCLE[(j - 1) % 10];
    }
    m.sigma_horizontal = 5.0;
    m.sigma_vertical = 2.5;
    m.rank = 3; /* a raised precedence, so that a round trip shows it is carried */
    return m;
}

/* The message of UAV 11, the second of three, of a solved plan over 40 steps. */
static inline coavoid_plan_t good_plan(void)
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
    m.horizon = 40;
    m.mode = COAVOID_PLAN_T_MODE_CENTRALISED;
    m.status = COAVOID_PLAN_T_STATUS_SOLVED;
    m.deviation = 1234.5;
    m.effort = 6;
    m.nodes_expanded = 999;
    m.vehicle_count = 3;
    m.planned_count = 3;
    for (i = 0; i < 3; ++i) {
        m.uav_ids[i] = 10 + i;
    }
    m.row_uav_id = 11;
    for (k = 0; k <= m.horizon; ++k) {
        m.offsets[k] = (k < 10) ? -k : -9;
    }
    return m;
}

/* The same plan's message for uav_ids[row]: row i's offsets are k * (i - 1) up to 9 steps. */
static inline coavoid_plan_t good_plan_row(int32_t row)
{
    coavoid_plan_t m = good_plan();
    int32_t k;
    m.row_uav_id = m.uav_ids[row];
    for (k = 0; k <= m.horizon; ++k) {
        m.offsets[k] = (k < 10) ? k * (row - 1) : 9 * (row - 1);
    }
    return m;
}

static inline coavoid_track_t good_track(void)
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

/* Tile 0 of a map of two tiles: two boxes and a pyramid of five vertices. */
static inline coavoid_obstacle_map_t good_map(void)
{
    coavoid_obstacle_map_t m;
    int32_t j;
    memset(&m, 0, sizeof m);
    m.utime = T0;
    m.map_id = 2;
    m.version = 4;
    m.tile_index = 0;
    m.tile_count = 2;
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
        m.vertices[j][0] = 1000.0 + 50.0 * (j % 2);
        m.vertices[j][1] = 50.0 * (j / 2);
        m.vertices[j][2] = (j == 4) ? 90.0 : 0.0;
    }
    return m;
}

/* Tile 1 of that map: one box. */
static inline coavoid_obstacle_map_t good_map_tile1(void)
{
    coavoid_obstacle_map_t m;
    memset(&m, 0, sizeof m);
    m.utime = T0;
    m.map_id = 2;
    m.version = 4;
    m.tile_index = 1;
    m.tile_count = 2;
    m.box_count = 1;
    m.box_min[0][0] = 500.0;
    m.box_max[0][0] = 600.0;
    m.box_max[0][1] = 60.0;
    m.box_max[0][2] = 70.0;
    return m;
}

static inline coavoid_conflict_report_t good_report(void)
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

static inline coavoid_status_t good_status(void)
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
    m.last_reject_code = COAVOID_LCM_ERR_NONFINITE;
    return m;
}

static inline coavoid_agreement_t good_agreement(void)
{
    coavoid_agreement_t m;
    memset(&m, 0, sizeof m);
    m.utime = T0;
    m.kind = COAVOID_AGREEMENT_T_KIND_ACCEPT;
    m.node_id = 2;
    m.coordinator_id = 65001;
    m.plan_id = 7;
    m.valid_from_utime = T0 - 250000;
    return m;
}

#endif /* COAVOID_TESTS_LCM_EXAMPLES_H */
