/* SPDX-License-Identifier: MIT */
/* check_crypto.h: the firmware check's message checks (check_crypto.c). */
#ifndef COAVOID_FIRMWARE_CHECK_CRYPTO_H
#define COAVOID_FIRMWARE_CHECK_CRYPTO_H

#include <stdbool.h>
#include <stddef.h>

/* Tags, signs and verifies a heartbeat and an intent, then runs the drivers' checks
 * (src/auth) on an intent and an outsider's copy, all built in `scratch` (a trust list and
 * an intent: about 4 KiB; the planner's buffer, free once the plans are reported,
 * aligned for any type), and reports each with its ticks (check_crypto.c's lines); false
 * when a result is wrong or scratch is short. */
bool fwc_crypto_run(unsigned char *scratch, size_t size);

#endif
