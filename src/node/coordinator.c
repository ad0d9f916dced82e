/* SPDX-License-Identifier: MIT */
/*
 * The coordinator node (node.h, step 3 of the cycle): the ground station that predicts
 * from the intents of the cycle, plans each conflicting cluster in one composite search
 * (decoupled for a cluster larger than its workspace), and publishes the plans, the
 * conflict report and its heartbeat.
 */
#include "protocol_internal.h"
#include "node_lcm.h"

#include <limits.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

/* A solved plan's agreement (docs/protocol.md): proposed to its UAVs (its rows sent, and
 * sent again until every UAV accepted), committed once every one has (COMMIT sent, and
 * sent again until every UAV said SWITCHED), or aborted (a UAV refused, did not answer
 * by the deadline, or a newer plan of the cycle took one of its UAVs). Members are
 * indexed as the plan's vehicles (info.uav_ids). */
typedef enum { AGREEMENT_PROPOSED, AGREEMENT_COMMITTED, AGREEMENT_ABORTED } agreement_state_t;

typedef struct {
    agreement_state_t state;
    coavoid_lcm_plan_info_t info;
    coa_plan_result_t result;
    int32_t offsets[(size_t)COA_MAX_VEHICLES * COAVOID_NODE_MAX_SAMPLES];
    uint32_t accepted; /* bit m: info.uav_ids[m] accepted */
    uint32_t refused;
    uint32_t switched;
    int64_t deadline;     /* proposed: every accept must have come by then */
    int64_t next_send;    /* when the rows (proposed), the commit (committed) or the abort
                          (aborted, aborts_left > 0) go again */
    uint32_t aborts_left; /* copies of the ABORT still to send */
} coordinator_agreement_t;

/* The solved plans of one cycle: every cluster's, the escalations' and the re-plans after
 * an abort; clusters have two UAVs or more, so MAX_PEERS / 2 plus a few. */
#define COORDINATOR_MAX_AGREEMENTS (COAVOID_NODE_MAX_PEERS / 2u + 8u)

struct coavoid_coordinator {
    coavoid_coordinator_config_t config;
    coavoid_node_lcm_t transport; /* its LCM subscriptions and the lcm it publishes on */
    void *solver_memory;          /* node->solver's workspaces */
    coavoid_coordinator_state_t state;
    bool started;
    bool degraded; /* a cluster's plan failed in this cycle */
    bool fault;    /* an internal error in this cycle */
    int64_t plan_id;
    int64_t report_sequence;
    int64_t status_sequence;
    int64_t last_plan_utime;
    int64_t cycle_stopwatch; /* its stopwatch when the cycle's planning began */
    uint64_t cycle_work;     /* work units its searches may still spend this cycle */

    uint32_t labels[COAVOID_NODE_MAX_PEERS];
    bool include[COAVOID_NODE_MAX_PEERS];
    size_t member[COA_MAX_VEHICLES]; /* live indices of the cluster planned */
    coa_vehicle_t vehicles[COA_MAX_VEHICLES];
    const coa_vec3_t *references[COA_MAX_VEHICLES];
    int32_t offsets[(size_t)COA_MAX_VEHICLES * COAVOID_NODE_MAX_SAMPLES];
    coavoid_plan_t tx_plan[COA_MAX_VEHICLES]; /* one message per UAV of a plan */
    coavoid_conflict_report_t tx_report;
    coavoid_status_t tx_status;

    /* The agreements of the current cycle (cycle_start): count in use. */
    int64_t cycle_start;
    uint32_t heartbeat_copies_left;
    int64_t heartbeat_copy_at;
    size_t agreement_count;
    coordinator_agreement_t agreements[COORDINATOR_MAX_AGREEMENTS];
    coavoid_agreement_t tx_agreement;

    coavoid_node_solver_t solver;
    coavoid_node_inbox_t inbox;
    coavoid_node_view_t view;
    coavoid_node_problem_tracks_t problem_tracks;
};

static int on_agreement(void *owner, const coavoid_agreement_t *msg);

