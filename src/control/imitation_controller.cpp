#include "pinball/control/imitation_controller.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace pinball::control {

namespace {

constexpr double kPi = 3.14159265358979323846;

std::size_t line_index(int flipper, bool rolling) {
  return static_cast<std::size_t>(flipper) * 2 + (rolling ? 1 : 0);
}

// Median of the first n values (n >= 1); reorders them.
double median(double* v, int n) {
  std::sort(v, v + n);
  return n % 2 == 1 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

}  // namespace

ShotTable::ShotTable(std::vector<ShotExample> examples, const ImitationConfig& config)
    : examples_(std::move(examples)), config_(config) {
  if (config.neighbours < 1 || config.neighbours > kMaxNeighbours) {
    throw std::invalid_argument("shot table: neighbours must be in [1, " + std::to_string(kMaxNeighbours) + "]");
  }
  if (!(config.angle_scale_rad > 0.0 && config.h_scale > 0.0 && config.speed_scale_mps > 0.0)) {
    throw std::invalid_argument("shot table: the distance scales must be > 0");
  }
  if (!(config.max_hold_s >= 0.0)) throw std::invalid_argument("shot table: max hold must be >= 0");
  if (!(config.lead_s >= 0.0 && config.lead_s < 1.0)) throw std::invalid_argument("shot table: lead must be in [0, 1) s");
  for (std::size_t i = 0; i < examples_.size(); ++i) {
    const ShotExample& e = examples_[i];
    const std::string where = "shot table: example " + std::to_string(i) + ": ";
    if (e.flipper != track::kLeftFlipper && e.flipper != track::kRightFlipper) {
      throw std::invalid_argument(where + "flipper must be 0 (left) or 1 (right)");
    }
    if (e.fired_flipper < -1 || e.fired_flipper > 1) {
      throw std::invalid_argument(where + "fired flipper must be -1 (pass), 0 or 1");
    }
    if (!std::isfinite(e.angle_rad) || !std::isfinite(e.h) || !std::isfinite(e.speed_mps) ||
        !std::isfinite(e.d_fire_m) || !std::isfinite(e.hold_s)) {
      throw std::invalid_argument(where + "numbers must be finite");
    }
    if (e.hold_s < 0.0) throw std::invalid_argument(where + "hold must be >= 0");
    by_line_[line_index(e.flipper, e.rolling)].push_back(i);
  }
}

ImitationDecision ShotTable::decide(const track::TrajectoryProjection& p) const {
  // k nearest by insertion into a fixed array: no allocation on the control path.
  std::array<double, kMaxNeighbours> dist{};
  std::array<std::size_t, kMaxNeighbours> index{};
  int found = 0;
  const int k = config_.neighbours;
  const std::size_t line = line_index(p.flipper == track::kRightFlipper ? 1 : 0, p.rolling);
  for (const std::size_t i : by_line_[line]) {
    const ShotExample& e = examples_[i];
    const double da = std::remainder(e.angle_rad - p.angle_rad, kPi) / config_.angle_scale_rad;
    const double dh = (e.h - p.h) / config_.h_scale;
    const double ds = (e.speed_mps - p.speed_mps) / config_.speed_scale_mps;
    const double d2 = da * da + dh * dh + ds * ds;
    if (found == k && d2 >= dist[static_cast<std::size_t>(k - 1)]) continue;
    int j = found < k ? found++ : k - 1;
    while (j > 0 && dist[static_cast<std::size_t>(j - 1)] > d2) {
      dist[static_cast<std::size_t>(j)] = dist[static_cast<std::size_t>(j - 1)];
      index[static_cast<std::size_t>(j)] = index[static_cast<std::size_t>(j - 1)];
      --j;
    }
    dist[static_cast<std::size_t>(j)] = d2;
    index[static_cast<std::size_t>(j)] = i;
  }
  ImitationDecision out;
  out.neighbours = found;
  std::array<double, kMaxNeighbours> d{};
  std::array<double, kMaxNeighbours> hold{};
  int fired = 0;
  std::array<int, 2> per_flipper{};
  for (int j = 0; j < found; ++j) {
    const ShotExample& e = examples_[index[static_cast<std::size_t>(j)]];
    if (e.fired_flipper < 0) continue;
    d[static_cast<std::size_t>(fired)] = e.d_fire_m;
    hold[static_cast<std::size_t>(fired)] = e.hold_s;
    ++per_flipper[static_cast<std::size_t>(e.fired_flipper)];
    ++fired;
  }
  if (found == 0 || 2 * fired <= found) return out;  // a tie passes: the teacher's default
  out.fire = true;
  out.flipper = per_flipper[1] > per_flipper[0] ? track::kRightFlipper : track::kLeftFlipper;
  out.d_critical_m = median(d.data(), fired);
  out.hold_s = median(hold.data(), fired);
  return out;
}

void ImitationController::reset(std::array<bool, 2>& energized) {
  energized = {false, false};
  held_ = -1;
}

void ImitationController::update(const track::TrackerOutput& out, double now_s, std::array<bool, 2>& energized) {
  if (out.launch.launched || out.launch.lost) {
    reset(energized);
    return;
  }
  if (held_ >= 0) {
    const double max_hold = table_.config().max_hold_s;
    if (now_s + 1e-6 < release_at_s_ && (max_hold <= 0.0 || now_s - held_since_s_ <= max_hold)) return;
    energized[static_cast<std::size_t>(held_)] = false;  // the hold is over: the next decision is a new one
    held_ = -1;
    return;
  }
  const track::TrajectoryProjection& p = out.projection;
  if (!p.valid || !p.hittable) return;
  const ImitationDecision act = table_.decide(p);
  if (!act.fire || p.d_m - p.speed_mps * table_.config().lead_s > act.d_critical_m) return;
  energized[static_cast<std::size_t>(act.flipper)] = true;
  held_ = act.flipper;
  held_since_s_ = now_s;
  release_at_s_ = now_s + act.hold_s;
  ++fires_;
}

}  // namespace pinball::control
