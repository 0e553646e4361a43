#include "handoffs.h"

#include <chrono>
#include <stdexcept>
#include <thread>

#include "pinball/core/clock.h"

namespace pinball::daemon {

double PipelineClock::now_s() const {
  if (!sim_mode_) return steady_now_s();
  if (lockstep_) return handoffs_.virtual_now_s.load(std::memory_order_acquire);
  return steady_now_s() - handoffs_.wall_offset_s.load(std::memory_order_acquire);
}

void Handoffs::take_injected_fault(ThreadId id) {
  InjectedFault& f = injected[static_cast<std::size_t>(id)];
  if (f.freeze_s.load(std::memory_order_relaxed) > 0.0) {
    std::this_thread::sleep_for(std::chrono::duration<double>(f.freeze_s.exchange(0.0)));
  }
  if (f.fail.load(std::memory_order_relaxed) && f.fail.exchange(false)) {
    throw std::runtime_error(std::string("injected failure of ") + kThreadTable[static_cast<std::size_t>(id)].name);
  }
}

}  // namespace pinball::daemon
