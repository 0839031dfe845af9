/* Cortex-M4F on QEMU's mps2-an386 board: vector table, reset handler (data
   and bss set up, the FPU enabled), semihosting stdio through newlib's
   librdimon, and the SysTick timer on the processor clock (25 MHz) as the
   tick counter. Under `qemu-system-arm -icount shift=S` the emulated clock
   advances 2^S ns per executed instruction, so ticks measure instructions:
   instructions = ticks * 40 ns / 2^S. */
#include <stdint.h>
#include <stdlib.h>

#include "port.h"

extern int main(void);
extern void initialise_monitor_handles(void);
extern uint32_t _sidata, _sdata, _edata, _sbss, _ebss, _estack;

#define SYST_CSR (*(volatile uint32_t*)0xE000E010u)
#define SYST_RVR (*(volatile uint32_t*)0xE000E014u)
#define SYST_CVR (*(volatile uint32_t*)0xE000E018u)
#define SCB_CPACR (*(volatile uint32_t*)0xE000ED88u)

void Reset_Handler(void);
void Default_Handler(void);
void _init(void);
void _fini(void);

/* The C runtime's init/fini hooks (no crti/crtn without the start files). */
void _init(void) {}
void _fini(void) {}

void Reset_Handler(void) {
  uint32_t* src = &_sidata;
  uint32_t* dst = &_sdata;
  while (dst < &_edata) *dst++ = *src++;
  for (dst = &_sbss; dst < &_ebss;) *dst++ = 0;
  SCB_CPACR |= 0xFu << 20; /* CP10, CP11: full access to the FPU */
  __asm volatile("dsb\n\tisb" ::: "memory");
  exit(main());
}

void Default_Handler(void) {
  for (;;) {
  }
}

typedef void (*Vector)(void);
__attribute__((section(".isr_vector"), used)) static const Vector kVectors[16] = {
    (Vector)(uintptr_t)&_estack, Reset_Handler,   Default_Handler, Default_Handler,
    Default_Handler,             Default_Handler, Default_Handler, 0,
    0,                           0,               0,               Default_Handler,
    Default_Handler,             0,               Default_Handler, Default_Handler,
};

void port_init(void) {
  initialise_monitor_handles();
  SYST_RVR = 0x00FFFFFFu;
  SYST_CVR = 0u;
  SYST_CSR = 5u; /* enable, processor clock, no interrupt */
}

uint32_t port_ticks(void) { return SYST_CVR; }

uint32_t port_elapsed(uint32_t start, uint32_t stop) { return (start - stop) & 0x00FFFFFFu; }

uint32_t port_tick_hz(void) { return 25000000u; }

uint32_t port_calibration_ticks(uint32_t iterations) {
  uint32_t start = SYST_CVR, n = iterations;
  __asm volatile(
      "1:\n\t"
      "subs %0, %0, #1\n\t"
      "bne 1b"
      : "+r"(n)
      :
      : "cc");
  return port_elapsed(start, SYST_CVR);
}
