/* SPDX-License-Identifier: MIT */
/*
 * main.c: the example firmware's board side (STM32F405-class, 168 MHz): a SysTick
 * interrupt counts time, and the main loop runs the collision-avoidance task once per
 * step of FW_DT seconds. The task runs in the main loop, never in an interrupt: an
 * interrupt only counts ticks here (a radio driver would only fill a spare copy of
 * fw_inputs' intents, swapped in between cycles).
 */
#include <stdint.h>

#include "firmware.h"

#define FW_CORE_HZ 168000000u
#define FW_TICK_HZ 100u
#define FW_TICKS_PER_CYCLE ((uint32_t)((float)FW_TICK_HZ * FW_DT))

#define SYST_CSR (*(volatile uint32_t *)0xE000E010u)
#define SYST_RVR (*(volatile uint32_t *)0xE000E014u)
#define SYST_CVR (*(volatile uint32_t *)0xE000E018u)

static volatile uint32_t ticks;

/* What a failsafe, a logger and the flight controller would read. */
volatile fw_status_t fw_last_status;
volatile float fw_altitude_setpoint;

void fw_systick_handler(void)
{
    ticks = ticks + 1u;
}

int main(void)
{
    uint32_t last;
    uint32_t cycles = 0;

    if (fw_task_init() != COA_OK) {
        for (;;) { /* workspaces too small for the sizes in firmware.h: a build error */
        }
    }
    fw_example_inputs();

    SYST_RVR = FW_CORE_HZ / FW_TICK_HZ - 1u;
    SYST_CVR = 0u;
    SYST_CSR = 7u; /* processor clock, interrupt, enable */
    last = ticks;
    for (;;) {
        __asm__ volatile("wfi");
        if (ticks - last < FW_TICKS_PER_CYCLE) {
            continue;
        }
        last += FW_TICKS_PER_CYCLE;
        fw_last_status = fw_task_cycle((coa_real_t)cycles * FW_DT);
        fw_altitude_setpoint = fw_outputs.altitude_setpoint;
        ++cycles;
    }
}
