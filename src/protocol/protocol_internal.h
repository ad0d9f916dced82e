/* SPDX-License-Identifier: MIT */
/*
 * protocol_internal.h: what the vehicle and the coordinator share beyond protocol.h
 * (common.c):
 *   - the inbox: checking, decoding and validation of the datagrams a transport hands it
 *     (coavoid_node_inbox_receive; node_lcm.h subscribes it to LCM), the
 *     counters, and the latest message of every sender (intents per UAV, tracks per
 *     source and track, the obstacle map, heartbeats);
 *   - the view of one cycle: the stored intents converted to the core's types on the
 *     cycle's clock (t = 0 at the cycle's start), stale UAVs turned into tracks;
 *   - the planner's track list for one problem (real tracks, UAVs as moving obstacles);
 *   - publishing into a buffer the node owns, handed to a link (coavoid_node_link_t), so
 *     that nothing is allocated per cycle by our code (a transport may: LCM's provider
 *     does inside lcm_publish).
 * Not part of the API: a driver includes protocol.h or node.h only.
 */
#ifndef COAVOID_PROTOCOL_INTERNAL_H
#define COAVOID_PROTOCOL_INTERNAL_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "protocol.h"

#define COAVOID_NODE_MAX_SAMPLES (COAVOID_NODE_MAX_HORIZON + 1u)
_Static_assert(COAVOID_NODE_MAX_SAMPLES == (unsigned)COAVOID_LCM_MAX_SAMPLES,
               "a node keeps N + 1 samples of an intent and a plan's row at its largest horizon");
/* How many steps beyond the horizon a vehicle's order search looks when it chooses among
 * the orders that solve the horizon (vehicle_order.c, look_ahead): enough to tell apart, in
 * 5-UAV encounter 231 of seed 1, the order whose plan leaves no way on from the one that
 * does (one step does; two leave a margin). A problem holds up to N + 1 + LOOKAHEAD
 * samples. */
#define COAVOID_NODE_LOOKAHEAD 2u
#define COAVOID_NODE_MAX_PROBLEM_SAMPLES (COAVOID_NODE_MAX_SAMPLES + COAVOID_NODE_LOOKAHEAD)

/* Room for one obstacle map: its tiles (a build may hold fewer than a map may have: a
 * map of more is refused, counted, and the configured obstacles stay), their obstacles
 * (boxes, then polytopes) and their vertices, as many as that many tiles can carry. */
#ifndef COAVOID_NODE_MAX_MAP_TILES
#define COAVOID_NODE_MAX_MAP_TILES ((size_t)COAVOID_OBSTACLE_MAP_T_MAX_TILES)
#endif
#define COAVOID_NODE_MIN_SIZE(a, b) ((size_t)(a) < (size_t)(b) ? (size_t)(a) : (size_t)(b))
#define COAVOID_NODE_MAX_MAP_OBSTACLES                                          \
    COAVOID_NODE_MIN_SIZE(                                                      \
        COAVOID_LCM_MAP_MAX_OBSTACLES,                                          \
        COAVOID_NODE_MAX_MAP_TILES *((size_t)COAVOID_OBSTACLE_MAP_T_MAX_BOXES + \
                                     (size_t)COAVOID_OBSTACLE_MAP_T_MAX_POLYTOPES))
/* What a node avoids: its configured obstacles, then the map's that are not among them. */
#define COAVOID_NODE_MAX_OBSTACLES \
    ((size_t)COAVOID_NODE_MAX_CONFIGURED_OBSTACLES + COAVOID_NODE_MAX_MAP_OBSTACLES)
#define COAVOID_NODE_MAX_VERTICES                                             \
    COAVOID_NODE_MIN_SIZE((size_t)COAVOID_OBSTACLE_MAP_T_MAX_MAP_POLYTOPES *( \
                              size_t)COAVOID_OBSTACLE_MAP_T_MAX_VERTICES,     \
                          COAVOID_NODE_MAX_MAP_TILES *(size_t)COAVOID_OBSTACLE_MAP_T_MAX_VERTICES)

/* Tracks one cycle can hold: the real ones plus every UAV as a moving obstacle (live or
 * stale: together at most MAX_PEERS). */
#define COAVOID_NODE_TRACK_CAPACITY (COAVOID_NODE_MAX_TRACKS + COAVOID_NODE_MAX_PEERS)

