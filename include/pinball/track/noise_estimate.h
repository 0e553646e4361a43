#pragma once
// The camera's noise, measured from the ball's own track (beyond the thesis).
// The tracker weighs its fits and finds collisions by χ² against the noise it
// was told (the calibration's σ). A camera noisier than that fails the χ²
// tests: the tracker flushes often and fits 3 points, and a planner playing
// from such fits drains balls down the middle (docs/results.md, "Camera noise
// the tracker does not expect"). So the tracker also measures it.
//
// Any three frames in a row give one residual that no straight path has:
// r = w0·p0 + w1·p1 + w2·p2 with w ∝ (1/Δt1, −1/Δt1 − 1/Δt2, 1/Δt2), scaled to
// |w| = 1, so r ~ N(0, σ²) per coordinate for a ball in flight at any frame
// spacing (gravity adds g·Δt²/√6, 0.01 mm at 200 fps). A bounce makes a large
// r, so σ is taken robustly, from the smaller half of the latest residuals'
// |r| (x and y both), which stands up to bounces in nearly half of them.
// Fixed buffers: add() allocates nothing.

#include <array>
#include <cstddef>
#include <optional>

#include "pinball/track/observation.h"

namespace pinball::track {

class ObservationNoiseEstimator {
 public:
  static constexpr std::size_t kResiduals = 1024;   ///< the latest residuals kept (x and y each count one): 2.6 s at 200 fps
  static constexpr std::size_t kMinResiduals = 64;  ///< fewer than this say nothing
  static constexpr double kMaxGap_s = 0.05;         ///< frames further apart do not make a triple

  /// Adds the next frame of the track (in time order; a frame not after the
  /// last one is ignored).
  void add(const Observation& observation);
  /// A new track (a new ball): the next triple starts afresh; the residuals stay (they are the camera's).
  void restart_track() { frames_ = 0; }
  /// σ per coordinate (m), once kMinResiduals residuals are in; none before.
  /// Refreshed every 32 frames.
  std::optional<double> sigma_m() const;
  /// Residuals kept (at most kResiduals).
  std::size_t residuals() const { return count_; }

 private:
  void push(double residual);

  std::array<Observation, 2> last_{};  // the previous two frames, older first
  std::size_t frames_ = 0;             // frames of the track so far (capped at 2)
  std::array<double, kResiduals> residuals_{};
  std::size_t next_ = 0;
  std::size_t count_ = 0;
  std::size_t since_estimate_ = 0;
  bool estimated_ = false;
  double sigma_m_ = 0.0;
  std::array<double, kResiduals> scratch_{};
};

}  // namespace pinball::track
