/* SPDX-License-Identifier: MIT */
/*
 * The vehicle node (node.h): one simulated UAV that flies its adopted plan, publishes its
 * intent, follows the coordinator while its heartbeat lasts and its plans come when they
 * are needed, and otherwise plans for itself in priority order (steps 2 and 4 of node.h's
 * cycle).
 */
#include "protocol_internal.h"

#include <limits.h>
#include <math.h>
#include <string.h>

/* Decided cycles without a conflict of its own after which a raised rank returns to 0
 * (docs/protocol.md, "Priority negotiation"). */
#define RANK_HOLD_CYCLES 3u
/* Decisions again within one cycle after being overtaken (poll), at most: each follows a
 * raise, and each UAV raises at most RAISES_MAX times an episode, so a cascade through a
 * cluster ends anyway; the bound keeps a cycle's work bounded whatever peers announce. */
#define REDECISIONS_MAX 4u
/* Raises of its rank per episode (raise_rank), at most: the first above every UAV before
 * it, the others only as far as they must. Over 100 encounters (seed 1, no loss, while
 * raises counted only the members of its cluster), 1, 2 and 3 left 8, 6 and 5 of the 60
 * four-UAV encounters some order solves with a loss of separation; with 5 UAVs 3 and 5
 * left 12 and 11 of 29. More turns help little, and each reorders the cluster again. */
#define RAISES_MAX 3u
/* The order search (search_order): clusters of at most ORDER_MEMBERS_MAX UAVs, and at
 * most ORDER_TRIES_MAX priority orders a search (5!, every order of 5 UAVs). Past that a
 * search could take n! orders of n single-UAV searches each: the greedy raise remains. */
#define ORDER_MEMBERS_MAX 8u
#define ORDER_TRIES_MAX 120u
/* How a UAV enters the view of a cycle's start (snapshot): not at all, by its intent of
 * the cycle before, or, in its first cycle, by its first intent with the offset it starts
 * at held (what it flew before it planned anything). */
#define SNAPSHOT_NONE 0u
#define SNAPSHOT_PREVIOUS 1u
#define SNAPSHOT_FIRST 2u

struct coavoid_vehicle_node {
    coavoid_vehicle_node_config_t config;
    coavoid_vehicle_node_state_t state;
    coa_real_t dh;
    int64_t first_cycle_start;
    int64_t cycle_start;
    int64_t wait_deadline;
    /* Following: when a conflict of its own with no answer yet makes it plan for itself
     * within the cycle (answer_overdue, the phase's ANSWER_WAIT). */
    int64_t answer_deadline;
    /* When answer_overdue found the held plan's self-commit not yet due: when it is
     * (INT64_MAX: none), and for which plan. */
    int64_t self_commit_at;
    int64_t self_commit_plan;
    bool self_answered; /* it answered its own conflict in the cycle before (distrust) */
    bool was_coordinated;
    bool cycle_conflict;    /* a conflict of its own in this cycle's prediction */
    bool distrust;          /* not following a coordinator it hears (cycle()) */
    int64_t distrust_cycle; /* the cycle it began */
    int64_t distrust_utime; /* and when */
    bool fault;             /* an internal error in this cycle */
    int64_t intent_sequence;
    int64_t status_sequence;
    int64_t last_plan_utime;
    /* The plan_id of the coordinator's plan of this cycle it switched to (state.plan).
     * Plans are ordered within a cycle only (node.h, step 4). */
    int64_t cycle_plan_id;
    bool cycle_plan_failed;  /* one listed it, in time, but was not solved */
    bool cycle_plan_refused; /* one listed it and was refused (on_plan) */
    bool last_cycle_refused; /* the same, of the cycle before (its heartbeat comes first) */
    bool unanswered;         /* had a conflict of its own in the last cycle and no plan came */
    /* Priority negotiation (docs/protocol.md): how many times it raised its rank
     * (state.rank) in this episode, and for how many decided cycles in a row it has had
     * no conflict. */
    uint32_t raises;
    uint32_t calm_cycles;
    int64_t settled_cycle; /* the cycle whose conflict settle_rank counted */
    /* The UAVs before it when it last decided in this cycle, with the sequence of the
     * intent it had of each, and how many times it decided again in redecided_cycle. */
    size_t decided_count;
    uint16_t decided_id[COAVOID_NODE_MAX_PEERS];
    int64_t decided_sequence[COAVOID_NODE_MAX_PEERS];
    uint32_t decided_digest[COAVOID_NODE_MAX_PEERS]; /* intent_digest of what it decided on */
    uint32_t decided_news; /* the inbox's world_news when it last decided */
    int64_t decided_cycle; /* the cycle it last decided in (note_order) */
    int64_t news_cycle;    /* the last cycle it decided again on world news (reconsider) */
    int64_t redecided_cycle;
    uint32_t redecisions;
    /* The other UAVs' rows in this cycle's solved plans (the latest plan_id each): what
     * each is to fly from this cycle's start, which a plan for this UAV is checked
     * against instead of their intents (record_rows). */
    size_t row_count;
    uint16_t row_id[COAVOID_NODE_MAX_PEERS];
    int64_t row_plan_id[COAVOID_NODE_MAX_PEERS];
    uint32_t row_samples[COAVOID_NODE_MAX_PEERS];
    int32_t row_offsets[COAVOID_NODE_MAX_PEERS][COAVOID_NODE_MAX_SAMPLES];

    /* The coordinator's plan it accepted this cycle and flies once it is committed
     * (docs/protocol.md; state.plan holds it): its row, and the plan's UAVs, whose
     * SWITCHED is a commit too. */
    int64_t pending_plan_id;
    uint32_t pending_count;
    int32_t pending_offsets[COAVOID_NODE_MAX_SAMPLES];
    size_t pending_members;
    uint16_t pending_ids[COA_MAX_VEHICLES];
    bool pending_accepted[COA_MAX_VEHICLES]; /* an ACCEPT heard from that UAV (own: sent) */
    int64_t pending_since;                   /* when it accepted */
    /* Copies still to send, and when the next goes: its intent, its SWITCHED. */
    uint32_t intent_copies_left;
    int64_t intent_copy_at;
    uint32_t answer_copies_left; /* of its last answer: ACCEPT or SWITCHED */
    int64_t answer_copy_at;
    int8_t answer_kind;
    int64_t answer_plan_id;
    coavoid_agreement_t tx_agreement;

    /* The adopted plan: offsets of samples plan_start .. plan_start + plan_count - 1; past
     * its end the last offset holds. */
    int64_t plan_start;
    uint32_t plan_count;
    int32_t plan_offsets[COAVOID_NODE_MAX_SAMPLES];

    /* This cycle's intent: samples k .. k + N. */
    coa_vec3_t own_reference[COAVOID_NODE_MAX_SAMPLES];
    int32_t own_offsets[COAVOID_NODE_MAX_SAMPLES];
    coa_vec3_t own_samples[COAVOID_NODE_MAX_SAMPLES];

    int32_t plan_out[COAVOID_NODE_MAX_SAMPLES];
    int32_t checked[COAVOID_NODE_MAX_SAMPLES];       /* a coordinator's plan over this window */
    coa_intent_plan_t plans[COAVOID_NODE_MAX_PEERS]; /* itself first, then the live peers */
    coa_intent_plan_t tall[COAVOID_NODE_MAX_PEERS];  /* the same, with unbounded height */
    uint32_t labels[COAVOID_NODE_MAX_PEERS];
    bool include[COAVOID_NODE_MAX_PEERS];
    coavoid_intent_t tx_intent;
    coavoid_status_t tx_status;

    /* The order search of this cycle (search_order): what it started the cycle as, the
     * group's members (indices into the view of the cycle's start) and their problem, and
     * the ranks it agreed for each member (agreed_cycle: the cycle they hold for, until
     * each member's own intent of the cycle says its rank). */
    coavoid_intent_t order_own; /* itself as its peers have it when the cycle began */
    int32_t start_offsets[COAVOID_NODE_MAX_SAMPLES]; /* its plan when the cycle began */
    uint8_t order_own_kind;                          /* SNAPSHOT_* */
    uint8_t order_kind[COAVOID_NODE_MAX_PEERS];
    size_t order_member[ORDER_MEMBERS_MAX];
    coa_vehicle_t order_vehicles[ORDER_MEMBERS_MAX];
    coa_vec3_t order_reference[ORDER_MEMBERS_MAX][COAVOID_NODE_MAX_PROBLEM_SAMPLES];
    const coa_vec3_t *order_references[ORDER_MEMBERS_MAX];
    int32_t order_offsets[ORDER_MEMBERS_MAX * COAVOID_NODE_MAX_SAMPLES];
    int32_t ahead_offsets[ORDER_MEMBERS_MAX * COAVOID_NODE_MAX_PROBLEM_SAMPLES]; /* look_ahead */
    int64_t agreed_cycle;
    size_t searched_first; /* first intents of the cycle its last search saw (first_intents) */
    size_t agreed_count;
    uint16_t agreed_id[ORDER_MEMBERS_MAX];
    int32_t agreed_rank[ORDER_MEMBERS_MAX];
    /* The joint plan's last search that found none (search_joint): its cycle and its
     * problem's digest. */
    int64_t joint_failed_cycle;
    uint64_t joint_failed_digest;

    coavoid_node_solver_t solver;
    coavoid_node_inbox_t inbox;
    coavoid_node_view_t view;
    coavoid_node_problem_tracks_t problem_tracks;
};

/* ---- its state machines (protocol.h; the tables are vehicle_states.c) ---- */

/* An event its machine does not allow where it stands: a fault, and nothing moves. */
static void not_allowed(coavoid_vehicle_node_t *node)
{
    node->fault = true;
    node->state.protocol_faults++;
}

/* Moves the phase on `event`, and what the state reports with it: following the
 * coordinator (FOLLOWING, FOLLOWED), and waiting to decide. O(table). */
static void phase_on(coavoid_vehicle_node_t *node, coavoid_vehicle_event_t event)
{
    const coavoid_vehicle_phase_t to = coavoid_vehicle_phase_next(node->state.phase, event);
    if (to == COAVOID_VEHICLE_PHASES) {
        not_allowed(node);
        return;
    }
    node->state.phase = to;
    node->state.coordinated = to == COAVOID_VEHICLE_FOLLOWING || to == COAVOID_VEHICLE_FOLLOWED;
    node->state.waiting = to == COAVOID_VEHICLE_DECIDING || to == COAVOID_VEHICLE_GATHERING ||
                          to == COAVOID_VEHICLE_ANSWERING || to == COAVOID_VEHICLE_ANSWER_GATHERING;
}

/* Moves its plan state on `event`. O(table). */
static void plan_on(coavoid_vehicle_node_t *node, coavoid_vehicle_event_t event)
{
    const coavoid_vehicle_plan_t to = coavoid_vehicle_plan_next(node->state.plan, event);
    if (to == COAVOID_VEHICLE_PLAN_STATES) {
        not_allowed(node);
        return;
    }
    node->state.plan = to;
}

static bool started(const coavoid_vehicle_node_t *node)
{
    return node->state.phase != COAVOID_VEHICLE_IDLE;
}

/* Deciding for itself since the answer wait of this cycle. */
static bool answering(const coavoid_vehicle_node_t *node)
{
    const coavoid_vehicle_phase_t p = node->state.phase;
    return p == COAVOID_VEHICLE_ANSWERING || p == COAVOID_VEHICLE_ANSWER_GATHERING ||
           p == COAVOID_VEHICLE_ANSWERED;
}

/* Waiting for its first cycle's intents to gather (plan_self), until gather_end(). */
static bool gather_wait(const coavoid_vehicle_node_t *node)
{
    return node->state.phase == COAVOID_VEHICLE_GATHERING ||
           node->state.phase == COAVOID_VEHICLE_ANSWER_GATHERING;
}

/* Holds an accepted plan of this cycle, undecided. */
static bool holds_plan(const coavoid_vehicle_node_t *node)
{
    const coavoid_vehicle_plan_t p = node->state.plan;
    return p == COAVOID_VEHICLE_PLAN_HOLDING || p == COAVOID_VEHICLE_PLAN_STANDBY ||
           p == COAVOID_VEHICLE_PLAN_SWITCHED_HOLDING;
}

/* Flies a coordinator's plan of this cycle it switched to. */
static bool flies_plan(const coavoid_vehicle_node_t *node)
{
    return node->state.plan == COAVOID_VEHICLE_PLAN_SWITCHED ||
           node->state.plan == COAVOID_VEHICLE_PLAN_SWITCHED_HOLDING;
}

/* Planned a standby at the answer wait of this cycle, and flies it unless committed. */
static bool on_standby(const coavoid_vehicle_node_t *node)
{
    return node->state.plan == COAVOID_VEHICLE_PLAN_STANDBY ||
           node->state.plan == COAVOID_VEHICLE_PLAN_ON_STANDBY;
}

static int32_t offset_at(const coavoid_vehicle_node_t *node, int64_t k)
{
    int64_t i = k - node->plan_start;
    if (i < 0) {
        i = 0;
    }
    if (i >= (int64_t)node->plan_count) {
        i = (int64_t)node->plan_count - 1;
    }
    return node->plan_offsets[i];
}

static coa_vec3_t lifted(coa_vec3_t reference, int32_t offset, coa_real_t dh)
{
    /* As the planner and every receiver compute it (coavoid_lcm_intent_to_core). */
    reference.z += (coa_real_t)offset * dh;
    return reference;
}

/* The intent of cycle k from the adopted plan, which is then re-based at k so that its
 * storage never needs more than N + 1 samples. */
static void build_own(coavoid_vehicle_node_t *node, int64_t k)
{
    const coavoid_node_common_t *c = &node->config.common;
    const uint32_t n = c->horizon + 1u;
    for (uint32_t j = 0; j < n; j++) {
        node->own_reference[j] =
            coa_reference_at(&node->config.vehicle, (coa_real_t)(k + (int64_t)j) * c->dt);
        node->own_offsets[j] = offset_at(node, k + (int64_t)j);
    }
    for (uint32_t j = 0; j < n; j++) {
        node->plan_offsets[j] = node->own_offsets[j];
        node->own_samples[j] = lifted(node->own_reference[j], node->own_offsets[j], node->dh);
    }
    node->plan_start = k;
    node->plan_count = n;
}