coavoid_coordinator_t *coavoid_coordinator_create(const coavoid_coordinator_config_t *config,
                                                  lcm_t *lcm, lcm_t *rx_lcm, int *error)
{
    int dummy = 0;
    if (error == NULL) {
        error = &dummy;
    }
    *error = COA_ERR_ARGUMENT;
    if (config == NULL || lcm == NULL || coavoid_node_common_check(&config->common) != COA_OK ||
        !coavoid_node_floor_ok(&config->common) || config->max_centralised > COA_MAX_CENTRALISED ||
        config->collect_us < 0 || config->collect_us >= config->common.dt_us ||
        config->plan_budget_us < 0) {
        return NULL;
    }
    const coavoid_node_common_t *c = &config->common;
    const size_t max_centralised = config->max_centralised == 0u ? 3u : config->max_centralised;
    const coavoid_node_solver_shape_t shape = {c->horizon, c->horizon, max_centralised, c->beta};
    const size_t solver_size = coavoid_node_solver_size(&shape);
    if (solver_size == 0u) {
        return NULL;
    }
    coavoid_coordinator_t *node = calloc(1, sizeof *node);
    void *solver_memory = malloc(solver_size);
    int rc = node != NULL && solver_memory != NULL
                 ? coavoid_node_solver_place(&node->solver, solver_memory, solver_size, &shape)
                 : COA_ERR_WORKSPACE;
    if (rc != COA_OK) {
        free(node);
        free(solver_memory);
        *error = rc;
        return NULL;
    }
    node->solver_memory = solver_memory;
    node->config = *config;
    node->config.max_centralised = max_centralised;
    if (node->config.id == 0u) {
        node->config.id = (uint16_t)COAVOID_NODE_COORDINATOR_ID;
    }
    if (node->config.collect_us == 0) {
        node->config.collect_us = c->dt_us / 4;
    }
    if (node->config.ack_timeout_us <= 0) {
        node->config.ack_timeout_us = c->dt_us / 4 > 0 ? c->dt_us / 4 : 1;
    }
    if (node->config.plan_work == 0u) {
        node->config.plan_work = coavoid_node_work_of(
            node->config.plan_budget_us > 0 ? node->config.plan_budget_us
                                            : (c->dt_us - node->config.collect_us) * 3 / 4);
    }
    if (node->config.resend_us <= 0) {
        node->config.resend_us = c->dt_us / 40 > 0 ? c->dt_us / 40 : 1;
    }
    node->state.cycle = -1;
    node->state.last_outcome = -1;
    /* No UAV is its own: intents are all others'. */
    coavoid_node_lcm_init(&node->transport, lcm, rx_lcm);
    const coavoid_node_link_t link = coavoid_node_lcm_link(&node->transport);
    rc = coavoid_node_inbox_init(&node->inbox, c, 0u, node->config.id, 0u, COAVOID_NODE_MAX_PEERS,
                                 &link, &node->state.rx, false, NULL, node);
    if (rc == COA_OK) {
        node->inbox.coordinator_id = node->config.id; /* the agreements on its own plans */
        coavoid_node_inbox_agreements(&node->inbox, on_agreement);
        rc = coavoid_node_lcm_subscribe(&node->transport, &node->inbox);
        if (rc != COA_OK) {
            coavoid_node_inbox_fini(&node->inbox);
        }
    }
    if (rc != COA_OK) {
        free(node->solver_memory);
        free(node);
        *error = rc;
        return NULL;
    }
    node->config.common.signer = NULL; /* copied by the inbox: the caller's may go */
    node->config.common.trust = NULL;
    *error = COA_OK;
    return node;
}

void coavoid_coordinator_destroy(coavoid_coordinator_t *node)
{
    if (node == NULL) {
        return;
    }
    coavoid_node_lcm_unsubscribe(&node->transport);
    coavoid_node_inbox_fini(&node->inbox);
    free(node->solver_memory);
    free(node);
}

const coavoid_coordinator_state_t *coavoid_coordinator_state(const coavoid_coordinator_t *node)
{
    return node != NULL ? &node->state : NULL;
}

static int publish_report(coavoid_coordinator_t *node, int64_t now, int64_t cycle_start,
                          const coa_predict_result_t *result)
{
    const coavoid_node_common_t *c = &node->config.common;
    const coavoid_node_view_t *view = &node->view;
    coavoid_lcm_context_t ctx = coavoid_node_context(&node->inbox, now, cycle_start);
    int rc = coavoid_lcm_conflict_report_from_core(
        node->solver.conflicts, result->conflict_count, result->conflicts_found, view->live_id,
        view->live_count, view->track_ids, view->track_count,
        view->live_count > 0u ? node->labels : NULL, now, node->config.id, node->report_sequence++,
        cycle_start, c->dt, c->horizon, &ctx, &node->tx_report, NULL);
    if (rc != COA_OK) {
        return COA_ERR_ARGUMENT;
    }
    return coavoid_node_publish_conflicts(&node->inbox.tx, &node->tx_report);
}

