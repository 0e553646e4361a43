/* The 8 end-of-stroke switch inputs, on port C so one IDR read samples all
 * of them at the same instant:
 *
 *   driver | 0   | 1   | 2   | 3   | 4   | 5   | 6    | 7
 *   pin    | PC0 | PC1 | PC2 | PC3 | PC4 | PC5 | PC10 | PC11
 *
 * (PC6..PC9 are coil outputs, coils.c.) Each switch closes to ground; the
 * internal pull-up (30..50 kOhm, datasheet DS10693, I/O static characteristics) holds an open switch high,
 * so a missing switch reads open. The reading is raw, not debounced: Status
 * reports it every 10 ms and the host judges it. */

#include "drivers.h"
#include "registers.h"

#define EOS_PINS_LOW 0x003Fu  /* PC0..PC5: drivers 0..5 */
#define EOS_PINS_HIGH 0x0C00u /* PC10, PC11: drivers 6, 7 */

void eos_init(void) {
  RCC->AHB1ENR |= RCC_AHB1ENR_GPIOCEN;
  (void)RCC->AHB1ENR;
  uint32_t moder_mask = 0u;
  uint32_t pull_ups = 0u;
  for (unsigned pin = 0; pin < 16u; ++pin) {
    if (((EOS_PINS_LOW | EOS_PINS_HIGH) >> pin) & 1u) {
      moder_mask |= 0x3u << (2u * pin);
      pull_ups |= GPIO_PULL_UP << (2u * pin);
    }
  }
  GPIOC->PUPDR = (GPIOC->PUPDR & ~moder_mask) | pull_ups;
  GPIOC->MODER &= ~moder_mask; /* 00: input */
}

uint8_t eos_read(void) {
  const uint32_t closed = ~GPIOC->IDR; /* low = closed */
  return (uint8_t)((closed & EOS_PINS_LOW) | ((closed & EOS_PINS_HIGH) >> 4));
}
