/* SPDX-License-Identifier: MIT */
/*
 * A scenario's conflicts predicted and its prediction result written (run.h,
 * coavoid_scenario_predict).
 *
 * A scenario has no published plans, so each UAV's plan is taken to be its reference at
 * its initial_offset, sampled on the scenario's own grid (t0 = 0, step dt, N+1 samples):
 * the predictor's alignment is then the identity and the answer is exactly the planner's
 * view of "no manoeuvre".
 */
#include <math.h>
#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "coavoid/coavoid.h"
#include "coavoid/predict.h"
#include "output.h"
#include "run.h"
#include "scenario.h"

/* a * b + c without wrapping; false when it would. */
static bool size_mul_add(size_t a, size_t b, size_t c, size_t *out)
{
    if (b != 0 && a > (SIZE_MAX - c) / b) {
        return false;
    }
    *out = a * b + c;
    return true;
}

static int compare_conflicts(const void *pa, const void *pb)
{
    const coavoid_output_conflict_t *a = pa;
    const coavoid_output_conflict_t *b = pb;
    if (a->kind != b->kind) {
        return a->kind < b->kind ? -1 : 1;
    }
    if (a->a != b->a) {
        return a->a < b->a ? -1 : 1;
    }
    if (a->b != b->b) {
        return a->b < b->b ? -1 : 1;
    }
    return 0;
}

/* The core's conflicts (plan, track and obstacle indices) in the contract's terms (ids),
 * sorted by kind, a, b. Returns false when the core named an index out of range. */
static bool map_conflicts(const coavoid_scenario_t *s, const coa_conflict_t *in, size_t count,
                          coavoid_output_conflict_t *out)
{
    for (size_t i = 0; i < count; i++) {
        const coa_conflict_t *c = &in[i];
        coavoid_output_conflict_t *o = &out[i];
        if (c->a >= s->vehicle_count) {
            return false;
        }
        o->kind = c->kind;
        o->a = s->vehicles[c->a].id;
        switch (c->kind) {
        case COA_CONFLICT_VEHICLE: {
            if (c->b >= s->vehicle_count || c->b == c->a) {
                return false;
            }
            /* The core orders by index; the contract by id. */
            uint32_t other = s->vehicles[c->b].id;
            o->b = other > o->a ? other : o->a;
            o->a = other > o->a ? o->a : other;
            break;
        }
        case COA_CONFLICT_TRACK:
            if (c->b >= s->track_count) {
                return false;
            }
            o->b = s->tracks[c->b].id;
            break;
        case COA_CONFLICT_OBSTACLE:
            if (c->b >= s->obstacle_count) {
                return false;
            }
            o->b = c->b;
            break;
        default:
            return false;
        }
        o->first_step = c->first_step;
        o->first_time = (double)c->first_time;
        o->min_horizontal = (double)c->min_horizontal;
        o->min_vertical = (double)c->min_vertical;
        o->probability = c->probability;
    }
    qsort(out, count, sizeof *out, compare_conflicts);
    return true;
}

typedef struct {
    uint32_t id;
    uint32_t label;
} labelled_t;

static int compare_labelled(const void *pa, const void *pb)
{
    const labelled_t *a = pa;
    const labelled_t *b = pb;
    return a->id < b->id ? -1 : (a->id > b->id ? 1 : 0);
}

/* The core's cluster labels (by plan index, clusters numbered by smallest plan index) as
 * the contract's clusters: ids ascending within each, clusters by their smallest id.
 * `ids` and `start` have room for n and n + 1 entries; `scratch` for n. Returns false
 * when a label is out of range or names no UAV, or out of memory. */
