#include "pinball/track/camera_model.h"

#include <cmath>
#include <stdexcept>
#include <string>

#include "pinball/core/check.h"

namespace pinball::track {

double observation_sigma_m(const CameraModelConfig& c) {
  const double quantisation = c.m_per_px * c.m_per_px / 12.0;
  const double noise = c.noise_px * c.m_per_px;
  return std::sqrt(quantisation + noise * noise);
}

CameraModel::CameraModel(const CameraModelConfig& config, std::uint64_t seed) : config_(config), rng_(seed) {
  check_input(std::isfinite(config.fps) && config.fps > 0.0, "camera model", "fps must be > 0");
  check_input(std::isfinite(config.m_per_px) && config.m_per_px > 0.0, "camera model", "m_per_px must be > 0");
  check_input(std::isfinite(config.noise_px) && config.noise_px >= 0.0, "camera model", "noise_px must be >= 0");
  check_input(std::isfinite(config.latency_s) && config.latency_s >= 0.0, "camera model", "latency_s must be >= 0");
  check_input(config.drop_probability >= 0.0 && config.drop_probability < 1.0, "camera model", "drop_probability must be in [0, 1)");
  period_s_ = 1.0 / config.fps;
}

void CameraModel::reset(double now_s) {
  head_ = 0;
  size_ = 0;
  next_frame_s_ = now_s;
}

double CameraModel::quantise(double coordinate_m) {
  // The detector's centroid lands on the pixel grid after the noise.
  const double px = coordinate_m / config_.m_per_px + config_.noise_px * rng_.normal();
  return std::round(px) * config_.m_per_px;
}

void CameraModel::expose(double now_s, const Vec2& p_true, bool visible) {
  // Tolerance of a nanosecond: frame times are sums of periods.
  if (now_s + 1e-9 < next_frame_s_) return;
  next_frame_s_ += period_s_;
  if (next_frame_s_ <= now_s) next_frame_s_ = now_s + period_s_;  // caller skipped frames: resync
  ++frames_;
  if (!visible) return;
  if (config_.drop_probability > 0.0 && rng_.uniform01() < config_.drop_probability) {
    ++dropped_;
    return;
  }
  if (size_ == kCapacity) {
    ++overflowed_;
    return;
  }
  Observation& o = pending_[(head_ + size_) % kCapacity];
  o.t_s = now_s;  // the position is the one at now_s, a step after the frame fell due at most
  o.p_board = Vec2{quantise(p_true.x()), quantise(p_true.y())};
  o.confidence = 1.0;
  ++size_;
}

bool CameraModel::deliver(double now_s, Observation& out) {
  if (size_ == 0) return false;
  const Observation& o = pending_[head_];
  if (o.t_s + config_.latency_s > now_s + 1e-9) return false;
  out = o;
  out.latency_s = config_.latency_s;  // what the lab's latency calibration tells the detector
  head_ = (head_ + 1) % kCapacity;
  --size_;
  return true;
}

}  // namespace pinball::track
