#include "ceiling_bench.h"

#include <atomic>
#include <chrono>
#include <cmath>
#include <limits>
#include <mutex>
#include <sstream>
#include <stdexcept>

#include "pinball/control/spastic_controller.h"
#include "pinball/learn/evaluator.h"
#include "pinball/learn/parallel_runner.h"
#include "pinball/sim/ball_runner.h"
#include "pinball/sim/model_world.h"
#include "pinball/simlab/oracle_policy.h"

namespace pinball::bench {

CeilingBenchOptions quick_ceiling_bench_options() {
  CeilingBenchOptions o;
  o.balls = 10;
  return o;
}

CeilingBall play_ceiling_bench_ball(sim::World& world, const sim::ThesisStepper& model,
                                    const CeilingBenchOptions& options, CeilingPlayerKind kind,
                                    std::uint64_t ball_seed) {
  const table::Board& board = model.board();  // the belief: what the tracker and the planner assume
  sim::GameState state = sim::make_game_state(world.board(), ball_seed);
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
    learn::LookaheadPlayer player(model, options.planner, options.actuation_delay_s);
    r = sim::play_ball(world, state, limits, [&](sim::GameState& s) { player.act(s); }, observer);
    ball.decisions = player.decisions();
    ball.branch_steps = player.branch_steps();
  } else if (kind == CeilingPlayerKind::kSpastic) {
    simlab::DelayLine delay(board.flippers.size(), options.actuation_delay_s);
    r = sim::play_ball(
        world, state, limits,
        [&](sim::GameState& s) {
          simlab::oracle_spastic_policy(world.board(), s, options.spastic_reach_factor);
          delay.apply(s);
        },
        observer);
  } else if (kind == CeilingPlayerKind::kTrackerSpastic || kind == CeilingPlayerKind::kController) {
    // The evaluator's own loop and seeds: camera model, tracker, controller, actuation delay.
    const std::unique_ptr<control::FlipperController> controller =
        kind == CeilingPlayerKind::kController ? control::make_flipper_controller(*options.controller)
                                               : std::make_unique<control::SpasticController>();
    if (kind == CeilingPlayerKind::kController) limits.pull = options.controller->launcher_pull;
    r = learn::play_through_tracker(world, board, state, options.camera,
                                    track::default_tracker_config(board, options.camera), *controller,
                                    options.actuation_delay_s, limits, ball_seed, observer);
  } else {
    r = sim::play_ball(world, state, limits, [](sim::GameState&) {}, observer);
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
    case CeilingPlayerKind::kTrackerSpastic: return "tracker_spastic";
    case CeilingPlayerKind::kController: return "controller";
  }
  return "?";
}

