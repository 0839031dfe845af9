/* A generated controller on an STM32F4 (Cortex-M4F, e.g. STM32F407 at
   168 MHz): a timer interrupt every sample period reads the force sensor on
   the ADC, calls ctrl_step and writes the valve duty as PWM.

     TIM2 update interrupt   every CTRL_TS seconds (the controller's Ts)
     ADC1 channel 0 (PA0)    the force sensor, 12 bits, scaled to N
     TIM3 channel 1 (PA6)    the valve's PWM, duty = the controller's u in %

   Registers are written by address (RM0090), so that the example needs no
   vendor headers; a project with CMSIS would use its definitions instead.
   The clock tree is the board's start-up code's (SystemInit): TIMER_HZ is
   the timers' input clock it sets (84 MHz for SYSCLK 168 MHz, APB1 / 2).
   Everything the controller needs is in ctrl.h / ctrl.c from

     pneumid codegen --model MODEL --controller mpc --rule auto --plant ipa \
         --precision float --prefix ctrl -o gen

   A faulty reading (ADC out of its valid range, e.g. a broken wire at 0 or a
   short at 4095) is a fault of the controller's guard: build with
   -DCTRL_Y_VALID_MIN=... -DCTRL_Y_VALID_MAX=... to set the range in N, and
   -DCTRL_SAFE_INPUT=0.0f to vent instead of holding the last duty. */
#include <stdint.h>

#include "ctrl.h"

#ifndef TIMER_HZ
#define TIMER_HZ 84000000u /* TIM2/TIM3 input clock */
#endif
#ifndef PWM_HZ
#define PWM_HZ 300u /* valve PWM frequency */
#endif
#ifndef SENSOR_N_PER_COUNT
#define SENSOR_N_PER_COUNT 0.0610501f /* 250 N over 4095 counts */
#endif
#ifndef SENSOR_OFFSET_N
#define SENSOR_OFFSET_N 0.0f
#endif
#ifndef SETPOINT_N
#define SETPOINT_N 80.0f
#endif

#define REG(addr) (*(volatile uint32_t*)(addr))
/* RCC */
#define RCC_AHB1ENR REG(0x40023830u)
#define RCC_APB1ENR REG(0x40023840u)
#define RCC_APB2ENR REG(0x40023844u)
/* GPIOA */
#define GPIOA_MODER REG(0x40020000u)
#define GPIOA_AFRL REG(0x40020020u)
/* Timers: TIM2 at 0x40000000, TIM3 at 0x40000400 */
#define TIM_CR1(t) REG((t) + 0x00u)
#define TIM_DIER(t) REG((t) + 0x0Cu)
#define TIM_SR(t) REG((t) + 0x10u)
#define TIM_EGR(t) REG((t) + 0x14u)
#define TIM_CCMR1(t) REG((t) + 0x18u)
#define TIM_CCER(t) REG((t) + 0x20u)
#define TIM_PSC(t) REG((t) + 0x28u)
#define TIM_ARR(t) REG((t) + 0x2Cu)
#define TIM_CCR1(t) REG((t) + 0x34u)
#define TIM2 0x40000000u
#define TIM3 0x40000400u
/* ADC1 */
#define ADC1_SR REG(0x40012000u)
#define ADC1_CR2 REG(0x40012008u)
#define ADC1_SMPR2 REG(0x40012010u)
#define ADC1_SQR3 REG(0x40012034u)
#define ADC1_DR REG(0x4001204Cu)
/* Core */
#define NVIC_ISER0 REG(0xE000E100u)
#define SCB_CPACR REG(0xE000ED88u)
#define TIM2_IRQN 28u

static ctrl_state controller;
static volatile uint32_t overruns; /* interrupts that found the last one running */
static volatile uint32_t busy;

static float read_force_n(void) {
  ADC1_CR2 |= 1u << 30; /* SWSTART */
  while (!(ADC1_SR & (1u << 1))) {
  } /* EOC */
  return SENSOR_N_PER_COUNT * (float)(ADC1_DR & 0xFFFu) + SENSOR_OFFSET_N;
}

static void write_duty_percent(float u) {
  const uint32_t period = TIM_ARR(TIM3) + 1u;
  if (!(u > 0.0f)) u = 0.0f; /* also NaN, which the controller never returns */
  if (u > 100.0f) u = 100.0f;
  TIM_CCR1(TIM3) = (uint32_t)(u * 0.01f * (float)period);
}

void TIM2_IRQHandler(void);
void TIM2_IRQHandler(void) {
  TIM_SR(TIM2) = 0u; /* clear the update flag */
  if (busy) {
    ++overruns;
    return;
  }
  busy = 1u;
  write_duty_percent(ctrl_step(&controller, SETPOINT_N, read_force_n()));
  busy = 0u;
}

static void setup(void) {
  SCB_CPACR |= 0xFu << 20; /* the FPU, before any float instruction */
  __asm volatile("dsb\n\tisb" ::: "memory");
  RCC_AHB1ENR |= 1u << 0;              /* GPIOA */
  RCC_APB1ENR |= (1u << 0) | (1u << 1); /* TIM2, TIM3 */
  RCC_APB2ENR |= 1u << 8;              /* ADC1 */
  /* PA0 analog, PA6 alternate function 2 (TIM3_CH1). */
  GPIOA_MODER |= 3u << (0 * 2);
  GPIOA_MODER = (GPIOA_MODER & ~(3u << (6 * 2))) | (2u << (6 * 2));
  GPIOA_AFRL = (GPIOA_AFRL & ~(0xFu << (6 * 4))) | (2u << (6 * 4));
  /* ADC1: channel 0, 84 cycles sampling, on. */
  ADC1_SMPR2 = 4u << 0;
  ADC1_SQR3 = 0u;
  ADC1_CR2 = 1u;
  /* TIM3: PWM mode 1 on channel 1 at PWM_HZ with a 1 MHz count. */
  TIM_PSC(TIM3) = TIMER_HZ / 1000000u - 1u;
  TIM_ARR(TIM3) = 1000000u / PWM_HZ - 1u;
  TIM_CCMR1(TIM3) = (6u << 4) | (1u << 3);
  TIM_CCER(TIM3) = 1u;
  TIM_CCR1(TIM3) = 0u;
  TIM_EGR(TIM3) = 1u;
  TIM_CR1(TIM3) = 1u;
  /* TIM2: an update every CTRL_TS s with a 1 MHz count. */
  TIM_PSC(TIM2) = TIMER_HZ / 1000000u - 1u;
  TIM_ARR(TIM2) = (uint32_t)(CTRL_TS * 1e6 + 0.5) - 1u;
  TIM_EGR(TIM2) = 1u;
  TIM_SR(TIM2) = 0u;
  TIM_DIER(TIM2) = 1u;
  NVIC_ISER0 = 1u << TIM2_IRQN;
  /* The controller at rest at the vented state and the force read now. */
  ctrl_reset(&controller, 0.0f, read_force_n());
  TIM_CR1(TIM2) = 1u;
}

int main(void) {
  setup();
  for (;;) __asm volatile("wfi");
}