/* Senders per sequence table: every UAV, plus a few coordinators and trackers. */
#define COAVOID_NODE_MAX_SENDERS (COAVOID_NODE_MAX_PEERS + 8u)

/* An intent older than this many horizons is dropped, not extrapolated: its constant-
 * velocity guess is meaningless by then. */
#define COAVOID_NODE_DROP_HORIZONS 1

/* Encoded messages are written here before they go to the link: one datagram at most. */
#define COAVOID_NODE_TX_BYTES ((size_t)COAVOID_LCM_MAX_DATAGRAM_BYTES)

/* Plans whose rows a UAV collects at once: the coordinator sends a plan's rows back to
 * back, so one is usually enough; more keep a plan whole when rows of another (a late
 * one, a forger's) come between. */
#ifndef COAVOID_NODE_PLAN_SLOTS
#define COAVOID_NODE_PLAN_SLOTS 4u
#endif

/* How many of its latest intents a node remembers, to tell them when they come back: all
 * it can send in one cycle (its intent and 8 copies in its first, then up to 4 decisions
 * again with 4 copies each: 29), so that a copy that comes back late, behind a cycle whose
 * planning overran, is still known as its own and not taken for a twin's. */
#define COAVOID_NODE_OWN_INTENTS 32u

/* The channels an inbox listens to (coavoid_node_inbox_channel): intents, tracks, the
 * obstacle map, heartbeats, plans and agreements; bit COAVOID_NODE_WANTS(X) of `wants`. */
enum {
    COAVOID_NODE_CHANNEL_INTENT,
    COAVOID_NODE_CHANNEL_TRACK,
    COAVOID_NODE_CHANNEL_MAP,
    COAVOID_NODE_CHANNEL_STATUS,
    COAVOID_NODE_CHANNEL_PLAN,
    COAVOID_NODE_CHANNEL_AGREEMENT
};
#define COAVOID_NODE_WANTS(x) (1u << COAVOID_NODE_CHANNEL_##x)

/* Where a node encodes what it publishes, and the key it signs it with. */
typedef struct {
    coavoid_node_link_t link;
    bool sign;                    /* false only for an insecure node */
    coavoid_auth_signer_t signer; /* a copy of common.signer, zeroed at fini */
    const int64_t *clock;         /* the driver's: the signatures' timestamps */
    uint8_t buf[COAVOID_NODE_TX_BYTES];
} coavoid_node_tx_t;

/* A sequence table with the time each sender was last heard, so that a sender silent
 * past a limit is forgotten (a restarted node numbers from 0 again). */
typedef struct {
    coavoid_lcm_sequence_table_t table;
    coavoid_lcm_sender_t entries[COAVOID_NODE_MAX_SENDERS];
    uint32_t heard_sender[COAVOID_NODE_MAX_SENDERS];
    int64_t heard_utime[COAVOID_NODE_MAX_SENDERS];
    size_t heard_count;
} coavoid_node_senders_t;

/* An intent as a node keeps it (coavoid_node_intent_keep): every field as received, but
 * the node's samples only (a longer intent is refused on arrival) and its reference points
 * in the core's precision, to which every use converts them first (so the opened message
 * converts exactly as the received one did). What a node reads of it without opening it
 * (coavoid_node_intent_open) is copied out: utime, plan_utime and uav_id. */
#define COAVOID_NODE_INTENT_HEAD offsetof(coavoid_intent_t, reference)
#define COAVOID_NODE_INTENT_TAIL_AT \
    (offsetof(coavoid_intent_t, offsets) + sizeof(((coavoid_intent_t *)NULL)->offsets))
_Static_assert(offsetof(coavoid_intent_t, offsets) ==
                   COAVOID_NODE_INTENT_HEAD + sizeof(((coavoid_intent_t *)NULL)->reference),
               "intent_t: the offsets follow the reference points");
typedef struct {
    int64_t utime;
    int64_t plan_utime;
    int32_t uav_id;
    uint8_t head[COAVOID_NODE_INTENT_HEAD]; /* the fields before the reference points */
    coa_real_t reference[COAVOID_NODE_MAX_SAMPLES][3];
    int32_t offsets[COAVOID_NODE_MAX_SAMPLES];
    uint8_t tail[sizeof(coavoid_intent_t) - COAVOID_NODE_INTENT_TAIL_AT]; /* and after them */
} coavoid_node_intent_t;

