/* SPDX-License-Identifier: MIT */
/*
 * check_io.c: the firmware check's clock and output (check_io.h): SysTick counting the
 * processor clock, and lines written through ARM semihosting.
 */
#include "check_io.h"

#include <string.h>

/* SysTick, free-running on the processor clock: 24 bits, the wraps counted in the
 * interrupt. */
#define SYST_CSR (*(volatile uint32_t *)0xE000E010u)
#define SYST_RVR (*(volatile uint32_t *)0xE000E014u)
#define SYST_CVR (*(volatile uint32_t *)0xE000E018u)
#define SYST_PERIOD 0x1000000u

static volatile uint32_t systick_wraps;

void fw_systick_handler(void)
{
    systick_wraps = systick_wraps + 1u;
}

/* A loop of exactly 2 * n + 1 instructions (subs and a taken bne per round, the last bne
 * not taken, plus the mov), for the calibration. */
void fwc_spin(uint32_t n)
{
    __asm__ volatile("mov r0, %0\n1:\n\tsubs r0, #1\n\tbne 1b" : : "r"(n) : "r0", "cc");
}

void fwc_ticks_start(void)
{
    SYST_RVR = SYST_PERIOD - 1u;
    SYST_CVR = 0u;
    SYST_CSR = 7u;   /* processor clock, interrupt, enable */
    fwc_spin(1000u); /* past the first reload from the 0 written above */
}

uint64_t fwc_ticks_now(void)
{
    uint32_t wraps;
    uint32_t value;
    do {
        wraps = systick_wraps;
        value = SYST_CVR;
    } while (wraps != systick_wraps);
    return (uint64_t)wraps * SYST_PERIOD + (SYST_PERIOD - 1u - value);
}

/* ARM semihosting (the "Angel" interface): operation in r0, argument in r1, bkpt 0xAB in
 * Thumb state; the debugger or emulator does the operation and resumes. */
#define SYS_WRITE0 0x04u
#define SYS_EXIT 0x18u
#define ADP_STOPPED_APPLICATION_EXIT 0x20026u
#define ADP_STOPPED_RUN_TIME_ERROR 0x20023u

static void semihost(uint32_t op, const void *arg)
{
    __asm__ volatile("mov r0, %0\n\tmov r1, %1\n\tbkpt 0xab"
                     :
                     : "r"(op), "r"(arg)
                     : "r0", "r1", "memory");
}

/* The operations that answer in r0: SYS_OPEN, SYS_CLOSE, SYS_READ. */
#define SYS_OPEN 0x01u
#define SYS_CLOSE 0x02u
#define SYS_READ 0x06u
#define SYS_OPEN_READ_BINARY 1u

static int32_t semihost_answer(uint32_t op, const void *arg)
{
    register uint32_t r0 __asm__("r0") = op;
    register const void *r1 __asm__("r1") = arg;
    __asm__ volatile("bkpt 0xab" : "+r"(r0) : "r"(r1) : "memory");
    return (int32_t)r0;
}

int32_t fwc_file_open(const char *name)
{
    const uint32_t args[3] = {(uint32_t)(uintptr_t)name, SYS_OPEN_READ_BINARY,
                              (uint32_t)strlen(name)};
    return semihost_answer(SYS_OPEN, args);
}

void fwc_file_close(int32_t handle)
{
    const uint32_t args[1] = {(uint32_t)handle};
    (void)semihost_answer(SYS_CLOSE, args);
}

size_t fwc_file_read(int32_t handle, void *buffer, size_t n)
{
    const uint32_t args[3] = {(uint32_t)handle, (uint32_t)(uintptr_t)buffer, (uint32_t)n};
    const int32_t left = semihost_answer(SYS_READ, args); /* bytes not read */
    return left < 0 || (size_t)left > n ? 0u : n - (size_t)left;
}

/* Output goes through a line buffer: one semihosting call per line, not per character. */
static char line[512];
static size_t line_length;

void fwc_put(const char *s)
{
    while (*s != '\0' && line_length + 2u < sizeof line) {
        line[line_length++] = *s++;
    }
}

void fwc_end_line(void)
{
    line[line_length++] = '\n';
    line[line_length] = '\0';
    semihost(SYS_WRITE0, line);
    line_length = 0;
}

void fwc_put_u64(uint64_t v)
{
    char digits[21];
    size_t i = sizeof digits - 1u;
    digits[i] = '\0';
    do {
        digits[--i] = (char)('0' + (int)(v % 10u));
        v /= 10u;
    } while (v != 0u);
    fwc_put(&digits[i]);
}

void fwc_put_i64(int64_t v)
{
    if (v < 0) {
        fwc_put("-");
        fwc_put_u64(0u - (uint64_t)v);
    } else {
        fwc_put_u64((uint64_t)v);
    }
}

void fwc_put_hex(const unsigned char *bytes, size_t n)
{
    static const char hex[] = "0123456789abcdef";
    char pair[3] = {0, 0, 0};
    for (size_t i = 0; i < n; ++i) {
        pair[0] = hex[bytes[i] >> 4];
        pair[1] = hex[bytes[i] & 0xfu];
        fwc_put(pair);
    }
}

void fwc_put_hex64(uint64_t v)
{
    unsigned char bytes[8];
    for (int i = 7; i >= 0; --i) {
        bytes[i] = (unsigned char)(v & 0xffu);
        v >>= 8;
    }
    fwc_put_hex(bytes, sizeof bytes);
}

void fwc_exit(bool ok)
{
    semihost(SYS_EXIT, (const void *)(uintptr_t)(ok ? ADP_STOPPED_APPLICATION_EXIT
                                                    : ADP_STOPPED_RUN_TIME_ERROR));
}
