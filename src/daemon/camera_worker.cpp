#include "camera_worker.h"

#include <algorithm>
#include <chrono>
#include <thread>

#include "pinball/bus/message_convert.h"
#include "pinball/core/clock.h"
#include "pinball/daemon/hot_path.h"

namespace pinball::daemon {

CameraWorker::CameraWorker(Handoffs& handoffs, CameraStage& stage, bus::LcmBus& lcm, const PipelineClock& clock,
                           CameraInput input,
                           vision::FrameSource* frames, const FrameHandoffSource* handoff, bool retry_failed_reads,
                           bus::ObservationRing& observations, cv::Size frame_size)
    : h_(handoffs),
      stage_(stage),
      lcm_(lcm),
      clock_(clock),
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
    if (!retry_failed_reads_ || h_.stop.load(std::memory_order_acquire)) return false;
    back_off_after_failed_read();
    return true;
  }
  retry_wait_s_ = 0.0;
  if (handoff_ != nullptr) {
    contacts_ = handoff_->contacts();
    capture_wall_s_ = handoff_->capture_wall_s();
  } else {
    capture_wall_s_ = steady_now_s();  // a lab camera: no contact switches on this path yet
  }
  ready = true;
  return true;
}

// A camera that fails (unplugged, driver error) is retried with a growing
// wait, 1 ms to 100 ms, and counted: the daemon raises the alarm. No frame
// means no beat, so the CAN heartbeat stops and the board drops the coils.
void CameraWorker::back_off_after_failed_read() {
  h_.camera_read_failures.fetch_add(1, std::memory_order_relaxed);
  h_.main_bell.ring();
  retry_wait_s_ = std::clamp(retry_wait_s_ * 2.0, 0.001, 0.1);
  std::this_thread::sleep_for(std::chrono::duration<double>(retry_wait_s_));
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
    stage_.track(found, o, from_utime(incoming_.delivered_utime), c, now, record_);
    record_.detected_wall_s = now;
  }
  record_.projected_wall_s = steady_now_s();
  if (from_frames) {
    h_.latency[kCaptureToDetection].record((record_.detected_wall_s - record_.capture_wall_s) * 1e6);
  }
  h_.latency[kDetectionToProjection].record((record_.projected_wall_s - record_.detected_wall_s) * 1e6);
  if (!h_.records.try_push(record_)) h_.ring_overflows.fetch_add(1, std::memory_order_relaxed);
  h_.controller_bell.ring();
  // Dated as the tracker saw it: the ball's exposure, and the frame's stamp.
  const std::int64_t utime = to_utime(record_.found ? record_.observation.t_s : record_.t_s);
  if (from_frames) {
    lcm_.try_publish(bus::to_lcm_observation(utime, to_utime(record_.t_s), static_cast<std::int64_t>(record_.frame_seq),
                                             record_.found, record_.observation, record_.u_px, record_.v_px,
                                             record_.contacts));
  }
  lcm_.try_publish(bus::to_lcm_projection(utime, static_cast<std::int64_t>(record_.seq),
                                          static_cast<std::int64_t>(record_.frame_seq), record_.output));
  // Progress: in lockstep at the frame's own time (the driver polls on that
  // clock), else now (a lab frame's exposure time lags by the camera's latency).
  if (h_.liveness != nullptr) h_.liveness->beat(kCameraBeat, clock_.lockstep() ? record_.t_s : clock_.now_s());
}

void CameraWorker::run() {
  while (!h_.stop.load(std::memory_order_acquire)) {
    h_.take_injected_fault(kCameraThread);
    bool ready = false;
    if (!next(ready)) break;
    if (ready) process();
  }
  if (h_.liveness != nullptr) h_.liveness->retire(kCameraBeat);  // done on purpose: not a stall
  h_.camera_done.store(true, std::memory_order_release);
  h_.controller_bell.ring();
}

}  // namespace pinball::daemon
