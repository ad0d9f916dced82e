/* SPDX-License-Identifier: MIT */
/*
 * coavoid-vehicle: one simulated UAV of a scenario as a process of its own. It flies its
 * route, publishes its intent every cycle, follows the coordinator's plans while the
 * coordinator's heartbeat is heard and plans for itself in priority order when it is not
 * (or always, in decoupled mode). The node is src/protocol's vehicle; this file only reads
 * the options and runs it in real time (realtime.h). See VEHICLE_USAGE below.
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

/* Its joint search's workspace grows by 2 bytes per node (docs/benchmarks.md). */
#define VEHICLE_MAX_JOINT_BETA 1000000u

#define VEHICLE_USAGE                                                                             \
    "usage: coavoid-vehicle --scenario FILE --id ID [--mode centralised|decoupled]\n"             \
    "                       [--lcm-url URL] [--epoch UTIME] [--speed S] [--steps K]\n"            \
    "                       [--coordinator-timeout S] [--coordinator-id ID]\n"                    \
    "                       [--priority-wait S] [--joint-members N [--joint-beta B]]\n"           \
    "                       (--key FILE --trust FILE | --insecure)\n"                             \
    "       coavoid-vehicle --scenario FILE --list-ids\n"                                         \
    "\n"                                                                                          \
    "Flies the UAV with this id from the scenario in real time, exchanging intents and\n"         \
    "plans over LCM with the other vehicles, the coordinator and `coavoid world`.\n"              \
    "\n"                                                                                          \
    "options:\n"                                                                                  \
    "  --scenario FILE     the scenario (docs/scenario-format.md): route, dt, horizon, beta\n"    \
    "  --id ID             which of its vehicles this process flies\n"                            \
    "  --mode centralised  follow the coordinator; plan for itself while the coordinator\n"       \
    "                      is silent (default)\n"                                                 \
    "  --mode decoupled    always plan for itself, in priority order\n" COAVOID_RT_OPTIONS_USAGE  \
    "  --coordinator-timeout S  scenario seconds of coordinator silence after which it\n"         \
    "                      plans for itself; default 2.5 * dt\n"                                  \
    "  --coordinator-id ID the node id of the coordinator it follows (1 to 65535, not its\n"      \
    "                      own); heartbeats and plans from any other are refused; default\n"      \
    "                      65001, coavoid-coordinator's\n"                                        \
    "  --priority-wait S   decoupled: scenario seconds it waits for the intents of the\n"         \
    "                      higher-priority UAVs that pass near it, 0 <= S < dt; default dt / 2\n" \
    "  --joint-members N   centralised: while it plans for itself, it plans its group\n"          \
    "                      jointly, as the coordinator would, where no priority order\n"          \
    "                      solves it, for groups of up to N UAVs (2 to 6; 0: never, and\n"        \
    "                      its planner is then one UAV's); default the scenario's UAVs, at\n"     \
    "                      most 5; the same on every vehicle of the fleet\n"                      \
    "  --joint-beta B      centralised: the nodes that joint search may store, 1 to\n"            \
    "                      1000000; default 5000; the same on every vehicle of the fleet\n"       \
    "  --list-ids          print the scenario's vehicle ids, one per line, and exit (for\n"       \
    "                      scripts that start one process per UAV)\n"                             \
    "  -h, --help          show this help\n"                                                      \
    "\n"                                                                                          \
    "At the end (after K cycles, or on SIGINT/SIGTERM) it prints one summary line on\n"           \
    "stderr: cycles, plans run and adopted, fallbacks to its own planning, joint plans\n"         \
    "flown, messages received and rejected.\n"                                                    \
    "\n"                                                                                          \
    "exit status: 0 done, 2 invalid input or usage (one line on stderr), 3 internal error\n"

typedef struct {
    const char *scenario_path;
    const char *id_text;
    uint16_t id;
    bool list_ids;
    const char *mode;
    bool decoupled;
    const char *timeout_text;
    double timeout;
    const char *coordinator_text;
    uint16_t coordinator_id;
    const char *wait_text;
    double wait;
    const char *joint_members_text;
    uint64_t joint_members;
    const char *joint_beta_text;
    uint64_t joint_beta;
    coavoid_rt_options_t rt;
} vehicle_options_t;

/* A duration option in scenario seconds: finite, >= 0 (> 0 unless zero_ok). */
static int parse_seconds(int argc, char **argv, int *i, const char *name, bool zero_ok,
                         const char **text, double *out)
{
    int status = coavoid_cli_text_option(argc, argv, i, name, "scenario seconds", true, text);
    if (status == CLI_CONTINUE && (!coavoid_cli_parse_real(*text, out) || *out < 0 ||
                                   (*out == 0 && !zero_ok) || *out > COAVOID_LCM_MAX_STEP)) {
        status = coavoid_cli_fail(CLI_EXIT_INVALID,
                                  "%s: must be a number of seconds, %s %g, got '%.40s'", name,
                                  zero_ok ? "0 <= S <=" : "0 < S <=", COAVOID_LCM_MAX_STEP, *text);
    }
    return status;
}

