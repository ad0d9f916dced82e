/* SPDX-License-Identifier: MIT */
/*
 * test_vehicle.c: the vehicle protocol's rules (docs/protocol.md) on the library alone
 * (coavoid::protocol, no LCM): two vehicles in memory of their own, their datagrams
 * carried by a queue this file delivers (losing the ones a test says), and the
 * coordinator played by the test, which signs its heartbeats, plans and decisions with
 * its key. Two UAVs head-on, in conflict from cycle 0; the coordinator's plan climbs UAV 1
 * three steps and keeps UAV 2 level. Each test checks the state machines (state.phase,
 * state.plan), what the vehicles said, and that no event was refused by a machine.
 *   - following: both FOLLOWING, both accept the whole plan, COMMIT: both fly it;
 *   - a plan with a row missing is neither accepted nor refused;
 *   - the COMMIT lost to UAV 1: UAV 2's SWITCHED commits it for UAV 1 too;
 *   - ABORT: HOLDING -> NONE, the plan is not flown;
 *   - the coordinator silent after proposing, every ACCEPT heard: each commits itself
 *     at the answer wait;
 *   - ... UAV 2's ACCEPT lost to UAV 1: UAV 1 holds a STANDBY, and the plan is in doubt
 *     at the cycle's end;
 *   - no plan by the answer wait: each decides for itself (ANSWERING), and distrusts the
 *     coordinator into the next cycle (DECIDING);
 *   - a row that does not start where the UAV flies: REFUSE;
 *   - the rows sent again: ACCEPT again;
 *   - no coordinator at all: FALLBACK once its timeout has passed (DECIDING, fallbacks).
 * And how a node keeps a peer's intent: opened again, it is the message received, and
 * converts to the core's types exactly as the received one does.
 */
#include <check.h>
#include <stdlib.h>
#include <string.h>

#include <coavoid_lcmtypes/coavoid_agreement_t.h>
#include <coavoid_lcmtypes/coavoid_intent_t.h>
#include <coavoid_lcmtypes/coavoid_plan_t.h>
#include <coavoid_lcmtypes/coavoid_status_t.h>

#include "lcm_examples.h"
#include "protocol.h"
#include "protocol_internal.h"

#define EPOCH INT64_C(1000000000000000)
#define DT_US INT64_C(1000000)
#define HORIZON 12
#define UAVS 2u
#define QUEUE 1024u
#define COORDINATOR 0u /* a datagram's sender: the coordinator, or UAV i + 1 */

typedef struct {
    char channel[24];
    unsigned from;
    size_t size;
    uint8_t data[COAVOID_LCM_MAX_DATAGRAM_BYTES];
} datagram_t;

typedef struct bench bench_t;
typedef struct {
    bench_t *bench;
    unsigned from;
} link_user_t;

struct bench {
    int64_t now;
    coavoid_auth_trust_t trust;
    coavoid_auth_signer_t coordinator;
    coavoid_auth_signer_t key[UAVS];
    coa_vec3_t route[UAVS][2];
    void *memory[UAVS];
    coavoid_vehicle_node_t *uav[UAVS];
    link_user_t user[UAVS];
    datagram_t queue[QUEUE];
    size_t head, tail;
    /* Loses what `from` sends on `kind` (an agreement kind, or -1: every datagram) to UAV
     * `to` (1-based), while set. */
    bool lose_from[UAVS + 1u][UAVS + 1u];
    int lose_kind;
    /* What each UAV said: agreements by kind, intents and their last mode and offset 1. */
    unsigned said[UAVS][8];
    unsigned intents[UAVS];
    int8_t intent_mode[UAVS];
    int32_t intent_offset1[UAVS];
    int32_t intent_climb[UAVS]; /* the largest |offset| of its last intent */
    int64_t plan_id;
    int64_t status_sequence;
};

static bench_t bench;

