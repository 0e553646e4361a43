#pragma once
// A camera looking at the table, as the tracker sees it: frames at a fixed
// rate, positions quantised to the pixel grid with Gaussian noise, delivered
// after a latency, some frames dropped. The simulator's true ball position
// goes in; observations come out (thesis 4.1: no cheating with true state).

#include <array>
#include <cstdint>

#include "pinball/core/geometry.h"
#include "pinball/core/name_value.h"
#include "pinball/core/rng.h"
#include "pinball/track/observation.h"

namespace pinball::track {

/// Camera settings.
struct CameraModelConfig {
  double fps = 200.0;             ///< frames per second
  double m_per_px = 0.002;        ///< resolution on the table (m per pixel)
  double noise_px = 0.3;          ///< standard deviation of the centroid noise (px)
  /// Exposure to delivery (s). 5 ms is a good 200 fps USB machine-vision
  /// camera with one frame buffered: readout of a 640x480 frame at 200 fps
  /// (up to 5 ms), transfer and driver hand-over; cheaper set-ups add 5-30 ms.
  double latency_s = 0.005;
  double drop_probability = 0.0;  ///< chance a frame is lost

  /// The fields as every report spells them (core/json_write_archive.h).
  template <class Archive>
  void Serialize(Archive* a) {
    a->Visit(PINBALL_NVP(fps));
    a->Visit(PINBALL_NVP(m_per_px));
    a->Visit(PINBALL_NVP(noise_px));
    a->Visit(PINBALL_NVP(latency_s));
    a->Visit(PINBALL_NVP(drop_probability));
  }
};

/// Standard deviation (m) of one observed coordinate: quantisation (res²/12)
/// plus the Gaussian noise, added in quadrature.
double observation_sigma_m(const CameraModelConfig& config);

/// Turns a stream of true positions into delayed, noisy, quantised observations.
/// Allocates nothing after construction.
class CameraModel {
 public:
  /// Throws std::invalid_argument naming the setting when one is out of range.
  CameraModel(const CameraModelConfig& config, std::uint64_t seed);

  /// Feeds the true ball position at time now_s (call every simulation step,
  /// in time order). When a frame falls due it is exposed at this position.
  /// `visible` false (ball in the launcher, hidden) exposes no ball.
  void expose(double now_s, const Vec2& p_true, bool visible = true);

  /// Pops the next observation whose delivery time (exposure + latency) has
  /// come by now_s. Returns false when none is ready.
  bool deliver(double now_s, Observation& out);

  /// Forgets frames in flight and restarts the frame clock at now_s.
  void reset(double now_s);

  /// The settings.
  const CameraModelConfig& config() const { return config_; }
  /// Frames exposed, dropped, and lost because too many were in flight.
  std::uint64_t frames() const { return frames_; }
  std::uint64_t dropped() const { return dropped_; }
  std::uint64_t overflowed() const { return overflowed_; }

 private:
  static constexpr std::size_t kCapacity = 256;  // frames in flight: 1.28 s of latency at 200 fps

  double quantise(double coordinate_m);

  CameraModelConfig config_;
  Rng rng_;
  double period_s_ = 0.0;
  double next_frame_s_ = 0.0;
  std::array<Observation, kCapacity> pending_{};
  std::size_t head_ = 0;
  std::size_t size_ = 0;
  std::uint64_t frames_ = 0;
  std::uint64_t dropped_ = 0;
  std::uint64_t overflowed_ = 0;
};

}  // namespace pinball::track
