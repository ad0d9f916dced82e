/* SPDX-License-Identifier: MIT */
/* A vehicle behind a serial link (session.h): frames in, the drivers' calls, frames out. */
#include <string.h>

#include "protocol_internal.h"
#include "session.h"

void coavoid_session_put_record(coavoid_replay_kind_t kind, int64_t time, const char *channel,
                                size_t channel_length, const uint8_t *payload,
                                size_t payload_length, coavoid_link_put_t put, void *user)
{
    uint8_t header[COAVOID_REPLAY_HEADER_BYTES];
    coavoid_replay_write_header(header, kind, time, channel_length, payload_length);
    const uint8_t *const parts[] = {header, (const uint8_t *)channel, payload};
    const size_t lengths[] = {sizeof header, channel_length, payload_length};
    coavoid_link_put_frame(parts, lengths, 3u, put, user);
}

/* A record of the vehicle's onto the wire. */
static void send_record(const coavoid_session_t *s, coavoid_replay_kind_t kind, int64_t time,
                        const char *channel, size_t channel_length, const uint8_t *payload,
                        size_t payload_length)
{
    coavoid_session_put_record(kind, time, channel, channel_length, payload, payload_length, s->put,
                               s->user);
}

/* The node's link: each datagram goes to the ground at once, during the call. */
static int session_send(void *user, const char *channel, const uint8_t *data, size_t size)
{
    const coavoid_session_t *s = user;
    const size_t length = strlen(channel);
    if (length > COAVOID_REPLAY_MAX_CHANNEL || size > COAVOID_REPLAY_MAX_PAYLOAD) {
        return COA_ERR_ARGUMENT;
    }
    send_record(s, COAVOID_REPLAY_SENT, s->replay.now, channel, length, data, size);
    return COA_OK;
}

void coavoid_session_init(coavoid_session_t *s, void *memory, size_t size, coavoid_link_put_t put,
                          void *user)
{
    memset(s, 0, sizeof *s);
    s->memory = memory;
    s->size = size;
    s->put = put;
    s->user = user;
    s->polled = INT64_MIN;
}

/* The first error of the frame is its outcome. */
static void note(coavoid_session_t *s, int rc)
{
    if (rc < 0 && s->rc == COA_OK) {
        s->rc = rc;
    }
}

/* The deadline unless it was already polled for. */
static int64_t pending_deadline(const coavoid_session_t *s)
{
    const int64_t deadline = coavoid_vehicle_node_deadline(s->replay.node);
    return deadline == s->polled ? INT64_MAX : deadline;
}

/* A poll at `now`, remembering the deadline it was made for (so that a deadline the node
 * does not move is polled once, as the drivers' loop does). */
static void poll_at(coavoid_session_t *s, int64_t now)
{
    const int64_t deadline = coavoid_vehicle_node_deadline(s->replay.node);
    note(s, coavoid_vehicle_node_poll(s->replay.node, now));
    if (deadline <= now) {
        s->polled = deadline;
    }
}

/* What the drivers' loop does by `now`: the cycle that is due, then a deadline that came. */
static void due_calls(coavoid_session_t *s, int64_t now)
{
    const coavoid_node_common_t *c = &s->replay.config.common;
    if (now >= coavoid_node_cycle_utime(c, s->next_cycle)) {
        const int64_t k = coavoid_node_cycle_of(c, now);
        note(s, coavoid_vehicle_node_cycle(s->replay.node, now));
        s->next_cycle = k + 1;
    }
    if (pending_deadline(s) <= now) {
        poll_at(s, now);
    }
}

