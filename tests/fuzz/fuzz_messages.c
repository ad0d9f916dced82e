/* SPDX-License-Identifier: MIT */
/*
 * fuzz_messages.c: libFuzzer target for what a node does with a datagram from the network:
 * LCM's generated decoder, then src/lcm's check and conversion to the core's types (the
 * sequence rule included; a plan's rows and a map's tiles collected across inputs), for
 * each of the six message types.
 *
 * The first input byte picks the type (low bits) and the mode (high bit): raw, the rest of
 * the input is the datagram as it came; or mutated, the rest is XORed over the encoding
 * of a valid message of that type (tests/lcm_examples.h) after its 8-byte fingerprint, so
 * that the type hash holds and
 * the fuzzer reaches every field's validation instead of stopping at it.
 * Every datagram also goes through the signature check (auth.h) against a trust list of one
 * key. Kind 7 (no message type) feeds the bytes to the trust and secret key file parsers. Every input
 * after its first byte is also a datagram off the socket for the drivers' receiver's
 * framing (coavoid_rt_rx_parse), whose frame must lie inside it. And every datagram of a
 * type a vehicle takes in is handed to one (the vehicle protocol, protocol.h: insecure, so
 * that what it decodes reaches its inbox, its plan collection and its check of a plan
 * for it), which keeps what it stores from one input to the next and polls after each.
 * Its bytes are also a vehicle's record, the frames of a serial link, and the frames a
 * vehicle on the part takes (session.h).
 * Nothing may crash, leak or trip a sanitizer, whatever the bytes.
 */
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "auth.h"
#include "coavoid_lcm.h"
#include "lcm_examples.h"
#include "protocol.h"
#include "link.h"
#include "replay.h"
#include "session.h"
#include "realtime.h"

#define FUZZ_BUF 20000

/* Decodes `size` bytes as `type` into m, then runs `body` on it, then frees. */
#define FUZZ_DECODE(type, m, buf, size, body)                \
    do {                                                     \
        static type m;                                       \
        memset(&m, 0, sizeof m);                             \
        if (type##_decode((buf), 0, (int)(size), &m) >= 0) { \
            body;                                            \
            type##_decode_cleanup(&m);                       \
        }                                                    \
    } while (0)

/* The encoding of the example message of `kind` into buf; its size, or 0. */
static size_t example(unsigned kind, unsigned char *buf)
{
    static coavoid_intent_t i;
    static coavoid_plan_t p;
    static coavoid_obstacle_map_t o;
    coavoid_track_t t;
    coavoid_conflict_report_t c;
    coavoid_status_t s;
    coavoid_agreement_t a;
    int n = -1;
    switch (kind) {
    case 0:
        i = good_intent();
        n = coavoid_intent_t_encode(buf, 0, FUZZ_BUF, &i);
        break;
    case 1:
        p = good_plan();
        n = coavoid_plan_t_encode(buf, 0, FUZZ_BUF, &p);
        break;
    case 2:
        t = good_track();
        n = coavoid_track_t_encode(buf, 0, FUZZ_BUF, &t);
        break;
    case 3:
        o = good_map();
        n = coavoid_obstacle_map_t_encode(buf, 0, FUZZ_BUF, &o);
        break;
    case 4:
        c = good_report();
        n = coavoid_conflict_report_t_encode(buf, 0, FUZZ_BUF, &c);
        break;
    case 5:
        s = good_status();
        n = coavoid_status_t_encode(buf, 0, FUZZ_BUF, &s);
        break;
    default:
        a = good_agreement();
        n = coavoid_agreement_t_encode(buf, 0, FUZZ_BUF, &a);
        break;
    }
    return n > 0 ? (size_t)n : 0u;
}

static void receive_intent(const unsigned char *buf, size_t size, coavoid_lcm_context_t *ctx,
                           coavoid_lcm_sequence_table_t *seq)
{
    static coavoid_lcm_intent_arrays_t arrays;
    coavoid_lcm_intent_info_t info;
    coa_vehicle_t vehicle;
    coa_intent_plan_t plan;
    const char *why = NULL;
    FUZZ_DECODE(coavoid_intent_t, m, buf, size,
                coavoid_lcm_intent_to_core(&m, ctx, seq, &info, &vehicle, &plan, &arrays, &why));
}

