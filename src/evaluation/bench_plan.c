/* SPDX-License-Identifier: MIT */
/*
 * bench_plan.c: the harness of `coavoid bench plan` (bench_plan.h): the sets of problems
 * (a scenario file, the random encounters), the timed runs and their report.
 */
#define _POSIX_C_SOURCE 200809L

#include "bench_plan.h"

#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include <cjson/cJSON.h>

#include "coavoid/coavoid.h"
#include "encounter.h"
#include "evaluation_internal.h"
#include "output.h"
#include "run.h"
#include "scenario.h"

/* ---- the sets ---- */

typedef struct {
    char label[COAVOID_BENCH_PLAN_LABEL_MAX]; /* "paper", "2 UAVs" */
    uint32_t vehicles;                        /* per problem (the paper: its own) */
    coavoid_scenario_t *problems;             /* sampled */
    uint32_t count;
} bp_set_t;

static void set_free(bp_set_t *set)
{
    for (uint32_t j = 0; set->problems != NULL && j < set->count; j++) {
        coavoid_scenario_free(&set->problems[j]);
    }
    free(set->problems);
    memset(set, 0, sizeof *set);
}

static int build_random_set(const coavoid_bench_plan_config_t *o, uint32_t n, bp_set_t *set,
                            coavoid_run_error_t *e)
{
    snprintf(set->label, sizeof set->label, "%u UAVs", n);
    set->vehicles = n;
    set->problems = calloc(o->count, sizeof *set->problems);
    if (set->problems == NULL) {
        return coavoid_run_fail(e, COAVOID_RUN_ERR_INPUT, "--count: out of memory for %lu problems",
                                (unsigned long)o->count);
    }
    for (uint32_t j = 0; j < o->count; j++) {
        char json[COAVOID_ENCOUNTER_JSON_MAX];
        char why[COAVOID_SCENARIO_ERROR_MAX];
        set->count = j + 1u; /* so set_free frees this one too */
        if (!coavoid_encounter_json(&coavoid_encounter_bench, o->seed, n, j, 0u, json, sizeof json,
                                    NULL)) {
            return coavoid_run_fail(e, COAVOID_RUN_ERR_INTERNAL,
                                    "internal error: encounter %u of %u UAVs does "
                                    "not fit %u bytes",
                                    j, n, COAVOID_ENCOUNTER_JSON_MAX);
        }
        if (o->save != NULL && coavoid_encounter_save(o->save, "bench", o->seed, n, j, json) != 0) {
            return coavoid_run_fail(e, COAVOID_RUN_ERR_INPUT,
                                    "--save: cannot write encounter %u of %u UAVs in '%.200s'", j,
                                    n, o->save);
        }
        if (coavoid_scenario_parse(json, strlen(json), &set->problems[j], why, sizeof why) != 0 ||
            coavoid_scenario_sample(&set->problems[j], why, sizeof why) != 0) {
            return coavoid_run_fail(e, COAVOID_RUN_ERR_INTERNAL,
                                    "internal error: encounter %u of %u UAVs: %s", j, n, why);
        }
    }
    return COAVOID_RUN_DONE;
}

/* The scenario file as the set "paper": loaded, sampled and refused as `coavoid plan`
 * would ("FILE: field: reason"). */
static int build_paper_set(const coavoid_bench_plan_config_t *o, bp_set_t *set,
                           coavoid_run_error_t *e)
{
    snprintf(set->label, sizeof set->label, "paper");
    set->problems = calloc(1u, sizeof *set->problems);
    if (set->problems == NULL) {
        return coavoid_run_fail(e, COAVOID_RUN_ERR_INPUT, "--scenario: out of memory");
    }
    set->count = 1u;
    char why[COAVOID_SCENARIO_ERROR_MAX];
    int status = COAVOID_RUN_DONE;
    if (coavoid_scenario_load(o->scenario, &set->problems[0], why, sizeof why) != 0 ||
        coavoid_scenario_sample(&set->problems[0], why, sizeof why) != 0) {
        status = coavoid_run_fail(e, COAVOID_RUN_ERR_INPUT, "%s: %s", o->scenario, why);
    }
    if (status == COAVOID_RUN_DONE && set->problems[0].vehicle_count > COA_MAX_CENTRALISED) {
        status = coavoid_run_fail(e, COAVOID_RUN_ERR_INPUT,
                                  "%s: %zu vehicles, at most %u can be planned "
                                  "centrally",
                                  o->scenario, set->problems[0].vehicle_count, COA_MAX_CENTRALISED);
    }
    set->vehicles = (uint32_t)set->problems[0].vehicle_count;
    return status;
}

