/* SPDX-License-Identifier: MIT */
/* Records over a byte stream: SLIP framing with a CRC-32 (link.h). */
#include "link.h"

uint32_t coavoid_link_crc32(uint32_t crc, const uint8_t *data, size_t n)
{
    /* Bitwise, without a table: 256 words of flash are dearer on the part than the time a
     * 1.4 kB frame takes at a UART's rate. */
    crc = ~crc;
    for (size_t i = 0; i < n; i++) {
        crc ^= data[i];
        for (unsigned k = 0; k < 8u; k++) {
            crc = (crc >> 1) ^ (UINT32_C(0xEDB88320) & (0u - (crc & 1u)));
        }
    }
    return ~crc;
}

/* One byte escaped as SLIP does, through put. */
static void put_escaped(uint8_t byte, coavoid_link_put_t put, void *user)
{
    if (byte == COAVOID_LINK_END || byte == COAVOID_LINK_ESC) {
        put(user, COAVOID_LINK_ESC);
        put(user, byte == COAVOID_LINK_END ? COAVOID_LINK_ESC_END : COAVOID_LINK_ESC_ESC);
    } else {
        put(user, byte);
    }
}

void coavoid_link_put_frame(const uint8_t *const *parts, const size_t *lengths, size_t count,
                            coavoid_link_put_t put, void *user)
{
    uint32_t crc = 0;
    put(user, COAVOID_LINK_END);
    for (size_t p = 0; p < count; p++) {
        crc = coavoid_link_crc32(crc, parts[p], lengths[p]);
        for (size_t i = 0; i < lengths[p]; i++) {
            put_escaped(parts[p][i], put, user);
        }
    }
    for (unsigned k = 0; k < COAVOID_LINK_CRC_BYTES; k++) {
        put_escaped((uint8_t)(crc >> (8u * k)), put, user);
    }
    put(user, COAVOID_LINK_END);
}

/* Bytes into a buffer already known to be large enough. */
typedef struct {
    uint8_t *out;
    size_t at;
} buffer_put_t;

static void buffer_put(void *user, uint8_t byte)
{
    buffer_put_t *b = user;
    b->out[b->at++] = byte;
}

size_t coavoid_link_frame(const uint8_t *data, size_t n, uint8_t *out, size_t capacity)
{
    size_t need = 2u;
    for (size_t i = 0; i < n; i++) {
        need += data[i] == COAVOID_LINK_END || data[i] == COAVOID_LINK_ESC ? 2u : 1u;
    }
    need += 2u * COAVOID_LINK_CRC_BYTES; /* at most */
    if (out == NULL || need > capacity) {
        return 0u;
    }
    buffer_put_t b = {out, 0u};
    const uint8_t *const parts[] = {data};
    coavoid_link_put_frame(parts, &n, 1u, buffer_put, &b);
    return b.at;
}

void coavoid_link_rx_init(coavoid_link_rx_t *r, uint8_t *buffer, size_t capacity)
{
    r->buffer = buffer;
    r->capacity = capacity;
    r->length = 0;
    r->escaped = false;
    r->discarding = false;
    r->frames = 0;
    r->dropped = 0;
}

/* A frame's END: its length when whole and its CRC matches, else 0 (counted). */
static size_t frame_end(coavoid_link_rx_t *r)
{
    const size_t n = r->length;
    const bool bad = r->discarding || r->escaped;
    r->length = 0;
    r->escaped = false;
    r->discarding = false;
    if (n == 0u && !bad) {
        return 0u; /* ENDs between frames */
    }
    if (bad || n < COAVOID_LINK_CRC_BYTES) {
        r->dropped++;
        return 0u;
    }
    const size_t body = n - COAVOID_LINK_CRC_BYTES;
    uint32_t crc = 0;
    for (unsigned k = 0; k < COAVOID_LINK_CRC_BYTES; k++) {
        crc |= (uint32_t)r->buffer[body + k] << (8u * k);
    }
    if (coavoid_link_crc32(0u, r->buffer, body) != crc) {
        r->dropped++;
        return 0u;
    }
    r->frames++;
    return body;
}

size_t coavoid_link_rx_byte(coavoid_link_rx_t *r, uint8_t byte)
{
    if (byte == COAVOID_LINK_END) {
        return frame_end(r);
    }
    if (r->discarding) {
        return 0u;
    }
    if (r->escaped) {
        r->escaped = false;
        if (byte != COAVOID_LINK_ESC_END && byte != COAVOID_LINK_ESC_ESC) {
            r->discarding = true; /* no such escape: a garbled frame */
            return 0u;
        }
        byte = byte == COAVOID_LINK_ESC_END ? COAVOID_LINK_END : COAVOID_LINK_ESC;
    } else if (byte == COAVOID_LINK_ESC) {
        r->escaped = true;
        return 0u;
    }
    if (r->length == r->capacity) {
        r->discarding = true; /* longer than any frame it takes */
        return 0u;
    }
    r->buffer[r->length++] = byte;
    return 0u;
}
