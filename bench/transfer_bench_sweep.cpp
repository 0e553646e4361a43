// The transfer bench's sweep: what each perturbation changes in the world,
// and the values (the measurement: transfer_bench.cpp).
#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>

#include "transfer_bench.h"

namespace pinball::bench {

std::string_view perturbation_name(Perturbation p) {
  switch (p) {
    case Perturbation::kPivotY_mm: return "pivot_y_mm";
    case Perturbation::kThetaMin_deg: return "theta_min_deg";
    case Perturbation::kFlipperMu_pct: return "flipper_mu_pct";
    case Perturbation::kWallRho: return "wall_rho";
    case Perturbation::kGravity_pct: return "gravity_pct";
    case Perturbation::kActuationDelay_ms: return "actuation_delay_ms";
    case Perturbation::kCameraLatency_ms: return "camera_latency_ms";
    case Perturbation::kCameraNoise_px: return "camera_noise_px";
  }
  return "?";
}

std::string_view perturbation_label(Perturbation p) {
  switch (p) {
    case Perturbation::kPivotY_mm: return "flipper pivots moved up the table (mm)";
    case Perturbation::kThetaMin_deg: return "flipper rest angle theta_min (deg)";
    case Perturbation::kFlipperMu_pct: return "flipper mu (%)";
    case Perturbation::kWallRho: return "wall rho (added)";
    case Perturbation::kGravity_pct: return "g along the table (%)";
    case Perturbation::kActuationDelay_ms: return "actuation delay (ms)";
    case Perturbation::kCameraLatency_ms: return "camera latency (ms)";
    case Perturbation::kCameraNoise_px: return "camera noise (px)";
  }
  return "?";
}

bool is_offset(Perturbation p) {
  return p != Perturbation::kActuationDelay_ms && p != Perturbation::kCameraLatency_ms &&
         p != Perturbation::kCameraNoise_px;
}

double nominal_value(Perturbation p, const TransferBenchOptions& options) {
  switch (p) {
    case Perturbation::kActuationDelay_ms: return options.actuation_delay_s * 1e3;
    case Perturbation::kCameraLatency_ms: return options.camera.latency_s * 1e3;
    case Perturbation::kCameraNoise_px: return options.camera.noise_px;
    default: return 0.0;
  }
}

std::vector<SweepFamily> default_transfer_sweep() {
  return {{Perturbation::kPivotY_mm, {-5, -3, -1, 1, 3, 5}},
          {Perturbation::kThetaMin_deg, {-1, -0.5, 0.5, 1}},
          {Perturbation::kFlipperMu_pct, {-20, 20}},
          {Perturbation::kWallRho, {-0.1, 0.1}},
          {Perturbation::kGravity_pct, {-10, -5, -3, 3, 5, 10}},
          {Perturbation::kActuationDelay_ms, {0, 10, 20}},
          {Perturbation::kCameraLatency_ms, {0, 10}},
          {Perturbation::kCameraNoise_px, {1, 2}}};
}

std::vector<SweepFamily> quick_transfer_sweep() {
  return {{Perturbation::kPivotY_mm, {3}},         {Perturbation::kThetaMin_deg, {-1}},
          {Perturbation::kFlipperMu_pct, {20}},    {Perturbation::kWallRho, {-0.1}},
          {Perturbation::kGravity_pct, {10}},      {Perturbation::kActuationDelay_ms, {20}},
          {Perturbation::kCameraLatency_ms, {10}}, {Perturbation::kCameraNoise_px, {2}}};
}

WorldSettings perturb(const WorldSettings& nominal, Perturbation p, double value) {
  if (!std::isfinite(value)) throw std::invalid_argument("transfer bench: a perturbation's value must be finite");
  WorldSettings w = nominal;
  table::Board& b = w.board;
  switch (p) {
    case Perturbation::kPivotY_mm:
      for (table::Flipper& f : b.flippers) f.pivot.y() += value * 1e-3;
      break;
    case Perturbation::kThetaMin_deg:
      for (table::Flipper& f : b.flippers) {
        f.theta_min_rad += value * std::numbers::pi / 180.0;
        if (!(f.theta_min_rad < f.theta_max_rad)) {
          throw std::invalid_argument("transfer bench: theta_min " + std::to_string(value) +
                                      " deg puts flipper " + f.name + "'s rest stop above its up stop");
        }
      }
      break;
    case Perturbation::kFlipperMu_pct:
      for (table::Flipper& f : b.flippers) {
        f.mu *= 1.0 + value / 100.0;
        if (!(f.mu > 0.0)) throw std::invalid_argument("transfer bench: flipper mu must stay > 0 (mu -100 % or less)");
      }
      break;
    case Perturbation::kWallRho:
      // Walls that lose energy (ρ ≤ 1); kickers (ρ > 1) and the drain keep theirs.
      for (table::Obstacle& o : b.obstacles) {
        if (o.rho <= 1.0 && !o.action.eats_ball) o.rho = std::clamp(o.rho + value, 0.0, 1.0);
      }
      break;
    case Perturbation::kGravity_pct:
      b.gravity_mps2 *= 1.0 + value / 100.0;
      if (!(b.gravity_mps2 > 0.0)) throw std::invalid_argument("transfer bench: g must stay > 0 (g -100 % or less)");
      break;
    case Perturbation::kActuationDelay_ms:
      if (!(value >= 0.0 && value < 1000.0)) throw std::invalid_argument("transfer bench: actuation delay must be in [0, 1000) ms");
      w.actuation_delay_s = value * 1e-3;
      break;
    case Perturbation::kCameraLatency_ms:
      if (!(value >= 0.0)) throw std::invalid_argument("transfer bench: camera latency must be >= 0 ms");
      w.camera.latency_s = value * 1e-3;
      break;
    case Perturbation::kCameraNoise_px:
      if (!(value >= 0.0)) throw std::invalid_argument("transfer bench: camera noise must be >= 0 px");
      w.camera.noise_px = value;
      break;
  }
  return w;
}

}  // namespace pinball::bench
