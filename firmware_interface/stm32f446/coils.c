/* The 8 coil gate outputs: hardware PWM on TIM3 and TIM4, channels 1..4.
 *
 *   driver | pin | timer channel | Nucleo-F446RE
 *   -------+-----+---------------+--------------------
 *     0    | PC6 | TIM3_CH1 AF2  | CN10-4
 *     1    | PC7 | TIM3_CH2 AF2  | CN10-19 (Arduino D9)
 *     2    | PC8 | TIM3_CH3 AF2  | CN10-2
 *     3    | PC9 | TIM3_CH4 AF2  | CN10-1
 *     4    | PB6 | TIM4_CH1 AF2  | CN10-17 (Arduino D10)
 *     5    | PB7 | TIM4_CH2 AF2  | CN7-21
 *     6    | PB8 | TIM4_CH3 AF2  | CN10-3 (Arduino D15)
 *     7    | PB9 | TIM4_CH4 AF2  | CN10-5 (Arduino D14)
 *
 * (alternate functions: datasheet DS10693, alternate function table; header
 * pins: user manual UM1724, the Nucleo-64 morpho and Arduino connectors.)
 *
 * PWM at 20 kHz with 1 % steps: each timer counts at 2 MHz (PSC) through
 * ARR = 99, so CCR is the duty in percent, exactly, on either clock tree.
 * 20 kHz is above hearing, so a held coil does not whine; a solenoid's L/R
 * time constant (milliseconds) is far longer than the 50 us period, so the
 * current ripple is small; and the switching loss of a logic-level MOSFET
 * with a gate driver is still small at that rate. PWM mode 1 (RM0390,
 * "PWM mode"): the output is high while CNT < CCR, so CCR = 0 is low all the
 * time and CCR = 100 > ARR is high all the time (a pulse).
 *
 * CCR preload is off (OCxPE = 0): a new duty, and above all 0, takes effect
 * at once rather than at the next period; the price is at most one
 * shortened or stretched period on a change, which a coil cannot notice.
 *
 * Off at reset: after any reset these pins are floating inputs (RM0390,
 * GPIO functional description) until coils_safe runs, and they float again
 * while the MCU is held in reset, so the board needs an external pull-down on every gate
 * (10 kOhm gate to source at the MOSFET or gate driver input): that resistor,
 * not the firmware, keeps the coils off while the MCU is in reset. The
 * firmware then drives the pins low (coils_safe) before anything else, and
 * hands them to the timers only once every channel is at 0 %. */

#include "drivers.h"
#include "registers.h"

#define PWM_COUNTER_HZ 2000000u
#define PWM_PERIOD_COUNTS 100u /* ARR + 1: 20 kHz, CCR in percent */

/* Driver d's timer channel: a function of d, not a table in RAM, so the
 * emergency path depends on nothing a runaway program may have overwritten. */
static tim_regs* coil_timer(unsigned d) { return d < 4u ? TIM3 : TIM4; }
static unsigned coil_channel(unsigned d) { return d & 3u; } /* 0..3 = CH1..CH4 */

/* The coil pins are 6..9 on both ports (PC for drivers 0..3, PB for 4..7). */
#define COIL_PINS_MASK (0xFu << 6)
/* The 2-bit fields of pins 6..9 in MODER, PUPDR, OSPEEDR, and a value in all four. */
#define PINS_FIELD2_MASK (0xFFu << 12)
#define PINS_FIELD2(v) (((v)*0x55u) << 12)

/* Drives PC6..9 and PB6..9 low as plain push-pull outputs: the output
 * register first, so no pin ever drives high on the way. */
static void drive_low(gpio_regs* port) {
  port->BSRR = COIL_PINS_MASK << 16; /* reset half: ODR bits to 0 */
  port->OTYPER &= ~COIL_PINS_MASK;
  port->PUPDR = (port->PUPDR & ~PINS_FIELD2_MASK) | PINS_FIELD2(GPIO_PULL_DOWN);
  port->MODER = (port->MODER & ~PINS_FIELD2_MASK) | PINS_FIELD2(GPIO_MODE_OUTPUT);
}

void coils_safe(void) {
  RCC->AHB1ENR |= RCC_AHB1ENR_GPIOBEN | RCC_AHB1ENR_GPIOCEN;
  (void)RCC->AHB1ENR;
  drive_low(GPIOC);
  drive_low(GPIOB);
}

