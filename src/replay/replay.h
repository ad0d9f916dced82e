/* SPDX-License-Identifier: MIT */
/*
 * replay.h: a vehicle's record and its replay (coavoid::replay). A record is what one
 * vehicle of the protocol library was given and what it did, call by call, in a run of
 * `coavoid sim --record-vehicle`: its configuration (keys included), every datagram it
 * received with its clock at the time, every cycle and poll call with its time, every
 * datagram it sent during a call and its state after each cycle and poll. A replay builds
 * the same vehicle from the record, makes the same calls with the same datagrams at the
 * same times, and checks that it sends the same bytes and reaches the same states: on the
 * host (`coavoid replay`) and on the part (the firmware's replay ELF under qemu), so
 * that a vehicle on the Cortex-M4F is shown to fly as the simulation's does, and its
 * calls can be counted there.
 *
 * The record's format (all numbers little-endian): the 8 bytes "COAVREC1", then records,
 * each a 16-byte header (kind u8, 0 u8, channel length u16, payload length u32, time
 * i64: the vehicle's clock, us) followed by the channel's bytes (no NUL) and the payload.
 * The first record is COAVOID_REPLAY_CONFIG. A record holds the recorded vehicle's secret
 * key: a record made with a flight key is as secret as the key.
 *
 * No I/O, no heap: the caller reads the bytes and gives the memory. Not thread-safe.
 */
#ifndef COAVOID_REPLAY_H
#define COAVOID_REPLAY_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "protocol.h"

#define COAVOID_REPLAY_MAGIC "COAVREC1"
#define COAVOID_REPLAY_MAGIC_BYTES 8u
#define COAVOID_REPLAY_HEADER_BYTES 16u
#define COAVOID_REPLAY_MAX_CHANNEL 32u
/* The largest payload: a configuration of the largest route, obstacles and trust list a
 * replay holds, or one datagram. */
#define COAVOID_REPLAY_MAX_PAYLOAD 16384u
/* What a replay holds of a configuration: route points, configured obstacles and their
 * polytopes' vertices (a record of more is refused). A build may hold fewer (-D: the
 * Cortex-M4F build holds 16 points and 64 vertices). */
#ifndef COAVOID_REPLAY_MAX_ROUTE
#define COAVOID_REPLAY_MAX_ROUTE 64u
#endif
#ifndef COAVOID_REPLAY_MAX_VERTICES
#define COAVOID_REPLAY_MAX_VERTICES 256u
#endif
/* Datagrams a vehicle sends in one call, at most, for the comparison. */
#define COAVOID_REPLAY_MAX_SENT 64u

typedef enum {
    COAVOID_REPLAY_CONFIG = 1,  /* payload: the vehicle's configuration */
    COAVOID_REPLAY_RECEIVE = 2, /* channel, payload: a datagram handed to the vehicle */
    COAVOID_REPLAY_CYCLE = 3,   /* coavoid_vehicle_node_cycle at `time` */
    COAVOID_REPLAY_POLL = 4,    /* coavoid_vehicle_node_poll at `time` */
    COAVOID_REPLAY_SENT = 5,    /* channel, payload: a datagram the vehicle sent */
    COAVOID_REPLAY_STATE = 6,   /* payload: its state after the call before */
    /* Only on a live link (session.h), never in a record: */
    COAVOID_REPLAY_TIME = 7,      /* the ground's clock at `time`, no datagram */
    COAVOID_REPLAY_SUBSCRIBE = 8, /* channel: one the vehicle takes in */
    COAVOID_REPLAY_READY = 9      /* the vehicle took the frame before; payload: its state */
} coavoid_replay_kind_t;

/* Errors beyond the core's: the bytes are no record (truncated, a bad header or field),
 * or the replayed vehicle did something else than the recorded one. */
#define COAVOID_REPLAY_ERR_FORMAT (-140)
#define COAVOID_REPLAY_ERR_DIFFERS (-141)

/* One record, pointing into the caller's bytes. */
typedef struct {
    coavoid_replay_kind_t kind;
    int64_t time;
    const char *channel; /* not NUL-terminated */
    size_t channel_length;
    const uint8_t *payload;
    size_t payload_length;
} coavoid_replay_record_t;

/* The header's payload and channel lengths, so that a reader knows how much follows:
 * COA_OK or COAVOID_REPLAY_ERR_FORMAT (unknown kind, a length past the limits). O(1). */
int coavoid_replay_header(const uint8_t header[COAVOID_REPLAY_HEADER_BYTES], size_t *rest);

/* The record at data[0..size): its header and all that follows it. *used is its length.
 * COA_OK or COAVOID_REPLAY_ERR_FORMAT (truncated or bad). O(1); no copy. */
int coavoid_replay_parse(const uint8_t *data, size_t size, coavoid_replay_record_t *record,
                         size_t *used);

/* How a reader gets a record's bytes: up to n into out, returning how many it read (fewer
 * only at the end of the record or on an error). */
