#pragma once
// The trajectory projection (thesis 4.1.3): where and how the ball will meet
// the 'V' of the down flippers if they stayed down, computed from a fitted
// trajectory; and the special projection for a ball rolling on a flipper
// (4.1.2). Every degenerate case gives a defined answer, never NaN.

#include <cstdint>

#include "pinball/track/flipper_geometry.h"
#include "pinball/track/trajectory_fit.h"

namespace pinball::track {

/// Why there is no projection.
enum class NoProjection : std::uint8_t {
  kNone = 0,          ///< there is a projection
  kTooFewPoints,      ///< fewer than 3 usable observations on the current trajectory
  kOutsideCritical,   ///< ball above the critical area (not worth computing)
  kBelowFlippers,     ///< ball already below the flipper lines
  kNoImpact,          ///< the trajectory never meets the 'V' in the future
  kNumerical,         ///< the numbers came out non-finite (never seen; guarded)
};

/// Name of a NoProjection value for CSV and JSON ("none", "too_few_points", ...).
const char* to_string(NoProjection reason);

/// The trajectory projection (f, s, θ, h, d) plus its time (thesis 4.1).
struct TrajectoryProjection {
  bool valid = false;            ///< a projection exists (reason == kNone)
  NoProjection reason = NoProjection::kTooFewPoints;  ///< why not, when not valid
  int flipper = kLeftFlipper;    ///< f_impact: the flipper line the ball meets
  double speed_mps = 0.0;        ///< s_impact: speed at impact (m/s)
  double angle_rad = 0.0;        ///< θ_impact: slope of the velocity at impact, in [−π/2, π/2]
  double h = 0.0;                ///< h_impact: 0 at the pivot, 1 at the tip, h_apex at the V's centre
  double d_m = 0.0;              ///< d_impact: distance from the ball now to the impact point (m)
  double t_impact_s = 0.0;       ///< time from the newest observation to impact (s)
  double t_observation_s = 0.0;  ///< time of the newest observation (s)
  double latency_s = 0.0;        ///< that observation's camera latency: it was delivered this long after (s)
  Vec2 impact_point = Vec2::Zero();  ///< where (m)
  bool hittable = false;         ///< impact on the 'V' (0 <= h <= h_apex): the controller acts on these only
  bool rolling = false;          ///< the rolling-ball projection of 4.1.2
};

/// Projects a fitted trajectory onto the 'V' (thesis eq. 4.6–4.11): the
/// nearest future meeting with either flipper line between its pivot and the
/// apex. `fit` must be valid.
TrajectoryProjection project_trajectory(const TrajectoryFit& fit, const FlipperGeometry& geometry);

/// The projection for a ball rolling on flipper `rolling_on` (thesis 4.1.2):
/// heading for the V's centre (h = h_apex) of the other flipper, at
/// `speed_mps`, at the angle of the down flipper it rolls on.
TrajectoryProjection rolling_projection(const FlipperGeometry& geometry, int rolling_on, const Vec2& p_now,
                                        double speed_mps, double t_now_s);

/// The projection as it will be `lead_s` after its newest observation (the
/// camera's latency plus the coil's actuation delay: when a command given now
/// takes effect): d from where the ball will then be to the impact point and
/// t_impact from then, along `fit` (a rolling ball: at its speed). An impact
/// sooner than that gives d = 0 and t_impact = 0: the coil is already late.
/// Impact point, speed, angle and h do not change; an invalid projection is
/// returned as it is.
TrajectoryProjection lead_projection(const TrajectoryProjection& projection, const TrajectoryFit& fit, double lead_s);

/// Folds a direction angle into [−π/2, π/2] (the thesis's tan⁻¹(ẏ/ẋ)
/// without a division).
double fold_to_half_plane(double angle_rad);

/// The slope angle of a velocity, in [−π/2, π/2]: fold_to_half_plane(atan2(vy, vx)),
/// except that a velocity within 1e-9 rad of vertical is exactly −π/2 falling
/// and +π/2 rising, whatever the sign of a round-off vx.
double slope_angle(const Vec2& v);

}  // namespace pinball::track
