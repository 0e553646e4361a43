#pragma once
// Least-squares fit of a free-flight parabola to recent observations (thesis
// 4.1.1): x(τ) = x0 + vx·τ, y(τ) = y0 + vy·τ − g·τ²/2, with g fixed at the
// calibrated value, τ = t − t_newest so the normal equations stay well
// conditioned however long the clock has run.

#include <span>

#include "pinball/core/geometry.h"
#include "pinball/track/observation.h"

namespace pinball::track {

/// A fitted trajectory, referred to the newest observation's time.
struct TrajectoryFit {
  bool valid = false;              ///< false: too few points or a singular system
  double t_ref_s = 0.0;            ///< newest observation time: τ = 0 (s)
  Vec2 p_ref = Vec2::Zero();       ///< fitted position at τ = 0 (m)
  Vec2 v_ref = Vec2::Zero();       ///< fitted velocity at τ = 0 (m/s)
  double g_mps2 = 0.0;             ///< gravity along −y used (fixed) or found (free fit)
  int points = 0;                  ///< observations used
  double chi2 = 0.0;               ///< Σ |residual|² / σ² over both coordinates
  int dof = 0;                     ///< degrees of freedom: 2·points − parameters

  /// Position (m) at time t_s.
  Vec2 position_at(double t_s) const {
    const double tau = t_s - t_ref_s;
    return {p_ref.x() + v_ref.x() * tau, p_ref.y() + v_ref.y() * tau - 0.5 * g_mps2 * tau * tau};
  }
  /// Velocity (m/s) at time t_s.
  Vec2 velocity_at(double t_s) const { return {v_ref.x(), v_ref.y() - g_mps2 * (t_s - t_ref_s)}; }
};

/// A known parabola as a fit (exact truth, or a predictor's guess): passes
/// through p_ref with velocity v_ref at t_ref_s under g_mps2.
TrajectoryFit exact_trajectory(const Vec2& p_ref, const Vec2& v_ref, double g_mps2, double t_ref_s);

/// Fits with g fixed (4 parameters). `observations` oldest first; needs at
/// least 3 points with distinct times; sigma_m scales the χ².
TrajectoryFit fit_fixed_gravity(std::span<const Observation> observations, double g_mps2, double sigma_m);

/// Fits with g free (5 parameters): the baseline the thesis improves on.
/// Needs at least 3 points with distinct times.
TrajectoryFit fit_free_gravity(std::span<const Observation> observations, double sigma_m);

/// A parabola with an acceleration of its own in both coordinates: what a
/// ball follows when something besides g pushes it, e.g. one that skids on
/// the playfield (sliding friction against its slip), which the model's
/// rolling ball never does.
struct AccelerationFit {
  bool valid = false;              ///< false: too few points or a singular system
  double t_ref_s = 0.0;            ///< newest observation time: τ = 0 (s)
  Vec2 p_ref = Vec2::Zero();       ///< fitted position at τ = 0 (m)
  Vec2 v_ref = Vec2::Zero();       ///< fitted velocity at τ = 0 (m/s)
  Vec2 a_mps2 = Vec2::Zero();      ///< fitted acceleration (m/s²); a ball under the board's g alone has (0, −g)
  int points = 0;                  ///< observations used
  double chi2 = 0.0;               ///< Σ |residual|² / σ² over both coordinates
  int dof = 0;                     ///< degrees of freedom: 2·points − 6
};

/// Fits p + v·τ + a·τ²/2 with a free in both coordinates (6 parameters).
/// Needs at least 3 points with distinct times.
AccelerationFit fit_free_acceleration(std::span<const Observation> observations, double sigma_m);

/// χ² above which `dof` degrees of freedom do not fit at the 99.9 % level
/// (Wilson–Hilferty approximation of the χ² quantile).
double chi2_threshold(int dof);

}  // namespace pinball::track
