#ifndef PINBALL_FIRMWARE_CORE_HAL_H
#define PINBALL_FIRMWARE_CORE_HAL_H
/* The hardware a driver board gives the firmware core, and one pass of the
 * board's main loop over it. The output stage (set a coil's drive) is the
 * board's `set_coil` callback, called from inside the rules at the exact time
 * a rule acts; the rest is here: a monotonic clock, the CAN controller's
 * receive and transmit, the end-of-stroke switches. The STM32 board
 * (firmware_interface/stm32f446/) implements it on registers, the core's tests on a
 * scripted bus. */

#include "pinball/firmware/core/board.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct pbfw_hal {
  void* context;
  /* Monotonic time (ns), never backwards. */
  pbfw_time_ns (*now_ns)(void* context);
  /* Takes the next received frame; false when none is waiting. */
  bool (*receive)(void* context, pbfw_frame* frame);
  /* Hands a frame to the transmitter; false when it has no room now (the
   * frame stays queued on the board and is offered again next pass). */
  bool (*send)(void* context, const pbfw_frame* frame);
  /* The end-of-stroke switches, bit d closed for driver d, read at once (one
   * consistent sample, one port read); NULL when the board has none. */
  uint8_t (*end_of_stroke)(void* context);
} pbfw_hal;

/* One pass of the main loop, bounded so a flood of frames cannot starve the
 * timers or the hardware watchdog: reads the clock once, handles at most
 * `max_frames` received frames at that time, reads the switches, runs the
 * timers, then offers queued replies to the transmitter until it is full.
 * Returns the frames handled. */
unsigned pbfw_board_service(pbfw_board* board, const pbfw_hal* hal, unsigned max_frames);

#ifdef __cplusplus
}
#endif

#endif /* PINBALL_FIRMWARE_CORE_HAL_H */
