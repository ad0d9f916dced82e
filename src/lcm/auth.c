/* SPDX-License-Identifier: MIT */
/* Signed messages (auth.h). */
#include "auth.h"

#include <string.h>

#include <sodium.h>

#include "coavoid/common.h"

_Static_assert(crypto_sign_BYTES == COAVOID_AUTH_SIGNATURE_BYTES, "an Ed25519 signature");
_Static_assert(crypto_sign_PUBLICKEYBYTES == COAVOID_AUTH_PUBLIC_BYTES, "an Ed25519 public key");
_Static_assert(crypto_sign_SECRETKEYBYTES == COAVOID_AUTH_SECRET_BYTES, "an Ed25519 secret key");

int coavoid_auth_init(void)
{
    return sodium_init() >= 0 ? COA_OK : COA_ERR_ARGUMENT;
}

int coavoid_auth_keypair(unsigned char public_key[COAVOID_AUTH_PUBLIC_BYTES],
                         unsigned char secret_key[COAVOID_AUTH_SECRET_BYTES])
{
    if (public_key == NULL || secret_key == NULL || coavoid_auth_init() != COA_OK) {
        return COA_ERR_ARGUMENT;
    }
    return crypto_sign_keypair(public_key, secret_key) == 0 ? COA_OK : COA_ERR_ARGUMENT;
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
    t->last_timestamp[t->count] = INT64_MIN;
    t->last_sequence[t->count] = INT64_MIN;
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

int coavoid_auth_sign(const coavoid_auth_signer_t *s, unsigned char *datagram, size_t size)
{
    if (s == NULL || datagram == NULL || size < COAVOID_AUTH_TAIL_BYTES + 8u) {
        return COA_ERR_ARGUMENT;
    }
    const size_t signed_size = size - COAVOID_AUTH_SIGNATURE_BYTES;
    return crypto_sign_detached(datagram + signed_size, NULL, datagram, signed_size,
                                s->secret_key) == 0
               ? COA_OK
               : COA_ERR_ARGUMENT;
}

/* The key_id of a datagram's auth_t: the 4 big-endian bytes before its two int64s and
 * its signature. */
static uint32_t datagram_key_id(const unsigned char *datagram, size_t size)
{
    const unsigned char *p = datagram + size - COAVOID_AUTH_TAIL_BYTES;
    return (uint32_t)p[0] << 24 | (uint32_t)p[1] << 16 | (uint32_t)p[2] << 8 | (uint32_t)p[3];
}

int coavoid_auth_verify(const coavoid_auth_trust_t *t, const unsigned char *datagram, size_t size,
                        size_t *key)
{
    if (t == NULL || datagram == NULL || key == NULL || size < COAVOID_AUTH_TAIL_BYTES + 8u) {
        return COAVOID_AUTH_ERR_UNSIGNED;
    }
    const uint32_t id = datagram_key_id(datagram, size);
    if (id == 0u) {
        return COAVOID_AUTH_ERR_UNSIGNED;
    }
    size_t i = 0;
    while (i < t->count && t->keys[i].key_id != id) {
        i++;
    }
    if (i == t->count) {
        return COAVOID_AUTH_ERR_KEY;
    }
    const size_t signed_size = size - COAVOID_AUTH_SIGNATURE_BYTES;
    if (crypto_sign_verify_detached(datagram + signed_size, datagram, signed_size,
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

int coavoid_auth_fresh(coavoid_auth_trust_t *t, size_t key, int64_t timestamp_us, int64_t sequence,
                       int64_t now, int64_t window_us)
{
    if (t == NULL || key >= t->count) {
        return COAVOID_AUTH_ERR_REPLAY;
    }
    if (timestamp_us < now - window_us || timestamp_us > now + window_us) {
        return COAVOID_AUTH_ERR_CLOCK;
    }
    if (timestamp_us < t->last_timestamp[key] ||
        (timestamp_us == t->last_timestamp[key] && sequence <= t->last_sequence[key])) {
        return COAVOID_AUTH_ERR_REPLAY;
    }
    t->last_timestamp[key] = timestamp_us;
    t->last_sequence[key] = sequence;
    return COA_OK;
}
