/* SPDX-License-Identifier: MIT */
/* A vehicle's record: its format, written and read (replay.h). */
#include <string.h>

#include "replay_internal.h"

void coavoid_replay_put(coavoid_replay_buf_t *b, const void *data, size_t n)
{
    if (!b->ok || n > b->capacity - b->length) {
        b->ok = false;
        return;
    }
    memcpy(b->data + b->length, data, n);
    b->length += n;
}

void coavoid_replay_put_u(coavoid_replay_buf_t *b, uint64_t v, size_t bytes)
{
    uint8_t le[8];
    for (size_t i = 0; i < bytes; i++) {
        le[i] = (uint8_t)(v >> (8u * i));
    }
    coavoid_replay_put(b, le, bytes);
}

void coavoid_replay_put_f(coavoid_replay_buf_t *b, double v)
{
    uint64_t bits;
    memcpy(&bits, &v, sizeof bits);
    coavoid_replay_put_u(b, bits, 8u);
}

void coavoid_replay_get(coavoid_replay_buf_t *b, void *out, size_t n)
{
    if (!b->ok || n > b->length - b->at) {
        b->ok = false;
        memset(out, 0, n);
        return;
    }
    memcpy(out, b->data + b->at, n);
    b->at += n;
}

uint64_t coavoid_replay_get_u(coavoid_replay_buf_t *b, size_t bytes)
{
    uint8_t le[8];
    uint64_t v = 0;
    coavoid_replay_get(b, le, bytes);
    for (size_t i = 0; i < bytes; i++) {
        v |= (uint64_t)le[i] << (8u * i);
    }
    return v;
}

double coavoid_replay_get_f(coavoid_replay_buf_t *b)
{
    uint64_t bits = coavoid_replay_get_u(b, 8u);
    double v;
    memcpy(&v, &bits, sizeof v);
    return v;
}

void coavoid_replay_write_header(uint8_t out[COAVOID_REPLAY_HEADER_BYTES],
                                 coavoid_replay_kind_t kind, int64_t time, size_t channel_length,
                                 size_t payload_length)
{
    coavoid_replay_buf_t b = {out, COAVOID_REPLAY_HEADER_BYTES, 0, 0, true};
    coavoid_replay_put_u(&b, (uint64_t)kind, 1u);
    coavoid_replay_put_u(&b, 0u, 1u);
    coavoid_replay_put_u(&b, (uint64_t)channel_length, 2u);
    coavoid_replay_put_u(&b, (uint64_t)payload_length, 4u);
    coavoid_replay_put_u(&b, (uint64_t)time, 8u);
}

int coavoid_replay_header(const uint8_t header[COAVOID_REPLAY_HEADER_BYTES], size_t *rest)
{
    coavoid_replay_buf_t b = {(uint8_t *)(uintptr_t)header, 0, COAVOID_REPLAY_HEADER_BYTES, 0,
                              true};
    const uint64_t kind = coavoid_replay_get_u(&b, 1u);
    const uint64_t zero = coavoid_replay_get_u(&b, 1u);
    const uint64_t channel = coavoid_replay_get_u(&b, 2u);
    const uint64_t payload = coavoid_replay_get_u(&b, 4u);
    if (kind < COAVOID_REPLAY_CONFIG || kind > COAVOID_REPLAY_READY || zero != 0u ||
        channel > COAVOID_REPLAY_MAX_CHANNEL || payload > COAVOID_REPLAY_MAX_PAYLOAD) {
        return COAVOID_REPLAY_ERR_FORMAT;
    }
    *rest = (size_t)channel + (size_t)payload;
    return COA_OK;
}

int coavoid_replay_parse(const uint8_t *data, size_t size, coavoid_replay_record_t *record,
                         size_t *used)
{
    size_t rest = 0;
    if (data == NULL || size < COAVOID_REPLAY_HEADER_BYTES ||
        coavoid_replay_header(data, &rest) != COA_OK || rest > size - COAVOID_REPLAY_HEADER_BYTES) {
        return COAVOID_REPLAY_ERR_FORMAT;
    }
    coavoid_replay_buf_t b = {(uint8_t *)(uintptr_t)data, 0, COAVOID_REPLAY_HEADER_BYTES, 0, true};
    record->kind = (coavoid_replay_kind_t)coavoid_replay_get_u(&b, 1u);
    (void)coavoid_replay_get_u(&b, 1u);
    record->channel_length = (size_t)coavoid_replay_get_u(&b, 2u);
    record->payload_length = (size_t)coavoid_replay_get_u(&b, 4u);
    record->time = (int64_t)coavoid_replay_get_u(&b, 8u);
    record->channel = (const char *)(data + COAVOID_REPLAY_HEADER_BYTES);
    record->payload = data + COAVOID_REPLAY_HEADER_BYTES + record->channel_length;
    *used = COAVOID_REPLAY_HEADER_BYTES + rest;
    return COA_OK;
}

