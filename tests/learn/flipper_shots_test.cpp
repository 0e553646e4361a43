#include "pinball/learn/flipper_shots.h"

#include <cmath>

#include <gtest/gtest.h>

#include "pinball/core/data_path.h"
#include "pinball/core/rng.h"
#include "pinball/learn/free_flight.h"
#include "pinball/sim/game_state.h"
#include "pinball/sim/model_world.h"
#include "pinball/table/board_loader.h"

namespace pinball::learn {
namespace {

constexpr double kFrame_s = 0.005;
constexpr double kSigma_m = 0.0003;

table::Board flipper_scene() { return table::load_board(find_data_file("boards/scenes/flipper.board")); }

// Balls dropped onto the scene's one flipper in the thesis model, which the
// coil raises `rise_delay_s` after each recorded command (the recording's
// clock sees the command, the world the bat's motion), fired at varied
// moments so the bat meets the balls all along its stroke.
bus::RecordedPlay record_shots(const table::Board& board, double rise_delay_s, int shots, std::uint64_t seed) {
  const auto world = sim::make_model_world(board);
  const table::Flipper& f = board.flippers[0];
  Rng rng(seed);
  bus::RecordedPlay play;
  play.source = "flipper shots";
  const auto steps_per_frame = static_cast<int>(std::lround(kFrame_s / world->dt_s()));
  double t0 = 1.0;
  std::int64_t seq = 0;
  for (int i = 0; i < shots; ++i) {
    sim::GameState state = sim::make_game_state(board, seed + i);
    const double arm = 0.03 + 0.04 * rng.uniform01();
    const Vec2 above = f.pivot + arm * Vec2(std::cos(f.theta_max_rad), std::sin(f.theta_max_rad));
    state.ball.position_m = above + Vec2(0.0, board.ball.radius_m + 0.06);
    state.ball.velocity_mps = Vec2(0.0, -0.6);
    state.ball_in_play = true;
    const double fire_s = 0.06 + 0.1 * rng.uniform01();  // from the drop: early fires meet the ball high
    play.commands.push_back({t0 + fire_s - rise_delay_s, 0, true, 0});
    bool fired = false;
    for (double t = 0.0; t < 0.3; t += kFrame_s) {
      for (int k = 0; k < steps_per_frame; ++k) {
        if (!fired && t + k * world->dt_s() >= fire_s) state.flippers[0].energized = fired = true;
        world->step(state);
      }
      const Vec2 seen = state.ball.position_m + kSigma_m * Vec2(rng.normal(), rng.normal());
      play.frames.push_back({t0 + t + kFrame_s, seq++, true, seen, state.flippers[0].ball_contact, false});
    }
    play.commands.push_back({t0 + 0.35, 0, false, 0});
    t0 += 0.6;
  }
  return play;
}

TEST(FlipperShots, RecoverTheModelsRiseDelayStrokeSpeedAndMu) {
  const table::Board board = flipper_scene();
  const double rise_delay_s = 0.012;
  const std::vector<bus::RecordedPlay> plays{record_shots(board, rise_delay_s, 60, 3)};
  FlightOptions flight_options;
  flight_options.sigma_m = kSigma_m;
  const std::vector<FreeFlight> flights = find_free_flights(plays[0], 0, board, flight_options);
  const std::vector<FlipperShot> shots = find_flipper_shots(board, plays, flights);
  ASSERT_GE(shots.size(), 20u) << flights.size() << " flights";
  double lowest = INFINITY, highest = 0.0;
  for (const FlipperShot& s : shots) {
    EXPECT_EQ(s.flipper, 0);
    lowest = std::min(lowest, s.stroke_rad);
    highest = std::max(highest, s.stroke_rad);
  }
  EXPECT_GT(highest - lowest, 0.3) << "the bat met the balls along its stroke";

  const table::Flipper& f = board.flippers[0];
  const FlipperStrokeFit fit = fit_flipper_stroke(board, 0, shots, 0.0);
  ASSERT_TRUE(fit.identified) << fit.why_not;
  EXPECT_NEAR(fit.rise_delay_s.value, rise_delay_s, 0.0015);
  EXPECT_NEAR(fit.omega_rad_s.value, f.omega_rad_s, 0.1 * f.omega_rad_s);
  ASSERT_TRUE(fit.mu.has_value());
  EXPECT_NEAR(fit.mu->value, f.mu, 0.1 * f.mu);
  EXPECT_LT(std::abs(fit.mu->value - f.mu), 3.0 * fit.mu->stderr_);
  EXPECT_LT(fit.velocity_error_fitted_mps, 0.5 * fit.velocity_error_nominal_mps)
      << "the replayed shots leave as the recorded ones do once the delay is known";
  EXPECT_TRUE(fit.stroke_replays_better() || fit.velocity_error_fitted_mps < 1.5 * fit.velocity_error_delay_only_mps)
      << "the board is the model: its own stroke replays as well as the fitted one";
  // The uncertainties say how far the values may be off.
  EXPECT_LT(std::abs(fit.rise_delay_s.value - rise_delay_s), 5.0 * fit.rise_delay_s.stderr_ + 0.0005);
  EXPECT_GT(fit.timing_rms_nominal_s, 0.01) << "the board's zero delay misses every contact by 12 ms";
  EXPECT_LT(fit.timing_rms_fitted_s, 0.002);
}

TEST(FlipperShots, ABatAlreadyUpOrNoCommandGivesNoShot) {
  const table::Board board = flipper_scene();
  std::vector<bus::RecordedPlay> plays{record_shots(board, 0.01, 20, 5)};
  // Every energize stamped 0.2 s early: too soon after the last release, and too long before the contact.
  bus::RecordedPlay late = plays[0];
  for (std::size_t i = 0; i + 1 < late.commands.size(); i += 2) late.commands[i].t_s = late.commands[i].t_s - 0.2;
  std::vector<bus::RecordedPlay> no_commands{plays[0]};
  no_commands[0].commands.clear();
  FlightOptions flight_options;
  flight_options.sigma_m = kSigma_m;
  const std::vector<FreeFlight> flights = find_free_flights(plays[0], 0, board, flight_options);
  EXPECT_GT(find_flipper_shots(board, plays, flights).size(), 5u);
  EXPECT_TRUE(find_flipper_shots(board, no_commands, flights).empty());
  const std::vector<bus::RecordedPlay> stale{late};
  ShotOptions options;
  options.max_stroke_s = 0.1;
  EXPECT_TRUE(find_flipper_shots(board, stale, flights, options).empty())
      << "a command 0.2 s earlier than the bat moved the contact: the bat was long up";
}

TEST(FlipperShots, TooFewShotsSayHowManyAndWhatIsNeeded) {
  const table::Board board = flipper_scene();
  const std::vector<bus::RecordedPlay> plays{record_shots(board, 0.01, 3, 9)};
  FlightOptions flight_options;
  flight_options.sigma_m = kSigma_m;
  const std::vector<FreeFlight> flights = find_free_flights(plays[0], 0, board, flight_options);
  const std::vector<FlipperShot> shots = find_flipper_shots(board, plays, flights);
  const FlipperStrokeFit fit = fit_flipper_stroke(board, 0, shots, 0.004);
  EXPECT_FALSE(fit.identified);
  EXPECT_NE(fit.why_not.find("needs 8"), std::string::npos) << fit.why_not;
  EXPECT_EQ(fit.name, "left-flipper");
}

}  // namespace
}  // namespace pinball::learn
