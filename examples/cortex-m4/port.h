/* What the closed-loop example needs from the machine it runs on: a tick
   counter for the cost of a step and a way to stop. port_host.c for the
   build machine, port_mps2.c for the Cortex-M4F of QEMU's mps2-an386 board. */
#ifndef PORT_H_
#define PORT_H_

#include <stdint.h>

/* Starts the tick counter (and, on the target, semihosting stdio). */
void port_init(void);
/* The tick counter now. */
uint32_t port_ticks(void);
/* Ticks from `start` to `stop` (the counter may count down and wrap). */
uint32_t port_elapsed(uint32_t start, uint32_t stop);
/* Ticks taken by a loop of `iterations` x 2 instructions (subs, bne), to
   convert ticks into executed instructions (0 on the host). */
uint32_t port_calibration_ticks(uint32_t iterations);
/* Tick frequency in Hz (0: no counter). */
uint32_t port_tick_hz(void);

#endif
