#include "frame_handoff.h"

#include <utility>

namespace pinball::daemon {

bool FrameHandoffSource::read(vision::Frame& out) {
  int index = -1;
  while (!h_.frames.try_pop(index)) {
    if (h_.stop.load(std::memory_order_acquire)) return false;
    if (h_.producer_done.load(std::memory_order_acquire) && h_.frames.empty()) return false;
    h_.camera_bell.wait(0.05);
  }
  FrameSlot& slot = h_.pool[static_cast<std::size_t>(index)];
  std::swap(out.gray, slot.frame.gray);  // the slot keeps the reader's old buffer for the next frame
  out.t_s = slot.frame.t_s;
  out.driver_t_s = slot.frame.driver_t_s;
  out.sequence = slot.frame.sequence;
  contacts_ = slot.contacts;
  capture_wall_s_ = slot.capture_wall_s;
  ++counters_.frames;
  return true;
}

}  // namespace pinball::daemon
