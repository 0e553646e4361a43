#include "pinball/view/log_player.h"

#include <gtest/gtest.h>

#include <stdexcept>

#include "view/view_log.h"

namespace pinball::view {
namespace {


TEST(LogPlayer, SeekShowsTheBallWhereTheLogSaysItWas) {
  LogPlayer player = pinball::testing::recorded_view_game("log_player");
  EXPECT_NEAR(player.duration_s(), 1.0, 1e-9);
  player.seek(0.5001);  // frame 100 at 0.5 s
  ASSERT_TRUE(player.state().ball().has_value());
  const Vec2 truth = pinball::testing::view_log_ball(0.5);
  EXPECT_NEAR((player.state().ball()->p_board - truth).norm(), 0.0, 1e-12);
}

TEST(LogPlayer, GoingBackGivesTheSameViewAsComingForward) {
  LogPlayer a = pinball::testing::recorded_view_game("log_player");
  LogPlayer b = pinball::testing::recorded_view_game("log_player");
  a.seek(0.95);
  a.seek(0.3);
  b.seek(0.3);
  ASSERT_TRUE(a.state().ball() && b.state().ball());
  EXPECT_EQ(a.state().ball()->seq, b.state().ball()->seq);
  EXPECT_EQ(a.state().trail().size(), b.state().trail().size());
  EXPECT_EQ(a.state().commands().size(), b.state().commands().size());
  EXPECT_EQ(a.state().figures().frames_dropped, b.state().figures().frames_dropped);
}

TEST(LogPlayer, StepsFrameByFrameOverADroppedFrame) {
  LogPlayer player = pinball::testing::recorded_view_game("log_player");
  player.seek(0.2001);  // frame 40
  ASSERT_EQ(player.state().ball()->seq, 40);
  ASSERT_TRUE(player.step_frame_forward());
  EXPECT_EQ(player.state().ball()->seq, 41);
  player.seek(0.2451);  // frame 49; frame 50 is not in the log
  ASSERT_TRUE(player.step_frame_forward());
  EXPECT_EQ(player.state().ball()->seq, 51);
  ASSERT_TRUE(player.step_frame_back());
  EXPECT_EQ(player.state().ball()->seq, 49);
  EXPECT_EQ(player.state().figures().frames_dropped, 0);  // the gap is after this frame
}

TEST(LogPlayer, StopsAtBothEnds) {
  LogPlayer player = pinball::testing::recorded_view_game("log_player");
  player.seek(-5.0);
  EXPECT_EQ(player.position_s(), 0.0);
  EXPECT_FALSE(player.step_frame_back());
  player.seek(1e9);
  EXPECT_EQ(player.position_s(), player.duration_s());
  EXPECT_FALSE(player.step_frame_forward());
}

TEST(LogPlayer, ThePlayedLogCarriesTheCommandsCoilsAndStats) {
  LogPlayer player = pinball::testing::recorded_view_game("log_player");
  player.seek(pinball::testing::kViewLogFire_s + 0.05);
  EXPECT_TRUE(player.state().coil_on(0));
  ASSERT_EQ(player.state().commands().size(), 1u);
  EXPECT_TRUE(player.state().commands().back().energize);
  player.seek(player.duration_s());
  EXPECT_FALSE(player.state().coil_on(0));
  EXPECT_EQ(player.state().commands().size(), 2u);
  EXPECT_DOUBLE_EQ(player.state().figures().frame_to_can_p99_us, 812.0);
  EXPECT_EQ(player.state().malformed(), 0u);
  EXPECT_EQ(player.state().messages(), player.events());
}

// lcm-logger stamps each event on receipt: an NTP step 30 s back halfway through had put the game's
// end before its start ("ends at 10.54 s", the last ball at -9.15 s). The daemon's own message times
// are the clock, as the live view reads them.
TEST(LogPlayer, PlaysOnTheDaemonsClockNotTheLoggersStamps) {
  const std::string path = pinball::testing::temp_path("log_player_ntp", "game.lcmlog");
  pinball::testing::write_view_log(path);
  std::vector<bus::LcmLogEvent> events = bus::read_lcm_log(path);
  for (std::size_t i = events.size() / 2; i < events.size(); ++i) events[i].utime -= 30'000'000;
  LogPlayer player(std::move(events));
  EXPECT_NEAR(player.duration_s(), 1.0, 1e-9);
  player.seek(0.9001);  // frame 180
  ASSERT_TRUE(player.state().ball().has_value());
  EXPECT_NEAR((player.state().ball()->p_board - pinball::testing::view_log_ball(0.9)).norm(), 0.0, 1e-12);
}

TEST(LogPlayer, RefusesALogWithoutEvents) { EXPECT_THROW(LogPlayer({}), std::invalid_argument); }

}  // namespace
}  // namespace pinball::view
