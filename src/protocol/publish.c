/* SPDX-License-Identifier: MIT */
/*
 * Publishing (protocol_internal.h): every message encoded into the node's buffer, signed,
 * and handed to its link; the heartbeat built from what the node reports.
 */
#include "protocol_internal.h"

#include <limits.h>
#include <math.h>
#include <string.h>

/* Dropped unchecked since start: over the inbox budget, or by the transport; saturated. */
static int64_t dropped_unchecked(const coavoid_node_inbox_t *in)
{
    const uint64_t transport =
        in->common.transport_dropped != NULL ? *in->common.transport_dropped : 0u;
    const uint64_t total = (uint64_t)in->dropped + transport;
    return total > (uint64_t)INT64_MAX || total < transport ? INT64_MAX : (int64_t)total;
}

/* Datagrams a second over the last whole cycle, saturated. */
static int32_t inbox_rate(const coavoid_node_inbox_t *in)
{
    const double rate = (double)in->last_cycle_datagrams * 1e6 / (double)in->common.dt_us;
    return rate >= (double)INT32_MAX ? INT32_MAX : (int32_t)rate;
}

int coavoid_node_publish_heartbeat(coavoid_node_inbox_t *in, coavoid_status_t *m, int64_t now,
                                   int64_t cycle_start, const coavoid_node_heartbeat_t *h)
{
    memset(m, 0, sizeof *m);
    m->utime = now;
    m->node_id = h->node_id;
    m->node_kind = h->node_kind;
    m->sequence = h->sequence;
    const bool refused = h->rx->rejected > in->rejected_at_heartbeat;
    in->rejected_at_heartbeat = h->rx->rejected;
    coavoid_node_inbox_roll(in, now);
    const int64_t dropped = dropped_unchecked(in);
    const bool flooded =
        dropped > in->dropped_at_heartbeat || in->last_cycle_datagrams > COAVOID_NODE_INBOX_FLOOD;
    in->dropped_at_heartbeat = dropped;
    m->reasons = h->reasons | (refused ? COAVOID_STATUS_T_REASON_MESSAGES_REFUSED : 0) |
                 (flooded ? COAVOID_STATUS_T_REASON_INBOX_FLOOD : 0) |
                 (in->have_map ? 0 : COAVOID_STATUS_T_REASON_NO_MAP) |
                 (in->secure ? 0 : COAVOID_STATUS_T_REASON_INSECURE);
    m->health = coavoid_lcm_health_of(m->reasons);
    m->mode = h->mode;
    m->last_plan_utime = h->last_plan_utime;
    m->last_plan_duration_us = h->last_plan_duration_us;
    m->nodes_expanded =
        h->last_nodes_expanded > (uint64_t)INT64_MAX ? INT64_MAX : (int64_t)h->last_nodes_expanded;
    m->outcome = h->last_outcome < 0 ? COAVOID_STATUS_T_OUTCOME_NONE : (int8_t)h->last_outcome;
    m->conflicts = h->conflicts > (uint32_t)INT32_MAX ? INT32_MAX : (int32_t)h->conflicts;
    m->plans_run = h->plans_run > (uint32_t)INT32_MAX ? INT32_MAX : (int32_t)h->plans_run;
    m->messages_received = h->rx->received;
    m->messages_rejected = h->rx->rejected;
    m->last_reject_code = h->rx->last_reject_code;
    m->messages_dropped = dropped;
    m->inbox_rate = inbox_rate(in);
    coavoid_lcm_context_t ctx = coavoid_node_context(in, now, cycle_start);
    if (coavoid_lcm_status_check(m, &ctx, NULL) != COA_OK) {
        return COA_ERR_ARGUMENT;
    }
    return coavoid_node_publish_status(&in->tx, m);
}

/* ---- publishing ---- */

void coavoid_node_tx_init(coavoid_node_tx_t *tx, const coavoid_node_link_t *link,
                          const coavoid_node_common_t *c)
{
    tx->link = *link;
    tx->clock = c->clock;
    tx->sign = !c->insecure && c->signer != NULL;
    memset(&tx->signer, 0, sizeof tx->signer);
    if (tx->sign) {
        tx->signer = *c->signer;
    }
}

