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

#include "protocol.h"

/* ---- vehicle over LCM ---- */

/* A vehicle node built as init does in memory it allocates, with LCM as its transport:
 * it publishes on lcm and subscribes on rx_lcm, or on lcm when that is NULL (both the
 * caller's, outliving the node). A simulation of a lossy network gives each node its own
 * rx_lcm and decides itself which messages reach it and when (src/sim); the drivers give
 * their receiver's (src/realtime). Returns NULL with *error as init (also COA_ERR_ARGUMENT when LCM refuses a
 * subscription; COA_ERR_WORKSPACE when out of memory). */
coavoid_vehicle_node_t *coavoid_vehicle_node_create(const coavoid_vehicle_node_config_t *config,
                                                    lcm_t *lcm, lcm_t *rx_lcm, int *error);
/* Unsubscribes and frees a node that create made. NULL is fine. */
void coavoid_vehicle_node_destroy(coavoid_vehicle_node_t *node);

/* What a vehicle made by create receives and sends, as it happens: each datagram with its
 * channel, `sent` false for one handed to its inbox (before the inbox sees it), true for
 * one it published. For a record of the vehicle (`coavoid sim --record-vehicle`,
 * src/replay). tap NULL: nothing more. O(1). */
typedef void (*coavoid_node_tap_t)(void *user, bool sent, const char *channel, const void *data,
                                   size_t size);
void coavoid_vehicle_node_tap(coavoid_vehicle_node_t *node, coavoid_node_tap_t tap, void *user);

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
                                                  lcm_t *lcm, lcm_t *rx_lcm, int *error);
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
