/* SPDX-License-Identifier: MIT */
/*
 * flood.c: a flooder on the multicast group, for the flights of scripts/lossy.sh --flood
 * (docs/security.md, "Floods"). It listens to the group and keeps the latest datagram of
 * each (channel, key id) it hears, and sends them back, round robin, at --rate datagrams a
 * second:
 *
 *   heard   each copy as heard, a signature byte flipped: stamps as heard, so a receiver
 *           that accepted the original refuses it from its tail (a replay);
 *   fresh   the same with the stamp moved ahead of the original (its timestamp one
 *           microsecond later per copy sent of it): only the fleet tag or, without a
 *           fleet key, the signature check can refuse it;
 *   signed  each copy stamped afresh and signed with a stolen vehicle key (--key, with its
 *           trust file --trust for the fleet key): valid signatures and tags, so every
 *           copy on a channel that key may use costs a receiver a signature check.
 *
 * It sends from a socket of its own with multicast loopback off, in LCM's short-message
 * framing ("LC02", a sequence number, the channel, the datagram): what it sends reaches
 * the other hosts on the link, not its own listener. It stops on SIGINT or SIGTERM, or
 * after --seconds, and prints how many it sent, at what rate from its first send, and how
 * many datagrams it heard.
 *
 * usage: coavoid_test_flood --lcm-url udpm://GROUP:PORT[?...] --mode heard|fresh|signed
 *                           --rate N [--seconds S] [--key FILE --trust FILE]
 */
#define _GNU_SOURCE

#include <arpa/inet.h>
#include <errno.h>
#include <netinet/in.h>
#include <signal.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <time.h>
#include <unistd.h>

#include <lcm/lcm.h>

#include "auth.h"

#define FLOOD_SLOTS 128
#define FLOOD_BYTES 1500
#define FLOOD_BATCH 64
#define FLOOD_HEADER 40 /* "LC02", a sequence number and a channel name of up to 31 bytes */

typedef struct {
    char channel[32];
    uint32_t key_id;
    size_t size;
    int64_t timestamp; /* the heard stamp */
    int64_t sent;      /* copies sent of this one */
    unsigned char bytes[FLOOD_BYTES];
} slot_t;

typedef struct {
    int mode; /* 0 heard, 1 fresh, 2 signed */
    slot_t slots[FLOOD_SLOTS];
    size_t used, next;
    int64_t heard, sent;
    int64_t first_send; /* us, monotonic; 0 before the first */
    uint32_t sequence;
    coavoid_auth_signer_t signer;
    int sock;
} flooder_t;

static volatile sig_atomic_t stop = 0;

static void on_signal(int sig)
{
    stop = sig;
}

static int64_t mono_us(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (int64_t)ts.tv_sec * 1000000 + ts.tv_nsec / 1000;
}

static uint64_t get_be(const unsigned char *p, size_t n)
{
    uint64_t v = 0;
    for (size_t i = 0; i < n; i++) {
        v = v << 8 | p[i];
    }
    return v;
}

static void put_be(unsigned char *p, uint64_t v, size_t n)
{
    for (size_t i = 0; i < n; i++) {
        p[i] = (unsigned char)(v >> (8u * (n - 1u - i)));
    }
}

/* Keeps a datagram heard: the latest of its (channel, key id). */
static void on_any(const lcm_recv_buf_t *rbuf, const char *channel, void *user)
{
    flooder_t *f = user;
    const size_t n = rbuf->data_size;
    if (n < COAVOID_AUTH_TAIL_BYTES + 8u || n > FLOOD_BYTES || strlen(channel) >= 32u) {
        return;
    }
    const unsigned char *tail = (const unsigned char *)rbuf->data + n - COAVOID_AUTH_TAIL_BYTES;
    const uint32_t key_id = (uint32_t)get_be(tail, 4u);
    size_t i = 0;
    while (i < f->used && (f->slots[i].key_id != key_id || strcmp(f->slots[i].channel, channel))) {
        i++;
    }
    if (i == f->used) {
        if (f->used == FLOOD_SLOTS) {
            return;
        }
        f->used++;
    }
    slot_t *s = &f->slots[i];
    strcpy(s->channel, channel);
    s->key_id = key_id;
    s->size = n;
    s->timestamp = (int64_t)get_be(tail + 4u, 8u);
    s->sent = 0;
    memcpy(s->bytes, rbuf->data, n);
    f->heard++;
}

