#include "pinball/track/tracker.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace pinball::track {

TrackerConfig default_tracker_config(const table::Board& board, const CameraModelConfig& camera) {
  TrackerConfig c;
  c.g_mps2 = board.gravity_mps2;
  double length = 0.0;
  double pivot_y = 0.0;
  for (const table::Flipper& f : board.flippers) {
    length = std::max(length, f.length_m);
    pivot_y = std::max(pivot_y, f.pivot.y());
  }
  if (length > 0.0) {
    c.window_distance_m = 0.5 * length;
    c.rolling_epsilon_m = 0.1 * length;
  }
  c.sigma_m = observation_sigma_m(camera);
  c.critical_y_m = pivot_y + 0.35;
  if (camera.fps > 0.0) c.max_gap_s = std::max(c.max_gap_s, 3.0 / camera.fps);  // a slow camera's lost frame or two
  return c;
}

Tracker::Tracker(const FlipperGeometry& geometry, const TrackerConfig& config)
    : geometry_(geometry), config_(config), launch_(flipper_ellipse(geometry), config.launch) {
  if (!(config.window_distance_m > 0.0) || !(config.rolling_epsilon_m > 0.0) || !(config.sigma_m > 0.0) ||
      config.max_window < 3 || config.max_window > static_cast<int>(kHistory) || config.min_window < 0 ||
      config.min_window > config.max_window || !std::isfinite(config.g_mps2) || !(config.max_push_mps2 >= 0.0) ||
      !std::isfinite(config.max_push_mps2) || !(config.max_gap_s > 0.0)) {
    throw std::invalid_argument(
        "tracker: window distance, rolling epsilon, sigma and max gap must be > 0, max_window in [3, 512], "
        "min_window in [0, max_window], g finite, max push finite and >= 0");
  }
}

void Tracker::reset() {
  noise_.restart_track();
  head_ = 0;
  size_ = 0;
  was_rolling_ = false;
  behind_in_a_row_ = 0;
  launch_.reset();
  out_ = TrackerOutput{};
}

void Tracker::keep_newest(std::size_t n) {
  n = std::min(n, size_);
  head_ = (head_ + size_ - n) % kHistory;
  size_ = n;
}

std::span<const Observation> Tracker::newest(std::size_t n) {
  n = std::min(n, size_);
  for (std::size_t i = 0; i < n; ++i) scratch_[i] = back(n - 1 - i);  // oldest first
  return {scratch_.data(), n};
}

std::size_t Tracker::window_length() const {
  // Thesis eq. 4.5: the first n with |B_n − B_0| >= d, so slow balls use many
  // points and fast ones few; all we have if none is that far yet.
  // A floor of min_window points keeps fast balls from being fitted on a
  // handful of points (docs/results.md: the thesis rule alone misses the h
  // target at 2 mm/px); the χ² flush keeps the floor from spanning collisions.
  const Vec2& b0 = back(0).p_board;
  const std::size_t limit = std::min<std::size_t>(size_, static_cast<std::size_t>(config_.max_window));
  const std::size_t floor = std::min<std::size_t>(limit, static_cast<std::size_t>(std::max(config_.min_window, 0)));
  for (std::size_t n = 1; n < limit; ++n) {
    if ((back(n).p_board - b0).norm() >= config_.window_distance_m) return std::max(n + 1, floor);
  }
  return limit;
}

double Tracker::rolling_speed() const {
  // Thesis 4.1.2: distance to the first point at least ε back, over the time between.
  const Vec2& b0 = back(0).p_board;
  for (std::size_t n = 1; n < size_; ++n) {
    const double dist = (back(n).p_board - b0).norm();
    if (dist >= config_.rolling_epsilon_m) {
      const double dt = back(0).t_s - back(n).t_s;
      return dt > 0.0 ? dist / dt : 0.0;
    }
  }
  return 0.0;
}

double Tracker::sigma_m() const {
  const std::optional<double> measured = config_.estimate_noise ? noise_.sigma_m() : std::nullopt;
  return measured && measured_noise_overrides(*measured, config_.sigma_m) ? *measured : config_.sigma_m;
}

