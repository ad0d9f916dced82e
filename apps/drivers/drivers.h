/* SPDX-License-Identifier: MIT */
/*
 * drivers.h: what the real-time drivers (apps/coordinator, apps/vehicle, `coavoid world`)
 * share on top of the loop of realtime.h: their common options (--lcm-url, --epoch,
 * --speed, --steps), the set-up from a scenario, and running one node to the end with its
 * summary line.
 */
#ifndef COAVOID_DRIVERS_H
#define COAVOID_DRIVERS_H

#include "realtime.h"
#include "scenario.h"

/* ---- options every driver shares ---- */

typedef struct {
    const char *lcm_url;    /* NULL until given; then COAVOID_RT_DEFAULT_LCM_URL */
    const char *epoch_text; /* NULL until given */
    int64_t epoch_utime;    /* --epoch; when not given, coavoid_rt_options_finish sets now */
    const char *speed_text; /* NULL: 1 */
    double speed;
    const char *steps_text; /* NULL: 2N */
    int64_t steps;          /* K >= 1 */
    const char *key_path;   /* --key: its secret key file */
    const char *trust_path; /* --trust: the keys it accepts */
    bool insecure;          /* --insecure: neither */
    /* What --key and --trust hold once read (coavoid_rt_keys); common.signer and
     * common.trust point here. */
    coavoid_auth_signer_t signer;
    coavoid_auth_trust_t trust;
} coavoid_rt_options_t;

/* Sets the defaults (no epoch yet, speed 1, steps unset, the default URL). */
void coavoid_rt_options_init(coavoid_rt_options_t *o);

/* Whether argv[*i] is one of --lcm-url, --epoch, --speed, --steps, --key, --trust,
 * --insecure; if so consumes it
 * (and its value) and returns CLI_CONTINUE, or returns CLI_EXIT_INVALID after the one-line
 * error (missing or bad value, given twice). Returns CLI_UNKNOWN_OPTION for any other
 * argument (cli.h's option parser contract). */
int coavoid_rt_parse_option(int argc, char **argv, int *i, coavoid_rt_options_t *o);

/* The same for a driver that flies a scenario given as its argument (coavoid-vehicle,
 * coavoid-coordinator, coavoid bridge): also --scenario FILE, the argument's old spelling,
 * which sets *scenario_path with its warning (coavoid_cli_scenario_option). */
int coavoid_rt_driver_option(int argc, char **argv, int *i, coavoid_rt_options_t *o,
                             const char **scenario_path);

/* After the scenario is loaded: steps defaults to 2 * horizon; the epoch defaults to now
 * (a process run alone starts at once; processes that run together must all be given
 * one --epoch); an epoch more than COAVOID_RT_MAX_EPOCH_AHEAD_US ahead, or one whose run of
 * `steps` cycles of dt_us has already ended, is refused. Returns CLI_CONTINUE or
 * CLI_EXIT_INVALID after the one-line error. */
int coavoid_rt_options_finish(coavoid_rt_options_t *o, int64_t dt_us, uint32_t horizon);

/* What every driver does once its options are parsed and the scenario at `path` is loaded
 * into *s (coavoid_cli_run_scenario): samples it, refuses a horizon beyond COAVOID_NODE_MAX_HORIZON,
 * finishes the options (coavoid_rt_options_finish), and fills *common with the node defaults
 * on the scenario's dt and horizon, the epoch, `now` as the clock, the monotonic
 * stopwatch, and the scenario's beta when it gives one. Returns CLI_CONTINUE, or
 * CLI_EXIT_INVALID after the one-line error. Cost: sampling the scenario; no memory
 * beyond the scenario's samples. */
int coavoid_rt_setup(const char *path, coavoid_scenario_t *s, coavoid_rt_options_t *o,
                     const int64_t *now, coavoid_node_common_t *common);

/* The largest key or trust file read: 128 keys of one 255-character line each, with room
 * for comments. */
#define COAVOID_RT_KEY_FILE_MAX 65536u

/* Reads the trust file at path (at most COAVOID_RT_KEY_FILE_MAX bytes) into t, for --trust.
 * Returns CLI_CONTINUE, or CLI_EXIT_INVALID after one line ("--trust: PATH: line N: why",
 * unreadable, too large, or holding the fleet key while readable by others). */
int coavoid_rt_load_trust(const char *path, coavoid_auth_trust_t *t);

