/* SPDX-License-Identifier: MIT */
/*
 * vehicle_options.h: a vehicle's options and its configuration from them, the same for
 * coavoid-vehicle (the vehicle in a process of its own) and `coavoid bridge` (the vehicle
 * on the part, behind its serial link), so that both fly the same vehicle for the same
 * options.
 */
#ifndef COAVOID_VEHICLE_OPTIONS_H
#define COAVOID_VEHICLE_OPTIONS_H

#include <stdbool.h>
#include <stdint.h>

#include "drivers.h"

/* The usage lines of a vehicle's scenario and options. */
#define COAVOID_VEHICLE_OPTIONS_USAGE                                                             \
    "  SCENARIO.json       the scenario (docs/scenario-format.md): route, dt, horizon, beta;\n"   \
    "                      --scenario FILE, its old spelling, works with a warning\n"             \
    "  --id ID             which of its vehicles this process flies\n"                            \
    "  --mode centralised  follow the coordinator; plan for itself while the coordinator\n"       \
    "                      is silent (default)\n"                                                 \
    "  --mode decoupled    always plan for itself, in priority order\n" COAVOID_RT_OPTIONS_USAGE  \
    "  --coordinator-timeout S  scenario seconds of coordinator silence after which it\n"         \
    "                      plans for itself; default 2.5 * dt\n"                                  \
    "  --coordinator-id ID the node id of the coordinator it follows (1 to 65535, not its\n"      \
    "                      own); heartbeats and plans from any other are refused; default\n"      \
    "                      65001, coavoid-coordinator's\n"                                        \
    "  --priority-wait S   decoupled: scenario seconds it waits for the intents of the\n"         \
    "                      higher-priority UAVs that pass near it, 0 <= S < dt; default dt / 2\n" \
    "  --joint-members N   centralised: while it plans for itself, it plans its group\n"          \
    "                      jointly, as the coordinator would, where no priority order\n"          \
    "                      solves it, for groups of up to N UAVs (2 to 10; 0: never, and\n"       \
    "                      its planner is then one UAV's); default the scenario's UAVs, at\n"     \
    "                      most 5; the same on every vehicle of the fleet\n"                      \
    "  --joint-beta B      centralised: the nodes that joint search may store, 1 to\n"            \
    "                      1000000; default 5000; the same on every vehicle of the fleet\n"

typedef struct {
    const char *scenario_path;
    const char *id_text;
    uint16_t id;
    bool list_ids;
    const char *mode;
    bool decoupled;
    const char *timeout_text;
    double timeout;
    const char *coordinator_text;
    uint16_t coordinator_id;
    const char *wait_text;
    double wait;
    const char *joint_members_text;
    uint64_t joint_members;
    const char *joint_beta_text;
    uint64_t joint_beta;
    coavoid_rt_options_t rt;
} coavoid_vehicle_options_t;

/* Sets the defaults (as coavoid_rt_options_init, nothing given). */
void coavoid_vehicle_options_init(coavoid_vehicle_options_t *o);

/* One of a vehicle's options at argv[*i] (cli.h's option parser contract): CLI_CONTINUE,
 * CLI_EXIT_INVALID after its one line, or CLI_UNKNOWN_OPTION. */
int coavoid_vehicle_option(int argc, char **argv, int *i, coavoid_vehicle_options_t *o);

/* --joint-members N at argv[*i] (the vehicles' and `coavoid sim`'s): 0 or 2 to
 * COA_MAX_CENTRALISED, as cli.h's option functions do. */
int coavoid_joint_members_option(int argc, char **argv, int *i, const char **text, uint64_t *value);

/* After the options and the scenario: --id given, and the options that do not go together
 * refused. CLI_CONTINUE, or CLI_EXIT_INVALID after one line. */
int coavoid_vehicle_options_check(const coavoid_vehicle_options_t *o);

/* The vehicle's configuration from the options and the scenario loaded from
 * o->scenario_path into s (coavoid_rt_setup, the keys, the vehicle, its mode and timings),
 * with `now` as its clock. CLI_CONTINUE, or CLI_EXIT_INVALID after one line. */
int coavoid_vehicle_options_config(coavoid_vehicle_options_t *o, coavoid_scenario_t *s,
                                   const int64_t *now, coavoid_vehicle_node_config_t *config);

#endif /* COAVOID_VEHICLE_OPTIONS_H */
