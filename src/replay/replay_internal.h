/* SPDX-License-Identifier: MIT */
/* replay_internal.h: the little-endian reader and writer of the record's fields
 * (record.c), shared by the configuration's codec (config.c) and the replay (replay.c). */
#ifndef COAVOID_REPLAY_INTERNAL_H
#define COAVOID_REPLAY_INTERNAL_H

#include "replay.h"

/* Writing: data[0..capacity), length so far. Reading: data[0..length), at so far. ok turns
 * false on the first field that does not fit (then nothing more is written, and what is
 * read is 0). */
typedef struct {
    uint8_t *data;
    size_t capacity;
    size_t length;
    size_t at;
    bool ok;
} coavoid_replay_buf_t;

void coavoid_replay_put(coavoid_replay_buf_t *b, const void *data, size_t n);
void coavoid_replay_put_u(coavoid_replay_buf_t *b, uint64_t v, size_t bytes);
void coavoid_replay_put_f(coavoid_replay_buf_t *b, double v);
void coavoid_replay_get(coavoid_replay_buf_t *b, void *out, size_t n);
uint64_t coavoid_replay_get_u(coavoid_replay_buf_t *b, size_t bytes);
double coavoid_replay_get_f(coavoid_replay_buf_t *b);

#endif /* COAVOID_REPLAY_INTERNAL_H */
