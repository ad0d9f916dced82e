/* SPDX-License-Identifier: MIT */
/*
 * protocol.h: the vehicle's side of the coavoid protocol (docs/protocol.md), as a library
 * with no I/O: an autopilot, the Linux driver (apps/vehicle) and the simulation run the
 * same code.
 *
 *   events in                          actions out
 *   coavoid_vehicle_node_receive  --> |           | --> datagrams through the link
 *     (a datagram and its channel)    |  vehicle  |     (intents, heartbeats, answers)
 *   coavoid_vehicle_node_cycle    --> |           | --> coavoid_vehicle_node_state:
 *     (each cycle's start)            |           |     the offset to fly, health and
 *   coavoid_vehicle_node_poll     --> |           |     its reasons, counters
 *     (by coavoid_vehicle_node_deadline, and after messages)
 *
 * Every call takes the time; none reads a clock. The message handlers read the time from
 * common.clock, a variable the caller sets before it hands a datagram in. Memory: the
 * caller's, one block of coavoid_vehicle_node_size bytes for the configuration,
 * allocated by nothing here (as the planner's workspace, plan.h). No stdio, no heap, no
 * LCM: messages are LCM's encoding (lcmtypes/, the lcm-gen coders, which need only
 * lcm_coretypes.h), signed and checked by coavoid::auth.
 *
 * Errors are negative (COA_ERR_*, COAVOID_LCM_ERR_*, COAVOID_AUTH_ERR_*); a refused
 * message is counted, never returned; a failed planning call is no error of the node (it
 * keeps its plan, and its heartbeat says HEALTH_DEGRADED with the outcome).
 * node.h's file comment gives the cycle in full; docs/protocol.md the rules and states.
 */
#ifndef COAVOID_PROTOCOL_H
#define COAVOID_PROTOCOL_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "auth.h"
#include "coavoid/coavoid.h"
#include "coavoid_lcm.h"

#define COAVOID_CHANNEL_INTENT "COAVOID_INTENT"
#define COAVOID_CHANNEL_PLAN "COAVOID_PLAN"
#define COAVOID_CHANNEL_TRACK "COAVOID_TRACK"
#define COAVOID_CHANNEL_OBSTACLES "COAVOID_OBSTACLES"
#define COAVOID_CHANNEL_CONFLICTS "COAVOID_CONFLICTS"
#define COAVOID_CHANNEL_STATUS "COAVOID_STATUS"
#define COAVOID_CHANNEL_AGREEMENT "COAVOID_AGREEMENT"

/* Capacities of one node's view of the airspace. A build may set the first, second and
 * fourth lower (-D, the same for every file that includes this header): an autopilot's
 * vehicle sized for its fleet (the Cortex-M4F build sets 9, 4 and 16:
 * src/protocol/CMakeLists.txt). */
#ifndef COAVOID_NODE_MAX_PEERS
#define COAVOID_NODE_MAX_PEERS 64u /* co-operative UAVs a node tracks, itself included */
#endif
#ifndef COAVOID_NODE_MAX_TRACKS
#define COAVOID_NODE_MAX_TRACKS 32u /* non-cooperative tracks */
#endif
/* N: intent_t carries N + 1 samples, in one datagram; a build that keeps fewer samples
 * (COAVOID_LCM_MAX_SAMPLES: the Cortex-M4F build keeps 25) flies a shorter horizon. */
#define COAVOID_NODE_MAX_HORIZON ((unsigned)COAVOID_LCM_MAX_SAMPLES - 1u)
/* The largest steep factor of the UAVs a node plans (itself, and its peers in its order
 * search and joint plan): its planner's tables are sized for it. A build may set it lower
 * (2..COA_MAX_STEEP_FACTOR: the Cortex-M4F build sets 2); a vehicle configured above it is
 * refused at init, and a peer's intent above it is refused (counted). */
#ifndef COAVOID_NODE_MAX_STEEP_FACTOR
#define COAVOID_NODE_MAX_STEEP_FACTOR COA_MAX_STEEP_FACTOR
#endif
#ifndef COAVOID_NODE_MAX_CONFIGURED_OBSTACLES
#define COAVOID_NODE_MAX_CONFIGURED_OBSTACLES 80u /* a node's own terrain database */
#endif

