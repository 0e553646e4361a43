#pragma once
// The simulator's frames as the camera thread sees them: a vision::FrameSource
// over the hand-off queue, so that the camera thread reads one FrameSource in
// simulation as in the lab (docs/vision.md). A read swaps the image buffer
// with the pool's slot (no copy, no allocation). The flipper contact switches
// and the hand-over time travel with the frame in simulation; a lab camera
// has neither, so they are asked of this source, not of FrameSource.

#include "handoffs.h"
#include "pinball/vision/frame_source.h"

namespace pinball::daemon {

/// Reads the frames the simulator thread hands over.
class FrameHandoffSource final : public vision::FrameSource {
 public:
  /// Borrows the hand-offs; `fps` and `size` describe the simulated camera.
  FrameHandoffSource(Handoffs& handoffs, double fps, cv::Size size) : h_(handoffs), fps_(fps), size_(size) {}

  /// Waits for the next frame; false once the simulator is done and every frame was read, or on stop.
  bool read(vision::Frame& out) override;
  cv::Size frame_size() const override { return size_; }
  double fps() const override { return fps_; }
  vision::FrameSourceCounters counters() const override { return counters_; }
  std::string describe() const override { return "the simulated camera's frames, handed over by pb-sim"; }

  /// The contact switches read with the last frame.
  const track::ContactSensors& contacts() const { return contacts_; }
  /// Steady clock when the last frame was handed over (s).
  double capture_wall_s() const { return capture_wall_s_; }

 private:
  Handoffs& h_;
  double fps_;
  cv::Size size_;
  vision::FrameSourceCounters counters_;
  track::ContactSensors contacts_;
  double capture_wall_s_ = 0.0;
};

}  // namespace pinball::daemon
