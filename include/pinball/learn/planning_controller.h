#pragma once
// The online planner: a flipper controller that, every tracker update while
// the ball falls near a flipper, plays its candidate plans ahead in the belief
// model (LookaheadPlanner) from the tracker's estimate of the ball and acts on
// the best plan's first frame. Unlike the ceiling player it never sees the
// world's state: the ball is the tracker's fitted parabola advanced to the
// update's time (so the camera's latency is compensated), the bats are where
// its own commands, through the actuation delay it believes, put them in the
// belief model. Because it replans from what the camera sees every frame, an
// error of the model costs one approach, not every approach after it
// (docs/learning.md, "The online planner").

#include <array>
#include <cstdint>
#include <memory>

#include "pinball/control/controller_file.h"
#include "pinball/control/flipper_controller.h"
#include "pinball/control/planner_settings.h"
#include "pinball/learn/lookahead_player.h"
#include "pinball/simlab/delay_line.h"
#include "pinball/sim/game_state.h"
#include "pinball/sim/thesis_stepper.h"
#include "pinball/table/board.h"

namespace pinball::learn {

/// The lookahead planner's settings for a planner spec: frames of the belief
/// stepper's default step (5 ms each), the two holds rounded to frames.
LookaheadConfig lookahead_config(const control::PlannerSettings& settings, double dt_s);

/// Plans in the belief model from the tracker's output. Allocates nothing in
/// update() after its first plan.
class PlanningController final : public control::FlipperController {
 public:
  /// Borrows `belief` (it must outlive the controller). Throws
  /// std::invalid_argument for settings out of range or a board without a
  /// left and a right flipper.
  PlanningController(const table::Board& belief, const control::PlannerSettings& settings);

  void update(const track::TrackerOutput& output, double now_s, std::array<bool, 2>& energized) override;
  void reset(std::array<bool, 2>& energized) override;

  /// Updates at which the candidates were played, flips fired, and belief steps simulated in plans.
  long decisions() const { return decisions_; }
  long fires() const { return fires_; }
  std::uint64_t branch_steps() const { return planner_->branch_steps(); }
  /// The most belief steps one decision simulated: never above the settings' step_budget.
  std::uint64_t max_decision_steps() const { return max_decision_steps_; }

 private:
  void advance_bats_to(double now_s);
  /// The commands (board order) as a controller gives them: [kLeftFlipper, kRightFlipper].
  std::array<bool, 2> energized_by_side() const;
  bool place_ball(const track::TrackerOutput& output, double now_s);

  const table::Board& belief_;
  control::PlannerSettings settings_;
  std::unique_ptr<const sim::ThesisStepper> stepper_;  // owned; the planner borrows it
  std::unique_ptr<LookaheadPlanner> planner_;
  sim::GameState state_;      // the belief: bats as commanded, the ball as last estimated
  simlab::DelayLine delay_;   // the believed actuation delay on our own commands
  simlab::DelayLine idle_delay_;  // nothing in flight: reset() copies it (same size, no allocation)
  std::array<int, 2> by_side_;    // board index of the left and the right flipper
  std::array<bool, 2> command_{false, false};  // per board flipper, in the board's order
  bool started_ = false;
  int held_ = -1;
  double release_at_s_ = 0.0;
  double frame_s_ = 0.0;
  long decisions_ = 0;
  long fires_ = 0;
  std::uint64_t max_decision_steps_ = 0;
};

/// The flipper controller a spec describes, every kind: the planner (which
/// plans in `belief`, borrowed), otherwise control::make_flipper_controller.
std::unique_ptr<control::FlipperController> make_controller(const control::ControllerSpec& spec,
                                                            const table::Board& belief);

}  // namespace pinball::learn
