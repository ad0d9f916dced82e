/* SPDX-License-Identifier: MIT */
/*
 * coavoid plan: reads a scenario (docs/scenario-format.md), plans altitude manoeuvres
 * centrally or decoupled, and prints the plan result as JSON. See PLAN_USAGE below.
 */
#define _POSIX_C_SOURCE 200809L

#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "cli.h"
#include "commands.h"
#include "coavoid/coavoid.h"
#include "output.h"
#include "scenario.h"

/* How many priority orders --reorder tries unless --max-orders says otherwise. n UAVs have
 * n! orders and a failing order costs up to n searches, so an unbounded search can run for
 * hours (12! is 479 million); 7! tries every order of up to 7 UAVs, which is still well
 * under a second for small problems, and bounds the rest. */
#define COAVOID_DEFAULT_MAX_ORDERS 5040u
#define COAVOID_DEFAULT_MAX_ORDERS_COVER 7u /* the UAV count whose orders it covers */
_Static_assert(COAVOID_DEFAULT_MAX_ORDERS == 7u * 6u * 5u * 4u * 3u * 2u * 1u &&
                   COAVOID_DEFAULT_MAX_ORDERS_COVER == 7u,
               "the default max orders is COAVOID_DEFAULT_MAX_ORDERS_COVER factorial");

/* A printf format so that the limits it quotes come from one place. */
#define PLAN_USAGE                                                                            \
    "usage: coavoid plan SCENARIO.json --mode centralised|decoupled\n"                        \
    "                    [--priority ID,ID,...] [--beta N] [--reorder [--max-orders N]]\n"    \
    "\n"                                                                                      \
    "Reads a scenario (JSON, at most %u MiB) and prints the plan result as JSON.\n"           \
    "\n"                                                                                      \
    "options:\n"                                                                              \
    "  --mode centralised  optimal for all UAVs together (at most %u UAVs)\n"                 \
    "  --mode decoupled    each UAV in turn, in priority order\n"                             \
    "  --priority ID,...   decoupled: plan in this order (every vehicle id exactly once)\n"   \
    "  --beta N            nodes a joint search may store, N >= 1; overrides the\n"           \
    "                      scenario's \"beta\"; default %u, lowered so the workspace stays\n" \
    "                      within 1 GiB (a node is 70 + 2 bytes per UAV)\n"                   \
    "  --reorder           decoupled: when a UAV fails, try other priority orders\n"          \
    "  --max-orders N      with --reorder: try at most N orders, N >= 1; default %u\n"        \
    "                      (every order of up to %u UAVs); stats.all_orders_covered\n"        \
    "                      says whether a failure is proven for every order\n"                \
    "  -h, --help          show this help\n"                                                  \
    "\n"                                                                                      \
    "Fields of the scenario that the format does not define are ignored.\n"                   \
    "\n"                                                                                      \
    "exit status: 0 solved, 1 infeasible or budget exhausted, 2 invalid input or usage\n"     \
    "(one line on stderr naming the input and why), 3 internal error\n"

/* ---- options ---- */

typedef struct {
    const char *scenario_path;
    const char *mode; /* NULL until given */
    bool decoupled;
    const char *priority; /* NULL: priority order */
    const char *beta_text;
    uint32_t beta;
    bool reorder;
    const char *max_orders_text; /* NULL: COAVOID_DEFAULT_MAX_ORDERS */
    uint32_t max_orders;
} plan_options_t;

static void plan_help(void)
{
    printf(PLAN_USAGE, SCENARIO_MAX_BYTES / (1024u * 1024u), COA_MAX_CENTRALISED,
           COAVOID_DEFAULT_BETA, COAVOID_DEFAULT_MAX_ORDERS, COAVOID_DEFAULT_MAX_ORDERS_COVER);
}