typedef struct {
    bool used;
    bool forgotten;            /* its sequence was forgotten when it went stale */
    coavoid_node_intent_t msg; /* validated on arrival */
    /* The latest intent of an earlier cycle than msg's (has_prev): what a vehicle's order
     * search reads as the intents of a cycle's start, whether or not the UAV has already
     * published its intent of the cycle (vehicle_order.c, coavoid_vehicle_search_order). */
    bool has_prev;
    coavoid_node_intent_t prev;
} coavoid_node_peer_t;

/* Keeps a validated intent (sample_count at most COAVOID_NODE_MAX_SAMPLES). O(samples). */
void coavoid_node_intent_keep(coavoid_node_intent_t *kept, const coavoid_intent_t *msg);

/* The kept intent as a whole message, in *out; returns out. O(samples). */
const coavoid_intent_t *coavoid_node_intent_open(const coavoid_node_intent_t *kept,
                                                 coavoid_intent_t *out);

typedef struct {
    bool used;
    coavoid_track_t msg; /* validated on arrival */
} coavoid_node_track_slot_t;

typedef struct coavoid_node_inbox coavoid_node_inbox_t;

/* The inbox of a vehicle node, for its transport's subscriptions (node_lcm.c). O(1). */
coavoid_node_inbox_t *coavoid_vehicle_node_inbox(coavoid_vehicle_node_t *node);

/* Called for a whole plan: the message that completed it (every listed UAV's row decoded
 * and passed validation, from its coordinator); msg is the plan's first message, its
 * header. No sequence rule is applied to plans (vehicle_agreement.c orders those of one cycle,
 * decides on adoption and counts the outcome itself). */
typedef void (*coavoid_node_plan_handler_t)(void *owner, const coavoid_plan_t *msg,
                                            const coavoid_lcm_plan_info_t *info,
                                            const coa_plan_result_t *result,
                                            const int32_t *offsets);

/* Called for an agreement that passed its checks (signature, role, coavoid_lcm_agreement_check)
 * and is not the node's own; returns COA_OK, or the refusal to count against it. */
typedef int (*coavoid_node_agreement_handler_t)(void *owner, const coavoid_agreement_t *msg);

struct coavoid_node_inbox {
    coavoid_node_common_t common;
    uint16_t self_uav;       /* intents from this UAV are the node's own (0: none) */
    uint16_t self_node;      /* status and plans from this node id are its own */
    uint16_t coordinator_id; /* the only coordinator it hears (0: none) */
    size_t peer_capacity;    /* other UAVs it keeps (vehicle: MAX_PEERS - 1) */
    int64_t max_age_us;      /* validation window (context max_age) */
    /* Unless insecure: the trust list (a copy of common.trust, with its freshness marks);
     * every message must verify against it before it is decoded further. */
    bool secure;
    coavoid_auth_trust_t trust;
    unsigned wants;             /* COAVOID_NODE_WANTS bits: the channels it takes in */
    coavoid_lcm_rx_stats_t *rx; /* the owner's counters (its state's rx) */

    coavoid_node_senders_t intent_seq;
    coavoid_node_senders_t track_seq;
    coavoid_node_senders_t map_seq;
    coavoid_node_senders_t status_seq;

    coavoid_node_peer_t peers[COAVOID_NODE_MAX_PEERS];
    coavoid_node_track_slot_t tracks[COAVOID_NODE_MAX_TRACKS];

    bool have_map;
    int32_t map_id; /* the map in use (have_map) */
    int64_t map_version;
    /* The tiles of the version being assembled (map_tiles_have: bit i, tile i has come):
     * it replaces the map in use once every tile has come, never before. */
    coavoid_obstacle_map_t map_tiles[COAVOID_NODE_MAX_MAP_TILES];
    uint32_t map_tiles_have;
    coa_obstacle_t map_obstacles[COAVOID_NODE_MAX_MAP_OBSTACLES]; /* the map in use */
    size_t map_obstacle_count;
    /* What the node avoids (obstacles_merge): common.obstacles, then the map's others. */
    coa_obstacle_t obstacles[COAVOID_NODE_MAX_OBSTACLES];
    size_t obstacle_count;
    coa_vec3_t vertices[COAVOID_NODE_MAX_VERTICES];