static void adopt(coavoid_vehicle_node_t *node, const int32_t *offsets, uint32_t count)
{
    const uint32_t n = node->config.common.horizon + 1u;
    node->plan_start = node->state.cycle;
    node->plan_count = count < COAVOID_NODE_MAX_SAMPLES ? count : COAVOID_NODE_MAX_SAMPLES;
    memcpy(node->plan_offsets, offsets, node->plan_count * sizeof offsets[0]);
    for (uint32_t j = 0; j < n; j++) {
        node->own_offsets[j] = offset_at(node, node->state.cycle + (int64_t)j);
        node->own_samples[j] = lifted(node->own_reference[j], node->own_offsets[j], node->dh);
    }
    node->state.plans_adopted++;
}

static bool stale_inputs(const coavoid_vehicle_node_t *node, int64_t now)
{
    for (size_t i = 0; i < COAVOID_NODE_MAX_PEERS; i++) {
        const coavoid_node_peer_t *p = &node->inbox.peers[i];
        if (p->used && now - p->msg.utime > node->config.common.stale_after_us) {
            return true;
        }
    }
    return false;
}

/* Why its health is not OK (status_t's REASON_* bits). */
static int32_t health_reasons(const coavoid_vehicle_node_t *node, int64_t now, bool twin)
{
    const coavoid_vehicle_node_state_t *s = &node->state;
    int32_t r = 0;
    r |= node->fault ? COAVOID_STATUS_T_REASON_INTERNAL_ERROR : 0;
    r |= twin ? COAVOID_STATUS_T_REASON_DUPLICATE_ID : 0;
    r |= s->last_outcome > 0 ? COAVOID_STATUS_T_REASON_PLANNING_FAILED : 0;
    r |= stale_inputs(node, now) ? COAVOID_STATUS_T_REASON_STALE_PEERS : 0;
    r |= node->config.mode == COAVOID_NODE_CENTRALISED && !s->coordinated
             ? COAVOID_STATUS_T_REASON_NOT_FOLLOWING
             : 0;
    r |= node->last_cycle_refused ? COAVOID_STATUS_T_REASON_PLAN_REFUSED : 0;
    r |= node->unanswered ? COAVOID_STATUS_T_REASON_NO_PLAN : 0;
    return r;
}

static int publish_status(coavoid_vehicle_node_t *node, int64_t now)
{
    const coavoid_vehicle_node_state_t *s = &node->state;
    /* Another UAV using its id makes every peer's view of it wrong: a fault for as long
     * as that UAV's intents keep coming. */
    const bool twin = node->inbox.foreign_intents > 0u;
    node->inbox.foreign_intents = 0;
    const coavoid_node_heartbeat_t h = {node->config.vehicle.id,
                                        COAVOID_STATUS_T_NODE_VEHICLE,
                                        node->status_sequence++,
                                        health_reasons(node, now, twin),
                                        s->coordinated ? COAVOID_STATUS_T_MODE_CENTRALISED
                                                       : COAVOID_STATUS_T_MODE_DECOUPLED,
                                        node->last_plan_utime,
                                        s->last_plan_duration_us,
                                        s->last_nodes_expanded,
                                        s->last_outcome,
                                        s->conflicts,
                                        s->plans_run,
                                        &s->rx};
    return coavoid_node_publish_heartbeat(&node->inbox, &node->tx_status, now, node->cycle_start,
                                          &h);
}

/* Its intent's fields of this cycle at `now` beyond the samples, numbered `sequence`. */
static coavoid_lcm_intent_info_t intent_info(const coavoid_vehicle_node_t *node, int64_t now,
                                             int64_t sequence)
{
    const coavoid_node_common_t *c = &node->config.common;
    coavoid_lcm_intent_info_t info;
    memset(&info, 0, sizeof info);
    info.utime = now;
    info.sequence = sequence;
    /* A coordinator's plan switched to in this cycle is flown to its end (reconsider()),
     * coordinated or not (a self-commit, a standby that a COMMIT replaced): it says so, or
     * a peer's order search would count it in and plan around a row it never flies. */
    info.mode = node->state.coordinated || flies_plan(node) ? COAVOID_INTENT_T_MODE_CENTRALISED
                                                            : COAVOID_INTENT_T_MODE_DECOUPLED;
    /* The state at `now`: it moves straight from sample k to sample k + 1. */
    coa_vec3_t p0 = node->own_samples[0];
    coa_vec3_t p1 = node->own_samples[1];
    double u = (double)(now - node->cycle_start) / (double)c->dt_us;
    u = u < 0.0 ? 0.0 : (u > 1.0 ? 1.0 : u);
    info.velocity.x = (p1.x - p0.x) / c->dt;
    info.velocity.y = (p1.y - p0.y) / c->dt;
    info.velocity.z = (p1.z - p0.z) / c->dt;
    info.position.x = p0.x + (coa_real_t)u * (p1.x - p0.x);
    info.position.y = p0.y + (coa_real_t)u * (p1.y - p0.y);
    info.position.z = p0.z + (coa_real_t)u * (p1.z - p0.z);
    info.plan_utime = node->cycle_start;
    info.step = c->dt;
    info.sigma_horizontal = node->config.sigma_horizontal;
    info.sigma_vertical = node->config.sigma_vertical;
    info.rank = (int8_t)node->state.rank;
    return info;
}

/* Copies of its first cycle's intent: twice intent_copies. Every peer's order search
 * starts from the intents as the cycle began (docs/protocol.md, "Priority negotiation"),
 * and a peer that lost every copy of one UAV's first one plans the group without it
 * while the others plan it in. O(1). */
static uint32_t first_copies(const coavoid_vehicle_node_t *node)
{
    return 2u * node->config.intent_copies;
}

/* Publishes its intent of this cycle as it stands at `now` (its state moved on, the same
 * plan), and schedules its copies. COA_OK or a negative error (a fault). */
static int publish_intent(coavoid_vehicle_node_t *node, int64_t now)
{
    const coavoid_node_common_t *c = &node->config.common;
    const coavoid_lcm_intent_info_t info = intent_info(node, now, node->intent_sequence++);
    coavoid_lcm_context_t ctx = coavoid_node_context(&node->inbox, now, node->cycle_start);
    int rc = coavoid_lcm_intent_from_core(&node->config.vehicle, &info, node->own_reference,
                                          node->own_offsets, (size_t)c->horizon + 1u, &ctx,
                                          &node->tx_intent, NULL);
    if (rc == COA_OK) {
        rc = coavoid_node_publish_intent(&node->inbox, &node->tx_intent);
    } else {
        rc = COA_ERR_ARGUMENT; /* its own reference left the range a message can carry */
    }
    if (rc != COA_OK) {
        node->fault = true;
    }
    const bool first = node->cycle_start == node->first_cycle_start;
    node->intent_copies_left = first ? first_copies(node) : node->config.intent_copies;
    node->intent_copy_at = now + node->config.resend_us;
    return rc;
}

/* Publishes this cycle's intent and heartbeat; the wait, if any, is over. Returns 1 or a
 * negative error. */
static int finish(coavoid_vehicle_node_t *node, int64_t now)
{
    int rc = publish_intent(node, now);
    phase_on(node, COAVOID_VEHICLE_EVENT_PUBLISH);
    node->state.published = rc == COA_OK;
    node->wait_deadline = INT64_MAX;
    int status_rc = publish_status(node, now);
    if (rc != COA_OK) {
        return rc;
    }
    return status_rc != COA_OK ? status_rc : 1;
}

/* The one-UAV problem of this cycle: itself from the offset it flies now along its
 * reference window, the known obstacles and node->problem_tracks (filled by the caller).
 * vehicle and references are the caller's storage the problem points to. */
static coa_problem_t own_problem(const coavoid_vehicle_node_t *node, coa_vehicle_t *vehicle,
                                 const coa_vec3_t **references)
{
    const coavoid_node_common_t *c = &node->config.common;
    *vehicle = node->config.vehicle;
    vehicle->initial_offset = node->state.offset;
    references[0] = node->own_reference;
    coa_problem_t problem;
    memset(&problem, 0, sizeof problem);
    problem.dt = c->dt;
    problem.horizon = c->horizon;
    problem.vehicles = vehicle;
    problem.vehicle_count = 1;
    problem.references = references;
    problem.obstacles = node->inbox.obstacles;
    problem.obstacle_count = node->inbox.obstacle_count;
    problem.tracks = node->problem_tracks.tracks;
    problem.track_count = node->problem_tracks.count;
    problem.track_samples = node->problem_tracks.samples;
    problem.has_floor = c->has_floor;
    problem.floor_z = c->min_altitude;
    return problem;
}

/* One one-UAV A* search for itself around the view's tracks and the live UAVs marked in
 * node->include. Returns COA_OK with *result, or a negative error. */
static int search_self(coavoid_vehicle_node_t *node, int64_t now, coa_plan_result_t *result)
{
    const coavoid_node_common_t *c = &node->config.common;
    int rc = coavoid_node_problem_tracks(&node->problem_tracks, &node->view, node->include, c,
                                         c->horizon);
    if (rc != COA_OK) {
        return rc;
    }
    coa_vehicle_t vehicle;
    const coa_vec3_t *references[1];
    coa_problem_t problem = own_problem(node, &vehicle, references);

    int64_t start = coavoid_node_stopwatch(c);
    rc = coa_plan_centralised(node->solver.planner, &problem, node->plan_out, result);
    int64_t duration = coavoid_node_stopwatch(c) - start;
    node->state.plans_run++;
    node->last_plan_utime = now;
    node->state.last_plan_duration_us = duration > 0 ? duration : 0;
    if (rc != COA_OK) {
        return rc;
    }
    node->state.last_outcome = (int)result->status;
    node->state.last_nodes_expanded = result->nodes_expanded;
    return COA_OK;
}

static int plan_hits_known(coavoid_vehicle_node_t *node, const int32_t *offsets, size_t count,
                           int64_t now, bool own);

/* Adopts its own solved plan (node->plan_out) once the check every plan gets before it is
 * flown finds it clear of what its search avoided; a plan that fails it is a planner
 * bug: not flown, and the node reports a fault this cycle. Returns COA_OK or a negative
 * error. */
static int own_plan_checked(coavoid_vehicle_node_t *node, int64_t now)
{
    const uint32_t samples = node->config.common.horizon + 1u;
    int hit = plan_hits_known(node, node->plan_out, samples, now, true);
    if (hit < 0) {
        return hit;
    }
    if (hit > 0) {
        node->fault = true;
        return COA_OK;
    }
    adopt(node, node->plan_out, samples);
    return COA_OK;
}

/* Whether live UAV i of the view comes before this UAV in the decoupled order: i's rank as
 * its latest intent announces it, its own as it announces it now (coavoid_node_precedes).
 * Every node orders two UAVs alike once it has both their latest intents. O(1). */
static bool peer_first(const coavoid_vehicle_node_t *node, size_t i)
{
    const coa_vehicle_t *self = &node->config.vehicle;
    const coa_vehicle_t *peer = &node->view.live_vehicle[i];
    return coavoid_node_precedes(node->view.live_info[i].rank, peer->priority, peer->id,
                                 node->state.rank, self->priority, self->id);
}

/* When the last copy of the first intents published as the first cycle began is due
 * (publish_intent: first_copies(), resend_us apart). */
static int64_t gather_end(const coavoid_vehicle_node_t *node)
{
    return node->first_cycle_start + (int64_t)first_copies(node) * node->config.resend_us;
}

/* Whether, in its first cycle, the copies of the first intents its peers published as the
 * cycle began may still come. Before gather_end() a UAV that finds no plan below those
 * before it may only be missing some of them (lost, a copy on its way), and a raise made
 * then reorders the cluster for nothing. */
static bool gathering(const coavoid_vehicle_node_t *node, int64_t now)
{
    return node->cycle_start == node->first_cycle_start && now < gather_end(node);
}

/* One search in the decoupled order as it stands: against obstacles, tracks, stale UAVs
 * and every live UAV that is not a later member of its cluster (my = its cluster label).
 * While the first intents are gathering it keeps clear of no later UAV at all: a later
 * UAV's first plan may have been made before it heard this one (or others before it), so
 * keeping clear of it can take that UAV's only way out; the later UAV plans around this
 * one's intent once it hears it. Returns COA_OK with *result, or a negative error. */
static int plan_in_order(coavoid_vehicle_node_t *node, int64_t now, uint32_t my,
                         coa_plan_result_t *result)
{
    const coavoid_node_view_t *view = &node->view;
    const bool first = gathering(node, now);
    bool lower_outside = false;
    for (size_t i = 0; i < view->live_count; i++) {
        bool lower = !peer_first(node, i);
        node->include[i] = !(lower && (first || node->labels[i + 1u] == my));
        lower_outside = lower_outside || (lower && node->include[i]);
    }
    int rc = search_self(node, now, result);
    /* Later UAVs outside its cluster are kept clear of while that is possible; when it is
     * not (its way out of a conflict crosses their paths), it plans as
     * coa_plan_decoupled orders it, around the earlier ones only: the others then see the
     * conflict and plan around it. */
    if (rc == COA_OK && result->status != COA_PLAN_SOLVED && lower_outside) {
        for (size_t i = 0; i < view->live_count; i++) {
            node->include[i] = peer_first(node, i);
        }
        rc = search_self(node, now, result);
    }
    return rc;
}

/* The highest rank of the live UAVs before it, -1 when there are none. O(peers). */
static int32_t top_rank(const coavoid_vehicle_node_t *node)
{
    const coavoid_node_view_t *view = &node->view;
    int32_t top = -1;
    for (size_t i = 0; i < view->live_count; i++) {
        if (peer_first(node, i) && view->live_info[i].rank > top) {
            top = view->live_info[i].rank;
        }
    }
    return top;
}

/* The next rank above `from` worth trying, for a UAV at rank `old` that found no plan:
 * each rank of a live UAV before it (where its priority may win the tie) or one above it
 * (just above that UAV), else `ceiling`. O(peers). */
