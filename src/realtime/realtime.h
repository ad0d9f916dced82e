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
 * The loop (coavoid_rt_run). Between events it waits on the receiver's descriptor (or
 * LCM's, for providers other than udpm) and, for every datagram, sets the clock variable
 * the nodes read (common.clock) and delivers it to their handlers (coavoid_rt_rx_deliver,
 * or lcm_handle_timeout); it stops delivering as soon as an event is due (after one
 * datagram at least), so that a flood delays an event by one datagram's handling at most.
 * At its times it calls:
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

/* LCM itself or the receiver failed: waiting on a descriptor, lcm_handle or the socket
 * returned an error, so the transport is unusable. */
#define COAVOID_RT_ERR_LCM (-200)

/* ---- the receiver ----
 *
 * LCM 1.3.1's udpm provider receives in a thread of its own, which reads every datagram
 * as it arrives into a queue that grows without bound (its ring buffer grows by half
 * whenever it is full) and hands them over one at a time through a pipe: about 20 us of
 * CPU per datagram before a node can even refuse it, and memory in proportion to what
 * arrives while the loop is busy. Under a flood that is where a node's CPU goes. So the
 * drivers receive from a udpm group themselves: one non-blocking socket, read in batches
 * of COAVOID_RT_RX_BATCH (recvmmsg) only when the loop asks for the next datagram, LCM's
 * short-message framing checked here, and each datagram handed at once to the nodes'
 * handlers through an in-process LCM (memq://, the lcm_t the nodes subscribe on: the
 * rx_lcm of the nodes' create functions), whose queue so never holds more than one. What
 * the loop does not read in time the kernel drops at the socket, within its receive
 * buffer, and counts (SO_RXQ_OVFL): kernel_dropped. The wire is LCM's: the nodes publish through LCM,
 * and lcm-spy and lcm-logger hear the same datagrams. Every message of docs/messages.md
 * fits one datagram, so LCM's fragments ("LC03") are counted and never reassembled. Only
 * the fleet's channels (node.h, COAVOID_CHANNEL_*) are handed on: LCM keeps a list of
 * handlers for every channel name it has been given, for ever, so datagrams on ever new
 * names would cost each node memory without bound; they are counted as foreign.
 *
 * Memory: one allocation at open, about COAVOID_RT_RX_BATCH * COAVOID_RT_RX_DATAGRAM
 * bytes (the batch), plus LCM's memq provider; nothing per datagram beyond memq's copy of
 * the one being delivered. Not thread-safe. */
#define COAVOID_RT_RX_BATCH 64u
#define COAVOID_RT_RX_DATAGRAM 2048u /* longer datagrams are not ours: counted and dropped */

/* coavoid_rt_rx_parse's results besides COA_OK. */
#define COAVOID_RT_RX_MALFORMED (-210) /* not LCM's framing, or a channel name without its end */
#define COAVOID_RT_RX_FRAGMENT (-211)  /* a fragment of a message longer than one datagram */

typedef struct {
    uint64_t datagrams;      /* read from the socket */
    uint64_t delivered;      /* handed to the nodes' handlers (a channel some node subscribes to) */
    uint64_t malformed;      /* refused by coavoid_rt_rx_parse */
    uint64_t fragments;      /* LCM fragments, dropped */
    uint64_t oversize;       /* longer than COAVOID_RT_RX_DATAGRAM, dropped */
    uint64_t foreign;        /* on a channel that is not the fleet's, dropped */
    uint64_t kernel_dropped; /* dropped at the socket, its buffer full, since open */
} coavoid_rt_rx_stats_t;

typedef struct {
    uint32_t sequence;            /* the sender's, as LCM numbers its datagrams */
    const char *channel;          /* NUL-terminated, 1..63 characters, inside the datagram */
    const unsigned char *payload; /* the message, inside the datagram */
    size_t payload_size;
} coavoid_rt_rx_frame_t;

/* One datagram in LCM's short-message framing: the magic "LC02" and a sequence number,
 * both big-endian, the channel name and its NUL (at most 63 characters before it), then
 * the message. COA_OK with *frame pointing into the datagram; COAVOID_RT_RX_FRAGMENT,
 * COAVOID_RT_RX_MALFORMED, or COA_ERR_ARGUMENT for a NULL pointer. O(channel). Never
 * reads outside datagram[0..size). */