/* After coavoid_rt_setup: reads --key (a secret key file, readable by its owner only) and
 * --trust; checks that the trust file lists this key as the node's (role and node_id, the
 * same public key), so that a key file of another node is refused at start, not by every
 * receiver; gives the signer the trust file's fleet key; and points common->signer and
 * common->trust at them. Or, with --insecure (and neither file),
 * sets common->insecure. Returns CLI_CONTINUE, or CLI_EXIT_INVALID after one line naming
 * the option and why (missing, unreadable, too large, a bad line, not this node's key).
 * Cost: reading two files of at most COAVOID_RT_KEY_FILE_MAX bytes; no memory. */
int coavoid_rt_keys(coavoid_rt_options_t *o, coavoid_auth_role_t role, uint16_t node_id,
                    coavoid_node_common_t *common);

/* The usage lines of the shared options (for each driver's --help). */
#define COAVOID_RT_OPTIONS_USAGE                                                          \
    "  --lcm-url URL       LCM provider; default " COAVOID_RT_DEFAULT_LCM_URL "\n"        \
    "                      (ttl=0: the traffic stays on this host)\n"                     \
    "  --epoch UTIME       wall-clock microseconds since 1970 at which cycle 0 starts;\n" \
    "                      every process of a run must be given the same value;\n"        \
    "                      default: now\n"                                                \
    "  --speed S           scenario seconds per wall second, 0 < S <= 1000; default 1\n"  \
    "  --steps K           run K cycles, flying samples 0..K; default 2 * horizon\n"      \
    "  --key FILE          its secret key (coavoid keygen): it signs every message\n"     \
    "  --trust FILE        the keys it accepts messages from, with their roles\n"         \
    "  --insecure          neither sign nor check signatures (tests only; its\n"          \
    "                      heartbeat says so); else --key and --trust are required\n"

/* A driver's transport: the LCM its node publishes on and, for a udpm URL, the receiver
 * its node subscribes on (realtime.h, "The receiver"). */
typedef struct {
    lcm_t *lcm;
    coavoid_rt_rx_t *rx; /* NULL for other providers: LCM receives */
} coavoid_rt_transport_t;

/* Opens both for `url` and points common->transport_dropped at the receiver's count of
 * drops at the socket (coavoid_rt_transport_rx_lcm: its LCM, for the node's create). Returns
 * CLI_CONTINUE, or CLI_EXIT_INVALID after one line on stderr (a bad URL, no multicast
 * route), with nothing left open. */
int coavoid_rt_transport_open(coavoid_rt_transport_t *t, const char *url,
                              coavoid_node_common_t *common);

/* The same for a node that subscribes to nothing (a world): LCM to publish on, no
 * receiver; its loop is deaf (coavoid_rt_loop_t.deaf). */
int coavoid_rt_transport_open_send_only(coavoid_rt_transport_t *t, const char *url);

/* The LCM a node subscribes on: the receiver's, or NULL (the one it publishes on). O(1). */
lcm_t *coavoid_rt_transport_rx_lcm(const coavoid_rt_transport_t *t);

/* Closes what coavoid_rt_transport_open opened; after the node is destroyed. */
void coavoid_rt_transport_close(coavoid_rt_transport_t *t);

/* Sets the loop's fields every driver sets alike: the clock (epoch, speed) and steps from
 * the finished options, the transport, now, common, name, and warnings on stderr; the
 * rest (the nodes, collect_us, world_lead_us) is zero for the caller to set. O(1). */
void coavoid_rt_loop_init(coavoid_rt_loop_t *loop, const coavoid_rt_options_t *o,
                          const coavoid_rt_transport_t *transport, int64_t *now,
                          const coavoid_node_common_t *common, const char *name);

/* Prints a driver's summary line on stderr from its node's state, starting with the
 * loop's name and ending with `tail` (coavoid_rt_result_text). */
typedef void (*coavoid_rt_report_t)(void *user, const char *name, const coavoid_rt_result_t *result,
                                    const char *tail);

/* What every driver does once its node is in the loop: installs the signal handlers, runs
 * the loop and calls report. Returns CLI_EXIT_OK, or CLI_EXIT_INTERNAL when a node call
 * failed, or after the line "NAME: cannot handle SIGINT/SIGTERM" (nothing ran) or "NAME:
 * LCM failed while running (URL)". The caller destroys its node and the transport afterwards.
 * Cost and memory: coavoid_rt_run's. */
int coavoid_rt_drive(const coavoid_rt_loop_t *loop, const char *lcm_url, coavoid_rt_report_t report,
                     void *user);

#endif /* COAVOID_DRIVERS_H */
