/* SPDX-License-Identifier: MIT */
/*
 * coavoid montecarlo: the paper's question (does centralised planning succeed more often
 * and more cheaply than decoupled planning?) asked of thousands of seeded random
 * encounters instead of a few illustrations. See MONTECARLO_USAGE below and
 * docs/evaluation.md.
 *
 * Each encounter (encounter.h, design coavoid_encounter_montecarlo: UAVs converging on a point
 * over hills, with non-cooperative tracks crossing) is solved three ways on the same
 * problem: centralised (coa_plan_centralised), decoupled in the fixed priority order
 * (coa_plan_decoupled, max_orders 1) and decoupled with reordering (max_orders M). A draw
 * whose reference plan (every offset 0) has no conflict, or has one in its first step
 * (which includes t = 0, where nothing can be done), is replaced by the next draw of the
 * same encounter; the redraws are counted.
 *
 * The centralised plan is optimal, so wherever both solve, a decoupled plan's exact
 * deviation must be at least the centralised one's, lexicographically with the effort;
 * a decoupled plan is a plan for the group, so the centralised search cannot have proven
 * one absent (infeasible); every solved plan must be conflict-free by
 * coa_plan_find_conflict, and must move someone (the reference conflicts). A violation is a
 * defect of the planner: it is printed on stderr and the command exits 3 after writing
 * everything else.
 *
 * Jobs. Encounters are independent: --jobs J worker threads take them in order, each with
 * its own planner workspaces, and the main thread writes the CSV rows in encounter order
 * as they complete and reports progress. So the output does not depend on J, except for
 * the times.
 */
#define _POSIX_C_SOURCE 200809L

#include <math.h>
#include <pthread.h>
#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include <cjson/cJSON.h>

#include "bench_support.h"
#include "cli.h"
#include "coavoid/coavoid.h"
#include "commands.h"
#include "encounter.h"
#include "output.h"
#include "scenario.h"

#define MC_DEFAULT_SEED 1u
#define MC_DEFAULT_COUNT 100u
#define MC_MAX_COUNT 100000u
#define MC_MAX_JOBS 64u
#define MC_MAX_ATTEMPTS 1000u /* draws per encounter before giving up (a design bug) */
#define MC_SIZES (ENCOUNTER_MAX_VEHICLES - ENCOUNTER_MIN_VEHICLES + 1u)
#define MC_Z95 1.959963984540054 /* the normal quantile of a two-sided 95 % interval */

enum { MC_CENTRALISED, MC_FIXED, MC_REORDERED, MC_METHODS };
static const char *const method_names[MC_METHODS] = {"centralised", "decoupled_fixed",
                                                     "decoupled_reordered"};

#define MONTECARLO_USAGE                                                                    \
    "usage: coavoid montecarlo --vehicles N[,N...] [--count C] [--seed S] [--beta B]\n"     \
    "                          [--max-orders M] [--csv FILE] [--svg FILE] [--json]\n"       \
    "                          [--save DIR] [--jobs J] [--quiet]\n"                         \
    "\n"                                                                                    \
    "Draws C random encounters of N UAVs (for each N listed) converging on a point over\n"  \
    "hills, with 0 to 2 non-cooperative tracks crossing (%u steps of %g s), and solves\n"   \
    "each one centralised, decoupled in the fixed priority order and decoupled with\n"      \
    "reordering. Prints per N and method the outcomes, the success rate with its 95%%\n"    \
    "Wilson interval, the distribution of the decoupled/centralised deviation ratio\n"      \
    "over the encounters both solve, and the planning times (a text summary, or a JSON\n"   \
    "object with --json). See docs/evaluation.md.\n"                                        \
    "\n"                                                                                    \
    "options:\n"                                                                            \
    "  --vehicles N,...  UAVs per encounter, each %u..%u, e.g. 2,3,4 (required)\n"          \
    "  --count C         encounters per N, 1..%u; default %u\n"                             \
    "  --seed S          the encounters' random seed, an integer >= 0; default %u\n"        \
    "  --beta B          closed-set bound, B >= 1, for every search; default %u, lowered\n" \
    "                    per N where the centralised workspace would pass 1 GiB\n"          \
    "  --max-orders M    reordering: at most M priority orders, M >= 1; default N!\n"       \
    "                    (every order)\n"                                                   \
    "  --csv FILE        one row per encounter and method (times in time_us)\n"             \
    "  --svg FILE        success rates and the ratio's cumulative distribution\n"           \
    "  --save DIR        write each encounter as DIR/montecarlo-SEED-N-INDEX.json (an\n"    \
    "                    existing directory), for `coavoid plan` to replay\n"               \
    "  --json            print the summary as a JSON object\n"                              \
    "  --jobs J          worker threads, 1..%u; default 1; results do not depend on it\n"   \
    "  --quiet           no progress on stderr (otherwise: a line updated every second\n"   \
    "                    on a terminal, a line every 10%% when stderr is not one)\n"        \
    "  -h, --help        show this help\n"                                                  \
    "\n"                                                                                    \
    "A seed gives the same encounters and results on every machine with the same C\n"       \
    "maths library (headings use cos and sin), except the times.\n"                         \
    "\n"                                                                                    \
    "exit status: 0 done (whatever the plans' outcomes), 2 invalid usage (one line on\n"    \
    "stderr naming the option and why), 3 internal error or a defect of the planner (a\n"   \
    "decoupled plan cheaper than the optimal centralised one or where it proved none, a\n"  \
    "solved plan in conflict or with no deviation: one line each on stderr)\n"

static void montecarlo_help(void)
{
    printf(MONTECARLO_USAGE, coavoid_encounter_montecarlo.horizon, coavoid_encounter_montecarlo.dt,
           ENCOUNTER_MIN_VEHICLES, ENCOUNTER_MAX_VEHICLES, MC_MAX_COUNT, MC_DEFAULT_COUNT,
           MC_DEFAULT_SEED, CLI_DEFAULT_BETA, MC_MAX_JOBS);
}

/* ---- options ---- */

typedef struct {
    const char *vehicles_text;
    uint32_t sizes[MC_SIZES]; /* UAV counts in the order given */
    uint32_t size_count;
    const char *count_text;
    uint32_t count;
    const char *seed_text;
    uint64_t seed;
    const char *beta_text;
    uint32_t beta;
    const char *max_orders_text;
    uint32_t max_orders;
    const char *csv;
    const char *svg;
    const char *save; /* a directory for every encounter's scenario, or NULL */
    bool json;
    const char *jobs_text;
    uint32_t jobs;
    bool quiet;
} mc_options_t;

/* "2,3,4": each 2..6, each once. */
static int parse_sizes(mc_options_t *o)
{
    const char *token = o->vehicles_text;
    for (;;) {
        const char *comma = strchr(token, ',');
        size_t length = comma != NULL ? (size_t)(comma - token) : strlen(token);
        uint64_t n = 0;
        if (!coavoid_cli_parse_count(token, length, ENCOUNTER_MAX_VEHICLES, &n) ||
            n < ENCOUNTER_MIN_VEHICLES) {
            return coavoid_cli_fail(CLI_EXIT_INVALID,
                                    "--vehicles: each entry must be an integer from %u to %u, got "
                                    "'%.*s'",
                                    ENCOUNTER_MIN_VEHICLES, ENCOUNTER_MAX_VEHICLES,
                                    (int)(length > 40 ? 40 : length), token);
        }
        for (uint32_t k = 0; k < o->size_count; k++) {
            if (o->sizes[k] == n) {
                return coavoid_cli_fail(CLI_EXIT_INVALID, "--vehicles: %lu is listed twice",
                                        (unsigned long)n);
            }
        }
        o->sizes[o->size_count++] = (uint32_t)n; /* at most MC_SIZES distinct values */
        if (comma == NULL) {
            return CLI_CONTINUE;
        }
        token = comma + 1;
    }
}

