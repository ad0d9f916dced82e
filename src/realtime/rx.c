/* SPDX-License-Identifier: MIT */
/*
 * rx.c: the drivers' receiver of LCM's UDP multicast (realtime.h, "The receiver").
 */
#define _GNU_SOURCE /* recvmmsg, SO_RXQ_OVFL */

#include "realtime.h"

#include <arpa/inet.h>
#include <errno.h>
#include <netinet/in.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <unistd.h>

#define RX_MAGIC_SHORT 0x4c433032u /* "LC02": a whole message */
#define RX_MAGIC_LONG 0x4c433033u  /* "LC03": a fragment of a longer one */
#define RX_HEADER_BYTES 8u         /* the magic and a sequence number */
#define RX_CHANNEL_MAX 63u         /* LCM's longest channel name */
#define RX_DEFAULT_PORT 7667u      /* LCM's, when the URL names none */
#define RX_CONTROL_BYTES 64u       /* room for the SO_RXQ_OVFL counter's control message */

struct coavoid_rt_rx {
    int fd;
    lcm_t *deliver; /* memq: the nodes' handlers, called as each datagram is delivered */
    coavoid_rt_rx_stats_t stats;
    uint32_t overflow_seen; /* the socket's drop counter when last read */
    unsigned count, next;   /* datagrams of the last batch, and the next to deliver */
    struct mmsghdr msgs[COAVOID_RT_RX_BATCH];
    struct iovec iov[COAVOID_RT_RX_BATCH];
    unsigned char control[COAVOID_RT_RX_BATCH][RX_CONTROL_BYTES];
    unsigned char data[COAVOID_RT_RX_BATCH][COAVOID_RT_RX_DATAGRAM];
};

static uint32_t get_be32(const unsigned char *p)
{
    return (uint32_t)p[0] << 24 | (uint32_t)p[1] << 16 | (uint32_t)p[2] << 8 | (uint32_t)p[3];
}

int coavoid_rt_rx_parse(const unsigned char *datagram, size_t size, coavoid_rt_rx_frame_t *frame)
{
    if (datagram == NULL || frame == NULL) {
        return COA_ERR_ARGUMENT;
    }
    memset(frame, 0, sizeof *frame);
    if (size < RX_HEADER_BYTES) {
        return COAVOID_RT_RX_MALFORMED;
    }
    const uint32_t magic = get_be32(datagram);
    if (magic == RX_MAGIC_LONG) {
        return COAVOID_RT_RX_FRAGMENT;
    }
    if (magic != RX_MAGIC_SHORT) {
        return COAVOID_RT_RX_MALFORMED;
    }
    const unsigned char *name = datagram + RX_HEADER_BYTES;
    const size_t room = size - RX_HEADER_BYTES;
    const unsigned char *end =
        memchr(name, '\0', room < RX_CHANNEL_MAX + 1u ? room : RX_CHANNEL_MAX + 1u);
    if (end == NULL || end == name) {
        return COAVOID_RT_RX_MALFORMED;
    }
    frame->sequence = get_be32(datagram + 4);
    frame->channel = (const char *)name;
    frame->payload = end + 1;
    frame->payload_size = size - (size_t)(frame->payload - datagram);
    return COA_OK;
}

bool coavoid_rt_rx_fleet_channel(const char *channel)
{
    static const char *const fleet[] = {COAVOID_CHANNEL_INTENT,    COAVOID_CHANNEL_PLAN,
                                        COAVOID_CHANNEL_TRACK,     COAVOID_CHANNEL_OBSTACLES,
                                        COAVOID_CHANNEL_CONFLICTS, COAVOID_CHANNEL_STATUS,
                                        COAVOID_CHANNEL_AGREEMENT};
    for (size_t i = 0; channel != NULL && i < sizeof fleet / sizeof fleet[0]; i++) {
        if (strcmp(channel, fleet[i]) == 0) {
            return true;
        }
    }
    return false;
}

bool coavoid_rt_rx_is_udpm(const char *url)
{
    return url != NULL && strncmp(url, "udpm://", 7) == 0;
}

/* The group, the port and the requested receive buffer (0: the kernel's) of a udpm URL:
 * udpm://A.B.C.D[:PORT][?key=value&...]. Keys other than recv_buf_size are the
 * publisher's (ttl) and are left to LCM. 0, or -1 with err set. */