static bool build_clusters(const coavoid_scenario_t *s, const uint32_t *label, size_t label_count,
                           labelled_t *scratch, uint32_t *ids, size_t *start, size_t *cluster_count)
{
    const size_t n = s->vehicle_count;
    size_t clustered = 0;
    for (size_t i = 0; i < n; i++) {
        if (label[i] == COA_NO_CLUSTER) {
            continue;
        }
        if (label[i] >= label_count) {
            return false;
        }
        scratch[clustered].id = s->vehicles[i].id;
        scratch[clustered].label = label[i];
        clustered++;
    }
    qsort(scratch, clustered, sizeof *scratch, compare_labelled);
    /* Walking the ids in ascending order meets each cluster first at its smallest id:
     * that is the contract's order of clusters. rank maps a core label to it. */
    size_t *rank = calloc(label_count + 1u, sizeof *rank);
    size_t *size = calloc(label_count + 1u, sizeof *size);
    if (rank == NULL || size == NULL) {
        free(rank);
        free(size);
        return false;
    }
    for (size_t c = 0; c < label_count; c++) {
        rank[c] = SIZE_MAX;
    }
    size_t ranked = 0;
    for (size_t j = 0; j < clustered; j++) {
        if (rank[scratch[j].label] == SIZE_MAX) {
            rank[scratch[j].label] = ranked++;
        }
        scratch[j].label = (uint32_t)rank[scratch[j].label];
        size[scratch[j].label]++;
    }
    free(rank);
    bool ok = ranked == label_count; /* every label the core counted has a member */
    start[0] = 0;
    for (size_t c = 0; c < label_count; c++) {
        start[c + 1] = start[c] + size[c];
    }
    /* Placing members in id order keeps every cluster ascending. */
    for (size_t c = 0; c <= label_count; c++) {
        size[c] = 0;
    }
    for (size_t j = 0; j < clustered; j++) {
        size_t c = scratch[j].label;
        ids[start[c] + size[c]++] = scratch[j].id;
    }
    free(size);
    *cluster_count = label_count;
    return ok;
}

typedef struct {
    coa_vec3_t *samples;
    coa_intent_plan_t *plans;
    void *workspace;
    coa_conflict_t *conflicts;
    coavoid_output_conflict_t *listed;
    uint32_t *label;
    labelled_t *scratch;
    uint32_t *cluster_ids;
    size_t *cluster_start;
    size_t size;      /* workspace bytes */
    size_t max_pairs; /* candidate pairs the predictor is sized for; the conflicts' room */
} predict_memory_t;

static void predict_memory_free(predict_memory_t *m)
{
    free(m->samples);
    free(m->plans);
    free(m->workspace);
    free(m->conflicts);
    free(m->listed);
    free(m->label);
    free(m->scratch);
    free(m->cluster_ids);
    free(m->cluster_start);
}

/* Each UAV's plan: its sampled reference raised by initial_offset climb steps. Returns 0,
 * or an error with e set. */
static int build_plans(coavoid_run_error_t *e, const char *file, const coavoid_scenario_t *s,
                       predict_memory_t *m)
{
    const size_t per_row = (size_t)s->horizon + 1u;
    for (size_t i = 0; i < s->vehicle_count; i++) {
        const coa_vehicle_t *v = &s->vehicles[i];
        const coa_real_t lift = (coa_real_t)v->initial_offset * coa_climb_step(v, s->dt);
        coa_vec3_t *row = m->samples + i * per_row;
        for (size_t k = 0; k < per_row; k++) {
            row[k] = s->references[i][k];
            row[k].z += lift;
            if (!isfinite(row[k].z)) {
                return coavoid_run_fail(
                    e, COAVOID_RUN_ERR_INPUT,
                    "%s: vehicles[%zu]: initial_offset: the altitude it gives is "
                    "not finite",
                    file, i);
            }
        }
        coa_intent_plan_t *p = &m->plans[i];
        p->id = v->id;
        p->volume = v->volume;
        p->t0 = 0;
        p->step = s->dt;
        p->samples = row;
        p->count = per_row;
        p->sigma_horizontal = 0;
        p->sigma_vertical = 0;
    }
    return 0;
}