static int mc_option(int argc, char **argv, int *i, void *options)
{
    mc_options_t *o = options;
    const char *arg = argv[*i];
    uint64_t value = 0;
    int status = CLI_UNKNOWN_OPTION;
    if (coavoid_cli_option_is(arg, "--vehicles")) {
        status =
            coavoid_cli_text_option(argc, argv, i, "--vehicles",
                                    "UAV counts from 2 to 6, e.g. 2,3,4", false, &o->vehicles_text);
        if (status == CLI_CONTINUE) {
            status = parse_sizes(o);
        }
    } else if (coavoid_cli_option_is(arg, "--count")) {
        status = coavoid_cli_count_option(argc, argv, i, "--count", NULL, false, MC_MAX_COUNT,
                                          &o->count_text, &value);
        o->count = (uint32_t)value;
    } else if (coavoid_cli_option_is(arg, "--seed")) {
        status = coavoid_cli_count_option(argc, argv, i, "--seed", NULL, true, UINT64_MAX,
                                          &o->seed_text, &value);
        o->seed = value;
    } else if (coavoid_cli_option_is(arg, "--beta")) {
        status = coavoid_cli_count_option(argc, argv, i, "--beta", "an integer >= 1", false,
                                          UINT32_MAX, &o->beta_text, &value);
        o->beta = (uint32_t)value;
    } else if (coavoid_cli_option_is(arg, "--max-orders")) {
        status = coavoid_cli_count_option(argc, argv, i, "--max-orders", "an integer >= 1", false,
                                          UINT32_MAX, &o->max_orders_text, &value);
        o->max_orders = (uint32_t)value;
    } else if (coavoid_cli_option_is(arg, "--csv")) {
        status = coavoid_cli_text_option(argc, argv, i, "--csv", "a file to write", false, &o->csv);
    } else if (coavoid_cli_option_is(arg, "--svg")) {
        status = coavoid_cli_text_option(argc, argv, i, "--svg", "a file to write", false, &o->svg);
    } else if (coavoid_cli_option_is(arg, "--save")) {
        status = coavoid_cli_text_option(argc, argv, i, "--save", "a directory", false, &o->save);
    } else if (coavoid_cli_option_is(arg, "--json")) {
        status = coavoid_cli_flag_option(arg, "--json", &o->json);
    } else if (coavoid_cli_option_is(arg, "--jobs")) {
        status = coavoid_cli_count_option(argc, argv, i, "--jobs", NULL, false, MC_MAX_JOBS,
                                          &o->jobs_text, &value);
        o->jobs = (uint32_t)value;
    } else if (coavoid_cli_option_is(arg, "--quiet")) {
        status = coavoid_cli_flag_option(arg, "--quiet", &o->quiet);
    }
    return status;
}

static const coavoid_cli_command_t montecarlo_command = {
    "montecarlo", "coavoid montecarlo", 2, {NULL, NULL}, "it takes options only", montecarlo_help,
    mc_option};

static int parse_mc_options(int argc, char **argv, mc_options_t *o)
{
    memset(o, 0, sizeof *o);
    int status = coavoid_cli_parse_args(&montecarlo_command, argc, argv, o, NULL);
    if (status != CLI_CONTINUE) {
        return status;
    }
    if (o->vehicles_text == NULL) {
        return coavoid_cli_fail(CLI_EXIT_INVALID,
                                "--vehicles: required (UAV counts from %u to %u, "
                                "e.g. 2,3,4)",
                                ENCOUNTER_MIN_VEHICLES, ENCOUNTER_MAX_VEHICLES);
    }
    if (o->csv != NULL && o->svg != NULL && strcmp(o->csv, o->svg) == 0) {
        return coavoid_cli_fail(CLI_EXIT_INVALID, "--svg: the same file as --csv ('%.200s')",
                                o->csv);
    }
    if (o->count_text == NULL) {
        o->count = MC_DEFAULT_COUNT;
    }
    if (o->seed_text == NULL) {
        o->seed = MC_DEFAULT_SEED;
    }
    if (o->jobs_text == NULL) {
        o->jobs = 1u;
    }
    return CLI_CONTINUE;
}

/* ---- one encounter ---- */

typedef struct {
    coa_plan_status_t status;
    double deviation;
    coa_cost_t units;
    uint32_t effort;
    uint64_t expanded, generated;
    uint32_t orders_tried;
    double time_us;
} mc_outcome_t;

typedef struct {
    uint32_t vehicles, index;
    uint32_t redraws;
    coavoid_encounter_info_t info;
    uint32_t first_conflict_step;
    mc_outcome_t m[MC_METHODS];
    char defect[256]; /* empty unless a check failed */
} mc_result_t;

typedef struct {
    uint32_t n;
    uint32_t beta;
    uint32_t max_orders;
} mc_size_t;

/* A planner for every encounter of the design: its horizon, steep factor 2 (the
 * generator's) and its offset band (unbounded when it draws none). */
static coa_planner_config_t mc_config(uint32_t searched, uint32_t beta)
{
    const coavoid_encounter_design_t *d = &coavoid_encounter_montecarlo;
    coa_planner_config_t c;
    c.vehicles = searched;
    c.beta = beta;
    c.horizon = d->horizon;
    c.steep_factor = 2u;
    c.max_offset = d->max_offset_max > 0u ? (int32_t)d->max_offset_max : -1;
    return c;
}

static uint32_t factorial(uint32_t n)
{
    uint32_t f = 1u;
    for (uint32_t k = 2u; k <= n; k++) {
        f *= k;
    }
    return f;
}

/* One worker's planners, rebuilt when the UAV count changes (the items come in order, so
 * at most once per count). */
typedef struct {
    uint32_t n;
    void *central_buffer, *decoupled_buffer;
    coa_planner_t *central, *decoupled;
    int32_t *offsets; /* ENCOUNTER_MAX_VEHICLES * (COA_MAX_HORIZON + 1) */
    int32_t *zeros;
} mc_planners_t;

static void planners_free(mc_planners_t *p)
{
    free(p->central_buffer);
    free(p->decoupled_buffer);
    free(p->offsets);
    free(p->zeros);
    memset(p, 0, sizeof *p);
}

/* Returns 0, or -1 with the reason in err. */
static int planners_ready(mc_planners_t *p, const mc_size_t *size, char *err, size_t err_size)
{
    if (p->n == size->n && p->central != NULL) {
        return 0;
    }
    free(p->central_buffer);
    free(p->decoupled_buffer);
    p->central_buffer = p->decoupled_buffer = NULL;
    p->central = p->decoupled = NULL;
    p->n = size->n;
    size_t rows = (size_t)ENCOUNTER_MAX_VEHICLES * (COA_MAX_HORIZON + 1u);
    if (p->offsets == NULL) {
        p->offsets = calloc(rows, sizeof *p->offsets);
        p->zeros = calloc(rows, sizeof *p->zeros);
    }
    coa_planner_config_t central_config = mc_config(size->n, size->beta);
    coa_planner_config_t decoupled_config = mc_config(1u, size->beta);
    size_t central = coa_planner_workspace_size(&central_config);
    size_t decoupled = coa_planner_workspace_size(&decoupled_config);
    if (central == 0 || decoupled == 0) {
        snprintf(err, err_size,
                 "--beta: %lu is too large for %lu UAVs centralised (the node "
                 "pool would pass 2^30)",
                 (unsigned long)size->beta, (unsigned long)size->n);
        return -1;
    }
    p->central_buffer = malloc(central);
    p->decoupled_buffer = malloc(decoupled);
    if (p->central_buffer == NULL || p->decoupled_buffer == NULL || p->offsets == NULL ||
        p->zeros == NULL) {
        snprintf(err, err_size,
                 "out of memory for %zu bytes of workspace (%lu UAVs at beta "
                 "%lu; lower --beta or --jobs)",
                 central, (unsigned long)size->n, (unsigned long)size->beta);
        return -1;
    }
    p->central = coa_planner_init(p->central_buffer, central, &central_config);
    p->decoupled = coa_planner_init(p->decoupled_buffer, decoupled, &decoupled_config);
    if (p->central == NULL || p->decoupled == NULL) {
        snprintf(err, err_size, "internal error: the planner refused its workspace");
        return -1;
    }
    return 0;
}

