/* SPDX-License-Identifier: MIT */
/*
 * check_messages.c: an intent's way through a vehicle on the part, counted (check.c runs
 * it when the cross build has the messages, CMakeLists.txt: lcmtypes/ with LCM's coders
 * only, src/lcm's validation and src/auth's checks). The sender builds an intent from the
 * core's types (coavoid_lcm_intent_from_core, which checks it as a receiver would),
 * encodes it in LCM's wire encoding (the lcm-gen coder) and stamps it (src/auth); the
 * receiver prechecks and verifies it, decodes it and converts it to the core's types
 * (coavoid_lcm_intent_to_core, the check included). Lines:
 *   crypto message-build 0 rc RC ticks T
 *   crypto message-encode BYTES rc RC ticks T    (RC: the encoder's length)
 *   crypto message-stamp BYTES rc RC ticks T
 *   crypto message-receive BYTES rc RC ticks T   (precheck, verify, decode, convert)
 * Nothing is allocated: the messages and the core's views live in the caller's scratch.
 */
#include <stdbool.h>
#include <stdint.h>
#include <string.h>

#include "auth.h"
#include "check_crypto.h"
#include "check_io.h"
#include "check_messages.h"
#include "coavoid_lcm.h"

#define MESSAGE_SAMPLES 25u /* N = 24, the example firmware's horizon */

typedef struct {
    coavoid_intent_t sent;
    coavoid_intent_t received;
    coavoid_lcm_intent_arrays_t arrays;
    coa_vec3_t reference[MESSAGE_SAMPLES];
    int32_t offsets[MESSAGE_SAMPLES];
    unsigned char datagram[COAVOID_LCM_MAX_DATAGRAM_BYTES];
} message_scratch_t;

/* UAV 1 flying east at 100 m, 25 samples a second apart, climbing one step at sample 3. */
static int build(message_scratch_t *s, const coavoid_lcm_context_t *ctx)
{
    const coa_vehicle_t vehicle = {.id = 1u,
                                   .priority = 1u,
                                   .cruise_speed = (coa_real_t)10,
                                   .climb_rate = (coa_real_t)2,
                                   .steep_factor = 2u,
                                   .volume = {(coa_real_t)15, (coa_real_t)5},
                                   .max_offset = -1};
    for (uint32_t j = 0; j < MESSAGE_SAMPLES; ++j) {
        s->reference[j] =
            (coa_vec3_t){(coa_real_t)(10.0f * (float)j), (coa_real_t)0, (coa_real_t)100};
        s->offsets[j] = j >= 3u ? 1 : 0;
    }
    coavoid_lcm_intent_info_t info;
    memset(&info, 0, sizeof info);
    info.utime = FWC_NOW_US;
    info.mode = COAVOID_INTENT_T_MODE_DECOUPLED;
    info.position = s->reference[0];
    info.velocity = (coa_vec3_t){(coa_real_t)10, (coa_real_t)0, (coa_real_t)0};
    info.plan_utime = FWC_NOW_US;
    info.step = (coa_real_t)1;
    const char *reason = NULL;
    return coavoid_lcm_intent_from_core(&vehicle, &info, s->reference, s->offsets, MESSAGE_SAMPLES,
                                        ctx, &s->sent, &reason);
}

/* What a receiver does with the datagram: its auth tail and tag, its signature, LCM's
 * decoder, then every field's check and the conversion to the core's views. */
static int receive(message_scratch_t *s, const coavoid_auth_trust_t *trust, int bytes,
                   const coavoid_lcm_context_t *ctx)
{
    const coavoid_auth_expect_t expect = {COAVOID_AUTH_STREAM_INTENT, COAVOID_AUTH_VEHICLE,
                                          FWC_NOW_US, ctx->max_age_us, ctx->max_future_us};
    size_t key = 0;
    int rc = coavoid_auth_precheck(trust, s->datagram, (size_t)bytes, &expect, &key);
    if (rc == COA_OK) {
        rc = coavoid_auth_verify(trust, s->datagram, (size_t)bytes, &key);
    }
    if (rc == COA_OK && coavoid_intent_t_decode(s->datagram, 0, bytes, &s->received) != bytes) {
        rc = COAVOID_LCM_ERR_VALUE;
    }
    if (rc == COA_OK) {
        coavoid_lcm_intent_info_t info;
        coa_vehicle_t vehicle;
        coa_intent_plan_t plan;
        const char *reason = NULL;
        rc = coavoid_lcm_intent_to_core(&s->received, ctx, NULL, &info, &vehicle, &plan, &s->arrays,
                                        &reason);
    }
    return rc;
}

bool fwc_messages_run(unsigned char *scratch, size_t size, coavoid_auth_signer_t *signer,
                      const coavoid_auth_trust_t *trust)
{
    if (size < sizeof(message_scratch_t)) {
        fwc_put("error messages: the scratch buffer is too small");
        fwc_end_line();
        return false;
    }
    message_scratch_t *s = (message_scratch_t *)(void *)scratch;
    const coavoid_lcm_context_t ctx = {FWC_NOW_US, FWC_MAX_AGE_US, FWC_MAX_AGE_US, FWC_NOW_US};
    uint64_t start = fwc_ticks_now();
    const int built = build(s, &ctx);
    fwc_crypto_line("message-build", 0u, built, fwc_ticks_now() - start);
    s->sent.auth.key_id = (int32_t)signer->key_id;
    start = fwc_ticks_now();
    const int bytes = coavoid_intent_t_encode(s->datagram, 0, (int)sizeof s->datagram, &s->sent);
    fwc_crypto_line("message-encode", (size_t)bytes, bytes, fwc_ticks_now() - start);
    if (built != COA_OK || bytes <= 0) {
        return false;
    }
    start = fwc_ticks_now();
    const int stamped = coavoid_auth_stamp(signer, FWC_NOW_US, s->datagram, (size_t)bytes);
    fwc_crypto_line("message-stamp", (size_t)bytes, stamped, fwc_ticks_now() - start);
    start = fwc_ticks_now();
    const int received = receive(s, trust, bytes, &ctx);
    fwc_crypto_line("message-receive", (size_t)bytes, received, fwc_ticks_now() - start);
    return stamped == COA_OK && received == COA_OK;
}