    /* Its latest published intents (FNV-1a of the encoded bytes, and their size): an
     * intent with its own UAV id that is none of these was sent by another UAV using the
     * same id, even when the times and sequence numbers happen to agree. */
    uint64_t own_hash[COAVOID_NODE_OWN_INTENTS];
    int own_size[COAVOID_NODE_OWN_INTENTS];
    size_t own_next;
    uint32_t foreign_intents; /* such intents since the owner last cleared it */

    int64_t rejected_at_heartbeat; /* rx->rejected when the last heartbeat was sent */

    /* The inbox budget of cycle budget_cycle (node.h, COAVOID_NODE_CHECKS_PER_*): the
     * signature checks made per key and stream and in all, the datagrams taken in (this
     * cycle's and the last's), and those dropped unchecked (since start, and when the
     * last heartbeat was sent). */
    int64_t budget_cycle;
    uint16_t checks[COAVOID_AUTH_MAX_KEYS][COAVOID_AUTH_STREAMS];
    uint32_t cycle_checks;
    uint32_t cycle_datagrams;
    uint32_t last_cycle_datagrams;
    int64_t dropped;
    int64_t dropped_at_heartbeat;

    /* Counts the tracks it took in while holding none of theirs, and the obstacle maps it
     * put in use (wraps): what it knows of the world grew when it changed, which a vehicle
     * that decided before then decides again on (vehicle_decide.c, coavoid_vehicle_reconsider). */
    uint32_t world_news;

    bool heard_coordinator;    /* a coordinator's status_t was received */
    int64_t coordinator_utime; /* when (driver clock) */

    coavoid_node_plan_handler_t on_plan;
    coavoid_node_agreement_handler_t on_agreement;
    /* Optional: shown every plan message of its coordinator (signature and role checked,
     * not yet collected); true when the owner already holds that plan (it answers again),
     * so that the message is not collected: one row of a plan sent again is enough to
     * tell that an answer was lost. */
    bool (*on_plan_row)(void *owner, const coavoid_plan_t *msg);
    void *owner;

    /* Decoding buffers (LCM dispatches one message at a time) and the transmit buffer. */
    union {
        coavoid_intent_t intent;
        coavoid_plan_t plan;
        coavoid_track_t track;
        coavoid_obstacle_map_t map;
        coavoid_status_t status;
        coavoid_agreement_t agreement;
    } rx_msg;
    coavoid_lcm_intent_arrays_t rx_arrays;
    /* The plans whose rows are being collected, and a whole plan's offsets. */
    coavoid_lcm_plan_slot_t plan_slots[COAVOID_NODE_PLAN_SLOTS];
    coavoid_lcm_plan_rows_t plan_rows;
    int32_t rx_offsets[(size_t)COAVOID_LCM_PLAN_ROWS * COAVOID_NODE_MAX_SAMPLES];
    coavoid_node_tx_t tx;
};

/* The cycle's view: live UAVs (ascending id) and tracks (real ones first, by source and
 * id, then the stale UAVs by id), on the clock whose t = 0 is cycle_start. A stale UAV's
 * track is the last plan it announced (its intent's positions at their own times, then
 * the velocity of its last leg), its sigma grown with its silence. */
typedef struct {
    int64_t cycle_start;
    size_t live_count;
    uint16_t live_id[COAVOID_NODE_MAX_PEERS];
    bool live_current[COAVOID_NODE_MAX_PEERS]; /* an intent for this cycle: plan_utime ==
                                              cycle_start, step dt, N + 1 samples */
    coa_vehicle_t live_vehicle[COAVOID_NODE_MAX_PEERS];
    coa_intent_plan_t live_plan[COAVOID_NODE_MAX_PEERS];
    coavoid_lcm_intent_info_t live_info[COAVOID_NODE_MAX_PEERS];
    coavoid_lcm_intent_arrays_t live_arrays[COAVOID_NODE_MAX_PEERS];

    size_t real_track_count;
    size_t track_count; /* real + stale UAVs */
    coa_track_t tracks[COAVOID_NODE_TRACK_CAPACITY];
    uint32_t track_ids[COAVOID_NODE_TRACK_CAPACITY];
    coa_track_point_t real_paths[COAVOID_NODE_MAX_TRACKS][COAVOID_TRACK_T_MAX_PATH];
    size_t stale_count; /* tracks[real_track_count ..] are stale UAVs */
    /* A stale UAV's last plan as its track's path, and the conversion's scratch. */
    coa_track_point_t stale_paths[COAVOID_NODE_MAX_PEERS][COAVOID_NODE_MAX_SAMPLES];
    coavoid_lcm_intent_arrays_t stale_arrays;
    coavoid_intent_t opened; /* scratch: a kept intent opened to be converted or read */
} coavoid_node_view_t;