/* DIR/montecarlo-SEED-N-INDEX.json, so that `coavoid plan` can replay an encounter. */
static int save_encounter(const char *dir, uint64_t seed, uint32_t n, uint32_t index,
                          const char *json)
{
    char path[4096];
    int length = snprintf(path, sizeof path, "%s/montecarlo-%llu-%lu-%lu.json", dir,
                          (unsigned long long)seed, (unsigned long)n, (unsigned long)index);
    if (length < 0 || (size_t)length >= sizeof path) {
        return -1;
    }
    FILE *f = fopen(path, "w");
    if (f == NULL) {
        return -1;
    }
    bool ok = fputs(json, f) >= 0 && fputc('\n', f) != EOF;
    return fclose(f) == 0 && ok ? 0 : -1;
}

/* The accepted draw of encounter (n, index), sampled, in *s; saved in save_dir unless
 * NULL. Returns 0 or -1 with err. */
static int draw_encounter(uint64_t seed, const mc_size_t *size, uint32_t index,
                          const char *save_dir, mc_planners_t *p, coavoid_scenario_t *s,
                          mc_result_t *r, char *err, size_t err_size)
{
    const uint32_t n = size->n;
    size_t which[ENCOUNTER_MAX_VEHICLES];
    for (size_t i = 0; i < n; i++) {
        which[i] = i;
    }
    for (uint32_t attempt = 0; attempt < MC_MAX_ATTEMPTS; attempt++) {
        char json[ENCOUNTER_JSON_MAX];
        char why[SCENARIO_ERROR_MAX];
        if (!coavoid_encounter_json(&coavoid_encounter_montecarlo, seed, n, index, attempt, json,
                                    sizeof json, &r->info)) {
            snprintf(err, err_size,
                     "internal error: encounter %lu of %lu UAVs does not fit %u "
                     "bytes",
                     (unsigned long)index, (unsigned long)n, ENCOUNTER_JSON_MAX);
            return -1;
        }
        memset(s, 0, sizeof *s);
        if (coavoid_scenario_parse(json, strlen(json), s, why, sizeof why) != 0 ||
            coavoid_scenario_sample(s, why, sizeof why) != 0) {
            coavoid_scenario_free(s);
            snprintf(err, err_size, "internal error: encounter %lu of %lu UAVs: %s",
                     (unsigned long)index, (unsigned long)n, why);
            return -1;
        }
        coa_problem_t problem = coavoid_scenario_problem(s);
        size_t vehicle = 0;
        uint32_t step = 0;
        int rc = coa_plan_find_conflict(&problem, p->zeros, which, n, &vehicle, &step);
        if (rc < 0) {
            coavoid_scenario_free(s);
            snprintf(err, err_size,
                     "internal error: encounter %lu of %lu UAVs: the conflict "
                     "check failed (%s)",
                     (unsigned long)index, (unsigned long)n, coa_status_name(rc));
            return -1;
        }
        if (rc == 1 && step > 0) {
            if (save_dir != NULL && save_encounter(save_dir, seed, n, index, json) != 0) {
                coavoid_scenario_free(s);
                snprintf(err, err_size,
                         "--save: cannot write encounter %lu of %lu UAVs in "
                         "'%.200s'",
                         (unsigned long)index, (unsigned long)n, save_dir);
                return -1;
            }
            r->redraws = attempt;
            r->first_conflict_step = step;
            return 0;
        }
        coavoid_scenario_free(s);
    }
    snprintf(err, err_size,
             "internal error: encounter %lu of %lu UAVs: no draw in %u has a "
             "conflict after its first step",
             (unsigned long)index, (unsigned long)n, MC_MAX_ATTEMPTS);
    return -1;
}

static double cost_to_double(coa_cost_t c)
{
    return (double)c.hi * 18446744073709551616.0 + (double)c.lo;
}

/* Solves encounter (size, index) three ways into *r. Returns 0 or -1 with err (an error
 * of the tool, not of a plan: plans' defects go to r->defect). */
/* Plans the encounter with method m into r->m[m], and records a defect when a solved plan
 * has a conflict. -1 with err set when the planner failed. */
static int solve_method(int m, const coa_problem_t *problem, const mc_size_t *size, uint32_t index,
                        mc_planners_t *p, mc_result_t *r, char *err, size_t err_size)
{
    size_t which[ENCOUNTER_MAX_VEHICLES];
    coa_plan_result_t result;
    struct timespec start, end;
    memset(&result, 0, sizeof result);
    clock_gettime(CLOCK_MONOTONIC, &start);
    int rc = m == MC_CENTRALISED
                 ? coa_plan_centralised(p->central, problem, p->offsets, &result)
                 : coa_plan_decoupled(p->decoupled, problem, NULL,
                                      m == MC_FIXED ? 1u : size->max_orders, p->offsets, &result);
    clock_gettime(CLOCK_MONOTONIC, &end);
    if (rc != COA_OK) {
        snprintf(err, err_size,
                 "internal error: encounter %lu of %lu UAVs, %s: the "
                 "planner failed (%s)",
                 (unsigned long)index, (unsigned long)size->n, method_names[m],
                 coa_status_name(rc));
        return -1;
    }
    mc_outcome_t *o = &r->m[m];
    o->status = result.status;
    o->deviation = result.deviation;
    o->units = result.deviation_units;
    o->effort = result.effort;
    o->expanded = result.nodes_expanded;
    o->generated = result.nodes_generated;
    o->orders_tried = result.orders_tried;
    o->time_us = bench_elapsed_ms(&start, &end) * 1e3;
    if (result.status == COA_PLAN_SOLVED && r->defect[0] == '\0') {
        size_t vehicle = 0;
        uint32_t step = 0;
        for (size_t i = 0; i < size->n; i++) {
            which[i] = i;
        }
        rc = coa_plan_find_conflict(problem, p->offsets, which, size->n, &vehicle, &step);
        if (rc != 0) {
            snprintf(r->defect, sizeof r->defect,
                     "the %s plan has a conflict (check %d) "
                     "at step %lu",
                     method_names[m], rc, (unsigned long)step);
        }
    }
    return 0;
}

/* The defects the methods' outcomes can show against each other: the reference plan
 * conflicts, so every plan moves someone (a deviation of 0 would be wrong, and the ratios
 * divide by it); a decoupled plan is a plan for the whole group, which the centralised
 * search cannot have proven absent, nor beaten. */
static void cross_check(mc_result_t *r)
{
    const mc_outcome_t *c = &r->m[MC_CENTRALISED];
    if (r->defect[0] == '\0' && c->status == COA_PLAN_SOLVED && c->units.hi == 0 &&
        c->units.lo == 0) {
        snprintf(r->defect, sizeof r->defect,
                 "the centralised plan has no deviation although "
                 "the reference plan conflicts at step %lu",
                 (unsigned long)r->first_conflict_step);
    }
    for (int m = MC_FIXED; m < MC_METHODS && r->defect[0] == '\0'; m++) {
        const mc_outcome_t *d = &r->m[m];
        if (c->status == COA_PLAN_INFEASIBLE && d->status == COA_PLAN_SOLVED) {
            snprintf(r->defect, sizeof r->defect,
                     "%s solved an encounter the centralised "
                     "search proved infeasible",
                     method_names[m]);
            continue;
        }
        if (c->status != COA_PLAN_SOLVED || d->status != COA_PLAN_SOLVED) {
            continue;
        }
        int cmp = coa_cost_compare(d->units, c->units);
        if (cmp < 0 || (cmp == 0 && d->effort < c->effort)) {
            snprintf(r->defect, sizeof r->defect,
                     "%s plan (deviation %.17g units, effort %lu) "
                     "is cheaper than the optimal centralised one (%.17g units, effort %lu)",
                     method_names[m], cost_to_double(d->units), (unsigned long)d->effort,
                     cost_to_double(c->units), (unsigned long)c->effort);
        }
    }
}

