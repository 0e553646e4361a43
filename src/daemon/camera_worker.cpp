#include "camera_worker.h"

#include <chrono>
#include <thread>

#include "pinball/bus/message_convert.h"
#include "pinball/core/clock.h"
#include "pinball/daemon/hot_path.h"

namespace pinball::daemon {

CameraWorker::CameraWorker(Handoffs& handoffs, CameraStage& stage, bus::LcmBus& lcm, CameraInput input,
                           vision::FrameSource* frames, const FrameHandoffSource* handoff, bool retry_failed_reads,
                           bus::ObservationRing& observations, cv::Size frame_size)
    : h_(handoffs),
      stage_(stage),
      lcm_(lcm),
      input_(input),
      frames_(frames),
      handoff_(handoff),
      retry_failed_reads_(retry_failed_reads),
      observations_(observations) {
  frame_.gray.create(frame_size, CV_8UC1);  // the buffer a hand-off read swaps with the pool's
}

bool CameraWorker::next(bool& ready) {
  ready = false;
  if (input_ == CameraInput::kLcm) {
    if (!observations_.try_pop(incoming_)) {
      std::this_thread::sleep_for(std::chrono::microseconds(200));
      return true;
    }
    ready = true;
    return true;
  }
  if (!frames_->read(frame_)) {  // the camera's own blocking grab, or the hand-off's wait
    return retry_failed_reads_ && !h_.stop.load(std::memory_order_acquire);
  }
  if (handoff_ != nullptr) {
    contacts_ = handoff_->contacts();
    capture_wall_s_ = handoff_->capture_wall_s();
  } else {
    capture_wall_s_ = steady_now_s();  // a lab camera: no contact switches on this path yet
  }
  ready = true;
  return true;
}

void CameraWorker::process() {
  HotPathScope hot;
  const bool from_frames = input_ == CameraInput::kFrames;
  if (from_frames) {
    stage_.process(frame_, contacts_, capture_wall_s_, record_);
  } else {
    bool found = false;
    track::Observation o;
    track::ContactSensors c;
    bus::from_lcm_observation(incoming_, found, o, c);
    const double now = steady_now_s();
    stage_.track(found, o, o.t_s, c, now, record_);
    record_.detected_wall_s = now;
  }
  record_.projected_wall_s = steady_now_s();
  if (from_frames) {
    h_.latency[kCaptureToDetection].record((record_.detected_wall_s - record_.capture_wall_s) * 1e6);
  }
  h_.latency[kDetectionToProjection].record((record_.projected_wall_s - record_.detected_wall_s) * 1e6);
  if (!h_.records.try_push(record_)) h_.ring_overflows.fetch_add(1, std::memory_order_relaxed);
  h_.controller_bell.ring();
  const std::int64_t utime = to_utime(record_.t_s);
  if (from_frames) {
    lcm_.try_publish(bus::to_lcm_observation(utime, static_cast<std::int64_t>(record_.frame_seq), record_.found,
                                             record_.observation, record_.u_px, record_.v_px, record_.contacts));
  }
  lcm_.try_publish(bus::to_lcm_projection(utime, static_cast<std::int64_t>(record_.seq),
                                          static_cast<std::int64_t>(record_.frame_seq), record_.output));
}

void CameraWorker::run() {
  while (!h_.stop.load(std::memory_order_acquire)) {
    bool ready = false;
    if (!next(ready)) break;
    if (ready) process();
  }
  h_.camera_done.store(true, std::memory_order_release);
  h_.controller_bell.ring();
}

}  // namespace pinball::daemon
