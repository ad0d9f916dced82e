/* SPDX-License-Identifier: MIT */
/*
 * coavoid world: the terrain database and the tracker of a real-time run, standing in for
 * the ground station's sources: every cycle it publishes the scenario's obstacle map and
 * the estimate of every non-cooperative track at that cycle's start. The node is
 * src/node/world.c, run in real time by src/realtime/realtime.c. See WORLD_USAGE below.
 */
#define _POSIX_C_SOURCE 200809L

#include <stdio.h>
#include <string.h>

#include "cli.h"
#include "commands.h"

#include "node.h"
#include "drivers.h"
#include "scenario.h"

#define WORLD_USAGE                                                                          \
    "usage: coavoid world SCENARIO.json [--lcm-url URL] [--epoch UTIME] [--speed S]\n"       \
    "                     [--steps K] (--key FILE --trust FILE | --insecure)\n"              \
    "\n"                                                                                     \
    "Publishes the scenario's obstacle map and its tracks' estimates over LCM every cycle\n" \
    "of a real-time run, for the coordinator and the vehicles (coavoid-coordinator,\n"       \
    "coavoid-vehicle).\n"                                                                    \
    "\n"                                                                                     \
    "options:\n" COAVOID_RT_OPTIONS_USAGE "  -h, --help          show this help\n"           \
    "      --version       print the version\n"                                              \
    "\n"                                                                                     \
    "exit status: 0 done, 2 invalid input or usage (one line on stderr), 3 internal error\n"

static void world_help(void)
{
    fputs(WORLD_USAGE, stdout);
}

static int world_option(int argc, char **argv, int *i, void *options)
{
    return coavoid_rt_parse_option(argc, argv, i, options);
}

static const coavoid_cli_command_t world_command = {
    "world",    "coavoid world", 2,    {"SCENARIO.json", NULL}, "one scenario only",
    world_help, world_option,    false};

typedef struct {
    const char *path;
    coavoid_rt_options_t rt;
} world_options_t;

static void world_report(void *user, const char *name, const coavoid_rt_result_t *result,
                         const char *tail)
{
    const coavoid_scenario_t *s = user;
    fprintf(stderr, "%s: %lld cycles, %zu obstacles and %zu tracks published each%s\n", name,
            (long long)result->cycles, s->obstacle_count, s->track_count, tail);
}

/* Everything after the scenario is loaded. Returns the exit status. */
static int world(void *options, coavoid_scenario_t *s)
{
    world_options_t *o = options;
    int64_t now = 0; /* the node's clock (common.clock), written by the loop */
    coavoid_world_config_t config;
    memset(&config, 0, sizeof config);
    int status = coavoid_rt_setup(o->path, s, &o->rt, &now, &config.common);
    if (status != CLI_CONTINUE) {
        return status;
    }
    /* It receives nothing: --trust checks that --key is the world's and gives the fleet
     * key it tags with. */
    status = coavoid_rt_keys(&o->rt, COAVOID_AUTH_WORLD, (uint16_t)COAVOID_NODE_WORLD_ID,
                             &config.common);
    if (status != CLI_CONTINUE) {
        return status;
    }
    config.id = COAVOID_NODE_WORLD_ID;
    config.obstacles = s->obstacles;
    config.obstacle_count = s->obstacle_count;
    config.tracks = s->tracks;
    config.track_count = s->track_count;
    config.copies = COAVOID_NODE_DEFAULT_COPIES;

    coavoid_rt_transport_t transport;
    status = coavoid_rt_transport_open_send_only(&transport, o->rt.lcm_url);
    if (status != CLI_CONTINUE) {
        return status;
    }
    int error = COA_OK;
    coavoid_world_t *node = coavoid_world_create(&config, transport.lcm, &error);
    if (node == NULL) {
        coavoid_rt_transport_close(&transport);
        return coavoid_cli_fail(error == COA_ERR_ARGUMENT ? CLI_EXIT_INVALID : CLI_EXIT_INTERNAL,
                                "world: %s: cannot publish it (%s)", o->path,
                                coavoid_lcm_error_name(error));
    }
    coavoid_rt_loop_t loop;
    coavoid_rt_loop_init(&loop, &o->rt, &transport, &now, &config.common, "world");
    loop.world = node;
    loop.deaf = true; /* it publishes the scenario's map and tracks, and hears nothing */
    loop.world_lead_us = config.common.dt_us / 4;
    status = coavoid_rt_drive(&loop, o->rt.lcm_url, world_report, s);
    coavoid_world_destroy(node);
    coavoid_rt_transport_close(&transport);
    return status;
}

int coavoid_command_world(int argc, char **argv)
{
    world_options_t options;
    options.path = NULL;
    coavoid_rt_options_init(&options.rt);
    int status = coavoid_cli_parse_args(&world_command, argc, argv, &options.rt, &options.path);
    if (status != CLI_CONTINUE) {
        return status;
    }
    return coavoid_cli_run_scenario(options.path, world, &options);
}
