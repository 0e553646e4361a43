/* The monotonic clock: TIM2, a 32-bit general-purpose timer (RM0390, TIM2
 * to TIM5), counting up at 1 MHz from reset to 0xFFFFFFFF and around, extended in
 * software to 64 bits and handed to the core in its unit, nanoseconds.
 *
 * No interrupt: the count wraps every 2^32 us (71.6 min), and time_ns adds
 * the unsigned difference since its previous call, which is right for any
 * gap shorter than that. The main loop calls it every iteration and the
 * IWDG resets the MCU if the loop stops for IWDG_TIMEOUT_MS, so the gap is
 * never near the limit. */

#include "drivers.h"
#include "registers.h"

#define TIME_TICK_HZ 1000000u

static uint32_t last_count;
static int64_t elapsed_us;

void time_init(const clock_tree* clock) {
  RCC->APB1ENR |= RCC_APB1_TIM2;
  (void)RCC->APB1ENR;
  /* A reset of the block leaves every register at its documented value. */
  RCC->APB1RSTR |= RCC_APB1_TIM2;
  RCC->APB1RSTR &= ~RCC_APB1_TIM2;

  /* 90 MHz / 90 or 16 MHz / 16: PSC holds the divider minus one
   * (RM0390, TIMx_PSC); both trees give an exact 1 MHz. */
  TIM2->PSC = clock->apb1_timer_hz / TIME_TICK_HZ - 1u;
  TIM2->ARR = 0xFFFFFFFFu;
  /* PSC is buffered (RM0390, time-base unit): the update event generated
   * here loads it now instead of at the first overflow, and zeroes the
   * counter. */
  TIM2->EGR = TIM_EGR_UG;
  TIM2->SR = 0u;
  TIM2->CR1 = TIM_CR1_CEN;

  last_count = TIM2->CNT;
  elapsed_us = 0;
}

pbfw_time_ns time_ns(void) {
  const uint32_t count = TIM2->CNT;
  elapsed_us += (uint32_t)(count - last_count); /* modulo 2^32: right across the wrap */
  last_count = count;
  return elapsed_us * 1000; /* 2^63 ns is 292 years: no overflow */
}

uint32_t time_raw_count(void) { return TIM2->CNT; }
