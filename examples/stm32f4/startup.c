/* STM32F4 start-up: the vector table (the 16 core exceptions and the 82
   interrupts of the STM32F407; TIM2 is interrupt 28), and the reset handler
   that copies .data, clears .bss and calls main. */
#include <stdint.h>

extern int main(void);
extern uint32_t _sidata, _sdata, _edata, _sbss, _ebss, _estack;

void Reset_Handler(void);
void Default_Handler(void);
void TIM2_IRQHandler(void);

void Reset_Handler(void) {
  uint32_t* src = &_sidata;
  uint32_t* dst = &_sdata;
  while (dst < &_edata) *dst++ = *src++;
  for (dst = &_sbss; dst < &_ebss;) *dst++ = 0;
  (void)main();
  for (;;) {
  }
}

void Default_Handler(void) {
  for (;;) {
  }
}

typedef void (*Vector)(void);
#define IRQ(n) [16 + (n)]

__attribute__((section(".isr_vector"), used)) static const Vector kVectors[16 + 82] = {
    [0] = (Vector)(uintptr_t)&_estack,
    [1] = Reset_Handler,
    [2] = Default_Handler, /* NMI */
    [3] = Default_Handler, /* HardFault */
    [4] = Default_Handler, /* MemManage */
    [5] = Default_Handler, /* BusFault */
    [6] = Default_Handler, /* UsageFault */
    [11] = Default_Handler, /* SVCall */
    [14] = Default_Handler, /* PendSV */
    [15] = Default_Handler, /* SysTick */
    IRQ(28) = TIM2_IRQHandler,
};
