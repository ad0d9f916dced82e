/* SPDX-License-Identifier: MIT */
/*
 * auth.c: signing and checking datagrams (auth.h): the tail, the fleet tag, the
 * signature, freshness and roles. No stdio, no heap, no clock and no random numbers, so
 * that the same code checks messages in the Linux drivers and on the part (the firmware
 * build links it with libsodium compiled for the Cortex-M4F, cmake/libsodium_arm.cmake).
 * Keys and their files are made and read on the ground: auth_files.c.
 */
#include "auth.h"

#include <string.h>

#include <sodium/crypto_shorthash_siphash24.h>
#include <sodium/crypto_sign_ed25519.h>
#include <sodium/utils.h>

#include "coavoid/common.h"

/* The wire names the algorithms (docs/messages.md): Ed25519 and SipHash-2-4, called by
 * name rather than through libsodium's generic crypto_sign and crypto_shorthash, whose
 * choice a later libsodium could change. */
_Static_assert(crypto_sign_ed25519_BYTES == COAVOID_AUTH_SIGNATURE_BYTES, "an Ed25519 signature");
_Static_assert(crypto_sign_ed25519_PUBLICKEYBYTES == COAVOID_AUTH_PUBLIC_BYTES,
               "an Ed25519 public key");
_Static_assert(crypto_sign_ed25519_SECRETKEYBYTES == COAVOID_AUTH_SECRET_BYTES,
               "an Ed25519 secret key");
_Static_assert(crypto_shorthash_siphash24_KEYBYTES == COAVOID_AUTH_FLEET_KEY_BYTES,
               "a SipHash-2-4 key");
_Static_assert(crypto_shorthash_siphash24_BYTES == COAVOID_AUTH_TAG_BYTES, "a SipHash-2-4 output");

int coavoid_auth_trust_set_fleet_key(coavoid_auth_trust_t *t,
                                     const unsigned char key[COAVOID_AUTH_FLEET_KEY_BYTES])
{
    if (t == NULL || key == NULL) {
        return COA_ERR_ARGUMENT;
    }
    memcpy(t->fleet_key, key, COAVOID_AUTH_FLEET_KEY_BYTES);
    t->has_fleet_key = true;
    return COA_OK;
}

void coavoid_auth_signer_use_fleet(coavoid_auth_signer_t *s, const coavoid_auth_trust_t *t)
{
    s->has_fleet_key = t->has_fleet_key;
    memcpy(s->fleet_key, t->fleet_key, COAVOID_AUTH_FLEET_KEY_BYTES);
}

/* The tag of the datagram's first `tagged` bytes with `key`: SipHash-2-4, a PRF made for
 * authenticating short messages, 3 times faster here than a keyed BLAKE2b of an intent
 * and 32-bit friendly (docs/benchmarks.md, "Refusing before the signature"). */
static void fleet_tag(const unsigned char key[COAVOID_AUTH_FLEET_KEY_BYTES],
                      const unsigned char *datagram, size_t tagged,
                      unsigned char tag[COAVOID_AUTH_TAG_BYTES])
{
    (void)crypto_shorthash_siphash24(tag, datagram, tagged, key);
}

int coavoid_auth_tag_check(const coavoid_auth_trust_t *t, const unsigned char *datagram,
                           size_t size)
{
    if (t == NULL || datagram == NULL || size < COAVOID_AUTH_TAIL_BYTES + 8u) {
        return COAVOID_AUTH_ERR_TAG;
    }
    if (!t->has_fleet_key) {
        return COA_OK;
    }
    unsigned char tag[COAVOID_AUTH_TAG_BYTES];
    const size_t tagged = size - COAVOID_AUTH_TAG_BYTES;
    fleet_tag(t->fleet_key, datagram, tagged, tag);
    return sodium_memcmp(tag, datagram + tagged, COAVOID_AUTH_TAG_BYTES) == 0
               ? COA_OK
               : COAVOID_AUTH_ERR_TAG;
}

void coavoid_auth_trust_init(coavoid_auth_trust_t *t)
{
    memset(t, 0, sizeof *t);
}

int coavoid_auth_trust_add(coavoid_auth_trust_t *t, const coavoid_auth_key_t *key)
{
    if (t == NULL || key == NULL || t->count == COAVOID_AUTH_MAX_KEYS || key->key_id == 0u ||
        key->key_id > (uint32_t)INT32_MAX) {
        return COA_ERR_ARGUMENT;
    }
    for (size_t i = 0; i < t->count; i++) {
        if (t->keys[i].key_id == key->key_id) {
            return COA_ERR_ARGUMENT;
        }
    }
    t->keys[t->count] = *key;
    for (size_t stream = 0; stream < COAVOID_AUTH_STREAMS; stream++) {
        t->last_timestamp[t->count][stream] = INT64_MIN;
        t->last_sequence[t->count][stream] = INT64_MIN;
    }
    t->count++;
    return COA_OK;
}