/* ---- the runs ---- */

/* One planner for every problem of the set at beta `wanted`, lowered to
 * coavoid_default_beta where its workspace would pass COAVOID_DEFAULT_WORKSPACE_MAX (the
 * programs' sizing policy, scenario.h). */
static coa_planner_config_t set_planner(const bp_set_t *set, size_t searched, uint32_t wanted)
{
    coa_planner_config_t config =
        coavoid_scenario_planner_config(&set->problems[0], searched, wanted);
    for (uint32_t j = 1; j < set->count; j++) {
        coa_planner_config_t other =
            coavoid_scenario_planner_config(&set->problems[j], searched, wanted);
        coavoid_planner_config_widen(&config, &other);
    }
    if (!coavoid_workspace_fits(&config)) {
        config.beta = coavoid_default_beta(&config);
    }
    return config;
}

/* The tallies of one plan's result. ratios[] gets the plan's ratio to its bound. */
static void tally(const coa_plan_result_t *result, bool decoupled, coavoid_bench_plan_row_t *row,
                  double *ratios, size_t *ratio_count)
{
    row->nodes_expanded += result->nodes_expanded;
    row->nodes_generated += result->nodes_generated;
    row->work += result->work;
    if (result->workspace_touched_bytes > row->touched_bytes) {
        row->touched_bytes = result->workspace_touched_bytes;
    }
    row->solved += result->status == COA_PLAN_SOLVED;
    row->infeasible += result->status == COA_PLAN_INFEASIBLE;
    row->budget_exhausted += result->status == COA_PLAN_BUDGET_EXHAUSTED;
    if (decoupled || result->status != COA_PLAN_SOLVED) {
        return;
    }
    row->optimal += result->optimal;
    row->bounded += !result->optimal;
    if (result->bound_deviation > 0) {
        ratios[(*ratio_count)++] =
            coavoid_bound_ratio(result->optimal, result->deviation, result->bound_deviation);
    }
}

/* One run over the set: adds the time (ms), each problem's into problem_ms[], and fills
 * the tallies of row. */
static int run_once(coa_planner_t *planner, const bp_set_t *set, bool decoupled, uint64_t work,
                    int32_t *offsets, double *ms, double *problem_ms, coavoid_bench_plan_row_t *row,
                    coavoid_run_error_t *e)
{
    size_t ratio_count = 0;
    double *ratios = calloc(set->count, sizeof *ratios);
    if (ratios == NULL) {
        return coavoid_run_fail(e, COAVOID_RUN_ERR_INPUT, "%s: out of memory", set->label);
    }
    *ms = 0;
    row->nodes_expanded = row->nodes_generated = row->work = 0;
    row->solved = row->infeasible = row->budget_exhausted = row->optimal = row->bounded = 0;
    int status = COAVOID_RUN_DONE;
    for (uint32_t j = 0; status == COAVOID_RUN_DONE && j < set->count; j++) {
        coa_problem_t problem = coavoid_scenario_problem(&set->problems[j]);
        coa_plan_result_t result;
        memset(&result, 0, sizeof result);
        struct timespec start, end;
        (void)coa_planner_set_work(planner, work);
        clock_gettime(CLOCK_MONOTONIC, &start);
        int rc = decoupled ? coa_plan_decoupled(planner, &problem, NULL, 1u, offsets, &result)
                           : coa_plan_centralised(planner, &problem, offsets, &result);
        clock_gettime(CLOCK_MONOTONIC, &end);
        if (rc != COA_OK) {
            status = coavoid_run_fail(
                e, rc == COA_ERR_RANGE ? COAVOID_RUN_ERR_INPUT : COAVOID_RUN_ERR_INTERNAL,
                "%s, problem %u: the planner failed (%s)", set->label, j, coa_status_name(rc));
            break;
        }
        problem_ms[j] = coavoid_timing_elapsed_ms(&start, &end);
        *ms += problem_ms[j];
        tally(&result, decoupled, row, ratios, &ratio_count);
    }
    if (status == COAVOID_RUN_DONE && ratio_count > 0) {
        double lo = 0;
        coavoid_timing_summarise(ratios, (uint32_t)ratio_count, &row->ratio_median, &lo,
                                 &row->ratio_max);
    }
    free(ratios);
    return status;
}

