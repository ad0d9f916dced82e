/* SPDX-License-Identifier: MIT */
/*
 * node.h: the coavoid nodes (a UAV, the ground coordinator, and the "world" that stands
 * in for the terrain database and the tracker), written once and driven two ways:
 *   - in real time over UDP multicast by apps/vehicle, apps/coordinator and
 *     `coavoid world` (src/realtime/realtime.h), one process each;
 *   - deterministically in one process over LCM's memq provider by `coavoid sim`, which
 *     calls the same functions at simulated times.
 * A node never reads a clock: every call takes the time (utime, microseconds), and the
 * message handlers read the driver's clock through the pointer given at init. So a
 * simulation is repeatable bit for bit, and a real-time run is the same code.
 *
 * Time. All nodes share an epoch and the scenario's dt: cycle k starts at
 *     cycle_utime(k) = epoch_utime + k * dt_us,   dt_us = llround(dt * 1e6),
 * which is scenario time t_k = k * dt (a UAV's reference is sampled at k * dt exactly).
 *
 * One cycle (the closed loop of docs/scenario-format.md, "Simulation result"):
 *   1. At cycle_utime(k) the world publishes every tile of the obstacle map and every
 *      track's estimate (in real time a quarter cycle ahead, so that they are there when
 *      the UAVs decide). Every message fits one datagram (COAVOID_LCM_MAX_DATAGRAM_BYTES,
 *      docs/messages.md): a map is tiles, a plan one message per UAV.
 *   2. At cycle_utime(k) every UAV steps its simulated flight to sample k (the offset its
 *      adopted plan gives for k; a plan past its end holds its last offset).
 *      - centralised (a heartbeat of its coordinator heard within
 *        coordinator_timeout_us, or still inside that time since start, and the
 *        coordinator not found wanting, below): it publishes its intent at once
 *        (reference and offsets for samples k..k+N) and follows the coordinator. Its
 *        coordinator is the node id it is configured with: heartbeats of a coordinator
 *        and plans from any other id are refused (COAVOID_LCM_ERR_ID), and a heartbeat with
 *        HEALTH_FAULT does not count. A heartbeat alone does not keep a UAV safe (plans
 *        that come late, an impostor): so at the start of cycle k + 1, a UAV that
 *        followed the coordinator in cycle k and got no answer from it there (it adopted
 *        none of its plans, and no plan for it came in time saying the search failed:
 *        the coordinator tried, and planning alone would not do better) runs its own
 *        prediction (as decoupled, without waiting: its intent of k + 1 and its peers'
 *        latest). When it has a conflict of its own that begins within cycle k's horizon
 *        (first step < N - 1 on the new clock; one that only now enters the horizon is
 *        the coordinator's to plan in k + 1), it plans for itself as in decoupled mode
 *        in cycle k + 1 (counted in fallbacks), and follows again from cycle k + 2 if it
 *        has heard the coordinator since (one unanswered cycle, a lost answer, must not
 *        keep it out of the coordinator's plans: the coordinator plans no UAV whose
 *        intent says it plans for itself);
 *      - decoupled: first it waits (until priority_wait_us has passed) for this cycle's
 *        intents of the higher-priority UAVs whose paths pass near its own horizontally
 *        within the horizon (the predictor's test with unbounded heights): only their
 *        new plans can bring it a conflict it cannot see yet, since a UAV changes only
 *        its altitude. So it decides on what they decided this cycle, whatever the order
 *        in which the processes run, as in the simulation. Then it predicts over samples
 *        k..k+N with its own plan and its peers' latest intents. With no conflict in its
 *        cluster (coa_predict_clusters over its view) it publishes its intent at once.
 *        Otherwise it waits until every higher-priority UAV of its cluster has published
 *        an intent for this cycle (plan_utime == cycle_utime(k)), or until
 *        priority_wait_us has passed, then plans for itself alone (one-UAV A*) against
 *        obstacles, tracks and the intents of every UAV that is not a lower-priority
 *        member of its cluster (as moving obstacles, in the planner's track form), adopts
 *        the plan when solved, and publishes its intent.
 *        So a cluster plans in priority order, as coa_plan_decoupled does: every member
 *        plans, the highest priority too when its only conflicts are with lower ones
 *        (ignoring them, it returns towards its reference where it can: an offset it
 *        merely kept could leave a lower priority no way out). When that search fails
 *        and lower-priority UAVs outside its cluster were in it, it searches again
 *        around the higher priorities only (coa_plan_decoupled's rule), and the others
 *        plan around it in turn.
 *        Before all this (unless configured with greedy_negotiation), the order search
 *        (its group leaves out every UAV whose intent says it follows a coordinator):
 *        from the intents as they stood when the cycle began (each UAV's last of
 *        cycle k - 1, or in its first cycle its first intent with the offset it starts
 *        at held; its own included), it predicts, and when its group of UAVs that pass
 *        near each other has a conflict it plans that group as coa_plan_decoupled does,
 *        first in the order the ranks announce. Only when that order fails does it try
 *        the others (at most 120), and when one solves it flies its own row of that
 *        plan and announces its place in the order as its rank (docs/protocol.md,
 *        "Priority negotiation", "The first cycle"). Every member has the same inputs
 *        when nothing was lost, so each finds the same order and rows by itself;
 *        otherwise the ranks announced and the greedy raise settle the order.
 *   3. At cycle_utime(k) + collect_us the coordinator predicts over samples k..k+N from the
 *      intents for this cycle, plans each conflicting cluster (of the UAVs whose intent
 *      says they follow it: one that plans for itself is a moving obstacle, since the
 *      others' plans must not rely on a move it will not make) in one centralised search
 *      (decoupled, in the coordinator, for a cluster larger than its workspace holds, or
 *      when the composite search runs out of beta before proving anything),
 *      clusters in ascending order, each later cluster treating the new plans of the
 *      earlier ones as moving obstacles; publishes one plan per cluster (valid_from =
 *      cycle_utime(k), valid_until = cycle_utime(k + 1)) as one plan_t per UAV of the
 *      cluster, back to back (each with the plan's header, its UAV list and that UAV's
 *      row), the conflict report, and its heartbeat. Past its planning budget
 *      (plan_budget_us) a cluster is abandoned instead: a plan with STATUS_ABANDONED
 *      lists its UAVs (a message to each, no rows), which are not answered by it and plan
 *      for themselves. A cluster is only who conflicts now, and its way out can be blocked by
 *      UAVs that do not (a UAV that must climb over terrain into the altitude of passing
 *      traffic): when a cluster's plan fails, every clustered UAV is planned again as one
 *      group, and failing that every UAV, from the intents as they came; that plan_t
 *      (a newer plan_id) supersedes the cycle's earlier ones for its UAVs.
 *   4. A UAV collects the messages of each plan (every plan, for it or not) and decides on
 *      a plan only once it holds the row of every UAV the plan lists: a plan missing a row
 *      is never adopted, nor refused (it did not come: the UAV is unanswered, above), and
 *      a message that disagrees with the rest of its plan is refused. Adopting is agreed
 *      on (docs/protocol.md, agreement_t on COAVOID_AGREEMENT): the UAV answers ACCEPT
 *      and holds its row; it flies it only on the coordinator's COMMIT (sent once every
 *      UAV of the plan accepted) or a sibling's SWITCHED, answering SWITCHED; an ABORT,
 *      or no decision by the cycle's end, and it flies on as before; a plan it refuses it
 *      answers REFUSE (the coordinator then plans the others again, coavoid_coordinator_poll).
 *      Answers go out with intent_copies copies, and again on any row of the plan sent
 *      again. It accepts a whole plan that lists it among the planned rows, is solved, arrives
 *      before valid_until, has valid_from == the current cycle's start, has a plan_id
 *      greater than that of any plan it adopted in this cycle (so that a later plan of
 *      the cycle supersedes), starts at the offset the UAV flies now, and over this
 *      cycle's samples k..k+N runs into none of the obstacles and tracks (silent UAVs
 *      included) the UAV knows, nor into any other live UAV, taken on its row of this
 *      cycle's latest solved plan that lists it (what it will fly) or else on its
 *      latest intent (coa_plan_find_conflict: a coordinator may know less terrain, or
 *      be an impostor); anything else is not adopted (counted in status as rejected
 *      with the reason). Its own plans get the same check against what their search
 *      avoided before they are flown (one that fails is a planner bug: not flown, and
 *      the heartbeat says HEALTH_FAULT). Plan ids are not compared across cycles: valid_from
 *      already ties a plan to its cycle, and a rule across cycles would let one forged
 *      plan_id INT64_MAX, or a coordinator restarted with its numbering at 0, lock every
 *      later plan out.
 * Every node publishes its heartbeat (status_t) once per cycle; the world, a stand-in for
 * external sources that status_t has no kind for, does not. Its health is HEALTH_FAULT
 * after an internal error (a UAV: also while another UAV uses its id), else
 * HEALTH_DEGRADED when messages were refused since its previous heartbeat (a clock that
 * disagrees, more peers than it holds, a bad sender), a planning call failed, a peer is
 * stale, no obstacle map has arrived, or (a UAV) it is not following the coordinator
 * while centralised, it refused a plan for it in its last cycle, or a conflict of its own
 * went unanswered; else HEALTH_OK. The heartbeat's reasons field names each of these
 * (status_t's REASON_* bits).
 *
 * A peer whose last intent is older than stale_after_us is no longer a co-operative UAV
 * to its receivers: they treat it as a non-cooperative track along the last plan it
 * announced (its intent's positions at their own times, then the velocity of the plan's
 * last leg; constant velocity from its last state if that intent no longer converts),
 * with its sigma grown by stale_sigma_rate * age (the predictor then grows it further
 * with look-ahead): a UAV that has gone silent most likely flies what it said.
 *
 * Messages arrive through LCM subscriptions made at init; each is verified (its signature
 * over the raw bytes, then its key's role and freshness: common.trust, auth.h), decoded
 * and validated (src/lcm) with the driver's clock, counted, and stored (the latest intent
 * per UAV, per track, the obstacle map, the coordinator's heartbeat). A map's tiles are
 * assembled per version, and a version replaces the map in use only once every one of its
 * tiles has come (a half map never replaces a whole one; the configured obstacles always
 * stay); a refused message is counted in
 * the node's status and otherwise ignored, never fatal. A node's own messages come back
 * to it and are not counted; but an intent with a UAV's own id that it did not publish
 * (not byte for byte one of its latest) is another UAV using the same id: refused
 * (COAVOID_LCM_ERR_ID), and the UAV's next heartbeat says HEALTH_FAULT.
 *
 * Memory: a node is one struct of fixed size plus the planner and predictor workspaces,
 * allocated once by init and released by fini: nothing is allocated per cycle.
 * Errors: negative codes (COA_ERR_*, COAVOID_LCM_ERR_*); a failed planning call is not an
 * error of the node (it keeps its plan, reports HEALTH_DEGRADED and the outcome).
 */
