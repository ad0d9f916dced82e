/* SPDX-License-Identifier: MIT */
/*
 * coavoid bench: the dispatcher of the benchmarks, and `coavoid bench predict`'s options
 * (BENCH_USAGE below). The harness, which builds the random airspace, times the
 * prediction cycles and reports, is coavoid::evaluation's (bench_predict.h,
 * docs/benchmarks.md); `coavoid bench plan` is bench_plan.c, `coavoid bench auth`
 * bench_auth.c (built with the messaging library only: COAVOID_HAVE_LCM).
 */
#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include "bench_predict.h"
#include "cli.h"
#include "coavoid/coavoid.h"
#include "commands.h"

/* The benchmarks built: auth only with the messaging library. */
#ifdef COAVOID_HAVE_LCM
#define BENCH_NAMES "predict, plan or auth"
#else
#define BENCH_NAMES "predict or plan"
#endif

#define BENCH_DEFAULT_SEED 1u
#define BENCH_DEFAULT_REPEAT 21u
#define BENCH_MAX_REPEAT 100000u
#define BENCH_MAX_SIDE_KM 1000.0

#define BENCH_USAGE                                                                         \
    "usage: coavoid bench predict --vehicles N --horizon H [--seed S] [--repeat R]\n"       \
    "                             [--side-km L] [--all-pairs] [--json]\n"                   \
    "\n"                                                                                    \
    "Builds a random airspace of N UAVs (%g per km^2, four altitude layers, 8-20 m/s,\n"    \
    "routes of 2-3 legs, plans published unaligned with steps of 0.5, 1 or 2 s) and N/%u\n" \
    "tracks with position uncertainty, then times the core's prediction cycle\n"            \
    "(coa_predict, dt = %g s over H steps, threshold %g) R times on one core.\n"            \
    "Prints the median, min and max time per cycle and the work done, one\n"                \
    "'key: value' per line (or a JSON object with --json). See docs/benchmarks.md.\n"       \
    "\n"                                                                                    \
    "options:\n"                                                                            \
    "  --vehicles N   UAVs, 1..%u\n"                                                        \
    "  --horizon H    steps predicted, 1..%u\n"                                             \
    "  --seed S       the airspace's random seed, an integer >= 0; default %u\n"            \
    "  --repeat R     timed cycles, 1..%u; default %u\n"                                    \
    "  --side-km L    fly in a fixed L km x L km square (0 < L <= %g) instead of\n"         \
    "                 one sized for %g UAVs per km^2\n"                                     \
    "  --all-pairs    skip the broad phase: every pair is tested (the reference)\n"         \
    "  --json         print a JSON object instead of 'key: value' lines\n"                  \
    "  -h, --help     show this help\n"                                                     \
    "      --version  print the version\n"                                                  \
    "\n"                                                                                    \
    "A benchmark is deterministic for a seed except for its times.\n"                       \
    "\n"                                                                                    \
    "exit status: 0 done, 2 invalid usage or a size beyond the benchmark's memory\n"        \
    "limits (one line on stderr naming the option and why), 3 internal error\n"

static void print_usage(void)
{
    printf(BENCH_USAGE, COAVOID_BENCH_PREDICT_DENSITY_PER_KM2,
           COAVOID_BENCH_PREDICT_TRACKS_PER_VEHICLE, COAVOID_BENCH_PREDICT_DT,
           COAVOID_BENCH_PREDICT_THRESHOLD, COAVOID_BENCH_PREDICT_MAX_VEHICLES, COA_MAX_HORIZON,
           BENCH_DEFAULT_SEED, BENCH_MAX_REPEAT, BENCH_DEFAULT_REPEAT, BENCH_MAX_SIDE_KM,
           COAVOID_BENCH_PREDICT_DENSITY_PER_KM2);
}

typedef struct {
    const char *vehicles_text;
    uint32_t vehicles;
    const char *horizon_text;
    uint32_t horizon;
    const char *seed_text;
    uint64_t seed;
    const char *repeat_text;
    uint32_t repeat;
    const char *side_text;
    double side_km;
    bool all_pairs;
    bool json;
} bench_options_t;

