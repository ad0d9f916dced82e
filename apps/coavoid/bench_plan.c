/* SPDX-License-Identifier: MIT */
/*
 * coavoid bench plan: times the core's planner (coa_plan_centralised and
 * coa_plan_decoupled) on the paper scenario and on seeded random encounters of 2 to 5 UAVs.
 * See BENCH_PLAN_USAGE below and docs/benchmarks.md ("Planning").
 *
 * The encounters. n UAVs converge on one point: their headings are spread evenly around it
 * (plus up to 0.3 rad of jitter), each at 8-12 m/s, arriving 8-12 s into a 20-step horizon
 * (dt 1 s), so every pair's paths cross near the point at about the same time. Altitudes are
 * staggered on a 2 m grid within 3 steps of 100 m (climb rates 1.5-3 m/s, so within a few
 * climb steps): against 10 m of combined half-heights most pairs conflict unless someone
 * moves, and some pairs already clear each other. Half the encounters have a terrain box
 * under the point whose top is 4 m below the lowest UAV's volume, so diving is limited
 * there. The problems (encounter.h, design coavoid_encounter_bench, shared with coavoid
 * montecarlo) are written as scenario JSON and go through the scenario loader, so they are
 * checked like any file.
 *
 * Everything comes from our own PRNG (splitmix64) seeded by --seed, so a seed gives the
 * same problems on every machine with the same libm (headings use cos and sin); only the
 * times differ.
 *
 * What is timed: the planning call alone (clock_gettime around it). One run plans every
 * problem of a set once; a set's time is the sum over its problems, reported as the
 * median, min and max over --repeat runs. Each (set, mode) gets one planner workspace,
 * allocated and initialised outside the timing and reused by every problem and run, as a
 * deployment would. One untimed run first warms caches and the workspace's pages; every
 * timed run must repeat its results exactly.
 */
#define _POSIX_C_SOURCE 200809L

#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include <cjson/cJSON.h>

#include "bench_support.h"
#include "cli.h"
#include "coavoid/coavoid.h"
#include "commands.h"
#include "encounter.h"
#include "output.h"
#include "scenario.h"

#define BP_DEFAULT_SEED 1u
#define BP_DEFAULT_REPEAT 5u
#define BP_DEFAULT_COUNT 5u
#define BP_MAX_REPEAT 10000u
#define BP_MAX_COUNT 10000u
#define BP_MIN_VEHICLES ENCOUNTER_MIN_VEHICLES
#define BP_MAX_VEHICLES ENCOUNTER_MAX_VEHICLES
/* Without --vehicles a run times the sets up to 5 UAVs; 6 only on request, since one
 * 6-UAV set takes minutes where the others take seconds (docs/benchmarks.md). */
#define BP_DEFAULT_MAX_VEHICLES 5u
_Static_assert(BP_MIN_VEHICLES == 2u && BP_MAX_VEHICLES == 6u, "--vehicles' hint says 2 to 6");
#define BP_DEFAULT_SCENARIO "scenarios/paper.json"
#define BP_HORIZON coavoid_encounter_bench.horizon
#define BP_DT coavoid_encounter_bench.dt
#define BP_SET_MAX (1u + BP_MAX_VEHICLES - BP_MIN_VEHICLES + 1u)

#define BENCH_PLAN_USAGE                                                                    \
    "usage: coavoid bench plan [--vehicles N] [--count C] [--seed S] [--repeat R]\n"        \
    "                          [--beta B] [--scenario FILE] [--json]\n"                     \
    "\n"                                                                                    \
    "Times the planner, centralised and decoupled, on the paper scenario and on C random\n" \
    "encounters each of 2, 3, 4 and 5 UAVs (6 with --vehicles 6) converging on one point\n" \
    "(staggered altitudes, half with a terrain box; %u steps of %g s), or on the N-UAV\n"   \
    "encounters only with --vehicles. One run plans every problem of a set once; prints\n"  \
    "per set and mode the median, min and max run time over R runs, the nodes expanded,\n"  \
    "nodes per second, the workspace and the outcomes (a table, or a JSON object with\n"    \
    "--json).\n"                                                                            \
    "See docs/benchmarks.md.\n"                                                             \
    "\n"                                                                                    \
    "options:\n"                                                                            \
    "  --vehicles N     only the random encounters of N UAVs, %u..%u\n"                     \
    "  --count C        random encounters per UAV count, 1..%u; default %u\n"               \
    "  --seed S         the encounters' random seed, an integer >= 0; default %u\n"         \
    "  --repeat R       timed runs, 1..%u; default %u\n"                                    \
    "  --beta B         closed-set bound, B >= 1; default the scenario's, else %u;\n"       \
    "                   either way lowered where the workspace would pass 1 GiB\n"          \
    "  --scenario FILE  the scenario timed as 'paper' (without --vehicles);\n"              \
    "                   default %s, relative to the working directory\n"                    \
    "  --json           print a JSON object instead of a table\n"                           \
    "  -h, --help       show this help\n"                                                   \
    "\n"                                                                                    \
    "A benchmark is deterministic for a seed except for its times.\n"                       \
    "\n"                                                                                    \
    "exit status: 0 done (whatever the plans' outcomes), 2 invalid usage or input (one\n"   \
    "line on stderr naming the option and why), 3 internal error\n"

