/* SPDX-License-Identifier: MIT */
/*
 * coavoid montecarlo: its options (MONTECARLO_USAGE below); the engine, which draws the
 * encounters, plans them on worker threads, cross-checks and reports, is
 * coavoid::evaluation's (montecarlo.h, docs/evaluation.md).
 */
#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include "cli.h"
#include "commands.h"
#include "encounter.h"
#include "montecarlo.h"
#include "scenario.h"

#define MC_DEFAULT_SEED 1u
#define MC_DEFAULT_COUNT 100u
#define MC_MAX_COUNT COAVOID_MONTECARLO_MAX_COUNT
#define MC_MAX_FIRST 1000000000u

#define MONTECARLO_USAGE                                                                    \
    "usage: coavoid montecarlo --vehicles N[,N...] [--count C] [--first I] [--seed S]\n"    \
    "                          [--beta B] [--max-orders M] [--work W] [--csv FILE]\n"       \
    "                          [--svg FILE]\n"                                              \
    "                          [--json] [--save DIR] [--jobs J] [--quiet]\n"                \
    "                          [--fly [--loss P] [--delay S] [--jitter S] [--net-seed N]\n" \
    "                                 [--coordinator-stops-sweep all|ends]]\n"              \
    "       coavoid montecarlo --figure-from A.csv,B.csv,... --svg FILE\n"                  \
    "       coavoid montecarlo --merge A.csv,B.csv,... [--svg FILE] [--json]\n"             \
    "\n"                                                                                    \
    "Draws C random encounters of N UAVs (for each N listed) converging on a point over\n"  \
    "hills, with 0 to 2 non-cooperative tracks crossing (%u steps of %g s), and solves\n"   \
    "each one centralised, decoupled in the fixed priority order and decoupled with\n"      \
    "reordering. Prints per N and method the outcomes, the success rate with its 95%%\n"    \
    "Wilson interval, the distribution of the decoupled/centralised deviation ratio\n"      \
    "over the encounters both solve, and the planning times (a text summary, or a JSON\n"   \
    "object with --json). See docs/evaluation.md.\n"                                        \
    "\n"                                                                                    \
    "options:\n"                                                                            \
    "  --vehicles N,...  UAVs per encounter, each %u..%u, e.g. 2,3,4 (required)\n"          \
    "  --count C         encounters per N, 1..%u; default %u\n"                             \
    "  --first I         the first encounter's index, 0..%u; default 0: runs encounters\n"  \
    "                    I..I+C-1 of the seed, so a long run split in parts (one --first\n" \
    "                    each) gives the rows of one run\n"                                 \
    "  --seed S          the encounters' random seed, an integer >= 0; default %u\n"        \
    "  --beta B          closed-set bound, B >= 1, for every search; default %u, lowered\n" \
    "                    per N where the centralised workspace would pass 1 GiB\n"          \
    "  --max-orders M    reordering: at most M priority orders, M >= 1; default N!\n"       \
    "                    (every order)\n"                                                   \
    "  --work W          work units each planning call may spend, 0 for no limit;\n"        \
    "                    default %llu (as coavoid plan's)\n"                                \
    "  --csv FILE        one row per encounter and method (times in time_us)\n"             \
    "  --svg FILE        success rates, the ratio's cumulative distribution and the\n"      \
    "                    centralised plans' over their lower bounds\n"                      \
    "  --save DIR        write each encounter as DIR/montecarlo-SEED-N-INDEX.json (an\n"    \
    "                    existing directory), for `coavoid plan` to replay\n"               \
    "  --json            print the summary as a JSON object\n"                              \
    "  --jobs J          worker threads, 1..%u; default 1; results do not depend on it\n"   \
    "  --quiet           no progress on stderr (otherwise: a line updated every second\n"   \
    "                    on a terminal, a line every 10%% when stderr is not one)\n"

