#pragma once
// A player that looks ahead with the simulator: every camera frame (5 ms)
// while the ball falls near a flipper, it plays candidate plans ahead on copies
// of the game state ("don't fire", and "fire at frame k, hold H frames,
// release") and acts on the best one's first frame (receding horizon).
//
// Given the simulator's TRUE state it CHEATS: `pinball bench ceiling` uses it
// as a ceiling reference, and `pinball learn --method imitate` uses it as the
// teacher whose shots a real controller learns to copy (docs/learning.md).
// A branch ends when the ball comes back falling into a decision zone after
// having left every zone (the next approach), when the ball is lost, or at the
// horizon; its value is the score gained in it, minus `drain_penalty` if the
// ball was lost. Ties go to the earlier candidate, so "don't fire" wins when
// nothing is better. Commands pass through the actuation delay (DelayLine) in
// the branches as in the real play.

#include <cstdint>
#include <memory>
#include <vector>

#include "pinball/learn/shot_values.h"
#include "pinball/simlab/delay_line.h"
#include "pinball/sim/game_state.h"
#include "pinball/sim/thesis_stepper.h"

namespace pinball::learn {

/// The lookahead planner's settings.
struct LookaheadConfig {
  int frame_steps = 10;                  ///< decision period in stepper steps (10 x 0.5 ms = 5 ms)
  int fire_frames = 8;                   ///< K: fire candidates at frames 0..K from now
  std::vector<int> hold_frames = {6, 20};  ///< H candidates, in frames (30 ms, 100 ms at 5 ms)
  double zone_factor = 5.0;              ///< decision zone: ball within this many radii of a flipper's rest segment
  double falling_speed_mps = 0.05;       ///< the ball counts as falling when vy < -this
  double horizon_s = 3.0;                ///< longest branch (simulated s)
  double drain_penalty = 20000.0;        ///< subtracted from a branch in which the ball is lost
  /// Most stepper steps one evaluate() may simulate, all candidates together
  /// (0: only the horizon bounds them). Each branch gets an equal share, so
  /// the candidates are still compared over the same length; a branch cut by
  /// it ends as one cut by the horizon. What bounds a decision's time on the
  /// controller thread, deterministically (the same plans on every machine).
  std::int64_t step_budget = 0;
  /// Where a branch's shot is read: the ball, having touched a bat, rises
  /// through this height above the highest pivot (m).
  double shot_exit_height_m = 0.10;
  /// What shots are worth (none: every branch is valued by what it played).
  /// With a table, a branch ends at its shot and is worth its points so far
  /// plus the table's value of the shot, where the table has one.
  std::shared_ptr<const ShotValueTable> shot_values;
};

/// One candidate plan and its branch's outcome.
struct LookaheadCandidate {
  int fire_frame = -1;      ///< frame (from now) at which the flipper is fired; -1: don't fire
  int hold_frames = 0;      ///< frames held before release
  double value = 0.0;       ///< score gained minus the drain penalty if lost
  double score = 0.0;       ///< score gained in the branch
  bool lost = false;        ///< the ball was lost within the branch
  double length_s = 0.0;    ///< simulated length of the branch
  /// The branch's shot, if the ball rose off a bat through the shot line in it.
  int shot_flipper = -1;            ///< the bat it last touched; -1: no shot
  double shot_direction_deg = 0.0;  ///< direction of travel there (atan2 of the velocity)
  double shot_speed_mps = 0.0;
  double score_at_shot = 0.0;       ///< points gained before the shot
  bool valued_by_table = false;     ///< value is score_at_shot plus the shot-value table's
};

/// Plays candidate plans ahead on copies of the state. Holds scratch copies
/// sized for one board; evaluate() allocates nothing after the first call.
class LookaheadPlanner {
 public:
  /// Borrows the stepper (and its board). Throws std::invalid_argument for bad settings.
  LookaheadPlanner(const sim::ThesisStepper& stepper, const LookaheadConfig& config);

  /// The flipper to plan for: the one nearest the ball when the ball is in
  /// play, falling and within the decision zone; -1 otherwise.
  int decision_flipper(const sim::GameState& state) const;

  /// Evaluates "don't fire" (index 0) and every fire plan for `flipper` from
  /// `state` (commands all off from now, `delay` as it stands). Leaves state and delay untouched.
  const std::vector<LookaheadCandidate>& evaluate(const sim::GameState& state, const simlab::DelayLine& delay,
                                                int flipper);
  /// Index of the best candidate of the last evaluate(): the first of the highest value.
  std::size_t best() const;
  /// The longest branch in steps: the horizon, or the step budget's share if shorter.
  std::uint64_t max_branch_steps() const { return max_branch_steps_; }
  /// Stepper steps simulated in branches so far.
  std::uint64_t branch_steps() const { return branch_steps_; }
  /// The settings.
  const LookaheadConfig& config() const { return config_; }
  /// The candidates of the last evaluate().
  const std::vector<LookaheadCandidate>& candidates() const { return candidates_; }

 private:
  bool in_zone(const sim::GameState& state) const;
  void play_branch(LookaheadCandidate& c, int flipper);

  const sim::ThesisStepper& stepper_;
  LookaheadConfig config_;
  std::vector<LookaheadCandidate> candidates_;
  sim::GameState scratch_;
  simlab::DelayLine scratch_delay_;
  const sim::GameState* origin_ = nullptr;
  const simlab::DelayLine* origin_delay_ = nullptr;
  std::uint64_t branch_steps_ = 0;
  std::uint64_t max_branch_steps_ = 0;
  double shot_y_m_ = 0.0;  // the shot line
};

/// The looking-ahead player on the true state: plans every frame while no flip
/// is under way, fires for the best plan's hold, then releases and plans again.
class LookaheadPlayer {
 public:
  /// Borrows the stepper. Throws std::invalid_argument for bad settings.
  LookaheadPlayer(const sim::ThesisStepper& stepper, const LookaheadConfig& config, double actuation_delay_s);

  /// One simulation step: sets the flipper commands in `state` (through the
  /// actuation delay). Decides at every config.frame_steps-th step.
  void act(sim::GameState& state);
  /// The same, deciding when `frame` is true (e.g. when a camera frame arrived).
  void act(sim::GameState& state, bool frame);
  /// The flipper fired by the last act() (-1: none), and the hold it chose (s).
  int fired_flipper() const { return fired_; }
  double fired_hold_s() const { return fired_hold_s_; }
  /// Frames at which candidates were evaluated, and lookahead steps simulated.
  int decisions() const { return decisions_; }
  std::uint64_t branch_steps() const { return planner_.branch_steps(); }
  /// The planner, for its last candidates.
  const LookaheadPlanner& planner() const { return planner_; }

 private:
  void decide(const sim::GameState& s);

  LookaheadPlanner planner_;
  simlab::DelayLine delay_;
  std::vector<bool> command_;
  std::uint64_t step_ = 0;
  int held_ = -1;
  int release_in_ = 0;
  int decisions_ = 0;
  int fired_ = -1;
  double fired_hold_s_ = 0.0;
  double frame_s_ = 0.0;  // one decision frame (s)
};

}  // namespace pinball::learn