/* Sizes and allocates everything a prediction of the scenario needs. Every pair (UAV-UAV,
 * UAV-track and UAV-obstacle) may be a candidate and may conflict: a scenario is small
 * enough to size for that, so neither the pair set nor the conflict array can run out.
 * Returns 0, or an error with e set. */
static int predict_allocate(coavoid_run_error_t *e, const char *file, const coavoid_scenario_t *s,
                            predict_memory_t *m)
{
    const size_t n = s->vehicle_count;
    size_t vehicle_pairs = n * (n - 1u) / 2u; /* n <= COA_MAX_VEHICLES */
    size_t with_tracks;
    if (!size_mul_add(n, s->track_count, vehicle_pairs, &with_tracks) ||
        !size_mul_add(n, s->obstacle_count, with_tracks, &m->max_pairs)) {
        return coavoid_run_fail(e, COAVOID_RUN_ERR_INPUT,
                                "%s: too many tracks and obstacles to size for", file);
    }
    if (m->max_pairs == 0) {
        m->max_pairs = 1; /* one UAV alone: the size function refuses a limit of 0 */
    }
    m->size = coa_predictor_workspace_size(n, s->track_count, s->horizon, m->max_pairs);
    if (m->size == 0) {
        return coavoid_run_fail(
            e, COAVOID_RUN_ERR_INPUT,
            "%s: too large: the predictor's workspace for %zu vehicles, %zu tracks, "
            "%zu obstacles and %lu steps is beyond its limits",
            file, n, s->track_count, s->obstacle_count, (unsigned long)s->horizon);
    }
    m->samples = calloc(n * ((size_t)s->horizon + 1u), sizeof *m->samples);
    m->plans = calloc(n, sizeof *m->plans);
    m->workspace = malloc(m->size);
    m->conflicts = calloc(m->max_pairs, sizeof *m->conflicts);
    m->listed = calloc(m->max_pairs, sizeof *m->listed);
    m->label = calloc(n, sizeof *m->label);
    m->scratch = calloc(n, sizeof *m->scratch);
    m->cluster_ids = calloc(n, sizeof *m->cluster_ids);
    m->cluster_start = calloc(n + 1u, sizeof *m->cluster_start);
    if (m->samples == NULL || m->plans == NULL || m->workspace == NULL || m->conflicts == NULL ||
        m->listed == NULL || m->label == NULL || m->scratch == NULL || m->cluster_ids == NULL ||
        m->cluster_start == NULL) {
        return coavoid_run_fail(e, COAVOID_RUN_ERR_INPUT,
                                "%s: cannot allocate %zu bytes of predictor workspace and %zu "
                                "conflicts",
                                file, m->size, m->max_pairs);
    }
    return build_plans(e, file, s, m);
}

/* Clusters the conflicts found and writes the prediction result; COAVOID_RUN_DONE, or an
 * error with e set. */
static int predict_report(const coavoid_scenario_t *s, predict_memory_t *m,
                          const coa_predict_result_t *result, FILE *out, coavoid_run_error_t *e)
{
    const size_t n = s->vehicle_count;
    size_t cluster_labels = 0;
    char err[COAVOID_SCENARIO_ERROR_MAX];
    if (coa_predict_clusters(m->conflicts, result->conflict_count, n, m->label, &cluster_labels) !=
            COA_OK ||
        cluster_labels > n) {
        return coavoid_run_fail(e, COAVOID_RUN_ERR_INTERNAL,
                                "internal error: the conflicts do not cluster");
    }
    if (!map_conflicts(s, m->conflicts, result->conflict_count, m->listed)) {
        return coavoid_run_fail(e, COAVOID_RUN_ERR_INTERNAL,
                                "internal error: the predictor named a vehicle, track or obstacle "
                                "out of range");
    }
    coavoid_output_predict_t view;
    memset(&view, 0, sizeof view);
    view.scenario = s->name;
    view.conflicts = m->listed;
    view.conflict_count = result->conflict_count;
    view.cluster_ids = m->cluster_ids;
    view.cluster_start = m->cluster_start;
    if (!build_clusters(s, m->label, cluster_labels, m->scratch, m->cluster_ids, m->cluster_start,
                        &view.cluster_count)) {
        return coavoid_run_fail(e, COAVOID_RUN_ERR_INTERNAL, "internal error: bad cluster labels");
    }
    if (coavoid_output_predict(out, &view, err, sizeof err) != 0) {
        return coavoid_run_fail(e, COAVOID_RUN_ERR_INTERNAL, "%s", err);
    }
    return COAVOID_RUN_DONE;
}

