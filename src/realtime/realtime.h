/* SPDX-License-Identifier: MIT */
/*
 * realtime.h (coavoid::realtime): running the nodes of node.h in real time, one process each
 * (the drivers of apps/: coavoid-vehicle, coavoid-coordinator, `coavoid world`), over an LCM
 * provider such as UDP multicast. Their shared options are apps/drivers/drivers.h.
 *
 * The scenario clock. Every process of a run is given the same epoch (the wall-clock
 * utime at which cycle 0 starts) and the same speed S (scenario seconds per wall second),
 * and computes the same scenario time from its own wall clock:
 *     scenario utime = epoch + (wall utime - epoch) * S      for wall >= epoch;
 *     scenario utime = wall utime                            before (waiting for epoch).
 * Messages are stamped, validated and judged in scenario time, so a run at S = 4 is the
 * same closed loop as at S = 1, four times faster, as long as each node's work fits its
 * slot in wall time: the coordinator's plan must reach the vehicles within
 * (dt - collect) / S wall seconds of its collect time. Processes on one host share one
 * wall clock; on several hosts they need synchronised clocks (NTP) to well under a cycle.
 *
 * The loop (coavoid_rt_run). Between events it waits on LCM's file descriptor and, for every
 * message, sets the clock variable the nodes read (common.clock) and lets LCM dispatch it
 * (lcm_handle_timeout); it stops dispatching as soon as an event is due (after one message
 * at least), so that a flood delays an event by one message's handling at most. At its
 * times it calls:
 *   - at cycle_utime(k), k = first..K: the world's cycle, then each vehicle's cycle (a
 *     world alone in its process runs cycle k world_lead_us earlier);
 *   - at cycle_utime(k) + collect_us, k = first..K-1: the coordinator's cycle;
 *   - a vehicle's poll at its deadline, and after every message while it waits.
 * So a run of K cycles (--steps K) flies samples 0..K, as `coavoid sim --steps K` does:
 * cycle K only takes the vehicles to their last sample and publishes their last intents
 * (waits included), and the coordinator does not plan at cycle K. A process started after
 * epoch joins at the current cycle.
 *
 * Overruns. Work that ends after the node's next event (a vehicle's cycle after the next
 * cycle start; the coordinator's after valid_until, so its plans arrive too late to be
 * adopted) is reported on the warning stream, one line per occurrence; an event that
 * could not run before its successor was due is skipped, reported the same way, and the
 * loop resumes at the current cycle. A node's error return is reported once per
 * occurrence and the loop goes on: one failed publish must not ground a UAV.
 *
 * Stopping: SIGINT or SIGTERM (coavoid_rt_install_signal_handlers) ends the loop at its next
 * wake-up, within a few milliseconds; the caller then destroys its nodes and LCM.
 *
 * Memory: nothing is allocated by the loop. Not thread-safe: one loop per process (the
 * stop flag is process-wide).
 */
#ifndef COAVOID_REALTIME_H
#define COAVOID_REALTIME_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

#include <lcm/lcm.h>

#include "node.h"

/* The LCM URL of every driver unless --lcm-url says otherwise: LCM's default group and
 * port, with ttl=0 so that the traffic never leaves the host. */
#define COAVOID_RT_DEFAULT_LCM_URL "udpm://239.255.76.67:7667?ttl=0"

/* Largest --speed: beyond it even a 1 s cycle is shorter than the loop's own jitter. */
#define COAVOID_RT_MAX_SPEED 1000.0

/* How far ahead an --epoch may be: a value further out is more likely seconds or
 * nanoseconds than the microseconds meant. */
#define COAVOID_RT_MAX_EPOCH_AHEAD_US (24LL * 3600LL * 1000000LL)

typedef struct {
    int64_t epoch_utime; /* wall-clock utime of cycle 0's start, > 0 */
    double speed;        /* scenario seconds per wall second, 0 < speed <= COAVOID_RT_MAX_SPEED */
} coavoid_rt_clock_t;

