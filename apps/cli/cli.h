/* SPDX-License-Identifier: MIT */
/*
 * cli.h: what every coavoid command shares: exit statuses, the one-line error report,
 * option parsing in one style ("--opt value" or "--opt=value", each option at most once),
 * and loading a scenario with the loader's messages.
 *
 * Every command reports a usage or input error as exactly one line on stderr,
 * "coavoid: <what>: <why>", naming the option or the file and field, and exits
 * CLI_EXIT_INVALID; the tests rely on that shape.
 */
#ifndef COAVOID_APP_CLI_H
#define COAVOID_APP_CLI_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <time.h>

#include "coavoid/common.h"
#include "coavoid/plan.h"
#include "run.h"
#include "scenario.h"

/* malloc's alignment is what every workspace buffer (planner, predictor) relies on. */
_Static_assert(_Alignof(max_align_t) >= COA_WORKSPACE_ALIGNMENT,
               "malloc does not align enough for the core's workspaces");

enum {
    CLI_EXIT_OK = 0,
    CLI_EXIT_NOT_SOLVED = 1, /* plan: infeasible or budget exhausted */
    CLI_EXIT_INVALID = 2,    /* bad usage or bad input */
    CLI_EXIT_INTERNAL = 3    /* a bug, or the result could not be written */
};

/* Returned by a command's steps to mean "go on": any other value is the exit status
 * (help printed: CLI_EXIT_OK; a usage or input error: CLI_EXIT_INVALID; ...). */
#define CLI_CONTINUE (-1)

#if defined(__GNUC__)
#define CLI_PRINTF_LIKE(fmt, args) __attribute__((format(printf, fmt, args)))
#else
#define CLI_PRINTF_LIKE(fmt, args)
#endif

/* Prints "coavoid: <message>" as exactly one line (control characters that came from the
 * input, such as a file name or an option value, are replaced so they cannot split it) and
 * returns `status`, so that every check reads `return coavoid_cli_fail(...)`. */
int coavoid_cli_fail(int status, const char *fmt, ...) CLI_PRINTF_LIKE(2, 3);

/* Warns on stderr, as one coavoid_cli_fail line, that the spelling `old` still works and
 * goes in the next MINOR version, and names what to `use` in its place. */
void coavoid_cli_deprecated(const char *old, const char *use);

/* A library's return (run.h: a verdict, or an error with its report in e) as the exit
 * status: COAVOID_RUN_DONE -> CLI_EXIT_OK, COAVOID_RUN_NOT_SOLVED -> CLI_EXIT_NOT_SOLVED, an
 * error -> its report on stderr (coavoid_cli_fail) and CLI_EXIT_INVALID or
 * CLI_EXIT_INTERNAL. */
int coavoid_cli_run_status(int rc, const coavoid_run_error_t *e);

/* Whether `arg` is the option `name`, alone or as "name=value". */
bool coavoid_cli_option_is(const char *arg, const char *name);

/* The value of option `name` (argv[*i], already matched by coavoid_cli_option_is): the text after
 * '=', or the next argument (consumed). false when there is none. */
bool coavoid_cli_option_value(int argc, char **argv, int *i, const char *name, const char **value);

/* ---- a command's arguments ---- */

/* A command's own options: argv[*i] starts with '-'. Returns CLI_CONTINUE when it was one
 * of them (consumed with its value), CLI_UNKNOWN_OPTION when it is not, or the exit status
 * after the one-line message. */
#define CLI_UNKNOWN_OPTION (-2)
typedef int (*cli_option_parser_t)(int argc, char **argv, int *i, void *options);

typedef struct {
    const char *name;         /* its messages' prefix: "plan", "coordinator" */
    const char *see;          /* how its help is asked for: "coavoid plan" */
    int first;                /* argv index of its first argument: 2 for coavoid's commands */
    const char *arguments[2]; /* its arguments in order ("LOGFILE", "SCENARIO.json"), NULL
                                  after the last; none for the drivers, which take options */
    const char *too_many;     /* why one more argument is refused: "one scenario only" */
    void (*help)(void);       /* prints the usage on stdout */
    cli_option_parser_t option;
    bool arguments_optional; /* the drivers' scenario: an argument, or --scenario (the old
                                spelling), checked by coavoid_cli_scenario_given */
} coavoid_cli_command_t;

/* The drivers' scenario, the first argument as for every coavoid command; --scenario FILE,
 * the old spelling, still works: coavoid_cli_scenario_option takes it at argv[*i] with a
 * deprecation warning (coavoid_cli_text_option's returns), and coavoid_cli_scenario_given,
 * after the arguments, sets *path from the argument and fails, with one line, when both or
 * neither were given. */
int coavoid_cli_scenario_option(int argc, char **argv, int *i, const char **path);
int coavoid_cli_scenario_given(const coavoid_cli_command_t *c, const char *argument,
                               const char **path);

/* Prints "PROGRAM VERSION (PRECISION precision)" and a newline on stdout: what every
 * program's --version shows, the program's name up to the first space of program. */
void coavoid_cli_print_version(const char *program);

