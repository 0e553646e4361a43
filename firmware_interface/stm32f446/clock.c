/* The clock tree: 8 MHz HSE bypass -> PLL -> 180 MHz, APB1 45 MHz, APB2
 * 90 MHz; or, when any step does not complete in time, the 16 MHz HSI the
 * MCU reset on.
 *
 * The Nucleo-F446RE feeds OSC_IN with the ST-LINK's 8 MHz MCO output (user
 * manual UM1724, OSC clock "MCO from ST-LINK", the default solder bridges):
 * an external clock, not a crystal, hence HSE bypass (RM0390, RCC "HSE
 * clock").
 *
 * PLL (RM0390, RCC "PLL" and RCC_PLLCFGR): f_in = 8 MHz / M(4) = 2 MHz (the
 * manual recommends 2 MHz to limit jitter), VCO = 2 MHz * N(180) = 360 MHz (within
 * 100..432), SYSCLK = VCO / P(2) = 180 MHz. PLLQ = 8 (45 MHz) and PLLR = 2
 * feed only USB/SDIO and I2S/SAI, which are unused.
 *
 * 180 MHz needs voltage scale 1 with over-drive (RM0390, PWR, over-drive)
 * and 5 flash wait states at 2.7..3.6 V (RM0390, the flash wait-state
 * table). APB1 may run at most 45 MHz and APB2 90 MHz (RM0390, RCC
 * "Clocks"): /4 and /2.
 *
 * Every wait on a ready flag is bounded (CLOCK_WAIT_LOOPS). On a timeout the
 * tree goes back to the HSI and clock_tree says which step failed. QEMU does
 * not model the RCC (reads 0), so there the image runs on this fallback. */

#include "drivers.h"
#include "registers.h"

/* Each iteration reads one peripheral register (at least 2 AHB/APB cycles)
 * and compares and branches: >= 4 cycles, so >= 25 ms at 16 MHz, the longest
 * any step can take. HSE bypass is ready within a few clock edges, the PLL
 * locks within 100 us (datasheet DS10693, t_LOCK), the regulator switches in
 * well under 1 ms. */
#define CLOCK_WAIT_LOOPS 100000u

#define HSI_HZ 16000000u
#define PLL_M 4u
#define PLL_N 180u
#define PLL_P_DIV2 0u /* PLLP bits 00 = /2 */
#define PLL_Q 8u
#define PLL_R 2u
#define SYSCLK_PLL_HZ 180000000u
#define FLASH_WAIT_STATES_180MHZ 5u

/* Waits until (*reg & mask) == value, for at most CLOCK_WAIT_LOOPS reads. */
static bool wait_for(const reg32* reg, uint32_t mask, uint32_t value) {
  for (uint32_t i = 0; i < CLOCK_WAIT_LOOPS; ++i) {
    if ((*reg & mask) == value) return true;
  }
  return false;
}

/* Back to the reset clock: SYSCLK from HSI, no dividers, PLL, HSE and
 * over-drive off. Safe from any point of the bring-up: the switch to HSI
 * comes first, so nothing is ever clocked faster than its limit. */
static clock_tree fall_back_to_hsi(clock_step failed) {
  RCC->CR |= RCC_CR_HSION;
  (void)wait_for(&RCC->CR, RCC_CR_HSIRDY, RCC_CR_HSIRDY);
  RCC->CFGR = RCC_CFGR_SW_HSI; /* all prescalers /1 */
  (void)wait_for(&RCC->CFGR, RCC_CFGR_SWS_MASK, RCC_CFGR_SWS_HSI);
  RCC->CR &= ~(RCC_CR_PLLON | RCC_CR_CSSON | RCC_CR_HSEON);
  RCC->CR &= ~RCC_CR_HSEBYP; /* writable only with HSEON clear (RM0390, RCC_CR) */
  PWR->CR &= ~(PWR_CR_ODSWEN | PWR_CR_ODEN);
  /* 0 wait states are enough at 16 MHz; lowered after the frequency. */
  FLASH->ACR = FLASH_ACR_PRFTEN | FLASH_ACR_ICEN | FLASH_ACR_DCEN;
  clock_tree tree = {
      .source = CLOCK_HSI_16MHZ,
      .failed_step = failed,
      .sysclk_hz = HSI_HZ,
      .apb1_hz = HSI_HZ,
      .apb1_timer_hz = HSI_HZ, /* APB1 undivided: timers at PCLK1 x1 */
  };
  return tree;
}

