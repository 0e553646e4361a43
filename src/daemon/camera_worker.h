#pragma once
// The camera thread (pb-camera): reads the next frame from its one
// FrameSource (the simulator's hand-off, or the lab camera or video file) or
// the next observation received on LCM, runs the camera stage (detector and
// tracker) on it, hands the projection to the controller thread and publishes
// the observation and the projection on LCM.

#include "frame_handoff.h"
#include "handoffs.h"
#include "pinball/bus/lcm_bus.h"
#include "pinball/vision/frame_source.h"

namespace pinball::daemon {

/// Where the camera thread's input comes from (camera.source, read once from the configuration).
enum class CameraInput : std::uint8_t {
  kFrames,  ///< frames of a FrameSource: the simulated camera's hand-off, a V4L2 camera or a video file
  kLcm,     ///< observations received on PINBALL_OBSERVATION (no frames)
};

/// One run() per daemon run, on its own thread.
class CameraWorker {
 public:
  /// Borrows everything. With kFrames, `frames` is read on this thread; `handoff`
  /// is that same source when it is the simulator's (it carries the contact
  /// switches), else null; `retry_failed_reads` keeps reading after a failed
  /// grab (a camera) instead of ending (a video file, the simulator).
  /// `observations` is read with kLcm only.
  /// Each processed input is a beat of h.liveness (kCameraBeat) at `clock`'s time.
  CameraWorker(Handoffs& handoffs, CameraStage& stage, bus::LcmBus& lcm, const PipelineClock& clock, CameraInput input,
               vision::FrameSource* frames, const FrameHandoffSource* handoff, bool retry_failed_reads,
               bus::ObservationRing& observations, cv::Size frame_size);
  /// Until the input ends or the daemon stops.
  void run();

 private:
  // Waits for the next input; false when it ended. `ready` tells whether one arrived.
  bool next(bool& ready);
  void process();
  void back_off_after_failed_read();

  Handoffs& h_;
  CameraStage& stage_;
  bus::LcmBus& lcm_;
  const PipelineClock& clock_;
  double retry_wait_s_ = 0.0;  // grows while a camera keeps failing, so a dead device does not spin
  CameraInput input_;
  vision::FrameSource* frames_;
  const FrameHandoffSource* handoff_;
  bool retry_failed_reads_;
  bus::ObservationRing& observations_;
  vision::Frame frame_;
  track::ContactSensors contacts_;
  double capture_wall_s_ = 0.0;
  pinball_lcm::lcmt_pinball_observation incoming_;
  ProjectionRecord record_;
};

}  // namespace pinball::daemon
