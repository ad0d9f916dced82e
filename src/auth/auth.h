/* SPDX-License-Identifier: MIT */
/*
 * auth.h: signed messages. Every message type ends with an auth_t (lcmtypes/auth_t.lcm):
 * the sender's key id, its clock when it signed, a sequence, an Ed25519 signature and the
 * fleet's tag. As the last field of every type it is the last COAVOID_AUTH_TAIL_BYTES of
 * every datagram, the tag the last COAVOID_AUTH_TAG_BYTES and the signature the
 * COAVOID_AUTH_SIGNATURE_BYTES before it, so that signing and checking work on the
 * datagram's bytes whatever its type:
 *
 *   signed bytes = the datagram before its signature: the type's fingerprint, every field
 *                  in LCM's encoding, then key_id, timestamp_us and sequence;
 *   tagged bytes = the datagram before its tag: the signed bytes and the signature.
 *
 * (docs/messages.md, "Signed messages", defines it for other implementations.) The
 * fingerprint binds the type, and with it the channel, since each type has one.
 *
 * A receiver holds a trust list: the public keys it accepts, each with the role it may
 * speak for (the coordinator, the world, or one vehicle by id), and the fleet's key.
 * coavoid_auth_precheck refuses what a datagram's tail and tag rule out, for the cost of
 * a key lookup and one keyed hash; coavoid_auth_verify checks its signature against the
 * key its key_id names; coavoid_auth_fresh then accepts it only when it is newer than the
 * last accepted from that key (timestamp, then sequence) and within a window of the
 * receiver's clock, so a copied or replayed message is refused, and a sender that
 * restarts (a later clock, its sequence from 0) is accepted at once: nobody is locked out.
 *
 * Two keys, two questions. The fleet key, shared by every node of the fleet, answers "is
 * this from inside the fleet?" cheaply, so that an outsider's flood costs a receiver a
 * hash instead of a signature check; it cannot tell one member from another. The
 * per-sender Ed25519 key answers "which member?", so that no vehicle can speak for
 * another or for the coordinator. A trust list without a fleet key neither writes nor
 * checks tags (each is zero).
 *
 * Ed25519 by libsodium (crypto_sign_ed25519_detached / _verify_detached); the tag is
 * SipHash-2-4 (crypto_shorthash_siphash24: a 16-byte key, an 8-byte output). Memory: the
 * caller's structs; nothing is allocated. Cost: one signature or verification over the
 * datagram (tens of microseconds on a PC, milliseconds on a Cortex-M4F), one keyed hash
 * (under a microsecond on a PC; docs/benchmarks.md, docs/embedded.md).
 *
 * Two parts. Signing and checking (auth.c) use no stdio, no heap, no clock and no random
 * numbers: the same code runs in the Linux drivers and on the part. Making keys and
 * reading and writing their files (coavoid_auth_init, _keypair, _keypair_seed,
 * _fleet_key, the _parse and _line functions: auth_files.c) is for the ground, and only
 * the host build has it.
 */
#ifndef COAVOID_AUTH_H
#define COAVOID_AUTH_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#define COAVOID_AUTH_SIGNATURE_BYTES 64u
#define COAVOID_AUTH_TAG_BYTES 8u
#define COAVOID_AUTH_TAIL_BYTES \
    (4u + 8u + 8u + COAVOID_AUTH_SIGNATURE_BYTES + COAVOID_AUTH_TAG_BYTES)
#define COAVOID_AUTH_FLEET_KEY_BYTES 16u
#define COAVOID_AUTH_PUBLIC_BYTES 32u
#define COAVOID_AUTH_SECRET_BYTES 64u
/* Keys one receiver trusts: a coordinator, a world and every UAV a node holds, with room.
 * A build may set fewer (a part's trust list holds its own fleet only: the cross build's
 * is 16, 2,456 bytes on the Cortex-M4F); every translation unit of a build must agree. */
#ifndef COAVOID_AUTH_MAX_KEYS
#define COAVOID_AUTH_MAX_KEYS 128u
#endif
/* Freshness is kept per key and per stream (one stream per message type, numbered by the
 * caller: COAVOID_AUTH_STREAM_*), since UDP may reorder one sender's datagrams of
 * different types, and a heartbeat overtaken by the intent sent after it is no replay. */
#define COAVOID_AUTH_STREAMS 7u
#define COAVOID_AUTH_STREAM_INTENT 0u
#define COAVOID_AUTH_STREAM_PLAN 1u
#define COAVOID_AUTH_STREAM_TRACK 2u
#define COAVOID_AUTH_STREAM_MAP 3u
#define COAVOID_AUTH_STREAM_CONFLICTS 4u
#define COAVOID_AUTH_STREAM_STATUS 5u
#define COAVOID_AUTH_STREAM_AGREEMENT 6u