static int32_t next_rank(const coavoid_vehicle_node_t *node, int32_t old, int32_t from,
                         int32_t ceiling)
{
    const coa_vehicle_t *self = &node->config.vehicle;
    const coavoid_node_view_t *view = &node->view;
    int32_t next = ceiling;
    for (size_t i = 0; i < view->live_count; i++) {
        const coa_vehicle_t *peer = &view->live_vehicle[i];
        const int32_t r = view->live_info[i].rank;
        if (!coavoid_node_precedes(r, peer->priority, peer->id, old, self->priority, self->id)) {
            continue;
        }
        next = r > from && r < next ? r : next;
        next = r + 1 > from && r + 1 < next ? r + 1 : next;
    }
    return next;
}

/* After a search found no plan below the UAVs that come before it (those of its cluster,
 * and those outside it its search avoided, which may be what blocks it: a track's
 * conflict makes a cluster of one): it raises its rank to the lowest that gives it a plan
 * (trying each rank next_rank offers, upwards), or else to one above all of them, where
 * it plans against only what stays before it (others must then avoid it: it cannot
 * avoid them). At most MAX_RANK,
 * and at most RAISES_MAX times an episode (until its rank is back to 0), so that UAVs
 * that each fail below another cannot take turns for ever. *result is the last search.
 * Returns COA_OK or a negative error. Cost: at most 2 * peers + 1 plan_in_order. */
static int raise_rank(coavoid_vehicle_node_t *node, int64_t now, uint32_t my,
                      coa_plan_result_t *result)
{
    const int32_t old = node->state.rank;
    const int32_t top = top_rank(node);
    const int32_t ceiling = top < 0 ? -1 : (top < COAVOID_INTENT_T_MAX_RANK ? top + 1 : top);
    if (node->raises >= RAISES_MAX || ceiling <= old) {
        return COA_OK;
    }
    int rc = COA_OK;
    /* The first raise of an episode goes above them all, as coa_plan_decoupled's
     * reordering first moves a failing UAV to the front; the ranks it leaves apart let a
     * later raise stop between two members. */
    int32_t r = node->raises == 0u ? ceiling - 1 : old;
    do {
        r = next_rank(node, old, r, ceiling);
        node->state.rank = r;
        rc = plan_in_order(node, now, my, result);
    } while (rc == COA_OK && result->status != COA_PLAN_SOLVED && r < ceiling);
    node->state.rank_raises++;
    node->raises++;
    node->calm_cycles = 0;
    return rc;
}

/* A raised rank returns to 0 once it has had no conflict of its own (conflict false) for
 * RANK_HOLD_CYCLES decided cycles in a row: the encounter it was raised for is over, and
 * the configured order holds again. O(1). */
static void settle_rank(coavoid_vehicle_node_t *node, bool conflict)
{
    if (node->settled_cycle == node->state.cycle) {
        return; /* decided again in the same cycle (poll): counted once */
    }
    node->settled_cycle = node->state.cycle;
    node->calm_cycles = conflict ? 0u : node->calm_cycles + 1u;
    if (node->state.rank != 0 && node->calm_cycles >= RANK_HOLD_CYCLES) {
        node->state.rank = 0;
        node->raises = 0;
    }
}

/* While it follows the coordinator, which plans in its own order, it claims no
 * precedence among the decoupled UAVs: its rank returns to 0 at once. O(1). */
static void drop_rank(coavoid_vehicle_node_t *node)
{
    node->state.rank = 0;
    node->raises = 0;
    node->calm_cycles = 0;
}

/* Plans for itself in the decoupled order (plan_in_order); when it finds no plan there, it
 * raises its rank and, if it did, plans again at once, now against only the UAVs still
 * before it; adopts a solved plan. Returns COA_OK (whatever the outcome), 1 when it found
 * no plan while its first cycle's intents are still gathering (it waits until then, and
 * decides again on what comes meanwhile: decide), or a negative error. */
static int plan_self(coavoid_vehicle_node_t *node, int64_t now, uint32_t my)
{
    coa_plan_result_t result;
    int rc = plan_in_order(node, now, my, &result);
    if (rc == COA_OK && result.status != COA_PLAN_SOLVED && gathering(node, now)) {
        phase_on(node, COAVOID_VEHICLE_EVENT_GATHER);
        return 1;
    }
    if (rc == COA_OK && result.status != COA_PLAN_SOLVED) {
        rc = raise_rank(node, now, my, &result);
    }
    if (rc == COA_OK && result.status == COA_PLAN_SOLVED) {
        rc = own_plan_checked(node, now);
    }
    return rc;
}

/* The ranks its order search agreed this cycle (search_order), for the members whose
 * intent of the cycle has not come yet: those still announce the order of the cycle
 * before, and it must wait for the members before it in the new one. O(peers * members). */
static void apply_agreed(coavoid_vehicle_node_t *node)
{
    coavoid_node_view_t *view = &node->view;
    if (node->agreed_cycle != node->state.cycle) {
        return;
    }
    for (size_t i = 0; i < view->live_count; i++) {
        for (size_t a = 0; a < node->agreed_count && !view->live_current[i]; a++) {
            if (node->agreed_id[a] == view->live_id[i]) {
                view->live_info[i].rank = (int8_t)node->agreed_rank[a];
            }
        }
    }
}

/* Builds the cycle's view at `now` and the plans to predict: its own intent first, then
 * the live UAVs' (view order). Returns their count. */
static size_t gather(coavoid_vehicle_node_t *node, int64_t now)
{
    const coavoid_node_common_t *c = &node->config.common;
    const coa_vehicle_t *self = &node->config.vehicle;
    coavoid_node_view_t *view = &node->view;
    coavoid_node_view_build(view, &node->inbox, node->cycle_start, now);
    apply_agreed(node);
    coa_intent_plan_t *own = &node->plans[0];
    memset(own, 0, sizeof *own);
    own->id = self->id;
    own->volume = self->volume;
    own->t0 = 0;
    own->step = c->dt;
    own->samples = node->own_samples;
    own->count = (size_t)c->horizon + 1u;
    own->sigma_horizontal = node->config.sigma_horizontal;
    own->sigma_vertical = node->config.sigma_vertical;
    for (size_t i = 0; i < view->live_count; i++) {
        node->plans[i + 1u] = view->live_plan[i];
    }
    return view->live_count + 1u;
}

/* Predicts over the n gathered plans with the view's tracks and the known obstacles:
 * node->labels, the solver's conflicts and state.conflicts. Returns COA_OK or the
 * prediction's error. */
static int predict(coavoid_vehicle_node_t *node, size_t n, coa_predict_result_t *result)
{
    size_t clusters = 0;
    coavoid_node_solver_t *sv = &node->solver;
    int rc = coavoid_node_predict(sv->predictor, &node->config.common, node->plans, n, &node->view,
                                  &node->inbox, sv->conflicts, sv->conflict_capacity, result,
                                  node->labels, &clusters);
    if (rc != COA_OK) {
        return rc;
    }
    node->state.conflicts =
        result->conflicts_found > UINT32_MAX ? UINT32_MAX : (uint32_t)result->conflicts_found;
    return COA_OK;
}

/* At the start of a cycle, after following the coordinator in the one before without
 * adopting a plan: whether it had a conflict of its own there that the coordinator
 * left open. It predicts as decoupled, on this cycle's clock with its own intent of this
 * cycle (the last one flown on) and its peers' latest, and counts only conflicts that
 * begin within the previous cycle's horizon (first step below N - 1 here): one that
 * only now enters the horizon is the coordinator's to plan in this cycle. Predicting at
 * the previous cycle's start instead would have seen some peers' intents of the cycle
 * before it, without the plans they adopted since, and taken a solved conflict for an
 * open one. Returns COA_OK or the prediction's error. */
static int missed_conflict(coavoid_vehicle_node_t *node, int64_t now, bool *conflict)
{
    coa_predict_result_t result;
    *conflict = false;
    int rc = predict(node, gather(node, now), &result);
    if (rc != COA_OK) {
        return rc;
    }
    const uint32_t horizon = node->config.common.horizon;
    for (size_t j = 0; j < result.conflict_count; j++) {
        const coa_conflict_t *cf = &node->solver.conflicts[j];
        if (cf->a == 0u && cf->first_step + 1u < horizon) {
            *conflict = true;
        }
    }
    return COA_OK;
}

static bool row_flown(const coavoid_vehicle_node_t *node, uint16_t id, const int32_t *offsets,
                      size_t count);

/* Whether live UAV i has published what it decided for this cycle: an intent of this
 * cycle, which, when it decides at the answer wait itself (answering), must also say the
 * UAV plans for itself or fly its row of a coordinator's plan of this cycle (one still
 * following may be about to answer itself too). O(N). */
static bool decided_peer(const coavoid_vehicle_node_t *node, size_t i)
{
    const coavoid_node_view_t *view = &node->view;
    return view->live_current[i] &&
           !(answering(node) && view->live_info[i].mode == COAVOID_INTENT_T_MODE_CENTRALISED &&
             !row_flown(node, view->live_id[i], view->live_arrays[i].offsets,
                        view->live_plan[i].count));
}

/* Whether a UAV before it in the decoupled order (peer_first: ranks, then priorities) that
 * may still publish this cycle's intent passes near it horizontally within the horizon. A
 * UAV changes only its altitude, so such a UAV is the only one whose new plan can bring a
 * conflict it does not see yet: it waits for those (until the deadline), as it would wait
 * in a cluster. Without this it would decide on their previous intents and react a cycle
 * late, which the simulation, where the intents of higher priorities happen to arrive
 * first, would never show. The test is the
 * predictor's own, with every volume made as tall as a message allows, so that only the
 * horizontal distance (and its uncertainty) decides. Cost: one coa_predict over the live
 * UAVs, no obstacles or tracks. */
static bool near_pending(coavoid_vehicle_node_t *node, size_t n)
{
    const coavoid_node_common_t *c = &node->config.common;
    const coavoid_node_view_t *view = &node->view;
    bool any = false;
    for (size_t i = 0; i < view->live_count; i++) {
        if (!decided_peer(node, i) && peer_first(node, i)) {
            any = true;
        }
    }
    if (!any) {
        return false;
    }
    for (size_t i = 0; i < n; i++) {
        node->tall[i] = node->plans[i];
        node->tall[i].volume.half_height = (coa_real_t)COAVOID_LCM_MAX_SIZE;
    }
    coa_predict_config_t config = coavoid_node_predict_config(c);
    coa_predict_result_t result;
    coavoid_node_solver_t *sv = &node->solver;
    if (coa_predict(sv->predictor, &config, node->tall, n, NULL, 0, NULL, 0, sv->conflicts,
                    sv->conflict_capacity, &result) != COA_OK) {
        return true; /* cannot tell: wait, bounded by the deadline */
    }
    /* Vehicle pairs come first in ascending (a, b), so its own (a == 0) survive an
     * overflow of the array. */
    for (size_t j = 0; j < result.conflict_count; j++) {
        const coa_conflict_t *cf = &node->solver.conflicts[j];
        if (cf->kind != COA_CONFLICT_VEHICLE || cf->a != 0u) {
            break;
        }
        size_t i = cf->b - 1u;
        if (!decided_peer(node, i) && peer_first(node, i)) {
            return true;
        }
    }
    return result.overflow && result.conflict_count == 0u;
}

/* A digest of what an intent says the UAV will fly (its plan's time and offsets, FNV-1a):
 * the copies of one intent, each stamped afresh, have the same. O(samples). */
static uint32_t intent_digest(const coavoid_intent_t *m)
{
    uint32_t h = 2166136261u;
    const int32_t n = m->sample_count < COAVOID_INTENT_T_MAX_SAMPLES ? m->sample_count
                                                                     : COAVOID_INTENT_T_MAX_SAMPLES;
    const uint64_t words[2] = {(uint64_t)m->plan_utime, (uint64_t)(uint32_t)n};
    for (size_t w = 0; w < 2u; w++) {
        for (unsigned b = 0; b < 64u; b += 8u) {
            h = (h ^ (uint32_t)((words[w] >> b) & 0xffu)) * 16777619u;
        }
    }
    for (int32_t j = 0; j < n; j++) {
        for (unsigned b = 0; b < 32u; b += 8u) {
            h = (h ^ (((uint32_t)m->offsets[j] >> b) & 0xffu)) * 16777619u;
        }
    }
    return h;
}

static bool first_intent(const coavoid_vehicle_node_t *node, const coavoid_node_peer_t *peer);
static bool searches(const coavoid_vehicle_node_t *node);

/* Whether peer's intent is a first intent that a searching UAV counts as a newcomer's
 * (overtaken; note_order keeps its digest). O(1). */
static bool newcomer(const coavoid_vehicle_node_t *node, const coavoid_node_peer_t *peer)
{
    return searches(node) && first_intent(node, peer);
}

/* Remembers which live UAVs come before it as it decides, and a digest of the intent it
 * has of each (overtaken). O(peers^2 + peers * samples). */
static void note_order(coavoid_vehicle_node_t *node)
{
    const coavoid_node_view_t *view = &node->view;
    const bool centralised = node->config.mode == COAVOID_NODE_CENTRALISED;
    const bool news = node->news_cycle == node->state.cycle;
    node->decided_count = 0;
    node->decided_news = node->inbox.world_news;
    node->decided_cycle = node->state.cycle;
    for (size_t i = 0; i < view->live_count; i++) {
        if (!peer_first(node, i)) {
            continue;
        }
        /* Only overtaken()'s answered peers (UAVs started centralised), newcomers and, in a
         * cycle with world news, every UAV before it use the digest. */
        uint32_t digest = 0;
        for (size_t p = 0; p < COAVOID_NODE_MAX_PEERS; p++) {
            const coavoid_intent_t *m = &node->inbox.peers[p].msg;
            if (node->inbox.peers[p].used && (uint16_t)m->uav_id == view->live_id[i]) {
                const bool digested = centralised || news || newcomer(node, &node->inbox.peers[p]);
                digest = digested ? intent_digest(m) : 0u;
                break; /* one slot per UAV */
            }
        }
        node->decided_id[node->decided_count] = view->live_id[i];
        node->decided_sequence[node->decided_count] = view->live_info[i].sequence;
        node->decided_digest[node->decided_count] = digest;
        node->decided_count++;
    }
}

