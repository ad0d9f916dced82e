/* SPDX-License-Identifier: MIT */
/*
 * net.c: the simulated network of net.h: per-node memq buses, the routing of each
 * published message, and a min-heap of the copies in flight by (due, order sent).
 */
#include "net.h"

#include <stdlib.h>
#include <string.h>

#include "coavoid/coavoid.h"
#include "coavoid_lcm.h"
#include "prng.h"

/* Channels are the nodes' own (COAVOID_CHANNEL_*): far shorter. */
#define NET_CHANNEL_MAX 64u

typedef struct {
    uint32_t refs; /* copies in flight that carry it; 0: free */
    uint32_t size;
    char channel[NET_CHANNEL_MAX];
    uint8_t data[COAVOID_LCM_MAX_DATAGRAM_BYTES];
} net_message_t;

typedef struct {
    int64_t due;
    uint64_t order; /* ties in due: the order the copies were made */
    uint32_t message;
    uint32_t receiver;
} net_copy_t;

/* A node's side of the network. */
typedef struct {
    coavoid_sim_net_t *net;
    size_t index;
    lcm_t *tx;
    lcm_t *rx; /* NULL: it receives nothing */
    lcm_subscription_t *heard;
    bool stopped;
    bool limited; /* coavoid_sim_net_stop_after: only `allowance` more go out */
    uint64_t allowance;
    uint64_t sent; /* its messages that went out */
    coavoid_sim_net_tap_t tap;
    void *tap_user;
    double loss;
} net_node_t;

struct coavoid_sim_net {
    coavoid_sim_net_config_t config;
    size_t count;
    net_node_t *nodes;
    coavoid_prng_t prng;
    int64_t now;
    int error; /* the first error inside a handler */
    net_message_t *messages;
    uint32_t *free_messages; /* a stack of free message slots */
    size_t free_count;
    net_copy_t *heap;
    size_t heap_count;
    uint64_t order;
    coavoid_sim_net_stats_t stats;
    uint64_t digest;
};

#define NET_FNV_OFFSET UINT64_C(14695981039346656037)
#define NET_FNV_PRIME UINT64_C(1099511628211)

static uint64_t fnv(uint64_t h, const void *data, size_t size)
{
    const uint8_t *b = data;
    for (size_t k = 0; k < size; k++) {
        h = (h ^ b[k]) * NET_FNV_PRIME;
    }
    return h;
}

/* Uniform in [0, 1), from the seeded stream (prng.h: the same for a seed everywhere). */
static double net_uniform(coavoid_sim_net_t *net)
{
    return coavoid_prng_uniform(&net->prng, 0.0, 1.0);
}

static bool copy_before(const net_copy_t *a, const net_copy_t *b)
{
    return a->due < b->due || (a->due == b->due && a->order < b->order);
}

static void heap_push(coavoid_sim_net_t *net, net_copy_t c)
{
    size_t i = net->heap_count++;
    while (i > 0u) {
        size_t parent = (i - 1u) / 2u;
        if (!copy_before(&c, &net->heap[parent])) {
            break;
        }
        net->heap[i] = net->heap[parent];
        i = parent;
    }
    net->heap[i] = c;
}

static net_copy_t heap_pop(coavoid_sim_net_t *net)
{
    net_copy_t top = net->heap[0];
    net_copy_t last = net->heap[--net->heap_count];
    size_t i = 0;
    for (;;) {
        size_t child = 2u * i + 1u;
        if (child >= net->heap_count) {
            break;
        }
        if (child + 1u < net->heap_count &&
            copy_before(&net->heap[child + 1u], &net->heap[child])) {
            child++;
        }
        if (!copy_before(&net->heap[child], &last)) {
            break;
        }
        net->heap[i] = net->heap[child];
        i = child;
    }
    if (net->heap_count > 0u) {
        net->heap[i] = last;
    }
    return top;
}

static void fail(coavoid_sim_net_t *net, int error)
{
    net->error = net->error != COA_OK ? net->error : error;
}

static void hand(coavoid_sim_net_t *net, size_t receiver, const char *channel, const void *data,
                 uint32_t size)
{
    if (lcm_publish(net->nodes[receiver].rx, channel, data, size) != 0) {
        fail(net, COA_ERR_ARGUMENT);
    }
}

/* A copy of the message for receiver j, due at `due`: stored once per message (*slot,
 * taken on the first copy that waits). */