static int plan_option(int argc, char **argv, int *i, void *options)
{
    plan_options_t *o = options;
    const char *arg = argv[*i];
    uint64_t value = 0;
    int status = CLI_UNKNOWN_OPTION;
    if (coavoid_cli_option_is(arg, "--mode")) {
        status = coavoid_cli_mode_option(argc, argv, i, &o->mode, &o->decoupled);
    } else if (coavoid_cli_option_is(arg, "--priority")) {
        status = coavoid_cli_text_option(argc, argv, i, "--priority", "vehicle ids, e.g. 3,1,2",
                                         true, &o->priority);
    } else if (coavoid_cli_option_is(arg, "--beta")) {
        status = coavoid_cli_count_option(argc, argv, i, "--beta", "an integer >= 1", false,
                                          UINT32_MAX, &o->beta_text, &value);
        o->beta = (uint32_t)value;
    } else if (coavoid_cli_option_is(arg, "--reorder")) {
        status = coavoid_cli_flag_option(arg, "--reorder", &o->reorder);
    } else if (coavoid_cli_option_is(arg, "--max-orders")) {
        status = coavoid_cli_count_option(argc, argv, i, "--max-orders", "an integer >= 1", false,
                                          UINT32_MAX, &o->max_orders_text, &value);
        o->max_orders = (uint32_t)value;
    }
    return status;
}

static const coavoid_cli_command_t plan_command = {
    "plan",    "coavoid plan", 2, {"SCENARIO.json", NULL}, "one scenario only",
    plan_help, plan_option};

/* Returns CLI_CONTINUE, or the exit status (help printed: 0; a usage error: 2). */
static int parse_plan_options(int argc, char **argv, plan_options_t *o)
{
    memset(o, 0, sizeof *o);
    int status = coavoid_cli_parse_args(&plan_command, argc, argv, o, &o->scenario_path);
    if (status != CLI_CONTINUE) {
        return status;
    }
    if (o->mode == NULL) {
        return coavoid_cli_fail(CLI_EXIT_INVALID, "--mode: required (centralised or decoupled)");
    }
    /* Centralised plans everyone in one search: an order would mean nothing, so asking
     * for one is more likely a mistake than something to ignore. */
    if (!o->decoupled && o->priority != NULL) {
        return coavoid_cli_fail(CLI_EXIT_INVALID, "--priority: only valid with --mode decoupled");
    }
    if (!o->decoupled && o->reorder) {
        return coavoid_cli_fail(CLI_EXIT_INVALID, "--reorder: only valid with --mode decoupled");
    }
    /* Without --reorder exactly one order is planned: a bound on orders would do nothing. */
    if (o->max_orders_text != NULL && !o->reorder) {
        return coavoid_cli_fail(CLI_EXIT_INVALID,
                                "--max-orders: only valid with --reorder (and --mode decoupled)");
    }
    if (o->max_orders_text == NULL) {
        o->max_orders = COAVOID_DEFAULT_MAX_ORDERS;
    }
    return CLI_CONTINUE;
}

/* --priority as vehicle indices into order[0..n-1]: a permutation of the ids. Returns
 * CLI_CONTINUE when valid, else the exit status after the message. */
static int parse_priority(const char *text, const coavoid_scenario_t *s, size_t *order)
{
    bool listed[COA_MAX_VEHICLES] = {false};
    size_t count = 0;
    const char *token = text;
    for (;;) {
        const char *comma = strchr(token, ',');
        size_t length = comma != NULL ? (size_t)(comma - token) : strlen(token);
        uint64_t id;
        if (!coavoid_cli_parse_count(token, length, 65535u, &id)) {
            if (text[0] == '\0') {
                return coavoid_cli_fail(CLI_EXIT_INVALID,
                                        "--priority: empty (expected vehicle ids separated "
                                        "by commas)");
            }
            if (length == 0) {
                return coavoid_cli_fail(CLI_EXIT_INVALID,
                                        "--priority: empty entry in '%.80s' "
                                        "(expected vehicle ids separated by commas)",
                                        text);
            }
            return coavoid_cli_fail(CLI_EXIT_INVALID, "--priority: '%.*s' is not a vehicle id",
                                    (int)(length > 40 ? 40 : length), token);
        }
        long index = coavoid_scenario_vehicle_index(s, (long)id);
        if (index < 0) {
            return coavoid_cli_fail(CLI_EXIT_INVALID, "--priority: %lu is not a vehicle id",
                                    (unsigned long)id);
        }
        if (listed[index]) {
            return coavoid_cli_fail(CLI_EXIT_INVALID, "--priority: %lu is listed twice",
                                    (unsigned long)id);
        }
        listed[index] = true;
        order[count++] = (size_t)index;
        if (comma == NULL) {
            break;
        }
        token = comma + 1;
    }
    for (size_t i = 0; i < s->vehicle_count; i++) {
        if (!listed[i]) {
            return coavoid_cli_fail(CLI_EXIT_INVALID,
                                    "--priority: vehicle %u is missing (list every id once)",
                                    (unsigned)s->vehicles[i].id);
        }
    }
    return CLI_CONTINUE;
}

