/* SPDX-License-Identifier: MIT */
#define _POSIX_C_SOURCE 200809L

#include "cli.h"

#include <assert.h>
#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "coavoid/coavoid.h"

/* One line on stderr, "coavoid: " then the message; control characters that came from the
 * input cannot split it. */
static void print_line(const char *fmt, va_list ap)
{
    char line[1024];
    vsnprintf(line, sizeof line, fmt, ap);
    for (char *c = line; *c != '\0'; c++) {
        if ((unsigned char)*c < 0x20u || *c == 0x7f) {
            *c = '?';
        }
    }
    fprintf(stderr, "coavoid: %s\n", line);
}

int coavoid_cli_fail(int status, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    print_line(fmt, ap);
    va_end(ap);
    return status;
}

void coavoid_cli_deprecated(const char *old, const char *use)
{
    /* The version that drops it: the next MINOR one (docs/library.md, "Versions"). */
    coavoid_cli_fail(0, "warning: %s is deprecated and goes in %d.%d.0: use %s", old,
                     COAVOID_VERSION_MAJOR, COAVOID_VERSION_MINOR + 1, use);
}

int coavoid_cli_run_status(int rc, const coavoid_run_error_t *e)
{
    switch (rc) {
    case COAVOID_RUN_DONE:
        return CLI_EXIT_OK;
    case COAVOID_RUN_NOT_SOLVED:
        return CLI_EXIT_NOT_SOLVED;
    case COAVOID_RUN_ERR_INPUT:
        return coavoid_cli_fail(CLI_EXIT_INVALID, "%s", e->text);
    default:
        return coavoid_cli_fail(CLI_EXIT_INTERNAL, "%s", e->text);
    }
}

bool coavoid_cli_option_is(const char *arg, const char *name)
{
    size_t length = strlen(name);
    return strncmp(arg, name, length) == 0 && (arg[length] == '\0' || arg[length] == '=');
}

bool coavoid_cli_option_value(int argc, char **argv, int *i, const char *name, const char **value)
{
    const char *arg = argv[*i];
    size_t length = strlen(name);
    if (arg[length] == '=') {
        *value = arg + length + 1;
        return true;
    }
    if (*i + 1 >= argc) {
        return false;
    }
    *value = argv[++*i];
    return true;
}

int coavoid_cli_text_option(int argc, char **argv, int *i, const char *name, const char *hint,
                            bool allow_empty, const char **text)
{
    const char *value = NULL;
    if (*text != NULL) {
        return coavoid_cli_fail(CLI_EXIT_INVALID, "%s: given more than once", name);
    }
    if (!coavoid_cli_option_value(argc, argv, i, name, &value) ||
        (value[0] == '\0' && !allow_empty)) {
        return coavoid_cli_fail(CLI_EXIT_INVALID, "%s: missing value (%s)", name, hint);
    }
    *text = value;
    return CLI_CONTINUE;
}

int coavoid_cli_count_option(int argc, char **argv, int *i, const char *name, const char *hint,
                             bool zero_ok, uint64_t max, const char **text, uint64_t *out)
{
    char range[64];
    const char *value = *text;
    snprintf(range, sizeof range, "an integer from %d to %llu", zero_ok ? 0 : 1,
             (unsigned long long)max);
    int status =
        coavoid_cli_text_option(argc, argv, i, name, hint != NULL ? hint : range, true, &value);
    if (status != CLI_CONTINUE) {
        return status;
    }
    if (!(zero_ok ? coavoid_cli_parse_index(value, max, out)
                  : coavoid_cli_parse_count(value, strlen(value), max, out))) {
        return coavoid_cli_fail(CLI_EXIT_INVALID, "%s: must be %s, got '%.40s'", name, range,
                                value);
    }
    *text = value;
    return CLI_CONTINUE;
}

int coavoid_cli_flag_option(const char *arg, const char *name, bool *flag)
{
    if (strcmp(arg, name) != 0) {
        return coavoid_cli_fail(CLI_EXIT_INVALID, "%s: takes no value", name);
    }
    if (*flag) {
        return coavoid_cli_fail(CLI_EXIT_INVALID, "%s: given more than once", name);
    }
    *flag = true;
    return CLI_CONTINUE;
}

