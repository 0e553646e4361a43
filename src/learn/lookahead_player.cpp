#include "pinball/learn/lookahead_player.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>

namespace pinball::learn {

LookaheadPlanner::LookaheadPlanner(const sim::ThesisStepper& stepper, const LookaheadConfig& config)
    : stepper_(stepper),
      config_(config),
      scratch_(sim::make_game_state(stepper.board(), 0)),
      scratch_delay_(stepper.board().flippers.size(), 0.0) {
  if (config.frame_steps < 1) throw std::invalid_argument("ceiling planner: frame_steps must be >= 1");
  if (config.fire_frames < 0) throw std::invalid_argument("ceiling planner: fire_frames must be >= 0");
  if (config.hold_frames.empty()) throw std::invalid_argument("ceiling planner: hold_frames must not be empty");
  for (const int h : config.hold_frames) {
    if (h < 1) throw std::invalid_argument("ceiling planner: every hold must be >= 1 frame");
  }
  if (!(config.zone_factor > 0.0)) throw std::invalid_argument("ceiling planner: zone_factor must be > 0");
  if (!(config.horizon_s > 0.0)) throw std::invalid_argument("ceiling planner: horizon must be > 0");
  if (!std::isfinite(config.drain_penalty)) throw std::invalid_argument("ceiling planner: drain penalty must be finite");
  if (config.step_budget < 0) throw std::invalid_argument("ceiling planner: step budget must be >= 0");
  candidates_.push_back({});  // don't fire
  for (int k = 0; k <= config.fire_frames; ++k) {
    for (const int h : config.hold_frames) candidates_.push_back({k, h, 0.0, 0.0, false, 0.0});
  }
  const auto horizon_steps = static_cast<std::uint64_t>(std::llround(config.horizon_s / stepper.dt_s()));
  max_branch_steps_ = std::max<std::uint64_t>(1, horizon_steps);
  if (config.step_budget > 0) {
    const auto share = static_cast<std::uint64_t>(config.step_budget) / candidates_.size();
    if (share < 1) throw std::invalid_argument("ceiling planner: step budget is less than one step per candidate");
    max_branch_steps_ = std::min(max_branch_steps_, share);
  }
  shot_y_m_ = shot_line_y_m(stepper.board(),
                            config.shot_values ? config.shot_values->exit_height_m : config.shot_exit_height_m);
}

namespace {

// Distance from the ball to the nearest flipper's rest segment, and which flipper.
std::pair<int, double> nearest_flipper(const table::Board& board, const sim::GameState& state) {
  return table::nearest_flipper_at_rest(board, state.ball.position_m);
}

}  // namespace

bool LookaheadPlanner::in_zone(const sim::GameState& state) const {
  const table::Board& board = stepper_.board();
  return state.ball_in_play && nearest_flipper(board, state).second <= config_.zone_factor * board.ball.radius_m;
}

int LookaheadPlanner::decision_flipper(const sim::GameState& state) const {
  if (!in_zone(state) || !(state.ball.velocity_mps.y() < -config_.falling_speed_mps)) return -1;
  return nearest_flipper(stepper_.board(), state).first;
}

const std::vector<LookaheadCandidate>& LookaheadPlanner::evaluate(const sim::GameState& state,
                                                              const simlab::DelayLine& delay, int flipper) {
  if (flipper < 0 || static_cast<std::size_t>(flipper) >= state.flippers.size()) {
    throw std::invalid_argument("ceiling planner: no flipper " + std::to_string(flipper));
  }
  origin_ = &state;
  origin_delay_ = &delay;
  for (LookaheadCandidate& c : candidates_) play_branch(c, flipper);
  return candidates_;
}

void LookaheadPlanner::play_branch(LookaheadCandidate& c, int flipper) {
  // Copy-assignment into the scratch objects reuses their storage.
  scratch_ = *origin_;
  scratch_delay_ = *origin_delay_;
  const double score0 = scratch_.score;
  const double t0 = scratch_.time_s;
  bool on = false;
  bool left_zone = false;
  int touched = -1;  // the bat the ball last touched
  c.lost = false;
  c.shot_flipper = -1;
  c.valued_by_table = false;
  for (std::uint64_t j = 0;; ++j) {
    // Same frame clock as the real player: commands change only at frame starts.
    if (j % static_cast<std::uint64_t>(config_.frame_steps) == 0) {
      const auto frame = static_cast<int>(j / static_cast<std::uint64_t>(config_.frame_steps));
      if (frame == c.fire_frame) on = true;
      if (c.fire_frame >= 0 && frame == c.fire_frame + c.hold_frames) on = false;
    }
    for (std::size_t i = 0; i < scratch_.flippers.size(); ++i) {
      scratch_.flippers[i].energized = on && static_cast<int>(i) == flipper;
    }
    scratch_delay_.apply(scratch_);
    const sim::StepEvents events = stepper_.step(scratch_);
    ++branch_steps_;
    if (events.has(sim::StepEvents::kBallLost)) {
      c.lost = true;
      break;
    }
    if (c.shot_flipper < 0) {
      if (const std::optional<Shot> shot = read_shot(scratch_, shot_y_m_, touched)) {
        c.shot_flipper = shot->flipper;
        c.shot_direction_deg = shot->direction_deg;
        c.shot_speed_mps = shot->speed_mps;
        c.score_at_shot = scratch_.score - score0;
        if (config_.shot_values) {
          const std::optional<double> after =
              shot_value(*config_.shot_values, shot->flipper, shot->direction_deg, shot->speed_mps);
          if (after) {
            c.valued_by_table = true;
            c.score = c.score_at_shot;
            c.value = c.score_at_shot + *after;
            c.length_s = scratch_.time_s - t0;
            return;
          }
        }
      }
    }
    if (j + 1 >= max_branch_steps_) break;  // the horizon or the budget's share
    if (!in_zone(scratch_)) {
      left_zone = true;
    } else if (left_zone && scratch_.ball.velocity_mps.y() < -config_.falling_speed_mps) {
      break;  // the next approach: its own decisions start here
    }
  }
  c.score = scratch_.score - score0;
  c.value = c.score - (c.lost ? config_.drain_penalty : 0.0);
  c.length_s = scratch_.time_s - t0;
}

std::size_t LookaheadPlanner::best() const {
  std::size_t b = 0;
  for (std::size_t i = 1; i < candidates_.size(); ++i) {
    if (candidates_[i].value > candidates_[b].value) b = i;
  }
  return b;
}

LookaheadPlayer::LookaheadPlayer(const sim::ThesisStepper& stepper, const LookaheadConfig& config,
                                 double actuation_delay_s)
    : planner_(stepper, config),
      delay_(stepper.board().flippers.size(), actuation_delay_s),
      command_(stepper.board().flippers.size(), false),
      frame_s_(stepper.dt_s() * config.frame_steps) {}

void LookaheadPlayer::act(sim::GameState& s) {
  const bool frame = step_ % static_cast<std::uint64_t>(planner_.config().frame_steps) == 0;
  ++step_;
  act(s, frame);
}

void LookaheadPlayer::act(sim::GameState& s, bool frame) {
  fired_ = -1;
  if (frame) decide(s);
  for (std::size_t i = 0; i < command_.size(); ++i) s.flippers[i].energized = command_[i];
  delay_.apply(s);
}

void LookaheadPlayer::decide(const sim::GameState& s) {
  if (held_ >= 0) {
    if (--release_in_ > 0) return;
    command_[static_cast<std::size_t>(held_)] = false;
    held_ = -1;
  }
  const int f = planner_.decision_flipper(s);
  if (f < 0) return;
  ++decisions_;
  const std::vector<LookaheadCandidate>& c = planner_.evaluate(s, delay_, f);
  const LookaheadCandidate& b = c[planner_.best()];
  if (b.fire_frame == 0) {
    command_[static_cast<std::size_t>(f)] = true;
    held_ = f;
    release_in_ = b.hold_frames;
    fired_ = f;
    fired_hold_s_ = b.hold_frames * frame_s_;
  }
}

}  // namespace pinball::learn
