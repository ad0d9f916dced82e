/* SPDX-License-Identifier: MIT */
/*
 * net.h: the network between the nodes of a one-process run (sim.c), inside
 * coavoid::sim. Each node publishes on an lcm_t of its own (LCM's memq provider) and
 * subscribes on another (the rx_lcm of coavoid_vehicle_node_create and
 * coavoid_coordinator_create); the network hears everything a node publishes and
 * decides, per receiver, whether and when the message reaches it:
 *   - back to the sender itself at once, never lost (a multicast socket's loopback);
 *   - to each other receiving node independently: dropped with that receiver's loss
 *     probability, else delivered after delay + a uniform jitter in [0, jitter]
 *     (microseconds of the nodes' clock), from a seeded splitmix64 stream.
 * So the nodes are the real node code: the network only decides who hears what, and
 * when. The draws follow the order in which messages are sent and receivers are numbered,
 * which the simulation makes deterministic: one seed, one run. With no loss, no delay and
 * no jitter nothing is drawn and each message reaches every node at once, in the order
 * sent: what one shared bus does.
 *
 * Copies waiting for their time are in a queue of fixed capacity (set at create; the
 * caller sizes it from the fleet and how long a message may be in flight): a copy that
 * does not fit is an error of the run, never a silent loss.
 */
#ifndef COAVOID_SIM_NET_H
#define COAVOID_SIM_NET_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include <lcm/lcm.h>

typedef struct {
    double loss;       /* each receiver's loss probability, 0..1 (coavoid_sim_net_set_loss) */
    int64_t delay_us;  /* >= 0 */
    int64_t jitter_us; /* >= 0 */
    uint64_t seed;
    /* Messages (payloads) and copies in flight at once at most; 0 and 0 when nothing is
     * ever delayed (delay and jitter 0). */
    size_t message_capacity;
    size_t copy_capacity;
    /* Optional (scripted loss, for tests): asked about every copy to another receiver
     * that the random loss spared, with its channel, its sender's and receiver's node
     * numbers, its bytes and the time it is sent; true drops it (counted as dropped). It
     * must not publish. NULL: nothing more is dropped. */
    bool (*drop)(void *user, const char *channel, size_t from, size_t to, const void *data,
                 size_t size, int64_t now);
    void *drop_user;
} coavoid_sim_net_config_t;

/* What the network did since create. Every copy to another receiver is delivered,
 * dropped, or still in flight. Loopback copies are not counted. */
typedef struct {
    uint64_t sent;      /* messages published by the nodes and put on the network */
    uint64_t delivered; /* copies handed to another node */
    uint64_t dropped;   /* copies lost */
    uint64_t in_flight; /* copies still waiting for their time */
    uint64_t cut;       /* messages published after their node's cut: never copied, not sent */
} coavoid_sim_net_stats_t;

typedef struct coavoid_sim_net coavoid_sim_net_t;

/* A network of `nodes` nodes (numbered 0..nodes-1): node i publishes on
 * coavoid_sim_net_tx(net, i), and, when receives[i], subscribes on coavoid_sim_net_rx(net,
 * i). Allocates the queue (about 1.5 kB per message and 24 bytes per copy of the capacity)
 * and 2 memq lcm_t per receiving node, 1 per other. Returns NULL with *error COA_ERR_ARGUMENT
 * (a bad config: loss outside 0..1, a negative delay or jitter, a delay with no capacity,
 * or LCM refused a memq instance or a subscription) or COA_ERR_WORKSPACE (out of memory). */
coavoid_sim_net_t *coavoid_sim_net_create(const coavoid_sim_net_config_t *config, size_t nodes,
                                          const bool *receives, int *error);
/* Frees everything, copies in flight included. NULL is fine. */
void coavoid_sim_net_destroy(coavoid_sim_net_t *net);

/* Node i's lcm to publish on, and to subscribe on (NULL when it does not receive). O(1). */
lcm_t *coavoid_sim_net_tx(const coavoid_sim_net_t *net, size_t i);
lcm_t *coavoid_sim_net_rx(const coavoid_sim_net_t *net, size_t i);

/* Receiver i's loss probability from now on (0..1; 1: it hears no other node). O(1). */
void coavoid_sim_net_set_loss(coavoid_sim_net_t *net, size_t i, double loss);
/* Node i is gone (a coordinator stopped): no copy is made for it any more. O(1). */
void coavoid_sim_net_stop(coavoid_sim_net_t *net, size_t i);
/* Node i's link is cut after `count` more messages: counted from this call on, the first
 * count it publishes go out as any other, and every later one is never copied, to no node
 * (itself included). Whatever the messages' kinds: a node that dies between any two of its
 * messages, mid-cycle too, with or without loss and delay (copies already made still
 * travel). A later call sets a new count. O(1). */
void coavoid_sim_net_stop_after(coavoid_sim_net_t *net, size_t i, uint64_t count);
/* True once node i's count (coavoid_sim_net_stop_after) is spent: nothing more it
 * publishes reaches anyone. O(1). */
bool coavoid_sim_net_cut(const coavoid_sim_net_t *net, size_t i);
/* Messages node i published that went out (the cut ones not). O(1). */
uint64_t coavoid_sim_net_sent_by(const coavoid_sim_net_t *net, size_t i);

/* Node i's tap: tap(user, channel, data, size) sees every message of node i that goes out,
 * as it goes out (NULL: none). O(1). */
typedef void (*coavoid_sim_net_tap_t)(void *user, const char *channel, const void *data,
                                      uint32_t size);
void coavoid_sim_net_tap(coavoid_sim_net_t *net, size_t i, coavoid_sim_net_tap_t tap, void *user);
/* A digest (64-bit FNV-1a) of every message that went out so far, sender, channel and
 * bytes, in order: two runs of the same nodes whose digests differ have sent different
 * things (a replay checks that it still is the run it replays). O(1). */
uint64_t coavoid_sim_net_digest(const coavoid_sim_net_t *net);

/* At `now` (the nodes' clock, which must not go back between calls): takes every
 * message the nodes published since the last call (each sent at `now`), makes its copies,
 * hands the receivers every copy due at or before now, and lets their handlers run, until
 * nothing is left to do. Returns COA_OK, COA_ERR_WORKSPACE (the queue is full, or a
 * message is larger than a datagram: the run cannot go on truthfully) or COA_ERR_ARGUMENT
 * (LCM failed). Cost: O(log copies) per copy plus the handlers'; no memory. */
int coavoid_sim_net_pump(coavoid_sim_net_t *net, int64_t now);

/* When the next copy in flight is due, or INT64_MAX. O(1). */
int64_t coavoid_sim_net_next(const coavoid_sim_net_t *net);

/* The counts so far. O(1). */
coavoid_sim_net_stats_t coavoid_sim_net_stats(const coavoid_sim_net_t *net);

#endif /* COAVOID_SIM_NET_H */
