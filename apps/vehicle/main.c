/* SPDX-License-Identifier: MIT */
/*
 * coavoid-vehicle: one simulated UAV of a scenario as a process of its own. It flies its
 * route, publishes its intent every cycle, follows the coordinator's plans while the
 * coordinator's heartbeat is heard and plans for itself in priority order when it is not
 * (or always, in decoupled mode). The node is src/protocol's vehicle; this file only reads
 * the options and runs it in real time (realtime.h). See VEHICLE_USAGE below.
 */
#define _POSIX_C_SOURCE 200809L

#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include "cli.h"
#include "node.h"
#include "drivers.h"
#include "vehicle_options.h"
#include "scenario.h"

#define VEHICLE_USAGE                                                                       \
    "usage: coavoid-vehicle SCENARIO.json --id ID [--mode centralised|decoupled]\n"         \
    "                       [--lcm-url URL] [--epoch UTIME] [--speed S] [--steps K]\n"      \
    "                       [--coordinator-timeout S] [--coordinator-id ID]\n"              \
    "                       [--priority-wait S] [--joint-members N [--joint-beta B]]\n"     \
    "                       (--key FILE --trust FILE | --insecure)\n"                       \
    "       coavoid-vehicle SCENARIO.json --list-ids\n"                                     \
    "\n"                                                                                    \
    "Flies the UAV with this id from the scenario in real time, exchanging intents and\n"   \
    "plans over LCM with the other vehicles, the coordinator and `coavoid world`.\n"        \
    "\n"                                                                                    \
    "options:\n" COAVOID_VEHICLE_OPTIONS_USAGE                                              \
    "  --list-ids          print the scenario's vehicle ids, one per line, and exit (for\n" \
    "                      scripts that start one process per UAV)\n"                       \
    "  -h, --help          show this help\n"                                                \
    "      --version       print the version\n"                                             \
    "\n"                                                                                    \
    "At the end (after K cycles, or on SIGINT/SIGTERM) it prints one summary line on\n"     \
    "stderr: cycles, plans run and adopted, fallbacks to its own planning, joint plans\n"   \
    "flown, messages received and rejected.\n"                                              \
    "\n"                                                                                    \
    "exit status: 0 done, 2 invalid input or usage (one line on stderr), 3 internal error\n"

typedef struct {
    coavoid_vehicle_options_t v;
    bool list_ids;
} vehicle_options_t;

static void vehicle_help(void)
{
    fputs(VEHICLE_USAGE, stdout);
}

static int vehicle_option(int argc, char **argv, int *i, void *options)
{
    vehicle_options_t *o = options;
    if (coavoid_cli_option_is(argv[*i], "--list-ids")) {
        return coavoid_cli_flag_option(argv[*i], "--list-ids", &o->list_ids);
    }
    return coavoid_vehicle_option(argc, argv, i, &o->v);
}

static const coavoid_cli_command_t vehicle_command = {
    "vehicle",    "coavoid-vehicle", 1,   {"SCENARIO.json", NULL}, "one scenario only",
    vehicle_help, vehicle_option,    true};

static int parse_options(int argc, char **argv, vehicle_options_t *o)
{
    memset(o, 0, sizeof *o);
    coavoid_vehicle_options_init(&o->v);
    const char *scenario = NULL;
    int status = coavoid_cli_parse_args(&vehicle_command, argc, argv, o, &scenario);
    if (status == CLI_CONTINUE) {
        status = coavoid_cli_scenario_given(&vehicle_command, scenario, &o->v.scenario_path);
    }
    if (status != CLI_CONTINUE || !o->list_ids) {
        return status != CLI_CONTINUE ? status : coavoid_vehicle_options_check(&o->v);
    }
    const coavoid_vehicle_options_t *v = &o->v;
    if (v->id_text != NULL || v->mode != NULL || v->timeout_text != NULL ||
        v->coordinator_text != NULL || v->wait_text != NULL || v->joint_members_text != NULL ||
        v->joint_beta_text != NULL || v->rt.lcm_url != NULL || v->rt.epoch_text != NULL ||
        v->rt.speed_text != NULL || v->rt.steps_text != NULL) {
        return coavoid_cli_fail(CLI_EXIT_INVALID, "--list-ids: takes only the scenario");
    }
    return CLI_CONTINUE;
}

/* The scenario's vehicle ids, one a line (--list-ids). */
static int list_ids(const coavoid_scenario_t *s)
{
    for (size_t i = 0; i < s->vehicle_count; i++) {
        printf("%u\n", (unsigned)s->vehicles[i].id);
    }
    return fflush(stdout) == 0 ? CLI_EXIT_OK
                               : coavoid_cli_fail(CLI_EXIT_INTERNAL, "--list-ids: cannot write");
}

static void vehicle_report(void *user, const char *name, const coavoid_rt_result_t *result,
                           const char *tail)
{
    const coavoid_vehicle_node_state_t *st = coavoid_vehicle_node_state(user);
    fprintf(stderr,
            "%s: %lld cycles, plans run %u, plans adopted %u, fallbacks %u, joint plans %u, "
            "messages received %lld, rejected %lld (last: %s)%s\n",
            name, (long long)result->cycles, (unsigned)st->plans_run, (unsigned)st->plans_adopted,
            (unsigned)st->fallbacks, (unsigned)st->joint_plans, (long long)st->rx.received,
            (long long)st->rx.rejected, st->rx.last_reason != NULL ? st->rx.last_reason : "none",
            tail);
}

/* Everything after the options and the scenario. Returns the exit status. */
static int run(void *options, coavoid_scenario_t *s)
{
    vehicle_options_t *o = options;
    if (o->list_ids) {
        return list_ids(s);
    }
    coavoid_vehicle_options_t *v = &o->v;
    int64_t now = 0; /* the nodes' clock (common.clock), written by the loop */
    coavoid_vehicle_node_config_t config;
    int status = coavoid_vehicle_options_config(v, s, &now, &config);
    if (status != CLI_CONTINUE) {
        return status;
    }

    coavoid_rt_transport_t transport;
    status = coavoid_rt_transport_open(&transport, v->rt.lcm_url, &config.common);
    if (status != CLI_CONTINUE) {
        return status;
    }
    int error = COA_OK;
    coavoid_vehicle_node_t *node = coavoid_vehicle_node_create(
        &config, transport.lcm, coavoid_rt_transport_rx_lcm(&transport), &error);
    if (node == NULL) {
        coavoid_rt_transport_close(&transport);
        return coavoid_cli_fail(error == COA_ERR_ARGUMENT ? CLI_EXIT_INVALID : CLI_EXIT_INTERNAL,
                                "vehicle %u: cannot start (%s)", (unsigned)v->id,
                                coavoid_lcm_error_name(error));
    }
    char name[32];
    snprintf(name, sizeof name, "vehicle %u", (unsigned)v->id);
    coavoid_vehicle_node_t *const vehicles[1] = {node};
    coavoid_rt_loop_t loop;
    coavoid_rt_loop_init(&loop, &v->rt, &transport, &now, &config.common, name);
    loop.vehicles = vehicles;
    loop.vehicle_count = 1;
    status = coavoid_rt_drive(&loop, v->rt.lcm_url, vehicle_report, node);
    coavoid_vehicle_node_destroy(node);
    coavoid_rt_transport_close(&transport);
    return status;
}

int main(int argc, char **argv)
{
    vehicle_options_t options;
    int status = parse_options(argc, argv, &options);
    if (status != CLI_CONTINUE) {
        return status;
    }
    return coavoid_cli_run_scenario(options.v.scenario_path, run, &options);
}
