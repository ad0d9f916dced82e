/* SPDX-License-Identifier: MIT */
/* A vehicle behind a serial link, joined to the LCM group (bridge.h). */
#define _DEFAULT_SOURCE

#include "bridge.h"

#include <errno.h>
#include <fcntl.h>
#include <poll.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/un.h>
#include <termios.h>
#include <unistd.h>

#include "session.h"

/* The longest a wait lasts before the loop looks at the stop flag again. */
#define BRIDGE_MAX_WAIT_MS 100
/* Datagrams taken off the receiver between two looks at the link. */
#define BRIDGE_MAX_DRAIN 64
/* The vehicle's last datagrams, kept to know them when the group loops them back. */
#define BRIDGE_SENT_KEPT 32u

typedef struct {
    char channel[COAVOID_REPLAY_MAX_CHANNEL + 1u];
    size_t size;
    uint8_t data[COAVOID_RT_RX_DATAGRAM];
} bridge_datagram_t;

/* Datagrams waiting for the link, a ring. */
typedef struct {
    bridge_datagram_t *items;
    size_t capacity;
    size_t head, count;
} bridge_queue_t;

/* What the run keeps: the queues, the link's receiver, the frame on its way out. The
 * agreement's messages (plans, agreements, heartbeats) have their own queue, which goes
 * first: they have deadlines within the cycle (a plan is accepted within a quarter of it),
 * while intents, maps and tracks come with copies and are good for the cycle; and the link
 * is the slowest part of the path. The group promises no order between senders either. */
typedef struct {
    const coavoid_rt_bridge_t *b;
    coavoid_rt_bridge_result_t *result;
    bridge_queue_t urgent;   /* COAVOID_RT_BRIDGE_URGENT plans, agreements, heartbeats */
    bridge_queue_t bulk;     /* COAVOID_RT_BRIDGE_QUEUE intents, maps, tracks */
    bridge_datagram_t *sent; /* BRIDGE_SENT_KEPT of them, a ring */
    size_t sent_next;
    lcm_subscription_t *subs[COAVOID_NODE_CHANNELS];
    char sub_channels[COAVOID_NODE_CHANNELS][COAVOID_REPLAY_MAX_CHANNEL + 1u];
    size_t sub_count;
    coavoid_link_rx_t link;
    uint8_t link_buffer[COAVOID_SESSION_MAX_RECORD + COAVOID_LINK_CRC_BYTES];
    uint8_t out[COAVOID_LINK_FRAMED_MAX(COAVOID_SESSION_MAX_RECORD)];
    size_t out_length;
    bool failed;        /* the link failed */
    bool in_flight;     /* a frame waits for its READY */
    bool config_flight; /* ... and it is the CONFIG */
    int64_t sent_wall;  /* when it left */
    int64_t wake;       /* the scenario time the vehicle asked for, INT64_MAX none */
} bridge_run_t;

static speed_t baud_constant(long baud)
{
    static const struct {
        long baud;
        speed_t constant;
    } rates[] = {{9600, B9600},       {19200, B19200},     {38400, B38400},     {57600, B57600},
                 {115200, B115200},   {230400, B230400},   {460800, B460800},   {500000, B500000},
                 {921600, B921600},   {1000000, B1000000}, {1500000, B1500000}, {2000000, B2000000},
                 {3000000, B3000000}, {4000000, B4000000}};
    for (size_t i = 0; i < sizeof rates / sizeof rates[0]; i++) {
        if (rates[i].baud == baud) {
            return rates[i].constant;
        }
    }
    return B0;
}

