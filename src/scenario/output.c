/* SPDX-License-Identifier: MIT */
#include "output.h"

#include <errno.h>
#include <stdarg.h>
#include <stdlib.h>
#include <string.h>

#include <cjson/cJSON.h>

const char *coavoid_output_status_name(coa_plan_status_t status)
{
    switch (status) {
    case COA_PLAN_SOLVED:
        return "solved";
    case COA_PLAN_INFEASIBLE:
        return "infeasible";
    case COA_PLAN_BUDGET_EXHAUSTED:
        return "budget_exhausted";
    }
    return "unknown";
}

static int set_error(char *err, size_t err_size, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 3, 4)))
#endif
    ;

static int set_error(char *err, size_t err_size, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(err, err_size, fmt, ap);
    va_end(ap);
    return -1;
}

/* cJSON keeps numbers as doubles and prints them with the shortest of %.15g and %.17g that
 * reads back to the same double, so every value here round-trips exactly (integers up to
 * 2^53, far beyond any count the planner reaches). */
static bool add_number(cJSON *obj, const char *key, double value)
{
    return cJSON_AddNumberToObject(obj, key, value) != NULL;
}

bool coavoid_output_append(cJSON *array, cJSON *item)
{
    if (item == NULL) {
        return false;
    }
    if (!cJSON_AddItemToArray(array, item)) {
        cJSON_Delete(item);
        return false;
    }
    return true;
}

/* One entry of "vehicles". Returns 0, -1 out of memory, -2 a row the core should never
 * have produced (err set). */
static int add_vehicle(cJSON *array, const coavoid_scenario_t *s, size_t index, const int32_t *row,
                       char *err, size_t err_size)
{
    const coa_vehicle_t *v = &s->vehicles[index];
    double deviation = 0;
    uint32_t effort = 0;
    if (coa_plan_vehicle_cost(v, s->dt, s->horizon, row, &deviation, &effort) != COA_OK) {
        set_error(err, err_size, "internal error: vehicle %u's plan is not a sequence of actions",
                  (unsigned)v->id);
        return -2;
    }
    cJSON *entry = cJSON_CreateObject();
    if (!coavoid_output_append(array, entry) || !add_number(entry, "id", v->id)) {
        return -1;
    }
    cJSON *offsets = cJSON_AddArrayToObject(entry, "offsets");
    cJSON *actions = cJSON_AddArrayToObject(entry, "actions");
    if (offsets == NULL || actions == NULL) {
        return -1;
    }
    for (uint32_t k = 0; k <= s->horizon; k++) {
        if (!coavoid_output_append(offsets, cJSON_CreateNumber(row[k]))) {
            return -1;
        }
    }
    for (uint32_t k = 0; k < s->horizon; k++) {
        int action = coa_action_between(row[k], row[k + 1], v->steep_factor);
        if (action < 0) {
            set_error(err, err_size,
                      "internal error: vehicle %u moves from offset %ld to %ld at step %lu",
                      (unsigned)v->id, (long)row[k], (long)row[k + 1], (unsigned long)k);
            return -2;
        }
        if (!coavoid_output_append(actions,
                                   cJSON_CreateString(coa_action_name((coa_action_t)action)))) {
            return -1;
        }
    }
    if (!add_number(entry, "deviation", deviation) || !add_number(entry, "effort", effort)) {
        return -1;
    }
    return 0;
}

/* Centralised: whether the plan is proven optimal, and the lower bound on the optimum
 * (none when infeasible). 0, or -1 out of memory. */
static int build_bound(cJSON *root, const coa_plan_result_t *r)
{
    if (cJSON_AddBoolToObject(root, "optimal", r->optimal) == NULL) {
        return -1;
    }
    if (r->status != COA_PLAN_INFEASIBLE) {
        cJSON *bound = cJSON_AddObjectToObject(root, "bound");
        if (bound == NULL || !add_number(bound, "deviation", r->bound_deviation) ||
            !add_number(bound, "effort", r->bound_effort)) {
            return -1;
        }
    }
    return 0;
}

/* The contract's name of the limit that ended a call early. */
static const char *limit_name(coa_plan_limit_t limit)
{
    switch (limit) {
    case COA_PLAN_LIMIT_BETA:
        return "beta";
    case COA_PLAN_LIMIT_WORK:
        return "work";
    case COA_PLAN_LIMIT_NONE:
    default:
        return "none";
    }
}

