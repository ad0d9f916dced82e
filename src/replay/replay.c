/* SPDX-License-Identifier: MIT */
/* A vehicle's replay (replay.h): the recorded calls made again, what it does compared. */
#include <string.h>

#include "protocol_internal.h"
#include "replay_internal.h"

/* A datagram's identity: its channel and bytes. */
static uint64_t datagram_hash(const char *channel, size_t channel_length, const void *data,
                              size_t size)
{
    const uint64_t h = coavoid_node_fnv(COAVOID_NODE_FNV_OFFSET, channel, channel_length);
    return coavoid_node_fnv(coavoid_node_fnv(h, "", 1u), data, size);
}

/* The vehicle's link: what it sends is remembered, for the SENT records that follow. */
static int replay_send(void *user, const char *channel, const uint8_t *data, size_t size)
{
    coavoid_replay_t *r = user;
    if (r->sent_count == COAVOID_REPLAY_MAX_SENT) {
        r->sent_overflow = true;
        return COA_OK;
    }
    r->sent_hash[r->sent_count++] = datagram_hash(channel, strlen(channel), data, size);
    r->sent++;
    return COA_OK;
}

int coavoid_replay_start(coavoid_replay_t *r, void *memory, size_t size)
{
    const coavoid_node_link_t link = {replay_send, r};
    int error = COA_ERR_ARGUMENT;
    r->node = coavoid_vehicle_node_init(memory, size, &r->config, &link, &error);
    return r->node != NULL ? COA_OK : error;
}

static int differ(coavoid_replay_t *r, const char *what)
{
    if (!r->differs) {
        r->differs = true;
        r->first_difference = r->records;
        r->difference = what;
    }
    return COAVOID_REPLAY_ERR_DIFFERS;
}

/* A new call: whatever the last one sent must all have been recorded. */
static int begin_call(coavoid_replay_t *r, int64_t time)
{
    const bool unrecorded = r->sent_checked != r->sent_count || r->sent_overflow;
    r->sent_count = 0;
    r->sent_checked = 0;
    r->sent_overflow = false;
    r->now = time;
    return unrecorded ? differ(r, "the vehicle sent a datagram the record does not have") : COA_OK;
}

static int check_sent(coavoid_replay_t *r, const coavoid_replay_record_t *rec)
{
    if (r->sent_checked == r->sent_count) {
        return differ(r, "the record has a datagram the vehicle did not send");
    }
    const uint64_t h =
        datagram_hash(rec->channel, rec->channel_length, rec->payload, rec->payload_length);
    return r->sent_hash[r->sent_checked++] == h
               ? COA_OK
               : differ(r, "the vehicle sent other bytes than recorded");
}

static int check_state(coavoid_replay_t *r, int rc, const coavoid_replay_record_t *rec)
{
    uint8_t state[COAVOID_REPLAY_STATE_BYTES];
    coavoid_replay_write_state(rc, coavoid_vehicle_node_state(r->node), state);
    if (rec->payload_length != sizeof state) {
        return COAVOID_REPLAY_ERR_FORMAT;
    }
    return memcmp(state, rec->payload, sizeof state) == 0
               ? COA_OK
               : differ(r, "the vehicle's state after a call is not the recorded one");
}

/* The call a record makes; *rc its return value. */
static int call(coavoid_replay_t *r, const coavoid_replay_record_t *rec, int *rc)
{
    int begun = begin_call(r, rec->time);
    switch (rec->kind) {
    case COAVOID_REPLAY_RECEIVE: {
        char channel[COAVOID_REPLAY_MAX_CHANNEL + 1u];
        coavoid_replay_channel(rec, channel);
        *rc = coavoid_vehicle_node_receive(r->node, channel, rec->payload, rec->payload_length);
        r->receives++;
        break;
    }
    case COAVOID_REPLAY_CYCLE:
        *rc = coavoid_vehicle_node_cycle(r->node, rec->time);
        r->cycles++;
        break;
    default:
        *rc = coavoid_vehicle_node_poll(r->node, rec->time);
        r->polls++;
        break;
    }
    return begun;
}

int coavoid_replay_apply(coavoid_replay_t *r, const coavoid_replay_record_t *rec)
{
    int rc = COA_OK;
    if (r == NULL || r->node == NULL || rec == NULL) {
        return COA_ERR_ARGUMENT;
    }
    r->records++;
    switch (rec->kind) {
    case COAVOID_REPLAY_RECEIVE:
    case COAVOID_REPLAY_CYCLE:
    case COAVOID_REPLAY_POLL:
        rc = call(r, rec, &r->last_rc);
        break;
    case COAVOID_REPLAY_SENT:
        rc = check_sent(r, rec);
        break;
    case COAVOID_REPLAY_STATE:
        rc = check_state(r, r->last_rc, rec);
        break;
    default:
        rc = COAVOID_REPLAY_ERR_FORMAT; /* a second CONFIG */
        break;
    }
    return rc;
}

int coavoid_replay_finish(coavoid_replay_t *r)
{
    return begin_call(r, r->now);
}