static int solve_encounter(uint64_t seed, const mc_size_t *size, uint32_t index,
                           const char *save_dir, mc_planners_t *p, mc_result_t *r, char *err,
                           size_t err_size)
{
    memset(r, 0, sizeof *r);
    r->vehicles = size->n;
    r->index = index;
    if (planners_ready(p, size, err, err_size) != 0) {
        return -1;
    }
    coavoid_scenario_t s;
    if (draw_encounter(seed, size, index, save_dir, p, &s, r, err, err_size) != 0) {
        return -1;
    }
    coa_problem_t problem = coavoid_scenario_problem(&s);
    int status = 0;
    for (int m = 0; m < MC_METHODS && status == 0; m++) {
        status = solve_method(m, &problem, size, index, p, r, err, err_size);
    }
    coavoid_scenario_free(&s);
    if (status == 0) {
        cross_check(r);
    }
    return status;
}

/* ---- the run: workers and the main thread's writing and progress ---- */

typedef struct {
    const mc_options_t *o;
    const mc_size_t *sizes;
    uint32_t total;
    mc_result_t *results;
    bool *done;
    pthread_mutex_t lock;
    uint32_t next; /* the next item a worker takes */
    bool stop;     /* an error: workers take nothing more */
    char error[SCENARIO_ERROR_MAX + 128];
} mc_run_t;

static const mc_size_t *item_size(const mc_run_t *run, uint32_t item)
{
    return &run->sizes[item / run->o->count];
}

static void *worker(void *arg)
{
    mc_run_t *run = arg;
    mc_planners_t planners;
    memset(&planners, 0, sizeof planners);
    for (;;) {
        pthread_mutex_lock(&run->lock);
        uint32_t item = run->next;
        bool go = !run->stop && item < run->total;
        if (go) {
            run->next++;
        }
        pthread_mutex_unlock(&run->lock);
        if (!go) {
            break;
        }
        mc_result_t result;
        char err[sizeof run->error];
        int rc = solve_encounter(run->o->seed, item_size(run, item), item % run->o->count,
                                 run->o->save, &planners, &result, err, sizeof err);
        pthread_mutex_lock(&run->lock);
        if (rc != 0) {
            if (!run->stop) {
                snprintf(run->error, sizeof run->error, "%s", err);
            }
            run->stop = true;
        } else {
            run->results[item] = result;
            run->done[item] = true;
        }
        pthread_mutex_unlock(&run->lock);
    }
    planners_free(&planners);
    return NULL;
}

/* The decimal digits of a 128-bit cost. */
static void cost_text(coa_cost_t c, char *buf, size_t size)
{
    char digits[48];
    size_t k = 0;
    uint32_t limb[4] = {(uint32_t)(c.hi >> 32), (uint32_t)c.hi, (uint32_t)(c.lo >> 32),
                        (uint32_t)c.lo};
    do {
        uint64_t rem = 0;
        bool zero = true;
        for (int j = 0; j < 4; j++) {
            uint64_t cur = (rem << 32) | limb[j];
            limb[j] = (uint32_t)(cur / 10u);
            rem = cur % 10u;
            zero = zero && limb[j] == 0;
        }
        digits[k++] = (char)('0' + rem);
        if (zero) {
            break;
        }
    } while (k < sizeof digits);
    size_t j = 0;
    for (; j < k && j + 1 < size; j++) {
        buf[j] = digits[k - 1 - j];
    }
    buf[j] = '\0';
}

#define MC_CSV_HEADER                                                             \
    "seed,vehicles,index,redraws,hills,tracks,first_conflict_step,method,status," \
    "deviation,deviation_units,effort,expanded,generated,orders_tried,time_us\n"

static void csv_rows(FILE *f, uint64_t seed, const mc_result_t *r)
{
    for (int m = 0; m < MC_METHODS; m++) {
        const mc_outcome_t *o = &r->m[m];
        /* Costs only of a plan: a failed decoupled attempt's partial costs are not one. */
        char costs[128] = ",,";
        if (o->status == COA_PLAN_SOLVED) {
            char units[48];
            cost_text(o->units, units, sizeof units);
            snprintf(costs, sizeof costs, "%.6f,%s,%lu", o->deviation, units,
                     (unsigned long)o->effort);
        }
        fprintf(f, "%llu,%lu,%lu,%lu,%lu,%lu,%lu,%s,%s,%s,%llu,%llu,%lu,%.1f\n",
                (unsigned long long)seed, (unsigned long)r->vehicles, (unsigned long)r->index,
                (unsigned long)r->redraws, (unsigned long)r->info.hills,
                (unsigned long)r->info.tracks, (unsigned long)r->first_conflict_step,
                method_names[m], coavoid_output_status_name(o->status), costs,
                (unsigned long long)o->expanded, (unsigned long long)o->generated,
                (unsigned long)o->orders_tried, o->time_us);
    }
}

static double seconds_since(const struct timespec *start)
{
    struct timespec now;
    clock_gettime(CLOCK_MONOTONIC, &now);
    return bench_elapsed_ms(start, &now) * 1e-3;
}

typedef struct {
    bool tty;
    bool quiet;
    uint32_t reported_tenth; /* not a tty: the last 10 % step reported */
    double reported_at;      /* a tty: when the line was last updated, s */
    bool line_open;          /* a tty: the line has no newline yet */
} mc_progress_t;

static void progress(mc_progress_t *p, uint32_t done, uint32_t total, double elapsed, bool last)
{
    if (p->quiet || (done == 0 && !last)) {
        return;
    }
    uint32_t tenth = (uint32_t)((uint64_t)done * 10u / total);
    if (p->tty ? !(last || elapsed - p->reported_at >= 1.0) : tenth == p->reported_tenth) {
        return;
    }
    double eta = done > 0 ? elapsed * (double)(total - done) / (double)done : 0.0;
    fprintf(stderr, "%smontecarlo: %lu/%lu encounters (%.0f%%), %.0f s elapsed, ETA %.0f s%s",
            p->tty ? "\r" : "", (unsigned long)done, (unsigned long)total, 100.0 * done / total,
            elapsed, eta, p->tty && !last ? "   " : "\n");
    fflush(stderr);
    p->reported_tenth = tenth;
    p->reported_at = elapsed;
    p->line_open = p->tty && !last;
}

/* Runs every item; writes CSV rows (when f is not NULL) in order as they complete. Returns
 * CLI_CONTINUE, or the exit status after the message. */
static int run_all(mc_run_t *run, FILE *csv)
{
    const mc_options_t *o = run->o;
    uint32_t jobs = o->jobs < run->total ? o->jobs : run->total;
    pthread_t threads[MC_MAX_JOBS];
    uint32_t started = 0;
    pthread_mutex_init(&run->lock, NULL);
    for (; started < jobs; started++) {
        if (pthread_create(&threads[started], NULL, worker, run) != 0) {
            break;
        }
    }
    if (started == 0) {
        pthread_mutex_destroy(&run->lock);
        return coavoid_cli_fail(CLI_EXIT_INTERNAL, "cannot start a worker thread");
    }
    mc_progress_t prog = {isatty(STDERR_FILENO) == 1, o->quiet, 0u, 0.0, false};
    struct timespec start;
    clock_gettime(CLOCK_MONOTONIC, &start);
    uint32_t written = 0;
    for (;;) {
        pthread_mutex_lock(&run->lock);
        uint32_t ready = written;
        while (ready < run->total && run->done[ready]) {
            ready++;
        }
        bool stop = run->stop;
        pthread_mutex_unlock(&run->lock);
        /* Items below `ready` are final: workers write each result once, before done. */
        for (; written < ready; written++) {
            if (csv != NULL) {
                csv_rows(csv, o->seed, &run->results[written]);
            }
            if (run->results[written].defect[0] != '\0') {
                if (prog.line_open) {
                    fputc('\n', stderr);
                    prog.line_open = false;
                }
                coavoid_cli_fail(
                    CLI_EXIT_INTERNAL,
                    "montecarlo: defect: seed %llu, %lu UAVs, "
                    "encounter %lu: %s",
                    (unsigned long long)o->seed, (unsigned long)run->results[written].vehicles,
                    (unsigned long)run->results[written].index, run->results[written].defect);
            }
        }
        if (csv != NULL) {
            fflush(csv);
        }
        double elapsed = seconds_since(&start);
        if (written == run->total || stop) {
            progress(&prog, written, run->total, elapsed, true);
            break;
        }
        progress(&prog, written, run->total, elapsed, false);
        struct timespec pause = {0, 50 * 1000 * 1000};
        nanosleep(&pause, NULL);
    }
    for (uint32_t t = 0; t < started; t++) {
        pthread_join(threads[t], NULL);
    }
    pthread_mutex_destroy(&run->lock);
    if (run->stop) {
        return coavoid_cli_fail(strncmp(run->error, "internal error", 14) == 0 ? CLI_EXIT_INTERNAL
                                                                               : CLI_EXIT_INVALID,
                                "montecarlo: %s", run->error);
    }
    return CLI_CONTINUE;
}

