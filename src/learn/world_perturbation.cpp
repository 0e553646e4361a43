#include "pinball/learn/world_perturbation.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>

#include "pinball/core/format.h"
#include "pinball/core/read_archive.h"

namespace pinball::learn {

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

Perturbation parse_perturbation(std::string_view name) {
  std::string names;
  for (const Perturbation p : kAllPerturbations) {
    if (perturbation_name(p) == name) return p;
    names += (names.empty() ? "" : ", ") + std::string(perturbation_name(p));
  }
  throw std::invalid_argument("perturbation: no perturbation named '" + std::string(name) + "' (names: " + names + ")");
}

std::pair<Perturbation, double> parse_perturbation_setting(std::string_view text) {
  const std::size_t eq = text.find('=');
  const std::string quoted = quote_value(std::string(text));
  if (eq == std::string_view::npos) {
    throw std::invalid_argument("perturbation " + quoted + ": expected NAME=VALUE, e.g. gravity_pct=-10");
  }
  const Perturbation p = parse_perturbation(text.substr(0, eq));
  std::string_view number = text.substr(eq + 1);
  const bool plus = !number.empty() && number.front() == '+';  // "+3" reads as a sweep row names it
  if (plus) number.remove_prefix(1);
  double value = 0.0;
  const auto [end, ec] = std::from_chars(number.data(), number.data() + number.size(), value);
  if (number.empty() || (plus && number.front() == '-') || ec != std::errc() ||
      end != number.data() + number.size() || !std::isfinite(value)) {
    throw std::invalid_argument("perturbation " + quoted + ": the value is not a finite number");
  }
  return {p, value};
}

bool changes_table(Perturbation p) {
  return p != Perturbation::kActuationDelay_ms && p != Perturbation::kCameraLatency_ms &&
         p != Perturbation::kCameraNoise_px;
}

bool is_offset(Perturbation p) { return changes_table(p); }

WorldSettings perturb(const WorldSettings& nominal, Perturbation p, double value) {
  if (!std::isfinite(value)) throw std::invalid_argument("perturbation: a perturbation's value must be finite");
  WorldSettings w = nominal;
  table::Board& b = w.board;
  switch (p) {
    case Perturbation::kPivotY_mm:
      // A perturbation is a calibration error; 10 cm moves the bats onto another table.
      if (!(std::abs(value) <= 100.0)) throw std::invalid_argument("perturbation: pivot_y must be in [-100, 100] mm");
      for (table::Flipper& f : b.flippers) f.pivot.y() += value * 1e-3;
      break;
    case Perturbation::kThetaMin_deg:
      for (table::Flipper& f : b.flippers) {
        f.theta_min_rad += value * std::numbers::pi / 180.0;
        if (!(f.theta_min_rad < f.theta_max_rad)) {
          throw std::invalid_argument("perturbation: theta_min " + std::to_string(value) +
                                      " deg puts flipper " + f.name + "'s rest stop above its up stop");
        }
      }
      break;
    case Perturbation::kFlipperMu_pct:
      for (table::Flipper& f : b.flippers) {
        f.mu *= 1.0 + value / 100.0;
        if (!(f.mu > 0.0)) throw std::invalid_argument("perturbation: flipper mu must stay > 0 (mu -100 % or less)");
        if (!(f.mu <= table::kMaxFlipperMu)) {
          throw std::invalid_argument("perturbation: flipper mu must stay at most " +
                                      format_number(table::kMaxFlipperMu) + ", a board's largest");
        }
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
      if (!(b.gravity_mps2 > 0.0)) throw std::invalid_argument("perturbation: g must stay > 0 (g -100 % or less)");
      if (!(b.gravity_mps2 <= table::kMaxGravity_mps2)) {
        throw std::invalid_argument("perturbation: g must stay at most " + format_number(table::kMaxGravity_mps2) +
                                    " m/s^2 along the table, a board's largest");
      }
      break;
    case Perturbation::kActuationDelay_ms:
      if (!(value >= 0.0 && value < 1000.0)) throw std::invalid_argument("perturbation: actuation delay must be in [0, 1000) ms");
      w.actuation_delay_s = value * 1e-3;
      break;
    case Perturbation::kCameraLatency_ms:
      if (!(value >= 0.0 && value < 1000.0)) {
        throw std::invalid_argument("perturbation: camera latency must be in [0, 1000) ms");
      }
      w.camera.latency_s = value * 1e-3;
      break;
    case Perturbation::kCameraNoise_px:
      if (!(value >= 0.0 && value <= 100.0)) {
        throw std::invalid_argument("perturbation: camera noise must be in [0, 100] px");
      }
      w.camera.noise_px = value;
      break;
  }
  return w;
}

}  // namespace pinball::learn
