#include "pinball/control/spastic_controller.h"

namespace pinball::control {

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