/* The tracks of one planning problem, sampled over the horizon. */
typedef struct {
    size_t count;
    coa_track_t tracks[COAVOID_NODE_TRACK_CAPACITY];
    const coa_vec3_t *samples[COAVOID_NODE_TRACK_CAPACITY];
    coa_vec3_t storage[COAVOID_NODE_TRACK_CAPACITY][COAVOID_NODE_MAX_PROBLEM_SAMPLES];
    coa_track_point_t paths[COAVOID_NODE_MAX_PEERS][COAVOID_NODE_MAX_SAMPLES];
} coavoid_node_problem_tracks_t;

/* A node's prediction and planning memory, in the caller's memory (one block laid out by
 * coavoid_node_solver_place): room for every pair coavoid_node_max_pairs allows, and one
 * workspace that holds either a predictor over MAX_PEERS plans and TRACK_CAPACITY tracks
 * or a planner of `searched` UAVs a search, whichever ran last: a node predicts, then
 * plans, then predicts again, never both at once, and neither keeps anything a later call
 * needs. coavoid_node_solver_predictor and coavoid_node_solver_planner hand it out. */
typedef struct {
    coa_conflict_t *conflicts;
    size_t conflict_capacity;
    void *workspace;
    size_t workspace_size;
    uint32_t horizon; /* the predictor's */
    coa_planner_config_t planner_config;
    coa_predictor_t *predictor; /* NULL while the planner holds the workspace */
    coa_planner_t *planner;     /* NULL while the predictor holds it */
} coavoid_node_solver_t;

/* What a solver is sized for: predictions over `horizon` steps (N), and a planner of
 * `searched` UAVs at beta over at most plan_horizon steps (>= horizon: a vehicle's order
 * search looks further). */
typedef struct {
    uint32_t horizon;
    uint32_t plan_horizon;
    size_t searched;
    uint32_t beta;
} coavoid_node_solver_shape_t;

/* What a node's heartbeat (status_t) says: who it is and how it is, as the node judges,
 * and the counters its state keeps (saturated to the message's types when sent). */
typedef struct {
    uint16_t node_id;
    int8_t node_kind; /* COAVOID_STATUS_T_NODE_* */
    int64_t sequence;
    /* COAVOID_STATUS_T_REASON_* bits (refused messages are added when sent): the health
     * follows from them, HEALTH_FAULT for INTERNAL_ERROR or DUPLICATE_ID, DEGRADED for
     * any other, else OK. */
    int32_t reasons;
    int8_t mode; /* COAVOID_STATUS_T_MODE_* */
    int64_t last_plan_utime;
    int64_t last_plan_duration_us;
    uint64_t last_nodes_expanded;
    int last_outcome; /* coa_plan_status_t, -1 none */
    uint32_t conflicts;
    uint32_t plans_run;
    const coavoid_lcm_rx_stats_t *rx;
} coavoid_node_heartbeat_t;

/* Checks a common configuration (node.h's ranges; a signer unless insecure). COA_OK or
 * COA_ERR_ARGUMENT. O(1). */
int coavoid_node_common_check(const coavoid_node_common_t *c);

/* Whether a common configuration's floor is one a node can hold (node.h: none, or a
 * finite min_altitude within COAVOID_LCM_MAX_COORDINATE). O(1). */
static inline bool coavoid_node_floor_ok(const coavoid_node_common_t *c)
{
    return !c->has_floor || ((double)c->min_altitude >= -COAVOID_LCM_MAX_COORDINATE &&
                             (double)c->min_altitude <= COAVOID_LCM_MAX_COORDINATE);
}

/* The validation context at `now` with t = 0 at `epoch`: messages up to a horizon and
 * stale_after old, at most one cycle ahead. Cannot fail; O(1). */
coavoid_lcm_context_t coavoid_node_context(const coavoid_node_inbox_t *in, int64_t now,
                                           int64_t epoch);

