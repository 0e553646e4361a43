#pragma once
// The settings of the online planner (`learn::PlanningController`): every
// camera frame while the ball falls near a flipper, it plays "don't fire" and
// "fire at frame k, hold H" ahead in the belief model from the tracker's
// estimate of the ball and acts on the best plan's first frame. A controller
// file holds them under "planner" (docs/learning.md); the planner itself lives
// in learn, which has the simulator.

#include <optional>

#include "pinball/core/check.h"
#include "pinball/core/name_value.h"
#include "pinball/firmware/flipper_actuation.h"

namespace pinball::control {

/// Planning from several starts (beyond the thesis). The tracker's estimate
/// is not the ball's state, and on a chaotic table a plan that is best for
/// the estimate exactly is often best by luck: fed the true state plus 0.3 mm
/// of noise the planner loses most of what it gains on the exact state
/// (docs/results.md). With this section each plan is scored by its value
/// summed over `samples` starts: the estimate, and samples - 1 with the
/// ball's position and velocity moved by Gaussian noise of these standard
/// deviations per coordinate; the plan best across them is the one acted on.
struct StartSampling {
  int samples = 8;                   ///< starts per decision, the estimate among them
  double position_sigma_m = 0.001;   ///< per coordinate (m)
  double velocity_sigma_mps = 0.02;  ///< per coordinate (m/s)

  template <class Archive>
  void Serialize(Archive* a) {
    a->Visit(PINBALL_NVP(samples));
    a->Visit(PINBALL_NVP(position_sigma_m));
    a->Visit(PINBALL_NVP(velocity_sigma_mps));
  }
};

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
  /// Several starts per decision (absent: the estimate alone). Each start's
  /// plans have the whole step_budget, so a decision may simulate samples x
  /// step_budget steps and take that many times as long.
  std::optional<StartSampling> start_sampling;

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
    a->Visit(PINBALL_NVP(start_sampling));
  }
};

/// The first setting outside its range: fire_frames 0..40, holds in
/// [0.005, 1] s, zone factor in (0, 50], horizon in (0, 10] s, drain penalty
/// finite and >= 0, actuation delay in [0, 0.1] s, step budget in [1000,
/// 10^7] steps; start sampling: 1..64 samples, position sigma in [0, 0.05] m,
/// velocity sigma in [0, 2] m/s.
RangeViolation check_planner_settings(const PlannerSettings& settings);

}  // namespace pinball::control