static int publish_status(coavoid_coordinator_t *node, int64_t now, int64_t cycle_start)
{
    const coavoid_coordinator_state_t *s = &node->state;
    const coavoid_node_heartbeat_t h = {
        node->config.id,
        COAVOID_STATUS_T_NODE_COORDINATOR,
        node->status_sequence++,
        (node->fault ? COAVOID_STATUS_T_REASON_INTERNAL_ERROR : 0) |
            (node->degraded ? COAVOID_STATUS_T_REASON_PLANNING_FAILED : 0) |
            (node->view.stale_count > 0u ? COAVOID_STATUS_T_REASON_STALE_PEERS : 0),
        COAVOID_STATUS_T_MODE_CENTRALISED,
        node->last_plan_utime,
        s->last_plan_duration_us,
        s->last_nodes_expanded,
        s->last_outcome,
        s->conflicts,
        s->plans_run,
        &s->rx};
    return coavoid_node_publish_heartbeat(&node->inbox, &node->tx_status, now, cycle_start, &h);
}

/* Which UAVs a planning call takes: one cluster, every clustered UAV, or every UAV. */
#define GROUP_CLUSTERED (COA_NO_CLUSTER - 1u)
#define GROUP_ALL COA_NO_CLUSTER

/* The UAVs of `group` (a cluster label, GROUP_CLUSTERED or GROUP_ALL) with an intent for
 * this cycle that follow the coordinator, ascending id; past COA_MAX_VEHICLES (a plan_t's
 * rows) only the highest priorities are planned and the rest stay moving obstacles.
 * Returns the count. */
static size_t cluster_members(coavoid_coordinator_t *node, uint32_t group)
{
    const coavoid_node_view_t *view = &node->view;
    size_t count = 0;
    for (size_t i = 0; i < view->live_count; i++) {
        bool in =
            group == GROUP_ALL || (group == GROUP_CLUSTERED ? node->labels[i] != COA_NO_CLUSTER
                                                            : node->labels[i] == group);
        /* A UAV that says it plans for itself (decoupled intent) will not fly a plan of
         * the coordinator's: planning it jointly would leave the others' plans relying on
         * a move it does not make. It stays a moving obstacle. */
        if (!in || !view->live_current[i] ||
            view->live_info[i].mode != COAVOID_INTENT_T_MODE_CENTRALISED) {
            continue;
        }
        if (count < COA_MAX_VEHICLES) {
            node->member[count++] = i;
            continue;
        }
        /* Full: replace the lowest-ranked member if this one outranks it. */
        size_t worst = 0;
        for (size_t m = 1; m < count; m++) {
            const coa_vehicle_t *a = &view->live_vehicle[node->member[m]];
            const coa_vehicle_t *b = &view->live_vehicle[node->member[worst]];
            if (coavoid_node_outranks(b->priority, b->id, a->priority, a->id)) {
                worst = m;
            }
        }
        const coa_vehicle_t *w = &view->live_vehicle[node->member[worst]];
        const coa_vehicle_t *v = &view->live_vehicle[i];
        if (coavoid_node_outranks(v->priority, v->id, w->priority, w->id)) {
            node->member[worst] = i;
        }
    }
    /* Keep ascending id (the order the plan's rows follow). */
    for (size_t a = 1; a < count; a++) {
        size_t x = node->member[a];
        size_t b = a;
        while (b > 0 && node->member[b - 1] > x) {
            node->member[b] = node->member[b - 1];
            b--;
        }
        node->member[b] = x;
    }
    return count;
}

/* Plans one cluster and publishes its plan; a solved plan replaces the members' positions
 * in the view, so that later clusters plan around it. *solved says how it went. */
/* The problem of the cluster's `count` members (node->member), around everything else the
 * view has as tracks. */
static int cluster_problem(coavoid_coordinator_t *node, size_t count, coa_problem_t *problem)
{
    coavoid_node_view_t *view = &node->view;
    for (size_t i = 0; i < view->live_count; i++) {
        node->include[i] = true;
    }
    for (size_t m = 0; m < count; m++) {
        size_t i = node->member[m];
        node->include[i] = false;
        node->vehicles[m] = view->live_vehicle[i];
        node->references[m] = view->live_arrays[i].reference;
    }
    int rc =
        coavoid_node_problem(problem, &node->problem_tracks, view, node->include, &node->inbox,
                             node->vehicles, node->references, count, node->config.common.horizon);
    problem->has_floor = node->config.common.has_floor;
    problem->floor_z = node->config.common.min_altitude;
    return rc;
}

/* Plans the cluster, centralised when it is small enough. A joint search can fill its beta
 * nodes: when beta runs out before it proves anything, the cluster is planned decoupled
 * (in priority order) rather than left to fly into its conflict. A proof of infeasibility
 * stands: no order beats it. *centralised says which plan it is. */
