/* SPDX-License-Identifier: MIT */
/*
 * node_lcm.h: the LCM transport of a node. What a node sends goes out with lcm_publish on
 * one lcm; what it takes in comes from subscriptions on another (or the same), one per
 * channel its inbox takes in, each handing the datagram to coavoid_node_inbox_receive.
 * A firmware has its own transport and needs none of this.
 */
#ifndef COAVOID_NODE_LCM_H
#define COAVOID_NODE_LCM_H

#include <lcm/lcm.h>

#include "node.h"
#include "protocol_internal.h"

typedef struct {
    lcm_t *tx; /* where it publishes */
    lcm_t *rx; /* where it subscribes */
    lcm_subscription_t *subs[COAVOID_NODE_CHANNELS];
    size_t sub_count;
    coavoid_node_inbox_t *in; /* what it subscribed */
    coavoid_node_tap_t tap;   /* NULL, or told of every datagram (coavoid_vehicle_node_tap) */
    void *tap_user;
} coavoid_node_lcm_t;

/* Prepares t to publish on tx and to subscribe on rx (NULL: tx); nothing subscribed yet.
 * The link that publishes on tx. O(1). */
void coavoid_node_lcm_init(coavoid_node_lcm_t *t, lcm_t *tx, lcm_t *rx);
coavoid_node_link_t coavoid_node_lcm_link(coavoid_node_lcm_t *t);

/* Subscribes the inbox to every channel it takes in (coavoid_node_inbox_channel's order),
 * each with a queue of COAVOID_NODE_QUEUE_CAPACITY messages. COA_OK, or COA_ERR_ARGUMENT
 * when LCM refused one (nothing stays subscribed). O(channels). */
int coavoid_node_lcm_subscribe(coavoid_node_lcm_t *t, coavoid_node_inbox_t *in);

/* Unsubscribes everything subscribe made. O(channels). */
void coavoid_node_lcm_unsubscribe(coavoid_node_lcm_t *t);

#endif /* COAVOID_NODE_LCM_H */
