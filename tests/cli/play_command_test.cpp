// `pinball play` without a window: a key script played headless, the score
// file it appends to, --stats, and every refusal before anything is written.

#include <filesystem>
#include <fstream>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "common/command_test.h"

namespace {

namespace fs = std::filesystem;

using pinball::testing::CommandResult;
using pinball::testing::count_lines;
using pinball::testing::slurp;

class Play : public pinball::testing::CommandTest {
 protected:
  std::string csv() const { return (dir_ / "scores.csv").string(); }
};

TEST_F(Play, AHeadlessScriptPlaysBallsAndEachGetsItsRow) {
  const CommandResult r = run("play boards/mit1993.board --headless --player ada --csv " + csv() +
                              " --keys '0.2:launch,2.0:left,2.5:right,3.0:left-down,4.0:left-up' --balls 1"
                              " --max-ball-time 30 --json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j.at("balls"), 1);
  EXPECT_EQ(j.at("player"), "ada");
  EXPECT_EQ(j.at("mode"), "headless");
  EXPECT_DOUBLE_EQ(j.at("max_score").get<double>(), j.at("ball_scores")[0].at("score").get<double>());
  EXPECT_EQ(j.at("world"), "thesis");
  EXPECT_GT(j.at("steps").get<double>(), 0.0);
  EXPECT_GT(j.at("ball_scores")[0].at("duration_s").get<double>(), 0.0);
  const std::string text = slurp(csv());
  EXPECT_EQ(text.rfind("player,date,board,world,ball,score,duration_s,cut\nada,", 0), 0u) << text;
  EXPECT_EQ(count_lines(text), 2);

  // A second session on the event stepper appends (no second header); --stats reads both.
  const CommandResult again = run("play boards/mit1993.board --headless --player bob --stepper event --csv " + csv() +
                                  " --keys 0.2:launch --max-ball-time 20");
  ASSERT_EQ(again.exit_code, 0) << again.err;
  EXPECT_NE(again.out.find("bob (1 ball appended"), std::string::npos) << again.out;
  EXPECT_EQ(count_lines(slurp(csv())), 3);
  EXPECT_NE(slurp(csv()).find(",event,1,"), std::string::npos);
  const CommandResult stats = run("play --stats " + csv() + " --json");
  ASSERT_EQ(stats.exit_code, 0) << stats.err;
  const auto s = nlohmann::json::parse(stats.out);
  ASSERT_EQ(s.at("players").size(), 2u);
  EXPECT_EQ(s.at("players")[0].at("player"), "ada");
  EXPECT_EQ(s.at("players")[0].at("balls"), 1);
  EXPECT_TRUE(s.at("players")[0].at("score_ci95_half_width").is_null());  // one ball: no interval
  EXPECT_EQ(s.at("pooled").at("balls"), 2);
  EXPECT_EQ(s.at("balls_by_world"), (nlohmann::json{{"event", 1}, {"thesis", 1}}));
  EXPECT_EQ(s.at("balls_by_board"), (nlohmann::json{{"boards/mit1993.board", 2}}));
  EXPECT_DOUBLE_EQ(s.at("players")[0].at("mean_score_per_ball").get<double>(),
                   j.at("ball_scores")[0].at("score").get<double>());
  EXPECT_DOUBLE_EQ(s.at("pooled").at("mean_score_per_ball").get<double>(),
                   (s.at("players")[0].at("mean_score_per_ball").get<double>() +
                    s.at("players")[1].at("mean_score_per_ball").get<double>()) / 2.0);
  const CommandResult table = run("play --stats " + csv());
  ASSERT_EQ(table.exit_code, 0) << table.err;
  EXPECT_NE(table.out.find("Number balls"), std::string::npos) << table.out;
  EXPECT_NE(table.out.find("all players"), std::string::npos) << table.out;
  EXPECT_NE(table.out.find("worlds: event 1, thesis 1; boards: boards/mit1993.board 2\n"
                           "the means below pool these games"),
            std::string::npos)
      << table.out;
  EXPECT_NE(table.out.find(" ± ∞\n"), std::string::npos) << "one ball bounds nothing:\n" << table.out;
  EXPECT_EQ(table.out.find(" ± 0\n"), std::string::npos) << table.out;
}

TEST_F(Play, WithoutADisplayItSaysSoAndWritesNothing) {
  const CommandResult r = run_shell("cd " PINBALL_SOURCE_DIR " && env -u DISPLAY " PINBALL_EXE
                                    " play boards/mit1993.board --csv " + csv());
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("pinball play needs a display (DISPLAY is not set); use --headless with --keys to play a script"),
            std::string::npos) << r.err;
  EXPECT_EQ(count_lines(r.err), 1);
  EXPECT_FALSE(fs::exists(csv()));
  // A display that does not answer (a stale SSH forwarding) had aborted in Qt: SIGABRT, exit 134.
  const CommandResult stale = run_shell("cd " PINBALL_SOURCE_DIR " && env -u WAYLAND_DISPLAY -u QT_QPA_PLATFORM "
                                        "DISPLAY=:987 " PINBALL_EXE " play boards/mit1993.board --csv " + csv());
  EXPECT_EQ(stale.exit_code, 1);
  EXPECT_NE(stale.err.find("needs a display (DISPLAY :987: no X server answers at /tmp/.X11-unix/X987)"),
            std::string::npos)
      << stale.err;
  EXPECT_FALSE(fs::exists(csv()));
}

// A report that did not reach stdout (a full disk) is not a success for a script.
TEST_F(Play, AnOutputThatDidNotReachStdoutExitsOne) {
  const CommandResult r = run_shell(PINBALL_EXE " --version > /dev/full");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("pinball: the output did not all reach standard output"), std::string::npos) << r.err;
}