static void vehicle_help(void)
{
    fputs(VEHICLE_USAGE, stdout);
}

static int vehicle_option(int argc, char **argv, int *i, void *options)
{
    vehicle_options_t *o = options;
    const char *arg = argv[*i];
    uint64_t value = 0;
    int status = coavoid_rt_parse_option(argc, argv, i, &o->rt);
    if (status != CLI_UNKNOWN_OPTION) {
        return status;
    }
    if (coavoid_cli_option_is(arg, "--scenario")) {
        status = coavoid_cli_text_option(argc, argv, i, "--scenario", "a scenario file", false,
                                         &o->scenario_path);
    } else if (coavoid_cli_option_is(arg, "--id")) {
        status = coavoid_cli_text_option(argc, argv, i, "--id", "a vehicle id", true, &o->id_text);
        if (status == CLI_CONTINUE &&
            !coavoid_cli_parse_count(o->id_text, strlen(o->id_text), 65535u, &value)) {
            status = coavoid_cli_fail(CLI_EXIT_INVALID,
                                      "--id: must be a vehicle id from 1 to 65535, got '%.40s'",
                                      o->id_text);
        }
        o->id = (uint16_t)value;
    } else if (coavoid_cli_option_is(arg, "--list-ids")) {
        status = coavoid_cli_flag_option(arg, "--list-ids", &o->list_ids);
    } else if (coavoid_cli_option_is(arg, "--mode")) {
        status = coavoid_cli_mode_option(argc, argv, i, &o->mode, &o->decoupled);
    } else if (coavoid_cli_option_is(arg, "--coordinator-timeout")) {
        status = parse_seconds(argc, argv, i, "--coordinator-timeout", false, &o->timeout_text,
                               &o->timeout);
    } else if (coavoid_cli_option_is(arg, "--coordinator-id")) {
        status = coavoid_cli_text_option(argc, argv, i, "--coordinator-id", "a node id", true,
                                         &o->coordinator_text);
        if (status == CLI_CONTINUE &&
            !coavoid_cli_parse_count(o->coordinator_text, strlen(o->coordinator_text), 65535u,
                                     &value)) {
            status =
                coavoid_cli_fail(CLI_EXIT_INVALID,
                                 "--coordinator-id: must be a node id from 1 to 65535, got '%.40s'",
                                 o->coordinator_text);
        }
        o->coordinator_id = (uint16_t)value;
    } else if (coavoid_cli_option_is(arg, "--priority-wait")) {
        status = parse_seconds(argc, argv, i, "--priority-wait", true, &o->wait_text, &o->wait);
    } else if (coavoid_cli_option_is(arg, "--joint-members")) {
        status = coavoid_cli_count_option(argc, argv, i, "--joint-members", "0 or 2 to 6", true,
                                          COA_MAX_CENTRALISED, &o->joint_members_text,
                                          &o->joint_members);
        if (status == CLI_CONTINUE && o->joint_members == 1u) {
            status = coavoid_cli_fail(CLI_EXIT_INVALID,
                                      "--joint-members: must be 0 or 2 to %u, got 1 (a group of "
                                      "one is planned alone)",
                                      COA_MAX_CENTRALISED);
        }
    } else if (coavoid_cli_option_is(arg, "--joint-beta")) {
        status =
            coavoid_cli_count_option(argc, argv, i, "--joint-beta", NULL, false,
                                     VEHICLE_MAX_JOINT_BETA, &o->joint_beta_text, &o->joint_beta);
    }
    return status;
}

static const coavoid_cli_command_t vehicle_command = {
    "vehicle",    "coavoid-vehicle", 1, {NULL, NULL}, "the scenario is --scenario FILE",
    vehicle_help, vehicle_option};