void coavoid_auth_next(coavoid_auth_signer_t *s, int64_t now, int32_t *key_id,
                       int64_t *timestamp_us, int64_t *sequence)
{
    /* Within one timestamp the sequence orders messages; a new timestamp starts it again,
     * so that a restarted sender (its clock later, its count from 0) is newer. */
    if (now > s->last_timestamp) {
        s->last_timestamp = now;
        s->sequence = 0;
    } else {
        s->sequence++;
    }
    *key_id = (int32_t)s->key_id;
    *timestamp_us = s->last_timestamp;
    *sequence = s->sequence;
}

int coavoid_auth_signer_matches(const coavoid_auth_trust_t *t, const coavoid_auth_signer_t *s,
                                coavoid_auth_role_t role, uint16_t node_id)
{
    if (t == NULL || s == NULL) {
        return COAVOID_AUTH_ERR_KEY;
    }
    unsigned char public_key[COAVOID_AUTH_PUBLIC_BYTES];
    crypto_sign_ed25519_sk_to_pk(public_key, s->secret_key);
    for (size_t i = 0; i < t->count; i++) {
        if (t->keys[i].key_id != s->key_id) {
            continue;
        }
        if (sodium_memcmp(t->keys[i].public_key, public_key, sizeof public_key) != 0) {
            return COAVOID_AUTH_ERR_KEY;
        }
        return coavoid_auth_may_send(t, i, role, node_id);
    }
    return COAVOID_AUTH_ERR_KEY;
}

void coavoid_auth_signer_clear(coavoid_auth_signer_t *s)
{
    if (s != NULL) {
        sodium_memzero(s, sizeof *s);
    }
}

int coavoid_auth_sign(const coavoid_auth_signer_t *s, unsigned char *datagram, size_t size)
{
    if (s == NULL || datagram == NULL || size < COAVOID_AUTH_TAIL_BYTES + 8u) {
        return COA_ERR_ARGUMENT;
    }
    const size_t tagged = size - COAVOID_AUTH_TAG_BYTES;
    const size_t signed_size = tagged - COAVOID_AUTH_SIGNATURE_BYTES;
    if (crypto_sign_ed25519_detached(datagram + signed_size, NULL, datagram, signed_size,
                                     s->secret_key) != 0) {
        return COA_ERR_ARGUMENT;
    }
    if (s->has_fleet_key) {
        fleet_tag(s->fleet_key, datagram, tagged, datagram + tagged);
    } else {
        memset(datagram + tagged, 0, COAVOID_AUTH_TAG_BYTES);
    }
    return COA_OK;
}

static void put_be(unsigned char *p, uint64_t v, size_t bytes)
{
    for (size_t i = 0; i < bytes; i++) {
        p[i] = (unsigned char)(v >> (8u * (bytes - 1u - i)));
    }
}

int coavoid_auth_stamp(coavoid_auth_signer_t *s, int64_t now, unsigned char *datagram, size_t size)
{
    if (s == NULL || datagram == NULL || size < COAVOID_AUTH_TAIL_BYTES + 8u) {
        return COA_ERR_ARGUMENT;
    }
    coavoid_auth_signer_t next = *s;
    int32_t key_id = 0;
    int64_t timestamp = 0, sequence = 0;
    coavoid_auth_next(&next, now, &key_id, &timestamp, &sequence);
    unsigned char *tail = datagram + size - COAVOID_AUTH_TAIL_BYTES;
    put_be(tail, (uint32_t)key_id, 4u);
    put_be(tail + 4, (uint64_t)timestamp, 8u);
    put_be(tail + 12, (uint64_t)sequence, 8u);
    int rc = coavoid_auth_sign(&next, datagram, size);
    if (rc == COA_OK) {
        s->last_timestamp = next.last_timestamp;
        s->sequence = next.sequence;
    }
    sodium_memzero(&next, sizeof next);
    return rc;
}

static uint64_t get_be(const unsigned char *p, size_t bytes)
{
    uint64_t v = 0;
    for (size_t i = 0; i < bytes; i++) {
        v = v << 8 | p[i];
    }
    return v;
}

/* The key_id of a datagram's auth_t: the 4 big-endian bytes before its two int64s and
 * its signature. */
static uint32_t datagram_key_id(const unsigned char *datagram, size_t size)
{
    return (uint32_t)get_be(datagram + size - COAVOID_AUTH_TAIL_BYTES, 4u);
}

/* The index in t of the key a datagram of `size` bytes (checked long enough) names: COA_OK
 * with *key, COAVOID_AUTH_ERR_UNSIGNED (key_id 0) or COAVOID_AUTH_ERR_KEY (not in t). */
static int datagram_key(const coavoid_auth_trust_t *t, const unsigned char *datagram, size_t size,
                        size_t *key)
{
    const uint32_t id = datagram_key_id(datagram, size);
    if (id == 0u) {
        return COAVOID_AUTH_ERR_UNSIGNED;
    }
    size_t i = 0;
    while (i < t->count && t->keys[i].key_id != id) {
        i++;
    }
    *key = i;
    return i == t->count ? COAVOID_AUTH_ERR_KEY : COA_OK;
}