/* Returns CLI_CONTINUE, or the exit status (help printed: 0; a usage error: 2). */
static int parse_bench_options(int argc, char **argv, bench_options_t *o)
{
    memset(o, 0, sizeof *o);
    /* argv[2] is the benchmark's name, checked by the caller. */
    for (int i = 3; i < argc; i++) {
        const char *arg = argv[i];
        uint64_t value = 0;
        int status = CLI_CONTINUE;
        if (strcmp(arg, "-h") == 0 || strcmp(arg, "--help") == 0) {
            print_usage();
            return CLI_EXIT_OK;
        } else if (strcmp(arg, "--version") == 0) {
            coavoid_cli_print_version("coavoid");
            return CLI_EXIT_OK;
        } else if (coavoid_cli_option_is(arg, "--vehicles")) {
            status = coavoid_cli_count_option(argc, argv, &i, "--vehicles", NULL, false,
                                              COAVOID_BENCH_PREDICT_MAX_VEHICLES, &o->vehicles_text,
                                              &value);
            o->vehicles = (uint32_t)value;
        } else if (coavoid_cli_option_is(arg, "--horizon")) {
            status = coavoid_cli_count_option(argc, argv, &i, "--horizon", NULL, false,
                                              COA_MAX_HORIZON, &o->horizon_text, &value);
            o->horizon = (uint32_t)value;
        } else if (coavoid_cli_option_is(arg, "--seed")) {
            status = coavoid_cli_count_option(argc, argv, &i, "--seed", NULL, true, UINT64_MAX,
                                              &o->seed_text, &value);
            o->seed = value;
        } else if (coavoid_cli_option_is(arg, "--repeat")) {
            status = coavoid_cli_count_option(argc, argv, &i, "--repeat", NULL, false,
                                              BENCH_MAX_REPEAT, &o->repeat_text, &value);
            o->repeat = (uint32_t)value;
        } else if (coavoid_cli_option_is(arg, "--side-km")) {
            status = coavoid_cli_text_option(argc, argv, &i, "--side-km", "km, > 0", true,
                                             &o->side_text);
            if (status == CLI_CONTINUE && (!coavoid_cli_parse_real(o->side_text, &o->side_km) ||
                                           !(o->side_km > 0) || o->side_km > BENCH_MAX_SIDE_KM)) {
                return coavoid_cli_fail(CLI_EXIT_INVALID,
                                        "--side-km: must be a number with 0 < L <= %g, got '%.40s'",
                                        BENCH_MAX_SIDE_KM, o->side_text);
            }
        } else if (coavoid_cli_option_is(arg, "--all-pairs")) {
            status = coavoid_cli_flag_option(arg, "--all-pairs", &o->all_pairs);
        } else if (coavoid_cli_option_is(arg, "--json")) {
            status = coavoid_cli_flag_option(arg, "--json", &o->json);
        } else {
            return coavoid_cli_fail(
                CLI_EXIT_INVALID,
                "bench predict: unexpected argument '%.40s' (see 'coavoid bench "
                "predict --help')",
                arg);
        }
        if (status != CLI_CONTINUE) {
            return status;
        }
    }
    if (o->vehicles_text == NULL) {
        return coavoid_cli_fail(CLI_EXIT_INVALID,
                                "--vehicles: required (the number of UAVs, 1..%u)",
                                COAVOID_BENCH_PREDICT_MAX_VEHICLES);
    }
    if (o->horizon_text == NULL) {
        return coavoid_cli_fail(CLI_EXIT_INVALID, "--horizon: required (steps to predict, 1..%u)",
                                COA_MAX_HORIZON);
    }
    if (o->seed_text == NULL) {
        o->seed = BENCH_DEFAULT_SEED;
    }
    if (o->repeat_text == NULL) {
        o->repeat = BENCH_DEFAULT_REPEAT;
    }
    return CLI_CONTINUE;
}

static int bench_predict(int argc, char **argv)
{
    bench_options_t o;
    int status = parse_bench_options(argc, argv, &o);
    if (status != CLI_CONTINUE) {
        return status;
    }
    coavoid_bench_predict_config_t config;
    memset(&config, 0, sizeof config);
    config.vehicles = o.vehicles;
    config.horizon = o.horizon;
    config.seed = o.seed;
    config.repeat = o.repeat;
    config.side_km = o.side_text != NULL ? o.side_km : 0.0; /* 0: sized for the density */
    config.all_pairs = o.all_pairs;
    coavoid_bench_predict_result_t result;
    coavoid_run_error_t e;
    int rc = coavoid_bench_predict_run(&config, &result, &e);
    if (rc != COAVOID_RUN_DONE) {
        return coavoid_cli_run_status(rc, &e);
    }
    return coavoid_bench_predict_report(stdout, &config, &result, o.json) == 0
               ? CLI_EXIT_OK
               : coavoid_cli_fail(CLI_EXIT_INTERNAL, "cannot write the result");
}

int coavoid_command_bench(int argc, char **argv)
{
    if (argc < 3) {
        return coavoid_cli_fail(CLI_EXIT_INVALID, "bench: missing benchmark (" BENCH_NAMES
                                                  "; see 'coavoid bench --help')");
    }
    const char *name = argv[2];
    if (strcmp(name, "-h") == 0 || strcmp(name, "--help") == 0) {
        /* Benchmarks with their own options: name each, each one's help has the rest. */
        printf("usage: coavoid bench predict --vehicles N --horizon H [options]\n"
               "       coavoid bench plan [--vehicles N] [--count C] [options]\n"
#ifdef COAVOID_HAVE_LCM
               "       coavoid bench auth [--vehicles N[,N...]] [--repeat R] [--json]\n"
#endif
               "\n"
               "  predict  times the conflict prediction cycle on a random airspace\n"
               "  plan     times the planner, centralised and decoupled, on the paper\n"
               "           scenario and random encounters\n"
#ifdef COAVOID_HAVE_LCM
               "  auth     times signing and checking each message type, per message\n"
               "           and per cycle of a fleet's nodes\n"
#endif
               "\n"
               "Run 'coavoid bench NAME --help' for a benchmark's options.\n"
               "See docs/benchmarks.md.\n");
        return CLI_EXIT_OK;
    }
    if (strcmp(name, "predict") == 0) {
        return bench_predict(argc, argv);
    }
    if (strcmp(name, "plan") == 0) {
        return coavoid_bench_plan(argc, argv);
    }
#ifdef COAVOID_HAVE_LCM
    if (strcmp(name, "auth") == 0) {
        return coavoid_bench_auth(argc, argv);
    }
#endif
    return coavoid_cli_fail(CLI_EXIT_INVALID,
                            "bench: unknown benchmark '%.40s' (expected " BENCH_NAMES
                            "; see 'coavoid bench --help')",
                            name);
}
