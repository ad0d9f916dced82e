/* SPDX-License-Identifier: MIT */
/*
 * link.h: records (replay.h) over a byte stream, such as a vehicle's UART to the ground
 * (coavoid::replay). Each frame is one record, its bytes followed by their CRC-32 (IEEE
 * 802.3, little-endian), escaped and delimited as SLIP does (RFC 1055: END 0xC0 before and
 * after, ESC 0xDB: ESC ESC_END 0xDC for a 0xC0 byte, ESC ESC_ESC 0xDD for a 0xDB byte).
 * A receiver that joins mid-stream, or loses or garbles a byte, drops that frame
 * (counted) and finds the next one at its END: nothing past a frame's end is lost, and no
 * garbled frame is handed on, unless it also matches its CRC (about 2^-32 for random
 * damage; the signatures inside a datagram still stand behind it).
 *
 * No I/O, no heap: the caller owns the buffers and moves the bytes. Not thread-safe.
 */
#ifndef COAVOID_LINK_H
#define COAVOID_LINK_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#define COAVOID_LINK_END 0xC0u
#define COAVOID_LINK_ESC 0xDBu
#define COAVOID_LINK_ESC_END 0xDCu
#define COAVOID_LINK_ESC_ESC 0xDDu
#define COAVOID_LINK_CRC_BYTES 4u

/* The bytes a frame of n bytes may take on the wire, at most (every byte escaped). */
#define COAVOID_LINK_FRAMED_MAX(n) (2u * ((size_t)(n) + COAVOID_LINK_CRC_BYTES) + 2u)

/* CRC-32 (IEEE) of data[0..n), continuing from crc (0 to start). O(n). */
uint32_t coavoid_link_crc32(uint32_t crc, const uint8_t *data, size_t n);

/* Frames data[0..n) into out (capacity bytes). Returns the bytes written, or 0 when out is
 * too small (COAVOID_LINK_FRAMED_MAX(n) always suffices). O(n). */
size_t coavoid_link_frame(const uint8_t *data, size_t n, uint8_t *out, size_t capacity);

/* One byte onto the wire. */
typedef void (*coavoid_link_put_t)(void *user, uint8_t byte);

/* Frames the bytes of parts[0..count) (lengths[i] each, in turn) as one frame, as
 * coavoid_link_frame does, one byte at a time through put: no buffer. O(bytes). */
void coavoid_link_put_frame(const uint8_t *const *parts, const size_t *lengths, size_t count,
                            coavoid_link_put_t put, void *user);

/* A receiver: the frame being gathered, in the caller's buffer. */
typedef struct {
    uint8_t *buffer;
    size_t capacity;
    size_t length;
    bool escaped;     /* the last byte was ESC */
    bool discarding;  /* the frame in progress is dropped: skip to its END */
    uint64_t frames;  /* frames handed on */
    uint64_t dropped; /* frames dropped: too long, a bad escape, a bad CRC or too short */
} coavoid_link_rx_t;

/* Empties r over buffer[0..capacity): a frame of more than capacity - 4 bytes is dropped. */
void coavoid_link_rx_init(coavoid_link_rx_t *r, uint8_t *buffer, size_t capacity);

/* Takes one byte off the wire. Returns the length of the frame it completes (its bytes at
 * r->buffer, CRC checked and removed; good until the next call), or 0. Between frames, a
 * run of ENDs is no frame. O(1), or O(frame) at its END for the CRC. */
size_t coavoid_link_rx_byte(coavoid_link_rx_t *r, uint8_t byte);

#endif /* COAVOID_LINK_H */