/* ---- the summary ---- */

typedef struct {
    uint32_t count;
    double min, p25, median, p75, p90, max, mean;
    double equal_share; /* ratio exactly 1 (the same exact deviation) */
} mc_dist_t;

/* The p-quantile of sorted x[0..m-1] (m >= 1), interpolating linearly between order
 * statistics (numpy's default, "type 7"), so scripts can recompute it. */
static double quantile(const double *x, uint32_t m, double p)
{
    double h = (double)(m - 1u) * p;
    double lo = floor(h);
    uint32_t k = (uint32_t)lo;
    return k + 1u < m ? x[k] + (h - lo) * (x[k + 1u] - x[k]) : x[m - 1u];
}

/* Sorts x and summarises it; equal: how many were exactly equal. */
static mc_dist_t distribution(double *x, uint32_t m, uint32_t equal)
{
    mc_dist_t d;
    memset(&d, 0, sizeof d);
    d.count = m;
    if (m == 0) {
        return d;
    }
    qsort(x, m, sizeof *x, bench_compare_doubles);
    double sum = 0;
    for (uint32_t k = 0; k < m; k++) {
        sum += x[k];
    }
    d.min = x[0];
    d.p25 = quantile(x, m, 0.25);
    d.median = quantile(x, m, 0.5);
    d.p75 = quantile(x, m, 0.75);
    d.p90 = quantile(x, m, 0.9);
    d.max = x[m - 1u];
    d.mean = sum / m;
    d.equal_share = (double)equal / m;
    return d;
}

typedef struct {
    uint32_t solved, infeasible, budget;
    double rate, low, high; /* success rate and its 95 % Wilson interval */
    mc_dist_t time_ms;      /* of every encounter */
    mc_dist_t expanded;
    mc_dist_t ratio; /* decoupled methods: deviation / centralised's, both solved */
    uint32_t fails_where_central_solves, solves_where_central_fails;
    double mean_deviation_both; /* mean deviation (m^2) over the encounters both solve */
    double central_mean_deviation_both;
} mc_method_summary_t;

typedef struct {
    mc_size_t size;
    uint32_t encounters, redraws;
    mc_method_summary_t m[MC_METHODS];
} mc_summary_t;

static void wilson(uint32_t k, uint32_t n, double *rate, double *low, double *high)
{
    double p = (double)k / n, z2 = MC_Z95 * MC_Z95, nn = (double)n;
    double centre = (p + z2 / (2.0 * nn)) / (1.0 + z2 / nn);
    double half = MC_Z95 * sqrt(p * (1.0 - p) / nn + z2 / (4.0 * nn * nn)) / (1.0 + z2 / nn);
    *rate = p;
    /* Exactly 0 and 1 at the ends, where rounding would leave a few ulps. */
    *low = k == 0 || centre - half < 0 ? 0 : centre - half;
    *high = k == n || centre + half > 1 ? 1 : centre + half;
}

/* Summarises the count results of one size; x: room for count doubles. */
static void summarise(const mc_result_t *results, uint32_t count, const mc_size_t *size, double *x,
                      mc_summary_t *s)
{
    memset(s, 0, sizeof *s);
    s->size = *size;
    s->encounters = count;
    for (uint32_t j = 0; j < count; j++) {
        s->redraws += results[j].redraws;
    }
    for (int m = 0; m < MC_METHODS; m++) {
        mc_method_summary_t *ms = &s->m[m];
        for (uint32_t j = 0; j < count; j++) {
            coa_plan_status_t st = results[j].m[m].status;
            ms->solved += st == COA_PLAN_SOLVED;
            ms->infeasible += st == COA_PLAN_INFEASIBLE;
            ms->budget += st == COA_PLAN_BUDGET_EXHAUSTED;
            x[j] = results[j].m[m].time_us * 1e-3;
        }
        wilson(ms->solved, count, &ms->rate, &ms->low, &ms->high);
        ms->time_ms = distribution(x, count, 0u);
        for (uint32_t j = 0; j < count; j++) {
            x[j] = (double)results[j].m[m].expanded;
        }
        ms->expanded = distribution(x, count, 0u);
        if (m == MC_CENTRALISED) {
            continue;
        }
        uint32_t both = 0, equal = 0;
        double dev = 0, cdev = 0;
        for (uint32_t j = 0; j < count; j++) {
            const mc_outcome_t *c = &results[j].m[MC_CENTRALISED], *d = &results[j].m[m];
            bool cs = c->status == COA_PLAN_SOLVED, ds = d->status == COA_PLAN_SOLVED;
            ms->fails_where_central_solves += cs && !ds;
            ms->solves_where_central_fails += ds && !cs;
            if (cs && ds) {
                x[both++] = cost_to_double(d->units) / cost_to_double(c->units);
                equal += coa_cost_compare(d->units, c->units) == 0;
                dev += d->deviation;
                cdev += c->deviation;
            }
        }
        ms->mean_deviation_both = both > 0 ? dev / both : 0;
        ms->central_mean_deviation_both = both > 0 ? cdev / both : 0;
        ms->ratio = distribution(x, both, equal);
    }
}

static void text_summary(FILE *f, const mc_options_t *o, const mc_summary_t *s, uint32_t sizes)
{
    const coavoid_encounter_design_t *d = &coavoid_encounter_montecarlo;
    fprintf(f, "montecarlo: seed %llu, %lu encounters per UAV count, %u steps of %g s\n",
            (unsigned long long)o->seed, (unsigned long)o->count, d->horizon, d->dt);
    for (uint32_t k = 0; k < sizes; k++) {
        const mc_summary_t *z = &s[k];
        fprintf(f, "\n%lu UAVs: %lu encounters (%lu redraws), beta %lu, max orders %lu\n",
                (unsigned long)z->size.n, (unsigned long)z->encounters, (unsigned long)z->redraws,
                (unsigned long)z->size.beta, (unsigned long)z->size.max_orders);
        fprintf(f, "  %-20s %7s %10s %7s %8s %16s %10s %10s %10s %12s\n", "method", "solved",
                "infeasible", "budget", "success", "95% Wilson", "median_ms", "p90_ms", "max_ms",
                "median_nodes");
        for (int m = 0; m < MC_METHODS; m++) {
            const mc_method_summary_t *ms = &z->m[m];
            fprintf(f,
                    "  %-20s %7lu %10lu %7lu %7.1f%% %7.1f-%5.1f%% %10.3f %10.3f %10.3f %12.0f\n",
                    method_names[m], (unsigned long)ms->solved, (unsigned long)ms->infeasible,
                    (unsigned long)ms->budget, 100 * ms->rate, 100 * ms->low, 100 * ms->high,
                    ms->time_ms.median, ms->time_ms.p90, ms->time_ms.max, ms->expanded.median);
        }
        fprintf(f, "  deviation ratio to centralised, over the encounters both solve:\n");
        fprintf(f, "  %-20s %6s %7s %7s %7s %7s %7s %7s %7s %7s %9s %9s\n", "method", "both", "min",
                "p25", "median", "p75", "p90", "max", "mean", "=1", "fails*", "solves*");
        for (int m = MC_FIXED; m < MC_METHODS; m++) {
            const mc_method_summary_t *ms = &z->m[m];
            const mc_dist_t *r = &ms->ratio;
            double fails = 100.0 * ms->fails_where_central_solves / z->encounters;
            double solves = 100.0 * ms->solves_where_central_fails / z->encounters;
            if (r->count == 0) {
                /* No ratio at all, not ratios of 0 (a ratio is at least 1). */
                fprintf(f, "  %-20s %6lu %7s %7s %7s %7s %7s %7s %7s %7s %8.1f%% %8.1f%%\n",
                        method_names[m], 0ul, "-", "-", "-", "-", "-", "-", "-", "-", fails,
                        solves);
                continue;
            }
            fprintf(f,
                    "  %-20s %6lu %7.3f %7.3f %7.3f %7.3f %7.3f %7.3f %7.3f %6.1f%% %8.1f%% "
                    "%8.1f%%\n",
                    method_names[m], (unsigned long)r->count, r->min, r->p25, r->median, r->p75,
                    r->p90, r->max, r->mean, 100 * r->equal_share, fails, solves);
        }
    }
    fprintf(f, "\nbudget: beta exhausted (nothing proven); =1: the same exact deviation as "
               "centralised;\nfails*: share of encounters it fails and centralised solves; "
               "solves*: it solves and centralised fails\n");
}

