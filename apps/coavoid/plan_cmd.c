/* SPDX-License-Identifier: MIT */
/*
 * coavoid plan: its options, and --priority's ids as an order; the plan is
 * coavoid::scenario's (run.h, coavoid_scenario_plan). See PLAN_USAGE below.
 */
#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include "cli.h"
#include "coavoid/coavoid.h"
#include "commands.h"
#include "run.h"
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
    "                    [--priority ID,ID,...] [--beta N] [--work W]\n"                      \
    "                    [--reorder [--max-orders N]]\n"                                      \
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
    "  --work W            work units the planning call may spend (10-40 ns each),\n"         \
    "                      W >= 0, 0 for no limit; default %llu; centralised, the best\n"     \
    "                      plan found by then is the answer, with its lower bound\n"          \
    "  --reorder           decoupled: when a UAV fails, try other priority orders\n"          \
    "  --max-orders N      with --reorder: try at most N orders, N >= 1; default %u\n"        \
    "                      (every order of up to %u UAVs); stats.all_orders_covered\n"        \
    "                      says whether a failure is proven for every order\n"                \
    "  -h, --help          show this help\n"                                                  \
    "      --version       print the version\n"                                               \
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
    const char *work_text; /* NULL: COAVOID_DEFAULT_WORK */
    uint64_t work;
    bool reorder;
    const char *max_orders_text; /* NULL: COAVOID_DEFAULT_MAX_ORDERS */
    uint32_t max_orders;
} plan_options_t;

static void plan_help(void)
{
    printf(PLAN_USAGE, COAVOID_SCENARIO_MAX_BYTES / (1024u * 1024u), COA_MAX_CENTRALISED,
           COAVOID_DEFAULT_BETA, (unsigned long long)COAVOID_DEFAULT_WORK,
           COAVOID_DEFAULT_MAX_ORDERS, COAVOID_DEFAULT_MAX_ORDERS_COVER);
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
    } else if (coavoid_cli_option_is(arg, "--work")) {
        status = coavoid_cli_count_option(argc, argv, i, "--work", "an integer >= 0", true,
                                          UINT64_MAX, &o->work_text, &o->work);
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
    "plan",    "coavoid plan", 2,    {"SCENARIO.json", NULL}, "one scenario only",
    plan_help, plan_option,    false};

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

static int plan(void *options, coavoid_scenario_t *s)
{
    const plan_options_t *o = options;
    size_t order[COA_MAX_VEHICLES];
    if (o->priority != NULL) {
        int status = parse_priority(o->priority, s, order);
        if (status != CLI_CONTINUE) {
            return status;
        }
    }
    const coavoid_plan_config_t config = {
        .scenario_path = o->scenario_path,
        .decoupled = o->decoupled,
        .order = o->priority != NULL ? order : NULL,
        .has_beta = o->beta_text != NULL,
        .beta = o->beta,
        .work = o->work_text != NULL ? o->work : COAVOID_DEFAULT_WORK,
        .max_orders = o->reorder ? o->max_orders : 1u,
    };
    coavoid_run_error_t e;
    int rc = coavoid_scenario_plan(&config, s, stdout, &e);
    return coavoid_cli_run_status(rc, &e);
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