/* The rank its order search agreed this cycle for UAV id, -1 when none. O(members). */
static int32_t agreed_rank_of(const coavoid_vehicle_node_t *node, uint16_t id)
{
    for (size_t a = 0; a < node->agreed_count && node->agreed_cycle == node->state.cycle; a++) {
        if (node->agreed_id[a] == id) {
            return node->agreed_rank[a];
        }
    }
    return -1;
}

/* Whether, since it decided in this cycle, a UAV with a raised rank that comes before it
 * now published an intent of this cycle it did not decide on: one that raised its rank
 * above it after it decided, or one before it that planned again. Only raised ranks
 * count, so that with every rank 0 a UAV decides once per cycle, as before priority
 * negotiation; but for a UAV before it in its first cycle (a newcomer) whose first intent
 * it had not heard when it decided (lost, and come by a copy: it would have waited for
 * it), or which published another plan since (it had decided from fewer first intents
 * than came later; intent_digest: a copy is not another plan). Without loss that never
 * happens (each decides after the UAVs before it published, on all of theirs). Started
 * centralised, it also decides again on a UAV before it that answered its own conflict
 * at the answer wait (rank 0, mode decoupled), or switched to its row of a coordinator's
 * plan (row_flown), with another plan than the one it decided on (intent_digest: a copy
 * is not another plan). In a cycle it decided again on world news
 * (reconsider), so do the UAVs before it, with another plan too. O(peers^2 + peers *
 * samples). */
static bool overtaken(const coavoid_vehicle_node_t *node)
{
    const coa_vehicle_t *self = &node->config.vehicle;
    const bool news = node->news_cycle == node->state.cycle;
    for (size_t i = 0; i < COAVOID_NODE_MAX_PEERS; i++) {
        const coavoid_intent_t *m = &node->inbox.peers[i].msg;
        if (!node->inbox.peers[i].used || m->plan_utime != node->cycle_start) {
            continue; /* before the row comparison: no intent of this cycle to compare */
        }
        const bool first = m->rank <= 0 && (newcomer(node, &node->inbox.peers[i]) || news);
        const bool answered =
            node->config.mode == COAVOID_NODE_CENTRALISED && m->rank <= 0 &&
            (m->mode == COAVOID_INTENT_T_MODE_DECOUPLED ||
             row_flown(node, (uint16_t)m->uav_id, m->offsets, (size_t)m->sample_count));
        if ((m->rank <= 0 && !first && !answered) ||
            !coavoid_node_precedes(m->rank, (uint32_t)m->priority, (uint16_t)m->uav_id,
                                   node->state.rank, self->priority, self->id)) {
            continue;
        }
        if (agreed_rank_of(node, (uint16_t)m->uav_id) == m->rank) {
            continue; /* a member of its agreed order, where it was expected */
        }
        size_t j = 0;
        while (j < node->decided_count && node->decided_id[j] != (uint16_t)m->uav_id) {
            j++;
        }
        if (j == node->decided_count) {
            return true;
        }
        const bool changed = answered || first ? node->decided_digest[j] != intent_digest(m)
                                               : node->decided_sequence[j] < m->sequence;
        if (changed) {
            return true;
        }
    }
    return false;
}

/* ---- the order search (docs/protocol.md, "Priority negotiation") ---- */

/* Adds `msg` to the view of the cycle's start (node->view) as `kind`: converted as every
 * node converts it; SNAPSHOT_FIRST with its first offset held and rank 0. Returns false
 * when it does not fit or convert. O(N). */
static bool snapshot_add(coavoid_vehicle_node_t *node, const coavoid_intent_t *msg, uint8_t kind)
{
    coavoid_node_view_t *view = &node->view;
    const size_t i = view->live_count;
    const coavoid_lcm_context_t ctx =
        coavoid_node_context(&node->inbox, node->cycle_start, node->cycle_start);
    if (i >= COAVOID_NODE_MAX_PEERS ||
        coavoid_lcm_intent_to_core(msg, &ctx, NULL, &view->live_info[i], &view->live_vehicle[i],
                                   &view->live_plan[i], &view->live_arrays[i], NULL) != COA_OK) {
        return false;
    }
    if (kind == SNAPSHOT_FIRST) {
        coavoid_lcm_intent_arrays_t *a = &view->live_arrays[i];
        const coa_real_t dh = coa_climb_step(&view->live_vehicle[i], node->config.common.dt);
        for (size_t j = 0; j < view->live_plan[i].count; j++) {
            a->offsets[j] = a->offsets[0];
            a->samples[j] = lifted(a->reference[j], a->offsets[0], dh);
        }
        view->live_info[i].rank = 0;
    }
    view->live_id[i] = (uint16_t)msg->uav_id;
    view->live_current[i] = false;
    node->order_kind[i] = kind;
    view->live_count++;
    return true;
}

/* Whether it runs the order search when it decides for itself: unless told to negotiate
 * greedily. One configured centralised searches only in the cycles it distrusts its
 * coordinator (decide_own; at the answer wait it decides without a search, and
 * reconsider() skips it while it follows), and the search's group leaves out every UAV
 * whose intent says it follows (order_eligible), so no search hands a row to a UAV that
 * flies the coordinator's. O(1). */
static bool searches(const coavoid_vehicle_node_t *node)
{
    return !node->config.greedy_negotiation;
}

/* At the cycle's start (fly_to): itself as its peers will have it when they search
 * (node->order_own): its last intent of the cycle before, or in its first cycle its
 * intent with the offset it starts at held, encoded as it would publish it. */
static void snapshot_own(coavoid_vehicle_node_t *node)
{
    const coavoid_node_common_t *c = &node->config.common;
    const coavoid_intent_t *last = &node->tx_intent;
    node->order_own_kind = SNAPSHOT_NONE;
    if (!searches(node)) {
        return; /* it never searches (decide_own) */
    }
    if (node->intent_sequence > 0 && last->plan_utime == node->cycle_start - c->dt_us) {
        node->order_own = *last;
        node->order_own_kind = SNAPSHOT_PREVIOUS;
    } else if (node->first_cycle_start == node->cycle_start) {
        coavoid_lcm_intent_info_t info = intent_info(node, node->cycle_start, 0);
        info.mode = COAVOID_INTENT_T_MODE_DECOUPLED;
        info.rank = 0;
        const coavoid_lcm_context_t ctx =
            coavoid_node_context(&node->inbox, node->cycle_start, node->cycle_start);
        node->order_own_kind =
            coavoid_lcm_intent_from_core(&node->config.vehicle, &info, node->own_reference,
                                         node->own_offsets, (size_t)c->horizon + 1u, &ctx,
                                         &node->order_own, NULL) == COA_OK
                ? SNAPSHOT_FIRST
                : SNAPSHOT_NONE;
    }
}

/* Whether a peer is in the view of the cycle's start by its first intent, of this cycle:
 * the only way that view grows within a cycle. O(1). */
static bool first_intent(const coavoid_vehicle_node_t *node, const coavoid_node_peer_t *peer)
{
    const int64_t start = node->cycle_start;
    return peer->used && peer->msg.plan_utime == start &&
           !(peer->has_prev && peer->prev.plan_utime < start);
}

/* How many peers are in the view of the cycle's start by their first intent. O(peers). */
static size_t first_intents(const coavoid_vehicle_node_t *node)
{
    size_t n = 0;
    for (size_t p = 0; p < COAVOID_NODE_MAX_PEERS; p++) {
        n += first_intent(node, &node->inbox.peers[p]) ? 1u : 0u;
    }
    return n;
}

/* The view of the cycle's start in node->view: every UAV by its intent of an earlier
 * cycle (SNAPSHOT_PREVIOUS when of the cycle before), a UAV whose first intent is of
 * this cycle as SNAPSHOT_FIRST, and itself last (snapshot_own), whatever came since the
 * cycle began: every member builds it alike. Returns its own index, or live_count when it
 * is not in it. O(peers * N). */
static size_t snapshot(coavoid_vehicle_node_t *node, int64_t previous)
{
    coavoid_node_view_t *view = &node->view;
    const int64_t start = node->cycle_start;
    coavoid_node_view_build_before(view, &node->inbox, start, start, start);
    for (size_t i = 0; i < view->live_count; i++) {
        node->order_kind[i] =
            view->live_info[i].plan_utime == previous ? SNAPSHOT_PREVIOUS : SNAPSHOT_NONE;
    }
    node->searched_first = 0;
    for (size_t p = 0; p < COAVOID_NODE_MAX_PEERS; p++) {
        const coavoid_node_peer_t *peer = &node->inbox.peers[p];
        if (first_intent(node, peer)) {
            node->searched_first++;
            (void)snapshot_add(node, &peer->msg, SNAPSHOT_FIRST);
        }
    }
    if (node->order_own_kind == SNAPSHOT_NONE ||
        !snapshot_add(node, &node->order_own, node->order_own_kind)) {
        return view->live_count;
    }
    view->live_id[view->live_count - 1u] = node->config.vehicle.id;
    return view->live_count - 1u;
}

/* Whether live UAV i of the view of the cycle's start can be searched: it is in it by an
 * intent of the cycle before or its first one (snapshot), says it plans for itself, and
 * spans the horizon. O(1). */
static bool order_eligible(const coavoid_vehicle_node_t *node, size_t i)
{
    const coavoid_node_common_t *c = &node->config.common;
    const coavoid_lcm_intent_info_t *info = &node->view.live_info[i];
    return node->order_kind[i] != SNAPSHOT_NONE && info->mode == COAVOID_INTENT_T_MODE_DECOUPLED &&
           info->step == c->dt && node->view.live_plan[i].count == (size_t)c->horizon + 1u;
}

/* Labels the view of the cycle's start (node->plans) as near_pending judges nearness:
 * UAVs whose paths pass near each other horizontally within the horizon, with every
 * volume as tall as a message allows, joined into groups (coa_predict_clusters). Returns
 * COA_OK or an error. Cost: one coa_predict over the live UAVs. */
static int label_near(coavoid_vehicle_node_t *node, size_t n)
{
    coavoid_node_solver_t *sv = &node->solver;
    for (size_t i = 0; i < n; i++) {
        node->tall[i] = node->plans[i];
        node->tall[i].volume.half_height = (coa_real_t)COAVOID_LCM_MAX_SIZE;
    }
    const coa_predict_config_t config = coavoid_node_predict_config(&node->config.common);
    coa_predict_result_t result;
    int rc = coa_predict(sv->predictor, &config, node->tall, n, NULL, 0, NULL, 0, sv->conflicts,
                         sv->conflict_capacity, &result);
    if (rc == COA_OK && result.overflow) {
        rc = COA_ERR_WORKSPACE;
    }
    size_t groups = 0;
    return rc != COA_OK ? rc
                        : coa_predict_clusters(sv->conflicts, result.conflict_count, n,
                                               node->labels, &groups);
}

/* The UAVs its order search plans (self: its index in the view of the cycle's start),
 * into node->order_member by ascending id: its group of UAVs near each other
 * (label_near), when one of them has a conflict there (its prediction). Not its cluster
 * alone: a UAV outside it whose plan leaves a member no room may have to plan around
 * that member, and only a UAV near can. Returns their count; 0 when none of them has a
 * conflict, or one of them cannot be searched (the greedy raise remains). Cost: two
 * coa_predict. */
static size_t order_members(coavoid_vehicle_node_t *node, size_t self)
{
    const coavoid_node_view_t *view = &node->view;
    coavoid_node_solver_t *sv = &node->solver;
    const size_t n = view->live_count;
    for (size_t i = 0; i < n; i++) {
        node->plans[i] = view->live_plan[i];
    }
    coa_predict_result_t result;
    size_t clusters = 0;
    if (coavoid_node_predict(sv->predictor, &node->config.common, node->plans, n, view,
                             &node->inbox, sv->conflicts, sv->conflict_capacity, &result,
                             node->labels, &clusters) != COA_OK) {
        return 0;
    }
    for (size_t i = 0; i < n; i++) {
        node->include[i] = node->labels[i] != COA_NO_CLUSTER; /* in conflict */
    }
    if (label_near(node, n) != COA_OK || node->labels[self] == COA_NO_CLUSTER) {
        return 0;
    }
    size_t count = 0;
    bool conflict = false;
    for (size_t i = 0; i < n; i++) {
        if (node->labels[i] != node->labels[self]) {
            continue;
        }
        if (!order_eligible(node, i) || count == ORDER_MEMBERS_MAX) {
            return 0;
        }
        conflict = conflict || node->include[i];
        size_t m = count++;
        while (m > 0 && view->live_id[node->order_member[m - 1]] > view->live_id[i]) {
            node->order_member[m] = node->order_member[m - 1];
            m--;
        }
        node->order_member[m] = i;
    }
    return count >= 2u && conflict ? count : 0u;
}

/* The members' problem over `horizon` steps (N + COAVOID_NODE_LOOKAHEAD: search_order
 * searches it over N first, look_ahead whole): each from the offset its intent of the
 * cycle before flies at the cycle's start, along that
 * intent's reference from there (past its last sample, which that intent does not reach,
 * carried on along its last leg: every member extrapolates alike), or in its first cycle
 * from its first intent's offset along its reference (and past it likewise); around
 * everything else of the view (coavoid_node_problem). Returns its error. */
