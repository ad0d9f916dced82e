/* SPDX-License-Identifier: MIT */
/* A vehicle's options and its configuration (vehicle_options.h). */
#include "vehicle_options.h"

#include <math.h>
#include <string.h>

#include "cli.h"

/* Its joint search's workspace grows by 2 bytes per node (docs/benchmarks.md). */
#define VEHICLE_MAX_JOINT_BETA 1000000u

/* A duration option in scenario seconds: finite, >= 0 (> 0 unless zero_ok). */
static int parse_seconds(int argc, char **argv, int *i, const char *name, bool zero_ok,
                         const char **text, double *out)
{
    int status = coavoid_cli_text_option(argc, argv, i, name, "scenario seconds", true, text);
    if (status == CLI_CONTINUE && (!coavoid_cli_parse_real(*text, out) || *out < 0 ||
                                   (*out == 0 && !zero_ok) || *out > COAVOID_LCM_MAX_STEP)) {
        status = coavoid_cli_fail(CLI_EXIT_INVALID,
                                  "%s: must be a number of seconds, %s %g, got '%.40s'", name,
                                  zero_ok ? "0 <= S <=" : "0 < S <=", COAVOID_LCM_MAX_STEP, *text);
    }
    return status;
}

/* The help and the hint below name the bound as text. */
_Static_assert(COA_MAX_CENTRALISED == 10u, "--joint-members: 0 or 2 to 10");

int coavoid_joint_members_option(int argc, char **argv, int *i, const char **text, uint64_t *value)
{
    int status = coavoid_cli_count_option(argc, argv, i, "--joint-members", "0 or 2 to 10", true,
                                          COA_MAX_CENTRALISED, text, value);
    if (status == CLI_CONTINUE && *value == 1u) {
        status = coavoid_cli_fail(CLI_EXIT_INVALID,
                                  "--joint-members: must be 0 or 2 to %u, got 1 (a group of "
                                  "one is planned alone)",
                                  COA_MAX_CENTRALISED);
    }
    return status;
}

int coavoid_vehicle_option(int argc, char **argv, int *i, coavoid_vehicle_options_t *o)
{
    const char *arg = argv[*i];
    uint64_t value = 0;
    int status = coavoid_rt_driver_option(argc, argv, i, &o->rt, &o->scenario_path);
    if (status != CLI_UNKNOWN_OPTION) {
        return status;
    }
    if (coavoid_cli_option_is(arg, "--id")) {
        status = coavoid_cli_text_option(argc, argv, i, "--id", "a vehicle id", true, &o->id_text);
        if (status == CLI_CONTINUE &&
            !coavoid_cli_parse_count(o->id_text, strlen(o->id_text), 65535u, &value)) {
            status = coavoid_cli_fail(CLI_EXIT_INVALID,
                                      "--id: must be a vehicle id from 1 to 65535, got '%.40s'",
                                      o->id_text);
        }
        o->id = (uint16_t)value;
    } else if (coavoid_cli_option_is(arg, "--list-ids")) {
        status = coavoid_cli_flag_option(arg, "--list-ids", &o->list_ids);
    } else if (coavoid_cli_option_is(arg, "--mode")) {
        status = coavoid_cli_mode_option(argc, argv, i, &o->mode, &o->decoupled);
    } else if (coavoid_cli_option_is(arg, "--coordinator-timeout")) {
        status = parse_seconds(argc, argv, i, "--coordinator-timeout", false, &o->timeout_text,
                               &o->timeout);
    } else if (coavoid_cli_option_is(arg, "--coordinator-id")) {
        status = coavoid_cli_text_option(argc, argv, i, "--coordinator-id", "a node id", true,
                                         &o->coordinator_text);
        if (status == CLI_CONTINUE &&
            !coavoid_cli_parse_count(o->coordinator_text, strlen(o->coordinator_text), 65535u,
                                     &value)) {
            status =
                coavoid_cli_fail(CLI_EXIT_INVALID,
                                 "--coordinator-id: must be a node id from 1 to 65535, got '%.40s'",
                                 o->coordinator_text);
        }
        o->coordinator_id = (uint16_t)value;
    } else if (coavoid_cli_option_is(arg, "--priority-wait")) {
        status = parse_seconds(argc, argv, i, "--priority-wait", true, &o->wait_text, &o->wait);
    } else if (coavoid_cli_option_is(arg, "--joint-members")) {
        status =
            coavoid_joint_members_option(argc, argv, i, &o->joint_members_text, &o->joint_members);
    } else if (coavoid_cli_option_is(arg, "--joint-beta")) {
        status =
            coavoid_cli_count_option(argc, argv, i, "--joint-beta", NULL, false,
                                     VEHICLE_MAX_JOINT_BETA, &o->joint_beta_text, &o->joint_beta);
    }
    return status;
}