#ifndef COAVOID_NODE_H
#define COAVOID_NODE_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include <lcm/lcm.h>

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

/* Capacities of one node's view of the airspace. */
#define COAVOID_NODE_MAX_PEERS 64u   /* co-operative UAVs a node tracks, itself included */
#define COAVOID_NODE_MAX_TRACKS 32u  /* non-cooperative tracks */
#define COAVOID_NODE_MAX_HORIZON 40u /* N: intent_t carries N + 1 samples, in one datagram */
#define COAVOID_NODE_MAX_CONFIGURED_OBSTACLES 80u /* a node's own terrain database */

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

/* The world's id (map_id of the obstacle map, source_id of tracks) by default. */
#define COAVOID_NODE_WORLD_ID 65000u
#define COAVOID_NODE_COORDINATOR_ID 65001u

/* Copies of every intent a vehicle sends, and of every heartbeat the coordinator sends,
 * by default in the drivers and the simulation (intent_copies, heartbeat_copies): with
 * each receiver losing a share p of datagrams, a cycle's intent or heartbeat is lost to
 * it with p^5 rather than p: a UAV the coordinator does not hear of in cycle 0 is one its
 * first plan cannot include, and a conflict one step ahead leaves no second cycle
 * (docs/evaluation.md measures the count). */
