#include "pinball/learn/planning_controller.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "pinball/core/check.h"
#include "pinball/track/flipper_geometry.h"

namespace pinball::learn {

LookaheadConfig lookahead_config(const control::PlannerSettings& s, double dt_s) {
  LookaheadConfig c;
  const double frame_s = dt_s * c.frame_steps;
  c.fire_frames = s.fire_frames;
  const auto frames = [&](double hold_s) { return std::max(1, static_cast<int>(std::lround(hold_s / frame_s))); };
  c.hold_frames = {frames(s.short_hold_s), frames(s.long_hold_s)};
  c.zone_factor = s.zone_factor;
  c.horizon_s = s.horizon_s;
  c.drain_penalty = s.drain_penalty;
  c.step_budget = s.step_budget;
  if (s.shot_values) {
    try {
      c.shot_values = std::make_shared<const ShotValueTable>(read_shot_value_table(*s.shot_values));
    } catch (const std::runtime_error& e) {  // said as the controller's key, not as if the board were at fault
      throw std::runtime_error(std::string("the planner's shot_values table: ") + e.what());
    }
  }
  return c;
}

PlanningController::PlanningController(const table::Board& belief, const control::PlannerSettings& settings)
    : belief_(belief),
      settings_(settings),
      state_(sim::make_game_state(belief, 0)),
      delay_(belief.flippers.size(), settings.actuation_delay_s),
      idle_delay_(delay_),
      by_side_(table::flippers_by_side(belief)) {
  check_input(check_planner_settings(settings), "planner");
  check_input(belief.flippers.size() == 2 && by_side_[0] >= 0 && by_side_[1] >= 0, "planner",
              "the belief board must have a left and a right flipper");
  stepper_ = std::make_unique<const sim::ThesisStepper>(belief);
  const LookaheadConfig config = lookahead_config(settings, stepper_->dt_s());
  planner_ = std::make_unique<LookaheadPlanner>(*stepper_, config);
  frame_s_ = stepper_->dt_s() * config.frame_steps;
}

void PlanningController::reset(std::array<bool, 2>& energized) {
  energized = {false, false};
  command_ = {false, false};
  held_ = -1;
  started_ = false;
  state_.ball_in_play = false;
  for (sim::FlipperState& f : state_.flippers) f = sim::FlipperState{};
  for (std::size_t i = 0; i < state_.flippers.size(); ++i) state_.flippers[i].theta_rad = belief_.flippers[i].theta_min_rad;
  delay_ = idle_delay_;
}

void PlanningController::advance_bats_to(double now_s) {
  const double dt = stepper_->dt_s();
  // A long gap (a paused feed): the bats have long settled where the command holds them.
  if (now_s - state_.time_s > 1.0) state_.time_s = now_s - 1.0;
  state_.ball_in_play = false;  // only the bats move here
  while (state_.time_s + 0.5 * dt < now_s) {
    for (std::size_t i = 0; i < 2; ++i) state_.flippers[i].energized = command_[i];
    delay_.apply(state_);
    stepper_->step(state_);
  }
}

bool PlanningController::place_ball(const track::TrackerOutput& o, double now_s) {
  if (o.fit.valid) {
    state_.ball.position_m = o.fit.position_at(now_s);
    state_.ball.velocity_mps = o.fit.velocity_at(now_s);
    return true;
  }
  const track::TrajectoryProjection& p = o.projection;
  if (!(p.valid && p.rolling)) return false;
  // A ball rolling down a bat (4.1.2): along the bat's slope, downhill, d short of the impact point.
  Vec2 u(std::cos(p.angle_rad), std::sin(p.angle_rad));
  if (u.y() > 0.0) u = -u;
  const double moved_m = p.speed_mps * std::max(0.0, now_s - p.t_observation_s);
  state_.ball.position_m = p.impact_point - (p.d_m - moved_m) * u;
  state_.ball.velocity_mps = p.speed_mps * u;
  return true;
}

void PlanningController::update(const track::TrackerOutput& o, double now_s, std::array<bool, 2>& energized) {
  if (o.launch.launched || o.launch.lost) {
    reset(energized);
    return;
  }
  if (!started_) {
    state_.time_s = now_s;
    started_ = true;
  }
  advance_bats_to(now_s);
  if (held_ >= 0) {
    if (now_s + 0.5 * frame_s_ < release_at_s_) return;
    command_[static_cast<std::size_t>(held_)] = false;
    held_ = -1;
  }
  energized = energized_by_side();
  if (!place_ball(o, now_s)) return;
  state_.ball_in_play = true;
  const int f = planner_->decision_flipper(state_);
  if (f >= 0) {
    ++decisions_;
    const std::uint64_t steps_before = planner_->branch_steps();
    const LookaheadCandidate& best = planner_->evaluate(state_, delay_, f)[planner_->best()];
    max_decision_steps_ = std::max(max_decision_steps_, planner_->branch_steps() - steps_before);
    if (best.fire_frame == 0) {
      command_[static_cast<std::size_t>(f)] = true;
      held_ = f;
      release_at_s_ = now_s + best.hold_frames * frame_s_;
      ++fires_;
    }
  }
  state_.ball_in_play = false;
  energized = energized_by_side();
}

std::array<bool, 2> PlanningController::energized_by_side() const {
  return {command_[static_cast<std::size_t>(by_side_[track::kLeftFlipper])],
          command_[static_cast<std::size_t>(by_side_[track::kRightFlipper])]};
}

std::unique_ptr<control::FlipperController> make_controller(const control::ControllerSpec& spec,
                                                            const table::Board& belief) {
  if (spec.planner && !spec.spastic && !spec.cradle) return std::make_unique<PlanningController>(belief, *spec.planner);
  return control::make_flipper_controller(spec);
}

}  // namespace pinball::learn
