/* SPDX-License-Identifier: MIT */
/*
 * coavoid sim: its options; the run is coavoid::sim's (sim.h, coavoid_sim_run).
 */
#define _POSIX_C_SOURCE 200809L

#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include "cli.h"
#include "commands.h"

#include "node.h"
#include "scenario.h"
#include "sim.h"
#include "vehicle_options.h"

#define SIM_USAGE                                                                                \
    "usage: coavoid sim SCENARIO.json --mode centralised|decoupled [--steps K] [--json]\n"       \
    "                   [--svg FILE] [--coordinator-stops STEP[:M]] [--insecure]\n"              \
    "                   [--loss P] [--delay S] [--jitter S] [--net-seed N]\n"                    \
    "                   [--record-vehicle ID:FILE] [--joint-members N]\n"                        \
    "\n"                                                                                         \
    "Flies the scenario in closed loop: every step each UAV publishes its intent, conflicts\n"   \
    "are predicted and planned for (by the coordinator, or by each UAV in priority order),\n"    \
    "and every UAV flies one step of its plan. The nodes are those of the real-time apps,\n"     \
    "over LCM's in-process provider on a simulated clock: the output is repeatable.\n"           \
    "\n"                                                                                         \
    "options:\n"                                                                                 \
    "  --mode centralised   a coordinator plans each conflicting cluster; the UAVs follow\n"     \
    "                       it, and plan for themselves when its heartbeat stops\n"              \
    "  --mode decoupled     no coordinator: each UAV plans for itself in priority order\n"       \
    "  --steps K            fly K steps (samples 0..K), K >= 1; default 2 * horizon\n"           \
    "  --json               print the simulation result as JSON (default: text)\n"               \
    "  --svg FILE           write the figure (top view, altitude profiles) to FILE\n"            \
    "  --coordinator-stops STEP[:M]\n"                                                           \
    "                       centralised: stop the coordinator in cycle STEP (0..K): its\n"       \
    "                       first M messages of that cycle go out (whatever they are),\n"        \
    "                       then nothing more; STEP alone: before it sends any (M = 0)\n"        \
    "  --insecure           the nodes neither sign nor check their messages (by default they\n"  \
    "                       do, with the simulation's fixed keys; the flight is the same)\n"     \
    "  --loss P             each message reaches each other node with probability 1 - P,\n"      \
    "                       independently (0 <= P < 1); default 0\n"                             \
    "  --delay S            ... after S seconds (>= 0); default 0\n"                             \
    "  --jitter S           ... plus a uniform time in [0, S] seconds; default 0. A node\n"      \
    "                       hears its own at once; delay + jitter must be less than dt\n"        \
    "  --net-seed N         the network's random seed, an integer >= 0; default 1 (--seed N,\n"  \
    "                       its old spelling, works with a warning)\n"                           \
    "  --record-vehicle ID:FILE\n"                                                               \
    "                       write UAV ID's record to FILE: its configuration and keys, every\n"  \
    "                       datagram it received and call made, with their times, and what\n"    \
    "                       it sent and its state after each call (`coavoid replay FILE`\n"      \
    "                       makes them again and compares)\n"                                    \
    "  --joint-members N    centralised: every vehicle plans its group jointly, while it\n"      \
    "                       plans for itself and no priority order solves it, for groups\n"      \
    "                       of up to N UAVs (0: never; else at least 2), as the\n"               \
    "                       vehicles' --joint-members; default the scenario's UAVs, at most 5\n" \
    "  -h, --help           show this help\n"                                                    \
    "      --version        print the version\n"                                                 \
    "\n"                                                                                         \
    "Beyond the contract's fields the result has \"fallbacks\" (times a UAV went from\n"         \
    "following the coordinator to planning for itself), with --coordinator-stops,\n"             \
    "\"coordinator_stopped_at\" (with :M also \"coordinator_stopped_after\", M, and\n"           \
    "\"coordinator_messages_cut\", what it published after them that no one got; in\n"           \
    "text a \"coordinator:\" line), and with --loss, --delay or --jitter, \"network\" (those\n"  \
    "settings and the messages sent, copies delivered, dropped and in flight at the end).\n"     \
    "\n"                                                                                         \
    "The scenario's horizon may be at most %u steps (an intent carries N + 1 samples) and\n"     \
    "it may have at most %u UAVs. What its messages carry over the run (references and\n"        \
    "tracks up to t = (K + N) dt, with the climbs a UAV can make) must stay within their\n"      \
    "bounds: positions %g m, speeds %g m/s, sizes and sigmas %g m.\n"                            \
    "\n"                                                                                         \
    "exit status: 0 no loss of separation, 1 a loss of separation, 2 invalid input or\n"         \
    "usage (one line on stderr naming the input and why), 3 internal error\n"