static int cluster_plan(coavoid_coordinator_t *node, int64_t now, const coa_problem_t *problem,
                        bool *centralised, coa_plan_result_t *result)
{
    const coavoid_node_common_t *c = &node->config.common;
    coa_planner_t *planner = coavoid_node_solver_planner(&node->solver);
    const size_t count = problem->vehicle_count;
    int rc;
    *centralised = count <= node->config.max_centralised;
    int64_t start = coavoid_node_stopwatch(c);
    if (*centralised) {
        /* At least one unit: 0 would mean no limit. */
        (void)coa_planner_set_work(planner, node->cycle_work > 0u ? node->cycle_work : 1u);
        rc = coa_plan_centralised(planner, problem, node->offsets, result);
        node->state.last_plan_work = rc == COA_OK ? result->work : 0u;
        /* A cycle with no work left gave its search 1 unit, which it may spend. */
        node->cycle_work -= node->state.last_plan_work < node->cycle_work
                                ? node->state.last_plan_work
                                : node->cycle_work;
        if (rc == COA_OK && result->status == COA_PLAN_BUDGET_EXHAUSTED && count > 1u) {
            node->state.plans_run++;
            node->state.clusters_planned++;
            *centralised = false;
            (void)coa_planner_set_work(planner, 0u);
            rc = coa_plan_decoupled(planner, problem, NULL, 1u, node->offsets, result);
        }
    } else {
        (void)coa_planner_set_work(planner, 0u);
        rc = coa_plan_decoupled(planner, problem, NULL, 1u, node->offsets, result);
    }
    int64_t duration = coavoid_node_stopwatch(c) - start;
    node->state.plans_run++;
    node->state.clusters_planned++;
    node->last_plan_utime = now;
    node->state.last_plan_duration_us = duration > 0 ? duration : 0;
    if (rc == COA_OK) {
        node->state.last_outcome = (int)result->status;
        node->state.last_nodes_expanded = result->nodes_expanded;
    }
    return rc;
}

/* The messages of a plan, one per UAV in the result's order, each checked as a receiver
 * would (COA_ERR_ARGUMENT when one fails: none is sent), stamped `now`, then published
 * back to back (the first publishing error in *published). */
static int publish_rows(coavoid_coordinator_t *node, int64_t now, int64_t cycle_start,
                        const coavoid_lcm_plan_info_t *plan, const coa_plan_result_t *result,
                        const int32_t *offsets, int *published)
{
    const coavoid_node_common_t *c = &node->config.common;
    coavoid_lcm_plan_info_t info = *plan;
    info.utime = now;
    coavoid_lcm_context_t ctx = coavoid_node_context(&node->inbox, now, cycle_start);
    for (size_t row = 0; row < info.vehicle_count; row++) {
        coavoid_plan_t *msg = &node->tx_plan[row];
        int rc = coavoid_lcm_plan_from_core(&info, result, offsets, row, &ctx, msg, NULL);
        if (rc == COA_OK) {
            /* The validity window in exact microseconds, whatever the core's precision. */
            msg->valid_from_utime = cycle_start;
            msg->valid_until_utime = cycle_start + c->dt_us;
            rc = coavoid_lcm_plan_check(msg, &ctx, NULL);
        }
        if (rc != COA_OK) {
            return COA_ERR_ARGUMENT;
        }
    }
    *published = COA_OK;
    for (size_t row = 0; row < info.vehicle_count; row++) {
        int rc = coavoid_node_publish_plan(&node->inbox.tx, &node->tx_plan[row]);
        *published = (*published == COA_OK) ? rc : *published;
    }
    return COA_OK;
}

/* The header of the cluster's plan (node->vehicles[0..count)), with the next plan_id. */
static coavoid_lcm_plan_info_t cluster_info(coavoid_coordinator_t *node, int64_t now, size_t count,
                                            bool centralised, bool abandoned)
{
    const coavoid_node_common_t *c = &node->config.common;
    coavoid_lcm_plan_info_t info;
    memset(&info, 0, sizeof info);
    info.utime = now;
    info.coordinator_id = node->config.id;
    info.plan_id = node->plan_id++;
    info.valid_from = 0;
    info.valid_until = c->dt;
    info.dt = c->dt;
    info.horizon = c->horizon;
    info.mode = centralised ? COAVOID_PLAN_T_MODE_CENTRALISED : COAVOID_PLAN_T_MODE_DECOUPLED;
    info.vehicle_count = count;
    info.abandoned = abandoned;
    for (size_t m = 0; m < count; m++) {
        info.uav_ids[m] = node->vehicles[m].id;
    }
    return info;
}

/* Whether the cycle's planning has run past its budget (config.plan_budget_us). */
static bool over_budget(const coavoid_coordinator_t *node)
{
    const int64_t budget = node->config.plan_budget_us;
    return budget > 0 &&
           coavoid_node_stopwatch(&node->config.common) - node->cycle_stopwatch > budget;
}

/* Live UAV i of the view flies row m of `offsets` from now on: so that later plans of the
 * cycle plan around it. */
