#include "pinball/control/action_function.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>

namespace pinball::control {

ActionFunctionConfig uniform_partition(int k) {
  if (k < 1) throw std::invalid_argument("action function: k (angle partitions) must be >= 1, got " + std::to_string(k));
  ActionFunctionConfig c;
  for (int i = 1; i < k; ++i) c.angle_borders_rad.push_back(-std::numbers::pi / 2 + std::numbers::pi * i / k);
  return c;
}

namespace {

constexpr double kMaxHBorder = 100.0;  // flipper lengths: the tracker's h is about 0..1.3

RangeViolation check_borders(const std::vector<double>& v, double lo, double hi, const char* key) {
  if (v.size() >= static_cast<std::size_t>(kMaxBins)) {
    return {key, "must have at most " + std::to_string(kMaxBins - 1) + " borders (" + std::to_string(kMaxBins) + " bins)"};
  }
  for (std::size_t i = 0; i < v.size(); ++i) {
    if (!std::isfinite(v[i]) || v[i] <= lo || v[i] >= hi || (i > 0 && v[i] <= v[i - 1])) {
      return {key, "must be finite, strictly increasing and inside (" + std::to_string(lo) + ", " + std::to_string(hi) + ")"};
    }
  }
  return {};
}

}  // namespace

RangeViolation check_action_function_config(const ActionFunctionConfig& c) {
  if (RangeViolation v = check_borders(c.angle_borders_rad, -std::numbers::pi / 2, std::numbers::pi / 2, "angle_borders_rad")) {
    return v;
  }
  if (RangeViolation v = check_borders(c.h_borders, -kMaxHBorder, kMaxHBorder, "h_borders")) return v;
  for (double g : c.gain_range) {
    if (!(g >= 0.0 && g <= kMaxGain)) return {"gain_range", "must each be in [0, 10]"};  // kMaxGain
  }
  return {};
}

RangeViolation check_minicontroller(const Minicontroller& m) {
  for (double g : m.a) {
    if (!(std::abs(g) <= kMaxGain)) return {"a", "must each be in [-10, 10]"};  // ±kMaxGain
  }
  if (m.flipper != track::kLeftFlipper && m.flipper != track::kRightFlipper) return {"flipper", "must be left or right"};
  return {};
}

ActionFunction::ActionFunction(ActionFunctionConfig config) : config_(std::move(config)) {
  check_input(check_action_function_config(config_), "action function");
  const int n = 2 * angle_bins() * h_bins() + (config_.rolling_minicontrollers ? 2 : 0);
  minis_.assign(static_cast<std::size_t>(n), Minicontroller{});
  for (int i = 0; i < n; ++i) minis_[static_cast<std::size_t>(i)].flipper = i < n / 2 ? 0 : 1;
  if (config_.rolling_minicontrollers) {
    for (int f = 0; f < 2; ++f) minis_[static_cast<std::size_t>(2 * angle_bins() * h_bins() + f)].flipper = f;
    for (int i = 0; i < 2 * angle_bins() * h_bins(); ++i) {
      minis_[static_cast<std::size_t>(i)].flipper = i < angle_bins() * h_bins() ? 0 : 1;
    }
  }
}

int ActionFunction::angle_bin(double angle_rad) const {
  const auto& b = config_.angle_borders_rad;
  return static_cast<int>(std::upper_bound(b.begin(), b.end(), angle_rad) - b.begin());
}

int ActionFunction::h_bin(double h) const {
  const auto& b = config_.h_borders;
  return static_cast<int>(std::upper_bound(b.begin(), b.end(), h) - b.begin());
}

int ActionFunction::partition_of(const track::TrajectoryProjection& p) const {
  const int f = p.flipper == track::kRightFlipper ? 1 : 0;
  if (p.rolling && config_.rolling_minicontrollers) return 2 * angle_bins() * h_bins() + f;
  return (f * angle_bins() + angle_bin(p.angle_rad)) * h_bins() + h_bin(p.h);
}

double ActionFunction::d_critical(int partition, const track::TrajectoryProjection& p) const {
  const auto& a = minis_[static_cast<std::size_t>(partition)].a;
  return a[0] * p.angle_rad + a[1] * p.h + a[2] * p.speed_mps + a[3];
}

Action ActionFunction::action(const track::TrajectoryProjection& p) const {
  Action act;
  act.partition = partition_of(p);
  act.d_critical_m = d_critical(act.partition, p);
  act.flipper = minis_[static_cast<std::size_t>(act.partition)].flipper;
  return act;
}

Minicontroller ActionFunction::random_minicontroller(Rng& rng) const {
  Minicontroller m;
  for (int i = 0; i < 4; ++i) m.a[static_cast<std::size_t>(i)] = rng.uniform(-config_.gain_range[i], config_.gain_range[i]);
  m.flipper = rng.uniform01() < 0.5 ? track::kLeftFlipper : track::kRightFlipper;
  return m;
}

void ActionFunction::randomise(Rng& rng) {
  for (auto& m : minis_) m = random_minicontroller(rng);
}

std::string ActionFunction::partition_name(int i) const {
  const int plain = 2 * angle_bins() * h_bins();
  if (i >= plain) return std::string(i == plain ? "L" : "R") + " rolling";
  const int f = i / (angle_bins() * h_bins());
  const int rest = i % (angle_bins() * h_bins());
  std::string name = std::string(f == 0 ? "L" : "R") + " angle " + std::to_string(rest / h_bins());
  if (h_bins() > 1) name += " h " + std::to_string(rest % h_bins());
  return name;
}

}  // namespace pinball::control
