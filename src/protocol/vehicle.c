/* SPDX-License-Identifier: MIT */
/*
 * The vehicle node (protocol.h): one UAV that flies its adopted plan, publishes its
 * intent and heartbeat, and starts each cycle following the coordinator or deciding
 * for itself (the phase, vehicle_states.c); its memory, its cycle and its polls.
 * Deciding for itself is vehicle_decide.c, the order search and the joint plan
 * vehicle_order.c, the agreement on the coordinator's plans vehicle_agreement.c.
 */
#include "vehicle_internal.h"

#include <limits.h>
#include <math.h>
#include <string.h>

/* An event its machine does not allow where it stands: a fault, and nothing moves. */
static void not_allowed(coavoid_vehicle_node_t *node)
{
    node->fault = true;
    node->state.protocol_faults++;
}

/* Moves the phase on `event`, and what the state reports with it: following the
 * coordinator (FOLLOWING, FOLLOWED), and waiting to decide. O(table). */
void coavoid_vehicle_phase_on(coavoid_vehicle_node_t *node, coavoid_vehicle_event_t event)
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
void coavoid_vehicle_plan_on(coavoid_vehicle_node_t *node, coavoid_vehicle_event_t event)
{
    const coavoid_vehicle_plan_t to = coavoid_vehicle_plan_next(node->state.plan, event);
    if (to == COAVOID_VEHICLE_PLAN_STATES) {
        not_allowed(node);
        return;
    }
    node->state.plan = to;
}

bool coavoid_vehicle_started(const coavoid_vehicle_node_t *node)
{
    return node->state.phase != COAVOID_VEHICLE_IDLE;
}

/* Deciding for itself since the answer wait of this cycle. */
bool coavoid_vehicle_answering(const coavoid_vehicle_node_t *node)
{
    const coavoid_vehicle_phase_t p = node->state.phase;
    return p == COAVOID_VEHICLE_ANSWERING || p == COAVOID_VEHICLE_ANSWER_GATHERING ||
           p == COAVOID_VEHICLE_ANSWERED;
}

/* Waiting for its first cycle's intents to gather (plan_self), until
 * coavoid_vehicle_gather_end(). */
static bool gather_wait(const coavoid_vehicle_node_t *node)
{
    return node->state.phase == COAVOID_VEHICLE_GATHERING ||
           node->state.phase == COAVOID_VEHICLE_ANSWER_GATHERING;
}

/* Holds an accepted plan of this cycle, undecided. */
bool coavoid_vehicle_holds_plan(const coavoid_vehicle_node_t *node)
{
    const coavoid_vehicle_plan_t p = node->state.plan;
    return p == COAVOID_VEHICLE_PLAN_HOLDING || p == COAVOID_VEHICLE_PLAN_STANDBY ||
           p == COAVOID_VEHICLE_PLAN_SWITCHED_HOLDING;
}

/* Flies a coordinator's plan of this cycle it switched to. */
bool coavoid_vehicle_flies_plan(const coavoid_vehicle_node_t *node)
{
    return node->state.plan == COAVOID_VEHICLE_PLAN_SWITCHED ||
           node->state.plan == COAVOID_VEHICLE_PLAN_SWITCHED_HOLDING;
}

/* Planned a standby at the answer wait of this cycle, and flies it unless committed. */
bool coavoid_vehicle_on_standby(const coavoid_vehicle_node_t *node)
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

coa_vec3_t coavoid_vehicle_lifted(coa_vec3_t reference, int32_t offset, coa_real_t dh)
{
    /* As the planner and every receiver compute it (coavoid_lcm_intent_to_core). */
    reference.z += (coa_real_t)offset * dh;
    return reference;
}

/* The intent of cycle k from the adopted plan, which is then re-based at k so that its
 * storage never needs more than N + 1 samples. */
void coavoid_vehicle_build_own(coavoid_vehicle_node_t *node, int64_t k)
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
        node->own_samples[j] =
            coavoid_vehicle_lifted(node->own_reference[j], node->own_offsets[j], node->dh);
    }
    node->plan_start = k;
    node->plan_count = n;
}

