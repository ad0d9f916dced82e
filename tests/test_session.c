/* SPDX-License-Identifier: MIT */
/*
 * test_session.c: a vehicle behind a serial link (src/replay/session.h), the firmware's
 * side of `coavoid bridge`, on the host: frames in, frames out, over an in-memory wire.
 *   - a CONFIG is answered with a SUBSCRIBE per channel the vehicle takes in and READY,
 *     whose time is cycle 0's start;
 *   - flown by TIME frames at the times its READYs ask for, it sends, byte for byte, what
 *     the same vehicle sends when the drivers' schedule is run on it directly, and its
 *     state is the same;
 *   - a datagram handed in over the link reaches the node, and it polls after it;
 *   - frames out of place (before the CONFIG, of a kind the ground does not send, cut),
 *     and a CONFIG with other bytes, are answered with an error and change nothing; the
 *     same CONFIG again is answered as the first, and the vehicle flies on; a frame's
 *     time before the vehicle's clock does not take it back.
 */
#include <check.h>
#include <stdlib.h>
#include <string.h>

#include "protocol_internal.h"
#include "session.h"

#define EPOCH INT64_C(1000000000000000)
#define HORIZON 12u
#define WIRE 65536u
#define FRAMES 256u

/* What came off the vehicle's side of the wire, as frames. */
typedef struct {
    uint8_t rx_buffer[COAVOID_SESSION_MAX_RECORD + COAVOID_LINK_CRC_BYTES];
    coavoid_link_rx_t rx;
    uint8_t frames[FRAMES][2048];
    size_t sizes[FRAMES];
    size_t count;
} ground_t;

static void ground_put(void *user, uint8_t byte)
{
    ground_t *g = user;
    const size_t n = coavoid_link_rx_byte(&g->rx, byte);
    if (n > 0u) {
        ck_assert_uint_lt(g->count, FRAMES);
        ck_assert_uint_le(n, sizeof g->frames[0]);
        memcpy(g->frames[g->count], g->rx.buffer, n);
        g->sizes[g->count++] = n;
    }
}

static coa_vec3_t route[2][2];

/* UAV id, flying east (1) or west (2) at 100 m. */
static coavoid_vehicle_node_config_t uav_config(int64_t *clock, uint16_t id)
{
    coavoid_vehicle_node_config_t c;
    memset(&c, 0, sizeof c);
    ck_assert_int_eq(coavoid_node_common_defaults(&c.common, EPOCH, (coa_real_t)1, HORIZON, clock),
                     COA_OK);
    c.common.insecure = true;
    coa_vec3_t *r = route[id == 1u ? 0 : 1];
    r[0].x = id == 1u ? (coa_real_t)0 : (coa_real_t)400;
    r[1].x = id == 1u ? (coa_real_t)400 : (coa_real_t)0;
    r[0].z = r[1].z = (coa_real_t)100;
    c.vehicle.id = id;
    c.vehicle.priority = id;
    c.vehicle.cruise_speed = (coa_real_t)10;
    c.vehicle.climb_rate = (coa_real_t)10;
    c.vehicle.steep_factor = 2u;
    c.vehicle.volume.radius = (coa_real_t)15;
    c.vehicle.volume.half_height = (coa_real_t)5;
    c.vehicle.route = r;
    c.vehicle.route_count = 2u;
    c.vehicle.max_offset = -1;
    c.mode = COAVOID_NODE_DECOUPLED;
    c.intent_copies = COAVOID_NODE_DEFAULT_COPIES;
    return c;
}

static coavoid_vehicle_node_config_t config(int64_t *clock)
{
    return uav_config(clock, 1u);
}

static int64_t clock_now;
static ground_t ground;
static coavoid_session_t session;
static void *block;
static size_t block_size;
static uint8_t wire[WIRE];

