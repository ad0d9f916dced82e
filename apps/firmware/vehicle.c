/* SPDX-License-Identifier: MIT */
/*
 * vehicle.c: the vehicle protocol on the part, flown over its UART. The firmware is a
 * vehicle of the fleet: `coavoid bridge` on the ground, at the other end of USART1 (a
 * serial line, or qemu's -serial), sends it its configuration, the datagrams of the group
 * and the clock, and publishes what it sends (src/replay/session.h has the frames; the
 * bridge and the Linux vehicles run the same protocol library). Everything is static:
 * the vehicle's block, the session, one frame's buffer. It runs until reset.
 */
#include <stdint.h>

#include "firmware.h"
#include "session.h"
#include "usart.h"

/* The vehicle's block: coavoid_vehicle_node_size of a decoupled vehicle with 8 neighbours
 * at N = 24 on the part (docs/embedded.md). A configuration that needs more is refused,
 * and the READY says so (COA_ERR_WORKSPACE). */
#ifndef FW_VEHICLE_BLOCK_BYTES
#define FW_VEHICLE_BLOCK_BYTES 111104u
#endif
/* A frame's largest record on the part: a datagram, or a configuration of what the
 * part's replay holds (16 route points, 64 vertices); a longer frame is dropped. */
#define FW_VEHICLE_FRAME_BYTES (2048u + COAVOID_LINK_CRC_BYTES)

static uint8_t block[FW_VEHICLE_BLOCK_BYTES] __attribute__((aligned(8)));
static coavoid_session_t session;
static uint8_t frame[FW_VEHICLE_FRAME_BYTES];
static coavoid_link_rx_t rx;

static void put_byte(void *user, uint8_t byte)
{
    (void)user;
    fw_usart_put(byte);
}

/* SysTick is not used here; the vector table names its handler. */
void fw_systick_handler(void)
{
}

int main(void)
{
    fw_usart_init();
    coavoid_link_rx_init(&rx, frame, sizeof frame);
    coavoid_session_init(&session, block, sizeof block, put_byte, NULL);
    for (;;) {
        const size_t n = coavoid_link_rx_byte(&rx, fw_usart_get());
        if (n > 0u) {
            (void)coavoid_session_take(&session, frame, n);
        }
    }
}