void coavoid_vehicle_adopt(coavoid_vehicle_node_t *node, const int32_t *offsets, uint32_t count)
{
    const uint32_t n = node->config.common.horizon + 1u;
    node->plan_start = node->state.cycle;
    node->plan_count = count < COAVOID_NODE_MAX_SAMPLES ? count : COAVOID_NODE_MAX_SAMPLES;
    memcpy(node->plan_offsets, offsets, node->plan_count * sizeof offsets[0]);
    for (uint32_t j = 0; j < n; j++) {
        node->own_offsets[j] = offset_at(node, node->state.cycle + (int64_t)j);
        node->own_samples[j] =
            coavoid_vehicle_lifted(node->own_reference[j], node->own_offsets[j], node->dh);
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
coavoid_lcm_intent_info_t coavoid_vehicle_intent_info(const coavoid_vehicle_node_t *node,
                                                      int64_t now, int64_t sequence)
{
    const coavoid_node_common_t *c = &node->config.common;
    coavoid_lcm_intent_info_t info;
    memset(&info, 0, sizeof info);
    info.utime = now;
    info.sequence = sequence;
    /* A coordinator's plan switched to in this cycle is flown to its end
     * (coavoid_vehicle_reconsider()), coordinated or not (a self-commit, a standby that a COMMIT
     * replaced): it says so, or a peer's order search would count it in and plan around a row it
     * never flies. */
    info.mode = node->state.coordinated || coavoid_vehicle_flies_plan(node)
                    ? COAVOID_INTENT_T_MODE_CENTRALISED
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
uint32_t coavoid_vehicle_first_copies(const coavoid_vehicle_node_t *node)
{
    return 2u * node->config.intent_copies;
}

/* Publishes its intent of this cycle as it stands at `now` (its state moved on, the same
 * plan), and schedules its copies. COA_OK or a negative error (a fault). */
int coavoid_vehicle_publish_intent(coavoid_vehicle_node_t *node, int64_t now)
{
    const coavoid_node_common_t *c = &node->config.common;
    const coavoid_lcm_intent_info_t info =
        coavoid_vehicle_intent_info(node, now, node->intent_sequence++);
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
    node->intent_copies_left =
        first ? coavoid_vehicle_first_copies(node) : node->config.intent_copies;
    node->intent_copy_at = now + node->config.resend_us;
    return rc;
}

/* Publishes this cycle's intent and heartbeat; the wait, if any, is over. Returns 1 or a
 * negative error. */
int coavoid_vehicle_finish(coavoid_vehicle_node_t *node, int64_t now)
{
    int rc = coavoid_vehicle_publish_intent(node, now);
    coavoid_vehicle_phase_on(node, COAVOID_VEHICLE_EVENT_PUBLISH);
    node->state.published = rc == COA_OK;
    node->wait_deadline = INT64_MAX;
    int status_rc = publish_status(node, now);
    if (rc != COA_OK) {
        return rc;
    }
    return status_rc != COA_OK ? status_rc : 1;
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
        config->coordinator_timeout_us > COAVOID_NODE_MAX_DURATION_US ||
        config->priority_wait_us > COAVOID_NODE_MAX_DURATION_US ||
        config->resend_us > COAVOID_NODE_MAX_DURATION_US ||
        config->answer_wait_us > COAVOID_NODE_MAX_DURATION_US ||
        config->intent_copies > COAVOID_NODE_MAX_COPIES ||
        !isfinite((double)config->sigma_horizontal) || !isfinite((double)config->sigma_vertical) ||
        config->sigma_horizontal < (coa_real_t)0 || config->sigma_vertical < (coa_real_t)0 ||
        !(coa_climb_step(&config->vehicle, config->common.dt) > (coa_real_t)0) ||
        config->joint_members == 1u || config->joint_members > COA_MAX_CENTRALISED ||
        config->vehicle.steep_factor > COAVOID_NODE_MAX_STEEP_FACTOR) {
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
    return coavoid_node_align_up(sizeof(coavoid_vehicle_node_t));
}

/* The block a vehicle whose solver has this shape needs: its struct, then the solver; 0
 * on overflow. */
static size_t vehicle_bytes(const coavoid_node_solver_shape_t *shape)
{
    const size_t solver = coavoid_node_solver_size(shape);
    return solver > SIZE_MAX - vehicle_head() ? 0u : vehicle_head() + solver;
}

size_t coavoid_vehicle_node_size(const coavoid_vehicle_node_config_t *config)
{
    coavoid_vehicle_node_config_t filled;
    coavoid_node_solver_shape_t shape;
    return vehicle_prepare(config, &filled, &shape) == COA_OK ? vehicle_bytes(&shape) : 0u;
}

coavoid_vehicle_node_t *coavoid_vehicle_node_init(void *memory, size_t size,
                                                  const coavoid_vehicle_node_config_t *config,
                                                  const coavoid_node_link_t *link, int *error)
{
    int dummy = 0;
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
        size < vehicle_bytes(&shape)) {
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
    *error = coavoid_node_inbox_init(
        &node->inbox, &config->common, filled.vehicle.id, filled.vehicle.id, filled.coordinator_id,
        COAVOID_NODE_MAX_PEERS - 1u, link, &node->state.rx, centralised,
        centralised ? coavoid_vehicle_on_plan : NULL, node);
    if (*error != COA_OK) {
        return NULL;
    }
    if (centralised) {
        node->inbox.on_plan_row = coavoid_vehicle_on_plan_row;
        coavoid_node_inbox_agreements(&node->inbox, coavoid_vehicle_on_agreement);
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
    node->state.plans_in_doubt += coavoid_vehicle_holds_plan(node) ? 1u : 0u;
    node->state.plans_standby += node->state.plan == COAVOID_VEHICLE_PLAN_STANDBY ? 1u : 0u;
    coavoid_vehicle_plan_on(node, COAVOID_VEHICLE_EVENT_CYCLE);
    node->answer_copies_left = 0;
    node->intent_copies_left = 0;
    node->cycle_plan_failed = false;
    node->last_cycle_refused = node->cycle_plan_refused;
    node->cycle_plan_refused = false;
    node->row_count = 0;
    node->state.cycle = k;
    node->cycle_start = coavoid_node_cycle_utime(&node->config.common, k);
    coavoid_node_inbox_expire(&node->inbox, now);
    coavoid_vehicle_build_own(node, k);
    node->state.offset = node->own_offsets[0];
    node->state.reference = node->own_reference[0];
    node->state.position = node->own_samples[0];
    memcpy(node->start_offsets, node->plan_offsets, sizeof node->start_offsets);
    coavoid_vehicle_snapshot_own(node);
}

/* Whether a cycle of distrust has passed and the coordinator was heard since it began. */
static bool heard_since_distrust(const coavoid_vehicle_node_t *node, int64_t k)
{
    return k > node->distrust_cycle && node->inbox.heard_coordinator &&
           node->inbox.coordinator_utime > node->distrust_utime;
}

/* At the start of cycle k. A coordinator answers, within its cycle, for the conflicts of the UAVs
 * that follow it. One that followed it, had a conflict of its own and got no answer in that cycle
 * (no plan for it adopted, nor one that says the coordinator's search failed: plans late, an
 * impostor's or a dead coordinator's heartbeat, a plan it refused) plans for itself instead, until
 * a cycle in which it adopts one of the coordinator's plans or has no conflict of its own: a
 * heartbeat alone keeps no UAV safe. Decoupled cycles tell their conflicts in
 * coavoid_vehicle_decide(). Returns COA_OK or the prediction's error (the node then trusts as if it
 * had no conflict, and reports the fault). */
static int update_trust(coavoid_vehicle_node_t *node, int64_t k, int64_t now, bool previous_adopted,
                        bool previous_answered)
{
    int predicted = COA_OK;
    bool conflict = node->cycle_conflict;
    const bool self_answered = node->self_answered;
    node->self_answered = false;
    if (node->was_coordinated && !previous_answered) {
        predicted = coavoid_vehicle_missed_conflict(node, now, &conflict);
        if (predicted != COA_OK) {
            node->fault = true;
            conflict = false; /* cannot tell: the error is reported */
        }
    }
    node->unanswered = node->was_coordinated && conflict && !previous_answered;
    if (node->unanswered) {
        coavoid_vehicle_distrust_from(node, k, now);
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
    if (coavoid_vehicle_started(node) && k <= node->state.cycle) {
        return COA_OK;
    }
    if (!coavoid_vehicle_started(node)) {
        node->first_cycle_start = coavoid_node_cycle_utime(c, k);
    }
    node->fault = false;
    const bool previous_adopted = coavoid_vehicle_flies_plan(node);
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
    coavoid_vehicle_phase_on(node, coordinated ? COAVOID_VEHICLE_EVENT_FOLLOW
                                               : COAVOID_VEHICLE_EVENT_DECIDE);
    int rc;
    if (coordinated) {
        coavoid_vehicle_drop_rank(node);
        rc = coavoid_vehicle_finish(node, now);
    } else {
        rc = coavoid_vehicle_decide_own(node, now);
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
        (void)coavoid_vehicle_publish_intent(node, now);
        node->intent_copies_left = left;
        sent = 1;
    }
    if (node->answer_copies_left > 0u && now >= node->answer_copy_at) {
        node->answer_copies_left--;
        node->answer_copy_at = now + node->config.resend_us;
        (void)coavoid_vehicle_answer(node, now, node->answer_kind, node->answer_plan_id);
        sent = 1;
    }
    return sent;
}

int coavoid_vehicle_node_poll(coavoid_vehicle_node_t *node, int64_t now)
{
    if (node == NULL) {
        return COA_ERR_ARGUMENT;
    }
    if (!coavoid_vehicle_started(node) || now >= node->cycle_start + node->config.common.dt_us) {
        return 0; /* copies belong to their cycle */
    }
    int sent = send_copies(node, now);
    if (now >= node->self_commit_at) {
        node->self_commit_at = INT64_MAX;
        if (coavoid_vehicle_holds_plan(node) && node->pending_plan_id == node->self_commit_plan &&
            coavoid_vehicle_all_accepted(node)) {
            return coavoid_vehicle_self_commit(node, now);
        }
    }
    if (node->state.phase == COAVOID_VEHICLE_FOLLOWING && now >= node->answer_deadline) {
        int overdue = coavoid_vehicle_answer_overdue(node, now);
        if (overdue != 0) {
            return overdue;
        }
    }
    if (!node->state.waiting) {
        int again = coavoid_vehicle_reconsider(node, now);
        return again == 0 ? sent : again;
    }
    int rc = coavoid_vehicle_decide(node, now);
    return rc == 0 ? sent : rc;
}

int64_t coavoid_vehicle_node_deadline(const coavoid_vehicle_node_t *node)
{
    if (node == NULL) {
        return INT64_MAX;
    }
    int64_t deadline = node->state.waiting ? node->wait_deadline : INT64_MAX;
    if (gather_wait(node) && coavoid_vehicle_gather_end(node) < deadline) {
        deadline = coavoid_vehicle_gather_end(node);
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