/* The result's scenario, mode, status, planning order and, when there is one, the failed
 * vehicle and the cost. 0, or -1 out of memory, -2 an inconsistent result (err set). */
static int build_head(cJSON *root, const coavoid_output_plan_t *plan, char *err, size_t err_size)
{
    const coavoid_scenario_t *s = plan->scenario;
    const coa_plan_result_t *r = plan->result;
    const size_t n = s->vehicle_count;
    if (cJSON_AddStringToObject(root, "scenario", s->name) == NULL ||
        cJSON_AddStringToObject(root, "mode", plan->decoupled ? "decoupled" : "centralised") ==
            NULL ||
        cJSON_AddStringToObject(root, "status", coavoid_output_status_name(r->status)) == NULL) {
        return -1;
    }
    cJSON *order = cJSON_AddArrayToObject(root, "priority_order");
    if (order == NULL) {
        return -1;
    }
    for (size_t j = 0; j < n; j++) {
        /* Centralised plans everyone at once: its "order" is the input order. */
        size_t i = plan->decoupled ? r->order[j] : j;
        if (i >= n) {
            set_error(err, err_size, "internal error: planning order names vehicle index %zu", i);
            return -2;
        }
        if (!coavoid_output_append(order, cJSON_CreateNumber(s->vehicles[i].id))) {
            return -1;
        }
    }
    if (plan->decoupled && r->status != COA_PLAN_SOLVED) {
        if (r->failed_vehicle >= n) {
            set_error(err, err_size, "internal error: no failed vehicle reported");
            return -2;
        }
        if (!add_number(root, "failed_vehicle", s->vehicles[r->failed_vehicle].id)) {
            return -1;
        }
    }
    if (r->status == COA_PLAN_SOLVED) {
        cJSON *cost = cJSON_AddObjectToObject(root, "cost");
        if (cost == NULL || !add_number(cost, "deviation", r->deviation) ||
            !add_number(cost, "effort", r->effort)) {
            return -1;
        }
    }
    return plan->decoupled ? 0 : build_bound(root, r);
}

/* The search statistics. 0, or -1 out of memory. */
static int build_stats(cJSON *root, const coavoid_output_plan_t *plan)
{
    const coa_plan_result_t *r = plan->result;
    cJSON *stats = cJSON_AddObjectToObject(root, "stats");
    if (stats == NULL || !add_number(stats, "nodes_expanded", (double)r->nodes_expanded) ||
        !add_number(stats, "nodes_generated", (double)r->nodes_generated) ||
        !add_number(stats, "time_us", (double)plan->time_us) ||
        !add_number(stats, "workspace_bytes", (double)r->workspace_bytes) ||
        !add_number(stats, "workspace_touched_bytes", (double)r->workspace_touched_bytes) ||
        !add_number(stats, "beta", plan->beta) || !add_number(stats, "work", (double)r->work) ||
        !add_number(stats, "work_budget", (double)plan->work_budget) ||
        cJSON_AddStringToObject(stats, "limit", limit_name(r->limit)) == NULL ||
        (plan->decoupled && !add_number(stats, "orders_tried", r->orders_tried))) {
        return -1;
    }
    /* Whether the failure, if any, holds for every order: with --max-orders an unsolved
     * result may only say that the orders tried failed. */
    if (plan->decoupled &&
        cJSON_AddBoolToObject(stats, "all_orders_covered", r->all_orders_covered) == NULL) {
        return -1;
    }
    return 0;
}

/* The vehicles with a plan: solved, everyone in input order; decoupled and not solved, those
 * planned before the failure, in planning order; centralised and not solved, nobody. 0, -1
 * out of memory, -2 an inconsistent result (err set). */
static int build_vehicles(cJSON *root, const coavoid_output_plan_t *plan, char *err,
                          size_t err_size)
{
    const coavoid_scenario_t *s = plan->scenario;
    const coa_plan_result_t *r = plan->result;
    const size_t n = s->vehicle_count;
    const bool solved = r->status == COA_PLAN_SOLVED;
    cJSON *vehicles = cJSON_AddArrayToObject(root, "vehicles");
    if (vehicles == NULL) {
        return -1;
    }
    size_t listed = solved ? n : (plan->decoupled ? r->planned_count : 0);
    if (listed > n) {
        set_error(err, err_size, "internal error: %zu planned vehicles of %zu", listed, n);
        return -2;
    }
    for (size_t j = 0; j < listed; j++) {
        size_t i = solved ? j : r->order[j];
        int rc = add_vehicle(vehicles, s, i, plan->offsets + i * ((size_t)s->horizon + 1u), err,
                             err_size);
        if (rc < 0) {
            return rc;
        }
    }
    return 0;
}

