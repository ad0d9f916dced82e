/* SPDX-License-Identifier: MIT */
/*
 * test_node: the nodes of src/node (node.h) over LCM's in-process provider, driven on a
 * hand-set clock:
 *   - what arrives is counted (undecodable bytes too) and never the node's own messages;
 *     another UAV's intents under the node's id are refused and reported as a fault;
 *     a node that refused messages since its last heartbeat says it is degraded;
 *   - a UAV that restarts its numbering is accepted once it has been silent;
 *   - a coordinator's plan is adopted only under the rules of node.h (this cycle, from
 *     the offset flown, a plan_id newer than the last adopted in the cycle, before
 *     valid_until), no plan_id (forged, or from a restarted coordinator) locks later
 *     cycles out, and a plan into the terrain the UAV knows is refused;
 *   - the UAV falls back to planning for itself when the heartbeat stops and returns
 *     when it comes back; it follows only the coordinator it is configured with, not
 *     one that reports a fault, and not one whose plans do not come while it has a
 *     conflict (a plan that says its search failed is an answer); the coordinator plans
 *     no UAV that plans for itself;
 *   - a lower priority waits for the higher, up to its deadline; every member of a
 *     cluster in conflict plans, the highest priority too;
 *   - priority negotiation: a pair with no plan in the configured order agree the
 *     reverse by their order search (from cycle 0, on their first intents), each flying
 *     its row and announcing its rank, in the same cycle, or in the next one when the
 *     rank was lost to the UAV it overtakes; the ranks return to 0 after the encounter;
 *     and with greedy_negotiation, the greedy raise alone does the same without the
 *     search: 2 raises its rank, 1 climbs around it (the same cycle, or the next when
 *     the raise was lost to it);
 *   - a silent UAV is avoided as a track;
 *   - the world's track estimates reproduce the scenario's path over the horizon;
 *   - bad configurations are refused.
 */
#include <check.h>
#include <stdio.h>
#include <stdlib.h>

#include <math.h>
#include <string.h>

#include <lcm/lcm.h>

#include "net.h"
#include "node.h"
#include "test_support.h"

#define EPOCH INT64_C(1000000000000000)
#define DT_US INT64_C(1000000)

/* Publishes an unsigned message as an insecure node would: LCM's encoding of the type on
 * the channel; 0, or -1 when it does not encode or LCM refuses it. */
