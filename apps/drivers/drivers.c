/* SPDX-License-Identifier: MIT */
/*
 * drivers.c: the options every real-time driver shares, the set-up from a scenario and
 * the run of one node with its summary line (drivers.h).
 */
#define _POSIX_C_SOURCE 200809L

#include "drivers.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <string.h>
#include <sys/stat.h>

#include "cli.h"

/* Largest --steps: a day of 0.1 s cycles; more is a typo, not a run. */
#define RT_MAX_STEPS 1000000u

/* ---- options ---- */

void coavoid_rt_options_init(coavoid_rt_options_t *o)
{
    memset(o, 0, sizeof *o);
    o->speed = 1.0;
}

int coavoid_rt_parse_option(int argc, char **argv, int *i, coavoid_rt_options_t *o)
{
    const char *arg = argv[*i];
    uint64_t value = 0;
    int status = CLI_UNKNOWN_OPTION;
    if (coavoid_cli_option_is(arg, "--lcm-url")) {
        status = coavoid_cli_text_option(argc, argv, i, "--lcm-url",
                                         "an LCM URL, e.g. " COAVOID_RT_DEFAULT_LCM_URL, false,
                                         &o->lcm_url);
    } else if (coavoid_cli_option_is(arg, "--epoch")) {
        status = coavoid_cli_text_option(
            argc, argv, i, "--epoch", "wall-clock microseconds since 1970", true, &o->epoch_text);
        if (status == CLI_CONTINUE && !coavoid_cli_parse_count(o->epoch_text, strlen(o->epoch_text),
                                                               (uint64_t)INT64_MAX, &value)) {
            status =
                coavoid_cli_fail(CLI_EXIT_INVALID,
                                 "--epoch: must be a positive integer (wall-clock microseconds "
                                 "since 1970), got '%.40s'",
                                 o->epoch_text);
        }
        o->epoch_utime = (int64_t)value;
    } else if (coavoid_cli_option_is(arg, "--speed")) {
        status = coavoid_cli_text_option(argc, argv, i, "--speed",
                                         "scenario seconds per wall second", true, &o->speed_text);
        if (status == CLI_CONTINUE && (!coavoid_cli_parse_real(o->speed_text, &o->speed) ||
                                       !(o->speed > 0) || o->speed > COAVOID_RT_MAX_SPEED)) {
            status = coavoid_cli_fail(CLI_EXIT_INVALID,
                                      "--speed: must be a number with 0 < S <= %g, got '%.40s'",
                                      COAVOID_RT_MAX_SPEED, o->speed_text);
        }
    } else if (coavoid_cli_option_is(arg, "--steps")) {
        status = coavoid_cli_count_option(argc, argv, i, "--steps", "an integer >= 1", false,
                                          RT_MAX_STEPS, &o->steps_text, &value);
        o->steps = (int64_t)value;
    } else if (coavoid_cli_option_is(arg, "--key")) {
        status = coavoid_cli_text_option(argc, argv, i, "--key", "a secret key file", false,
                                         &o->key_path);
    } else if (coavoid_cli_option_is(arg, "--trust")) {
        status = coavoid_cli_text_option(argc, argv, i, "--trust", "a trust file", false,
                                         &o->trust_path);
    } else if (coavoid_cli_option_is(arg, "--insecure")) {
        status = coavoid_cli_flag_option(arg, "--insecure", &o->insecure);
    }
    return status;
}

int coavoid_rt_driver_option(int argc, char **argv, int *i, coavoid_rt_options_t *o,
                             const char **scenario_path)
{
    if (coavoid_cli_option_is(argv[*i], "--scenario")) {
        return coavoid_cli_scenario_option(argc, argv, i, scenario_path);
    }
    return coavoid_rt_parse_option(argc, argv, i, o);
}

/* ---- keys ---- */

/* Reads the file at path (at most COAVOID_RT_KEY_FILE_MAX bytes) into buf; its length, or
 * -1 after the one-line error. A secret key must be readable by its owner only. */
static long read_key_file(const char *option, const char *path, bool secret, char *buf)
{
    FILE *f = fopen(path, "rb");
    if (f == NULL) {
        coavoid_cli_fail(CLI_EXIT_INVALID, "%s: cannot read '%.200s': %s", option, path,
                         strerror(errno));
        return -1;
    }
    struct stat st;
    if (secret && fstat(fileno(f), &st) == 0 && (st.st_mode & (S_IRWXG | S_IRWXO)) != 0) {
        fclose(f);
        coavoid_cli_fail(CLI_EXIT_INVALID,
                         "%s: '%.200s' is readable by others (mode %03o): a secret key must be "
                         "its owner's only (chmod 600)",
                         option, path, (unsigned)(st.st_mode & 0777));
        return -1;
    }
    size_t n = fread(buf, 1, COAVOID_RT_KEY_FILE_MAX, f);
    const bool more = n == COAVOID_RT_KEY_FILE_MAX && fgetc(f) != EOF;
    const bool failed = ferror(f) != 0;
    fclose(f);
    if (more || failed) {
        coavoid_cli_fail(CLI_EXIT_INVALID, "%s: '%.200s': %s", option, path,
                         more ? "larger than 64 KiB" : "read error");
        return -1;
    }
    return (long)n;
}