#define SIM_DEFAULT_SEED 1u

typedef struct {
    const char *scenario_path;
    const char *mode;
    bool decoupled;
    const char *steps_text;
    uint32_t steps;
    bool json;
    const char *svg_path;
    const char *stop_text;
    uint32_t stop_step;
    bool has_stop_messages;
    uint32_t stop_messages;
    bool insecure;
    coavoid_cli_network_t network;
    const char *record_text;
    const char *record_path;
    uint16_t record_uav;
    const char *joint_text;
    uint64_t joint_members;
} sim_options_t;

static void sim_help(void)
{
    printf(SIM_USAGE, COAVOID_NODE_MAX_HORIZON, COA_MAX_VEHICLES, COAVOID_LCM_MAX_COORDINATE,
           COAVOID_LCM_MAX_SPEED, COAVOID_LCM_MAX_SIZE);
}

/* The whole number text[0..length) (shorter than `room` characters, at most `max`) into
 * *value: false when it is not one. */
static bool parse_prefix(const char *text, size_t length, size_t room, uint64_t max,
                         uint64_t *value)
{
    char digits[16];
    if (length >= room || length >= sizeof digits) {
        return false;
    }
    memcpy(digits, text, length);
    digits[length] = '\0';
    return coavoid_cli_parse_index(digits, max, value);
}

/* --coordinator-stops STEP or STEP:M, each a whole number from 0 (M: messages, at most
 * COAVOID_SIM_MAX_STEPS too: far more than a coordinator sends in a cycle). */
static int parse_stop(sim_options_t *o)
{
    const char *text = o->stop_text;
    const char *colon = strchr(text, ':');
    uint64_t value = 0, messages = 0;
    size_t length = colon != NULL ? (size_t)(colon - text) : strlen(text);
    bool ok =
        parse_prefix(text, length, 16u, COAVOID_SIM_MAX_STEPS, &value) &&
        (colon == NULL || coavoid_cli_parse_index(colon + 1, COAVOID_SIM_MAX_STEPS, &messages));
    if (!ok) {
        return coavoid_cli_fail(CLI_EXIT_INVALID,
                                "--coordinator-stops: must be STEP or STEP:M, a step from 0 to %u "
                                "and a message count from 0 to %u, got '%.40s'",
                                COAVOID_SIM_MAX_STEPS, COAVOID_SIM_MAX_STEPS, text);
    }
    o->stop_step = (uint32_t)value;
    o->has_stop_messages = colon != NULL;
    o->stop_messages = (uint32_t)messages;
    return CLI_CONTINUE;
}

/* --record-vehicle ID:FILE, ID a UAV id (1..65535). */
static int parse_record(sim_options_t *o)
{
    const char *text = o->record_text;
    const char *colon = strchr(text, ':');
    uint64_t value = 0;
    bool ok = colon != NULL && colon > text && colon[1] != '\0' &&
              parse_prefix(text, (size_t)(colon - text), 8u, 65535u, &value) && value >= 1u;
    if (!ok) {
        return coavoid_cli_fail(CLI_EXIT_INVALID,
                                "--record-vehicle: must be ID:FILE, a UAV id from 1 to 65535 and "
                                "a file to write, got '%.40s'",
                                text);
    }
    o->record_uav = (uint16_t)value;
    o->record_path = colon + 1;
    return CLI_CONTINUE;
}

