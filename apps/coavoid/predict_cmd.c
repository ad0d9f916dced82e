/* SPDX-License-Identifier: MIT */
/*
 * coavoid predict: its options; the prediction is coavoid::scenario's (run.h,
 * coavoid_scenario_predict). See PREDICT_USAGE below.
 */
#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include "cli.h"
#include "commands.h"
#include "run.h"
#include "scenario.h"

/* The probability from which a pair with uncertainty is listed, unless --threshold says
 * otherwise: a 1 % chance of losing separation is worth planning for. */
#define COAVOID_DEFAULT_THRESHOLD 0.01

/* A printf format so that the numbers it quotes come from one place. */
#define PREDICT_USAGE                                                                        \
    "usage: coavoid predict SCENARIO.json [--threshold P] [--sigma-growth H,V]\n"            \
    "\n"                                                                                     \
    "Reads a scenario (JSON, at most %u MiB) and predicts its conflicts over the horizon,\n" \
    "taking every UAV's plan to be its reference trajectory at its initial_offset (no\n"     \
    "manoeuvre) and every track and obstacle as given. Prints the prediction result as\n"    \
    "JSON: the conflicting pairs, and the clusters of UAVs to plan together.\n"              \
    "\n"                                                                                     \
    "options:\n"                                                                             \
    "  --threshold P       list a pair with position uncertainty (a track with \"sigma\")\n" \
    "                      when its probability of conflict is >= P, 0 < P <= 1;\n"          \
    "                      default %g. Pairs without uncertainty are listed whenever\n"      \
    "                      they conflict (probability 1)\n"                                  \
    "  --sigma-growth H,V  every track's one-sigma position error grows by H m/s\n"          \
    "                      horizontally and V m/s vertically of look-ahead time\n"           \
    "                      (H, V >= 0; default 0,0: a track's \"sigma\" as given)\n"         \
    "  -h, --help          show this help\n"                                                 \
    "      --version       print the version\n"                                              \
    "\n"                                                                                     \
    "Conflicts are listed UAV pairs first, then tracks, then obstacles, each by a then b.\n" \
    "\n"                                                                                     \
    "exit status: 0 predicted (whether or not there are conflicts), 2 invalid input or\n"    \
    "usage (one line on stderr naming the input and why), 3 internal error\n"

typedef struct {
    const char *scenario_path;
    const char *threshold_text; /* NULL: COAVOID_DEFAULT_THRESHOLD */
    double threshold;
    const char *growth_text; /* NULL: no growth */
    double growth_horizontal;
    double growth_vertical;
} predict_options_t;

/* --sigma-growth's "H,V": two finite numbers >= 0. */
static bool parse_growth(const char *text, double *horizontal, double *vertical)
{
    const char *comma = strchr(text, ',');
    char first[64];
    size_t length = comma != NULL ? (size_t)(comma - text) : 0;
    if (comma == NULL || length >= sizeof first) {
        return false;
    }
    memcpy(first, text, length);
    first[length] = '\0';
    return coavoid_cli_parse_real(first, horizontal) &&
           coavoid_cli_parse_real(comma + 1, vertical) && *horizontal >= 0 && *vertical >= 0;
}

static void predict_help(void)
{
    printf(PREDICT_USAGE, COAVOID_SCENARIO_MAX_BYTES / (1024u * 1024u), COAVOID_DEFAULT_THRESHOLD);
}

static int predict_option(int argc, char **argv, int *i, void *options)
{
    predict_options_t *o = options;
    const char *arg = argv[*i];
    if (coavoid_cli_option_is(arg, "--threshold")) {
        int status = coavoid_cli_text_option(argc, argv, i, "--threshold",
                                             "a probability, 0 < P <= 1", true, &o->threshold_text);
        if (status == CLI_CONTINUE && (!coavoid_cli_parse_real(o->threshold_text, &o->threshold) ||
                                       !(o->threshold > 0) || o->threshold > 1)) {
            status = coavoid_cli_fail(CLI_EXIT_INVALID,
                                      "--threshold: must be a number with 0 < P <= 1, got '%.40s'",
                                      o->threshold_text);
        }
        return status;
    }
    if (coavoid_cli_option_is(arg, "--sigma-growth")) {
        int status = coavoid_cli_text_option(argc, argv, i, "--sigma-growth",
                                             "H,V in m/s, e.g. 0.5,0.1", true, &o->growth_text);
        if (status == CLI_CONTINUE &&
            !parse_growth(o->growth_text, &o->growth_horizontal, &o->growth_vertical)) {
            status = coavoid_cli_fail(CLI_EXIT_INVALID,
                                      "--sigma-growth: must be two numbers >= 0 as H,V (m/s), "
                                      "got '%.40s'",
                                      o->growth_text);
        }
        return status;
    }
    return CLI_UNKNOWN_OPTION;
}

static const coavoid_cli_command_t predict_command = {
    "predict",    "coavoid predict", 2,    {"SCENARIO.json", NULL}, "one scenario only",
    predict_help, predict_option,    false};

/* Returns CLI_CONTINUE, or the exit status (help printed: 0; a usage error: 2). */
static int parse_predict_options(int argc, char **argv, predict_options_t *o)
{
    memset(o, 0, sizeof *o);
    int status = coavoid_cli_parse_args(&predict_command, argc, argv, o, &o->scenario_path);
    if (status != CLI_CONTINUE) {
        return status;
    }
    if (o->threshold_text == NULL) {
        o->threshold = COAVOID_DEFAULT_THRESHOLD;
    }
    return CLI_CONTINUE;
}

static int predict(void *options, coavoid_scenario_t *s)
{
    const predict_options_t *o = options;
    const coavoid_predict_config_t config = {
        .scenario_path = o->scenario_path,
        .threshold = o->threshold,
        .growth_horizontal = o->growth_horizontal,
        .growth_vertical = o->growth_vertical,
    };
    coavoid_run_error_t e;
    int rc = coavoid_scenario_predict(&config, s, stdout, &e);
    return coavoid_cli_run_status(rc, &e);
}

int coavoid_command_predict(int argc, char **argv)
{
    predict_options_t options;
    int status = parse_predict_options(argc, argv, &options);
    if (status != CLI_CONTINUE) {
        return status;
    }
    return coavoid_cli_run_scenario(options.scenario_path, predict, &options);
}
