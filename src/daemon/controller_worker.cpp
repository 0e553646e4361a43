#include "controller_worker.h"

#include "pinball/bus/message_convert.h"
#include "pinball/core/clock.h"
#include "pinball/daemon/hot_path.h"

namespace pinball::daemon {

// Writes the commands' CAN frames on the controller thread, saving the wake-up
// of the driver thread; when the driver thread is busy sending, it takes them.
void ControllerWorker::send_now(ControllerStage::Commands& cmds, int n, double now_s) {
  if (n == 0 || !bus_.send_queued(now_s, firmware::DriverBus::WhenFull::kLeaveQueued)) return;
  const double written = steady_now_s();
  for (int i = 0; i < n; ++i) cmds[static_cast<std::size_t>(i)].written_wall_s = written;
}

void ControllerWorker::publish(const ControllerStage::Commands& cmds, int n) {
  for (int i = 0; i < n; ++i) {
    const CommandRecord& c = cmds[static_cast<std::size_t>(i)];
    if (!h_.commands.try_push(c)) h_.ring_overflows.fetch_add(1, std::memory_order_relaxed);
    lcm_.try_publish(bus::to_lcm_flipper_command(to_utime(c.t_s), static_cast<std::int64_t>(c.seq), c.projection_seq,
                                                 c.flipper, c.energize, static_cast<std::int8_t>(c.cause)));
  }
}

void ControllerWorker::run() {
  ProjectionRecord record;
  ControllerStage::Commands cmds;
  const bool lockstep = clock_.lockstep();
  while (!h_.stop.load(std::memory_order_acquire)) {
    h_.take_injected_fault(kControllerThread);
    if (h_.records.try_pop(record)) {
      HotPathScope hot;
      if (lockstep) h_.virtual_now_s.store(record.t_s, std::memory_order_release);
      const double now = lockstep ? record.t_s : clock_.now_s();
      beat(now);
      const int n = stage_.on_record(record, now, steady_now_s(), cmds);
      send_now(cmds, n, now);
      h_.latency[kProjectionToDecision].record((steady_now_s() - record.projected_wall_s) * 1e6);
      publish(cmds, n);
      h_.records_done.fetch_add(1, std::memory_order_acq_rel);
      h_.driver_bell.ring();
      continue;
    }
    if (h_.camera_done.load(std::memory_order_acquire) && h_.records.empty()) break;
    h_.controller_bell.wait(frame_period_s_);
    if (!lockstep) {
      HotPathScope hot;
      const double now = clock_.now_s();
      beat(now);  // alive between frames too: a missing camera is the camera's beat's business
      const int n = stage_.on_idle(now, steady_now_s(), cmds);
      send_now(cmds, n, now);
      if (n > 0) {
        publish(cmds, n);
        h_.driver_bell.ring();
      }
    }
  }
  if (h_.liveness != nullptr) h_.liveness->retire(kControllerBeat);  // done on purpose: not a stall
  h_.controller_done.store(true, std::memory_order_release);
  h_.driver_bell.ring();
}

}  // namespace pinball::daemon