/* Each problem's median time over the runs (times[k * count + j]: run k, problem j), and
 * their median and largest over the problems. */
static int problems_summarise(const double *times, uint32_t count, uint32_t repeat,
                              coavoid_bench_plan_row_t *row)
{
    double *each = calloc(count, sizeof *each);
    double *runs = calloc(repeat, sizeof *runs);
    if (each == NULL || runs == NULL) {
        free(each);
        free(runs);
        return -1;
    }
    for (uint32_t j = 0; j < count; j++) {
        double lo = 0;
        double hi = 0;
        for (uint32_t k = 0; k < repeat; k++) {
            runs[k] = times[(size_t)k * count + j];
        }
        coavoid_timing_summarise(runs, repeat, &each[j], &lo, &hi);
    }
    double lo = 0;
    coavoid_timing_summarise(each, count, &row->problem_median_ms, &lo, &row->problem_max_ms);
    free(each);
    free(runs);
    return 0;
}

static int run_set(const coavoid_bench_plan_config_t *o, const bp_set_t *set, bool decoupled,
                   coavoid_bench_plan_row_t *row, coavoid_run_error_t *e)
{
    memset(row, 0, sizeof *row);
    memcpy(row->set, set->label, sizeof row->set);
    row->decoupled = decoupled;
    row->vehicles = set->vehicles;
    row->problems = set->count;
    size_t searched = decoupled ? 1u : set->vehicles;
    uint32_t wanted = o->beta != 0                                    ? o->beta
                      : set->count == 1u && set->problems[0].has_beta ? set->problems[0].beta
                                                                      : COAVOID_DEFAULT_BETA;
    coa_planner_config_t config = set_planner(set, searched, wanted);
    row->beta_lowered = config.beta != wanted;
    row->beta = config.beta;
    size_t size = coa_planner_workspace_size(&config);
    void *workspace = size != 0 ? malloc(size) : NULL;
    int32_t *offsets = calloc((size_t)set->vehicles * (COA_MAX_HORIZON + 1u), sizeof *offsets);
    double *times = calloc(o->repeat, sizeof *times);
    double *problem_ms = calloc((size_t)o->repeat * set->count, sizeof *problem_ms);
    int status = COAVOID_RUN_DONE;
    coa_planner_t *planner = NULL;
    if (workspace == NULL || offsets == NULL || times == NULL || problem_ms == NULL) {
        status = coavoid_run_fail(e, COAVOID_RUN_ERR_INPUT,
                                  "%s: out of memory for %zu bytes of workspace", set->label, size);
    } else if ((planner = coa_planner_init(workspace, size, &config)) == NULL) {
        status = coavoid_run_fail(e, COAVOID_RUN_ERR_INTERNAL,
                                  "internal error: the planner refused its workspace");
    }
    row->workspace_bytes = size;
    coavoid_bench_plan_row_t first;
    memset(&first, 0, sizeof first);
    double ms = 0;
    if (status == COAVOID_RUN_DONE) { /* untimed: warms caches and the workspace's pages */
        first = *row;
        status = run_once(planner, set, decoupled, o->work, offsets, &ms, problem_ms, &first, e);
    }
    for (uint32_t k = 0; status == COAVOID_RUN_DONE && k < o->repeat; k++) {
        status = run_once(planner, set, decoupled, o->work, offsets, &times[k],
                          &problem_ms[(size_t)k * set->count], row, e);
        if (status == COAVOID_RUN_DONE &&
            (row->nodes_expanded != first.nodes_expanded ||
             row->nodes_generated != first.nodes_generated || row->solved != first.solved ||
             row->budget_exhausted != first.budget_exhausted || row->work != first.work ||
             row->optimal != first.optimal)) {
            status = coavoid_run_fail(e, COAVOID_RUN_ERR_INTERNAL,
                                      "internal error: %s, run %lu differs from the "
                                      "first",
                                      set->label, (unsigned long)k + 1u);
        }
    }
    if (status == COAVOID_RUN_DONE) {
        coavoid_timing_summarise(times, o->repeat, &row->median_ms, &row->min_ms, &row->max_ms);
        if (problems_summarise(problem_ms, set->count, o->repeat, row) != 0) {
            status = coavoid_run_fail(e, COAVOID_RUN_ERR_INPUT, "%s: out of memory", set->label);
        }
    }
    free(problem_ms);
    free(times);
    free(offsets);
    free(workspace);
    return status;
}

