#pragma once
// The settings of the online planner (`learn::PlanningController`): every
// camera frame while the ball falls near a flipper, it plays "don't fire" and
// "fire at frame k, hold H" ahead in the belief model from the tracker's
// estimate of the ball and acts on the best plan's first frame. A controller
// file holds them under "planner" (docs/learning.md); the planner itself lives
// in learn, which has the simulator.

#include <optional>
#include <string>

#include "pinball/core/check.h"
#include "pinball/core/name_value.h"
#include "pinball/firmware/flipper_actuation.h"

namespace pinball::control {

/// What the planner tries and what it believes of the coil.
struct PlannerSettings {
  int fire_frames = 4;           ///< fire candidates at frames 0..fire_frames from now (5 ms frames)
  double short_hold_s = 0.03;    ///< the short hold candidate (s)
  double long_hold_s = 0.10;     ///< the long hold candidate (s)
  double zone_factor = 5.0;      ///< plan while the ball is within this many radii of a flipper's rest segment
  double horizon_s = 0.5;        ///< longest branch (simulated s)
  double drain_penalty = 20000.0;  ///< points a branch loses when the ball drains in it
  /// Command to bat motion the planner assumes (s): the calibrated or identified delay.
  double actuation_delay_s = firmware::kDefaultActuationDelay_s;
  /// Most belief steps (0.5 ms each) one decision simulates, all plans
  /// together: the bound on a decision's time on the controller thread. Each
  /// plan gets an equal share, so a share shorter than the horizon shortens
  /// every plan alike. Steps near the flippers, where plans are made, cost up
  /// to 0.29 us in pinballd (docs/results.md), so 12000 steps is 3.5 ms of the
  /// 5 ms frame; the defaults (11 plans of 0.5 s) need 11000.
  int step_budget = 12000;
  /// A shot-value table (learn/shot_values.h, `pinball learn --method
  /// shot-values`) that values each plan at its shot rather than by the
  /// branch played past it; a relative path is from the controller file's
  /// folder. None by default.
  std::optional<std::string> shot_values;

  template <class Archive>
  void Serialize(Archive* a) {
    a->Visit(PINBALL_NVP(fire_frames));
    a->Visit(PINBALL_NVP(short_hold_s));
    a->Visit(PINBALL_NVP(long_hold_s));
    a->Visit(PINBALL_NVP(zone_factor));
    a->Visit(PINBALL_NVP(horizon_s));
    a->Visit(PINBALL_NVP(drain_penalty));
    a->Visit(PINBALL_NVP(actuation_delay_s));
    a->Visit(PINBALL_NVP(step_budget));
    a->Visit(PINBALL_NVP(shot_values));
  }
};

/// The first setting outside its range: fire_frames 0..40, holds in
/// [0.005, 1] s, zone factor in (0, 50], horizon in (0, 10] s, drain penalty
/// finite and >= 0, actuation delay in [0, 0.1] s, step budget in [1000,
/// 10^7] steps.
RangeViolation check_planner_settings(const PlannerSettings& settings);

}  // namespace pinball::control