/* Initialises the inbox to take in intents, tracks and the obstacle map, and heartbeats
 * (want_status) and plans (plan_handler non-NULL) when asked; counts into rx; publishes
 * through link. A coordinator's heartbeat or a plan from another node than
 * coordinator_id is refused (COAVOID_LCM_ERR_ID). Unless common->insecure, every message
 * must carry a signature of a key in common->trust whose role may send it, and be fresh
 * (COAVOID_AUTH_ERR_* otherwise, counted as refused).
 * Returns COA_OK, or COA_ERR_ARGUMENT when a secure node has no trust list. O(senders);
 * no memory. */
int coavoid_node_inbox_init(coavoid_node_inbox_t *in, const coavoid_node_common_t *common,
                            uint16_t self_uav, uint16_t self_node, uint16_t coordinator_id,
                            size_t peer_capacity, const coavoid_node_link_t *link,
                            coavoid_lcm_rx_stats_t *rx, bool want_status,
                            coavoid_node_plan_handler_t plan_handler, void *owner);

/* Takes in the agreements on plans (COAVOID_AGREEMENT) of the inbox's coordinator too:
 * each that verifies, may be sent by its signer's role and passes
 * coavoid_lcm_agreement_check goes to handler (its own, come back, do not). O(1). */
void coavoid_node_inbox_agreements(coavoid_node_inbox_t *in,
                                   coavoid_node_agreement_handler_t handler);

/* The name of channel i (0..COAVOID_NODE_CHANNELS-1) when the inbox takes it in, else
 * NULL: what a transport subscribes to, in this order. O(1). */
const char *coavoid_node_inbox_channel(const coavoid_node_inbox_t *in, size_t i);

/* One datagram as it arrived on `channel`, at the time *common.clock says: checked
 * (tail, fleet tag, budget, signature, sender), decoded, validated and stored, or
 * counted as refused or dropped; a whole plan or an agreement goes on to the owner's
 * handler. Returns COA_OK when the inbox takes the channel in (whatever became of the
 * datagram: a refusal is counted, never returned), COA_ERR_ARGUMENT for a channel it
 * does not take in or a NULL argument. Cost: at most one signature verification, the
 * decoding and validation, O(senders), plus the handler's; no memory. */
int coavoid_node_inbox_receive(coavoid_node_inbox_t *in, const char *channel, const void *data,
                               size_t size);

/* Brings the inbox budget (node.h, COAVOID_NODE_CHECKS_PER_*) to the cycle of `now`: a
 * new cycle starts it afresh, keeping the last whole cycle's datagram count. O(1). */
void coavoid_node_inbox_roll(coavoid_node_inbox_t *in, int64_t now);

/* How old an intent or a track may be before it is dropped rather than extrapolated:
 * stale_after plus COAVOID_NODE_DROP_HORIZONS horizons. O(1). */
int64_t coavoid_node_inbox_drop_after(const coavoid_node_inbox_t *in);

/* Stops taking anything in and clears the copy of the signing key. O(1). */
void coavoid_node_inbox_fini(coavoid_node_inbox_t *in);

/* Forgets senders silent past stale_after (a restarted one numbers from 0 again) and
 * drops intents and tracks too old to be of use. Cost O(senders). */
void coavoid_node_inbox_expire(coavoid_node_inbox_t *in, int64_t now);

/* Builds the view of the cycle starting at cycle_start, at `now`. Cost O(peers * samples +
 * tracks). Cannot fail: a stored message that no longer converts is left out. */
void coavoid_node_view_build(coavoid_node_view_t *view, const coavoid_node_inbox_t *in,
                             int64_t cycle_start, int64_t now);

/* The same from each UAV's latest intent of a cycle that began before `before` (its
 * latest, or the one before it: coavoid_node_peer_t's prev); a UAV with none is left out.
 * With before = cycle_start = now, the view of the intents as they stood when the cycle
 * began, whatever came since. Same cost. */
void coavoid_node_view_build_before(coavoid_node_view_t *view, const coavoid_node_inbox_t *in,
                                    int64_t cycle_start, int64_t now, int64_t before);

/* FNV-1a (64 bits) of size bytes at data, continuing from h (COAVOID_NODE_FNV_OFFSET to
 * start). O(size). */
#define COAVOID_NODE_FNV_OFFSET UINT64_C(14695981039346656037)
uint64_t coavoid_node_fnv(uint64_t h, const void *data, size_t size);

