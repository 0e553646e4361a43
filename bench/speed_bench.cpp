#include "speed_bench.h"

#include <algorithm>
#include <chrono>
#include <sstream>

#include "staged_progress.h"
#include "pinball/sim/ball_runner.h"
#include "pinball/sim/model_world.h"
#include "pinball/simlab/oracle_policy.h"
#include "pinball/simlab/world_factory.h"
#include "pinball/sim/state_hash.h"
#include "pinball/sim/thesis_stepper.h"

namespace pinball::bench {

table::Board with_far_obstacles(const table::Board& board, int copies) {
  table::Board crowded = board;
  const double stride_m = board.width_m + 0.5;  // well beyond the ball's reach
  const std::size_t n = board.shapes.size();
  crowded.shapes.reserve(n * (copies + 1));
  crowded.obstacles.reserve(n * (copies + 1));
  for (int k = 1; k <= copies; ++k) {
    const Vec2 shift{k * stride_m, 0.0};
    for (std::size_t i = 0; i < n; ++i) {
      table::Shape s = board.shapes[i];
      s.p0 += shift;
      s.p1 += shift;
      table::Obstacle o = board.obstacles[i];
      o.bank = -1;
      o.name += "+far" + std::to_string(k);
      crowded.shapes.push_back(s);
      crowded.obstacles.push_back(o);
    }
  }
  return crowded;
}

namespace {

struct Timed {
  double seconds = 0.0;
  double mean_candidates = 0.0;
  std::uint64_t hash = 0;
  std::uint64_t steps = 0;
};

// Plays balls with the spastic policy until `steps` steps have run.
// `stepper` is the world's own stepper, asked only for its candidate counts.
Timed run_once(sim::World& world, const sim::ThesisStepper& stepper, std::uint64_t steps, std::uint64_t seed) {
  const table::Board& board = stepper.board();
  sim::GameState state = sim::make_game_state(board, seed);
  sim::BallLimits limits;
  limits.max_ball_time_s = 60.0;
  std::uint64_t candidates = 0;
  const auto start = std::chrono::steady_clock::now();
  while (state.steps < steps) {
    sim::play_ball(world, state, limits,
                   [&](sim::GameState& s) { simlab::oracle_spastic_policy(board, s); },
                   [&](const sim::GameState&, const sim::StepEvents&) {});
  }
  const auto stop = std::chrono::steady_clock::now();
  // Candidate counts come from a second, untimed pass so they cost nothing above.
  sim::GameState replay = sim::make_game_state(board, seed);
  while (replay.steps < std::min<std::uint64_t>(steps, 200'000)) {
    sim::play_ball(world, replay, limits,
                   [&](sim::GameState& s) { simlab::oracle_spastic_policy(board, s); },
                   [&](const sim::GameState& s, const sim::StepEvents& e) {
                     if (e.has(sim::StepEvents::kLaunch)) return;  // not a step
                     candidates += stepper.obstacle_candidates(s.ball.position_m).size();
                   });
  }
  Timed t;
  t.seconds = std::chrono::duration<double>(stop - start).count();
  t.mean_candidates = static_cast<double>(candidates) / static_cast<double>(std::max<std::uint64_t>(replay.steps, 1));
  t.hash = sim::hash_state(state);
  t.steps = state.steps;
  return t;
}

SpeedRun measure(const std::string& name, const table::Board& board, bool use_grid, const SpeedBenchOptions& options,
                 const std::function<void(const std::string&)>& progress) {
  sim::ModelWorldOptions wo;
  wo.thesis.use_grid = use_grid;
  const std::unique_ptr<sim::World> world = sim::make_model_world(board, wo);
  const sim::ThesisStepper stepper(board, wo.thesis);
  std::vector<double> times;
  SpeedRun run;
  run.name = name;
  run.use_grid = use_grid;
  run.obstacles = board.shapes.size();
  for (int i = 0; i < std::max(1, options.repeats); ++i) {
    const Timed t = run_once(*world, stepper, options.steps, options.seed);
    times.push_back(t.seconds);
    run.mean_candidates = t.mean_candidates;
    run.final_hash = t.hash;
    run.steps = t.steps;  // play_ball finishes its ball, so a run may pass `steps` a little
  }
  std::sort(times.begin(), times.end());
  run.median_s = times[times.size() / 2];
  run.steps_per_s = static_cast<double>(run.steps) / run.median_s;
  if (progress) {
    std::ostringstream line;
    line << name << ": " << run.steps << " steps, median " << run.median_s << " s, " << run.steps_per_s
         << " steps/s";
    progress(line.str());
  }
  return run;
}

// A world (the event stepper, the twin): the same play, timed the same way.
EventSpeedRun measure_world(const std::string& name, sim::World& world, std::uint64_t steps,
                            const SpeedBenchOptions& options, const std::function<void(const std::string&)>& progress) {
  const table::Board& board = world.board();
  sim::BallLimits limits;
  limits.max_ball_time_s = 60.0;
  std::vector<double> times;
  EventSpeedRun run;
  run.name = name;
  run.obstacles = board.shapes.size();
  for (int i = 0; i < std::max(1, options.repeats); ++i) {
    sim::GameState state = sim::make_game_state(board, options.seed);
    const auto start = std::chrono::steady_clock::now();
    while (state.steps < steps) {
      sim::play_ball(world, state, limits, [&](sim::GameState& s) { simlab::oracle_spastic_policy(board, s); },
                     [&](const sim::GameState&, const sim::StepEvents&) {});
    }
    times.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
    run.steps = state.steps;
    run.events = state.events;
    run.simulated_s = state.time_s;
  }
  std::sort(times.begin(), times.end());
  run.median_s = times[times.size() / 2];
  run.events_per_s = static_cast<double>(run.events) / run.median_s;
  run.steps_per_s = static_cast<double>(run.steps) / run.median_s;
  run.sim_s_per_wall_s = run.simulated_s / run.median_s;
  if (progress) {
    std::ostringstream line;
    line << name << ": " << run.events << " events in " << run.simulated_s << " s simulated, median " << run.median_s
         << " s, " << run.events_per_s << " events/s, " << run.sim_s_per_wall_s << " simulated s per wall s";
    progress(line.str());
  }
  return run;
}

}  // namespace

SpeedReport run_speed_bench(const table::Board& board, const SpeedBenchOptions& options,
                            const std::function<void(const std::string&)>& report_line) {
  // Six timed configurations: each line says how far the bench is and its ETA.
  const auto progress = staged_progress(report_line, "speed", 7, "runs");
  SpeedReport report;
  report.board = board.source;
  report.dt_s = board.dt_s;
  const table::Board crowded = with_far_obstacles(board, options.crowd_factor);
  report.runs.push_back(measure("grid", board, true, options, progress));
  report.runs.push_back(measure("linear", board, false, options, progress));
  report.runs.push_back(measure("grid_crowded", crowded, true, options, progress));
  report.runs.push_back(measure("linear_crowded", crowded, false, options, progress));
  const SpeedRun& grid = report.runs[0];
  const SpeedRun& linear = report.runs[1];
  const SpeedRun& grid_crowded = report.runs[2];
  report.grid_speedup = grid.steps_per_s / linear.steps_per_s;
  report.crowded_cost_ratio = (grid_crowded.median_s / static_cast<double>(grid_crowded.steps)) /
                              (grid.median_s / static_cast<double>(grid.steps));
  report.grid_matches_linear = grid.final_hash == linear.final_hash && grid.steps == linear.steps;
  sim::ModelWorldOptions event_options;
  event_options.stepper = sim::StepperKind::kEvent;
  report.event_runs.push_back(
      measure_world("event", *sim::make_model_world(board, event_options), options.steps, options, progress));
  report.event_runs.push_back(
      measure_world("event_crowded", *sim::make_model_world(crowded, event_options), options.steps, options, progress));
  const EventSpeedRun& event = report.event_runs[0];
  const EventSpeedRun& event_crowded = report.event_runs[1];
  report.event_crowded_cost_ratio =
      (event_crowded.median_s / event_crowded.simulated_s) / (event.median_s / event.simulated_s);
  report.thesis_sim_s_per_wall_s = static_cast<double>(grid.steps) * board.dt_s / grid.median_s;
  if (simlab::twin_available()) {
    simlab::WorldSpec twin;
    twin.kind = simlab::WorldKind::kTwin;
    const simlab::OwnedWorld world = simlab::make_world(twin, board);
    report.event_runs.push_back(measure_world("twin", *world, options.twin_steps, options, progress));
  } else {
    report.twin_skipped = "this build has no MuJoCo twin (libmujoco-dev)";
    progress("twin: skipped, " + report.twin_skipped);
  }
  return report;
}

nlohmann::json to_json(const SpeedReport& report) {
  nlohmann::json runs = nlohmann::json::array();
  for (const SpeedRun& r : report.runs) {
    runs.push_back({{"name", r.name},
                    {"use_grid", r.use_grid},
                    {"obstacles", r.obstacles},
                    {"steps", r.steps},
                    {"median_s", r.median_s},
                    {"steps_per_s", r.steps_per_s},
                    {"mean_candidates_per_step", r.mean_candidates}});
  }
  nlohmann::json event_runs = nlohmann::json::array();
  for (const EventSpeedRun& r : report.event_runs) {
    event_runs.push_back({{"name", r.name},
                          {"obstacles", r.obstacles},
                          {"steps", r.steps},
                          {"events", r.events},
                          {"simulated_s", r.simulated_s},
                          {"median_s", r.median_s},
                          {"events_per_s", r.events_per_s},
                          {"steps_per_s", r.steps_per_s},
                          {"sim_s_per_wall_s", r.sim_s_per_wall_s}});
  }
  return {{"benchmark", "speed"},
          {"board", report.board},
          {"dt_s", report.dt_s},
          {"runs", runs},
          {"grid_speedup", report.grid_speedup},
          {"crowded_cost_ratio", report.crowded_cost_ratio},
          {"grid_matches_linear", report.grid_matches_linear},
          {"event_runs", event_runs},
          {"event_crowded_cost_ratio", report.event_crowded_cost_ratio},
          {"thesis_sim_s_per_wall_s", report.thesis_sim_s_per_wall_s},
          {"twin_skipped", report.twin_skipped}};
}

}  // namespace pinball::bench