/* The CONFIG: the node built, or the same bytes again (the ground started again). */
static void take_config(coavoid_session_t *s, const coavoid_replay_record_t *rec)
{
    const uint64_t hash =
        coavoid_node_fnv(COAVOID_NODE_FNV_OFFSET, rec->payload, rec->payload_length);
    if (s->replay.node != NULL) {
        note(s, hash == s->config_hash ? COA_OK : COAVOID_REPLAY_ERR_FORMAT);
        return;
    }
    int rc = coavoid_replay_config(&s->replay, rec->payload, rec->payload_length);
    s->replay.now = rec->time;
    if (rc == COA_OK) {
        const coavoid_node_link_t link = {session_send, s};
        s->replay.node =
            coavoid_vehicle_node_init(s->memory, s->size, &s->replay.config, &link, &rc);
    }
    if (s->replay.node == NULL) {
        note(s, rc);
        return;
    }
    s->config_hash = hash;
    const coavoid_node_common_t *c = &s->replay.config.common;
    s->next_cycle = rec->time < c->epoch_utime ? 0 : coavoid_node_cycle_of(c, rec->time);
}

/* The channels the node takes in, one SUBSCRIBE each. */
static void send_channels(const coavoid_session_t *s)
{
    for (size_t i = 0; i < COAVOID_NODE_CHANNELS; i++) {
        const char *channel = coavoid_vehicle_node_channel(s->replay.node, i);
        if (channel != NULL) {
            send_record(s, COAVOID_REPLAY_SUBSCRIBE, s->replay.now, channel, strlen(channel), NULL,
                        0u);
        }
    }
}

/* A datagram off the group, at the frame's time, and the poll after it. */
static void take_datagram(coavoid_session_t *s, const coavoid_replay_record_t *rec)
{
    char channel[COAVOID_REPLAY_MAX_CHANNEL + 1u];
    coavoid_replay_channel(rec, channel);
    note(s,
         coavoid_vehicle_node_receive(s->replay.node, channel, rec->payload, rec->payload_length));
    poll_at(s, s->replay.now);
}

/* READY: the frame's outcome, the state, and when the vehicle next needs a frame. */
static void send_ready(coavoid_session_t *s)
{
    uint8_t state[COAVOID_REPLAY_STATE_BYTES];
    coavoid_vehicle_node_state_t idle;
    int64_t wake = INT64_MAX;
    const coavoid_vehicle_node_state_t *st = &idle;
    if (s->replay.node != NULL) {
        const int64_t start = coavoid_node_cycle_utime(&s->replay.config.common, s->next_cycle);
        wake = pending_deadline(s);
        wake = start < wake ? start : wake;
        st = coavoid_vehicle_node_state(s->replay.node);
    } else {
        memset(&idle, 0, sizeof idle);
        idle.cycle = -1;
    }
    coavoid_replay_write_state(s->rc, st, state);
    send_record(s, COAVOID_REPLAY_READY, wake, NULL, 0u, state, sizeof state);
    s->refused += s->rc < 0 ? 1u : 0u;
}

int coavoid_session_take(coavoid_session_t *s, const uint8_t *frame, size_t size)
{
    coavoid_replay_record_t rec;
    size_t used = 0;
    s->rc = COA_OK;
    s->frames++;
    if (coavoid_replay_parse(frame, size, &rec, &used) != COA_OK || used != size) {
        note(s, COAVOID_REPLAY_ERR_FORMAT);
    } else if (rec.kind == COAVOID_REPLAY_CONFIG) {
        take_config(s, &rec);
        if (s->rc == COA_OK) {
            send_channels(s);
        }
    } else if (s->replay.node == NULL ||
               (rec.kind != COAVOID_REPLAY_RECEIVE && rec.kind != COAVOID_REPLAY_TIME)) {
        note(s, COAVOID_REPLAY_ERR_FORMAT);
    } else {
        /* The vehicle's clock never goes back, whatever a frame says. */
        s->replay.now = rec.time > s->replay.now ? rec.time : s->replay.now;
        due_calls(s, s->replay.now);
        if (rec.kind == COAVOID_REPLAY_RECEIVE) {
            take_datagram(s, &rec);
        }
        due_calls(s, s->replay.now);
    }
    const int rc = s->rc;
    send_ready(s);
    return rc;
}
