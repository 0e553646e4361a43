#include "pinball/calibration/gravity_calibration.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <stdexcept>

#include <Eigen/Dense>

#include "pinball/core/format.h"
#include "pinball/core/statistics.h"
#include "pinball/table/board.h"

namespace pinball::calibration {
namespace {

// Least squares of value(t) = c0 + c1·τ + c2·τ², τ = t − t0, over obs[first, last].
struct Quadratic {
  Eigen::Vector3d c = Eigen::Vector3d::Zero();
  Eigen::Matrix3d inv_normal = Eigen::Matrix3d::Zero();  // (XᵀX)⁻¹
  double t0 = 0.0;
};

Quadratic fit_quadratic(std::span<const track::Observation> obs, std::size_t first, std::size_t last, int axis) {
  Quadratic q;
  q.t0 = 0.5 * (obs[first].t_s + obs[last].t_s);
  Eigen::Matrix3d n = Eigen::Matrix3d::Zero();
  Eigen::Vector3d r = Eigen::Vector3d::Zero();
  for (std::size_t i = first; i <= last; ++i) {
    const double tau = obs[i].t_s - q.t0;
    const Eigen::Vector3d x(1.0, tau, tau * tau);
    n += x * x.transpose();
    r += x * obs[i].p_board(axis);
  }
  q.inv_normal = n.inverse();
  q.c = q.inv_normal * r;
  return q;
}

double eval(const Quadratic& q, double t) {
  const double tau = t - q.t0;
  return q.c(0) + tau * (q.c(1) + tau * q.c(2));
}

}  // namespace

double student_t_quantile(double confidence, int dof) {
  // Two-sided quantiles t_{1 − (1 − c)/2, ν} for ν = 1..30.
  static constexpr std::array<double, 30> k90{6.314, 2.920, 2.353, 2.132, 2.015, 1.943, 1.895, 1.860, 1.833, 1.812,
                                              1.796, 1.782, 1.771, 1.761, 1.753, 1.746, 1.740, 1.734, 1.729, 1.725,
                                              1.721, 1.717, 1.714, 1.711, 1.708, 1.706, 1.703, 1.701, 1.699, 1.697};
  static constexpr std::array<double, 30> k95{12.706, 4.303, 3.182, 2.776, 2.571, 2.447, 2.365, 2.306, 2.262, 2.228,
                                              2.201,  2.179, 2.160, 2.145, 2.131, 2.120, 2.110, 2.101, 2.093, 2.086,
                                              2.080,  2.074, 2.069, 2.064, 2.060, 2.056, 2.052, 2.048, 2.045, 2.042};
  static constexpr std::array<double, 30> k99{63.657, 9.925, 5.841, 4.604, 4.032, 3.707, 3.499, 3.355, 3.250, 3.169,
                                              3.106,  3.055, 3.012, 2.977, 2.947, 2.921, 2.898, 2.878, 2.861, 2.845,
                                              2.831,  2.819, 2.807, 2.797, 2.787, 2.779, 2.771, 2.763, 2.756, 2.750};
  const std::array<double, 30>* table = nullptr;
  double z = 0.0;
  if (std::abs(confidence - 0.90) < 1e-9) {
    table = &k90;
    z = 1.6448536;
  } else if (std::abs(confidence - 0.95) < 1e-9) {
    table = &k95;
    z = 1.9599640;
  } else if (std::abs(confidence - 0.99) < 1e-9) {
    table = &k99;
    z = 2.5758293;
  } else {
    throw std::invalid_argument("student_t_quantile: confidence must be 0.90, 0.95 or 0.99");
  }
  if (dof < 1) throw std::invalid_argument("student_t_quantile: dof must be >= 1");
  if (dof <= 30) return (*table)[static_cast<std::size_t>(dof - 1)];
  // Cornish-Fisher expansion in 1/ν (Abramowitz & Stegun 26.7.5).
  const double n = dof, z3 = z * z * z, z5 = z3 * z * z, z7 = z5 * z * z;
  return z + (z3 + z) / (4 * n) + (5 * z5 + 16 * z3 + 3 * z) / (96 * n * n) +
         (3 * z7 + 19 * z5 + 17 * z3 - 15 * z) / (384 * n * n * n);
}

// What noise may add to a roll's starting speed (m/s) before it counts as no start from rest.
constexpr double kStartSpeedSlack_mps = 0.05;

RollFit fit_roll(const GravityRoll& roll, const GravityOptions& o) {
  RollFit f;
  f.source = roll.source;
  const std::span<const track::Observation> obs(roll.observations);
  const std::size_t n = obs.size();
  const std::size_t min_points = static_cast<std::size_t>(std::max(o.min_points, 4));
  if (n < min_points) {
    f.why = std::to_string(n) + " observations";
    return f;
  }
  // Start: the first observation clearly away from where the ball rested.
  const Vec2 rest = obs[0].p_board;
  std::size_t first = 0;
  while (first < n && (obs[first].p_board - rest).norm() < o.start_motion_m) ++first;
  if (n - first < min_points) {
    f.why = "the ball never moved " + format_number(o.start_motion_m * 1e3) + " mm from where it started";
    return f;
  }
  // Grow the parabola until two points in a row fall off it (the ball hit something).
  std::size_t last = first + min_points - 1;
  int misses = 0;
  for (std::size_t k = last + 1; k < n; ++k) {
    const Quadratic y = fit_quadratic(obs, first, last, 1);
    const Quadratic x = fit_quadratic(obs, first, last, 0);
    const double dy = obs[k].p_board.y() - eval(y, obs[k].t_s);
    const double dx = obs[k].p_board.x() - eval(x, obs[k].t_s);
    if (std::hypot(dx, dy) > o.cut_sigmas * o.sigma_m) {
      if (++misses >= 2) break;
      continue;
    }
    misses = 0;
    last = k;
  }
  const double duration = obs[last].t_s - obs[first].t_s;
  if (duration < o.min_duration_s) {
    f.why = "only " + std::to_string(duration) + " s on a parabola";
    return f;
  }
  const Quadratic y = fit_quadratic(obs, first, last, 1);
  const Quadratic x = fit_quadratic(obs, first, last, 0);
  double ss = 0.0;
  for (std::size_t i = first; i <= last; ++i) ss += std::pow(obs[i].p_board.y() - eval(y, obs[i].t_s), 2);
  const std::size_t m = last - first + 1;
  const double s2 = ss / static_cast<double>(m - 3);
  f.usable = true;
  f.first = first;
  f.last = last;
  f.t0_s = y.t0;
  f.c0 = y.c(0);
  f.c1 = y.c(1);
  f.c2 = y.c(2);
  f.accel_mps2 = -2.0 * y.c(2);
  f.accel_stderr_mps2 = 2.0 * std::sqrt(s2 * y.inv_normal(2, 2));
  f.lateral_mps2 = 2.0 * x.c(2);
  f.rms_m = std::sqrt(ss / static_cast<double>(m));
  if (!(f.accel_mps2 > 0.0)) {
    f.usable = false;
    f.why = "the ball did not speed up down the table";
    return f;
  }
  if (f.accel_mps2 > table::kMaxGravity_mps2) {
    f.usable = false;
    f.why = "the ball sped up at " + format_number(f.accel_mps2) + " m/s^2 down the table, more than g itself (" +
            format_number(table::kMaxGravity_mps2) + " at most): not a ball rolling on this table";
    return f;
  }
  // Let go from rest, the ball has only the speed its short way gave it; a launch or a
  // shot (a whole game's trace) has far more, and its parabola is no roll's.
  const double t_first = obs[first].t_s - y.t0;
  const double start_speed_mps = std::hypot(x.c(1) + 2.0 * x.c(2) * t_first, y.c(1) + 2.0 * y.c(2) * t_first);
  const double moved_m = (obs[first].p_board - rest).norm();
  const double from_rest_mps = std::sqrt(2.0 * f.accel_mps2 * moved_m);
  if (start_speed_mps > 3.0 * from_rest_mps + kStartSpeedSlack_mps) {
    f.usable = false;
    f.why = "the ball moved at " + format_number(start_speed_mps) + " m/s once it had gone " +
            format_number(moved_m * 1e3) + " mm (from rest: about " + format_number(from_rest_mps) +
            " m/s): a roll starts from rest, let go, not launched";
  }
  return f;
}

GravityCalibration calibrate_gravity(std::span<const GravityRoll> rolls, const GravityOptions& o) {
  if (!(o.sigma_m > 0.0) || !(o.cut_sigmas > 0.0) || !(o.outlier_mads > 0.0) || o.min_points < 4) {
    throw std::runtime_error("gravity calibration: sigma_m, cut_sigmas and outlier_mads must be > 0, min_points >= 4");
  }
  GravityCalibration out;
  std::vector<double> a;
  std::vector<double> se;
  for (const GravityRoll& r : rolls) {
    out.rolls.push_back(fit_roll(r, o));
    if (out.rolls.back().usable) {
      a.push_back(out.rolls.back().accel_mps2);
      se.push_back(out.rolls.back().accel_stderr_mps2);
    }
  }
  if (a.empty()) {
    std::string why = "gravity calibration: no usable roll of " + std::to_string(rolls.size());
    for (std::size_t i = 0; i < out.rolls.size(); ++i) {
      why += (i == 0 ? " (" : "; ") + out.rolls[i].source + ": " + out.rolls[i].why;
    }
    throw std::runtime_error(why + (out.rolls.empty() ? "" : ")"));
  }
  // Outliers by median/MAD, from 3 rolls on; the robust σ never falls below
  // what the rolls' own fits allow (identical rolls must not reject each other).
  const double med = median(a);
  const double sigma = std::max(robust_sigma(a), 2.0 * median(se));
  GravityEstimate& e = out.estimate;
  e.confidence = o.confidence;
  double sum = 0.0;
  std::vector<double> kept;
  for (RollFit& f : out.rolls) {
    if (!f.usable) {
      ++e.rolls_rejected;
      continue;
    }
    e.per_roll_mps2.push_back(f.accel_mps2);
    f.outlier = a.size() >= 3 && std::abs(f.accel_mps2 - med) > o.outlier_mads * sigma;
    if (f.outlier) {
      ++e.rolls_rejected;
      continue;
    }
    kept.push_back(f.accel_mps2);
    sum += f.accel_mps2;
  }
  e.rolls_used = static_cast<int>(kept.size());
  e.g_mps2 = sum / static_cast<double>(kept.size());
  double half = 0.0;
  if (kept.size() >= 2) {
    double ss = 0.0;
    for (const double x : kept) ss += (x - e.g_mps2) * (x - e.g_mps2);
    const double s = std::sqrt(ss / static_cast<double>(kept.size() - 1));
    half = student_t_quantile(o.confidence, static_cast<int>(kept.size()) - 1) * s /
           std::sqrt(static_cast<double>(kept.size()));
  } else {
    // One roll: only its own fit's error is known (a normal quantile on it).
    for (const RollFit& f : out.rolls) {
      if (f.usable && !f.outlier) half = student_t_quantile(o.confidence, 1000) * f.accel_stderr_mps2;
    }
  }
  e.ci_low_mps2 = e.g_mps2 - half;
  e.ci_high_mps2 = e.g_mps2 + half;
  return out;
}

}  // namespace pinball::calibration