int coavoid_cli_mode_option(int argc, char **argv, int *i, const char **mode, bool *decoupled)
{
    const char *value = *mode;
    int status =
        coavoid_cli_text_option(argc, argv, i, "--mode", "centralised or decoupled", true, &value);
    if (status != CLI_CONTINUE) {
        return status;
    }
    if (strcmp(value, "centralised") != 0 && strcmp(value, "decoupled") != 0) {
        return coavoid_cli_fail(CLI_EXIT_INVALID,
                                "--mode: unknown mode '%.40s' (expected centralised or decoupled)",
                                value);
    }
    *mode = value;
    if (decoupled != NULL) {
        *decoupled = strcmp(value, "decoupled") == 0;
    }
    return CLI_CONTINUE;
}

bool coavoid_cli_parse_count(const char *text, size_t length, uint64_t max, uint64_t *out)
{
    uint64_t value = 0;
    if (length == 0) {
        return false;
    }
    for (size_t i = 0; i < length; i++) {
        if (text[i] < '0' || text[i] > '9') {
            return false;
        }
        uint64_t digit = (uint64_t)(text[i] - '0');
        /* Checked before it happens: max may be UINT64_MAX, past which value would wrap. */
        if (digit > max || value > (max - digit) / 10u) {
            return false;
        }
        value = value * 10u + digit;
    }
    *out = value;
    return value >= 1;
}

bool coavoid_cli_parse_index(const char *text, uint64_t max, uint64_t *out)
{
    if (strcmp(text, "0") == 0) {
        *out = 0;
        return true;
    }
    return coavoid_cli_parse_count(text, strlen(text), max, out);
}

bool coavoid_cli_parse_real(const char *text, double *out)
{
    const char *c = text;
    bool digits = false;
    if (*c == '+' || *c == '-') {
        c++;
    }
    while ((*c >= '0' && *c <= '9') || *c == '.') {
        digits = digits || *c != '.';
        c++;
    }
    if (!digits) {
        return false;
    }
    if (*c == 'e' || *c == 'E') {
        c++;
        if (*c == '+' || *c == '-') {
            c++;
        }
        if (*c < '0' || *c > '9') {
            return false;
        }
    }
    char *end = NULL;
    errno = 0;
    double value = strtod(text, &end);
    if (end == text || *end != '\0' || !isfinite(value)) {
        return false;
    }
    *out = value;
    return true;
}

int64_t coavoid_cli_elapsed_us(const struct timespec *start, const struct timespec *end)
{
    return (int64_t)(end->tv_sec - start->tv_sec) * 1000000 +
           (int64_t)(end->tv_nsec - start->tv_nsec) / 1000;
}

int coavoid_cli_load_scenario(const char *path, coavoid_scenario_t *s)
{
    char err[COAVOID_SCENARIO_ERROR_MAX];
    if (coavoid_scenario_load(path, s, err, sizeof err) != 0) {
        return coavoid_cli_fail(CLI_EXIT_INVALID, "%s: %s", path, err);
    }
    return CLI_CONTINUE;
}

int coavoid_cli_sample_scenario(const char *path, coavoid_scenario_t *s)
{
    char err[COAVOID_SCENARIO_ERROR_MAX];
    if (coavoid_scenario_sample(s, err, sizeof err) != 0) {
        return coavoid_cli_fail(CLI_EXIT_INVALID, "%s: %s", path, err);
    }
    return CLI_CONTINUE;
}

/* Argument j of c was not given: one line naming it, CLI_EXIT_INVALID. */
static int missing_argument(const coavoid_cli_command_t *c, size_t j)
{
    return coavoid_cli_fail(CLI_EXIT_INVALID, "%s: missing %s (see '%s --help')", c->name,
                            c->arguments[j], c->see);
}

int coavoid_cli_parse_args(const coavoid_cli_command_t *c, int argc, char **argv, void *options,
                           const char **args)
{
    size_t wanted = 0;
    size_t given = 0;
    bool options_done = false;
    while (wanted < sizeof c->arguments / sizeof c->arguments[0] && c->arguments[wanted] != NULL) {
        wanted++;
    }
    for (int i = c->first; i < argc; i++) {
        const char *arg = argv[i];
        if (options_done || arg[0] != '-' || (wanted > 0u && strcmp(arg, "-") == 0)) {
            if (given == wanted) {
                return coavoid_cli_fail(CLI_EXIT_INVALID, "%s: unexpected argument '%.80s' (%s)",
                                        c->name, arg, c->too_many);
            }
            args[given++] = arg;
            continue;
        }
        if (wanted > 0u && strcmp(arg, "--") == 0) {
            options_done = true;
            continue;
        }
        if (strcmp(arg, "-h") == 0 || strcmp(arg, "--help") == 0) {
            c->help();
            return CLI_EXIT_OK;
        }
        if (strcmp(arg, "--version") == 0) {
            coavoid_cli_print_version(c->see);
            return CLI_EXIT_OK;
        }
        int status = c->option(argc, argv, &i, options);
        if (status == CLI_UNKNOWN_OPTION) {
            return coavoid_cli_fail(CLI_EXIT_INVALID,
                                    "%s: unknown option '%.40s' (see '%s --help')", c->name, arg,
                                    c->see);
        }
        if (status != CLI_CONTINUE) {
            return status;
        }
    }
    if (given < wanted && !c->arguments_optional) {
        return missing_argument(c, given);
    }
    return CLI_CONTINUE;
}

