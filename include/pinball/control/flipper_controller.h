#pragma once
// The seam between the tracker and the flipper solenoids (thesis 5.2.3): a
// flipper controller turns each tracker update into solenoid commands. Two
// implementations: the spastic flipper and the learned action function with
// its actuator controller.

#include <array>

#include "pinball/firmware/protocol.h"
#include "pinball/track/tracker.h"

namespace pinball::control {

/// Longest hold a controller setting may ask for (s): the CAN protocol's
/// absolute hold cap, past which the driver board cuts the coil anyway.
inline constexpr double kMaxHold_s = firmware::kAbsMaxHoldMs * 1e-3;

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