/* The inbox budget (docs/security.md, "Floods"). A datagram whose tail and fleet tag
 * pass (coavoid_auth_precheck) costs a signature check; per cycle, a node makes at most
 * COAVOID_NODE_CHECKS_PER_VEHICLE of them for one vehicle's key on one channel (a UAV
 * sends an intent, at most 4 more when overtaken in the decoupled order, a heartbeat and
 * its answers on a few plans), COAVOID_NODE_CHECKS_PER_KEY for the coordinator's or the
 * world's (a plan row per UAV and plan; 16 map tiles and 32 tracks), and
 * COAVOID_NODE_CHECKS_PER_CYCLE in all, and drops the rest unchecked (counted, heartbeat
 * REASON_INBOX_FLOOD). So a stolen vehicle key's flood costs a receiver at most
 * COAVOID_NODE_CHECKS_PER_VEHICLE checks per channel and cycle. COAVOID_NODE_INBOX_FLOOD:
 * datagrams per cycle (refused ones included) above which a node calls its inbox flooded
 * even when it dropped nothing. */
#define COAVOID_NODE_CHECKS_PER_VEHICLE 32u
#define COAVOID_NODE_CHECKS_PER_KEY 128u
#define COAVOID_NODE_CHECKS_PER_CYCLE 4096u
#define COAVOID_NODE_INBOX_FLOOD 4096u

/* The longest duration a node may be configured with (a timeout, a wait, a resend
 * interval, the staleness of an intent): an hour, the longest dt (COAVOID_LCM_MAX_STEP),
 * so that no time a node computes from one can overflow. */
#define COAVOID_NODE_MAX_DURATION_US (INT64_C(3600) * INT64_C(1000000))

/* The world's id (map_id of the obstacle map, source_id of tracks) by default. */
#define COAVOID_NODE_WORLD_ID 65000u
#define COAVOID_NODE_COORDINATOR_ID 65001u

/* Copies of every intent a vehicle sends, and of every heartbeat the coordinator sends,
 * by default in the drivers and the simulation (intent_copies, heartbeat_copies): with
 * each receiver losing a share p of datagrams, a cycle's intent or heartbeat is lost to
 * it with p^5 rather than p: a UAV the coordinator does not hear of in cycle 0 is one its
 * first plan cannot include, and a conflict one step ahead leaves no second cycle
 * (docs/evaluation.md flies the protocol with these copies at up to 50 % loss). */
#define COAVOID_NODE_DEFAULT_COPIES 4u
/* The most copies a vehicle may be configured to send (intent_copies): a copy is a whole
 * datagram to every node, so more is a flood of its own, and the times of its copies
 * (count times resend_us) must not overflow. */
#define COAVOID_NODE_MAX_COPIES 64u

/* The joint plan of a vehicle's group when no priority order solves it (joint_members,
 * joint_beta of coavoid_vehicle_node_config_t): groups of up to this many UAVs, in the
 * drivers and the simulation, for vehicles that follow a coordinator; and the search's
 * bound on stored nodes by default, which solves the encounters that needed it in
 * docs/evaluation.md ("The coordinator stopped anywhere"; 2,000 do not solve them all). */
#define COAVOID_NODE_DEFAULT_JOINT_MEMBERS 5u
#define COAVOID_NODE_DEFAULT_JOINT_BETA 5000u

/* Work units (plan.h, "Work") a node's planner is given per microsecond of the time a
 * planning call may take: 25, a unit at 40 ns, above the dearest cost of a unit measured
 * on the host (docs/benchmarks.md, "Within a work budget"), so that a call ends within
 * its time on such a core whatever it plans. A slower processor needs fewer. */
#define COAVOID_NODE_WORK_PER_US 25u

/* The work units of `us` microseconds at COAVOID_NODE_WORK_PER_US, at least 1 (a budget
 * of 0 sets no limit) and at most UINT64_MAX. O(1). */