int coavoid_rt_load_trust(const char *path, coavoid_auth_trust_t *t)
{
    static char text[COAVOID_RT_KEY_FILE_MAX];
    char why[COAVOID_AUTH_LINE_MAX];
    long n = read_key_file("--trust", path, false, text);
    if (n < 0) {
        return CLI_EXIT_INVALID;
    }
    int rc = coavoid_auth_trust_parse(t, text, (size_t)n, why, sizeof why);
    memset(text, 0, sizeof text);
    if (rc != COA_OK) {
        return coavoid_cli_fail(CLI_EXIT_INVALID, "--trust: %.200s: %s", path, why);
    }
    /* The fleet key is a secret: its file is kept as a secret key's is. */
    struct stat st;
    if (t->has_fleet_key && stat(path, &st) == 0 && (st.st_mode & (S_IRWXG | S_IRWXO)) != 0) {
        return coavoid_cli_fail(CLI_EXIT_INVALID,
                                "--trust: '%.200s' holds the fleet key and is readable by others "
                                "(mode %03o): it must be its owner's only (chmod 600)",
                                path, (unsigned)(st.st_mode & 0777));
    }
    return CLI_CONTINUE;
}

int coavoid_rt_keys(coavoid_rt_options_t *o, coavoid_auth_role_t role, uint16_t node_id,
                    coavoid_node_common_t *common)
{
    if (o->insecure) {
        if (o->key_path != NULL || o->trust_path != NULL) {
            return coavoid_cli_fail(CLI_EXIT_INVALID,
                                    "--insecure: cannot go with --key or --trust (choose one)");
        }
        common->insecure = true;
        return CLI_CONTINUE;
    }
    if (o->key_path == NULL || o->trust_path == NULL) {
        return coavoid_cli_fail(CLI_EXIT_INVALID,
                                "%s: required: every message is signed and checked "
                                "(coavoid keygen writes keys), or --insecure to run without",
                                o->key_path == NULL ? "--key" : "--trust");
    }
    static char text[COAVOID_RT_KEY_FILE_MAX];
    char why[COAVOID_AUTH_LINE_MAX];
    long n = read_key_file("--key", o->key_path, true, text);
    if (n < 0) {
        return CLI_EXIT_INVALID;
    }
    int rc = coavoid_auth_signer_parse(&o->signer, text, (size_t)n, why, sizeof why);
    memset(text, 0, sizeof text);
    if (rc != COA_OK) {
        return coavoid_cli_fail(CLI_EXIT_INVALID, "--key: %.200s: %s", o->key_path, why);
    }
    common->signer = &o->signer;
    if (coavoid_rt_load_trust(o->trust_path, &o->trust) != CLI_CONTINUE) {
        return CLI_EXIT_INVALID;
    }
    if (coavoid_auth_signer_matches(&o->trust, &o->signer, role, node_id) != COA_OK) {
        return coavoid_cli_fail(CLI_EXIT_INVALID,
                                "--key: key %lu is not this node's in %.200s (its role, node id "
                                "%u, and public key must be listed there)",
                                (unsigned long)o->signer.key_id, o->trust_path, (unsigned)node_id);
    }
    coavoid_auth_signer_use_fleet(&o->signer, &o->trust);
    common->trust = &o->trust;
    return CLI_CONTINUE;
}

int coavoid_rt_options_finish(coavoid_rt_options_t *o, int64_t dt_us, uint32_t horizon)
{
    if (o->lcm_url == NULL) {
        o->lcm_url = COAVOID_RT_DEFAULT_LCM_URL;
    }
    if (o->steps_text == NULL) {
        o->steps = 2 * (int64_t)horizon;
    }
    int64_t now = coavoid_rt_wall_utime();
    if (o->epoch_text == NULL) {
        o->epoch_utime = now;
        return CLI_CONTINUE;
    }
    if (o->epoch_utime > now && o->epoch_utime - now > COAVOID_RT_MAX_EPOCH_AHEAD_US) {
        return coavoid_cli_fail(
            CLI_EXIT_INVALID,
            "--epoch: %lld is more than a day ahead of this clock (%lld): it is "
            "microseconds since 1970, e.g. $(( $(date +%%s) + 2 ))000000",
            (long long)o->epoch_utime, (long long)now);
    }
    /* The run's last event is the start of cycle K, in wall time. */
    double run_us = (double)o->steps * (double)dt_us / o->speed;
    double end = (double)o->epoch_utime + run_us;
    if (end < (double)now) {
        return coavoid_cli_fail(CLI_EXIT_INVALID,
                                "--epoch: the run of %lld cycles from %lld ended %.1f s ago (this "
                                "clock: %lld)",
                                (long long)o->steps, (long long)o->epoch_utime,
                                ((double)now - end) * 1e-6, (long long)now);
    }
    return CLI_CONTINUE;
}

