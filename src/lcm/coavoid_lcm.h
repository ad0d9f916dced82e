/* SPDX-License-Identifier: MIT */
/*
 * coavoid_lcm.h: validation of LCM messages and conversion between them and core types.
 *
 * Everything that arrives over the network is untrusted. Each *_check function applies
 * every rule of its message (finite numbers within sane bounds, counts within the
 * message's capacity, known enum values, valid ids, sane times); each *_to_core function
 * runs the check, then the sender's sequence rule, and only then converts, so the core
 * never sees a number that was not validated. A refusal returns a named negative
 * COAVOID_LCM_ERR_* code and sets *reason to a static string naming the message and the
 * field; the caller counts it and reports it in its status message: it is never fatal.
 *
 * *_from_core functions build a message from core types and run the same check on the
 * result, so a node cannot publish what its peers would refuse.
 *
 * Times. Messages carry int64 microseconds (utime); the core works in seconds of
 * coa_real_t on a clock whose origin the caller chooses (context epoch_utime):
 * t = (utime - epoch_utime) * 1e-6.
 *
 * Memory: nothing is allocated. Arrays the core types point into are the caller's.
 */
#ifndef COAVOID_LCM_H
#define COAVOID_LCM_H

#include "coavoid/common.h"
#include "coavoid/geometry.h"
#include "coavoid/plan.h"
#include "coavoid/predict.h"
#include "coavoid/trajectory.h"
#include "auth.h"

#include <coavoid_lcmtypes/coavoid_agreement_t.h>
#include <coavoid_lcmtypes/coavoid_conflict_report_t.h>
#include <coavoid_lcmtypes/coavoid_intent_t.h>
#include <coavoid_lcmtypes/coavoid_obstacle_map_t.h>
#include <coavoid_lcmtypes/coavoid_plan_t.h>
#include <coavoid_lcmtypes/coavoid_status_t.h>
#include <coavoid_lcmtypes/coavoid_track_t.h>

