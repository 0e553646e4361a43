#include "pinball/control/spastic_controller.h"

#include <string>

namespace pinball::control {

RangeViolation check_spastic_config(const SpasticConfig& c) {
  if (!(c.reach_m > 0.0 && c.reach_m <= 1.0)) return {"reach_m", "must be in (0, 1] m"};
  // Unlike the actuator's, 0 is no setting here: the spastic flipper would drop the coil every update.
  if (!(c.max_hold_s > 0.0 && c.max_hold_s <= kMaxHold_s)) {
    return {"max_hold_s", "must be in (0, " + std::to_string(firmware::kAbsMaxHoldMs / 1000) +
                              "] s (the driver board's hold cap)"};
  }
  return {};
}

SpasticController::SpasticController(const SpasticConfig& config) : config_(config) {
  check_input(check_spastic_config(config_), "spastic controller");
}

void SpasticController::reset(std::array<bool, 2>& energized) {
  energized = {false, false};
  held_since_s_ = {0.0, 0.0};
}

void SpasticController::update(const track::TrackerOutput& out, double now_s, std::array<bool, 2>& energized) {
  if (out.launch.launched || out.launch.lost) {
    reset(energized);
    return;
  }
  std::array<bool, 2> timed_out{};
  for (int f = 0; f < 2; ++f) {
    timed_out[f] = energized[f] && now_s - held_since_s_[f] > config_.max_hold_s;
    if (timed_out[f]) energized[f] = false;  // the coil drops for at least one update
  }
  const track::TrajectoryProjection& p = out.projection;
  if (p.valid && p.hittable && p.d_m <= config_.reach_m && !energized[p.flipper] && !timed_out[p.flipper]) {
    energized[p.flipper] = true;
    held_since_s_[p.flipper] = now_s;
  }
}

}  // namespace pinball::control
