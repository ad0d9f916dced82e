/* SPDX-License-Identifier: MIT */
/*
 * tape.c: the recording of tape.h: the messages' channels and bytes one after another in
 * one growing buffer, and per call where its messages start, its digest and plans_run.
 */
#include "tape.h"

#include <stdlib.h>
#include <string.h>

#include "coavoid/coavoid.h"

typedef struct {
    uint64_t digest;
    int64_t at;          /* the nodes' clock at the call */
    bool poll;           /* a poll (else a cycle) */
    size_t first, count; /* its messages */
    uint32_t plans_run;
} tape_call_t;

typedef struct {
    size_t offset;         /* of its channel, NUL-terminated, then its bytes */
    size_t channel_length; /* without the NUL */
    uint32_t size;
} tape_message_t;

struct coavoid_sim_tape {
    bool failed; /* out of memory while recording */
    tape_call_t *calls;
    size_t call_count, call_capacity;
    tape_message_t *messages;
    size_t message_count, message_capacity;
    uint8_t *bytes;
    size_t byte_count, byte_capacity;
};

coavoid_sim_tape_t *coavoid_sim_tape_create(void)
{
    return calloc(1u, sizeof(coavoid_sim_tape_t));
}

void coavoid_sim_tape_destroy(coavoid_sim_tape_t *t)
{
    if (t != NULL) {
        free(t->calls);
        free(t->messages);
        free(t->bytes);
        free(t);
    }
}

void coavoid_sim_tape_clear(coavoid_sim_tape_t *t)
{
    t->failed = false;
    t->call_count = t->message_count = t->byte_count = 0;
}

bool coavoid_sim_tape_ok(const coavoid_sim_tape_t *t)
{
    return !t->failed;
}

/* Room for `more` elements of `size` bytes in *array (doubling). False when out of memory
 * or the sizes would overflow. */
static bool grow(void **array, size_t *capacity, size_t count, size_t more, size_t size)
{
    if (count + more <= *capacity) {
        return true;
    }
    size_t want = *capacity > 0u ? *capacity : 64u;
    while (want < count + more && want < SIZE_MAX / 2u / size) {
        want *= 2u;
    }
    if (want < count + more) {
        return false;
    }
    void *p = realloc(*array, want * size);
    if (p == NULL) {
        return false;
    }
    *array = p;
    *capacity = want;
    return true;
}

bool coavoid_sim_tape_begin(coavoid_sim_tape_t *t, uint64_t digest, int64_t at, bool poll)
{
    if (t->failed ||
        !grow((void **)&t->calls, &t->call_capacity, t->call_count, 1u, sizeof *t->calls)) {
        t->failed = true;
        return false;
    }
    t->calls[t->call_count++] = (tape_call_t){digest, at, poll, t->message_count, 0u, 0u};
    return true;
}

void coavoid_sim_tape_message(void *tape, const char *channel, const void *data, uint32_t size)
{
    coavoid_sim_tape_t *t = tape;
    const size_t length = strlen(channel);
    /* A message before the first call (none is: the coordinator publishes only in its
     * calls) could not be replayed at its place: the tape refuses to be used. */
    if (t->failed || t->call_count == 0u || length >= SIZE_MAX / 4u ||
        !grow((void **)&t->messages, &t->message_capacity, t->message_count, 1u,
              sizeof *t->messages) ||
        !grow((void **)&t->bytes, &t->byte_capacity, t->byte_count, length + 1u + size, 1u)) {
        t->failed = true;
        return;
    }
    t->messages[t->message_count++] = (tape_message_t){t->byte_count, length, size};
    memcpy(t->bytes + t->byte_count, channel, length + 1u);
    memcpy(t->bytes + t->byte_count + length + 1u, data, size);
    t->byte_count += length + 1u + size;
    t->calls[t->call_count - 1u].count++;
}

void coavoid_sim_tape_end(coavoid_sim_tape_t *t, uint32_t plans_run)
{
    if (t->call_count > 0u) {
        t->calls[t->call_count - 1u].plans_run = plans_run;
    }
}

bool coavoid_sim_tape_next(const coavoid_sim_tape_t *t, size_t call, int64_t *at, bool *poll)
{
    if (t->failed || call >= t->call_count) {
        return false;
    }
    *at = t->calls[call].at;
    *poll = t->calls[call].poll;
    return true;
}

int coavoid_sim_tape_play(const coavoid_sim_tape_t *t, size_t call, uint64_t digest, lcm_t *tx,
                          uint32_t *plans_run)
{
    if (t->failed || call >= t->call_count || t->calls[call].digest != digest) {
        return COA_ERR_ARGUMENT;
    }
    const tape_call_t *c = &t->calls[call];
    for (size_t k = c->first; k < c->first + c->count; k++) {
        const tape_message_t *m = &t->messages[k];
        const char *channel = (const char *)t->bytes + m->offset;
        if (lcm_publish(tx, channel, t->bytes + m->offset + m->channel_length + 1u, m->size) != 0) {
            return COA_ERR_ARGUMENT;
        }
    }
    *plans_run = c->plans_run;
    return COA_OK;
}