static int order_problem(coavoid_vehicle_node_t *node, size_t count, uint32_t horizon,
                         coa_problem_t *problem)
{
    const uint32_t n = node->config.common.horizon;
    const coavoid_node_view_t *view = &node->view;
    for (size_t i = 0; i < view->live_count; i++) {
        node->include[i] = true;
    }
    for (size_t m = 0; m < count; m++) {
        const size_t i = node->order_member[m];
        const coavoid_lcm_intent_arrays_t *a = &view->live_arrays[i];
        coa_vec3_t *r = node->order_reference[m];
        node->include[i] = false;
        node->order_vehicles[m] = view->live_vehicle[i];
        node->order_references[m] = r;
        uint32_t known = n + 1u; /* samples of r taken from the intent */
        if (node->order_kind[i] == SNAPSHOT_FIRST) {
            memcpy(r, a->reference, known * sizeof r[0]); /* of this cycle */
        } else {
            node->order_vehicles[m].initial_offset = a->offsets[1];
            known = n;
            memcpy(r, &a->reference[1], known * sizeof r[0]);
        }
        /* r[k] is the intent's sample k + shift; past its last, n, along its last leg. */
        const uint32_t shift = n + 1u - known;
        const coa_vec3_t last = a->reference[n];
        const coa_vec3_t leg = {last.x - a->reference[n - 1u].x, last.y - a->reference[n - 1u].y,
                                last.z - a->reference[n - 1u].z};
        for (uint32_t k = known; k <= horizon; k++) {
            const coa_real_t j = (coa_real_t)(k + shift - n);
            r[k].x = last.x + j * leg.x;
            r[k].y = last.y + j * leg.y;
            r[k].z = last.z + j * leg.z;
        }
    }
    int rc = coavoid_node_problem(problem, &node->problem_tracks, view, node->include, &node->inbox,
                                  node->order_vehicles, node->order_references, count, horizon);
    problem->has_floor = node->config.common.has_floor;
    problem->floor_z = node->config.common.min_altitude;
    return rc;
}

/* The members' decoupled order as the intents of the cycle's start announce it (rank,
 * priority, id), as indices into order_member. O(count^2). */
static void order_current(const coavoid_vehicle_node_t *node, size_t count, size_t *order)
{
    const coavoid_node_view_t *view = &node->view;
    for (size_t m = 0; m < count; m++) {
        const size_t x = node->order_member[m];
        size_t p = m;
        while (p > 0) {
            const size_t y = node->order_member[order[p - 1]];
            if (!coavoid_node_precedes(view->live_info[x].rank, view->live_vehicle[x].priority,
                                       view->live_id[x], view->live_info[y].rank,
                                       view->live_vehicle[y].priority, view->live_id[y])) {
                break;
            }
            order[p] = order[p - 1];
            p--;
        }
        order[p] = m;
    }
}

/* The ranks of a solving order: count - p at position p, above every UAV at rank 0. Its
 * own at once; the others' it uses (apply_agreed) until each member's own intent of the
 * cycle announces its rank. Its row of the solving plan goes to node->plan_out
 * (fly_agreed). A new episode of raises begins. O(count + N). */
static void order_agree(coavoid_vehicle_node_t *node, size_t count, const size_t *order,
                        size_t self)
{
    node->agreed_cycle = node->state.cycle;
    node->agreed_count = count;
    for (size_t p = 0; p < count; p++) {
        const size_t i = node->order_member[order[p]];
        node->agreed_id[p] = node->view.live_id[i];
        node->agreed_rank[p] = (int32_t)(count - p);
        if (i == self) {
            const size_t samples = (size_t)node->config.common.horizon + 1u;
            memcpy(node->plan_out, &node->order_offsets[order[p] * samples],
                   samples * sizeof node->plan_out[0]);
            node->state.rank = (int32_t)(count - p);
            node->raises = 0;
            node->calm_cycles = 0;
        }
    }
    node->state.orders_agreed++;
}

/* A search that no longer agrees the order an earlier one of this cycle agreed (its view
 * of the cycle's start grew since: a UAV's first intent came, in its first cycle or
 * after its intents were lost): that order is withdrawn, and its rank and plan are again
 * those it began the cycle with, which the others' searches assume. O(N). */
static void order_withdraw(coavoid_vehicle_node_t *node)
{
    if (node->agreed_cycle == node->state.cycle) {
        node->agreed_cycle = -1;
        node->state.rank = node->order_own.rank;
        /* Back on the plan it began the cycle with. */
        memcpy(node->plan_offsets, node->start_offsets, sizeof node->plan_offsets);
        node->plan_start = node->state.cycle;
        node->plan_count = node->config.common.horizon + 1u;
        build_own(node, node->state.cycle);
    }
}

/* The order search found an order that solves the horizon (*result, rows in
 * order_offsets); the first order that solves it does not know what comes after, and its
 * plan may leave the fleet no way on a step later where another order's would (5-UAV
 * encounter 231 of seed 1). So it looks COAVOID_NODE_LOOKAHEAD steps further, each member
 * and track carried on along its last leg (*problem, built that far and searched so far
 * over N: its first N + 1 samples are the same): when that order also solves the longer
 * horizon, nothing changes; otherwise the first order that does (tried from that one, as
 * coa_plan_decoupled tries them) replaces it, its rows cut to the horizon. When none
 * does, the order stays. Every member looks alike, so they still agree. Returns COA_OK
 * or an error of the search. Cost: at most one more search of the order over N +
 * COAVOID_NODE_LOOKAHEAD steps (search_order's). Memory: ahead_offsets. */
static int look_ahead(coavoid_vehicle_node_t *node, size_t count, coa_problem_t *problem,
                      coa_plan_result_t *result)
{
    const uint32_t n = node->config.common.horizon;
    const uint32_t far = n + COAVOID_NODE_LOOKAHEAD;
    problem->horizon = far;
    coa_plan_result_t ahead;
    int rc = coa_plan_decoupled(node->solver.planner, problem, result->order, ORDER_TRIES_MAX,
                                node->ahead_offsets, &ahead);
    if (rc != COA_OK || ahead.status != COA_PLAN_SOLVED || ahead.orders_tried <= 1u) {
        return rc; /* the order holds beyond the horizon, or no order does */
    }
    for (size_t m = 0; m < count; m++) {
        memcpy(&node->order_offsets[m * (n + 1u)], &node->ahead_offsets[m * (far + 1u)],
               ((size_t)n + 1u) * sizeof node->order_offsets[0]);
    }
    *result = ahead;
    return COA_OK;
}

/* No priority order solves the group (search_order, *problem over the horizon): with
 * joint_members, it plans the group jointly as a coordinator would (coa_plan_centralised,
 * at most joint_beta stored nodes), from the same problem. Every member has the same
 * problem and the search is deterministic, so each finds the same rows, as with an order;
 * it takes its place in the order the ranks announce (`order`: order_current's), its row
 * the joint plan's. Returns 1 when agreed; 0 when the group has more than joint_members
 * UAVs or the search finds no plan (infeasible, or out of beta: the greedy raise
 * remains; the same problem again in the cycle, or one the memo holds, is not searched
 * again); or an error of the search. Cost: a digest of the problem, and one joint search
 * (2n tables, then at most joint_beta stored nodes a group). Memory: the node's planner,
 * sized for it at create. */
static int search_joint(coavoid_vehicle_node_t *node, size_t count, size_t self,
                        const coa_problem_t *problem, const size_t *order)
{
    if (count > node->config.joint_members) {
        return 0;
    }
    /* The order search runs several times a cycle on the same intents (overtaken, a
     * first intent, world news); the same problem fails the same way, and so it does in
     * the search of any vehicle that shares the memo (the same beta and work: in the key). */
    const uint64_t digest = coavoid_node_problem_digest(problem);
    const uint64_t key = coavoid_node_fnv(
        coavoid_node_fnv(digest, &node->config.joint_beta, sizeof node->config.joint_beta),
        &node->config.joint_work, sizeof node->config.joint_work);
    if ((node->joint_failed_cycle == node->state.cycle && node->joint_failed_digest == digest) ||
        coavoid_node_joint_memo_has(node->config.joint_memo, key)) {
        return 0;
    }
    coa_plan_result_t result;
    (void)coa_planner_set_work(node->solver.planner, node->config.joint_work);
    const int rc =
        coa_plan_centralised(node->solver.planner, problem, node->order_offsets, &result);
    (void)coa_planner_set_work(node->solver.planner, 0u); /* its other searches: tables */
    if (rc != COA_OK) {
        return rc;
    }
    if (result.status != COA_PLAN_SOLVED) {
        node->joint_failed_cycle = node->state.cycle;
        node->joint_failed_digest = digest;
        coavoid_node_joint_memo_add(node->config.joint_memo, key);
        return 0;
    }
    order_agree(node, count, order, self);
    node->state.joint_plans++;
    return 1;
}

/* The order search, at the start of a decoupled cycle and again within it (decide_own,
 * search_again). From the intents as they stood when the cycle began (snapshot: each
 * UAV's last of the cycle before, its own included, whatever came since), it predicts, and
 * when its group of UAVs near each other has a conflict (order_members), plans the group
 * as coa_plan_decoupled does, first in the order the ranks announce; only when that order
 * fails it tries the others (at most ORDER_TRIES_MAX), and when one solves takes its
 * place in it (order_agree). Every member has the same intents when none was lost, so
 * each finds the same order and rows without a message or a central node, and the ranks
 * they announce make the order hold for anyone who did not. When none does, the group's
 * joint plan may (search_joint). Changes nothing when the current order solves, or
 * nothing does (but withdraws an order it agreed earlier in the cycle: order_withdraw).
 * Returns 1 when it agreed a new order or a joint plan, 0 when not, or an error of the
 * search (then the greedy raise remains). Cost: one view, two predictions; with a
 * conflict, a decoupled plan of at most ORDER_MEMBERS_MAX UAVs, and when the order fails
 * at most ORDER_TRIES_MAX orders of at most ORDER_MEMBERS_MAX single-UAV searches each
 * (coa_plan_decoupled's cost), and when none solves search_joint's. Memory: the node's
 * (order_*) and its solver's workspace. */
static int search_order(coavoid_vehicle_node_t *node)
{
    const size_t self = snapshot(node, node->cycle_start - node->config.common.dt_us);
    if (self == node->view.live_count) {
        return COA_OK;
    }
    const size_t count = order_members(node, self);
    if (count == 0u) {
        order_withdraw(node);
        return COA_OK;
    }
    /* Built once as far as the look-ahead reaches; searched over N first. */
    coa_problem_t problem;
    int rc =
        order_problem(node, count, node->config.common.horizon + COAVOID_NODE_LOOKAHEAD, &problem);
    if (rc != COA_OK) {
        return rc;
    }
    problem.horizon = node->config.common.horizon;
    size_t order[ORDER_MEMBERS_MAX];
    order_current(node, count, order);
    coa_plan_result_t result;
    rc = coa_plan_decoupled(node->solver.planner, &problem, order, ORDER_TRIES_MAX,
                            node->order_offsets, &result);
    if (rc != COA_OK || result.orders_tried <= 1u) {
        order_withdraw(node);
        return rc != COA_OK ? rc : 0; /* the order holds: a check, not a plan of its own */
    }
    node->state.plans_run++;
    if (result.status != COA_PLAN_SOLVED) {
        rc = search_joint(node, count, self, &problem, order);
        if (rc != 1) {
            order_withdraw(node);
        }
        return rc;
    }
    rc = look_ahead(node, count, &problem, &result);
    if (rc != COA_OK) {
        order_withdraw(node);
        return rc;
    }
    order_agree(node, count, result.order, self);
    return 1;
}

static int decide(coavoid_vehicle_node_t *node, int64_t now);
static int decide_own(coavoid_vehicle_node_t *node, int64_t now);
static void switch_to_pending(coavoid_vehicle_node_t *node, int64_t now);
static bool all_accepted(const coavoid_vehicle_node_t *node);

/* In a cycle whose order search agreed a new order: it flies its row of the solving plan
 * (node->plan_out) at once, as every other member does with its own, once the check every
 * plan gets finds it clear of the obstacles and tracks it knows (its row was planned
 * around the others' intents of the cycle's start, which their rows replace), and
 * publishes it with its new rank. A row that fails the check is left: it decides as any
 * cycle (decide), in the agreed order. Returns as decide. */
static int fly_agreed(coavoid_vehicle_node_t *node, int64_t now)
{
    (void)gather(node, now);
    note_order(node);
    memset(node->include, 0, sizeof node->include);
    const uint32_t samples = node->config.common.horizon + 1u;
    int hit = plan_hits_known(node, node->plan_out, samples, now, true);
    if (hit != 0) {
        return decide(node, now);
    }
    adopt(node, node->plan_out, samples);
    node->state.last_outcome = (int)COA_PLAN_SOLVED;
    node->cycle_conflict = true;
    settle_rank(node, true);
    return finish(node, now);
}

/* With a plan of the coordinator's it accepted and holds undecided at the answer wait: a
 * standby plan, flown at t_{k+1} only if no COMMIT (nor a sibling's SWITCHED) comes, which
 * would switch it to the held row. The standby avoids every live UAV on its intent (the
 * future of a sibling that never switches) and, checked as a coordinator's plan is, every
 * sibling on its row (the future of one that switches); without such a plan it keeps
 * the one it flies, as before. Returns COA_OK (whatever the outcome) or a negative error;
 * *adopted tells whether it has a standby. Cost: one search and one plan check. */
static int standby(coavoid_vehicle_node_t *node, int64_t now, bool *adopted)
{
    *adopted = false;
    for (size_t i = 0; i < node->view.live_count; i++) {
        node->include[i] = true;
    }
    coa_plan_result_t result;
    int rc = search_self(node, now, &result);
    if (rc != COA_OK || result.status != COA_PLAN_SOLVED) {
        return rc;
    }
    const uint32_t samples = node->config.common.horizon + 1u;
    int hit = plan_hits_known(node, node->plan_out, samples, now, false);
    if (hit != 0) {
        return hit < 0 ? hit : COA_OK;
    }
    adopt(node, node->plan_out, samples);
    *adopted = true;
    return COA_OK;
}

/* It distrusts its coordinator from cycle k (at `now`): it plans for itself until
 * update_trust() lets it follow again. O(1). */
static void distrust_from(coavoid_vehicle_node_t *node, int64_t k, int64_t now)
{
    node->distrust = true;
    node->distrust_cycle = k;
    node->distrust_utime = now;
}

/* Every UAV of the plan it holds holds it and said so, and no decision came by the
 * coordinator's ack timeout (dt / 4 by default) after it accepted, plus four resends (an
 * ABORT goes out with four copies): a coordinator that heard those answers would have
 * committed, so it stopped, or every copy of its decision was lost. It commits as the
 * coordinator would: it switches and says SWITCHED, which its siblings take as the
 * commit. Returns 1 (it published). */
static int self_commit(coavoid_vehicle_node_t *node, int64_t now)
{
    node->state.plans_self_committed++;
    switch_to_pending(node, now);
    phase_on(node, COAVOID_VEHICLE_EVENT_SELF_COMMIT);
    return 1;
}