/* The rest of the usage: one string literal is at most 4095 characters in C11. */
#define MONTECARLO_USAGE_FLY                                                                 \
    "  --fly             also fly each encounter in closed loop, centralised and\n"          \
    "                    decoupled, by the nodes of `coavoid sim` (insecure: nothing\n"      \
    "                    else is on its bus) over a simulated network, and report\n"         \
    "                    per N and mode the loss-of-separation rate, also over the\n"        \
    "                    encounters the one-shot centralised plan, or some priority\n"       \
    "                    order, solves\n"                                                    \
    "  --loss P          with --fly: each message reaches each other node with\n"            \
    "                    probability 1 - P (0 <= P < 1); default 0\n"                        \
    "  --delay S         with --fly: ... after S seconds; default 0\n"                       \
    "  --jitter S        with --fly: ... plus a uniform time in [0, S] seconds; default\n"   \
    "                    0; delay + jitter must be under dt. The network's random\n"         \
    "                    stream comes from --net-seed and the encounter\n"                   \
    "  --net-seed N      with --fly: the network's seed, an integer >= 0, apart from the\n"  \
    "                    encounters' --seed; default: --seed\n"                              \
    "  --coordinator-stops-sweep all|ends\n"                                                 \
    "                    with --fly: also fly each encounter centralised with the\n"         \
    "                    coordinator stopped at every cycle and, in it, after each number\n" \
    "                    of its messages it sent there unstopped (all), or after 0, 1,\n"    \
    "                    half and all but one of them (ends); report the runs that lose\n"   \
    "                    separation, and those where decoupled keeps it\n"                   \
    "  --figure-from A.csv,...\n"                                                            \
    "                    runs nothing: reads the CSVs of montecarlo --fly runs (one loss\n"  \
    "                    each, up to %u files) and writes with --svg the closed loop's\n"    \
    "                    loss-of-separation rate against loss per N and mode; prints the\n"  \
    "                    points\n"                                                           \
    "  --merge A.csv,... runs nothing: reads the CSVs of the parts of one run (up to %u\n"   \
    "                    runs with the same options but --first and --count, which\n"        \
    "                    together cover encounters I..I+C-1, in any order) and prints\n"     \
    "                    the summary (--json) and draws the figure (--svg) of the whole\n"   \
    "                    run, the times being the parts'; exit 2 with one line naming\n"     \
    "                    the file when the parts do not make one run\n"                      \
    "  -h, --help        show this help\n"                                                   \
    "      --version     print the version\n"                                                \
    "\n"                                                                                     \
    "A seed gives the same encounters and results on every machine with the same C\n"        \
    "maths library (headings use cos and sin), except the times.\n"                          \
    "\n"                                                                                     \
    "exit status: 0 done (whatever the plans' outcomes), 2 invalid usage (one line on\n"     \
    "stderr naming the option and why), 3 internal error or a defect of the planner (a\n"    \
    "decoupled plan cheaper than the optimal centralised one or where it proved none, a\n"   \
    "solved plan in conflict or with no deviation: one line each on stderr)\n"

static void montecarlo_help(void)
{
    printf(MONTECARLO_USAGE, coavoid_encounter_montecarlo.horizon, coavoid_encounter_montecarlo.dt,
           COAVOID_ENCOUNTER_MIN_VEHICLES, COAVOID_ENCOUNTER_MAX_VEHICLES, MC_MAX_COUNT,
           MC_DEFAULT_COUNT, MC_MAX_FIRST, MC_DEFAULT_SEED, COAVOID_DEFAULT_BETA,
           (unsigned long long)COAVOID_DEFAULT_WORK, COAVOID_MONTECARLO_MAX_JOBS);
    printf(MONTECARLO_USAGE_FLY, COAVOID_MC_FIGURE_MAX_FILES, COAVOID_MC_MERGE_MAX_FILES);
}

/* ---- options ---- */

typedef struct {
    const char *vehicles_text;
    uint32_t sizes[COAVOID_MONTECARLO_MAX_SIZES]; /* UAV counts in the order given */
    uint32_t size_count;
    const char *count_text;
    uint32_t count;
    const char *first_text;
    uint32_t first;
    const char *seed_text;
    uint64_t seed;
    const char *beta_text;
    uint32_t beta;
    const char *max_orders_text;
    uint32_t max_orders;
    const char *work_text; /* NULL: COAVOID_DEFAULT_WORK */
    uint64_t work;
    const char *csv;
    const char *svg;
    const char *save; /* a directory for every encounter's scenario, or NULL */
    bool json;
    const char *jobs_text;
    uint32_t jobs;
    bool quiet;
    bool fly;
    coavoid_cli_network_t network;
    const char *net_seed_text;
    uint64_t net_seed;
    const char *sweep_text;  /* --coordinator-stops-sweep: all or ends */
    const char *figure_text; /* --figure-from: the list as given */
    const char *merge_text;  /* --merge: the list as given */
    char list[65536];        /* the list's copy, cut at the commas */
    const char *files[COAVOID_MC_MERGE_MAX_FILES];
    size_t file_count;
} mc_options_t;