uint64_t coavoid_node_work_of(int64_t us);

typedef enum {
    COAVOID_NODE_CENTRALISED = 0, /* follow the coordinator; plan for itself when it is silent */
    COAVOID_NODE_DECOUPLED = 1    /* always plan for itself in priority order */
} coavoid_node_mode_t;

/* What every node shares. */
typedef struct {
    int64_t epoch_utime;  /* cycle 0 starts here; > 0 */
    coa_real_t dt;        /* s, > 0: the scenario's dt */
    int64_t dt_us;        /* llround(dt * 1e6), >= 1 */
    uint32_t horizon;     /* N, 1..COAVOID_NODE_MAX_HORIZON */
    const int64_t *clock; /* the driver's current utime, read by the message handlers */
    /* Optional: a monotonic microsecond reader used only to measure how long planning
     * took (status_t.last_plan_duration_us). NULL in simulation, where durations are 0 so
     * that a run's output is repeatable. */
    int64_t (*stopwatch_us)(void *user);
    void *stopwatch_user;
    /* Prediction: threshold and sigma growth per second of look-ahead (m/s), as
     * coavoid predict; and the growth of a silent UAV's sigma per second since its last
     * intent. */
    double threshold;
    coa_real_t vehicle_sigma_rate_horizontal;
    coa_real_t vehicle_sigma_rate_vertical;
    coa_real_t track_sigma_rate_horizontal;
    coa_real_t track_sigma_rate_vertical;
    coa_real_t stale_sigma_rate;
    int64_t stale_after_us; /* peer intent older than this: a track (default 2.5 dt) */
    uint32_t beta;          /* closed-set bound of the node's planner */
    /* The obstacles the node was configured with (its terrain database; the caller's,
     * outliving the node; none by default), at most COAVOID_NODE_MAX_CONFIGURED_OBSTACLES.
     * They are always part of what it avoids and checks: an obstacle map received adds
     * its obstacles to them and never removes one, so a forged or stale map cannot take
     * terrain away. */
    const coa_obstacle_t *obstacles;
    size_t obstacle_count;
    /* The floor (the scenario's min_altitude; plan.h, "Floor"): with has_floor, every plan
     * the node makes keeps each UAV's protected volume at or above min_altitude (m, finite,
     * within COAVOID_LCM_MAX_COORDINATE) at every sample, and a vehicle refuses a plan
     * that would take it below (COAVOID_LCM_ERR_VALUE). false (the default): none. */
    bool has_floor;
    coa_real_t min_altitude;
    /* Signed messages (auth.h, docs/messages.md): the key it signs everything it publishes
     * with, and the keys it accepts messages from, each with its role. Both the caller's,
     * copied at create. Unless `insecure`, both are required (the world, which receives
     * nothing, needs no trust list), and a message is accepted only when signed by a key
     * of the trust list whose role may send it, and fresh (coavoid_auth_fresh per key and
     * message type, within the validation window): the per-sender sequence rule is then
     * the signature's. `insecure`: it neither signs (auth all zero) nor checks, accepts
     * what validates as before, and every heartbeat says so (REASON_INSECURE, so
     * HEALTH_DEGRADED): for a one-process simulation and tests, never for flight. */
    const coavoid_auth_signer_t *signer;
    const coavoid_auth_trust_t *trust;
    bool insecure;
    /* Datagrams the transport dropped before any handler saw them, since start (the
     * realtime receiver's count of drops at its socket), read at each heartbeat; NULL:
     * none known. They count as dropped unchecked (messages_dropped, REASON_INBOX_FLOOD). */
    const uint64_t *transport_dropped;
} coavoid_node_common_t;

/* Fills c with the defaults for (epoch, dt, horizon, clock): threshold 0.01, no sigma
 * growth, stale_after 2.5 cycles, stale_sigma_rate 1 m/s, beta 20000, no
 * transport_dropped, no keys and not insecure (so a node is not created until the caller
 * sets keys or insecure). Returns COA_OK or COA_ERR_ARGUMENT (dt, horizon, epoch or clock
 * invalid). */
