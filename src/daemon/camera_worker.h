#pragma once
// The camera thread (pb-camera): takes the next frame (from the simulator's
// hand-off, or grabbed from the lab camera) or the next observation received
// on LCM, runs the camera stage (detector and tracker) on it, hands the
// projection to the controller thread and publishes the observation and the
// projection on LCM.

#include "handoffs.h"
#include "pinball/bus/lcm_bus.h"
#include "pinball/vision/capture_source.h"

namespace pinball::daemon {

/// Where the camera thread's input comes from (camera.source, read once from the configuration).
enum class CameraInput : std::uint8_t {
  kSimulator,  ///< frames the simulator thread hands over (Handoffs::frames)
  kCapture,    ///< a V4L2 camera or a video file, grabbed on this thread
  kLcm,        ///< observations received on PINBALL_OBSERVATION (no frames)
};

/// One run() per daemon run, on its own thread.
class CameraWorker {
 public:
  /// Borrows everything; `capture` is used with kCapture only (`capture_is_device`: a
  /// camera, whose failed grab is retried, not a video file, whose end ends the run),
  /// `observations` with kLcm only.
  CameraWorker(Handoffs& handoffs, CameraStage& stage, bus::LcmBus& lcm, CameraInput input,
               vision::CaptureSource* capture, bool capture_is_device, bus::ObservationRing& observations)
      : h_(handoffs),
        stage_(stage),
        lcm_(lcm),
        input_(input),
        capture_(capture),
        capture_is_device_(capture_is_device),
        observations_(observations) {}
  /// Until the input ends or the daemon stops.
  void run();

 private:
  // Waits for the next input: a frame slot (nullptr with `incoming` filled for kLcm). False: the input ended.
  bool next(const FrameSlot*& slot, pinball_lcm::lcmt_pinball_observation& incoming, bool& ready);
  void process(const FrameSlot* slot, const pinball_lcm::lcmt_pinball_observation& incoming);

  Handoffs& h_;
  CameraStage& stage_;
  bus::LcmBus& lcm_;
  CameraInput input_;
  vision::CaptureSource* capture_;
  bool capture_is_device_;
  bus::ObservationRing& observations_;
  FrameSlot lab_slot_;
  ProjectionRecord record_;
};

}  // namespace pinball::daemon
