/* SPDX-License-Identifier: MIT */
/*
 * commands.h: the coavoid subcommands main() dispatches to. Each takes main's argc and
 * argv unchanged (argv[1] is the command's name, its arguments start at argv[2]; bench
 * takes its benchmark's name at argv[2]) and returns the process exit status (cli.h).
 */
#ifndef COAVOID_APP_COMMANDS_H
#define COAVOID_APP_COMMANDS_H

int coavoid_command_plan(int argc, char **argv);       /* plan_cmd.c */
int coavoid_command_predict(int argc, char **argv);    /* predict_cmd.c */
int coavoid_command_bench(int argc, char **argv);      /* bench.c */
int coavoid_bench_plan(int argc, char **argv);         /* bench_plan.c: coavoid bench plan */
int coavoid_bench_auth(int argc, char **argv);         /* bench_auth.c: needs the LCM library */
int coavoid_command_montecarlo(int argc, char **argv); /* montecarlo.c */
int coavoid_command_world(int argc, char **argv);      /* world_cmd.c: needs the node library */
int coavoid_command_sim(int argc, char **argv);        /* sim_cmd.c: needs the node library */
int coavoid_command_summary(int argc, char **argv);    /* summary_cmd.c: needs the node library */
int coavoid_command_keygen(int argc, char **argv);     /* keygen_cmd.c: needs the node library */
int coavoid_command_replay(int argc, char **argv);     /* replay_cmd.c: needs the node library */
int coavoid_command_bridge(int argc, char **argv);     /* bridge_cmd.c: needs the node library */

#endif /* COAVOID_APP_COMMANDS_H */