int coavoid_node_common_defaults(coavoid_node_common_t *c, int64_t epoch_utime, coa_real_t dt,
                                 uint32_t horizon, const int64_t *clock);

/* utime of cycle k's start, and the cycle a time falls in (floor; negative before epoch). */
int64_t coavoid_node_cycle_utime(const coavoid_node_common_t *c, int64_t k);
int64_t coavoid_node_cycle_of(const coavoid_node_common_t *c, int64_t utime);

/* ---- vehicle ---- */

/* Problems whose joint search (joint_members) found no plan, so that vehicles that search
 * alike need not search one again. A vehicle on its own needs none: it skips a problem it
 * failed on earlier in the cycle by itself. The simulation flies every member of a group
 * in one process, and each searches the group's same problem; a sweep of coordinator
 * stops flies an encounter again and again from the same start: one memo shared by them
 * turns those repeats into look-ups (the search is deterministic, so the flight is the
 * same). Keys are 64-bit digests of the problem and the search's bound: exact up to a
 * collision (2^-64 a pair). The caller owns the keys (capacity, a power of two); once
 * half of them are used it remembers nothing more (still exact, only slower). Not
 * thread-safe: one memo a thread. */
typedef struct {
    uint64_t *keys;  /* 0: an empty slot */
    size_t capacity; /* a power of two, or 0: remembers nothing */
    size_t count;
} coavoid_node_joint_memo_t;

/* Empties memo over keys[0..capacity-1]. COA_ERR_ARGUMENT (memo left remembering nothing)
 * when capacity is neither 0 nor a power of two, or keys is NULL with capacity > 0.
 * O(capacity). */
int coavoid_node_joint_memo_init(coavoid_node_joint_memo_t *memo, uint64_t *keys, size_t capacity);
/* Whether memo (NULL: none) holds key, and adds it (nothing once half full). Expected
 * O(1): linear probing in a table at most half full. */
bool coavoid_node_joint_memo_has(const coavoid_node_joint_memo_t *memo, uint64_t key);
void coavoid_node_joint_memo_add(coavoid_node_joint_memo_t *memo, uint64_t key);

typedef struct {
    coavoid_node_common_t common;
    coa_vehicle_t vehicle; /* its route is the caller's and must outlive the node */
    coavoid_node_mode_t mode;
    int64_t coordinator_timeout_us; /* heartbeat silence before it plans for itself (0: the
                                       default, 2.5 dt) */
    int64_t priority_wait_us;       /* bounded wait for higher-priority intents (0: the
                                       default, dt / 2) */
    coa_real_t sigma_horizontal;    /* its own position uncertainty, published (default 0) */
    coa_real_t sigma_vertical;
    uint16_t coordinator_id; /* the only node whose heartbeats and plans it follows
                                       (0: the default, COAVOID_NODE_COORDINATOR_ID); not its
                                       own id */
    /* Against loss (docs/protocol.md): every intent it publishes goes out again
     * intent_copies times (freshly stamped), resend_us apart, and so does its SWITCHED
     * when it switches to a committed plan (resend_us 0: the default, dt / 40;
     * intent_copies 0: none, which is also the default). */
    int64_t resend_us;
    uint32_t intent_copies;
    /* Deciding for itself: negotiate the order by the greedy raise alone, without the search
     * of the order (docs/protocol.md, "Priority negotiation"): no search's cost, and the
     * negotiation of a fleet without it. false (the default): search. */
    bool greedy_negotiation;
    /* Following the coordinator, how long into a cycle it waits for an answer to a
     * conflict of its own (a plan committed; one saying the search failed is none by
     * then) before it plans for itself within that cycle, or commits a plan every UAV of
     * it accepted (docs/protocol.md, "The answer wait"). 0: the default, dt / 2 + 4
     * resend_us: the coordinator plans at dt / 4, gives its UAVs dt / 4 to accept, and
     * sends its ABORT with four copies. */
    int64_t answer_wait_us;
    /* Deciding for itself, when its order search finds that no priority order solves its
     * group (docs/protocol.md, "Priority negotiation", step 5): it plans the group jointly,
     * as a coordinator would, in one search of at most joint_beta stored nodes, when the
     * group has at most joint_members UAVs. Every member does the same from the same
     * intents, so all find the same rows without a message: every vehicle of a fleet must
     * have the same two values, as it has the same dt and horizon (the drivers and the
     * simulation: coavoid_node_joint_members). joint_members 0 (the default): never; else
     * 2..COA_MAX_CENTRALISED, and its planner is one for a joint search of that many UAVs
     * (docs/benchmarks.md has the bytes). joint_beta 0: COAVOID_NODE_DEFAULT_JOINT_BETA. */
    size_t joint_members;
    uint32_t joint_beta;
    /* The work budget of that search (plan.h, "Work"), so that it ends within its time
     * like the rest of the cycle; the same on every vehicle of a fleet, like joint_beta
     * (a search stopped by it answers the same everywhere). 0: the default,
     * coavoid_node_work_of(dt / 4). */
    uint64_t joint_work;
    /* NULL, or a memo of failed joint searches shared with vehicles that search alike
     * (coavoid_node_joint_memo_t: the simulation's; the same joint_beta and joint_work on
     * each); not owned, and it must outlive the node. */
    coavoid_node_joint_memo_t *joint_memo;
} coavoid_vehicle_node_config_t;