static int64_t cycle_at(int64_t k)
{
    return EPOCH + k * DT_US;
}

static void enqueue(bench_t *b, unsigned from, const char *channel, const uint8_t *data,
                    size_t size)
{
    ck_assert_uint_lt(b->tail - b->head, QUEUE);
    ck_assert_uint_le(size, sizeof b->queue[0].data);
    datagram_t *d = &b->queue[b->tail++ % QUEUE];
    strncpy(d->channel, channel, sizeof d->channel - 1u);
    d->channel[sizeof d->channel - 1u] = '\0';
    d->from = from;
    d->size = size;
    memcpy(d->data, data, size);
}

static int link_send(void *user, const char *channel, const uint8_t *data, size_t size)
{
    const link_user_t *u = user;
    enqueue(u->bench, u->from, channel, data, size);
    return COA_OK;
}

/* Notes what a UAV said; whether the datagram is lost to UAV `to`. */
static bool note_and_lose(bench_t *b, const datagram_t *d, unsigned to)
{
    int kind = -1;
    if (strcmp(d->channel, COAVOID_CHANNEL_AGREEMENT) == 0) {
        coavoid_agreement_t m;
        ck_assert_int_ge(coavoid_agreement_t_decode(d->data, 0, (int)d->size, &m), 0);
        kind = m.kind;
    }
    return d->from != to && b->lose_from[d->from][to] && (b->lose_kind < 0 || b->lose_kind == kind);
}

static void note_said(bench_t *b, const datagram_t *d)
{
    if (d->from == COORDINATOR) {
        return;
    }
    const unsigned i = d->from - 1u;
    if (strcmp(d->channel, COAVOID_CHANNEL_AGREEMENT) == 0) {
        coavoid_agreement_t m;
        ck_assert_int_ge(coavoid_agreement_t_decode(d->data, 0, (int)d->size, &m), 0);
        ck_assert_int_lt(m.kind, 8);
        b->said[i][m.kind]++;
    } else if (strcmp(d->channel, COAVOID_CHANNEL_INTENT) == 0) {
        coavoid_intent_t m;
        ck_assert_int_ge(coavoid_intent_t_decode(d->data, 0, (int)d->size, &m), 0);
        b->intents[i]++;
        b->intent_mode[i] = m.mode;
        b->intent_offset1[i] = m.offsets[1];
        b->intent_climb[i] = 0;
        for (int32_t j = 0; j < m.sample_count && j < COAVOID_INTENT_T_MAX_SAMPLES; j++) {
            const int32_t a = m.offsets[j] < 0 ? -m.offsets[j] : m.offsets[j];
            b->intent_climb[i] = a > b->intent_climb[i] ? a : b->intent_climb[i];
        }
    }
}

/* Whether UAV `to` takes in `channel` (coavoid_vehicle_node_channel). */
static bool takes(const bench_t *b, unsigned to, const char *channel)
{
    for (size_t i = 0; i < COAVOID_NODE_CHANNELS; i++) {
        const char *c = coavoid_vehicle_node_channel(b->uav[to - 1u], i);
        if (c != NULL && strcmp(c, channel) == 0) {
            return true;
        }
    }
    return false;
}

/* Hands every queued datagram to every UAV that takes its channel in (its own back to it,
 * as a multicast socket does), but those a test loses. */
static void deliver(bench_t *b)
{
    while (b->head != b->tail) {
        const datagram_t d = b->queue[b->head++ % QUEUE];
        note_said(b, &d);
        for (unsigned to = 1; to <= UAVS; to++) {
            if (takes(b, to, d.channel) && !note_and_lose(b, &d, to)) {
                ck_assert_int_eq(
                    coavoid_vehicle_node_receive(b->uav[to - 1u], d.channel, d.data, d.size),
                    COA_OK);
            }
        }
    }
}