static void net_delay(coavoid_sim_net_t *net, size_t j, int64_t due, const lcm_recv_buf_t *rbuf,
                      const char *channel, uint32_t *slot)
{
    if (*slot == UINT32_MAX) {
        if (net->free_count == 0u || strlen(channel) >= NET_CHANNEL_MAX ||
            rbuf->data_size > COAVOID_LCM_MAX_DATAGRAM_BYTES) {
            fail(net, COA_ERR_WORKSPACE);
            return;
        }
        *slot = net->free_messages[--net->free_count];
        net_message_t *m = &net->messages[*slot];
        m->refs = 0;
        m->size = rbuf->data_size;
        strcpy(m->channel, channel);
        memcpy(m->data, rbuf->data, rbuf->data_size);
    }
    if (net->heap_count >= net->config.copy_capacity) {
        fail(net, COA_ERR_WORKSPACE);
        return;
    }
    net->messages[*slot].refs++;
    net->stats.in_flight++;
    net_copy_t c = {due, net->order++, *slot, (uint32_t)j};
    heap_push(net, c);
}

/* A message node->index published: its copies (lcm's handler on the node's tx). */
static void on_sent(const lcm_recv_buf_t *rbuf, const char *channel, void *user)
{
    net_node_t *from = user;
    coavoid_sim_net_t *net = from->net;
    /* A cut link: the message never leaves the node, and nothing is drawn for it. */
    if (from->limited && from->allowance == 0u) {
        net->stats.cut++;
        return;
    }
    from->allowance -= from->limited ? 1u : 0u;
    from->sent++;
    net->stats.sent++;
    const uint32_t sender = (uint32_t)from->index;
    net->digest = fnv(net->digest, &sender, sizeof sender);
    net->digest = fnv(net->digest, channel, strlen(channel) + 1u);
    net->digest = fnv(net->digest, rbuf->data, rbuf->data_size);
    if (from->tap != NULL) {
        from->tap(from->tap_user, channel, rbuf->data, rbuf->data_size);
    }
    if (from->rx != NULL && !from->stopped) {
        hand(net, from->index, channel, rbuf->data, rbuf->data_size);
    }
    uint32_t slot = UINT32_MAX;
    for (size_t j = 0; j < net->count; j++) {
        const net_node_t *to = &net->nodes[j];
        if (j == from->index || to->rx == NULL || to->stopped) {
            continue;
        }
        if ((to->loss > 0.0 && net_uniform(net) < to->loss) ||
            (net->config.drop != NULL &&
             net->config.drop(net->config.drop_user, channel, from->index, j, rbuf->data,
                              (size_t)rbuf->data_size, net->now))) {
            net->stats.dropped++;
            continue;
        }
        int64_t delay = net->config.delay_us;
        if (net->config.jitter_us > 0) {
            delay += (int64_t)(net_uniform(net) * (double)(net->config.jitter_us + 1));
        }
        if (delay <= 0) {
            net->stats.delivered++;
            hand(net, j, channel, rbuf->data, rbuf->data_size);
        } else {
            net_delay(net, j, net->now + delay, rbuf, channel, &slot);
        }
    }
}

/* Handles everything queued on lcm; the count, or -1 when LCM failed. */
static long drain(lcm_t *lcm)
{
    long handled = 0;
    for (;;) {
        int rc = lcm_handle_timeout(lcm, 0);
        if (rc == 0) {
            return handled;
        }
        if (rc < 0) {
            return -1;
        }
        handled++;
    }
}

/* Every copy due at or before now, handed to its receiver. */
static void deliver_due(coavoid_sim_net_t *net)
{
    while (net->heap_count > 0u && net->heap[0].due <= net->now) {
        net_copy_t c = heap_pop(net);
        net_message_t *m = &net->messages[c.message];
        net->stats.in_flight--;
        net->stats.delivered++;
        hand(net, c.receiver, m->channel, m->data, m->size);
        if (--m->refs == 0u) {
            net->free_messages[net->free_count++] = c.message;
        }
    }
}

int coavoid_sim_net_pump(coavoid_sim_net_t *net, int64_t now)
{
    net->now = now > net->now ? now : net->now;
    for (;;) {
        long handled = 0;
        for (size_t i = 0; i < net->count; i++) {
            long rc = drain(net->nodes[i].tx);
            if (rc < 0) {
                return COA_ERR_ARGUMENT;
            }
            handled += rc;
        }
        if (net->error != COA_OK) {
            return net->error;
        }
        deliver_due(net);
        for (size_t i = 0; i < net->count; i++) {
            long rc = net->nodes[i].rx != NULL ? drain(net->nodes[i].rx) : 0;
            if (rc < 0) {
                return COA_ERR_ARGUMENT;
            }
            handled += rc;
        }
        if (net->error != COA_OK) {
            return net->error;
        }
        /* A handler may publish (none does today): go round until all is quiet. */
        if (handled == 0) {
            return COA_OK;
        }
    }
}

int64_t coavoid_sim_net_next(const coavoid_sim_net_t *net)
{
    return net->heap_count > 0u ? net->heap[0].due : INT64_MAX;
}

coavoid_sim_net_stats_t coavoid_sim_net_stats(const coavoid_sim_net_t *net)
{
    return net->stats;
}

lcm_t *coavoid_sim_net_tx(const coavoid_sim_net_t *net, size_t i)
{
    return net->nodes[i].tx;
}