/* What a key may speak for. */
typedef enum {
    COAVOID_AUTH_COORDINATOR = 1, /* plans, the conflict report and coordinator heartbeats */
    COAVOID_AUTH_WORLD = 2,       /* obstacle maps and tracks */
    COAVOID_AUTH_VEHICLE = 3      /* the intents and heartbeats of one UAV (node_id) */
} coavoid_auth_role_t;

/* A fleet's key ids, as `coavoid keygen` writes them and `coavoid sim` uses them: any
 * numbering works as long as each is unique in a trust list. */
#define COAVOID_AUTH_KEY_ID_COORDINATOR 1u
#define COAVOID_AUTH_KEY_ID_WORLD 2u
#define COAVOID_AUTH_KEY_ID_VEHICLE_BASE 100u /* + the UAV's id */

typedef struct {
    uint32_t key_id; /* 1..2^31-1, unique in a trust list */
    coavoid_auth_role_t role;
    uint16_t node_id; /* the node it speaks for: a UAV's id, the coordinator's, the world's */
    unsigned char public_key[COAVOID_AUTH_PUBLIC_BYTES];
} coavoid_auth_key_t;

/* A receiver's trust list, the fleet's key and, per key and stream, the newest message
 * accepted from it (20,000 bytes on x86-64). */
typedef struct {
    coavoid_auth_key_t keys[COAVOID_AUTH_MAX_KEYS];
    size_t count;
    bool has_fleet_key; /* tags are written and checked */
    unsigned char fleet_key[COAVOID_AUTH_FLEET_KEY_BYTES];
    int64_t last_timestamp[COAVOID_AUTH_MAX_KEYS][COAVOID_AUTH_STREAMS];
    int64_t last_sequence[COAVOID_AUTH_MAX_KEYS][COAVOID_AUTH_STREAMS];
} coavoid_auth_trust_t;

/* A sender's key, the fleet's key it tags with (coavoid_auth_signer_use_fleet), and the
 * numbers of its next signature. */
typedef struct {
    uint32_t key_id;
    unsigned char secret_key[COAVOID_AUTH_SECRET_BYTES];
    bool has_fleet_key;
    unsigned char fleet_key[COAVOID_AUTH_FLEET_KEY_BYTES];
    int64_t last_timestamp;
    int64_t sequence;
} coavoid_auth_signer_t;

/* Errors beyond the core's (COA_ERR_*): negative, after COAVOID_LCM_ERR_* (-100..-109). */
#define COAVOID_AUTH_ERR_UNSIGNED (-120)  /* key_id 0, or too short to carry an auth_t */
#define COAVOID_AUTH_ERR_KEY (-121)       /* key_id not in the trust list */
#define COAVOID_AUTH_ERR_SIGNATURE (-122) /* the signature does not verify */
#define COAVOID_AUTH_ERR_ROLE (-123)      /* the key may not send this (role or node) */
#define COAVOID_AUTH_ERR_REPLAY (-124)    /* not newer than the last from that key */
#define COAVOID_AUTH_ERR_CLOCK (-125)     /* timestamp outside the receiver's window */
#define COAVOID_AUTH_ERR_TAG (-126)       /* the fleet tag does not match: not from the fleet */

/* Initialises libsodium; on the host, call once before anything else here (thread-safe,
 * idempotent; the part's portable build needs none). Returns COA_OK or COA_ERR_ARGUMENT
 * when the library cannot start. */
int coavoid_auth_init(void);

/* A new key pair from the system's random source. Returns COA_OK or COA_ERR_ARGUMENT. */
int coavoid_auth_keypair(unsigned char public_key[COAVOID_AUTH_PUBLIC_BYTES],
                         unsigned char secret_key[COAVOID_AUTH_SECRET_BYTES]);

/* The key pair derived from a 32-byte seed (libsodium's crypto_sign_seed_keypair): the
 * same seed, the same keys. For repeatable simulations and tests only: a flying node's
 * keys come from coavoid_auth_keypair. Returns COA_OK or COA_ERR_ARGUMENT. */
#define COAVOID_AUTH_SEED_BYTES 32u
int coavoid_auth_keypair_seed(const unsigned char seed[COAVOID_AUTH_SEED_BYTES],
                              unsigned char public_key[COAVOID_AUTH_PUBLIC_BYTES],
                              unsigned char secret_key[COAVOID_AUTH_SECRET_BYTES]);

/* A new fleet key from the system's random source. Returns COA_OK or COA_ERR_ARGUMENT. */
int coavoid_auth_fleet_key(unsigned char key[COAVOID_AUTH_FLEET_KEY_BYTES]);

