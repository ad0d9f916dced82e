/* SPDX-License-Identifier: MIT */
/*
 * test_rx.c: the drivers' receiver of LCM's UDP multicast (src/realtime/rx.c). LCM's
 * short-message framing parsed exactly, and refused when malformed or a fragment, never
 * read beyond the datagram; then on a real socket, on a group and port of the test's own
 * with multicast loopback: datagrams delivered to a subscriber of the receiver's LCM in
 * the order sent, the others counted by kind, those of channels not the fleet's never
 * handed to LCM; the socket's drops counted when it is not
 * read in time, every datagram sent either read or dropped; a bad URL refused with one
 * line.
 */
#define _GNU_SOURCE

#include <arpa/inet.h>
#include <netinet/in.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <unistd.h>

#include <lcm/lcm.h>

#include "realtime.h"
#include "test_support.h"

/* "LC02", sequence, channel, NUL, payload into out; its size. */
static size_t frame(unsigned char *out, uint32_t magic, uint32_t sequence, const char *channel,
                    const void *payload, size_t size)
{
    const uint32_t head[2] = {htonl(magic), htonl(sequence)};
    memcpy(out, head, sizeof head);
    const size_t name = strlen(channel) + 1u;
    memcpy(out + 8, channel, name);
    memcpy(out + 8 + name, payload, size);
    return 8u + name + size;
}

START_TEST(parse_reads_a_short_message)
{
    unsigned char d[128];
    const size_t n = frame(d, 0x4c433032u, 77u, "COAVOID_INTENT", "abc", 3u);
    coavoid_rt_rx_frame_t f;
    ck_assert_int_eq(coavoid_rt_rx_parse(d, n, &f), COA_OK);
    ck_assert_uint_eq(f.sequence, 77u);
    ck_assert_str_eq(f.channel, "COAVOID_INTENT");
    ck_assert_uint_eq(f.payload_size, 3u);
    ck_assert_int_eq(memcmp(f.payload, "abc", 3u), 0);
    /* An empty message is still a message. */
    const size_t e = frame(d, 0x4c433032u, 1u, "X", "", 0u);
    ck_assert_int_eq(coavoid_rt_rx_parse(d, e, &f), COA_OK);
    ck_assert_uint_eq(f.payload_size, 0u);
}
END_TEST

START_TEST(parse_refuses_what_is_not_one)
{
    unsigned char d[256];
    coavoid_rt_rx_frame_t f;
    size_t n = frame(d, 0x4c433033u, 1u, "COAVOID_PLAN", "x", 1u);
    ck_assert_int_eq(coavoid_rt_rx_parse(d, n, &f), COAVOID_RT_RX_FRAGMENT);
    n = frame(d, 0x4c433031u, 1u, "COAVOID_PLAN", "x", 1u);
    ck_assert_int_eq(coavoid_rt_rx_parse(d, n, &f), COAVOID_RT_RX_MALFORMED);
    ck_assert_int_eq(coavoid_rt_rx_parse(d, 7u, &f), COAVOID_RT_RX_MALFORMED);
    /* No NUL within the datagram: the name's end is never looked for beyond it. */
    n = frame(d, 0x4c433032u, 1u, "COAVOID_PLAN", "", 0u);
    ck_assert_int_eq(coavoid_rt_rx_parse(d, n - 1u, &f), COAVOID_RT_RX_MALFORMED);
    /* An empty channel name. */
    n = frame(d, 0x4c433032u, 1u, "", "x", 1u);
    ck_assert_int_eq(coavoid_rt_rx_parse(d, n, &f), COAVOID_RT_RX_MALFORMED);
    ck_assert_int_eq(coavoid_rt_rx_parse(NULL, 9u, &f), COA_ERR_ARGUMENT);
    ck_assert_int_eq(coavoid_rt_rx_parse(d, n, NULL), COA_ERR_ARGUMENT);
}
END_TEST

START_TEST(parse_takes_names_of_63_characters_not_64)
{
    unsigned char d[256];
    char name[65];
    coavoid_rt_rx_frame_t f;
    memset(name, 'C', 64u);
    name[64] = '\0';
    size_t n = frame(d, 0x4c433032u, 1u, name, "x", 1u);
    ck_assert_int_eq(coavoid_rt_rx_parse(d, n, &f), COAVOID_RT_RX_MALFORMED);
    name[63] = '\0';
    n = frame(d, 0x4c433032u, 1u, name, "x", 1u);
    ck_assert_int_eq(coavoid_rt_rx_parse(d, n, &f), COA_OK);
    ck_assert_uint_eq(strlen(f.channel), 63u);
}
END_TEST

