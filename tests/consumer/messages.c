/* SPDX-License-Identifier: MIT */
/* A downstream user of the installed message library (find_package(coavoid COMPONENTS
 * messages), or pkg-config coavoid-messages): makes the intents of two UAVs with
 * coavoid_lcm_intent_from_core, encodes them with the generated coders, stamps and signs
 * each with its UAV's key and the fleet's, and takes each in as a receiver does: the tail
 * (precheck), the signature, the decoder, the intent's rules and the key's right to speak
 * for the UAV. A byte flipped must fail the tag and the signature, a copy must be a replay.
 * With LOG, it also writes the datagrams, and a foreign and a truncated one, as an LCM log
 * (the input of tests/consumer/intents.expected). Exits 0 only when every check holds. */
#include <coavoid/coavoid.h>
#include <coavoid_lcmtypes/coavoid_intent_t.h>
#include <coavoid_messages/auth.h>
#include <coavoid_messages/coavoid_lcm.h>

#include <stdio.h>
#include <string.h>

#define T0 INT64_C(1700000000000000) /* 2023-11-14T22:13:20Z */
#define SAMPLES 7u
#define STEP 0.5 /* s: a plan's step, half the cycle */

/* One intent of the log: its UAV, time after T0, cycle (plan_utime = T0 + cycle s),
 * sequence, mode, rank, and its offsets: from `first`, one climb step a step, to `target`;
 * its plan's SAMPLES samples are STEP apart. */
typedef struct {
    uint16_t uav;
    int64_t after_us;
    int64_t cycle;
    int64_t sequence;
    int8_t mode;
    int8_t rank;
    int32_t first;
    int32_t target;
} sent_t;

/* Cycle 0: each UAV's intent and a copy (the same plan, its state moved on); cycle 1:
 * UAV 1's next, UAV 2's next, then its plan again with its rank raised, and a copy. */
static const sent_t SENT[] = {
    {1, 0, 0, 0, COAVOID_INTENT_T_MODE_CENTRALISED, 0, 0, 2},
    {2, 1000, 0, 0, COAVOID_INTENT_T_MODE_DECOUPLED, 0, 0, 0},
    {1, 25000, 0, 1, COAVOID_INTENT_T_MODE_CENTRALISED, 0, 0, 2},
    {2, 26000, 0, 1, COAVOID_INTENT_T_MODE_DECOUPLED, 0, 0, 0},
    {1, 1000000, 1, 2, COAVOID_INTENT_T_MODE_CENTRALISED, 0, 1, 2},
    {2, 1001000, 1, 2, COAVOID_INTENT_T_MODE_DECOUPLED, 0, 0, 0},
    {2, 1300000, 1, 3, COAVOID_INTENT_T_MODE_DECOUPLED, 1, 0, -2},
    {2, 1325000, 1, 4, COAVOID_INTENT_T_MODE_DECOUPLED, 1, 0, -2},
};
#define SENT_COUNT (sizeof SENT / sizeof SENT[0])

static int failures;

static void expect(int ok, const char *what)
{
    if (!ok) {
        fprintf(stderr, "messages: FAIL: %s\n", what);
        failures++;
    }
}

/* UAV 1 flies east at 10 m/s at 100 m from (0, 0); UAV 2 west from (200, 50) at 120 m. */
static coa_vec3_t where(uint16_t uav, double t)
{
    const coa_vec3_t p = {uav == 1 ? 10.0 * t : 200.0 - 10.0 * t, uav == 1 ? 0.0 : 50.0,
                          uav == 1 ? 100.0 : 120.0};
    return p;
}