/* One coa_predict over the scenario's reference plans; its result checked. Returns 0, or
 * an error with e set. */
static int predict_once(const coavoid_predict_config_t *c, const coavoid_scenario_t *s,
                        predict_memory_t *m, coa_predict_result_t *result, coavoid_run_error_t *e)
{
    const char *file = c->scenario_path;
    coa_predictor_t *predictor = coa_predictor_init(m->workspace, m->size, s->vehicle_count,
                                                    s->track_count, s->horizon, m->max_pairs);
    if (predictor == NULL) {
        return coavoid_run_fail(e, COAVOID_RUN_ERR_INTERNAL,
                                "internal error: the predictor refused its workspace");
    }
    coa_predict_config_t config;
    memset(&config, 0, sizeof config);
    config.t0 = 0;
    config.dt = s->dt;
    config.horizon = s->horizon;
    config.track_sigma_rate_horizontal = (coa_real_t)c->growth_horizontal;
    config.track_sigma_rate_vertical = (coa_real_t)c->growth_vertical;
    config.threshold = c->threshold;
    config.all_pairs = false;
    memset(result, 0, sizeof *result);
    int rc =
        coa_predict(predictor, &config, m->plans, s->vehicle_count, s->obstacles, s->obstacle_count,
                    s->tracks, s->track_count, m->conflicts, m->max_pairs, result);
    if (rc == COA_ERR_ARGUMENT) {
        /* The loader checked every field the contract defines; what is left is a
         * combination the core refuses (like plan's problem check). */
        return coavoid_run_fail(e, COAVOID_RUN_ERR_INPUT,
                                "%s: rejected by the core's predictor (%s)", file,
                                coa_status_name(rc));
    }
    if (rc != COA_OK) {
        return coavoid_run_fail(e, COAVOID_RUN_ERR_INTERNAL,
                                "internal error: the predictor failed (%s)", coa_status_name(rc));
    }
    if (result->overflow || result->conflict_count > m->max_pairs ||
        result->conflicts_found != result->conflict_count) {
        return coavoid_run_fail(e, COAVOID_RUN_ERR_INTERNAL,
                                "internal error: the predictor found %zu conflicts, room for %zu",
                                result->conflicts_found, m->max_pairs);
    }
    return 0;
}

int coavoid_scenario_predict(const coavoid_predict_config_t *c, coavoid_scenario_t *s, FILE *out,
                             coavoid_run_error_t *e)
{
    const char *file = c->scenario_path;
    char err[COAVOID_SCENARIO_ERROR_MAX];
    e->text[0] = '\0';
    if (coavoid_scenario_sample(s, err, sizeof err) != 0) {
        return coavoid_run_fail(e, COAVOID_RUN_ERR_INPUT, "%s: %s", file, err);
    }
    predict_memory_t m;
    memset(&m, 0, sizeof m);
    coa_predict_result_t result;
    int status = predict_allocate(e, file, s, &m);
    if (status == 0) {
        status = predict_once(c, s, &m, &result, e);
    }
    if (status == 0) {
        status = predict_report(s, &m, &result, out, e);
    }
    predict_memory_free(&m);
    return status;
}
