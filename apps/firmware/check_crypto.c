/* SPDX-License-Identifier: MIT */
/*
 * check_crypto.c: the message checks of docs/messages.md on the part (check.c runs it when
 * the cross build has libsodium, cmake/libsodium_arm.cmake), counted with check_io.h's
 * clock: the fleet tag (SipHash-2-4), an Ed25519 signature, its verification, and the
 * verification of a datagram with one byte changed, each over a heartbeat (192 bytes) and
 * an intent (1,398 bytes), the smallest and a large datagram a vehicle checks every cycle.
 *
 * The datagrams, the key seed and the fleet key are fixed patterns (byte i of each below),
 * so tests/firmware/qemu_compare.py computes the same tag and signature with the host's
 * libsodium and compares them with these lines:
 *   crypto tag BYTES HEX ticks T           the tag over the datagram's first BYTES - 8
 *   crypto sign BYTES HEX ticks T          the signature over its first BYTES - 72
 *   crypto verify BYTES rc RC ticks T      RC 0: the signature verifies
 *   crypto refuse BYTES rc RC ticks T      the same with one signed byte changed: RC -1
 * then the drivers' own path (src/auth/auth.c) on an intent:
 *   crypto stamp BYTES rc 0 ticks T        a vehicle's signer stamps, signs and tags it
 *   crypto check BYTES rc 0 ticks T        a receiver's precheck (tail, tag) and verify
 *   crypto outsider BYTES rc -126 ticks T  an outsider's copy, refused by the tag
 * and, before them, `crypto memory trust BYTES signer BYTES`: the structs' sizes on the part.
 */
#include <stdbool.h>
#include <stdint.h>
#include <string.h>

#include <sodium/crypto_shorthash_siphash24.h>
#include <sodium/crypto_sign_ed25519.h>

#include "auth.h"
#include "check_crypto.h"
#include "coavoid/common.h"
#include "check_io.h"
#include "check_messages.h"

#define CRYPTO_TAG_BYTES 8u
#define CRYPTO_SIGNATURE_BYTES 64u
#define CRYPTO_LARGEST 1398u
#define CRYPTO_KEY_ID 101u /* UAV 1's, as coavoid keygen numbers it */

static unsigned char public_key[crypto_sign_ed25519_PUBLICKEYBYTES];
static unsigned char secret_key[crypto_sign_ed25519_SECRETKEYBYTES];
static unsigned char fleet_key[crypto_shorthash_siphash24_KEYBYTES];

static void fill(unsigned char *bytes, size_t n, unsigned multiplier, unsigned offset)
{
    for (size_t i = 0; i < n; ++i) {
        bytes[i] = (unsigned char)((i * multiplier + offset) & 0xffu);
    }
}

static void put_result(const char *what, size_t bytes)
{
    fwc_put("crypto ");
    fwc_put(what);
    fwc_put(" ");
    fwc_put_u64(bytes);
}

static void put_ticks(uint64_t ticks)
{
    fwc_put(" ticks ");
    fwc_put_u64(ticks);
    fwc_end_line();
}

void fwc_crypto_line(const char *what, size_t bytes, int64_t rc, uint64_t ticks)
{
    put_result(what, bytes);
    fwc_put(" rc ");
    fwc_put_i64(rc);
    put_ticks(ticks);
}

/* Verifies the signature of a datagram of `bytes` bytes and reports it as `what`; its rc. */
static int verify_counted(const char *what, const unsigned char *datagram, size_t bytes)
{
    const size_t signed_size = bytes - CRYPTO_TAG_BYTES - CRYPTO_SIGNATURE_BYTES;
    const uint64_t start = fwc_ticks_now();
    const int rc = crypto_sign_ed25519_verify_detached(datagram + signed_size, datagram,
                                                       signed_size, public_key);
    fwc_crypto_line(what, bytes, rc, fwc_ticks_now() - start);
    return rc;
}

/* Tags, signs and verifies one datagram of `bytes` bytes in place; false on a wrong result. */
static bool check_size(unsigned char *datagram, size_t bytes)
{
    const size_t tagged = bytes - CRYPTO_TAG_BYTES;
    const size_t signed_size = tagged - CRYPTO_SIGNATURE_BYTES;
    unsigned char *const signature = datagram + signed_size;
    fill(datagram, bytes, 7u, 3u);

    uint64_t start = fwc_ticks_now();
    crypto_sign_ed25519_detached(signature, NULL, datagram, signed_size, secret_key);
    uint64_t ticks = fwc_ticks_now() - start;
    put_result("sign", bytes);
    fwc_put(" ");
    fwc_put_hex(signature, CRYPTO_SIGNATURE_BYTES);
    put_ticks(ticks);

    start = fwc_ticks_now();
    crypto_shorthash_siphash24(datagram + tagged, datagram, tagged, fleet_key);
    ticks = fwc_ticks_now() - start;
    put_result("tag", bytes);
    fwc_put(" ");
    fwc_put_hex(datagram + tagged, CRYPTO_TAG_BYTES);
    put_ticks(ticks);

    const int good = verify_counted("verify", datagram, bytes);
    datagram[signed_size / 2u] ^= 0x01u;
    const int bad = verify_counted("refuse", datagram, bytes);
    return good == 0 && bad == -1;
}