int coavoid_cli_scenario_option(int argc, char **argv, int *i, const char **path)
{
    coavoid_cli_deprecated("--scenario FILE", "the scenario as the first argument");
    return coavoid_cli_text_option(argc, argv, i, "--scenario", "a scenario file", false, path);
}

int coavoid_cli_scenario_given(const coavoid_cli_command_t *c, const char *argument,
                               const char **path)
{
    if (argument != NULL && *path != NULL) {
        return coavoid_cli_fail(
            CLI_EXIT_INVALID, "%s: the scenario is given twice, as '%.80s' and --scenario '%.80s'",
            c->name, argument, *path);
    }
    if (argument != NULL) {
        *path = argument;
    }
    if (*path == NULL) {
        return missing_argument(c, 0);
    }
    return CLI_CONTINUE;
}

void coavoid_cli_print_version(const char *program)
{
    const char *space = strchr(program, ' ');
    int length = space != NULL ? (int)(space - program) : (int)strlen(program);
    printf("%.*s %s (%s precision)\n", length, program, COAVOID_VERSION,
           sizeof(coa_real_t) == sizeof(float) ? "single" : "double");
}

int coavoid_cli_run_scenario(const char *path, int (*run)(void *options, coavoid_scenario_t *s),
                             void *options)
{
    coavoid_scenario_t scenario;
    int status = coavoid_cli_load_scenario(path, &scenario);
    if (status == CLI_CONTINUE) {
        status = run(options, &scenario);
    }
    coavoid_scenario_free(&scenario);
    return status;
}

/* A real option's value into *out when check(value) holds: CLI_CONTINUE, or the error
 * "NAME: must be WHAT, got 'VALUE'". */
static int real_option(int argc, char **argv, int *i, const char *name, const char *what,
                       double max, const char **text, double *out)
{
    const char *value = *text;
    int status = coavoid_cli_text_option(argc, argv, i, name, what, false, &value);
    if (status != CLI_CONTINUE) {
        return status;
    }
    if (!coavoid_cli_parse_real(value, out) || !(*out >= 0.0 && *out < max)) {
        return coavoid_cli_fail(CLI_EXIT_INVALID, "%s: must be %s, got '%.40s'", name, what, value);
    }
    *text = value;
    return CLI_CONTINUE;
}

int coavoid_cli_network_option(int argc, char **argv, int *i, bool with_seed,
                               coavoid_cli_network_t *n)
{
    const char *arg = argv[*i];
    /* Seconds beyond an hour are a typo: no cycle is that long. */
    const double max_s = 3600.0;
    if (coavoid_cli_option_is(arg, "--loss")) {
        return real_option(argc, argv, i, "--loss", "a probability from 0 to below 1", 1.0,
                           &n->loss_text, &n->loss);
    }
    if (coavoid_cli_option_is(arg, "--delay")) {
        return real_option(argc, argv, i, "--delay", "a time in seconds, 0 or more (below 3600)",
                           max_s, &n->delay_text, &n->delay);
    }
    if (coavoid_cli_option_is(arg, "--jitter")) {
        return real_option(argc, argv, i, "--jitter", "a time in seconds, 0 or more (below 3600)",
                           max_s, &n->jitter_text, &n->jitter);
    }
    if (with_seed && coavoid_cli_option_is(arg, "--net-seed")) {
        return coavoid_cli_count_option(argc, argv, i, "--net-seed", NULL, true, UINT64_MAX,
                                        &n->seed_text, &n->seed);
    }
    if (with_seed && coavoid_cli_option_is(arg, "--seed")) {
        coavoid_cli_deprecated("--seed N (the network's seed)", "--net-seed N");
        return coavoid_cli_count_option(argc, argv, i, "--seed", NULL, true, UINT64_MAX,
                                        &n->seed_text, &n->seed);
    }
    return CLI_UNKNOWN_OPTION;
}

bool coavoid_cli_network_given(const coavoid_cli_network_t *n)
{
    return n->loss_text != NULL || n->delay_text != NULL || n->jitter_text != NULL;
}