static int parse_url(const char *url, struct in_addr *group, unsigned *port, int *rcvbuf, char *err,
                     size_t err_size)
{
    char host[64];
    const char *p = url + 7;
    size_t n = strcspn(p, ":?");
    if (n == 0 || n >= sizeof host) {
        snprintf(err, err_size, "%s: no multicast group in the URL", url);
        return -1;
    }
    memcpy(host, p, n);
    host[n] = '\0';
    if (inet_pton(AF_INET, host, group) != 1 || (ntohl(group->s_addr) >> 28) != 14u) {
        snprintf(err, err_size, "%s: '%s' is not an IPv4 multicast group", url, host);
        return -1;
    }
    p += n;
    *port = RX_DEFAULT_PORT;
    if (*p == ':') {
        char *after = NULL;
        unsigned long v = strtoul(p + 1, &after, 10);
        if (after == p + 1 || v == 0 || v > 65535 || (*after != '\0' && *after != '?')) {
            snprintf(err, err_size, "%s: the port is not 1..65535", url);
            return -1;
        }
        *port = (unsigned)v;
        p = after;
    }
    *rcvbuf = 0;
    const char *key = strstr(p, "recv_buf_size=");
    if (key != NULL) {
        long v = strtol(key + 14, NULL, 10);
        *rcvbuf = v > 0 && v <= (1L << 30) ? (int)v : 0;
    }
    return 0;
}

/* A non-blocking socket bound to the port and joined to the group, its drops counted. */
static int open_socket(const struct in_addr *group, unsigned port, int rcvbuf, char *err,
                       size_t err_size)
{
    int fd = socket(AF_INET, SOCK_DGRAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0);
    if (fd < 0) {
        snprintf(err, err_size, "cannot open a UDP socket: %s", strerror(errno));
        return -1;
    }
    const int on = 1;
    struct sockaddr_in addr;
    memset(&addr, 0, sizeof addr);
    addr.sin_family = AF_INET;
    addr.sin_addr.s_addr = htonl(INADDR_ANY);
    addr.sin_port = htons((uint16_t)port);
    struct ip_mreq join;
    join.imr_multiaddr = *group;
    join.imr_interface.s_addr = htonl(INADDR_ANY);
    const char *step = NULL;
    if (setsockopt(fd, SOL_SOCKET, SO_REUSEADDR, &on, sizeof on) != 0) {
        step = "SO_REUSEADDR";
    } else if (setsockopt(fd, SOL_SOCKET, SO_RXQ_OVFL, &on, sizeof on) != 0) {
        step = "SO_RXQ_OVFL";
    } else if (rcvbuf > 0 && setsockopt(fd, SOL_SOCKET, SO_RCVBUF, &rcvbuf, sizeof rcvbuf) != 0) {
        step = "SO_RCVBUF";
    } else if (bind(fd, (const struct sockaddr *)&addr, sizeof addr) != 0) {
        step = "bind";
    } else if (setsockopt(fd, IPPROTO_IP, IP_ADD_MEMBERSHIP, &join, sizeof join) != 0) {
        step = "joining the group (is there a multicast route?)";
    }
    if (step != NULL) {
        snprintf(err, err_size, "receiving on port %u: %s: %s", port, step, strerror(errno));
        close(fd);
        return -1;
    }
    return fd;
}

/* Points each of the batch's headers at its buffers, once: recvmmsg reads them and
 * writes only each header's lengths and flags. */
static void batch_init(coavoid_rt_rx_t *rx)
{
    for (unsigned i = 0; i < COAVOID_RT_RX_BATCH; i++) {
        rx->iov[i].iov_base = rx->data[i];
        rx->iov[i].iov_len = COAVOID_RT_RX_DATAGRAM;
        rx->msgs[i].msg_hdr.msg_iov = &rx->iov[i];
        rx->msgs[i].msg_hdr.msg_iovlen = 1;
        rx->msgs[i].msg_hdr.msg_control = rx->control[i];
    }
}

coavoid_rt_rx_t *coavoid_rt_rx_open(const char *url, char *err, size_t err_size)
{
    struct in_addr group;
    unsigned port = 0;
    int rcvbuf = 0;
    if (!coavoid_rt_rx_is_udpm(url)) {
        snprintf(err, err_size, "%s: not a udpm:// URL", url != NULL ? url : "(none)");
        return NULL;
    }
    if (parse_url(url, &group, &port, &rcvbuf, err, err_size) != 0) {
        return NULL;
    }
    coavoid_rt_rx_t *rx = calloc(1, sizeof *rx);
    if (rx == NULL) {
        snprintf(err, err_size, "out of memory for the receiver");
        return NULL;
    }
    rx->fd = open_socket(&group, port, rcvbuf, err, err_size);
    rx->deliver = rx->fd >= 0 ? lcm_create("memq://") : NULL;
    if (rx->deliver == NULL) {
        if (rx->fd >= 0) {
            snprintf(err, err_size, "cannot create LCM's in-process provider (memq://)");
            close(rx->fd);
        }
        free(rx);
        return NULL;
    }
    batch_init(rx);
    return rx;
}