/* Every cycle start and poll of both UAVs up to `until`, in time order. */
static void run_until(bench_t *b, int64_t until)
{
    for (;;) {
        const int64_t k = (b->now - EPOCH) / DT_US;
        const bool begun = coavoid_vehicle_node_state(b->uav[0])->cycle >= k;
        int64_t next = begun ? cycle_at(k + 1) : cycle_at(k);
        for (unsigned i = 0; i < UAVS; i++) {
            const int64_t d = coavoid_vehicle_node_deadline(b->uav[i]);
            next = d < next ? d : next;
        }
        if (next > until) {
            b->now = until;
            return;
        }
        b->now = next > b->now ? next : b->now;
        const bool start = (b->now - EPOCH) % DT_US == 0 &&
                           coavoid_vehicle_node_state(b->uav[0])->cycle < (b->now - EPOCH) / DT_US;
        for (unsigned i = 0; i < UAVS; i++) {
            if (start) {
                ck_assert_int_eq(coavoid_vehicle_node_cycle(b->uav[i], b->now), COA_OK);
            } else {
                ck_assert_int_ge(coavoid_vehicle_node_poll(b->uav[i], b->now), 0);
            }
            deliver(b);
        }
    }
}

static void key(bench_t *b, coavoid_auth_signer_t *s, uint32_t id, coavoid_auth_role_t role,
                uint16_t node)
{
    unsigned char seed[COAVOID_AUTH_SEED_BYTES] = {(unsigned char)id, 3};
    coavoid_auth_key_t k = {id, role, node, {0}};
    memset(s, 0, sizeof *s);
    s->key_id = id;
    coavoid_auth_signer_use_fleet(s, &b->trust);
    ck_assert_int_eq(coavoid_auth_keypair_seed(seed, k.public_key, s->secret_key), COA_OK);
    ck_assert_int_eq(coavoid_auth_trust_add(&b->trust, &k), COA_OK);
}

/* UAV i + 1: from x0 towards x1 at 10 m/s, 100 m up; 10 m climb steps. */
static coavoid_vehicle_node_config_t uav_config(bench_t *b, unsigned i, coavoid_node_mode_t mode)
{
    coavoid_vehicle_node_config_t c;
    memset(&c, 0, sizeof c);
    ck_assert_int_eq(
        coavoid_node_common_defaults(&c.common, EPOCH, (coa_real_t)1, (uint32_t)HORIZON, &b->now),
        COA_OK);
    c.common.trust = &b->trust;
    c.common.signer = &b->key[i];
    b->route[i][0].x = i == 0u ? (coa_real_t)0 : (coa_real_t)200;
    b->route[i][1].x = i == 0u ? (coa_real_t)400 : (coa_real_t)-200;
    b->route[i][0].z = b->route[i][1].z = (coa_real_t)100;
    c.vehicle.id = (uint16_t)(i + 1u);
    c.vehicle.priority = i + 1u;
    c.vehicle.cruise_speed = (coa_real_t)10;
    c.vehicle.climb_rate = (coa_real_t)10;
    c.vehicle.steep_factor = 2u;
    c.vehicle.volume.radius = (coa_real_t)15;
    c.vehicle.volume.half_height = (coa_real_t)5;
    c.vehicle.route = b->route[i];
    c.vehicle.route_count = 2u;
    c.vehicle.max_offset = -1;
    c.mode = mode;
    c.intent_copies = COAVOID_NODE_DEFAULT_COPIES;
    return c;
}