/* The wall clock (CLOCK_REALTIME) in microseconds. Cannot fail. */
int64_t coavoid_rt_wall_utime(void);

/* A monotonic microsecond count (CLOCK_MONOTONIC), with the signature of
 * coavoid_node_common_t.stopwatch_us; user is unused. Cannot fail. */
int64_t coavoid_rt_stopwatch_us(void *user);

/* Scenario utime at a wall utime, by the formula above (rounded down). O(1). */
int64_t coavoid_rt_scenario_utime(const coavoid_rt_clock_t *clock, int64_t wall_utime);

/* The earliest wall utime at which the scenario clock reaches `scenario_utime` (for
 * times before epoch, the time itself). O(1). */
int64_t coavoid_rt_wall_at(const coavoid_rt_clock_t *clock, int64_t scenario_utime);

/* lcm_create(url) with LCM's own multi-line messages on stderr held back: on failure
 * returns NULL with one line in err naming the URL and, for udpm, the multicast route
 * that is missing and how to add it. On success, anything LCM printed is passed on. */
lcm_t *coavoid_rt_lcm_create(const char *url, char *err, size_t err_size);

/* ---- the loop ---- */

typedef struct {
    coavoid_rt_clock_t clock;
    lcm_t *lcm;
    int64_t *now;                        /* the variable every node's common.clock points to */
    const coavoid_node_common_t *common; /* any node's: epoch (as scenario time), dt_us */
    int64_t steps;                       /* K */
    int64_t collect_us;                  /* the coordinator's, when there is one */
    /* The world alone (no vehicle in the loop): how long before cycle k's start it
     * publishes cycle k's map and track estimates (stamped with the cycle's start, at most
     * one cycle ahead), so that they are in every vehicle's view when the cycle begins, as
     * in `coavoid sim`, where the world's cycle runs first. 0: at the cycle's start. */
    int64_t world_lead_us;
    coavoid_world_t *world; /* each optional */
    coavoid_coordinator_t *coordinator;
    coavoid_vehicle_node_t *const *vehicles;
    size_t vehicle_count;
    const char *name; /* prefix of warning lines, e.g. "vehicle 3" */
    FILE *warnings;   /* stderr, usually */
} coavoid_rt_loop_t;

typedef struct {
    int64_t cycles;    /* cycle starts (or coordinator cycles) run */
    uint32_t overruns; /* calls that ended after the node's next event */
    uint32_t skipped;  /* events skipped because an earlier one ran late */
    uint32_t errors;   /* node calls that returned an error */
    int first_error;   /* the first such code, 0 none */
    int signal;        /* the signal that stopped the loop, 0 when it ran to the end */
} coavoid_rt_result_t;

/* Sets SIGINT and SIGTERM to ask the loop to stop (no SA_RESTART, so a wait is cut
 * short). Returns 0, or -1 when sigaction failed. */
int coavoid_rt_install_signal_handlers(void);

/* LCM itself failed: waiting on its descriptor or lcm_handle returned an error, so the
 * provider is unusable. */
#define COAVOID_RT_ERR_LCM (-200)

/* Runs the loop until cycle K is done or a signal asks it to stop. Returns COA_OK,
 * COA_ERR_ARGUMENT (no node, NULL lcm/now/common, steps < 1) or COAVOID_RT_ERR_LCM. Node
 * errors are counted in result, not returned. */
int coavoid_rt_run(const coavoid_rt_loop_t *loop, coavoid_rt_result_t *result);

/* The end of a driver's summary line: ", overruns N, skipped N" and, when a signal
 * stopped it, ", stopped by SIGTERM". Cannot fail (truncates to size). */
void coavoid_rt_result_text(const coavoid_rt_result_t *result, char *out, size_t size);

#endif /* COAVOID_REALTIME_H */