static void view_fly_row(coavoid_coordinator_t *node, size_t i, const int32_t *offsets, size_t m)
{
    const coavoid_node_common_t *c = &node->config.common;
    coavoid_node_view_t *view = &node->view;
    const size_t samples = (size_t)c->horizon + 1u;
    coavoid_lcm_intent_arrays_t *a = &view->live_arrays[i];
    coa_real_t dh = coa_climb_step(&view->live_vehicle[i], c->dt);
    for (size_t j = 0; j < samples; j++) {
        a->offsets[j] = offsets[m * samples + j];
        a->samples[j] = a->reference[j];
        a->samples[j].z += (coa_real_t)a->offsets[j] * dh;
    }
}

/* ---- agreement on a plan (docs/protocol.md) ---- */

static uint32_t all_members(const coordinator_agreement_t *a)
{
    return UINT32_MAX >> (32u - (uint32_t)a->info.vehicle_count);
}

/* The member index of UAV id in a's plan, or vehicle_count. */
static size_t member_of(const coordinator_agreement_t *a, int32_t id)
{
    size_t m = 0;
    while (m < a->info.vehicle_count && (int32_t)a->info.uav_ids[m] != id) {
        m++;
    }
    return m;
}

static int send_decision(coavoid_coordinator_t *node, int64_t now, const coordinator_agreement_t *a)
{
    coavoid_agreement_t *msg = &node->tx_agreement;
    memset(msg, 0, sizeof *msg);
    msg->utime = now;
    msg->kind = a->state == AGREEMENT_COMMITTED ? COAVOID_AGREEMENT_T_KIND_COMMIT
                                                : COAVOID_AGREEMENT_T_KIND_ABORT;
    msg->node_id = node->config.id;
    msg->coordinator_id = node->config.id;
    msg->plan_id = a->info.plan_id;
    msg->valid_from_utime = node->cycle_start;
    return coavoid_node_publish_agreement(&node->inbox.tx, msg);
}

/* Ends a proposal: committed (every member accepted) or aborted. The decision goes out at
 * once; a commit again every resend_us until every member switched. */
static int agreement_decide(coavoid_coordinator_t *node, int64_t now, coordinator_agreement_t *a,
                            agreement_state_t state)
{
    a->state = state;
    a->next_send = now + node->config.resend_us;
    /* An ABORT goes out with copies: a UAV that heard every member accept and no
     * decision commits the plan itself at its answer wait (docs/protocol.md). */
    a->aborts_left = state == AGREEMENT_ABORTED ? node->config.heartbeat_copies : 0u;
    node->state.plans_committed += state == AGREEMENT_COMMITTED ? 1u : 0u;
    node->state.plans_aborted += state == AGREEMENT_ABORTED ? 1u : 0u;
    return send_decision(node, now, a);
}

/* A newer plan of the cycle takes its UAVs from every proposal that lists one of them. */
static void agreement_supersede(coavoid_coordinator_t *node, int64_t now,
                                const coavoid_lcm_plan_info_t *newer)
{
    for (size_t i = 0; i < node->agreement_count; i++) {
        coordinator_agreement_t *a = &node->agreements[i];
        bool shared = false;
        for (size_t m = 0; m < newer->vehicle_count && !shared; m++) {
            shared = member_of(a, (int32_t)newer->uav_ids[m]) < a->info.vehicle_count;
        }
        if (shared && a->state == AGREEMENT_PROPOSED) {
            (void)agreement_decide(node, now, a, AGREEMENT_ABORTED);
        }
    }
}

/* Proposes a solved plan just published: its UAVs fly it only once all have accepted. A
 * cycle with more plans than room (it cannot happen with MAX_PEERS UAVs) leaves the
 * extra plan unproposed: never committed, so never flown. */
static void agreement_open(coavoid_coordinator_t *node, int64_t now,
                           const coavoid_lcm_plan_info_t *info, const coa_plan_result_t *result)
{
    agreement_supersede(node, now, info);
    if (node->agreement_count == COORDINATOR_MAX_AGREEMENTS) {
        node->fault = true;
        return;
    }
    coordinator_agreement_t *a = &node->agreements[node->agreement_count++];
    const size_t samples = (size_t)node->config.common.horizon + 1u;
    a->state = AGREEMENT_PROPOSED;
    a->info = *info;
    a->result = *result;
    memcpy(a->offsets, node->offsets, info->vehicle_count * samples * sizeof a->offsets[0]);
    a->accepted = 0u;
    a->refused = 0u;
    a->switched = 0u;
    a->deadline = now + node->config.ack_timeout_us;
    a->next_send = now + node->config.resend_us;
    node->state.plans_proposed++;
}

static coordinator_agreement_t *agreement_find(coavoid_coordinator_t *node, int64_t plan_id,
                                               int64_t valid_from)
{
    if (valid_from != node->cycle_start) {
        return NULL;
    }
    for (size_t i = 0; i < node->agreement_count; i++) {
        if (node->agreements[i].info.plan_id == plan_id) {
            return &node->agreements[i];
        }
    }
    return NULL;
}