/* "2,3,4": each 2..10, each once. */
static int parse_sizes(mc_options_t *o)
{
    const char *token = o->vehicles_text;
    for (;;) {
        const char *comma = strchr(token, ',');
        size_t length = comma != NULL ? (size_t)(comma - token) : strlen(token);
        uint64_t n = 0;
        if (!coavoid_cli_parse_count(token, length, COAVOID_ENCOUNTER_MAX_VEHICLES, &n) ||
            n < COAVOID_ENCOUNTER_MIN_VEHICLES) {
            return coavoid_cli_fail(CLI_EXIT_INVALID,
                                    "--vehicles: each entry must be an integer from %u to %u, got "
                                    "'%.*s'",
                                    COAVOID_ENCOUNTER_MIN_VEHICLES, COAVOID_ENCOUNTER_MAX_VEHICLES,
                                    (int)(length > 40 ? 40 : length), token);
        }
        for (uint32_t k = 0; k < o->size_count; k++) {
            if (o->sizes[k] == n) {
                return coavoid_cli_fail(CLI_EXIT_INVALID, "--vehicles: %lu is listed twice",
                                        (unsigned long)n);
            }
        }
        /* At most COAVOID_MONTECARLO_MAX_SIZES distinct values fit the range. */
        o->sizes[o->size_count++] = (uint32_t)n;
        if (comma == NULL) {
            return CLI_CONTINUE;
        }
        token = comma + 1;
    }
}

/* --figure-from or --merge A.csv,B.csv,...: 1 to max paths, none empty, into o->files. */
static int parse_files(mc_options_t *o, const char *option, const char *text, size_t max)
{
    if (strlen(text) >= sizeof o->list) {
        return coavoid_cli_fail(CLI_EXIT_INVALID, "%s: longer than %zu characters", option,
                                sizeof o->list - 1u);
    }
    strcpy(o->list, text);
    for (char *p = o->list;;) {
        char *comma = strchr(p, ',');
        if (comma != NULL) {
            *comma = '\0';
        }
        if (*p == '\0' || o->file_count == max) {
            return coavoid_cli_fail(CLI_EXIT_INVALID,
                                    "%s: 1 to %zu CSV files, comma-separated, none empty", option,
                                    max);
        }
        o->files[o->file_count++] = p;
        if (comma == NULL) {
            return CLI_CONTINUE;
        }
        p = comma + 1;
    }
}

static int mc_option(int argc, char **argv, int *i, void *options)
{
    mc_options_t *o = options;
    const char *arg = argv[*i];
    uint64_t value = 0;
    int status = coavoid_cli_network_option(argc, argv, i, false, &o->network);
    if (status != CLI_UNKNOWN_OPTION) {
        return status;
    }
    if (coavoid_cli_option_is(arg, "--vehicles")) {
        status = coavoid_cli_text_option(argc, argv, i, "--vehicles",
                                         "UAV counts from 2 to 10, e.g. 2,3,4", false,
                                         &o->vehicles_text);
        if (status == CLI_CONTINUE) {
            status = parse_sizes(o);
        }
    } else if (coavoid_cli_option_is(arg, "--count")) {
        status = coavoid_cli_count_option(argc, argv, i, "--count", NULL, false, MC_MAX_COUNT,
                                          &o->count_text, &value);
        o->count = (uint32_t)value;
    } else if (coavoid_cli_option_is(arg, "--first")) {
        status = coavoid_cli_count_option(argc, argv, i, "--first", NULL, true, MC_MAX_FIRST,
                                          &o->first_text, &value);
        o->first = (uint32_t)value;
    } else if (coavoid_cli_option_is(arg, "--seed")) {
        status = coavoid_cli_count_option(argc, argv, i, "--seed", NULL, true, UINT64_MAX,
                                          &o->seed_text, &value);
        o->seed = value;
    } else if (coavoid_cli_option_is(arg, "--beta")) {
        status = coavoid_cli_count_option(argc, argv, i, "--beta", "an integer >= 1", false,
                                          UINT32_MAX, &o->beta_text, &value);
        o->beta = (uint32_t)value;
    } else if (coavoid_cli_option_is(arg, "--work")) {
        status = coavoid_cli_count_option(argc, argv, i, "--work", "an integer >= 0", true,
                                          UINT64_MAX, &o->work_text, &o->work);
    } else if (coavoid_cli_option_is(arg, "--max-orders")) {
        status = coavoid_cli_count_option(argc, argv, i, "--max-orders", "an integer >= 1", false,
                                          UINT32_MAX, &o->max_orders_text, &value);
        o->max_orders = (uint32_t)value;
    } else if (coavoid_cli_option_is(arg, "--csv")) {
        status = coavoid_cli_text_option(argc, argv, i, "--csv", "a file to write", false, &o->csv);
    } else if (coavoid_cli_option_is(arg, "--svg")) {
        status = coavoid_cli_text_option(argc, argv, i, "--svg", "a file to write", false, &o->svg);
    } else if (coavoid_cli_option_is(arg, "--save")) {
        status = coavoid_cli_text_option(argc, argv, i, "--save", "a directory", false, &o->save);
    } else if (coavoid_cli_option_is(arg, "--json")) {
        status = coavoid_cli_flag_option(arg, "--json", &o->json);
    } else if (coavoid_cli_option_is(arg, "--jobs")) {
        status = coavoid_cli_count_option(argc, argv, i, "--jobs", NULL, false,
                                          COAVOID_MONTECARLO_MAX_JOBS, &o->jobs_text, &value);
        o->jobs = (uint32_t)value;
    } else if (coavoid_cli_option_is(arg, "--quiet")) {
        status = coavoid_cli_flag_option(arg, "--quiet", &o->quiet);
    } else if (coavoid_cli_option_is(arg, "--fly")) {
        status = coavoid_cli_flag_option(arg, "--fly", &o->fly);
    } else if (coavoid_cli_option_is(arg, "--figure-from")) {
        status = coavoid_cli_text_option(argc, argv, i, "--figure-from", "CSV files, A.csv,B.csv",
                                         false, &o->figure_text);
    } else if (coavoid_cli_option_is(arg, "--merge")) {
        status = coavoid_cli_text_option(argc, argv, i, "--merge", "CSV files, A.csv,B.csv", false,
                                         &o->merge_text);
    } else if (coavoid_cli_option_is(arg, "--net-seed")) {
        status = coavoid_cli_count_option(argc, argv, i, "--net-seed", NULL, true, UINT64_MAX,
                                          &o->net_seed_text, &o->net_seed);
    } else if (coavoid_cli_option_is(arg, "--coordinator-stops-sweep")) {
        status = coavoid_cli_text_option(argc, argv, i, "--coordinator-stops-sweep", "all or ends",
                                         false, &o->sweep_text);
        if (status == CLI_CONTINUE && strcmp(o->sweep_text, "all") != 0 &&
            strcmp(o->sweep_text, "ends") != 0) {
            status = coavoid_cli_fail(CLI_EXIT_INVALID,
                                      "--coordinator-stops-sweep: must be all or ends, got '%.40s'",
                                      o->sweep_text);
        }
    }
    return status;
}