/* A tty made raw, 8N1, with RTS/CTS, at baud. */
static int open_tty(const char *path, long baud, char *err, size_t err_size)
{
    const speed_t speed = baud_constant(baud);
    if (speed == B0) {
        snprintf(err, err_size, "%ld baud is not a rate a serial device takes", baud);
        return -1;
    }
    int fd = open(path, O_RDWR | O_NOCTTY | O_NONBLOCK | O_CLOEXEC);
    struct termios t;
    if (fd < 0 || tcgetattr(fd, &t) != 0) {
        snprintf(err, err_size, "%s: %s", path, strerror(errno));
        if (fd >= 0) {
            close(fd);
        }
        return -1;
    }
    cfmakeraw(&t);
    t.c_cflag |= CLOCAL | CREAD | CRTSCTS;
    if (cfsetispeed(&t, speed) != 0 || cfsetospeed(&t, speed) != 0 ||
        tcsetattr(fd, TCSANOW, &t) != 0) {
        snprintf(err, err_size, "%s: cannot set %ld baud, raw, RTS/CTS: %s", path, baud,
                 strerror(errno));
        close(fd);
        return -1;
    }
    return fd;
}

static int open_socket(const char *path, char *err, size_t err_size)
{
    struct sockaddr_un a;
    memset(&a, 0, sizeof a);
    a.sun_family = AF_UNIX;
    if (strlen(path) >= sizeof a.sun_path) {
        snprintf(err, err_size, "%.60s...: a socket's path is at most %zu characters", path,
                 sizeof a.sun_path - 1u);
        return -1;
    }
    memcpy(a.sun_path, path, strlen(path) + 1u);
    int fd = socket(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0);
    if (fd < 0 || connect(fd, (const struct sockaddr *)&a, sizeof a) != 0 ||
        fcntl(fd, F_SETFL, O_NONBLOCK) != 0) {
        snprintf(err, err_size, "%s: cannot connect: %s", path, strerror(errno));
        if (fd >= 0) {
            close(fd);
        }
        return -1;
    }
    return fd;
}

int coavoid_rt_link_open(const char *path, long baud, char *err, size_t err_size)
{
    struct stat st;
    if (path == NULL || stat(path, &st) != 0) {
        snprintf(err, err_size, "%s: %s", path != NULL ? path : "(none)",
                 path != NULL ? strerror(errno) : "no path");
        return -1;
    }
    if (S_ISSOCK(st.st_mode)) {
        return open_socket(path, err, err_size);
    }
    if (S_ISCHR(st.st_mode)) {
        return open_tty(path, baud, err, err_size);
    }
    snprintf(err, err_size, "%s: neither a serial device nor a socket", path);
    return -1;
}

/* All of data onto the link, waiting while it is full; false when it failed. */
static bool link_write(bridge_run_t *r, const uint8_t *data, size_t n)
{
    while (n > 0u) {
        const ssize_t w = write(r->b->fd, data, n);
        if (w > 0) {
            data += w;
            n -= (size_t)w;
            continue;
        }
        if (w < 0 && errno == EINTR) {
            continue;
        }
        struct pollfd p = {r->b->fd, POLLOUT, 0};
        if (w < 0 && errno == EAGAIN && poll(&p, 1, 1000) > 0) {
            continue;
        }
        r->failed = true;
        return false;
    }
    return true;
}

static void out_put(void *user, uint8_t byte)
{
    bridge_run_t *r = user;
    if (r->out_length < sizeof r->out) {
        r->out[r->out_length++] = byte;
    }
}

/* A frame to the vehicle, stamped `time`; it then waits for its READY. */
static void send_frame(bridge_run_t *r, coavoid_replay_kind_t kind, int64_t time,
                       const char *channel, const uint8_t *payload, size_t length)
{
    r->out_length = 0;
    coavoid_session_put_record(kind, time, channel, channel != NULL ? strlen(channel) : 0u, payload,
                               length, out_put, r);
    if (link_write(r, r->out, r->out_length)) {
        r->result->frames_sent++;
        r->in_flight = true;
        r->config_flight = kind == COAVOID_REPLAY_CONFIG;
        r->sent_wall = coavoid_rt_wall_utime();
    }
}

static int64_t scenario_now(const bridge_run_t *r)
{
    return coavoid_rt_scenario_utime(&r->b->clock, coavoid_rt_wall_utime());
}

/* Whether the datagram is one the vehicle sent, byte for byte: the vehicle drops its own
 * looped back unread (the inbox), so the link need not carry it. */
