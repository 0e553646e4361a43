#include "pinball/track/launch_detector.h"

#include <algorithm>
#include <cmath>

namespace pinball::track {

FlipperEllipse flipper_ellipse(const FlipperGeometry& g) {
  const FlipperLine& l = g.lines[kLeftFlipper];
  const FlipperLine& r = g.lines[kRightFlipper];
  FlipperEllipse e;
  e.centre = 0.25 * (l.pivot + l.tip + r.pivot + r.tip);
  const double length = 0.5 * (l.axis().norm() + r.axis().norm());
  e.a_m = 0.5 * std::abs(r.pivot.x() - l.pivot.x()) + length;
  e.b_m = length;
  return e;
}

LaunchDetector::LaunchDetector(const FlipperEllipse& ellipse, const LaunchDetectorConfig& config)
    : ellipse_(ellipse), config_(config) {}

void LaunchDetector::reset() {
  inside_ = false;
  falling_updates_ = 0;
}

LaunchEvent LaunchDetector::update(const Vec2& p, bool fit_valid, double vy_mps, bool rolling) {
  LaunchEvent e;
  const double level = ellipse_.level(p);
  const double inner = config_.inner_scale * config_.inner_scale;
  const double outer = config_.outer_scale * config_.outer_scale;
  if (!inside_ && level < inner) {
    inside_ = true;
    e.entered = true;
  } else if (inside_ && level > outer) {
    inside_ = false;
    if (p.y() >= ellipse_.centre.y()) {
      e.launched = true;
    } else {
      e.lost = true;
    }
  }
  // Reversal of the fitted vertical velocity: falling for a while, then rising.
  if (fit_valid && !rolling) {
    if (vy_mps < -config_.reversal_speed_mps) {
      falling_updates_ = std::min(falling_updates_ + 1, 1 << 20);
    } else if (vy_mps > config_.reversal_speed_mps) {
      if (falling_updates_ >= config_.reversal_min_falling && inside_) e.launched = true;
      falling_updates_ = 0;
    }
  } else if (rolling) {
    falling_updates_ = 0;
  }
  return e;
}

}  // namespace pinball::track
