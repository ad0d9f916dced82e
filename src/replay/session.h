/* SPDX-License-Identifier: MIT */
/*
 * session.h: a vehicle of the protocol library behind a serial link (coavoid::replay), the
 * way the example firmware flies it on the part, with `coavoid bridge` on the ground
 * joining the link to the LCM group (docs/embedded.md). Both ends speak link.h's frames,
 * each one record of replay.h:
 *
 *   ground -> vehicle                        vehicle -> ground
 *   CONFIG   its configuration, once         SUBSCRIBE  a channel it takes in (after CONFIG)
 *   RECEIVE  a datagram off the group        SENT       a datagram for the group, at once
 *   TIME     the clock, nothing else         READY      the frame is taken: its state, and
 *                                                       the time it next needs a frame
 *
 * The ground sends a frame only when the one before has its READY (or is given up), and
 * stamps it with its clock as it sends it: so a frame's time is the clock when the
 * vehicle takes it, to within its transfer, and the part needs no clock of its own. For
 * each frame the vehicle does what coavoid-vehicle's loop (realtime.h) does at that time:
 * it starts the cycle that time falls in when that is a new one, polls at its deadline,
 * hands the datagram in and polls after it, and polls again at a deadline that has come.
 * So it flies as coavoid-vehicle does, given the same datagrams at the same times.
 *
 * A second CONFIG with the same bytes (a ground that started again) is answered as the
 * first was, and the vehicle flies on; one with other bytes is refused. Every frame has
 * exactly one READY, whose state's return value says what became of it: COA_OK, the
 * node's error, COAVOID_REPLAY_ERR_FORMAT (a frame out of place: before the CONFIG, or a
 * kind the ground does not send) or the configuration's refusal.
 *
 * No I/O, no heap, no clock: the caller moves the bytes (put, one byte onto the wire) and
 * gives the node's block. Not thread-safe. The vehicle's secret key arrives in the
 * CONFIG: the link is as secret as the key (docs/security.md).
 */
#ifndef COAVOID_SESSION_H
#define COAVOID_SESSION_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "link.h"
#include "replay.h"

/* The longest frame either end sends, before framing: a datagram with its channel, or a
 * configuration of what a replay holds (the caller's receive buffer needs this much and
 * COAVOID_LINK_CRC_BYTES). */
#define COAVOID_SESSION_MAX_RECORD \
    (COAVOID_REPLAY_HEADER_BYTES + COAVOID_REPLAY_MAX_CHANNEL + COAVOID_REPLAY_MAX_PAYLOAD)

/* One record (kind, time, channel[0..channel_length), payload[0..payload_length); either
 * may be NULL when its length is 0) framed onto the wire through put, as both ends send
 * theirs. No buffer. O(bytes). */
void coavoid_session_put_record(coavoid_replay_kind_t kind, int64_t time, const char *channel,
                                size_t channel_length, const uint8_t *payload,
                                size_t payload_length, coavoid_link_put_t put, void *user);

typedef struct {
    coavoid_replay_t replay; /* the configuration's storage, the clock, the node */
    void *memory;            /* the node's block */
    size_t size;
    coavoid_link_put_t put;
    void *user;
    uint64_t config_hash; /* FNV-1a of the CONFIG taken */
    int64_t next_cycle;   /* the next cycle to start */
    int64_t polled;       /* the deadline last polled for */
    int rc;               /* the frame's outcome so far: its first error */
    uint64_t frames;      /* frames taken */
    uint64_t refused;     /* of those, answered with an error */
} coavoid_session_t;

/* Readies s for a CONFIG, with the node's block memory[0..size) (aligned to
 * COA_WORKSPACE_ALIGNMENT) and put. O(1). */
void coavoid_session_init(coavoid_session_t *s, void *memory, size_t size, coavoid_link_put_t put,
                          void *user);

/* Takes one frame (link.h's, CRC removed): makes the calls it asks for and sends the
 * vehicle's frames through put, READY last. Returns the READY's value (above). Cost: a
 * CONFIG, the node's init (O(block)); a RECEIVE or TIME, the calls it makes (protocol.h's
 * costs); framing O(what is sent). */
int coavoid_session_take(coavoid_session_t *s, const uint8_t *frame, size_t size);

#endif /* COAVOID_SESSION_H */