/* Whether (timestamp, sequence) would be fresh on key's stream at now: within the window
 * and after the last accepted. COA_OK, COAVOID_AUTH_ERR_CLOCK or _REPLAY; marks nothing. */
static int fresh_at(const coavoid_auth_trust_t *t, size_t key, size_t stream, int64_t timestamp_us,
                    int64_t sequence, int64_t now, int64_t max_age_us, int64_t max_ahead_us)
{
    if (timestamp_us < now - max_age_us || timestamp_us > now + max_ahead_us) {
        return COAVOID_AUTH_ERR_CLOCK;
    }
    const int64_t last_timestamp = t->last_timestamp[key][stream];
    if (timestamp_us < last_timestamp ||
        (timestamp_us == last_timestamp && sequence <= t->last_sequence[key][stream])) {
        return COAVOID_AUTH_ERR_REPLAY;
    }
    return COA_OK;
}

int coavoid_auth_precheck(const coavoid_auth_trust_t *t, const unsigned char *datagram, size_t size,
                          const coavoid_auth_expect_t *expect, size_t *key)
{
    if (t == NULL || datagram == NULL || expect == NULL || key == NULL ||
        size < COAVOID_AUTH_TAIL_BYTES + 8u) {
        return COAVOID_AUTH_ERR_UNSIGNED;
    }
    const unsigned char *tail = datagram + size - COAVOID_AUTH_TAIL_BYTES;
    size_t i = 0;
    int rc = datagram_key(t, datagram, size, &i);
    if (rc != COA_OK) {
        return rc;
    }
    if (expect->stream >= COAVOID_AUTH_STREAMS) {
        return COAVOID_AUTH_ERR_REPLAY;
    }
    if (expect->role != COAVOID_AUTH_ANY_ROLE && t->keys[i].role != expect->role) {
        return COAVOID_AUTH_ERR_ROLE;
    }
    rc = fresh_at(t, i, expect->stream, (int64_t)get_be(tail + 4, 8u),
                  (int64_t)get_be(tail + 12, 8u), expect->now, expect->max_age_us,
                  expect->max_ahead_us);
    if (rc == COA_OK) {
        rc = coavoid_auth_tag_check(t, datagram, size);
    }
    if (rc == COA_OK) {
        *key = i;
    }
    return rc;
}

int coavoid_auth_verify(const coavoid_auth_trust_t *t, const unsigned char *datagram, size_t size,
                        size_t *key)
{
    if (t == NULL || datagram == NULL || key == NULL || size < COAVOID_AUTH_TAIL_BYTES + 8u) {
        return COAVOID_AUTH_ERR_UNSIGNED;
    }
    size_t i = 0;
    const int rc = datagram_key(t, datagram, size, &i);
    if (rc != COA_OK) {
        return rc;
    }
    const size_t signed_size = size - COAVOID_AUTH_TAG_BYTES - COAVOID_AUTH_SIGNATURE_BYTES;
    if (crypto_sign_ed25519_verify_detached(datagram + signed_size, datagram, signed_size,
                                            t->keys[i].public_key) != 0) {
        return COAVOID_AUTH_ERR_SIGNATURE;
    }
    *key = i;
    return COA_OK;
}

int coavoid_auth_may_send(const coavoid_auth_trust_t *t, size_t key, coavoid_auth_role_t role,
                          uint16_t node_id)
{
    if (t == NULL || key >= t->count) {
        return COAVOID_AUTH_ERR_ROLE;
    }
    const coavoid_auth_key_t *k = &t->keys[key];
    return k->role == role && (node_id == 0u || k->node_id == node_id) ? COA_OK
                                                                       : COAVOID_AUTH_ERR_ROLE;
}

int coavoid_auth_fresh(coavoid_auth_trust_t *t, size_t key, size_t stream, int64_t timestamp_us,
                       int64_t sequence, int64_t now, int64_t max_age_us, int64_t max_ahead_us)
{
    if (t == NULL || key >= t->count || stream >= COAVOID_AUTH_STREAMS) {
        return COAVOID_AUTH_ERR_REPLAY;
    }
    const int rc = fresh_at(t, key, stream, timestamp_us, sequence, now, max_age_us, max_ahead_us);
    if (rc == COA_OK) {
        t->last_timestamp[key][stream] = timestamp_us;
        t->last_sequence[key][stream] = sequence;
    }
    return rc;
}

int coavoid_auth_accept(coavoid_auth_trust_t *t, size_t key, size_t stream,
                        coavoid_auth_role_t role, int32_t id, int64_t timestamp_us,
                        int64_t sequence, int64_t now, int64_t max_age_us, int64_t max_ahead_us)
{
    if (id < 1 || id > 65535) {
        return COAVOID_AUTH_ERR_ROLE;
    }
    int rc = coavoid_auth_may_send(t, key, role, (uint16_t)id);
    return rc == COA_OK ? coavoid_auth_fresh(t, key, stream, timestamp_us, sequence, now,
                                             max_age_us, max_ahead_us)
                        : rc;
}

/* ---- keys as text ---- */
