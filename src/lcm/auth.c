/* SPDX-License-Identifier: MIT */
/* Signed messages (auth.h). */
#include "auth.h"

#include <stdio.h>
#include <string.h>

#include <sodium.h>

#include "coavoid/common.h"

_Static_assert(crypto_sign_BYTES == COAVOID_AUTH_SIGNATURE_BYTES, "an Ed25519 signature");
_Static_assert(crypto_sign_PUBLICKEYBYTES == COAVOID_AUTH_PUBLIC_BYTES, "an Ed25519 public key");
_Static_assert(crypto_sign_SECRETKEYBYTES == COAVOID_AUTH_SECRET_BYTES, "an Ed25519 secret key");
_Static_assert(crypto_shorthash_KEYBYTES == COAVOID_AUTH_FLEET_KEY_BYTES, "a SipHash-2-4 key");
_Static_assert(crypto_shorthash_BYTES == COAVOID_AUTH_TAG_BYTES, "a SipHash-2-4 output");

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

int coavoid_auth_keypair_seed(const unsigned char seed[COAVOID_AUTH_SEED_BYTES],
                              unsigned char public_key[COAVOID_AUTH_PUBLIC_BYTES],
                              unsigned char secret_key[COAVOID_AUTH_SECRET_BYTES])
{
    if (seed == NULL || public_key == NULL || secret_key == NULL || coavoid_auth_init() != COA_OK) {
        return COA_ERR_ARGUMENT;
    }
    return crypto_sign_seed_keypair(public_key, secret_key, seed) == 0 ? COA_OK : COA_ERR_ARGUMENT;
}