static void setup_mode(coavoid_node_mode_t mode)
{
    bench_t *b = &bench;
    memset(b, 0, sizeof *b);
    b->now = EPOCH;
    b->lose_kind = -1;
    ck_assert_int_eq(coavoid_auth_init(), COA_OK);
    coavoid_auth_trust_init(&b->trust);
    const unsigned char fleet[COAVOID_AUTH_FLEET_KEY_BYTES] = "vehicle fleet";
    ck_assert_int_eq(coavoid_auth_trust_set_fleet_key(&b->trust, fleet), COA_OK);
    key(b, &b->coordinator, 1u, COAVOID_AUTH_COORDINATOR, (uint16_t)COAVOID_NODE_COORDINATOR_ID);
    for (unsigned i = 0; i < UAVS; i++) {
        key(b, &b->key[i], 101u + i, COAVOID_AUTH_VEHICLE, (uint16_t)(i + 1u));
    }
    for (unsigned i = 0; i < UAVS; i++) {
        const coavoid_vehicle_node_config_t c = uav_config(b, i, mode);
        const size_t size = coavoid_vehicle_node_size(&c);
        ck_assert_uint_gt(size, 0u);
        b->memory[i] = malloc(size);
        ck_assert_ptr_nonnull(b->memory[i]);
        b->user[i].bench = b;
        b->user[i].from = i + 1u;
        const coavoid_node_link_t link = {link_send, &b->user[i]};
        int error = -99;
        b->uav[i] = coavoid_vehicle_node_init(b->memory[i], size, &c, &link, &error);
        ck_assert_int_eq(error, COA_OK);
        ck_assert_ptr_eq(b->uav[i], b->memory[i]);
        ck_assert_int_eq(coavoid_vehicle_node_state(b->uav[i])->phase, COAVOID_VEHICLE_IDLE);
    }
}

static void setup(void)
{
    setup_mode(COAVOID_NODE_CENTRALISED);
}

static void teardown(void)
{
    for (unsigned i = 0; i < UAVS; i++) {
        ck_assert_uint_eq(coavoid_vehicle_node_state(bench.uav[i])->protocol_faults, 0u);
        coavoid_vehicle_node_fini(bench.uav[i]);
        free(bench.memory[i]);
    }
}

static const coavoid_vehicle_node_state_t *state(unsigned uav)
{
    return coavoid_vehicle_node_state(bench.uav[uav - 1u]);
}

/* ---- the coordinator, played by the test ---- */

#define COORD_SEND(type, channel, msg)                                                           \
    do {                                                                                         \
        uint8_t buf_[COAVOID_LCM_MAX_DATAGRAM_BYTES];                                            \
        const int size_ = type##_encode(buf_, 0, (int)sizeof buf_, (msg));                       \
        ck_assert_int_gt(size_, 0);                                                              \
        ck_assert_int_eq(coavoid_auth_stamp(&bench.coordinator, bench.now, buf_, (size_t)size_), \
                         COA_OK);                                                                \
        enqueue(&bench, COORDINATOR, (channel), buf_, (size_t)size_);                            \
    } while (0)

static void heartbeat(void)
{
    coavoid_status_t m;
    memset(&m, 0, sizeof m);
    m.utime = bench.now;
    m.node_id = (int32_t)COAVOID_NODE_COORDINATOR_ID;
    m.node_kind = COAVOID_STATUS_T_NODE_COORDINATOR;
    m.sequence = bench.status_sequence++;
    m.health = COAVOID_STATUS_T_HEALTH_OK;
    m.mode = COAVOID_STATUS_T_MODE_CENTRALISED;
    m.outcome = COAVOID_STATUS_T_OUTCOME_NONE;
    COORD_SEND(coavoid_status_t, COAVOID_CHANNEL_STATUS, &m);
    deliver(&bench);
}

/* The plan of cycle k, one message per UAV listed (rows: UAV 1 climbs 3 steps plus
 * `shift`, UAV 2 stays level), only the rows of `rows` (bit i: UAV i + 1's) sent. Returns
 * its plan_id. */