/* A plan's rows are collected across inputs, as a receiver collects them across
 * datagrams, so that fuzzed rows also complete (or disagree with) a plan. */
static void receive_plan(const unsigned char *buf, size_t size, coavoid_lcm_context_t *ctx)
{
    static int32_t offsets[COAVOID_PLAN_T_MAX_VEHICLES * COAVOID_PLAN_T_MAX_SAMPLES];
    static coavoid_lcm_plan_slot_t slots[2];
    static coavoid_lcm_plan_rows_t rows;
    coavoid_lcm_plan_info_t info;
    coa_plan_result_t result;
    const coavoid_plan_t *whole = NULL;
    const char *why = NULL;
    if (rows.slots == NULL) {
        coavoid_lcm_plan_rows_init(&rows, slots, 2);
    }
    FUZZ_DECODE(coavoid_plan_t, m, buf, size,
                coavoid_lcm_plan_collect(&rows, &m, ctx, &whole, &info, &result, offsets,
                                         sizeof offsets / sizeof offsets[0], &why));
}

static void receive_track(const unsigned char *buf, size_t size, coavoid_lcm_context_t *ctx,
                          coavoid_lcm_sequence_table_t *seq)
{
    coa_track_point_t path[COAVOID_TRACK_T_MAX_PATH];
    coavoid_lcm_track_info_t info;
    coa_track_t track;
    const char *why = NULL;
    FUZZ_DECODE(coavoid_track_t, m, buf, size,
                coavoid_lcm_track_to_core(&m, ctx, seq, &info, &track, path,
                                          COAVOID_TRACK_T_MAX_PATH, &why));
}

/* Accepted tiles are kept across inputs by index, as a receiver keeps them, and every
 * tile count's worth of them is assembled (whatever versions they are of: the assembly
 * judges that). */
static void receive_map(const unsigned char *buf, size_t size, coavoid_lcm_context_t *ctx,
                        coavoid_lcm_sequence_table_t *seq)
{
    static coavoid_obstacle_map_t tiles[COAVOID_OBSTACLE_MAP_T_MAX_TILES];
    static coa_obstacle_t obstacles[COAVOID_LCM_MAP_MAX_OBSTACLES];
    static coa_vec3_t
        vertices[COAVOID_OBSTACLE_MAP_T_MAX_MAP_POLYTOPES * COAVOID_OBSTACLE_MAP_T_MAX_VERTICES];
    size_t count = 0;
    const char *why = NULL;
    FUZZ_DECODE(
        coavoid_obstacle_map_t, m, buf, size,
        if (coavoid_lcm_obstacle_map_accept(&m, ctx, seq, &why) == COA_OK) {
            tiles[m.tile_index] = m;
            (void)coavoid_lcm_obstacle_map_to_core(tiles, (size_t)m.tile_count, ctx, obstacles,
                                                   COAVOID_LCM_MAP_MAX_OBSTACLES, &count, vertices,
                                                   sizeof vertices / sizeof vertices[0], &why);
        });
}

/* The signature check of any datagram, against a trust list of one known key. */
static void check_signature(const unsigned char *buf, size_t n)
{
    static coavoid_auth_trust_t trust;
    static int ready;
    if (!ready) {
        coavoid_auth_key_t key = {7, COAVOID_AUTH_VEHICLE, 3, {0}};
        unsigned char secret[COAVOID_AUTH_SECRET_BYTES];
        coavoid_auth_trust_init(&trust);
        if (coavoid_auth_keypair(key.public_key, secret) != COA_OK ||
            coavoid_auth_trust_add(&trust, &key) != COA_OK) {
            __builtin_trap();
        }
        ready = 1;
    }
    size_t key = 0;
    if (coavoid_auth_verify(&trust, buf, n, &key) == COA_OK) {
        (void)coavoid_auth_fresh(&trust, key, COAVOID_AUTH_STREAM_STATUS, T0, 0, T0, 1000000,
                                 1000000);
    }
}

/* The text parsers of the key files a user hands over. */
static void parse_key_files(const char *text, size_t n)
{
    static coavoid_auth_trust_t trust;
    coavoid_auth_signer_t signer;
    char err[128];
    (void)coavoid_auth_trust_parse(&trust, text, n, err, sizeof err);
    (void)coavoid_auth_signer_parse(&signer, text, n, err, sizeof err);
}

