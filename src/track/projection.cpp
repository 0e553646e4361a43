#include "pinball/track/projection.h"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace pinball::track {

const char* to_string(NoProjection reason) {
  switch (reason) {
    case NoProjection::kNone: return "none";
    case NoProjection::kTooFewPoints: return "too_few_points";
    case NoProjection::kOutsideCritical: return "outside_critical_area";
    case NoProjection::kBelowFlippers: return "below_flippers";
    case NoProjection::kNoImpact: return "no_impact";
    case NoProjection::kNumerical: return "numerical";
  }
  return "unknown";
}

double fold_to_half_plane(double angle_rad) {
  constexpr double kHalfPi = std::numbers::pi / 2.0;
  if (angle_rad > kHalfPi) return angle_rad - std::numbers::pi;
  if (angle_rad < -kHalfPi) return angle_rad + std::numbers::pi;
  return angle_rad;
}

double slope_angle(const Vec2& v) {
  constexpr double kHalfPi = std::numbers::pi / 2.0;
  if (std::abs(v.x()) <= 1e-9 * std::abs(v.y())) return v.y() < 0.0 ? -kHalfPi : kHalfPi;
  return fold_to_half_plane(std::atan2(v.y(), v.x()));
}

namespace {

TrajectoryProjection none(NoProjection reason, double t_s) {
  TrajectoryProjection p;
  p.reason = reason;
  p.t_observation_s = t_s;
  return p;
}

bool finite(const TrajectoryProjection& p) {
  return std::isfinite(p.speed_mps) && std::isfinite(p.angle_rad) && std::isfinite(p.h) && std::isfinite(p.d_m) &&
         std::isfinite(p.t_impact_s) && std::isfinite(p.impact_point.x()) && std::isfinite(p.impact_point.y());
}

}  // namespace

TrajectoryProjection project_trajectory(const TrajectoryFit& fit, const FlipperGeometry& g) {
  if (!fit.valid) return none(NoProjection::kTooFewPoints, fit.t_ref_s);
  const Vec2 p0 = fit.p_ref;
  const Vec2 v0 = fit.v_ref;
  if (!above_flippers(g, p0)) return none(NoProjection::kBelowFlippers, fit.t_ref_s);

  TrajectoryProjection best = none(NoProjection::kNoImpact, fit.t_ref_s);
  double best_t = INFINITY;
  for (int f = 0; f < 2; ++f) {
    const FlipperLine& line = g.lines[f];
    const Vec2 axis = line.axis();
    // (trajectory(τ) − P) × F = 0 (eq. 4.6–4.7 with h eliminated):
    // (g·Fx/2)·τ² + (vx·Fy − vy·Fx)·τ + ((x0−Px)·Fy − (y0−Py)·Fx) = 0
    const Vec2 rel = p0 - line.pivot;
    const QuadraticRoots roots =
        solve_quadratic(0.5 * fit.g_mps2 * axis.x(), v0.x() * axis.y() - v0.y() * axis.x(), cross(rel, axis));
    for (int k = 0; k < roots.count; ++k) {
      const double tau = k == 0 ? roots.t0 : roots.t1;
      if (!(tau >= 0.0) || tau >= best_t) continue;  // past roots do not matter
      const Vec2 at = fit.position_at(fit.t_ref_s + tau);
      const double h = (at - line.pivot).dot(axis) / axis.squaredNorm();
      if (h < 0.0 || h > g.h_apex[f]) continue;  // misses this arm of the V
      best_t = tau;
      const Vec2 v = fit.velocity_at(fit.t_ref_s + tau);
      best.valid = true;
      best.reason = NoProjection::kNone;
      best.flipper = f;
      best.speed_mps = v.norm();
      best.angle_rad = slope_angle(v);
      best.h = h;
      best.d_m = (at - p0).norm();
      best.t_impact_s = tau;
      best.impact_point = at;
      best.hittable = true;
    }
  }
  if (best.valid && !finite(best)) return none(NoProjection::kNumerical, fit.t_ref_s);
  return best;
}

TrajectoryProjection lead_projection(const TrajectoryProjection& p, const TrajectoryFit& fit, double lead_s) {
  if (!p.valid || !(lead_s > 0.0)) return p;
  TrajectoryProjection led = p;
  if (lead_s >= p.t_impact_s) {
    led.d_m = 0.0;
    led.t_impact_s = 0.0;
    return led;
  }
  led.t_impact_s = p.t_impact_s - lead_s;
  if (p.rolling || !fit.valid) {
    led.d_m = std::max(0.0, p.d_m - p.speed_mps * lead_s);
  } else {
    led.d_m = (p.impact_point - fit.position_at(p.t_observation_s + lead_s)).norm();
  }
  return led;
}

TrajectoryProjection rolling_projection(const FlipperGeometry& g, int rolling_on, const Vec2& p_now,
                                        double speed_mps, double t_now_s) {
  TrajectoryProjection p;
  const int other = rolling_on == kLeftFlipper ? kRightFlipper : kLeftFlipper;
  const Vec2 axis = g.lines[rolling_on].axis();
  p.valid = true;
  p.reason = NoProjection::kNone;
  p.rolling = true;
  p.hittable = true;
  p.flipper = other;
  p.h = g.h_apex[other];
  p.impact_point = g.apex;
  p.speed_mps = std::isfinite(speed_mps) ? speed_mps : 0.0;
  p.angle_rad = slope_angle(axis);
  p.d_m = (g.apex - p_now).norm();
  // A ball at rest on the flipper never arrives: say so with an infinite wait
  // capped to a large finite number, so consumers never see inf or NaN.
  p.t_impact_s = p.speed_mps > 1e-6 ? p.d_m / p.speed_mps : 1e6;
  p.t_observation_s = t_now_s;
  if (!finite(p)) {
    p = TrajectoryProjection{};
    p.reason = NoProjection::kNumerical;
  }
  return p;
}

}  // namespace pinball::track