/* The vehicle's state machines (docs/protocol.md, "Vehicle", where both are drawn from
 * their tables in vehicle_states.c). Two, because they are independent: a plan of the
 * coordinator's may be held, switched to or dropped whatever the vehicle is deciding.
 *
 * Its phase: who decides the cycle, and how far it is. Entered at every cycle's start as
 * FOLLOWING (it follows the coordinator) or DECIDING (fallback, or decoupled). */
typedef enum {
    COAVOID_VEHICLE_IDLE = 0,         /* before its first cycle */
    COAVOID_VEHICLE_FOLLOWING,        /* follows the coordinator; the answer wait is ahead */
    COAVOID_VEHICLE_FOLLOWED,         /* ... past the answer wait, nothing of its own to do */
    COAVOID_VEHICLE_DECIDING,         /* decides for itself; waits for the UAVs before it */
    COAVOID_VEHICLE_GATHERING,        /* ... first cycle: waits for the first intents' copies */
    COAVOID_VEHICLE_DECIDED,          /* ... decided and published */
    COAVOID_VEHICLE_ANSWERING,        /* unanswered at the answer wait: decides, waits */
    COAVOID_VEHICLE_ANSWER_GATHERING, /* ... first cycle: waits for the first intents' copies */
    COAVOID_VEHICLE_ANSWERED          /* ... decided and published */
} coavoid_vehicle_phase_t;
#define COAVOID_VEHICLE_PHASES 9u

/* Its coordinator's plans of this cycle (docs/protocol.md, "One plan (at a vehicle of it)").
 * NONE again at every cycle's start: a plan held then is dropped, in doubt. */
typedef enum {
    COAVOID_VEHICLE_PLAN_NONE = 0,        /* no plan of the cycle held or flown */
    COAVOID_VEHICLE_PLAN_HOLDING,         /* holds an accepted plan, undecided */
    COAVOID_VEHICLE_PLAN_STANDBY,         /* ... and flies a standby unless it is committed */
    COAVOID_VEHICLE_PLAN_ON_STANDBY,      /* the held plan aborted: flies the standby */
    COAVOID_VEHICLE_PLAN_SWITCHED,        /* flies a plan of the cycle (committed) */
    COAVOID_VEHICLE_PLAN_SWITCHED_HOLDING /* ... and holds a newer one, undecided */
} coavoid_vehicle_plan_t;
#define COAVOID_VEHICLE_PLAN_STATES 6u

/* What moves them: each event is allowed in some states only (vehicle_states.c), and one
 * in any other is a fault of the node (state.protocol_faults, heartbeat INTERNAL_ERROR)
 * that leaves the state as it was. */