const TrackerOutput& Tracker::update(const Observation& obs, const ContactSensors& contacts) {
  const double since_s = size_ > 0 ? obs.t_s - back(0).t_s : 0.0;
  // A frame far behind the newest is a stale one, unless frames keep coming from there: then the clock
  // jumped back, or the newest was stamped far ahead, and waiting would ignore every frame from now on.
  const bool clock_jumped_back = since_s < -config_.max_gap_s && ++behind_in_a_row_ >= kFramesBehindForNewClock;
  if (!std::isfinite(obs.t_s) || !obs.p_board.allFinite() || (!(since_s > 0.0) && size_ > 0 && !clock_jumped_back)) {
    // No sighting, or an out of order or repeated frame: ignore it, keep the last answer.
    ++ignored_;
    out_.launch = LaunchEvent{};
    return out_;
  }
  behind_in_a_row_ = 0;
  if (since_s > config_.max_gap_s || clock_jumped_back) {
    // The old points are another path: a fit across the gap bends to join the two, and names the wrong flipper.
    keep_newest(0);
    noise_.restart_track();
    was_rolling_ = false;
    ++gap_restarts_;
  }
  if (size_ == kHistory) keep_newest(kHistory - 1);
  history_[(head_ + size_) % kHistory] = obs;
  ++size_;
  if (config_.estimate_noise) noise_.add(obs);
  const double sigma = sigma_m();

  out_ = TrackerOutput{};
  out_.ball_m = obs.p_board;
  const bool rolling = contacts.left || contacts.right;
  if (!rolling && was_rolling_) keep_newest(1);  // rolling points are no parabola
  was_rolling_ = rolling;

  if (rolling) {
    const int on = contacts.left ? kLeftFlipper : kRightFlipper;
    out_.projection = rolling_projection(geometry_, on, obs.p_board, rolling_speed(), obs.t_s);
    out_.projection.latency_s = obs.latency_s;
    out_.launch = launch_.update(obs.p_board, false, 0.0, true);
    return out_;
  }

  if (obs.p_board.y() > config_.critical_y_m) {
    out_.projection.reason = NoProjection::kOutsideCritical;
    out_.projection.t_observation_s = obs.t_s;
    out_.launch = launch_.update(obs.p_board, false, 0.0, false);
    return out_;
  }

  std::size_t n = window_length();
  const std::span<const Observation> fitted = newest(n);
  TrajectoryFit fit = fit_fixed_gravity(fitted, config_.g_mps2, sigma);
  // A push shows as the χ² an acceleration of its own saves (a likelihood
  // ratio test, far finer than g's χ² alone, which a skid can pass while its
  // velocity is already off by the push times half the window). It saves at
  // most all of g's χ².
  const double push_chi2 = chi2_threshold(2);
  if (fit.valid && config_.max_push_mps2 > 0.0 && fit.chi2 > push_chi2) {
    const AccelerationFit own = fit_free_acceleration(fitted, sigma);
    if (own.valid && fit.chi2 - own.chi2 > push_chi2 && own.chi2 <= chi2_threshold(own.dof) &&
        (own.a_mps2 - Vec2(0.0, -config_.g_mps2)).norm() <= config_.max_push_mps2) {
      // One smooth path with a push: its own state, projected under g.
      fit = exact_trajectory(own.p_ref, own.v_ref, config_.g_mps2, own.t_ref_s);
      fit.points = own.points;
      fit.dof = own.dof;
      fit.chi2 = own.chi2;
      out_.pushed = true;
      ++pushes_;
    }
  }
  if (config_.chi2_flush && !out_.pushed && fit.valid && fit.chi2 > chi2_threshold(fit.dof)) {
    // The newest points left the old parabola (thesis 4.1.1's proposal): find
    // the fewest newest points whose removal leaves the older ones fitting one
    // parabola; those are after the collision, so drop everything before them
    // at once. (Fitting short runs of newest points instead would not work: a
    // 3- or 4-point fit absorbs the kink and keeps stale points.)
    std::size_t good = 1;
    for (std::size_t m = 1; m + 3 <= n; ++m) {
      const std::span<const Observation> window = newest(n);
      const TrajectoryFit older = fit_fixed_gravity(window.first(n - m), config_.g_mps2, sigma);
      if (older.valid && older.chi2 <= chi2_threshold(older.dof)) {
        good = m;
        break;
      }
    }
    keep_newest(good);
    out_.flushed = true;
    ++flushes_;
    n = good;
    fit = fit_fixed_gravity(newest(n), config_.g_mps2, sigma);
  }
  out_.fit = fit;
  out_.window = static_cast<int>(std::min(n, size_));
  out_.projection = fit.valid ? project_trajectory(fit, geometry_) : TrajectoryProjection{};
  out_.projection.t_observation_s = obs.t_s;
  out_.projection.latency_s = obs.latency_s;
  out_.launch = launch_.update(obs.p_board, fit.valid, fit.v_ref.y(), false);
  return out_;
}

}  // namespace pinball::track