lcm_t *coavoid_sim_net_rx(const coavoid_sim_net_t *net, size_t i)
{
    return net->nodes[i].rx;
}

void coavoid_sim_net_set_loss(coavoid_sim_net_t *net, size_t i, double loss)
{
    net->nodes[i].loss = loss;
}

void coavoid_sim_net_stop(coavoid_sim_net_t *net, size_t i)
{
    net->nodes[i].stopped = true;
}

void coavoid_sim_net_stop_after(coavoid_sim_net_t *net, size_t i, uint64_t count)
{
    net->nodes[i].limited = true;
    net->nodes[i].allowance = count;
}

bool coavoid_sim_net_cut(const coavoid_sim_net_t *net, size_t i)
{
    return net->nodes[i].limited && net->nodes[i].allowance == 0u;
}

uint64_t coavoid_sim_net_sent_by(const coavoid_sim_net_t *net, size_t i)
{
    return net->nodes[i].sent;
}

void coavoid_sim_net_tap(coavoid_sim_net_t *net, size_t i, coavoid_sim_net_tap_t tap, void *user)
{
    net->nodes[i].tap = tap;
    net->nodes[i].tap_user = user;
}

uint64_t coavoid_sim_net_digest(const coavoid_sim_net_t *net)
{
    return net->digest;
}

void coavoid_sim_net_destroy(coavoid_sim_net_t *net)
{
    if (net == NULL) {
        return;
    }
    for (size_t i = 0; net->nodes != NULL && i < net->count; i++) {
        net_node_t *node = &net->nodes[i];
        if (node->heard != NULL) {
            lcm_unsubscribe(node->tx, node->heard);
        }
        if (node->tx != NULL) {
            lcm_destroy(node->tx);
        }
        if (node->rx != NULL) {
            lcm_destroy(node->rx);
        }
    }
    free(net->nodes);
    free(net->messages);
    free(net->free_messages);
    free(net->heap);
    free(net);
}

static bool config_ok(const coavoid_sim_net_config_t *c)
{
    const bool delayed = c->delay_us > 0 || c->jitter_us > 0;
    return c->loss >= 0.0 && c->loss <= 1.0 && c->delay_us >= 0 && c->jitter_us >= 0 &&
           c->message_capacity < UINT32_MAX && c->copy_capacity < UINT32_MAX &&
           (!delayed || (c->message_capacity > 0u && c->copy_capacity > 0u));
}

/* Node i's buses and the network's ear on its tx. */
static int node_open(coavoid_sim_net_t *net, size_t i, bool receives)
{
    net_node_t *node = &net->nodes[i];
    node->net = net;
    node->index = i;
    node->loss = net->config.loss;
    node->tx = lcm_create("memq://");
    node->rx = receives ? lcm_create("memq://") : NULL;
    if (node->tx == NULL || (receives && node->rx == NULL)) {
        return COA_ERR_ARGUMENT;
    }
    node->heard = lcm_subscribe(node->tx, ".*", on_sent, node);
    return node->heard != NULL ? COA_OK : COA_ERR_ARGUMENT;
}

coavoid_sim_net_t *coavoid_sim_net_create(const coavoid_sim_net_config_t *config, size_t nodes,
                                          const bool *receives, int *error)
{
    if (config == NULL || receives == NULL || nodes == 0u || !config_ok(config)) {
        *error = COA_ERR_ARGUMENT;
        return NULL;
    }
    coavoid_sim_net_t *net = calloc(1u, sizeof *net);
    if (net == NULL) {
        *error = COA_ERR_WORKSPACE;
        return NULL;
    }
    net->config = *config;
    net->prng.state = config->seed;
    net->digest = NET_FNV_OFFSET;
    net->error = COA_OK;
    net->nodes = calloc(nodes, sizeof *net->nodes);
    const size_t m = config->message_capacity, c = config->copy_capacity;
    net->messages = m > 0u ? malloc(m * sizeof *net->messages) : NULL;
    net->free_messages = m > 0u ? malloc(m * sizeof *net->free_messages) : NULL;
    net->heap = c > 0u ? malloc(c * sizeof *net->heap) : NULL;
    if (net->nodes == NULL || (m > 0u && (net->messages == NULL || net->free_messages == NULL)) ||
        (c > 0u && net->heap == NULL)) {
        coavoid_sim_net_destroy(net);
        *error = COA_ERR_WORKSPACE;
        return NULL;
    }
    for (size_t k = 0; k < m; k++) {
        net->free_messages[k] = (uint32_t)(m - 1u - k);
    }
    net->free_count = m;
    int rc = COA_OK;
    for (size_t i = 0; i < nodes && rc == COA_OK; i++) {
        net->count = i + 1u;
        rc = node_open(net, i, receives[i]);
    }
    if (rc != COA_OK) {
        coavoid_sim_net_destroy(net);
        *error = rc;
        return NULL;
    }
    return net;
}