/* A record framed, then handed to the session byte by byte as a UART would. */
static int send_frame(coavoid_replay_kind_t kind, int64_t time, const char *channel,
                      const uint8_t *payload, size_t length)
{
    uint8_t record[COAVOID_SESSION_MAX_RECORD];
    const size_t channel_length = channel != NULL ? strlen(channel) : 0u;
    coavoid_replay_write_header(record, kind, time, channel_length, length);
    if (channel_length > 0u) {
        memcpy(record + COAVOID_REPLAY_HEADER_BYTES, channel, channel_length);
    }
    if (length > 0u) {
        memcpy(record + COAVOID_REPLAY_HEADER_BYTES + channel_length, payload, length);
    }
    const size_t n = COAVOID_REPLAY_HEADER_BYTES + channel_length + length;
    const size_t framed = coavoid_link_frame(record, n, wire, sizeof wire);
    ck_assert_uint_gt(framed, 0u);
    static uint8_t buffer[COAVOID_SESSION_MAX_RECORD + COAVOID_LINK_CRC_BYTES];
    coavoid_link_rx_t rx;
    coavoid_link_rx_init(&rx, buffer, sizeof buffer);
    int rc = 1;
    for (size_t i = 0; i < framed; i++) {
        const size_t got = coavoid_link_rx_byte(&rx, wire[i]);
        if (got > 0u) {
            rc = coavoid_session_take(&session, buffer, got);
        }
    }
    ck_assert_int_ne(rc, 1);
    return rc;
}

static size_t config_bytes(uint8_t *out, size_t capacity, int64_t *clock)
{
    const coavoid_vehicle_node_config_t c = config(clock);
    const size_t n = coavoid_replay_write_config(&c, out, capacity);
    ck_assert_uint_gt(n, 0u);
    return n;
}

static coavoid_replay_record_t frame_at(size_t i)
{
    coavoid_replay_record_t rec;
    size_t used = 0;
    ck_assert_uint_lt(i, ground.count);
    ck_assert_int_eq(coavoid_replay_parse(ground.frames[i], ground.sizes[i], &rec, &used), COA_OK);
    ck_assert_uint_eq(used, ground.sizes[i]);
    return rec;
}

/* The last frame is a READY: its state's return value, and its time. */
static int ready_rc(int64_t *wake, coavoid_vehicle_node_state_t *state)
{
    const coavoid_replay_record_t rec = frame_at(ground.count - 1u);
    ck_assert_int_eq(rec.kind, COAVOID_REPLAY_READY);
    int rc = 1;
    ck_assert_int_eq(coavoid_replay_read_state(rec.payload, rec.payload_length, &rc, state),
                     COA_OK);
    *wake = rec.time;
    return rc;
}

static void setup(void)
{
    memset(&ground, 0, sizeof ground);
    coavoid_link_rx_init(&ground.rx, ground.rx_buffer, sizeof ground.rx_buffer);
    const coavoid_vehicle_node_config_t c = config(&clock_now);
    block_size = coavoid_vehicle_node_size(&c);
    block = aligned_alloc(COA_WORKSPACE_ALIGNMENT, (block_size + COA_WORKSPACE_ALIGNMENT - 1u) &
                                                       ~(size_t)(COA_WORKSPACE_ALIGNMENT - 1u));
    ck_assert_ptr_nonnull(block);
    coavoid_session_init(&session, block, block_size, ground_put, &ground);
}

static void teardown(void)
{
    coavoid_vehicle_node_fini(session.replay.node);
    free(block);
}