static int64_t plan(int64_t k, unsigned rows, int32_t shift)
{
    const int64_t id = ++bench.plan_id;
    for (unsigned i = 0; i < UAVS; i++) {
        if ((rows & (1u << i)) == 0u) {
            continue;
        }
        coavoid_plan_t m;
        memset(&m, 0, sizeof m);
        m.utime = bench.now;
        m.coordinator_id = (int32_t)COAVOID_NODE_COORDINATOR_ID;
        m.plan_id = id;
        m.valid_from_utime = cycle_at(k);
        m.valid_until_utime = cycle_at(k + 1);
        m.dt = 1.0;
        m.horizon = HORIZON;
        m.mode = COAVOID_PLAN_T_MODE_CENTRALISED;
        m.status = COAVOID_PLAN_T_STATUS_SOLVED;
        m.vehicle_count = (int32_t)UAVS;
        m.planned_count = (int32_t)UAVS;
        m.uav_ids[0] = 1;
        m.uav_ids[1] = 2;
        m.row_uav_id = (int32_t)(i + 1u);
        for (int32_t j = 0; j <= HORIZON; j++) {
            m.offsets[j] = i == 0u ? (j < 3 ? j : 3) + shift : 0;
        }
        COORD_SEND(coavoid_plan_t, COAVOID_CHANNEL_PLAN, &m);
    }
    deliver(&bench);
    return id;
}

static void decision(int8_t kind, int64_t k, int64_t plan_id)
{
    coavoid_agreement_t m;
    memset(&m, 0, sizeof m);
    m.utime = bench.now;
    m.kind = kind;
    m.node_id = (int32_t)COAVOID_NODE_COORDINATOR_ID;
    m.coordinator_id = (int32_t)COAVOID_NODE_COORDINATOR_ID;
    m.plan_id = plan_id;
    m.valid_from_utime = cycle_at(k);
    COORD_SEND(coavoid_agreement_t, COAVOID_CHANNEL_AGREEMENT, &m);
    deliver(&bench);
}

/* Cycle 0 up to the coordinator's collect (a quarter cycle), with its heartbeat. */
static void to_collect(void)
{
    run_until(&bench, cycle_at(0));
    heartbeat();
    run_until(&bench, cycle_at(0) + DT_US / 4);
}

/* ---- the rules ---- */

START_TEST(test_follow_accept_commit)
{
    to_collect();
    for (unsigned u = 1; u <= UAVS; u++) {
        ck_assert_int_eq(state(u)->phase, COAVOID_VEHICLE_FOLLOWING);
        ck_assert_int_eq(bench.intent_mode[u - 1u], COAVOID_INTENT_T_MODE_CENTRALISED);
    }
    const int64_t id = plan(0, 3u, 0);
    for (unsigned u = 1; u <= UAVS; u++) {
        ck_assert_int_eq(state(u)->plan, COAVOID_VEHICLE_PLAN_HOLDING);
        ck_assert_uint_eq(bench.said[u - 1u][COAVOID_AGREEMENT_T_KIND_ACCEPT], 1u);
    }
    decision(COAVOID_AGREEMENT_T_KIND_COMMIT, 0, id);
    for (unsigned u = 1; u <= UAVS; u++) {
        ck_assert_int_eq(state(u)->plan, COAVOID_VEHICLE_PLAN_SWITCHED);
        ck_assert_uint_eq(state(u)->plans_switched, 1u);
        ck_assert_uint_eq(bench.said[u - 1u][COAVOID_AGREEMENT_T_KIND_SWITCHED], 1u);
    }
    ck_assert_int_eq(bench.intent_offset1[0], 1); /* its new intent: climbing */
    run_until(&bench, cycle_at(1));
    ck_assert_int_eq(state(1)->offset, 1);
    ck_assert_int_eq(state(1)->plan, COAVOID_VEHICLE_PLAN_NONE);
    ck_assert_uint_eq(state(1)->plans_in_doubt, 0u);
}
END_TEST