typedef enum {
    /* the phase */
    COAVOID_VEHICLE_EVENT_FOLLOW = 0,  /* a cycle starts, following the coordinator */
    COAVOID_VEHICLE_EVENT_DECIDE,      /* a cycle starts, deciding for itself */
    COAVOID_VEHICLE_EVENT_WAIT,        /* UAVs before it may still publish: it waits */
    COAVOID_VEHICLE_EVENT_GATHER,      /* no plan below them while the first intents gather */
    COAVOID_VEHICLE_EVENT_PUBLISH,     /* its intent of the cycle is published */
    COAVOID_VEHICLE_EVENT_REDECIDE,    /* overtaken, or the world grew: it decides again */
    COAVOID_VEHICLE_EVENT_ANSWER_WAIT, /* the answer wait passes while it follows */
    COAVOID_VEHICLE_EVENT_UNANSWERED,  /* ... a conflict of its own and no plan: it decides */
    COAVOID_VEHICLE_EVENT_STANDBY,     /* ... it holds an undecided plan: it plans a standby */
    COAVOID_VEHICLE_EVENT_SELF_COMMIT, /* it commits the plan it holds itself */
    /* its coordinator's plans */
    COAVOID_VEHICLE_EVENT_ACCEPT, /* a whole plan for it checked: ACCEPT, and held */
    COAVOID_VEHICLE_EVENT_COMMIT, /* COMMIT, a sibling's SWITCHED, or its own self-commit */
    COAVOID_VEHICLE_EVENT_ABORT,  /* ABORT of the plan it holds */
    COAVOID_VEHICLE_EVENT_CYCLE   /* the next cycle starts */
} coavoid_vehicle_event_t;
#define COAVOID_VEHICLE_EVENTS 14u

/* The state a phase or plan state goes to on `event`; COAVOID_VEHICLE_PHASES (or
 * COAVOID_VEHICLE_PLAN_STATES) when the event is not allowed there, or for an event of
 * the other machine. O(1). */
coavoid_vehicle_phase_t coavoid_vehicle_phase_next(coavoid_vehicle_phase_t from,
                                                   coavoid_vehicle_event_t event);
coavoid_vehicle_plan_t coavoid_vehicle_plan_next(coavoid_vehicle_plan_t from,
                                                 coavoid_vehicle_event_t event);

/* Names, for logs and the drawing in docs/protocol.md ("?" when out of range). O(1). */
const char *coavoid_vehicle_phase_name(coavoid_vehicle_phase_t phase);
const char *coavoid_vehicle_plan_name(coavoid_vehicle_plan_t plan);
const char *coavoid_vehicle_event_name(coavoid_vehicle_event_t event);

/* What a vehicle did; read by drivers, the simulation and tests. */
typedef struct {
    coavoid_vehicle_phase_t phase; /* its state machines, as they stand */
    coavoid_vehicle_plan_t plan;
    uint32_t protocol_faults; /* events its machines did not allow, since start (0) */
    int64_t cycle;            /* the current cycle k (-1 before the first) */
    int32_t offset;           /* offset flown at sample k */
    coa_vec3_t reference;     /* reference at t_k */
    coa_vec3_t position;      /* reference + offset * dh: where it is */
    bool coordinated;         /* following the coordinator this cycle */
    bool waiting;             /* decoupled: still waiting for higher priorities */
    bool published;           /* published its intent for this cycle */
    uint32_t plans_run;       /* its own planning calls since start */
    uint32_t plans_adopted;   /* plans adopted (own and coordinator's) */
    int last_outcome;         /* coa_plan_status_t of its last call, -1 none */
    uint64_t last_nodes_expanded;
    int64_t last_plan_duration_us; /* measured by the driver's clock: 0 in simulation */
    uint32_t conflicts;            /* conflicts in its last prediction */
    uint32_t fallbacks;            /* switches from coordinated to own planning */
    uint32_t plans_accepted;       /* coordinator's plans it accepted (docs/protocol.md) */
    uint32_t plans_refused;        /* ... it refused (a REFUSE answer) */
    uint32_t plans_switched;       /* ... it switched to on a commit (or a sibling's word) */
    uint32_t plans_aborted;        /* ... accepted, then aborted by the coordinator */
    uint32_t plans_in_doubt;       /* ... accepted, and no decision came within the cycle */
    uint32_t plans_self_committed; /* ... switched to at the answer wait, every UAV of it
                                      heard accepting and no decision come (coordinator
                                      stopped): docs/protocol.md */
    uint32_t plans_standby;        /* ... held undecided at the answer wait, and in doubt
                                      at the cycle's end: it flew its standby instead */
    /* Its precedence in the decoupled order, announced in its intents (0..
     * COAVOID_INTENT_T_MAX_RANK; docs/protocol.md, "Priority negotiation"), and how many
     * times it raised it since start. */
    int32_t rank;
    uint32_t rank_raises;
    /* Times its order search found a new order for its cluster and it took its place in
     * it (docs/protocol.md, "Priority negotiation"). */
    uint32_t orders_agreed;
    /* Of those, the times no order solved and it flew its row of the group's joint plan
     * (joint_members). */
    uint32_t joint_plans;
    coavoid_lcm_rx_stats_t rx;
} coavoid_vehicle_node_state_t;