/* A UAV's answer. Answers on plans of other cycles, or unknown ones, are late or stray:
 * accepted as messages and ignored. A kind only the coordinator sends, from another
 * node, was refused before (role). */
static int on_agreement(void *owner, const coavoid_agreement_t *msg)
{
    coavoid_coordinator_t *node = owner;
    const int64_t now = *node->config.common.clock;
    coordinator_agreement_t *a = agreement_find(node, msg->plan_id, msg->valid_from_utime);
    if (a == NULL) {
        return COA_OK;
    }
    const size_t m = member_of(a, msg->node_id);
    if (m == a->info.vehicle_count) {
        return COAVOID_LCM_ERR_ID; /* not a UAV of this plan */
    }
    const uint32_t bit = UINT32_C(1) << (uint32_t)m;
    if (msg->kind == COAVOID_AGREEMENT_T_KIND_ACCEPT) {
        a->accepted |= bit;
    } else if (msg->kind == COAVOID_AGREEMENT_T_KIND_REFUSE) {
        a->refused |= bit;
        a->deadline = a->state == AGREEMENT_PROPOSED ? now : a->deadline; /* abort at once */
    } else if (msg->kind == COAVOID_AGREEMENT_T_KIND_SWITCHED) {
        a->switched |= bit;
        a->accepted |= bit;
    }
    if (a->state == AGREEMENT_PROPOSED && a->accepted == all_members(a)) {
        a->next_send = now; /* committed by the poll that follows at once: the coordinator
                               publishes from its own calls only, never from inside a
                               message handler, so that its messages follow its calls */
    }
    return COA_OK;
}

static int plan_cluster(coavoid_coordinator_t *node, int64_t now, int64_t cycle_start, size_t count,
                        bool *solved)
{
    coa_problem_t problem;
    coa_plan_result_t result;
    bool centralised = false;
    *solved = false;
    int rc = cluster_problem(node, count, &problem);
    if (rc != COA_OK) {
        return rc;
    }
    /* Past the budget the plan would come late: the cluster is abandoned, before its
     * search or after it. */
    memset(&result, 0, sizeof result);
    result.status = COA_PLAN_BUDGET_EXHAUSTED;
    for (size_t m = 0; m < count; m++) {
        result.order[m] = m;
    }
    bool abandoned = over_budget(node);
    if (!abandoned) {
        rc = cluster_plan(node, now, &problem, &centralised, &result);
        if (rc != COA_OK) {
            return rc;
        }
        abandoned = over_budget(node);
    }
    node->state.plans_abandoned += abandoned ? 1u : 0u;
    int published = COA_OK;
    const coavoid_lcm_plan_info_t info = cluster_info(node, now, count, centralised, abandoned);
    if (publish_rows(node, now, cycle_start, &info, &result, node->offsets, &published) != COA_OK) {
        return COA_ERR_ARGUMENT;
    }
    rc = published;
    if (abandoned || result.status != COA_PLAN_SOLVED) {
        return rc;
    }
    agreement_open(node, now, &info, &result);
    *solved = true;
    node->state.plans_published++;
    for (size_t m = 0; m < count; m++) {
        view_fly_row(node, node->member[m], node->offsets, m);
    }
    return rc;
}

/* The clusters in label order (by smallest id), each around the plans before it; the
 * size of the largest that found no plan (0: none). Keeps the first error in *first_error. */
static size_t plan_clusters(coavoid_coordinator_t *node, int64_t now, int64_t cycle_start,
                            size_t clusters, int *first_error)
{
    size_t failed_size = 0;
    for (uint32_t label = 0; label < clusters; label++) {
        size_t count = cluster_members(node, label);
        if (count == 0u) {
            continue;
        }
        bool solved = false;
        int rc = plan_cluster(node, now, cycle_start, count, &solved);
        if (rc != COA_OK) {
            node->fault = true;
            *first_error = *first_error != COA_OK ? *first_error : rc;
        }
        if (!solved && count > failed_size) {
            failed_size = count;
        }
    }
    return failed_size;
}

/* A cluster is only the UAVs that conflict now; its way out may be blocked by UAVs that do
 * not (a UAV that must climb over terrain into traffic at the altitude it needs). Then the
 * clusters are planned as one group, and failing that every UAV, each from the intents as
 * they came (the plans just published are superseded by the newer plan_id, which every UAV
 * of the group adopts). Returns the size of the group left without a plan (0: none). */
