/* SPDX-License-Identifier: MIT */
/*
 * bench_auth.c: `coavoid bench auth` (bench_auth.h): the timed signatures and checks of
 * each message type, the cycles derived from them, and their report.
 */
/* clock_gettime */
#define _POSIX_C_SOURCE 200809L
#include "bench_auth.h"
#include "node.h"

#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include <cjson/cJSON.h>

#include <coavoid_lcmtypes/coavoid_agreement_t.h>
#include <coavoid_lcmtypes/coavoid_conflict_report_t.h>
#include <coavoid_lcmtypes/coavoid_intent_t.h>
#include <coavoid_lcmtypes/coavoid_obstacle_map_t.h>
#include <coavoid_lcmtypes/coavoid_plan_t.h>
#include <coavoid_lcmtypes/coavoid_status_t.h>
#include <coavoid_lcmtypes/coavoid_track_t.h>

#include "coavoid/coavoid.h"
#include "output.h"
#include "run.h"

/* Any epoch works; one in 2026 keeps the numbers those of a real clock. */
#define BENCH_AUTH_EPOCH_US 1780000000000000LL
/* The receiver's window, as a node's: messages up to a cycle old and a cycle ahead. */
#define BENCH_AUTH_WINDOW_US 1000000LL

/* ---- the datagrams: each type's zeroed struct, encoded ---- */

/* The encoded zeroed struct of `type` in a new buffer (*out, the caller frees it): its
 * size, or -1 (memory, or an encoder that disagrees with its own size). Every array of
 * the types is fixed-size, so this is the size of every message of the type. */
#define BENCH_AUTH_DEFINE_ENCODE(function, type)                         \
    static int function(unsigned char **out)                             \
    {                                                                    \
        type *msg = calloc(1, sizeof *msg);                              \
        int size = msg != NULL ? type##_encoded_size(msg) : -1;          \
        *out = size > 0 ? malloc((size_t)size) : NULL;                   \
        if (*out == NULL || type##_encode(*out, 0, size, msg) != size) { \
            free(*out);                                                  \
            *out = NULL;                                                 \
            size = -1;                                                   \
        }                                                                \
        free(msg);                                                       \
        return size;                                                     \
    }

BENCH_AUTH_DEFINE_ENCODE(encode_intent, coavoid_intent_t)
BENCH_AUTH_DEFINE_ENCODE(encode_plan, coavoid_plan_t)
BENCH_AUTH_DEFINE_ENCODE(encode_track, coavoid_track_t)
BENCH_AUTH_DEFINE_ENCODE(encode_map, coavoid_obstacle_map_t)
BENCH_AUTH_DEFINE_ENCODE(encode_conflicts, coavoid_conflict_report_t)
BENCH_AUTH_DEFINE_ENCODE(encode_status, coavoid_status_t)
BENCH_AUTH_DEFINE_ENCODE(encode_agreement, coavoid_agreement_t)

/* The three senders: who signs which type, as node.h's roles say. */
enum { SENDER_VEHICLE, SENDER_COORDINATOR, SENDER_WORLD, SENDERS };

static const struct {
    coavoid_auth_role_t role;
    uint32_t key_id;
    uint16_t node_id;
} senders[SENDERS] = {
    [SENDER_VEHICLE] = {COAVOID_AUTH_VEHICLE, COAVOID_AUTH_KEY_ID_VEHICLE_BASE + 1u, 1u},
    [SENDER_COORDINATOR] = {COAVOID_AUTH_COORDINATOR, COAVOID_AUTH_KEY_ID_COORDINATOR, 65000u},
    [SENDER_WORLD] = {COAVOID_AUTH_WORLD, COAVOID_AUTH_KEY_ID_WORLD, 65001u},
};

/* Indexed by freshness stream (COAVOID_AUTH_STREAM_*), the order of the report. */
static const struct {
    const char *name;
    int (*encode)(unsigned char **out);
    size_t sender;
} kinds[COAVOID_BENCH_AUTH_TYPES] = {
    [COAVOID_AUTH_STREAM_INTENT] = {"intent", encode_intent, SENDER_VEHICLE},
    [COAVOID_AUTH_STREAM_PLAN] = {"plan", encode_plan, SENDER_COORDINATOR},
    [COAVOID_AUTH_STREAM_TRACK] = {"track", encode_track, SENDER_WORLD},
    [COAVOID_AUTH_STREAM_MAP] = {"obstacle_map", encode_map, SENDER_WORLD},
    [COAVOID_AUTH_STREAM_CONFLICTS] = {"conflict_report", encode_conflicts, SENDER_COORDINATOR},
    [COAVOID_AUTH_STREAM_STATUS] = {"status", encode_status, SENDER_VEHICLE},
    [COAVOID_AUTH_STREAM_AGREEMENT] = {"agreement", encode_agreement, SENDER_VEHICLE},
};

