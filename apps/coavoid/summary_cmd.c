/* SPDX-License-Identifier: MIT */
/*
 * coavoid summary: its options; the log is read and judged by coavoid::sim (sim.h,
 * coavoid_sim_summarise).
 */
#define _POSIX_C_SOURCE 200809L

#include <inttypes.h>
#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include "cli.h"
#include "coavoid_lcm.h"
#include "commands.h"
#include "drivers.h"
#include "node.h"
#include "scenario.h"
#include "sim.h"

#define SUMMARY_USAGE                                                                             \
    "usage: coavoid summary LOGFILE SCENARIO.json --mode centralised|decoupled\n"                 \
    "                       [--json] [--svg FILE] [--epoch UTIME] [--trust FILE]\n"               \
    "\n"                                                                                          \
    "Rebuilds what each UAV of the scenario flew from an lcm-logger log of a real-time\n"         \
    "run (the intents on " COAVOID_CHANNEL_INTENT "), judges it as 'coavoid sim' does (loss of\n" \
    "separation, deviation, effort), and counts the planning calls (" COAVOID_CHANNEL_STATUS      \
    ",\n" COAVOID_CHANNEL_PLAN ").\n"                                                             \
    "\n"                                                                                          \
    "options:\n"                                                                                  \
    "  --mode MODE     centralised or decoupled: the mode the run was started in\n"               \
    "  --json          print the simulation result as JSON (with a \"log\" object)\n"             \
    "  --svg FILE      write the figure (top view, altitude per UAV) to FILE\n"                   \
    "  --epoch UTIME   cycle 0's start, in microseconds; default: the earliest\n"                 \
    "                  plan_utime of the scenario's UAVs in the log\n"                            \
    "  --trust FILE    the run's trust file: only intents, plans and heartbeats signed\n"         \
    "                  by a key that may send them, and newer than the last from that\n"          \
    "                  key, count; the others are ignored and counted as unauthenticated\n"       \
    "  -h, --help      show this help\n"                                                          \
    "      --version   print the version\n"                                                       \
    "\n"                                                                                          \
    "Replans are the planning calls of every node up to the last sample, from the\n"              \
    "plans_run of their heartbeats (as coavoid sim counts them).\n"                               \
    "Samples run from cycle 0 to the last cycle in which every UAV's own intent was\n"            \
    "logged, at most twice the scenario's horizon. A sample no intent covers is taken\n"          \
    "from the scenario's reference with the offset held, and reported.\n"                         \
    "\n"                                                                                          \
    "exit status: 0 no loss of separation, 1 loss of separation, 2 invalid input or usage\n"      \
    "(one line on stderr naming the input and why), 3 internal error\n"

/* ---- options ---- */

typedef struct {
    const char *log_path;
    const char *scenario_path;
    const char *mode;
    bool json;
    const char *svg_path;
    const char *epoch_text;
    int64_t epoch;
    const char *trust_path;
    coavoid_auth_trust_t trust;
} summary_options_t;

static void summary_help(void)
{
    fputs(SUMMARY_USAGE, stdout);
}

static int summary_option(int argc, char **argv, int *i, void *options)
{
    summary_options_t *o = options;
    const char *arg = argv[*i];
    int status = CLI_UNKNOWN_OPTION;
    if (coavoid_cli_option_is(arg, "--mode")) {
        status = coavoid_cli_mode_option(argc, argv, i, &o->mode, NULL);
    } else if (coavoid_cli_option_is(arg, "--json")) {
        status = coavoid_cli_flag_option(arg, "--json", &o->json);
    } else if (coavoid_cli_option_is(arg, "--svg")) {
        status =
            coavoid_cli_text_option(argc, argv, i, "--svg", "a file to write", false, &o->svg_path);
    } else if (coavoid_cli_option_is(arg, "--trust")) {
        status = coavoid_cli_text_option(argc, argv, i, "--trust", "a trust file", false,
                                         &o->trust_path);
    } else if (coavoid_cli_option_is(arg, "--epoch")) {
        uint64_t epoch = 0;
        status = coavoid_cli_text_option(argc, argv, i, "--epoch", "microseconds, an integer >= 1",
                                         true, &o->epoch_text);
        if (status == CLI_CONTINUE && !coavoid_cli_parse_count(o->epoch_text, strlen(o->epoch_text),
                                                               (uint64_t)INT64_MAX / 2u, &epoch)) {
            return coavoid_cli_fail(CLI_EXIT_INVALID,
                                    "--epoch: must be an integer from 1 to %" PRIu64
                                    " (microseconds), got '%.40s'",
                                    (uint64_t)INT64_MAX / 2u, o->epoch_text);
        }
        o->epoch = (int64_t)epoch;
    }
    return status;
}

static const coavoid_cli_command_t summary_command = {
    "summary",    "coavoid summary", 2,    {"LOGFILE", "SCENARIO.json"}, "one log and one scenario",
    summary_help, summary_option,    false};

/* Whether the file at path begins as an lcm-logger log does (its first event's magic). */
static bool is_lcm_log(const char *path)
{
    static const unsigned char magic[4] = {0xEDu, 0xA1u, 0xDAu, 0x01u};
    unsigned char head[4] = {0};
    FILE *f = fopen(path, "rb");
    const bool log = f != NULL && fread(head, 1, sizeof head, f) == sizeof head &&
                     memcmp(head, magic, sizeof magic) == 0;
    if (f != NULL) {
        fclose(f);
    }
    return log;
}

static int parse_summary_options(int argc, char **argv, summary_options_t *o)
{
    const char *args[2] = {NULL, NULL};
    memset(o, 0, sizeof *o);
    int status = coavoid_cli_parse_args(&summary_command, argc, argv, o, args);
    if (status != CLI_CONTINUE) {
        return status;
    }
    o->log_path = args[0];
    o->scenario_path = args[1];
    /* The two given the other way round would read the log as JSON ("NUL byte"). */
    if (is_lcm_log(o->scenario_path)) {
        return coavoid_cli_fail(CLI_EXIT_INVALID,
                                "%.200s is an lcm-logger log, not a scenario: the log comes first "
                                "(coavoid summary LOGFILE SCENARIO.json)",
                                o->scenario_path);
    }
    if (o->mode == NULL) {
        return coavoid_cli_fail(CLI_EXIT_INVALID, "--mode: required (centralised or decoupled)");
    }
    if (o->trust_path != NULL) {
        return coavoid_rt_load_trust(o->trust_path, &o->trust);
    }
    return CLI_CONTINUE;
}

static int summarise(void *options, coavoid_scenario_t *s)
{
    const summary_options_t *o = options;
    const coavoid_sim_log_config_t config = {
        .scenario_path = o->scenario_path,
        .log_path = o->log_path,
        .mode = o->mode,
        .json = o->json,
        .svg_path = o->svg_path,
        .has_epoch = o->epoch_text != NULL,
        .epoch = o->epoch,
        .trust = o->trust_path != NULL ? &o->trust : NULL,
    };
    coavoid_run_error_t e;
    return coavoid_cli_run_status(coavoid_sim_summarise(&config, s, stdout, &e), &e);
}

int coavoid_command_summary(int argc, char **argv)
{
    static summary_options_t options; /* a trust list: 18 kB */
    int status = parse_summary_options(argc, argv, &options);
    if (status != CLI_CONTINUE) {
        return status;
    }
    return coavoid_cli_run_scenario(options.scenario_path, summarise, &options);
}
