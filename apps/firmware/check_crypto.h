/* SPDX-License-Identifier: MIT */
/* check_crypto.h: the firmware check's message checks (check_crypto.c). */
#ifndef COAVOID_FIRMWARE_CHECK_CRYPTO_H
#define COAVOID_FIRMWARE_CHECK_CRYPTO_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

/* The sender's and the receiver's clock in every check (a time in 2026, us), and the
 * freshness window either side of it. */
#define FWC_NOW_US 1795000000000000LL
#define FWC_MAX_AGE_US 3000000LL

/* Writes the line "crypto WHAT BYTES rc RC ticks T" (check_crypto.c's format, which
 * tests/firmware/qemu_compare.py reads). */
void fwc_crypto_line(const char *what, size_t bytes, int64_t rc, uint64_t ticks);

/* Tags, signs and verifies a heartbeat and an intent, then runs the drivers' checks
 * (src/auth) on an intent and an outsider's copy, all built in `scratch` (a trust list and
 * an intent: about 4 KiB; the planner's buffer, free once the plans are reported,
 * aligned for any type), and reports each with its ticks (check_crypto.c's lines); false
 * when a result is wrong or scratch is short. */
bool fwc_crypto_run(unsigned char *scratch, size_t size);

#endif
