/* SPDX-License-Identifier: MIT */
/*
 * test_link.c: records over a byte stream (src/replay/link.h): frames come out as they
 * went in, whatever bytes they hold; a garbled, cut, over-long or badly escaped frame is
 * dropped and counted, and the next frame is found at its END.
 */
#include <check.h>
#include <stdlib.h>
#include <string.h>

#include "link.h"

#define FRAMES 3u
#define FRAME_BYTES 300u

typedef struct {
    uint8_t data[FRAMES][FRAME_BYTES];
    size_t size[FRAMES];
    uint8_t wire[FRAMES * COAVOID_LINK_FRAMED_MAX(FRAME_BYTES)];
    size_t wire_length;
    size_t starts[FRAMES]; /* where each frame begins on the wire */
} stream_t;

/* Three frames, rich in END and ESC bytes, one after the other on the wire. */
static void stream_make(stream_t *s, unsigned seed)
{
    srand(seed);
    s->wire_length = 0;
    for (size_t f = 0; f < FRAMES; f++) {
        s->size[f] = 1u + (size_t)rand() % FRAME_BYTES;
        for (size_t i = 0; i < s->size[f]; i++) {
            const int r = rand() % 4;
            s->data[f][i] = r == 0 ? COAVOID_LINK_END : r == 1 ? COAVOID_LINK_ESC : (uint8_t)rand();
        }
        s->starts[f] = s->wire_length;
        const size_t n = coavoid_link_frame(s->data[f], s->size[f], s->wire + s->wire_length,
                                            sizeof s->wire - s->wire_length);
        ck_assert_uint_gt(n, 0u);
        s->wire_length += n;
    }
}

/* Feeds wire[from..) to a receiver; returns how many frames came out, each checked
 * against the frame `expect` says (or any, for -1). */
static size_t feed(const stream_t *s, size_t from, const int *expect, coavoid_link_rx_t *r)
{
    size_t got = 0;
    for (size_t i = from; i < s->wire_length; i++) {
        const size_t n = coavoid_link_rx_byte(r, s->wire[i]);
        if (n > 0u) {
            const int f = expect[got++];
            ck_assert_uint_eq(n, s->size[f]);
            ck_assert_int_eq(memcmp(r->buffer, s->data[f], n), 0);
        }
    }
    return got;
}

START_TEST(test_crc_check_value)
{
    ck_assert_uint_eq(coavoid_link_crc32(0u, (const uint8_t *)"123456789", 9u), 0xCBF43926u);
}
END_TEST

START_TEST(test_frames_round_trip)
{
    static stream_t s;
    static uint8_t buffer[FRAME_BYTES + COAVOID_LINK_CRC_BYTES];
    coavoid_link_rx_t r;
    const int all[FRAMES] = {0, 1, 2};
    for (unsigned seed = 1; seed <= 50u; seed++) {
        stream_make(&s, seed);
        coavoid_link_rx_init(&r, buffer, sizeof buffer);
        ck_assert_uint_eq(feed(&s, 0, all, &r), FRAMES);
        ck_assert_uint_eq(r.frames, FRAMES);
        ck_assert_uint_eq(r.dropped, 0u);
    }
}
END_TEST

START_TEST(test_garbled_frame_dropped)
{
    static stream_t s;
    static uint8_t buffer[FRAME_BYTES + COAVOID_LINK_CRC_BYTES];
    coavoid_link_rx_t r;
    const int others[2] = {0, 2};
    stream_make(&s, 7u);
    /* One bit of frame 1's first data byte (not an END: that would split it in two). */
    s.wire[s.starts[1] + 1u] ^= 0x01u;
    coavoid_link_rx_init(&r, buffer, sizeof buffer);
    ck_assert_uint_eq(feed(&s, 0, others, &r), 2u);
    ck_assert_uint_eq(r.dropped, 1u);
}
END_TEST

START_TEST(test_joined_midway)
{
    static stream_t s;
    static uint8_t buffer[FRAME_BYTES + COAVOID_LINK_CRC_BYTES];
    coavoid_link_rx_t r;
    const int later[2] = {1, 2};
    stream_make(&s, 11u);
    coavoid_link_rx_init(&r, buffer, sizeof buffer);
    /* From the middle of frame 0: its tail is no frame, frames 1 and 2 come whole. */
    ck_assert_uint_eq(feed(&s, s.starts[1] / 2u + 1u, later, &r), 2u);
    ck_assert_uint_le(r.dropped, 1u);
}
END_TEST

START_TEST(test_too_long_and_bad_escape)
{
    static stream_t s;
    static uint8_t crc_only[COAVOID_LINK_CRC_BYTES];
    static uint8_t buffer[FRAME_BYTES + COAVOID_LINK_CRC_BYTES];
    coavoid_link_rx_t r;
    const int all[FRAMES] = {0, 1, 2};
    stream_make(&s, 3u);
    /* A receiver with room for no frame (every frame holds a byte) drops each, counted. */
    coavoid_link_rx_init(&r, crc_only, sizeof crc_only);
    ck_assert_uint_eq(feed(&s, 0, all, &r), 0u);
    ck_assert_uint_eq(r.dropped, FRAMES);
    /* ESC followed by no escape code: that frame is dropped, the ones after it kept. */
    const uint8_t bad[] = {COAVOID_LINK_END, 'a', COAVOID_LINK_ESC, 'b', 'c', COAVOID_LINK_END};
    coavoid_link_rx_init(&r, buffer, sizeof buffer);
    for (size_t i = 0; i < sizeof bad; i++) {
        ck_assert_uint_eq(coavoid_link_rx_byte(&r, bad[i]), 0u);
    }
    ck_assert_uint_eq(r.dropped, 1u);
    ck_assert_uint_eq(feed(&s, 0, all, &r), FRAMES);
}
END_TEST

START_TEST(test_frame_needs_room)
{
    const uint8_t data[4] = {COAVOID_LINK_END, COAVOID_LINK_ESC, 1, 2};
    uint8_t out[COAVOID_LINK_FRAMED_MAX(4)];
    ck_assert_uint_eq(coavoid_link_frame(data, sizeof data, out, 3u), 0u);
    ck_assert_uint_eq(coavoid_link_frame(data, sizeof data, NULL, 0u), 0u);
    const size_t n = coavoid_link_frame(data, sizeof data, out, sizeof out);
    ck_assert_uint_gt(n, 0u);
    ck_assert_uint_eq(out[0], COAVOID_LINK_END);
    ck_assert_uint_eq(out[n - 1u], COAVOID_LINK_END);
    for (size_t i = 1; i + 1u < n; i++) {
        ck_assert_uint_ne(out[i], COAVOID_LINK_END); /* an END only at the ends */
    }
}
END_TEST

int main(void)
{
    Suite *s = suite_create("link");
    TCase *tc = tcase_create("frames");
    tcase_add_test(tc, test_crc_check_value);
    tcase_add_test(tc, test_frames_round_trip);
    tcase_add_test(tc, test_garbled_frame_dropped);
    tcase_add_test(tc, test_joined_midway);
    tcase_add_test(tc, test_too_long_and_bad_escape);
    tcase_add_test(tc, test_frame_needs_room);
    suite_add_tcase(s, tc);
    SRunner *sr = srunner_create(s);
    srunner_run_all(sr, CK_NORMAL);
    const int failed = srunner_ntests_failed(sr);
    srunner_free(sr);
    return failed == 0 ? EXIT_SUCCESS : EXIT_FAILURE;
}
