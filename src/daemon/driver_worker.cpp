#include "driver_worker.h"

#include "pinball/bus/message_convert.h"
#include "pinball/core/clock.h"

namespace pinball::daemon {

void DriverWorker::run() {
  CommandRecord c;
  double next_status_s = 0.0;
  std::uint64_t status_seq = 0;
  const bool lockstep = clock_.lockstep();
  while (!h_.stop.load(std::memory_order_acquire)) {
    h_.take_injected_fault(kDriverThread);
    std::uint64_t done = 0;
    if (lockstep) {
      done = h_.records_done.load(std::memory_order_acquire);
      if (done == h_.driver_done.load(std::memory_order_relaxed)) {
        if (h_.controller_done.load(std::memory_order_acquire)) break;
        h_.driver_bell.wait(0.05);
        continue;
      }
    } else {
      h_.driver_bell.wait(0.001);
      if (h_.controller_done.load(std::memory_order_acquire) && h_.commands.empty()) break;
    }
    const double now = clock_.now_s();
    bus_.poll_once(now);
    const double polled = steady_now_s();
    while (h_.commands.try_pop(c)) {
      const double written = c.written_wall_s > 0.0 ? c.written_wall_s : polled;  // > 0: sent by the controller thread
      h_.latency[kCommandToCan].record((written - c.command_wall_s) * 1e6);
      if (c.capture_wall_s > 0.0) h_.latency[kFrameToCan].record((written - c.capture_wall_s) * 1e6);
      if (c.energize && c.flipper >= 0) {
        h_.can_written_wall_s[static_cast<std::size_t>(driver_of_flipper_[static_cast<std::size_t>(c.flipper)])]
            .store(written);
      }
    }
    if (now >= next_status_s) {
      next_status_s = now + 0.1;
      lcm_.try_publish(bus::to_lcm_driver_status(to_utime(now), static_cast<std::int64_t>(status_seq++), bus_.state(),
                                                 bus_.board(), bus_.counters()));
    }
    if (lockstep) {
      h_.driver_done.store(done, std::memory_order_release);
      h_.sim_bell.ring();
    }
  }
  if (lockstep) {
    h_.driver_done.store(~std::uint64_t{0}, std::memory_order_release);
    h_.sim_bell.ring();
  }
}

}  // namespace pinball::daemon