static int sim_option(int argc, char **argv, int *i, void *options)
{
    sim_options_t *o = options;
    const char *arg = argv[*i];
    uint64_t value = 0;
    int status = coavoid_cli_network_option(argc, argv, i, true, &o->network);
    if (status != CLI_UNKNOWN_OPTION) {
        return status;
    }
    if (coavoid_cli_option_is(arg, "--mode")) {
        status = coavoid_cli_mode_option(argc, argv, i, &o->mode, &o->decoupled);
    } else if (coavoid_cli_option_is(arg, "--steps")) {
        status = coavoid_cli_count_option(argc, argv, i, "--steps", "an integer >= 1", false,
                                          COAVOID_SIM_MAX_STEPS, &o->steps_text, &value);
        o->steps = (uint32_t)value;
    } else if (coavoid_cli_option_is(arg, "--json")) {
        status = coavoid_cli_flag_option(arg, "--json", &o->json);
    } else if (coavoid_cli_option_is(arg, "--insecure")) {
        status = coavoid_cli_flag_option(arg, "--insecure", &o->insecure);
    } else if (coavoid_cli_option_is(arg, "--svg")) {
        status =
            coavoid_cli_text_option(argc, argv, i, "--svg", "a file to write", false, &o->svg_path);
    } else if (coavoid_cli_option_is(arg, "--coordinator-stops")) {
        status = coavoid_cli_text_option(argc, argv, i, "--coordinator-stops", "a step, 0 or more",
                                         true, &o->stop_text);
        status = status == CLI_CONTINUE ? parse_stop(o) : status;
    } else if (coavoid_cli_option_is(arg, "--record-vehicle")) {
        status = coavoid_cli_text_option(argc, argv, i, "--record-vehicle", "ID:FILE", false,
                                         &o->record_text);
        status = status == CLI_CONTINUE ? parse_record(o) : status;
    } else if (coavoid_cli_option_is(arg, "--joint-members")) {
        status = coavoid_joint_members_option(argc, argv, i, &o->joint_text, &o->joint_members);
    }
    return status;
}

static const coavoid_cli_command_t sim_command = {
    "sim",    "coavoid sim", 2,    {"SCENARIO.json", NULL}, "one scenario only",
    sim_help, sim_option,    false};

static int parse_sim_options(int argc, char **argv, sim_options_t *o)
{
    memset(o, 0, sizeof *o);
    int status = coavoid_cli_parse_args(&sim_command, argc, argv, o, &o->scenario_path);
    if (status != CLI_CONTINUE) {
        return status;
    }
    if (o->mode == NULL) {
        return coavoid_cli_fail(CLI_EXIT_INVALID, "--mode: required (centralised or decoupled)");
    }
    if (o->decoupled && o->joint_text != NULL) {
        return coavoid_cli_fail(CLI_EXIT_INVALID,
                                "--joint-members: only valid with --mode centralised");
    }
    if (o->decoupled && o->stop_text != NULL) {
        return coavoid_cli_fail(
            CLI_EXIT_INVALID, "--coordinator-stops: only valid with --mode centralised (decoupled "
                              "runs without a coordinator)");
    }
    return CLI_CONTINUE;
}

static int sim(void *options, coavoid_scenario_t *s)
{
    const sim_options_t *o = options;
    const coavoid_sim_config_t config = {
        .scenario_path = o->scenario_path,
        .mode = o->mode,
        .decoupled = o->decoupled,
        .has_steps = o->steps_text != NULL,
        .steps = o->steps,
        .has_stop = o->stop_text != NULL,
        .stop_step = o->stop_step,
        .has_stop_messages = o->has_stop_messages,
        .stop_messages = o->stop_messages,
        .json = o->json,
        .svg_path = o->svg_path,
        .record_path = o->record_path,
        .record_uav = o->record_uav,
        .has_joint_members = o->joint_text != NULL,
        .joint_members = (size_t)o->joint_members,
        .insecure = o->insecure,
        .network = coavoid_cli_network_given(&o->network),
        .loss = o->network.loss,
        .delay = o->network.delay,
        .jitter = o->network.jitter,
        .seed = o->network.seed_text != NULL ? o->network.seed : SIM_DEFAULT_SEED,
    };
    coavoid_run_error_t e;
    int rc = coavoid_sim_run(&config, s, stdout, &e);
    return coavoid_cli_run_status(rc, &e);
}

int coavoid_command_sim(int argc, char **argv)
{
    sim_options_t options;
    int status = parse_sim_options(argc, argv, &options);
    if (status != CLI_CONTINUE) {
        return status;
    }
    return coavoid_cli_run_scenario(options.scenario_path, sim, &options);
}