/* Following its coordinator, answer_wait_us into the cycle, with a conflict of its own and
 * no plan of the coordinator's adopted (told that a search failed for it or not): it plans
 * for itself in this cycle and announces it. Holding no plan, it accepted none, so no
 * COMMIT can include it: it decides as a decoupled UAV (decide()), waiting up to a quarter
 * cycle for the UAVs before it that answer themselves at the same time. Holding an
 * undecided one, it plans a standby (standby()). Waiting for the next cycle's fallback
 * instead could leave a conflict one step ahead unsolved (a coordinator that stops in
 * cycle 0 before its first plan is agreed). Returns 1 when it published, 0 when there was
 * nothing to do or it waits, or a negative error. Cost: one prediction, then as decide or
 * standby. */
static int answer_overdue(coavoid_vehicle_node_t *node, int64_t now)
{
    phase_on(node, COAVOID_VEHICLE_EVENT_ANSWER_WAIT);
    if (flies_plan(node)) {
        return 0; /* a failed search it was told of is no answer by now: on_plan */
    }
    coa_predict_result_t result;
    int rc = predict(node, gather(node, now), &result);
    if (rc != COA_OK) {
        node->fault = true;
        return rc;
    }
    if (node->labels[0] == COA_NO_CLUSTER) {
        return 0;
    }
    node->cycle_conflict = true;
    if (!holds_plan(node)) {
        /* Distrusted as an unanswered UAV's: it decides for itself in the next cycle too,
         * unless it hears the coordinator again by then. */
        distrust_from(node, node->state.cycle, now);
        node->self_answered = true;
        phase_on(node, COAVOID_VEHICLE_EVENT_UNANSWERED);
        const int64_t last = node->cycle_start + node->config.common.dt_us - 1;
        const int64_t until = now + node->config.answer_wait_us / 2;
        node->wait_deadline = until < last ? until : last; /* decided within its cycle */
        return decide(node, now);
    }
    const int64_t decided_by =
        node->pending_since + node->config.common.dt_us / 4 + 4 * node->config.resend_us;
    if (all_accepted(node) && now >= decided_by) {
        return self_commit(node, now);
    }
    /* Not yet due (the rows came after the coordinator's collect: delayed, or sent
     * again): it commits when it is, within the cycle, if every UAV has accepted by then;
     * meanwhile it holds a standby as any UAV whose plan is undecided. */
    node->self_commit_at = decided_by;
    node->self_commit_plan = node->pending_plan_id;
    bool planned = false;
    rc = standby(node, now, &planned);
    if (rc == COA_OK && planned) {
        /* It flies the standby unless the plan it holds is committed. */
        phase_on(node, COAVOID_VEHICLE_EVENT_STANDBY);
        plan_on(node, COAVOID_VEHICLE_EVENT_STANDBY);
        rc = publish_intent(node, now);
    }
    node->fault = node->fault || rc != COA_OK;
    return rc != COA_OK ? rc : (planned ? 1 : 0);
}

/* The decoupled step: predict with what it has; publish at once without a conflict;
 * otherwise wait for the members of its cluster before it in the decoupled order (until
 * the deadline), then plan (raising its rank if it must) and publish. Returns 1 when it
 * published, 0 while it waits, or an error. */
static int decide(coavoid_vehicle_node_t *node, int64_t now)
{
    const coavoid_node_view_t *view = &node->view;
    const size_t n = gather(node, now);
    if (now < node->wait_deadline && near_pending(node, n)) {
        phase_on(node, COAVOID_VEHICLE_EVENT_WAIT);
        return 0;
    }
    note_order(node);
    coa_predict_result_t result;
    int rc = predict(node, n, &result);
    if (rc != COA_OK) {
        node->fault = true;
        int published = finish(node, now);
        return published < 0 ? published : rc;
    }
    const uint32_t my = node->labels[0];
    node->cycle_conflict = my != COA_NO_CLUSTER;
    settle_rank(node, node->cycle_conflict);
    if (my == COA_NO_CLUSTER) {
        return finish(node, now);
    }
    bool pending = false;
    for (size_t i = 0; i < view->live_count; i++) {
        if (node->labels[i + 1u] == my && !decided_peer(node, i) && peer_first(node, i)) {
            pending = true;
        }
    }
    if (pending && now < node->wait_deadline) {
        phase_on(node, COAVOID_VEHICLE_EVENT_WAIT);
        return 0;
    }
    /* Every member of a cluster in conflict plans, in the decoupled order, as
     * coa_plan_decoupled orders it, even one whose only conflicts are with lower
     * priorities: ignoring them, it plans around what it must avoid and returns towards
     * its reference where it can. Holding an old offset instead can leave a lower
     * priority no way out. */
    rc = plan_self(node, now, my);
    if (rc == 1) {
        return 0; /* GATHERING */
    }
    if (rc != COA_OK) {
        node->fault = true;
        int published = finish(node, now);
        return published < 0 ? published : rc;
    }
    return finish(node, now);
}

/* After it published this cycle's intent: a UAV's first intent came since its last
 * search (in cycle 0 each UAV hears the others' one by one, some only by a copy), so its
 * view of the cycle's start grew. It searches again: when that agrees an order it flies
 * its row; when it withdraws an order it agreed earlier in the cycle it decides again;
 * otherwise nothing changes (a flight whose order holds flies as before). At most once per
 * such intent. Returns as decide, 0 when there is nothing to do. */
static int search_again(coavoid_vehicle_node_t *node, int64_t now)
{
    const bool agreed = node->agreed_cycle == node->state.cycle;
    const int found = search_order(node);
    if (found != 1 && !(agreed && node->agreed_cycle != node->state.cycle)) {
        return 0;
    }
    node->wait_deadline = node->cycle_start + node->config.priority_wait_us;
    phase_on(node, COAVOID_VEHICLE_EVENT_REDECIDE);
    return found == 1 ? fly_agreed(node, now) : decide(node, now);
}

/* Whether a track it held nothing of, or a new obstacle map, came since it decided in this
 * cycle on its own (not a standby; reconsider() already leaves out a coordinator's plan it
 * switched to): what it decided on lacked it. In its first cycle every node starts at
 * once, so a UAV first in its order decides before the world's first estimates reach it
 * whenever the network has any latency. O(1). */
static bool world_news(const coavoid_vehicle_node_t *node)
{
    return node->decided_cycle == node->state.cycle && !on_standby(node) &&
           node->inbox.world_news != node->decided_news;
}

/* After it published this cycle's intent on its own decision (not a coordinator's plan
 * it switched to in the cycle, which its siblings fly too): when it has been overtaken
 * (overtaken()) or the world it knows grew since (world_news()), it decides again at
 * once, waiting as before (until the cycle's priority wait ends) and publishing its intent
 * again, at most REDECISIONS_MAX times a cycle, so that a raise reorders its cluster, and
 * a track heard late is avoided, within the cycle rather than the next. Returns as
 * decide, 0 when there is nothing to do. */
static int reconsider(coavoid_vehicle_node_t *node, int64_t now)
{
    if (!started(node) || node->state.coordinated || !node->state.published || flies_plan(node)) {
        return 0; /* a coordinator's plan it switched to is flown by every sibling too */
    }
    if (node->redecided_cycle != node->state.cycle) {
        node->redecided_cycle = node->state.cycle;
        node->redecisions = 0;
    }
    if (searches(node) && first_intents(node) > node->searched_first) {
        const int again = search_again(node, now);
        if (again != 0) {
            return again;
        }
    }
    const bool news = world_news(node);
    if (node->redecisions >= REDECISIONS_MAX || !(news || overtaken(node))) {
        return 0;
    }
    node->redecisions++;
    node->news_cycle = news ? node->state.cycle : node->news_cycle;
    phase_on(node, COAVOID_VEHICLE_EVENT_REDECIDE);
    return decide_own(node, now);
}

static void reject(coavoid_vehicle_node_t *node, int code, const char *reason)
{
    coavoid_lcm_rx_count(&node->state.rx, code, reason);
}

/* A plan for it refused: counted, and said in its next heartbeat. */
static void reject_plan(coavoid_vehicle_node_t *node, int code, const char *reason)
{
    node->cycle_plan_refused = true;
    reject(node, code, reason);
}

static int answer(coavoid_vehicle_node_t *node, int64_t now, int8_t kind, int64_t plan_id);
static void answer_with_copies(coavoid_vehicle_node_t *node, int64_t now, int8_t kind,
                               int64_t plan_id);

/* A plan of this cycle for it that it will not fly: refused, and the coordinator told
 * (REFUSE), so that it plans the others again without waiting for its answer. Following
 * the coordinator, with no plan of the cycle adopted or held, it does not wait for the
 * answer wait either: its deadline is now, so the next poll runs answer_overdue, which
 * plans for itself in this cycle when it has a conflict (docs/protocol.md, "Refusals"). */
static void refuse_plan(coavoid_vehicle_node_t *node, int64_t now, int64_t plan_id, int code,
                        const char *reason)
{
    reject_plan(node, code, reason);
    node->state.plans_refused++;
    answer_with_copies(node, now, COAVOID_AGREEMENT_T_KIND_REFUSE, plan_id);
    if (node->state.phase == COAVOID_VEHICLE_FOLLOWING && !flies_plan(node) && !holds_plan(node) &&
        now < node->answer_deadline) {
        node->answer_deadline = now;
    }
}

/* The slot of UAV id's row of this cycle's plans: row_count when it has none. O(rows). */
static size_t row_slot(const coavoid_vehicle_node_t *node, uint16_t id)
{
    size_t slot = 0;
    while (slot < node->row_count && node->row_id[slot] != id) {
        slot++;
    }
    return slot;
}

/* Keeps the other UAVs' rows of a solved plan of this cycle, unless a later plan of the
 * cycle (a larger plan_id) already gave one: the coordinator's newest word on what each
 * will fly. O(rows * (peers + N)). */
static void record_rows(coavoid_vehicle_node_t *node, const coavoid_plan_t *msg,
                        const coavoid_lcm_plan_info_t *info, const coa_plan_result_t *result,
                        const int32_t *offsets)
{
    const size_t samples = (size_t)info->horizon + 1u;
    for (size_t i = 0; i < result->planned_count && i < info->vehicle_count; i++) {
        const uint16_t id = info->uav_ids[i];
        const size_t slot = row_slot(node, id);
        if (id == node->config.vehicle.id || slot == COAVOID_NODE_MAX_PEERS ||
            (slot < node->row_count && node->row_plan_id[slot] >= msg->plan_id)) {
            continue;
        }
        node->row_count += slot == node->row_count ? 1u : 0u;
        node->row_id[slot] = id;
        node->row_plan_id[slot] = msg->plan_id;
        node->row_samples[slot] = (uint32_t)samples;
        memcpy(node->row_offsets[slot], offsets + i * samples, samples * sizeof *offsets);
    }
}

/* Sample j of the row in `slot` (past its end the last offset holds). O(1). */
static int32_t row_offset(const coavoid_vehicle_node_t *node, size_t slot, size_t j)
{
    const uint32_t count = node->row_samples[slot];
    return node->row_offsets[slot][j < count ? j : count - 1u];
}

/* Moves live UAV i of the view onto its row from this cycle's plans, when it has one and
 * its intent is of this cycle (the same samples): reference + row offset * its dh, as it
 * will fly them if it adopts the plan. */
static void apply_row(coavoid_vehicle_node_t *node, size_t i)
{
    coavoid_node_view_t *view = &node->view;
    const size_t slot = row_slot(node, view->live_id[i]);
    if (slot == node->row_count || !view->live_current[i]) {
        return;
    }
    const coa_real_t dh = coa_climb_step(&view->live_vehicle[i], node->config.common.dt);
    coavoid_lcm_intent_arrays_t *a = &view->live_arrays[i];
    for (size_t j = 0; j < view->live_plan[i].count; j++) {
        a->offsets[j] = row_offset(node, slot, j);
        a->samples[j] = lifted(a->reference[j], a->offsets[j], dh);
    }
}

/* Whether UAV id's intent of this cycle (its `count` offsets) is its row of this cycle's
 * plans: it flies a coordinator's plan it switched to, so it has decided for the cycle
 * (decided_peer, overtaken). O(N). */
static bool row_flown(const coavoid_vehicle_node_t *node, uint16_t id, const int32_t *offsets,
                      size_t count)
{
    const size_t slot = row_slot(node, id);
    if (slot == node->row_count) {
        return false;
    }
    for (size_t j = 0; j < count; j++) {
        if (offsets[j] != row_offset(node, slot, j)) {
            return false;
        }
    }
    return true;
}

/* Whether flying `offsets` (a plan's row from this cycle's start, `count` samples; past its
 * end the last offset holds) over this cycle's window runs into what the UAV knows: 1 an
 * obstacle or a track (real tracks and silent UAVs), 2 another live UAV (a coordinator's
 * plan: every live UAV, on its row of this cycle's plans, else on its intent, since a
 * plan must not rely on a move nobody was told to make; its own plan (own): the live UAVs
 * node->include marks, those its search avoided). A coordinator may know less terrain
 * than the UAV, or be an impostor, and a search may have a bug: what the UAV knows it
 * checks before it flies. Returns 0 (clear), 1, 2, or a negative error (it cannot tell).
 * Cost: two conflict checks, O(N * (obstacles + tracks + peers)). */
static int plan_hits_known(coavoid_vehicle_node_t *node, const int32_t *offsets, size_t count,
                           int64_t now, bool own)
{
    const coavoid_node_common_t *c = &node->config.common;
    bool searched[COAVOID_NODE_MAX_PEERS];
    memcpy(searched, node->include, sizeof searched);
    const size_t n = (size_t)c->horizon + 1u;
    for (size_t j = 0; j < n; j++) {
        node->checked[j] = offsets[j < count ? j : count - 1u];
    }
    coavoid_node_view_build(&node->view, &node->inbox, node->cycle_start, now);
    coa_vehicle_t vehicle;
    const coa_vec3_t *references[1];
    const size_t which[1] = {0};
    int hit = 0;
    for (int pass = 1; pass <= 2 && hit == 0; pass++) {
        for (size_t i = 0; i < node->view.live_count; i++) {
            node->include[i] = pass == 2 && (!own || searched[i]);
            if (pass == 2 && !own) {
                apply_row(node, i);
            }
        }
        int rc = coavoid_node_problem_tracks(&node->problem_tracks, &node->view, node->include, c,
                                             c->horizon);
        if (rc != COA_OK) {
            return rc;
        }
        coa_problem_t problem = own_problem(node, &vehicle, references);
        rc = coa_plan_find_conflict(&problem, node->checked, which, 1, NULL, NULL);
        hit = rc > 0 ? pass : rc;
    }
    return hit;
}