/* Every size of every random datagram: the frame, when there is one, lies inside it. */
START_TEST(parse_stays_inside_random_datagrams)
{
    uint64_t seed = 34u;
    unsigned char d[96];
    for (int round = 0; round < 20000; round++) {
        for (size_t i = 0; i < sizeof d; i++) {
            d[i] = (unsigned char)splitmix(&seed);
        }
        if (round % 2 == 0) {
            const uint32_t magic = htonl(0x4c433032u);
            memcpy(d, &magic, 4u);
        }
        const size_t n = pick(&seed, (uint32_t)sizeof d + 1u);
        coavoid_rt_rx_frame_t f;
        if (coavoid_rt_rx_parse(d, n, &f) == COA_OK) {
            const unsigned char *c = (const unsigned char *)f.channel;
            REQUIRE(c == d + 8 && f.payload > c && f.payload + f.payload_size == d + n);
            REQUIRE(strlen(f.channel) >= 1u && strlen(f.channel) <= 63u);
        }
    }
}
END_TEST

/* A group and port of this test's own, so that other tests' traffic never reaches it. */
static unsigned test_port(void)
{
    return 20000u + (unsigned)getpid() % 20000u;
}

typedef struct {
    uint32_t seen[64];
    size_t count;
} ear_t;

static void on_message(const lcm_recv_buf_t *rbuf, const char *channel, void *user)
{
    (void)channel;
    ear_t *ear = user;
    uint32_t v = 0;
    REQUIRE(rbuf->data_size == sizeof v && ear->count < 64u);
    memcpy(&v, rbuf->data, sizeof v);
    ear->seen[ear->count++] = v;
}

/* A sender to the test's group with loopback on, so this process hears itself. */
static int open_sender(unsigned port)
{
    int s = socket(AF_INET, SOCK_DGRAM, 0);
    ck_assert_int_ge(s, 0);
    const unsigned char on = 1;
    ck_assert_int_eq(setsockopt(s, IPPROTO_IP, IP_MULTICAST_LOOP, &on, sizeof on), 0);
    struct sockaddr_in to;
    memset(&to, 0, sizeof to);
    to.sin_family = AF_INET;
    to.sin_port = htons((uint16_t)port);
    to.sin_addr.s_addr = inet_addr("239.255.76.99");
    ck_assert_int_eq(connect(s, (const struct sockaddr *)&to, sizeof to), 0);
    return s;
}

static coavoid_rt_rx_t *open_rx(unsigned port, const char *options)
{
    char url[128];
    char err[256] = "";
    snprintf(url, sizeof url, "udpm://239.255.76.99:%u?ttl=0%s", port, options);
    coavoid_rt_rx_t *rx = coavoid_rt_rx_open(url, err, sizeof err);
    ck_assert_msg(rx != NULL, "%s (the test needs a multicast route)", err);
    return rx;
}

static void deliver_all(coavoid_rt_rx_t *rx)
{
    for (int i = 0; i < 100000; i++) {
        const int rc = coavoid_rt_rx_deliver(rx);
        ck_assert_int_ge(rc, 0);
        if (rc == 0) {
            return;
        }
    }
    ck_abort_msg("the receiver never ran dry");
}

START_TEST(receiver_delivers_and_counts)
{
    const unsigned port = test_port();
    coavoid_rt_rx_t *rx = open_rx(port, "");
    ear_t ear = {{0}, 0};
    lcm_subscription_t *sub =
        lcm_subscribe(coavoid_rt_rx_lcm(rx), "COAVOID_STATUS", on_message, &ear);
    int s = open_sender(port);
    unsigned char d[4096];
    for (uint32_t v = 1; v <= 5u; v++) {
        ck_assert_int_gt(send(s, d, frame(d, 0x4c433032u, v, "COAVOID_STATUS", &v, sizeof v), 0),
                         0);
    }
    const uint32_t v = 9u;
    ck_assert_int_gt(send(s, d, frame(d, 0x4c433032u, 6u, "OTHER", &v, sizeof v), 0), 0);
    ck_assert_int_gt(send(s, d, frame(d, 0x4c433033u, 7u, "COAVOID_STATUS", &v, sizeof v), 0), 0);
    ck_assert_int_gt(send(s, d, 5u, 0), 0);
    static const unsigned char big[3000];
    ck_assert_int_gt(send(s, d, frame(d, 0x4c433032u, 8u, "COAVOID_STATUS", big, sizeof big), 0),
                     0);
    deliver_all(rx);
    const coavoid_rt_rx_stats_t *st = coavoid_rt_rx_stats(rx);
    ck_assert_uint_eq(ear.count, 5u);
    for (uint32_t i = 0; i < 5u; i++) {
        ck_assert_uint_eq(ear.seen[i], i + 1u);
    }
    ck_assert_uint_eq(st->datagrams, 9u);
    ck_assert_uint_eq(st->delivered, 5u);
    ck_assert_uint_eq(st->foreign, 1u); /* OTHER is not the fleet's */
    ck_assert_uint_eq(st->fragments, 1u);
    ck_assert_uint_eq(st->malformed, 1u);
    ck_assert_uint_eq(st->oversize, 1u);
    ck_assert_uint_eq(st->kernel_dropped, 0u);
    ck_assert(!coavoid_rt_rx_pending(rx));
    close(s);
    lcm_unsubscribe(coavoid_rt_rx_lcm(rx), sub);
    coavoid_rt_rx_close(rx);
}
END_TEST

