#include "pinball/learn/free_flight.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <Eigen/Dense>
#include <unsupported/Eigen/NonLinearOptimization>
#include <unsupported/Eigen/NumericalDiff>

#include "pinball/core/rng.h"
#include "pinball/core/statistics.h"

namespace pinball::learn {
namespace {

constexpr int kFlipperSweepSamples = 9;  // bat positions checked from down to up stop

double distance_to_segment(const Vec2& p, const Vec2& a, const Vec2& b) {
  const Vec2 ab = b - a;
  const double s = std::clamp((p - a).dot(ab) / ab.squaredNorm(), 0.0, 1.0);
  return (p - (a + s * ab)).norm();
}

// The frames of one run of clear sightings as observations for the tracker's fits.
std::vector<track::Observation> observations_of(const bus::RecordedPlay& play, std::size_t first, std::size_t last) {
  std::vector<track::Observation> obs;
  obs.reserve(last - first + 1);
  for (std::size_t i = first; i <= last; ++i) obs.push_back({play.frames[i].t_s, play.frames[i].p_board, 1.0, 0.0});
  return obs;
}

bool fits_one_parabola(std::span<const track::Observation> obs, double sigma_m, track::TrajectoryFit& fit) {
  fit = track::fit_free_gravity(obs, sigma_m);
  return fit.valid && fit.chi2 <= track::chi2_threshold(fit.dof);
}

// Splits the clear run [first, last] into the longest stretches one parabola fits.
void split_run(const bus::RecordedPlay& play, std::size_t recording, std::size_t first, std::size_t last,
               const FlightOptions& o, std::vector<FreeFlight>& out) {
  const std::vector<track::Observation> obs = observations_of(play, first, last);
  const std::size_t n = obs.size(), min_n = static_cast<std::size_t>(o.min_points);
  std::size_t i = 0;
  while (i + min_n <= n) {
    track::TrajectoryFit fit;
    std::size_t end = i + min_n;  // one past the last point
    if (!fits_one_parabola(std::span(obs).subspan(i, end - i), o.sigma_m, fit)) {
      ++i;
      continue;
    }
    track::TrajectoryFit longer;
    while (end < n && fits_one_parabola(std::span(obs).subspan(i, end + 1 - i), o.sigma_m, longer)) {
      fit = longer;
      ++end;
    }
    const double duration = obs[end - 1].t_s - obs[i].t_s;
    const double speed = fit.v_ref.norm();
    if (duration >= o.min_duration_s && speed >= o.min_speed_mps)
      out.push_back({recording, first + i, first + end - 1, obs[i].t_s, obs[end - 1].t_s, fit});
    i = end;
  }
}

// --- The shared acceleration, by variable projection ------------------------

// Each flight's frames relative to its first one, both coordinates.
struct FlightData {
  std::vector<double> tau_s, x_m, y_m;
};

// f(τ) = (1 − e^{−cτ})/c and h(τ) = (τ − f)/c: a drag c turns the flight
// p0 + v0·τ + a·τ²/2 into p0 + v0·f + a·h (series where c·τ is small).
void drag_basis(double c, double tau, double& f, double& h) {
  const double x = c * tau;
  if (std::abs(x) < 1e-3) {
    f = tau * (1.0 - x / 2.0 + x * x / 6.0);
    h = tau * tau * (0.5 - x / 6.0 + x * x / 24.0);
  } else {
    f = -std::expm1(-x) / c;
    h = (tau - f) / c;
  }
}

// Residuals of one coordinate of one flight after its start position and
// velocity are fitted (projection of data − a·h off span{1, f}).
void project_out(const std::vector<double>& tau, const std::vector<double>& data, double c, double accel,
                 Eigen::VectorXd& r, Eigen::Index at) {
  const std::size_t n = tau.size();
  double s11 = 0, s12 = 0, s22 = 0, b1 = 0, b2 = 0;
  for (std::size_t k = 0; k < n; ++k) {
    double f = 0, h = 0;
    drag_basis(c, tau[k], f, h);
    const double z = data[k] - accel * h;
    s11 += 1.0;
    s12 += f;
    s22 += f * f;
    b1 += z;
    b2 += f * z;
  }
  const double det = s11 * s22 - s12 * s12;
  const double p0 = (s22 * b1 - s12 * b2) / det, v0 = (s11 * b2 - s12 * b1) / det;
  for (std::size_t k = 0; k < n; ++k) {
    double f = 0, h = 0;
    drag_basis(c, tau[k], f, h);
    r(at + static_cast<Eigen::Index>(k)) = data[k] - accel * h - p0 - v0 * f;
  }
}

// Eigen's Levenberg–Marquardt functor: parameters (g, lateral[, c]).
struct SharedAccelerationResiduals {
  using Scalar = double;
  enum { InputsAtCompileTime = Eigen::Dynamic, ValuesAtCompileTime = Eigen::Dynamic };
  using InputType = Eigen::VectorXd;
  using ValueType = Eigen::VectorXd;
  using JacobianType = Eigen::MatrixXd;