START_TEST(test_row_missing_is_not_answered)
{
    to_collect();
    (void)plan(0, 1u, 0); /* UAV 1's row only */
    ck_assert_int_eq(state(1)->plan, COAVOID_VEHICLE_PLAN_NONE);
    ck_assert_uint_eq(bench.said[0][COAVOID_AGREEMENT_T_KIND_ACCEPT], 0u);
    ck_assert_uint_eq(bench.said[0][COAVOID_AGREEMENT_T_KIND_REFUSE], 0u);
}
END_TEST

START_TEST(test_sibling_switched_commits)
{
    to_collect();
    const int64_t id = plan(0, 3u, 0);
    bench.lose_from[COORDINATOR][1] = true; /* the COMMIT never reaches UAV 1 */
    decision(COAVOID_AGREEMENT_T_KIND_COMMIT, 0, id);
    ck_assert_int_eq(state(2)->plan, COAVOID_VEHICLE_PLAN_SWITCHED);
    ck_assert_int_eq(state(1)->plan, COAVOID_VEHICLE_PLAN_SWITCHED); /* on UAV 2's word */
    ck_assert_uint_eq(state(1)->plans_switched, 1u);
}
END_TEST

START_TEST(test_abort_drops_the_plan)
{
    to_collect();
    const int64_t id = plan(0, 3u, 0);
    decision(COAVOID_AGREEMENT_T_KIND_ABORT, 0, id);
    ck_assert_int_eq(state(1)->plan, COAVOID_VEHICLE_PLAN_NONE);
    ck_assert_uint_eq(state(1)->plans_aborted, 1u);
    run_until(&bench, cycle_at(0) + DT_US / 2);
    ck_assert_int_eq(bench.intent_offset1[0], 0); /* it never flew it */
}
END_TEST

START_TEST(test_silent_coordinator_self_commit)
{
    to_collect();
    (void)plan(0, 3u, 0);
    /* No decision: at the answer wait each has heard every ACCEPT, due since the ack
     * timeout and four resends: it commits itself. */
    run_until(&bench, cycle_at(1) - 1);
    /* UAV 1, polled first, commits itself; its SWITCHED commits it for UAV 2, which then
     * has nothing of its own to do at its answer wait. */
    ck_assert_uint_eq(state(1)->plans_self_committed, 1u);
    ck_assert_int_eq(state(1)->phase, COAVOID_VEHICLE_DECIDED);
    ck_assert_uint_eq(state(2)->plans_self_committed, 0u);
    ck_assert_int_eq(state(2)->phase, COAVOID_VEHICLE_FOLLOWED);
    for (unsigned u = 1; u <= UAVS; u++) {
        ck_assert_int_eq(state(u)->plan, COAVOID_VEHICLE_PLAN_SWITCHED);
        ck_assert_uint_eq(state(u)->plans_switched, 1u);
    }
}
END_TEST

START_TEST(test_unheard_accept_standby)
{
    to_collect();
    bench.lose_from[2][1] = true; /* UAV 2's answers never reach UAV 1 */
    bench.lose_kind = COAVOID_AGREEMENT_T_KIND_ACCEPT;
    (void)plan(0, 3u, 0);
    run_until(&bench, cycle_at(1) - 1);
    ck_assert_int_eq(state(1)->plan, COAVOID_VEHICLE_PLAN_STANDBY);
    ck_assert_int_eq(state(1)->phase, COAVOID_VEHICLE_DECIDED);
    /* UAV 2 heard every ACCEPT, but UAV 1's standby left it no conflict of its own: it
     * commits nothing by itself, and the plan is in doubt for both at the cycle's end. */
    ck_assert_int_eq(state(2)->plan, COAVOID_VEHICLE_PLAN_HOLDING);
    ck_assert_int_eq(state(2)->phase, COAVOID_VEHICLE_FOLLOWED);
    run_until(&bench, cycle_at(1));
    ck_assert_uint_eq(state(1)->plans_in_doubt, 1u);
    ck_assert_uint_eq(state(1)->plans_standby, 1u);
    ck_assert_uint_eq(state(2)->plans_in_doubt, 1u);
    ck_assert_uint_eq(state(2)->plans_standby, 0u);
    ck_assert_uint_ge(state(1)->plans_adopted, 1u); /* the standby, flown */
}
END_TEST