static bool own_echo(const bridge_run_t *r, const char *channel, const void *data, size_t size)
{
    for (size_t i = 0; i < BRIDGE_SENT_KEPT; i++) {
        const bridge_datagram_t *d = &r->sent[i];
        if (d->size == size && strcmp(d->channel, channel) == 0 &&
            memcmp(d->data, data, size) == 0) {
            return true;
        }
    }
    return false;
}

/* A datagram on a channel the vehicle takes in: queued, or dropped when the queue is full. */
static void on_datagram(const lcm_recv_buf_t *rbuf, const char *channel, void *user)
{
    bridge_run_t *r = user;
    if (rbuf == NULL || rbuf->data == NULL || rbuf->data_size > COAVOID_RT_RX_DATAGRAM ||
        strlen(channel) > COAVOID_REPLAY_MAX_CHANNEL) {
        return;
    }
    if (own_echo(r, channel, rbuf->data, rbuf->data_size)) {
        r->result->echoes++;
        return;
    }
    const bool urgent = strcmp(channel, COAVOID_CHANNEL_PLAN) == 0 ||
                        strcmp(channel, COAVOID_CHANNEL_AGREEMENT) == 0 ||
                        strcmp(channel, COAVOID_CHANNEL_STATUS) == 0;
    bridge_queue_t *q = urgent ? &r->urgent : &r->bulk;
    if (q->count == q->capacity) {
        r->result->queue_dropped++;
        return;
    }
    bridge_datagram_t *d = &q->items[(q->head + q->count++) % q->capacity];
    const uint64_t waiting = r->urgent.count + r->bulk.count;
    r->result->queue_peak = waiting > r->result->queue_peak ? waiting : r->result->queue_peak;
    memcpy(d->channel, channel, strlen(channel) + 1u);
    memcpy(d->data, rbuf->data, rbuf->data_size);
    d->size = rbuf->data_size;
}

/* The vehicle asks for a channel: subscribed once. */
static void subscribe(bridge_run_t *r, const coavoid_replay_record_t *rec)
{
    char channel[COAVOID_REPLAY_MAX_CHANNEL + 1u];
    coavoid_replay_channel(rec, channel);
    if (!coavoid_rt_rx_fleet_channel(channel) || r->sub_count == COAVOID_NODE_CHANNELS) {
        return;
    }
    lcm_t *lcm = r->b->rx != NULL ? coavoid_rt_rx_lcm(r->b->rx) : r->b->lcm;
    for (size_t i = 0; i < r->sub_count; i++) {
        if (strcmp(r->sub_channels[i], channel) == 0) {
            return;
        }
    }
    lcm_subscription_t *sub = lcm_subscribe(lcm, channel, on_datagram, r);
    if (sub != NULL) {
        lcm_subscription_set_queue_capacity(sub, (int)COAVOID_RT_BRIDGE_QUEUE);
        memcpy(r->sub_channels[r->sub_count], channel, sizeof channel);
        r->subs[r->sub_count++] = sub;
    }
}

static void publish(bridge_run_t *r, const coavoid_replay_record_t *rec)
{
    char channel[COAVOID_REPLAY_MAX_CHANNEL + 1u];
    coavoid_replay_channel(rec, channel);
    if (coavoid_rt_rx_fleet_channel(channel) && rec->payload_length <= COAVOID_RT_RX_DATAGRAM &&
        lcm_publish(r->b->lcm, channel, rec->payload, (unsigned)rec->payload_length) == 0) {
        r->result->published++;
        bridge_datagram_t *d = &r->sent[r->sent_next++ % BRIDGE_SENT_KEPT];
        memcpy(d->channel, channel, sizeof channel);
        memcpy(d->data, rec->payload, rec->payload_length);
        d->size = rec->payload_length;
    } else {
        r->result->publish_failed++;
    }
}

/* The vehicle's READY: the frame in flight is answered. */
static void ready(bridge_run_t *r, const coavoid_replay_record_t *rec)
{
    int code = COA_OK;
    coavoid_vehicle_node_state_t state;
    if (coavoid_replay_read_state(rec->payload, rec->payload_length, &code, &state) != COA_OK) {
        return;
    }
    if (r->config_flight) {
        r->result->configured = code == COA_OK;
        r->result->refused_code = code;
    }
    r->result->frames_refused += code < 0 ? 1u : 0u;
    r->result->state = state;
    r->wake = rec->time;
    r->in_flight = false;
}