/* A vehicle's record (coavoid replay's input, src/replay): each record it holds parsed,
 * and a configuration read. */
static void parse_record(const uint8_t *data, size_t n)
{
    static coavoid_replay_t replay;
    coavoid_replay_record_t rec;
    size_t used = 0;
    size_t at = n >= COAVOID_REPLAY_MAGIC_BYTES ? COAVOID_REPLAY_MAGIC_BYTES : n;
    while (coavoid_replay_parse(data + at, n - at, &rec, &used) == COA_OK) {
        if (used < COAVOID_REPLAY_HEADER_BYTES || used > n - at ||
            rec.channel_length > COAVOID_REPLAY_MAX_CHANNEL) {
            __builtin_trap();
        }
        if (rec.kind == COAVOID_REPLAY_CONFIG) {
            (void)coavoid_replay_config(&replay, rec.payload, rec.payload_length);
        }
        at += used;
    }
}

/* The same bytes as they would come off a vehicle's serial link (link.h): every frame the
 * receiver hands on fits its buffer and its CRC. */
static void read_link(const uint8_t *data, size_t n)
{
    static uint8_t buffer[64];
    coavoid_link_rx_t r;
    coavoid_link_rx_init(&r, buffer, sizeof buffer);
    for (size_t i = 0; i < n; i++) {
        const size_t got = coavoid_link_rx_byte(&r, data[i]);
        if (got > sizeof buffer - COAVOID_LINK_CRC_BYTES ||
            (got > 0u &&
             coavoid_link_crc32(0u, buffer, got) !=
                 ((uint32_t)buffer[got] | (uint32_t)buffer[got + 1u] << 8 |
                  (uint32_t)buffer[got + 2u] << 16 | (uint32_t)buffer[got + 3u] << 24))) {
            __builtin_trap();
        }
    }
}

static void drop_put(void *user, uint8_t byte)
{
    (void)user, (void)byte;
}

/* The same bytes as the frames a vehicle on the part takes (session.h): each record after
 * the magic is a frame, then the whole input; a fresh session each input. Every frame
 * gets an answer, whatever it holds. */
static void take_frames(const uint8_t *data, size_t n)
{
    static coavoid_session_t session;
    static uint8_t block[4u << 20] __attribute__((aligned(8)));
    coavoid_replay_record_t rec;
    size_t used = 0;
    size_t at = n >= COAVOID_REPLAY_MAGIC_BYTES ? COAVOID_REPLAY_MAGIC_BYTES : n;
    coavoid_vehicle_node_fini(session.replay.node);
    coavoid_session_init(&session, block, sizeof block, drop_put, NULL);
    while (coavoid_replay_parse(data + at, n - at, &rec, &used) == COA_OK) {
        (void)coavoid_session_take(&session, data + at, used);
        at += used;
    }
    (void)coavoid_session_take(&session, data, n);
    if (session.frames == 0u) {
        __builtin_trap();
    }
}

/* LCM's framing as the drivers' receiver reads it: a frame inside the datagram, or none. */
static void check_frame(const unsigned char *datagram, size_t size)
{
    coavoid_rt_rx_frame_t f;
    if (coavoid_rt_rx_parse(datagram, size, &f) != COA_OK) {
        return;
    }
    const unsigned char *name = (const unsigned char *)f.channel;
    const size_t length = strlen(f.channel);
    if (name != datagram + 8 || length < 1u || length > 63u || f.payload != name + length + 1u ||
        f.payload + f.payload_size != datagram + size) {
        __builtin_trap();
    }
}

static int64_t vehicle_clock = T0;

static int drop_send(void *user, const char *channel, const uint8_t *data, size_t size)
{
    (void)user, (void)channel, (void)data, (void)size;
    return COA_OK;
}

/* UAV 10 of the example plan, following its coordinator, in the cycle that starts at T0
 * (epoch T0 - 5 s, dt 1 s, N 40): built once, in memory of its own, kept for the run. */