START_TEST(test_config_subscribes_and_wakes_at_cycle_0)
{
    uint8_t payload[4096];
    const size_t n = config_bytes(payload, sizeof payload, &clock_now);
    ck_assert_int_eq(send_frame(COAVOID_REPLAY_CONFIG, EPOCH - 500000, NULL, payload, n), COA_OK);
    /* Decoupled: intents, tracks and the map; no plans, heartbeats or agreements. */
    const char *const expect[] = {COAVOID_CHANNEL_INTENT, COAVOID_CHANNEL_TRACK,
                                  COAVOID_CHANNEL_OBSTACLES};
    ck_assert_uint_eq(ground.count, 4u);
    for (size_t i = 0; i < 3u; i++) {
        const coavoid_replay_record_t rec = frame_at(i);
        ck_assert_int_eq(rec.kind, COAVOID_REPLAY_SUBSCRIBE);
        ck_assert_uint_eq(rec.channel_length, strlen(expect[i]));
        ck_assert_int_eq(memcmp(rec.channel, expect[i], rec.channel_length), 0);
    }
    int64_t wake = 0;
    coavoid_vehicle_node_state_t st;
    ck_assert_int_eq(ready_rc(&wake, &st), COA_OK);
    ck_assert_int_eq(wake, EPOCH);
    ck_assert_int_eq(st.phase, COAVOID_VEHICLE_IDLE);
}
END_TEST

/* The drivers' schedule, on a node flown directly: what it sends, hashed in order. */
typedef struct {
    uint64_t hash[FRAMES];
    size_t count;
} sent_t;

static int direct_send(void *user, const char *channel, const uint8_t *data, size_t size)
{
    sent_t *s = user;
    ck_assert_uint_lt(s->count, FRAMES);
    const uint64_t h = coavoid_node_fnv(COAVOID_NODE_FNV_OFFSET, channel, strlen(channel));
    s->hash[s->count++] = coavoid_node_fnv(h, data, size);
    return COA_OK;
}

START_TEST(test_flies_as_the_drivers_schedule)
{
    uint8_t payload[4096];
    const size_t n = config_bytes(payload, sizeof payload, &clock_now);
    ck_assert_int_eq(send_frame(COAVOID_REPLAY_CONFIG, EPOCH - 1, NULL, payload, n), COA_OK);
    /* The same vehicle, direct: cycle at each start, poll at each deadline (once). */
    int64_t direct_now = 0;
    const coavoid_vehicle_node_config_t c = config(&direct_now);
    void *memory = aligned_alloc(COA_WORKSPACE_ALIGNMENT, (block_size + 63u) & ~(size_t)63u);
    sent_t direct = {{0}, 0};
    const coavoid_node_link_t link = {direct_send, &direct};
    int error = -99;
    coavoid_vehicle_node_t *node = coavoid_vehicle_node_init(memory, block_size, &c, &link, &error);
    ck_assert_ptr_nonnull(node);
    int64_t wake = 0;
    int64_t next_cycle = 0;
    int64_t polled = INT64_MIN;
    coavoid_vehicle_node_state_t st;
    size_t frames = 0;
    for (int steps = 0; steps < 200; steps++) {
        ck_assert_int_eq(ready_rc(&wake, &st), COA_OK);
        if (wake > EPOCH + 4 * INT64_C(1000000)) {
            break;
        }
        frames = ground.count;
        ck_assert_int_eq(send_frame(COAVOID_REPLAY_TIME, wake, NULL, NULL, 0u), COA_OK);
        direct_now = wake;
        if (wake >= EPOCH + next_cycle * INT64_C(1000000)) {
            ck_assert_int_eq(coavoid_vehicle_node_cycle(node, wake), COA_OK);
            next_cycle = coavoid_node_cycle_of(&c.common, wake) + 1;
        }
        const int64_t deadline = coavoid_vehicle_node_deadline(node);
        if (deadline <= wake && deadline != polled) {
            ck_assert_int_ge(coavoid_vehicle_node_poll(node, wake), 0);
            polled = deadline;
        }
        /* What the session sent for this frame equals what the node sent now. */
        for (size_t i = frames; i + 1u < ground.count; i++) {
            const coavoid_replay_record_t rec = frame_at(i);
            ck_assert_int_eq(rec.kind, COAVOID_REPLAY_SENT);
        }
    }
    /* Every datagram, in order, the same bytes. */
    size_t k = 0;
    for (size_t i = 0; i < ground.count; i++) {
        const coavoid_replay_record_t rec = frame_at(i);
        if (rec.kind == COAVOID_REPLAY_SENT) {
            ck_assert_uint_lt(k, direct.count);
            const uint64_t h =
                coavoid_node_fnv(COAVOID_NODE_FNV_OFFSET, rec.channel, rec.channel_length);
            ck_assert_uint_eq(coavoid_node_fnv(h, rec.payload, rec.payload_length), direct.hash[k]);
            k++;
        }
    }
    ck_assert_uint_eq(k, direct.count);
    ck_assert_uint_ge(k, 10u); /* intents and their copies, heartbeats: it flew */
    ck_assert_int_eq(st.cycle, coavoid_vehicle_node_state(node)->cycle);
    ck_assert_int_ge(st.cycle, 3);
    coavoid_vehicle_node_fini(node);
    free(memory);
}
END_TEST