START_TEST(test_unanswered_decides_itself)
{
    to_collect();
    run_until(&bench, cycle_at(1) - 1); /* no plan at all */
    for (unsigned u = 1; u <= UAVS; u++) {
        ck_assert_int_eq(state(u)->phase, COAVOID_VEHICLE_ANSWERED);
        ck_assert_int_eq(bench.intent_mode[u - 1u], COAVOID_INTENT_T_MODE_DECOUPLED);
    }
    /* It distrusts the coordinator into the next cycle, unless it hears it since. */
    run_until(&bench, cycle_at(1) + 1);
    ck_assert(!state(1)->coordinated);
    ck_assert_int_ne(state(1)->phase, COAVOID_VEHICLE_FOLLOWING);
    heartbeat();
    run_until(&bench, cycle_at(2) + 1);
    ck_assert_int_eq(state(1)->phase, COAVOID_VEHICLE_FOLLOWING);
}
END_TEST

START_TEST(test_row_not_from_its_offset_refused)
{
    to_collect();
    (void)plan(0, 3u, 1); /* UAV 1's row starts one step up */
    ck_assert_int_eq(state(1)->plan, COAVOID_VEHICLE_PLAN_NONE);
    ck_assert_uint_eq(bench.said[0][COAVOID_AGREEMENT_T_KIND_REFUSE], 1u);
    ck_assert_uint_eq(state(1)->plans_refused, 1u);
    ck_assert_int_eq(state(2)->plan, COAVOID_VEHICLE_PLAN_HOLDING);
}
END_TEST

START_TEST(test_rows_again_answered_again)
{
    to_collect();
    const int64_t id = plan(0, 3u, 0);
    const unsigned before = bench.said[0][COAVOID_AGREEMENT_T_KIND_ACCEPT];
    bench.plan_id = id - 1; /* the same plan, sent again */
    (void)plan(0, 1u, 0);
    ck_assert_uint_eq(bench.said[0][COAVOID_AGREEMENT_T_KIND_ACCEPT], before + 1u);
    ck_assert_int_eq(state(1)->plan, COAVOID_VEHICLE_PLAN_HOLDING);
}
END_TEST

START_TEST(test_no_coordinator_falls_back)
{
    run_until(&bench, cycle_at(3) + 1); /* coordinator_timeout: 2.5 cycles */
    for (unsigned u = 1; u <= UAVS; u++) {
        ck_assert(!state(u)->coordinated);
        ck_assert_uint_ge(state(u)->fallbacks, 1u);
        ck_assert_int_eq(bench.intent_mode[u - 1u], COAVOID_INTENT_T_MODE_DECOUPLED);
    }
}
END_TEST

START_TEST(test_decoupled_decides)
{
    teardown();
    setup_mode(COAVOID_NODE_DECOUPLED);
    run_until(&bench, cycle_at(0) + DT_US / 2 + 1);
    for (unsigned u = 1; u <= UAVS; u++) {
        ck_assert_int_eq(state(u)->phase, COAVOID_VEHICLE_DECIDED);
        ck_assert(!state(u)->coordinated);
    }
    /* In priority order: UAV 1 decides first, on nothing yet, and flies on; UAV 2 waits
     * for its intent and plans around it. */
    ck_assert_uint_eq(state(1)->plans_adopted, 0u);
    ck_assert_uint_ge(state(2)->plans_adopted, 1u);
    ck_assert_int_eq(bench.intent_climb[0], 0);
    ck_assert_int_gt(bench.intent_climb[1], 0);
}
END_TEST