static void bench_plan_help(void)
{
    printf(BENCH_PLAN_USAGE, BP_HORIZON, BP_DT, BP_MIN_VEHICLES, BP_MAX_VEHICLES, BP_MAX_COUNT,
           BP_DEFAULT_COUNT, BP_DEFAULT_SEED, BP_MAX_REPEAT, BP_DEFAULT_REPEAT, CLI_DEFAULT_BETA,
           BP_DEFAULT_SCENARIO);
}

typedef struct {
    const char *vehicles_text;
    uint32_t vehicles;
    const char *count_text;
    uint32_t count;
    const char *seed_text;
    uint64_t seed;
    const char *repeat_text;
    uint32_t repeat;
    const char *beta_text;
    uint32_t beta;
    const char *scenario;
    bool json;
} bp_options_t;

static int bp_option(int argc, char **argv, int *i, void *options)
{
    bp_options_t *o = options;
    const char *arg = argv[*i];
    uint64_t value = 0;
    int status = CLI_UNKNOWN_OPTION;
    if (coavoid_cli_option_is(arg, "--vehicles")) {
        /* 2..6, which coavoid_cli_count_option (1..max) cannot say. */
        status = coavoid_cli_text_option(argc, argv, i, "--vehicles", "an integer from 2 to 6",
                                         true, &o->vehicles_text);
        if (status == CLI_CONTINUE &&
            (!coavoid_cli_parse_count(o->vehicles_text, strlen(o->vehicles_text), BP_MAX_VEHICLES,
                                      &value) ||
             value < BP_MIN_VEHICLES)) {
            status = coavoid_cli_fail(CLI_EXIT_INVALID,
                                      "--vehicles: must be an integer from %u to %u, "
                                      "got '%.40s'",
                                      BP_MIN_VEHICLES, BP_MAX_VEHICLES, o->vehicles_text);
        }
        o->vehicles = (uint32_t)value;
    } else if (coavoid_cli_option_is(arg, "--count")) {
        status = coavoid_cli_count_option(argc, argv, i, "--count", NULL, false, BP_MAX_COUNT,
                                          &o->count_text, &value);
        o->count = (uint32_t)value;
    } else if (coavoid_cli_option_is(arg, "--seed")) {
        status = coavoid_cli_count_option(argc, argv, i, "--seed", NULL, true, UINT64_MAX,
                                          &o->seed_text, &value);
        o->seed = value;
    } else if (coavoid_cli_option_is(arg, "--repeat")) {
        status = coavoid_cli_count_option(argc, argv, i, "--repeat", NULL, false, BP_MAX_REPEAT,
                                          &o->repeat_text, &value);
        o->repeat = (uint32_t)value;
    } else if (coavoid_cli_option_is(arg, "--beta")) {
        status = coavoid_cli_count_option(argc, argv, i, "--beta", "an integer >= 1", false,
                                          UINT32_MAX, &o->beta_text, &value);
        o->beta = (uint32_t)value;
    } else if (coavoid_cli_option_is(arg, "--scenario")) {
        status = coavoid_cli_text_option(argc, argv, i, "--scenario", "a scenario file", false,
                                         &o->scenario);
    } else if (coavoid_cli_option_is(arg, "--json")) {
        status = coavoid_cli_flag_option(arg, "--json", &o->json);
    }
    return status;
}

/* bench's argv[2] is the benchmark's name, so options start at argv[3]. */
static const coavoid_cli_command_t bench_plan_command = {
    "bench plan", "coavoid bench plan", 3, {NULL, NULL}, "it takes options only", bench_plan_help,
    bp_option};

