/* The independent watchdog (RM0390, IWDG chapter) and the reset cause.
 *
 * The IWDG runs from the LSI (its own RC oscillator, independent of every
 * clock clock.c sets up and of the core), so it resets the MCU when the main
 * loop stalls for any reason: a hang, a fault handler, a lost clock, a
 * lockup. Reset turns every coil off (coils.c).
 *
 * Timeout: prescaler /4 and reload 79 count 80 periods (RLR + 1: RM0390's
 * IWDG timeout table gives 0.125 ms for RLR 0 at /4), 80 * 4 / 32 kHz =
 * 10 ms at the LSI's nominal 32 kHz. The LSI is only specified between 17 and 47 kHz
 * (datasheet DS10693, LSI characteristics), so the real timeout is 6.8 to
 * 18.8 ms. Why 10 ms: a stalled loop must not leave a coil at full power
 * for long; 18.8 ms at worst is well under the protocol's 100 ms absolute
 * pulse cap and near its smallest host watchdog (10 ms), which is what the
 * IWDG stands in for when the core itself cannot run. The main loop
 * refreshes it every iteration: a few microseconds idle, under 1 ms even
 * with 16 frames to handle (docs/results.md), so even the shortest 6.8 ms
 * leaves a margin of 7x at worst.
 *
 * It keeps running while a debugger halts the core: a halted board resets
 * within 19 ms with its coils off, rather than holding a coil on under a
 * breakpoint. openocd's stm32f4x.cfg sets DBGMCU_APB1_FZ's DBG_IWDG_STOP
 * (and DBG_WWDG_STOP) when it attaches, which would freeze the IWDG under a
 * halt while the PWM timers run on (a coil at its pulse or hold duty until
 * someone resumes). So every refresh clears it again: microseconds after an
 * attach, long before anyone types `halt`. A bench build for single-stepping
 * with coil power off defines PBFW_IWDG_MAY_STOP_UNDER_HALT and keeps
 * whatever the debugger set. */

#include "drivers.h"
#include "registers.h"

#define IWDG_PRESCALER_DIV4 0u
#define IWDG_RELOAD 79u /* 80 periods of 125 us at 32 kHz / 4: 10 ms */

/* The prescaler and reload reach the LSI domain within 5 LSI periods
 * (RM0390, IWDG_SR PVU/RVU): under 300 us at 17 kHz. Bounded by a loop count
 * (>= 4 cycles each, >= 2.8 ms at 180 MHz); the IWDG's default reset
 * timeout, 512 ms, is running meanwhile. */
#define IWDG_UPDATE_WAIT_LOOPS 500000u

uint32_t reset_cause_take(void) {
  const uint32_t causes = RCC->CSR & (RCC_CSR_BORRSTF | RCC_CSR_PINRSTF | RCC_CSR_PORRSTF | RCC_CSR_SFTRSTF |
                                      RCC_CSR_IWDGRSTF | RCC_CSR_WWDGRSTF | RCC_CSR_LPWRRSTF);
  RCC->CSR |= RCC_CSR_RMVF; /* clears the flags for the next reset (RM0390, RCC_CSR) */
  return causes;
}

void iwdg_start(void) {
  /* The start key first: it also turns the LSI on (RM0390, IWDG functional
   * description), which the PR/RLR update below needs to complete. */
  IWDG->KR = IWDG_KR_START;
  IWDG->KR = IWDG_KR_UNLOCK;
  IWDG->PR = IWDG_PRESCALER_DIV4;
  IWDG->RLR = IWDG_RELOAD;
  for (uint32_t i = 0; i < IWDG_UPDATE_WAIT_LOOPS && (IWDG->SR & (IWDG_SR_PVU | IWDG_SR_RVU)) != 0u; ++i) {
  }
  /* A refresh loads the counter with the new reload value. If the update
   * had not completed, the old values stay in force: the default 512 ms,
   * still a reset. */
  IWDG->KR = IWDG_KR_REFRESH;
}

void iwdg_refresh(void) {
  IWDG->KR = IWDG_KR_REFRESH;
#ifndef PBFW_IWDG_MAY_STOP_UNDER_HALT
  DBGMCU->APB1_FZ &= ~DBGMCU_APB1_FZ_DBG_IWDG_STOP;
#endif
}