/* A node's first intent. */
typedef struct {
    uint8_t data[COAVOID_LCM_MAX_DATAGRAM_BYTES];
    size_t size;
} last_t;

static int last_send(void *user, const char *channel, const uint8_t *data, size_t size)
{
    last_t *l = user;
    if (l->size == 0u && strcmp(channel, COAVOID_CHANNEL_INTENT) == 0) {
        ck_assert_uint_le(size, sizeof l->data);
        memcpy(l->data, data, size);
        l->size = size;
    }
    return COA_OK;
}

START_TEST(test_datagram_reaches_the_node)
{
    uint8_t payload[4096];
    const size_t n = config_bytes(payload, sizeof payload, &clock_now);
    ck_assert_int_eq(send_frame(COAVOID_REPLAY_CONFIG, EPOCH - 1, NULL, payload, n), COA_OK);
    ck_assert_int_eq(send_frame(COAVOID_REPLAY_TIME, EPOCH, NULL, NULL, 0u), COA_OK);
    /* UAV 2's first intent. */
    int64_t other_now = EPOCH;
    const coavoid_vehicle_node_config_t c2 = uav_config(&other_now, 2u);
    void *memory = aligned_alloc(COA_WORKSPACE_ALIGNMENT, (block_size + 63u) & ~(size_t)63u);
    last_t last = {{0}, 0};
    const coavoid_node_link_t link = {last_send, &last};
    int error = -99;
    coavoid_vehicle_node_t *other =
        coavoid_vehicle_node_init(memory, block_size, &c2, &link, &error);
    ck_assert_ptr_nonnull(other);
    ck_assert_int_eq(coavoid_vehicle_node_cycle(other, EPOCH), COA_OK);
    coavoid_vehicle_node_fini(other);
    free(memory);
    ck_assert_uint_gt(last.size, 0u);
    uint8_t *const copy = last.data;
    const coavoid_replay_record_t rec = {COAVOID_REPLAY_RECEIVE, 0, NULL, 0, NULL, last.size};
    const int64_t received = coavoid_vehicle_node_state(session.replay.node)->rx.received;
    ck_assert_int_eq(send_frame(COAVOID_REPLAY_RECEIVE, EPOCH + 1000, COAVOID_CHANNEL_INTENT, copy,
                                rec.payload_length),
                     COA_OK);
    ck_assert_int_eq(coavoid_vehicle_node_state(session.replay.node)->rx.received, received + 1);
    /* A channel it does not take in: the node's refusal, in the READY. */
    int64_t wake = 0;
    coavoid_vehicle_node_state_t st;
    ck_assert_int_eq(send_frame(COAVOID_REPLAY_RECEIVE, EPOCH + 2000, COAVOID_CHANNEL_PLAN, copy,
                                rec.payload_length),
                     COA_ERR_ARGUMENT);
    ck_assert_int_eq(ready_rc(&wake, &st), COA_ERR_ARGUMENT);
    ck_assert_uint_eq(session.refused, 1u);
}
END_TEST