/* ---- the report ---- */

static double nodes_per_s(const coavoid_bench_plan_row_t *row)
{
    return row->median_ms > 0 ? (double)row->nodes_expanded / (row->median_ms * 1e-3) : 0.0;
}

static int report_text(FILE *f, const coavoid_bench_plan_config_t *o,
                       const coavoid_bench_plan_row_t *rows, size_t count)
{
    fprintf(f, "benchmark: plan\nseed: %llu\nrepeat: %lu\ncount: %lu\nwork: %llu\n",
            (unsigned long long)o->seed, (unsigned long)o->repeat, (unsigned long)o->count,
            (unsigned long long)o->work);
    fprintf(f,
            "%-7s %-11s %8s %6s %7s %7s %10s %6s %5s %6s %10s %10s %10s %9s %9s %7s %14s %12s %12s "
            "%15s %13s\n",
            "set", "mode", "problems", "solved", "optimal", "bounded", "infeasible", "budget",
            "uavs", "beta", "median_ms", "min_ms", "max_ms", "prob_med", "prob_max", "ratio",
            "nodes_expanded", "nodes_per_s", "work", "workspace_bytes", "touched_bytes");
    for (size_t i = 0; i < count; i++) {
        const coavoid_bench_plan_row_t *r = &rows[i];
        fprintf(f,
                "%-7s %-11s %8lu %6lu %7lu %7lu %10lu %6lu %5lu %5lu%s %10.3f %10.3f %10.3f %9.3f "
                "%9.3f "
                "%7.3f %14llu %12.0f %12llu %15zu %13zu\n",
                r->set, r->decoupled ? "decoupled" : "centralised", (unsigned long)r->problems,
                (unsigned long)r->solved, (unsigned long)r->optimal, (unsigned long)r->bounded,
                (unsigned long)r->infeasible, (unsigned long)r->budget_exhausted,
                (unsigned long)r->vehicles, (unsigned long)r->beta, r->beta_lowered ? "*" : " ",
                r->median_ms, r->min_ms, r->max_ms, r->problem_median_ms, r->problem_max_ms,
                r->ratio_median, (unsigned long long)r->nodes_expanded, nodes_per_s(r),
                (unsigned long long)r->work, r->workspace_bytes, r->touched_bytes);
    }
    fprintf(f, "times: per run over the set's problems; prob_med, prob_max: per problem (its "
               "median over the runs); budget: no plan found within beta or the work budget; "
               "optimal, bounded: centralised plans proven optimal or not; ratio: the median "
               "centralised plan's deviation over its lower bound; touched_bytes: of the "
               "workspace, the most one problem's call wrote; beta*: lowered to keep the "
               "workspace within 1 GiB\n");
    return fflush(f) == 0 && !ferror(f) ? 0 : -1;
}

