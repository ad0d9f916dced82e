/* SPDX-License-Identifier: MIT */
/*
 * Deciding for itself (docs/protocol.md, "Priority negotiation"): the wait for the
 * UAVs before it, prediction, its own search in the decoupled order, the greedy raise
 * of its rank, and deciding again when overtaken or when the world it knows grew.
 */
#include "vehicle_internal.h"

#include <limits.h>
#include <math.h>
#include <string.h>

/* The one-UAV problem of this cycle: itself from the offset it flies now along its
 * reference window, the known obstacles and node->problem_tracks (filled by the caller).
 * vehicle and references are the caller's storage the problem points to. */
coa_problem_t coavoid_vehicle_own_problem(const coavoid_vehicle_node_t *node,
                                          coa_vehicle_t *vehicle, const coa_vec3_t **references)
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
int coavoid_vehicle_search_self(coavoid_vehicle_node_t *node, int64_t now,
                                coa_plan_result_t *result)
{
    const coavoid_node_common_t *c = &node->config.common;
    int rc = coavoid_node_problem_tracks(&node->problem_tracks, &node->view, node->include, c,
                                         c->horizon);
    if (rc != COA_OK) {
        return rc;
    }
    coa_vehicle_t vehicle;
    const coa_vec3_t *references[1];
    coa_problem_t problem = coavoid_vehicle_own_problem(node, &vehicle, references);

    int64_t start = coavoid_node_stopwatch(c);
    rc = coa_plan_centralised(coavoid_node_solver_planner(&node->solver), &problem, node->plan_out,
                              result);
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

/* Adopts its own solved plan (node->plan_out) once the check every plan gets before it is
 * flown finds it clear of what its search avoided; a plan that fails it is a planner
 * bug: not flown, and the node reports a fault this cycle. Returns COA_OK or a negative
 * error. */
static int own_plan_checked(coavoid_vehicle_node_t *node, int64_t now)
{
    const uint32_t samples = node->config.common.horizon + 1u;
    int hit = coavoid_vehicle_plan_hits_known(node, node->plan_out, samples, now, true);
    if (hit < 0) {
        return hit;
    }
    if (hit > 0) {
        node->fault = true;
        return COA_OK;
    }
    coavoid_vehicle_adopt(node, node->plan_out, samples);
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
 * (publish_intent: coavoid_vehicle_first_copies(), resend_us apart). */
int64_t coavoid_vehicle_gather_end(const coavoid_vehicle_node_t *node)
{
    return node->first_cycle_start +
           (int64_t)coavoid_vehicle_first_copies(node) * node->config.resend_us;
}

/* Whether, in its first cycle, the copies of the first intents its peers published as the cycle
 * began may still come. Before coavoid_vehicle_gather_end() a UAV that finds no plan below those
 * before it may only be missing some of them (lost, a copy on its way), and a raise made then
 * reorders the cluster for nothing. */
static bool gathering(const coavoid_vehicle_node_t *node, int64_t now)
{
    return node->cycle_start == node->first_cycle_start && now < coavoid_vehicle_gather_end(node);
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
    int rc = coavoid_vehicle_search_self(node, now, result);
    /* Later UAVs outside its cluster are kept clear of while that is possible; when it is
     * not (its way out of a conflict crosses their paths), it plans as
     * coa_plan_decoupled orders it, around the earlier ones only: the others then see the
     * conflict and plan around it. */
    if (rc == COA_OK && result->status != COA_PLAN_SOLVED && lower_outside) {
        for (size_t i = 0; i < view->live_count; i++) {
            node->include[i] = peer_first(node, i);
        }
        rc = coavoid_vehicle_search_self(node, now, result);
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
void coavoid_vehicle_drop_rank(coavoid_vehicle_node_t *node)
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
        coavoid_vehicle_phase_on(node, COAVOID_VEHICLE_EVENT_GATHER);
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
size_t coavoid_vehicle_gather(coavoid_vehicle_node_t *node, int64_t now)
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
int coavoid_vehicle_predict(coavoid_vehicle_node_t *node, size_t n, coa_predict_result_t *result)
{
    size_t clusters = 0;
    coavoid_node_solver_t *sv = &node->solver;
    int rc = coavoid_node_predict(coavoid_node_solver_predictor(sv), &node->config.common,
                                  node->plans, n, &node->view, &node->inbox, sv->conflicts,
                                  sv->conflict_capacity, result, node->labels, &clusters);
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
int coavoid_vehicle_missed_conflict(coavoid_vehicle_node_t *node, int64_t now, bool *conflict)
{
    coa_predict_result_t result;
    *conflict = false;
    int rc = coavoid_vehicle_predict(node, coavoid_vehicle_gather(node, now), &result);
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

/* Whether live UAV i has published what it decided for this cycle: an intent of this
 * cycle, which, when it decides at the answer wait itself (answering), must also say the
 * UAV plans for itself or fly its row of a coordinator's plan of this cycle (one still
 * following may be about to answer itself too). O(N). */
static bool decided_peer(const coavoid_vehicle_node_t *node, size_t i)
{
    const coavoid_node_view_t *view = &node->view;
    return view->live_current[i] &&
           !(coavoid_vehicle_answering(node) &&
             view->live_info[i].mode == COAVOID_INTENT_T_MODE_CENTRALISED &&
             !coavoid_vehicle_row_flown(node, view->live_id[i], view->live_arrays[i].offsets,
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
    if (coa_predict(coavoid_node_solver_predictor(sv), &config, node->tall, n, NULL, 0, NULL, 0,
                    sv->conflicts, sv->conflict_capacity, &result) != COA_OK) {
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

/* Whether peer's intent is a first intent that a searching UAV counts as a newcomer's
 * (overtaken; note_order keeps its digest). O(1). */
static bool newcomer(const coavoid_vehicle_node_t *node, const coavoid_node_peer_t *peer)
{
    return coavoid_vehicle_searches(node) && coavoid_vehicle_first_intent(node, peer);
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
            const coavoid_node_intent_t *m = &node->inbox.peers[p].msg;
            if (node->inbox.peers[p].used && (uint16_t)m->uav_id == view->live_id[i]) {
                const bool digested = centralised || news || newcomer(node, &node->inbox.peers[p]);
                digest =
                    digested ? intent_digest(coavoid_node_intent_open(m, &node->view.opened)) : 0u;
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
static bool overtaken(coavoid_vehicle_node_t *node)
{
    const coa_vehicle_t *self = &node->config.vehicle;
    const bool news = node->news_cycle == node->state.cycle;
    for (size_t i = 0; i < COAVOID_NODE_MAX_PEERS; i++) {
        const coavoid_node_peer_t *peer = &node->inbox.peers[i];
        if (!peer->used || peer->msg.plan_utime != node->cycle_start) {
            continue; /* before the row comparison: no intent of this cycle to compare */
        }
        const coavoid_intent_t *m = coavoid_node_intent_open(&peer->msg, &node->view.opened);
        const bool first = m->rank <= 0 && (newcomer(node, &node->inbox.peers[i]) || news);
        const bool answered = node->config.mode == COAVOID_NODE_CENTRALISED && m->rank <= 0 &&
                              (m->mode == COAVOID_INTENT_T_MODE_DECOUPLED ||
                               coavoid_vehicle_row_flown(node, (uint16_t)m->uav_id, m->offsets,
                                                         (size_t)m->sample_count));
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

/* In a cycle whose order search agreed a new order: it flies its row of the solving plan
 * (node->plan_out) at once, as every other member does with its own, once the check every
 * plan gets finds it clear of the obstacles and tracks it knows (its row was planned
 * around the others' intents of the cycle's start, which their rows replace), and
 * publishes it with its new rank. A row that fails the check is left: it decides as any
 * cycle (decide), in the agreed order. Returns as decide. */
static int fly_agreed(coavoid_vehicle_node_t *node, int64_t now)
{
    (void)coavoid_vehicle_gather(node, now);
    note_order(node);
    memset(node->include, 0, sizeof node->include);
    const uint32_t samples = node->config.common.horizon + 1u;
    int hit = coavoid_vehicle_plan_hits_known(node, node->plan_out, samples, now, true);
    if (hit != 0) {
        return coavoid_vehicle_decide(node, now);
    }
    coavoid_vehicle_adopt(node, node->plan_out, samples);
    node->state.last_outcome = (int)COA_PLAN_SOLVED;
    node->cycle_conflict = true;
    settle_rank(node, true);
    return coavoid_vehicle_finish(node, now);
}

/* The decoupled step: predict with what it has; publish at once without a conflict;
 * otherwise wait for the members of its cluster before it in the decoupled order (until
 * the deadline), then plan (raising its rank if it must) and publish. Returns 1 when it
 * published, 0 while it waits, or an error. */
int coavoid_vehicle_decide(coavoid_vehicle_node_t *node, int64_t now)
{
    const coavoid_node_view_t *view = &node->view;
    const size_t n = coavoid_vehicle_gather(node, now);
    if (now < node->wait_deadline && near_pending(node, n)) {
        coavoid_vehicle_phase_on(node, COAVOID_VEHICLE_EVENT_WAIT);
        return 0;
    }
    note_order(node);
    coa_predict_result_t result;
    int rc = coavoid_vehicle_predict(node, n, &result);
    if (rc != COA_OK) {
        node->fault = true;
        int published = coavoid_vehicle_finish(node, now);
        return published < 0 ? published : rc;
    }
    const uint32_t my = node->labels[0];
    node->cycle_conflict = my != COA_NO_CLUSTER;
    settle_rank(node, node->cycle_conflict);
    if (my == COA_NO_CLUSTER) {
        return coavoid_vehicle_finish(node, now);
    }
    bool pending = false;
    for (size_t i = 0; i < view->live_count; i++) {
        if (node->labels[i + 1u] == my && !decided_peer(node, i) && peer_first(node, i)) {
            pending = true;
        }
    }
    if (pending && now < node->wait_deadline) {
        coavoid_vehicle_phase_on(node, COAVOID_VEHICLE_EVENT_WAIT);
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
        int published = coavoid_vehicle_finish(node, now);
        return published < 0 ? published : rc;
    }
    return coavoid_vehicle_finish(node, now);
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
    const int found = coavoid_vehicle_search_order(node);
    if (found != 1 && !(agreed && node->agreed_cycle != node->state.cycle)) {
        return 0;
    }
    node->wait_deadline = node->cycle_start + node->config.priority_wait_us;
    coavoid_vehicle_phase_on(node, COAVOID_VEHICLE_EVENT_REDECIDE);
    return found == 1 ? fly_agreed(node, now) : coavoid_vehicle_decide(node, now);
}

/* Whether a track it held nothing of, or a new obstacle map, came since it decided in this cycle on
 * its own (not a standby; coavoid_vehicle_reconsider() already leaves out a coordinator's plan it
 * switched to): what it decided on lacked it. In its first cycle every node starts at once, so a
 * UAV first in its order decides before the world's first estimates reach it whenever the network
 * has any latency. O(1). */
static bool world_news(const coavoid_vehicle_node_t *node)
{
    return node->decided_cycle == node->state.cycle && !coavoid_vehicle_on_standby(node) &&
           node->inbox.world_news != node->decided_news;
}

/* After it published this cycle's intent on its own decision (not a coordinator's plan
 * it switched to in the cycle, which its siblings fly too): when it has been overtaken
 * (overtaken()) or the world it knows grew since (world_news()), it decides again at
 * once, waiting as before (until the cycle's priority wait ends) and publishing its intent
 * again, at most REDECISIONS_MAX times a cycle, so that a raise reorders its cluster, and
 * a track heard late is avoided, within the cycle rather than the next. Returns as
 * decide, 0 when there is nothing to do. */
int coavoid_vehicle_reconsider(coavoid_vehicle_node_t *node, int64_t now)
{
    if (!coavoid_vehicle_started(node) || node->state.coordinated || !node->state.published ||
        coavoid_vehicle_flies_plan(node)) {
        return 0; /* a coordinator's plan it switched to is flown by every sibling too */
    }
    if (node->redecided_cycle != node->state.cycle) {
        node->redecided_cycle = node->state.cycle;
        node->redecisions = 0;
    }
    if (coavoid_vehicle_searches(node) &&
        coavoid_vehicle_first_intents(node) > node->searched_first) {
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
    coavoid_vehicle_phase_on(node, COAVOID_VEHICLE_EVENT_REDECIDE);
    return coavoid_vehicle_decide_own(node, now);
}

/* A cycle it decides for itself: the order search (coavoid_vehicle_searches()), then its own
 * decision. An error of the search leaves the order as it was: the greedy raise still applies.
 * Returns as decide. */
int coavoid_vehicle_decide_own(coavoid_vehicle_node_t *node, int64_t now)
{
    node->wait_deadline = node->cycle_start + node->config.priority_wait_us;
    const bool agreed = coavoid_vehicle_searches(node) && coavoid_vehicle_search_order(node) == 1;
    return agreed ? fly_agreed(node, now) : coavoid_vehicle_decide(node, now);
}
