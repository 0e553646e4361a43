#pragma once
// Labels a camera-fed controller can act on (docs/learning.md, "Value
// labels"). The teacher plans on the true state, so its best plan for one
// approach is the best for that exact ball, which the tracker cannot tell
// from its neighbours; after a collision the outcome is chaotic, so copying
// each exact best makes the table vote among lucky shots. Instead every
// approach keeps the teacher's value of each plan it played ahead ("don't
// fire", "fire when d has come down to D, hold H"), and is relabelled with
// the plan whose value, averaged over the k approaches nearest it in what the
// tracker sees (θ, h, s on the same flipper line), is highest: the action
// best on average over the balls that look alike, which is the one a
// controller that sees only the tracker should take.

#include <array>
#include <cstddef>
#include <vector>

#include "pinball/control/imitation_controller.h"
#include "pinball/learn/lookahead_player.h"

namespace pinball::learn {

/// Most fire plans one approach's values hold ((fire_frames + 1) x holds).
inline constexpr int kMaxValuedPlans = 32;

/// The teacher's values of one approach's plans, taken at the first frame it
/// judged the approach (trivially copyable: it travels in a demonstration blob).
struct ApproachValues {
  int flipper = -1;           ///< tracker index of the bat the plans fire; -1: no values (keep the label)
  int plans = 0;              ///< fire plans held
  double pass_value = 0.0;    ///< value of "don't fire"
  double d_step_m = 0.0;      ///< how much d falls between successive fire frames (m)
  std::array<double, kMaxValuedPlans> d_m{};     ///< d at which each plan fires (m)
  std::array<double, kMaxValuedPlans> hold_s{};  ///< each plan's hold (s)
  std::array<double, kMaxValuedPlans> value{};   ///< each plan's value (score gained, less the drain penalty if lost)
};

/// The values of the candidates of one LookaheadPlanner::evaluate for the bat
/// with tracker index `flipper`, at a frame whose projection says d = `d_m`
/// at `speed_mps`; a plan firing k frames later fires at d − speed·k·frame_s.
/// Throws std::invalid_argument for more than kMaxValuedPlans fire plans.
ApproachValues approach_values(const std::vector<LookaheadCandidate>& candidates, int flipper, double d_m,
                               double speed_mps, double frame_s);

/// Each example with values relabelled by the plan best on average over its
/// `neighbours` nearest examples with values (the lookup's distance in
/// `scales`; the example itself included). A fire plan is averaged over the
/// neighbours whose own plans fire the same bat with the same hold within
/// half a frame's travel of its d; it competes only when at least half the
/// neighbours have one. Ties go to "don't fire". Examples without values keep
/// their label. `values` runs parallel to `examples`. Throws
/// std::invalid_argument when the sizes differ or `neighbours` < 1.
std::vector<control::ShotExample> relabel_by_values(const std::vector<control::ShotExample>& examples,
                                                    const std::vector<ApproachValues>& values, int neighbours,
                                                    const control::ImitationConfig& scales);

}  // namespace pinball::learn