int coavoid_rt_setup(const char *path, coavoid_scenario_t *s, coavoid_rt_options_t *o,
                     const int64_t *now, coavoid_node_common_t *common)
{
    int status = coavoid_cli_sample_scenario(path, s);
    if (status != CLI_CONTINUE) {
        return status;
    }
    if (s->horizon > COAVOID_NODE_MAX_HORIZON) {
        return coavoid_cli_fail(CLI_EXIT_INVALID,
                                "%s: horizon: %lu steps, the nodes' messages carry at most %u",
                                path, (unsigned long)s->horizon, COAVOID_NODE_MAX_HORIZON);
    }
    int64_t dt_us = llround((double)s->dt * 1e6);
    if (dt_us < 1) {
        return coavoid_cli_fail(CLI_EXIT_INVALID, "%s: dt: below a microsecond", path);
    }
    status = coavoid_rt_options_finish(o, dt_us, s->horizon);
    if (status != CLI_CONTINUE) {
        return status;
    }
    if (coavoid_node_common_defaults(common, o->epoch_utime, s->dt, s->horizon, now) != COA_OK) {
        return coavoid_cli_fail(CLI_EXIT_INVALID, "%s: dt or horizon refused by the nodes", path);
    }
    common->stopwatch_us = coavoid_rt_stopwatch_us;
    common->stopwatch_user = NULL;
    if (s->has_beta) {
        common->beta = s->beta;
    }
    /* Every node keeps the scenario's obstacles as its own terrain database: the world's
     * map may add to them, never take them away. */
    if (s->obstacle_count > COAVOID_NODE_MAX_CONFIGURED_OBSTACLES) {
        return coavoid_cli_fail(CLI_EXIT_INVALID,
                                "%s: obstacles: %zu, a node holds at most %u of its own", path,
                                s->obstacle_count, COAVOID_NODE_MAX_CONFIGURED_OBSTACLES);
    }
    common->obstacles = s->obstacles;
    common->has_floor = s->has_floor;
    common->min_altitude = s->min_altitude;
    common->obstacle_count = s->obstacle_count;
    return CLI_CONTINUE;
}

/* ---- the loop ---- */

int coavoid_rt_transport_open_send_only(coavoid_rt_transport_t *t, const char *url)
{
    char err[512];
    t->rx = NULL;
    t->lcm = coavoid_rt_lcm_create(url, err, sizeof err);
    if (t->lcm == NULL) {
        return coavoid_cli_fail(CLI_EXIT_INVALID, "%s", err);
    }
    return CLI_CONTINUE;
}

int coavoid_rt_transport_open(coavoid_rt_transport_t *t, const char *url,
                              coavoid_node_common_t *common)
{
    char err[512];
    int status = coavoid_rt_transport_open_send_only(t, url);
    if (status != CLI_CONTINUE) {
        return status;
    }
    if (coavoid_rt_rx_is_udpm(url)) {
        t->rx = coavoid_rt_rx_open(url, err, sizeof err);
        if (t->rx == NULL) {
            lcm_destroy(t->lcm);
            t->lcm = NULL;
            return coavoid_cli_fail(CLI_EXIT_INVALID, "%s", err);
        }
        common->transport_dropped = &coavoid_rt_rx_stats(t->rx)->kernel_dropped;
    }
    return CLI_CONTINUE;
}

lcm_t *coavoid_rt_transport_rx_lcm(const coavoid_rt_transport_t *t)
{
    return t->rx != NULL ? coavoid_rt_rx_lcm(t->rx) : NULL;
}

void coavoid_rt_transport_close(coavoid_rt_transport_t *t)
{
    coavoid_rt_rx_close(t->rx);
    if (t->lcm != NULL) {
        lcm_destroy(t->lcm);
    }
    t->rx = NULL;
    t->lcm = NULL;
}

void coavoid_rt_loop_init(coavoid_rt_loop_t *loop, const coavoid_rt_options_t *o,
                          const coavoid_rt_transport_t *transport, int64_t *now,
                          const coavoid_node_common_t *common, const char *name)
{
    memset(loop, 0, sizeof *loop);
    loop->clock.epoch_utime = o->epoch_utime;
    loop->clock.speed = o->speed;
    loop->lcm = transport->lcm;
    loop->rx = transport->rx;
    loop->now = now;
    loop->common = common;
    loop->steps = o->steps;
    loop->name = name;
    loop->warnings = stderr;
}

int coavoid_rt_drive(const coavoid_rt_loop_t *loop, const char *lcm_url, coavoid_rt_report_t report,
                     void *user)
{
    if (coavoid_rt_install_signal_handlers() != 0) {
        return coavoid_cli_fail(CLI_EXIT_INTERNAL, "%s: cannot handle SIGINT/SIGTERM", loop->name);
    }
    coavoid_rt_result_t result;
    int rc = coavoid_rt_run(loop, &result);
    char tail[512];
    coavoid_rt_result_text(&result, tail, sizeof tail);
    report(user, loop->name, &result, tail);
    if (rc != COA_OK) {
        return coavoid_cli_fail(CLI_EXIT_INTERNAL, "%s: LCM failed while running (%s)", loop->name,
                                lcm_url);
    }
    return result.errors > 0 ? CLI_EXIT_INTERNAL : CLI_EXIT_OK;
}