TEST_F(Play, BadInputIsRefusedBeforeTheGameAndWritesNothing) {
  const std::string to_csv = " --csv " + csv();
  const struct {
    std::string args;  // after `play`
    std::string says;  // in the one-line error
  } cases[] = {
      {"boards/mit1993.board --headless --keys '0.1:launch,0.5:jump'" + to_csv, "entry 2 '0.5:jump': unknown action 'jump'"},
      {"boards/mit1993.board --headless --keys 0.1:launch --csv /no-such-dir/s.csv", "/no-such-dir/s.csv"},
      {"boards/mit1993.board --player 'a,b' --headless --keys 0.1:launch" + to_csv, "player name"},
      {"boards/mit1993.board --headless" + to_csv, "--headless needs --keys"},
      {"boards/mit1993.board --pull 0.01 --headless --keys 0.1:launch" + to_csv, "pull"},
  };
  for (const auto& c : cases) {
    const CommandResult r = run("play " + c.args);
    EXPECT_EQ(r.exit_code, 1) << c.args;
    EXPECT_NE(r.err.find(c.says), std::string::npos) << c.args << ": " << r.err;
    EXPECT_EQ(count_lines(r.err), 1) << r.err;
  }
  // A board path that names no file is a bad argument, as for every command (it had exited 1).
  const CommandResult missing = run("play boards/no-such.board --headless --keys 0.1:launch" + to_csv);
  EXPECT_EQ(missing.exit_code, 2);
  EXPECT_NE(missing.err.find("board: File does not exist: boards/no-such.board"), std::string::npos) << missing.err;
  EXPECT_FALSE(fs::exists(csv()));
}

TEST_F(Play, StatsOnABadFileNamesTheFileAndLine) {
  std::ofstream(csv()) << "player,date,board,world,ball,score,duration_s,cut\n"
                       << "ada,2026-12-02T13:45:21Z,b,thesis,1,100,3.5,0\n"
                       << "ada,2026-12-02T13:46:00Z,b,thesis,two,100,3.5,0\n";
  const CommandResult r = run("play --stats " + csv());
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find(csv() + ":3: column 'ball'"), std::string::npos) << r.err;
  // A path that names no file is a bad argument, as for every input option.
  const CommandResult missing = run("play --stats " + (dir_ / "none.csv").string());
  EXPECT_EQ(missing.exit_code, 2);
  EXPECT_NE(missing.err.find("--stats: File does not exist: " + (dir_ / "none.csv").string()), std::string::npos)
      << missing.err;
}

}  // namespace