#define TEST_PUBLISH(lcm, type, channel, msg) \
    publish_encoded((lcm), (channel), type##_encode(publish_buf, 0, (int)sizeof publish_buf, (msg)))
static uint8_t publish_buf[65536];
static int publish_encoded(lcm_t *lcm, const char *channel, int size)
{
    return size < 0 ? -1 : lcm_publish(lcm, channel, publish_buf, (unsigned int)size);
}

typedef struct {
    lcm_t *lcm;
    int64_t now;
    coavoid_node_common_t common;
} rig_t;

static void rig_init(rig_t *r, uint32_t horizon)
{
    r->lcm = lcm_create("memq://");
    ck_assert_ptr_nonnull(r->lcm);
    r->now = EPOCH;
    ck_assert_int_eq(
        coavoid_node_common_defaults(&r->common, EPOCH, (coa_real_t)1, horizon, &r->now), COA_OK);
    /* The rig injects unsigned messages; signed nodes are tested apart (test_signed_*). */
    r->common.insecure = true;
}

static void drain(lcm_t *lcm)
{
    while (lcm_handle_timeout(lcm, 0) > 0) {
    }
}

/* The coordinator's cycle at `now` and the agreement it leads (docs/protocol.md): its
 * plans, the UAVs' answers, and every poll that is then due, each answer delivered, until
 * nothing more is due at `now` (a commit included). */
static void coordinate(lcm_t *lcm, coavoid_coordinator_t *co, int64_t now)
{
    ck_assert_int_eq(coavoid_coordinator_cycle(co, now), COA_OK);
    drain(lcm);
    while (coavoid_coordinator_deadline(co) <= now) {
        ck_assert_int_ge(coavoid_coordinator_poll(co, now), 0);
        drain(lcm);
    }
}

static int64_t cycle(int64_t k)
{
    return EPOCH + k * DT_US;
}

/* A UAV on a straight level route from (x0, y, z) towards x1 at 10 m/s. */
static coa_vehicle_t uav(uint16_t id, uint32_t priority, coa_vec3_t *route, coa_real_t x0,
                         coa_real_t x1, coa_real_t y, coa_real_t z)
{
    coa_vehicle_t v;
    memset(&v, 0, sizeof v);
    route[0].x = x0;
    route[0].y = y;
    route[0].z = z;
    route[1].x = x1;
    route[1].y = y;
    route[1].z = z;
    v.id = id;
    v.priority = priority;
    v.cruise_speed = 10;
    v.climb_rate = 2;
    v.steep_factor = 2;
    v.volume.radius = 15;
    v.volume.half_height = 5;
    v.route = route;
    v.route_count = 2;
    v.initial_offset = 0;
    v.max_offset = -1;
    return v;
}

/* A vehicle node on the rig's bus; answer_wait_us as coavoid_vehicle_node_config_t's
 * (0: the default). */
static coavoid_vehicle_node_t *vehicle_node_waiting(const rig_t *r, coa_vehicle_t v,
                                                    coavoid_node_mode_t mode,
                                                    int64_t answer_wait_us)
{
    coavoid_vehicle_node_config_t config;
    memset(&config, 0, sizeof config);
    config.common = r->common;
    config.vehicle = v;
    config.mode = mode;
    config.answer_wait_us = answer_wait_us;
    int error = -99;
    coavoid_vehicle_node_t *node = coavoid_vehicle_node_create(&config, r->lcm, NULL, &error);
    ck_assert_ptr_nonnull(node);
    ck_assert_int_eq(error, COA_OK);
    return node;
}

static coavoid_vehicle_node_t *vehicle_node(const rig_t *r, coa_vehicle_t v,
                                            coavoid_node_mode_t mode)
{
    return vehicle_node_waiting(r, v, mode, 0);
}

static void heartbeat_from(lcm_t *lcm, int64_t now, int64_t sequence, int32_t node_id,
                           int8_t health)
{
    coavoid_status_t m;
    memset(&m, 0, sizeof m);
    m.utime = now;
    m.node_id = node_id;
    m.node_kind = COAVOID_STATUS_T_NODE_COORDINATOR;
    m.sequence = sequence;
    m.health = health;
    m.reasons = health == COAVOID_STATUS_T_HEALTH_FAULT ? COAVOID_STATUS_T_REASON_INTERNAL_ERROR
                : health == COAVOID_STATUS_T_HEALTH_DEGRADED
                    ? COAVOID_STATUS_T_REASON_PLANNING_FAILED
                    : 0;
    m.mode = COAVOID_STATUS_T_MODE_CENTRALISED;
    m.outcome = COAVOID_STATUS_T_OUTCOME_NONE;
    ck_assert_int_eq(TEST_PUBLISH(lcm, coavoid_status_t, COAVOID_CHANNEL_STATUS, &m), 0);
}

static void heartbeat(lcm_t *lcm, int64_t now, int64_t sequence)
{
    coavoid_status_t m;
    memset(&m, 0, sizeof m);
    m.utime = now;
    m.node_id = COAVOID_NODE_COORDINATOR_ID;
    m.node_kind = COAVOID_STATUS_T_NODE_COORDINATOR;
    m.sequence = sequence;
    m.health = COAVOID_STATUS_T_HEALTH_OK;
    m.mode = COAVOID_STATUS_T_MODE_CENTRALISED;
    m.outcome = COAVOID_STATUS_T_OUTCOME_NONE;
    ck_assert_int_eq(TEST_PUBLISH(lcm, coavoid_status_t, COAVOID_CHANNEL_STATUS, &m), 0);
}

/* A solved plan_t's header from the default coordinator for the cycle starting at
 * valid_from, for `count` UAVs (the caller fills their ids and, in each UAV's message,
 * row_uav_id and its offsets). */
static coavoid_plan_t solved_plan(int64_t now, int64_t plan_id, int64_t valid_from, int32_t horizon,
                                  int32_t count)
{
    coavoid_plan_t m;
    memset(&m, 0, sizeof m);
    m.utime = now;
    m.coordinator_id = (int32_t)COAVOID_NODE_COORDINATOR_ID;
    m.plan_id = plan_id;
    m.valid_from_utime = valid_from;
    m.valid_until_utime = valid_from + DT_US;
    m.dt = 1.0;
    m.horizon = horizon;
    m.mode = COAVOID_PLAN_T_MODE_CENTRALISED;
    m.status = COAVOID_PLAN_T_STATUS_SOLVED;
    m.vehicle_count = count;
    m.planned_count = count;
    return m;
}

/* Coordinator `from`'s COMMIT of a plan (docs/protocol.md): the rig plays the
 * coordinator, which commits once every UAV of the plan accepted. */
static void commit_msg(lcm_t *lcm, int64_t now, int32_t from, int64_t plan_id, int64_t valid_from)
{
    coavoid_agreement_t m;
    memset(&m, 0, sizeof m);
    m.utime = now;
    m.kind = COAVOID_AGREEMENT_T_KIND_COMMIT;
    m.node_id = from;
    m.coordinator_id = from;
    m.plan_id = plan_id;
    m.valid_from_utime = valid_from;
    ck_assert_int_eq(TEST_PUBLISH(lcm, coavoid_agreement_t, COAVOID_CHANNEL_AGREEMENT, &m), 0);
}

/* A one-UAV plan_t from coordinator `from`: offsets 0, 1, 2, then level at 2, plus
 * `shift`; then its commit (what the coordinator sends once the UAV accepted). */
static void plan_msg_from(lcm_t *lcm, int64_t now, int32_t from, int64_t plan_id,
                          int64_t valid_from, uint16_t id, int32_t horizon, int32_t shift)
{
    coavoid_plan_t m = solved_plan(now, plan_id, valid_from, horizon, 1);
    m.coordinator_id = from;
    m.uav_ids[0] = id;
    m.row_uav_id = id;
    for (int32_t k = 0; k <= horizon; k++) {
        m.offsets[k] = (k < 2 ? k : 2) + shift;
    }
    ck_assert_int_eq(TEST_PUBLISH(lcm, coavoid_plan_t, COAVOID_CHANNEL_PLAN, &m), 0);
    commit_msg(lcm, now, from, plan_id, valid_from);
}

/* The same from the default coordinator. */
static void plan_msg(lcm_t *lcm, int64_t now, int64_t plan_id, int64_t valid_from, uint16_t id,
                     int32_t horizon, int32_t shift)
{
    plan_msg_from(lcm, now, (int32_t)COAVOID_NODE_COORDINATOR_ID, plan_id, valid_from, id, horizon,
                  shift);
}

/* An obstacle map with no obstacles from the world: a node that has none reports
 * REASON_NO_MAP, so the health tests give theirs one first. */
static void empty_map(lcm_t *lcm, int64_t now)
{
    coavoid_obstacle_map_t m;
    memset(&m, 0, sizeof m);
    m.utime = now;
    m.map_id = (int32_t)COAVOID_NODE_WORLD_ID;
    m.version = 1;
    m.tile_count = 1;
    ck_assert_int_eq(TEST_PUBLISH(lcm, coavoid_obstacle_map_t, COAVOID_CHANNEL_OBSTACLES, &m), 0);
}

/* ---- counting ---- */

START_TEST(test_undecodable_counted_own_ignored)
{
    rig_t r;
    rig_init(&r, 10);
    coa_vec3_t route[2];
    coavoid_vehicle_node_t *a =
        vehicle_node(&r, uav(1, 1, route, 0, 500, 0, 100), COAVOID_NODE_CENTRALISED);
    const coavoid_vehicle_node_state_t *s = coavoid_vehicle_node_state(a);
    ck_assert_int_eq(s->cycle, -1);

    /* Its own intent and heartbeat come back over memq: neither is counted. */
    ck_assert_int_eq(coavoid_vehicle_node_cycle(a, r.now), COA_OK);
    drain(r.lcm);
    ck_assert(s->published);
    ck_assert_int_eq(s->rx.received, 0);

    const uint8_t junk[7] = {1, 2, 3, 4, 5, 6, 7};
    const char *channels[] = {COAVOID_CHANNEL_INTENT, COAVOID_CHANNEL_TRACK,
                              COAVOID_CHANNEL_OBSTACLES, COAVOID_CHANNEL_STATUS,
                              COAVOID_CHANNEL_PLAN};
    for (size_t i = 0; i < 5; i++) {
        ck_assert_int_eq(lcm_publish(r.lcm, channels[i], junk, sizeof junk), 0);
    }
    drain(r.lcm);
    ck_assert_int_eq(s->rx.received, 5);
    ck_assert_int_eq(s->rx.rejected, 5);
    ck_assert_int_eq(s->rx.last_reject_code, COAVOID_LCM_ERR_DECODE);

    /* Another UAV's intent is counted and accepted. */
    coa_vec3_t route2[2];
    coavoid_vehicle_node_t *b =
        vehicle_node(&r, uav(2, 2, route2, 0, 500, 500, 100), COAVOID_NODE_DECOUPLED);
    ck_assert_int_eq(coavoid_vehicle_node_cycle(b, r.now), COA_OK);
    drain(r.lcm);
    ck_assert_int_eq(s->rx.received, 7); /* its intent and its heartbeat */
    ck_assert_int_eq(s->rx.rejected, 5);
    coavoid_vehicle_node_destroy(b);
    coavoid_vehicle_node_destroy(a);
    lcm_destroy(r.lcm);
}
END_TEST

/* A peer that restarts numbers its intents from 0 again: refused while its old numbering
 * is remembered, accepted once it has been silent past stale_after. */
START_TEST(test_restarted_peer_accepted_after_silence)
{
    rig_t r;
    rig_init(&r, 10);
    coa_vec3_t r1[2], r2[2];
    coa_vehicle_t v2 = uav(2, 2, r2, 0, 500, 800, 100);
    coavoid_vehicle_node_t *a =
        vehicle_node(&r, uav(1, 1, r1, 0, 500, 0, 100), COAVOID_NODE_DECOUPLED);
    coavoid_vehicle_node_t *b = vehicle_node(&r, v2, COAVOID_NODE_DECOUPLED);
    const coavoid_vehicle_node_state_t *s = coavoid_vehicle_node_state(a);
    for (int64_t k = 0; k <= 3; k++) {
        r.now = cycle(k);
        coavoid_vehicle_node_cycle(a, r.now);
        coavoid_vehicle_node_cycle(b, r.now);
        drain(r.lcm);
    }
    ck_assert_int_eq(s->rx.rejected, 0);
    coavoid_vehicle_node_destroy(b);
    b = vehicle_node(&r, v2, COAVOID_NODE_DECOUPLED); /* restarted: sequence 0 again */
    int64_t rejected_at[10] = {0};
    for (int64_t k = 4; k <= 9; k++) {
        r.now = cycle(k);
        coavoid_vehicle_node_cycle(a, r.now);
        drain(r.lcm);
        coavoid_vehicle_node_cycle(b, r.now);
        drain(r.lcm);
        rejected_at[k] = s->rx.rejected;
    }
    /* Last accepted at cycle 3; its numbering is forgotten once 2.5 cycles have passed,
     * at cycle 6's expiry: the intents of cycles 4 and 5 (sequences 0, 1) are refused,
     * those from cycle 6 on (2, 3, ...) are not. */
    ck_assert_int_eq(rejected_at[4], 1);
    ck_assert_int_eq(rejected_at[5], 2);
    ck_assert_int_eq(rejected_at[6], 2);
    ck_assert_int_eq(rejected_at[9], 2);
    ck_assert_int_eq(s->rx.last_reject_code, COAVOID_LCM_ERR_SEQUENCE);
    coavoid_vehicle_node_destroy(b);
    coavoid_vehicle_node_destroy(a);
    lcm_destroy(r.lcm);
}
END_TEST

/* ---- adoption of the coordinator's plans ---- */

START_TEST(test_plan_adoption_rules)
{
    rig_t r;
    rig_init(&r, 10);
    coa_vec3_t route[2];
    coavoid_vehicle_node_t *a =
        vehicle_node(&r, uav(1, 1, route, 0, 500, 0, 100), COAVOID_NODE_CENTRALISED);
    const coavoid_vehicle_node_state_t *s = coavoid_vehicle_node_state(a);
    ck_assert_int_eq(coavoid_vehicle_node_cycle(a, cycle(0)), COA_OK);
    drain(r.lcm);
    r.now = cycle(0) + DT_US / 4;
    int64_t rejected = s->rx.rejected;

    /* Not for it: received, neither rejected nor adopted. */
    plan_msg(r.lcm, r.now, 1, cycle(0), 7, 10, 0);
    drain(r.lcm);
    ck_assert_int_eq(s->rx.rejected, rejected);
    ck_assert_int_eq(s->plans_adopted, 0);
    /* For the previous cycle: refused. */
    plan_msg(r.lcm, r.now, 2, cycle(0) - DT_US, 1, 10, 0);
    drain(r.lcm);
    ck_assert_int_eq(s->rx.rejected, ++rejected);
    ck_assert_int_eq(s->rx.last_reject_code, COAVOID_LCM_ERR_TIME);
    /* Not from the offset it flies (0): refused. */
    plan_msg(r.lcm, r.now, 3, cycle(0), 1, 10, 3);
    drain(r.lcm);
    ck_assert_int_eq(s->rx.rejected, ++rejected);
    ck_assert_int_eq(s->rx.last_reject_code, COAVOID_LCM_ERR_VALUE);
    /* Right: adopted. */
    plan_msg(r.lcm, r.now, 4, cycle(0), 1, 10, 0);
    drain(r.lcm);
    ck_assert_int_eq(s->rx.rejected, rejected);
    ck_assert_int_eq(s->plans_adopted, 1);
    /* The same plan again (the coordinator sends again what it heard no answer to):
     * answered again, neither refused nor adopted twice. */
    plan_msg(r.lcm, r.now, 4, cycle(0), 1, 10, 0);
    drain(r.lcm);
    ck_assert_int_eq(s->rx.rejected, rejected);
    ck_assert_int_eq(s->plans_adopted, 1);
    /* An older plan_id: refused. */
    plan_msg(r.lcm, r.now, 3, cycle(0), 1, 10, 0);
    drain(r.lcm);
    ck_assert_int_eq(s->rx.rejected, ++rejected);
    ck_assert_int_eq(s->rx.last_reject_code, COAVOID_LCM_ERR_SEQUENCE);
    /* Too late (valid_until has come): refused. */
    r.now = cycle(1);
    plan_msg(r.lcm, r.now, 5, cycle(0), 1, 10, 0);
    drain(r.lcm);
    ck_assert_int_eq(s->rx.rejected, ++rejected);
    ck_assert_int_eq(s->rx.last_reject_code, COAVOID_LCM_ERR_TIME);
    ck_assert_int_eq(s->plans_adopted, 1);

    /* It flies the adopted plan: 1 at sample 1, 2 from sample 2 on, 2 dh above. */
    const int32_t want[4] = {0, 1, 2, 2};
    for (int64_t k = 1; k <= 3; k++) {
        ck_assert_int_eq(coavoid_vehicle_node_cycle(a, cycle(k)), COA_OK);
        drain(r.lcm);
        ck_assert_int_eq(s->offset, want[k]);
        ck_assert(s->position.z == s->reference.z + (coa_real_t)want[k] * (coa_real_t)2);
    }
    coavoid_vehicle_node_destroy(a);
    lcm_destroy(r.lcm);
}
END_TEST

/* Plans are ordered within a cycle only: valid_from already ties a plan to one cycle. A
 * forged plan_id INT64_MAX (for another UAV, or for this one) does not lock out the real
 * coordinator, whose heartbeats keep coming, and a restarted coordinator's numbering
 * from 0 is adopted at once. */
START_TEST(test_plan_ids_do_not_lock_out)
{
    rig_t r;
    rig_init(&r, 10);
    coa_vec3_t route[2];
    coavoid_vehicle_node_t *a =
        vehicle_node(&r, uav(1, 1, route, 0, 500, 0, 100), COAVOID_NODE_CENTRALISED);
    const coavoid_vehicle_node_state_t *s = coavoid_vehicle_node_state(a);
    int64_t sequence = 0;
    ck_assert_int_eq(coavoid_vehicle_node_cycle(a, cycle(0)), COA_OK);
    drain(r.lcm);
    r.now = cycle(0) + DT_US / 4;
    heartbeat(r.lcm, r.now, sequence++);
    /* A forged plan for a UAV that does not exist, then the real one for this UAV. */
    plan_msg(r.lcm, r.now, INT64_MAX, cycle(0), 999, 10, 0);
    plan_msg(r.lcm, r.now, 0, cycle(0), 1, 10, 0);
    drain(r.lcm);
    ck_assert_int_eq(s->plans_adopted, 1);
    ck_assert_int_eq(s->rx.rejected, 0);
    /* A forged plan for this UAV: within this cycle it supersedes, and the real
     * coordinator's next plan of this cycle is not newer. */
    plan_msg(r.lcm, r.now, INT64_MAX, cycle(0), 1, 10, 0);
    drain(r.lcm);
    ck_assert_int_eq(s->plans_adopted, 2);
    plan_msg(r.lcm, r.now, 1, cycle(0), 1, 10, 0);
    drain(r.lcm);
    ck_assert_int_eq(s->plans_adopted, 2);
    ck_assert_int_eq(s->rx.last_reject_code, COAVOID_LCM_ERR_SEQUENCE);
    /* From the next cycle on the real coordinator's plans are adopted again, and so are a
     * restarted coordinator's, numbered from 0. */
    const int64_t ids[4] = {2, 3, 0, 1};
    for (int64_t k = 1; k <= 4; k++) {
        r.now = cycle(k);
        ck_assert_int_eq(coavoid_vehicle_node_cycle(a, r.now), COA_OK);
        drain(r.lcm);
        ck_assert(s->coordinated);
        r.now = cycle(k) + DT_US / 4;
        heartbeat(r.lcm, r.now, sequence++);
        plan_msg(r.lcm, r.now, ids[k - 1], cycle(k), 1, 10, s->offset);
        drain(r.lcm);
        ck_assert_msg(s->plans_adopted == (uint32_t)(2 + k), "cycle %d: %s", (int)k,
                      s->rx.last_reason);
    }
    coavoid_vehicle_node_destroy(a);
    lcm_destroy(r.lcm);
}
END_TEST

/* A plan is checked against the terrain (and tracks) the UAV knows before it is adopted:
 * a forged plan that dives into a box below is refused, the real one is adopted. */
/* Terrain 2 km wide up to 90 m, under a UAV at 100 m. */
static coa_obstacle_t terrain_box(void)
{
    coa_obstacle_t box;
    memset(&box, 0, sizeof box);
    box.kind = COA_OBSTACLE_BOX;
    box.box.min.x = -1000;
    box.box.min.y = -1000;
    box.box.min.z = 0;
    box.box.max.x = 1000;
    box.box.max.y = 1000;
    box.box.max.z = 90;
    return box;
}

/* A coordinator's plan for UAV 1 (a forged plan_id near the top) that dives steeply from
 * 100 m: its bottom is below terrain_box's top from sample 3 on. It must be refused as
 * flying into terrain the UAV knows. */
static void dive_into_terrain(rig_t *r, const coavoid_vehicle_node_state_t *s)
{
    coavoid_plan_t m = solved_plan(r->now, INT64_MAX - 5, cycle(0), 10, 1);
    m.uav_ids[0] = 1;
    m.row_uav_id = 1;
    for (int32_t k = 0; k <= 10; k++) {
        m.offsets[k] = -2 * k;
    }
    const uint32_t adopted = s->plans_adopted;
    const int64_t rejected = s->rx.rejected;
    ck_assert_int_eq(TEST_PUBLISH(r->lcm, coavoid_plan_t, COAVOID_CHANNEL_PLAN, &m), 0);
    drain(r->lcm);
    ck_assert_int_eq(s->plans_adopted, adopted);
    ck_assert_int_eq(s->rx.rejected, rejected + 1);
    ck_assert_int_eq(s->rx.last_reject_code, COAVOID_LCM_ERR_VALUE);
    ck_assert_str_eq(s->rx.last_reason, "plan: flies this UAV into an obstacle or track it knows");
}

START_TEST(test_plan_into_terrain_refused)
{
    rig_t r;
    rig_init(&r, 10);
    coa_obstacle_t box = terrain_box();
    coavoid_world_config_t wc;
    memset(&wc, 0, sizeof wc);
    wc.common = r.common;
    wc.obstacles = &box;
    wc.obstacle_count = 1;
    int error = -99;
    coavoid_world_t *w = coavoid_world_create(&wc, r.lcm, &error);
    ck_assert_ptr_nonnull(w);
    coa_vec3_t route[2];
    coavoid_vehicle_node_t *a =
        vehicle_node(&r, uav(1, 1, route, 0, 500, 0, 100), COAVOID_NODE_CENTRALISED);
    const coavoid_vehicle_node_state_t *s = coavoid_vehicle_node_state(a);
    ck_assert_int_eq(coavoid_world_cycle(w, r.now), COA_OK);
    drain(r.lcm);
    ck_assert_int_eq(coavoid_vehicle_node_cycle(a, r.now), COA_OK);
    drain(r.lcm);
    r.now = cycle(0) + DT_US / 4;
    heartbeat(r.lcm, r.now, 0);
    drain(r.lcm);
    const int64_t rejected = s->rx.rejected;
    dive_into_terrain(&r, s);
    /* The real coordinator's plan (a climb) is adopted, although its plan_id is lower. */
    plan_msg(r.lcm, r.now, 0, cycle(0), 1, 10, 0);
    drain(r.lcm);
    ck_assert_int_eq(s->plans_adopted, 1);
    ck_assert_int_eq(s->rx.rejected, rejected + 1);
    for (int64_t k = 1; k <= 10; k++) {
        r.now = cycle(k);
        ck_assert_int_eq(coavoid_world_cycle(w, r.now), COA_OK);
        drain(r.lcm);
        ck_assert_int_eq(coavoid_vehicle_node_cycle(a, r.now), COA_OK);
        drain(r.lcm);
        ck_assert(s->position.z >= (coa_real_t)100);
    }
    coavoid_vehicle_node_destroy(a);
    coavoid_world_destroy(w);
    lcm_destroy(r.lcm);
}
END_TEST

/* A vehicle configured with a floor (min_altitude 90 m; its volume's bottom flies at
 * 95 m) refuses a plan whose dive takes that bottom below it at some sample, with a
 * reason that says so, adopts one that descends only to the floor, and never flies
 * below it. A floor no message could carry is refused at create. */
START_TEST(test_plan_below_floor_refused)
{
    rig_t r;
    rig_init(&r, 10);
    r.common.has_floor = true;
    r.common.min_altitude = (coa_real_t)90;
    coa_vec3_t route[2];
    coavoid_vehicle_node_t *a =
        vehicle_node(&r, uav(1, 1, route, 0, 500, 0, 100), COAVOID_NODE_CENTRALISED);
    const coavoid_vehicle_node_state_t *s = coavoid_vehicle_node_state(a);
    ck_assert_int_eq(coavoid_vehicle_node_cycle(a, r.now), COA_OK);
    drain(r.lcm);
    r.now = cycle(0) + DT_US / 4;
    heartbeat(r.lcm, r.now, 0);
    drain(r.lcm);
    /* Offsets 0, -1, -2, ... (dh 2 m): the bottom reaches 89 m at sample 3. */
    coavoid_plan_t m = solved_plan(r.now, 5, cycle(0), 10, 1);
    m.uav_ids[0] = 1;
    m.row_uav_id = 1;
    for (int32_t k = 0; k <= 10; k++) {
        m.offsets[k] = -k;
    }
    const int64_t rejected = s->rx.rejected;
    ck_assert_int_eq(TEST_PUBLISH(r.lcm, coavoid_plan_t, COAVOID_CHANNEL_PLAN, &m), 0);
    drain(r.lcm);
    ck_assert_int_eq(s->plans_adopted, 0);
    ck_assert_int_eq(s->rx.rejected, rejected + 1);
    ck_assert_int_eq(s->rx.last_reject_code, COAVOID_LCM_ERR_VALUE);
    ck_assert_str_eq(s->rx.last_reason, "plan: takes this UAV below its floor (min_altitude)");
    /* Down to offset -2 and level there: the bottom at 91 m, above the floor: adopted. */
    for (int32_t k = 0; k <= 10; k++) {
        m.offsets[k] = k < 2 ? -k : -2;
    }
    m.plan_id = 6;
    ck_assert_int_eq(TEST_PUBLISH(r.lcm, coavoid_plan_t, COAVOID_CHANNEL_PLAN, &m), 0);
    commit_msg(r.lcm, r.now, (int32_t)COAVOID_NODE_COORDINATOR_ID, 6, cycle(0));
    drain(r.lcm);
    ck_assert_int_eq(s->plans_adopted, 1);
    ck_assert_int_eq(s->rx.rejected, rejected + 1);
    for (int64_t k = 1; k <= 10; k++) {
        ck_assert_int_eq(coavoid_vehicle_node_cycle(a, cycle(k)), COA_OK);
        drain(r.lcm);
        ck_assert(s->position.z - (coa_real_t)5 >= (coa_real_t)90);
    }
    ck_assert_int_eq(s->offset, -2);
    coavoid_vehicle_node_destroy(a);

    coavoid_vehicle_node_config_t config;
    memset(&config, 0, sizeof config);
    config.common = r.common;
    config.vehicle = uav(1, 1, route, 0, 500, 0, 100);
    int error = COA_OK;
    config.common.min_altitude = (coa_real_t)NAN;
    ck_assert_ptr_null(coavoid_vehicle_node_create(&config, r.lcm, NULL, &error));
    ck_assert_int_eq(error, COA_ERR_ARGUMENT);
    config.common.min_altitude = (coa_real_t)2e7;
    ck_assert_ptr_null(coavoid_vehicle_node_create(&config, r.lcm, NULL, &error));
    lcm_destroy(r.lcm);
}
END_TEST

/* A coordinator's plan is checked against the other UAVs too: a row that climbs UAV 1
 * into UAV 2 (flying 12 m above it on the same track) is refused while UAV 2 keeps its
 * intent, and adopted when the same plan moves UAV 2 out of the way (its row in the
 * plan, not its intent, is what UAV 2 will fly). */
START_TEST(test_plan_into_other_uav_refused)
{
    rig_t r;
    rig_init(&r, 10);
    coa_vec3_t route_a[2], route_b[2];
    coavoid_vehicle_node_t *a =
        vehicle_node(&r, uav(1, 1, route_a, 0, 500, 0, 100), COAVOID_NODE_CENTRALISED);
    coavoid_vehicle_node_t *b =
        vehicle_node(&r, uav(2, 2, route_b, 0, 500, 0, 112), COAVOID_NODE_CENTRALISED);
    const coavoid_vehicle_node_state_t *s = coavoid_vehicle_node_state(a);
    ck_assert_int_eq(coavoid_vehicle_node_cycle(a, cycle(0)), COA_OK);
    ck_assert_int_eq(coavoid_vehicle_node_cycle(b, cycle(0)), COA_OK);
    drain(r.lcm);
    r.now = cycle(0) + DT_US / 4;
    plan_msg(r.lcm, r.now, 1, cycle(0), 1, 10, 0); /* 2 steps up: its top at 109 m */
    drain(r.lcm);
    ck_assert_int_eq(s->plans_adopted, 0);
    ck_assert_int_eq(s->rx.last_reject_code, COAVOID_LCM_ERR_VALUE);
    ck_assert_str_eq(s->rx.last_reason, "plan: flies this UAV into another UAV's plan or intent");
    coavoid_plan_t m = solved_plan(r.now, 2, cycle(0), 10, 2);
    m.uav_ids[0] = 1;
    m.uav_ids[1] = 2;
    /* One message per UAV; UAV 2 climbs 8 m, ahead of UAV 1. */
    for (int32_t row = 0; row < 2; row++) {
        m.row_uav_id = m.uav_ids[row];
        for (int32_t k = 0; k <= 10; k++) {
            m.offsets[k] = row == 0 ? (k < 2 ? k : 2) : (k < 4 ? k : 4);
        }
        ck_assert_int_eq(TEST_PUBLISH(r.lcm, coavoid_plan_t, COAVOID_CHANNEL_PLAN, &m), 0);
    }
    drain(r.lcm);
    ck_assert_int_eq(s->plans_adopted, 0); /* accepted, not flown before the commit */
    ck_assert_int_eq(s->plans_accepted, 1);
    commit_msg(r.lcm, r.now, (int32_t)COAVOID_NODE_COORDINATOR_ID, 2, cycle(0));
    drain(r.lcm);
    ck_assert_int_eq(s->plans_adopted, 1);
    ck_assert_int_eq(coavoid_vehicle_node_state(b)->plans_adopted, 1);
    coavoid_vehicle_node_destroy(a);
    coavoid_vehicle_node_destroy(b);
    lcm_destroy(r.lcm);
}
END_TEST

/* A UAV keeps the terrain it was configured with: a forged map (the world's id, the
 * largest version, no obstacles) takes nothing away, and the real map, refused afterwards
 * as older, is not needed to refuse a plan into that terrain. A map still adds: another
 * box it carries is avoided too. */
START_TEST(test_forged_map_keeps_terrain)
{
    rig_t r;
    rig_init(&r, 10);
    const coa_obstacle_t box = terrain_box();
    r.common.obstacles = &box;
    r.common.obstacle_count = 1;
    coa_vec3_t route[2];
    coavoid_vehicle_node_t *a =
        vehicle_node(&r, uav(1, 1, route, 0, 500, 0, 100), COAVOID_NODE_CENTRALISED);
    const coavoid_vehicle_node_state_t *s = coavoid_vehicle_node_state(a);
    coavoid_obstacle_map_t map;
    memset(&map, 0, sizeof map);
    map.utime = r.now;
    map.map_id = COAVOID_NODE_WORLD_ID;
    map.version = INT64_MAX;
    map.tile_count = 1;
    ck_assert_int_eq(TEST_PUBLISH(r.lcm, coavoid_obstacle_map_t, COAVOID_CHANNEL_OBSTACLES, &map),
                     0);
    drain(r.lcm);
    ck_assert_int_eq(coavoid_vehicle_node_cycle(a, r.now), COA_OK);
    drain(r.lcm);
    r.now = cycle(0) + DT_US / 4;
    heartbeat(r.lcm, r.now, 0);
    drain(r.lcm);
    dive_into_terrain(&r, s);
    /* A map of another publisher adds a lid from 107 m: a climb of 2 steps (2 m each:
     * its top from 105 to 109 m) is refused now; the UAV's own hold is still clear. */
    map.map_id = 7;
    map.version = 1;
    map.box_count = 1;
    const double lid_min[3] = {-1000, -1000, 107}, lid_max[3] = {1000, 1000, 200};
    memcpy(map.box_min[0], lid_min, sizeof lid_min);
    memcpy(map.box_max[0], lid_max, sizeof lid_max);
    ck_assert_int_eq(TEST_PUBLISH(r.lcm, coavoid_obstacle_map_t, COAVOID_CHANNEL_OBSTACLES, &map),
                     0);
    drain(r.lcm);
    plan_msg(r.lcm, r.now, 0, cycle(0), 1, 10, 0);
    drain(r.lcm);
    ck_assert_int_eq(s->plans_adopted, 0);
    ck_assert_str_eq(s->rx.last_reason, "plan: flies this UAV into an obstacle or track it knows");
    coavoid_vehicle_node_destroy(a);
    lcm_destroy(r.lcm);
}
END_TEST

/* The heartbeats of one node id, as its receivers see them. */
typedef struct {
    int32_t node_id;
    int count;
    int8_t health;
    int32_t reasons;
} health_probe_t;

static void on_status_probe(const lcm_recv_buf_t *rbuf, const char *channel, void *user)
{
    health_probe_t *p = user;
    (void)channel;
    coavoid_status_t m;
    REQUIRE(coavoid_status_t_decode(rbuf->data, 0, (int)rbuf->data_size, &m) >= 0);
    if (m.node_id == p->node_id) {
        /* The rig's nodes are insecure and say so in every heartbeat: the tests judge the
         * other reasons, and the health those give. */
        REQUIRE(m.reasons & COAVOID_STATUS_T_REASON_INSECURE);
        p->count++;
        p->reasons = m.reasons & ~COAVOID_STATUS_T_REASON_INSECURE;
        p->health = coavoid_lcm_health_of(p->reasons);
    }
}

/* Tile `index` of `count` of the world's map `version`: with `lid`, a box over everything
 * from 107 m up (a UAV at 100 m whose top is at 105 m climbs into it with 2 steps). */
static void map_tile(lcm_t *lcm, int64_t now, int64_t version, int32_t index, int32_t count,
                     bool lid)
{
    coavoid_obstacle_map_t m;
    memset(&m, 0, sizeof m);
    m.utime = now;
    m.map_id = (int32_t)COAVOID_NODE_WORLD_ID;
    m.version = version;
    m.tile_index = index;
    m.tile_count = count;
    if (lid) {
        const double lo[3] = {-1000, -1000, 107}, hi[3] = {1000, 1000, 200};
        m.box_count = 1;
        memcpy(m.box_min[0], lo, sizeof lo);
        memcpy(m.box_max[0], hi, sizeof hi);
    }
    ck_assert_int_eq(TEST_PUBLISH(lcm, coavoid_obstacle_map_t, COAVOID_CHANNEL_OBSTACLES, &m), 0);
}

/* A map is used only whole: until every tile of a version has come, the node has no map
 * (REASON_NO_MAP) or keeps the one it has, so a half map never replaces a whole one. A
 * tile whose tile_count is not its version's is refused. */
START_TEST(test_map_used_only_whole)
{
    rig_t r;
    rig_init(&r, 10);
    health_probe_t probe = {1, 0, -1, 0};
    lcm_subscription_t *sub = lcm_subscribe(r.lcm, COAVOID_CHANNEL_STATUS, on_status_probe, &probe);
    coa_vec3_t route[2];
    coavoid_vehicle_node_t *a =
        vehicle_node(&r, uav(1, 1, route, 0, 500, 0, 100), COAVOID_NODE_CENTRALISED);
    const coavoid_vehicle_node_state_t *s = coavoid_vehicle_node_state(a);
    map_tile(r.lcm, r.now, 1, 0, 2, true);
    drain(r.lcm);
    ck_assert_int_eq(coavoid_vehicle_node_cycle(a, cycle(0)), COA_OK);
    drain(r.lcm);
    ck_assert_int_ne(probe.reasons & COAVOID_STATUS_T_REASON_NO_MAP, 0);
    map_tile(r.lcm, r.now, 1, 1, 2, false);
    drain(r.lcm);
    r.now = cycle(1);
    ck_assert_int_eq(coavoid_vehicle_node_cycle(a, r.now), COA_OK);
    drain(r.lcm);
    ck_assert_int_eq(probe.reasons & COAVOID_STATUS_T_REASON_NO_MAP, 0);
    /* Version 1 has the lid: a climb of 2 steps is refused. */
    r.now = cycle(1) + DT_US / 4;
    plan_msg(r.lcm, r.now, 1, cycle(1), 1, 10, 0);
    drain(r.lcm);
    ck_assert_str_eq(s->rx.last_reason, "plan: flies this UAV into an obstacle or track it knows");
    /* Half of version 2, without the lid, changes nothing. */
    map_tile(r.lcm, r.now, 2, 0, 2, false);
    drain(r.lcm);
    plan_msg(r.lcm, r.now, 2, cycle(1), 1, 10, 0);
    drain(r.lcm);
    ck_assert_int_eq(s->plans_adopted, 0);
    ck_assert_str_eq(s->rx.last_reason, "plan: flies this UAV into an obstacle or track it knows");
    const int64_t rejected = s->rx.rejected;
    map_tile(r.lcm, r.now, 2, 1, 3, false);
    drain(r.lcm);
    ck_assert_int_eq(s->rx.rejected, rejected + 1);
    ck_assert_int_eq(s->rx.last_reject_code, COAVOID_LCM_ERR_COUNT);
    /* The whole of version 2 replaces version 1: the climb is clear now. */
    map_tile(r.lcm, r.now, 2, 1, 2, false);
    drain(r.lcm);
    plan_msg(r.lcm, r.now, 3, cycle(1), 1, 10, 0);
    drain(r.lcm);
    ck_assert_int_eq(s->plans_adopted, 1);
    ck_assert_int_eq(s->rx.rejected, rejected + 1);
    lcm_unsubscribe(r.lcm, sub);
    coavoid_vehicle_node_destroy(a);
    lcm_destroy(r.lcm);
}
END_TEST

/* A plan is decided on only whole: a UAV holding its own row but not its sibling's adopts
 * nothing and refuses nothing (unanswered, as if the plan had not come); the sibling's
 * row completes it. A row that disagrees with its plan's other rows is refused. */
START_TEST(test_plan_adopted_only_whole)
{
    rig_t r;
    rig_init(&r, 10);
    coa_vec3_t route[2];
    coavoid_vehicle_node_t *a =
        vehicle_node(&r, uav(1, 1, route, 0, 500, 0, 100), COAVOID_NODE_CENTRALISED);
    const coavoid_vehicle_node_state_t *s = coavoid_vehicle_node_state(a);
    ck_assert_int_eq(coavoid_vehicle_node_cycle(a, cycle(0)), COA_OK);
    drain(r.lcm);
    r.now = cycle(0) + DT_US / 4;
    const int64_t rejected = s->rx.rejected;
    coavoid_plan_t m = solved_plan(r.now, 4, cycle(0), 10, 2);
    m.uav_ids[0] = 1;
    m.uav_ids[1] = 9; /* far away: not in its view */
    m.row_uav_id = 1;
    for (int32_t k = 0; k <= 10; k++) {
        m.offsets[k] = k < 2 ? k : 2;
    }
    ck_assert_int_eq(TEST_PUBLISH(r.lcm, coavoid_plan_t, COAVOID_CHANNEL_PLAN, &m), 0);
    drain(r.lcm);
    ck_assert_int_eq(s->plans_adopted, 0);
    ck_assert_int_eq(s->rx.rejected, rejected);
    coavoid_plan_t other = m;
    other.row_uav_id = 9;
    memset(other.offsets, 0, sizeof other.offsets);
    other.deviation = 5.0; /* not what its sibling said */
    ck_assert_int_eq(TEST_PUBLISH(r.lcm, coavoid_plan_t, COAVOID_CHANNEL_PLAN, &other), 0);
    drain(r.lcm);
    ck_assert_int_eq(s->plans_adopted, 0);
    ck_assert_int_eq(s->rx.rejected, rejected + 1);
    ck_assert_int_eq(s->rx.last_reject_code, COAVOID_LCM_ERR_VALUE);
    other.deviation = m.deviation;
    ck_assert_int_eq(TEST_PUBLISH(r.lcm, coavoid_plan_t, COAVOID_CHANNEL_PLAN, &other), 0);
    commit_msg(r.lcm, r.now, (int32_t)COAVOID_NODE_COORDINATOR_ID, 4, cycle(0));
    drain(r.lcm);
    ck_assert_int_eq(s->plans_adopted, 1);
    ck_assert_int_eq(s->rx.rejected, rejected + 1);
    coavoid_vehicle_node_destroy(a);
    lcm_destroy(r.lcm);
}
END_TEST

/* Another UAV with this node's id: its intents are not this node's own looped back, even
 * at the same times and sequence numbers; they are refused and the node reports a fault
 * while they come. */
START_TEST(test_duplicate_id_reported)
{
    rig_t r;
    rig_init(&r, 10);
    health_probe_t probe = {1, 0, -1, 0};
    lcm_subscription_t *sub = lcm_subscribe(r.lcm, COAVOID_CHANNEL_STATUS, on_status_probe, &probe);
    coa_vec3_t r1[2], r2[2];
    coavoid_vehicle_node_t *a =
        vehicle_node(&r, uav(1, 1, r1, 0, 500, 0, 100), COAVOID_NODE_DECOUPLED);
    const coavoid_vehicle_node_state_t *s = coavoid_vehicle_node_state(a);
    empty_map(r.lcm, r.now);
    drain(r.lcm);
    ck_assert_int_eq(coavoid_vehicle_node_cycle(a, r.now), COA_OK);
    drain(r.lcm);
    ck_assert_int_eq(probe.health, COAVOID_STATUS_T_HEALTH_OK);
    ck_assert_int_eq(s->rx.received, 1); /* the map; its own intent came back: not counted */
    /* Its twin starts in the same cycle, on the same clock: the same utime and sequence. */
    coavoid_vehicle_node_t *b =
        vehicle_node(&r, uav(1, 1, r2, 0, 500, 800, 100), COAVOID_NODE_DECOUPLED);
    ck_assert_int_eq(coavoid_vehicle_node_cycle(b, r.now), COA_OK);
    drain(r.lcm);
    coavoid_vehicle_node_destroy(b);
    ck_assert_int_eq(s->rx.received, 2);
    ck_assert_int_eq(s->rx.rejected, 1);
    ck_assert_int_eq(s->rx.last_reject_code, COAVOID_LCM_ERR_ID);
    ck_assert_str_eq(s->rx.last_reason, "intent: another UAV uses this node's id");
    r.now = cycle(1);
    ck_assert_int_eq(coavoid_vehicle_node_cycle(a, r.now), COA_OK);
    drain(r.lcm);
    ck_assert_int_eq(probe.health, COAVOID_STATUS_T_HEALTH_FAULT);
    ck_assert(probe.reasons & COAVOID_STATUS_T_REASON_DUPLICATE_ID);
    /* The twin is gone: no fault any more. */
    r.now = cycle(2);
    ck_assert_int_eq(coavoid_vehicle_node_cycle(a, r.now), COA_OK);
    drain(r.lcm);
    ck_assert_int_ne(probe.health, COAVOID_STATUS_T_HEALTH_FAULT);
    ck_assert_int_eq(s->rx.received, 2);
    lcm_unsubscribe(r.lcm, sub);
    coavoid_vehicle_node_destroy(a);
    lcm_destroy(r.lcm);
}
END_TEST

/* A heartbeat says why it is not OK: no map yet (REASON_NO_MAP), then a refused plan for
 * it (REASON_PLAN_REFUSED, in the next cycle's heartbeat, which comes before that cycle's
 * plans), and OK once neither holds. */
START_TEST(test_health_reasons)
{
    rig_t r;
    rig_init(&r, 10);
    health_probe_t probe = {1, 0, -1, 0};
    lcm_subscription_t *sub = lcm_subscribe(r.lcm, COAVOID_CHANNEL_STATUS, on_status_probe, &probe);
    coa_vec3_t route[2];
    coavoid_vehicle_node_t *a =
        vehicle_node(&r, uav(1, 1, route, 0, 500, 0, 100), COAVOID_NODE_CENTRALISED);
    ck_assert_int_eq(coavoid_vehicle_node_cycle(a, cycle(0)), COA_OK);
    drain(r.lcm);
    ck_assert_int_eq(probe.health, COAVOID_STATUS_T_HEALTH_DEGRADED);
    ck_assert_int_eq(probe.reasons, COAVOID_STATUS_T_REASON_NO_MAP);
    empty_map(r.lcm, cycle(0));
    drain(r.lcm);
    r.now = cycle(0) + DT_US / 4;
    plan_msg(r.lcm, r.now, 1, cycle(0), 1, 10, 3); /* not from the offset it flies: refused */
    drain(r.lcm);
    r.now = cycle(1);
    ck_assert_int_eq(coavoid_vehicle_node_cycle(a, r.now), COA_OK);
    drain(r.lcm);
    ck_assert_int_eq(probe.health, COAVOID_STATUS_T_HEALTH_DEGRADED);
    ck_assert_int_eq(probe.reasons, COAVOID_STATUS_T_REASON_PLAN_REFUSED |
                                        COAVOID_STATUS_T_REASON_MESSAGES_REFUSED);
    r.now = cycle(2);
    ck_assert_int_eq(coavoid_vehicle_node_cycle(a, r.now), COA_OK);
    drain(r.lcm);
    ck_assert_int_eq(probe.health, COAVOID_STATUS_T_HEALTH_OK);
    ck_assert_int_eq(probe.reasons, 0);
    lcm_unsubscribe(r.lcm, sub);
    coavoid_vehicle_node_destroy(a);
    lcm_destroy(r.lcm);
}
END_TEST

/* A node whose messages are being refused (a peer's clock running ahead, bytes that do
 * not decode) says so in its next heartbeat: HEALTH_DEGRADED, then OK again once nothing
 * more is refused. */
START_TEST(test_refusals_degrade_health)
{
    rig_t r;
    rig_init(&r, 10);
    health_probe_t pa = {1, 0, -1, 0};
    health_probe_t pc = {(int32_t)COAVOID_NODE_COORDINATOR_ID, 0, -1, 0};
    lcm_subscription_t *sa = lcm_subscribe(r.lcm, COAVOID_CHANNEL_STATUS, on_status_probe, &pa);
    lcm_subscription_t *sc = lcm_subscribe(r.lcm, COAVOID_CHANNEL_STATUS, on_status_probe, &pc);
    coa_vec3_t r1[2], r2[2];
    coavoid_vehicle_node_t *a =
        vehicle_node(&r, uav(1, 1, r1, 0, 500, 0, 100), COAVOID_NODE_DECOUPLED);
    const coavoid_vehicle_node_state_t *s = coavoid_vehicle_node_state(a);
    coavoid_coordinator_config_t cc;
    memset(&cc, 0, sizeof cc);
    cc.common = r.common;
    cc.common.beta = 1000;
    int error = -99;
    coavoid_coordinator_t *co = coavoid_coordinator_create(&cc, r.lcm, NULL, &error);
    ck_assert_ptr_nonnull(co);
    /* A peer whose clock runs 1.5 cycles ahead: its intents come from the future. */
    int64_t ahead = r.now + 3 * DT_US / 2;
    coavoid_vehicle_node_config_t config;
    memset(&config, 0, sizeof config);
    config.common = r.common;
    config.common.clock = &ahead;
    config.vehicle = uav(2, 2, r2, 0, 500, 800, 100);
    config.mode = COAVOID_NODE_DECOUPLED;
    coavoid_vehicle_node_t *b = coavoid_vehicle_node_create(&config, r.lcm, NULL, &error);
    ck_assert_ptr_nonnull(b);
    const char junk[3] = {1, 2, 3};
    for (int64_t k = 0; k <= 3; k++) {
        r.now = cycle(k);
        empty_map(r.lcm, r.now);
        drain(r.lcm);
        ck_assert_int_eq(coavoid_vehicle_node_cycle(a, r.now), COA_OK);
        drain(r.lcm);
        coordinate(r.lcm, co, r.now + DT_US / 4);
        const int8_t want =
            k == 0 || k == 3 ? COAVOID_STATUS_T_HEALTH_OK : COAVOID_STATUS_T_HEALTH_DEGRADED;
        ck_assert_msg(pa.health == want, "cycle %d: vehicle health %d", (int)k, pa.health);
        ck_assert_msg(pc.health == want, "cycle %d: coordinator health %d", (int)k, pc.health);
        if (k == 0) {
            ahead = r.now + 3 * DT_US / 2;
            ck_assert_int_eq(coavoid_vehicle_node_cycle(b, ahead), COA_OK);
            drain(r.lcm);
            ck_assert_int_eq(s->rx.last_reject_code, COAVOID_LCM_ERR_TIME);
        } else if (k == 1) {
            ck_assert_int_eq(lcm_publish(r.lcm, COAVOID_CHANNEL_INTENT, junk, sizeof junk), 0);
            drain(r.lcm);
            ck_assert_int_eq(s->rx.last_reject_code, COAVOID_LCM_ERR_DECODE);
        }
    }
    ck_assert_int_eq(pa.count, 4);
    lcm_unsubscribe(r.lcm, sa);
    lcm_unsubscribe(r.lcm, sc);
    coavoid_vehicle_node_destroy(b);
    coavoid_coordinator_destroy(co);
    coavoid_vehicle_node_destroy(a);
    lcm_destroy(r.lcm);
}
END_TEST

/* ---- fallback ---- */

START_TEST(test_fallback_and_return)
{
    rig_t r;
    rig_init(&r, 10);
    coa_vec3_t route[2];
    coavoid_vehicle_node_t *a =
        vehicle_node(&r, uav(1, 1, route, 0, 500, 0, 100), COAVOID_NODE_CENTRALISED);
    const coavoid_vehicle_node_state_t *s = coavoid_vehicle_node_state(a);
    int64_t sequence = 0;
    /* Heartbeats at k + 1/4 for k in 0..4 and 10..14; timeout 2.5 cycles. */
    const char *want = "CCCCCCCDDDDCCCCCCDDD";
    const uint32_t fallbacks[20] = {0, 0, 0, 0, 0, 0, 0, 1, 1, 1, 1, 1, 1, 1, 1, 1, 1, 2, 2, 2};
    for (int64_t k = 0; k < 20; k++) {
        r.now = cycle(k);
        ck_assert_int_eq(coavoid_vehicle_node_cycle(a, r.now), COA_OK);
        drain(r.lcm);
        ck_assert_msg(s->coordinated == (want[k] == 'C'), "cycle %d", (int)k);
        ck_assert_uint_eq(s->fallbacks, fallbacks[k]);
        ck_assert(s->published);
        if (k <= 4 || (k >= 10 && k <= 14)) {
            r.now = cycle(k) + DT_US / 4;
            heartbeat(r.lcm, r.now, sequence++);
            drain(r.lcm);
        }
    }
    ck_assert_int_eq(s->rx.rejected, 0);
    coavoid_vehicle_node_destroy(a);
    lcm_destroy(r.lcm);
}
END_TEST

/* A UAV follows the coordinator it is configured with: heartbeats and plans from any other
 * node id are refused (here the default id's, the UAV being configured with 700). */
START_TEST(test_configured_coordinator_only)
{
    rig_t r;
    rig_init(&r, 10);
    coa_vec3_t route[2];
    coavoid_vehicle_node_config_t config;
    memset(&config, 0, sizeof config);
    config.common = r.common;
    config.vehicle = uav(1, 1, route, 0, 500, 0, 100);
    config.mode = COAVOID_NODE_CENTRALISED;
    config.coordinator_id = 1;
    int error = -99;
    ck_assert_ptr_null(coavoid_vehicle_node_create(&config, r.lcm, NULL, &error)); /* its own id */
    ck_assert_int_eq(error, COA_ERR_ARGUMENT);
    config.coordinator_id = 700;
    coavoid_vehicle_node_t *a = coavoid_vehicle_node_create(&config, r.lcm, NULL, &error);
    ck_assert_ptr_nonnull(a);
    const coavoid_vehicle_node_state_t *s = coavoid_vehicle_node_state(a);
    /* Cycles 0..5: only the default id speaks. After 2.5 cycles without its own
     * coordinator the UAV plans for itself. */
    const char *want = "CCCDDDDC";
    for (int64_t k = 0; k < 8; k++) {
        r.now = cycle(k);
        ck_assert_int_eq(coavoid_vehicle_node_cycle(a, r.now), COA_OK);
        drain(r.lcm);
        ck_assert_msg(s->coordinated == (want[k] == 'C'), "cycle %d", (int)k);
        r.now = cycle(k) + DT_US / 4;
        const int32_t from = k <= 5 ? (int32_t)COAVOID_NODE_COORDINATOR_ID : 700;
        const int64_t rejected = s->rx.rejected;
        heartbeat_from(r.lcm, r.now, k, from, COAVOID_STATUS_T_HEALTH_OK);
        drain(r.lcm);
        if (k <= 5) {
            ck_assert_int_eq(s->rx.rejected, rejected + 1);
            ck_assert_int_eq(s->rx.last_reject_code, COAVOID_LCM_ERR_ID);
            ck_assert_str_eq(s->rx.last_reason, "status: a coordinator that is not this UAV's");
        } else {
            ck_assert_int_eq(s->rx.rejected, rejected);
        }
        plan_msg_from(r.lcm, r.now, from, k, cycle(k), 1, 10, s->offset);
        drain(r.lcm);
        if (k <= 5) {
            /* Its heartbeat, its plan and its commit. */
            ck_assert_int_eq(s->rx.rejected, rejected + 3);
            ck_assert_str_eq(s->rx.last_reason,
                             "agreement: on a plan of a coordinator that is not this node's");
            ck_assert_int_eq(s->plans_adopted, 0);
        }
    }
    ck_assert_int_eq(s->plans_adopted, 2);
    coavoid_vehicle_node_destroy(a);
    lcm_destroy(r.lcm);
}
END_TEST

/* A coordinator that reports a fault is not followed: its heartbeats do not keep the UAV
 * coordinated. */
START_TEST(test_faulty_coordinator_not_followed)
{
    rig_t r;
    rig_init(&r, 10);
    coa_vec3_t route[2];
    coavoid_vehicle_node_t *a =
        vehicle_node(&r, uav(1, 1, route, 0, 500, 0, 100), COAVOID_NODE_CENTRALISED);
    const coavoid_vehicle_node_state_t *s = coavoid_vehicle_node_state(a);
    /* Heartbeats every cycle, HEALTH_FAULT from cycle 2 on: the last one that counts is
     * at 1.25, so from cycle 4 (2.75 s later) the UAV plans for itself. */
    const char *want = "CCCCDDDD";
    for (int64_t k = 0; k < 8; k++) {
        r.now = cycle(k);
        ck_assert_int_eq(coavoid_vehicle_node_cycle(a, r.now), COA_OK);
        drain(r.lcm);
        ck_assert_msg(s->coordinated == (want[k] == 'C'), "cycle %d", (int)k);
        r.now = cycle(k) + DT_US / 4;
        heartbeat_from(r.lcm, r.now, k, (int32_t)COAVOID_NODE_COORDINATOR_ID,
                       k < 2 ? COAVOID_STATUS_T_HEALTH_OK : COAVOID_STATUS_T_HEALTH_FAULT);
        drain(r.lcm);
    }
    ck_assert_uint_eq(s->fallbacks, 1);
    ck_assert_int_eq(s->rx.rejected, 0);
    coavoid_vehicle_node_destroy(a);
    lcm_destroy(r.lcm);
}
END_TEST

/* Polls the n vehicles at their deadlines, in time order, up to (not at) `until`. */
static void poll_until(rig_t *r, coavoid_vehicle_node_t *const *v, size_t n, int64_t until)
{
    for (;;) {
        size_t first = n;
        int64_t at = until;
        for (size_t i = 0; i < n; i++) {
            const int64_t d = coavoid_vehicle_node_deadline(v[i]);
            if (d < at) {
                at = d;
                first = i;
            }
        }
        if (first == n) {
            return;
        }
        r->now = at > r->now ? at : r->now;
        ck_assert_int_ge(coavoid_vehicle_node_poll(v[first], r->now), 0);
        drain(r->lcm);
    }
}

/* Flies a head-on pair 90 m apart (their volumes meet 3 s ahead) under a coordinator that
 * sends heartbeats and never a plan (one stopped after its heartbeat in cycle 0), with the
 * given answer_wait_us; fills p with the flown positions of cycles 0..8. With `refused`,
 * a plan for each UAV comes with every heartbeat, one it refuses (it does not start at
 * the offset it flies), as an impostor's or a faulty coordinator's would. */
static void fly_answered_by(int64_t answer_wait_us, bool refused, coa_vec3_t p[2][9]);

static void fly_unanswered(int64_t answer_wait_us, coa_vec3_t p[2][9])
{
    fly_answered_by(answer_wait_us, false, p);
}

static void fly_answered_by(int64_t answer_wait_us, bool refused, coa_vec3_t p[2][9])
{
    rig_t r;
    rig_init(&r, 24);
    coa_vec3_t r1[2], r2[2];
    coavoid_vehicle_node_t *v[2];
    v[0] = vehicle_node_waiting(&r, uav(1, 1, r1, 0, 600, 0, 100), COAVOID_NODE_CENTRALISED,
                                answer_wait_us);
    v[1] = vehicle_node_waiting(&r, uav(2, 2, r2, 90, -510, 0, 100), COAVOID_NODE_CENTRALISED,
                                answer_wait_us);
    for (int64_t k = 0; k <= 8; k++) {
        r.now = cycle(k);
        for (int i = 0; i < 2; i++) {
            ck_assert_int_eq(coavoid_vehicle_node_cycle(v[i], r.now), COA_OK);
            drain(r.lcm);
            p[i][k] = coavoid_vehicle_node_state(v[i])->position;
        }
        r.now = cycle(k) + DT_US / 4;
        heartbeat_from(r.lcm, r.now, k, (int32_t)COAVOID_NODE_COORDINATOR_ID,
                       COAVOID_STATUS_T_HEALTH_OK);
        drain(r.lcm);
        for (int i = 0; refused && i < 2; i++) {
            const coavoid_vehicle_node_state_t *s = coavoid_vehicle_node_state(v[i]);
            const uint32_t before = s->plans_refused;
            plan_msg(r.lcm, r.now, 2 * k + i, cycle(k), (uint16_t)(i + 1), 24, s->offset + 7);
            drain(r.lcm);
            ck_assert_uint_eq(s->plans_refused, before + 1u);
        }
        poll_until(&r, v, 2, cycle(k + 1));
    }
    coavoid_vehicle_node_destroy(v[1]);
    coavoid_vehicle_node_destroy(v[0]);
    lcm_destroy(r.lcm);
}

static bool flown_conflict(const coa_vec3_t *pa, const coa_vec3_t *pb, int64_t n);

/* Polls the nodes (in that order) at `at`, each after the messages of the one before. */
static void poll_all(rig_t *r, coavoid_vehicle_node_t *const *v, size_t n, int64_t at)
{
    r->now = at;
    for (size_t i = 0; i < n; i++) {
        ck_assert_int_ge(coavoid_vehicle_node_poll(v[i], r->now), 0);
        drain(r->lcm);
    }
}

/* A head-on pair, both following, whose volumes meet 3 s after the start of cycle k (UAV 2
 * starts 90 + 20 k m from UAV 1): in cycle k the coordinator's plan for UAV 1 alone (a
 * climb to 16 m) comes at `plan_at` after the cycle's start and no COMMIT follows; UAV 1
 * commits it itself when due (ack timeout + 4 resends after it accepted), UAV 2, holding
 * nothing, answers its conflict at the answer wait. Flies cycles 0 to k - 1 (no conflict
 * within the horizon of 4 steps) and cycle k up to the plan; v[0] is UAV 2. */
static void fly_self_commit_beside(rig_t *r, int64_t k, int64_t plan_at,
                                   coavoid_vehicle_node_t *v[2])
{
    static coa_vec3_t r1[2], r2[2];
    const coa_real_t x2 = (coa_real_t)(90 + 20 * k);
    v[0] = vehicle_node(r, uav(2, 2, r2, x2, x2 - 600, 0, 100), COAVOID_NODE_CENTRALISED);
    v[1] = vehicle_node(r, uav(1, 1, r1, 0, 600, 0, 100), COAVOID_NODE_CENTRALISED);
    for (int64_t j = 0; j <= k; j++) {
        r->now = cycle(j);
        for (int i = 0; i < 2; i++) {
            ck_assert_int_eq(coavoid_vehicle_node_cycle(v[i], r->now), COA_OK);
            drain(r->lcm);
            ck_assert(coavoid_vehicle_node_state(v[i])->coordinated);
        }
        heartbeat(r->lcm, cycle(j) + DT_US / 4, j);
        drain(r->lcm);
        if (j < k) {
            poll_until(r, v, 2, cycle(j + 1));
        }
    }
    r->now = cycle(k) + plan_at;
    coavoid_plan_t m = solved_plan(r->now, 0, cycle(k), 4, 1);
    m.uav_ids[0] = 1;
    m.row_uav_id = 1;
    for (int32_t j = 0; j <= 4; j++) {
        m.offsets[j] = 2 * j;
    }
    ck_assert_int_eq(TEST_PUBLISH(r->lcm, coavoid_plan_t, COAVOID_CHANNEL_PLAN, &m), 0);
    drain(r->lcm);
}

/* A UAV answering its conflict at the answer wait waits for the UAVs before it whose
 * intent says they follow, since they may answer theirs at the same moment; one whose
 * intent is its row of a coordinator's plan of the cycle has switched to it, which is a
 * decision: the answering UAV decides at once (here UAV 1 commits its plan itself at the
 * answer wait, and says it follows from then on). */
START_TEST(test_answer_does_not_wait_for_a_switched_uav)
{
    rig_t r;
    rig_init(&r, 4);
    coavoid_vehicle_node_t *v[2];
    fly_self_commit_beside(&r, 0, DT_US / 4, v);
    const coavoid_vehicle_node_state_t *s2 = coavoid_vehicle_node_state(v[0]);
    const coavoid_vehicle_node_state_t *s1 = coavoid_vehicle_node_state(v[1]);
    const int64_t answer_wait = cycle(0) + DT_US / 2 + 4 * (DT_US / 40);
    poll_all(&r, v, 2, answer_wait);
    ck_assert(s2->waiting); /* UAV 1 still followed when UAV 2 looked */
    ck_assert_uint_eq(s1->plans_self_committed, 1);
    ck_assert(!s1->coordinated);
    poll_all(&r, v, 1, answer_wait);
    ck_assert(!s2->waiting);
    ck_assert(s2->published);
    coavoid_vehicle_node_destroy(v[1]);
    coavoid_vehicle_node_destroy(v[0]);
    lcm_destroy(r.lcm);
}
END_TEST

/* How many intents (new sequences: not copies) UAV `id` published. */
typedef struct {
    int32_t id;
    int64_t last_sequence;
    uint32_t intents;
} intent_probe_t;

static void on_intent_probe(const lcm_recv_buf_t *rbuf, const char *channel, void *user)
{
    intent_probe_t *p = user;
    (void)channel;
    coavoid_intent_t m;
    REQUIRE(coavoid_intent_t_decode(rbuf->data, 0, (int)rbuf->data_size, &m) >= 0);
    if (m.uav_id == p->id && m.sequence > p->last_sequence) {
        p->last_sequence = m.sequence;
        p->intents++;
    }
}

/* A UAV that answered its conflict decides again when a UAV before it then switches to
 * its row of a coordinator's plan: here UAV 1's plan came late, so at the answer wait it
 * flies a standby (UAV 2 decides around it), and when its self-commit falls due it
 * switches to the plan's row, another plan than the standby. */
START_TEST(test_switch_before_it_is_decided_on_again)
{
    rig_t r;
    rig_init(&r, 4);
    coavoid_vehicle_node_t *v[2];
    intent_probe_t probe = {2, -1, 0};
    ck_assert_ptr_nonnull(lcm_subscribe(r.lcm, COAVOID_CHANNEL_INTENT, on_intent_probe, &probe));
    fly_self_commit_beside(&r, 2, DT_US * 4 / 10, v);
    const coavoid_vehicle_node_state_t *s2 = coavoid_vehicle_node_state(v[0]);
    const coavoid_vehicle_node_state_t *s1 = coavoid_vehicle_node_state(v[1]);
    const int64_t answer_wait = cycle(2) + DT_US / 2 + 4 * (DT_US / 40);
    poll_all(&r, v, 2, answer_wait);
    poll_all(&r, v, 1, answer_wait);
    ck_assert_uint_eq(s1->plans_self_committed, 0);
    ck_assert_uint_eq(s1->plans_standby, 0); /* counted at the cycle's end */
    ck_assert(!s2->waiting && s2->published);
    const uint32_t decided = probe.intents;
    const int64_t due = cycle(2) + DT_US * 4 / 10 + DT_US / 4 + 4 * (DT_US / 40);
    poll_all(&r, v, 2, due);
    ck_assert_uint_eq(s1->plans_self_committed, 1);
    poll_all(&r, v, 1, due);
    ck_assert_uint_gt(probe.intents, decided);
    coavoid_vehicle_node_destroy(v[1]);
    coavoid_vehicle_node_destroy(v[0]);
    lcm_destroy(r.lcm);
}
END_TEST

/* A UAV following a coordinator that has a conflict of its own and no answer (no plan it
 * holds, flies, or was told failed) by answer_wait_us plans for itself within the cycle:
 * with a conflict 3 s ahead that one UAV alone can climb clear of only from cycle 0, the
 * pair keeps separation; waiting for the next cycle's fallback, it does not. */
START_TEST(test_unanswered_conflict_planned_within_cycle)
{
    coa_vec3_t p[2][9];
    fly_unanswered(0, p);
    ck_assert_msg(!flown_conflict(p[0], p[1], 8), "loss of separation with the rule");
    fly_unanswered(2 * DT_US, p);
    ck_assert_msg(flown_conflict(p[0], p[1], 8), "the encounter needs the rule");
}
END_TEST

/* A refused plan answers nothing, and the UAV does not wait for the answer wait to say so
 * (docs/protocol.md, "Refusals"): it plans for itself in the cycle the plan came, so with
 * an answer wait past the cycle's end (under which an unanswered pair collides:
 * test_unanswered_conflict_planned_within_cycle) the pair whose every plan is refused
 * stays apart. */
START_TEST(test_refused_plan_planned_within_cycle)
{
    coa_vec3_t p[2][9];
    fly_answered_by(2 * DT_US, true, p);
    ck_assert_msg(!flown_conflict(p[0], p[1], 8), "loss of separation after refusals");
}
END_TEST

/* Whether two UAVs' flown positions (samples 0..n) conflict over any step. */
static bool flown_conflict(const coa_vec3_t *pa, const coa_vec3_t *pb, int64_t n)
{
    for (int64_t k = 0; k < n; k++) {
        coa_sweep_t x = {{15, 5}, pa[k], pa[k + 1]};
        coa_sweep_t y = {{15, 5}, pb[k], pb[k + 1]};
        if (coa_conflict_volumes(&x, &y)) {
            return true;
        }
    }
    return false;
}

/* A heartbeat alone does not keep a UAV following the coordinator: here the coordinator's
 * plans always come a cycle late (valid_from the cycle before), its heartbeats in time.
 * A UAV that followed it, had a conflict and adopted no plan in that cycle plans for
 * itself in the next one, and the head-on pair stays separated. */
START_TEST(test_late_plans_fall_back)
{
    rig_t r;
    rig_init(&r, 24);
    coa_vec3_t r1[2], r2[2];
    coavoid_vehicle_node_t *v[2];
    /* Waiting a cycle for an answer: the fallback of the next cycle is what is tested. */
    v[0] = vehicle_node_waiting(&r, uav(1, 1, r1, 0, 600, 0, 100), COAVOID_NODE_CENTRALISED,
                                2 * DT_US);
    v[1] = vehicle_node_waiting(&r, uav(2, 2, r2, 300, -300, 0, 100), COAVOID_NODE_CENTRALISED,
                                2 * DT_US);
    const coavoid_vehicle_node_state_t *s[2] = {coavoid_vehicle_node_state(v[0]),
                                                coavoid_vehicle_node_state(v[1])};
    coavoid_coordinator_config_t cc;
    memset(&cc, 0, sizeof cc);
    cc.common = r.common;
    cc.common.beta = 5000;
    int error = -99;
    coavoid_coordinator_t *co = coavoid_coordinator_create(&cc, r.lcm, NULL, &error);
    ck_assert_ptr_nonnull(co);
    coa_vec3_t p[2][31];
    for (int64_t k = 0; k <= 30; k++) {
        /* The coordinator's messages of cycle k - 1, still queued, reach the UAVs with
         * the first message of cycle k, after the cycle has begun. */
        r.now = cycle(k);
        for (int i = 0; i < 2; i++) {
            ck_assert_int_eq(coavoid_vehicle_node_cycle(v[i], r.now), COA_OK);
            drain(r.lcm);
        }
        while (coavoid_vehicle_node_deadline(v[1]) != INT64_MAX) {
            r.now = coavoid_vehicle_node_deadline(v[1]);
            ck_assert_int_ge(coavoid_vehicle_node_poll(v[1], r.now), 0);
            drain(r.lcm);
        }
        if (k == 1) {
            /* In the first cycle after the conflict showed, both plan for themselves. */
            ck_assert(!s[0]->coordinated && !s[1]->coordinated);
            ck_assert_uint_ge(s[1]->plans_run, 1);
        }

        r.now = cycle(k) + DT_US / 4;
        ck_assert_int_eq(coavoid_coordinator_cycle(co, r.now), COA_OK);
        for (int i = 0; i < 2; i++) {
            p[i][k] = s[i]->position;
        }
    }
    ck_assert_msg(!flown_conflict(p[0], p[1], 30), "loss of separation");
    for (int i = 0; i < 2; i++) {
        ck_assert_uint_ge(s[i]->fallbacks, 1);
        ck_assert_int_eq(s[i]->rx.last_reject_code, COAVOID_LCM_ERR_TIME);
    }
    coavoid_coordinator_destroy(co);
    coavoid_vehicle_node_destroy(v[1]);
    coavoid_vehicle_node_destroy(v[0]);
    lcm_destroy(r.lcm);
}
END_TEST

/* A plan that lists the UAV in time but was not solved is the coordinator's answer: its
 * search found nothing for the cluster this cycle. The UAV keeps following it (planning
 * for itself would take it out of the coordinator's next, larger searches). */
START_TEST(test_failed_plan_is_an_answer)
{
    rig_t r;
    rig_init(&r, 24);
    coa_vec3_t r1[2], r2[2];
    coavoid_vehicle_node_t *v[2];
    v[0] = vehicle_node(&r, uav(1, 1, r1, 0, 600, 0, 100), COAVOID_NODE_CENTRALISED);
    v[1] = vehicle_node(&r, uav(2, 2, r2, 300, -300, 0, 100), COAVOID_NODE_CENTRALISED);
    for (int64_t k = 0; k < 6; k++) {
        r.now = cycle(k);
        for (int i = 0; i < 2; i++) {
            ck_assert_int_eq(coavoid_vehicle_node_cycle(v[i], r.now), COA_OK);
            drain(r.lcm);
            ck_assert_msg(coavoid_vehicle_node_state(v[i])->coordinated, "cycle %d", (int)k);
        }
        r.now = cycle(k) + DT_US / 4;
        heartbeat(r.lcm, r.now, k);
        coavoid_plan_t m;
        memset(&m, 0, sizeof m);
        m.utime = r.now;
        m.coordinator_id = COAVOID_NODE_COORDINATOR_ID;
        m.plan_id = k;
        m.valid_from_utime = cycle(k);
        m.valid_until_utime = cycle(k + 1);
        m.dt = 1.0;
        m.horizon = 24;
        m.mode = COAVOID_PLAN_T_MODE_CENTRALISED;
        m.status = COAVOID_PLAN_T_STATUS_INFEASIBLE;
        m.vehicle_count = 2;
        m.planned_count = 0;
        m.uav_ids[0] = 1;
        m.uav_ids[1] = 2;
        for (int32_t row = 0; row < 2; row++) { /* one message per UAV, no rows */
            m.row_uav_id = m.uav_ids[row];
            ck_assert_int_eq(TEST_PUBLISH(r.lcm, coavoid_plan_t, COAVOID_CHANNEL_PLAN, &m), 0);
        }
        drain(r.lcm);
    }
    for (int i = 0; i < 2; i++) {
        const coavoid_vehicle_node_state_t *s = coavoid_vehicle_node_state(v[i]);
        ck_assert_uint_eq(s->fallbacks, 0);
        ck_assert_int_eq(s->rx.rejected, 0);
        coavoid_vehicle_node_destroy(v[i]);
    }
    lcm_destroy(r.lcm);
}
END_TEST

/* The UAVs of the plans a coordinator publishes (one message per UAV: a plan is counted
 * at its first UAV's). */
typedef struct {
    int plans;
    int messages;
    int32_t rows;
    int32_t ids[4];
    int8_t status; /* the last plan's */
} plan_probe_t;

static void on_plan_probe(const lcm_recv_buf_t *rbuf, const char *channel, void *user)
{
    plan_probe_t *p = user;
    (void)channel;
    coavoid_plan_t m;
    REQUIRE(coavoid_plan_t_decode(rbuf->data, 0, (int)rbuf->data_size, &m) >= 0);
    p->messages++;
    p->plans += m.row_uav_id == m.uav_ids[0] ? 1 : 0;
    p->rows = m.vehicle_count;
    p->status = m.status;
    for (int32_t i = 0; i < m.vehicle_count && i < 4; i++) {
        p->ids[i] = m.uav_ids[i];
    }
}

/* Two UAVs crossing, a coordinator (configured as `cc`, its common part the rig's but a
 * beta it gives) and a probe of its plans: cycle 0 flown up to the coordinator's plan. */
typedef struct {
    rig_t r;
    plan_probe_t probe;
    lcm_subscription_t *sub;
    coa_vec3_t r1[2], r2[2];
    coavoid_vehicle_node_t *a, *b;
    coavoid_coordinator_t *co;
} crossing_t;

static void crossing_fly(crossing_t *x, coavoid_node_mode_t mode_a, coavoid_coordinator_config_t cc)
{
    rig_init(&x->r, 24);
    memset(&x->probe, 0, sizeof x->probe);
    x->sub = lcm_subscribe(x->r.lcm, COAVOID_CHANNEL_PLAN, on_plan_probe, &x->probe);
    x->a = vehicle_node(&x->r, uav(1, 1, x->r1, 0, 600, 0, 100), mode_a);
    x->b = vehicle_node(&x->r, uav(2, 2, x->r2, 300, -300, 0, 100), COAVOID_NODE_CENTRALISED);
    const uint32_t beta = cc.common.beta; /* 0: the rig's */
    cc.common = x->r.common;
    cc.common.beta = beta != 0u ? beta : cc.common.beta;
    int error = -99;
    x->co = coavoid_coordinator_create(&cc, x->r.lcm, NULL, &error);
    ck_assert_ptr_nonnull(x->co);
    ck_assert_int_eq(coavoid_vehicle_node_cycle(x->a, x->r.now), COA_OK);
    drain(x->r.lcm);
    ck_assert_int_eq(coavoid_vehicle_node_cycle(x->b, x->r.now), COA_OK);
    drain(x->r.lcm);
    x->r.now = cycle(0) + DT_US / 4;
    coordinate(x->r.lcm, x->co, x->r.now);
}

static void crossing_free(crossing_t *x)
{
    lcm_unsubscribe(x->r.lcm, x->sub);
    coavoid_coordinator_destroy(x->co);
    coavoid_vehicle_node_destroy(x->b);
    coavoid_vehicle_node_destroy(x->a);
    lcm_destroy(x->r.lcm);
}

/* The coordinator does not plan a UAV that says it plans for itself (a decoupled intent):
 * the others' plans would rely on a move it does not make. It plans the others around it. */
START_TEST(test_coordinator_skips_decoupled_uav)
{
    static crossing_t x;
    coavoid_coordinator_config_t cc;
    memset(&cc, 0, sizeof cc);
    cc.common.beta = 5000; /* crossing_fly fills the rest of common from the rig */
    crossing_fly(&x, COAVOID_NODE_DECOUPLED, cc);
    ck_assert_int_eq(x.probe.plans, 1);
    ck_assert_int_eq(x.probe.rows, 1);
    ck_assert_int_eq(x.probe.ids[0], 2);
    ck_assert_uint_eq(coavoid_vehicle_node_state(x.b)->plans_adopted, 1);
    crossing_free(&x);
}
END_TEST

/* A cycle's work (plan_work) bounds the coordinator's search: one too small for even the
 * tables stops the centralised call within it, and the cluster is still answered (in
 * priority order, decoupled, outside the budget); the default, from the cycle, lets it
 * plan centrally. */
START_TEST(test_coordinator_answers_within_its_work)
{
    for (int small = 1; small >= 0; small--) {
        static crossing_t x;
        coavoid_coordinator_config_t cc;
        memset(&cc, 0, sizeof cc);
        cc.plan_work = small ? 2000u : 0u;
        crossing_fly(&x, COAVOID_NODE_CENTRALISED, cc);
        const coavoid_coordinator_state_t *s = coavoid_coordinator_state(x.co);
        ck_assert_int_eq(x.probe.plans, 1);
        ck_assert_int_eq(x.probe.status, COAVOID_PLAN_T_STATUS_SOLVED);
        ck_assert_int_eq(x.probe.rows, 2);
        if (small) {
            ck_assert_uint_le(s->last_plan_work, 2000u);
            ck_assert_uint_gt(s->last_plan_work, 0u);
            ck_assert_uint_eq(s->plans_run, 2); /* the stopped search, then the order's */
        } else {
            ck_assert_uint_le(s->last_plan_work, coavoid_node_work_of((DT_US - DT_US / 4) * 3 / 4));
            ck_assert_uint_eq(s->plans_run, 1);
        }
        ck_assert_uint_eq(coavoid_vehicle_node_state(x.b)->plans_adopted, 1);
        crossing_free(&x);
    }
}
END_TEST

/* A stopwatch that moves 10 ms each time it is read: any planning runs over a 5 ms budget. */
static int64_t slow_stopwatch(void *user)
{
    int64_t *t = user;
    *t += 10000;
    return *t;
}

/* Past its planning budget the coordinator abandons a cluster instead of sending a plan
 * late: a plan_t with STATUS_ABANDONED lists its UAVs, which adopt nothing, are not taken
 * as answered, and plan for themselves from the next cycle (the heartbeat says
 * REASON_NO_PLAN). */
START_TEST(test_coordinator_abandons_past_budget)
{
    rig_t r;
    rig_init(&r, 24);
    plan_probe_t probe;
    memset(&probe, 0, sizeof probe);
    lcm_subscription_t *sub = lcm_subscribe(r.lcm, COAVOID_CHANNEL_PLAN, on_plan_probe, &probe);
    coa_vec3_t r1[2], r2[2];
    coavoid_vehicle_node_t *a =
        vehicle_node(&r, uav(1, 1, r1, 0, 600, 0, 100), COAVOID_NODE_CENTRALISED);
    coavoid_vehicle_node_t *b =
        vehicle_node(&r, uav(2, 2, r2, 300, -300, 0, 100), COAVOID_NODE_CENTRALISED);
    int64_t watch = 0;
    coavoid_coordinator_config_t cc;
    memset(&cc, 0, sizeof cc);
    cc.common = r.common;
    cc.common.beta = 5000;
    cc.common.stopwatch_us = slow_stopwatch;
    cc.common.stopwatch_user = &watch;
    cc.plan_budget_us = 5000;
    int error = -99;
    coavoid_coordinator_t *co = coavoid_coordinator_create(&cc, r.lcm, NULL, &error);
    ck_assert_ptr_nonnull(co);
    for (int64_t k = 0; k <= 1; k++) {
        r.now = cycle(k);
        ck_assert_int_eq(coavoid_vehicle_node_cycle(a, r.now), COA_OK);
        ck_assert_int_eq(coavoid_vehicle_node_cycle(b, r.now), COA_OK);
        drain(r.lcm);
        if (k == 0) {
            heartbeat(r.lcm, r.now, 0);
            r.now = cycle(0) + DT_US / 4;
            coordinate(r.lcm, co, r.now);
            ck_assert_int_eq(probe.plans, 1);
            ck_assert_int_eq(probe.status, COAVOID_PLAN_T_STATUS_ABANDONED);
            ck_assert_int_eq(probe.rows, 2);
            ck_assert_uint_eq(coavoid_coordinator_state(co)->plans_abandoned, 1);
            ck_assert_uint_eq(coavoid_coordinator_state(co)->plans_run, 0);
        }
    }
    /* No plan came: both plan for themselves from cycle 1 (the higher priority at once). */
    ck_assert_uint_eq(coavoid_vehicle_node_state(a)->fallbacks, 1);
    ck_assert_uint_eq(coavoid_vehicle_node_state(b)->fallbacks, 1);
    ck_assert_uint_ge(coavoid_vehicle_node_state(a)->plans_run, 1);
    lcm_unsubscribe(r.lcm, sub);
    coavoid_coordinator_destroy(co);
    coavoid_vehicle_node_destroy(b);
    coavoid_vehicle_node_destroy(a);
    lcm_destroy(r.lcm);
}
END_TEST

/* ---- decoupled: waiting for higher priorities ---- */

START_TEST(test_lower_priority_waits)
{
    rig_t r;
    rig_init(&r, 24);
    coa_vec3_t r1[2], r2[2];
    /* Head-on, conflict around t = 13.5 s. 1 has priority. */
    coavoid_vehicle_node_t *a =
        vehicle_node(&r, uav(1, 1, r1, 0, 600, 0, 100), COAVOID_NODE_DECOUPLED);
    coavoid_vehicle_node_t *b =
        vehicle_node(&r, uav(2, 2, r2, 300, -300, 0, 100), COAVOID_NODE_DECOUPLED);
    const coavoid_vehicle_node_state_t *sa = coavoid_vehicle_node_state(a);
    const coavoid_vehicle_node_state_t *sb = coavoid_vehicle_node_state(b);
    /* Cycle 0: only 1 runs, so 2 knows 1's intent of cycle 0 and nothing newer. */
    ck_assert_int_eq(coavoid_vehicle_node_cycle(a, cycle(0)), COA_OK);
    drain(r.lcm);
    /* Cycle 1: 2 first. It sees the conflict with a higher priority whose intent for this
     * cycle has not come: it waits, until cycle start + dt / 2. */
    r.now = cycle(1);
    ck_assert_int_eq(coavoid_vehicle_node_cycle(b, r.now), COA_OK);
    drain(r.lcm);
    ck_assert(sb->waiting);
    ck_assert(!sb->published);
    ck_assert_int_eq(coavoid_vehicle_node_deadline(b), cycle(1) + DT_US / 2);
    ck_assert_int_eq(coavoid_vehicle_node_poll(b, r.now), 0);
    ck_assert_uint_eq(sb->plans_run, 0);
    /* 1 publishes (2 has published nothing yet: 1 sees no conflict and does not plan). */
    ck_assert_int_eq(coavoid_vehicle_node_cycle(a, r.now), COA_OK);
    drain(r.lcm);
    ck_assert_uint_eq(sa->plans_run, 0);
    ck_assert(sa->published);
    ck_assert_int_eq(coavoid_vehicle_node_poll(b, r.now), 1);
    ck_assert(!sb->waiting);
    ck_assert(sb->published);
    ck_assert_uint_eq(sb->plans_run, 1);
    ck_assert_uint_eq(sb->plans_adopted, 1);
    ck_assert_int_eq(sb->last_outcome, COA_PLAN_SOLVED);
    ck_assert_int_eq(coavoid_vehicle_node_deadline(b), INT64_MAX);
    coavoid_vehicle_node_destroy(b);
    coavoid_vehicle_node_destroy(a);
    lcm_destroy(r.lcm);
}
END_TEST

/* A UAV waits for the intents of the higher priorities that pass near it horizontally,
 * even with no conflict in sight: their plans for this cycle may climb into it. A far
 * one is not waited for. */
START_TEST(test_waits_for_near_higher_priority)
{
    rig_t r;
    rig_init(&r, 24);
    coa_vec3_t r1[2], r2[2], r3[2];
    /* 1 and 2 meet head-on 30 m apart vertically (clear); 3 is 5 km away. */
    coavoid_vehicle_node_t *a =
        vehicle_node(&r, uav(1, 1, r1, 0, 600, 0, 100), COAVOID_NODE_DECOUPLED);
    coavoid_vehicle_node_t *b =
        vehicle_node(&r, uav(2, 2, r2, 300, -300, 0, 130), COAVOID_NODE_DECOUPLED);
    coavoid_vehicle_node_t *c =
        vehicle_node(&r, uav(3, 1, r3, 0, 600, 5000, 100), COAVOID_NODE_DECOUPLED);
    const coavoid_vehicle_node_state_t *sb = coavoid_vehicle_node_state(b);
    ck_assert_int_eq(coavoid_vehicle_node_cycle(a, cycle(0)), COA_OK);
    ck_assert_int_eq(coavoid_vehicle_node_cycle(c, cycle(0)), COA_OK);
    drain(r.lcm);
    r.now = cycle(1);
    ck_assert_int_eq(coavoid_vehicle_node_cycle(b, r.now), COA_OK);
    drain(r.lcm);
    ck_assert(sb->waiting);
    ck_assert(!sb->published);
    ck_assert_uint_eq(sb->conflicts, 0);
    ck_assert_int_eq(coavoid_vehicle_node_cycle(a, r.now), COA_OK);
    drain(r.lcm);
    /* 3 has not published for this cycle either, but it is far: 2 goes on. */
    ck_assert_int_eq(coavoid_vehicle_node_poll(b, r.now), 1);
    ck_assert(sb->published);
    ck_assert_uint_eq(sb->plans_run, 0);
    coavoid_vehicle_node_destroy(c);
    coavoid_vehicle_node_destroy(b);
    coavoid_vehicle_node_destroy(a);
    lcm_destroy(r.lcm);
}
END_TEST

START_TEST(test_wait_ends_at_deadline)
{
    rig_t r;
    rig_init(&r, 24);
    coa_vec3_t r1[2], r2[2];
    coavoid_vehicle_node_t *a =
        vehicle_node(&r, uav(1, 1, r1, 0, 600, 0, 100), COAVOID_NODE_DECOUPLED);
    coavoid_vehicle_node_t *b =
        vehicle_node(&r, uav(2, 2, r2, 300, -300, 0, 100), COAVOID_NODE_DECOUPLED);
    const coavoid_vehicle_node_state_t *sb = coavoid_vehicle_node_state(b);
    ck_assert_int_eq(coavoid_vehicle_node_cycle(a, cycle(0)), COA_OK);
    drain(r.lcm);
    /* 1 says nothing in cycle 1: 2 waits out its deadline, then plans around 1's intent of
     * cycle 0, which still covers the encounter. */
    r.now = cycle(1);
    ck_assert_int_eq(coavoid_vehicle_node_cycle(b, r.now), COA_OK);
    drain(r.lcm);
    ck_assert(sb->waiting);
    r.now = cycle(1) + DT_US / 2 - 1;
    ck_assert_int_eq(coavoid_vehicle_node_poll(b, r.now), 0);
    r.now = coavoid_vehicle_node_deadline(b);
    ck_assert_int_eq(coavoid_vehicle_node_poll(b, r.now), 1);
    ck_assert(sb->published);
    ck_assert_uint_eq(sb->plans_adopted, 1);
    /* Then both fly on: 1 on its reference, 2 on its plan; they stay separated. */
    coa_vec3_t pa[31], pb[31];
    for (int64_t k = 2; k <= 30; k++) {
        r.now = cycle(k);
        coavoid_vehicle_node_cycle(a, r.now);
        drain(r.lcm);
        coavoid_vehicle_node_cycle(b, r.now);
        drain(r.lcm);
        while (coavoid_vehicle_node_deadline(b) != INT64_MAX) {
            r.now = coavoid_vehicle_node_deadline(b);
            coavoid_vehicle_node_poll(b, r.now);
            drain(r.lcm);
        }
        pa[k] = coavoid_vehicle_node_state(a)->position;
        pb[k] = sb->position;
    }
    for (int64_t k = 2; k < 30; k++) {
        coa_sweep_t x = {{15, 5}, pa[k], pa[k + 1]};
        coa_sweep_t y = {{15, 5}, pb[k], pb[k + 1]};
        ck_assert_msg(!coa_conflict_volumes(&x, &y), "conflict over step %d", (int)k);
    }
    coavoid_vehicle_node_destroy(b);
    coavoid_vehicle_node_destroy(a);
    lcm_destroy(r.lcm);
}
END_TEST

/* Every member of a cluster in conflict plans, the highest priority too: 1 holds an offset
 * (6 steps, 12 m up) that puts it at 2's altitude head-on, and 2 may deviate by one step
 * only, which is not enough. 1, planning around what it must avoid and ignoring 2,
 * returns to its reference, which frees 2. Before, 1 never planned for a conflict with a
 * lower priority, and they met. */
START_TEST(test_higher_priority_replans_in_cluster)
{
    rig_t r;
    rig_init(&r, 24);
    coa_vec3_t r1[2], r2[2];
    coa_vehicle_t v1 = uav(1, 1, r1, 0, 800, 0, 100);
    v1.initial_offset = 6;
    coa_vehicle_t v2 = uav(2, 2, r2, 600, -200, 0, 112);
    v2.max_offset = 1;
    coavoid_vehicle_node_t *v[2] = {vehicle_node(&r, v1, COAVOID_NODE_DECOUPLED),
                                    vehicle_node(&r, v2, COAVOID_NODE_DECOUPLED)};
    const coavoid_vehicle_node_state_t *sa = coavoid_vehicle_node_state(v[0]);
    const coavoid_vehicle_node_state_t *sb = coavoid_vehicle_node_state(v[1]);
    coa_vec3_t p[2][41];
    for (int64_t k = 0; k <= 40; k++) {
        r.now = cycle(k);
        for (int i = 0; i < 2; i++) {
            ck_assert_int_eq(coavoid_vehicle_node_cycle(v[i], r.now), COA_OK);
            drain(r.lcm);
        }
        for (int i = 0; i < 2; i++) {
            while (coavoid_vehicle_node_deadline(v[i]) != INT64_MAX) {
                r.now = coavoid_vehicle_node_deadline(v[i]);
                ck_assert_int_ge(coavoid_vehicle_node_poll(v[i], r.now), 0);
                drain(r.lcm);
            }
        }
        p[0][k] = sa->position;
        p[1][k] = sb->position;
    }
    ck_assert_uint_ge(sa->plans_run, 1);
    ck_assert_int_eq(sa->offset, 0);
    ck_assert_msg(!flown_conflict(p[0], p[1], 40), "loss of separation");
    for (int i = 0; i < 2; i++) {
        coavoid_vehicle_node_destroy(v[i]);
    }
    lcm_destroy(r.lcm);
}
END_TEST

/* ---- decoupled: priority negotiation ---- */

/* Decoupled vehicles over the simulation's network (net.h), so that a message can be lost
 * to one receiver: vehicle i publishes on the network's tx i and listens on its rx i. */
typedef struct {
    coavoid_sim_net_t *net;
    int64_t now;
    coavoid_node_common_t common;
    coavoid_vehicle_node_t *v[2];
} net_rig_t;

static void net_rig_init_as(net_rig_t *r, const coa_vehicle_t *vehicles, bool greedy)
{
    coavoid_sim_net_config_t nc;
    memset(&nc, 0, sizeof nc);
    nc.seed = 1;
    const bool receives[2] = {true, true};
    int error = -99;
    r->net = coavoid_sim_net_create(&nc, 2, receives, &error);
    ck_assert_ptr_nonnull(r->net);
    r->now = EPOCH;
    ck_assert_int_eq(coavoid_node_common_defaults(&r->common, EPOCH, (coa_real_t)1, 24, &r->now),
                     COA_OK);
    r->common.insecure = true;
    for (size_t i = 0; i < 2; i++) {
        coavoid_vehicle_node_config_t config;
        memset(&config, 0, sizeof config);
        config.common = r->common;
        config.vehicle = vehicles[i];
        config.mode = COAVOID_NODE_DECOUPLED;
        config.greedy_negotiation = greedy;
        r->v[i] = coavoid_vehicle_node_create(&config, coavoid_sim_net_tx(r->net, i),
                                              coavoid_sim_net_rx(r->net, i), &error);
        ck_assert_ptr_nonnull(r->v[i]);
    }
}

/* Vehicles that search their order (the default). */
static void net_rig_init(net_rig_t *r, const coa_vehicle_t *vehicles)
{
    net_rig_init_as(r, vehicles, false);
}

static void net_rig_fini(net_rig_t *r)
{
    for (size_t i = 0; i < 2; i++) {
        coavoid_vehicle_node_destroy(r->v[i]);
    }
    coavoid_sim_net_destroy(r->net);
}

/* The rest of a cycle, as coavoid sim runs it: every vehicle polled (a wait ends, or an
 * overtaken vehicle decides again) until none moves on, then the clock to the next
 * deadline, until none is left. */
static void net_rig_settle(net_rig_t *r)
{
    for (;;) {
        bool changed = true;
        while (changed) {
            changed = false;
            for (size_t i = 0; i < 2; i++) {
                int rc = coavoid_vehicle_node_poll(r->v[i], r->now);
                ck_assert_int_ge(rc, 0);
                changed = changed || rc > 0;
                ck_assert_int_eq(coavoid_sim_net_pump(r->net, r->now), COA_OK);
            }
        }
        int64_t d = coavoid_vehicle_node_deadline(r->v[0]);
        int64_t d1 = coavoid_vehicle_node_deadline(r->v[1]);
        d = d1 < d ? d1 : d;
        if (d == INT64_MAX) {
            return;
        }
        r->now = d;
    }
}

/* Cycle k: each vehicle in turn starts it and its messages go out, vehicle `deaf` (0 or
 * 1; 2: none) hearing nothing the other sends before the rest of the cycle. */
static void net_rig_cycle(net_rig_t *r, int64_t k, size_t deaf)
{
    r->now = cycle(k);
    for (size_t i = 0; i < 2; i++) {
        ck_assert_int_eq(coavoid_vehicle_node_cycle(r->v[i], r->now), COA_OK);
        if (deaf < 2) {
            coavoid_sim_net_set_loss(r->net, deaf, 1.0);
        }
        ck_assert_int_eq(coavoid_sim_net_pump(r->net, r->now), COA_OK);
        coavoid_sim_net_set_loss(r->net, deaf < 2 ? deaf : 0, 0.0);
    }
    net_rig_settle(r);
}

/* Head-on at one altitude: 1 has priority and may climb; 2 is held to its level
 * (max_offset 0, an altitude block), so in the configured order, 1 first, 2 has no plan:
 * 1 keeps its reference, as nothing it must avoid is in its way. */
static void held_pair(coa_vehicle_t *v, coa_vec3_t *r1, coa_vec3_t *r2)
{
    v[0] = uav(1, 1, r1, 0, 600, 0, 100);
    v[1] = uav(2, 2, r2, 300, -300, 0, 100);
    v[1].max_offset = 0;
}

/* Flies cycles 0..40 with vehicle `deaf` hearing nothing from the other in cycle
 * deaf_cycle, and checks that they stay separated. */
static void fly_held_pair(net_rig_t *r, size_t deaf, int64_t deaf_cycle)
{
    coa_vec3_t p[2][41];
    for (int64_t k = 0; k <= 40; k++) {
        net_rig_cycle(r, k, k == deaf_cycle ? deaf : 2u);
        for (size_t i = 0; i < 2; i++) {
            p[i][k] = coavoid_vehicle_node_state(r->v[i])->position;
        }
    }
    ck_assert_msg(!flown_conflict(p[0], p[1], 40), "loss of separation");
}

/* The fixed order has no plan, the reverse has. In cycle 0, 2 decides second, with 1's
 * first intent: its order search, from their first intents (each at the offset it starts
 * at), finds that 1 first fails and 2 first solves; 2 flies its row of that plan and
 * announces rank 2. 1, overtaken after it decided (before it had heard of 2: no
 * conflict, no plan), searches the same view, finds the same order and flies its row
 * (rank 1) in the same cycle; nobody raises greedily. Every later cycle 1 waits for 2,
 * which comes first now; once they have passed, the ranks return to 0. */
START_TEST(test_raise_reorders)
{
    coa_vec3_t r1[2], r2[2];
    coa_vehicle_t v[2];
    held_pair(v, r1, r2);
    net_rig_t r;
    net_rig_init(&r, v);
    const coavoid_vehicle_node_state_t *sa = coavoid_vehicle_node_state(r.v[0]);
    const coavoid_vehicle_node_state_t *sb = coavoid_vehicle_node_state(r.v[1]);
    net_rig_cycle(&r, 0, 2);
    ck_assert_int_eq(sb->rank, 2);
    ck_assert_uint_eq(sb->orders_agreed, 1);
    ck_assert_uint_eq(sb->rank_raises, 0);
    ck_assert_int_eq(sa->rank, 1);
    ck_assert_uint_eq(sa->orders_agreed, 1);
    ck_assert_uint_eq(sa->plans_run, 1);
    ck_assert_uint_eq(sa->plans_adopted, 1);
    /* Cycle 1: 2's intent of cycle 0 announced its rank, so 1 waits for it. */
    r.now = cycle(1);
    ck_assert_int_eq(coavoid_vehicle_node_cycle(r.v[0], r.now), COA_OK);
    ck_assert(sa->waiting);
    ck_assert_int_eq(coavoid_sim_net_pump(r.net, r.now), COA_OK);
    ck_assert_int_eq(coavoid_vehicle_node_cycle(r.v[1], r.now), COA_OK);
    ck_assert_int_eq(coavoid_sim_net_pump(r.net, r.now), COA_OK);
    net_rig_settle(&r);
    ck_assert(!sa->waiting && sa->published);
    fly_held_pair(&r, 2, -1);
    ck_assert_uint_eq(sb->rank_raises, 0);
    ck_assert_uint_eq(sb->orders_agreed, 1); /* the order held from then on */
    ck_assert_int_eq(sb->rank, 0);
    ck_assert_int_eq(sa->rank, 0);
    net_rig_fini(&r);
}
END_TEST

/* The raise is lost to the UAV it overtakes: in cycle 0, 1 hears nothing from 2, so it
 * neither knows 2's rank nor decides again (2 agreed the order 2, 1 by its search, alone).
 * In cycle 1 it hears 2's next intent, with the rank (an intent announces it every
 * cycle), and is overtaken: it searches, with 2 in its view as a UAV in its first cycle
 * (it has no intent of 2 from before), finds the same order, flies its row of it and
 * takes rank 1, under 2: the new order comes a cycle late, and they stay separated. */
START_TEST(test_lost_raise_heard_next_cycle)
{
    coa_vec3_t r1[2], r2[2];
    coa_vehicle_t v[2];
    held_pair(v, r1, r2);
    net_rig_t r;
    net_rig_init(&r, v);
    const coavoid_vehicle_node_state_t *sa = coavoid_vehicle_node_state(r.v[0]);
    const coavoid_vehicle_node_state_t *sb = coavoid_vehicle_node_state(r.v[1]);
    net_rig_cycle(&r, 0, 0);
    ck_assert_int_eq(sb->rank, 2);
    ck_assert_uint_eq(sb->orders_agreed, 1);
    ck_assert_uint_eq(sa->plans_run, 0);
    ck_assert_int_eq(sa->offset, 0);
    net_rig_cycle(&r, 1, 2);
    ck_assert_uint_ge(sa->plans_adopted, 1);
    ck_assert_uint_eq(sa->orders_agreed, 1);
    ck_assert_int_eq(sa->rank, 1);
    fly_held_pair(&r, 2, -1);
    ck_assert_uint_eq(sb->rank_raises, 0);
    net_rig_fini(&r);
}
END_TEST

/* The greedy raise alone (greedy_negotiation: what the order search falls back on). The
 * fixed order has no plan, the reverse has: 2 finds none below 1, raises its rank in
 * cycle 0 and plans first; 1, overtaken after it decided, decides again in the same
 * cycle and climbs around 2. Every later cycle 1 waits for 2, which comes first now; once
 * they have passed, 2's rank returns to 0. */
START_TEST(test_greedy_raise_reorders)
{
    coa_vec3_t r1[2], r2[2];
    coa_vehicle_t v[2];
    held_pair(v, r1, r2);
    net_rig_t r;
    net_rig_init_as(&r, v, true);
    const coavoid_vehicle_node_state_t *sa = coavoid_vehicle_node_state(r.v[0]);
    const coavoid_vehicle_node_state_t *sb = coavoid_vehicle_node_state(r.v[1]);
    net_rig_cycle(&r, 0, 2);
    ck_assert_int_eq(sb->rank, 1);
    ck_assert_uint_eq(sb->rank_raises, 1);
    ck_assert_int_eq(sa->rank, 0);
    /* 1 decided first, before it had heard of 2 (no conflict, no plan); overtaken, it
     * decided again and planned. */
    ck_assert_uint_eq(sa->plans_run, 1);
    ck_assert_uint_eq(sa->plans_adopted, 1);
    /* Cycle 1: 2's intent of cycle 0 announced its rank, so 1 waits for it. */
    r.now = cycle(1);
    ck_assert_int_eq(coavoid_vehicle_node_cycle(r.v[0], r.now), COA_OK);
    ck_assert(sa->waiting);
    ck_assert_int_eq(coavoid_sim_net_pump(r.net, r.now), COA_OK);
    ck_assert_int_eq(coavoid_vehicle_node_cycle(r.v[1], r.now), COA_OK);
    ck_assert_int_eq(coavoid_sim_net_pump(r.net, r.now), COA_OK);
    net_rig_settle(&r);
    ck_assert(!sa->waiting && sa->published);
    fly_held_pair(&r, 2, -1);
    ck_assert_uint_eq(sb->rank_raises, 1);
    ck_assert_int_eq(sb->rank, 0);
    ck_assert_int_eq(sa->rank, 0);
    net_rig_fini(&r);
}
END_TEST

/* The greedy raise alone, lost to the UAV it overtakes: in cycle 0, 1 hears nothing from 2, so it
 * neither knows 2's rank nor decides again. In cycle 1 it hears 2's next intent, with
 * the rank (an intent announces it every cycle), decides again and climbs around 2: the
 * new order comes a cycle late, and they stay separated. */
START_TEST(test_lost_greedy_raise_heard_next_cycle)
{
    coa_vec3_t r1[2], r2[2];
    coa_vehicle_t v[2];
    held_pair(v, r1, r2);
    net_rig_t r;
    net_rig_init_as(&r, v, true);
    const coavoid_vehicle_node_state_t *sa = coavoid_vehicle_node_state(r.v[0]);
    const coavoid_vehicle_node_state_t *sb = coavoid_vehicle_node_state(r.v[1]);
    net_rig_cycle(&r, 0, 0);
    ck_assert_int_eq(sb->rank, 1);
    ck_assert_uint_eq(sa->plans_run, 0);
    ck_assert_int_eq(sa->offset, 0);
    net_rig_cycle(&r, 1, 2);
    ck_assert_uint_ge(sa->plans_adopted, 1);
    fly_held_pair(&r, 2, -1);
    ck_assert_uint_eq(sb->rank_raises, 1);
    net_rig_fini(&r);
}
END_TEST

/* ---- a silent UAV is a track ---- */

START_TEST(test_silent_uav_avoided_as_track)
{
    rig_t r;
    rig_init(&r, 24);
    coa_vec3_t r1[2], r2[2];
    /* 2 has priority and is 620 m away head-on: they would meet around t = 30 s, beyond
     * the first horizon. 2 publishes once and falls silent. */
    coa_vehicle_t v2 = uav(2, 1, r2, 620, -1380, 0, 100);
    coavoid_vehicle_node_t *a =
        vehicle_node(&r, uav(1, 2, r1, 0, 2000, 0, 100), COAVOID_NODE_DECOUPLED);
    coavoid_vehicle_node_t *b = vehicle_node(&r, v2, COAVOID_NODE_DECOUPLED);
    const coavoid_vehicle_node_state_t *sa = coavoid_vehicle_node_state(a);
    ck_assert_int_eq(coavoid_vehicle_node_cycle(a, cycle(0)), COA_OK);
    ck_assert_int_eq(coavoid_vehicle_node_cycle(b, cycle(0)), COA_OK);
    drain(r.lcm);
    coavoid_vehicle_node_destroy(b);
    coa_vec3_t pa[41];
    pa[0] = sa->position;
    uint32_t plans_before_stale = 0;
    for (int64_t k = 1; k <= 40; k++) {
        r.now = cycle(k);
        coavoid_vehicle_node_cycle(a, r.now);
        drain(r.lcm);
        while (coavoid_vehicle_node_deadline(a) != INT64_MAX) {
            r.now = coavoid_vehicle_node_deadline(a);
            coavoid_vehicle_node_poll(a, r.now);
            drain(r.lcm);
        }
        if (k == 2) {
            plans_before_stale = sa->plans_run;
        }
        pa[k] = sa->position;
    }
    /* It planned only once 2 was a track (silent for more than 2.5 s). */
    ck_assert_uint_eq(plans_before_stale, 0);
    ck_assert_uint_gt(sa->plans_run, 0);
    for (int64_t k = 0; k < 40; k++) {
        coa_vec3_t q0 = coa_reference_at(&v2, (coa_real_t)k);
        coa_vec3_t q1 = coa_reference_at(&v2, (coa_real_t)(k + 1));
        coa_sweep_t x = {{15, 5}, pa[k], pa[k + 1]};
        coa_sweep_t y = {{15, 5}, q0, q1};
        ck_assert_msg(!coa_conflict_volumes(&x, &y), "conflict over step %d", (int)k);
    }
    ck_assert_int_eq(sa->rx.rejected, 0);
    coavoid_vehicle_node_destroy(a);
    lcm_destroy(r.lcm);
}
END_TEST

/* ---- the world's track estimates ---- */

typedef struct {
    rig_t *rig;
    coa_track_t original;
    int count;
    int truncated;
    double worst;
} track_probe_t;

static void on_track(const lcm_recv_buf_t *rbuf, const char *channel, void *user)
{
    track_probe_t *p = user;
    (void)channel;
    coavoid_track_t msg;
    REQUIRE(coavoid_track_t_decode(rbuf->data, 0, (int)rbuf->data_size, &msg) >= 0);
    const int64_t k = (p->rig->now - EPOCH) / DT_US;
    coavoid_lcm_context_t ctx = {p->rig->now, 30 * DT_US, DT_US, cycle(k)};
    coavoid_lcm_track_info_t info;
    coa_track_t got;
    coa_track_point_t path[COAVOID_TRACK_T_MAX_PATH];
    REQUIRE(coavoid_lcm_track_to_core(&msg, &ctx, NULL, &info, &got, path, COAVOID_TRACK_T_MAX_PATH,
                                      NULL) == COA_OK);
    REQUIRE(got.path_count >= 2);
    p->truncated += got.path_count == COAVOID_TRACK_T_MAX_PATH;
    const coa_real_t covered = got.path[got.path_count - 1u].t;
    for (int j = 0; j <= 20 && (coa_real_t)j <= covered; j++) {
        coa_vec3_t a = coa_track_at(&got, (coa_real_t)j);
        coa_vec3_t b = coa_track_at(&p->original, (coa_real_t)(k + j));
        double e = fmax(fabs((double)(a.x - b.x)),
                        fmax(fabs((double)(a.y - b.y)), fabs((double)(a.z - b.z))));
        p->worst = fmax(p->worst, e);
    }
    /* The path reaches the horizon's end unless the message ran out of points. */
    REQUIRE(covered >= (coa_real_t)20 || got.path_count == COAVOID_TRACK_T_MAX_PATH);
    p->count++;
}

START_TEST(test_world_track_estimates)
{
    rig_t r;
    rig_init(&r, 20);
    coa_track_point_t path[24];
    for (int j = 0; j < 24; j++) {
        /* A zig-zag: every point a turn, some a second apart (more than a message holds
         * within one horizon), some five. */
        double t = j < 4 ? 5.0 * j : 15.0 + (j - 3);
        path[j].t = (coa_real_t)t;
        path[j].p.x = (coa_real_t)(150 + 3 * t);
        path[j].p.y = (coa_real_t)((j % 2) ? 40 : -40);
        path[j].p.z = (coa_real_t)(100 + j);
    }
    track_probe_t probe;
    memset(&probe, 0, sizeof probe);
    probe.rig = &r;
    probe.original.id = 9;
    probe.original.volume.radius = 20;
    probe.original.volume.half_height = 8;
    probe.original.path = path;
    probe.original.path_count = 24;
    coavoid_world_config_t config;
    memset(&config, 0, sizeof config);
    config.common = r.common;
    config.tracks = &probe.original;
    config.track_count = 1;
    int error = -99;
    coavoid_world_t *w = coavoid_world_create(&config, r.lcm, &error);
    ck_assert_ptr_nonnull(w);
    lcm_subscription_t *sub = lcm_subscribe(r.lcm, COAVOID_CHANNEL_TRACK, on_track, &probe);
    for (int64_t k = 0; k <= 45; k++) {
        r.now = cycle(k);
        ck_assert_int_eq(coavoid_world_cycle(w, r.now), COA_OK);
        ck_assert_int_eq(coavoid_world_cycle(w, r.now), COA_OK); /* again: nothing */
        drain(r.lcm);
    }
    ck_assert_int_eq(probe.count, 46);
    ck_assert_int_gt(probe.truncated, 0);
    /* Rounding only: of the core's precision, on coordinates of a few hundred metres. */
    const double tolerance = 100 * (sizeof(coa_real_t) == sizeof(float) ? 1.2e-7 : 2.3e-16) * 300;
    ck_assert_msg(probe.worst < tolerance, "worst error %g m", probe.worst);
    lcm_unsubscribe(r.lcm, sub);
    coavoid_world_destroy(w);
    lcm_destroy(r.lcm);
}
END_TEST

/* ---- configuration ---- */

/* Every datagram the nodes publish, by channel: how many and the largest. */
typedef struct {
    int count[6];
    int largest;
} datagram_probe_t;

static void on_any_datagram(const lcm_recv_buf_t *rbuf, const char *channel, void *user)
{
    static const char *const channels[6] = {COAVOID_CHANNEL_INTENT,    COAVOID_CHANNEL_PLAN,
                                            COAVOID_CHANNEL_TRACK,     COAVOID_CHANNEL_OBSTACLES,
                                            COAVOID_CHANNEL_CONFLICTS, COAVOID_CHANNEL_STATUS};
    datagram_probe_t *p = user;
    for (int i = 0; i < 6; i++) {
        p->count[i] += strcmp(channel, channels[i]) == 0;
    }
    p->largest = (int)rbuf->data_size > p->largest ? (int)rbuf->data_size : p->largest;
}

/* The busiest traffic the nodes make fits one datagram each (COAVOID_LCM_MAX_DATAGRAM_BYTES):
 * the largest horizon, a full map (64 boxes, 16 polytopes of 32 vertices: 16 tiles), a
 * track, and three head-on pairs of UAVs under a coordinator (plans of two rows each).
 * The UAVs still assemble the map and the plans. */
START_TEST(test_every_datagram_fits)
{
    rig_t r;
    rig_init(&r, COAVOID_NODE_MAX_HORIZON);
    static coa_obstacle_t obstacles[80];
    static coa_vec3_t points[32];
    for (int j = 0; j < 32; j++) {
        double a = 2.0 * 3.141592653589793 * (j % 16) / 16.0;
        points[j] = (coa_vec3_t){(coa_real_t)(50000 + 100 * cos(a)), (coa_real_t)(100 * sin(a)),
                                 (coa_real_t)(j < 16 ? 0 : 50)};
    }
    for (int i = 0; i < 80; i++) {
        memset(&obstacles[i], 0, sizeof obstacles[i]);
        if (i < 64) {
            obstacles[i].kind = COA_OBSTACLE_BOX;
            obstacles[i].box.min = (coa_vec3_t){(coa_real_t)(60000 + 10 * i), 0, 0};
            obstacles[i].box.max = (coa_vec3_t){(coa_real_t)(60005 + 10 * i), 5, 5};
        } else {
            obstacles[i].kind = COA_OBSTACLE_POLYTOPE;
            obstacles[i].polytope.vertices = points;
            obstacles[i].polytope.count = 32;
        }
    }
    coa_track_t track;
    memset(&track, 0, sizeof track);
    track.id = 5;
    track.volume.radius = 20;
    track.volume.half_height = 8;
    track.position = (coa_vec3_t){-30000, 0, 100};
    coavoid_world_config_t wc;
    memset(&wc, 0, sizeof wc);
    wc.common = r.common;
    wc.obstacles = obstacles;
    wc.obstacle_count = 80;
    wc.tracks = &track;
    wc.track_count = 1;
    int error = -99;
    coavoid_world_t *w = coavoid_world_create(&wc, r.lcm, &error);
    ck_assert_ptr_nonnull(w);
    coavoid_coordinator_config_t cc;
    memset(&cc, 0, sizeof cc);
    cc.common = r.common;
    cc.common.beta = 5000;
    coavoid_coordinator_t *co = coavoid_coordinator_create(&cc, r.lcm, NULL, &error);
    ck_assert_ptr_nonnull(co);
    static coa_vec3_t routes[6][2];
    coavoid_vehicle_node_t *v[6];
    for (int i = 0; i < 6; i++) {
        const coa_real_t y = (coa_real_t)(i / 2) * 100;
        v[i] = vehicle_node(
            &r,
            uav((uint16_t)(i + 1), 1, routes[i], i % 2 ? 200 : -200, i % 2 ? -400 : 400, y, 100),
            COAVOID_NODE_CENTRALISED);
    }
    datagram_probe_t probe;
    memset(&probe, 0, sizeof probe);
    lcm_subscription_t *sub = lcm_subscribe(r.lcm, "COAVOID_.*", on_any_datagram, &probe);
    for (int64_t k = 0; k < 3; k++) {
        r.now = cycle(k);
        ck_assert_int_eq(coavoid_world_cycle(w, r.now), COA_OK);
        drain(r.lcm);
        for (int i = 0; i < 6; i++) {
            ck_assert_int_eq(coavoid_vehicle_node_cycle(v[i], r.now), COA_OK);
            drain(r.lcm);
        }
        r.now = cycle(k) + DT_US / 4;
        coordinate(r.lcm, co, r.now);
    }
    ck_assert_int_le(probe.largest, COAVOID_LCM_MAX_DATAGRAM_BYTES);
    ck_assert_int_eq(probe.count[3], 3 * 16); /* 16 tiles a cycle */
    ck_assert_int_eq(probe.count[2], 3);
    ck_assert_int_ge(probe.count[1], 2); /* a plan is a message per UAV */
    for (int c = 0; c < 6; c++) {
        ck_assert_int_gt(probe.count[c], 0);
    }
    uint32_t adopted = 0;
    for (int i = 0; i < 6; i++) {
        adopted += coavoid_vehicle_node_state(v[i])->plans_adopted;
        ck_assert_int_eq(coavoid_vehicle_node_state(v[i])->rx.rejected, 0);
        coavoid_vehicle_node_destroy(v[i]);
    }
    ck_assert_msg(adopted > 0u, "published %u, outcome %d, plan messages %d",
                  coavoid_coordinator_state(co)->plans_published,
                  coavoid_coordinator_state(co)->last_outcome, probe.count[1]);
    lcm_unsubscribe(r.lcm, sub);
    coavoid_coordinator_destroy(co);
    coavoid_world_destroy(w);
    lcm_destroy(r.lcm);
}
END_TEST

START_TEST(test_bad_configs_refused)
{
    rig_t r;
    rig_init(&r, 10);
    coavoid_node_common_t c;
    ck_assert_int_eq(coavoid_node_common_defaults(&c, EPOCH, (coa_real_t)1, 128, &r.now),
                     COA_ERR_ARGUMENT);
    ck_assert_int_eq(coavoid_node_common_defaults(&c, EPOCH, (coa_real_t)0, 10, &r.now),
                     COA_ERR_ARGUMENT);
    ck_assert_int_eq(coavoid_node_common_defaults(&c, 0, (coa_real_t)1, 10, &r.now),
                     COA_ERR_ARGUMENT);
    ck_assert_int_eq(coavoid_node_common_defaults(&c, EPOCH, (coa_real_t)1, 10, NULL),
                     COA_ERR_ARGUMENT);
    ck_assert_int_eq(coavoid_node_cycle_of(&r.common, EPOCH - 1), -1);
    ck_assert_int_eq(coavoid_node_cycle_of(&r.common, EPOCH + 2 * DT_US), 2);
    ck_assert_int_eq(coavoid_node_cycle_utime(&r.common, 3), EPOCH + 3 * DT_US);

    coa_vec3_t route[2];
    coavoid_vehicle_node_config_t vc;
    memset(&vc, 0, sizeof vc);
    vc.common = r.common;
    vc.vehicle = uav(1, 1, route, 0, 500, 0, 100);
    vc.mode = COAVOID_NODE_DECOUPLED;
    int error = 0;
    vc.vehicle.cruise_speed = -1;
    ck_assert_ptr_null(coavoid_vehicle_node_create(&vc, r.lcm, NULL, &error));
    ck_assert_int_eq(error, COA_ERR_ARGUMENT);
    vc.vehicle.cruise_speed = 10;
    vc.mode = (coavoid_node_mode_t)7;
    ck_assert_ptr_null(coavoid_vehicle_node_create(&vc, r.lcm, NULL, &error));
    vc.mode = COAVOID_NODE_DECOUPLED;
    vc.common.horizon = 128;
    ck_assert_ptr_null(coavoid_vehicle_node_create(&vc, r.lcm, NULL, &error));
    vc.common.horizon = 10;
    ck_assert_ptr_null(coavoid_vehicle_node_create(&vc, NULL, NULL, &error));
    vc.priority_wait_us = -1;
    ck_assert_ptr_null(coavoid_vehicle_node_create(&vc, r.lcm, NULL, &error));
    vc.priority_wait_us = 0;
    /* A duration past an hour (the fuzzer's configuration over the part's link once
     * overflowed the answer wait's default, 4 resend intervals): refused, each one. */
    int64_t *const durations[] = {&vc.coordinator_timeout_us, &vc.priority_wait_us, &vc.resend_us,
                                  &vc.answer_wait_us, &vc.common.stale_after_us};
    for (size_t d = 0; d < sizeof durations / sizeof durations[0]; d++) {
        const int64_t kept = *durations[d];
        *durations[d] = COAVOID_NODE_MAX_DURATION_US + 1;
        ck_assert_ptr_null(coavoid_vehicle_node_create(&vc, r.lcm, NULL, &error));
        ck_assert_int_eq(error, COA_ERR_ARGUMENT);
        *durations[d] = INT64_C(3533689840342138880);
        ck_assert_ptr_null(coavoid_vehicle_node_create(&vc, r.lcm, NULL, &error));
        *durations[d] = kept;
    }
    /* ... and copies past COAVOID_NODE_MAX_COPIES, whose times (count times the resend
     * interval) overflowed the same way. */
    vc.intent_copies = COAVOID_NODE_MAX_COPIES + 1u;
    vc.resend_us = COAVOID_NODE_MAX_DURATION_US;
    ck_assert_ptr_null(coavoid_vehicle_node_create(&vc, r.lcm, NULL, &error));
    vc.intent_copies = UINT32_MAX;
    ck_assert_ptr_null(coavoid_vehicle_node_create(&vc, r.lcm, NULL, &error));
    vc.intent_copies = 0u;
    vc.resend_us = 0;
    /* A joint plan of one UAV is its own plan; more than a planner searches together is
     * none. */
    vc.joint_members = 1u;
    ck_assert_ptr_null(coavoid_vehicle_node_create(&vc, r.lcm, NULL, &error));
    ck_assert_int_eq(error, COA_ERR_ARGUMENT);
    vc.joint_members = COA_MAX_CENTRALISED + 1u;
    ck_assert_ptr_null(coavoid_vehicle_node_create(&vc, r.lcm, NULL, &error));
    vc.joint_members = 0u;
    ck_assert_uint_eq(coavoid_node_joint_members(COAVOID_NODE_CENTRALISED, 1u), 0u);
    ck_assert_uint_eq(coavoid_node_joint_members(COAVOID_NODE_CENTRALISED, 3u), 3u);
    ck_assert_uint_eq(coavoid_node_joint_members(COAVOID_NODE_CENTRALISED, 30u),
                      COAVOID_NODE_DEFAULT_JOINT_MEMBERS);
    ck_assert_uint_eq(coavoid_node_joint_members(COAVOID_NODE_DECOUPLED, 4u), 0u);
    /* The memo of failed joint searches: a power of two of keys, or none. */
    uint64_t keys[8];
    coavoid_node_joint_memo_t memo;
    ck_assert_int_eq(coavoid_node_joint_memo_init(&memo, keys, 6u), COA_ERR_ARGUMENT);
    ck_assert(!coavoid_node_joint_memo_has(&memo, 5u));
    coavoid_node_joint_memo_add(&memo, 5u); /* a refused memo remembers nothing */
    ck_assert(!coavoid_node_joint_memo_has(&memo, 5u));
    ck_assert_int_eq(coavoid_node_joint_memo_init(&memo, NULL, 8u), COA_ERR_ARGUMENT);
    ck_assert_int_eq(coavoid_node_joint_memo_init(&memo, NULL, 0u), COA_OK);
    coavoid_node_joint_memo_add(&memo, 5u);
    ck_assert(!coavoid_node_joint_memo_has(&memo, 5u));
    ck_assert(!coavoid_node_joint_memo_has(NULL, 5u));
    ck_assert_int_eq(coavoid_node_joint_memo_init(&memo, keys, 8u), COA_OK);
    /* Keys that share a slot (the same low bits), 0 among them: each found, none else. */
    const uint64_t same_slot[4] = {0u, 8u, UINT64_C(16) << 32, 24u};
    for (size_t k = 0; k < 4u; k++) {
        ck_assert(!coavoid_node_joint_memo_has(&memo, same_slot[k]));
        coavoid_node_joint_memo_add(&memo, same_slot[k]);
        coavoid_node_joint_memo_add(&memo, same_slot[k]); /* once only */
    }
    ck_assert_uint_eq(memo.count, 4u);
    for (size_t k = 0; k < 4u; k++) {
        ck_assert(coavoid_node_joint_memo_has(&memo, same_slot[k]));
    }
    /* Half full: it adds nothing more, and a look-up still ends. */
    coavoid_node_joint_memo_add(&memo, 3u);
    ck_assert_uint_eq(memo.count, 4u);
    ck_assert(!coavoid_node_joint_memo_has(&memo, 3u));
    ck_assert(!coavoid_node_joint_memo_has(&memo, 32u));
    /* Its own obstacles: at most COAVOID_NODE_MAX_CONFIGURED_OBSTACLES, each valid. */
    coa_obstacle_t own[COAVOID_NODE_MAX_CONFIGURED_OBSTACLES + 1u];
    for (size_t i = 0; i <= COAVOID_NODE_MAX_CONFIGURED_OBSTACLES; i++) {
        own[i] = terrain_box();
    }
    vc.common.obstacles = own;
    vc.common.obstacle_count = COAVOID_NODE_MAX_CONFIGURED_OBSTACLES + 1u;
    ck_assert_ptr_null(coavoid_vehicle_node_create(&vc, r.lcm, NULL, &error));
    own[0].box.max.z = -1; /* below its min */
    vc.common.obstacle_count = 1;
    ck_assert_ptr_null(coavoid_vehicle_node_create(&vc, r.lcm, NULL, &error));
    vc.common.obstacles = NULL;
    ck_assert_ptr_null(coavoid_vehicle_node_create(&vc, r.lcm, NULL, &error));
    vc.common.obstacles = own + 1;
    vc.common.obstacle_count = COAVOID_NODE_MAX_CONFIGURED_OBSTACLES;
    coavoid_vehicle_node_t *fits = coavoid_vehicle_node_create(&vc, r.lcm, NULL, &error);
    ck_assert_ptr_nonnull(fits);
    coavoid_vehicle_node_destroy(fits);
    vc.common.obstacles = NULL;
    vc.common.obstacle_count = 0;

    coavoid_coordinator_config_t cc;
    memset(&cc, 0, sizeof cc);
    cc.common = r.common;
    cc.max_centralised = COA_MAX_CENTRALISED + 1u;
    ck_assert_ptr_null(coavoid_coordinator_create(&cc, r.lcm, NULL, &error));
    ck_assert_int_eq(error, COA_ERR_ARGUMENT);
    cc.max_centralised = 2;
    cc.collect_us = DT_US;
    ck_assert_ptr_null(coavoid_coordinator_create(&cc, r.lcm, NULL, &error));

    coavoid_world_config_t wc;
    memset(&wc, 0, sizeof wc);
    wc.common = r.common;
    coa_obstacle_t boxes[65];
    memset(boxes, 0, sizeof boxes);
    wc.obstacles = boxes;
    wc.obstacle_count = 65; /* one more than a map message holds */
    ck_assert_ptr_null(coavoid_world_create(&wc, r.lcm, &error));
    ck_assert_int_eq(error, COA_ERR_ARGUMENT);

    ck_assert_int_eq(coavoid_vehicle_node_cycle(NULL, EPOCH), COA_ERR_ARGUMENT);
    ck_assert_int_eq(coavoid_coordinator_cycle(NULL, EPOCH), COA_ERR_ARGUMENT);
    ck_assert_int_eq(coavoid_world_cycle(NULL, EPOCH), COA_ERR_ARGUMENT);
    coavoid_vehicle_node_destroy(NULL);
    coavoid_coordinator_destroy(NULL);
    coavoid_world_destroy(NULL);
    lcm_destroy(r.lcm);
}
END_TEST

/* ---- signed messages ---- */

/* The signed tests' fleet: key ids as coavoid keygen numbers them (the coordinator 1, the
 * world 2, UAV i 100 + i), from fixed seeds, and a fleet key; every node trusts every key. */
typedef struct {
    coavoid_auth_trust_t trust;
    coavoid_auth_signer_t coordinator, world, uav[2]; /* uav[i]: UAV i + 1 */
} fleet_keys_t;

static void fleet_key(fleet_keys_t *k, coavoid_auth_signer_t *s, uint32_t id,
                      coavoid_auth_role_t role, uint16_t node)
{
    unsigned char seed[COAVOID_AUTH_SEED_BYTES] = {(unsigned char)id, 7};
    coavoid_auth_key_t key = {id, role, node, {0}};
    memset(s, 0, sizeof *s);
    s->key_id = id;
    coavoid_auth_signer_use_fleet(s, &k->trust);
    ck_assert_int_eq(coavoid_auth_keypair_seed(seed, key.public_key, s->secret_key), COA_OK);
    ck_assert_int_eq(coavoid_auth_trust_add(&k->trust, &key), COA_OK);
}

static void fleet_keys(fleet_keys_t *k)
{
    coavoid_auth_trust_init(&k->trust);
    const unsigned char fleet[COAVOID_AUTH_FLEET_KEY_BYTES] = "test fleet key";
    ck_assert_int_eq(coavoid_auth_trust_set_fleet_key(&k->trust, fleet), COA_OK);
    fleet_key(k, &k->coordinator, 1, COAVOID_AUTH_COORDINATOR,
              (uint16_t)COAVOID_NODE_COORDINATOR_ID);
    fleet_key(k, &k->world, 2, COAVOID_AUTH_WORLD, (uint16_t)COAVOID_NODE_WORLD_ID);
    fleet_key(k, &k->uav[0], 101, COAVOID_AUTH_VEHICLE, 1);
    fleet_key(k, &k->uav[1], 102, COAVOID_AUTH_VEHICLE, 2);
}

/* A UAV node of the signed fleet: it signs with its key and checks every message. */
static coavoid_vehicle_node_t *signed_vehicle(rig_t *r, fleet_keys_t *k, coa_vehicle_t v,
                                              coavoid_node_mode_t mode)
{
    r->common.insecure = false;
    r->common.trust = &k->trust;
    r->common.signer = &k->uav[v.id - 1u];
    coavoid_vehicle_node_t *node = vehicle_node(r, v, mode);
    r->common.signer = NULL; /* copied by the node */
    return node;
}

/* Publishes size encoded bytes in buf, first signed at `now` by signer (NULL: as they
 * are). */
static void publish_bytes(lcm_t *lcm, const char *channel, unsigned char *buf, int size,
                          coavoid_auth_signer_t *signer, int64_t now)
{
    ck_assert_int_gt(size, 0);
    if (signer != NULL) {
        ck_assert_int_eq(coavoid_auth_stamp(signer, now, buf, (size_t)size), COA_OK);
    }
    ck_assert_int_eq(lcm_publish(lcm, channel, buf, (unsigned)size), 0);
}

/* Room for any datagram of the node's types. */
#define TAP_BYTES 20000

/* The latest intent datagram of one UAV, and the latest heartbeat reasons of one node. */
typedef struct {
    int32_t uav;
    int size;
    unsigned char bytes[TAP_BYTES];
    int32_t node;
    int32_t reasons;
    int64_t dropped;
    int32_t inbox_rate;
} wiretap_t;

static void on_tapped_intent(const lcm_recv_buf_t *rbuf, const char *channel, void *user)
{
    wiretap_t *t = user;
    static coavoid_intent_t m;
    (void)channel;
    if (coavoid_intent_t_decode(rbuf->data, 0, (int)rbuf->data_size, &m) > 0 &&
        m.uav_id == t->uav && rbuf->data_size <= sizeof t->bytes) {
        t->size = (int)rbuf->data_size;
        memcpy(t->bytes, rbuf->data, rbuf->data_size);
    }
}

static void on_tapped_status(const lcm_recv_buf_t *rbuf, const char *channel, void *user)
{
    wiretap_t *t = user;
    coavoid_status_t m;
    (void)channel;
    if (coavoid_status_t_decode(rbuf->data, 0, (int)rbuf->data_size, &m) > 0 &&
        m.node_id == t->node) {
        t->reasons = m.reasons;
        t->dropped = m.messages_dropped;
        t->inbox_rate = m.inbox_rate;
    }
}

/* One forgery heard by a signed node: refused with `code`, counted once. */
static void expect_refused(rig_t *r, const coavoid_vehicle_node_state_t *s, int code,
                           const char *what)
{
    const int64_t before = s->rx.rejected;
    drain(r->lcm);
    ck_assert_msg(s->rx.rejected == before + 1 && s->rx.last_reject_code == code,
                  "%s: rejected %lld -> %lld, code %d (want %d)", what, (long long)before,
                  (long long)s->rx.rejected, s->rx.last_reject_code, code);
}

/* Two signed UAVs on one bus, 1 in mode_a and 2 decoupled, with a wiretap of UAV 2's
 * intents and node 1's heartbeats. A test destroys its nodes, then signed_pair_fini. */
typedef struct {
    fleet_keys_t k;
    rig_t r;
    wiretap_t tap;
    lcm_subscription_t *si, *ss;
    coa_vec3_t r1[2], r2[2];
    coavoid_vehicle_node_t *a, *b;
} signed_pair_t;

static void signed_pair(signed_pair_t *p, coavoid_node_mode_t mode_a)
{
    fleet_keys(&p->k);
    rig_init(&p->r, 10);
    memset(&p->tap, 0, sizeof p->tap);
    p->tap.uav = 2;
    p->tap.node = 1;
    p->si = lcm_subscribe(p->r.lcm, COAVOID_CHANNEL_INTENT, on_tapped_intent, &p->tap);
    p->ss = lcm_subscribe(p->r.lcm, COAVOID_CHANNEL_STATUS, on_tapped_status, &p->tap);
    p->a = signed_vehicle(&p->r, &p->k, uav(1, 1, p->r1, 0, 500, 0, 100), mode_a);
    p->b = signed_vehicle(&p->r, &p->k, uav(2, 2, p->r2, 0, 500, 800, 100), COAVOID_NODE_DECOUPLED);
}

static void signed_pair_fini(signed_pair_t *p)
{
    lcm_unsubscribe(p->r.lcm, p->si);
    lcm_unsubscribe(p->r.lcm, p->ss);
    lcm_destroy(p->r.lcm);
}

/* The signed fleet's world on the pair's bus. */
static coavoid_world_t *signed_world(signed_pair_t *p)
{
    coavoid_world_config_t wc;
    memset(&wc, 0, sizeof wc);
    wc.common = p->r.common;
    wc.common.signer = &p->k.world;
    int error = -99;
    coavoid_world_t *w = coavoid_world_create(&wc, p->r.lcm, &error);
    ck_assert_ptr_nonnull(w);
    return w;
}

/* Signed nodes accept each other's messages and say they are secure; every forgery is
 * refused with its own code: a replay, a changed byte, no signature, a key of another role
 * (the world's on an intent, a UAV's on a plan or a map), an unknown key, a time ahead of
 * the window. A UAV that restarts (its sequence from 0 again) is heard again at once. */
START_TEST(test_signed_messages)
{
    static signed_pair_t p;
    signed_pair(&p, COAVOID_NODE_CENTRALISED);
    coavoid_vehicle_node_t *a = p.a, *b = p.b;
    coavoid_world_t *w = signed_world(&p);
    ck_assert_int_eq(coavoid_world_cycle(w, p.r.now), COA_OK);
    drain(p.r.lcm);
    ck_assert_int_eq(coavoid_vehicle_node_cycle(b, p.r.now), COA_OK);
    drain(p.r.lcm);
    ck_assert_int_eq(coavoid_vehicle_node_cycle(a, p.r.now), COA_OK);
    drain(p.r.lcm);
    const coavoid_vehicle_node_state_t *s = coavoid_vehicle_node_state(a);
    ck_assert_int_eq(s->rx.rejected, 0);
    ck_assert_int_ge(s->rx.received, 3); /* the map, UAV 2's intent and heartbeat */
    ck_assert_int_eq(p.tap.reasons & COAVOID_STATUS_T_REASON_INSECURE, 0);
    ck_assert_int_gt(p.tap.size, 0);

    static unsigned char buf[TAP_BYTES];
    memcpy(buf, p.tap.bytes, (size_t)p.tap.size);
    publish_bytes(p.r.lcm, COAVOID_CHANNEL_INTENT, buf, p.tap.size, NULL, 0);
    expect_refused(&p.r, s, COAVOID_AUTH_ERR_REPLAY, "UAV 2's intent again");
    buf[(size_t)p.tap.size - COAVOID_AUTH_TAIL_BYTES + 19u] ^=
        1; /* its auth sequence, one higher */
    publish_bytes(p.r.lcm, COAVOID_CHANNEL_INTENT, buf, p.tap.size, NULL, 0);
    expect_refused(&p.r, s, COAVOID_AUTH_ERR_TAG, "a copy numbered higher");
    static coavoid_intent_t m;
    ck_assert_int_gt(coavoid_intent_t_decode(p.tap.bytes, 0, p.tap.size, &m), 0);
    m.sequence++;
    memset(&m.auth, 0, sizeof m.auth);
    const int size = coavoid_intent_t_encode(buf, 0, (int)sizeof buf, &m);
    publish_bytes(p.r.lcm, COAVOID_CHANNEL_INTENT, buf, size, NULL, 0);
    expect_refused(&p.r, s, COAVOID_AUTH_ERR_UNSIGNED, "unsigned");
    publish_bytes(p.r.lcm, COAVOID_CHANNEL_INTENT, buf, size, &p.k.world, p.r.now);
    expect_refused(&p.r, s, COAVOID_AUTH_ERR_ROLE, "UAV 2's intent signed by the world");
    coavoid_auth_signer_t stranger = p.k.uav[1];
    stranger.key_id = 999;
    publish_bytes(p.r.lcm, COAVOID_CHANNEL_INTENT, buf, size, &stranger, p.r.now);
    expect_refused(&p.r, s, COAVOID_AUTH_ERR_KEY, "an unknown key");
    coavoid_auth_signer_t uav2 = p.k.uav[1];
    publish_bytes(p.r.lcm, COAVOID_CHANNEL_INTENT, buf, size, &uav2, p.r.now + 2 * DT_US);
    expect_refused(&p.r, s, COAVOID_AUTH_ERR_CLOCK, "signed two cycles ahead");
    coavoid_plan_t plan = solved_plan(p.r.now, 1, p.r.now, 10, 1);
    plan.uav_ids[0] = 1;
    int n = coavoid_plan_t_encode(buf, 0, (int)sizeof buf, &plan);
    publish_bytes(p.r.lcm, COAVOID_CHANNEL_PLAN, buf, n, &uav2, p.r.now);
    expect_refused(&p.r, s, COAVOID_AUTH_ERR_ROLE, "a plan signed by UAV 2");
    static coavoid_obstacle_map_t map;
    memset(&map, 0, sizeof map);
    map.utime = p.r.now;
    map.map_id = (int32_t)COAVOID_NODE_WORLD_ID;
    map.version = INT64_MAX;
    n = coavoid_obstacle_map_t_encode(buf, 0, (int)sizeof buf, &map);
    publish_bytes(p.r.lcm, COAVOID_CHANNEL_OBSTACLES, buf, n, &uav2, p.r.now);
    expect_refused(&p.r, s, COAVOID_AUTH_ERR_ROLE, "a map signed by UAV 2");

    /* UAV 2 restarts a cycle later: a new node, its numbering from 0, the same key. */
    coavoid_vehicle_node_destroy(b);
    p.r.now = cycle(1);
    b = signed_vehicle(&p.r, &p.k, uav(2, 2, p.r2, 10, 500, 800, 100), COAVOID_NODE_DECOUPLED);
    ck_assert_int_eq(coavoid_vehicle_node_cycle(b, p.r.now), COA_OK);
    const int64_t rejected = s->rx.rejected, received = s->rx.received;
    drain(p.r.lcm);
    ck_assert_int_gt(coavoid_intent_t_decode(p.tap.bytes, 0, p.tap.size, &m), 0);
    ck_assert_int_eq(m.sequence, 0);
    ck_assert_int_eq(s->rx.rejected, rejected);
    ck_assert_int_eq(s->rx.received, received + 2); /* its intent and heartbeat */

    coavoid_world_destroy(w);
    coavoid_vehicle_node_destroy(b);
    coavoid_vehicle_node_destroy(a);
    signed_pair_fini(&p);
}
END_TEST

/* The inbox budget: a stolen key's flood of fresh, validly signed intents costs a node at
 * most COAVOID_NODE_CHECKS_PER_VEHICLE signature checks in a cycle; the rest are dropped
 * unchecked, counted, and said in its next heartbeat with the rate it took them in at.
 * Another key's message in the same cycle is still checked and accepted, and the next
 * cycle's budget is whole again. */
START_TEST(test_inbox_budget)
{
    static signed_pair_t p;
    signed_pair(&p, COAVOID_NODE_DECOUPLED);
    coavoid_vehicle_node_t *a = p.a, *b = p.b;
    ck_assert_int_eq(coavoid_vehicle_node_cycle(b, p.r.now), COA_OK);
    ck_assert_int_eq(coavoid_vehicle_node_cycle(a, p.r.now), COA_OK);
    drain(p.r.lcm);
    const coavoid_vehicle_node_state_t *s = coavoid_vehicle_node_state(a);
    ck_assert_int_eq(p.tap.dropped, 0);
    ck_assert_int_eq(p.tap.reasons & COAVOID_STATUS_T_REASON_INBOX_FLOOD, 0);

    /* UAV 2's key stolen: fresh intents of UAV 2, each signed, one after another, in
     * cycle 1. */
    p.r.now = cycle(1);
    ck_assert_int_eq(coavoid_vehicle_node_cycle(a, p.r.now), COA_OK);
    drain(p.r.lcm);
    p.r.now = cycle(1) + DT_US / 4;
    static coavoid_intent_t m;
    ck_assert_int_gt(coavoid_intent_t_decode(p.tap.bytes, 0, p.tap.size, &m), 0);
    static unsigned char buf[TAP_BYTES];
    const uint32_t flood = COAVOID_NODE_CHECKS_PER_VEHICLE + 10u;
    int64_t received = s->rx.received;
    for (uint32_t i = 0; i < flood; i++) {
        m.sequence++;
        const int size = coavoid_intent_t_encode(buf, 0, (int)sizeof buf, &m);
        publish_bytes(p.r.lcm, COAVOID_CHANNEL_INTENT, buf, size, &p.k.uav[1], p.r.now);
        drain(p.r.lcm);
    }
    ck_assert_int_eq(s->rx.received, received + COAVOID_NODE_CHECKS_PER_VEHICLE);
    /* The world's map in the same cycle: another key, still checked. */
    coavoid_world_t *w = signed_world(&p);
    ck_assert_int_eq(coavoid_world_cycle(w, p.r.now), COA_OK);
    drain(p.r.lcm);
    ck_assert_int_eq(s->rx.received, received + COAVOID_NODE_CHECKS_PER_VEHICLE + 1);
    ck_assert_int_eq(s->rx.rejected, 0);

    p.r.now = cycle(2);
    ck_assert_int_eq(coavoid_vehicle_node_cycle(a, p.r.now), COA_OK);
    drain(p.r.lcm);
    ck_assert(p.tap.reasons & COAVOID_STATUS_T_REASON_INBOX_FLOOD);
    ck_assert_int_eq(p.tap.dropped, 10);
    ck_assert_int_ge(p.tap.inbox_rate, (int32_t)flood);
    /* A new cycle, a whole budget: UAV 2's next intent is checked and accepted. */
    m.sequence++;
    int size = coavoid_intent_t_encode(buf, 0, (int)sizeof buf, &m);
    publish_bytes(p.r.lcm, COAVOID_CHANNEL_INTENT, buf, size, &p.k.uav[1], p.r.now + 1);
    drain(p.r.lcm);
    ck_assert_int_eq(s->rx.received, received + COAVOID_NODE_CHECKS_PER_VEHICLE + 2);
    p.r.now = cycle(3);
    ck_assert_int_eq(coavoid_vehicle_node_cycle(a, p.r.now), COA_OK);
    drain(p.r.lcm);
    ck_assert_int_eq(p.tap.reasons & COAVOID_STATUS_T_REASON_INBOX_FLOOD, 0);
    ck_assert_int_eq(p.tap.dropped, 10);

    coavoid_world_destroy(w);
    coavoid_vehicle_node_destroy(b);
    coavoid_vehicle_node_destroy(a);
    signed_pair_fini(&p);
}
END_TEST

/* A node refuses to start without its keys unless told it is insecure; an insecure node
 * says so in every heartbeat. */
START_TEST(test_keys_required)
{
    static fleet_keys_t k;
    fleet_keys(&k);
    rig_t r;
    rig_init(&r, 10);
    r.common.insecure = false;
    coa_vec3_t route[2];
    coavoid_vehicle_node_config_t config;
    memset(&config, 0, sizeof config);
    config.common = r.common;
    config.vehicle = uav(1, 1, route, 0, 500, 0, 100);
    config.mode = COAVOID_NODE_DECOUPLED;
    int error = -99;
    ck_assert_ptr_null(coavoid_vehicle_node_create(&config, r.lcm, NULL, &error)); /* no key */
    ck_assert_int_eq(error, COA_ERR_ARGUMENT);
    config.common.signer = &k.uav[0];
    ck_assert_ptr_null(coavoid_vehicle_node_create(&config, r.lcm, NULL, &error)); /* no trust */
    ck_assert_int_eq(error, COA_ERR_ARGUMENT);
    coavoid_world_config_t wc;
    memset(&wc, 0, sizeof wc);
    wc.common = r.common;
    ck_assert_ptr_null(coavoid_world_create(&wc, r.lcm, &error));
    wc.common.signer = &k.world; /* the world receives nothing: a key is enough */
    coavoid_world_t *w = coavoid_world_create(&wc, r.lcm, &error);
    ck_assert_ptr_nonnull(w);
    coavoid_world_destroy(w);
    static wiretap_t tap;
    tap.node = 1;
    lcm_subscription_t *ss = lcm_subscribe(r.lcm, COAVOID_CHANNEL_STATUS, on_tapped_status, &tap);
    config.common.signer = NULL;
    config.common.insecure = true;
    coavoid_vehicle_node_t *a = coavoid_vehicle_node_create(&config, r.lcm, NULL, &error);
    ck_assert_ptr_nonnull(a);
    ck_assert_int_eq(coavoid_vehicle_node_cycle(a, r.now), COA_OK);
    drain(r.lcm);
    ck_assert(tap.reasons & COAVOID_STATUS_T_REASON_INSECURE);
    lcm_unsubscribe(r.lcm, ss);
    coavoid_vehicle_node_destroy(a);
    lcm_destroy(r.lcm);
}
END_TEST

/* A UAV that goes silent is avoided along the last plan it announced, not on a straight
 * line: 2 announced a climb (2 m a second) into the altitude of 1, which it will
 * meet head-on at t = 12 s, and fell silent; 1 starts at t = 3 s, when 2 is already stale,
 * and hears that intent. Without sigma growth a straight line at 2's altitude misses 1 by
 * 24 m; 2's plan does not: 1 has to get out of the way of the climb. */
START_TEST(test_silent_uav_avoided_along_its_plan)
{
    rig_t r;
    rig_init(&r, 24);
    r.common.stale_sigma_rate = 0;
    static wiretap_t tap;
    tap.uav = 2;
    lcm_subscription_t *si = lcm_subscribe(r.lcm, COAVOID_CHANNEL_INTENT, on_tapped_intent, &tap);
    coa_vec3_t r1[2], r2[2];
    coa_vehicle_t v2 = uav(2, 1, r2, 240, -1760, 0, 100);
    coavoid_vehicle_node_t *b = vehicle_node(&r, v2, COAVOID_NODE_DECOUPLED);
    ck_assert_int_eq(coavoid_vehicle_node_cycle(b, cycle(0)), COA_OK);
    drain(r.lcm);
    coavoid_vehicle_node_destroy(b);
    static coavoid_intent_t m;
    ck_assert_int_gt(coavoid_intent_t_decode(tap.bytes, 0, tap.size, &m), 0);
    for (int32_t j = 0; j < m.sample_count; j++) {
        m.offsets[j] = j; /* a climb: one step of 2 m a sample */
    }
    const coa_real_t dh = coa_climb_step(&v2, (coa_real_t)1);
    ck_assert(dh == (coa_real_t)2);
    r.now = cycle(3);
    coavoid_vehicle_node_t *a =
        vehicle_node(&r, uav(1, 2, r1, -30, 1970, 0, 124), COAVOID_NODE_DECOUPLED);
    const coavoid_vehicle_node_state_t *sa = coavoid_vehicle_node_state(a);
    ck_assert_int_eq(TEST_PUBLISH(r.lcm, coavoid_intent_t, COAVOID_CHANNEL_INTENT, &m), 0);
    drain(r.lcm);
    coa_vec3_t pa[31], q[31];
    for (int64_t k = 3; k <= 30; k++) {
        q[k] = coa_reference_at(&v2, (coa_real_t)k);
        q[k].z += dh * (coa_real_t)k; /* it flies the climb it announced, and on */
        r.now = cycle(k);
        coavoid_vehicle_node_cycle(a, r.now);
        drain(r.lcm);
        while (coavoid_vehicle_node_deadline(a) != INT64_MAX) {
            r.now = coavoid_vehicle_node_deadline(a);
            coavoid_vehicle_node_poll(a, r.now);
            drain(r.lcm);
        }
        pa[k] = sa->position;
    }
    ck_assert_uint_gt(sa->plans_run, 0);
    for (int64_t k = 3; k < 30; k++) {
        coa_sweep_t x = {{15, 5}, pa[k], pa[k + 1]};
        coa_sweep_t y = {{15, 5}, q[k], q[k + 1]};
        ck_assert_msg(!coa_conflict_volumes(&x, &y),
                      "conflict over step %d: 1 at (%.0f, %.1f), 2 at (%.0f, %.1f)", (int)k,
                      (double)pa[k].x, (double)pa[k].z, (double)q[k].x, (double)q[k].z);
    }
    lcm_unsubscribe(r.lcm, si);
    coavoid_vehicle_node_destroy(a);
    lcm_destroy(r.lcm);
}
END_TEST

static Suite *node_suite(void)
{
    Suite *s = suite_create("node");
    TCase *tc = tcase_create("node");
    tcase_set_timeout(tc, 120);
    tcase_add_test(tc, test_undecodable_counted_own_ignored);
    tcase_add_test(tc, test_restarted_peer_accepted_after_silence);
    tcase_add_test(tc, test_plan_adoption_rules);
    tcase_add_test(tc, test_plan_adopted_only_whole);
    tcase_add_test(tc, test_map_used_only_whole);
    tcase_add_test(tc, test_plan_ids_do_not_lock_out);
    tcase_add_test(tc, test_plan_into_terrain_refused);
    tcase_add_test(tc, test_plan_below_floor_refused);
    tcase_add_test(tc, test_forged_map_keeps_terrain);
    tcase_add_test(tc, test_plan_into_other_uav_refused);
    tcase_add_test(tc, test_duplicate_id_reported);
    tcase_add_test(tc, test_refusals_degrade_health);
    tcase_add_test(tc, test_health_reasons);
    tcase_add_test(tc, test_fallback_and_return);
    tcase_add_test(tc, test_configured_coordinator_only);
    tcase_add_test(tc, test_faulty_coordinator_not_followed);
    tcase_add_test(tc, test_late_plans_fall_back);
    tcase_add_test(tc, test_unanswered_conflict_planned_within_cycle);
    tcase_add_test(tc, test_refused_plan_planned_within_cycle);
    tcase_add_test(tc, test_answer_does_not_wait_for_a_switched_uav);
    tcase_add_test(tc, test_switch_before_it_is_decided_on_again);
    tcase_add_test(tc, test_failed_plan_is_an_answer);
    tcase_add_test(tc, test_coordinator_skips_decoupled_uav);
    tcase_add_test(tc, test_coordinator_abandons_past_budget);
    tcase_add_test(tc, test_coordinator_answers_within_its_work);
    tcase_add_test(tc, test_lower_priority_waits);
    tcase_add_test(tc, test_waits_for_near_higher_priority);
    tcase_add_test(tc, test_wait_ends_at_deadline);
    tcase_add_test(tc, test_higher_priority_replans_in_cluster);
    tcase_add_test(tc, test_raise_reorders);
    tcase_add_test(tc, test_lost_raise_heard_next_cycle);
    tcase_add_test(tc, test_greedy_raise_reorders);
    tcase_add_test(tc, test_lost_greedy_raise_heard_next_cycle);
    tcase_add_test(tc, test_silent_uav_avoided_as_track);
    tcase_add_test(tc, test_silent_uav_avoided_along_its_plan);
    tcase_add_test(tc, test_world_track_estimates);
    tcase_add_test(tc, test_every_datagram_fits);
    tcase_add_test(tc, test_bad_configs_refused);
    tcase_add_test(tc, test_signed_messages);
    tcase_add_test(tc, test_inbox_budget);
    tcase_add_test(tc, test_keys_required);
    suite_add_tcase(s, tc);
    return s;
}

int main(void)
{
    SRunner *sr = srunner_create(node_suite());
    srunner_run_all(sr, CK_NORMAL);
    int failed = srunner_ntests_failed(sr);
    srunner_free(sr);
    return failed == 0 ? EXIT_SUCCESS : EXIT_FAILURE;
}