CeilingPlayerReport run_player(const sim::World& world, const sim::ThesisStepper& model,
                               const CeilingBenchOptions& options,
                               CeilingPlayerKind kind, const std::function<void(const std::string&)>& progress) {
  const auto n = static_cast<std::size_t>(options.balls);
  std::vector<CeilingBall> balls(n);
  std::atomic<int> done{0};
  std::mutex progress_mutex;
  const int every = std::max(1, options.balls / 10);
  const auto start = std::chrono::steady_clock::now();
  learn::parallel_for(n, options.threads, [&](std::size_t i) {
    const std::unique_ptr<sim::World> ball_world = world.fork();
    balls[i] = play_ceiling_bench_ball(*ball_world, model, options, kind, ball_seed(options.seed, i));
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

CeilingReport run_ceiling_bench(const table::Board& board, const CeilingBenchOptions& options,
                                const std::function<void(const std::string&)>& progress, const sim::World* world) {
  if (options.balls < 1) throw std::invalid_argument("ceiling bench: balls must be >= 1");
  if (!(options.max_ball_time_s > 0.0)) throw std::invalid_argument("ceiling bench: max ball time must be > 0");
  const sim::ThesisStepper model(board);
  const std::unique_ptr<sim::World> world_prototype = world != nullptr ? world->fork() : sim::make_model_world(board);
  sim::check_same_flippers(world_prototype->board(), board);
  CeilingReport report;
  report.board = board.source;
  report.world_board = world_prototype->board().source;
  report.world = std::string(world_prototype->name());
  report.options = options;
  report.ceiling = run_player(*world_prototype, model, options, CeilingPlayerKind::kCeiling, progress);
  report.spastic = run_player(*world_prototype, model, options, CeilingPlayerKind::kSpastic, progress);
  report.no_flipping = run_player(*world_prototype, model, options, CeilingPlayerKind::kNoFlipping, progress);
  report.tracker_spastic = run_player(*world_prototype, model, options, CeilingPlayerKind::kTrackerSpastic, progress);
  if (options.controller != nullptr) {
    report.controller = run_player(*world_prototype, model, options, CeilingPlayerKind::kController, progress);
  }
  const auto ratio = [](double a, double b) { return b != 0.0 ? a / b : 0.0; };
  report.ceiling_over_spastic = ratio(report.ceiling.score.mean(), report.spastic.score.mean());
  const double ts = report.tracker_spastic.score.mean();
  report.ceiling_over_tracker_spastic = ratio(report.ceiling.score.mean(), ts);
  if (report.controller) report.controller_over_tracker_spastic = ratio(report.controller->score.mean(), ts);
  return report;
}

nlohmann::json to_json(const CeilingReport& r) {
  const CeilingBenchOptions& o = r.options;
  const learn::LookaheadConfig& p = o.planner;
  nlohmann::json players = {{"ceiling", player_json(r.ceiling)},
                            {"spastic", player_json(r.spastic)},
                            {"no_flipping", player_json(r.no_flipping)},
                            {"tracker_spastic", player_json(r.tracker_spastic)}};
  if (r.controller) players["controller"] = player_json(*r.controller);
  return {{"benchmark", "ceiling"},
          {"board", r.board},
          {"world_board", r.world_board},
          {"world", r.world},
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
          {"players", players},
          {"controller", o.controller_name},
          {"ceiling_over_spastic", r.ceiling_over_spastic},
          {"ceiling_over_tracker_spastic", r.ceiling_over_tracker_spastic},
          {"controller_over_tracker_spastic", r.controller_over_tracker_spastic}};
}

std::string to_text(const CeilingReport& r) {
  std::ostringstream out;
  const CeilingBenchOptions& o = r.options;
  out << "ceiling reference on " << r.board << " (world: " << r.world_board << " on the " << r.world
      << " stepper): " << o.balls << " balls per player (seed " << o.seed
      << "), cut at " << o.max_ball_time_s << " s, actuation delay " << o.actuation_delay_s * 1e3 << " ms\n"
      << "the ceiling player CHEATS (true state, lookahead with the true simulator): a reference, not a "
         "controller\n";
  std::vector<const CeilingPlayerReport*> players = {&r.ceiling, &r.spastic, &r.no_flipping, &r.tracker_spastic};
  if (r.controller) players.push_back(&*r.controller);
  for (const CeilingPlayerReport* p : players) {
    out << "  " << p->name << ": " << p->score.mean() << " +- " << p->score.ci95_half_width()
        << " per ball (95 %), " << p->duration_s.mean() << " s per ball, " << p->flips.mean()
        << " flips per ball, " << p->cut << " cut; drains: left outlane " << p->drains_left_outlane << ", elsewhere "
        << p->drains_elsewhere << "; wall " << p->wall_s << " s\n";
  }
  out << "  ceiling planning: " << r.ceiling.decisions_per_ball << " decisions, " << r.ceiling.branch_steps_per_ball
      << " lookahead steps per ball\n"
      << "ceiling / spastic: " << r.ceiling_over_spastic << "x; ceiling / spastic through the tracker: "
      << r.ceiling_over_tracker_spastic << "x\n";
  if (r.controller) {
    out << "controller (" << o.controller_name << ") / spastic through the tracker: " << r.controller_over_tracker_spastic
        << "x\n";
  }
  return out.str();
}

}  // namespace pinball::bench
