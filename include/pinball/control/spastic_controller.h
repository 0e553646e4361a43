#pragma once
// The thesis's "spastic flipper" (1.1.1) on the tracker's projections: flip
// the flipper the ball is heading for whenever a projection says the ball is
// within reach; release on a detected launch or loss (5.2.3). The baseline
// every learned controller is compared against.

#include <array>

#include "pinball/control/flipper_controller.h"
#include "pinball/track/tracker.h"

namespace pinball::control {

/// Settings of the spastic flipper.
struct SpasticConfig {
  double reach_m = 0.02;     ///< flip when d_impact <= this (m): about 1.5 ball radii (docs/results.md)
  double max_hold_s = 1.0;   ///< release a flipper held this long with no launch seen (a cradled ball)
};

/// Flipper commands from tracker output.
class SpasticController final : public FlipperController {
 public:
  explicit SpasticController(const SpasticConfig& config = {}) : config_(config) {}

  /// Updates the commands from one tracker update at time now_s.
  /// energized[track::kLeftFlipper] / [track::kRightFlipper] are the solenoid commands.
  void update(const track::TrackerOutput& output, double now_s, std::array<bool, 2>& energized) override;

  /// Releases everything and forgets (new ball).
  void reset(std::array<bool, 2>& energized) override;

 private:
  SpasticConfig config_;
  std::array<double, 2> held_since_s_{};
};

}  // namespace pinball::control
