/* SPDX-License-Identifier: MIT */
#include "node_lcm.h"

#include <limits.h>
#include <stdlib.h>

/* A generous queue per subscription: a cycle publishes one intent and one heartbeat per
 * UAV and one estimate per track, all handled before the next cycle. LCM's default (30)
 * would drop messages of a large fleet without a word. */
#define COAVOID_NODE_QUEUE_CAPACITY \
    ((int)(4u * COAVOID_NODE_MAX_PEERS + 2u * COAVOID_NODE_MAX_TRACKS + 16u))

static int lcm_send(void *user, const char *channel, const uint8_t *data, size_t size)
{
    coavoid_node_lcm_t *t = user;
    if (size > (size_t)UINT_MAX) {
        return COA_ERR_ARGUMENT;
    }
    if (lcm_publish(t->tx, channel, data, (unsigned int)size) != 0) {
        return COA_ERR_ARGUMENT;
    }
    if (t->tap != NULL) {
        t->tap(t->tap_user, true, channel, data, size);
    }
    return COA_OK;
}

void coavoid_node_lcm_init(coavoid_node_lcm_t *t, lcm_t *tx, lcm_t *rx)
{
    t->tx = tx;
    t->rx = rx != NULL ? rx : tx;
    t->sub_count = 0;
    t->in = NULL;
    t->tap = NULL;
    t->tap_user = NULL;
}

coavoid_node_link_t coavoid_node_lcm_link(coavoid_node_lcm_t *t)
{
    const coavoid_node_link_t link = {lcm_send, t};
    return link;
}

/* A refusal is counted by the inbox; a channel it does not take in was not subscribed. */
static void on_datagram(const lcm_recv_buf_t *rbuf, const char *channel, void *user)
{
    coavoid_node_lcm_t *t = user;
    if (rbuf != NULL && rbuf->data != NULL) {
        if (t->tap != NULL) {
            t->tap(t->tap_user, false, channel, rbuf->data, rbuf->data_size);
        }
        (void)coavoid_node_inbox_receive(t->in, channel, rbuf->data, rbuf->data_size);
    }
}

int coavoid_node_lcm_subscribe(coavoid_node_lcm_t *t, coavoid_node_inbox_t *in)
{
    t->in = in;
    for (size_t i = 0; i < COAVOID_NODE_CHANNELS; i++) {
        const char *channel = coavoid_node_inbox_channel(in, i);
        if (channel == NULL) {
            continue;
        }
        lcm_subscription_t *sub = lcm_subscribe(t->rx, channel, on_datagram, t);
        if (sub == NULL) {
            coavoid_node_lcm_unsubscribe(t);
            return COA_ERR_ARGUMENT;
        }
        lcm_subscription_set_queue_capacity(sub, COAVOID_NODE_QUEUE_CAPACITY);
        t->subs[t->sub_count++] = sub;
    }
    return COA_OK;
}

void coavoid_node_lcm_unsubscribe(coavoid_node_lcm_t *t)
{
    for (size_t i = 0; i < t->sub_count; i++) {
        lcm_unsubscribe(t->rx, t->subs[i]);
    }
    t->sub_count = 0;
}

/* A vehicle made by create: its transport first, then the node (at an aligned offset),
 * in one block; the node's link points at the transport, so destroy finds the block. */
static size_t transport_head(void)
{
    return coavoid_node_align_up(sizeof(coavoid_node_lcm_t));
}

coavoid_vehicle_node_t *coavoid_vehicle_node_create(const coavoid_vehicle_node_config_t *config,
                                                    lcm_t *lcm, lcm_t *rx_lcm, int *error)
{
    int dummy = 0;
    error = error != NULL ? error : &dummy;
    *error = COA_ERR_ARGUMENT;
    const size_t size = config != NULL && lcm != NULL ? coavoid_vehicle_node_size(config) : 0u;
    if (size == 0u || size > SIZE_MAX - transport_head()) {
        return NULL;
    }
    uint8_t *block = malloc(transport_head() + size);
    if (block == NULL) {
        *error = COA_ERR_WORKSPACE;
        return NULL;
    }
    coavoid_node_lcm_t *t = (coavoid_node_lcm_t *)(void *)block;
    coavoid_node_lcm_init(t, lcm, rx_lcm);
    const coavoid_node_link_t link = coavoid_node_lcm_link(t);
    coavoid_vehicle_node_t *node =
        coavoid_vehicle_node_init(block + transport_head(), size, config, &link, error);
    if (node != NULL) {
        *error = coavoid_node_lcm_subscribe(t, coavoid_vehicle_node_inbox(node));
    }
    if (*error != COA_OK) {
        coavoid_vehicle_node_fini(node);
        free(block);
        return NULL;
    }
    return node;
}

void coavoid_vehicle_node_destroy(coavoid_vehicle_node_t *node)
{
    if (node == NULL) {
        return;
    }
    coavoid_node_lcm_t *t = coavoid_vehicle_node_inbox(node)->tx.link.user;
    coavoid_node_lcm_unsubscribe(t);
    coavoid_vehicle_node_fini(node);
    free(t);
}

void coavoid_vehicle_node_tap(coavoid_vehicle_node_t *node, coavoid_node_tap_t tap, void *user)
{
    if (node != NULL) {
        coavoid_node_lcm_t *t = coavoid_vehicle_node_inbox(node)->tx.link.user;
        t->tap = tap;
        t->tap_user = user;
    }
}
