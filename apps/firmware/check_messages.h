/* SPDX-License-Identifier: MIT */
/* check_messages.h: an intent's way through a vehicle on the part (check_messages.c). */
#ifndef COAVOID_FIRMWARE_CHECK_MESSAGES_H
#define COAVOID_FIRMWARE_CHECK_MESSAGES_H

#include <stdbool.h>
#include <stddef.h>

#include "auth.h"

/* Builds, encodes and stamps an intent with signer, then receives it against trust (which
 * must list signer's key as UAV 1's, with the fleet key), reporting each step with its
 * ticks; all in scratch (about 12 KiB, aligned for any type). False when a step failed
 * or scratch is short. */
bool fwc_messages_run(unsigned char *scratch, size_t size, coavoid_auth_signer_t *signer,
                      const coavoid_auth_trust_t *trust);

#endif
