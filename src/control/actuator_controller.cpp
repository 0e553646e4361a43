#include "pinball/control/actuator_controller.h"

#include <string>

namespace pinball::control {

RangeViolation check_actuator_config(const ActuatorConfig& c) {
  if (!(c.max_hold_s >= 0.0 && c.max_hold_s <= kMaxHold_s))
    return {"max_hold_s", "must be in [0, " + std::to_string(firmware::kAbsMaxHoldMs / 1000) +
                              "] s (the driver board's hold cap; 0: no limit of its own)"};
  return check_lead_actuation_delay(c.lead_actuation_delay_s);
}

ActuatorController::ActuatorController(ActionFunction action_function, const ActuatorConfig& config)
    : action_(std::move(action_function)), config_(config) {
  check_input(check_actuator_config(config_), "actuator controller");
}

void ActuatorController::reset(std::array<bool, 2>& energized) {
  energized = {false, false};
  fired_ = false;
  responsible_ = -1;
  held_since_s_ = {0.0, 0.0};
}

void ActuatorController::update(const track::TrackerOutput& out, double now_s, std::array<bool, 2>& energized) {
  if (out.launch.launched || out.launch.lost) {  // 5.2.3: release on launch or loss
    reset(energized);
    return;
  }
  if (config_.max_hold_s > 0.0) {
    for (int f = 0; f < 2; ++f) {
      if (energized[f] && now_s - held_since_s_[f] > config_.max_hold_s) {
        energized[f] = false;  // a cradled ball: drop the coil and allow a new approach
        fired_ = false;
      }
    }
  }
  const track::TrajectoryProjection p = projection_to_act_on(out, config_.lead_actuation_delay_s);
  if (!p.valid || !p.hittable) return;
  const Action act = action_.action(p);
  responsible_ = act.partition;
  if (!fired_ && p.d_m <= act.d_critical_m) {
    energized[act.flipper] = true;
    held_since_s_[act.flipper] = now_s;
    fired_ = true;
    ++fires_;
  }
}

}  // namespace pinball::control