static coavoid_vehicle_node_t *vehicle(void)
{
    static coavoid_vehicle_node_t *node;
    static coa_vec3_t route[2] = {{0, 0, 100}, {1000, 0, 100}};
    if (node != NULL) {
        return node;
    }
    coavoid_vehicle_node_config_t c;
    memset(&c, 0, sizeof c);
    if (coavoid_node_common_defaults(&c.common, T0 - INT64_C(5000000), (coa_real_t)1, 40u,
                                     &vehicle_clock) != COA_OK) {
        abort();
    }
    c.common.insecure = true;
    c.vehicle.id = 10;
    c.vehicle.priority = 1;
    c.vehicle.cruise_speed = (coa_real_t)10;
    c.vehicle.climb_rate = (coa_real_t)2;
    c.vehicle.steep_factor = 2;
    c.vehicle.volume.radius = (coa_real_t)15;
    c.vehicle.volume.half_height = (coa_real_t)5;
    c.vehicle.route = route;
    c.vehicle.route_count = 2;
    c.vehicle.max_offset = -1;
    c.mode = COAVOID_NODE_CENTRALISED;
    const size_t size = coavoid_vehicle_node_size(&c);
    static void *memory; /* for the whole run: a leak check at exit does not see it lost */
    memory = size > 0u ? malloc(size) : NULL;
    const coavoid_node_link_t link = {drop_send, NULL};
    node = memory != NULL ? coavoid_vehicle_node_init(memory, size, &c, &link, NULL) : NULL;
    if (node == NULL || coavoid_vehicle_node_cycle(node, T0) != COA_OK) {
        abort();
    }
    return node;
}

/* The datagram to the vehicle on its type's channel, then a poll. */
static void to_vehicle(unsigned kind, const unsigned char *buf, size_t n)
{
    static const char *const channels[] = {COAVOID_CHANNEL_INTENT,    COAVOID_CHANNEL_PLAN,
                                           COAVOID_CHANNEL_TRACK,     COAVOID_CHANNEL_OBSTACLES,
                                           COAVOID_CHANNEL_CONFLICTS, COAVOID_CHANNEL_STATUS,
                                           COAVOID_CHANNEL_AGREEMENT};
    coavoid_vehicle_node_t *node = vehicle();
    vehicle_clock = T0 + 1000;
    (void)coavoid_vehicle_node_receive(node, channels[kind], buf, n);
    (void)coavoid_vehicle_node_poll(node, vehicle_clock);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    static unsigned char buf[FUZZ_BUF];
    static coavoid_lcm_sender_t senders[8];
    if (size < 1u || size > FUZZ_BUF) {
        return 0;
    }
    check_frame(data + 1, size - 1u);
    const unsigned kind = (data[0] & 0x7fu) % 8u;
    if (kind == 7u) {
        parse_key_files((const char *)data + 1, size - 1u);
        parse_record(data + 1, size - 1u);
        read_link(data + 1, size - 1u);
        take_frames(data + 1, size - 1u);
        return 0;
    }
    const int raw = (data[0] & 0x80u) != 0;
    size_t n = size - 1u;
    if (raw) {
        memcpy(buf, data + 1, n);
    } else {
        size_t base = example(kind, buf);
        for (size_t k = 0; k < n && 8u + k < base; k++) {
            buf[8u + k] ^= data[1 + k];
        }
        n = base;
    }
    check_signature(buf, n);
    to_vehicle(kind, buf, n);
    coavoid_lcm_context_t ctx = ctx_now();
    coavoid_lcm_sequence_table_t seq;
    coavoid_lcm_sequence_init(&seq, senders, sizeof senders / sizeof senders[0]);
    const char *why = NULL;
    switch (kind) {
    case 0:
        receive_intent(buf, n, &ctx, &seq);
        break;
    case 1:
        receive_plan(buf, n, &ctx);
        break;
    case 2:
        receive_track(buf, n, &ctx, &seq);
        break;
    case 3:
        receive_map(buf, n, &ctx, &seq);
        break;
    case 4:
        FUZZ_DECODE(coavoid_conflict_report_t, m, buf, n,
                    coavoid_lcm_conflict_report_check(&m, &ctx, &why));
        break;
    case 5:
        FUZZ_DECODE(coavoid_status_t, m, buf, n, coavoid_lcm_status_check(&m, &ctx, &why));
        break;
    default:
        FUZZ_DECODE(coavoid_agreement_t, m, buf, n, coavoid_lcm_agreement_check(&m, &ctx, &why));
        break;
    }
    return 0;
}
