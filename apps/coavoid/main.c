/* SPDX-License-Identifier: MIT */
/*
 * coavoid: the command-line front end of the core. main() only dispatches; each command
 * lives in its own file (commands.h) and shares option parsing, error reporting and
 * scenario loading through cli.h.
 *
 *   coavoid plan SCENARIO.json --mode centralised|decoupled [...]   plan_cmd.c
 *   coavoid predict SCENARIO.json [--threshold P] [...]             predict_cmd.c
 *   coavoid bench predict --vehicles N --horizon H [...]            bench.c
 *   coavoid bench plan [--vehicles N] [--count C] [...]              bench_plan.c
 *   coavoid bench auth [--vehicles N[,N...]] [--repeat R] [--json]  bench_auth.c (LCM)
 *   coavoid montecarlo --vehicles N[,N...] [--count C] [...]        montecarlo.c
 *   coavoid world SCENARIO.json [--lcm-url URL] [--epoch UTIME] [...] world_cmd.c
 *   coavoid sim SCENARIO.json --mode centralised|decoupled [...]    sim_cmd.c
 *   coavoid summary LOGFILE SCENARIO.json --mode MODE [...]         summary_cmd.c (LCM)
 *   coavoid replay RECORD                                           replay_cmd.c (LCM)
 *   coavoid bridge --uart PATH --scenario FILE --id ID [...]        bridge_cmd.c (LCM)
 *
 * Exit status: 0 success, 1 plan infeasible or budget exhausted, 2 invalid input or usage
 * (one line on stderr naming the input and why), 3 internal error.
 */
#include <stdio.h>
#include <string.h>

#include "cli.h"
#include "commands.h"

/* sim, summary, world, keygen, replay and bridge run the nodes over LCM or make their keys: they are built, and listed, only with
 * the node library (COAVOID_BUILD_LCM, which gives this program COAVOID_HAVE_NODE). This is
 * the one place where that option reaches the code: their sources are left out of the
 * build otherwise, not replaced by stubs. */
#ifdef COAVOID_HAVE_NODE
#define USAGE_NODES                                                                      \
    "  sim         fly a scenario in closed loop over the nodes (deterministic)\n"       \
    "  summary     judge a real-time run from its lcm-logger log (costs, figure)\n"      \
    "  world       publish a scenario's terrain and tracks to a real-time run\n"         \
    "  keygen      write fresh signing keys and the trust file for a scenario's fleet\n" \
    "  replay      make a vehicle's record (sim --record-vehicle) again, and compare\n"  \
    "  bridge      fly a vehicle on the part (the example firmware) over its serial link\n"
#else
#define USAGE_NODES ""
#endif

/* bench auth times the messaging library's signatures: offered only when it is built
 * (COAVOID_HAVE_LCM, from coavoid::evaluation), like the commands above. */
#ifdef COAVOID_HAVE_LCM
#define USAGE_BENCH "  bench       time the core and signed messages: bench predict, plan, auth\n"
#else
#define USAGE_BENCH "  bench       time the core: bench predict, bench plan\n"
#endif

#define USAGE                                                                                  \
    "usage: coavoid <command> [options]\n"                                                     \
    "       coavoid --version\n"                                                               \
    "\n"                                                                                       \
    "commands:\n"                                                                              \
    "  plan        plan collision-free altitude manoeuvres for a scenario\n"                   \
    "  predict     predict the conflicts of a scenario's reference trajectories\n" USAGE_BENCH \
    "  montecarlo  compare centralised and decoupled planning over random "                    \
    "encounters\n" USAGE_NODES "\n"                                                            \
    "Run 'coavoid <command> --help' for the options of a command.\n"

int main(int argc, char **argv)
{
    if (argc < 2) {
        return coavoid_cli_fail(CLI_EXIT_INVALID, "missing command (see 'coavoid --help')");
    }
    const char *command = argv[1];
    if (strcmp(command, "-h") == 0 || strcmp(command, "--help") == 0) {
        fputs(USAGE, stdout);
        return CLI_EXIT_OK;
    }
    if (strcmp(command, "--version") == 0) {
        coavoid_cli_print_version("coavoid");
        return CLI_EXIT_OK;
    }
    if (strcmp(command, "plan") == 0) {
        return coavoid_command_plan(argc, argv);
    }
    if (strcmp(command, "predict") == 0) {
        return coavoid_command_predict(argc, argv);
    }
    if (strcmp(command, "bench") == 0) {
        return coavoid_command_bench(argc, argv);
    }
    if (strcmp(command, "montecarlo") == 0) {
        return coavoid_command_montecarlo(argc, argv);
    }
#ifdef COAVOID_HAVE_NODE
    if (strcmp(command, "sim") == 0) {
        return coavoid_command_sim(argc, argv);
    }
    if (strcmp(command, "summary") == 0) {
        return coavoid_command_summary(argc, argv);
    }
    if (strcmp(command, "world") == 0) {
        return coavoid_command_world(argc, argv);
    }
    if (strcmp(command, "keygen") == 0) {
        return coavoid_command_keygen(argc, argv);
    }
    if (strcmp(command, "replay") == 0) {
        return coavoid_command_replay(argc, argv);
    }
    if (strcmp(command, "bridge") == 0) {
        return coavoid_command_bridge(argc, argv);
    }
#endif
    if (command[0] == '-') {
        return coavoid_cli_fail(CLI_EXIT_INVALID, "unknown option '%.40s' (see 'coavoid --help')",
                                command);
    }
    return coavoid_cli_fail(CLI_EXIT_INVALID, "unknown command '%.40s' (see 'coavoid --help')",
                            command);
}