typedef size_t (*coavoid_replay_read_t)(void *user, void *out, size_t n);

/* The record's channel as a C string, into out. O(channel). */
void coavoid_replay_channel(const coavoid_replay_record_t *record,
                            char out[COAVOID_REPLAY_MAX_CHANNEL + 1u]);

/* The next record through read into buf (capacity bytes, which the record points into):
 * 1, 0 at the end (nothing more to read), or COAVOID_REPLAY_ERR_FORMAT (cut, bad, or
 * longer than capacity). O(the record's length). */
int coavoid_replay_next(coavoid_replay_read_t read, void *user, uint8_t *buf, size_t capacity,
                        coavoid_replay_record_t *record);

/* Writing a record: its header (channel_length and payload_length within the limits), the
 * configuration's payload (0 when it exceeds the limits or capacity) and a state's. */
void coavoid_replay_write_header(uint8_t out[COAVOID_REPLAY_HEADER_BYTES],
                                 coavoid_replay_kind_t kind, int64_t time, size_t channel_length,
                                 size_t payload_length);
size_t coavoid_replay_write_config(const coavoid_vehicle_node_config_t *config, uint8_t *out,
                                   size_t capacity);
#define COAVOID_REPLAY_STATE_BYTES 96u
void coavoid_replay_write_state(int rc, const coavoid_vehicle_node_state_t *state,
                                uint8_t out[COAVOID_REPLAY_STATE_BYTES]);
/* A state's payload read back: the call's return value and the fields it holds (phase,
 * plan, published, waiting, cycle, offset, rank, the counters, rx.received and
 * rx.rejected; the rest zero). COA_OK, or COAVOID_REPLAY_ERR_FORMAT for another length. O(1). */
int coavoid_replay_read_state(const uint8_t *payload, size_t size, int *rc,
                              coavoid_vehicle_node_state_t *state);

/* A replay in progress: the configuration read from the record (its route, obstacles and
 * keys in here), the vehicle's clock, and what the vehicle sent in the current call. */
typedef struct {
    coavoid_vehicle_node_config_t config;
    coa_vec3_t route[COAVOID_REPLAY_MAX_ROUTE];
    coa_obstacle_t obstacles[COAVOID_NODE_MAX_CONFIGURED_OBSTACLES];
    coa_vec3_t vertices[COAVOID_REPLAY_MAX_VERTICES];
    coavoid_auth_signer_t signer;
    coavoid_auth_trust_t trust;
    int64_t now;
    coavoid_vehicle_node_t *node;
    int last_rc;                                 /* what the last call returned */
    uint64_t sent_hash[COAVOID_REPLAY_MAX_SENT]; /* FNV-1a of channel and bytes */
    size_t sent_count;                           /* sent in the current call */
    size_t sent_checked;                         /* of those, matched by SENT records */
    bool sent_overflow;
    /* Since the start: records applied, calls made, datagrams sent; the first difference
     * (its record's index and what differed), if any. */
    uint64_t records;
    uint64_t cycles;
    uint64_t polls;
    uint64_t receives;
    uint64_t sent;
    uint64_t first_difference; /* record index, valid when differs */
    bool differs;
    const char *difference;
} coavoid_replay_t;

/* Reads a CONFIG record's payload into r->config (pointing into r), r->now its clock.
 * COA_OK, COAVOID_REPLAY_ERR_FORMAT (truncated or bad), COAVOID_LCM_ERR_CAPACITY (more
 * route points, obstacles or vertices than a replay holds). O(payload). */
int coavoid_replay_config(coavoid_replay_t *r, const uint8_t *payload, size_t size);

/* The start of a record through read: the magic and the configuration, read into r
 * (coavoid_replay_config), r->now the configuration's time. COA_OK,
 * COAVOID_REPLAY_ERR_FORMAT (not a record), or the configuration's error. */
int coavoid_replay_open(coavoid_replay_t *r, coavoid_replay_read_t read, void *user, uint8_t *buf,
                        size_t capacity);

/* Builds the vehicle in memory (coavoid_vehicle_node_size(&r->config) bytes, aligned as
 * coavoid_vehicle_node_init wants), sending into the replay. Returns init's error. */
int coavoid_replay_start(coavoid_replay_t *r, void *memory, size_t size);

/* Applies one record after the CONFIG: a RECEIVE, CYCLE or POLL is made as recorded; a
 * SENT or STATE is compared with what the vehicle did in the call before. Returns COA_OK,
 * COAVOID_REPLAY_ERR_DIFFERS (r->difference says what; the first one is kept) or
 * COAVOID_REPLAY_ERR_FORMAT (a record out of place). Cost: the call's, or O(payload). */
int coavoid_replay_apply(coavoid_replay_t *r, const coavoid_replay_record_t *record);

/* At the end of the record: COA_OK, or COAVOID_REPLAY_ERR_DIFFERS when the vehicle sent
 * more in its last call than was recorded. */
int coavoid_replay_finish(coavoid_replay_t *r);

#endif /* COAVOID_REPLAY_H */
