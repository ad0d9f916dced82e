/* SPDX-License-Identifier: MIT */
/*
 * coavoid bench auth: its options (BENCH_AUTH_USAGE below). The harness, which times the
 * signatures and checks of each message type and derives each node's cost per cycle, is
 * coavoid::evaluation's (bench_auth.h, docs/benchmarks.md, "Signed messages"). Built only
 * with the messaging library (COAVOID_HAVE_LCM).
 */
#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include "bench_auth.h"
#include "cli.h"
#include "commands.h"

#define BA_DEFAULT_REPEAT 1001u /* odd: the median is one of the times */
#define BA_MAX_REPEAT 1000000u

#define BENCH_AUTH_USAGE                                                                   \
    "usage: coavoid bench auth [--vehicles N[,N...]] [--repeat R] [--json]\n"              \
    "\n"                                                                                   \
    "Times signing (coavoid_auth_stamp) and checking (tail, fleet tag, signature, role,\n" \
    "freshness) one message of each type (intent, plan, track, obstacle_map,\n"            \
    "conflict_report, status, agreement) at its encoded size, R times on one core, and\n"  \
    "prints the median, min and max; then the refusals of a copy, an unknown key, an\n"    \
    "outsider's forgery (the fleet tag) and the same without a fleet key (signature).\n"   \
    "Then, for fleets of N UAVs on one channel, the messages a vehicle, the coordinator\n" \
    "and the world sign and check per cycle (worst case: one plan per UAV), their\n"       \
    "microseconds per cycle from the medians, the share of dt (%g s), and the bytes:\n"    \
    "traffic, auth_t tails (%u a message) and the node's keys (signer, trust list).\n"     \
    "One 'key: value' per line, or a JSON object with --json. See docs/benchmarks.md.\n"   \
    "\n"                                                                                   \
    "options:\n"                                                                           \
    "  --vehicles N,...  fleet sizes, each 1..%u, at most %u; default %u,%u\n"             \
    "                    (the demo's 3 UAVs, and 100)\n"                                   \
    "  --repeat R        timed signatures and checks per type, 1..%u; default %u\n"        \
    "  --json            print a JSON object instead of 'key: value' lines\n"              \
    "  -h, --help        show this help\n"                                                 \
    "      --version     print the version\n"                                              \
    "\n"                                                                                   \
    "exit status: 0 done, 2 invalid usage (one line on stderr naming the option and\n"     \
    "why), 3 internal error (a check that should pass failed)\n"

static void print_usage(void)
{
    printf(BENCH_AUTH_USAGE, COAVOID_BENCH_AUTH_DT_US / 1e6, COAVOID_AUTH_TAIL_BYTES,
           COAVOID_BENCH_AUTH_MAX_VEHICLES, COAVOID_BENCH_AUTH_MAX_FLEETS,
           COAVOID_BENCH_AUTH_DEMO_VEHICLES, COAVOID_BENCH_AUTH_LARGE_VEHICLES, BA_MAX_REPEAT,
           BA_DEFAULT_REPEAT);
}

typedef struct {
    const char *vehicles_text;
    const char *repeat_text;
    uint64_t repeat;
    bool json;
    coavoid_bench_auth_config_t config;
} ba_options_t;

/* "3,100": each 1..MAX_VEHICLES, each once, at most MAX_FLEETS. */
static int parse_fleets(ba_options_t *o)
{
    const char *token = o->vehicles_text;
    coavoid_bench_auth_config_t *c = &o->config;
    for (;;) {
        const char *comma = strchr(token, ',');
        size_t length = comma != NULL ? (size_t)(comma - token) : strlen(token);
        uint64_t n = 0;
        if (!coavoid_cli_parse_count(token, length, COAVOID_BENCH_AUTH_MAX_VEHICLES, &n)) {
            return coavoid_cli_fail(CLI_EXIT_INVALID,
                                    "--vehicles: each entry must be an integer from 1 to %u, got "
                                    "'%.*s'",
                                    COAVOID_BENCH_AUTH_MAX_VEHICLES,
                                    (int)(length > 40 ? 40 : length), token);
        }
        for (size_t k = 0; k < c->fleet_count; k++) {
            if (c->vehicles[k] == n) {
                return coavoid_cli_fail(CLI_EXIT_INVALID, "--vehicles: %lu is listed twice",
                                        (unsigned long)n);
            }
        }
        if (c->fleet_count == COAVOID_BENCH_AUTH_MAX_FLEETS) {
            return coavoid_cli_fail(CLI_EXIT_INVALID, "--vehicles: at most %u fleet sizes",
                                    COAVOID_BENCH_AUTH_MAX_FLEETS);
        }
        c->vehicles[c->fleet_count++] = (uint32_t)n;
        if (comma == NULL) {
            return CLI_CONTINUE;
        }
        token = comma + 1;
    }
}

/* Returns CLI_CONTINUE, or the exit status (help printed: 0; a usage error: 2). */
static int parse_options(int argc, char **argv, ba_options_t *o)
{
    memset(o, 0, sizeof *o);
    /* argv[2] is the benchmark's name, checked by the caller. */
    for (int i = 3; i < argc; i++) {
        const char *arg = argv[i];
        int status = CLI_CONTINUE;
        if (strcmp(arg, "-h") == 0 || strcmp(arg, "--help") == 0) {
            print_usage();
            return CLI_EXIT_OK;
        } else if (strcmp(arg, "--version") == 0) {
            coavoid_cli_print_version("coavoid");
            return CLI_EXIT_OK;
        } else if (coavoid_cli_option_is(arg, "--vehicles")) {
            status = coavoid_cli_text_option(argc, argv, &i, "--vehicles", "UAV counts, e.g. 3,100",
                                             false, &o->vehicles_text);
            status = status == CLI_CONTINUE ? parse_fleets(o) : status;
        } else if (coavoid_cli_option_is(arg, "--repeat")) {
            status = coavoid_cli_count_option(argc, argv, &i, "--repeat", NULL, false,
                                              BA_MAX_REPEAT, &o->repeat_text, &o->repeat);
        } else if (coavoid_cli_option_is(arg, "--json")) {
            status = coavoid_cli_flag_option(arg, "--json", &o->json);
        } else {
            return coavoid_cli_fail(CLI_EXIT_INVALID,
                                    "bench auth: unexpected argument '%.40s' (see 'coavoid bench "
                                    "auth --help')",
                                    arg);
        }
        if (status != CLI_CONTINUE) {
            return status;
        }
    }
    if (o->vehicles_text == NULL) {
        o->config.vehicles[0] = COAVOID_BENCH_AUTH_DEMO_VEHICLES;
        o->config.vehicles[1] = COAVOID_BENCH_AUTH_LARGE_VEHICLES;
        o->config.fleet_count = 2u;
    }
    o->config.repeat = o->repeat_text != NULL ? (uint32_t)o->repeat : BA_DEFAULT_REPEAT;
    return CLI_CONTINUE;
}

int coavoid_bench_auth(int argc, char **argv)
{
    ba_options_t o;
    int status = parse_options(argc, argv, &o);
    if (status != CLI_CONTINUE) {
        return status;
    }
    coavoid_bench_auth_result_t result;
    coavoid_run_error_t e;
    int rc = coavoid_bench_auth_run(&o.config, &result, &e);
    if (rc != COAVOID_RUN_DONE) {
        return coavoid_cli_run_status(rc, &e);
    }
    return coavoid_bench_auth_report(stdout, &o.config, &result, o.json) == 0
               ? CLI_EXIT_OK
               : coavoid_cli_fail(CLI_EXIT_INTERNAL, "cannot write the result");
}
