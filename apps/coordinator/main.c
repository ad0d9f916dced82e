/* SPDX-License-Identifier: MIT */
/*
 * coavoid-coordinator: the ground station as a process of its own. Every cycle, a
 * collection time after the cycle starts, it predicts from the intents the vehicles
 * published, plans each conflicting cluster in one centralised search, and publishes the
 * plans, the conflict report and its heartbeat. The node is src/node/coordinator.c; this
 * file only reads the options and runs it in real time (realtime.h). See
 * COORDINATOR_USAGE below.
 */
#define _POSIX_C_SOURCE 200809L

#include <math.h>
#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include "cli.h"
#include "node.h"
#include "drivers.h"
#include "scenario.h"

#define COORDINATOR_DEFAULT_MAX_CENTRALISED 3u

#define COORDINATOR_USAGE                                                                         \
    "usage: coavoid-coordinator SCENARIO.json [--lcm-url URL] [--epoch UTIME] [--speed S]\n"      \
    "                           [--steps K] [--beta B] [--max-centralised N] [--collect S]\n"     \
    "                           (--key FILE --trust FILE | --insecure)\n"                         \
    "\n"                                                                                          \
    "The ground coordinator of a real-time run: plans the conflicting clusters of the\n"          \
    "vehicles it hears over LCM centrally and publishes the plans. The scenario gives dt,\n"      \
    "the horizon and the default beta; the vehicles and obstacles come from the messages.\n"      \
    "\n"                                                                                          \
    "options:\n"                                                                                  \
    "  SCENARIO.json       the scenario (docs/scenario-format.md); --scenario FILE, its\n"        \
    "                      old spelling, works with a warning\n" COAVOID_RT_OPTIONS_USAGE         \
    "  --beta B            nodes a joint search of its planner stores, B >= 1; default the\n"     \
    "                      scenario's \"beta\", else %u lowered so the workspace fits 1 GiB\n"    \
    "  --max-centralised N largest cluster planned centrally, 1..%u (default %u); the\n"          \
    "                      workspace grows by about 20 kB per UAV; a larger cluster is planned\n" \
    "                      decoupled by the coordinator\n"                                        \
    "  --collect S         scenario seconds after each cycle start at which it plans,\n"          \
    "                      0 < S < dt; default dt / 4. Its plans must reach the vehicles\n"       \
    "                      before the next cycle starts: planning gets (dt - S) / speed\n"        \
    "                      wall seconds\n"                                                        \
    "  -h, --help          show this help\n"                                                      \
    "      --version       print the version\n"                                                   \
    "\n"                                                                                          \
    "At the end (after K cycles, or on SIGINT/SIGTERM) it prints one summary line on\n"           \
    "stderr.\n"                                                                                   \
    "\n"                                                                                          \
    "exit status: 0 done, 2 invalid input or usage (one line on stderr), 3 internal error\n"

typedef struct {
    const char *scenario_path;
    const char *beta_text;
    uint32_t beta;
    const char *max_text;
    size_t max_centralised;
    const char *collect_text;
    double collect;
    coavoid_rt_options_t rt;
} coordinator_options_t;

static void coordinator_help(void)
{
    printf(COORDINATOR_USAGE, COAVOID_DEFAULT_BETA, COA_MAX_CENTRALISED,
           COORDINATOR_DEFAULT_MAX_CENTRALISED);
}

static int coordinator_option(int argc, char **argv, int *i, void *options)
{
    coordinator_options_t *o = options;
    const char *arg = argv[*i];
    uint64_t value = 0;
    int status = coavoid_rt_driver_option(argc, argv, i, &o->rt, &o->scenario_path);
    if (status != CLI_UNKNOWN_OPTION) {
        return status;
    }
    if (coavoid_cli_option_is(arg, "--beta")) {
        status = coavoid_cli_count_option(argc, argv, i, "--beta", "an integer >= 1", false,
                                          UINT32_MAX, &o->beta_text, &value);
        o->beta = (uint32_t)value;
    } else if (coavoid_cli_option_is(arg, "--max-centralised")) {
        status = coavoid_cli_count_option(argc, argv, i, "--max-centralised", NULL, false,
                                          COA_MAX_CENTRALISED, &o->max_text, &value);
        o->max_centralised = (size_t)value;
    } else if (coavoid_cli_option_is(arg, "--collect")) {
        status = coavoid_cli_text_option(argc, argv, i, "--collect", "scenario seconds", true,
                                         &o->collect_text);
        if (status == CLI_CONTINUE &&
            (!coavoid_cli_parse_real(o->collect_text, &o->collect) || !(o->collect > 0))) {
            status = coavoid_cli_fail(CLI_EXIT_INVALID,
                                      "--collect: must be a number of seconds > 0, got '%.40s'",
                                      o->collect_text);
        }
    }
    return status;
}

static const coavoid_cli_command_t coordinator_command = {
    "coordinator",    "coavoid-coordinator", 1,   {"SCENARIO.json", NULL}, "one scenario only",
    coordinator_help, coordinator_option,    true};

static int parse_options(int argc, char **argv, coordinator_options_t *o)
{
    memset(o, 0, sizeof *o);
    coavoid_rt_options_init(&o->rt);
    o->max_centralised = COORDINATOR_DEFAULT_MAX_CENTRALISED;
    const char *scenario = NULL;
    int status = coavoid_cli_parse_args(&coordinator_command, argc, argv, o, &scenario);
    if (status != CLI_CONTINUE) {
        return status;
    }
    return coavoid_cli_scenario_given(&coordinator_command, scenario, &o->scenario_path);
}

