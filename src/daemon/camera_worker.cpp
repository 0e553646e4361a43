#include "camera_worker.h"

#include <chrono>
#include <thread>

#include "pinball/bus/message_convert.h"
#include "pinball/core/clock.h"
#include "pinball/daemon/hot_path.h"

namespace pinball::daemon {

bool CameraWorker::next(const FrameSlot*& slot, pinball_lcm::lcmt_pinball_observation& incoming, bool& ready) {
  slot = nullptr;
  ready = false;
  switch (input_) {
    case CameraInput::kSimulator: {
      int index = -1;
      if (!h_.frames.try_pop(index)) {
        if (h_.producer_done.load(std::memory_order_acquire) && h_.frames.empty()) return false;
        h_.camera_bell.wait(0.05);
        return true;
      }
      slot = &h_.pool[static_cast<std::size_t>(index)];
      ready = true;
      return true;
    }
    case CameraInput::kLcm:
      if (!observations_.try_pop(incoming)) {
        std::this_thread::sleep_for(std::chrono::microseconds(200));
        return true;
      }
      ready = true;
      return true;
    case CameraInput::kCapture:
      if (!capture_->read(lab_slot_.frame)) {  // the camera's own blocking grab
        return capture_is_device_;  // a camera retries; a video file has ended
      }
      lab_slot_.capture_wall_s = steady_now_s();
      slot = &lab_slot_;
      ready = true;
      return true;
  }
  return false;
}

void CameraWorker::process(const FrameSlot* slot, const pinball_lcm::lcmt_pinball_observation& incoming) {
  HotPathScope hot;
  if (slot != nullptr) {
    stage_.process(slot->frame, slot->contacts, slot->capture_wall_s, record_);
  } else {
    bool found = false;
    track::Observation o;
    track::ContactSensors c;
    bus::from_lcm_observation(incoming, found, o, c);
    const double now = steady_now_s();
    stage_.track(found, o, o.t_s, c, now, record_);
    record_.detected_wall_s = now;
  }
  record_.projected_wall_s = steady_now_s();
  if (slot != nullptr) {
    h_.latency[kCaptureToDetection].record((record_.detected_wall_s - record_.capture_wall_s) * 1e6);
  }
  h_.latency[kDetectionToProjection].record((record_.projected_wall_s - record_.detected_wall_s) * 1e6);
  if (!h_.records.try_push(record_)) h_.ring_overflows.fetch_add(1, std::memory_order_relaxed);
  h_.controller_bell.ring();
  const std::int64_t utime = to_utime(record_.t_s);
  if (input_ != CameraInput::kLcm) {
    lcm_.try_publish(bus::to_lcm_observation(utime, static_cast<std::int64_t>(record_.frame_seq), record_.found,
                                             record_.observation, record_.u_px, record_.v_px, record_.contacts));
  }
  lcm_.try_publish(bus::to_lcm_projection(utime, static_cast<std::int64_t>(record_.seq),
                                          static_cast<std::int64_t>(record_.frame_seq), record_.output));
}

void CameraWorker::run() {
  pinball_lcm::lcmt_pinball_observation incoming;
  while (!h_.stop.load(std::memory_order_acquire)) {
    const FrameSlot* slot = nullptr;
    bool ready = false;
    if (!next(slot, incoming, ready)) break;
    if (ready) process(slot, incoming);
  }
  h_.camera_done.store(true, std::memory_order_release);
  h_.controller_bell.ring();
}

}  // namespace pinball::daemon