/* ---- the agreement on a coordinator's plan (docs/protocol.md) ---- */

/* Says `kind` on plan_id now, and again intent_copies times, resend_us apart, unless a
 * later answer replaces it: an answer lost stalls the plan until the coordinator sends
 * the plan again. */
static void answer_with_copies(coavoid_vehicle_node_t *node, int64_t now, int8_t kind,
                               int64_t plan_id)
{
    (void)answer(node, now, kind, plan_id);
    node->answer_kind = kind;
    node->answer_plan_id = plan_id;
    node->answer_copies_left = node->config.intent_copies;
    node->answer_copy_at = now + node->config.resend_us;
}

static int answer(coavoid_vehicle_node_t *node, int64_t now, int8_t kind, int64_t plan_id)
{
    coavoid_agreement_t *msg = &node->tx_agreement;
    memset(msg, 0, sizeof *msg);
    msg->utime = now;
    msg->kind = kind;
    msg->node_id = node->config.vehicle.id;
    msg->coordinator_id = node->config.coordinator_id;
    msg->plan_id = plan_id;
    msg->valid_from_utime = node->cycle_start;
    int rc = coavoid_node_publish_agreement(&node->inbox.tx, msg);
    node->fault = node->fault || rc != COA_OK;
    return rc;
}

/* Holds its row of a whole, checked plan until the plan is committed, and says so. */
static void hold(coavoid_vehicle_node_t *node, int64_t now, const coavoid_lcm_plan_info_t *info,
                 const int32_t *row, size_t samples)
{
    plan_on(node, COAVOID_VEHICLE_EVENT_ACCEPT);
    node->pending_plan_id = info->plan_id;
    node->pending_count = (uint32_t)samples;
    memcpy(node->pending_offsets, row, samples * sizeof row[0]);
    node->pending_members = info->vehicle_count;
    node->pending_since = now;
    for (size_t i = 0; i < info->vehicle_count; i++) {
        node->pending_ids[i] = info->uav_ids[i];
        node->pending_accepted[i] = info->uav_ids[i] == node->config.vehicle.id;
    }
    node->state.plans_accepted++;
    answer_with_copies(node, now, COAVOID_AGREEMENT_T_KIND_ACCEPT, info->plan_id);
}

/* Flies the plan it holds from now on: committed by the coordinator, or a sibling's
 * SWITCHED says it was. Says SWITCHED (again resend_us later, intent_copies times) and
 * announces its new intent at once, so that every node learns of the change this cycle. */
static void switch_to_pending(coavoid_vehicle_node_t *node, int64_t now)
{
    plan_on(node, COAVOID_VEHICLE_EVENT_COMMIT);
    adopt(node, node->pending_offsets, node->pending_count);
    node->cycle_plan_id = node->pending_plan_id;
    node->state.plans_switched++;
    answer_with_copies(node, now, COAVOID_AGREEMENT_T_KIND_SWITCHED, node->cycle_plan_id);
    if (node->state.published) {
        (void)publish_intent(node, now);
    }
}

static bool pending_member(const coavoid_vehicle_node_t *node, int32_t id)
{
    for (size_t i = 0; i < node->pending_members; i++) {
        if ((int32_t)node->pending_ids[i] == id) {
            return true;
        }
    }
    return false;
}

/* Notes a sibling's ACCEPT of the plan it holds. O(members). */
static void note_accept(coavoid_vehicle_node_t *node, int32_t id)
{
    for (size_t i = 0; i < node->pending_members; i++) {
        node->pending_accepted[i] =
            node->pending_accepted[i] || (int32_t)node->pending_ids[i] == id;
    }
}

/* Whether every UAV of the plan it holds has accepted it, as far as it heard. O(members). */
static bool all_accepted(const coavoid_vehicle_node_t *node)
{
    for (size_t i = 0; i < node->pending_members; i++) {
        if (!node->pending_accepted[i]) {
            return false;
        }
    }
    return true;
}

/* A word on a plan of its coordinator's (the inbox checked signature, role and fields). */
static int on_agreement(void *owner, const coavoid_agreement_t *msg)
{
    coavoid_vehicle_node_t *node = owner;
    const int64_t now = *node->config.common.clock;
    const bool this_cycle = started(node) && msg->valid_from_utime == node->cycle_start &&
                            now < node->cycle_start + node->config.common.dt_us;
    if (!this_cycle) {
        return COA_OK; /* late, or of a plan it never held */
    }
    const bool held = holds_plan(node) && msg->plan_id == node->pending_plan_id;
    const bool flown = flies_plan(node) && msg->plan_id == node->cycle_plan_id;
    if (msg->kind == COAVOID_AGREEMENT_T_KIND_COMMIT && flown) {
        (void)answer(node, now, COAVOID_AGREEMENT_T_KIND_SWITCHED, msg->plan_id); /* unheard */
    } else if (held && (msg->kind == COAVOID_AGREEMENT_T_KIND_COMMIT ||
                        (msg->kind == COAVOID_AGREEMENT_T_KIND_SWITCHED &&
                         pending_member(node, msg->node_id)))) {
        switch_to_pending(node, now);
    } else if (held && msg->kind == COAVOID_AGREEMENT_T_KIND_ACCEPT) {
        note_accept(node, msg->node_id);
    } else if (held && msg->kind == COAVOID_AGREEMENT_T_KIND_ABORT) {
        plan_on(node, COAVOID_VEHICLE_EVENT_ABORT);
        node->answer_copies_left = 0;
        node->state.plans_aborted++;
    }
    return COA_OK;
}

/* A plan of this cycle it already answered, sent again because its answer was lost:
 * answered again, as before (its own copies of the answer were all lost, or are not yet
 * sent). */
static bool answer_again(coavoid_vehicle_node_t *node, int64_t now, const coavoid_plan_t *msg)
{
    if (!started(node) || msg->valid_from_utime != node->cycle_start) {
        return false;
    }
    if (holds_plan(node) && msg->plan_id == node->pending_plan_id) {
        (void)answer(node, now, COAVOID_AGREEMENT_T_KIND_ACCEPT, msg->plan_id);
        return true;
    }
    if (flies_plan(node) && msg->plan_id == node->cycle_plan_id) {
        (void)answer(node, now, COAVOID_AGREEMENT_T_KIND_SWITCHED, msg->plan_id);
        return true;
    }
    return false;
}

/* The inbox's row hook: any one message of a plan it holds or flies is an answer lost. */
static bool on_plan_row(void *owner, const coavoid_plan_t *msg)
{
    coavoid_vehicle_node_t *node = owner;
    return answer_again(node, *node->config.common.clock, msg);
}

/* Why this UAV cannot fly a plan's row of this cycle (`samples` offsets from the cycle's
 * start; past its end the last offset holds), or NULL: an offset beyond its max_offset, a
 * step it cannot take, or a sample that puts its volume below its floor (node.h), judged
 * at the positions it would fly (reference + offset * dh, as the planner computes them).
 * O(N). */
static const char *row_unflyable(const coavoid_vehicle_node_t *node, const int32_t *mine,
                                 size_t samples)
{
    const coavoid_node_common_t *c = &node->config.common;
    const coa_vehicle_t *self = &node->config.vehicle;
    for (size_t j = 0; j < samples; j++) {
        if (self->max_offset >= 0 && (mine[j] > self->max_offset || mine[j] < -self->max_offset)) {
            return "plan: an offset beyond this UAV's max_offset";
        }
        if (j > 0 && coa_action_between(mine[j - 1], mine[j], self->steep_factor) < 0) {
            return "plan: a step this UAV cannot fly";
        }
    }
    for (size_t j = 0; c->has_floor && j <= c->horizon; j++) {
        const coa_vec3_t p =
            lifted(node->own_reference[j], mine[j < samples ? j : samples - 1u], node->dh);
        if (!coa_above_floor(c->min_altitude, &self->volume, p.z)) {
            return "plan: takes this UAV below its floor (min_altitude)";
        }
    }
    return NULL;
}

/* Step 4 of node.h: a coordinator's plan that lists it. */
static void on_plan(void *owner, const coavoid_plan_t *msg, const coavoid_lcm_plan_info_t *info,
                    const coa_plan_result_t *result, const int32_t *offsets)
{
    coavoid_vehicle_node_t *node = owner;
    const coa_vehicle_t *self = &node->config.vehicle;
    const int64_t now = *node->config.common.clock;
    size_t row = SIZE_MAX;
    for (size_t i = 0; i < info->vehicle_count; i++) {
        if (info->uav_ids[i] == self->id) {
            row = i;
        }
    }
    if (row != SIZE_MAX && result->status != COA_PLAN_SOLVED && !info->abandoned && started(node) &&
        msg->valid_from_utime == node->cycle_start && now < msg->valid_until_utime) {
        /* The coordinator tried this cycle and found nothing: that answers the cycle for
         * update_trust (a UAV told so is not unanswered at its end), and it may still send
         * a larger plan that includes it. A UAV that holds neither that nor a plan of its
         * own by the answer wait plans for itself all the same: the coordinator may have
         * stopped right after the notice, and flying on into a conflict answers nothing. */
        node->cycle_plan_failed = true;
    }
    if (result->status == COA_PLAN_SOLVED && started(node) &&
        msg->valid_from_utime == node->cycle_start && now < msg->valid_until_utime) {
        record_rows(node, msg, info, result, offsets);
    }
    if (row == SIZE_MAX || result->status != COA_PLAN_SOLVED || row >= result->planned_count) {
        coavoid_lcm_rx_count(&node->state.rx, COA_OK, NULL); /* not a plan for it */
        return;
    }
    if (!started(node) || msg->valid_from_utime != node->cycle_start) {
        reject_plan(node, COAVOID_LCM_ERR_TIME, "plan: valid_from is not this cycle's start");
        return;
    }
    if (now >= msg->valid_until_utime) {
        reject_plan(node, COAVOID_LCM_ERR_TIME, "plan: arrived after valid_until");
        return;
    }
    if (flies_plan(node) && msg->plan_id <= node->cycle_plan_id) {
        refuse_plan(node, now, msg->plan_id, COAVOID_LCM_ERR_SEQUENCE,
                    "plan: plan_id not after the one adopted this cycle");
        return;
    }
    if (msg->dt != (double)node->config.common.dt) {
        refuse_plan(node, now, msg->plan_id, COAVOID_LCM_ERR_VALUE, "plan: dt is not this UAV's");
        return;
    }
    const size_t samples = (size_t)info->horizon + 1u;
    const int32_t *mine = offsets + row * samples;
    if (mine[0] != node->state.offset) {
        refuse_plan(node, now, msg->plan_id, COAVOID_LCM_ERR_VALUE,
                    "plan: does not start at the offset flown now");
        return;
    }
    const char *unflyable = row_unflyable(node, mine, samples);
    if (unflyable != NULL) {
        refuse_plan(node, now, msg->plan_id, COAVOID_LCM_ERR_VALUE, unflyable);
        return;
    }
    int hit = plan_hits_known(node, mine, samples, now, false);
    if (hit != 0) {
        refuse_plan(node, now, msg->plan_id, hit > 0 ? COAVOID_LCM_ERR_VALUE : hit,
                    hit == 1 ? "plan: flies this UAV into an obstacle or track it knows"
                    : hit == 2
                        ? "plan: flies this UAV into another UAV's plan or intent"
                        : "plan: cannot be checked against the obstacles and tracks it knows");
        return;
    }
    hold(node, now, info, mine, samples);
    coavoid_lcm_rx_count(&node->state.rx, COA_OK, NULL);
}

/* The configured times left 0 (or, for the answer wait and copies, negative) take their
 * defaults (node.h). O(1). */
static void fill_defaults(coavoid_vehicle_node_config_t *config)
{
    const int64_t dt_us = config->common.dt_us;
    const int64_t half = dt_us / 2 > 0 ? dt_us / 2 : 1;
    if (config->coordinator_timeout_us == 0) {
        config->coordinator_timeout_us = (int64_t)llround(2.5 * (double)dt_us);
    }
    if (config->priority_wait_us == 0) {
        config->priority_wait_us = half;
    }
    if (config->resend_us <= 0) {
        config->resend_us = dt_us / 40 > 0 ? dt_us / 40 : 1;
    }
    if (config->answer_wait_us <= 0) {
        config->answer_wait_us = half + 4 * config->resend_us;
    }
    if (config->joint_beta == 0u) {
        config->joint_beta = COAVOID_NODE_DEFAULT_JOINT_BETA;
    }
    if (config->joint_work == 0u) {
        config->joint_work = coavoid_node_work_of(dt_us / 4);
    }
}

/* A vehicle before its first cycle: flying its initial offset, nothing decided. */
static void vehicle_start(coavoid_vehicle_node_t *node, const coavoid_vehicle_node_config_t *config)
{
    node->config = *config;
    node->dh = coa_climb_step(&node->config.vehicle, config->common.dt);
    node->plan_start = 0;
    node->plan_count = 1;
    node->plan_offsets[0] = node->config.vehicle.initial_offset;
    node->state.cycle = -1;
    node->settled_cycle = -1;
    node->redecided_cycle = node->agreed_cycle = node->news_cycle = node->decided_cycle = -1;
    node->joint_failed_cycle = -1;
    node->self_commit_at = INT64_MAX;
    node->state.offset = node->config.vehicle.initial_offset;
    node->state.last_outcome = -1;
    node->wait_deadline = INT64_MAX;
}

/* Checks config and fills *filled (its defaults) and *shape (its planner's and
 * predictor's sizes). COA_OK or COA_ERR_ARGUMENT. */
