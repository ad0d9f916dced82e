/* SPDX-License-Identifier: MIT */
/*
 * output.h: the result objects of docs/scenario-format.md ("Plan result", "Prediction result"),
 * printed as JSON.
 */
#ifndef COAVOID_SCENARIO_OUTPUT_H
#define COAVOID_SCENARIO_OUTPUT_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

#include <cjson/cJSON.h>

#include "coavoid/coavoid.h"
#include "coavoid/predict.h"
#include "scenario.h"

typedef struct {
    const coavoid_scenario_t *scenario;
    bool decoupled; /* mode: decoupled, else centralised */
    const coa_plan_result_t *result;
    const int32_t *offsets; /* vehicle_count rows of horizon+1, row i is vehicle i */
    int64_t time_us;        /* wall time of the planning call */
    uint32_t beta;          /* the closed-set bound the planner ran with */
    uint64_t work_budget;   /* the work budget it ran with (0: none) */
} coavoid_output_plan_t;

/* Writes the result object (and a newline) to `out`. Returns 0, or -1 with the reason in
 * err: out of memory, a write error, or a result the core should never produce (a step
 * that is no action, a failed vehicle index out of range). */
int coavoid_output_plan(FILE *out, const coavoid_output_plan_t *plan, char *err, size_t err_size);

/* The contract's name of a plan status ("solved", "infeasible", "budget_exhausted"). */
const char *coavoid_output_status_name(coa_plan_status_t status);

/* One entry of the prediction result's "conflicts", already in the contract's terms. */
typedef struct {
    coa_conflict_kind_t kind;
    uint32_t a; /* UAV id */
    uint32_t b; /* the other UAV's id (a < b), the track's id or the obstacle's index */
    uint32_t first_step;
    double first_time;     /* s, t of first_step */
    double min_horizontal; /* m, as coa_conflict_t */
    double min_vertical;   /* m */
    double probability;
} coavoid_output_conflict_t;

typedef struct {
    const char *scenario;                       /* the scenario's name */
    const coavoid_output_conflict_t *conflicts; /* in the order to print */
    size_t conflict_count;
    const uint32_t *cluster_ids; /* the clusters' UAV ids, one cluster after another */
    const size_t *cluster_start; /* cluster c is cluster_ids[cluster_start[c] ..
                                            cluster_start[c + 1] - 1]: cluster_count + 1 entries */
    size_t cluster_count;
} coavoid_output_predict_t;

/* Writes the prediction result object (and a newline) to `out`. Returns 0, or -1 with the
 * reason in err (out of memory, a write error). */
int coavoid_output_predict(FILE *out, const coavoid_output_predict_t *prediction, char *err,
                           size_t err_size);

/* The contract's name of a conflict kind ("vehicle", "track", "obstacle"). */
const char *coavoid_output_conflict_kind_name(coa_conflict_kind_t kind);

/* Adds `item` to `array`; an item that is NULL (a failed cJSON_Create*) or cannot be added
 * is deleted and false returned, so a builder can chain creations without leaking. */
bool coavoid_output_append(cJSON *array, cJSON *item);

/* Prints `root` (cJSON's indented form) and a newline to `out`, flushes, and deletes root
 * whatever happens: every JSON report of the commands ends here. Returns 0, or -1 with the
 * reason in err (out of memory, a write error and its errno text); err may be NULL with
 * err_size 0 when the caller words its own message. */
int coavoid_output_json(FILE *out, cJSON *root, char *err, size_t err_size);

#endif /* COAVOID_SCENARIO_OUTPUT_H */
