/* SPDX-License-Identifier: MIT */
/*
 * coavoid bridge: a vehicle of the fleet on the part (the example firmware's
 * coavoid-firmware-vehicle.elf, on a board or in qemu) joined to the LCM group through its
 * serial link (src/realtime/bridge.h, src/replay/session.h). It takes the options of
 * coavoid-vehicle, sends the part the vehicle they configure, and is its radio and clock.
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "bridge.h"
#include "cli.h"
#include "commands.h"
#include "replay.h"
#include "vehicle_options.h"

#define BRIDGE_DEFAULT_BAUD 921600L

#define BRIDGE_USAGE                                                                               \
    "usage: coavoid bridge SCENARIO.json --uart PATH [--baud B] --id ID\n"                         \
    "                      [the options of coavoid-vehicle]\n"                                     \
    "\n"                                                                                           \
    "Flies UAV ID of the scenario on the part at the other end of PATH (the example\n"             \
    "firmware, coavoid-firmware-vehicle.elf: docs/embedded.md), joined to the LCM group:\n"        \
    "sends it the vehicle's configuration and keys, the datagrams of the channels it asks\n"       \
    "for and the scenario clock, and publishes what it sends. To the fleet it is one more\n"       \
    "coavoid-vehicle, configured by the same options.\n"                                           \
    "\n"                                                                                           \
    "options:\n"                                                                                   \
    "  --uart PATH         the part's serial link: a serial device (raw, 8N1, RTS/CTS)\n"          \
    "                      or a Unix socket (qemu -serial unix:PATH,server=on,wait=off)\n"         \
    "  --baud B            a serial device's rate; default 921600\n" COAVOID_VEHICLE_OPTIONS_USAGE \
    "  -h, --help          show this help\n"                                                       \
    "      --version       print the version\n"                                                    \
    "\n"                                                                                           \
    "At the end (after K cycles, or on SIGINT/SIGTERM) it prints one summary line on\n"            \
    "stderr: the vehicle's cycles, plans and messages as coavoid-vehicle's line has them,\n"       \
    "and the link's frames.\n"                                                                     \
    "\n"                                                                                           \
    "exit status: 0 done, 2 invalid input or usage (one line on stderr), 3 internal error\n"       \
    "(the link or LCM failed, the part refused the configuration, or it was not through\n"         \
    "the last cycle a cycle after it ended)\n"

typedef struct {
    coavoid_vehicle_options_t v;
    const char *uart;
    const char *baud_text;
    uint64_t baud;
} bridge_options_t;

static void bridge_help(void)
{
    fputs(BRIDGE_USAGE, stdout);
}

static int bridge_option(int argc, char **argv, int *i, void *options)
{
    bridge_options_t *o = options;
    if (coavoid_cli_option_is(argv[*i], "--uart")) {
        return coavoid_cli_text_option(argc, argv, i, "--uart", "the part's serial link", false,
                                       &o->uart);
    }
    if (coavoid_cli_option_is(argv[*i], "--baud")) {
        return coavoid_cli_count_option(argc, argv, i, "--baud", NULL, false, 4000000u,
                                        &o->baud_text, &o->baud);
    }
    return coavoid_vehicle_option(argc, argv, i, &o->v);
}

static const coavoid_cli_command_t bridge_command = {
    "bridge",    "coavoid bridge", 2,   {"SCENARIO.json", NULL}, "one scenario only",
    bridge_help, bridge_option,    true};

static void bridge_report(const char *name, const coavoid_rt_bridge_result_t *r)
{
    const coavoid_vehicle_node_state_t *st = &r->state;
    char tail[512];
    coavoid_rt_result_text(&r->loop, tail, sizeof tail);
    fprintf(stderr,
            "%s: %lld cycles, plans run %u, plans adopted %u, fallbacks %u, joint plans %u, "
            "messages received %lld, rejected %lld; link: frames sent %llu (refused %llu, given "
            "up %llu), received %llu (dropped %llu), published %llu (failed %llu), echoes %llu, "
            "queue full %llu (peak %llu)%s\n",
            name, (long long)r->loop.cycles, (unsigned)st->plans_run, (unsigned)st->plans_adopted,
            (unsigned)st->fallbacks, (unsigned)st->joint_plans, (long long)st->rx.received,
            (long long)st->rx.rejected, (unsigned long long)r->frames_sent,
            (unsigned long long)r->frames_refused, (unsigned long long)r->frames_given_up,
            (unsigned long long)r->frames_received, (unsigned long long)r->link_dropped,
            (unsigned long long)r->published, (unsigned long long)r->publish_failed,
            (unsigned long long)r->echoes, (unsigned long long)r->queue_dropped,
            (unsigned long long)r->queue_peak, tail);
}

/* The bridge's run over an open link and transport. */
static int bridge_fly(bridge_options_t *o, const coavoid_vehicle_node_config_t *config, int fd,
                      const coavoid_rt_transport_t *transport)
{
    static uint8_t payload[COAVOID_REPLAY_MAX_PAYLOAD];
    const size_t size = coavoid_replay_write_config(config, payload, sizeof payload);
    if (size == 0u) {
        return coavoid_cli_fail(CLI_EXIT_INVALID,
                                "%s: the vehicle's configuration is larger than a frame holds",
                                o->v.scenario_path);
    }
    char name[32];
    snprintf(name, sizeof name, "bridge %u", (unsigned)o->v.id);
    const coavoid_rt_bridge_t b = {{o->v.rt.epoch_utime, o->v.rt.speed},
                                   transport->lcm,
                                   transport->rx,
                                   &config->common,
                                   o->v.rt.steps,
                                   fd,
                                   payload,
                                   size,
                                   0,
                                   name,
                                   stderr};
    if (coavoid_rt_install_signal_handlers() != 0) {
        return coavoid_cli_fail(CLI_EXIT_INTERNAL, "%s: cannot handle SIGINT/SIGTERM", name);
    }
    coavoid_rt_bridge_result_t result;
    const int rc = coavoid_rt_bridge_run(&b, &result);
    bridge_report(name, &result);
    if (rc == COAVOID_RT_ERR_REFUSED) {
        return coavoid_cli_fail(CLI_EXIT_INTERNAL, "%s: the part refused the configuration (%s)",
                                name, coavoid_lcm_error_name(result.refused_code));
    }
    if (rc == COAVOID_RT_ERR_LATE) {
        return coavoid_cli_fail(CLI_EXIT_INTERNAL,
                                "%s: the part was not through cycle %lld a cycle after it "
                                "ended (%s: silent, or too slow for --speed)",
                                name, (long long)o->v.rt.steps, o->uart);
    }
    if (rc != COA_OK) {
        return coavoid_cli_fail(CLI_EXIT_INTERNAL, "%s: the link or LCM failed (%s, %s)", name,
                                o->uart, o->v.rt.lcm_url);
    }
    return CLI_EXIT_OK;
}