static int parse_bp_options(int argc, char **argv, bp_options_t *o)
{
    memset(o, 0, sizeof *o);
    int status = coavoid_cli_parse_args(&bench_plan_command, argc, argv, o, NULL);
    if (status != CLI_CONTINUE) {
        return status;
    }
    if (o->scenario != NULL && o->vehicles_text != NULL) {
        return coavoid_cli_fail(
            CLI_EXIT_INVALID, "--scenario: only without --vehicles (which times random encounters "
                              "only)");
    }
    if (o->seed_text == NULL) {
        o->seed = BP_DEFAULT_SEED;
    }
    if (o->repeat_text == NULL) {
        o->repeat = BP_DEFAULT_REPEAT;
    }
    if (o->count_text == NULL) {
        o->count = BP_DEFAULT_COUNT;
    }
    if (o->scenario == NULL) {
        o->scenario = BP_DEFAULT_SCENARIO;
    }
    return CLI_CONTINUE;
}

/* ---- the encounters ---- */

/* ---- the sets ---- */

typedef struct {
    char label[16];               /* "paper", "2 UAVs" */
    uint32_t vehicles;            /* per problem (the paper: its own) */
    coavoid_scenario_t *problems; /* sampled */
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

static int build_random_set(const bp_options_t *o, uint32_t n, bp_set_t *set)
{
    snprintf(set->label, sizeof set->label, "%u UAVs", n);
    set->vehicles = n;
    set->problems = calloc(o->count, sizeof *set->problems);
    if (set->problems == NULL) {
        return coavoid_cli_fail(CLI_EXIT_INVALID, "--count: out of memory for %lu problems",
                                (unsigned long)o->count);
    }
    for (uint32_t j = 0; j < o->count; j++) {
        char json[ENCOUNTER_JSON_MAX];
        char err[SCENARIO_ERROR_MAX];
        set->count = j + 1u; /* so set_free frees this one too */
        if (!coavoid_encounter_json(&coavoid_encounter_bench, o->seed, n, j, 0u, json, sizeof json,
                                    NULL)) {
            return coavoid_cli_fail(CLI_EXIT_INTERNAL,
                                    "internal error: encounter %u of %u UAVs does "
                                    "not fit %u bytes",
                                    j, n, ENCOUNTER_JSON_MAX);
        }
        if (coavoid_scenario_parse(json, strlen(json), &set->problems[j], err, sizeof err) != 0 ||
            coavoid_scenario_sample(&set->problems[j], err, sizeof err) != 0) {
            return coavoid_cli_fail(CLI_EXIT_INTERNAL,
                                    "internal error: encounter %u of %u UAVs: %s", j, n, err);
        }
    }
    return CLI_CONTINUE;
}

static int build_paper_set(const bp_options_t *o, bp_set_t *set)
{
    snprintf(set->label, sizeof set->label, "paper");
    set->problems = calloc(1u, sizeof *set->problems);
    if (set->problems == NULL) {
        return coavoid_cli_fail(CLI_EXIT_INVALID, "--scenario: out of memory");
    }
    set->count = 1u;
    int status = coavoid_cli_load_scenario(o->scenario, &set->problems[0]);
    if (status == CLI_CONTINUE) {
        status = coavoid_cli_sample_scenario(o->scenario, &set->problems[0]);
    }
    if (status == CLI_CONTINUE && set->problems[0].vehicle_count > COA_MAX_CENTRALISED) {
        status = coavoid_cli_fail(CLI_EXIT_INVALID,
                                  "%s: %zu vehicles, at most %u can be planned "
                                  "centrally",
                                  o->scenario, set->problems[0].vehicle_count, COA_MAX_CENTRALISED);
    }
    set->vehicles = (uint32_t)set->problems[0].vehicle_count;
    return status;
}

/* ---- the runs ---- */

typedef struct {
    const char *set;
    bool decoupled;
    uint32_t vehicles, problems, beta;
    bool beta_lowered; /* the chosen beta's workspace passed 1 GiB */
    double median_ms, min_ms, max_ms;
    uint64_t nodes_expanded, nodes_generated;
    size_t workspace_bytes;
    uint32_t solved, infeasible, budget_exhausted;
} bp_row_t;

/* One run over the set: adds the time (ms) and fills the tallies of row. */
static int run_once(coa_planner_t *planner, const bp_set_t *set, bool decoupled, int32_t *offsets,
                    double *ms, bp_row_t *row)
{
    *ms = 0;
    row->nodes_expanded = row->nodes_generated = 0;
    row->solved = row->infeasible = row->budget_exhausted = 0;
    for (uint32_t j = 0; j < set->count; j++) {
        coa_problem_t problem = coavoid_scenario_problem(&set->problems[j]);
        coa_plan_result_t result;
        memset(&result, 0, sizeof result);
        struct timespec start, end;
        clock_gettime(CLOCK_MONOTONIC, &start);
        int rc = decoupled ? coa_plan_decoupled(planner, &problem, NULL, 1u, offsets, &result)
                           : coa_plan_centralised(planner, &problem, offsets, &result);
        clock_gettime(CLOCK_MONOTONIC, &end);
        if (rc != COA_OK) {
            return coavoid_cli_fail(rc == COA_ERR_RANGE ? CLI_EXIT_INVALID : CLI_EXIT_INTERNAL,
                                    "%s, problem %u: the planner failed (%s)", set->label, j,
                                    coa_status_name(rc));
        }
        *ms += bench_elapsed_ms(&start, &end);
        row->nodes_expanded += result.nodes_expanded;
        row->nodes_generated += result.nodes_generated;
        row->solved += result.status == COA_PLAN_SOLVED;
        row->infeasible += result.status == COA_PLAN_INFEASIBLE;
        row->budget_exhausted += result.status == COA_PLAN_BUDGET_EXHAUSTED;
    }
    return CLI_CONTINUE;
}

static int run_set(const bp_options_t *o, const bp_set_t *set, bool decoupled, bp_row_t *row)
{
    memset(row, 0, sizeof *row);
    row->set = set->label;
    row->decoupled = decoupled;
    row->vehicles = set->vehicles;
    row->problems = set->count;
    size_t searched = decoupled ? 1u : set->vehicles;
    uint32_t wanted = o->beta_text != NULL                            ? o->beta
                      : set->count == 1u && set->problems[0].has_beta ? set->problems[0].beta
                                                                      : CLI_DEFAULT_BETA;
    coa_planner_config_t config = coavoid_cli_planner_config(&set->problems[0], searched, wanted);
    for (uint32_t j = 1; j < set->count; j++) {
        coa_planner_config_t other =
            coavoid_cli_planner_config(&set->problems[j], searched, wanted);
        coavoid_cli_planner_config_widen(&config, &other);
    }
    if (!coavoid_cli_workspace_fits(&config)) {
        config.beta = coavoid_cli_default_beta(&config);
    }
    row->beta_lowered = config.beta != wanted;
    row->beta = config.beta;
    size_t size = coa_planner_workspace_size(&config);
    void *workspace = size != 0 ? malloc(size) : NULL;
    int32_t *offsets = calloc((size_t)set->vehicles * (COA_MAX_HORIZON + 1u), sizeof *offsets);
    double *times = calloc(o->repeat, sizeof *times);
    int status = CLI_CONTINUE;
    coa_planner_t *planner = NULL;
    if (workspace == NULL || offsets == NULL || times == NULL) {
        status = coavoid_cli_fail(CLI_EXIT_INVALID, "%s: out of memory for %zu bytes of workspace",
                                  set->label, size);
    } else if ((planner = coa_planner_init(workspace, size, &config)) == NULL) {
        status = coavoid_cli_fail(CLI_EXIT_INTERNAL,
                                  "internal error: the planner refused its workspace");
    }
    row->workspace_bytes = size;
    bp_row_t first;
    memset(&first, 0, sizeof first);
    double ms = 0;
    if (status == CLI_CONTINUE) { /* untimed: warms caches and the workspace's pages */
        first = *row;
        status = run_once(planner, set, decoupled, offsets, &ms, &first);
    }
    for (uint32_t k = 0; status == CLI_CONTINUE && k < o->repeat; k++) {
        status = run_once(planner, set, decoupled, offsets, &times[k], row);
        if (status == CLI_CONTINUE &&
            (row->nodes_expanded != first.nodes_expanded ||
             row->nodes_generated != first.nodes_generated || row->solved != first.solved ||
             row->budget_exhausted != first.budget_exhausted)) {
            status = coavoid_cli_fail(CLI_EXIT_INTERNAL,
                                      "internal error: %s, run %lu differs from the "
                                      "first",
                                      set->label, (unsigned long)k + 1u);
        }
    }
    if (status == CLI_CONTINUE) {
        bench_summarise(times, o->repeat, &row->median_ms, &row->min_ms, &row->max_ms);
    }
    free(times);
    free(offsets);
    free(workspace);
    return status;
}

/* ---- the report ---- */

static double nodes_per_s(const bp_row_t *row)
{
    return row->median_ms > 0 ? (double)row->nodes_expanded / (row->median_ms * 1e-3) : 0.0;
}

static int report_text(FILE *f, const bp_options_t *o, const bp_row_t *rows, size_t count)
{
    fprintf(f, "benchmark: plan\nseed: %llu\nrepeat: %lu\ncount: %lu\n",
            (unsigned long long)o->seed, (unsigned long)o->repeat, (unsigned long)o->count);
    fprintf(f, "%-7s %-11s %8s %6s %10s %6s %5s %6s %10s %10s %10s %14s %12s %15s\n", "set", "mode",
            "problems", "solved", "infeasible", "budget", "uavs", "beta", "median_ms", "min_ms",
            "max_ms", "nodes_expanded", "nodes_per_s", "workspace_bytes");
    for (size_t i = 0; i < count; i++) {
        const bp_row_t *r = &rows[i];
        fprintf(f,
                "%-7s %-11s %8lu %6lu %10lu %6lu %5lu %5lu%s %10.3f %10.3f %10.3f %14llu %12.0f "
                "%15zu\n",
                r->set, r->decoupled ? "decoupled" : "centralised", (unsigned long)r->problems,
                (unsigned long)r->solved, (unsigned long)r->infeasible,
                (unsigned long)r->budget_exhausted, (unsigned long)r->vehicles,
                (unsigned long)r->beta, r->beta_lowered ? "*" : " ", r->median_ms, r->min_ms,
                r->max_ms, (unsigned long long)r->nodes_expanded, nodes_per_s(r),
                r->workspace_bytes);
    }
    fprintf(f, "times: per run over the set's problems; budget: budget exhausted; "
               "beta*: lowered to keep the workspace within 1 GiB\n");
    return fflush(f) == 0 && !ferror(f) ? 0 : -1;
}

static int report_json(FILE *f, const bp_options_t *o, const bp_row_t *rows, size_t count)
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
              (list = cJSON_AddArrayToObject(root, "results")) != NULL;
    for (size_t i = 0; ok && i < count; i++) {
        const bp_row_t *r = &rows[i];
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
             cJSON_AddNumberToObject(row, "solved", r->solved) != NULL &&
             cJSON_AddNumberToObject(row, "infeasible", r->infeasible) != NULL &&
             cJSON_AddNumberToObject(row, "budget_exhausted", r->budget_exhausted) != NULL;
    }
    if (!ok) {
        cJSON_Delete(root);
        return -1;
    }
    return coavoid_output_json(f, root, NULL, 0);
}