/* The core's COA_ERR_RANGE from the problem check or the planner. Weights that cannot be
 * exact (the only cause the current limits allow) are named by the parser first, so what
 * is left is the worst-case cost over the horizon outgrowing the core's exact integers:
 * horizon is what the user is most likely to change. A backstop. */
static int range_error(const char *file, const coavoid_scenario_t *s)
{
    return coavoid_cli_fail(
        CLI_EXIT_INVALID,
        "%s: horizon: %lu steps is too long for these vehicles' offsets and costs "
        "(beyond the core's integer range; shorten it or bound max_offset)",
        file, (unsigned long)s->horizon);
}

/* beta from --beta, else the scenario, else the default; *source names it for messages. */
static uint32_t choose_beta(const plan_options_t *o, const coavoid_scenario_t *s, size_t searched,
                            char *source, size_t source_size)
{
    if (o->beta_text != NULL) {
        snprintf(source, source_size, "--beta %lu", (unsigned long)o->beta);
        return o->beta;
    }
    if (s->has_beta) {
        snprintf(source, source_size, "%.400s: beta %lu", o->scenario_path, (unsigned long)s->beta);
        return s->beta;
    }
    coa_planner_config_t shape = coavoid_scenario_planner_config(s, searched, COAVOID_DEFAULT_BETA);
    uint32_t beta = coavoid_default_beta(&shape);
    snprintf(source, source_size, "default beta %lu", (unsigned long)beta);
    return beta;
}

/* Everything after the scenario is loaded. Returns the exit status. */
/* The planner for `searched` UAVs at `beta`, in a workspace of its exact size, and the
 * offsets' rows; *workspace and *offsets are the caller's to free, also on failure. */
static int plan_allocate(const char *file, const char *beta_source, const coavoid_scenario_t *s,
                         size_t searched, uint32_t beta, void **workspace, int32_t **offsets,
                         coa_planner_t **planner)
{
    coa_planner_config_t config = coavoid_scenario_planner_config(s, searched, beta);
    /* The tables alone (every reachable step and offset) do not depend on beta: when they
     * pass the limit no beta helps, whatever --beta or the scenario say. */
    if (beta == 0 || coa_planner_max_beta(&config, COAVOID_DEFAULT_WORKSPACE_MAX) == 0) {
        return coavoid_cli_fail(
            CLI_EXIT_INVALID,
            "%s: too large: the cost-to-go tables of a %lu-step horizon would not "
            "fit in %zu MiB of workspace (shorten the horizon or bound max_offset)",
            file, (unsigned long)s->horizon, COAVOID_DEFAULT_WORKSPACE_MAX >> 20);
    }
    size_t size = coa_planner_workspace_size(&config);
    if (size == 0) {
        return coavoid_cli_fail(
            CLI_EXIT_INVALID,
            "%s: too large: the workspace for %zu vehicle(s) over %lu steps would "
            "not fit in memory (lower it with --beta)",
            beta_source, searched, (unsigned long)s->horizon);
    }
    *workspace = malloc(size);
    if (*workspace == NULL) {
        return coavoid_cli_fail(CLI_EXIT_INVALID,
                                "%s: cannot allocate %zu bytes of workspace for %zu vehicle(s) "
                                "(lower it with --beta)",
                                beta_source, size, searched);
    }
    *planner = coa_planner_init(*workspace, size, &config);
    *offsets = calloc(s->vehicle_count * ((size_t)s->horizon + 1u), sizeof **offsets);
    if (*planner == NULL || *offsets == NULL) {
        return coavoid_cli_fail(CLI_EXIT_INTERNAL, "%s",
                                *planner == NULL
                                    ? "internal error: the planner refused its workspace"
                                    : "out of memory for the plan");
    }
    return CLI_CONTINUE;
}