/* ---- keys ---- */

typedef struct {
    coavoid_auth_signer_t signers[SENDERS];
    coavoid_auth_trust_t *trust;
    double *sign_us, *verify_us; /* one per repeat */
    uint32_t repeat;
    uint64_t failures;
} bench_t;

/* Fills b->trust to COAVOID_AUTH_MAX_KEYS keys, the three senders' last (a receiver
 * searches its list by key id: the last are its worst case), with a fleet key, and gives
 * each sender its seeded key pair and the fleet key. The other keys are never used to verify: their public keys stay zero.
 * COA_OK or COA_ERR_ARGUMENT. */
static int make_keys(bench_t *b)
{
    coavoid_auth_trust_init(b->trust);
    unsigned char fleet[COAVOID_AUTH_FLEET_KEY_BYTES];
    memset(fleet, 0x5a, sizeof fleet);
    (void)coavoid_auth_trust_set_fleet_key(b->trust, fleet);
    coavoid_auth_key_t key;
    memset(&key, 0, sizeof key);
    key.role = COAVOID_AUTH_VEHICLE;
    for (uint32_t i = 0; i < COAVOID_AUTH_MAX_KEYS - SENDERS; i++) {
        key.key_id = 10000u + i; /* clear of the fleet's ids */
        key.node_id = (uint16_t)(1000u + i);
        if (coavoid_auth_trust_add(b->trust, &key) != COA_OK) {
            return COA_ERR_ARGUMENT;
        }
    }
    for (size_t i = 0; i < SENDERS; i++) {
        unsigned char seed[COAVOID_AUTH_SEED_BYTES];
        memset(seed, (int)(i + 1u), sizeof seed);
        coavoid_auth_signer_t *s = &b->signers[i];
        memset(s, 0, sizeof *s);
        s->key_id = senders[i].key_id;
        coavoid_auth_signer_use_fleet(s, b->trust);
        memset(&key, 0, sizeof key);
        key.key_id = senders[i].key_id;
        key.role = senders[i].role;
        key.node_id = senders[i].node_id;
        if (coavoid_auth_keypair_seed(seed, key.public_key, s->secret_key) != COA_OK ||
            coavoid_auth_trust_add(b->trust, &key) != COA_OK) {
            return COA_ERR_ARGUMENT;
        }
    }
    return COA_OK;
}

/* ---- timing ---- */

static double elapsed_us(const struct timespec *a, const struct timespec *b)
{
    return (double)(b->tv_sec - a->tv_sec) * 1e6 + (double)(b->tv_nsec - a->tv_nsec) / 1e3;
}

/* A big-endian int64 of the auth_t, as LCM encodes it. */
static int64_t read_be64(const unsigned char *p)
{
    uint64_t v = 0;
    for (int i = 0; i < 8; i++) {
        v = (v << 8) | p[i];
    }
    return (int64_t)v;
}

/* What a receiving node does with a datagram of `type` before it uses it (common.c,
 * signature_ok and sender_ok): the checks of its tail, the signature, then
 * coavoid_auth_accept (the key's role, freshness) at its clock `now`. The numbers are
 * read from the auth_t's bytes, where a node decodes them: the decoding is the same with
 * or without signatures, so it is not part of their cost. */
static int receive(coavoid_auth_trust_t *trust, size_t type, const unsigned char *d, size_t size,
                   int64_t now)
{
    const size_t tail = size - COAVOID_AUTH_TAIL_BYTES;
    const coavoid_auth_expect_t expect = {type, senders[kinds[type].sender].role, now,
                                          BENCH_AUTH_WINDOW_US, BENCH_AUTH_WINDOW_US};
    size_t key = 0;
    int rc = coavoid_auth_precheck(trust, d, size, &expect, &key);
    if (rc == COA_OK) {
        rc = coavoid_auth_verify(trust, d, size, &key);
    }
    if (rc == COA_OK) {
        rc = coavoid_auth_accept(trust, key, type, senders[kinds[type].sender].role,
                                 (int32_t)senders[kinds[type].sender].node_id,
                                 read_be64(d + tail + 4u), read_be64(d + tail + 12u), now,
                                 BENCH_AUTH_WINDOW_US, BENCH_AUTH_WINDOW_US);
    }
    return rc;
}