/* Every intent's view in the core's types, after a check on ctx. */
static void intent_core(const coavoid_intent_t *m, coavoid_lcm_intent_arrays_t *arrays,
                        coa_vehicle_t *vehicle, coa_intent_plan_t *plan)
{
    const coavoid_lcm_context_t ctx = ctx_now();
    coavoid_lcm_intent_info_t info;
    ck_assert_int_eq(coavoid_lcm_intent_to_core(m, &ctx, NULL, &info, vehicle, plan, arrays, NULL),
                     COA_OK);
}

START_TEST(test_kept_intent_opens_as_received)
{
    static coavoid_node_intent_t kept;
    static coavoid_intent_t opened;
    static coavoid_lcm_intent_arrays_t a;
    static coavoid_lcm_intent_arrays_t b;
    coa_vehicle_t va;
    coa_vehicle_t vb;
    coa_intent_plan_t pa;
    coa_intent_plan_t pb;
    coavoid_intent_t m = good_intent();
    m.sample_count = (int32_t)COAVOID_NODE_MAX_SAMPLES < m.sample_count
                         ? (int32_t)COAVOID_NODE_MAX_SAMPLES
                         : m.sample_count;
    m.auth.key_id = 3; /* a field after the samples */
    coavoid_node_intent_keep(&kept, &m);
    ck_assert_int_eq(kept.utime, m.utime);
    ck_assert_int_eq(kept.plan_utime, m.plan_utime);
    ck_assert_int_eq(kept.uav_id, m.uav_id);
    coavoid_node_intent_open(&kept, &opened);
    ck_assert_int_eq(opened.auth.key_id, 3);
    ck_assert_int_eq(opened.rank, m.rank);
    ck_assert(opened.sigma_vertical == m.sigma_vertical);
    ck_assert_int_eq(memcmp(opened.offsets, m.offsets, sizeof m.offsets), 0);
#ifndef COA_SINGLE_PRECISION
    ck_assert_int_eq(memcmp(&opened, &m, sizeof m), 0); /* kept whole */
#endif
    intent_core(&m, &a, &va, &pa);
    intent_core(&opened, &b, &vb, &pb);
    ck_assert_uint_eq(pa.count, pb.count);
    ck_assert_int_eq(memcmp(a.reference, b.reference, pa.count * sizeof a.reference[0]), 0);
    ck_assert_int_eq(memcmp(a.samples, b.samples, pa.count * sizeof a.samples[0]), 0);
    ck_assert(va.cruise_speed == vb.cruise_speed && va.volume.radius == vb.volume.radius);
}
END_TEST

static Suite *vehicle_suite(void)
{
    Suite *s = suite_create("vehicle");
    TCase *tc = tcase_create("rules");
    tcase_add_checked_fixture(tc, setup, teardown);
    tcase_set_timeout(tc, 60);
    tcase_add_test(tc, test_follow_accept_commit);
    tcase_add_test(tc, test_row_missing_is_not_answered);
    tcase_add_test(tc, test_sibling_switched_commits);
    tcase_add_test(tc, test_abort_drops_the_plan);
    tcase_add_test(tc, test_silent_coordinator_self_commit);
    tcase_add_test(tc, test_unheard_accept_standby);
    tcase_add_test(tc, test_unanswered_decides_itself);
    tcase_add_test(tc, test_row_not_from_its_offset_refused);
    tcase_add_test(tc, test_rows_again_answered_again);
    tcase_add_test(tc, test_no_coordinator_falls_back);
    tcase_add_test(tc, test_decoupled_decides);
    suite_add_tcase(s, tc);
    TCase *storage = tcase_create("storage");
    tcase_add_test(storage, test_kept_intent_opens_as_received);
    suite_add_tcase(s, storage);
    return s;
}

int main(void)
{
    SRunner *sr = srunner_create(vehicle_suite());
    srunner_run_all(sr, CK_NORMAL);
    const int failed = srunner_ntests_failed(sr);
    srunner_free(sr);
    return failed == 0 ? EXIT_SUCCESS : EXIT_FAILURE;
}