/* The intent of s, encoded into buf[size]: its length, or 0 (a failure counted). */
static int make_intent(const sent_t *s, unsigned char *buf, int size)
{
    static const coa_vec3_t unused[2] = {{0, 0, 0}, {1, 0, 0}};
    const coa_vehicle_t v = {s->uav, s->uav, 10.0, 2.0, 2, {15.0, 5.0}, unused, 2, 0, -1};
    coa_vec3_t reference[SAMPLES];
    int32_t offsets[SAMPLES];
    const int32_t up = s->target > s->first ? 1 : -1;
    for (uint32_t j = 0; j < SAMPLES; ++j) {
        reference[j] = where(s->uav, (double)s->cycle + STEP * j);
        const int32_t moved = s->first + up * (int32_t)j;
        offsets[j] = (moved - s->target) * up > 0 ? s->target : moved;
    }
    const double t = (double)s->after_us * 1e-6;
    coavoid_lcm_intent_info_t info;
    memset(&info, 0, sizeof info);
    info.utime = T0 + s->after_us;
    info.sequence = s->sequence;
    info.mode = s->mode;
    info.position = where(s->uav, t);
    info.position.z += offsets[0] * 2.0 * STEP;
    info.velocity.x = s->uav == 1 ? 10.0 : -10.0;
    info.plan_utime = T0 + s->cycle * 1000000;
    info.step = STEP;
    info.sigma_horizontal = 3.0;
    info.sigma_vertical = 1.5;
    info.rank = s->rank;
    const coavoid_lcm_context_t ctx = {0, 0, 0, T0};
    coavoid_intent_t msg;
    const char *reason = "";
    int rc =
        coavoid_lcm_intent_from_core(&v, &info, reference, offsets, SAMPLES, &ctx, &msg, &reason);
    if (rc != COA_OK) {
        fprintf(stderr, "messages: intent_from_core: %s (%s)\n", coavoid_lcm_error_name(rc),
                reason);
        failures++;
        return 0;
    }
    const int length = coavoid_intent_t_encode(buf, 0, size, &msg);
    expect(length == coavoid_intent_t_encoded_size(&msg) && length <= size, "encode");
    return length > 0 ? length : 0;
}

/* The checks of a receiver at `now` on a datagram from UAV `uav`: COA_OK or the first
 * refusal. */
static int receive(coavoid_auth_trust_t *trust, const unsigned char *buf, int length, uint16_t uav,
                   int64_t now)
{
    const coavoid_auth_expect_t expect_intent = {COAVOID_AUTH_STREAM_INTENT, COAVOID_AUTH_VEHICLE,
                                                 now, 5000000, 1000000};
    size_t key = 0;
    int rc = coavoid_auth_precheck(trust, buf, (size_t)length, &expect_intent, &key);
    if (rc == COA_OK) {
        rc = coavoid_auth_verify(trust, buf, (size_t)length, &key);
    }
    if (rc != COA_OK) {
        return rc;
    }
    coavoid_intent_t msg;
    if (coavoid_intent_t_decode(buf, 0, length, &msg) != length) {
        return COAVOID_LCM_ERR_DECODE;
    }
    const coavoid_lcm_context_t ctx = {now, 5000000, 1000000, T0};
    const char *reason = "";
    rc = coavoid_lcm_intent_check(&msg, &ctx, &reason);
    if (rc == COA_OK && msg.uav_id != uav) {
        rc = COAVOID_LCM_ERR_ID;
    }
    if (rc == COA_OK) {
        rc = coavoid_auth_accept(trust, key, COAVOID_AUTH_STREAM_INTENT, COAVOID_AUTH_VEHICLE,
                                 msg.uav_id, msg.auth.timestamp_us, msg.auth.sequence, now, 5000000,
                                 1000000);
    }
    coavoid_intent_t_decode_cleanup(&msg);
    return rc;
}

static void put_be(unsigned char *p, uint64_t v, int bytes)
{
    for (int i = bytes - 1; i >= 0; --i, v >>= 8) {
        p[i] = (unsigned char)(v & 0xffu);
    }
}

/* One event of an LCM log: sync word, event number, time, channel and data lengths. */
static void log_event(FILE *log, int64_t number, int64_t utime, const char *channel,
                      const unsigned char *data, int length)
{
    unsigned char header[28];
    put_be(header, 0xEDA1DA01u, 4);
    put_be(header + 4, (uint64_t)number, 8);
    put_be(header + 12, (uint64_t)utime, 8);
    put_be(header + 20, strlen(channel), 4);
    put_be(header + 24, (uint64_t)length, 4);
    expect(fwrite(header, sizeof header, 1, log) == 1 &&
               fwrite(channel, strlen(channel), 1, log) == 1 &&
               fwrite(data, (size_t)length, 1, log) == 1,
           "writing the log");
}

