#include "pinball/simlab/human_play.h"

#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>

#include "common/thesis_board.h"
#include "pinball/sim/model_world.h"

namespace pinball::simlab {
namespace {

using pinball::testing::thesis_board;

// Indices of the board's left and right flippers (the thesis table has one of each).
int flipper_on(table::Side side) {
  const auto& f = thesis_board().flippers;
  for (std::size_t i = 0; i < f.size(); ++i) {
    if (f[i].side == side) return static_cast<int>(i);
  }
  return -1;
}

TEST(KeyScript, ParsesActionsAndExpandsTapsInTimeOrder) {
  const auto s = parse_key_script("0.5:launch, 1.0:left, 1.05:right-down\n1.3:right-up");
  ASSERT_EQ(s.size(), 6u);
  EXPECT_EQ(s[0].key, Key::kLaunch);
  EXPECT_TRUE(s[0].down);
  EXPECT_FALSE(s[1].down);
  EXPECT_EQ(s[2].key, Key::kLeftFlipper);
  EXPECT_DOUBLE_EQ(s[2].t_s, 1.0);
  EXPECT_EQ(s[3].key, Key::kRightFlipper);  // the right press at 1.05 comes before the tap's release at 1.1
  EXPECT_EQ(s[4].key, Key::kLeftFlipper);
  EXPECT_FALSE(s[4].down);
  EXPECT_DOUBLE_EQ(s[4].t_s, 1.1);
  EXPECT_EQ(s[5].key, Key::kRightFlipper);
  EXPECT_FALSE(s[5].down);
}

TEST(KeyScript, BadEntriesAreNamed) {
  auto message = [](const std::string& text) {
    try {
      parse_key_script(text);
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(message("0.5:launch,1:jump").find("entry 2 '1:jump': unknown action 'jump'"), std::string::npos);
  EXPECT_NE(message("1:launch,0.5:left").find("times must not decrease"), std::string::npos);
  EXPECT_NE(message("x:launch").find("time must be a number"), std::string::npos);
  EXPECT_NE(message("0:launch,1e300:left").find("entry 2 '1e300:left': time must be at most 86400 s"),
            std::string::npos);
  EXPECT_NO_THROW(parse_key_script("86400:launch"));
  EXPECT_NE(message("launch").find("expected TIME:ACTION"), std::string::npos);
  EXPECT_NE(message(" , ").find("no entries"), std::string::npos);
}

TEST(PlaySession, ALaunchWithNoFlipsEndsABallWithAScoreAndADuration) {
  const auto world = sim::make_model_world(thesis_board());
  PlayConfig config;
  config.max_ball_time_s = 120.0;
  PlaySession session(*world, config);
  session.advance_to(0.5);
  EXPECT_FALSE(session.ball_in_play());
  EXPECT_TRUE(session.balls().empty());
  session.press(Key::kLaunch);
  session.release(Key::kLaunch);
  EXPECT_TRUE(session.ball_in_play());
  for (double t = 0.5; t < 200.0 && session.balls().empty(); t += 0.05) session.advance_to(t);
  ASSERT_EQ(session.balls().size(), 1u);
  const PlayedBall& b = session.balls()[0];
  EXPECT_FALSE(session.ball_in_play());
  EXPECT_GT(b.duration_s, 0.0);
  EXPECT_LE(b.duration_s, config.max_ball_time_s + world->dt_s());
  EXPECT_GE(b.score, 0.0);
  EXPECT_TRUE(std::isfinite(b.score));
  EXPECT_GE(b.launches, 1);
  EXPECT_EQ(session.state().flips, 0u);
}

TEST(PlaySession, AHeldFlipperKeyKeepsTheCoilEnergizedUntilReleased) {
  const auto world = sim::make_model_world(thesis_board());
  PlaySession session(*world, PlayConfig{});
  const int left = flipper_on(table::Side::kLeft);
  const int right = flipper_on(table::Side::kRight);
  ASSERT_GE(left, 0);
  ASSERT_GE(right, 0);
  const auto& flipper = thesis_board().flippers[static_cast<std::size_t>(left)];
  session.press(Key::kLeftFlipper);
  session.press(Key::kLeftFlipper);  // the keyboard's auto-repeat
  for (double t = 0.1; t <= 2.0; t += 0.1) {
    session.advance_to(t);
    EXPECT_TRUE(session.state().flippers[left].energized) << t;
    EXPECT_FALSE(session.state().flippers[right].energized) << t;
  }
  EXPECT_NEAR(session.state().flippers[left].theta_rad, flipper.theta_max_rad, 1e-9);  // held up: cradling
  session.release(Key::kLeftFlipper);
  EXPECT_FALSE(session.state().flippers[left].energized);
  session.advance_to(3.0);
  EXPECT_NEAR(session.state().flippers[left].theta_rad, flipper.theta_min_rad, 1e-9);
  EXPECT_EQ(session.state().flips, 1u);  // one press, however long it was held
  EXPECT_EQ(session.counters().key_events, 2u);
}

TEST(PlaySession, AdvanceNeverStepsPastTheTargetAndCapsItsSteps) {
  const auto world = sim::make_model_world(thesis_board());
  const double dt_s = world->dt_s();
  PlayConfig config;
  config.max_steps_per_advance = 100;
  PlaySession session(*world, config);
  EXPECT_EQ(session.advance_to(10.5 * dt_s), 10);
  EXPECT_LE(session.time_s(), 10.5 * dt_s);
  EXPECT_EQ(session.advance_to(10.9 * dt_s), 0);  // no whole step fits
  EXPECT_EQ(session.counters().fell_behind, 0u);
  // A one-second stall: 100 steps, the rest dropped, not caught up later.
  EXPECT_EQ(session.advance_to(1.0), 100);
  EXPECT_NEAR(session.time_s(), 110 * dt_s, 1e-12);
  EXPECT_EQ(session.counters().fell_behind, 1u);
  EXPECT_NEAR(session.counters().dropped_s, 1.0 - 110 * dt_s, 1e-9);
  EXPECT_NEAR(session.session_time_for_wall(1.0), session.time_s(), 1e-9);
  const int steps = session.advance_to(session.session_time_for_wall(1.0 + 20 * dt_s));
  EXPECT_EQ(steps, 20);
  EXPECT_EQ(session.counters().fell_behind, 1u);
  EXPECT_EQ(session.counters().steps, 130u);
}

TEST(PlaySession, AScriptPlaysTheSameKeysAtTheirTimes) {
  const auto world = sim::make_model_world(thesis_board());
  PlaySession session(*world, PlayConfig{});
  const auto script = parse_key_script("0.2:launch,1.0:left-down,1.5:left-up");
  std::size_t next = play_script_until(session, script, 0, 0.1);
  EXPECT_EQ(next, 0u);
  EXPECT_FALSE(session.ball_in_play());
  next = play_script_until(session, script, next, 1.2);
  EXPECT_EQ(next, 3u);
  EXPECT_TRUE(session.ball_in_play());
  EXPECT_TRUE(session.held(Key::kLeftFlipper));
  next = play_script_until(session, script, next, 2.0);
  EXPECT_EQ(next, script.size());
  EXPECT_FALSE(session.held(Key::kLeftFlipper));
  EXPECT_EQ(session.state().flips, 1u);
}

TEST(PlaySession, ABadPullIsRefusedBeforeTheGame) {
  const auto world = sim::make_model_world(thesis_board());
  PlayConfig config;
  config.pull = 0.01;
  EXPECT_THROW(PlaySession(*world, config), std::invalid_argument);
}

}  // namespace
}  // namespace pinball::simlab
