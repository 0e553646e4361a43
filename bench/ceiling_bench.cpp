#include "ceiling_bench.h"

#include <atomic>
#include <chrono>
#include <cmath>
#include <limits>
#include <mutex>
#include <sstream>
#include <stdexcept>

#include "pinball/learn/evaluator.h"
#include "pinball/learn/parallel_runner.h"
#include "pinball/sim/ball_runner.h"
#include "pinball/sim/oracle_policy.h"

namespace pinball::bench {

CeilingBenchOptions quick_ceiling_bench_options() {
  CeilingBenchOptions o;
  o.balls = 10;
  return o;
}

CeilingPlanner::CeilingPlanner(const sim::ThesisStepper& stepper, const CeilingPlannerConfig& config)
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
  candidates_.push_back({});  // don't fire
  for (int k = 0; k <= config.fire_frames; ++k) {
    for (const int h : config.hold_frames) candidates_.push_back({k, h, 0.0, 0.0, false, 0.0});
  }
}

namespace {

// Distance from the ball to the nearest flipper's rest segment, and which flipper.
std::pair<int, double> nearest_flipper(const sim::Board& board, const sim::GameState& state) {
  int nearest = -1;
  double nearest_d = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < board.flippers.size(); ++i) {
    const sim::Flipper& f = board.flippers[i];
    const double d = distance_point_segment(state.ball.position_m, f.pivot, sim::flipper_tip(f, f.theta_min_rad));
    if (d < nearest_d) {
      nearest_d = d;
      nearest = static_cast<int>(i);
    }
  }
  return {nearest, nearest_d};
}

}  // namespace

bool CeilingPlanner::in_zone(const sim::GameState& state) const {
  const sim::Board& board = stepper_.board();
  return state.ball_in_play && nearest_flipper(board, state).second <= config_.zone_factor * board.ball.radius_m;
}

int CeilingPlanner::decision_flipper(const sim::GameState& state) const {
  if (!in_zone(state) || !(state.ball.velocity_mps.y() < -config_.falling_speed_mps)) return -1;
  return nearest_flipper(stepper_.board(), state).first;
}

const std::vector<CeilingCandidate>& CeilingPlanner::evaluate(const sim::GameState& state,
                                                              const learn::DelayLine& delay, int flipper) {
  if (flipper < 0 || static_cast<std::size_t>(flipper) >= state.flippers.size()) {
    throw std::invalid_argument("ceiling planner: no flipper " + std::to_string(flipper));
  }
  origin_ = &state;
  origin_delay_ = &delay;
  for (CeilingCandidate& c : candidates_) play_branch(c, flipper);
  return candidates_;
}

