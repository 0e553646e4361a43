#pragma once
// The ball tracker (thesis Ch. 4, 5.2.5): turns timestamped observations into
// trajectory projections and launch events. A plain class: no threads, no
// I/O; fixed-size buffers, so update() never allocates.

#include <array>
#include <cstddef>
#include <optional>

#include "pinball/track/camera_model.h"
#include "pinball/track/flipper_geometry.h"
#include "pinball/track/launch_detector.h"
#include "pinball/track/noise_estimate.h"
#include "pinball/track/observation.h"
#include "pinball/track/projection.h"
#include "pinball/track/trajectory_fit.h"

namespace pinball::track {

/// Tracker settings.
struct TrackerConfig {
  double g_mps2 = 1.11;               ///< calibrated gravity along the table (m/s²)
  double window_distance_m = 0.038;   ///< d: fit over the first n with |B_n − B_0| >= d (half a flipper)
  double rolling_epsilon_m = 0.0076;  ///< ε: rolling speed from the first point this far back (10 % of a flipper)
  double sigma_m = 0.0007;            ///< standard deviation of one observed coordinate (m)
  double critical_y_m = 0.5;          ///< projections only while the ball is below this y (m)
  int min_window = 24;                ///< at least this many points when the trajectory has them (0: the thesis rule alone)
  int max_window = 64;                ///< at most this many points in a fit
  bool chi2_flush = true;             ///< drop the points before a collision at once (4.1.1)
  /// A window that an acceleration of its own fits better than g (by more
  /// than the 99.9 % point of χ²(2)), and within the camera's noise, no
  /// further than this from g's (m/s²), is one smooth path with a push:
  /// a ball skidding after a bounce (sliding friction μ·g_n, 1.9 m/s² on
  /// the twin's waxed playfield, plus the slope's fuller pull on a sliding
  /// ball) or rolling along a wall. Its state is that fit's, and nothing is
  /// flushed; forcing g on it would get the velocity wrong by the push times
  /// half the window. A kink (a collision) fits no parabola, or needs a far
  /// larger acceleration, and is flushed as before. 0: g's fit always, and
  /// every misfit flushes (the thesis's rule).
  double max_push_mps2 = 3.5;
  /// Measure the camera's noise from the track itself (ObservationNoiseEstimator)
  /// and weigh the fits by it where it is more than kNoiseOverCalibration times
  /// sigma_m: a camera noisier than its calibration says then no longer fails
  /// every χ² test. false: sigma_m always (the thesis).
  bool estimate_noise = true;
  /// Observations further apart than this (a camera that stalled, a ball
  /// out of sight, a clock that jumped either way) start a new trajectory:
  /// one parabola pushed across a gap had fitted the old path and the new
  /// one together and named the wrong flipper (s, > 0; ten frames at 200 fps;
  /// default_tracker_config makes it at least three frames of a slower camera).
  double max_gap_s = 0.05;
  LaunchDetectorConfig launch;        ///< launch detection
};

/// The measured noise replaces the calibrated σ only beyond this ratio: within
/// it the calibration stands, so a camera as good as its calibration is tracked
/// as before. On the simulated camera at its calibrated 0.3 px the estimate
/// read 0.57 to 1.30 mm against the calibration's 0.83 mm (a pixel grid's
/// rounding is not normal); at 1 px, 1.74 to 2.61 mm (docs/tracking.md).
inline constexpr double kNoiseOverCalibration = 2.0;

/// The rule both the tracker and its reports use: a measured noise replaces
/// the calibrated one when it exceeds kNoiseOverCalibration times it.
inline bool measured_noise_overrides(double measured_m, double calibrated_m) {
  return measured_m > kNoiseOverCalibration * calibrated_m;
}

/// Defaults for a board and a camera: g from the board, d and ε from the
/// flipper length, σ from the camera, the critical area 0.35 m above the pivots.
TrackerConfig default_tracker_config(const table::Board& board, const CameraModelConfig& camera);

/// Everything one update produced.
struct TrackerOutput {
  TrajectoryProjection projection;  ///< the projection (valid or with its reason)
  TrajectoryFit fit;                ///< the fit behind it (invalid when rolling or too few points)
  LaunchEvent launch;               ///< launch / loss / entry events of this update
  int window = 0;                   ///< observations in the fit
  bool flushed = false;             ///< the χ² test dropped points from before a collision
  bool pushed = false;              ///< the fit is the window's own acceleration's (TrackerConfig::max_push_mps2)
  Vec2 ball_m = Vec2::Zero();       ///< the newest observation's ball (m, board frame): where a resting ball lies
};

/// Stateful tracker for one ball at a time.
class Tracker {
 public:
  Tracker(const FlipperGeometry& geometry, const TrackerConfig& config);

  /// Adds one observation (in time order) with the flipper contact sensors
  /// read at the same time, and returns the new projection.
  const TrackerOutput& update(const Observation& observation, const ContactSensors& contacts);

  /// Forgets the ball (call when a ball is lost or a new one is launched).
  void reset();

  /// The geometry and settings in use.
  const FlipperGeometry& geometry() const { return geometry_; }
  const TrackerConfig& config() const { return config_; }
  /// Observations currently kept (the trajectory since the last break).
  std::size_t history_size() const { return size_; }
  /// Collisions detected by the χ² test since construction.
  std::size_t flushes() const { return flushes_; }
  /// Updates whose fit was a pushed ball's (TrackerOutput::pushed) since construction.
  std::size_t pushes() const { return pushes_; }
  /// Trajectories started afresh since construction: after a gap over TrackerConfig::max_gap_s, or
  /// where kFramesBehindForNewClock frames in a row came from that far behind the newest (a clock that
  /// jumped back, or a newest frame stamped far ahead).
  std::size_t gap_restarts() const { return gap_restarts_; }
  /// Observations ignored since construction: out of order, repeated, or with a time or position not finite.
  std::size_t ignored() const { return ignored_; }
  /// The σ per coordinate the fits use now (m): the calibrated one, or the
  /// measured one where it is more than kNoiseOverCalibration times that.
  double sigma_m() const;
  /// The camera's noise as measured from the tracks so far (none until enough frames).
  std::optional<double> measured_sigma_m() const { return noise_.sigma_m(); }

 private:
  static constexpr std::size_t kHistory = 512;
  static constexpr int kFramesBehindForNewClock = 3;  // frames in a row over max_gap_s behind the newest

  const Observation& back(std::size_t i) const { return history_[(head_ + size_ - 1 - i) % kHistory]; }
  void keep_newest(std::size_t n);
  std::span<const Observation> newest(std::size_t n);
  std::size_t window_length() const;
  double rolling_speed() const;

  FlipperGeometry geometry_;
  TrackerConfig config_;
  LaunchDetector launch_;
  ObservationNoiseEstimator noise_;  // kept across balls: it measures the camera
  std::array<Observation, kHistory> history_{};
  std::size_t head_ = 0;
  std::size_t size_ = 0;
  std::array<Observation, kHistory> scratch_{};
  bool was_rolling_ = false;
  std::size_t flushes_ = 0;
  std::size_t pushes_ = 0;
  std::size_t gap_restarts_ = 0;
  std::size_t ignored_ = 0;
  int behind_in_a_row_ = 0;
  TrackerOutput out_;
};

}  // namespace pinball::track
