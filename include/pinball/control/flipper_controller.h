#pragma once
// The seam between the tracker and the flipper solenoids (thesis 5.2.3): a
// flipper controller turns each tracker update into solenoid commands. Two
// implementations: the spastic flipper and the learned action function with
// its actuator controller.

#include <array>

#include "pinball/track/tracker.h"

namespace pinball::control {

/// Anything that decides flipper commands from tracker output.
class FlipperController {
 public:
  virtual ~FlipperController() = default;

  /// Updates the commands from one tracker update at time now_s.
  /// energized[track::kLeftFlipper] / [track::kRightFlipper] are the solenoid commands.
  virtual void update(const track::TrackerOutput& output, double now_s, std::array<bool, 2>& energized) = 0;

  /// Releases everything and forgets (new ball, lost ball).
  virtual void reset(std::array<bool, 2>& energized) = 0;
};

}  // namespace pinball::control