static int report_json(FILE *f, const coavoid_bench_plan_config_t *o,
                       const coavoid_bench_plan_row_t *rows, size_t count)
{
    char seed[32];
    snprintf(seed, sizeof seed, "%llu", (unsigned long long)o->seed);
    cJSON *root = cJSON_CreateObject();
    cJSON *list = NULL;
    /* A raw number keeps every digit of a 64-bit seed. */
    bool ok = root != NULL && cJSON_AddStringToObject(root, "benchmark", "plan") != NULL &&
              cJSON_AddRawToObject(root, "seed", seed) != NULL &&
              cJSON_AddNumberToObject(root, "repeat", o->repeat) != NULL &&
              cJSON_AddNumberToObject(root, "count", o->count) != NULL &&
              cJSON_AddNumberToObject(root, "work", (double)o->work) != NULL &&
              (list = cJSON_AddArrayToObject(root, "results")) != NULL;
    for (size_t i = 0; ok && i < count; i++) {
        const coavoid_bench_plan_row_t *r = &rows[i];
        cJSON *row = cJSON_CreateObject();
        ok = row != NULL && cJSON_AddItemToArray(list, row);
        ok = ok && cJSON_AddStringToObject(row, "set", r->set) != NULL &&
             cJSON_AddStringToObject(row, "mode", r->decoupled ? "decoupled" : "centralised") !=
                 NULL &&
             cJSON_AddNumberToObject(row, "vehicles", r->vehicles) != NULL &&
             cJSON_AddNumberToObject(row, "problems", r->problems) != NULL &&
             cJSON_AddNumberToObject(row, "beta", r->beta) != NULL &&
             cJSON_AddBoolToObject(row, "beta_lowered", r->beta_lowered) != NULL &&
             cJSON_AddNumberToObject(row, "median_ms", r->median_ms) != NULL &&
             cJSON_AddNumberToObject(row, "min_ms", r->min_ms) != NULL &&
             cJSON_AddNumberToObject(row, "max_ms", r->max_ms) != NULL &&
             cJSON_AddNumberToObject(row, "nodes_expanded", (double)r->nodes_expanded) != NULL &&
             cJSON_AddNumberToObject(row, "nodes_generated", (double)r->nodes_generated) != NULL &&
             cJSON_AddNumberToObject(row, "nodes_per_s", nodes_per_s(r)) != NULL &&
             cJSON_AddNumberToObject(row, "workspace_bytes", (double)r->workspace_bytes) != NULL &&
             cJSON_AddNumberToObject(row, "touched_bytes", (double)r->touched_bytes) != NULL &&
             cJSON_AddNumberToObject(row, "solved", r->solved) != NULL &&
             cJSON_AddNumberToObject(row, "infeasible", r->infeasible) != NULL &&
             cJSON_AddNumberToObject(row, "budget_exhausted", r->budget_exhausted) != NULL &&
             cJSON_AddNumberToObject(row, "optimal", r->optimal) != NULL &&
             cJSON_AddNumberToObject(row, "bounded", r->bounded) != NULL &&
             cJSON_AddNumberToObject(row, "problem_median_ms", r->problem_median_ms) != NULL &&
             cJSON_AddNumberToObject(row, "problem_max_ms", r->problem_max_ms) != NULL &&
             cJSON_AddNumberToObject(row, "ratio_median", r->ratio_median) != NULL &&
             cJSON_AddNumberToObject(row, "ratio_max", r->ratio_max) != NULL &&
             cJSON_AddNumberToObject(row, "work", (double)r->work) != NULL;
    }
    if (!ok) {
        cJSON_Delete(root);
        return -1;
    }
    return coavoid_output_json(f, root, NULL, 0);
}

int coavoid_bench_plan_report(FILE *f, const coavoid_bench_plan_config_t *config,
                              const coavoid_bench_plan_result_t *result, bool json)
{
    return json ? report_json(f, config, result->rows, result->row_count)
                : report_text(f, config, result->rows, result->row_count);
}

/* Every set, loaded or drawn before anything is timed: the scenario's, then one per UAV
 * count. *set_count counts the sets begun, which set_free must free. */
static int build_sets(const coavoid_bench_plan_config_t *o, bp_set_t *sets, size_t *set_count,
                      coavoid_run_error_t *e)
{
    int status = COAVOID_RUN_DONE;
    if (o->scenario != NULL) {
        status = build_paper_set(o, &sets[(*set_count)++], e);
    }
    for (uint32_t n = o->min_vehicles; status == COAVOID_RUN_DONE && n <= o->max_vehicles; n++) {
        status = build_random_set(o, n, &sets[(*set_count)++], e);
    }
    return status;
}

int coavoid_bench_plan_run(const coavoid_bench_plan_config_t *config,
                           coavoid_bench_plan_result_t *out, coavoid_run_error_t *e)
{
    memset(out, 0, sizeof *out);
    if (config->count == 0 || config->repeat == 0 ||
        config->min_vehicles < COAVOID_ENCOUNTER_MIN_VEHICLES ||
        config->max_vehicles > COAVOID_ENCOUNTER_MAX_VEHICLES) {
        return coavoid_run_fail(e, COAVOID_RUN_ERR_INPUT,
                                "bench plan: --count, --repeat or --vehicles out of range");
    }
    bp_set_t sets[COAVOID_BENCH_PLAN_MAX_SETS];
    memset(sets, 0, sizeof sets);
    size_t set_count = 0;
    int status = build_sets(config, sets, &set_count, e);
    for (size_t i = 0; status == COAVOID_RUN_DONE && i < set_count; i++) {
        for (int mode = 0; status == COAVOID_RUN_DONE && mode < 2; mode++) {
            status = run_set(config, &sets[i], mode == 1, &out->rows[out->row_count++], e);
        }
    }
    for (size_t i = 0; i < set_count; i++) {
        set_free(&sets[i]);
    }
    return status;
}
