/* SPDX-License-Identifier: MIT */
/*
 * coavoid bench plan: its options (BENCH_PLAN_USAGE below). The harness, which loads the
 * paper scenario, draws the random encounters (encounter.h, design
 * coavoid_encounter_bench), times the planner on them and reports, is
 * coavoid::evaluation's (bench_plan.h, docs/benchmarks.md, "Planning").
 */
#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include "bench_plan.h"
#include "cli.h"
#include "commands.h"
#include "encounter.h"
#include "scenario.h"

#define BP_DEFAULT_SEED 1u
#define BP_DEFAULT_REPEAT 5u
#define BP_DEFAULT_COUNT 5u
#define BP_MAX_REPEAT 10000u
#define BP_MAX_COUNT 10000u
#define BP_MIN_VEHICLES COAVOID_ENCOUNTER_MIN_VEHICLES
#define BP_MAX_VEHICLES COAVOID_ENCOUNTER_MAX_VEHICLES
/* Without --vehicles a run times the sets up to 5 UAVs; 6 only on request, since one
 * 6-UAV set takes minutes where the others take seconds (docs/benchmarks.md). */
#define BP_DEFAULT_MAX_VEHICLES 5u
_Static_assert(BP_MIN_VEHICLES == 2u && BP_MAX_VEHICLES == 10u, "--vehicles' hint says 2 to 10");
#define BP_DEFAULT_SCENARIO "scenarios/paper.json"
#define BP_HORIZON coavoid_encounter_bench.horizon
#define BP_DT coavoid_encounter_bench.dt

#define BENCH_PLAN_USAGE                                                                    \
    "usage: coavoid bench plan [--vehicles N] [--count C] [--seed S] [--repeat R]\n"        \
    "                          [--beta B] [--work W] [--scenario FILE] [--save DIR]\n"      \
    "                          [--json]\n"                                                  \
    "\n"                                                                                    \
    "Times the planner, centralised and decoupled, on the paper scenario and on C random\n" \
    "encounters each of 2, 3, 4 and 5 UAVs converging on one point (staggered\n"            \
    "altitudes, half with a terrain box; %u steps of %g s), or on the N-UAV (2 to 10)\n"    \
    "encounters only with --vehicles. One run plans every problem of a set once; prints\n"  \
    "per set and mode the median, min and max run time over R runs, the median and\n"       \
    "largest time of one problem, the nodes expanded, nodes per second, the work, the\n"    \
    "workspace, the outcomes (centralised: proven optimal or bounded) and the median\n"     \
    "ratio of a centralised plan to its lower bound (a table, or a JSON object with\n"      \
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
    "  --work W         work units each planning call may spend, 0 for no limit;\n"         \
    "                   default %llu (as coavoid plan's)\n"                                 \
    "  --scenario FILE  the scenario timed as 'paper' (without --vehicles);\n"              \
    "                   default %s, relative to the working directory\n"                    \
    "  --save DIR       write each random encounter as DIR/bench-SEED-N-INDEX.json (an\n"   \
    "                   existing directory), for `coavoid plan` to replay\n"                \
    "  --json           print a JSON object instead of a table\n"                           \
    "  -h, --help       show this help\n"                                                   \
    "      --version    print the version\n"                                                \
    "\n"                                                                                    \
    "A benchmark is deterministic for a seed except for its times.\n"                       \
    "\n"                                                                                    \
    "exit status: 0 done (whatever the plans' outcomes), 2 invalid usage or input (one\n"   \
    "line on stderr naming the option and why), 3 internal error\n"

static void bench_plan_help(void)
{
    printf(BENCH_PLAN_USAGE, BP_HORIZON, BP_DT, BP_MIN_VEHICLES, BP_MAX_VEHICLES, BP_MAX_COUNT,
           BP_DEFAULT_COUNT, BP_DEFAULT_SEED, BP_MAX_REPEAT, BP_DEFAULT_REPEAT,
           COAVOID_DEFAULT_BETA, (unsigned long long)COAVOID_DEFAULT_WORK, BP_DEFAULT_SCENARIO);
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
    const char *work_text; /* NULL: COAVOID_DEFAULT_WORK */
    uint64_t work;
    const char *scenario;
    const char *save;
    bool json;
} bp_options_t;

static int bp_option(int argc, char **argv, int *i, void *options)
{
    bp_options_t *o = options;
    const char *arg = argv[*i];
    uint64_t value = 0;
    int status = CLI_UNKNOWN_OPTION;
    if (coavoid_cli_option_is(arg, "--vehicles")) {
        /* 2..10, which coavoid_cli_count_option (1..max) cannot say. */
        status = coavoid_cli_text_option(argc, argv, i, "--vehicles", "an integer from 2 to 10",
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
    } else if (coavoid_cli_option_is(arg, "--work")) {
        status = coavoid_cli_count_option(argc, argv, i, "--work", "an integer >= 0", true,
                                          UINT64_MAX, &o->work_text, &o->work);
    } else if (coavoid_cli_option_is(arg, "--scenario")) {
        status = coavoid_cli_text_option(argc, argv, i, "--scenario", "a scenario file", false,
                                         &o->scenario);
    } else if (coavoid_cli_option_is(arg, "--save")) {
        status = coavoid_cli_text_option(argc, argv, i, "--save", "a directory", false, &o->save);
    } else if (coavoid_cli_option_is(arg, "--json")) {
        status = coavoid_cli_flag_option(arg, "--json", &o->json);
    }
    return status;
}

/* bench's argv[2] is the benchmark's name, so options start at argv[3]. */
static const coavoid_cli_command_t bench_plan_command = {"bench plan",
                                                         "coavoid bench plan",
                                                         3,
                                                         {NULL, NULL},
                                                         "it takes options only",
                                                         bench_plan_help,
                                                         bp_option,
                                                         false};

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

int coavoid_bench_plan(int argc, char **argv)
{
    bp_options_t o;
    int status = parse_bp_options(argc, argv, &o);
    if (status != CLI_CONTINUE) {
        return status;
    }
    /* Without --vehicles: the scenario, then the encounters of every UAV count up to the
     * default's. */
    bool all = o.vehicles_text == NULL;
    coavoid_bench_plan_config_t config;
    memset(&config, 0, sizeof config);
    config.scenario = all ? o.scenario : NULL;
    config.min_vehicles = all ? BP_MIN_VEHICLES : o.vehicles;
    config.max_vehicles = all ? BP_DEFAULT_MAX_VEHICLES : o.vehicles;
    config.count = o.count;
    config.seed = o.seed;
    config.repeat = o.repeat;
    config.beta = o.beta_text != NULL ? o.beta : 0u; /* 0: the scenario's, or the default */
    config.work = o.work_text != NULL ? o.work : COAVOID_DEFAULT_WORK;
    config.save = o.save;
    coavoid_bench_plan_result_t result;
    coavoid_run_error_t e;
    int rc = coavoid_bench_plan_run(&config, &result, &e);
    if (rc != COAVOID_RUN_DONE) {
        return coavoid_cli_run_status(rc, &e);
    }
    return coavoid_bench_plan_report(stdout, &config, &result, o.json) == 0
               ? CLI_EXIT_OK
               : coavoid_cli_fail(CLI_EXIT_INTERNAL, "cannot write the result");
}