#define COAVOID_NODE_DEFAULT_COPIES 4u

/* The joint plan of a vehicle's group when no priority order solves it (joint_members,
 * joint_beta of coavoid_vehicle_node_config_t): groups of up to this many UAVs, in the
 * drivers and the simulation, for vehicles that follow a coordinator; and the search's
 * bound on stored nodes by default, which solves the encounters that needed it in
 * docs/evaluation.md ("The sweep with the group's joint plan"; 2,000 do not solve all). */
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
    /* Where the node subscribes (the caller's, outliving the node), or NULL (the default):
     * the lcm it publishes on, as every driver has it. A simulation of a lossy network
     * gives each node its own, and decides itself which messages reach it and when
     * (src/sim); the node's code is the same either way. */
    lcm_t *rx_lcm;
    /* Datagrams the transport dropped before any handler saw them, since start (the
     * realtime receiver's count of drops at its socket), read at each heartbeat; NULL:
     * none known. They count as dropped unchecked (messages_dropped, REASON_INBOX_FLOOD). */
    const uint64_t *transport_dropped;
} coavoid_node_common_t;

/* Fills c with the defaults for (epoch, dt, horizon, clock): threshold 0.01, no sigma
 * growth, stale_after 2.5 cycles, stale_sigma_rate 1 m/s, beta 20000, no rx_lcm, no
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
     * negotiation as it was before the search. false (the default): search. */
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