START_TEST(test_frames_out_of_place)
{
    int64_t wake = 0;
    coavoid_vehicle_node_state_t st;
    /* Before the CONFIG: refused, READY says so and wants nothing. */
    ck_assert_int_eq(send_frame(COAVOID_REPLAY_TIME, EPOCH, NULL, NULL, 0u),
                     COAVOID_REPLAY_ERR_FORMAT);
    ck_assert_int_eq(ready_rc(&wake, &st), COAVOID_REPLAY_ERR_FORMAT);
    ck_assert_int_eq(wake, INT64_MAX);
    ck_assert_int_eq(st.cycle, -1);
    /* A cut record. */
    const uint8_t cut[5] = {COAVOID_REPLAY_TIME, 0, 0, 0, 0};
    ck_assert_int_eq(coavoid_session_take(&session, cut, sizeof cut), COAVOID_REPLAY_ERR_FORMAT);
    /* A configuration that is no configuration. */
    const uint8_t junk[3] = {1, 2, 3};
    ck_assert_int_eq(send_frame(COAVOID_REPLAY_CONFIG, EPOCH, NULL, junk, sizeof junk),
                     COAVOID_REPLAY_ERR_FORMAT);
    ck_assert_ptr_null(session.replay.node);

    uint8_t payload[4096];
    const size_t n = config_bytes(payload, sizeof payload, &clock_now);
    ck_assert_int_eq(send_frame(COAVOID_REPLAY_CONFIG, EPOCH - 1, NULL, payload, n), COA_OK);
    ck_assert_int_eq(send_frame(COAVOID_REPLAY_TIME, EPOCH + 1500000, NULL, NULL, 0u), COA_OK);
    ck_assert_int_eq(coavoid_vehicle_node_state(session.replay.node)->cycle, 1);
    /* The same CONFIG again: answered, nothing reset. */
    const size_t before = ground.count;
    ck_assert_int_eq(send_frame(COAVOID_REPLAY_CONFIG, EPOCH + 1600000, NULL, payload, n), COA_OK);
    ck_assert_uint_eq(ground.count, before + 4u);
    ck_assert_int_eq(coavoid_vehicle_node_state(session.replay.node)->cycle, 1);
    /* Another CONFIG: refused. */
    payload[n - 1u] ^= 1u;
    ck_assert_int_eq(send_frame(COAVOID_REPLAY_CONFIG, EPOCH + 1700000, NULL, payload, n),
                     COAVOID_REPLAY_ERR_FORMAT);
    /* Kinds only the vehicle sends. */
    ck_assert_int_eq(send_frame(COAVOID_REPLAY_READY, EPOCH + 1700000, NULL, NULL, 0u),
                     COAVOID_REPLAY_ERR_FORMAT);
    ck_assert_int_eq(send_frame(COAVOID_REPLAY_CYCLE, EPOCH + 1700000, NULL, NULL, 0u),
                     COAVOID_REPLAY_ERR_FORMAT);
    /* A time before its clock: the clock stays. */
    ck_assert_int_eq(send_frame(COAVOID_REPLAY_TIME, EPOCH, NULL, NULL, 0u), COA_OK);
    ck_assert_int_eq(session.replay.now, EPOCH + 1500000);
    ck_assert_int_eq(coavoid_vehicle_node_state(session.replay.node)->cycle, 1);
    ck_assert_uint_eq(session.refused, 6u);
}
END_TEST

static Suite *session_suite(void)
{
    Suite *s = suite_create("session");
    TCase *tc = tcase_create("session");
    tcase_add_checked_fixture(tc, setup, teardown);
    tcase_set_timeout(tc, 60);
    tcase_add_test(tc, test_config_subscribes_and_wakes_at_cycle_0);
    tcase_add_test(tc, test_flies_as_the_drivers_schedule);
    tcase_add_test(tc, test_datagram_reaches_the_node);
    tcase_add_test(tc, test_frames_out_of_place);
    suite_add_tcase(s, tc);
    return s;
}

int main(void)
{
    SRunner *runner = srunner_create(session_suite());
    srunner_run_all(runner, CK_NORMAL);
    const int failed = srunner_ntests_failed(runner);
    srunner_free(runner);
    return failed == 0 ? EXIT_SUCCESS : EXIT_FAILURE;
}