static size_t escalate(coavoid_coordinator_t *node, int64_t now, int64_t cycle_start,
                       size_t failed_size, int *first_error)
{
    const uint32_t escalation[2] = {GROUP_CLUSTERED, GROUP_ALL};
    for (size_t e = 0; e < 2u && failed_size > 0u && *first_error == COA_OK && !over_budget(node);
         e++) {
        size_t count = cluster_members(node, escalation[e]);
        if (count <= failed_size) {
            continue;
        }
        coavoid_node_view_build(&node->view, &node->inbox, cycle_start, now);
        bool solved = false;
        int rc = plan_cluster(node, now, cycle_start, count, &solved);
        if (rc != COA_OK) {
            node->fault = true;
            *first_error = rc;
        }
        failed_size = solved ? 0u : count;
    }
    return failed_size;
}

/* The live index of UAV id in the view, with an intent of this cycle that follows the
 * coordinator; or live_count. */
static size_t live_follower(const coavoid_node_view_t *view, uint16_t id)
{
    for (size_t i = 0; i < view->live_count; i++) {
        if (view->live_id[i] == id) {
            return view->live_current[i] &&
                           view->live_info[i].mode == COAVOID_INTENT_T_MODE_CENTRALISED
                       ? i
                       : view->live_count;
        }
    }
    return view->live_count;
}

/* The view of now, each UAV of the cycle's other live plans (proposed or committed) on
 * its row. */
static void view_with_plans(coavoid_coordinator_t *node, int64_t now,
                            const coordinator_agreement_t *skip)
{
    coavoid_node_view_t *view = &node->view;
    coavoid_node_view_build(view, &node->inbox, node->cycle_start, now);
    for (size_t k = 0; k < node->agreement_count; k++) {
        const coordinator_agreement_t *a = &node->agreements[k];
        if (a == skip || a->state == AGREEMENT_ABORTED) {
            continue;
        }
        for (size_t m = 0; m < a->info.vehicle_count; m++) {
            size_t i = live_follower(view, a->info.uav_ids[m]);
            if (i < view->live_count) {
                view_fly_row(node, i, a->offsets, m);
            }
        }
    }
}

/* After an abort for a refusal or silence: the UAVs that accepted are planned again, in
 * the same cycle when there is time for another round, around the others as they fly
 * now (a UAV that did not accept never switches: no commit can come for it). The new
 * plan is proposed as any other. Returns COA_OK or the planning call's error. */
static int replan_accepted(coavoid_coordinator_t *node, int64_t now, size_t index)
{
    const coavoid_coordinator_config_t *cf = &node->config;
    const int64_t end = node->cycle_start + cf->common.dt_us;
    if (now + cf->ack_timeout_us + 2 * cf->resend_us > end) {
        return COA_OK; /* no time to agree again: they are unanswered, and plan themselves */
    }
    const coordinator_agreement_t *a = &node->agreements[index];
    const uint32_t keep = a->accepted & ~a->refused;
    view_with_plans(node, now, a);
    size_t count = 0;
    for (size_t m = 0; m < a->info.vehicle_count; m++) {
        size_t i = live_follower(&node->view, a->info.uav_ids[m]);
        if ((keep & (UINT32_C(1) << (uint32_t)m)) != 0u && i < node->view.live_count) {
            node->member[count++] = i;
        }
    }
    if (count == 0u) {
        return COA_OK;
    }
    node->state.plans_replanned++;
    node->cycle_stopwatch = coavoid_node_stopwatch(&cf->common);
    node->cycle_work = cf->plan_work;
    bool solved = false;
    return plan_cluster(node, now, node->cycle_start, count, &solved);
}

/* One proposal or commit at `now`: decided, sent again, or left. Returns 1 when it
 * published, 0 when not, or a negative error. */
static int agreement_step(coavoid_coordinator_t *node, int64_t now, size_t index)
{
    coordinator_agreement_t *a = &node->agreements[index];
    const int64_t resend = node->config.resend_us;
    if (a->state == AGREEMENT_PROPOSED && a->accepted == all_members(a)) {
        int rc = agreement_decide(node, now, a, AGREEMENT_COMMITTED);
        return rc != COA_OK ? rc : 1;
    }
    if (a->state == AGREEMENT_PROPOSED && (now >= a->deadline || a->refused != 0u)) {
        int rc = agreement_decide(node, now, a, AGREEMENT_ABORTED);
        int replanned = replan_accepted(node, now, index);
        rc = rc != COA_OK ? rc : replanned;
        return rc != COA_OK ? rc : 1;
    }
    if (now < a->next_send) {
        return 0;
    }
    if (a->state == AGREEMENT_PROPOSED) {
        int published = COA_OK;
        a->next_send = now + resend;
        node->state.plans_resent++;
        int rc = publish_rows(node, now, node->cycle_start, &a->info, &a->result, a->offsets,
                              &published);
        rc = rc != COA_OK ? rc : published;
        return rc != COA_OK ? rc : 1;
    }
    if ((a->state == AGREEMENT_COMMITTED && a->switched != all_members(a)) ||
        (a->state == AGREEMENT_ABORTED && a->aborts_left > 0u)) {
        a->next_send = now + resend;
        a->aborts_left -= a->state == AGREEMENT_ABORTED ? 1u : 0u;
        int rc = send_decision(node, now, a);
        return rc != COA_OK ? rc : 1;
    }
    return 0;
}