/* The drivers' own path on the part (src/auth/auth.c): an intent stamped by a vehicle's
 * signer (its numbers, the signature, the fleet tag) is checked by a receiver's trust list
 * of that key, its tail and tag (coavoid_auth_precheck) then its signature
 * (coavoid_auth_verify); an outsider's copy of it, with a later stamp and the signature
 * broken, is refused by the tag. The trust list and the datagram are built in scratch. */
typedef struct {
    coavoid_auth_trust_t trust;
    unsigned char datagram[CRYPTO_LARGEST];
} auth_scratch_t;

static int check_counted(const char *what, const coavoid_auth_trust_t *trust,
                         const unsigned char *datagram, size_t bytes)
{
    const coavoid_auth_expect_t expect = {COAVOID_AUTH_STREAM_INTENT, COAVOID_AUTH_VEHICLE,
                                          FWC_NOW_US, FWC_MAX_AGE_US, FWC_MAX_AGE_US};
    size_t key = 0;
    const uint64_t start = fwc_ticks_now();
    int rc = coavoid_auth_precheck(trust, datagram, bytes, &expect, &key);
    if (rc == COA_OK) {
        rc = coavoid_auth_verify(trust, datagram, bytes, &key);
    }
    fwc_crypto_line(what, bytes, rc, fwc_ticks_now() - start);
    return rc;
}

static bool check_drivers_path(auth_scratch_t *s, size_t size)
{
    coavoid_auth_trust_init(&s->trust);
    coavoid_auth_key_t key = {CRYPTO_KEY_ID, COAVOID_AUTH_VEHICLE, 1u, {0}};
    memcpy(key.public_key, public_key, sizeof key.public_key);
    coavoid_auth_signer_t signer;
    memset(&signer, 0, sizeof signer);
    signer.key_id = CRYPTO_KEY_ID;
    memcpy(signer.secret_key, secret_key, sizeof signer.secret_key);
    if (coavoid_auth_trust_add(&s->trust, &key) != COA_OK ||
        coavoid_auth_trust_set_fleet_key(&s->trust, fleet_key) != COA_OK) {
        return false;
    }
    coavoid_auth_signer_use_fleet(&signer, &s->trust);
    fwc_put("crypto memory trust ");
    fwc_put_u64(sizeof s->trust);
    fwc_put(" signer ");
    fwc_put_u64(sizeof signer);
    fwc_end_line();
    fill(s->datagram, CRYPTO_LARGEST, 7u, 3u);
    const uint64_t start = fwc_ticks_now();
    const int stamped = coavoid_auth_stamp(&signer, FWC_NOW_US, s->datagram, CRYPTO_LARGEST);
    fwc_crypto_line("stamp", CRYPTO_LARGEST, stamped, fwc_ticks_now() - start);
    const int good = check_counted("check", &s->trust, s->datagram, CRYPTO_LARGEST);
    /* The outsider: a later stamp, a signature byte flipped, the tag as it was. */
    s->datagram[CRYPTO_LARGEST - COAVOID_AUTH_TAIL_BYTES + 11u] ^= 0x01u;
    s->datagram[CRYPTO_LARGEST - COAVOID_AUTH_TAG_BYTES - 1u] ^= 0x5au;
    const int outsider = check_counted("outsider", &s->trust, s->datagram, CRYPTO_LARGEST);
    bool messages = true;
#ifdef COAVOID_FW_MESSAGES
    /* The rest of scratch, past the trust list, 16-byte aligned. */
    const size_t used = (sizeof *s + 15u) & ~(size_t)15u;
    messages =
        size > used && fwc_messages_run((unsigned char *)s + used, size - used, &signer, &s->trust);
#else
    (void)size;
#endif
    coavoid_auth_signer_clear(&signer);
    return stamped == COA_OK && good == COA_OK && outsider == COAVOID_AUTH_ERR_TAG && messages;
}

bool fwc_crypto_run(unsigned char *scratch, size_t size)
{
    if (size < sizeof(auth_scratch_t)) {
        fwc_put("error crypto: the scratch buffer is too small");
        fwc_end_line();
        return false;
    }
    unsigned char seed[crypto_sign_ed25519_SEEDBYTES];
    fill(seed, sizeof seed, 1u, 0u);
    fill(fleet_key, sizeof fleet_key, 1u, 0x10u);
    if (crypto_sign_ed25519_seed_keypair(public_key, secret_key, seed) != 0) {
        fwc_put("error crypto: no key pair from the seed");
        fwc_end_line();
        return false;
    }
    const bool heartbeat = check_size(scratch, 192u);
    const bool intent = check_size(scratch, CRYPTO_LARGEST);
    /* scratch is the planner's buffer, aligned for any type. */
    const bool drivers = check_drivers_path((auth_scratch_t *)(void *)scratch, size);
    if (!drivers) {
        fwc_put("error crypto: the drivers' checks gave a wrong result");
        fwc_end_line();
    }
    return heartbeat && intent && drivers;
}