/* The scenario sampled and accepted by the core's problem check. */
static int plan_problem(const char *file, coavoid_scenario_t *s, coa_problem_t *problem)
{
    int rc = coavoid_cli_sample_scenario(file, s);
    if (rc != CLI_CONTINUE) {
        return rc;
    }
    *problem = coavoid_scenario_problem(s);
    rc = coa_problem_check(problem);
    if (rc == COA_ERR_RANGE) {
        return range_error(file, s);
    }
    if (rc != COA_OK) {
        return coavoid_cli_fail(CLI_EXIT_INVALID, "%s: rejected by the core's problem check (%s)",
                                file, coa_status_name(rc));
    }
    return CLI_CONTINUE;
}

/* Plans in the mode asked for and prints the result; the exit status. */
static int plan_run(const plan_options_t *o, const coavoid_scenario_t *s,
                    const coa_problem_t *problem, const size_t *order, coa_planner_t *planner,
                    int32_t *offsets, uint32_t beta)
{
    char err[SCENARIO_ERROR_MAX];
    coa_plan_result_t result;
    memset(&result, 0, sizeof result);
    struct timespec start, end;
    int rc;
    clock_gettime(CLOCK_MONOTONIC, &start);
    if (o->decoupled) {
        rc = coa_plan_decoupled(planner, problem, order, o->reorder ? o->max_orders : 1u, offsets,
                                &result);
    } else {
        rc = coa_plan_centralised(planner, problem, offsets, &result);
    }
    clock_gettime(CLOCK_MONOTONIC, &end);
    if (rc == COA_ERR_RANGE) {
        return range_error(o->scenario_path, s);
    }
    if (rc != COA_OK) {
        return coavoid_cli_fail(CLI_EXIT_INTERNAL, "internal error: the planner failed (%s)",
                                coa_status_name(rc));
    }
    coavoid_output_plan_t view = {
        s, o->decoupled, &result, offsets, coavoid_cli_elapsed_us(&start, &end), beta};
    if (coavoid_output_plan(stdout, &view, err, sizeof err) != 0) {
        return coavoid_cli_fail(CLI_EXIT_INTERNAL, "%s", err);
    }
    return result.status == COA_PLAN_SOLVED ? CLI_EXIT_OK : CLI_EXIT_NOT_SOLVED;
}

static int plan(void *options, coavoid_scenario_t *s)
{
    const plan_options_t *o = options;
    const char *file = o->scenario_path;
    size_t order_storage[COA_MAX_VEHICLES];
    const size_t *order = NULL;
    const size_t n = s->vehicle_count;
    if (o->priority != NULL) {
        int status = parse_priority(o->priority, s, order_storage);
        if (status != CLI_CONTINUE) {
            return status;
        }
        order = order_storage;
    }
    if (!o->decoupled && n > COA_MAX_CENTRALISED) {
        return coavoid_cli_fail(
            CLI_EXIT_INVALID,
            "--mode centralised: %zu vehicles, at most %u (COA_MAX_CENTRALISED) can be "
            "planned together",
            n, COA_MAX_CENTRALISED);
    }
    const size_t searched = o->decoupled ? 1u : n;
    char beta_source[SCENARIO_ERROR_MAX];
    uint32_t beta = choose_beta(o, s, searched, beta_source, sizeof beta_source);
    coa_problem_t problem;
    int status = plan_problem(file, s, &problem);
    if (status != CLI_CONTINUE) {
        return status;
    }
    void *workspace = NULL;
    int32_t *offsets = NULL;
    coa_planner_t *planner = NULL;
    status = plan_allocate(file, beta_source, s, searched, beta, &workspace, &offsets, &planner);
    if (status == CLI_CONTINUE) {
        status = plan_run(o, s, &problem, order, planner, offsets, beta);
    }
    free(workspace);
    free(offsets);
    return status;
}

int coavoid_command_plan(int argc, char **argv)
{
    plan_options_t options;
    int status = parse_plan_options(argc, argv, &options);
    if (status != CLI_CONTINUE) {
        return status;
    }
    return coavoid_cli_run_scenario(options.scenario_path, plan, &options);
}
