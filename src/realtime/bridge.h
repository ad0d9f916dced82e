/* SPDX-License-Identifier: MIT */
/*
 * bridge.h (coavoid::realtime): a vehicle behind a serial link (src/replay/session.h: the
 * example firmware on the part, or under qemu) joined to the LCM group, as `coavoid
 * bridge` runs it. To the group the vehicle is one more coavoid-vehicle; to the vehicle
 * the bridge is its radio and its clock:
 *   - it sends the vehicle its configuration (CONFIG), again every answer timeout until
 *     the vehicle answers (a part that starts after the bridge);
 *   - it subscribes to each channel the vehicle asks for (SUBSCRIBE) on the receiver of
 *     realtime.h, and queues every datagram that arrives on them, but for the vehicle's
 *     own looped back by the group, byte for byte, which the vehicle would drop unread
 *     (its inbox does) and the link need not carry;
 *   - one frame at a time, each only after the vehicle's READY for the one before: the
 *     next queued datagram (RECEIVE; plans, agreements and heartbeats before intents, maps
 *     and tracks: the first have deadlines within the cycle, the others come with copies,
 *     and the link is the slowest part of their way), or, with none queued, the clock
 *     (TIME) when the time
 *     the vehicle's READY asked for has come, each stamped with the scenario clock as it
 *     leaves (session.h); a READY that does not come within the answer timeout gives the
 *     frame up (counted) and the bridge goes on;
 *   - it publishes every datagram the vehicle sends (SENT) at once, as it arrives.
 * It stops once the vehicle has started cycle K and asks for nothing more within it (the
 * end of a coavoid-vehicle run of K cycles), or on SIGINT/SIGTERM
 * (coavoid_rt_install_signal_handlers). A vehicle that refuses its configuration stops it
 * with COAVOID_RT_ERR_REFUSED, and one that is not through cycle K by the end of cycle
 * K + 1 with COAVOID_RT_ERR_LATE. The datagrams are the vehicle's own: signed on the part,
 * checked on the part; the bridge reads nothing in them (docs/security.md).
 *
 * Memory: one allocation at the start, the queues (COAVOID_RT_BRIDGE_QUEUE and
 * COAVOID_RT_BRIDGE_URGENT datagrams of COAVOID_RT_RX_DATAGRAM bytes), the vehicle's last 32 datagrams and a frame's buffers,
 * freed at the end. A full queue
 * drops the datagram that arrives (counted): the vehicle's protocol takes losses. Not
 * thread-safe.
 */
#ifndef COAVOID_BRIDGE_H
#define COAVOID_BRIDGE_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

#include "realtime.h"

#define COAVOID_RT_BRIDGE_QUEUE 256u
#define COAVOID_RT_BRIDGE_URGENT 64u

/* The vehicle refused its configuration: the READY's code is in the result. */
#define COAVOID_RT_ERR_REFUSED (-201)
/* The vehicle was not through cycle K a whole cycle after K ended: silent (never
 * configured, or gone) or too slow for the run. */
#define COAVOID_RT_ERR_LATE (-202)

/* Opens the vehicle's link at path: a serial device (a tty: raw, 8N1, RTS/CTS flow
 * control, at `baud`, one of 9600..4000000 that termios names) or a Unix socket, such as
 * qemu's `-serial unix:PATH,server=on,wait=off`, connected to. Returns the descriptor
 * (non-blocking), or -1 with one line in err. */
int coavoid_rt_link_open(const char *path, long baud, char *err, size_t err_size);

typedef struct {
    coavoid_rt_clock_t clock;
    lcm_t *lcm;                          /* what it publishes on; receives on when rx is NULL */
    coavoid_rt_rx_t *rx;                 /* the receiver (udpm); its LCM is subscribed on */
    const coavoid_node_common_t *common; /* the vehicle's: epoch and dt */
    int64_t steps;                       /* K */
    int fd;                              /* the link, coavoid_rt_link_open's */
    const uint8_t *config;               /* the CONFIG's payload (coavoid_replay_write_config) */
    size_t config_size;
    int64_t answer_timeout_us; /* wall time a READY may take; 0: one cycle at the speed */
    const char *name;          /* of warning lines, e.g. "bridge 1" */
    FILE *warnings;            /* stderr, usually */
} coavoid_rt_bridge_t;

typedef struct {
    coavoid_rt_result_t loop; /* signal and the receiver's counters (cycles: the vehicle's) */
    bool configured;          /* the vehicle took its configuration */
    int refused_code;         /* ... or refused it with this code */
    coavoid_vehicle_node_state_t state; /* the vehicle's, as its last READY gave it */
    uint64_t frames_sent;               /* to the vehicle */
    uint64_t frames_refused;            /* ... answered with an error */
    uint64_t frames_given_up;           /* ... no READY within the answer timeout */
    uint64_t frames_received;           /* from the vehicle */
    uint64_t link_dropped;              /* ... garbled or cut on the link (link.h) */
    uint64_t published;                 /* its datagrams published */
    uint64_t publish_failed;
    uint64_t queue_dropped; /* datagrams dropped, the queue full */
    uint64_t queue_peak;    /* the most datagrams that waited at once, both queues */
    uint64_t echoes;        /* its own datagrams looped back, not sent to it */
} coavoid_rt_bridge_result_t;

/* Runs the bridge to the end (above). Returns COA_OK, COA_ERR_ARGUMENT (a NULL field, no
 * configuration, steps < 1), COA_ERR_WORKSPACE (no memory for the queue),
 * COAVOID_RT_ERR_REFUSED, COAVOID_RT_ERR_LATE, or COAVOID_RT_ERR_LCM when the link, LCM or
 * the receiver failed. */
int coavoid_rt_bridge_run(const coavoid_rt_bridge_t *b, coavoid_rt_bridge_result_t *result);

#endif /* COAVOID_BRIDGE_H */
