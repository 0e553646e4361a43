#pragma once
// The thesis's "spastic flipper" (1.1.1) on the tracker's projections: flip
// the flipper the ball is heading for whenever a projection says the ball is
// within reach; release on a detected launch or loss (5.2.3). The baseline
// every learned controller is compared against.

#include <array>

#include "pinball/control/flipper_controller.h"
#include "pinball/core/name_value.h"
#include "pinball/track/tracker.h"

namespace pinball::control {

/// Settings of the spastic flipper.
struct SpasticConfig {
  double reach_m = 0.02;     ///< flip when d_impact <= this (m): about 1.5 ball radii (docs/results.md)
  double max_hold_s = 1.0;   ///< release a flipper held this long with no launch seen (a cradled ball)

  /// The keys of a controller file's `spastic` object (docs/learning.md).
  template <class Archive>
  void Serialize(Archive* a) {
    a->Visit(PINBALL_NVP(reach_m));
    a->Visit(PINBALL_NVP(max_hold_s));
  }
};

/// A setting outside its range: reach_m in (0, 1] m, max_hold_s in (0, kMaxHold_s].
RangeViolation check_spastic_config(const SpasticConfig& config);

/// Flipper commands from tracker output.
class SpasticController final : public FlipperController {
 public:
  /// Throws std::invalid_argument for a setting out of range (check_spastic_config).
  explicit SpasticController(const SpasticConfig& config = {});

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