/* A digest of everything a planner reads of a problem (coa_problem_t, plan.h): dt, the
 * horizon, each UAV's fields and route, its references, each obstacle (its kind, box or
 * polytope's vertices), each track's volume and samples; each value by its own bytes, so
 * padding never enters it. Equal problems have equal digests; two problems that differ
 * share one with probability 2^-64. O(size of the problem). */
uint64_t coavoid_node_problem_digest(const coa_problem_t *problem);

/* The planning problem of `count` UAVs over `horizon` steps (the common N, or up to
 * COAVOID_NODE_LOOKAHEAD more; vehicles and references[i], horizon + 1 samples each: the
 * caller's, and the problem points to them) around the inbox's obstacles, the
 * view's tracks and the live UAVs `include` marks as moving obstacles (tracks, filled in
 * *tracks): what the coordinator plans a cluster in, and a vehicle's order search.
 * Returns COA_OK or COA_ERR_ARGUMENT (a track that cannot be sampled). Cost as
 * coavoid_node_problem_tracks. */
int coavoid_node_problem(coa_problem_t *problem, coavoid_node_problem_tracks_t *tracks,
                         const coavoid_node_view_t *view, const bool *include,
                         const coavoid_node_inbox_t *in, const coa_vehicle_t *vehicles,
                         const coa_vec3_t *const *references, size_t count, uint32_t horizon);

/* Whether a outranks b in the decoupled order (ascending priority, ties by ascending id).
 * O(1). */
bool coavoid_node_outranks(uint32_t priority_a, uint16_t id_a, uint32_t priority_b, uint16_t id_b);
/* Whether a comes before b in the decoupled order the vehicles negotiate (docs/protocol.md,
 * "Priority negotiation"): the higher announced rank first, then coavoid_node_outranks.
 * With every rank 0 it is coavoid_node_outranks, the configured order. O(1). */
bool coavoid_node_precedes(int32_t rank_a, uint32_t priority_a, uint16_t id_a, int32_t rank_b,
                           uint32_t priority_b, uint16_t id_b);

/* Fills out with the planner's tracks: every real and stale track of the view and each
 * live UAV i with include[i] (its positions as a path; exactly its samples when the intent
 * is for this cycle, as far as it reaches, then along its last leg), each sampled over
 * samples 0..horizon (N, or up to COAVOID_NODE_LOOKAHEAD more). Returns COA_OK or
 * COA_ERR_ARGUMENT (a track that does not sample, or a horizon beyond that). Cost
 * O(tracks * (horizon + path)). No memory. */
int coavoid_node_problem_tracks(coavoid_node_problem_tracks_t *out, const coavoid_node_view_t *view,
                                const bool *include, const coavoid_node_common_t *c,
                                uint32_t horizon);

/* The predictor's configuration for one cycle of a node: t = 0 at the cycle's start,
 * the common dt, horizon, sigma rates and threshold. Cannot fail; O(1). */
coa_predict_config_t coavoid_node_predict_config(const coavoid_node_common_t *c);

/* Predicts over samples 0..N of the view's clock for plans[0..n) against the view's
 * tracks and the inbox's obstacles, then clusters (labels[0..n)). n == 0 gives no
 * conflict. Returns COA_OK, the predictor's or the clustering's error, or
 * COA_ERR_WORKSPACE when the conflicts overflow `capacity`. Cost: coa_predict's. No
 * memory beyond the predictor's workspace. */
int coavoid_node_predict(coa_predictor_t *predictor, const coavoid_node_common_t *c,
                         const coa_intent_plan_t *plans, size_t n, const coavoid_node_view_t *view,
                         const coavoid_node_inbox_t *in, coa_conflict_t *conflicts, size_t capacity,
                         coa_predict_result_t *result, uint32_t *labels, size_t *cluster_count);

/* The predictor's pair bound for a node: every pair that can exist among its UAVs, real
 * tracks and obstacles, so that the broad phase cannot run out. A UAV is a plan or a
 * stale UAV's track, never both, and there are at most MAX_PEERS of them (a vehicle
 * counts itself): their pairs are at most MAX_PEERS (MAX_PEERS - 1) / 2, whatever the
 * split, plus MAX_PEERS times the real tracks and the obstacles. O(1). */
size_t coavoid_node_max_pairs(void);

/* x rounded up to COA_WORKSPACE_ALIGNMENT, where a caller's block places its next part
 * (the solver's workspaces, a vehicle's solver after its struct); 0 on overflow. O(1). */
size_t coavoid_node_align_up(size_t x);

