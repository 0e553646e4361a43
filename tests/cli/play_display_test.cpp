// `pinball play` with its window, under a virtual display (ctest runs this
// suite through xvfb-run): a scripted key sequence launches and flips, one
// ball is played in real time, and the score file gets its row.

#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "common/command_test.h"

namespace {

using pinball::testing::CommandResult;
using pinball::testing::count_lines;
using pinball::testing::slurp;

class PlayDisplay : public pinball::testing::CommandTest {};

TEST_F(PlayDisplay, AScriptedBallInTheWindowGetsItsRow) {
  ASSERT_NE(std::getenv("DISPLAY"), nullptr) << "run under xvfb-run (ctest does)";
  const std::string csv = (dir_ / "scores.csv").string();
  // Real time: the ball is cut after 8 s if it is still in play.
  const CommandResult r = run("play boards/mit1993.board --player 'Test Player' --csv " + csv +
                              " --keys '0.3:launch,1.5:left,2.0:right,2.5:left-down,3.5:left-up,4.0:right'"
                              " --balls 1 --max-ball-time 8 --json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j.at("mode"), "window");
  EXPECT_EQ(j.at("balls"), 1);
  EXPECT_GT(j.at("frames").get<long>(), 10);
  EXPECT_GT(j.at("steps").get<double>(), 0.0);
  EXPECT_GE(j.at("key_events").get<int>(), 4);  // the launch and the first flip reached the game
  // Reported, not asserted: a loaded CI machine may draw slower than a player's.
  std::cout << "draw rate " << j.at("draw_fps") << " frames/s (target " << j.at("target_fps") << "), physics "
            << j.at("steps_per_s") << " steps/s (real time " << j.at("physics_hz") << "), keyboard "
            << j.at("keyboard") << ", fell behind " << j.at("fell_behind") << " times\n";
  RecordProperty("draw_fps", std::to_string(j.at("draw_fps").get<double>()));
  RecordProperty("steps_per_s", std::to_string(j.at("steps_per_s").get<double>()));

  const std::string text = slurp(csv);
  ASSERT_EQ(count_lines(text), 2) << text;
  EXPECT_EQ(text.rfind("player,date,board,world,ball,score,duration_s,cut\nTest Player,", 0), 0u) << text;
  EXPECT_NE(text.find(",boards/mit1993.board,thesis,1,"), std::string::npos) << text;

  const CommandResult stats = run("play --stats " + csv + " --json");
  ASSERT_EQ(stats.exit_code, 0) << stats.err;
  const auto s = nlohmann::json::parse(stats.out);
  ASSERT_EQ(s.at("players").size(), 1u);
  EXPECT_EQ(s.at("players")[0].at("player"), "Test Player");
  EXPECT_EQ(s.at("players")[0].at("balls"), 1);
  EXPECT_DOUBLE_EQ(s.at("players")[0].at("mean_score_per_ball").get<double>(),
                   j.at("ball_scores")[0].at("score").get<double>());
}

}  // namespace