static bool add_dist(cJSON *parent, const char *name, const mc_dist_t *d, bool with_equal)
{
    cJSON *o = cJSON_AddObjectToObject(parent, name);
    bool ok = o != NULL && cJSON_AddNumberToObject(o, "count", d->count) != NULL;
    if (ok && d->count > 0) {
        ok = cJSON_AddNumberToObject(o, "min", d->min) != NULL &&
             cJSON_AddNumberToObject(o, "p25", d->p25) != NULL &&
             cJSON_AddNumberToObject(o, "median", d->median) != NULL &&
             cJSON_AddNumberToObject(o, "p75", d->p75) != NULL &&
             cJSON_AddNumberToObject(o, "p90", d->p90) != NULL &&
             cJSON_AddNumberToObject(o, "max", d->max) != NULL &&
             cJSON_AddNumberToObject(o, "mean", d->mean) != NULL;
    }
    if (ok && with_equal) {
        ok = cJSON_AddNumberToObject(o, "equal_share", d->count > 0 ? d->equal_share : 0) != NULL;
    }
    return ok;
}

static int json_summary(FILE *f, const mc_options_t *o, const mc_summary_t *s, uint32_t sizes)
{
    char seed[32];
    snprintf(seed, sizeof seed, "%llu", (unsigned long long)o->seed);
    cJSON *root = cJSON_CreateObject();
    cJSON *list = NULL;
    bool ok =
        root != NULL && cJSON_AddStringToObject(root, "command", "montecarlo") != NULL &&
        cJSON_AddRawToObject(root, "seed", seed) != NULL &&
        cJSON_AddNumberToObject(root, "count", o->count) != NULL &&
        cJSON_AddNumberToObject(root, "horizon", coavoid_encounter_montecarlo.horizon) != NULL &&
        cJSON_AddNumberToObject(root, "dt", coavoid_encounter_montecarlo.dt) != NULL &&
        (list = cJSON_AddArrayToObject(root, "sizes")) != NULL;
    for (uint32_t k = 0; ok && k < sizes; k++) {
        const mc_summary_t *z = &s[k];
        cJSON *item = cJSON_CreateObject();
        cJSON *methods = NULL;
        ok = item != NULL && cJSON_AddItemToArray(list, item) &&
             cJSON_AddNumberToObject(item, "vehicles", z->size.n) != NULL &&
             cJSON_AddNumberToObject(item, "encounters", z->encounters) != NULL &&
             cJSON_AddNumberToObject(item, "redraws", z->redraws) != NULL &&
             cJSON_AddNumberToObject(item, "beta", z->size.beta) != NULL &&
             cJSON_AddNumberToObject(item, "max_orders", z->size.max_orders) != NULL &&
             (methods = cJSON_AddArrayToObject(item, "methods")) != NULL;
        for (int m = 0; ok && m < MC_METHODS; m++) {
            const mc_method_summary_t *ms = &z->m[m];
            cJSON *mo = cJSON_CreateObject();
            ok = mo != NULL && cJSON_AddItemToArray(methods, mo) &&
                 cJSON_AddStringToObject(mo, "method", method_names[m]) != NULL &&
                 cJSON_AddNumberToObject(mo, "solved", ms->solved) != NULL &&
                 cJSON_AddNumberToObject(mo, "infeasible", ms->infeasible) != NULL &&
                 cJSON_AddNumberToObject(mo, "budget_exhausted", ms->budget) != NULL &&
                 cJSON_AddNumberToObject(mo, "success_rate", ms->rate) != NULL &&
                 cJSON_AddNumberToObject(mo, "wilson_low", ms->low) != NULL &&
                 cJSON_AddNumberToObject(mo, "wilson_high", ms->high) != NULL &&
                 add_dist(mo, "time_ms", &ms->time_ms, false) &&
                 add_dist(mo, "nodes_expanded", &ms->expanded, false);
            if (ok && m != MC_CENTRALISED) {
                ok = add_dist(mo, "deviation_ratio", &ms->ratio, true) &&
                     cJSON_AddNumberToObject(mo, "fails_where_centralised_solves",
                                             ms->fails_where_central_solves) != NULL &&
                     cJSON_AddNumberToObject(mo, "solves_where_centralised_fails",
                                             ms->solves_where_central_fails) != NULL &&
                     cJSON_AddNumberToObject(mo, "mean_deviation_both_solved",
                                             ms->mean_deviation_both) != NULL &&
                     cJSON_AddNumberToObject(mo, "centralised_mean_deviation_both_solved",
                                             ms->central_mean_deviation_both) != NULL;
            }
        }
    }
    if (!ok) {
        cJSON_Delete(root);
        return -1;
    }
    return coavoid_output_json(f, root, NULL, 0);
}

/* ---- the figure ---- */

#define SVG_W 960.0
#define SVG_H 420.0
#define SVG_PANEL_TOP 60.0
#define SVG_PANEL_H 260.0
#define SVG_BAR_LEFT 70.0
#define SVG_BAR_W 330.0
#define SVG_CDF_LEFT 520.0
#define SVG_CDF_W 400.0

static const char *const method_colours[MC_METHODS] = {"#1f77b4", "#ff7f0e", "#2ca02c"};
static const char *const size_colours[MC_SIZES] = {"#1f77b4", "#d62728", "#2ca02c", "#9467bd",
                                                   "#8c564b"};

/* The ratio axis, logarithmic: from 1 to the largest ratio seen, at least 2 and at most
 * 10 (a longer tail is drawn against the edge and said in the caption). */
static double cdf_right(const mc_summary_t *s, uint32_t sizes)
{
    double right = 2.0;
    for (uint32_t k = 0; k < sizes; k++) {
        for (int m = MC_FIXED; m < MC_METHODS; m++) {
            if (s[k].m[m].ratio.count > 0 && s[k].m[m].ratio.max > right) {
                right = s[k].m[m].ratio.max;
            }
        }
    }
    return right > 10.0 ? 10.0 : right;
}

static double cdf_x(double v, double right)
{
    v = v > right ? right : v;
    return SVG_CDF_LEFT + log(v) / log(right) * SVG_CDF_W;
}

/* The step function of the ratio's CDF of one size and method, merging steps closer than
 * half a pixel so that 1000 encounters stay a few hundred points. */
static void svg_cdf(FILE *f, const mc_result_t *results, uint32_t count, int m, double right,
                    double *x, const char *colour, bool dashed)
{
    uint32_t both = 0;
    for (uint32_t j = 0; j < count; j++) {
        const mc_outcome_t *c = &results[j].m[MC_CENTRALISED], *d = &results[j].m[m];
        if (c->status == COA_PLAN_SOLVED && d->status == COA_PLAN_SOLVED) {
            x[both++] = cost_to_double(d->units) / cost_to_double(c->units);
        }
    }
    if (both == 0) {
        return;
    }
    qsort(x, both, sizeof *x, bench_compare_doubles);
    const double y0 = SVG_PANEL_TOP + SVG_PANEL_H;
    fprintf(f, "<polyline fill=\"none\" stroke=\"%s\" stroke-width=\"1.8\"%s points=\"", colour,
            dashed ? " stroke-dasharray=\"6 4\"" : "");
    double last_px = SVG_CDF_LEFT, last_py = y0;
    fprintf(f, "%.1f,%.1f", last_px, last_py);
    for (uint32_t j = 0; j < both;) {
        uint32_t k = j;
        while (k < both && x[k] == x[j]) {
            k++;
        }
        double px = cdf_x(x[j], right);
        double py = y0 - (double)k / both * SVG_PANEL_H;
        if (px - last_px >= 0.5 || k == both) {
            fprintf(f, " %.1f,%.1f %.1f,%.1f", px, last_py, px, py);
            last_px = px;
        }
        last_py = py;
        j = k;
    }
    fprintf(f, " %.1f,%.1f\"/>\n", SVG_CDF_LEFT + SVG_CDF_W, last_py);
}