  const std::vector<const FlightData*>* flights = nullptr;
  int parameters = 2;
  int points = 0;  // residuals: 2 per frame

  int inputs() const { return parameters; }
  int values() const { return points; }
  int operator()(const Eigen::VectorXd& theta, Eigen::VectorXd& r) const {
    const double c = parameters == 3 ? theta(2) : 0.0;
    Eigen::Index at = 0;
    for (const FlightData* f : *flights) {
      const auto n = static_cast<Eigen::Index>(f->tau_s.size());
      project_out(f->tau_s, f->x_m, c, theta(1), r, at);
      project_out(f->tau_s, f->y_m, c, -theta(0), r, at + n);
      at += 2 * n;
    }
    return 0;
  }
};

struct SharedFit {
  Eigen::VectorXd theta;
  Eigen::VectorXd residuals;
  Eigen::MatrixXd covariance;  // σ̂²·(JᵀJ)⁻¹
};

SharedFit fit_shared(const std::vector<const FlightData*>& flights, const Eigen::VectorXd& start) {
  SharedAccelerationResiduals functor;
  functor.flights = &flights;
  functor.parameters = static_cast<int>(start.size());
  for (const FlightData* f : flights) functor.points += 2 * static_cast<int>(f->tau_s.size());
  Eigen::NumericalDiff<SharedAccelerationResiduals> diff(functor);
  Eigen::LevenbergMarquardt<Eigen::NumericalDiff<SharedAccelerationResiduals>> lm(diff);
  lm.parameters.xtol = 1e-10;
  lm.parameters.ftol = 1e-12;
  SharedFit fit;
  fit.theta = start;
  lm.minimize(fit.theta);
  fit.residuals.resize(functor.points);
  functor(fit.theta, fit.residuals);
  Eigen::MatrixXd jacobian(functor.points, functor.parameters);
  diff.df(fit.theta, jacobian);
  // Each flight spends 4 unknowns on its start position and velocity.
  const double dof = functor.points - functor.parameters - 4.0 * static_cast<double>(flights.size());
  const double variance = fit.residuals.squaredNorm() / std::max(1.0, dof);
  fit.covariance = variance * (jacobian.transpose() * jacobian).inverse();
  return fit;
}

double rms_per_coordinate(const Eigen::VectorXd& r) {
  return r.size() == 0 ? 0.0 : std::sqrt(r.squaredNorm() / static_cast<double>(r.size()));
}

}  // namespace

bool ball_is_clear(const table::Board& board, const Vec2& p, double clearance_m) {
  const double reach = board.ball.radius_m + clearance_m;
  for (const table::Shape& shape : board.shapes)
    if (table::distance_to_shape(shape, p) < reach) return false;
  return ball_clear_of_flippers(board, p, clearance_m);
}

bool ball_clear_of_flippers(const table::Board& board, const Vec2& p, double clearance_m) {
  const double reach = board.ball.radius_m + clearance_m;
  for (const table::Flipper& f : board.flippers) {
    if ((p - f.pivot).norm() > f.length_m + reach) continue;
    for (int k = 0; k < kFlipperSweepSamples; ++k) {
      const double theta = f.theta_min_rad + (f.theta_max_rad - f.theta_min_rad) * k / (kFlipperSweepSamples - 1);
      if (distance_to_segment(p, f.pivot, table::flipper_tip(f, theta)) < reach) return false;
    }
  }
  return true;
}

std::vector<FreeFlight> find_free_flights(const bus::RecordedPlay& play, std::size_t recording,
                                          const table::Board& board, const FlightOptions& options) {
  std::vector<FreeFlight> flights;
  const auto usable = [&](const bus::RecordedFrame& f) {
    return f.found && !f.contact_left && !f.contact_right && ball_is_clear(board, f.p_board, options.clearance_m);
  };
  std::size_t i = 0;
  const std::size_t n = play.frames.size();
  while (i < n) {
    if (!usable(play.frames[i])) {
      ++i;
      continue;
    }
    // A run of usable sightings with no long gap; frames without the ball may sit inside it.
    std::size_t last = i, j = i + 1;
    for (; j < n; ++j) {
      const bus::RecordedFrame& f = play.frames[j];
      if (f.t_s - play.frames[last].t_s > options.max_gap_s) break;
      if (!f.found) continue;
      if (!usable(f)) break;
      last = j;
    }
    // Only the sightings go to the fit: gather them, keeping their frame indices.
    std::vector<std::size_t> seen;
    for (std::size_t k = i; k <= last; ++k)
      if (play.frames[k].found) seen.push_back(k);
    if (seen.size() >= static_cast<std::size_t>(options.min_points)) {
      bus::RecordedPlay run;  // the sightings alone, so that indices into it are contiguous
      run.frames.reserve(seen.size());
      for (std::size_t k : seen) run.frames.push_back(play.frames[k]);
      std::vector<FreeFlight> parts;
      split_run(run, recording, 0, run.frames.size() - 1, options, parts);
      for (FreeFlight& part : parts) {
        part.first = seen[part.first];
        part.last = seen[part.last];
        flights.push_back(part);
      }
    }
    i = std::max(j, last + 1);
  }
  return flights;
}

FlightGravity fit_flight_gravity(std::span<const bus::RecordedPlay> recordings, std::span<const FreeFlight> flights,
                                 double nominal_g_mps2, double sigma_m, bool fit_drag, int bootstrap,
                                 std::uint64_t seed, const std::function<void(int, int)>& progress) {
  if (flights.size() < 2)
    throw std::runtime_error("gravity needs at least 2 free flights, found " + std::to_string(flights.size()));
  std::vector<FlightData> data(flights.size());
  for (std::size_t k = 0; k < flights.size(); ++k) {
    const FreeFlight& f = flights[k];
    const bus::RecordedPlay& play = recordings[f.recording];
    for (std::size_t i = f.first; i <= f.last; ++i) {
      if (!play.frames[i].found) continue;
      data[k].tau_s.push_back(play.frames[i].t_s - f.t_first_s);
      data[k].x_m.push_back(play.frames[i].p_board.x());
      data[k].y_m.push_back(play.frames[i].p_board.y());
    }
  }
  std::vector<const FlightData*> all;
  for (const FlightData& d : data) all.push_back(&d);

  Eigen::VectorXd start(fit_drag ? 3 : 2);
  start.setZero();
  start(0) = nominal_g_mps2;
  FlightGravity out;
  out.drag_fitted = fit_drag;
  {  // The "before": the board's g, no tilt, no drag.
    SharedAccelerationResiduals nominal;
    nominal.flights = &all;
    for (const FlightData* f : all) nominal.points += 2 * static_cast<int>(f->tau_s.size());
    Eigen::VectorXd r(nominal.points);
    Eigen::VectorXd theta(2);
    theta << nominal_g_mps2, 0.0;
    nominal(theta, r);
    out.rms_nominal_m = rms_per_coordinate(r);
  }
  // Fit, then leave out the flights that no shared acceleration fits (a
  // collision the segmentation missed, a ball rolling along a wire) and refit.
  SharedFit fit = fit_shared(all, start);
  std::vector<const FlightData*> kept;
  Eigen::Index at = 0;
  for (const FlightData* f : all) {
    const auto n = static_cast<Eigen::Index>(2 * f->tau_s.size());
    const double chi2 = fit.residuals.segment(at, n).squaredNorm() / (sigma_m * sigma_m);
    if (chi2 <= track::chi2_threshold(static_cast<int>(n) - 4)) kept.push_back(f);
    at += n;
  }
  if (kept.size() >= 2 && kept.size() < all.size()) fit = fit_shared(kept, fit.theta);
  else kept = all;
  out.flights = static_cast<int>(kept.size());
  out.flights_dropped = static_cast<int>(all.size() - kept.size());
  for (const FlightData* f : kept) out.points += f->tau_s.size();
  out.g_mps2 = fit.theta(0);
  out.lateral_mps2 = fit.theta(1);
  out.drag_per_s = fit_drag ? fit.theta(2) : 0.0;
  out.rms_fitted_m = rms_per_coordinate(fit.residuals);
  out.g_covariance_stderr_mps2 = std::sqrt(fit.covariance(0, 0));
  out.g_stderr_mps2 = out.g_covariance_stderr_mps2;
  out.lateral_stderr_mps2 = std::sqrt(fit.covariance(1, 1));
  out.drag_stderr_per_s = fit_drag ? std::sqrt(fit.covariance(2, 2)) : 0.0;
  if (bootstrap >= 2) {
    // Frames of one flight share the detector's errors and the ball's spin,
    // so whole flights are resampled: an honest stderr where the covariance
    // (which takes every frame as independent) is too narrow.
    Rng rng(seed);
    Eigen::MatrixXd estimates(bootstrap, fit.theta.size());
    std::vector<const FlightData*> sample(kept.size());
    if (progress) progress(0, bootstrap);
    for (int b = 0; b < bootstrap; ++b) {
      for (auto& s : sample) s = kept[static_cast<std::size_t>(rng.uniform01() * static_cast<double>(kept.size()))];
      estimates.row(b) = fit_shared(sample, fit.theta).theta.transpose();
      if (progress) progress(b + 1, bootstrap);
    }
    const Eigen::RowVectorXd mean = estimates.colwise().mean();
    const Eigen::RowVectorXd sd =
        ((estimates.rowwise() - mean).array().square().colwise().sum() / (bootstrap - 1)).sqrt();
    out.g_stderr_mps2 = sd(0);
    out.lateral_stderr_mps2 = sd(1);
    if (fit_drag) out.drag_stderr_per_s = sd(2);
    out.bootstrap_resamples = bootstrap;
  }
  return out;
}

SlidingFriction fit_sliding_friction(std::span<const bus::RecordedPlay> recordings,
                                     std::span<const FreeFlight> flights, const FlightGravity& gravity,
                                     double sigma_m, double min_duration_s) {
  constexpr double kSlideOverRoll = 7.0 / 5.0;  // a solid ball rolls down a slope at 5/7 of its sliding acceleration
  const Vec2 rolling{gravity.lateral_mps2, -gravity.g_mps2};
  SlidingFriction out;
  out.min_duration_s = min_duration_s;
  std::vector<double> decel;
  for (const FreeFlight& f : flights) {
    if (f.t_last_s - f.t_first_s < min_duration_s) continue;
    std::vector<track::Observation> seen;  // a flight may span a frame without the ball
    for (std::size_t i = f.first; i <= f.last; ++i) {
      const bus::RecordedFrame& frame = recordings[f.recording].frames[i];
      if (frame.found) seen.push_back({frame.t_s, frame.p_board, 1.0, 0.0});
    }
    const track::AccelerationFit own = track::fit_free_acceleration(seen, sigma_m);
    if (!own.valid) continue;
    ++out.flights;
    // χ² under the shared acceleration: the flight's residuals about it, each
    // coordinate's start and velocity its own (a linear fit of p − a·τ²/2).
    std::vector<track::Observation> shifted = seen;
    for (track::Observation& o : shifted) {
      const double tau = o.t_s - seen.back().t_s;
      o.p_board -= 0.5 * tau * tau * rolling;
    }
    const double shared_chi2 = track::fit_fixed_gravity(shifted, 0.0, sigma_m).chi2;
    if (shared_chi2 - own.chi2 <= track::chi2_threshold(2)) continue;
    ++out.skidding;
    decel.push_back((own.a_mps2 - kSlideOverRoll * rolling).norm());
  }
  if (decel.empty()) return out;
  out.decel_mps2 = median(decel);
  if (decel.size() >= 2) {
    // The median's standard error: 1.2533·σ/√n for a normal spread σ.
    out.decel_stderr_mps2 = 1.2533 * robust_sigma(decel) / std::sqrt(static_cast<double>(decel.size()));
  }
  return out;
}

}  // namespace pinball::learn