static void take_frame(bridge_run_t *r, size_t n)
{
    coavoid_replay_record_t rec;
    size_t used = 0;
    if (coavoid_replay_parse(r->link.buffer, n, &rec, &used) != COA_OK || used != n) {
        r->result->link_dropped++;
        return;
    }
    r->result->frames_received++;
    if (rec.kind == COAVOID_REPLAY_SENT) {
        publish(r, &rec);
    } else if (rec.kind == COAVOID_REPLAY_SUBSCRIBE) {
        subscribe(r, &rec);
    } else if (rec.kind == COAVOID_REPLAY_READY) {
        ready(r, &rec);
    }
}

/* Everything the link has for us now. */
static void read_link(bridge_run_t *r)
{
    uint8_t bytes[4096];
    for (;;) {
        const ssize_t n = read(r->b->fd, bytes, sizeof bytes);
        if (n == 0 || (n < 0 && errno != EAGAIN && errno != EINTR)) {
            r->failed = true; /* the other end closed, or the device went away */
            return;
        }
        if (n < 0) {
            return;
        }
        for (ssize_t i = 0; i < n; i++) {
            const size_t got = coavoid_link_rx_byte(&r->link, bytes[i]);
            if (got > 0u) {
                take_frame(r, got);
            }
        }
    }
}

/* The next frame, when the vehicle is free: a queued datagram, or the clock when due. */
static void feed(bridge_run_t *r)
{
    if (r->in_flight || !r->result->configured) {
        return;
    }
    const int64_t now = scenario_now(r);
    bridge_queue_t *q = r->urgent.count > 0u ? &r->urgent : &r->bulk;
    if (q->count > 0u) {
        const bridge_datagram_t *d = &q->items[q->head];
        send_frame(r, COAVOID_REPLAY_RECEIVE, now, d->channel, d->data, d->size);
        q->head = (q->head + 1u) % q->capacity;
        q->count--;
    } else if (now >= r->wake) {
        send_frame(r, COAVOID_REPLAY_TIME, now, NULL, NULL, 0u);
    }
}

/* A READY overdue: the CONFIG goes again, any other frame is given up. */
static void check_answer(bridge_run_t *r)
{
    const coavoid_rt_bridge_t *b = r->b;
    const int64_t timeout = b->answer_timeout_us > 0
                                ? b->answer_timeout_us
                                : (int64_t)((double)b->common->dt_us / b->clock.speed);
    if (!r->in_flight || coavoid_rt_wall_utime() - r->sent_wall < timeout) {
        return;
    }
    if (r->config_flight) {
        send_frame(r, COAVOID_REPLAY_CONFIG, scenario_now(r), NULL, b->config, b->config_size);
    } else {
        r->result->frames_given_up++;
        r->in_flight = false;
    }
}

/* How long to wait for the link or the group: until the vehicle's time, the answer
 * timeout or the stop check, whichever is first. */
static int wait_ms(const bridge_run_t *r)
{
    if (r->in_flight || !r->result->configured) {
        return 5;
    }
    if (r->urgent.count + r->bulk.count > 0u) {
        return 0;
    }
    const int64_t wall = coavoid_rt_wall_at(&r->b->clock, r->wake);
    const int64_t ms = (wall - coavoid_rt_wall_utime() + 999) / 1000;
    return ms < 0 ? 0 : ms > BRIDGE_MAX_WAIT_MS ? BRIDGE_MAX_WAIT_MS : (int)ms;
}

/* Datagrams off the group, queued; false when the receiver failed. */
static bool drain_group(bridge_run_t *r)
{
    for (int i = 0; i < BRIDGE_MAX_DRAIN; i++) {
        const int rc = coavoid_rt_deliver(r->b->lcm, r->b->rx);
        if (rc < 0) {
            return false;
        }
        if (rc == 0) {
            break;
        }
    }
    return true;
}

