/* SPDX-License-Identifier: MIT */
/*
 * bench_auth.h: the harness of `coavoid bench auth`: what signed messages (src/lcm/auth.h)
 * cost, in time and in memory, per message and per cycle of the protocol
 * (docs/benchmarks.md, "Signed messages").
 *
 * Per message type (intent, plan, track, obstacle map, conflict report, status): a datagram
 * of the type's encoded size (a zeroed struct, encoded: every array is fixed-size, so
 * that is the size of every message of the type, and it follows the types when they
 * change) is stamped and signed (coavoid_auth_stamp, as a publisher does) and then checked
 * as a receiver checks it (coavoid_auth_verify, coavoid_auth_may_send, coavoid_auth_fresh),
 * repeat times, each with fresh numbers so that every check must succeed. The receiver's
 * trust list is full (COAVOID_AUTH_MAX_KEYS keys) and the sender's key is its last: the
 * key lookup's worst case. Each call is timed alone (clock_gettime, monotonic); the
 * median, min and max are reported.
 *
 * Per cycle, for a fleet of N UAVs on one channel: the messages each node signs and checks
 * in one cycle of node.h's protocol, times the median costs above. Per cycle there are
 * N intents, each sent 1 + C times (C = COAVOID_NODE_DEFAULT_COPIES, 4), and N + 1
 * heartbeats (each UAV's, the coordinator's), the world's
 * COAVOID_BENCH_AUTH_MAPS_PER_CYCLE obstacle map tiles and one message per track (N / 50
 * tracks, bench_predict.h's traffic; none for the demo's 3 UAVs, as in
 * scenarios/paper.json), one conflict report and, in the worst case, one plan per UAV
 * (the coordinator plans every UAV in a cluster of its own). A node checks every datagram
 * on the channels it subscribes to, its own looped-back heartbeat included (the signature
 * is checked before anything is decoded; its own intent is known by its bytes first):
 * Each plan is agreed on (docs/protocol.md): its UAV's ACCEPT and SWITCHED (sent 1 + C
 * times) and the coordinator's COMMIT, each checked by every node that subscribes:
 *   - a vehicle (centralised) sends 1 + C intents, 1 heartbeat and 2 + C agreements, and
 *     checks the (N - 1)(1 + C) intents, N + 1 heartbeats, N plans, N (3 + C)
 *     agreements, the maps and the tracks;
 *   - the coordinator sends its heartbeat, the conflict report, N plans and N commits,
 *     and checks the N (1 + C) intents, N (2 + C) agreements, the maps and the tracks;
 *   - the world sends the maps and the tracks, each 1 + C times, and checks nothing (every
 *     node that listens checks all of them).
 * A conflict report is subscribed by none of the nodes (monitoring only).
 *
 * Memory: every node holds one signer (its key) and, unless it only publishes (the world),
 * one trust list with its freshness marks; every message carries COAVOID_AUTH_TAIL_BYTES.
 */
#ifndef COAVOID_EVALUATION_BENCH_AUTH_H
#define COAVOID_EVALUATION_BENCH_AUTH_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

#include "auth.h"
#include "run.h"

/* The message types, in the order of their freshness streams (COAVOID_AUTH_STREAM_*). */
#define COAVOID_BENCH_AUTH_TYPES COAVOID_AUTH_STREAMS
/* Fleets one run reports (--vehicles N,N,...). */
#define COAVOID_BENCH_AUTH_MAX_FLEETS 8u
#define COAVOID_BENCH_AUTH_MAX_VEHICLES 65535u /* UAV ids are 16-bit */
#define COAVOID_BENCH_AUTH_DEMO_VEHICLES 3u    /* scenarios/paper.json, the demo's fleet */
#define COAVOID_BENCH_AUTH_LARGE_VEHICLES 100u
/* Obstacle-map messages the world publishes per cycle in the worst case: a full map, every
 * tile of it (src/node/world.c republishes every tile every cycle). */
#define COAVOID_BENCH_AUTH_MAPS_PER_CYCLE ((uint32_t)COAVOID_OBSTACLE_MAP_T_MAX_TILES)
#define COAVOID_BENCH_AUTH_TRACKS_PER_VEHICLE 50u /* one track per 50 UAVs, as bench predict */
#define COAVOID_BENCH_AUTH_DT_US 1000000.0        /* the scenarios' cycle: dt = 1 s */

/* The nodes a fleet's cycle is reported for. */
enum { COAVOID_BENCH_AUTH_VEHICLE, COAVOID_BENCH_AUTH_COORDINATOR, COAVOID_BENCH_AUTH_WORLD };
#define COAVOID_BENCH_AUTH_NODES 3u

