#pragma once
// Launch detection (thesis 5.2.5): the ball entering the flipper ellipse and
// leaving it (with inner/outer hysteresis so camera jitter is no launch),
// plus the reversal of the fitted vertical velocity when not rolling.

#include "pinball/core/geometry.h"
#include "pinball/track/flipper_geometry.h"

namespace pinball::track {

/// The flipper ellipse and the reversal rule.
struct LaunchDetectorConfig {
  double inner_scale = 0.85;         ///< the ball must get inside this fraction of the ellipse to enter
  double outer_scale = 1.15;         ///< and outside this multiple to leave
  double reversal_speed_mps = 0.15;  ///< vy must fall below −this, then rise above +this
  int reversal_min_falling = 3;      ///< updates of falling before a rise counts as a reversal
};

/// The influence ellipse, axis-aligned: centre at the middle of the four
/// flipper end points, semi-axes reaching a flipper length beyond the pivots
/// sideways and a flipper length up and down.
struct FlipperEllipse {
  Vec2 centre = Vec2::Zero();  ///< (m)
  double a_m = 0.0;            ///< semi-axis along x (m)
  double b_m = 0.0;            ///< semi-axis along y (m)
  /// (x/a)² + (y/b)² relative to the centre: < 1 inside.
  double level(const Vec2& p) const {
    const Vec2 d = p - centre;
    return (d.x() * d.x()) / (a_m * a_m) + (d.y() * d.y()) / (b_m * b_m);
  }
};

/// The default ellipse for a pair of flippers.
FlipperEllipse flipper_ellipse(const FlipperGeometry& geometry);

/// What one update found.
struct LaunchEvent {
  bool launched = false;  ///< the ball left the ellipse upward, or its fall reversed
  bool lost = false;      ///< the ball left the ellipse downward (drained)
  bool entered = false;   ///< the ball entered the ellipse on this update
};

/// Stateful detector; feed it every observation in time order.
class LaunchDetector {
 public:
  LaunchDetector(const FlipperEllipse& ellipse, const LaunchDetectorConfig& config = {});

  /// One observation: position, fitted vertical velocity (when fit_valid) and
  /// whether the ball is rolling on a flipper (the reversal rule is off then).
  LaunchEvent update(const Vec2& p, bool fit_valid, double vy_mps, bool rolling);

  /// True while the ball is inside the ellipse (between entering and leaving).
  bool inside() const { return inside_; }
  /// Forgets everything (new ball).
  void reset();

 private:
  FlipperEllipse ellipse_;
  LaunchDetectorConfig config_;
  bool inside_ = false;
  int falling_updates_ = 0;
};

}  // namespace pinball::track