static int run(void *options, coavoid_scenario_t *s)
{
    bridge_options_t *o = options;
    int64_t now = 0; /* the configuration's clock: the part has its own */
    coavoid_vehicle_node_config_t config;
    int status = coavoid_vehicle_options_config(&o->v, s, &now, &config);
    if (status != CLI_CONTINUE) {
        return status;
    }
    char err[256];
    const int fd = coavoid_rt_link_open(
        o->uart, o->baud_text != NULL ? (long)o->baud : BRIDGE_DEFAULT_BAUD, err, sizeof err);
    if (fd < 0) {
        return coavoid_cli_fail(CLI_EXIT_INVALID, "--uart: %s", err);
    }
    coavoid_rt_transport_t transport;
    status = coavoid_rt_transport_open(&transport, o->v.rt.lcm_url, &config.common);
    if (status == CLI_CONTINUE) {
        status = bridge_fly(o, &config, fd, &transport);
        coavoid_rt_transport_close(&transport);
    }
    close(fd);
    return status;
}

int coavoid_command_bridge(int argc, char **argv)
{
    bridge_options_t o;
    memset(&o, 0, sizeof o);
    coavoid_vehicle_options_init(&o.v);
    const char *scenario = NULL;
    int status = coavoid_cli_parse_args(&bridge_command, argc, argv, &o, &scenario);
    if (status == CLI_CONTINUE) {
        status = coavoid_cli_scenario_given(&bridge_command, scenario, &o.v.scenario_path);
    }
    if (status == CLI_CONTINUE && o.uart == NULL) {
        status = coavoid_cli_fail(CLI_EXIT_INVALID, "--uart: required (the part's serial link)");
    }
    if (status == CLI_CONTINUE) {
        status = coavoid_vehicle_options_check(&o.v);
    }
    return status != CLI_CONTINUE ? status : coavoid_cli_run_scenario(o.v.scenario_path, run, &o);
}
