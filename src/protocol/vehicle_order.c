/* SPDX-License-Identifier: MIT */
/*
 * The order search and the joint plan (docs/protocol.md, "Priority negotiation",
 * "The first cycle"): the view of the cycle's start, its group, the priority orders
 * tried, the look-ahead, and the group's joint plan when no order solves it.
 */
#include "vehicle_internal.h"

#include <limits.h>
#include <math.h>
#include <string.h>

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
            a->samples[j] = coavoid_vehicle_lifted(a->reference[j], a->offsets[0], dh);
        }
        view->live_info[i].rank = 0;
    }
    view->live_id[i] = (uint16_t)msg->uav_id;
    view->live_current[i] = false;
    node->order_kind[i] = kind;
    view->live_count++;
    return true;
}

/* Whether it runs the order search when it decides for itself: unless told to negotiate greedily.
 * One configured centralised searches only in the cycles it distrusts its coordinator (decide_own;
 * at the answer wait it decides without a search, and coavoid_vehicle_reconsider() skips it while
 * it follows), and the search's group leaves out every UAV whose intent says it follows
 * (order_eligible), so no search hands a row to a UAV that flies the coordinator's. O(1). */
bool coavoid_vehicle_searches(const coavoid_vehicle_node_t *node)
{
    return !node->config.greedy_negotiation;
}

/* At the cycle's start (fly_to): itself as its peers will have it when they search
 * (node->order_own): its last intent of the cycle before, or in its first cycle its
 * intent with the offset it starts at held, encoded as it would publish it. */
void coavoid_vehicle_snapshot_own(coavoid_vehicle_node_t *node)
{
    const coavoid_node_common_t *c = &node->config.common;
    const coavoid_intent_t *last = &node->tx_intent;
    node->order_own_kind = SNAPSHOT_NONE;
    if (!coavoid_vehicle_searches(node)) {
        return; /* it never searches (decide_own) */
    }
    if (node->intent_sequence > 0 && last->plan_utime == node->cycle_start - c->dt_us) {
        node->order_own = *last;
        node->order_own_kind = SNAPSHOT_PREVIOUS;
    } else if (node->first_cycle_start == node->cycle_start) {
        coavoid_lcm_intent_info_t info = coavoid_vehicle_intent_info(node, node->cycle_start, 0);
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
bool coavoid_vehicle_first_intent(const coavoid_vehicle_node_t *node,
                                  const coavoid_node_peer_t *peer)
{
    const int64_t start = node->cycle_start;
    return peer->used && peer->msg.plan_utime == start &&
           !(peer->has_prev && peer->prev.plan_utime < start);
}

/* How many peers are in the view of the cycle's start by their first intent. O(peers). */
size_t coavoid_vehicle_first_intents(const coavoid_vehicle_node_t *node)
{
    size_t n = 0;
    for (size_t p = 0; p < COAVOID_NODE_MAX_PEERS; p++) {
        n += coavoid_vehicle_first_intent(node, &node->inbox.peers[p]) ? 1u : 0u;
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
        if (coavoid_vehicle_first_intent(node, peer)) {
            node->searched_first++;
            (void)snapshot_add(node, coavoid_node_intent_open(&peer->msg, &node->view.opened),
                               SNAPSHOT_FIRST);
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
    int rc = coa_predict(coavoid_node_solver_predictor(sv), &config, node->tall, n, NULL, 0, NULL,
                         0, sv->conflicts, sv->conflict_capacity, &result);
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
    if (coavoid_node_predict(coavoid_node_solver_predictor(sv), &node->config.common, node->plans,
                             n, view, &node->inbox, sv->conflicts, sv->conflict_capacity, &result,
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
        coavoid_vehicle_build_own(node, node->state.cycle);
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
    int rc = coa_plan_decoupled(coavoid_node_solver_planner(&node->solver), problem, result->order,
                                ORDER_TRIES_MAX, node->ahead_offsets, &ahead);
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
    coa_planner_t *planner = coavoid_node_solver_planner(&node->solver);
    (void)coa_planner_set_work(planner, node->config.joint_work);
    const int rc = coa_plan_centralised(planner, problem, node->order_offsets, &result);
    (void)coa_planner_set_work(planner, 0u); /* its other searches: tables */
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
int coavoid_vehicle_search_order(coavoid_vehicle_node_t *node)
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
    rc = coa_plan_decoupled(coavoid_node_solver_planner(&node->solver), &problem, order,
                            ORDER_TRIES_MAX, node->order_offsets, &result);
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
