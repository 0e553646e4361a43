#include "aim_bench.h"

#include <gtest/gtest.h>

#include <stdexcept>

#include "common/thesis_board.h"

namespace pinball::bench {
namespace {

using pinball::testing::thesis_board;

AimBenchOptions tiny_bench() {
  AimBenchOptions o;
  o.balls = 2;
  o.seed = 5;
  o.copies = 3;
  o.max_ball_time_s = 10.0;
  o.planner.fire_frames = 3;
  o.planner.horizon_s = 1.0;
  return o;
}

// A ball at rest just above the middle of the left bat, the bat down.
sim::GameState ball_on_left_bat(const table::Board& board, int left) {
  sim::GameState s = sim::make_game_state(board, 1);
  const table::Flipper& f = board.flippers[static_cast<std::size_t>(left)];
  const double theta = s.flippers[static_cast<std::size_t>(left)].theta_rad;
  const Vec2 tip = table::flipper_tip(f, theta);
  const Vec2 along = (tip - f.pivot).normalized();
  const Vec2 up = along.x() > 0 ? Vec2(-along.y(), along.x()) : Vec2(along.y(), -along.x());
  s.ball_in_play = true;
  s.ball.position_m = f.pivot + 0.5 * (tip - f.pivot) + up * (board.ball.radius_m + 1e-3);
  s.ball.velocity_mps = Vec2::Zero();
  return s;
}

TEST(AimBench, AFiredBatShootsTheBallUpAndAnIdleOneDoesNot) {
  const table::Board& board = thesis_board();
  const int left = table::flippers_by_side(board)[0];
  const sim::ThesisStepper stepper(board);
  const double exit_y = board.flippers[0].pivot.y() + 0.10;
  const sim::GameState s = ball_on_left_bat(board, left);
  const std::optional<double> fired = shot_direction_deg(stepper, s, left, 0.1, 0.004, exit_y, 0.6);
  ASSERT_TRUE(fired.has_value()) << "a bat fired under the ball shoots it";
  EXPECT_GT(*fired, 0.0);
  EXPECT_LT(*fired, 180.0);
  EXPECT_EQ(shot_direction_deg(stepper, s, left, 0.1, 0.004, exit_y, 0.6), fired) << "a replay is exact";
  EXPECT_FALSE(shot_direction_deg(stepper, s, left, 0.0, 0.004, exit_y, 0.6).has_value())
      << "a bat never fired lets the ball roll off downwards";
  EXPECT_FALSE(shot_direction_deg(stepper, s, left, 0.1, 0.004, exit_y, 0.001).has_value())
      << "no shot within the time allowed";
}

TEST(AimBench, ExactCopiesShootExactlyAndNoiseSpreadsTheShots) {
  AimBenchOptions o = tiny_bench();
  o.noise = {{0.0, 0.0}, {5e-3, 0.3}};
  const AimReport r = run_aim_bench(thesis_board(), o);
  ASSERT_GT(r.shots, 0) << "the ceiling player fired and shot";
  EXPECT_LE(r.shots, r.fires);
  ASSERT_EQ(r.results.size(), 2u);
  const AimNoiseResult& exact = r.results[0];
  EXPECT_EQ(exact.copies, r.shots * o.copies);
  EXPECT_EQ(exact.no_shot, 0);
  EXPECT_EQ(exact.median_error_deg, 0.0);
  EXPECT_EQ(exact.within_5_deg, 1.0);
  const AimNoiseResult& noisy = r.results[1];
  EXPECT_LT(noisy.within_10_deg, 1.0) << "5 mm and 0.3 m/s of noise move some shots";
  EXPECT_GE(noisy.p90_error_deg, noisy.median_error_deg);
  EXPECT_GT(r.bat_only_within_10_deg, 0.0) << "some of the ceiling's shots lie near their bat's median";
  EXPECT_LE(r.bat_only_within_10_deg, 1.0);
  EXPECT_EQ(run_aim_bench(thesis_board(), o).results[1].median_error_deg, noisy.median_error_deg)
      << "same seed, same copies";
  const nlohmann::json j = to_json(r);
  EXPECT_EQ(j.at("benchmark"), "aim");
  EXPECT_EQ(j.at("results").size(), 2u);
  EXPECT_EQ(j.at("results")[1].at("velocity_noise_mps"), 0.3);
  EXPECT_NE(to_text(r).find("within 10 deg"), std::string::npos);
}

TEST(AimBench, RefusesBadSettings) {
  const auto refused = [](auto change) {
    AimBenchOptions o = tiny_bench();
    change(o);
    EXPECT_THROW(run_aim_bench(thesis_board(), o), std::invalid_argument);
  };
  refused([](AimBenchOptions& o) { o.balls = 0; });
  refused([](AimBenchOptions& o) { o.copies = 0; });
  refused([](AimBenchOptions& o) { o.noise = {{-1e-3, 0.0}}; });
  refused([](AimBenchOptions& o) { o.noise = {{0.0, std::nan("")}}; });
  refused([](AimBenchOptions& o) { o.exit_height_m = 0.0; });
  refused([](AimBenchOptions& o) { o.shot_time_s = -1.0; });
}

}  // namespace
}  // namespace pinball::bench