static int compare_doubles(const void *a, const void *b)
{
    const double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* Sorts v[n] (n >= 1) and sets its median, min and max. */
static void summarise(double *v, size_t n, double *median, double *min, double *max)
{
    qsort(v, n, sizeof *v, compare_doubles);
    *median = n % 2u == 1u ? v[n / 2u] : (v[n / 2u - 1u] + v[n / 2u]) / 2.0;
    *min = v[0];
    *max = v[n - 1u];
}

/* Times `repeat` stamps and checks of one type on a datagram of its size. Each repeat is
 * signed one millisecond after the last, the types one after another (a sender signs
 * several types, and its clock only moves on), and checked at that time, so that every
 * check must pass (fresh numbers each time); one that does not is counted in b->failures.
 * COA_OK, or COA_ERR_WORKSPACE when the type does not encode. */
static int time_type(bench_t *b, size_t type, coavoid_bench_auth_type_t *out)
{
    unsigned char *d = NULL;
    const int size = kinds[type].encode(&d);
    if (size <= 0 || (size_t)size < COAVOID_AUTH_TAIL_BYTES) {
        free(d);
        return COA_ERR_WORKSPACE;
    }
    coavoid_auth_signer_t *s = &b->signers[kinds[type].sender];
    for (uint32_t r = 0; r < b->repeat; r++) {
        const int64_t now = BENCH_AUTH_EPOCH_US + ((int64_t)type * b->repeat + r) * 1000;
        struct timespec t0, t1, t2;
        clock_gettime(CLOCK_MONOTONIC, &t0);
        int rc = coavoid_auth_stamp(s, now, d, (size_t)size);
        clock_gettime(CLOCK_MONOTONIC, &t1);
        if (rc == COA_OK) {
            rc = receive(b->trust, type, d, (size_t)size, now);
        }
        clock_gettime(CLOCK_MONOTONIC, &t2);
        b->failures += rc != COA_OK;
        b->sign_us[r] = elapsed_us(&t0, &t1);
        b->verify_us[r] = elapsed_us(&t1, &t2);
    }
    free(d);
    out->name = kinds[type].name;
    out->bytes = (size_t)size;
    summarise(b->sign_us, b->repeat, &out->sign_median_us, &out->sign_min_us, &out->sign_max_us);
    summarise(b->verify_us, b->repeat, &out->verify_median_us, &out->verify_min_us,
              &out->verify_max_us);
    return COA_OK;
}

/* Times `repeat` receptions of the intent datagram d (accepted once before), each to be
 * refused with `expected`; another outcome is counted in b->failures. */
static void time_refusal(bench_t *b, const unsigned char *d, size_t size, int64_t now, int expected,
                         coavoid_bench_auth_refusal_t *out)
{
    for (uint32_t r = 0; r < b->repeat; r++) {
        struct timespec t0, t1;
        clock_gettime(CLOCK_MONOTONIC, &t0);
        const int rc = receive(b->trust, COAVOID_AUTH_STREAM_INTENT, d, size, now);
        clock_gettime(CLOCK_MONOTONIC, &t1);
        b->failures += rc != expected;
        b->verify_us[r] = elapsed_us(&t0, &t1);
    }
    summarise(b->verify_us, b->repeat, &out->median_us, &out->min_us, &out->max_us);
}

/* The refusals of coavoid_bench_auth_refusal_t, after the types were timed (the
 * intents' last numbers accepted). COA_OK, or COA_ERR_WORKSPACE when intents do not
 * encode. */
static int time_refusals(bench_t *b, coavoid_bench_auth_refusal_t *out)
{
    unsigned char *d = NULL;
    const int size = encode_intent(&d);
    if (size <= 0 || (size_t)size < COAVOID_AUTH_TAIL_BYTES) {
        free(d);
        return COA_ERR_WORKSPACE;
    }
    const size_t n = (size_t)size;
    const int64_t now = BENCH_AUTH_EPOCH_US + (int64_t)COAVOID_BENCH_AUTH_TYPES * b->repeat * 1000;
    coavoid_auth_signer_t *s = &b->signers[SENDER_VEHICLE];
    int rc = coavoid_auth_stamp(s, now, d, n);
    b->failures +=
        rc != COA_OK || receive(b->trust, COAVOID_AUTH_STREAM_INTENT, d, n, now) != COA_OK;
    out[0].name = "copy";
    time_refusal(b, d, n, now, COAVOID_AUTH_ERR_REPLAY, &out[0]);
    unsigned char *tail = d + n - COAVOID_AUTH_TAIL_BYTES;
    const unsigned char saved = tail[0];
    tail[0] = 0x7f; /* a key id nobody trusts */
    out[1].name = "unknown_key";
    time_refusal(b, d, n, now, COAVOID_AUTH_ERR_KEY, &out[1]);
    tail[0] = saved;
    rc = coavoid_auth_stamp(s, now + 1, d, n);
    b->failures += rc != COA_OK;
    d[n - COAVOID_AUTH_TAG_BYTES - 1u] ^= 0x01u; /* the signature broken, the tag stale */
    out[2].name = "outsider";
    time_refusal(b, d, n, now + 1, COAVOID_AUTH_ERR_TAG, &out[2]);
    b->trust->has_fleet_key = false;
    out[3].name = "signature";
    time_refusal(b, d, n, now + 1, COAVOID_AUTH_ERR_SIGNATURE, &out[3]);
    b->trust->has_fleet_key = true;
    free(d);
    return COA_OK;
}

/* ---- the cycles ---- */

/* The messages of each type a node signs (sent) and checks (received) per cycle in a
 * fleet f (bench_auth.h's file comment; node.h's protocol). */
static void count_messages(const coavoid_bench_auth_fleet_t *f, size_t node, uint32_t *sent,
                           uint32_t *received)
{
    memset(sent, 0, COAVOID_BENCH_AUTH_TYPES * sizeof *sent);
    memset(received, 0, COAVOID_BENCH_AUTH_TYPES * sizeof *received);
    const uint32_t sends = 1u + COAVOID_NODE_DEFAULT_COPIES;
    if (node == COAVOID_BENCH_AUTH_WORLD) {
        sent[COAVOID_AUTH_STREAM_MAP] = f->maps * sends;
        sent[COAVOID_AUTH_STREAM_TRACK] = f->tracks * sends;
        return;
    }
    /* Every node that listens hears every intent (each sent 1 + COPIES times), map and
     * track; a vehicle knows its own intent when it comes back before checking it
     * (common.c). Every plan (one UAV each, the worst case) is agreed on: its UAV's
     * ACCEPT and SWITCHED (sent 1 + COPIES times), the coordinator's COMMIT; every node
     * that subscribes checks them all, its own looped back included. */
    received[COAVOID_AUTH_STREAM_INTENT] =
        (node == COAVOID_BENCH_AUTH_VEHICLE ? f->vehicles - 1u : f->vehicles) * sends;
    received[COAVOID_AUTH_STREAM_MAP] = f->maps * sends;
    received[COAVOID_AUTH_STREAM_TRACK] = f->tracks * sends;
    received[COAVOID_AUTH_STREAM_AGREEMENT] = f->plans * (1u + sends);
    if (node == COAVOID_BENCH_AUTH_VEHICLE) {
        sent[COAVOID_AUTH_STREAM_INTENT] = sends;
        sent[COAVOID_AUTH_STREAM_STATUS] = 1u;
        sent[COAVOID_AUTH_STREAM_AGREEMENT] = 1u + sends;
        received[COAVOID_AUTH_STREAM_STATUS] = f->vehicles + 1u; /* the UAVs', the coordinator's */
        received[COAVOID_AUTH_STREAM_PLAN] = f->plans;
        received[COAVOID_AUTH_STREAM_AGREEMENT] += f->plans; /* the commits */
    } else {
        sent[COAVOID_AUTH_STREAM_STATUS] = 1u;
        sent[COAVOID_AUTH_STREAM_CONFLICTS] = 1u;
        sent[COAVOID_AUTH_STREAM_PLAN] = f->plans;
        sent[COAVOID_AUTH_STREAM_AGREEMENT] = f->plans; /* the commits */
    }
}

/* Of the datagrams a node receives per type, the repeats of a message it already has:
 * every send after the first of an intent, map tile, track, and SWITCHED (count_messages),
 * which its tail check refuses as copies before any signature. */
static void count_copies(const coavoid_bench_auth_fleet_t *f, size_t node, uint32_t *copies)
{
    memset(copies, 0, COAVOID_BENCH_AUTH_TYPES * sizeof *copies);
    if (node == COAVOID_BENCH_AUTH_WORLD) {
        return;
    }
    const uint32_t repeats = COAVOID_NODE_DEFAULT_COPIES;
    copies[COAVOID_AUTH_STREAM_INTENT] =
        (node == COAVOID_BENCH_AUTH_VEHICLE ? f->vehicles - 1u : f->vehicles) * repeats;
    copies[COAVOID_AUTH_STREAM_MAP] = f->maps * repeats;
    copies[COAVOID_AUTH_STREAM_TRACK] = f->tracks * repeats;
    copies[COAVOID_AUTH_STREAM_AGREEMENT] = f->plans * repeats;
}

/* A node's cycle: its counts times the types' median costs and sizes; a copy costs the
 * tail check's refusal. */
static void derive_node(const coavoid_bench_auth_result_t *r, const coavoid_bench_auth_fleet_t *f,
                        size_t node, coavoid_bench_auth_node_t *n)
{
    static const char *const names[COAVOID_BENCH_AUTH_NODES] = {"vehicle", "coordinator", "world"};
    uint32_t copies[COAVOID_BENCH_AUTH_TYPES];
    memset(n, 0, sizeof *n);
    n->name = names[node];
    count_messages(f, node, n->sent, n->received);
    count_copies(f, node, copies);
    for (size_t t = 0; t < COAVOID_BENCH_AUTH_TYPES; t++) {
        const coavoid_bench_auth_type_t *type = &r->types[t];
        n->sent_total += n->sent[t];
        n->received_total += n->received[t];
        n->copies_total += copies[t];
        n->sign_us += n->sent[t] * type->sign_median_us;
        n->verify_us += (n->received[t] - copies[t]) * type->verify_median_us +
                        copies[t] * r->refusals[0].median_us;
        n->traffic_bytes += (double)(n->sent[t] + n->received[t]) * (double)type->bytes;
    }
    n->us_per_cycle = n->sign_us + n->verify_us;
    n->dt_percent = 100.0 * n->us_per_cycle / COAVOID_BENCH_AUTH_DT_US;
    n->auth_bytes = (double)(n->sent_total + n->received_total) * COAVOID_AUTH_TAIL_BYTES;
    /* A node that checks nothing keeps no trust list (the world). */
    n->memory_bytes = r->signer_bytes + (n->received_total > 0u ? r->trust_bytes : 0u);
}

static void derive_fleet(const coavoid_bench_auth_result_t *r, uint32_t vehicles,
                         coavoid_bench_auth_fleet_t *f)
{
    f->vehicles = vehicles;
    f->tracks = vehicles / COAVOID_BENCH_AUTH_TRACKS_PER_VEHICLE;
    f->maps = COAVOID_BENCH_AUTH_MAPS_PER_CYCLE; /* the worst case: a full map */
    f->plans = vehicles;                         /* the worst case: one plan message per UAV */
    for (size_t node = 0; node < COAVOID_BENCH_AUTH_NODES; node++) {
        derive_node(r, f, node, &f->nodes[node]);
    }
}

/* ---- the run ---- */

static int check_config(const coavoid_bench_auth_config_t *c, coavoid_run_error_t *e)
{
    if (c->repeat < 1u) {
        return coavoid_run_fail(e, COAVOID_RUN_ERR_INPUT, "--repeat: must be at least 1");
    }
    if (c->fleet_count < 1u || c->fleet_count > COAVOID_BENCH_AUTH_MAX_FLEETS) {
        return coavoid_run_fail(e, COAVOID_RUN_ERR_INPUT, "--vehicles: 1 to %u fleets",
                                COAVOID_BENCH_AUTH_MAX_FLEETS);
    }
    for (size_t i = 0; i < c->fleet_count; i++) {
        if (c->vehicles[i] < 1u || c->vehicles[i] > COAVOID_BENCH_AUTH_MAX_VEHICLES) {
            return coavoid_run_fail(e, COAVOID_RUN_ERR_INPUT, "--vehicles: each from 1 to %u",
                                    COAVOID_BENCH_AUTH_MAX_VEHICLES);
        }
    }
    return COAVOID_RUN_DONE;
}

/* Times every type into out->types. COAVOID_RUN_DONE or COAVOID_RUN_ERR_INTERNAL. */
static int time_types(bench_t *b, coavoid_bench_auth_result_t *out, coavoid_run_error_t *e)
{
    if (make_keys(b) != COA_OK) {
        return coavoid_run_fail(e, COAVOID_RUN_ERR_INTERNAL, "bench auth: cannot make the keys");
    }
    for (size_t t = 0; t < COAVOID_BENCH_AUTH_TYPES; t++) {
        if (time_type(b, t, &out->types[t]) != COA_OK) {
            return coavoid_run_fail(e, COAVOID_RUN_ERR_INTERNAL,
                                    "bench auth: %s does not encode (or memory is short)",
                                    kinds[t].name);
        }
    }
    if (time_refusals(b, out->refusals) != COA_OK) {
        return coavoid_run_fail(e, COAVOID_RUN_ERR_INTERNAL,
                                "bench auth: intent does not encode (or memory is short)");
    }
    out->verify_failures = b->failures;
    if (b->failures > 0u) {
        return coavoid_run_fail(e, COAVOID_RUN_ERR_INTERNAL,
                                "bench auth: %llu of the checks failed",
                                (unsigned long long)b->failures);
    }
    return COAVOID_RUN_DONE;
}

int coavoid_bench_auth_run(const coavoid_bench_auth_config_t *config,
                           coavoid_bench_auth_result_t *out, coavoid_run_error_t *e)
{
    memset(out, 0, sizeof *out);
    int status = check_config(config, e);
    if (status != COAVOID_RUN_DONE) {
        return status;
    }
    if (coavoid_auth_init() != COA_OK) {
        return coavoid_run_fail(e, COAVOID_RUN_ERR_INTERNAL, "bench auth: libsodium did not start");
    }
    bench_t b;
    memset(&b, 0, sizeof b);
    b.repeat = config->repeat;
    b.trust = malloc(sizeof *b.trust);
    b.sign_us = calloc(config->repeat, sizeof *b.sign_us);
    b.verify_us = calloc(config->repeat, sizeof *b.verify_us);
    if (b.trust == NULL || b.sign_us == NULL || b.verify_us == NULL) {
        status = coavoid_run_fail(e, COAVOID_RUN_ERR_INTERNAL, "bench auth: out of memory");
    } else {
        status = time_types(&b, out, e);
    }
    for (size_t i = 0; i < SENDERS; i++) {
        coavoid_auth_signer_clear(&b.signers[i]);
    }
    free(b.trust);
    free(b.sign_us);
    free(b.verify_us);
    if (status != COAVOID_RUN_DONE) {
        return status;
    }
    out->trust_bytes = sizeof(coavoid_auth_trust_t);
    out->signer_bytes = sizeof(coavoid_auth_signer_t);
    out->fleet_count = config->fleet_count;
    for (size_t i = 0; i < config->fleet_count; i++) {
        derive_fleet(out, config->vehicles[i], &out->fleets[i]);
    }
    return COAVOID_RUN_DONE;
}

/* ---- the report ---- */

/* One "key: value" row, or one JSON member; keys get a prefix in the text form only. */
typedef struct {
    const char *key;
    double value;
    int decimals;
} row_t;

static void print_rows(FILE *f, const char *prefix, const row_t *rows, size_t n)
{
    for (size_t i = 0; i < n; i++) {
        fprintf(f, "%s%s: %.*f\n", prefix, rows[i].key, rows[i].decimals, rows[i].value);
    }
}

static cJSON *json_rows(cJSON *object, const row_t *rows, size_t n)
{
    for (size_t i = 0; object != NULL && i < n; i++) {
        if (cJSON_AddNumberToObject(object, rows[i].key, rows[i].value) == NULL) {
            cJSON_Delete(object);
            return NULL;
        }
    }
    return object;
}

#define BENCH_AUTH_TYPE_ROWS 7u
static void type_rows(const coavoid_bench_auth_type_t *t, row_t *rows)
{
    const row_t all[BENCH_AUTH_TYPE_ROWS] = {
        {"bytes", (double)t->bytes, 0},
        {"sign_median_us", t->sign_median_us, 2},
        {"sign_min_us", t->sign_min_us, 2},
        {"sign_max_us", t->sign_max_us, 2},
        {"verify_median_us", t->verify_median_us, 2},
        {"verify_min_us", t->verify_min_us, 2},
        {"verify_max_us", t->verify_max_us, 2},
    };
    memcpy(rows, all, sizeof all);
}

#define BENCH_AUTH_NODE_ROWS 10u
static void node_rows(const coavoid_bench_auth_node_t *n, row_t *rows)
{
    const row_t all[BENCH_AUTH_NODE_ROWS] = {
        {"sent", n->sent_total, 0},       {"received", n->received_total, 0},
        {"copies", n->copies_total, 0},   {"sign_us", n->sign_us, 1},
        {"verify_us", n->verify_us, 1},   {"us_per_cycle", n->us_per_cycle, 1},
        {"dt_percent", n->dt_percent, 3}, {"traffic_bytes", n->traffic_bytes, 0},
        {"auth_bytes", n->auth_bytes, 0}, {"memory_bytes", (double)n->memory_bytes, 0},
    };
    memcpy(rows, all, sizeof all);
}

#define BENCH_AUTH_HEAD_ROWS 6u
static void head_rows(const coavoid_bench_auth_config_t *c, const coavoid_bench_auth_result_t *r,
                      row_t *rows)
{
    const row_t all[BENCH_AUTH_HEAD_ROWS] = {
        {"repeat", c->repeat, 0},
        {"dt_us", COAVOID_BENCH_AUTH_DT_US, 0},
        {"auth_bytes_per_message", COAVOID_AUTH_TAIL_BYTES, 0},
        {"signer_bytes", (double)r->signer_bytes, 0},
        {"trust_list_bytes", (double)r->trust_bytes, 0},
        {"verify_failures", (double)r->verify_failures, 0},
    };
    memcpy(rows, all, sizeof all);
}

#define BENCH_AUTH_FLEET_ROWS 4u
static void fleet_rows(const coavoid_bench_auth_fleet_t *f, row_t *rows)
{
    const row_t all[BENCH_AUTH_FLEET_ROWS] = {
        {"vehicles", f->vehicles, 0},
        {"tracks", f->tracks, 0},
        {"maps", f->maps, 0},
        {"plans", f->plans, 0},
    };
    memcpy(rows, all, sizeof all);
}

#define BENCH_AUTH_REFUSAL_ROWS 3u
static void refusal_rows(const coavoid_bench_auth_refusal_t *x, row_t *rows)
{
    const row_t all[BENCH_AUTH_REFUSAL_ROWS] = {
        {"median_us", x->median_us, 3},
        {"min_us", x->min_us, 3},
        {"max_us", x->max_us, 3},
    };
    memcpy(rows, all, sizeof all);
}

static int report_text(FILE *f, const coavoid_bench_auth_config_t *c,
                       const coavoid_bench_auth_result_t *r)
{
    row_t rows[BENCH_AUTH_NODE_ROWS];
    char prefix[64];
    fprintf(f, "benchmark: auth\n");
    head_rows(c, r, rows);
    print_rows(f, "", rows, BENCH_AUTH_HEAD_ROWS);
    for (size_t t = 0; t < COAVOID_BENCH_AUTH_TYPES; t++) {
        type_rows(&r->types[t], rows);
        snprintf(prefix, sizeof prefix, "%s_", r->types[t].name);
        print_rows(f, prefix, rows, BENCH_AUTH_TYPE_ROWS);
    }
    for (size_t x = 0; x < COAVOID_BENCH_AUTH_REFUSALS; x++) {
        refusal_rows(&r->refusals[x], rows);
        snprintf(prefix, sizeof prefix, "refused_%s_", r->refusals[x].name);
        print_rows(f, prefix, rows, BENCH_AUTH_REFUSAL_ROWS);
    }
    for (size_t i = 0; i < r->fleet_count; i++) {
        const coavoid_bench_auth_fleet_t *fl = &r->fleets[i];
        snprintf(prefix, sizeof prefix, "fleet_%u_", (unsigned)fl->vehicles);
        fleet_rows(fl, rows);
        print_rows(f, prefix, rows, BENCH_AUTH_FLEET_ROWS);
        for (size_t n = 0; n < COAVOID_BENCH_AUTH_NODES; n++) {
            snprintf(prefix, sizeof prefix, "fleet_%u_%s_", (unsigned)fl->vehicles,
                     fl->nodes[n].name);
            node_rows(&fl->nodes[n], rows);
            print_rows(f, prefix, rows, BENCH_AUTH_NODE_ROWS);
        }
    }
    return fflush(f) == 0 && !ferror(f) ? 0 : -1;
}

/* Appends {tag: name, then the rows} to `array`. False when memory is short (nothing
 * appended, the object freed). */
static bool json_append_named(cJSON *array, const char *tag, const char *name, const row_t *rows,
                              size_t n)
{
    cJSON *o = cJSON_CreateObject();
    if (o != NULL && cJSON_AddStringToObject(o, tag, name) == NULL) {
        cJSON_Delete(o);
        o = NULL;
    }
    o = json_rows(o, rows, n);
    if (o == NULL || !cJSON_AddItemToArray(array, o)) {
        cJSON_Delete(o);
        return false;
    }
    return true;
}

/* The "types" array of the JSON report, or NULL (memory). */
static cJSON *json_types(const coavoid_bench_auth_result_t *r)
{
    cJSON *types = cJSON_CreateArray();
    row_t rows[BENCH_AUTH_TYPE_ROWS];
    for (size_t t = 0; types != NULL && t < COAVOID_BENCH_AUTH_TYPES; t++) {
        type_rows(&r->types[t], rows);
        if (!json_append_named(types, "type", r->types[t].name, rows, BENCH_AUTH_TYPE_ROWS)) {
            cJSON_Delete(types);
            return NULL;
        }
    }
    return types;
}

/* The "refusals" array of the JSON report, or NULL (memory). */
static cJSON *json_refusals(const coavoid_bench_auth_result_t *r)
{
    cJSON *all = cJSON_CreateArray();
    row_t rows[BENCH_AUTH_REFUSAL_ROWS];
    for (size_t x = 0; all != NULL && x < COAVOID_BENCH_AUTH_REFUSALS; x++) {
        refusal_rows(&r->refusals[x], rows);
        if (!json_append_named(all, "refusal", r->refusals[x].name, rows,
                               BENCH_AUTH_REFUSAL_ROWS)) {
            cJSON_Delete(all);
            return NULL;
        }
    }
    return all;
}

/* One fleet's JSON object with its "nodes" array, or NULL (memory). */
static cJSON *json_fleet(const coavoid_bench_auth_fleet_t *fl)
{
    row_t rows[BENCH_AUTH_NODE_ROWS];
    fleet_rows(fl, rows);
    cJSON *o = json_rows(cJSON_CreateObject(), rows, BENCH_AUTH_FLEET_ROWS);
    cJSON *nodes = o != NULL ? cJSON_AddArrayToObject(o, "nodes") : NULL;
    for (size_t n = 0; nodes != NULL && n < COAVOID_BENCH_AUTH_NODES; n++) {
        node_rows(&fl->nodes[n], rows);
        if (!json_append_named(nodes, "node", fl->nodes[n].name, rows, BENCH_AUTH_NODE_ROWS)) {
            nodes = NULL;
        }
    }
    if (nodes == NULL) {
        cJSON_Delete(o);
        return NULL;
    }
    return o;
}

static int report_json(FILE *f, const coavoid_bench_auth_config_t *c,
                       const coavoid_bench_auth_result_t *r)
{
    row_t rows[BENCH_AUTH_HEAD_ROWS];
    head_rows(c, r, rows);
    cJSON *root = cJSON_CreateObject();
    if (root != NULL && cJSON_AddStringToObject(root, "benchmark", "auth") == NULL) {
        cJSON_Delete(root);
        root = NULL;
    }
    root = json_rows(root, rows, BENCH_AUTH_HEAD_ROWS);
    cJSON *types = root != NULL ? json_types(r) : NULL;
    cJSON *refusals = types != NULL ? json_refusals(r) : NULL;
    cJSON *fleets = refusals != NULL ? cJSON_CreateArray() : NULL;
    bool ok = fleets != NULL && cJSON_AddItemToObject(root, "types", types);
    if (!ok) {
        cJSON_Delete(types);
    }
    if (!ok || !cJSON_AddItemToObject(root, "refusals", refusals)) {
        cJSON_Delete(refusals);
        ok = false;
    }
    for (size_t i = 0; ok && i < r->fleet_count; i++) {
        cJSON *fl = json_fleet(&r->fleets[i]);
        ok = fl != NULL && cJSON_AddItemToArray(fleets, fl);
        if (!ok) {
            cJSON_Delete(fl);
        }
    }
    if (!ok || !cJSON_AddItemToObject(root, "fleets", fleets)) {
        cJSON_Delete(fleets);
        cJSON_Delete(root);
        return -1;
    }
    return coavoid_output_json(f, root, NULL, 0);
}

int coavoid_bench_auth_report(FILE *f, const coavoid_bench_auth_config_t *config,
                              const coavoid_bench_auth_result_t *result, bool json)
{
    return json ? report_json(f, config, result) : report_text(f, config, result);
}
