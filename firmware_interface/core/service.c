/* One pass of a driver board's main loop over its HAL. */
#include "pinball/firmware/core/hal.h"

#include <stddef.h>

unsigned pbfw_board_service(pbfw_board* board, const pbfw_hal* hal, unsigned max_frames) {
  const pbfw_time_ns now = hal->now_ns(hal->context);
  unsigned handled = 0;
  pbfw_frame frame;
  while (handled < max_frames && hal->receive(hal->context, &frame)) {
    pbfw_board_on_frame(board, &frame, now);
    ++handled;
  }
  if (hal->end_of_stroke != NULL) {
    const uint8_t closed = hal->end_of_stroke(hal->context);
    for (unsigned d = 0; d < board->options.driver_count; ++d) pbfw_board_set_end_of_stroke(board, d, (closed >> d) & 1u);
  }
  pbfw_board_advance(board, now);
  while (pbfw_board_peek_tx(board, &frame) && hal->send(hal->context, &frame)) pbfw_board_pop_tx(board, &frame);
  return handled;
}
