#include "aim_bench.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <sstream>
#include <stdexcept>

#include "pinball/core/format.h"
#include "pinball/core/progress.h"
#include "pinball/core/rng.h"
#include "pinball/core/statistics.h"
#include "pinball/learn/shot_values.h"
#include "pinball/sim/ball_runner.h"
#include "pinball/sim/model_world.h"
#include "pinball/simlab/delay_line.h"

namespace pinball::bench {

std::optional<double> shot_direction_deg(const sim::ThesisStepper& stepper, sim::GameState state, int flipper,
                                         double hold_s, double actuation_delay_s, double exit_y_m,
                                         double shot_time_s) {
  simlab::DelayLine delay(state.flippers.size(), actuation_delay_s);
  const double t0 = state.time_s;
  int touched = -1;
  while (state.time_s - t0 < shot_time_s) {
    for (std::size_t i = 0; i < state.flippers.size(); ++i) {
      state.flippers[i].energized = static_cast<int>(i) == flipper && state.time_s - t0 < hold_s;
    }
    delay.apply(state);
    if (stepper.step(state).has(sim::StepEvents::kBallLost)) return std::nullopt;
    if (const std::optional<learn::Shot> shot = learn::read_shot(state, exit_y_m, touched)) return shot->direction_deg;
  }
  return std::nullopt;
}

namespace {

// The state before one of the ceiling player's fires, and what it fired.
struct Fire {
  sim::GameState before;
  int flipper = -1;
  double hold_s = 0.0;
};

// The share of `of` copies whose miss is at most `limit_deg` (a copy with no
// shot has no miss and is not counted in).
double share_within(const std::vector<double>& misses_deg, double limit_deg, std::size_t of) {
  if (of == 0) return 0.0;
  const auto n = std::count_if(misses_deg.begin(), misses_deg.end(), [&](double e) { return e <= limit_deg; });
  return static_cast<double>(n) / static_cast<double>(of);
}

void check_options(const AimBenchOptions& o) {
  if (o.balls < 1) throw std::invalid_argument("aim bench: balls must be >= 1");
  if (o.copies < 1) throw std::invalid_argument("aim bench: copies must be >= 1");
  if (!(o.max_ball_time_s > 0.0)) throw std::invalid_argument("aim bench: max ball time must be > 0");
  if (!(o.exit_height_m > 0.0) || !std::isfinite(o.exit_height_m))
    throw std::invalid_argument("aim bench: exit height must be > 0");
  if (!(o.shot_time_s > 0.0) || !std::isfinite(o.shot_time_s))
    throw std::invalid_argument("aim bench: shot time must be > 0");
  for (const StateNoise& n : o.noise) {
    if (!(n.position_m >= 0.0) || !(n.velocity_mps >= 0.0) || !std::isfinite(n.position_m) ||
        !std::isfinite(n.velocity_mps))
      throw std::invalid_argument("aim bench: noise must be finite and >= 0");
  }
}

}  // namespace

AimReport run_aim_bench(const table::Board& belief, const AimBenchOptions& options,
                        const std::function<void(const std::string&)>& progress) {
  check_options(options);
  const auto start = std::chrono::steady_clock::now();
  const auto elapsed_s = [&] { return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(); };
  const sim::ThesisStepper stepper(belief);
  const std::unique_ptr<sim::World> world = sim::make_model_world(belief);
  const double exit_y_m = learn::shot_line_y_m(belief, options.exit_height_m);

  std::vector<Fire> fires;
  sim::BallLimits limits;
  limits.max_ball_time_s = options.max_ball_time_s;
  for (int b = 0; b < options.balls; ++b) {
    sim::GameState state = sim::make_game_state(belief, ball_seed(options.seed, static_cast<std::uint64_t>(b)));
    learn::LookaheadPlayer player(stepper, options.planner, options.actuation_delay_s);
    sim::play_ball(
        *world, state, limits,
        [&](sim::GameState& s) {
          sim::GameState before = s;
          player.act(s);
          if (player.fired_flipper() >= 0) fires.push_back({std::move(before), player.fired_flipper(), player.fired_hold_s()});
        },
        [](const sim::GameState&, const sim::StepEvents&) {});
    if (progress) progress(format_progress("aim: ceiling balls", b + 1, options.balls, "balls", elapsed_s()));
  }

  AimReport report;
  report.options = options;
  report.fires = static_cast<int>(fires.size());
  std::vector<std::optional<double>> exact;
  exact.reserve(fires.size());
  for (const Fire& f : fires) {
    exact.push_back(shot_direction_deg(stepper, f.before, f.flipper, f.hold_s, options.actuation_delay_s, exit_y_m,
                                       options.shot_time_s));
    if (exact.back()) ++report.shots;
  }
  if (report.shots == 0) {
    // Every figure below is of shots: from none, a median of 0 deg would read as perfect aim.
    throw std::runtime_error("bench aim: no shot to measure in " + std::to_string(options.balls) + " balls (" +
                             std::to_string(report.fires) + " fires, balls cut at " +
                             format_number(options.max_ball_time_s) + " s); raise --balls or --max-ball-time");
  }
  // The baseline: each bat's shots against that bat's median direction.
  std::vector<std::vector<double>> by_bat(belief.flippers.size());
  for (std::size_t i = 0; i < fires.size(); ++i) {
    if (exact[i]) by_bat[static_cast<std::size_t>(fires[i].flipper)].push_back(*exact[i]);
  }
  std::vector<double> bat_only_errors_deg;
  for (const std::vector<double>& shots : by_bat) {
    const double centre = median(shots);
    for (const double d : shots) bat_only_errors_deg.push_back(std::abs(d - centre));
  }
  report.bat_only_median_error_deg = quantile(bat_only_errors_deg, 0.5);
  report.bat_only_within_10_deg = share_within(bat_only_errors_deg, 10.0, bat_only_errors_deg.size());

  Rng rng(ball_seed(options.seed, 0x61696d));  // "aim": its own stream, apart from the balls'
  for (const StateNoise& noise : options.noise) {
    AimNoiseResult r;
    r.noise = noise;
    std::vector<double> errors_deg;
    for (std::size_t i = 0; i < fires.size(); ++i) {
      if (!exact[i]) continue;
      for (int k = 0; k < options.copies; ++k) {
        sim::GameState copy = fires[i].before;
        copy.ball.position_m += Vec2(noise.position_m * rng.normal(), noise.position_m * rng.normal());
        copy.ball.velocity_mps += Vec2(noise.velocity_mps * rng.normal(), noise.velocity_mps * rng.normal());
        ++r.copies;
        const std::optional<double> d = shot_direction_deg(stepper, copy, fires[i].flipper, fires[i].hold_s,
                                                           options.actuation_delay_s, exit_y_m, options.shot_time_s);
        if (!d) {
          ++r.no_shot;
          continue;
        }
        errors_deg.push_back(std::abs(*d - *exact[i]));  // both upward, in (0°, 180°): no wrap
      }
    }
    r.median_error_deg = quantile(errors_deg, 0.5);
    r.p90_error_deg = quantile(errors_deg, 0.9);
    r.within_5_deg = share_within(errors_deg, 5.0, static_cast<std::size_t>(r.copies));
    r.within_10_deg = share_within(errors_deg, 10.0, static_cast<std::size_t>(r.copies));
    report.results.push_back(r);
  }
  report.wall_s = elapsed_s();
  return report;
}

nlohmann::json to_json(const AimReport& report) {
  const AimBenchOptions& o = report.options;
  nlohmann::json results = nlohmann::json::array();
  for (const AimNoiseResult& r : report.results) {
    results.push_back({{"position_noise_m", r.noise.position_m},
                       {"velocity_noise_mps", r.noise.velocity_mps},
                       {"copies", r.copies},
                       {"no_shot", r.no_shot},
                       {"median_error_deg", r.median_error_deg},
                       {"p90_error_deg", r.p90_error_deg},
                       {"within_5_deg", r.within_5_deg},
                       {"within_10_deg", r.within_10_deg}});
  }
  return {{"benchmark", "aim"},
          {"balls", o.balls},
          {"seed", o.seed},
          {"copies_per_fire", o.copies},
          {"max_ball_time_s", o.max_ball_time_s},
          {"actuation_delay_s", o.actuation_delay_s},
          {"exit_height_m", o.exit_height_m},
          {"shot_time_s", o.shot_time_s},
          {"planner_horizon_s", o.planner.horizon_s},
          {"fires", report.fires},
          {"shots", report.shots},
          {"bat_only_median_error_deg", report.bat_only_median_error_deg},
          {"bat_only_within_10_deg", report.bat_only_within_10_deg},
          {"results", results},
          {"wall_s", report.wall_s}};
}

std::string to_text(const AimReport& report) {
  const AimBenchOptions& o = report.options;
  std::ostringstream out;
  out << "the ceiling player's fires (" << format_number(o.planner.horizon_s) << " s planner, true state, "
      << o.balls << " balls, seed " << o.seed << "): " << report.fires << ", of which " << report.shots
      << " made a shot when replayed exactly; each replayed " << o.copies << " times from a noisy ball\n"
      << "a shot's direction: where it rises " << format_number(o.exit_height_m * 1e3)
      << " mm above the highest pivot, within " << format_number(o.shot_time_s) << " s\n"
      << "  baseline, knowing only which bat fires (its shots' median direction): median miss "
      << format_number(report.bat_only_median_error_deg) << " deg; within 10 deg "
      << format_number(100.0 * report.bat_only_within_10_deg) << " %\n";
  for (const AimNoiseResult& r : report.results) {
    out << "  noise " << format_number(r.noise.position_m * 1e3) << " mm, " << format_number(r.noise.velocity_mps * 1e3)
        << " mm/s: median miss " << format_number(r.median_error_deg) << " deg, p90 "
        << format_number(r.p90_error_deg) << " deg; within 5 deg " << format_number(100.0 * r.within_5_deg)
        << " %, within 10 deg " << format_number(100.0 * r.within_10_deg) << " %; no shot " << r.no_shot << " of "
        << r.copies << "\n";
  }
  return out.str();
}

}  // namespace pinball::bench
