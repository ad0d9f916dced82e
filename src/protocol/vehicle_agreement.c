/* SPDX-License-Identifier: MIT */
/*
 * The agreement on the coordinator's plans (docs/protocol.md, "One plan (at a vehicle
 * of it)", "The answer wait"): checking a whole plan, ACCEPT, REFUSE, COMMIT, a
 * sibling's SWITCHED, ABORT, the standby and the self-commit at the answer wait.
 */
#include "vehicle_internal.h"

#include <limits.h>
#include <math.h>
#include <string.h>

/* ---- answers and the plan it holds ---- */

/* Says `kind` on plan_id now, and again intent_copies times, resend_us apart, unless a
 * later answer replaces it: an answer lost stalls the plan until the coordinator sends
 * the plan again. */
static void answer_with_copies(coavoid_vehicle_node_t *node, int64_t now, int8_t kind,
                               int64_t plan_id)
{
    (void)coavoid_vehicle_answer(node, now, kind, plan_id);
    node->answer_kind = kind;
    node->answer_plan_id = plan_id;
    node->answer_copies_left = node->config.intent_copies;
    node->answer_copy_at = now + node->config.resend_us;
}

int coavoid_vehicle_answer(coavoid_vehicle_node_t *node, int64_t now, int8_t kind, int64_t plan_id)
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
    coavoid_vehicle_plan_on(node, COAVOID_VEHICLE_EVENT_ACCEPT);
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
    coavoid_vehicle_plan_on(node, COAVOID_VEHICLE_EVENT_COMMIT);
    coavoid_vehicle_adopt(node, node->pending_offsets, node->pending_count);
    node->cycle_plan_id = node->pending_plan_id;
    node->state.plans_switched++;
    answer_with_copies(node, now, COAVOID_AGREEMENT_T_KIND_SWITCHED, node->cycle_plan_id);
    if (node->state.published) {
        (void)coavoid_vehicle_publish_intent(node, now);
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
bool coavoid_vehicle_all_accepted(const coavoid_vehicle_node_t *node)
{
    for (size_t i = 0; i < node->pending_members; i++) {
        if (!node->pending_accepted[i]) {
            return false;
        }
    }
    return true;
}

/* ---- the rows of this cycle's plans ---- */

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
        a->samples[j] = coavoid_vehicle_lifted(a->reference[j], a->offsets[j], dh);
    }
}

/* Whether UAV id's intent of this cycle (its `count` offsets) is its row of this cycle's
 * plans: it flies a coordinator's plan it switched to, so it has decided for the cycle
 * (decided_peer, overtaken). O(N). */
bool coavoid_vehicle_row_flown(const coavoid_vehicle_node_t *node, uint16_t id,
                               const int32_t *offsets, size_t count)
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
int coavoid_vehicle_plan_hits_known(coavoid_vehicle_node_t *node, const int32_t *offsets,
                                    size_t count, int64_t now, bool own)
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
        coa_problem_t problem = coavoid_vehicle_own_problem(node, &vehicle, references);
        rc = coa_plan_find_conflict(&problem, node->checked, which, 1, NULL, NULL);
        hit = rc > 0 ? pass : rc;
    }
    return hit;
}

/* ---- refusals ---- */

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
    if (node->state.phase == COAVOID_VEHICLE_FOLLOWING && !coavoid_vehicle_flies_plan(node) &&
        !coavoid_vehicle_holds_plan(node) && now < node->answer_deadline) {
        node->answer_deadline = now;
    }
}

/* ---- the answer wait ---- */

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
    int rc = coavoid_vehicle_search_self(node, now, &result);
    if (rc != COA_OK || result.status != COA_PLAN_SOLVED) {
        return rc;
    }
    const uint32_t samples = node->config.common.horizon + 1u;
    int hit = coavoid_vehicle_plan_hits_known(node, node->plan_out, samples, now, false);
    if (hit != 0) {
        return hit < 0 ? hit : COA_OK;
    }
    coavoid_vehicle_adopt(node, node->plan_out, samples);
    *adopted = true;
    return COA_OK;
}

/* It distrusts its coordinator from cycle k (at `now`): it plans for itself until
 * update_trust() lets it follow again. O(1). */
void coavoid_vehicle_distrust_from(coavoid_vehicle_node_t *node, int64_t k, int64_t now)
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
int coavoid_vehicle_self_commit(coavoid_vehicle_node_t *node, int64_t now)
{
    node->state.plans_self_committed++;
    switch_to_pending(node, now);
    coavoid_vehicle_phase_on(node, COAVOID_VEHICLE_EVENT_SELF_COMMIT);
    return 1;
}

