/* SPDX-License-Identifier: MIT */
/*
 * usart.h: the example firmware's link to the ground, USART1 of an STM32F405 (PA9 TX,
 * PA10 RX, PA11 CTS, PA12 RTS, alternate function 7), 921,600 baud, 8N1, with hardware
 * flow control. Received bytes go through USART1's interrupt into a ring of
 * FW_USART_RING bytes; the processor sleeps (WFI) while it waits for one. Sending waits
 * for room in the transmit register.
 *
 * Nothing received is lost while the vehicle is busy in a call (a planning call takes up
 * to a few hundred milliseconds on the part): when the ring is full the interrupt stops
 * taking bytes, the receive register stays full, the USART deasserts RTS and the ground's
 * UART holds the next byte until the ring has room again. And the ground sends a frame
 * only after the vehicle's READY for the one before (session.h), so little waits. Under
 * qemu (netduinoplus2) the first -serial is USART1 and the same holding back is qemu's
 * (tests/firmware/qemu.sh checks it with usart_check.c).
 */
#ifndef COAVOID_FIRMWARE_USART_H
#define COAVOID_FIRMWARE_USART_H

#include <stdint.h>

#define FW_USART_RING 256u /* a power of two */

/* Clocks USART1 and its pins, enables it and its receive interrupt. Call once, first. */
void fw_usart_init(void);

/* The next byte received; sleeps until there is one. */
uint8_t fw_usart_get(void);

/* Sends one byte; waits for room in the transmit register. */
void fw_usart_put(uint8_t byte);

/* How many bytes the ring holds, 0..FW_USART_RING. */
uint32_t fw_usart_buffered(void);

#endif