static int parse_options(int argc, char **argv, vehicle_options_t *o)
{
    memset(o, 0, sizeof *o);
    coavoid_rt_options_init(&o->rt);
    int status = coavoid_cli_parse_args(&vehicle_command, argc, argv, o, NULL);
    if (status != CLI_CONTINUE) {
        return status;
    }
    if (o->scenario_path == NULL) {
        return coavoid_cli_fail(CLI_EXIT_INVALID, "--scenario: required (a scenario file)");
    }
    if (o->list_ids) {
        if (o->id_text != NULL || o->mode != NULL || o->timeout_text != NULL ||
            o->coordinator_text != NULL || o->wait_text != NULL || o->joint_members_text != NULL ||
            o->joint_beta_text != NULL || o->rt.lcm_url != NULL || o->rt.epoch_text != NULL ||
            o->rt.speed_text != NULL || o->rt.steps_text != NULL) {
            return coavoid_cli_fail(CLI_EXIT_INVALID, "--list-ids: takes only --scenario FILE");
        }
        return CLI_CONTINUE;
    }
    if (o->id_text == NULL) {
        return coavoid_cli_fail(CLI_EXIT_INVALID, "--id: required (which vehicle of the scenario)");
    }
    /* The coordinator timeout only decides when a centralised vehicle plans for itself. */
    if (o->decoupled && o->timeout_text != NULL) {
        return coavoid_cli_fail(CLI_EXIT_INVALID,
                                "--coordinator-timeout: only valid with --mode centralised");
    }
    if (o->decoupled && o->coordinator_text != NULL) {
        return coavoid_cli_fail(CLI_EXIT_INVALID,
                                "--coordinator-id: only valid with --mode centralised");
    }
    /* The joint plan is the coordinator's plan, made by its vehicles when it is gone. */
    if (o->decoupled && (o->joint_members_text != NULL || o->joint_beta_text != NULL)) {
        return coavoid_cli_fail(CLI_EXIT_INVALID, "%s: only valid with --mode centralised",
                                o->joint_members_text != NULL ? "--joint-members" : "--joint-beta");
    }
    if (o->joint_beta_text != NULL && o->joint_members_text != NULL && o->joint_members == 0u) {
        return coavoid_cli_fail(CLI_EXIT_INVALID,
                                "--joint-beta: --joint-members 0 plans no group jointly");
    }
    if (o->coordinator_text != NULL && o->coordinator_id == o->id) {
        return coavoid_cli_fail(CLI_EXIT_INVALID, "--coordinator-id: %u is this vehicle's own id",
                                (unsigned)o->id);
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
    int64_t now = 0; /* the nodes' clock (common.clock), written by the loop */
    coavoid_vehicle_node_config_t config;
    memset(&config, 0, sizeof config);
    int status = coavoid_rt_setup(o->scenario_path, s, &o->rt, &now, &config.common);
    if (status != CLI_CONTINUE) {
        return status;
    }
    long index = coavoid_scenario_vehicle_index(s, (long)o->id);
    if (index < 0) {
        return coavoid_cli_fail(CLI_EXIT_INVALID, "--id: %s has no vehicle %u", o->scenario_path,
                                (unsigned)o->id);
    }
    status = coavoid_rt_keys(&o->rt, COAVOID_AUTH_VEHICLE, o->id, &config.common);
    if (status != CLI_CONTINUE) {
        return status;
    }
    const int64_t dt_us = config.common.dt_us;
    config.vehicle = s->vehicles[index];
    config.mode = o->decoupled ? COAVOID_NODE_DECOUPLED : COAVOID_NODE_CENTRALISED;
    config.coordinator_id = o->coordinator_id; /* 0: the default */
    config.intent_copies = COAVOID_NODE_DEFAULT_COPIES;
    config.joint_members = o->joint_members_text != NULL
                               ? (size_t)o->joint_members
                               : coavoid_node_joint_members(config.mode, s->vehicle_count);
    config.joint_beta = (uint32_t)o->joint_beta; /* 0: the default */
    config.coordinator_timeout_us =
        o->timeout_text != NULL ? llround(o->timeout * 1e6) : llround(2.5 * (double)dt_us);
    config.priority_wait_us = o->wait_text != NULL ? llround(o->wait * 1e6) : dt_us / 2;
    if (config.coordinator_timeout_us < 1) {
        return coavoid_cli_fail(CLI_EXIT_INVALID, "--coordinator-timeout: below a microsecond");
    }
    /* A wait into the next cycle would publish this cycle's intent after the next one's. */
    if (config.priority_wait_us >= dt_us) {
        return coavoid_cli_fail(CLI_EXIT_INVALID,
                                "--priority-wait: %g s is not less than the scenario's dt (%g s)",
                                o->wait, (double)s->dt);
    }

    coavoid_rt_transport_t transport;
    status = coavoid_rt_transport_open(&transport, o->rt.lcm_url, &config.common);
    if (status != CLI_CONTINUE) {
        return status;
    }
    int error = COA_OK;
    coavoid_vehicle_node_t *node = coavoid_vehicle_node_create(
        &config, transport.lcm, coavoid_rt_transport_rx_lcm(&transport), &error);
    if (node == NULL) {
        coavoid_rt_transport_close(&transport);
        return coavoid_cli_fail(error == COA_ERR_ARGUMENT ? CLI_EXIT_INVALID : CLI_EXIT_INTERNAL,
                                "vehicle %u: cannot start (%s)", (unsigned)o->id,
                                coavoid_lcm_error_name(error));
    }
    char name[32];
    snprintf(name, sizeof name, "vehicle %u", (unsigned)o->id);
    coavoid_vehicle_node_t *const vehicles[1] = {node};
    coavoid_rt_loop_t loop;
    coavoid_rt_loop_init(&loop, &o->rt, &transport, &now, &config.common, name);
    loop.vehicles = vehicles;
    loop.vehicle_count = 1;
    status = coavoid_rt_drive(&loop, o->rt.lcm_url, vehicle_report, node);
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
    return coavoid_cli_run_scenario(options.scenario_path, run, &options);
}