/* Whether the vehicle is through cycle K: started it and wants nothing more in it. */
static bool done(const bridge_run_t *r)
{
    const coavoid_node_common_t *c = r->b->common;
    return r->result->configured && !r->in_flight && r->urgent.count + r->bulk.count == 0u &&
           r->result->state.cycle >= r->b->steps &&
           r->wake >= coavoid_node_cycle_utime(c, r->b->steps + 1);
}

static int bridge_loop(bridge_run_t *r)
{
    const coavoid_rt_bridge_t *b = r->b;
    const int group_fd = b->rx != NULL ? coavoid_rt_rx_fd(b->rx) : lcm_get_fileno(b->lcm);
    send_frame(r, COAVOID_REPLAY_CONFIG, scenario_now(r), NULL, b->config, b->config_size);
    while (!r->failed && !done(r)) {
        r->result->loop.signal = coavoid_rt_stop_signal();
        if (r->result->loop.signal != 0) {
            break;
        }
        if (r->in_flight == false && r->config_flight && !r->result->configured) {
            return COAVOID_RT_ERR_REFUSED;
        }
        if (scenario_now(r) > coavoid_node_cycle_utime(b->common, b->steps + 2)) {
            return COAVOID_RT_ERR_LATE;
        }
        feed(r);
        struct pollfd fds[2] = {{b->fd, POLLIN, 0}, {group_fd, POLLIN, 0}};
        const bool pending = b->rx != NULL && coavoid_rt_rx_pending(b->rx);
        if (poll(fds, 2, pending ? 0 : wait_ms(r)) < 0 && errno != EINTR) {
            return COAVOID_RT_ERR_LCM;
        }
        read_link(r);
        if ((pending || (fds[1].revents & POLLIN) != 0) && !drain_group(r)) {
            return COAVOID_RT_ERR_LCM;
        }
        check_answer(r);
    }
    return r->failed ? COAVOID_RT_ERR_LCM : COA_OK;
}

int coavoid_rt_bridge_run(const coavoid_rt_bridge_t *b, coavoid_rt_bridge_result_t *result)
{
    if (result != NULL) {
        memset(result, 0, sizeof *result);
    }
    if (b == NULL || result == NULL || b->lcm == NULL || b->common == NULL || b->fd < 0 ||
        b->config == NULL || b->config_size == 0u || b->steps < 1 || b->clock.speed <= 0) {
        return COA_ERR_ARGUMENT;
    }
    bridge_run_t *r = calloc(1, sizeof *r);
    bridge_datagram_t *queue = calloc(
        COAVOID_RT_BRIDGE_QUEUE + COAVOID_RT_BRIDGE_URGENT + BRIDGE_SENT_KEPT, sizeof *queue);
    if (r == NULL || queue == NULL) {
        free(r);
        free(queue);
        return COA_ERR_WORKSPACE;
    }
    r->b = b;
    r->result = result;
    r->bulk.items = queue;
    r->bulk.capacity = COAVOID_RT_BRIDGE_QUEUE;
    r->urgent.items = queue + COAVOID_RT_BRIDGE_QUEUE;
    r->urgent.capacity = COAVOID_RT_BRIDGE_URGENT;
    r->sent = r->urgent.items + COAVOID_RT_BRIDGE_URGENT;
    r->wake = INT64_MAX;
    coavoid_link_rx_init(&r->link, r->link_buffer, sizeof r->link_buffer);
    const int rc = bridge_loop(r);
    result->link_dropped += r->link.dropped;
    result->loop.cycles = result->state.cycle + 1;
    if (b->rx != NULL) {
        result->loop.received = true;
        result->loop.rx = *coavoid_rt_rx_stats(b->rx);
    }
    lcm_t *lcm = b->rx != NULL ? coavoid_rt_rx_lcm(b->rx) : b->lcm;
    for (size_t i = 0; i < r->sub_count; i++) {
        lcm_unsubscribe(lcm, r->subs[i]);
    }
    free(queue);
    free(r);
    return rc;
}
