/* SPDX-License-Identifier: MIT */
/*
 * check_io.h: the firmware check's clock and output (check.c, check_crypto.c), on an
 * STM32F405 under qemu or on the part.
 *
 * The clock is SysTick on the processor clock, its 24-bit wraps counted in
 * fw_systick_handler. Under qemu -icount shift=0 a tick is one guest instruction
 * (tests/firmware/qemu.sh). Output is one ARM semihosting call per line, through a
 * 512-byte line buffer: a longer line is cut, never overrun.
 */
#ifndef COAVOID_FIRMWARE_CHECK_IO_H
#define COAVOID_FIRMWARE_CHECK_IO_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

/* Starts SysTick, free-running; call once before fwc_ticks_now. */
void fwc_ticks_start(void);
/* Processor clock ticks since fwc_ticks_start. */
uint64_t fwc_ticks_now(void);
/* Exactly 2 * n + 1 instructions (n >= 1), for calibrating ticks against instructions. */
void fwc_spin(uint32_t n);

/* The line being written: text, integers, and bytes in lowercase hexadecimal. */
void fwc_put(const char *s);
void fwc_put_u64(uint64_t v);
void fwc_put_i64(int64_t v);
void fwc_put_hex64(uint64_t v); /* 16 digits */
void fwc_put_hex(const unsigned char *bytes, size_t n);
/* Ends the line and writes it. */
void fwc_end_line(void);

/* A host file through semihosting, for reading (binary): its handle, negative when it
 * cannot be opened; up to n of its bytes into buffer: how many were read (0 at the end or
 * on an error); and closed. */
int32_t fwc_file_open(const char *name);
size_t fwc_file_read(int32_t handle, void *buffer, size_t n);
void fwc_file_close(int32_t handle);

/* Ends the program through semihosting: exit status 0 when ok, 1 otherwise. */
void fwc_exit(bool ok);

#endif