/* The figure's header and title (seed, count, the betas used). */
static void svg_head(FILE *f, const mc_options_t *o, const mc_summary_t *s, uint32_t sizes)
{
    fprintf(f,
            "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
            "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"%.0f\" height=\"%.0f\" "
            "viewBox=\"0 0 %.0f %.0f\" font-family=\"sans-serif\" font-size=\"13\">\n"
            "<rect width=\"100%%\" height=\"100%%\" fill=\"white\"/>\n",
            SVG_W, SVG_H, SVG_W, SVG_H);
    char betas[64] = "";
    for (uint32_t k = 0, used = 0; k < sizes && used < sizeof betas; k++) {
        if (k == 0 || s[k].size.beta != s[k - 1].size.beta) {
            int w = snprintf(betas + used, sizeof betas - used, "%s%lu", k == 0 ? "" : "/",
                             (unsigned long)s[k].size.beta);
            used += w > 0 ? (uint32_t)w : 0u;
        }
    }
    fprintf(f,
            "<text x=\"%.0f\" y=\"24\" font-size=\"15\" font-weight=\"bold\">coavoid "
            "montecarlo: seed %llu, %lu encounters per UAV count, beta %s</text>\n",
            SVG_BAR_LEFT, (unsigned long long)o->seed, (unsigned long)o->count, betas);
}

/* Left: success rates, a group of three bars per UAV count, with Wilson intervals; budget
 * exhausted shown pale above a bar (unknown, not failed). */
static void svg_rates(FILE *f, const mc_summary_t *s, uint32_t sizes)
{
    const double y0 = SVG_PANEL_TOP + SVG_PANEL_H;
    fprintf(f,
            "<text x=\"%.0f\" y=\"%.0f\" font-weight=\"bold\">success rate (95%% Wilson "
            "interval)</text>\n",
            SVG_BAR_LEFT, SVG_PANEL_TOP - 10);
    for (int t = 0; t <= 10; t += 2) {
        double py = y0 - t / 10.0 * SVG_PANEL_H;
        fprintf(f,
                "<line x1=\"%.0f\" y1=\"%.1f\" x2=\"%.0f\" y2=\"%.1f\" stroke=\"#ddd\"/>\n"
                "<text x=\"%.0f\" y=\"%.1f\" text-anchor=\"end\">%d%%</text>\n",
                SVG_BAR_LEFT, py, SVG_BAR_LEFT + SVG_BAR_W, py, SVG_BAR_LEFT - 6, py + 4, t * 10);
    }
    double group = SVG_BAR_W / sizes, bar = group / (MC_METHODS + 1.5);
    for (uint32_t k = 0; k < sizes; k++) {
        double gx = SVG_BAR_LEFT + k * group + 0.75 * bar;
        for (int m = 0; m < MC_METHODS; m++) {
            const mc_method_summary_t *ms = &s[k].m[m];
            double bx = gx + m * bar, top = y0 - ms->rate * SVG_PANEL_H;
            double cx = bx + 0.45 * bar;
            if (ms->budget > 0) { /* above the bar, pale: unknown, not failed */
                double h = (double)ms->budget / s[k].encounters * SVG_PANEL_H;
                fprintf(f,
                        "<rect x=\"%.1f\" y=\"%.1f\" width=\"%.1f\" height=\"%.1f\" "
                        "fill=\"%s\" fill-opacity=\"0.3\"/>\n",
                        bx, top - h, 0.9 * bar, h, method_colours[m]);
            }
            fprintf(f,
                    "<rect x=\"%.1f\" y=\"%.1f\" width=\"%.1f\" height=\"%.1f\" "
                    "fill=\"%s\"/>\n"
                    "<line x1=\"%.1f\" y1=\"%.1f\" x2=\"%.1f\" y2=\"%.1f\" stroke=\"black\"/>\n",
                    bx, top, 0.9 * bar, y0 - top, method_colours[m], cx, y0 - ms->low * SVG_PANEL_H,
                    cx, y0 - ms->high * SVG_PANEL_H);
        }
        fprintf(f, "<text x=\"%.1f\" y=\"%.0f\" text-anchor=\"middle\">%lu UAVs</text>\n",
                gx + 1.5 * bar, y0 + 18, (unsigned long)s[k].size.n);
    }
    fprintf(f, "<line x1=\"%.0f\" y1=\"%.0f\" x2=\"%.0f\" y2=\"%.0f\" stroke=\"black\"/>\n",
            SVG_BAR_LEFT, y0, SVG_BAR_LEFT + SVG_BAR_W, y0);
    for (int m = 0; m < MC_METHODS; m++) {
        double ly = y0 + 44 + 16 * m;
        fprintf(f,
                "<rect x=\"%.0f\" y=\"%.0f\" width=\"12\" height=\"12\" fill=\"%s\"/>"
                "<text x=\"%.0f\" y=\"%.0f\">%s</text>\n",
                SVG_BAR_LEFT, ly - 10, method_colours[m], SVG_BAR_LEFT + 18, ly, method_names[m]);
    }
    fprintf(f, "<text x=\"%.0f\" y=\"%.0f\">pale above a bar: budget exhausted</text>\n",
            SVG_BAR_LEFT + 170, y0 + 44);
}

/* Right: the CDF of the deviation ratio per UAV count, fixed solid, reordered dashed. */
static void svg_ratios(FILE *f, const mc_options_t *o, const mc_run_t *run, const mc_summary_t *s,
                       uint32_t sizes, double *x)
{
    const double y0 = SVG_PANEL_TOP + SVG_PANEL_H;
    double right = cdf_right(s, sizes);
    fprintf(f,
            "<text x=\"%.0f\" y=\"%.0f\" font-weight=\"bold\">decoupled / centralised "
            "deviation, both solved (CDF)</text>\n",
            SVG_CDF_LEFT, SVG_PANEL_TOP - 10);
    for (int t = 0; t <= 4; t++) {
        double py = y0 - t / 4.0 * SVG_PANEL_H;
        fprintf(f,
                "<line x1=\"%.0f\" y1=\"%.1f\" x2=\"%.0f\" y2=\"%.1f\" stroke=\"#ddd\"/>\n"
                "<text x=\"%.0f\" y=\"%.1f\" text-anchor=\"end\">%.2f</text>\n",
                SVG_CDF_LEFT, py, SVG_CDF_LEFT + SVG_CDF_W, py, SVG_CDF_LEFT - 6, py + 4, t / 4.0);
    }
    static const double ticks[] = {1.0, 1.25, 1.5, 2.0, 3.0, 5.0, 10.0};
    for (size_t t = 0; t < sizeof ticks / sizeof ticks[0] && ticks[t] <= right * 1.0001; t++) {
        double px = cdf_x(ticks[t], right);
        fprintf(f,
                "<line x1=\"%.1f\" y1=\"%.0f\" x2=\"%.1f\" y2=\"%.0f\" stroke=\"#ddd\"/>\n"
                "<text x=\"%.1f\" y=\"%.0f\" text-anchor=\"middle\">%g</text>\n",
                px, SVG_PANEL_TOP, px, y0, px, y0 + 18, ticks[t]);
    }
    fprintf(f,
            "<text x=\"%.0f\" y=\"%.0f\" text-anchor=\"middle\">deviation ratio "
            "(log scale)</text>\n",
            SVG_CDF_LEFT + SVG_CDF_W / 2, y0 + 34);
    fprintf(f,
            "<text transform=\"translate(%.0f %.0f) rotate(-90)\" text-anchor=\"middle\">"
            "share of encounters</text>\n",
            SVG_CDF_LEFT - 44, SVG_PANEL_TOP + SVG_PANEL_H / 2);
    fprintf(f,
            "<rect x=\"%.0f\" y=\"%.0f\" width=\"%.0f\" height=\"%.0f\" fill=\"none\" "
            "stroke=\"black\"/>\n",
            SVG_CDF_LEFT, SVG_PANEL_TOP, SVG_CDF_W, SVG_PANEL_H);
    for (uint32_t k = 0; k < sizes; k++) {
        const mc_result_t *first = &run->results[k * o->count];
        const char *colour = size_colours[(s[k].size.n - ENCOUNTER_MIN_VEHICLES) % MC_SIZES];
        svg_cdf(f, first, o->count, MC_FIXED, right, x, colour, false);
        svg_cdf(f, first, o->count, MC_REORDERED, right, x, colour, true);
        double ly = y0 + 56 + 16 * k;
        fprintf(f,
                "<line x1=\"%.0f\" y1=\"%.0f\" x2=\"%.0f\" y2=\"%.0f\" stroke=\"%s\" "
                "stroke-width=\"2\"/><text x=\"%.0f\" y=\"%.0f\">%lu UAVs</text>\n",
                SVG_CDF_LEFT, ly - 4, SVG_CDF_LEFT + 24, ly - 4, colour, SVG_CDF_LEFT + 30, ly,
                (unsigned long)s[k].size.n);
    }
    fprintf(f,
            "<text x=\"%.0f\" y=\"%.0f\">solid: decoupled_fixed</text>\n"
            "<text x=\"%.0f\" y=\"%.0f\">dashed: decoupled_reordered</text>\n",
            SVG_CDF_LEFT + 110, y0 + 56, SVG_CDF_LEFT + 110, y0 + 72);
    if (right >= 10.0) {
        fprintf(f, "<text x=\"%.0f\" y=\"%.0f\">ratios above 10 at the right edge</text>\n",
                SVG_CDF_LEFT + 110, y0 + 88);
    }
}

