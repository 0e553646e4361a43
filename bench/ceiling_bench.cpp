#include "ceiling_bench.h"

#include <chrono>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "pinball/learn/planning_controller.h"
#include "pinball/core/progress.h"
#include "pinball/core/rng.h"
#include "pinball/control/spastic_controller.h"
#include "pinball/learn/evaluator.h"
#include "pinball/learn/parallel_runner.h"
#include "pinball/learn/team.h"
#include "pinball/sim/ball_runner.h"
#include "pinball/sim/model_world.h"
#include "pinball/simlab/oracle_policy.h"
#include "pinball/track/trajectory_fit.h"

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
  DrainWatch observer(state, drain_zones(board));
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
        kind == CeilingPlayerKind::kController ? learn::make_controller(*options.controller, board)
                                               : std::make_unique<control::SpasticController>();
    if (kind == CeilingPlayerKind::kController) limits.pull = options.controller->launcher_pull;
    r = learn::play_through_tracker(world, board, state, options.camera,
                                    track::default_tracker_config(board, options.camera), *controller,
                                    options.actuation_delay_s, limits, ball_seed, observer);
  } else if (kind == CeilingPlayerKind::kControllerTrueState) {
    // The controller as the tracker would drive it, but every frame's fit is
    // the true ball (plus the feed's noise): no camera, no tracker.
    const std::unique_ptr<control::FlipperController> controller = learn::make_controller(*options.controller, board);
    limits.pull = options.controller->launcher_pull;
    const CeilingBenchOptions::TrueStateFeed feed = *options.true_state_feed;
    simlab::DelayLine delay(board.flippers.size(), options.actuation_delay_s);
    Rng noise(learn::camera_seed(ball_seed));
    const auto jitter = [&](double sd) { return Vec2(sd * noise.normal(), sd * noise.normal()); };
    const std::array<int, 2> board_index = table::flippers_by_side(board);  // controller flipper -> board flipper
    track::TrackerOutput seen;
    seen.window = 24;
    std::array<bool, 2> energized{false, false};
    std::uint64_t step = 0;
    r = sim::play_ball(
        world, state, limits,
        [&](sim::GameState& s) {
          if (step++ % static_cast<std::uint64_t>(options.planner.frame_steps) == 0) {
            seen.fit = track::exact_trajectory(s.ball.position_m + jitter(feed.position_noise_m),
                                               s.ball.velocity_mps + jitter(feed.velocity_noise_mps),
                                               board.gravity_mps2, s.time_s);
            seen.fit.valid = s.ball_in_play;
            controller->update(seen, s.time_s, energized);
          }
          for (std::size_t f = 0; f < 2; ++f)
            s.flippers[static_cast<std::size_t>(board_index[f])].energized = energized[f];
          delay.apply(s);
        },
        observer);
  } else {
    r = sim::play_ball(world, state, limits, [](sim::GameState&) {}, observer);
  }
  static_cast<PlayedBall&>(ball) = played_ball(r, observer);
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
    case CeilingPlayerKind::kControllerTrueState: return "controller_true_state";
  }
  return "?";
}

CeilingPlayerReport run_player(const sim::World& world, const sim::ThesisStepper& model,
                               const CeilingBenchOptions& options,
                               CeilingPlayerKind kind, const std::function<void(const std::string&)>& progress) {
  const auto n = static_cast<std::size_t>(options.balls);
  std::vector<CeilingBall> balls(n);
  const auto start = std::chrono::steady_clock::now();
  // Across the job (MPI ranks x threads); progress counts this rank's share.
  const int share = std::max(1, options.balls / learn::team_size());
  SharedProgress balls_done(share, share / 10, [&](long d, double elapsed_s) {
    // "ceiling: 40/200 balls (20 %), 12 s elapsed, ETA 48 s"
    if (progress) progress(format_progress(player_name(kind), d, share, "balls", elapsed_s));
  });
  const std::vector<learn::Blob> blobs = learn::distributed_map(n, options.threads, [&](std::size_t i) {
    const std::unique_ptr<sim::World> ball_world = world.fork();
    const CeilingBall ball = play_ceiling_bench_ball(*ball_world, model, options, kind, ball_seed(options.seed, i));
    balls_done.one_done();
    learn::BlobWriter w;
    put_played_ball(w, ball);
    w.put(ball.decisions).put(ball.branch_steps);
    return w.take();
  });
  for (std::size_t i = 0; i < n; ++i) {
    learn::BlobReader r(blobs[i]);
    get_played_ball(r, balls[i]);
    balls[i].decisions = r.get<int>();
    balls[i].branch_steps = r.get<std::uint64_t>();
    r.expect_end();
  }
  const DrainZones zones = drain_zones(model.board());
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
    r.drains.add(classify_drain(zones, b.drain_x_m), b.left_table);
  }
  if (n > 0) {
    r.decisions_per_ball = decisions / static_cast<double>(n);
    r.branch_steps_per_ball = branch_steps / static_cast<double>(n);
  }
  return r;
}

}  // namespace

CeilingReport run_ceiling_bench(const table::Board& board, const CeilingBenchOptions& options,
                                const std::function<void(const std::string&)>& progress, const sim::World* world) {
  if (options.balls < 1) throw std::invalid_argument("ceiling bench: balls must be >= 1");
  if (!(options.max_ball_time_s > 0.0)) throw std::invalid_argument("ceiling bench: max ball time must be > 0");
  // The feed is checked before any ball is played: the players before it take minutes.
  if (const auto& feed = options.true_state_feed) {
    if (options.controller == nullptr)
      throw std::invalid_argument("ceiling bench: the true-state feed needs a controller to feed");
    // The feed writes the tracker's fit, which a planner places its ball by; a shot
    // table or the spastic flipper acts on the projection, which the feed does not make,
    // and would play a ball without ever firing.
    if (!options.controller->planner)
      throw std::invalid_argument("ceiling bench: the true-state feed drives a planner file only (it gives the "
                                  "tracker's fit, not the projection a shot table or the spastic flipper acts on)");
    if (!(feed->position_noise_m >= 0.0 && feed->velocity_noise_mps >= 0.0))
      throw std::invalid_argument("ceiling bench: the true-state feed's noise must be >= 0");
  }
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
  if (options.true_state_feed) {
    report.controller_true_state =
        run_player(*world_prototype, model, options, CeilingPlayerKind::kControllerTrueState, progress);
  }
  const auto ratio = [](double a, double b) { return b != 0.0 ? a / b : 0.0; };
  report.ceiling_over_spastic = ratio(report.ceiling.score.mean(), report.spastic.score.mean());
  const double ts = report.tracker_spastic.score.mean();
  report.ceiling_over_tracker_spastic = ratio(report.ceiling.score.mean(), ts);
  if (report.controller) report.controller_over_tracker_spastic = ratio(report.controller->score.mean(), ts);
  if (report.controller_true_state)
    report.controller_true_state_over_tracker_spastic = ratio(report.controller_true_state->score.mean(), ts);
  return report;
}

}  // namespace pinball::bench