/* Gives t the fleet key: from then on coavoid_auth_precheck requires every datagram's tag.
 * Returns COA_OK or COA_ERR_ARGUMENT (NULL). */
int coavoid_auth_trust_set_fleet_key(coavoid_auth_trust_t *t,
                                     const unsigned char key[COAVOID_AUTH_FLEET_KEY_BYTES]);

/* s tags what it signs with t's fleet key, or with none when t has none. O(1). */
void coavoid_auth_signer_use_fleet(coavoid_auth_signer_t *s, const coavoid_auth_trust_t *t);

/* Empties a trust list; adds a key (COA_ERR_ARGUMENT: list full, key_id 0 or repeated). */
void coavoid_auth_trust_init(coavoid_auth_trust_t *t);
int coavoid_auth_trust_add(coavoid_auth_trust_t *t, const coavoid_auth_key_t *key);

/* The auth_t numbers of the next message signed with s at the sender's clock `now`
 * (microseconds): its key_id, now (or one more than the last, when the clock did not
 * move on), and a sequence that starts again at 0 with each new timestamp. O(1). */
void coavoid_auth_next(coavoid_auth_signer_t *s, int64_t now, int32_t *key_id,
                       int64_t *timestamp_us, int64_t *sequence);

/* Whether t lists s's key as speaking for (role, node_id), with the public key that s's
 * secret key gives: a node checks at start that its key file is its own. COA_OK,
 * COAVOID_AUTH_ERR_KEY (not listed, or another public key) or COAVOID_AUTH_ERR_ROLE.
 * O(keys). */
int coavoid_auth_signer_matches(const coavoid_auth_trust_t *t, const coavoid_auth_signer_t *s,
                                coavoid_auth_role_t role, uint16_t node_id);

/* Zeroes s, its secret key in a way the compiler keeps (sodium_memzero): for a signer
 * that goes out of use. NULL is fine. O(1). */
void coavoid_auth_signer_clear(coavoid_auth_signer_t *s);

/* Signs an encoded datagram of `size` bytes whose auth_t already holds the signer's
 * key_id and numbers (coavoid_auth_next): writes the signature, then the fleet tag (zero
 * when s has no fleet key). Returns COA_OK or COA_ERR_ARGUMENT (NULL, or too short to end
 * with an auth_t). */
int coavoid_auth_sign(const coavoid_auth_signer_t *s, unsigned char *datagram, size_t size);

/* Stamps and signs an encoded datagram of `size` bytes in place, whatever its type: writes
 * the next numbers of s at `now` (coavoid_auth_next) into its auth_t, big-endian as LCM
 * encodes them, then the signature (coavoid_auth_sign). So a publisher needs no access to
 * the message's struct. Returns COA_OK or COA_ERR_ARGUMENT (NULL, or too short); s's
 * numbers move on only on success. Cost: one Ed25519 signature over size - 72 bytes and
 * one keyed hash over size - 8. */
int coavoid_auth_stamp(coavoid_auth_signer_t *s, int64_t now, unsigned char *datagram, size_t size);

/* What a receiver expects of a datagram on one channel, for coavoid_auth_precheck: its
 * stream, the role its key must have (COAVOID_AUTH_ANY_ROLE where the message names it,
 * as a heartbeat does), and the freshness window at the receiver's clock. */
#define COAVOID_AUTH_ANY_ROLE ((coavoid_auth_role_t)0)
typedef struct {
    size_t stream;
    coavoid_auth_role_t role;
    int64_t now;
    int64_t max_age_us;
    int64_t max_ahead_us;
} coavoid_auth_expect_t;

/* The checks a datagram allows before its signature, so that a copy, a replay or an
 * outsider's datagram costs a receiver a key lookup and a hash instead of a signature
 * check (docs/security.md, "Floods"). From the tail alone: signed and long enough, its
 * key_id in t, that key's role the expected one, and its (timestamp, sequence) fresh on
 * the stream as coavoid_auth_fresh would find it, without marking it; then, when t has a
 * fleet key, the tag (coavoid_auth_tag_check). COA_OK with *key (its index in t), or the
 * COAVOID_AUTH_ERR_* of the first check that failed. O(keys) and one keyed hash over the
 * datagram; no memory. */
int coavoid_auth_precheck(const coavoid_auth_trust_t *t, const unsigned char *datagram, size_t size,
                          const coavoid_auth_expect_t *expect, size_t *key);

/* Whether a datagram's tag is the fleet's: COA_OK (or t has no fleet key), or
 * COAVOID_AUTH_ERR_TAG (also too short). Constant time in the tag. One keyed hash. */
