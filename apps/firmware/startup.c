/* SPDX-License-Identifier: MIT */
/*
 * startup.c: the C runtime of the example firmware (no crt0, no libc start-up code):
 * the vector table, and a reset handler that turns the FPU on, copies .data, clears .bss
 * and calls main. The symbols come from stm32f405.ld.
 */
#include <stdint.h>

#include "firmware.h"

extern uint32_t fw_data_load[];
extern uint32_t fw_data_start[];
extern uint32_t fw_data_end[];
extern uint32_t fw_bss_start[];
extern uint32_t fw_bss_end[];
extern uint32_t fw_stack_top[];

int main(void);
void reset_handler(void);

/* System control block: coprocessor access (CP10 and CP11 are the FPU). */
#define SCB_CPACR (*(volatile uint32_t *)0xE000ED88u)

/* Entry 0 is the initial stack pointer, the others handlers: a union keeps the table ISO C
 * (an object pointer does not convert to a function pointer). */
typedef union {
    void (*handler)(void);
    const void *stack_top;
} fw_vector_t;

/* Faults: a real autopilot hands over to its failsafe here; the example stops. */
static void fault_handler(void)
{
    for (;;) {
    }
}

static void unused_handler(void)
{
    for (;;) {
    }
}

/* USART1's interrupt: the vehicle's link (usart.c) takes it; any other firmware never
 * enables it. */
__attribute__((weak)) void fw_usart1_handler(void)
{
    for (;;) {
    }
}

void reset_handler(void)
{
    const uint32_t *src = fw_data_load;
    uint32_t *dst;

    /* Every function compiled with -mfloat-abi=hard may use the FPU: turn it on (full
     * access for CP10 and CP11) before anything else runs, and let the write take effect
     * before the next instruction. This function itself uses no floating point. */
    SCB_CPACR |= 0xFu << 20;
    __asm__ volatile("dsb\n\tisb" ::: "memory");

    for (dst = fw_data_start; dst < fw_data_end; ++dst, ++src) {
        *dst = *src;
    }
    for (dst = fw_bss_start; dst < fw_bss_end; ++dst) {
        *dst = 0u;
    }
    (void)main();
    for (;;) {
    }
}

#define FW_IRQ1                   \
    {                             \
        .handler = unused_handler \
    }
#define FW_IRQ2 FW_IRQ1, FW_IRQ1
#define FW_IRQ4 FW_IRQ2, FW_IRQ2
#define FW_IRQ8 FW_IRQ4, FW_IRQ4
#define FW_IRQ16 FW_IRQ8, FW_IRQ8

/* The Cortex-M4 exceptions, then the STM32F405's 82 interrupt lines: only USART1's (37)
 * is used, by the vehicle's link. */
__attribute__((section(".isr_vector"), used)) const fw_vector_t fw_vectors[16 + 82] = {
    {.stack_top = fw_stack_top},
    {.handler = reset_handler},
    {.handler = fault_handler}, /* NMI */
    {.handler = fault_handler}, /* hard fault */
    {.handler = fault_handler}, /* memory management */
    {.handler = fault_handler}, /* bus fault (also a stack overflow, see the linker script) */
    {.handler = fault_handler}, /* usage fault */
    {.handler = 0},
    {.handler = 0},
    {.handler = 0},
    {.handler = 0},
    {.handler = unused_handler}, /* SVCall */
    {.handler = unused_handler}, /* debug monitor */
    {.handler = 0},
    {.handler = unused_handler}, /* PendSV */
    {.handler = fw_systick_handler},
    FW_IRQ16,                       /* 0..15 */
    FW_IRQ16,                       /* 16..31 */
    FW_IRQ4,                        /* 32..35 */
    FW_IRQ1,                        /* 36 */
    {.handler = fw_usart1_handler}, /* 37 */
    FW_IRQ16,                       /* 38..53 */
    FW_IRQ16,                       /* 54..69 */
    FW_IRQ8,                        /* 70..77 */
    FW_IRQ4,                        /* 78..81 */
};