static const coavoid_cli_command_t montecarlo_command = {"montecarlo",
                                                         "coavoid montecarlo",
                                                         2,
                                                         {NULL, NULL},
                                                         "it takes options only",
                                                         montecarlo_help,
                                                         mc_option,
                                                         false};

/* --figure-from and --merge run nothing: only --svg goes with the first, --svg and --json
 * with the second (the parts' rows hold the run's options). */
static int file_options(mc_options_t *o)
{
    const char *option = o->figure_text != NULL ? "--figure-from" : "--merge";
    if (o->figure_text != NULL && o->merge_text != NULL) {
        return coavoid_cli_fail(CLI_EXIT_INVALID, "--merge: not with --figure-from");
    }
    if (o->figure_text != NULL && o->svg == NULL) {
        return coavoid_cli_fail(CLI_EXIT_INVALID, "--figure-from: needs --svg FILE");
    }
    if (o->vehicles_text != NULL || o->count_text != NULL || o->first_text != NULL ||
        o->seed_text != NULL || o->beta_text != NULL || o->max_orders_text != NULL ||
        o->work_text != NULL || o->csv != NULL || o->save != NULL ||
        (o->json && o->figure_text != NULL) || o->jobs_text != NULL || o->quiet || o->fly ||
        coavoid_cli_network_given(&o->network) || o->net_seed_text != NULL ||
        o->sweep_text != NULL) {
        return coavoid_cli_fail(CLI_EXIT_INVALID, "%s: takes %s only (it runs no encounters)",
                                option, o->figure_text != NULL ? "--svg" : "--svg and --json");
    }
    return o->figure_text != NULL
               ? parse_files(o, option, o->figure_text, COAVOID_MC_FIGURE_MAX_FILES)
               : parse_files(o, option, o->merge_text, COAVOID_MC_MERGE_MAX_FILES);
}