void coavoid_rt_rx_close(coavoid_rt_rx_t *rx)
{
    if (rx == NULL) {
        return;
    }
    lcm_destroy(rx->deliver);
    close(rx->fd);
    free(rx);
}

int coavoid_rt_rx_fd(const coavoid_rt_rx_t *rx)
{
    return rx->fd;
}

lcm_t *coavoid_rt_rx_lcm(const coavoid_rt_rx_t *rx)
{
    return rx->deliver;
}

const coavoid_rt_rx_stats_t *coavoid_rt_rx_stats(const coavoid_rt_rx_t *rx)
{
    return &rx->stats;
}

bool coavoid_rt_rx_pending(const coavoid_rt_rx_t *rx)
{
    return rx->next < rx->count;
}

/* The socket's drop counter in the control messages of msg, if it carries one. */
static void note_overflow(coavoid_rt_rx_t *rx, struct msghdr *msg)
{
    for (struct cmsghdr *c = CMSG_FIRSTHDR(msg); c != NULL; c = CMSG_NXTHDR(msg, c)) {
        if (c->cmsg_level == SOL_SOCKET && c->cmsg_type == SO_RXQ_OVFL &&
            c->cmsg_len >= CMSG_LEN(sizeof(uint32_t))) {
            uint32_t dropped;
            memcpy(&dropped, CMSG_DATA(c), sizeof dropped);
            rx->stats.kernel_dropped += (uint32_t)(dropped - rx->overflow_seen);
            rx->overflow_seen = dropped;
        }
    }
}

/* Reads the next batch: how many, 0 when none is waiting, COAVOID_RT_ERR_LCM on failure. */
static int read_batch(coavoid_rt_rx_t *rx)
{
    for (unsigned i = 0; i < COAVOID_RT_RX_BATCH; i++) {
        rx->msgs[i].msg_hdr.msg_controllen = RX_CONTROL_BYTES; /* the last read shrank it */
    }
    rx->count = rx->next = 0;
    int n = recvmmsg(rx->fd, rx->msgs, COAVOID_RT_RX_BATCH, MSG_DONTWAIT, NULL);
    if (n < 0) {
        return errno == EAGAIN || errno == EWOULDBLOCK || errno == EINTR ? 0 : COAVOID_RT_ERR_LCM;
    }
    for (int i = 0; i < n; i++) {
        note_overflow(rx, &rx->msgs[i].msg_hdr);
    }
    rx->count = (unsigned)n;
    rx->stats.datagrams += (uint64_t)n;
    return n;
}

int coavoid_rt_rx_deliver(coavoid_rt_rx_t *rx)
{
    if (rx->next == rx->count) {
        int n = read_batch(rx);
        if (n <= 0) {
            return n;
        }
    }
    const struct mmsghdr *m = &rx->msgs[rx->next];
    const unsigned char *data = rx->data[rx->next];
    rx->next++;
    if (m->msg_hdr.msg_flags & MSG_TRUNC) {
        rx->stats.oversize++;
        return 1;
    }
    coavoid_rt_rx_frame_t frame;
    int rc = coavoid_rt_rx_parse(data, m->msg_len, &frame);
    if (rc != COA_OK) {
        rx->stats.fragments += rc == COAVOID_RT_RX_FRAGMENT;
        rx->stats.malformed += rc != COAVOID_RT_RX_FRAGMENT;
        return 1;
    }
    if (!coavoid_rt_rx_fleet_channel(frame.channel)) {
        rx->stats.foreign++;
        return 1;
    }
    /* memq copies the message and queues it, or drops it when no node subscribes to its
     * channel; handling it at once keeps memq's queue at one message at most. */
    if (lcm_publish(rx->deliver, frame.channel, frame.payload, (unsigned)frame.payload_size) != 0) {
        return COAVOID_RT_ERR_LCM;
    }
    const int handled = lcm_handle_timeout(rx->deliver, 0);
    if (handled < 0) {
        return COAVOID_RT_ERR_LCM;
    }
    rx->stats.delivered += handled > 0;
    return 1;
}