/* The next copy into out (LCM's framing included); its length, or 0. */
static size_t next_copy(flooder_t *f, unsigned char *out)
{
    if (f->used == 0) {
        return 0;
    }
    slot_t *s = &f->slots[f->next++ % f->used];
    const size_t name = strlen(s->channel) + 1u;
    put_be(out, 0x4c433032u, 4u);
    put_be(out + 4, f->sequence++, 4u);
    memcpy(out + 8, s->channel, name);
    unsigned char *d = out + 8 + name;
    memcpy(d, s->bytes, s->size);
    unsigned char *tail = d + s->size - COAVOID_AUTH_TAIL_BYTES;
    s->sent++;
    if (f->mode == 2) {
        put_be(tail, f->signer.key_id, 4u);
        if (coavoid_auth_stamp(&f->signer, s->timestamp + s->sent, d, s->size) != 0) {
            return 0;
        }
    } else {
        if (f->mode == 1) {
            put_be(tail + 4u, (uint64_t)(s->timestamp + s->sent), 8u);
        }
        tail[COAVOID_AUTH_TAIL_BYTES - COAVOID_AUTH_TAG_BYTES - 1u] ^= 0x5a;
    }
    return 8 + name + s->size;
}

/* Sends n copies in batches. */
static void send_copies(flooder_t *f, int64_t n)
{
    static unsigned char bufs[FLOOD_BATCH][FLOOD_BYTES + FLOOD_HEADER];
    struct mmsghdr msgs[FLOOD_BATCH];
    struct iovec iov[FLOOD_BATCH];
    while (n > 0) {
        unsigned batch = 0;
        while (batch < FLOOD_BATCH && (int64_t)batch < n) {
            const size_t len = next_copy(f, bufs[batch]);
            if (len == 0) {
                return;
            }
            iov[batch].iov_base = bufs[batch];
            iov[batch].iov_len = len;
            memset(&msgs[batch], 0, sizeof msgs[batch]);
            msgs[batch].msg_hdr.msg_iov = &iov[batch];
            msgs[batch].msg_hdr.msg_iovlen = 1;
            batch++;
        }
        if (f->first_send == 0) {
            f->first_send = mono_us();
        }
        const int sent = sendmmsg(f->sock, msgs, batch, 0);
        if (sent <= 0) {
            return;
        }
        f->sent += sent;
        n -= sent;
    }
}

/* A UDP socket connected to the URL's group and port, loopback off. -1 on failure. */
static int open_sender(const char *url)
{
    unsigned a, b, c, d, port;
    if (sscanf(url, "udpm://%u.%u.%u.%u:%u", &a, &b, &c, &d, &port) != 5) {
        return -1;
    }
    struct sockaddr_in to;
    memset(&to, 0, sizeof to);
    to.sin_family = AF_INET;
    to.sin_port = htons((uint16_t)port);
    to.sin_addr.s_addr = htonl(a << 24 | b << 16 | c << 8 | d);
    int s = socket(AF_INET, SOCK_DGRAM, 0);
    unsigned char off = 0, ttl = 1;
    if (s < 0 || setsockopt(s, IPPROTO_IP, IP_MULTICAST_LOOP, &off, sizeof off) != 0 ||
        setsockopt(s, IPPROTO_IP, IP_MULTICAST_TTL, &ttl, sizeof ttl) != 0 ||
        connect(s, (struct sockaddr *)&to, sizeof to) != 0) {
        if (s >= 0) {
            close(s);
        }
        return -1;
    }
    return s;
}

static int read_file(const char *path, char *text, size_t cap, size_t *n)
{
    FILE *in = fopen(path, "r");
    if (in == NULL) {
        return -1;
    }
    *n = fread(text, 1, cap, in);
    fclose(in);
    return 0;
}