typedef struct coavoid_vehicle_node coavoid_vehicle_node_t;

/* The planner config of a node planning `searched` UAVs at once over a horizon of N
 * steps: any UAV an intent may describe (steep factor up to COA_MAX_STEEP_FACTOR, offsets
 * unbounded), so that no valid intent meets a planner too small for it. */
coa_planner_config_t coavoid_node_planner_config(uint32_t horizon, size_t searched, uint32_t beta);

/* The joint_members the drivers and the simulation give every vehicle of a fleet of
 * `fleet` UAVs flying `mode`: following a coordinator, up to
 * COAVOID_NODE_DEFAULT_JOINT_MEMBERS and no more than the fleet (0 below 2 UAVs); in
 * decoupled mode 0, the paper's decoupled planning. O(1). */
size_t coavoid_node_joint_members(coavoid_node_mode_t mode, size_t fleet);

/* Where a node's datagrams go: send(user, channel, data, size) hands one signed, encoded
 * message (at most COAVOID_LCM_MAX_DATAGRAM_BYTES) to the transport and returns COA_OK,
 * or a negative error when the transport refused it. A node calls it from its cycle,
 * poll and receive functions, never from anywhere else. The drivers' and the
 * simulation's is LCM's (coavoid_vehicle_node_create); a firmware's is its own link. */
typedef struct {
    int (*send)(void *user, const char *channel, const uint8_t *data, size_t size);
    void *user;
} coavoid_node_link_t;

/* The bytes coavoid_vehicle_node_init needs for config: the node's tables, the conflicts
 * for N, and one workspace for the larger of the predictor for N and the planner (they
 * take turns in it) of coavoid_node_planner_config(N + 2, 1, beta)
 * (the order search looks two steps beyond the horizon; a one-UAV planner's size does not
 * depend on beta), or with joint_members that of coavoid_node_planner_config(N + 2,
 * joint_members, joint_beta), which also runs its one-UAV searches. The order search's
 * share is each peer's intent of the cycle before, kept in the inbox (a coordinator's
 * holds it too), and its problem's UAVs, references and rows, fixed like the rest
 * (docs/benchmarks.md has the sizes). 0 for a configuration init refuses. O(1). */
size_t coavoid_vehicle_node_size(const coavoid_vehicle_node_config_t *config);

/* Builds a vehicle node in memory (the caller's, aligned to COA_WORKSPACE_ALIGNMENT, at
 * least coavoid_vehicle_node_size(config) bytes, not moved while the node lives) that
 * sends through link (copied; its user outlives the node). Returns the node (at memory),
 * or NULL with *error (error may be NULL): COA_ERR_ARGUMENT for a bad config (invalid
 * vehicle, a duration beyond COAVOID_NODE_MAX_DURATION_US, intent_copies beyond
 * COAVOID_NODE_MAX_COPIES, horizon > COAVOID_NODE_MAX_HORIZON, joint_members 1 or above
 * COA_MAX_CENTRALISED, no trust list unless insecure, ...) or link, COA_ERR_WORKSPACE
 * for memory that is NULL, misaligned or too small. Nothing is allocated, now or later.
 * Cost: O(size) (it zeroes the node). */
