#include "sim_worker.h"

#include <chrono>
#include <thread>

#include "pinball/bus/message_convert.h"
#include "pinball/core/clock.h"

namespace pinball::daemon {

void SimWorker::run() {
  std::uint64_t pushed = 0;
  std::uint64_t seq = 0;
  auto on_event = [&](const simlab::GameEvent& e) {
    lcm_.try_publish(bus::to_lcm_game_event(to_utime(e.t_s), static_cast<std::int64_t>(seq++), e.kind, e.ball,
                                            e.points, e.ball_time_s));
  };
  h_.wall_offset_s.store(steady_now_s() - world_.time_s(), std::memory_order_release);
  while (!h_.stop.load(std::memory_order_acquire)) {
    h_.take_injected_fault(kSimThread);
    FrameSlot& slot = h_.pool[pushed % kFramePool];
    if (!world_.next_frame(slot.frame, slot.contacts, on_event)) break;
    h_.sim_time_s.store(world_.time_s(), std::memory_order_relaxed);
    // Coil-on stamps of the virtual board close the latency chain.
    if (world_.coil_on_count() != last_coil_on_count_) {
      last_coil_on_count_ = world_.coil_on_count();
      for (int d = 0; d < drivers_; ++d) {
        const double written = h_.can_written_wall_s[static_cast<std::size_t>(d)].exchange(0.0);
        if (written > 0.0) h_.latency[kCanToCoil].record((world_.coil_on_wall_s(d) - written) * 1e6);
      }
    }
    if (!lockstep_) {
      // Pace to the wall clock.
      const double wait_s = slot.frame.t_s + h_.wall_offset_s.load(std::memory_order_acquire) - steady_now_s();
      if (wait_s > 0.0) std::this_thread::sleep_for(std::chrono::duration<double>(wait_s));
    }
    slot.capture_wall_s = steady_now_s();
    if (!h_.frames.try_push(static_cast<int>(pushed % kFramePool))) {
      h_.frames_dropped.fetch_add(1, std::memory_order_relaxed);  // the camera thread is behind: this frame is lost
      continue;
    }
    ++pushed;
    h_.frames_pushed.store(pushed, std::memory_order_release);
    h_.camera_bell.ring();
    if (lockstep_) {
      while (h_.driver_done.load(std::memory_order_acquire) < pushed && !h_.stop.load(std::memory_order_acquire)) {
        h_.sim_bell.wait(0.1);
      }
      wait_for_lcm_backlog();
    }
  }
  h_.producer_done.store(true, std::memory_order_release);
  h_.camera_bell.ring();
}

void SimWorker::wait_for_lcm_backlog() {
  constexpr double kHalfFull = 0.5;
  constexpr double kLcmStallS = 0.5;
  if (lcm_stalled_) return;
  double fill = lcm_.outbox_fill();
  double progress_s = steady_now_s();
  while (fill > kHalfFull && !h_.stop.load(std::memory_order_acquire)) {
    std::this_thread::sleep_for(std::chrono::microseconds(200));
    const double now_fill = lcm_.outbox_fill();
    const double now_s = steady_now_s();
    if (now_fill < fill) {
      progress_s = now_s;
    } else if (now_s - progress_s > kLcmStallS) {
      lcm_stalled_ = true;  // from here on what does not fit is dropped, and counted
      return;
    }
    fill = now_fill;
  }
}

}  // namespace pinball::daemon