int coavoid_coordinator_poll(coavoid_coordinator_t *node, int64_t now)
{
    if (node == NULL) {
        return COA_ERR_ARGUMENT;
    }
    if (!node->started || now >= node->cycle_start + node->config.common.dt_us) {
        return 0;
    }
    int result = 0;
    if (node->heartbeat_copies_left > 0u && now >= node->heartbeat_copy_at) {
        node->heartbeat_copies_left--;
        node->heartbeat_copy_at = now + node->config.resend_us;
        result = publish_status(node, now, node->cycle_start);
        result = result < 0 ? result : 1;
    }
    /* A re-plan appends to the list: it is stepped in this same pass. */
    for (size_t i = 0; i < node->agreement_count; i++) {
        int rc = agreement_step(node, now, i);
        if (rc < 0) {
            node->fault = true;
            result = result < 0 ? result : rc;
        } else if (rc > 0 && result == 0) {
            result = 1;
        }
    }
    return result;
}

int64_t coavoid_coordinator_deadline(const coavoid_coordinator_t *node)
{
    if (node == NULL || !node->started) {
        return INT64_MAX;
    }
    const int64_t end = node->cycle_start + node->config.common.dt_us;
    int64_t deadline = node->heartbeat_copies_left > 0u ? node->heartbeat_copy_at : INT64_MAX;
    for (size_t i = 0; i < node->agreement_count; i++) {
        const coordinator_agreement_t *a = &node->agreements[i];
        int64_t t = INT64_MAX;
        if (a->state == AGREEMENT_PROPOSED) {
            t = a->deadline < a->next_send ? a->deadline : a->next_send;
        } else if ((a->state == AGREEMENT_COMMITTED && a->switched != all_members(a)) ||
                   (a->state == AGREEMENT_ABORTED && a->aborts_left > 0u)) {
            t = a->next_send;
        }
        deadline = t < deadline ? t : deadline;
    }
    return deadline < end ? deadline : INT64_MAX;
}

int coavoid_coordinator_cycle(coavoid_coordinator_t *node, int64_t now)
{
    if (node == NULL) {
        return COA_ERR_ARGUMENT;
    }
    const coavoid_node_common_t *c = &node->config.common;
    const int64_t k = coavoid_node_cycle_of(c, now);
    if (k < 0) {
        return COA_ERR_ARGUMENT;
    }
    if (node->started && k <= node->state.cycle) {
        return COA_OK;
    }
    node->started = true;
    node->state.cycle = k;
    node->state.clusters_planned = 0;
    node->degraded = false;
    node->fault = false;
    const int64_t cycle_start = coavoid_node_cycle_utime(c, k);
    node->cycle_start = cycle_start;
    node->agreement_count = 0; /* the last cycle's plans can no longer be adopted */
    coavoid_node_inbox_expire(&node->inbox, now);
    coavoid_node_view_t *view = &node->view;
    coavoid_node_view_build(view, &node->inbox, cycle_start, now);

    coa_predict_result_t result;
    size_t clusters = 0;
    coavoid_node_solver_t *sv = &node->solver;
    int first_error = coavoid_node_predict(coavoid_node_solver_predictor(sv), c, view->live_plan,
                                           view->live_count, view, &node->inbox, sv->conflicts,
                                           sv->conflict_capacity, &result, node->labels, &clusters);
    if (first_error != COA_OK) {
        memset(&result, 0, sizeof result);
        clusters = 0;
        node->fault = true;
    }
    node->state.conflicts =
        result.conflicts_found > UINT32_MAX ? UINT32_MAX : (uint32_t)result.conflicts_found;
    int rc = publish_report(node, now, cycle_start, &result);
    if (first_error == COA_OK) {
        first_error = rc;
    }
    node->cycle_stopwatch = coavoid_node_stopwatch(c);
    node->cycle_work = node->config.plan_work;
    size_t failed_size = plan_clusters(node, now, cycle_start, clusters, &first_error);
    failed_size = escalate(node, now, cycle_start, failed_size, &first_error);
    node->degraded = failed_size > 0u;
    rc = publish_status(node, now, cycle_start);
    node->heartbeat_copies_left = node->config.heartbeat_copies;
    node->heartbeat_copy_at = now + node->config.resend_us;
    if (first_error == COA_OK) {
        first_error = rc;
    }
    return first_error;
}