/* The bytes of a solver of this shape: the larger of the predictor's and the planner's
 * workspaces (coa_predictor_workspace_size, coa_planner_workspace_size) and the conflict
 * array, each rounded up to COA_WORKSPACE_ALIGNMENT; 0 for sizes the core refuses. O(1). */
size_t coavoid_node_solver_size(const coavoid_node_solver_shape_t *shape);

/* Lays a solver of this shape out in memory (aligned to COA_WORKSPACE_ALIGNMENT, size
 * bytes, the caller's, not moved while used). COA_OK, COA_ERR_ARGUMENT (sizes the core
 * refuses) or COA_ERR_WORKSPACE (memory NULL, misaligned or smaller than
 * coavoid_node_solver_size); *s is zeroed on failure. O(size of the workspaces' headers);
 * allocates nothing. */
int coavoid_node_solver_place(coavoid_node_solver_t *s, void *memory, size_t size,
                              const coavoid_node_solver_shape_t *shape);

/* The solver's predictor, or its planner, built afresh in the shared workspace when the
 * other one ran last (a planner so built has no work budget: a caller that wants one sets
 * it before each search). The handle is good until the other is asked for. NULL only for
 * a solver that was not placed. Cost O(1) when it holds the workspace already, else the
 * init's: the predictor's hash table (2 to 4 slots of 8 bytes per pair) or the planner's
 * first slots; no memory. */
coa_predictor_t *coavoid_node_solver_predictor(coavoid_node_solver_t *s);
coa_planner_t *coavoid_node_solver_planner(coavoid_node_solver_t *s);

/* Fills *m from h at `now`, validates it on the clock whose t = 0 is cycle_start
 * (coavoid_node_context) and publishes it. Its health is HEALTH_DEGRADED (unless a fault)
 * also when messages were refused since the previous heartbeat: a clock that disagrees,
 * more peers than the node holds or a bad sender show in the heartbeat as they happen.
 * Returns COA_OK, COA_ERR_ARGUMENT (it does not validate) or coavoid_node_publish_status's
 * error. O(1); no memory. */
int coavoid_node_publish_heartbeat(coavoid_node_inbox_t *in, coavoid_status_t *m, int64_t now,
                                   int64_t cycle_start, const coavoid_node_heartbeat_t *h);

/* Prepares tx for publishing through link as c says: signing with a copy of c->signer
 * at c's clock, unless c->insecure. fini zeroes the copy of the secret key. O(1); cannot
 * fail (c was checked). */
void coavoid_node_tx_init(coavoid_node_tx_t *tx, const coavoid_node_link_t *link,
                          const coavoid_node_common_t *c);
void coavoid_node_tx_fini(coavoid_node_tx_t *tx);

/* Publishing: encodes into tx->buf, signs it (coavoid_auth_stamp: one Ed25519 signature)
 * and hands it to the link on the type's channel. COA_OK, or COA_ERR_WORKSPACE (over
 * COAVOID_LCM_MAX_DATAGRAM_BYTES: never sent, or does not encode) or COA_ERR_ARGUMENT (the
 * link refused it, or it could not be signed). O(message); our code allocates nothing
 * (a transport may). */
int coavoid_node_publish_plan(coavoid_node_tx_t *tx, const coavoid_plan_t *msg);
int coavoid_node_publish_track(coavoid_node_tx_t *tx, const coavoid_track_t *msg);
int coavoid_node_publish_map(coavoid_node_tx_t *tx, const coavoid_obstacle_map_t *msg);
int coavoid_node_publish_conflicts(coavoid_node_tx_t *tx, const coavoid_conflict_report_t *msg);
int coavoid_node_publish_status(coavoid_node_tx_t *tx, const coavoid_status_t *msg);
int coavoid_node_publish_agreement(coavoid_node_tx_t *tx, const coavoid_agreement_t *msg);

/* Publishes the node's own intent as the functions above do, and remembers it so that the
 * inbox knows it when it comes back (node_internal.h, own_hash). Same returns and cost. */
int coavoid_node_publish_intent(coavoid_node_inbox_t *in, const coavoid_intent_t *msg);

/* The common stopwatch's reading (us), 0 without one: durations are differences. O(1). */
int64_t coavoid_node_stopwatch(const coavoid_node_common_t *c);

#endif /* COAVOID_PROTOCOL_INTERNAL_H */