void coavoid_vehicle_options_init(coavoid_vehicle_options_t *o)
{
    memset(o, 0, sizeof *o);
    coavoid_rt_options_init(&o->rt);
}

int coavoid_vehicle_options_check(const coavoid_vehicle_options_t *o)
{
    if (o->id_text == NULL) {
        return coavoid_cli_fail(CLI_EXIT_INVALID, "--id: required (which vehicle of the scenario)");
    }
    /* The coordinator timeout only decides when a centralised vehicle plans for itself. */
    if (o->decoupled && o->timeout_text != NULL) {
        return coavoid_cli_fail(CLI_EXIT_INVALID,
                                "--coordinator-timeout: only valid with --mode centralised");
    }
    if (o->decoupled && o->coordinator_text != NULL) {
        return coavoid_cli_fail(CLI_EXIT_INVALID,
                                "--coordinator-id: only valid with --mode centralised");
    }
    /* The joint plan is the coordinator's plan, made by its vehicles when it is gone. */
    if (o->decoupled && (o->joint_members_text != NULL || o->joint_beta_text != NULL)) {
        return coavoid_cli_fail(CLI_EXIT_INVALID, "%s: only valid with --mode centralised",
                                o->joint_members_text != NULL ? "--joint-members" : "--joint-beta");
    }
    if (o->joint_beta_text != NULL && o->joint_members_text != NULL && o->joint_members == 0u) {
        return coavoid_cli_fail(CLI_EXIT_INVALID,
                                "--joint-beta: --joint-members 0 plans no group jointly");
    }
    if (o->coordinator_text != NULL && o->coordinator_id == o->id) {
        return coavoid_cli_fail(CLI_EXIT_INVALID, "--coordinator-id: %u is this vehicle's own id",
                                (unsigned)o->id);
    }
    return CLI_CONTINUE;
}

int coavoid_vehicle_options_config(coavoid_vehicle_options_t *o, coavoid_scenario_t *s,
                                   const int64_t *now, coavoid_vehicle_node_config_t *config)
{
    memset(config, 0, sizeof *config);
    int status = coavoid_rt_setup(o->scenario_path, s, &o->rt, now, &config->common);
    if (status != CLI_CONTINUE) {
        return status;
    }
    long index = coavoid_scenario_vehicle_index(s, (long)o->id);
    if (index < 0) {
        return coavoid_cli_fail(CLI_EXIT_INVALID, "--id: %s has no vehicle %u", o->scenario_path,
                                (unsigned)o->id);
    }
    status = coavoid_rt_keys(&o->rt, COAVOID_AUTH_VEHICLE, o->id, &config->common);
    if (status != CLI_CONTINUE) {
        return status;
    }
    const int64_t dt_us = config->common.dt_us;
    config->vehicle = s->vehicles[index];
    config->mode = o->decoupled ? COAVOID_NODE_DECOUPLED : COAVOID_NODE_CENTRALISED;
    config->coordinator_id = o->coordinator_id; /* 0: the default */
    config->intent_copies = COAVOID_NODE_DEFAULT_COPIES;
    config->joint_members = o->joint_members_text != NULL
                                ? (size_t)o->joint_members
                                : coavoid_node_joint_members(config->mode, s->vehicle_count);
    config->joint_beta = (uint32_t)o->joint_beta; /* 0: the default */
    config->coordinator_timeout_us =
        o->timeout_text != NULL ? llround(o->timeout * 1e6) : llround(2.5 * (double)dt_us);
    config->priority_wait_us = o->wait_text != NULL ? llround(o->wait * 1e6) : dt_us / 2;
    if (config->coordinator_timeout_us < 1) {
        return coavoid_cli_fail(CLI_EXIT_INVALID, "--coordinator-timeout: below a microsecond");
    }
    /* A wait into the next cycle would publish this cycle's intent after the next one's. */
    if (config->priority_wait_us >= dt_us) {
        return coavoid_cli_fail(CLI_EXIT_INVALID,
                                "--priority-wait: %g s is not less than the scenario's dt (%g s)",
                                o->wait, (double)s->dt);
    }
    return CLI_CONTINUE;
}