static int vehicle_prepare(const coavoid_vehicle_node_config_t *config,
                           coavoid_vehicle_node_config_t *filled,
                           coavoid_node_solver_shape_t *shape)
{
    if (config == NULL || coavoid_node_common_check(&config->common) != COA_OK ||
        !coavoid_node_floor_ok(&config->common) || coa_vehicle_check(&config->vehicle) != COA_OK ||
        (config->mode != COAVOID_NODE_CENTRALISED && config->mode != COAVOID_NODE_DECOUPLED) ||
        config->coordinator_timeout_us < 0 || config->priority_wait_us < 0 ||
        !isfinite((double)config->sigma_horizontal) || !isfinite((double)config->sigma_vertical) ||
        config->sigma_horizontal < (coa_real_t)0 || config->sigma_vertical < (coa_real_t)0 ||
        !(coa_climb_step(&config->vehicle, config->common.dt) > (coa_real_t)0) ||
        config->joint_members == 1u || config->joint_members > COA_MAX_CENTRALISED) {
        return COA_ERR_ARGUMENT;
    }
    *filled = *config;
    if (filled->coordinator_id == 0u) {
        filled->coordinator_id = (uint16_t)COAVOID_NODE_COORDINATOR_ID;
    }
    if (filled->coordinator_id == config->vehicle.id) {
        return COA_ERR_ARGUMENT; /* its own heartbeats and plans would be its coordinator's */
    }
    fill_defaults(filled);
    /* One planner: its own searches, the order search's, and its group's joint plan. */
    const bool joint = filled->joint_members > 0u;
    shape->horizon = config->common.horizon;
    shape->plan_horizon = config->common.horizon + COAVOID_NODE_LOOKAHEAD;
    shape->searched = joint ? filled->joint_members : 1u;
    shape->beta = joint ? filled->joint_beta : config->common.beta;
    return coavoid_node_solver_size(shape) > 0u ? COA_OK : COA_ERR_ARGUMENT;
}

/* The bytes of the vehicle's struct, rounded up to the workspace alignment. */
static size_t vehicle_head(void)
{
    const size_t a = COA_WORKSPACE_ALIGNMENT;
    return (sizeof(coavoid_vehicle_node_t) + a - 1u) / a * a;
}

size_t coavoid_vehicle_node_size(const coavoid_vehicle_node_config_t *config)
{
    coavoid_vehicle_node_config_t filled;
    coavoid_node_solver_shape_t shape;
    if (vehicle_prepare(config, &filled, &shape) != COA_OK) {
        return 0u;
    }
    const size_t solver = coavoid_node_solver_size(&shape);
    return solver > SIZE_MAX - vehicle_head() ? 0u : vehicle_head() + solver;
}

coavoid_vehicle_node_t *coavoid_vehicle_node_init(void *memory, size_t size,
                                                  const coavoid_vehicle_node_config_t *config,
                                                  const coavoid_node_link_t *link, int *error)
{
    int dummy;
    error = error != NULL ? error : &dummy;
    coavoid_vehicle_node_config_t filled;
    coavoid_node_solver_shape_t shape;
    *error = vehicle_prepare(config, &filled, &shape);
    if (*error == COA_OK && (link == NULL || link->send == NULL)) {
        *error = COA_ERR_ARGUMENT;
    }
    if (*error != COA_OK) {
        return NULL;
    }
    if (memory == NULL || ((uintptr_t)memory % COA_WORKSPACE_ALIGNMENT) != 0u ||
        size < coavoid_vehicle_node_size(config)) {
        *error = COA_ERR_WORKSPACE;
        return NULL;
    }
    coavoid_vehicle_node_t *node = memory;
    memset(node, 0, sizeof *node);
    *error = coavoid_node_solver_place(&node->solver, (uint8_t *)memory + vehicle_head(),
                                       size - vehicle_head(), &shape);
    if (*error != COA_OK) {
        return NULL;
    }
    vehicle_start(node, &filled);
    const bool centralised = node->config.mode == COAVOID_NODE_CENTRALISED;
    *error =
        coavoid_node_inbox_init(&node->inbox, &config->common, filled.vehicle.id, filled.vehicle.id,
                                filled.coordinator_id, COAVOID_NODE_MAX_PEERS - 1u, link,
                                &node->state.rx, centralised, centralised ? on_plan : NULL, node);
    if (*error != COA_OK) {
        return NULL;
    }
    if (centralised) {
        node->inbox.on_plan_row = on_plan_row;
        coavoid_node_inbox_agreements(&node->inbox, on_agreement);
    }
    node->config.common.signer = NULL; /* copied by the inbox: the caller's may go */
    node->config.common.trust = NULL;
    return node;
}

void coavoid_vehicle_node_fini(coavoid_vehicle_node_t *node)
{
    if (node != NULL) {
        coavoid_node_inbox_fini(&node->inbox);
    }
}

int coavoid_vehicle_node_receive(coavoid_vehicle_node_t *node, const char *channel,
                                 const void *data, size_t size)
{
    return node != NULL ? coavoid_node_inbox_receive(&node->inbox, channel, data, size)
                        : COA_ERR_ARGUMENT;
}

const char *coavoid_vehicle_node_channel(const coavoid_vehicle_node_t *node, size_t i)
{
    return node != NULL ? coavoid_node_inbox_channel(&node->inbox, i) : NULL;
}

coavoid_node_inbox_t *coavoid_vehicle_node_inbox(coavoid_vehicle_node_t *node)
{
    return &node->inbox;
}

/* Enters cycle k at `now`: the last cycle's plan outcomes cleared (its refusals kept for
 * the heartbeat), the inbox aged, and the UAV at sample k of its plan. */
static void fly_to(coavoid_vehicle_node_t *node, int64_t k, int64_t now)
{
    /* A plan accepted and neither committed nor aborted within its cycle is not flown:
     * the coordinator commits only what every UAV accepted, so flying it on a guess
     * could split the plan; flying on as before is what an abort would have said. */
    node->state.plans_in_doubt += holds_plan(node) ? 1u : 0u;
    node->state.plans_standby += node->state.plan == COAVOID_VEHICLE_PLAN_STANDBY ? 1u : 0u;
    plan_on(node, COAVOID_VEHICLE_EVENT_CYCLE);
    node->answer_copies_left = 0;
    node->intent_copies_left = 0;
    node->cycle_plan_failed = false;
    node->last_cycle_refused = node->cycle_plan_refused;
    node->cycle_plan_refused = false;
    node->row_count = 0;
    node->state.cycle = k;
    node->cycle_start = coavoid_node_cycle_utime(&node->config.common, k);
    coavoid_node_inbox_expire(&node->inbox, now);
    build_own(node, k);
    node->state.offset = node->own_offsets[0];
    node->state.reference = node->own_reference[0];
    node->state.position = node->own_samples[0];
    memcpy(node->start_offsets, node->plan_offsets, sizeof node->start_offsets);
    snapshot_own(node);
}

/* A cycle it decides for itself: the order search (searches()), then its own decision.
 * An error of the search leaves the order as it was: the greedy raise still applies.
 * Returns as decide. */
static int decide_own(coavoid_vehicle_node_t *node, int64_t now)
{
    node->wait_deadline = node->cycle_start + node->config.priority_wait_us;
    const bool agreed = searches(node) && search_order(node) == 1;
    return agreed ? fly_agreed(node, now) : decide(node, now);
}

/* Whether a cycle of distrust has passed and the coordinator was heard since it began. */
static bool heard_since_distrust(const coavoid_vehicle_node_t *node, int64_t k)
{
    return k > node->distrust_cycle && node->inbox.heard_coordinator &&
           node->inbox.coordinator_utime > node->distrust_utime;
}

/* At the start of cycle k. A coordinator answers, within its cycle, for the conflicts of
 * the UAVs that follow it. One that followed it, had a conflict of its own and got no
 * answer in that cycle (no plan for it adopted, nor one that says the coordinator's search
 * failed: plans late, an impostor's or a dead coordinator's heartbeat, a plan it refused)
 * plans for itself instead, until a cycle in which it adopts one of the coordinator's
 * plans or has no conflict of its own: a heartbeat alone keeps no UAV safe. Decoupled
 * cycles tell their conflicts in decide(). Returns COA_OK or the prediction's error (the
 * node then trusts as if it had no conflict, and reports the fault). */
static int update_trust(coavoid_vehicle_node_t *node, int64_t k, int64_t now, bool previous_adopted,
                        bool previous_answered)
{
    int predicted = COA_OK;
    bool conflict = node->cycle_conflict;
    const bool self_answered = node->self_answered;
    node->self_answered = false;
    if (node->was_coordinated && !previous_answered) {
        predicted = missed_conflict(node, now, &conflict);
        if (predicted != COA_OK) {
            node->fault = true;
            conflict = false; /* cannot tell: the error is reported */
        }
    }
    node->unanswered = node->was_coordinated && conflict && !previous_answered;
    if (node->unanswered) {
        distrust_from(node, k, now);
    } else if (node->distrust && (previous_adopted || (!conflict && !self_answered) ||
                                  heard_since_distrust(node, k))) {
        /* One cycle of its own planning, then it follows again if the coordinator is
         * still there: one unanswered cycle (its plan or its answer lost) must not keep it
         * out of the coordinator's plans for the rest of a conflict, since the coordinator
         * plans no UAV that says it plans for itself. Unanswered again, it falls back
         * again; a coordinator it no longer hears it does not go back to. */
        node->distrust = false;
    }
    node->cycle_conflict = false;
    return predicted;
}

int coavoid_vehicle_node_cycle(coavoid_vehicle_node_t *node, int64_t now)
{
    if (node == NULL) {
        return COA_ERR_ARGUMENT;
    }
    const coavoid_node_common_t *c = &node->config.common;
    const int64_t k = coavoid_node_cycle_of(c, now);
    if (k < 0) {
        return COA_ERR_ARGUMENT;
    }
    if (started(node) && k <= node->state.cycle) {
        return COA_OK;
    }
    if (!started(node)) {
        node->first_cycle_start = coavoid_node_cycle_utime(c, k);
    }
    node->fault = false;
    const bool previous_adopted = flies_plan(node);
    const bool previous_answered = previous_adopted || node->cycle_plan_failed;
    fly_to(node, k, now);
    const int predicted = update_trust(node, k, now, previous_adopted, previous_answered);

    const int64_t timeout = node->config.coordinator_timeout_us;
    const bool coordinated =
        node->config.mode == COAVOID_NODE_CENTRALISED && !node->distrust &&
        ((node->inbox.heard_coordinator && now - node->inbox.coordinator_utime <= timeout) ||
         now - node->first_cycle_start < timeout);
    if (node->was_coordinated && !coordinated) {
        node->state.fallbacks++;
    }
    node->was_coordinated = coordinated;
    node->state.published = false;
    node->wait_deadline = INT64_MAX;
    node->self_commit_at = INT64_MAX;
    node->answer_deadline = node->cycle_start + node->config.answer_wait_us;
    phase_on(node, coordinated ? COAVOID_VEHICLE_EVENT_FOLLOW : COAVOID_VEHICLE_EVENT_DECIDE);
    int rc;
    if (coordinated) {
        drop_rank(node);
        rc = finish(node, now);
    } else {
        rc = decide_own(node, now);
    }
    if (rc >= 0 && predicted != COA_OK) {
        rc = predicted;
    }
    return rc < 0 ? rc : COA_OK;
}

/* The copies due at `now`: 1 when it sent one, 0 when none was due. */
static int send_copies(coavoid_vehicle_node_t *node, int64_t now)
{
    int sent = 0;
    if (node->intent_copies_left > 0u && now >= node->intent_copy_at && node->state.published) {
        uint32_t left = node->intent_copies_left - 1u;
        (void)publish_intent(node, now);
        node->intent_copies_left = left;
        sent = 1;
    }
    if (node->answer_copies_left > 0u && now >= node->answer_copy_at) {
        node->answer_copies_left--;
        node->answer_copy_at = now + node->config.resend_us;
        (void)answer(node, now, node->answer_kind, node->answer_plan_id);
        sent = 1;
    }
    return sent;
}

int coavoid_vehicle_node_poll(coavoid_vehicle_node_t *node, int64_t now)
{
    if (node == NULL) {
        return COA_ERR_ARGUMENT;
    }
    if (!started(node) || now >= node->cycle_start + node->config.common.dt_us) {
        return 0; /* copies belong to their cycle */
    }
    int sent = send_copies(node, now);
    if (now >= node->self_commit_at) {
        node->self_commit_at = INT64_MAX;
        if (holds_plan(node) && node->pending_plan_id == node->self_commit_plan &&
            all_accepted(node)) {
            return self_commit(node, now);
        }
    }
    if (node->state.phase == COAVOID_VEHICLE_FOLLOWING && now >= node->answer_deadline) {
        int overdue = answer_overdue(node, now);
        if (overdue != 0) {
            return overdue;
        }
    }
    if (!node->state.waiting) {
        int again = reconsider(node, now);
        return again == 0 ? sent : again;
    }
    int rc = decide(node, now);
    return rc == 0 ? sent : rc;
}

int64_t coavoid_vehicle_node_deadline(const coavoid_vehicle_node_t *node)
{
    if (node == NULL) {
        return INT64_MAX;
    }
    int64_t deadline = node->state.waiting ? node->wait_deadline : INT64_MAX;
    if (gather_wait(node) && gather_end(node) < deadline) {
        deadline = gather_end(node);
    }
    const int64_t end = node->cycle_start + node->config.common.dt_us;
    if (node->state.phase == COAVOID_VEHICLE_FOLLOWING && node->answer_deadline < deadline) {
        deadline = node->answer_deadline;
    }
    deadline = node->self_commit_at < deadline ? node->self_commit_at : deadline;
    if (node->intent_copies_left > 0u && node->state.published && node->intent_copy_at < end) {
        deadline = node->intent_copy_at < deadline ? node->intent_copy_at : deadline;
    }
    if (node->answer_copies_left > 0u && node->answer_copy_at < end) {
        deadline = node->answer_copy_at < deadline ? node->answer_copy_at : deadline;
    }
    return deadline < end ? deadline : INT64_MAX; /* poll does nothing from the cycle's end */
}

const coavoid_vehicle_node_state_t *coavoid_vehicle_node_state(const coavoid_vehicle_node_t *node)
{
    return node != NULL ? &node->state : NULL;
}