static void coordinator_report(void *user, const char *name, const coavoid_rt_result_t *result,
                               const char *tail)
{
    const coavoid_coordinator_state_t *st = coavoid_coordinator_state(user);
    fprintf(stderr,
            "%s: %lld cycles, plans run %u, plans published %u, last plan %.1f ms "
            "(%llu nodes expanded), messages received %lld, rejected %lld (last: %s)%s\n",
            name, (long long)result->cycles, (unsigned)st->plans_run, (unsigned)st->plans_published,
            (double)st->last_plan_duration_us * 1e-3, (unsigned long long)st->last_nodes_expanded,
            (long long)st->rx.received, (long long)st->rx.rejected,
            st->rx.last_reason != NULL ? st->rx.last_reason : "none", tail);
}

/* The planner's beta (--beta, the scenario's, or the default for max_centralised UAVs)
 * into config, what chose it and the workspace's size. CLI_CONTINUE, or CLI_EXIT_INVALID
 * after the line when that workspace cannot be sized. */
static int choose_beta(const coordinator_options_t *o, const coavoid_scenario_t *s,
                       coavoid_coordinator_config_t *config, const char **beta_source, size_t *size)
{
    if (o->beta_text != NULL) {
        config->common.beta = o->beta;
        *beta_source = "--beta";
    } else if (s->has_beta) {
        *beta_source = "the scenario's beta";
    } else {
        coa_planner_config_t shape = coavoid_node_planner_config(
            config->common.horizon, o->max_centralised, COAVOID_DEFAULT_BETA);
        config->common.beta = coavoid_default_beta(&shape);
        *beta_source = "the default beta";
    }
    coa_planner_config_t planner_config = coavoid_node_planner_config(
        config->common.horizon, o->max_centralised, config->common.beta);
    *size = coa_planner_workspace_size(&planner_config);
    if (*size == 0) {
        return coavoid_cli_fail(
            CLI_EXIT_INVALID,
            "%s %lu: the workspace for %zu vehicles would not fit in memory (lower "
            "--beta or --max-centralised)",
            *beta_source, (unsigned long)config->common.beta, o->max_centralised);
    }
    return CLI_CONTINUE;
}

/* Everything after the options. Returns the exit status. */
static int run(void *options, coavoid_scenario_t *s)
{
    coordinator_options_t *o = options;
    int64_t now = 0; /* the node's clock (common.clock), written by the loop */
    coavoid_coordinator_config_t config;
    memset(&config, 0, sizeof config);
    int status = coavoid_rt_setup(o->scenario_path, s, &o->rt, &now, &config.common);
    if (status != CLI_CONTINUE) {
        return status;
    }
    status = coavoid_rt_keys(&o->rt, COAVOID_AUTH_COORDINATOR,
                             (uint16_t)COAVOID_NODE_COORDINATOR_ID, &config.common);
    if (status != CLI_CONTINUE) {
        return status;
    }
    const int64_t dt_us = config.common.dt_us;
    config.id = COAVOID_NODE_COORDINATOR_ID;
    config.max_centralised = o->max_centralised;
    config.collect_us = o->collect_text != NULL ? llround(o->collect * 1e6) : dt_us / 4;
    config.heartbeat_copies = COAVOID_NODE_DEFAULT_COPIES;
    if (config.collect_us < 1 || config.collect_us >= dt_us) {
        return coavoid_cli_fail(
            CLI_EXIT_INVALID,
            "--collect: must be above 0 and below the scenario's dt (%g s), got %g", (double)s->dt,
            o->collect);
    }
    /* Plans must reach the vehicles before the cycle ends: of the wall time left after
     * collecting, ((dt - collect) / speed), planning may take three quarters; the rest is
     * for the messages. */
    config.plan_budget_us =
        (int64_t)llround(0.75 * (double)(dt_us - config.collect_us) / o->rt.speed);
    config.plan_budget_us = config.plan_budget_us > 0 ? config.plan_budget_us : 1;
    const char *beta_source = NULL;
    size_t size = 0;
    status = choose_beta(o, s, &config, &beta_source, &size);
    if (status != CLI_CONTINUE) {
        return status;
    }
    coavoid_rt_transport_t transport;
    status = coavoid_rt_transport_open(&transport, o->rt.lcm_url, &config.common);
    if (status != CLI_CONTINUE) {
        return status;
    }
    int error = COA_OK;
    coavoid_coordinator_t *node = coavoid_coordinator_create(
        &config, transport.lcm, coavoid_rt_transport_rx_lcm(&transport), &error);
    if (node == NULL) {
        coavoid_rt_transport_close(&transport);
        if (error == COA_ERR_WORKSPACE) {
            return coavoid_cli_fail(
                CLI_EXIT_INVALID,
                "%s %lu: cannot allocate the planner's %zu bytes for %zu vehicles "
                "(lower --beta or --max-centralised)",
                beta_source, (unsigned long)config.common.beta, size, o->max_centralised);
        }
        return coavoid_cli_fail(error == COA_ERR_ARGUMENT ? CLI_EXIT_INVALID : CLI_EXIT_INTERNAL,
                                "coordinator: cannot start (%s)", coavoid_lcm_error_name(error));
    }
    coavoid_rt_loop_t loop;
    coavoid_rt_loop_init(&loop, &o->rt, &transport, &now, &config.common, "coordinator");
    loop.collect_us = config.collect_us;
    loop.coordinator = node;
    status = coavoid_rt_drive(&loop, o->rt.lcm_url, coordinator_report, node);
    coavoid_coordinator_destroy(node);
    coavoid_rt_transport_close(&transport);
    return status;
}

int main(int argc, char **argv)
{
    coordinator_options_t options;
    int status = parse_options(argc, argv, &options);
    if (status != CLI_CONTINUE) {
        return status;
    }
    return coavoid_cli_run_scenario(options.scenario_path, run, &options);
}
