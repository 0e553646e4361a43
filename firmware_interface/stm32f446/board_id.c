/* The board id, the low nibble of every frame id (PROTOCOL.md, Frames).
 *
 * Four straps on PB12..PB15 (Nucleo-F446RE CN10-16, -30, -28, -26), bit 0 on
 * PB12: each has the internal pull-up, and a jumper to ground sets its bit,
 * so a board without jumpers is board 0. Read once at start-up: the id
 * cannot change under a running session.
 *
 * A build may fix the id instead (cmake -DPINBALL_BOARD_ID=n), for a board
 * without straps; the straps are then not read. */

#include "drivers.h"
#include "registers.h"

#ifdef PINBALL_BOARD_ID
_Static_assert(PINBALL_BOARD_ID >= 0 && PINBALL_BOARD_ID <= 15, "PINBALL_BOARD_ID is 0..15");

uint8_t board_id_read(void) { return (uint8_t)PINBALL_BOARD_ID; }

#else

#define STRAP_FIRST_PIN 12u
#define STRAP_FIELD2_MASK (0xFFu << (2u * STRAP_FIRST_PIN))

uint8_t board_id_read(void) {
  RCC->AHB1ENR |= RCC_AHB1ENR_GPIOBEN;
  (void)RCC->AHB1ENR;
  GPIOB->PUPDR = (GPIOB->PUPDR & ~STRAP_FIELD2_MASK) | ((GPIO_PULL_UP * 0x55u) << (2u * STRAP_FIRST_PIN));
  GPIOB->MODER &= ~STRAP_FIELD2_MASK; /* inputs */
  /* The pull-ups charge the pins' capacitance (a few pF through ~40 kOhm:
   * well under 1 us); read a few times and take the last. */
  uint32_t idr = 0u;
  for (unsigned i = 0; i < 64u; ++i) idr = GPIOB->IDR;
  return (uint8_t)((~idr >> STRAP_FIRST_PIN) & 0xFu);
}

#endif