#ifdef __cplusplus
extern "C" {
#endif

/* Refusals. Distinct from the core's -1..-3 so that a status message's last_reject_code
 * says which rule refused. COA_ERR_ARGUMENT is still returned for NULL arguments. */
#define COAVOID_LCM_ERR_DECODE \
    (-100) /* bytes do not decode: wrong type (fingerprint) or truncated */
#define COAVOID_LCM_ERR_NONFINITE (-101) /* NaN or infinity */
#define COAVOID_LCM_ERR_VALUE \
    (-102) /* a finite number outside its range (negative size, 1e300 m, ...) */
#define COAVOID_LCM_ERR_COUNT (-103)    /* a count beyond the message's capacity or inconsistent */
#define COAVOID_LCM_ERR_ENUM (-104)     /* an unknown mode, status, kind, ... */
#define COAVOID_LCM_ERR_ID (-105)       /* an id out of range or repeated */
#define COAVOID_LCM_ERR_TIME (-106)     /* a time stamp in the future, stale, or out of order */
#define COAVOID_LCM_ERR_SEQUENCE (-107) /* a sequence number (or version) that went backwards */
#define COAVOID_LCM_ERR_SENDERS (-108)  /* the caller's sequence table is full */
#define COAVOID_LCM_ERR_CAPACITY (-109) /* the caller's output array is too small */

/* Bounds on numbers, beyond finiteness. They keep every converted value finite in float
 * too (COA_SINGLE_PRECISION) and refuse values no aircraft has. */
#define COAVOID_LCM_MAX_COORDINATE 1.0e7 /* m, |x|, |y|, |z| of any position */
#define COAVOID_LCM_MAX_SPEED 1.0e4      /* m/s, each velocity component */
#define COAVOID_LCM_MAX_SIZE 1.0e5       /* m: radius, half-height, sigma */
#define COAVOID_LCM_MAX_STEP 3600.0      /* s: plan step or dt */
#define COAVOID_LCM_MAX_ID 65535         /* UAV and node ids are 1..65535 (coa_vehicle_t.id) */

/* The most bytes one message may take encoded (fingerprint and signature included). LCM's
 * UDP multicast sends a message as one datagram of LCM's header (8 bytes), the channel name
 * (at most 18 bytes with its NUL for ours) and the message; with the IP and UDP headers
 * (28 bytes) that is at most 1,454 bytes, within a 1,500-byte MTU: no message is
 * fragmented by the kernel, so a path that drops datagrams over 1,500 bytes (or loses IP
 * fragments) loses none (docs/messages.md, "One datagram"). Every type's fixed size is
 * at most this, and the nodes refuse to publish more. */
#define COAVOID_LCM_MAX_DATAGRAM_BYTES 1400

/* How the receiver judges times. All microseconds. */
typedef struct {
    int64_t now_utime;     /* receiver's clock; 0 disables the age and future checks */
    int64_t max_age_us;    /* utime < now - max_age: stale (also bounds plan/estimate
                             times around utime) */
    int64_t max_future_us; /* utime > now + max_future: a clock ahead or a bad stamp */
    int64_t epoch_utime;   /* origin of the core's clock */
} coavoid_lcm_context_t;

/* Per-sender last sequence numbers, in the caller's array (one table per message type). */
typedef struct {
    uint32_t sender;
    int64_t last;
} coavoid_lcm_sender_t;

typedef struct {
    coavoid_lcm_sender_t *entries;
    size_t capacity;
    size_t count;
} coavoid_lcm_sequence_table_t;

/* Empties the table over entries[0..capacity-1]. Cannot fail on non-NULL table. */
void coavoid_lcm_sequence_init(coavoid_lcm_sequence_table_t *table, coavoid_lcm_sender_t *entries,
                               size_t capacity);

/* Accepts `sequence` from `sender` when it is greater than the last one accepted (or
 * equal, with allow_equal: a republished version), recording it. Returns COA_OK,
 * COAVOID_LCM_ERR_SEQUENCE (backwards: nothing recorded), COAVOID_LCM_ERR_SENDERS (new sender,
 * table full) or COA_ERR_ARGUMENT. A sender that restarts its numbering is refused until
 * coavoid_lcm_sequence_forget (e.g. after its heartbeat went silent). Cost O(count). */
int coavoid_lcm_sequence_accept(coavoid_lcm_sequence_table_t *table, uint32_t sender,
                                int64_t sequence, bool allow_equal);

/* Forgets a sender. Cost O(count). */
void coavoid_lcm_sequence_forget(coavoid_lcm_sequence_table_t *table, uint32_t sender);

/* A short English name of any COAVOID_LCM_ERR_* or core status. Never NULL. */
const char *coavoid_lcm_error_name(int status);

/* ---- intent ---- */

/* What an intent carries beyond the core's vehicle and plan. */
typedef struct {
    int64_t utime;
    int64_t sequence;
    int8_t mode; /* COAVOID_INTENT_T_MODE_* */
    coa_vec3_t position;
    coa_vec3_t velocity;
    int64_t plan_utime; /* time of sample 0 (us) */
    coa_real_t step;    /* s */
    coa_real_t sigma_horizontal;
    coa_real_t sigma_vertical;
    /* The sender's precedence in the decoupled order, 0..COAVOID_INTENT_T_MAX_RANK
     * (docs/protocol.md, "Priority negotiation"); 0 unless it raised it. */
    int8_t rank;
} coavoid_lcm_intent_info_t;

/* The samples of an intent or of a plan's row a receiver keeps: every one a message may
 * carry (N + 1 = 41), unless a build sets fewer (a vehicle on the part: its fleet's
 * horizon). An intent of more samples, or a plan of a longer horizon, is refused
 * (COAVOID_LCM_ERR_CAPACITY); a sender's messages are not limited by it. */
#ifndef COAVOID_LCM_MAX_SAMPLES
#define COAVOID_LCM_MAX_SAMPLES COAVOID_INTENT_T_MAX_SAMPLES
#endif
_Static_assert(COAVOID_LCM_MAX_SAMPLES >= 2 &&
                   COAVOID_LCM_MAX_SAMPLES <= COAVOID_INTENT_T_MAX_SAMPLES &&
                   COAVOID_INTENT_T_MAX_SAMPLES == COAVOID_PLAN_T_MAX_SAMPLES,
               "a receiver keeps 2 to MAX_SAMPLES samples of intents and plans alike");

/* The arrays an intent's core view points into: the caller's, so that nothing is
 * allocated. */
typedef struct {
    coa_vec3_t reference[COAVOID_LCM_MAX_SAMPLES];
    coa_vec3_t samples[COAVOID_LCM_MAX_SAMPLES]; /* reference + offset * dh */
    int32_t offsets[COAVOID_LCM_MAX_SAMPLES];
} coavoid_lcm_intent_arrays_t;

/* Every rule of intent_t (its .lcm file): times, id, priority, mode, finite and bounded
 * state, volume and performance, sample count 2..MAX_SAMPLES, reference points that differ
 * horizontally, offsets within |32767| and max_offset whose consecutive changes are
 * actions, positions that stay finite and bounded once the offsets are applied, and a
 * rank in 0..MAX_RANK. Speeds, step, volume and route legs are also judged as the core sees them, in its
 * precision (coa_vehicle_check, a positive deviation weight and climb step), so every
 * accepted intent gives a vehicle the planner accepts.
 * Returns COA_OK or a COAVOID_LCM_ERR_* with *reason naming the field. Cost O(sample_count). */
int coavoid_lcm_intent_check(const coavoid_intent_t *msg, const coavoid_lcm_context_t *ctx,
                             const char **reason);

/* The core's views of an intent, after the check and the sequence rule (seq may be NULL:
 * no sequence rule):
 *   - *vehicle: a coa_vehicle_t a planner can plan for over the intent's samples: id,
 *     priority, speeds, steep factor, volume, max_offset, initial_offset = offsets[0],
 *     and route = arrays->reference (sample_count points), so coa_vehicle_check accepts
 *     it; plan it with dt = info->step and references[j] = arrays->reference[j].
 *   - *plan: the positions as the predictor takes them, t0 on ctx's clock, samples =
 *     arrays->samples computed as the planner computes positions (reference z +
 *     (coa_real_t)offset * coa_climb_step(vehicle, step)).
 * arrays must outlive both views. Errors as the check, plus COAVOID_LCM_ERR_SEQUENCE /
 * COAVOID_LCM_ERR_SENDERS, COA_ERR_ARGUMENT for NULL outputs; outputs are unspecified on an
 * error. Cost O(sample_count), no memory. */
int coavoid_lcm_intent_to_core(const coavoid_intent_t *msg, const coavoid_lcm_context_t *ctx,
                               coavoid_lcm_sequence_table_t *seq, coavoid_lcm_intent_info_t *info,
                               coa_vehicle_t *vehicle, coa_intent_plan_t *plan,
                               coavoid_lcm_intent_arrays_t *arrays, const char **reason);

/* An intent from a vehicle (its id, priority, volume, speeds, steep factor, max_offset;
 * its route is not read), info, and `count` reference points with their offsets. The
 * result is checked as a receiver would check it, so a node cannot publish what its
 * peers refuse. Returns COA_OK, COA_ERR_ARGUMENT (NULL), COAVOID_LCM_ERR_COUNT (count not in
 * 2..MAX_SAMPLES) or the check's refusal. Cost O(count). */
int coavoid_lcm_intent_from_core(const coa_vehicle_t *vehicle,
                                 const coavoid_lcm_intent_info_t *info, const coa_vec3_t *reference,
                                 const int32_t *offsets, size_t count,
                                 const coavoid_lcm_context_t *ctx, coavoid_intent_t *msg,
                                 const char **reason);

/* ---- plan ---- */

/* A plan as one whole: what a complete set of its messages (one per UAV) says. */
typedef struct {
    int64_t utime;
    uint32_t coordinator_id;
    int64_t plan_id;
    coa_real_t valid_from; /* core clock (s) of sample 0 */
    coa_real_t valid_until;
    coa_real_t dt;
    uint32_t horizon;
    int8_t mode; /* COAVOID_PLAN_T_MODE_* */
    size_t vehicle_count;
    uint16_t uav_ids[COAVOID_PLAN_T_MAX_VEHICLES];
    /* STATUS_ABANDONED: the coordinator gave up on these UAVs this cycle (no rows; the
     * result's status is then COA_PLAN_BUDGET_EXHAUSTED, nothing proven). From core: set
     * it to send one. */
    bool abandoned;
} coavoid_lcm_plan_info_t;

/* Every rule of one plan_t message: header (times, ids, horizon, mode, status, costs),
 * vehicle list (count, planned_count, ids in 1..65535 and distinct), and its row
 * (row_uav_id one of uav_ids; offsets within COA_MAX_OFFSET whose steps some action
 * makes for a planned UAV, all zero otherwise and past horizon). Returns COA_OK or a
 * COAVOID_LCM_ERR_* with *reason naming the field. O(vehicle_count^2 + MAX_SAMPLES). */
int coavoid_lcm_plan_check(const coavoid_plan_t *msg, const coavoid_lcm_context_t *ctx,
                           const char **reason);

/* The UAVs of the largest plan a receiver collects: every plan_t may list, unless a build
 * sets fewer (a vehicle on the part: its fleet); a plan of more is refused
 * (COAVOID_LCM_ERR_CAPACITY). */
#ifndef COAVOID_LCM_PLAN_ROWS
#define COAVOID_LCM_PLAN_ROWS COAVOID_PLAN_T_MAX_VEHICLES
#endif

/* The rows of the plans a receiver is collecting, in the caller's slots (one slot per
 * plan in progress): a plan is whole when a message of each of
 * its vehicle_count UAVs has come. */
typedef struct {
    bool used;
    coavoid_plan_t first; /* the first message of the plan: its header */
    uint32_t have;        /* bit i: the row of first.uav_ids[i] has come */
    int32_t offsets[COAVOID_LCM_PLAN_ROWS][COAVOID_LCM_MAX_SAMPLES];
} coavoid_lcm_plan_slot_t;

typedef struct {
    coavoid_lcm_plan_slot_t *slots;
    size_t capacity;
} coavoid_lcm_plan_rows_t;

/* Empties the collection over slots[0..capacity-1]. Cannot fail on non-NULL arguments. */
void coavoid_lcm_plan_rows_init(coavoid_lcm_plan_rows_t *rows, coavoid_lcm_plan_slot_t *slots,
                                size_t capacity);

/* Checks msg and adds its row to the plan it belongs to (coordinator_id, plan_id,
 * valid_from_utime); when no slot holds that plan, a free one, else the oldest plan's
 * (valid_from, then plan_id) is dropped unfinished. When this completes the plan (every
 * listed UAV's row has come), *whole points to the plan's first message (its header, in
 * the freed slot: valid until the next call), and info, result and offsets describe the
 * whole plan: offsets (capacity >= vehicle_count * (horizon + 1)
 * int32) row i = uav_ids[i] (the layout the planner writes), zero for UAVs without a plan;
 * result's status, costs, nodes_expanded and planned_count are set, order is 0..n-1.
 * Otherwise *whole is NULL and the other outputs are untouched. No sequence rule: the
 * caller orders plans. Returns COA_OK, the check's refusal, COAVOID_LCM_ERR_VALUE (a
 * message that disagrees with the header of its plan's earlier rows: nothing kept),
 * COAVOID_LCM_ERR_CAPACITY (offsets too small) or COA_ERR_ARGUMENT (NULL). Cost
 * O(check + slots + MAX_SAMPLES), and O(vehicle_count * horizon) to complete. No memory. */
int coavoid_lcm_plan_collect(coavoid_lcm_plan_rows_t *rows, const coavoid_plan_t *msg,
                             const coavoid_lcm_context_t *ctx, const coavoid_plan_t **whole,
                             coavoid_lcm_plan_info_t *info, coa_plan_result_t *result,
                             int32_t *offsets, size_t capacity, const char **reason);

/* The message of row `row` (0..vehicle_count-1, in the message's order: result->order)
 * of a plan: offsets as the planner wrote them for info->vehicle_count vehicles (rows in
 * vehicle index order; the message lists them in result->order). A plan goes out as the
 * messages of rows 0..vehicle_count-1. Returns COA_OK, COA_ERR_ARGUMENT (NULL, an order
 * naming no vehicle), COAVOID_LCM_ERR_COUNT (counts, horizon or row out of range),
 * COAVOID_LCM_ERR_VALUE (a number too large) or the check's refusal. O(vehicle_count +
 * horizon + check). */
int coavoid_lcm_plan_from_core(const coavoid_lcm_plan_info_t *info, const coa_plan_result_t *result,
                               const int32_t *offsets, size_t row, const coavoid_lcm_context_t *ctx,
                               coavoid_plan_t *msg, const char **reason);

/* ---- track ---- */

typedef struct {
    int64_t utime;
    uint32_t source_id;
    int64_t sequence;
} coavoid_lcm_track_info_t;

int coavoid_lcm_track_check(const coavoid_track_t *msg, const coavoid_lcm_context_t *ctx,
                            const char **reason);
/* track->position is extrapolated to the core clock's t = 0 (the core's convention);
 * path: capacity >= msg->path_count. */
int coavoid_lcm_track_to_core(const coavoid_track_t *msg, const coavoid_lcm_context_t *ctx,
                              coavoid_lcm_sequence_table_t *seq, coavoid_lcm_track_info_t *info,
                              coa_track_t *track, coa_track_point_t *path, size_t capacity,
                              const char **reason);
int coavoid_lcm_track_from_core(const coa_track_t *track, const coavoid_lcm_track_info_t *info,
                                const coavoid_lcm_context_t *ctx, coavoid_track_t *msg,
                                const char **reason);

/* ---- obstacle map ---- */

/* The most obstacles one map (all its tiles) holds: boxes and polytopes. */
#define COAVOID_LCM_MAP_MAX_OBSTACLES               \
    ((size_t)COAVOID_OBSTACLE_MAP_T_MAX_MAP_BOXES + \
     (size_t)COAVOID_OBSTACLE_MAP_T_MAX_MAP_POLYTOPES)

/* Every rule of one tile: time, map_id, version, tile_index < tile_count <= MAX_TILES,
 * box and polytope counts within the tile's capacity, each polytope >= 4 vertices and
 * their sum <= MAX_VERTICES, every number finite and within range, box_min <= box_max.
 * Returns COA_OK or a COAVOID_LCM_ERR_* with *reason. O(tile). */
int coavoid_lcm_obstacle_map_check(const coavoid_obstacle_map_t *msg,
                                   const coavoid_lcm_context_t *ctx, const char **reason);
/* The check, then the version rule (seq may be NULL: none): a version lower than one
 * already seen from this map_id is refused (COAVOID_LCM_ERR_SEQUENCE), an equal one is
 * accepted (a republished map). O(tile + senders). */
int coavoid_lcm_obstacle_map_accept(const coavoid_obstacle_map_t *msg,
                                    const coavoid_lcm_context_t *ctx,
                                    coavoid_lcm_sequence_table_t *seq, const char **reason);
/* A whole map from its tiles (tiles[i] is tile i of tile_count, all of one map_id and
 * version, each passing the check): every box, then every polytope, in tile order.
 * obstacles: capacity >= the map's boxes + polytopes; vertices: vertex_capacity >= the sum
 * of vertex_count. Returns COA_OK, the check's refusal, COAVOID_LCM_ERR_COUNT (tiles that
 * are not one whole version, or more than MAX_MAP_BOXES boxes or MAX_MAP_POLYTOPES
 * polytopes), COAVOID_LCM_ERR_CAPACITY or COA_ERR_ARGUMENT; nothing is written unless it
 * returns COA_OK. O(map). No memory. */
int coavoid_lcm_obstacle_map_to_core(const coavoid_obstacle_map_t *tiles, size_t tile_count,
                                     const coavoid_lcm_context_t *ctx, coa_obstacle_t *obstacles,
                                     size_t capacity, size_t *count, coa_vec3_t *vertices,
                                     size_t vertex_capacity, const char **reason);
/* How many tiles a map of these obstacles takes: boxes MAX_BOXES to a tile in order;
 * polytopes in order, a new tile when MAX_POLYTOPES or MAX_VERTICES would be passed.
 * Returns COA_OK, COAVOID_LCM_ERR_COUNT (more than the map's capacity or MAX_TILES
 * tiles, a polytope beyond MAX_VERTICES), COAVOID_LCM_ERR_ENUM or COA_ERR_ARGUMENT.
 * O(count). */
int coavoid_lcm_obstacle_map_tiles(const coa_obstacle_t *obstacles, size_t count,
                                   size_t *tile_count, const char **reason);
/* Tile tile_index of that tiling, checked. Errors as coavoid_lcm_obstacle_map_tiles, and
 * COAVOID_LCM_ERR_COUNT for a tile_index past the last tile, COAVOID_LCM_ERR_ID for
 * map_id. O(count + tile). */
int coavoid_lcm_obstacle_map_from_core(const coa_obstacle_t *obstacles, size_t count, int64_t utime,
                                       uint32_t map_id, int64_t version, size_t tile_index,
                                       const coavoid_lcm_context_t *ctx,
                                       coavoid_obstacle_map_t *msg, const char **reason);

/* ---- conflict report (monitoring) ---- */

int coavoid_lcm_conflict_report_check(const coavoid_conflict_report_t *msg,
                                      const coavoid_lcm_context_t *ctx, const char **reason);
/* From a prediction: a and b indices are mapped to ids through plan_ids (and track_ids
 * for track conflicts); obstacles keep their index. cluster may be NULL. Conflicts past
 * the message's capacity are counted in conflicts_found only. */
int coavoid_lcm_conflict_report_from_core(const coa_conflict_t *conflicts, size_t count,
                                          size_t conflicts_found, const uint16_t *plan_ids,
                                          size_t plan_count, const uint32_t *track_ids,
                                          size_t track_count, const uint32_t *cluster,
                                          int64_t utime, uint32_t reporter_id, int64_t sequence,
                                          int64_t prediction_utime, coa_real_t dt, uint32_t horizon,
                                          const coavoid_lcm_context_t *ctx,
                                          coavoid_conflict_report_t *msg, const char **reason);

/* ---- status ---- */

int coavoid_lcm_status_check(const coavoid_status_t *msg, const coavoid_lcm_context_t *ctx,
                             const char **reason);

/* The role whose key may sign a heartbeat of this node_kind: the coordinator's for
 * NODE_COORDINATOR, else a vehicle's. O(1). */
coavoid_auth_role_t coavoid_lcm_status_role(int8_t node_kind);

/* The health that status_t's REASON_* bits give: HEALTH_FAULT with INTERNAL_ERROR or
 * DUPLICATE_ID, HEALTH_DEGRADED with any other, HEALTH_OK with none. One rule for the
 * nodes that send heartbeats and for the check of those received. O(1). */
int8_t coavoid_lcm_health_of(int32_t reasons);

/* Check + sequence rule for the two types that have no core counterpart to convert to. */
int coavoid_lcm_conflict_report_accept(const coavoid_conflict_report_t *msg,
                                       const coavoid_lcm_context_t *ctx,
                                       coavoid_lcm_sequence_table_t *seq, const char **reason);
int coavoid_lcm_status_accept(const coavoid_status_t *msg, const coavoid_lcm_context_t *ctx,
                              coavoid_lcm_sequence_table_t *seq, const char **reason);

/* ---- agreement on a plan ---- */

/* Every rule of one agreement_t: utime, a known kind, ids in 1..65535 (node_id ==
 * coordinator_id for the coordinator's kinds), plan_id >= 0, valid_from_utime > 0. No
 * sequence rule: an agreement is idempotent (the same answer again changes nothing), and
 * a signed one is fresh by its signature. Returns COA_OK or a COAVOID_LCM_ERR_* with
 * *reason naming the field. O(1). */
int coavoid_lcm_agreement_check(const coavoid_agreement_t *msg, const coavoid_lcm_context_t *ctx,
                                const char **reason);

/* The role whose key may sign an agreement of this kind: the coordinator's for COMMIT and
 * ABORT, else a vehicle's (node_id's). O(1). */
coavoid_auth_role_t coavoid_lcm_agreement_role(int8_t kind);

/* ---- counting what arrives ---- */

/* What a node received and refused since it started, for its status message. */
typedef struct {
    int64_t received;         /* messages handed to the node, decoded or not */
    int64_t rejected;         /* refused by decoding or validation; <= received */
    int32_t last_reject_code; /* the last refusal's code (<= 0; 0: none yet) */
    const char *last_reason;  /* its reason (static string), or "none" */
} coavoid_lcm_rx_stats_t;

/* Zeroes the counters. Cannot fail on non-NULL stats. */
void coavoid_lcm_rx_init(coavoid_lcm_rx_stats_t *stats);

/* Counts one received message whose decode-and-validate step returned rc: a negative rc
 * (COAVOID_LCM_ERR_*, COA_ERR_*) is a refusal, recorded with its reason (NULL: the code's
 * name); COA_OK or any rc >= 0 (a decoder's byte count) is an acceptance. Saturates rather
 * than wrapping. Cannot fail on non-NULL stats. Cost O(1). */
void coavoid_lcm_rx_count(coavoid_lcm_rx_stats_t *stats, int rc, const char *reason);

#ifdef __cplusplus
}
#endif

#endif /* COAVOID_LCM_H */