/* Following its coordinator, answer_wait_us into the cycle, with a conflict of its own and no plan
 * of the coordinator's adopted (told that a search failed for it or not): it plans for itself in
 * this cycle and announces it. Holding no plan, it accepted none, so no COMMIT can include it: it
 * decides as a decoupled UAV (coavoid_vehicle_decide()), waiting up to a quarter cycle for the UAVs
 * before it that answer themselves at the same time. Holding an undecided one, it plans a standby
 * (standby()). Waiting for the next cycle's fallback instead could leave a conflict one step ahead
 * unsolved (a coordinator that stops in cycle 0 before its first plan is agreed). Returns 1 when it
 * published, 0 when there was nothing to do or it waits, or a negative error. Cost: one prediction,
 * then as decide or standby. */
int coavoid_vehicle_answer_overdue(coavoid_vehicle_node_t *node, int64_t now)
{
    coavoid_vehicle_phase_on(node, COAVOID_VEHICLE_EVENT_ANSWER_WAIT);
    if (coavoid_vehicle_flies_plan(node)) {
        return 0; /* a failed search it was told of is no answer by now: on_plan */
    }
    coa_predict_result_t result;
    int rc = coavoid_vehicle_predict(node, coavoid_vehicle_gather(node, now), &result);
    if (rc != COA_OK) {
        node->fault = true;
        return rc;
    }
    if (node->labels[0] == COA_NO_CLUSTER) {
        return 0;
    }
    node->cycle_conflict = true;
    if (!coavoid_vehicle_holds_plan(node)) {
        /* Distrusted as an unanswered UAV's: it decides for itself in the next cycle too,
         * unless it hears the coordinator again by then. */
        coavoid_vehicle_distrust_from(node, node->state.cycle, now);
        node->self_answered = true;
        coavoid_vehicle_phase_on(node, COAVOID_VEHICLE_EVENT_UNANSWERED);
        const int64_t last = node->cycle_start + node->config.common.dt_us - 1;
        const int64_t until = now + node->config.answer_wait_us / 2;
        node->wait_deadline = until < last ? until : last; /* decided within its cycle */
        return coavoid_vehicle_decide(node, now);
    }
    const int64_t decided_by =
        node->pending_since + node->config.common.dt_us / 4 + 4 * node->config.resend_us;
    if (coavoid_vehicle_all_accepted(node) && now >= decided_by) {
        return coavoid_vehicle_self_commit(node, now);
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
        coavoid_vehicle_phase_on(node, COAVOID_VEHICLE_EVENT_STANDBY);
        coavoid_vehicle_plan_on(node, COAVOID_VEHICLE_EVENT_STANDBY);
        rc = coavoid_vehicle_publish_intent(node, now);
    }
    node->fault = node->fault || rc != COA_OK;
    return rc != COA_OK ? rc : (planned ? 1 : 0);
}

/* ---- what arrives ---- */

/* A word on a plan of its coordinator's (the inbox checked signature, role and fields). */
int coavoid_vehicle_on_agreement(void *owner, const coavoid_agreement_t *msg)
{
    coavoid_vehicle_node_t *node = owner;
    const int64_t now = *node->config.common.clock;
    const bool this_cycle = coavoid_vehicle_started(node) &&
                            msg->valid_from_utime == node->cycle_start &&
                            now < node->cycle_start + node->config.common.dt_us;
    if (!this_cycle) {
        return COA_OK; /* late, or of a plan it never held */
    }
    const bool held = coavoid_vehicle_holds_plan(node) && msg->plan_id == node->pending_plan_id;
    const bool flown = coavoid_vehicle_flies_plan(node) && msg->plan_id == node->cycle_plan_id;
    if (msg->kind == COAVOID_AGREEMENT_T_KIND_COMMIT && flown) {
        (void)coavoid_vehicle_answer(node, now, COAVOID_AGREEMENT_T_KIND_SWITCHED,
                                     msg->plan_id); /* unheard */
    } else if (held && (msg->kind == COAVOID_AGREEMENT_T_KIND_COMMIT ||
                        (msg->kind == COAVOID_AGREEMENT_T_KIND_SWITCHED &&
                         pending_member(node, msg->node_id)))) {
        switch_to_pending(node, now);
    } else if (held && msg->kind == COAVOID_AGREEMENT_T_KIND_ACCEPT) {
        note_accept(node, msg->node_id);
    } else if (held && msg->kind == COAVOID_AGREEMENT_T_KIND_ABORT) {
        coavoid_vehicle_plan_on(node, COAVOID_VEHICLE_EVENT_ABORT);
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
    if (!coavoid_vehicle_started(node) || msg->valid_from_utime != node->cycle_start) {
        return false;
    }
    if (coavoid_vehicle_holds_plan(node) && msg->plan_id == node->pending_plan_id) {
        (void)coavoid_vehicle_answer(node, now, COAVOID_AGREEMENT_T_KIND_ACCEPT, msg->plan_id);
        return true;
    }
    if (coavoid_vehicle_flies_plan(node) && msg->plan_id == node->cycle_plan_id) {
        (void)coavoid_vehicle_answer(node, now, COAVOID_AGREEMENT_T_KIND_SWITCHED, msg->plan_id);
        return true;
    }
    return false;
}

/* The inbox's row hook: any one message of a plan it holds or flies is an answer lost. */
bool coavoid_vehicle_on_plan_row(void *owner, const coavoid_plan_t *msg)
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
        const coa_vec3_t p = coavoid_vehicle_lifted(node->own_reference[j],
                                                    mine[j < samples ? j : samples - 1u], node->dh);
        if (!coa_above_floor(c->min_altitude, &self->volume, p.z)) {
            return "plan: takes this UAV below its floor (min_altitude)";
        }
    }
    return NULL;
}