int coavoid_auth_tag_check(const coavoid_auth_trust_t *t, const unsigned char *datagram,
                           size_t size);

/* Checks a received datagram's signature against the key its key_id names in t. Returns
 * COA_OK with *key (its index in t) or a COAVOID_AUTH_ERR_*; reads only the datagram. */
int coavoid_auth_verify(const coavoid_auth_trust_t *t, const unsigned char *datagram, size_t size,
                        size_t *key);

/* Whether key `key` of t may send as `role` for node `node_id` (0: any node of the role,
 * for types without a sender id). COA_OK or COAVOID_AUTH_ERR_ROLE. O(1). */
int coavoid_auth_may_send(const coavoid_auth_trust_t *t, size_t key, coavoid_auth_role_t role,
                          uint16_t node_id);

/* Accepts the (timestamp, sequence) of a verified message of `stream`
 * (< COAVOID_AUTH_STREAMS) from key `key` at the receiver's clock `now`: it must be at
 * most max_age_us old and max_ahead_us ahead of now (clock skew: keep it small, or a
 * replayed message from a clock running ahead would lock its sender out until then), and
 * after the last accepted from that key on that stream (a later timestamp, or the same
 * with a larger sequence); then it becomes the last. COA_OK, COAVOID_AUTH_ERR_CLOCK or
 * COAVOID_AUTH_ERR_REPLAY (also for a bad key or stream). O(1). */
int coavoid_auth_fresh(coavoid_auth_trust_t *t, size_t key, size_t stream, int64_t timestamp_us,
                       int64_t sequence, int64_t now, int64_t max_age_us, int64_t max_ahead_us);

/* What a receiver checks once coavoid_auth_verify found the datagram's key `key` and the
 * message decoded: the key may send as `role` for the sender id the message names (any
 * int32: outside 1..65535 it may not: COAVOID_AUTH_ERR_ROLE), and the message is fresh
 * on its stream (coavoid_auth_fresh, which marks it). The nodes and `coavoid summary`
 * apply the same rule through it. COA_OK or COAVOID_AUTH_ERR_ROLE, _REPLAY, _CLOCK. O(1). */
int coavoid_auth_accept(coavoid_auth_trust_t *t, size_t key, size_t stream,
                        coavoid_auth_role_t role, int32_t id, int64_t timestamp_us,
                        int64_t sequence, int64_t now, int64_t max_age_us, int64_t max_ahead_us);

/* ---- keys as text ----
 * A trust file lists the keys a receiver accepts, one per line:
 *     KEY_ID ROLE NODE_ID PUBLIC_KEY_HEX
 * with ROLE coordinator, world or vehicle, NODE_ID the node it speaks for (1..65535) and
 * the public key as 64 hex digits, and at most one line
 *     fleet FLEET_KEY_HEX
 * with the fleet's key as 32 hex digits (a secret: a trust file that holds it is kept as
 * a secret key file is); blank lines and lines starting with '#' are skipped.
 * A secret key file is one line: "coavoid-secret-key KEY_ID SECRET_KEY_HEX" (128 digits).
 * Both are files a user hands us: every line is bounded (COAVOID_AUTH_LINE_MAX) and
 * checked, and the first problem is reported as "line N: why". */
#define COAVOID_AUTH_LINE_MAX 256u

/* Parses `length` bytes of a trust file into t (emptied first). COA_OK, or
 * COA_ERR_ARGUMENT with the reason in err. O(length * keys). */
int coavoid_auth_trust_parse(coavoid_auth_trust_t *t, const char *text, size_t length, char *err,
                             size_t err_size);

/* Parses a secret key file into s (its numbers zeroed). COA_OK or COA_ERR_ARGUMENT with err. */
int coavoid_auth_signer_parse(coavoid_auth_signer_t *s, const char *text, size_t length, char *err,
                              size_t err_size);

/* The trust line of k and the secret file line of s, each ending in '\n', into out[size]
 * (COAVOID_AUTH_LINE_MAX is enough). COA_OK or COA_ERR_ARGUMENT (too small, bad role). */
int coavoid_auth_key_line(const coavoid_auth_key_t *k, char *out, size_t size);
int coavoid_auth_signer_line(const coavoid_auth_signer_t *s, char *out, size_t size);

/* The trust file's line of a fleet key ("fleet HEX\n") into out[size]. COA_OK or
 * COA_ERR_ARGUMENT (NULL, or too small). */
int coavoid_auth_fleet_line(const unsigned char key[COAVOID_AUTH_FLEET_KEY_BYTES], char *out,
                            size_t size);

#endif /* COAVOID_AUTH_H */
