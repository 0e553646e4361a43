#include "handoffs.h"

#include "pinball/core/clock.h"

namespace pinball::daemon {

double PipelineClock::now_s() const {
  if (!sim_mode_) return steady_now_s();
  if (lockstep_) return handoffs_.virtual_now_s.load(std::memory_order_acquire);
  return steady_now_s() - handoffs_.wall_offset_s.load(std::memory_order_acquire);
}

}  // namespace pinball::daemon
