/* SPDX-License-Identifier: MIT */
/*
 * auth_files.c: keys made and read on the ground (auth.h): key pairs and the fleet key
 * from libsodium's random numbers, and the trust and secret key files' text. The drivers,
 * `coavoid keygen` and the tests use it; the firmware does not (it is given its keys).
 */
#include "auth.h"

#include <stdio.h>
#include <string.h>

#include <sodium.h>

#include "coavoid/common.h"

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
    return crypto_sign_ed25519_keypair(public_key, secret_key) == 0 ? COA_OK : COA_ERR_ARGUMENT;
}

int coavoid_auth_keypair_seed(const unsigned char seed[COAVOID_AUTH_SEED_BYTES],
                              unsigned char public_key[COAVOID_AUTH_PUBLIC_BYTES],
                              unsigned char secret_key[COAVOID_AUTH_SECRET_BYTES])
{
    if (seed == NULL || public_key == NULL || secret_key == NULL || coavoid_auth_init() != COA_OK) {
        return COA_ERR_ARGUMENT;
    }
    return crypto_sign_ed25519_seed_keypair(public_key, secret_key, seed) == 0 ? COA_OK
                                                                               : COA_ERR_ARGUMENT;
}

int coavoid_auth_fleet_key(unsigned char key[COAVOID_AUTH_FLEET_KEY_BYTES])
{
    if (key == NULL || coavoid_auth_init() != COA_OK) {
        return COA_ERR_ARGUMENT;
    }
    randombytes_buf(key, COAVOID_AUTH_FLEET_KEY_BYTES);
    return COA_OK;
}

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
