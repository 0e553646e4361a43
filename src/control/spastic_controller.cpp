#include "pinball/control/spastic_controller.h"

#include <cmath>
#include <numbers>
#include <string>

namespace pinball::control {

RangeViolation check_spastic_config(const SpasticConfig& c) {
  if (!(c.reach_m > 0.0 && c.reach_m <= 1.0)) return {"reach_m", "must be in (0, 1] m"};
  // Unlike the actuator's, 0 is no setting here: the spastic flipper would drop the coil every update.
  if (!(c.max_hold_s > 0.0 && c.max_hold_s <= kMaxHold_s)) {
    return {"max_hold_s", "must be in (0, " + std::to_string(firmware::kAbsMaxHoldMs / 1000) +
                              "] s (the driver board's hold cap)"};
  }
  if (c.reach_max_m && !(*c.reach_max_m >= c.reach_m && *c.reach_max_m <= 1.0)) {
    return {"reach_max_m", "must be in [reach_m, 1] m"};
  }
  return {};
}

double spastic_reach_m(const SpasticConfig& c, int fire_index) {
  if (!c.reach_max_m || fire_index <= 0) return c.reach_m;
  // Weyl's sequence k/phi mod 1: each new point falls in the largest gap left.
  const double u = std::fmod(fire_index * (std::numbers::phi - 1.0), 1.0);
  return c.reach_m + u * (*c.reach_max_m - c.reach_m);
}

SpasticController::SpasticController(const SpasticConfig& config) : config_(config) {
  check_input(check_spastic_config(config_), "spastic controller");
}

void SpasticController::reset(std::array<bool, 2>& energized) {
  release(energized);
  fires_ = {0, 0};
}

void SpasticController::release(std::array<bool, 2>& energized) {
  energized = {false, false};
  held_since_s_ = {0.0, 0.0};
}

void SpasticController::update(const track::TrackerOutput& out, double now_s, std::array<bool, 2>& energized) {
  if (out.launch.launched || out.launch.lost) {  // a shot leaving the bat, or a drain: not yet a new ball
    release(energized);
    return;
  }
  std::array<bool, 2> timed_out{};
  for (int f = 0; f < 2; ++f) {
    timed_out[f] = energized[f] && now_s - held_since_s_[f] > config_.max_hold_s;
    if (timed_out[f]) energized[f] = false;  // the coil drops for at least one update
  }
  const track::TrajectoryProjection& p = out.projection;
  if (p.valid && p.hittable && p.d_m <= spastic_reach_m(config_, fires_[p.flipper]) && !energized[p.flipper] &&
      !timed_out[p.flipper]) {
    energized[p.flipper] = true;
    held_since_s_[p.flipper] = now_s;
    ++fires_[p.flipper];
  }
}

}  // namespace pinball::control
