/*
 * coavoid world: the terrain database and the tracker of a real-time run, standing in for
 * the ground station's sources: every cycle it publishes the scenario's obstacle map and
 * the estimate of every non-cooperative track at that cycle's start. The node is
 * apps/node/world.c, run in real time by apps/node/realtime.c. See WORLD_USAGE below.
 */
#define _POSIX_C_SOURCE 200809L

#include <stdio.h>
#include <string.h>

#include "cli.h"
#include "commands.h"

#ifdef COAVOID_HAVE_NODE

#include "node.h"
#include "realtime.h"
#include "scenario.h"

#define WORLD_USAGE                                                                           \
    "usage: coavoid world SCENARIO.json [--lcm-url URL] [--epoch UTIME] [--speed S]\n"       \
    "                     [--steps K]\n"                                                      \
    "\n"                                                                                      \
    "Publishes the scenario's obstacle map and its tracks' estimates over LCM every cycle\n" \
    "of a real-time run, for the coordinator and the vehicles (coavoid-coordinator,\n"       \
    "coavoid-vehicle).\n"                                                                     \
    "\n"                                                                                      \
    "options:\n" COA_RT_OPTIONS_USAGE                                                         \
    "  -h, --help          show this help\n"                                                  \
    "\n"                                                                                      \
    "exit status: 0 done, 2 invalid input or usage (one line on stderr), 3 internal error\n"

int command_world(int argc, char **argv)
{
    const char *path = NULL;
    coa_rt_options_t rt;
    coa_rt_options_init(&rt);
    bool options_done = false;
    for (int i = 2; i < argc; i++) {
        const char *arg = argv[i];
        if (options_done || arg[0] != '-' || strcmp(arg, "-") == 0) {
            if (path != NULL) {
                return cli_fail(CLI_EXIT_INVALID,
                                "world: unexpected argument '%.80s' (one scenario only)", arg);
            }
            path = arg;
            continue;
        }
        if (strcmp(arg, "--") == 0) {
            options_done = true;
            continue;
        }
        if (strcmp(arg, "-h") == 0 || strcmp(arg, "--help") == 0) {
            fputs(WORLD_USAGE, stdout);
            return CLI_EXIT_OK;
        }
        int rc = coa_rt_parse_option(argc, argv, &i, &rt);
        if (rc == 0) {
            return cli_fail(CLI_EXIT_INVALID,
                            "world: unknown option '%.40s' (see 'coavoid world --help')", arg);
        }
        if (rc != 1) {
            return rc;
        }
    }
    if (path == NULL) {
        return cli_fail(CLI_EXIT_INVALID,
                        "world: missing SCENARIO.json (see 'coavoid world --help')");
    }

    int64_t now = 0; /* the node's clock (common.clock), written by the loop */
    scenario_t s;
    memset(&s, 0, sizeof s);
    coa_world_config_t config;
    memset(&config, 0, sizeof config);
    int status = coa_rt_setup(path, &s, &rt, &now, &config.common);
    if (status != CLI_CONTINUE) {
        scenario_free(&s);
        return status;
    }
    config.id = COA_NODE_WORLD_ID;
    config.obstacles = s.obstacles;
    config.obstacle_count = s.obstacle_count;
    config.tracks = s.tracks;
    config.track_count = s.track_count;

    char err[512];
    lcm_t *lcm = coa_rt_lcm_create(rt.lcm_url, err, sizeof err);
    if (lcm == NULL) {
        scenario_free(&s);
        return cli_fail(CLI_EXIT_INVALID, "%s", err);
    }
    int error = COA_OK;
    coa_world_t *node = coa_world_create(&config, lcm, &error);
    if (node == NULL) {
        lcm_destroy(lcm);
        scenario_free(&s);
        return cli_fail(error == COA_ERR_ARGUMENT ? CLI_EXIT_INVALID : CLI_EXIT_INTERNAL,
                        "world: %s: cannot publish it (%s)", path, coa_lcm_error_name(error));
    }
    if (coa_rt_install_signal_handlers() != 0) {
        coa_world_destroy(node);
        lcm_destroy(lcm);
        scenario_free(&s);
        return cli_fail(CLI_EXIT_INTERNAL, "world: cannot handle SIGINT/SIGTERM");
    }

    coa_rt_loop_t loop;
    memset(&loop, 0, sizeof loop);
    loop.clock.epoch_utime = rt.epoch_utime;
    loop.clock.speed = rt.speed;
    loop.lcm = lcm;
    loop.now = &now;
    loop.common = &config.common;
    loop.steps = rt.steps;
    loop.world = node;
    loop.world_lead_us = config.common.dt_us / 4;
    loop.name = "world";
    loop.warnings = stderr;
    coa_rt_result_t result;
    int rc = coa_rt_run(&loop, &result);

    char tail[256];
    coa_rt_result_text(&result, tail, sizeof tail);
    fprintf(stderr, "world: %lld cycles, %zu obstacles and %zu tracks published each%s\n",
            (long long)result.cycles, s.obstacle_count, s.track_count, tail);
    coa_world_destroy(node);
    lcm_destroy(lcm);
    scenario_free(&s);
    if (rc != COA_OK) {
        return cli_fail(CLI_EXIT_INTERNAL, "world: LCM failed while running (%s)", rt.lcm_url);
    }
    return result.errors > 0 ? CLI_EXIT_INTERNAL : CLI_EXIT_OK;
}

#else

int command_world(int argc, char **argv)
{
    (void)argc;
    (void)argv;
    return cli_fail(CLI_EXIT_INVALID,
                    "world: not built (this coavoid was built without LCM: COAVOID_BUILD_LCM)");
}

#endif
