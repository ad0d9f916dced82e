/* SPDX-License-Identifier: MIT */
/*
 * usart_check.c: USART1's receive ring (usart.h) behind a sender faster than the main loop,
 * under qemu (tests/firmware/qemu.sh sends USART_CHECK_BYTES bytes of a known sequence).
 * It lets the ring fill, stays busy while the next byte waits in the receive register,
 * then reads every byte. Each must come, in order: nothing is lost while the ring is full,
 * and the interrupt of a waiting byte does not keep the main loop from making room.
 * Reports one line by semihosting (check_io.h) and exits 0 when every byte came.
 */
#include <stdbool.h>
#include <stdint.h>

#include "check_io.h"
#include "usart.h"

#define USART_CHECK_BYTES 4096u

/* Byte i of the sender's sequence (qemu.sh writes the same). */
static uint8_t expected(uint32_t i)
{
    return (uint8_t)(i * 7u + 3u);
}

int main(void)
{
    fw_usart_init();
    while (fw_usart_buffered() < FW_USART_RING) {
    }
    fwc_spin(1000000u); /* busy with the ring full */
    uint32_t i = 0;
    while (i < USART_CHECK_BYTES && fw_usart_get() == expected(i)) {
        i++;
    }
    const bool ok = i == USART_CHECK_BYTES;
    fwc_put("usart check: ");
    fwc_put_u64(i);
    fwc_put(ok ? " bytes in order through a full ring" : " bytes in order, then a wrong one");
    fwc_end_line();
    fwc_exit(ok);
    return ok ? 0 : 1;
}