/* The stolen key and its trust file's fleet key into f->signer; 0 or -1. */
static int read_keys(flooder_t *f, const char *key, const char *trust_path)
{
    static char text[65536];
    static coavoid_auth_trust_t trust;
    char err[128] = "cannot read";
    size_t n = 0;
    if (read_file(key, text, sizeof text, &n) != 0 ||
        coavoid_auth_signer_parse(&f->signer, text, n, err, sizeof err) != 0 ||
        read_file(trust_path, text, sizeof text, &n) != 0 ||
        coavoid_auth_trust_parse(&trust, text, n, err, sizeof err) != 0) {
        fprintf(stderr, "flood: --key/--trust: %s\n", err);
        return -1;
    }
    coavoid_auth_signer_use_fleet(&f->signer, &trust);
    return 0;
}

typedef struct {
    const char *url, *key, *trust;
    double rate, seconds;
} options_t;

static int parse(int argc, char **argv, flooder_t *f, options_t *o)
{
    const char *mode = NULL;
    for (int i = 1; i + 1 < argc; i += 2) {
        const char *k = argv[i], *v = argv[i + 1];
        if (strcmp(k, "--lcm-url") == 0) {
            o->url = v;
        } else if (strcmp(k, "--mode") == 0) {
            mode = v;
        } else if (strcmp(k, "--rate") == 0) {
            o->rate = atof(v);
        } else if (strcmp(k, "--seconds") == 0) {
            o->seconds = atof(v);
        } else if (strcmp(k, "--key") == 0) {
            o->key = v;
        } else if (strcmp(k, "--trust") == 0) {
            o->trust = v;
        } else {
            return -1;
        }
    }
    static const char *const modes[3] = {"heard", "fresh", "signed"};
    f->mode = -1;
    for (int m = 0; mode != NULL && m < 3; m++) {
        f->mode = strcmp(mode, modes[m]) == 0 ? m : f->mode;
    }
    if (argc % 2 == 0 || o->url == NULL || f->mode < 0 || o->rate <= 0 || o->seconds <= 0 ||
        (f->mode == 2) != (o->key != NULL && o->trust != NULL)) {
        return -1;
    }
    return f->mode == 2 ? read_keys(f, o->key, o->trust) : 0;
}

int main(int argc, char **argv)
{
    static flooder_t f;
    options_t o = {NULL, NULL, NULL, 0, 1e9};
    if (parse(argc, argv, &f, &o) != 0) {
        fprintf(stderr, "usage: coavoid_test_flood --lcm-url udpm://GROUP:PORT --mode "
                        "heard|fresh|signed --rate N [--seconds S] [--key FILE --trust FILE]\n");
        return 2;
    }
    signal(SIGINT, on_signal);
    signal(SIGTERM, on_signal);
    lcm_t *lcm = lcm_create(o.url);
    f.sock = open_sender(o.url);
    if (lcm == NULL || f.sock < 0) {
        fprintf(stderr, "flood: cannot open %s\n", o.url);
        return 2;
    }
    lcm_subscription_t *sub = lcm_subscribe(lcm, "COAVOID_.*", on_any, &f);
    const int64_t start = mono_us(), end = start + (int64_t)(o.seconds * 1e6);
    double owed = 0;
    int64_t last = start;
    while (!stop && mono_us() < end) {
        while (lcm_handle_timeout(lcm, 0) > 0) {
        }
        const int64_t now = mono_us();
        owed += (double)(now - last) * o.rate / 1e6;
        last = now;
        if (owed >= 1.0) {
            send_copies(&f, (int64_t)owed);
            owed -= (double)(int64_t)owed;
        }
        usleep(500);
    }
    /* The rate counts from the first send: before the fleet speaks there is nothing to copy. */
    const double seconds = f.first_send > 0 ? (double)(mono_us() - f.first_send) / 1e6 : 0.0;
    printf("flood: sent %lld in %.1f s (%.0f a second), heard %lld\n", (long long)f.sent, seconds,
           f.sent > 0 && seconds > 0 ? (double)f.sent / seconds : 0.0, (long long)f.heard);
    lcm_unsubscribe(lcm, sub);
    lcm_destroy(lcm);
    close(f.sock);
    coavoid_auth_signer_clear(&f.signer);
    return 0;
}
