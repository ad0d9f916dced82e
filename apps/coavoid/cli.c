#define _POSIX_C_SOURCE 200809L

#include "cli.h"

#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "coavoid/coavoid.h"

int cli_fail(int status, const char *fmt, ...)
{
    char line[1024];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(line, sizeof line, fmt, ap);
    va_end(ap);
    for (char *c = line; *c != '\0'; c++) {
        if ((unsigned char)*c < 0x20u || *c == 0x7f) {
            *c = '?';
        }
    }
    fprintf(stderr, "coavoid: %s\n", line);
    return status;
}

bool cli_option_is(const char *arg, const char *name)
{
    size_t length = strlen(name);
    return strncmp(arg, name, length) == 0 && (arg[length] == '\0' || arg[length] == '=');
}

bool cli_option_value(int argc, char **argv, int *i, const char *name, const char **value)
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

bool cli_parse_count(const char *text, size_t length, uint64_t max, uint64_t *out)
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

bool cli_parse_real(const char *text, double *out)
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

bool cli_workspace_fits(size_t searched, uint32_t beta)
{
    size_t size = coa_planner_workspace_size(searched, beta);
    return size != 0u && size <= CLI_DEFAULT_WORKSPACE_MAX;
}

uint32_t cli_default_beta(size_t searched)
{
    uint32_t lo = 1u;
    uint32_t hi = CLI_DEFAULT_BETA;
    while (lo < hi) {
        uint32_t mid = lo + (hi - lo + 1u) / 2u;
        if (cli_workspace_fits(searched, mid)) {
            lo = mid;
        } else {
            hi = mid - 1u;
        }
    }
    return lo;
}

int64_t cli_elapsed_us(const struct timespec *start, const struct timespec *end)
{
    return (int64_t)(end->tv_sec - start->tv_sec) * 1000000 +
           (int64_t)(end->tv_nsec - start->tv_nsec) / 1000;
}

int cli_load_scenario(const char *path, scenario_t *s)
{
    char err[SCENARIO_ERROR_MAX];
    if (scenario_load(path, s, err, sizeof err) != 0) {
        return cli_fail(CLI_EXIT_INVALID, "%s: %s", path, err);
    }
    return CLI_CONTINUE;
}

int cli_sample_scenario(const char *path, scenario_t *s)
{
    char err[SCENARIO_ERROR_MAX];
    if (scenario_sample(s, err, sizeof err) != 0) {
        return cli_fail(CLI_EXIT_INVALID, "%s: %s", path, err);
    }
    return CLI_CONTINUE;
}