/* Walks argv[c->first..]: "-h" or "--help" prints the help and returns CLI_EXIT_OK, and so
 * does "--version" after coavoid_cli_print_version(c->see); every
 * other option goes to c->option; what is not an option is the next of c->arguments, and
 * args[j] (room for each) is set to argument j. A command that takes arguments also takes
 * "--" (the rest are arguments) and "-" (an argument). Returns CLI_CONTINUE, or
 * CLI_EXIT_INVALID after one of "NAME: unexpected argument 'ARG' (TOO_MANY)", "NAME:
 * unknown option 'ARG' (see 'SEE --help')", "NAME: missing ARGUMENT (see 'SEE --help')",
 * or c->option's status. O(argc) plus the parser's, no memory. */
int coavoid_cli_parse_args(const coavoid_cli_command_t *c, int argc, char **argv, void *options,
                           const char **args);

/* A command's step after its options: runs run(options, s) on the scenario at path, loaded
 * (coavoid_cli_load_scenario) and freed afterwards. Returns run's status, or CLI_EXIT_INVALID after
 * the loader's message. Memory: the scenario's, until run returns. */
int coavoid_cli_run_scenario(const char *path, int (*run)(void *options, coavoid_scenario_t *s),
                             void *options);

/* ---- one option's value ----
 * Each takes the option `name` at argv[*i] (already matched by coavoid_cli_option_is), consumes its
 * value (coavoid_cli_option_value), and returns CLI_CONTINUE, or CLI_EXIT_INVALID after one line:
 * "NAME: given more than once" (each option at most once), "NAME: missing value (HINT)",
 * or what each says of a bad value. O(length of the value), no memory. */

/* Any text, which *text (NULL until given) is set to. An empty value is missing unless
 * allow_empty (then the caller judges it). */
int coavoid_cli_text_option(int argc, char **argv, int *i, const char *name, const char *hint,
                            bool allow_empty, const char **text);

/* An integer from 1 (0 with zero_ok) to max: "NAME: must be an integer from 1 to MAX, got
 * 'VALUE'". hint NULL: "an integer from 1 to MAX". Sets *text (NULL until given) and *out. */
int coavoid_cli_count_option(int argc, char **argv, int *i, const char *name, const char *hint,
                             bool zero_ok, uint64_t max, const char **text, uint64_t *out);

/* A flag, `arg` matched by coavoid_cli_option_is(arg, name): "NAME: takes no value" for
 * "NAME=...". Sets *flag. */
int coavoid_cli_flag_option(const char *arg, const char *name, bool *flag);

/* --mode centralised|decoupled: "--mode: unknown mode 'VALUE' (expected centralised or
 * decoupled)". Sets *mode (NULL until given) and, unless NULL, *decoupled. */
int coavoid_cli_mode_option(int argc, char **argv, int *i, const char **mode, bool *decoupled);

/* The simulated network's options of `coavoid sim` and `coavoid montecarlo --fly`:
 * --loss P (0 <= P < 1), --delay S and --jitter S (seconds, >= 0; the simulation checks
 * them against the scenario's dt) and, with_seed, --net-seed N (an integer >= 0; --seed N,
 * its old spelling, with a deprecation warning). Each *_text
 * is NULL until given. */
typedef struct {
    const char *loss_text, *delay_text, *jitter_text, *seed_text;
    double loss, delay, jitter;
    uint64_t seed;
} coavoid_cli_network_t;

/* One of those options at argv[*i] into *n, as the other option parsers (CLI_CONTINUE or
 * CLI_EXIT_INVALID after one line: "--loss: must be a probability from 0 to below 1, got
 * 'VALUE'", "--delay: must be a time in seconds, 0 or more, got 'VALUE'"), or
 * CLI_UNKNOWN_OPTION when it is none of them. O(length of the value), no memory. */
int coavoid_cli_network_option(int argc, char **argv, int *i, bool with_seed,
                               coavoid_cli_network_t *n);

/* Whether any of --loss, --delay, --jitter was given. */
bool coavoid_cli_network_given(const coavoid_cli_network_t *n);

/* `length` characters of decimal digits only (no sign, no spaces) whose value is in
 * 1..max. */
bool coavoid_cli_parse_count(const char *text, size_t length, uint64_t max, uint64_t *out);

/* A whole string that is "0" or what coavoid_cli_parse_count takes: a value in 0..max. */
bool coavoid_cli_parse_index(const char *text, uint64_t max, uint64_t *out);

/* A whole string that is one finite decimal number (an optional sign, digits with at most
 * one point, an optional exponent): strtod alone would also take leading spaces, "nan",
 * "inf" and hexadecimal, which in an option are more likely a mistake than meant. */
bool coavoid_cli_parse_real(const char *text, double *out);

/* Microseconds from start to end. */
int64_t coavoid_cli_elapsed_us(const struct timespec *start, const struct timespec *end);

/* Loads and validates the scenario at `path` (coavoid_scenario_load). Returns CLI_CONTINUE, or
 * CLI_EXIT_INVALID after the loader's one-line message ("coavoid: FILE: field: reason").
 * Either way the caller calls coavoid_scenario_free(s) afterwards. */
int coavoid_cli_load_scenario(const char *path, coavoid_scenario_t *s);

/* Samples every reference and track of a loaded scenario over its horizon
 * (coavoid_scenario_sample). Returns CLI_CONTINUE, or CLI_EXIT_INVALID after the one-line message
 * naming `path` and the field. */
int coavoid_cli_sample_scenario(const char *path, coavoid_scenario_t *s);

#endif /* COAVOID_APP_CLI_H */