void coavoid_replay_write_state(int rc, const coavoid_vehicle_node_state_t *s,
                                uint8_t out[COAVOID_REPLAY_STATE_BYTES])
{
    coavoid_replay_buf_t b = {out, COAVOID_REPLAY_STATE_BYTES, 0, 0, true};
    const uint32_t counters[] = {s->protocol_faults, s->plans_run,      s->plans_adopted,
                                 s->conflicts,       s->fallbacks,      s->plans_accepted,
                                 s->plans_refused,   s->plans_switched, s->plans_aborted,
                                 s->plans_in_doubt,  s->plans_standby,  s->rank_raises,
                                 s->orders_agreed,   s->joint_plans};
    memset(out, 0, COAVOID_REPLAY_STATE_BYTES);
    coavoid_replay_put_u(&b, (uint64_t)(int64_t)rc, 4u);
    coavoid_replay_put_u(&b, (uint64_t)s->phase, 1u);
    coavoid_replay_put_u(&b, (uint64_t)s->plan, 1u);
    coavoid_replay_put_u(&b, (uint64_t)s->published, 1u);
    coavoid_replay_put_u(&b, (uint64_t)s->waiting, 1u);
    coavoid_replay_put_u(&b, (uint64_t)s->cycle, 8u);
    coavoid_replay_put_u(&b, (uint64_t)(int64_t)s->offset, 4u);
    coavoid_replay_put_u(&b, (uint64_t)(int64_t)s->rank, 4u);
    for (size_t i = 0; i < sizeof counters / sizeof counters[0]; i++) {
        coavoid_replay_put_u(&b, counters[i], 4u);
    }
    coavoid_replay_put_u(&b, (uint64_t)s->rx.received, 8u);
    coavoid_replay_put_u(&b, (uint64_t)s->rx.rejected, 8u);
}

void coavoid_replay_channel(const coavoid_replay_record_t *record,
                            char out[COAVOID_REPLAY_MAX_CHANNEL + 1u])
{
    memcpy(out, record->channel, record->channel_length);
    out[record->channel_length] = '\0';
}

int coavoid_replay_read_state(const uint8_t *payload, size_t size, int *rc,
                              coavoid_vehicle_node_state_t *s)
{
    if (payload == NULL || size != COAVOID_REPLAY_STATE_BYTES || rc == NULL || s == NULL) {
        return COAVOID_REPLAY_ERR_FORMAT;
    }
    coavoid_replay_buf_t b = {(uint8_t *)(uintptr_t)payload, 0, size, 0, true};
    uint32_t *const counters[] = {&s->protocol_faults, &s->plans_run,      &s->plans_adopted,
                                  &s->conflicts,       &s->fallbacks,      &s->plans_accepted,
                                  &s->plans_refused,   &s->plans_switched, &s->plans_aborted,
                                  &s->plans_in_doubt,  &s->plans_standby,  &s->rank_raises,
                                  &s->orders_agreed,   &s->joint_plans};
    memset(s, 0, sizeof *s);
    *rc = (int)(int32_t)(uint32_t)coavoid_replay_get_u(&b, 4u);
    s->phase = (coavoid_vehicle_phase_t)coavoid_replay_get_u(&b, 1u);
    s->plan = (coavoid_vehicle_plan_t)coavoid_replay_get_u(&b, 1u);
    s->published = coavoid_replay_get_u(&b, 1u) != 0u;
    s->waiting = coavoid_replay_get_u(&b, 1u) != 0u;
    s->cycle = (int64_t)coavoid_replay_get_u(&b, 8u);
    s->offset = (int32_t)(uint32_t)coavoid_replay_get_u(&b, 4u);
    s->rank = (int32_t)(uint32_t)coavoid_replay_get_u(&b, 4u);
    for (size_t i = 0; i < sizeof counters / sizeof counters[0]; i++) {
        *counters[i] = (uint32_t)coavoid_replay_get_u(&b, 4u);
    }
    s->rx.received = (int64_t)coavoid_replay_get_u(&b, 8u);
    s->rx.rejected = (int64_t)coavoid_replay_get_u(&b, 8u);
    return COA_OK;
}

int coavoid_replay_next(coavoid_replay_read_t read, void *user, uint8_t *buf, size_t capacity,
                        coavoid_replay_record_t *record)
{
    size_t rest = 0;
    size_t used = 0;
    if (capacity < COAVOID_REPLAY_HEADER_BYTES) {
        return COAVOID_REPLAY_ERR_FORMAT;
    }
    const size_t got = read(user, buf, COAVOID_REPLAY_HEADER_BYTES);
    if (got == 0u) {
        return 0;
    }
    if (got != COAVOID_REPLAY_HEADER_BYTES || coavoid_replay_header(buf, &rest) != COA_OK ||
        rest > capacity - COAVOID_REPLAY_HEADER_BYTES ||
        read(user, buf + COAVOID_REPLAY_HEADER_BYTES, rest) != rest ||
        coavoid_replay_parse(buf, COAVOID_REPLAY_HEADER_BYTES + rest, record, &used) != COA_OK) {
        return COAVOID_REPLAY_ERR_FORMAT;
    }
    return 1;
}

int coavoid_replay_open(coavoid_replay_t *r, coavoid_replay_read_t read, void *user, uint8_t *buf,
                        size_t capacity)
{
    coavoid_replay_record_t rec;
    char magic[COAVOID_REPLAY_MAGIC_BYTES];
    if (read(user, magic, sizeof magic) != sizeof magic ||
        memcmp(magic, COAVOID_REPLAY_MAGIC, sizeof magic) != 0 ||
        coavoid_replay_next(read, user, buf, capacity, &rec) != 1 ||
        rec.kind != COAVOID_REPLAY_CONFIG) {
        return COAVOID_REPLAY_ERR_FORMAT;
    }
    const int rc = coavoid_replay_config(r, rec.payload, rec.payload_length);
    r->now = rec.time;
    return rc;
}
