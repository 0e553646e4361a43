#pragma once
// A valid, hittable trajectory projection, for the controller tests.

#include "pinball/track/projection.h"

namespace pinball::testing {

inline track::TrajectoryProjection hittable_projection(int flipper, double angle_rad, double h = 0.5,
                                                       double speed_mps = 1.0, double d_m = 0.0) {
  track::TrajectoryProjection p;
  p.valid = true;
  p.reason = track::NoProjection::kNone;
  p.hittable = true;
  p.flipper = flipper;
  p.angle_rad = angle_rad;
  p.h = h;
  p.speed_mps = speed_mps;
  p.d_m = d_m;
  return p;
}

}  // namespace pinball::testing