static int write_svg(const char *path, const mc_options_t *o, const mc_run_t *run,
                     const mc_summary_t *s, uint32_t sizes, double *x)
{
    FILE *f = fopen(path, "w");
    if (f == NULL) {
        return -1;
    }
    svg_head(f, o, s, sizes);
    svg_rates(f, s, sizes);
    svg_ratios(f, o, run, s, sizes, x);
    fprintf(f, "</svg>\n");
    bool ok = !ferror(f);
    return fclose(f) == 0 && ok ? 0 : -1;
}

/* ---- the command ---- */

/* Each UAV count's beta and order limit; refused when its centralised planner cannot be
 * sized. */
static int mc_sizes(const mc_options_t *o, mc_size_t *sizes)
{
    for (uint32_t k = 0; k < o->size_count; k++) {
        uint32_t n = o->sizes[k];
        sizes[k].n = n;
        coa_planner_config_t shape = mc_config(n, CLI_DEFAULT_BETA);
        sizes[k].beta = o->beta_text != NULL ? o->beta : coavoid_cli_default_beta(&shape);
        sizes[k].max_orders = o->max_orders_text != NULL ? o->max_orders : factorial(n);
        shape.beta = sizes[k].beta;
        if (coa_planner_workspace_size(&shape) == 0) {
            return coavoid_cli_fail(CLI_EXIT_INVALID,
                                    "--beta: %lu is too large for %lu UAVs "
                                    "centralised (the node pool would pass 2^30)",
                                    (unsigned long)sizes[k].beta, (unsigned long)n);
        }
    }
    return CLI_CONTINUE;
}

/* The output files, checked before an hour's run rather than after: --save's directory,
 * --csv opened (in *csv) and --svg writable. */
static int mc_outputs(const mc_options_t *o, FILE **csv)
{
    struct stat info;
    if (o->save != NULL && (stat(o->save, &info) != 0 || !S_ISDIR(info.st_mode) ||
                            access(o->save, W_OK | X_OK) != 0)) {
        return coavoid_cli_fail(CLI_EXIT_INVALID,
                                "--save: '%.200s' is not a directory we can write in", o->save);
    }
    if (o->csv != NULL && (*csv = fopen(o->csv, "w")) == NULL) {
        return coavoid_cli_fail(CLI_EXIT_INVALID, "--csv: cannot write '%.200s'", o->csv);
    }
    if (o->svg != NULL) {
        FILE *probe = fopen(o->svg, "w");
        if (probe == NULL) {
            return coavoid_cli_fail(CLI_EXIT_INVALID, "--svg: cannot write '%.200s'", o->svg);
        }
        fclose(probe);
    }
    return CLI_CONTINUE;
}

/* Closes --csv's file; a write that failed is an error unless one came first. */
static int mc_close_csv(const mc_options_t *o, FILE *csv, int status)
{
    if (csv == NULL) {
        return status;
    }
    bool ok = !ferror(csv);
    if ((fclose(csv) != 0 || !ok) && status == CLI_CONTINUE) {
        return coavoid_cli_fail(CLI_EXIT_INTERNAL, "--csv: cannot write '%.200s'", o->csv);
    }
    return status;
}

/* The summaries of every UAV count, the figure and the table; the exit status. */
static int mc_report(const mc_options_t *o, mc_run_t *run, double *x)
{
    bool defects = false;
    for (uint32_t j = 0; j < run->total; j++) {
        defects = defects || run->results[j].defect[0] != '\0';
    }
    mc_summary_t summary[MC_SIZES];
    for (uint32_t k = 0; k < o->size_count; k++) {
        summarise(&run->results[k * o->count], o->count, &run->sizes[k], x, &summary[k]);
    }
    if (o->svg != NULL && write_svg(o->svg, o, run, summary, o->size_count, x) != 0) {
        return coavoid_cli_fail(CLI_EXIT_INTERNAL, "--svg: cannot write '%.200s'", o->svg);
    }
    int rc = 0;
    if (o->json) {
        rc = json_summary(stdout, o, summary, o->size_count);
    } else {
        text_summary(stdout, o, summary, o->size_count);
    }
    if (rc != 0 || fflush(stdout) != 0 || ferror(stdout)) {
        return coavoid_cli_fail(CLI_EXIT_INTERNAL, "cannot write the summary");
    }
    return defects ? coavoid_cli_fail(CLI_EXIT_INTERNAL, "montecarlo: defects found (above)")
                   : CLI_EXIT_OK;
}

int coavoid_command_montecarlo(int argc, char **argv)
{
    mc_options_t o;
    int status = parse_mc_options(argc, argv, &o);
    if (status != CLI_CONTINUE) {
        return status;
    }
    mc_size_t sizes[MC_SIZES];
    FILE *csv = NULL;
    status = mc_sizes(&o, sizes);
    if (status == CLI_CONTINUE) {
        status = mc_outputs(&o, &csv);
    }
    if (status != CLI_CONTINUE) {
        if (csv != NULL) {
            fclose(csv);
        }
        return status;
    }
    mc_run_t run;
    memset(&run, 0, sizeof run);
    run.o = &o;
    run.sizes = sizes;
    run.total = o.count * o.size_count;
    run.results = calloc(run.total, sizeof *run.results);
    run.done = calloc(run.total, sizeof *run.done);
    double *x = calloc(o.count, sizeof *x);
    if (run.results == NULL || run.done == NULL || x == NULL) {
        status = coavoid_cli_fail(CLI_EXIT_INVALID, "--count: out of memory for %lu encounters",
                                  (unsigned long)run.total);
    }
    if (status == CLI_CONTINUE && csv != NULL && fputs(MC_CSV_HEADER, csv) < 0) {
        status = coavoid_cli_fail(CLI_EXIT_INTERNAL, "--csv: cannot write '%.200s'", o.csv);
    }
    if (status == CLI_CONTINUE) {
        status = run_all(&run, csv);
    }
    status = mc_close_csv(&o, csv, status);
    if (status == CLI_CONTINUE) {
        status = mc_report(&o, &run, x);
    }
    free(x);
    free(run.done);
    free(run.results);
    return status;
}