clock_tree clock_init(void) {
  /* The power controller's clock, to select scale 1 and over-drive. The
   * read back makes the enable take effect before PWR is accessed
   * (RM0390, RCC: a delay after enabling a peripheral clock). */
  RCC->APB1ENR |= RCC_APB1_PWR;
  (void)RCC->APB1ENR;
  /* VOS is written while the PLL is off, and takes effect when it starts. */
  PWR->CR = (PWR->CR & ~(0x3u << PWR_CR_VOS_SHIFT)) | PWR_CR_VOS_SCALE1;

  /* HSE bypass: HSEBYP before HSEON (RM0390, RCC_CR). */
  RCC->CR |= RCC_CR_HSEBYP;
  RCC->CR |= RCC_CR_HSEON;
  if (!wait_for(&RCC->CR, RCC_CR_HSERDY, RCC_CR_HSERDY)) return fall_back_to_hsi(CLOCK_STEP_HSE_READY);

  /* PLLP's field is 0 for /2: written all the same, so every field is named. */
  /* cppcheck-suppress badBitmaskCheck */
  RCC->PLLCFGR = (PLL_M << RCC_PLLCFGR_PLLM_SHIFT) | (PLL_N << RCC_PLLCFGR_PLLN_SHIFT) |
                 (PLL_P_DIV2 << RCC_PLLCFGR_PLLP_SHIFT) | RCC_PLLCFGR_PLLSRC_HSE |
                 (PLL_Q << RCC_PLLCFGR_PLLQ_SHIFT) | (PLL_R << RCC_PLLCFGR_PLLR_SHIFT);
  RCC->CR |= RCC_CR_PLLON;

  /* Over-drive, in the order RM0390 (PWR, over-drive) gives: with the PLL
   * on, ODEN and wait ODRDY, then ODSWEN and wait ODSWRDY; then the PLL's
   * lock. */
  PWR->CR |= PWR_CR_ODEN;
  if (!wait_for(&PWR->CSR, PWR_CSR_ODRDY, PWR_CSR_ODRDY)) return fall_back_to_hsi(CLOCK_STEP_OVERDRIVE_READY);
  PWR->CR |= PWR_CR_ODSWEN;
  if (!wait_for(&PWR->CSR, PWR_CSR_ODSWRDY, PWR_CSR_ODSWRDY))
    return fall_back_to_hsi(CLOCK_STEP_OVERDRIVE_SWITCH);
  if (!wait_for(&RCC->CR, RCC_CR_PLLRDY, RCC_CR_PLLRDY)) return fall_back_to_hsi(CLOCK_STEP_PLL_READY);

  /* Wait states before the frequency goes up, checked by reading back
   * (RM0390, flash read latency); prefetch, instruction and data caches
   * (the ART accelerator, RM0390) hide most of them. */
  FLASH->ACR = FLASH_WAIT_STATES_180MHZ | FLASH_ACR_PRFTEN | FLASH_ACR_ICEN | FLASH_ACR_DCEN;
  if ((FLASH->ACR & FLASH_ACR_LATENCY_MASK) != FLASH_WAIT_STATES_180MHZ)
    return fall_back_to_hsi(CLOCK_STEP_FLASH_LATENCY);

  /* Bus dividers before the switch, so APB1 never sees more than 45 MHz;
   * AHB undivided (HPRE 0), written all the same. */
  /* cppcheck-suppress badBitmaskCheck */
  RCC->CFGR = (RCC->CFGR & RCC_CFGR_SW_MASK) | (0u << RCC_CFGR_HPRE_SHIFT) |
              (RCC_CFGR_PPRE_DIV4 << RCC_CFGR_PPRE1_SHIFT) | (RCC_CFGR_PPRE_DIV2 << RCC_CFGR_PPRE2_SHIFT);
  RCC->CFGR = (RCC->CFGR & ~RCC_CFGR_SW_MASK) | RCC_CFGR_SW_PLLP;
  if (!wait_for(&RCC->CFGR, RCC_CFGR_SWS_MASK, RCC_CFGR_SWS_PLLP)) return fall_back_to_hsi(CLOCK_STEP_SWITCH);

  /* Clock security system: if the MCO clock stops, the hardware switches to
   * HSI and raises the NMI (RM0390, RCC "Clock security system"), whose
   * handler switches the coils off and lets the IWDG reset the MCU, which
   * then boots on this code's HSI fallback. */
  RCC->CR |= RCC_CR_CSSON;

  clock_tree tree = {
      .source = CLOCK_HSE_PLL_180MHZ,
      .failed_step = CLOCK_STEP_NONE,
      .sysclk_hz = SYSCLK_PLL_HZ,
      .apb1_hz = SYSCLK_PLL_HZ / 4u,
      .apb1_timer_hz = SYSCLK_PLL_HZ / 2u, /* APB1 divided: timers at PCLK1 x2 */
  };
  return tree;
}