/* What any plan of this cycle tells, for it or not: a failed search for it (row: its row,
 * SIZE_MAX when it is not listed) answers the cycle for update_trust; a solved plan's rows
 * are what the others will fly (record_rows). */
static void note_plan(coavoid_vehicle_node_t *node, int64_t now, const coavoid_plan_t *msg,
                      const coavoid_lcm_plan_info_t *info, const coa_plan_result_t *result,
                      const int32_t *offsets, size_t row)
{
    const bool this_cycle = coavoid_vehicle_started(node) &&
                            msg->valid_from_utime == node->cycle_start &&
                            now < msg->valid_until_utime;
    if (row != SIZE_MAX && result->status != COA_PLAN_SOLVED && !info->abandoned && this_cycle) {
        /* The coordinator tried this cycle and found nothing: that answers the cycle for
         * update_trust (a UAV told so is not unanswered at its end), and it may still send
         * a larger plan that includes it. A UAV that holds neither that nor a plan of its
         * own by the answer wait plans for itself all the same: the coordinator may have
         * stopped right after the notice, and flying on into a conflict answers nothing. */
        node->cycle_plan_failed = true;
    }
    if (result->status == COA_PLAN_SOLVED && this_cycle) {
        record_rows(node, msg, info, result, offsets);
    }
}

/* Why it refuses its row `mine` (samples offsets) of a plan of this cycle for it, with
 * the refusal's code in *code, or NULL when it accepts it: the plan must come after the
 * one it flies, share its dt, start at the offset flown now, be flyable, and run into
 * nothing it knows (coavoid_vehicle_plan_hits_known). Cost: that check's. */
static const char *refusal(coavoid_vehicle_node_t *node, int64_t now, const coavoid_plan_t *msg,
                           const int32_t *mine, size_t samples, int *code)
{
    *code = COAVOID_LCM_ERR_VALUE;
    if (coavoid_vehicle_flies_plan(node) && msg->plan_id <= node->cycle_plan_id) {
        *code = COAVOID_LCM_ERR_SEQUENCE;
        return "plan: plan_id not after the one adopted this cycle";
    }
    if (msg->dt != (double)node->config.common.dt) {
        return "plan: dt is not this UAV's";
    }
    if (mine[0] != node->state.offset) {
        return "plan: does not start at the offset flown now";
    }
    const char *unflyable = row_unflyable(node, mine, samples);
    if (unflyable != NULL) {
        return unflyable;
    }
    const int hit = coavoid_vehicle_plan_hits_known(node, mine, samples, now, false);
    *code = hit > 0 ? COAVOID_LCM_ERR_VALUE : hit;
    return hit == 0   ? NULL
           : hit == 1 ? "plan: flies this UAV into an obstacle or track it knows"
           : hit == 2 ? "plan: flies this UAV into another UAV's plan or intent"
                      : "plan: cannot be checked against the obstacles and tracks it knows";
}

/* Step 4 of node.h: a coordinator's plan that lists it. */
void coavoid_vehicle_on_plan(void *owner, const coavoid_plan_t *msg,
                             const coavoid_lcm_plan_info_t *info, const coa_plan_result_t *result,
                             const int32_t *offsets)
{
    coavoid_vehicle_node_t *node = owner;
    const int64_t now = *node->config.common.clock;
    size_t row = SIZE_MAX;
    for (size_t i = 0; i < info->vehicle_count; i++) {
        row = info->uav_ids[i] == node->config.vehicle.id ? i : row;
    }
    note_plan(node, now, msg, info, result, offsets, row);
    if (row == SIZE_MAX || result->status != COA_PLAN_SOLVED || row >= result->planned_count) {
        coavoid_lcm_rx_count(&node->state.rx, COA_OK, NULL); /* not a plan for it */
        return;
    }
    if (!coavoid_vehicle_started(node) || msg->valid_from_utime != node->cycle_start) {
        reject_plan(node, COAVOID_LCM_ERR_TIME, "plan: valid_from is not this cycle's start");
        return;
    }
    if (now >= msg->valid_until_utime) {
        reject_plan(node, COAVOID_LCM_ERR_TIME, "plan: arrived after valid_until");
        return;
    }
    const size_t samples = (size_t)info->horizon + 1u;
    const int32_t *mine = offsets + row * samples;
    int code = COA_OK;
    const char *why = refusal(node, now, msg, mine, samples, &code);
    if (why != NULL) {
        refuse_plan(node, now, msg->plan_id, code, why);
        return;
    }
    hold(node, now, info, mine, samples);
    coavoid_lcm_rx_count(&node->state.rx, COA_OK, NULL);
}