void CeilingPlanner::play_branch(CeilingCandidate& c, int flipper) {
  // Copy-assignment into the scratch objects reuses their storage.
  scratch_ = *origin_;
  scratch_delay_ = *origin_delay_;
  const double score0 = scratch_.score;
  const double t0 = scratch_.time_s;
  const double dt = stepper_.dt_s();
  bool on = false;
  bool left_zone = false;
  c.lost = false;
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
    if (scratch_.time_s - t0 >= config_.horizon_s - 0.5 * dt) break;
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

std::size_t CeilingPlanner::best() const {
  std::size_t b = 0;
  for (std::size_t i = 1; i < candidates_.size(); ++i) {
    if (candidates_[i].value > candidates_[b].value) b = i;
  }
  return b;
}

namespace {

// The cheating player: plans every frame while no flip is under way (see the header).
class CeilingPlayer {
 public:
  CeilingPlayer(const sim::ThesisStepper& stepper, const CeilingBenchOptions& o)
      : planner_(stepper, o.planner),
        delay_(stepper.board().flippers.size(), o.actuation_delay_s),
        command_(stepper.board().flippers.size(), false) {}

  void act(sim::GameState& s) {
    if (step_ % static_cast<std::uint64_t>(planner_.config().frame_steps) == 0) decide(s);
    ++step_;
    for (std::size_t i = 0; i < command_.size(); ++i) s.flippers[i].energized = command_[i];
    delay_.apply(s);
  }
  int decisions() const { return decisions_; }
  std::uint64_t branch_steps() const { return planner_.branch_steps(); }

 private:
  void decide(const sim::GameState& s) {
    if (held_ >= 0) {
      if (--release_in_ > 0) return;
      command_[static_cast<std::size_t>(held_)] = false;
      held_ = -1;
    }
    const int f = planner_.decision_flipper(s);
    if (f < 0) return;
    ++decisions_;
    const std::vector<CeilingCandidate>& c = planner_.evaluate(s, delay_, f);
    const CeilingCandidate& b = c[planner_.best()];
    if (b.fire_frame == 0) {
      command_[static_cast<std::size_t>(f)] = true;
      held_ = f;
      release_in_ = b.hold_frames;
    }
  }

  CeilingPlanner planner_;
  learn::DelayLine delay_;
  std::vector<bool> command_;
  std::uint64_t step_ = 0;
  int held_ = -1;
  int release_in_ = 0;
  int decisions_ = 0;
};

}  // namespace

CeilingBall play_ceiling_bench_ball(const sim::ThesisStepper& stepper, const CeilingBenchOptions& options,
                                    CeilingPlayerKind kind, std::uint64_t ball_seed) {
  const sim::Board& board = stepper.board();
  sim::GameState state = sim::make_game_state(board, ball_seed);
  sim::BallLimits limits;
  limits.max_ball_time_s = options.max_ball_time_s;
  limits.pull = options.pull;
  CeilingBall ball;
  double last_x = state.ball.position_m.x();
  auto observer = [&](const sim::GameState& s, const sim::StepEvents& e) {
    // A lost ball is moved back to the launcher: keep where it was a step before.
    if (e.has(sim::StepEvents::kBallLost)) {
      ball.drain_x_m = last_x;
    } else {
      last_x = s.ball.position_m.x();
    }
  };
  sim::BallResult r;
  if (kind == CeilingPlayerKind::kCeiling) {
    CeilingPlayer player(stepper, options);
    r = sim::play_ball(stepper, state, limits, [&](sim::GameState& s) { player.act(s); }, observer);
    ball.decisions = player.decisions();
    ball.branch_steps = player.branch_steps();
  } else if (kind == CeilingPlayerKind::kSpastic) {
    learn::DelayLine delay(board.flippers.size(), options.actuation_delay_s);
    r = sim::play_ball(
        stepper, state, limits,
        [&](sim::GameState& s) {
          sim::oracle_spastic_policy(board, s, options.spastic_reach_factor);
          delay.apply(s);
        },
        observer);
  } else {
    r = sim::play_ball(stepper, state, limits, [](sim::GameState&) {}, observer);
  }
  ball.score = r.score;
  ball.duration_s = r.duration_s;
  ball.flips = r.flips;
  ball.cut = r.cut;
  ball.left_table = r.left_table;
  return ball;
}

namespace {

const char* player_name(CeilingPlayerKind kind) {
  switch (kind) {
    case CeilingPlayerKind::kCeiling: return "ceiling";
    case CeilingPlayerKind::kSpastic: return "spastic";
    case CeilingPlayerKind::kNoFlipping: return "no_flipping";
  }
  return "?";
}

CeilingPlayerReport run_player(const sim::ThesisStepper& stepper, const CeilingBenchOptions& options,
                               CeilingPlayerKind kind, const std::function<void(const std::string&)>& progress) {
  const auto n = static_cast<std::size_t>(options.balls);
  std::vector<CeilingBall> balls(n);
  std::atomic<int> done{0};
  std::mutex progress_mutex;
  const int every = std::max(1, options.balls / 10);
  const auto start = std::chrono::steady_clock::now();
  learn::parallel_for(n, options.threads, [&](std::size_t i) {
    balls[i] = play_ceiling_bench_ball(stepper, options, kind, learn::ball_seed(options.seed, i));
    const int d = ++done;
    if (progress && (d % every == 0 || d == options.balls)) {
      const std::lock_guard<std::mutex> lock(progress_mutex);
      progress(std::string(player_name(kind)) + ": " + std::to_string(d) + "/" + std::to_string(options.balls) +
               " balls");
    }
  });
  CeilingPlayerReport r;
  r.name = player_name(kind);
  r.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  double decisions = 0.0;
  double branch_steps = 0.0;
  for (const CeilingBall& b : balls) {
    r.score.add(b.score);
    r.duration_s.add(b.duration_s);
    r.flips.add(b.flips);
    decisions += b.decisions;
    branch_steps += static_cast<double>(b.branch_steps);
    if (b.cut) {
      ++r.cut;
      continue;
    }
    if (b.left_table) ++r.left_table;
    if (b.drain_x_m < options.left_outlane_x_m) {
      ++r.drains_left_outlane;
    } else {
      ++r.drains_elsewhere;
    }
  }
  if (n > 0) {
    r.decisions_per_ball = decisions / static_cast<double>(n);
    r.branch_steps_per_ball = branch_steps / static_cast<double>(n);
  }
  return r;
}

nlohmann::json player_json(const CeilingPlayerReport& r) {
  return {{"mean_score_per_ball", r.score.mean()},
          {"score_ci95_half_width", r.score.ci95_half_width()},
          {"score_stddev", r.score.stddev()},
          {"mean_ball_time_s", r.duration_s.mean()},
          {"flips_per_ball", r.flips.mean()},
          {"balls_cut_at_time_limit", r.cut},
          {"drains_left_outlane", r.drains_left_outlane},
          {"drains_elsewhere", r.drains_elsewhere},
          {"drains_left_table", r.left_table},
          {"decisions_per_ball", r.decisions_per_ball},
          {"branch_steps_per_ball", r.branch_steps_per_ball},
          {"wall_s", r.wall_s}};
}

}  // namespace

CeilingReport run_ceiling_bench(const sim::Board& board, const CeilingBenchOptions& options,
                                const std::function<void(const std::string&)>& progress) {
  if (options.balls < 1) throw std::invalid_argument("ceiling bench: balls must be >= 1");
  if (!(options.max_ball_time_s > 0.0)) throw std::invalid_argument("ceiling bench: max ball time must be > 0");
  const sim::ThesisStepper stepper(board);
  CeilingReport report;
  report.board = board.source;
  report.options = options;
  report.ceiling = run_player(stepper, options, CeilingPlayerKind::kCeiling, progress);
  report.spastic = run_player(stepper, options, CeilingPlayerKind::kSpastic, progress);
  report.no_flipping = run_player(stepper, options, CeilingPlayerKind::kNoFlipping, progress);
  const double s = report.spastic.score.mean();
  report.ceiling_over_spastic = s != 0.0 ? report.ceiling.score.mean() / s : 0.0;
  return report;
}

nlohmann::json to_json(const CeilingReport& r) {
  const CeilingBenchOptions& o = r.options;
  const CeilingPlannerConfig& p = o.planner;
  return {{"benchmark", "ceiling"},
          {"board", r.board},
          {"balls", o.balls},
          {"seed", o.seed},
          {"threads", o.threads},
          {"max_ball_time_s", o.max_ball_time_s},
          {"actuation_delay_s", o.actuation_delay_s},
          {"pull", o.pull},
          {"spastic_reach_factor", o.spastic_reach_factor},
          {"left_outlane_x_m", o.left_outlane_x_m},
          {"planner",
           {{"frame_steps", p.frame_steps},
            {"fire_frames", p.fire_frames},
            {"hold_frames", p.hold_frames},
            {"zone_factor", p.zone_factor},
            {"horizon_s", p.horizon_s},
            {"drain_penalty", p.drain_penalty}}},
          {"players",
           {{"ceiling", player_json(r.ceiling)},
            {"spastic", player_json(r.spastic)},
            {"no_flipping", player_json(r.no_flipping)}}},
          {"ceiling_over_spastic", r.ceiling_over_spastic}};
}

std::string to_text(const CeilingReport& r) {
  std::ostringstream out;
  const CeilingBenchOptions& o = r.options;
  out << "ceiling reference on " << r.board << ": " << o.balls << " balls per player (seed " << o.seed
      << "), cut at " << o.max_ball_time_s << " s, actuation delay " << o.actuation_delay_s * 1e3 << " ms\n"
      << "the ceiling player CHEATS (true state, lookahead with the true simulator): a reference, not a "
         "controller\n";
  for (const CeilingPlayerReport* p : {&r.ceiling, &r.spastic, &r.no_flipping}) {
    out << "  " << p->name << ": " << p->score.mean() << " +- " << p->score.ci95_half_width()
        << " per ball (95 %), " << p->duration_s.mean() << " s per ball, " << p->flips.mean()
        << " flips per ball, " << p->cut << " cut; drains: left outlane " << p->drains_left_outlane << ", elsewhere "
        << p->drains_elsewhere << "; wall " << p->wall_s << " s\n";
  }
  out << "  ceiling planning: " << r.ceiling.decisions_per_ball << " decisions, " << r.ceiling.branch_steps_per_ball
      << " lookahead steps per ball\n"
      << "ceiling / spastic: " << r.ceiling_over_spastic << "x\n";
  return out.str();
}

}  // namespace pinball::bench
