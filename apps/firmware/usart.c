/* SPDX-License-Identifier: MIT */
/* USART1 of an STM32F405: interrupt-driven receive into a ring, RTS/CTS (usart.h). */
#include "usart.h"

#include "firmware.h"

#define REG(address) (*(volatile uint32_t *)(address))

#define RCC_AHB1ENR REG(0x40023830u)
#define RCC_APB2ENR REG(0x40023844u)
#define RCC_AHB1ENR_GPIOAEN (1u << 0)
#define RCC_APB2ENR_USART1EN (1u << 4)

#define GPIOA_MODER REG(0x40020000u)
#define GPIOA_AFRH REG(0x40020024u)

#define USART1_SR REG(0x40011000u)
#define USART1_DR REG(0x40011004u)
#define USART1_BRR REG(0x40011008u)
#define USART1_CR1 REG(0x4001100Cu)
#define USART1_CR3 REG(0x40011014u)
#define USART_SR_RXNE (1u << 5)
#define USART_SR_TXE (1u << 7)
#define USART_CR1_RE (1u << 2)
#define USART_CR1_TE (1u << 3)
#define USART_CR1_RXNEIE (1u << 5)
#define USART_CR1_UE (1u << 13)
#define USART_CR3_RTSE (1u << 8)
#define USART_CR3_CTSE (1u << 9)

/* The NVIC's set- and clear-enable registers for interrupts 32..63: USART1 is 37. */
#define NVIC_ISER1 REG(0xE000E104u)
#define NVIC_ICER1 REG(0xE000E184u)
#define USART1_IRQ_BIT (1u << (37u - 32u))

/* 921,600 baud from APB2 at 84 MHz, oversampling by 16: 84e6 / (16 * 921600) = 5.6966,
 * mantissa 5, fraction round(0.6966 * 16) = 11 (0.7 % fast, within a UART's tolerance). */
#define USART1_BRR_921600 ((5u << 4) | 11u)

/* The ring: the interrupt writes at head, the main loop reads at tail (free-running
 * counts; each side writes only its own). */
static volatile uint8_t ring[FW_USART_RING];
static volatile uint32_t head;
static volatile uint32_t tail;

void fw_usart_init(void)
{
    RCC_AHB1ENR |= RCC_AHB1ENR_GPIOAEN;
    RCC_APB2ENR |= RCC_APB2ENR_USART1EN;
    /* PA9..PA12 to alternate function 7 (USART1). */
    GPIOA_MODER = (GPIOA_MODER & ~(0xFFu << 18)) | (0xAAu << 18);
    GPIOA_AFRH = (GPIOA_AFRH & ~0xFFFF0u) | 0x77770u;
    USART1_BRR = USART1_BRR_921600;
    USART1_CR3 = USART_CR3_RTSE | USART_CR3_CTSE;
    USART1_CR1 = USART_CR1_UE | USART_CR1_TE | USART_CR1_RE | USART_CR1_RXNEIE;
    NVIC_ISER1 = USART1_IRQ_BIT;
}

/* A byte into the ring; with the ring full, the byte stays in the register (RTS holds the
 * sender) and the interrupt is off in the NVIC until the main loop has made room. Off in
 * the NVIC, not by RXNEIE: qemu's USART (7.2) keeps its interrupt line up when RXNEIE is
 * cleared, so the handler would be taken again at once, for ever, and the main loop
 * never run to make room. The NVIC's enable registers are also written whole, so the
 * handler and the main loop never race on a read-modify-write. */
void fw_usart1_handler(void)
{
    if (head - tail == FW_USART_RING) {
        NVIC_ICER1 = USART1_IRQ_BIT;
        return;
    }
    if ((USART1_SR & USART_SR_RXNE) != 0u) {
        ring[head % FW_USART_RING] = (uint8_t)USART1_DR;
        head = head + 1u;
    }
}

uint8_t fw_usart_get(void)
{
    /* Interrupts masked between the look and the sleep, so that a byte arriving in
     * between still wakes WFI (a pending interrupt ends it, masked or not). */
    __asm__ volatile("cpsid i" ::: "memory");
    while (head == tail) {
        __asm__ volatile("wfi\n\tcpsie i\n\tcpsid i" ::: "memory");
    }
    __asm__ volatile("cpsie i" ::: "memory");
    const uint8_t byte = ring[tail % FW_USART_RING];
    tail = tail + 1u;
    NVIC_ISER1 = USART1_IRQ_BIT; /* room again */
    return byte;
}

void fw_usart_put(uint8_t byte)
{
    while ((USART1_SR & USART_SR_TXE) == 0u) {
    }
    USART1_DR = byte;
}

uint32_t fw_usart_buffered(void)
{
    return head - tail;
}
