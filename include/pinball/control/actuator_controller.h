#pragma once
// The actuator controller (thesis 5.2.3): fires the action's flipper once the
// ball is within d_critical of its projected impact, once per approach, and
// releases on a detected launch or a lost ball.

#include <array>
#include <optional>

#include "pinball/control/action_function.h"
#include "pinball/control/flipper_controller.h"
#include "pinball/core/name_value.h"

namespace pinball::control {

/// Settings of the actuator controller.
struct ActuatorConfig {
  /// Release a flipper held this long with no launch seen (a cradled ball), and
  /// allow a new approach; 0 disables (the thesis: launch or loss only; the
  /// driver board's hold cap still applies). 0..kMaxHold_s.
  double max_hold_s = 1.0;

  /// Lead (issue 20): act on the projection advanced to the moment a command
  /// given now takes effect, the newest frame's camera latency plus this
  /// actuation delay (s), so that d_critical means the same whatever the
  /// latency (track::lead_projection). Absent: the thesis's projection from
  /// the newest frame, which a learned d_critical tunes to one latency. 0..0.1 s.
  std::optional<double> lead_actuation_delay_s;

  /// The keys of a controller file (docs/learning.md).
  template <class Archive>
  void Serialize(Archive* a) {
    a->Visit(PINBALL_NVP(max_hold_s));
    a->Visit(PINBALL_NVP(lead_actuation_delay_s));
  }
};

/// A setting outside its range (max_hold_s in [0, kMaxHold_s]).
RangeViolation check_actuator_config(const ActuatorConfig& config);

/// The action function driving the flippers.
class ActuatorController final : public FlipperController {
 public:
  /// Throws std::invalid_argument for a setting out of range (check_actuator_config).
  ActuatorController(ActionFunction action_function, const ActuatorConfig& config = {});

  void update(const track::TrackerOutput& output, double now_s, std::array<bool, 2>& energized) override;
  void reset(std::array<bool, 2>& energized) override;

  /// Partition responsible for the current approach (the latest hittable
  /// projection's), or −1 when none since the last launch.
  int responsible_partition() const { return responsible_; }
  /// Flips fired since construction.
  long fires() const { return fires_; }
  /// The action function and settings.
  const ActionFunction& action_function() const { return action_; }
  const ActuatorConfig& config() const { return config_; }

 private:
  ActionFunction action_;
  ActuatorConfig config_;
  bool fired_ = false;        // fired in this approach
  int responsible_ = -1;
  std::array<double, 2> held_since_s_{};
  long fires_ = 0;
};

}  // namespace pinball::control