/* What a vehicle did; read by drivers, the simulation and tests. */
typedef struct {
    int64_t cycle;          /* the current cycle k (-1 before the first) */
    int32_t offset;         /* offset flown at sample k */
    coa_vec3_t reference;   /* reference at t_k */
    coa_vec3_t position;    /* reference + offset * dh: where it is */
    bool coordinated;       /* following the coordinator this cycle */
    bool waiting;           /* decoupled: still waiting for higher priorities */
    bool published;         /* published its intent for this cycle */
    uint32_t plans_run;     /* its own planning calls since start */
    uint32_t plans_adopted; /* plans adopted (own and coordinator's) */
    int last_outcome;       /* coa_plan_status_t of its last call, -1 none */
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

/* Creates a vehicle node publishing and subscribing on lcm (not owned). Allocates the node,
 * its planner and its predictor once: the node's tables, the predictor and conflicts for
 * N, and the workspace of coavoid_node_planner_config(N + 2, 1, beta) (the order search
 * looks two steps beyond the horizon; a one-UAV planner's size does not depend on beta),
 * or with joint_members that of coavoid_node_planner_config(N + 2, joint_members,
 * joint_beta), which also runs its one-UAV searches. The order search's share is each
 * peer's intent of the cycle before, kept in the inbox (a coordinator's holds it too), and
 * its problem's UAVs, references and rows, fixed like the rest (docs/benchmarks.md has the
 * sizes). Returns NULL on bad config (invalid vehicle, horizon > COAVOID_NODE_MAX_HORIZON,
 * joint_members 1 or above COA_MAX_CENTRALISED, ...: COA_ERR_ARGUMENT, also when LCM
 * refuses a subscription) or out of memory (COA_ERR_WORKSPACE), with *error set (error may
 * be NULL). */
coavoid_vehicle_node_t *coavoid_vehicle_node_create(const coavoid_vehicle_node_config_t *config,
                                                    lcm_t *lcm, int *error);
/* Unsubscribes and frees. NULL is fine. */
void coavoid_vehicle_node_destroy(coavoid_vehicle_node_t *node);

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

/* ---- coordinator ---- */

typedef struct {
    coavoid_node_common_t common;
    uint16_t id;            /* 0: the default, COAVOID_NODE_COORDINATOR_ID */
    size_t max_centralised; /* largest cluster planned in one composite search
                                        (1..COA_MAX_CENTRALISED; 0: the default, 3); larger clusters
                                        are planned decoupled by the coordinator */
    int64_t collect_us;     /* after the cycle start, when it plans, < dt (0: the
                                        default, dt / 4) */
    /* Its stopwatch's microseconds (common.stopwatch_us: wall time) it may spend planning
     * in one cycle; 0: no budget (a simulation, whose stopwatch reads 0, never runs over).
     * A cluster it comes to past the budget, or whose search ends past it, is abandoned:
     * a plan_t with STATUS_ABANDONED tells its UAVs, which then plan for themselves
     * rather than wait for a plan that would come late. */
    int64_t plan_budget_us;
    /* The work units (plan.h, "Work") its centralised searches may spend in one cycle,
     * all clusters together: each search gets what the cycle has left and answers within
     * it (its best plan, with a bound, when it is stopped), so a search ends on time
     * where plan_budget_us could only abandon it once it had overrun; deterministic, so a
     * simulation plans the same on every machine. A cluster whose search finds no plan is
     * planned decoupled in priority order (its UAVs' tables, outside the budget). 0: the
     * default, coavoid_node_work_of(plan_budget_us when it is set, else three quarters of
     * dt - collect_us, what coavoid-coordinator gives its planning in wall time). */
    uint64_t plan_work;
    /* The agreement on a plan (docs/protocol.md): how long after proposing a plan it
     * waits for every UAV's accept before it aborts the plan and plans the UAVs that
     * accepted again (0: the default, dt / 4), and how often it sends again what was not
     * answered: a proposal's rows, a commit (0: the default, dt / 20). */
    int64_t ack_timeout_us;
    int64_t resend_us;
    /* Its heartbeat goes out again this many times a cycle, resend_us apart (0: none,
     * the default): UAVs fall back after coordinator_timeout without one. */
    uint32_t heartbeat_copies;
} coavoid_coordinator_config_t;

typedef struct {
    int64_t cycle;
    uint32_t conflicts;        /* in its last prediction */
    uint32_t clusters_planned; /* planning calls in the last cycle */
    uint32_t plans_run;        /* planning calls since start */
    uint32_t plans_published;  /* solved plans published since start */
    uint32_t plans_abandoned;  /* clusters abandoned past the planning budget since start */
    uint32_t plans_proposed;   /* solved plans proposed to their UAVs since start */
    uint32_t plans_committed;  /* of them, accepted by every UAV and committed */
    uint32_t plans_aborted;    /* refused, unanswered in time, or superseded */
    uint32_t plans_replanned;  /* re-plans of the UAVs that accepted an aborted plan */
    uint32_t plans_resent;     /* proposals sent again for want of an accept */
    int last_outcome;
    uint64_t last_nodes_expanded;
    uint64_t last_plan_work; /* work units of its last centralised search */
    int64_t last_plan_duration_us;
    coavoid_lcm_rx_stats_t rx;
} coavoid_coordinator_state_t;

typedef struct coavoid_coordinator coavoid_coordinator_t;

/* As coavoid_vehicle_node_create, with a planner for max_centralised UAVs at once
 * (the workspace of coavoid_node_planner_config(N, max_centralised, beta): 1.3 MB for 3 UAVs
 * at N = 24 and beta 20,000), and room for the agreements of one cycle's plans (40 plans
 * of up to 32 rows: 0.23 MB). Errors as there (collect_us >= dt, max_centralised >
 * COA_MAX_CENTRALISED: COA_ERR_ARGUMENT). */
coavoid_coordinator_t *coavoid_coordinator_create(const coavoid_coordinator_config_t *config,
                                                  lcm_t *lcm, int *error);
/* Unsubscribes and frees. NULL is fine. */
void coavoid_coordinator_destroy(coavoid_coordinator_t *node);
/* Step 3 of the file comment for the cycle `now` falls in (call it at cycle start +
 * collect_us). Once per cycle; again within one cycle does nothing. Returns COA_OK or the
 * first negative error (NULL, before the epoch, a publishing or internal error); a plan
 * that fails is not an error. Cost: one prediction, then per cluster one search of at
 * most beta expansions each (centralised: independence detection's searches), and when one fails at most two
 * more over larger groups. No memory is allocated. */
int coavoid_coordinator_cycle(coavoid_coordinator_t *node, int64_t now);
/* The agreement steps due at `now` (docs/protocol.md): a proposal whose accepts are all in
 * is committed (the last accept makes the deadline now: the coordinator publishes from
 * its calls only, never inside a message handler); a proposal
 * past its ack deadline, or refused, is aborted and its accepting UAVs planned again
 * when the cycle leaves time; unanswered proposals and commits are sent again every
 * resend_us. Call it when coavoid_coordinator_deadline says. Returns 1 when it published,
 * 0 when nothing was due, or a negative error. Cost: a re-plan costs as one cluster of
 * the cycle; a resend O(rows). No memory. */
int coavoid_coordinator_poll(coavoid_coordinator_t *node, int64_t now);
/* When poll must run next (before the cycle ends), or INT64_MAX. O(plans of the cycle). */
int64_t coavoid_coordinator_deadline(const coavoid_coordinator_t *node);
const coavoid_coordinator_state_t *coavoid_coordinator_state(const coavoid_coordinator_t *node);

/* ---- world: the terrain database and the tracker of a scenario ---- */

typedef struct {
    coavoid_node_common_t common;
    uint16_t id;                     /* map_id and track source_id; 0: COAVOID_NODE_WORLD_ID */
    const coa_obstacle_t *obstacles; /* the caller's, outliving the node */
    size_t obstacle_count;
    const coa_track_t *tracks; /* positions at scenario t = 0 (epoch) */
    size_t track_count;
    /* Every tile and track estimate goes out again this many times a cycle (twice as many
     * in its first cycle), back to back (0: once, the default): against loss, as
     * COAVOID_NODE_DEFAULT_COPIES. */
    uint32_t copies;
} coavoid_world_config_t;

typedef struct coavoid_world coavoid_world_t;

/* Creates the world node (about 40 kB; it subscribes to nothing). NULL with
 * COA_ERR_ARGUMENT when the obstacles do not fit one map's tiles (64 boxes, 16 polytopes
 * of up to 32 vertices: coavoid_lcm_obstacle_map_tiles), there are more than
 * COAVOID_NODE_MAX_TRACKS tracks, or a track is invalid or its id not unique in
 * 1..2^31-1; COA_ERR_WORKSPACE when out of memory. */
coavoid_world_t *coavoid_world_create(const coavoid_world_config_t *config, lcm_t *lcm, int *error);
/* Frees. NULL is fine. */
void coavoid_world_destroy(coavoid_world_t *node);
/* Step 1 of the file comment: every tile of the obstacle map (version 1, republished every
 * cycle so that late joiners get it) and every track's estimate at the cycle's start (its position and
 * velocity there; a path track also with its path over the next horizon: its position
 * now, the path's points within N dt, and its position where the message's 16 points
 * end or the horizon does). Once per cycle. Returns COA_OK or the first error (a message
 * refused by its own check, or publishing failed). Cost O(obstacle vertices + tracks *
 * path). No memory. */
int coavoid_world_cycle(coavoid_world_t *node, int64_t now);

#endif /* COAVOID_NODE_H */
