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
 *   coavoid montecarlo --vehicles N[,N...] [--count C] [...]        montecarlo.c
 *   coavoid world SCENARIO.json [--lcm-url URL] [--epoch UTIME] [...] world_cmd.c
 *   coavoid sim SCENARIO.json --mode centralised|decoupled [...]    sim_cmd.c
 *   coavoid summary LOGFILE SCENARIO.json --mode MODE [...]         summary_cmd.c (LCM)
 *
 * Exit status: 0 success, 1 plan infeasible or budget exhausted, 2 invalid input or usage
 * (one line on stderr naming the input and why), 3 internal error.
 */
#include <stdio.h>
#include <string.h>

#include "cli.h"
#include "commands.h"

/* summary reads LCM logs and world publishes over LCM: only with the node library
 * (COAVOID_BUILD_LCM). */
#ifdef COAVOID_HAVE_NODE
#define USAGE_SUMMARY                                                                \
    "  summary     judge a real-time run from its lcm-logger log (costs, figure)\n" \
    "  world       publish a scenario's terrain and tracks to a real-time run\n"
#else
#define USAGE_SUMMARY ""
#endif

#define USAGE                                                                         \
    "usage: coavoid <command> [options]\n"                                            \
    "\n"                                                                              \
    "commands:\n"                                                                     \
    "  plan        plan collision-free altitude manoeuvres for a scenario\n"          \
    "  predict     predict the conflicts of a scenario's reference trajectories\n"    \
    "  bench       time the core: bench predict, bench plan\n"                        \
    "  montecarlo  compare centralised and decoupled planning over random encounters\n" \
    "  sim         fly a scenario in closed loop over the nodes (deterministic)\n"    \
    USAGE_SUMMARY                                                                     \
    "\n"                                                                              \
    "Run 'coavoid <command> --help' for the options of a command.\n"

int main(int argc, char **argv)
{
    if (argc < 2) {
        return cli_fail(CLI_EXIT_INVALID, "missing command (see 'coavoid --help')");
    }
    const char *command = argv[1];
    if (strcmp(command, "-h") == 0 || strcmp(command, "--help") == 0) {
        fputs(USAGE, stdout);
        return CLI_EXIT_OK;
    }
    if (strcmp(command, "plan") == 0) {
        return command_plan(argc, argv);
    }
    if (strcmp(command, "predict") == 0) {
        return command_predict(argc, argv);
    }
    if (strcmp(command, "bench") == 0) {
        return command_bench(argc, argv);
    }
    if (strcmp(command, "montecarlo") == 0) {
        return command_montecarlo(argc, argv);
    }
    if (strcmp(command, "world") == 0) {
        return command_world(argc, argv);
    }
    if (strcmp(command, "sim") == 0) {
        return command_sim(argc, argv);
    }
#ifdef COAVOID_HAVE_NODE
    if (strcmp(command, "summary") == 0) {
        return command_summary(argc, argv);
    }
#endif
    if (command[0] == '-') {
        return cli_fail(CLI_EXIT_INVALID, "unknown option '%.40s' (see 'coavoid --help')", command);
    }
    return cli_fail(CLI_EXIT_INVALID, "unknown command '%.40s' (see 'coavoid --help')", command);
}