coavoid_vehicle_node_t *coavoid_vehicle_node_init(void *memory, size_t size,
                                                  const coavoid_vehicle_node_config_t *config,
                                                  const coavoid_node_link_t *link, int *error);

/* Zeroes the node's copy of its signing key; the caller then frees the memory. NULL is
 * fine. O(1). */
void coavoid_vehicle_node_fini(coavoid_vehicle_node_t *node);

/* The channels the node takes in, i = 0..COAVOID_NODE_CHANNELS - 1: the name of the i-th
 * when it takes it in, else NULL (a decoupled vehicle takes no plans, agreements or
 * heartbeats). What a transport subscribes to, or a firmware forwards from its link.
 * O(1). */
#define COAVOID_NODE_CHANNELS 6u
const char *coavoid_vehicle_node_channel(const coavoid_vehicle_node_t *node, size_t i);

/* One datagram as it arrived on `channel` (COAVOID_CHANNEL_*), at the time of the common
 * clock: checked, decoded, validated and stored, or counted as refused (node.h's file
 * comment). A whole plan is decided on, and answered, at once. Returns COA_OK when the
 * node takes the channel in (whatever became of the datagram), COA_ERR_ARGUMENT for a
 * channel it does not or a NULL argument. Cost: at most one signature verification and
 * the message's decoding and validation, and for a whole plan its check (one
 * coa_plan_find_conflict); no memory. */
int coavoid_vehicle_node_receive(coavoid_vehicle_node_t *node, const char *channel,
                                 const void *data, size_t size);

/* Starts cycle k = coavoid_node_cycle_of(now): flies to sample k, then step 2 of the file
 * comment. Calling it again within the same cycle (or an earlier one) does nothing.
 * Returns COA_OK or a negative error (COA_ERR_ARGUMENT: NULL, now before the epoch, or an
 * intent it cannot publish; a publishing or internal error); it publishes its intent and
 * heartbeat even then, when it can. Cost: O(N + route) to fly; after a coordinated cycle
 * without an adopted plan, one prediction over its peers, tracks and obstacles
 * (coa_predict); decoupled, one more and at most two one-UAV searches of beta
 * expansions, and (without greedy_negotiation) the order search: two predictions, and with a
 * conflict near it one decoupled plan of at most 8 UAVs, or when the order fails at most
 * 120 orders of at most 8 one-UAV searches each, over N and, when one solves, once more
 * over N + 2 (the look-ahead). No memory is allocated. */
int coavoid_vehicle_node_cycle(coavoid_vehicle_node_t *node, int64_t now);

/* Completes a decoupled wait once its condition holds at `now` (the intents arrived, or
 * priority_wait_us has passed since the cycle began). After a decoupled vehicle has
 * published, it decides again (and publishes again) when a UAV with a raised rank now
 * comes before it with an intent of this cycle it did not decide on (docs/protocol.md,
 * "Priority negotiation"), at most 4 times a cycle, and it searches the order again when
 * a UAV's first intent came after its last search (flying its row, or deciding again,
 * only when that changes the order it agreed): call it whenever messages arrive, not only
 * while it waits. Returns 1 when it planned and published, 0 when there was
 * nothing to do or it still waits, negative on error. Cost while waiting: one
 * prediction (it looks again with the intents that came); then as
 * coavoid_vehicle_node_cycle; otherwise O(peers^2) to find it has nothing to do. No
 * memory. */
int coavoid_vehicle_node_poll(coavoid_vehicle_node_t *node, int64_t now);

/* The utime by which poll must be called again (the end of a wait), or INT64_MAX. O(1). */
int64_t coavoid_vehicle_node_deadline(const coavoid_vehicle_node_t *node);

const coavoid_vehicle_node_state_t *coavoid_vehicle_node_state(const coavoid_vehicle_node_t *node);

#endif /* COAVOID_PROTOCOL_H */