int coavoid_rt_rx_parse(const unsigned char *datagram, size_t size, coavoid_rt_rx_frame_t *frame);

typedef struct coavoid_rt_rx coavoid_rt_rx_t;

/* Whether channel is one of the fleet's (node.h, COAVOID_CHANNEL_*): what the receiver
 * hands on. O(1). */
bool coavoid_rt_rx_fleet_channel(const char *channel);

/* Whether url names LCM's UDP multicast provider (udpm://), which the receiver serves;
 * other providers keep LCM's own receiving. */
bool coavoid_rt_rx_is_udpm(const char *url);

/* Joins the group of a udpm URL (udpm://GROUP[:PORT][?...]: port 7667 by default; the
 * option recv_buf_size sets the socket's receive buffer, the others are the publisher's).
 * NULL on failure, with one line in err: a malformed URL, no multicast route, no memory. */
coavoid_rt_rx_t *coavoid_rt_rx_open(const char *url, char *err, size_t err_size);

/* Leaves the group and frees everything; NULL is ignored. */
void coavoid_rt_rx_close(coavoid_rt_rx_t *rx);

/* The descriptor to wait on, the LCM the nodes subscribe on, the counters. O(1). */
int coavoid_rt_rx_fd(const coavoid_rt_rx_t *rx);
lcm_t *coavoid_rt_rx_lcm(const coavoid_rt_rx_t *rx);
const coavoid_rt_rx_stats_t *coavoid_rt_rx_stats(const coavoid_rt_rx_t *rx);

/* Whether datagrams of the last batch are still to be delivered (the descriptor may then
 * be quiet while there is work). O(1). */
bool coavoid_rt_rx_pending(const coavoid_rt_rx_t *rx);

/* Delivers the next datagram: reads a batch when the last is used up, then hands one
 * datagram to the nodes' handlers (they run inside this call) or counts it as dropped.
 * Returns 1 (one datagram taken), 0 (none waiting), or COAVOID_RT_ERR_LCM when the socket
 * or LCM failed. One recvmmsg per COAVOID_RT_RX_BATCH datagrams, no allocation beyond
 * memq's copy. */
int coavoid_rt_rx_deliver(coavoid_rt_rx_t *rx);

/* ---- the loop ---- */

typedef struct {
    coavoid_rt_clock_t clock;
    lcm_t *lcm;          /* what the nodes publish on; LCM receives too when rx is NULL */
    coavoid_rt_rx_t *rx; /* the receiver (udpm): the nodes subscribe on its LCM */
    bool deaf;           /* the nodes subscribe to nothing (a world): the loop only waits */
    int64_t *now;        /* the variable every node's common.clock points to */
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
    bool received;     /* the loop had a receiver: rx holds its counters at the end */
    coavoid_rt_rx_stats_t rx;
} coavoid_rt_result_t;

/* Sets SIGINT and SIGTERM to ask the loop to stop (no SA_RESTART, so a wait is cut
 * short). Returns 0, or -1 when sigaction failed. */
int coavoid_rt_install_signal_handlers(void);

/* The signal that asked the loop to stop, or 0 (none yet). O(1). */
int coavoid_rt_stop_signal(void);

/* One datagram delivered to the handlers subscribed on the receiver's LCM (rx), or on lcm
 * when rx is NULL: 1, 0 when none is waiting, or COAVOID_RT_ERR_LCM. */
int coavoid_rt_deliver(lcm_t *lcm, coavoid_rt_rx_t *rx);

/* Runs the loop until cycle K is done or a signal asks it to stop. Returns COA_OK,
 * COA_ERR_ARGUMENT (no node, NULL lcm/now/common, steps < 1) or COAVOID_RT_ERR_LCM. Node
 * errors are counted in result, not returned. */
int coavoid_rt_run(const coavoid_rt_loop_t *loop, coavoid_rt_result_t *result);

/* The end of a driver's summary line: ", overruns N, skipped N", with a receiver
 * ", datagrams N (dropped at the socket N; ...)" with its malformed, fragment, oversize
 * and foreign counts, and, when a signal stopped it, ", stopped by SIGTERM". Cannot fail (truncates
 * to size). */
void coavoid_rt_result_text(const coavoid_rt_result_t *result, char *out, size_t size);

#endif /* COAVOID_REALTIME_H */