void coavoid_node_tx_fini(coavoid_node_tx_t *tx)
{
    coavoid_auth_signer_clear(&tx->signer);
    tx->sign = false;
}

/* Encodes msg into tx->buf with the type's functions and signs it; its size, or a
 * negative error. */
#define COAVOID_NODE_SEAL(tx, type, msg) \
    (seal((tx), type##_encoded_size(msg), type##_encode((tx)->buf, 0, (int)sizeof(tx)->buf, (msg))))

/* Whether an encoded message of `size` bytes may go out: at most one datagram
 * (COAVOID_LCM_MAX_DATAGRAM_BYTES), so that no message is fragmented on the way; every type
 * fits, so a larger one is a bug, refused rather than sent. O(1). */
static bool fits_datagram(int size)
{
    return size > 0 && size <= COAVOID_LCM_MAX_DATAGRAM_BYTES &&
           (size_t)size <= COAVOID_NODE_TX_BYTES;
}

/* The size of the message encoded into tx->buf (encoded: the encoder's return, expected
 * to be `size`), signed unless the node is insecure; or a negative error. Nothing over
 * one datagram is encoded. */
static int seal(coavoid_node_tx_t *tx, int size, int encoded)
{
    if (!fits_datagram(size) || encoded != size) {
        return COA_ERR_WORKSPACE;
    }
    if (tx->sign && coavoid_auth_stamp(&tx->signer, *tx->clock, tx->buf, (size_t)size) != COA_OK) {
        return COA_ERR_ARGUMENT;
    }
    return size;
}

static int send_sealed(coavoid_node_tx_t *tx, const char *channel, int size)
{
    if (size < 0) {
        return size;
    }
    return tx->link.send(tx->link.user, channel, tx->buf, (size_t)size) == COA_OK
               ? COA_OK
               : COA_ERR_ARGUMENT;
}

#define COAVOID_NODE_DEFINE_PUBLISH(function, type, channel)               \
    int function(coavoid_node_tx_t *tx, const type *msg)                   \
    {                                                                      \
        return send_sealed(tx, channel, COAVOID_NODE_SEAL(tx, type, msg)); \
    }

COAVOID_NODE_DEFINE_PUBLISH(coavoid_node_publish_plan, coavoid_plan_t, COAVOID_CHANNEL_PLAN)
COAVOID_NODE_DEFINE_PUBLISH(coavoid_node_publish_track, coavoid_track_t, COAVOID_CHANNEL_TRACK)
COAVOID_NODE_DEFINE_PUBLISH(coavoid_node_publish_map, coavoid_obstacle_map_t,
                            COAVOID_CHANNEL_OBSTACLES)
COAVOID_NODE_DEFINE_PUBLISH(coavoid_node_publish_conflicts, coavoid_conflict_report_t,
                            COAVOID_CHANNEL_CONFLICTS)
COAVOID_NODE_DEFINE_PUBLISH(coavoid_node_publish_status, coavoid_status_t, COAVOID_CHANNEL_STATUS)
COAVOID_NODE_DEFINE_PUBLISH(coavoid_node_publish_agreement, coavoid_agreement_t,
                            COAVOID_CHANNEL_AGREEMENT)

int coavoid_node_publish_intent(coavoid_node_inbox_t *in, const coavoid_intent_t *msg)
{
    coavoid_node_tx_t *tx = &in->tx;
    const int size = COAVOID_NODE_SEAL(tx, coavoid_intent_t, msg);
    if (size < 0) {
        return size;
    }
    /* Remembered before it is sent (signed, as it will come back): a provider may hand it
     * back within lcm_publish. */
    in->own_hash[in->own_next] = coavoid_node_fnv(COAVOID_NODE_FNV_OFFSET, tx->buf, (size_t)size);
    in->own_size[in->own_next] = size;
    in->own_next = (in->own_next + 1u) % COAVOID_NODE_OWN_INTENTS;
    return send_sealed(tx, COAVOID_CHANNEL_INTENT, size);
}