/* Builds the result object; NULL with err set on failure. */
static cJSON *build(const coavoid_output_plan_t *plan, char *err, size_t err_size)
{
    cJSON *root = cJSON_CreateObject();
    int rc = root == NULL ? -1 : build_head(root, plan, err, err_size);
    if (rc == 0) {
        rc = build_stats(root, plan);
    }
    if (rc == 0) {
        rc = build_vehicles(root, plan, err, err_size);
    }
    if (rc == 0) {
        return root;
    }
    if (rc == -1) {
        set_error(err, err_size, "out of memory printing the result");
    }
    cJSON_Delete(root);
    return NULL;
}

int coavoid_output_json(FILE *out, cJSON *root, char *err, size_t err_size)
{
    char *text = cJSON_Print(root);
    cJSON_Delete(root);
    if (text == NULL) {
        return set_error(err, err_size, "out of memory printing the result");
    }
    errno = 0;
    bool written = fputs(text, out) >= 0 && fputc('\n', out) != EOF && fflush(out) == 0;
    free(text);
    if (!written) {
        return set_error(err, err_size, "cannot write the result: %s",
                         errno != 0 ? strerror(errno) : "write error");
    }
    return 0;
}

int coavoid_output_plan(FILE *out, const coavoid_output_plan_t *plan, char *err, size_t err_size)
{
    cJSON *root = build(plan, err, err_size);
    if (root == NULL) {
        return -1;
    }
    return coavoid_output_json(out, root, err, err_size);
}

const char *coavoid_output_conflict_kind_name(coa_conflict_kind_t kind)
{
    switch (kind) {
    case COA_CONFLICT_VEHICLE:
        return "vehicle";
    case COA_CONFLICT_TRACK:
        return "track";
    case COA_CONFLICT_OBSTACLE:
        return "obstacle";
    }
    return "unknown";
}

static bool add_conflict(cJSON *array, const coavoid_output_conflict_t *c)
{
    cJSON *entry = cJSON_CreateObject();
    return coavoid_output_append(array, entry) &&
           cJSON_AddStringToObject(entry, "kind", coavoid_output_conflict_kind_name(c->kind)) !=
               NULL &&
           add_number(entry, "a", c->a) && add_number(entry, "b", c->b) &&
           add_number(entry, "first_step", c->first_step) &&
           add_number(entry, "probability", c->probability) &&
           add_number(entry, "first_time", c->first_time) &&
           add_number(entry, "min_horizontal", c->min_horizontal) &&
           add_number(entry, "min_vertical", c->min_vertical);
}

static cJSON *build_prediction(const coavoid_output_predict_t *p)
{
    cJSON *root = cJSON_CreateObject();
    if (root == NULL || cJSON_AddStringToObject(root, "scenario", p->scenario) == NULL) {
        goto fail;
    }
    cJSON *conflicts = cJSON_AddArrayToObject(root, "conflicts");
    if (conflicts == NULL) {
        goto fail;
    }
    for (size_t i = 0; i < p->conflict_count; i++) {
        if (!add_conflict(conflicts, &p->conflicts[i])) {
            goto fail;
        }
    }
    cJSON *clusters = cJSON_AddArrayToObject(root, "clusters");
    if (clusters == NULL) {
        goto fail;
    }
    for (size_t c = 0; c < p->cluster_count; c++) {
        cJSON *cluster = cJSON_CreateArray();
        if (!coavoid_output_append(clusters, cluster)) {
            goto fail;
        }
        for (size_t j = p->cluster_start[c]; j < p->cluster_start[c + 1]; j++) {
            if (!coavoid_output_append(cluster, cJSON_CreateNumber(p->cluster_ids[j]))) {
                goto fail;
            }
        }
    }
    return root;

fail:
    cJSON_Delete(root);
    return NULL;
}

int coavoid_output_predict(FILE *out, const coavoid_output_predict_t *prediction, char *err,
                           size_t err_size)
{
    cJSON *root = build_prediction(prediction);
    if (root == NULL) {
        return set_error(err, err_size, "out of memory printing the result");
    }
    return coavoid_output_json(out, root, err, err_size);
}