static void start_timer(tim_regs* timer, uint32_t apb1_bit, uint32_t timer_hz) {
  RCC->APB1ENR |= apb1_bit;
  (void)RCC->APB1ENR;
  RCC->APB1RSTR |= apb1_bit;
  RCC->APB1RSTR &= ~apb1_bit;
  timer->PSC = timer_hz / PWM_COUNTER_HZ - 1u; /* 44 at 90 MHz, 7 at 16 MHz */
  timer->ARR = PWM_PERIOD_COUNTS - 1u;
  for (unsigned ch = 0; ch < 4u; ++ch) timer->CCR[ch] = 0u;
  const uint32_t pwm1_both =
      (TIM_CCMR_OCM_PWM1 << TIM_CCMR_OCM_SHIFT(0u)) | (TIM_CCMR_OCM_PWM1 << TIM_CCMR_OCM_SHIFT(1u));
  timer->CCMR1 = pwm1_both; /* CH1, CH2: PWM mode 1, no preload, outputs */
  timer->CCMR2 = pwm1_both; /* CH3, CH4 */
  timer->CCER = TIM_CCER_CCE(0u) | TIM_CCER_CCE(1u) | TIM_CCER_CCE(2u) | TIM_CCER_CCE(3u); /* active high */
  timer->EGR = TIM_EGR_UG; /* load PSC now: it is buffered (RM0390, time-base unit) */
  timer->CR1 = TIM_CR1_ARPE | TIM_CR1_CEN;
}

static void hand_to_timer(gpio_regs* port) {
  /* AF2 on pins 6, 7 (AFR[0]) and 8, 9 (AFR[1]). */
  port->AFR[0] = (port->AFR[0] & ~(0xFFu << 24)) | (GPIO_AF2_TIM3_4_5 * 0x11u) << 24;
  port->AFR[1] = (port->AFR[1] & ~0xFFu) | (GPIO_AF2_TIM3_4_5 * 0x11u);
  port->OSPEEDR = (port->OSPEEDR & ~PINS_FIELD2_MASK) | PINS_FIELD2(GPIO_SPEED_MEDIUM);
  port->MODER = (port->MODER & ~PINS_FIELD2_MASK) | PINS_FIELD2(GPIO_MODE_AF);
}

void coils_start_pwm(const clock_tree* clock) {
  start_timer(TIM3, RCC_APB1_TIM3, clock->apb1_timer_hz);
  start_timer(TIM4, RCC_APB1_TIM4, clock->apb1_timer_hz);
  /* Every channel is at CCR 0, its output low: the pins change hands
   * without a glitch. */
  hand_to_timer(GPIOC);
  hand_to_timer(GPIOB);
}

void coils_set_duty(unsigned d, uint8_t duty_pct) {
  if (d >= COIL_COUNT) return;
  coil_timer(d)->CCR[coil_channel(d)] = duty_pct > 100u ? 100u : duty_pct;
}

bool coils_apply(unsigned d, pbfw_coil_state state, uint8_t duty_pct) {
  uint8_t duty = 0u;
  bool within_cap = true;
  if (state == PBFW_COIL_PULSE) {
    duty = 100u;
  } else if (state == PBFW_COIL_HOLD) {
    within_cap = duty_pct <= PBFW_ABS_MAX_HOLD_DUTY_PCT;
    duty = within_cap ? duty_pct : (uint8_t)PBFW_ABS_MAX_HOLD_DUTY_PCT;
  }
  coils_set_duty(d, duty);
  return within_cap;
}

uint8_t coils_duty(unsigned d) {
  if (d >= COIL_COUNT) return 0u;
  const uint32_t ccr = coil_timer(d)->CCR[coil_channel(d)];
  return (uint8_t)(ccr > 100u ? 100u : ccr);
}

void coils_emergency_off(void) {
  /* Also zero the duties, in case the pins stay with the timers somehow. */
  for (unsigned ch = 0; ch < 4u; ++ch) {
    TIM3->CCR[ch] = 0u;
    TIM4->CCR[ch] = 0u;
  }
  RCC->AHB1ENR |= RCC_AHB1ENR_GPIOBEN | RCC_AHB1ENR_GPIOCEN;
  (void)RCC->AHB1ENR;
  drive_low(GPIOC);
  drive_low(GPIOB);
}