typedef struct {
    uint32_t vehicles[COAVOID_BENCH_AUTH_MAX_FLEETS]; /* each 1..MAX_VEHICLES */
    size_t fleet_count;                               /* 1..MAX_FLEETS */
    uint32_t repeat;                                  /* timed signatures per type, >= 1 */
} coavoid_bench_auth_config_t;

/* One message type's costs, microseconds over the repeats. */
typedef struct {
    const char *name; /* "intent", "plan", ..., as the report's keys spell it */
    size_t bytes;     /* its encoded size, auth_t included */
    double sign_median_us, sign_min_us, sign_max_us;
    double verify_median_us, verify_min_us, verify_max_us;
} coavoid_bench_auth_type_t;

/* One node's cycle in a fleet. */
typedef struct {
    const char *name;                            /* "vehicle", "coordinator", "world" */
    uint32_t sent[COAVOID_BENCH_AUTH_TYPES];     /* messages it signs, per type */
    uint32_t received[COAVOID_BENCH_AUTH_TYPES]; /* messages it checks, per type */
    uint32_t sent_total, received_total;
    uint32_t copies_total; /* of received: repeats, refused from their tail as copies */
    double sign_us, verify_us, us_per_cycle; /* from the median costs */
    double dt_percent;                       /* us_per_cycle of dt */
    double traffic_bytes;                    /* encoded bytes sent + checked */
    double auth_bytes;                       /* of which auth_t tails */
    size_t memory_bytes;                     /* signer + trust list, sizeof */
} coavoid_bench_auth_node_t;

typedef struct {
    uint32_t vehicles, tracks, maps, plans; /* per cycle; plans: the worst case, one per UAV */
    coavoid_bench_auth_node_t nodes[COAVOID_BENCH_AUTH_NODES];
} coavoid_bench_auth_fleet_t;

/* What refusing a datagram costs a receiver, timed on intents (the largest): "copy", a
 * copy of one it accepted (refused as a replay from its tail); "unknown_key", a key id it
 * does not trust (refused from its tail); "outsider", a known key's fresh tail with a
 * signature that does not verify and no fleet tag, as an outsider forges it (refused by
 * the fleet tag); "signature", the same datagram at a receiver without a fleet key
 * (refused by the signature check). Microseconds over the repeats. */
#define COAVOID_BENCH_AUTH_REFUSALS 4u
typedef struct {
    const char *name;
    double median_us, min_us, max_us;
} coavoid_bench_auth_refusal_t;

typedef struct {
    coavoid_bench_auth_type_t types[COAVOID_BENCH_AUTH_TYPES];
    coavoid_bench_auth_refusal_t refusals[COAVOID_BENCH_AUTH_REFUSALS];
    coavoid_bench_auth_fleet_t fleets[COAVOID_BENCH_AUTH_MAX_FLEETS];
    size_t fleet_count;
    size_t trust_bytes, signer_bytes; /* sizeof each */
    uint64_t verify_failures;         /* checks that did not pass: 0, or the run failed */
} coavoid_bench_auth_result_t;

/* Times the signatures and derives the cycles. Returns COAVOID_RUN_DONE with *out filled,
 * or an error (evaluation.h, "Errors") with e set: COAVOID_RUN_ERR_INPUT for a config out
 * of range, COAVOID_RUN_ERR_INTERNAL when libsodium does not start, memory is short, a
 * type does not encode, or a check failed (out->verify_failures says how many; a benchmark
 * of a check that fails would time the wrong path). Memory: a trust list (about 18 kB),
 * one type's struct and datagram at a time (about 35 kB today for a plan), two doubles per
 * repeat, all freed before it returns. Cost: three seeded key pairs, then 6 x repeat
 * signatures and checks (about 0.6 s for 1,001 repeats). */
int coavoid_bench_auth_run(const coavoid_bench_auth_config_t *config,
                           coavoid_bench_auth_result_t *out, coavoid_run_error_t *e);

/* Prints the config and the result on f, one "key: value" per line or, with json, a JSON
 * object (the keys of docs/benchmarks.md). Returns 0, or -1 when a write (or cJSON's
 * memory) failed. */
int coavoid_bench_auth_report(FILE *f, const coavoid_bench_auth_config_t *config,
                              const coavoid_bench_auth_result_t *result, bool json);

#endif /* COAVOID_EVALUATION_BENCH_AUTH_H */