int coavoid_bench_plan(int argc, char **argv)
{
    bp_options_t o;
    int status = parse_bp_options(argc, argv, &o);
    if (status != CLI_CONTINUE) {
        return status;
    }
    bp_set_t sets[BP_SET_MAX];
    memset(sets, 0, sizeof sets);
    size_t set_count = 0;
    if (o.vehicles_text == NULL) {
        status = build_paper_set(&o, &sets[set_count++]);
        for (uint32_t n = BP_MIN_VEHICLES; status == CLI_CONTINUE && n <= BP_DEFAULT_MAX_VEHICLES;
             n++) {
            status = build_random_set(&o, n, &sets[set_count++]);
        }
    } else {
        status = build_random_set(&o, o.vehicles, &sets[set_count++]);
    }
    bp_row_t rows[2u * BP_SET_MAX];
    size_t row_count = 0;
    for (size_t i = 0; status == CLI_CONTINUE && i < set_count; i++) {
        for (int mode = 0; status == CLI_CONTINUE && mode < 2; mode++) {
            status = run_set(&o, &sets[i], mode == 1, &rows[row_count++]);
        }
    }
    if (status == CLI_CONTINUE) {
        int rc = o.json ? report_json(stdout, &o, rows, row_count)
                        : report_text(stdout, &o, rows, row_count);
        status =
            rc == 0 ? CLI_EXIT_OK : coavoid_cli_fail(CLI_EXIT_INTERNAL, "cannot write the result");
    }
    for (size_t i = 0; i < set_count; i++) {
        set_free(&sets[i]);
    }
    return status;
}