/* The UAVs' keys from fixed seeds, the fleet key, and the trust list that holds them. */
static void make_keys(coavoid_auth_signer_t signers[2], coavoid_auth_trust_t *trust)
{
    unsigned char fleet[COAVOID_AUTH_FLEET_KEY_BYTES];
    memset(fleet, 0x5a, sizeof fleet);
    coavoid_auth_trust_init(trust);
    expect(coavoid_auth_trust_set_fleet_key(trust, fleet) == COA_OK, "fleet key");
    for (uint16_t uav = 1; uav <= 2; ++uav) {
        unsigned char seed[COAVOID_AUTH_SEED_BYTES];
        memset(seed, uav, sizeof seed);
        coavoid_auth_key_t key = {
            COAVOID_AUTH_KEY_ID_VEHICLE_BASE + uav, COAVOID_AUTH_VEHICLE, uav, {0}};
        coavoid_auth_signer_t *s = &signers[uav - 1];
        memset(s, 0, sizeof *s);
        s->key_id = key.key_id;
        expect(coavoid_auth_keypair_seed(seed, key.public_key, s->secret_key) == COA_OK,
               "key pair");
        expect(coavoid_auth_trust_add(trust, &key) == COA_OK, "trust");
    }
    for (int i = 0; i < 2; ++i) {
        coavoid_auth_signer_use_fleet(&signers[i], trust);
        expect(coavoid_auth_signer_matches(trust, &signers[i], COAVOID_AUTH_VEHICLE,
                                           (uint16_t)(i + 1)) == COA_OK,
               "signer matches its trust line");
    }
}

int main(int argc, char **argv)
{
    static coavoid_auth_trust_t trust;
    coavoid_auth_signer_t signers[2];
    FILE *log = NULL;
    int64_t events = 0;
    if (argc > 2 || coavoid_auth_init() != COA_OK) {
        fprintf(stderr, "usage: messages [LOG]\n");
        return 2;
    }
    if (argc == 2 && (log = fopen(argv[1], "wb")) == NULL) {
        perror(argv[1]);
        return 2;
    }
    make_keys(signers, &trust);
    for (size_t i = 0; i < SENT_COUNT; ++i) {
        const sent_t *s = &SENT[i];
        const int64_t now = T0 + s->after_us;
        unsigned char buf[COAVOID_LCM_MAX_DATAGRAM_BYTES];
        const int length = make_intent(s, buf, (int)sizeof buf);
        if (length == 0 ||
            coavoid_auth_stamp(&signers[s->uav - 1], now, buf, (size_t)length) != COA_OK) {
            expect(0, "stamp");
            continue;
        }
        unsigned char bad[sizeof buf];
        memcpy(bad, buf, (size_t)length);
        bad[40] ^= 1u; /* in the position */
        size_t key;
        expect(coavoid_auth_tag_check(&trust, bad, (size_t)length) == COAVOID_AUTH_ERR_TAG,
               "a flipped byte fails the fleet tag");
        expect(coavoid_auth_verify(&trust, bad, (size_t)length, &key) == COAVOID_AUTH_ERR_SIGNATURE,
               "a flipped byte fails the signature");
        expect(receive(&trust, buf, length, s->uav, now) == COA_OK, "an intent taken in");
        expect(receive(&trust, buf, length, s->uav, now) == COAVOID_AUTH_ERR_REPLAY,
               "the same datagram again is a replay");
        if (log != NULL) {
            log_event(log, events++, now, "COAVOID_INTENT", buf, length);
            if (i == 2) { /* another channel, and a datagram on ours that does not decode */
                log_event(log, events++, now, "COAVOID_STATUS", buf, 8);
                log_event(log, events++, now, "COAVOID_INTENT", buf, length / 2);
            }
        }
    }
    if (log != NULL && fclose(log) != 0) {
        expect(0, "closing the log");
    }
    if (failures == 0) {
        printf("messages: %zu intents signed, checked and taken in\n", SENT_COUNT);
    }
    return failures == 0 ? 0 : 1;
}