START_TEST(receiver_counts_what_the_socket_dropped)
{
    const unsigned port = test_port() + 1u;
    coavoid_rt_rx_t *rx = open_rx(port, "&recv_buf_size=4096");
    int s = open_sender(port);
    unsigned char d[1500];
    const uint32_t v = 1u;
    const size_t n = frame(d, 0x4c433032u, 1u, "COAVOID_STATUS", &v, sizeof v);
    const uint64_t sent = 2000u;
    for (uint64_t i = 0; i < sent; i++) {
        ck_assert_int_gt(send(s, d, n, 0), 0);
    }
    deliver_all(rx);
    /* The next read brings the counter of drops since the last datagram read. */
    ck_assert_int_gt(send(s, d, n, 0), 0);
    deliver_all(rx);
    const coavoid_rt_rx_stats_t *st = coavoid_rt_rx_stats(rx);
    ck_assert_uint_gt(st->kernel_dropped, 0u);
    ck_assert_uint_eq(st->datagrams + st->kernel_dropped, sent + 1u);
    close(s);
    coavoid_rt_rx_close(rx);
}
END_TEST

/* LCM remembers every channel name it is given; the receiver gives it the fleet's only. */
START_TEST(receiver_hands_on_the_fleet_channels_only)
{
    const unsigned port = test_port() + 2u;
    coavoid_rt_rx_t *rx = open_rx(port, "");
    int s = open_sender(port);
    unsigned char d[256];
    const uint32_t v = 1u;
    const uint64_t sent = 3000u;
    for (uint64_t i = 0; i < sent; i++) {
        char name[32];
        snprintf(name, sizeof name, "COAVOID_INTENT_%llu", (unsigned long long)i);
        ck_assert_int_gt(send(s, d, frame(d, 0x4c433032u, 1u, name, &v, sizeof v), 0), 0);
        if (i % 64u == 63u) {
            deliver_all(rx); /* keeps the socket's buffer from overflowing */
        }
    }
    deliver_all(rx);
    const coavoid_rt_rx_stats_t *st = coavoid_rt_rx_stats(rx);
    ck_assert_uint_eq(st->foreign + st->kernel_dropped, sent);
    ck_assert_uint_eq(st->delivered, 0u);
    ck_assert(coavoid_rt_rx_fleet_channel("COAVOID_AGREEMENT"));
    ck_assert(!coavoid_rt_rx_fleet_channel("COAVOID_INTENTS"));
    ck_assert(!coavoid_rt_rx_fleet_channel(NULL));
    close(s);
    coavoid_rt_rx_close(rx);
}
END_TEST

START_TEST(receiver_refuses_bad_urls)
{
    char err[256];
    const char *bad[] = {"udpm://",
                         "udpm://10.0.0.1:7667",
                         "udpm://239.255.76.67:0",
                         "udpm://239.255.76.67:70000",
                         "udpm://239.255.76.67:12x",
                         "udpm://not-an-address:7667",
                         "memq://"};
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        err[0] = '\0';
        ck_assert_ptr_null(coavoid_rt_rx_open(bad[i], err, sizeof err));
        ck_assert_msg(err[0] != '\0' && strchr(err, '\n') == NULL, "%s: '%s'", bad[i], err);
    }
    ck_assert(coavoid_rt_rx_is_udpm("udpm://239.255.76.67:7667?ttl=0"));
    ck_assert(!coavoid_rt_rx_is_udpm("memq://"));
    ck_assert(!coavoid_rt_rx_is_udpm(NULL));
}
END_TEST

static Suite *rx_suite(void)
{
    Suite *s = suite_create("rx");
    TCase *parse = tcase_create("parse");
    tcase_add_test(parse, parse_reads_a_short_message);
    tcase_add_test(parse, parse_refuses_what_is_not_one);
    tcase_add_test(parse, parse_takes_names_of_63_characters_not_64);
    tcase_add_test(parse, parse_stays_inside_random_datagrams);
    suite_add_tcase(s, parse);
    TCase *socket_case = tcase_create("socket");
    tcase_add_test(socket_case, receiver_delivers_and_counts);
    tcase_add_test(socket_case, receiver_counts_what_the_socket_dropped);
    tcase_add_test(socket_case, receiver_hands_on_the_fleet_channels_only);
    tcase_add_test(socket_case, receiver_refuses_bad_urls);
    suite_add_tcase(s, socket_case);
    return s;
}

int main(void)
{
    SRunner *sr = srunner_create(rx_suite());
    srunner_run_all(sr, CK_NORMAL);
    int failed = srunner_ntests_failed(sr);
    srunner_free(sr);
    return failed == 0 ? EXIT_SUCCESS : EXIT_FAILURE;
}
