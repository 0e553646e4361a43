#include "pinball/learn/value_labels.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <utility>

namespace pinball::learn {

namespace {

constexpr double kPi = 3.14159265358979323846;

// Squared lookup distance between two examples' keys (ShotTable's metric: θ modulo π).
double key_distance2(const control::ShotExample& a, const control::ShotExample& b,
                     const control::ImitationConfig& s) {
  const double da = std::remainder(a.angle_rad - b.angle_rad, kPi) / s.angle_scale_rad;
  const double dh = (a.h - b.h) / s.h_scale;
  const double ds = (a.speed_mps - b.speed_mps) / s.speed_scale_mps;
  return da * da + dh * dh + ds * ds;
}

// The value neighbour `v` puts on firing `flipper` at d = `d_m` with hold `hold_s`:
// its plan with that bat and hold nearest in d, if within half a frame's travel.
bool value_at(const ApproachValues& v, int flipper, double d_m, double hold_s, double& out) {
  if (v.flipper != flipper) return false;
  double best_gap = 0.5 * v.d_step_m + 1e-9;
  bool found = false;
  for (int p = 0; p < v.plans; ++p) {
    const auto i = static_cast<std::size_t>(p);
    if (std::abs(v.hold_s[i] - hold_s) > 1e-9) continue;
    const double gap = std::abs(v.d_m[i] - d_m);
    if (gap <= best_gap) {
      best_gap = gap;
      out = v.value[i];
      found = true;
    }
  }
  return found;
}

}  // namespace

ApproachValues approach_values(const std::vector<LookaheadCandidate>& candidates, int flipper, double d_m,
                               double speed_mps, double frame_s) {
  ApproachValues v;
  v.flipper = flipper;
  v.d_step_m = speed_mps * frame_s;
  for (const LookaheadCandidate& c : candidates) {
    if (c.fire_frame < 0) {
      v.pass_value = c.value;
      continue;
    }
    if (v.plans == kMaxValuedPlans) {
      throw std::invalid_argument("value labels: more than " + std::to_string(kMaxValuedPlans) +
                                  " fire plans (fire frames x holds)");
    }
    const auto i = static_cast<std::size_t>(v.plans++);
    v.d_m[i] = d_m - speed_mps * c.fire_frame * frame_s;
    v.hold_s[i] = c.hold_frames * frame_s;
    v.value[i] = c.value;
  }
  return v;
}

std::vector<control::ShotExample> relabel_by_values(const std::vector<control::ShotExample>& examples,
                                                    const std::vector<ApproachValues>& values, int neighbours,
                                                    const control::ImitationConfig& scales) {
  if (values.size() != examples.size()) throw std::invalid_argument("value labels: one value record per example");
  if (neighbours < 1) throw std::invalid_argument("value labels: neighbours must be >= 1");
  std::vector<control::ShotExample> out = examples;
  std::vector<std::size_t> valued;
  for (std::size_t i = 0; i < examples.size(); ++i) {
    if (values[i].flipper >= 0) valued.push_back(i);
  }
  std::vector<std::pair<double, std::size_t>> near;
  for (const std::size_t i : valued) {
    const control::ShotExample& e = examples[i];
    near.clear();
    for (const std::size_t j : valued) {
      const control::ShotExample& o = examples[j];
      if (o.flipper != e.flipper || o.rolling != e.rolling) continue;
      near.emplace_back(key_distance2(e, o, scales), j);
    }
    const auto k = std::min<std::size_t>(near.size(), static_cast<std::size_t>(neighbours));
    std::partial_sort(near.begin(), near.begin() + static_cast<std::ptrdiff_t>(k), near.end());
    double pass = 0.0;
    for (std::size_t n = 0; n < k; ++n) pass += values[near[n].second].pass_value;
    pass /= static_cast<double>(k);
    // The example's own plans are the actions weighed.
    const ApproachValues& own = values[i];
    double best = pass;
    int best_plan = -1;
    for (int p = 0; p < own.plans; ++p) {
      const auto pi = static_cast<std::size_t>(p);
      double sum = 0.0;
      std::size_t covered = 0;
      for (std::size_t n = 0; n < k; ++n) {
        double v = 0.0;
        if (value_at(values[near[n].second], own.flipper, own.d_m[pi], own.hold_s[pi], v)) {
          sum += v;
          ++covered;
        }
      }
      if (2 * covered < k || covered == 0) continue;
      const double mean = sum / static_cast<double>(covered);
      if (mean > best) {
        best = mean;
        best_plan = p;
      }
    }
    control::ShotExample& label = out[i];
    if (best_plan < 0) {
      label.fired_flipper = -1;
      label.d_fire_m = 0.0;
      label.hold_s = 0.0;
    } else {
      const auto b = static_cast<std::size_t>(best_plan);
      label.fired_flipper = own.flipper;
      label.d_fire_m = own.d_m[b];
      label.hold_s = own.hold_s[b];
    }
  }
  return out;
}

}  // namespace pinball::learn