int coavoid_auth_fleet_key(unsigned char key[COAVOID_AUTH_FLEET_KEY_BYTES])
{
    if (key == NULL || coavoid_auth_init() != COA_OK) {
        return COA_ERR_ARGUMENT;
    }
    crypto_shorthash_keygen(key);
    return COA_OK;
}

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
    (void)crypto_shorthash(tag, datagram, tagged, key);
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
    if (crypto_sign_detached(datagram + signed_size, NULL, datagram, signed_size, s->secret_key) !=
        0) {
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

static const char *const ROLE_NAMES[4] = {NULL, "coordinator", "world", "vehicle"};

static int fail_line(char *err, size_t err_size, size_t line, const char *why)
{
    if (err != NULL && err_size > 0u) {
        snprintf(err, err_size, "line %zu: %s", line, why);
    }
    return COA_ERR_ARGUMENT;
}

/* The next line of text[*at..length) into buf (at most COAVOID_AUTH_LINE_MAX - 1 bytes,
 * without its newline); false at the end. *too_long when it did not fit. */
static bool next_line(const char *text, size_t length, size_t *at, char *buf, bool *too_long)
{
    if (*at >= length) {
        return false;
    }
    size_t n = 0;
    *too_long = false;
    while (*at < length && text[*at] != '\n') {
        if (n + 1u < COAVOID_AUTH_LINE_MAX) {
            buf[n++] = text[*at];
        } else {
            *too_long = true;
        }
        (*at)++;
    }
    (*at)++;
    buf[n] = '\0';
    return true;
}

/* Whether hex is exactly 2 * size hex digits; then its bytes are in out. */
static bool hex_bytes(const char *hex, unsigned char *out, size_t size)
{
    size_t bin_len = 0;
    return strlen(hex) == 2u * size &&
           sodium_hex2bin(out, size, hex, 2u * size, NULL, &bin_len, NULL) == 0 && bin_len == size;
}

static bool role_of(const char *name, coavoid_auth_role_t *role)
{
    for (int r = COAVOID_AUTH_COORDINATOR; r <= COAVOID_AUTH_VEHICLE; r++) {
        if (strcmp(name, ROLE_NAMES[r]) == 0) {
            *role = (coavoid_auth_role_t)r;
            return true;
        }
    }
    return false;
}

/* One trust line's fields into key. */
static const char *trust_line(const char *line, coavoid_auth_key_t *key)
{
    char role[16], hex[80], extra[2];
    unsigned long id = 0, node = 0;
    memset(key, 0, sizeof *key);
    if (sscanf(line, "%lu %15s %lu %79s %1s", &id, role, &node, hex, extra) != 4) {
        return "expected KEY_ID ROLE NODE_ID PUBLIC_KEY_HEX";
    }
    if (id < 1u || id > (unsigned long)INT32_MAX || node < 1u || node > 65535u) {
        return "KEY_ID must be in 1..2147483647 and NODE_ID in 1..65535";
    }
    if (!role_of(role, &key->role)) {
        return "ROLE must be coordinator, world or vehicle";
    }
    if (!hex_bytes(hex, key->public_key, COAVOID_AUTH_PUBLIC_BYTES)) {
        return "PUBLIC_KEY_HEX must be 64 hex digits";
    }
    key->key_id = (uint32_t)id;
    key->node_id = (uint16_t)node;
    return NULL;
}

/* A fleet line's key (after the word "fleet") into t. */
static const char *fleet_line(const char *rest, coavoid_auth_trust_t *t)
{
    char hex[80], extra[2];
    unsigned char key[COAVOID_AUTH_FLEET_KEY_BYTES];
    if (t->has_fleet_key) {
        return "a second fleet line";
    }
    if (sscanf(rest, "%79s %1s", hex, extra) != 1 ||
        !hex_bytes(hex, key, COAVOID_AUTH_FLEET_KEY_BYTES)) {
        sodium_memzero(hex, sizeof hex);
        return "expected fleet FLEET_KEY_HEX (32 hex digits)";
    }
    (void)coavoid_auth_trust_set_fleet_key(t, key);
    sodium_memzero(hex, sizeof hex);
    sodium_memzero(key, sizeof key);
    return NULL;
}

int coavoid_auth_trust_parse(coavoid_auth_trust_t *t, const char *text, size_t length, char *err,
                             size_t err_size)
{
    char line[COAVOID_AUTH_LINE_MAX];
    size_t at = 0, number = 0;
    bool too_long = false;
    if (t == NULL || text == NULL) {
        return fail_line(err, err_size, 0, "no text");
    }
    coavoid_auth_trust_init(t);
    while (next_line(text, length, &at, line, &too_long)) {
        number++;
        const char *p = line + strspn(line, " \t\r");
        if (too_long) {
            return fail_line(err, err_size, number, "longer than 255 characters");
        }
        if (*p == '\0' || *p == '#') {
            continue;
        }
        if (strncmp(p, "fleet", 5) == 0 && (p[5] == ' ' || p[5] == '\t')) {
            const char *why = fleet_line(p + 5, t);
            if (why != NULL) {
                return fail_line(err, err_size, number, why);
            }
            continue;
        }
        coavoid_auth_key_t key;
        const char *why = trust_line(p, &key);
        if (why != NULL) {
            return fail_line(err, err_size, number, why);
        }
        if (coavoid_auth_trust_add(t, &key) != COA_OK) {
            return fail_line(err, err_size, number, "KEY_ID repeated, or more than 128 keys");
        }
    }
    return COA_OK;
}

int coavoid_auth_signer_parse(coavoid_auth_signer_t *s, const char *text, size_t length, char *err,
                              size_t err_size)
{
    char line[COAVOID_AUTH_LINE_MAX], hex[160], extra[2];
    size_t at = 0;
    bool too_long = false;
    unsigned long id = 0;
    if (s == NULL || text == NULL || !next_line(text, length, &at, line, &too_long) || too_long) {
        return fail_line(err, err_size, 1, "expected one line of at most 255 characters");
    }
    memset(s, 0, sizeof *s);
    if (sscanf(line, "coavoid-secret-key %lu %159s %1s", &id, hex, extra) != 2 || id < 1u ||
        id > (unsigned long)INT32_MAX) {
        return fail_line(err, err_size, 1, "expected coavoid-secret-key KEY_ID SECRET_KEY_HEX");
    }
    if (!hex_bytes(hex, s->secret_key, COAVOID_AUTH_SECRET_BYTES)) {
        return fail_line(err, err_size, 1, "SECRET_KEY_HEX must be 128 hex digits");
    }
    s->key_id = (uint32_t)id;
    return COA_OK;
}

int coavoid_auth_key_line(const coavoid_auth_key_t *k, char *out, size_t size)
{
    char hex[2u * COAVOID_AUTH_PUBLIC_BYTES + 1u];
    if (k == NULL || out == NULL || k->role < COAVOID_AUTH_COORDINATOR ||
        k->role > COAVOID_AUTH_VEHICLE) {
        return COA_ERR_ARGUMENT;
    }
    sodium_bin2hex(hex, sizeof hex, k->public_key, COAVOID_AUTH_PUBLIC_BYTES);
    int n = snprintf(out, size, "%lu %s %u %s\n", (unsigned long)k->key_id, ROLE_NAMES[k->role],
                     (unsigned)k->node_id, hex);
    return n > 0 && (size_t)n < size ? COA_OK : COA_ERR_ARGUMENT;
}

int coavoid_auth_signer_line(const coavoid_auth_signer_t *s, char *out, size_t size)
{
    char hex[2u * COAVOID_AUTH_SECRET_BYTES + 1u];
    if (s == NULL || out == NULL) {
        return COA_ERR_ARGUMENT;
    }
    sodium_bin2hex(hex, sizeof hex, s->secret_key, COAVOID_AUTH_SECRET_BYTES);
    int n = snprintf(out, size, "coavoid-secret-key %lu %s\n", (unsigned long)s->key_id, hex);
    sodium_memzero(hex, sizeof hex);
    return n > 0 && (size_t)n < size ? COA_OK : COA_ERR_ARGUMENT;
}

int coavoid_auth_fleet_line(const unsigned char key[COAVOID_AUTH_FLEET_KEY_BYTES], char *out,
                            size_t size)
{
    char hex[2u * COAVOID_AUTH_FLEET_KEY_BYTES + 1u];
    if (key == NULL || out == NULL) {
        return COA_ERR_ARGUMENT;
    }
    sodium_bin2hex(hex, sizeof hex, key, COAVOID_AUTH_FLEET_KEY_BYTES);
    int n = snprintf(out, size, "fleet %s\n", hex);
    sodium_memzero(hex, sizeof hex);
    return n > 0 && (size_t)n < size ? COA_OK : COA_ERR_ARGUMENT;
}