static int parse_mc_options(int argc, char **argv, mc_options_t *o)
{
    memset(o, 0, sizeof *o);
    int status = coavoid_cli_parse_args(&montecarlo_command, argc, argv, o, NULL);
    if (status != CLI_CONTINUE) {
        return status;
    }
    if (o->figure_text != NULL || o->merge_text != NULL) {
        return file_options(o);
    }
    if (o->vehicles_text == NULL) {
        return coavoid_cli_fail(CLI_EXIT_INVALID,
                                "--vehicles: required (UAV counts from %u to %u, "
                                "e.g. 2,3,4)",
                                COAVOID_ENCOUNTER_MIN_VEHICLES, COAVOID_ENCOUNTER_MAX_VEHICLES);
    }
    if (o->csv != NULL && o->svg != NULL && strcmp(o->csv, o->svg) == 0) {
        return coavoid_cli_fail(CLI_EXIT_INVALID, "--svg: the same file as --csv ('%.200s')",
                                o->csv);
    }
    if (coavoid_cli_network_given(&o->network) && !o->fly) {
        return coavoid_cli_fail(CLI_EXIT_INVALID, "%s: only with --fly (the closed loop)",
                                o->network.loss_text != NULL    ? "--loss"
                                : o->network.delay_text != NULL ? "--delay"
                                                                : "--jitter");
    }
    if ((o->net_seed_text != NULL || o->sweep_text != NULL) && !o->fly) {
        return coavoid_cli_fail(CLI_EXIT_INVALID, "%s: only with --fly (the closed loop)",
                                o->net_seed_text != NULL ? "--net-seed"
                                                         : "--coordinator-stops-sweep");
    }
    if (o->network.delay + o->network.jitter >= coavoid_encounter_montecarlo.dt) {
        return coavoid_cli_fail(CLI_EXIT_INVALID,
                                "--delay: %g s plus --jitter %g s must be less than the "
                                "encounters' dt (%g s): a message may be at most a cycle late",
                                o->network.delay, o->network.jitter,
                                coavoid_encounter_montecarlo.dt);
    }
    if (o->count_text == NULL) {
        o->count = MC_DEFAULT_COUNT;
    }
    if (o->seed_text == NULL) {
        o->seed = MC_DEFAULT_SEED;
    }
    if (o->jobs_text == NULL) {
        o->jobs = 1u;
    }
    return CLI_CONTINUE;
}

/* ---- the command ---- */

/* The engine's defects, each one line on stderr as it is found. */
static void print_defect(void *context, const char *line)
{
    (void)context;
    coavoid_cli_fail(CLI_EXIT_INTERNAL, "%s", line);
}

static coavoid_montecarlo_config_t mc_engine_config(const mc_options_t *o)
{
    coavoid_montecarlo_config_t c;
    memset(&c, 0, sizeof c);
    memcpy(c.vehicles, o->sizes, sizeof c.vehicles);
    c.size_count = o->size_count;
    c.count = o->count;
    c.first = o->first;
    c.seed = o->seed;
    c.beta = o->beta_text != NULL ? o->beta : 0u;                   /* 0: the default */
    c.max_orders = o->max_orders_text != NULL ? o->max_orders : 0u; /* 0: every order */
    c.work = o->work_text != NULL ? o->work : COAVOID_DEFAULT_WORK;
    c.jobs = o->jobs;
    c.csv = o->csv;
    c.svg = o->svg;
    c.save = o->save;
    c.progress = o->quiet ? NULL : stderr;
    c.defect = print_defect;
    c.fly = o->fly;
    c.loss = o->network.loss;
    c.delay = o->network.delay;
    c.jitter = o->network.jitter;
    c.has_net_seed = o->net_seed_text != NULL;
    c.net_seed = o->net_seed;
    c.stops_sweep = o->sweep_text != NULL;
    c.stops_ends = c.stops_sweep && strcmp(o->sweep_text, "ends") == 0;
    return c;
}

int coavoid_command_montecarlo(int argc, char **argv)
{
    mc_options_t o;
    int status = parse_mc_options(argc, argv, &o);
    if (status != CLI_CONTINUE) {
        return status;
    }
    coavoid_run_error_t e;
    if (o.figure_text != NULL) {
        int rc = coavoid_montecarlo_figure(o.files, o.file_count, o.svg, stdout, &e);
        return coavoid_cli_run_status(rc, &e);
    }
    coavoid_montecarlo_t *mc = NULL;
    int rc = 0;
    if (o.merge_text != NULL) {
        rc = coavoid_montecarlo_merge(o.files, o.file_count, o.svg, print_defect, NULL, &mc, &e);
    } else {
        const coavoid_montecarlo_config_t config = mc_engine_config(&o);
        rc = coavoid_montecarlo_run(&config, &mc, &e);
    }
    if (rc == COAVOID_RUN_DONE) {
        rc = coavoid_montecarlo_report(mc, stdout, o.json, &e);
    }
    coavoid_montecarlo_free(mc);
    return coavoid_cli_run_status(rc, &e);
}
