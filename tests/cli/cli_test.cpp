// The `pinball` command as users and scripts run it: JSON on stdout, one-line
// errors, exit codes, and the same seed giving the same output to the bit.

#include <algorithm>
#include <cctype>
#include <cmath>
#include <csignal>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <regex>
#include <sstream>
#include <string>

#include <gtest/gtest.h>

#include "pinball/simlab/world_factory.h"
#include <nlohmann/json.hpp>
#include <opencv2/videoio.hpp>

#include "common/command_test.h"
#include "common/temp_path.h"
#include "pinball/core/geometry.h"

namespace {

namespace fs = std::filesystem;

using pinball::testing::CommandResult;
using pinball::testing::count_lines;
using pinball::testing::entries;
using pinball::testing::slurp;

class Cli : public pinball::testing::CommandTest {};

// The thesis table with one line replaced, written into the test's directory.
fs::path variant_board(const fs::path& dir, const std::string& from, const std::string& to) {
  std::string text = slurp(PINBALL_SOURCE_DIR "/boards/mit1993.board");
  const std::size_t at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  text.replace(at, from.size(), to);
  const fs::path path = dir / "world.board";
  std::ofstream(path) << text;
  return path;
}

TEST_F(Cli, SimPlaysTheWorldBoardWhileTheTrackerBelievesTheBoard) {
  const fs::path world = variant_board(dir_, "gravity 1110", "gravity 1000");
  const CommandResult model = run("sim boards/mit1993.board --policy spastic --balls 6 --seed 3 --json");
  const CommandResult other = run("sim boards/mit1993.board --policy spastic --balls 6 --seed 3 --json --world-board " +
                                  world.string());
  const CommandResult event = run("sim boards/mit1993.board --policy spastic --balls 6 --seed 3 --json --stepper event");
  ASSERT_EQ(model.exit_code, 0) << model.err;
  ASSERT_EQ(other.exit_code, 0) << other.err;
  ASSERT_EQ(event.exit_code, 0) << event.err;
  const auto m = nlohmann::json::parse(model.out), o = nlohmann::json::parse(other.out),
             e = nlohmann::json::parse(event.out);
  EXPECT_EQ(m.at("world_board"), "boards/mit1993.board");
  EXPECT_EQ(o.at("world_board"), world.string());
  EXPECT_EQ(o.at("board"), "boards/mit1993.board");
  EXPECT_EQ(e.at("stepper"), "event");
  EXPECT_NE(m.at("state_hash"), o.at("state_hash"));
  EXPECT_NE(m.at("state_hash"), e.at("state_hash"));
}

TEST_F(Cli, LearnAndBenchCeilingTakeTheWorldApartFromTheBelief) {
  const fs::path world = variant_board(dir_, "gravity 1110", "gravity 1000");
  const std::string eval = "learn boards/mit1993.board --method spastic --eval-balls 8 --seed 5 --threads 1 --json";
  const CommandResult model = run(eval);
  const CommandResult other = run(eval + " --world-board " + world.string());
  ASSERT_EQ(model.exit_code, 0) << model.err;
  ASSERT_EQ(other.exit_code, 0) << other.err;
  const auto m = nlohmann::json::parse(model.out), o = nlohmann::json::parse(other.out);
  EXPECT_EQ(o.at("world_board"), world.string());
  EXPECT_EQ(o.at("stepper"), "thesis");
  EXPECT_NE(m.at("evaluation").at("mean_score_per_ball"), o.at("evaluation").at("mean_score_per_ball"));
  const CommandResult ceiling =
      run("bench ceiling --balls 2 --max-ball-time 3 --threads 1 --json --stepper event --world-board " + world.string());
  ASSERT_EQ(ceiling.exit_code, 0) << ceiling.err;
  const auto c = nlohmann::json::parse(ceiling.out);
  EXPECT_EQ(c.at("world"), "event");
  EXPECT_EQ(c.at("world_board"), world.string());
}

TEST_F(Cli, LearnRandomizeSearchesAcrossDrawnWorldsAndJudgesInTheHomeWorld) {
  const fs::path ranges = dir_ / "ranges.yaml";
  std::ofstream(ranges) << "variants: 4\nseed: 2\nevent_stepper_share: 0.5\nranges:\n"
                           "  gravity_pct: [-5, 5]\n  camera_latency_ms: [0, 10]\n";
  const std::string cem = "learn boards/mit1993.board --method cem --budget-balls 64 --population 8 --seed 3 "
                          "--threads 1 --eval-balls 8 --max-ball-time 10 --json --out " + (dir_ / "c.json").string();
  const CommandResult r = run(cem + " --randomize " + ranges.string());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  ASSERT_EQ(j.at("randomize").at("worlds").size(), 4u);
  EXPECT_EQ(j.at("randomize").at("file"), ranges.string());
  EXPECT_EQ(j.at("randomize").at("worlds")[0].at("values").size(), 2u);
  EXPECT_EQ(j.at("evaluation").at("balls"), 8);
  EXPECT_EQ(j.at("world"), "thesis");  // the evaluation's: the belief's own model
  const CommandResult plain = run(cem);
  ASSERT_EQ(plain.exit_code, 0) << plain.err;
  EXPECT_FALSE(nlohmann::json::parse(plain.out).contains("randomize"));
  EXPECT_NE(nlohmann::json::parse(plain.out).at("best_estimated_mean"), j.at("best_estimated_mean"));

  // --lead writes the actuation delay the search led its projections by into the controller.
  const CommandResult led = run(cem + " --lead --actuation-delay 0.006");
  ASSERT_EQ(led.exit_code, 0) << led.err;
  EXPECT_EQ(nlohmann::json::parse(led.out).at("lead"), true);
  EXPECT_NE(pinball::testing::slurp(dir_ / "c.json").find("\"lead_actuation_delay_s\": 0.006"), std::string::npos);

  // Imitation too: its teacher and learner play the drawn worlds, the evaluation the home world.
  const std::string imitate = "learn boards/mit1993.board --method imitate --budget-balls 4 --rounds 2 --seed 3 "
                              "--threads 1 --eval-balls 4 --max-ball-time 5 --json --out " + (dir_ / "i.json").string();
  const CommandResult im = run(imitate + " --randomize " + ranges.string());
  ASSERT_EQ(im.exit_code, 0) << im.err;
  const auto ij = nlohmann::json::parse(im.out);
  ASSERT_EQ(ij.at("randomize").at("worlds").size(), 4u);
  EXPECT_EQ(ij.at("evaluation").at("balls"), 4);
  EXPECT_EQ(ij.at("world"), "thesis");
  EXPECT_NE(pinball::testing::slurp(dir_ / "i.json").find("--randomize " + ranges.string()), std::string::npos);
  const CommandResult im_plain = run(imitate);
  ASSERT_EQ(im_plain.exit_code, 0) << im_plain.err;
  EXPECT_FALSE(nlohmann::json::parse(im_plain.out).contains("randomize"));
  EXPECT_NE(nlohmann::json::parse(im_plain.out).at("rounds"), ij.at("rounds"));
  EXPECT_EQ(nlohmann::json::parse(im_plain.out).at("lead"), false);
  // --lead keys the shot table on the led projection and writes its delay into the table.
  const CommandResult im_led = run(imitate + " --lead --actuation-delay 0.006");
  ASSERT_EQ(im_led.exit_code, 0) << im_led.err;
  EXPECT_EQ(nlohmann::json::parse(im_led.out).at("lead"), true);
  const nlohmann::json led_table = nlohmann::json::parse(pinball::testing::slurp(dir_ / "i.json")).at("imitation");
  EXPECT_EQ(led_table.at("lead_actuation_delay_s"), 0.006);
  const CommandResult spastic_led = run("learn boards/mit1993.board --method spastic --eval-balls 2 --lead");
  EXPECT_EQ(spastic_led.exit_code, 1);
  EXPECT_NE(spastic_led.err.find("learn spastic: --lead applies to tournament, relay, cem and imitate only"),
            std::string::npos)
      << spastic_led.err;

  const CommandResult spastic = run("learn boards/mit1993.board --method spastic --eval-balls 2 --randomize " +
                                    ranges.string());
  EXPECT_EQ(spastic.exit_code, 1);
  EXPECT_NE(spastic.err.find("--randomize"), std::string::npos) << spastic.err;
  std::ofstream(dir_ / "bad.yaml") << "variants: 4\nseed: 2\nevent_stepper_share: 0\nranges:\n  g: [0, 1]\n";
  const CommandResult bad = run(cem + " --randomize " + (dir_ / "bad.yaml").string());
  EXPECT_EQ(bad.exit_code, 1);
  EXPECT_NE(bad.err.find("bad.yaml:ranges.g"), std::string::npos) << bad.err;
}

// controllers/spastic.json is the baseline itself, so a command that reads
// controller files (pinballd among them) plays the ratios' denominator.
TEST_F(Cli, TheSpasticControllerFilePlaysTheSpasticBaseline) {
  const std::string balls = " --eval-balls 20 --max-ball-time 20 --seed 4 --threads 2 --json";
  const CommandResult method = run("learn boards/mit1993.board --method spastic" + balls);
  const CommandResult file = run("learn boards/mit1993.board --method evaluate --controller controllers/spastic.json" + balls);
  ASSERT_EQ(method.exit_code, 0) << method.err;
  ASSERT_EQ(file.exit_code, 0) << file.err;
  const nlohmann::json a = nlohmann::json::parse(method.out).at("evaluation");
  const nlohmann::json b = nlohmann::json::parse(file.out).at("evaluation");
  EXPECT_GT(a.at("mean_score_per_ball").get<double>(), 0.0);
  EXPECT_EQ(a.at("mean_score_per_ball"), b.at("mean_score_per_ball")) << "the same balls, the same flips";
  EXPECT_EQ(a.at("flips_per_ball"), b.at("flips_per_ball"));
  EXPECT_EQ(a.at("mean_ball_time_s"), b.at("mean_ball_time_s"));
  const CommandResult policy = run("sim boards/mit1993.board --policy spastic --balls 3 --seed 3 --json");
  const CommandResult played = run("sim boards/mit1993.board --controller controllers/spastic.json --balls 3 --seed 3 --json");
  ASSERT_EQ(policy.exit_code, 0) << policy.err;
  ASSERT_EQ(played.exit_code, 0) << played.err;
  EXPECT_EQ(nlohmann::json::parse(policy.out).at("state_hash"), nlohmann::json::parse(played.out).at("state_hash"));
}

TEST_F(Cli, SimLearnAndBenchCeilingPlayTheTwin) {
  if (!pinball::simlab::twin_available()) GTEST_SKIP() << "this build has no MuJoCo twin";
  const CommandResult sim = run("sim boards/mit1993.board --world twin --policy spastic --balls 2 --seed 3 --json");
  ASSERT_EQ(sim.exit_code, 0) << sim.err;
  const auto s = nlohmann::json::parse(sim.out);
  EXPECT_EQ(s.at("world"), "twin");
  EXPECT_EQ(s.at("twin_params"), "config/twin.yaml");
  EXPECT_TRUE(s.at("stepper").is_null()) << "MuJoCo integrates the twin; it had said thesis";
  EXPECT_EQ(s.at("world_warnings").at("instability"), 0);
  EXPECT_EQ(s.at("balls_left_table"), 0);
  const CommandResult again = run("sim boards/mit1993.board --world twin --policy spastic --balls 2 --seed 3 --json");
  EXPECT_EQ(nlohmann::json::parse(again.out).at("state_hash"), s.at("state_hash")) << "the same seed, the same game";
  const CommandResult learn = run("learn boards/mit1993.board --method evaluate --controller controllers/best.json "
                                  "--world twin --eval-balls 4 --max-ball-time 10 --seed 5 --threads 2 --json");
  ASSERT_EQ(learn.exit_code, 0) << learn.err;
  EXPECT_EQ(nlohmann::json::parse(learn.out).at("world"), "twin");
  const CommandResult ceiling = run("bench ceiling --balls 2 --max-ball-time 3 --threads 1 --json --world twin");
  ASSERT_EQ(ceiling.exit_code, 0) << ceiling.err;
  EXPECT_EQ(nlohmann::json::parse(ceiling.out).at("world"), "twin");
}

TEST_F(Cli, ABadTwinParameterFileIsRefusedNamingFileAndKey) {
  if (!pinball::simlab::twin_available()) GTEST_SKIP() << "this build has no MuJoCo twin";
  std::ifstream in(PINBALL_SOURCE_DIR "/config/twin.yaml");
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const std::size_t at = text.find("\nball_mass_kg:");
  ASSERT_NE(at, std::string::npos);
  const fs::path params = dir_ / "twin.yaml";
  std::ofstream(params) << text.substr(0, at) << "\nball_mass_kg: {value: 80.9, unit: g, source: scale}\n"
                        << text.substr(text.find('\n', at + 1));
  const CommandResult r = run("sim boards/mit1993.board --world twin --balls 1 --twin-params " + params.string());
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("twin.yaml:ball_mass_kg: must be given in kg, not 'g'"), std::string::npos) << r.err;
}

TEST_F(Cli, AWorldWithOtherFlippersIsRefusedNamingBothBoards) {
  const fs::path world = variant_board(dir_, "flipper left ", "flipper right ");
  const CommandResult r = run("sim boards/mit1993.board --balls 1 --world-board " + world.string());
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("world.board"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("mit1993.board"), std::string::npos) << r.err;
  EXPECT_EQ(run("sim boards/mit1993.board --balls 1 --stepper euler").exit_code, 2);
}

TEST_F(Cli, VersionNamesTheProgramAndItsVersion) {
  const CommandResult r = run("--version");
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.out.rfind("pinball 0.", 0), 0u) << r.out;
}

TEST_F(Cli, SimPlaysTheEventStepper) {
  const CommandResult r = run("sim boards/mit1993.board --stepper event --policy spastic --balls 5 --seed 3 --json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j.at("stepper"), "event");
  EXPECT_EQ(j.at("balls"), 5);
  EXPECT_GT(j.at("events").get<double>(), 0.0);
  EXPECT_GT(j.at("events_per_s").get<double>(), 0.0);
  EXPECT_GT(j.at("steps").get<double>(), 0.0);
  EXPECT_EQ(j.at("balls_left_table"), 0);
  // Same seed, same run.
  const CommandResult again = run("sim boards/mit1993.board --stepper event --policy spastic --balls 5 --seed 3 --json");
  EXPECT_EQ(nlohmann::json::parse(again.out).at("state_hash"), j.at("state_hash"));
  EXPECT_EQ(run("sim boards/mit1993.board --stepper rk4").exit_code, 2);
}

TEST_F(Cli, SimJsonReportsEveryFigure) {
  const CommandResult r = run("sim boards/mit1993.board --policy spastic --balls 5 --seed 3 --json --progress");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j.at("balls"), 5);
  for (const char* key : {"mean_score_per_ball", "score_ci95_half_width", "mean_ball_time_s", "steps_per_s",
                          "steps", "state_hash", "balls_cut_at_time_limit", "max_ball_time_s", "wall_s"}) {
    EXPECT_TRUE(j.contains(key)) << key;
  }
  EXPECT_GT(j.at("mean_score_per_ball").get<double>(), 0.0);
  EXPECT_GT(j.at("steps_per_s").get<double>(), 0.0);
  EXPECT_NE(r.err.find("sim: 5/5 balls (100 %)"), std::string::npos) << "progress goes to stderr: " << r.err;
}

TEST_F(Cli, SameSeedGivesTheSameTraceAndScores) {
  const std::string a = (dir_ / "a.csv").string();
  const std::string b = (dir_ / "b.csv").string();
  const CommandResult ra = run("sim boards/mit1993.board --policy spastic --balls 3 --seed 9 --json --trace " + a);
  const CommandResult rb = run("sim boards/mit1993.board --policy spastic --balls 3 --seed 9 --json --trace " + b);
  ASSERT_EQ(ra.exit_code, 0) << ra.err;
  ASSERT_EQ(rb.exit_code, 0) << rb.err;
  const std::string ta = slurp(a);
  EXPECT_GT(count_lines(ta), 1000);
  EXPECT_EQ(ta.rfind("t,x,y,vx,vy,event\n", 0), 0u);
  EXPECT_NE(ta.find("launch"), std::string::npos);
  EXPECT_NE(ta.find("lost"), std::string::npos);
  EXPECT_EQ(ta, slurp(b));
  auto ja = nlohmann::json::parse(ra.out);
  auto jb = nlohmann::json::parse(rb.out);
  for (auto* j : {&ja, &jb}) {
    j->erase("wall_s");
    j->erase("steps_per_s");
  }
  EXPECT_EQ(ja, jb);
  const CommandResult rc = run("sim boards/mit1993.board --policy spastic --balls 3 --seed 10 --json");
  EXPECT_NE(nlohmann::json::parse(rc.out).at("state_hash"), ja.at("state_hash"));
}

// The row of a lost ball had held the launcher's position and no speed: the state after that step,
// already reset. It is where the ball was lost, one step on from the row before.
TEST_F(Cli, TheTraceRowOfALostBallIsWhereItWasLost) {
  const std::string trace = (dir_ / "lost.csv").string();
  const CommandResult r = run("sim boards/mit1993.board --balls 3 --seed 4 --trace " + trace);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  std::istringstream rows(slurp(trace));
  std::string row;
  std::getline(rows, row);  // the header
  double previous[5] = {};
  int lost = 0;
  while (std::getline(rows, row)) {
    double v[5];
    std::istringstream cells(row);
    std::string cell;
    for (double& x : v) {
      std::getline(cells, cell, ',');
      x = std::stod(cell);
    }
    std::getline(cells, cell);
    if (cell.find("lost") != std::string::npos) {
      ++lost;
      const double dt = v[0] - previous[0];
      EXPECT_GT(std::hypot(v[3], v[4]), 0.0) << row;
      EXPECT_LT(std::hypot(v[1] - previous[1], v[2] - previous[2]), std::hypot(v[3], v[4]) * dt * 2 + 1e-3) << row;
    }
    std::copy(v, v + 5, previous);
  }
  EXPECT_EQ(lost, 3);
}

// A run that fails late (here its video meets a file size limit, as on a full disk) had left a cut
// video and had already replaced the old trace: both stay as they were, and no temporary is left.
TEST_F(Cli, ARunThatFailsLeavesItsOldOutputsAsTheyWere) {
  const fs::path dir = dir_ / "late";
  fs::create_directories(dir);
  std::ofstream(dir / "t.csv") << "the old trace\n";
  std::ofstream(dir / "v.avi") << "the old video\n";
  const CommandResult r = run_shell("cd " PINBALL_SOURCE_DIR " && trap '' XFSZ && ulimit -f 1024 && " PINBALL_EXE
                                    " sim boards/mit1993.board --balls 1 --seed 2 --max-ball-time 1 --trace " +
                                    (dir / "t.csv").string() + " --video " + (dir / "v.avi").string());
  EXPECT_EQ(r.exit_code, 1) << r.err;
  EXPECT_NE(r.err.find((dir / "v.avi").string() + ": the video was not written whole"), std::string::npos) << r.err;
  EXPECT_EQ(r.err.find("Unexpected element"), std::string::npos) << "OpenCV's reader is quiet: " << r.err;
  EXPECT_EQ(slurp((dir / "t.csv").string()), "the old trace\n");
  EXPECT_EQ(slurp((dir / "v.avi").string()), "the old video\n");
  EXPECT_EQ(entries(dir), 2u);
  // A device is written as the run goes, and one that takes nothing stops the run after its first ball.
  const CommandResult full = run("sim boards/mit1993.board --balls 50 --trace /dev/full --progress");
  EXPECT_EQ(full.exit_code, 1);
  EXPECT_NE(full.err.find("error writing trace file '/dev/full' (No space left on device)"), std::string::npos)
      << full.err;
  EXPECT_EQ(full.err.find("50/50 balls"), std::string::npos) << full.err;
}

TEST_F(Cli, FlipsCanGoThroughTheCanPath) {
  const CommandResult r = run("sim boards/mit1993.board --policy spastic --balls 3 --actuation can --json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j.at("actuation"), "can");
  EXPECT_GT(j.at("flips").get<int>(), 0);
  // The CAN path runs on the simulated clock: same seed, same game.
  const CommandResult again = run("sim boards/mit1993.board --policy spastic --balls 3 --actuation can --json");
  EXPECT_EQ(nlohmann::json::parse(again.out).at("state_hash"), j.at("state_hash"));
}

TEST_F(Cli, LauncherSearchTriesTwentyPullsTenTimesEach) {
  const CommandResult r = run("learn boards/mit1993.board --method launcher --json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  ASSERT_EQ(j.at("pulls").size(), 20u);
  EXPECT_EQ(j.at("launches_per_pull"), 10);
  int best = 0;
  for (const auto& p : j.at("pulls")) best = std::max(best, p.at("hittable").get<int>());
  EXPECT_EQ(j.at("best_hittable").get<int>(), best);
  EXPECT_GT(best, 0);
}

TEST_F(Cli, LearnImitateWritesAShotTableThatEvaluateAndSimPlay) {
  const std::string out = (dir_ / "imitate.json").string();
  const std::string common = " --seed 3 --threads 2 --max-ball-time 4 --eval-balls 4 --json";
  const CommandResult r =
      run("learn boards/mit1993.board --method imitate --budget-balls 3 --rounds 2 --out " + out + " --curve " +
          (dir_ / "imitate.csv").string() + " --plot " + (dir_ / "imitate.png").string() + common + " --progress");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  ASSERT_EQ(j.at("rounds").size(), 2u);
  EXPECT_EQ(j.at("rounds")[0].at("player"), "teacher");
  EXPECT_EQ(j.at("rounds")[1].at("player"), "learner");
  EXPECT_EQ(j.at("rounds")[0].at("balls").get<int>() + j.at("rounds")[1].at("balls").get<int>(), 3);
  EXPECT_EQ(j.at("evaluation").at("balls"), 4);
  EXPECT_NE(r.err.find("round 2/2"), std::string::npos) << "progress goes to stderr";
  EXPECT_EQ(count_lines(slurp((dir_ / "imitate.csv").string())), 3) << "a header and one row per round";
  EXPECT_TRUE(fs::exists(dir_ / "imitate.png"));
  EXPECT_TRUE(j.contains("cycle_found"));
  const auto file = nlohmann::json::parse(slurp(out));
  EXPECT_EQ(file.at("imitation").at("shots").size(), j.at("rounds")[1].at("examples").get<std::size_t>());
  // The saved table plays the same balls to the same score.
  const CommandResult e = run("learn boards/mit1993.board --method evaluate --controller " + out + common);
  ASSERT_EQ(e.exit_code, 0) << e.err;
  EXPECT_EQ(nlohmann::json::parse(e.out).at("evaluation").at("mean_score_per_ball"),
            j.at("evaluation").at("mean_score_per_ball"));
  EXPECT_EQ(run("sim boards/mit1993.board --controller " + out + " --balls 2 --max-ball-time 4 --json").exit_code, 0);
  // Fewer balls than rounds, and no --out, are refused in one line.
  const CommandResult few = run("learn boards/mit1993.board --method imitate --budget-balls 1 --rounds 2 --out " + out);
  EXPECT_NE(few.exit_code, 0);
  EXPECT_NE(few.err.find("cannot give each of 2 rounds (--rounds) a ball"), std::string::npos) << few.err;
  EXPECT_NE(run("learn boards/mit1993.board --method imitate --budget-balls 2").exit_code, 0);
}

// What shots are worth: `learn --method shot-values` writes a table that the
// imitate teacher and a planner file value their plans by; the same seed gives
// the same table whatever the threads.
TEST_F(Cli, LearnShotValuesWritesATableThatImitateAndThePlannerUse) {
  const std::string table = (dir_ / "shots.json").string();
  const std::string common = " --seed 3 --max-ball-time 4 --json";
  const CommandResult r = run("learn boards/mit1993.board --method shot-values --budget-balls 3 --threads 2 --out " +
                              table + common + " --progress");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j.at("method"), "shot-values");
  EXPECT_GT(j.at("shots").get<double>(), 100.0);
  EXPECT_GT(j.at("valued_bins").get<int>(), 0);
  EXPECT_NE(r.err.find("3/3 balls"), std::string::npos) << "progress goes to stderr";
  const std::string one = (dir_ / "shots1.json").string();
  ASSERT_EQ(run("learn boards/mit1993.board --method shot-values --budget-balls 3 --threads 1 --out " + one + common)
                .exit_code, 0);
  EXPECT_EQ(slurp(one), slurp(table));
  // The imitate teacher values its plans by it.
  const std::string learned = (dir_ / "imitate.json").string();
  const CommandResult im = run("learn boards/mit1993.board --method imitate --budget-balls 2 --rounds 1 --eval-balls 2 --out " +
                               learned + " --shot-values " + table + common);
  ASSERT_EQ(im.exit_code, 0) << im.err;
  EXPECT_EQ(nlohmann::json::parse(im.out).at("shot_values"), table);
  // A planner file names it.
  auto planner = nlohmann::json::parse(slurp(PINBALL_SOURCE_DIR "/controllers/planner.json"));
  planner["planner"]["shot_values"] = table;
  const std::string planner_file = (dir_ / "planner_sv.json").string();
  std::ofstream(planner_file) << planner.dump(1);
  EXPECT_EQ(run("learn boards/mit1993.board --method evaluate --controller " + planner_file + " --eval-balls 2" + common)
                .exit_code, 0);
  // Refused in one line: no --out; another world; --shot-values outside imitate; a file that is no table.
  const CommandResult no_out = run("learn boards/mit1993.board --method shot-values --budget-balls 1");
  EXPECT_NE(no_out.exit_code, 0);
  EXPECT_NE(no_out.err.find("--out"), std::string::npos) << no_out.err;
  const CommandResult twin = run("learn boards/mit1993.board --method shot-values --budget-balls 1 --world twin --out " + one);
  EXPECT_NE(twin.exit_code, 0);
  EXPECT_NE(twin.err.find("belief's own model"), std::string::npos) << twin.err;
  const CommandResult outside = run("learn boards/mit1993.board --method cem --budget-balls 2 --out " + learned +
                                    " --shot-values " + table);
  EXPECT_NE(outside.exit_code, 0);
  EXPECT_NE(outside.err.find("learn cem: --shot-values applies to imitate only"), std::string::npos) << outside.err;
  const CommandResult wrong = run("learn boards/mit1993.board --method imitate --budget-balls 2 --rounds 1 --out " + learned +
                                  " --shot-values " + planner_file);
  EXPECT_NE(wrong.exit_code, 0);
  EXPECT_NE(wrong.err.find("not a shot-value table"), std::string::npos) << wrong.err;
}

// --drain-penalty prices a lost ball for the shot-value player (and so its
// table) and for imitate's teacher; other methods refuse it.
TEST_F(Cli, LearnDrainPenaltyPricesTheShotTableAndTheTeacher) {
  const std::string common = " --seed 3 --max-ball-time 4 --json";
  const std::string table = (dir_ / "shots.json").string(), cheap = (dir_ / "shots_cheap.json").string();
  const CommandResult r = run("learn boards/mit1993.board --method shot-values --budget-balls 3 --threads 2 --out " +
                              table + common);
  const CommandResult c = run("learn boards/mit1993.board --method shot-values --budget-balls 3 --threads 2 --out " +
                              cheap + common + " --drain-penalty 5000");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  ASSERT_EQ(c.exit_code, 0) << c.err;
  EXPECT_EQ(nlohmann::json::parse(r.out).at("drain_penalty"), 20000.0) << "the planner's default";
  EXPECT_EQ(nlohmann::json::parse(c.out).at("drain_penalty"), 5000.0);
  EXPECT_NE(slurp(cheap), slurp(table)) << "a lost ball costs its branch less, so the values differ";
  const std::string learned = (dir_ / "imitate.json").string();
  const std::string imitate = "learn boards/mit1993.board --method imitate --budget-balls 2 --rounds 1 --eval-balls 2 --out ";
  const CommandResult plain = run(imitate + learned + common);
  const CommandResult priced = run(imitate + learned + common + " --drain-penalty 12000");
  ASSERT_EQ(plain.exit_code, 0) << plain.err;
  ASSERT_EQ(priced.exit_code, 0) << priced.err;
  EXPECT_EQ(nlohmann::json::parse(plain.out).at("teacher_drain_penalty"), 20000.0);
  EXPECT_EQ(nlohmann::json::parse(priced.out).at("teacher_drain_penalty"), 12000.0);
  // A checkpoint remembers the teacher's price and table: resumed with others, it is another run's.
  const std::string resume = imitate + learned + common + " --checkpoint " + (dir_ / "imitate.ckpt").string();
  ASSERT_EQ(run(resume).exit_code, 0);
  for (const std::string& other : {std::string(" --drain-penalty 12000"), " --shot-values " + table}) {
    const CommandResult resumed = run(resume + " --resume" + other);
    EXPECT_EQ(resumed.exit_code, 1) << other;
    EXPECT_NE(resumed.err.find("another run"), std::string::npos) << resumed.err;
    // The key that differs is named, not two lines of every key.
    EXPECT_NE(resumed.err.find(other.find("drain") != std::string::npos ? "drain_penalty (none recorded, 12000"
                                                                        : "shot_values (none recorded, "),
              std::string::npos)
        << resumed.err;
  }
  const CommandResult same = run(resume + " --resume");
  EXPECT_EQ(same.exit_code, 0) << same.err;
  // Every ball came from the file: no rate is made up from no time.
  const nlohmann::json replayed = nlohmann::json::parse(same.out).at("evaluation");
  EXPECT_TRUE(replayed.at("balls_per_s").is_null()) << same.out;
  EXPECT_GT(nlohmann::json::parse(same.out).at("wall_s").get<double>(), 0.0);
  for (const std::string& method : {"cem --budget-balls 2 --out " + learned, std::string("launcher")}) {
    const CommandResult refused = run("learn boards/mit1993.board --method " + method + " --drain-penalty 5000");
    EXPECT_EQ(refused.exit_code, 1) << method;
    EXPECT_NE(refused.err.find("--drain-penalty applies to imitate and shot-values only"), std::string::npos)
        << refused.err;
  }
  EXPECT_EQ(run(imitate + learned + " --drain-penalty -1").exit_code, 2) << "below the range";
}

// A learn stopped by a signal says what its checkpoint keeps, dies of the
// signal, writes no half result, and --resume goes on from the batches kept.
TEST_F(Cli, AnInterruptedLearnSaysWhatItsCheckpointKeepsAndResumes) {
  const std::string out = (dir_ / "cem.json").string();
  const std::string ckpt = (dir_ / "cem.ckpt").string();
  const std::string err = (dir_ / "cem.err").string();
  const std::string learn = "learn boards/mit1993.board --method cem --budget-balls 1200 --population 8 --seed 3 "
                            "--threads 1 --eval-balls 8 --out " + out + " --checkpoint " + ckpt;
  // Once a batch or two are in the file (about 1.7 kB each), SIGTERM.
  const std::string wait_for_batches = "i=0; while [ $(stat -c %s " + ckpt +
                                       " 2>/dev/null || echo 0) -lt 3000 ] && [ $i -lt 1200 ]; do sleep 0.05; "
                                       "i=$((i+1)); done";
  const CommandResult stopped =
      run_shell("cd " PINBALL_SOURCE_DIR " && { " PINBALL_EXE " " + learn + " 2> " + err + " & pid=$!; " +
                wait_for_batches + "; kill -TERM $pid; wait $pid; echo $?; }");
  EXPECT_EQ(stopped.out, std::to_string(128 + SIGTERM) + "\n") << "died of the signal, as before";
  EXPECT_NE(slurp(err).find("learn: interrupted; " + ckpt + " keeps every batch of balls finished so far"),
            std::string::npos)
      << slurp(err);
  EXPECT_FALSE(std::filesystem::exists(out)) << "no result from half a run";
  const CommandResult resumed = run(learn + " --resume --json");
  ASSERT_EQ(resumed.exit_code, 0) << resumed.err;
  EXPECT_GT(nlohmann::json::parse(resumed.out).at("team").at("checkpoint").at("replayed").get<int>(), 0);
  EXPECT_TRUE(std::filesystem::exists(out));
}

// The overlay `pinball identify` writes (docs/identification.md) is part of
// the belief: the report names it, and a bad one is refused naming file:key.
TEST_F(Cli, SimNamesTheIdentifiedOverlayAndRefusesABadOne) {
  const std::string head = "version: 1\ndate: 2026-12-02T13:45:21Z\nboard: boards/mit1993.board\nrecordings: []\n";
  const fs::path over = dir_ / "over.yaml";
  std::ofstream(over) << head << "gravity_mps2: {value: 1.0, stderr: 0.01, events: 40}\n";
  const std::string sim = "sim boards/mit1993.board --policy spastic --balls 4 --seed 3 --max-ball-time 10 --json";
  const CommandResult plain = run(sim);
  const CommandResult identified = run(sim + " --identified " + over.string());
  ASSERT_EQ(plain.exit_code, 0) << plain.err;
  ASSERT_EQ(identified.exit_code, 0) << identified.err;
  const auto p = nlohmann::json::parse(plain.out), i = nlohmann::json::parse(identified.out);
  EXPECT_TRUE(p.at("identified").is_null());
  EXPECT_EQ(i.at("identified"), over.string());
  EXPECT_EQ(i.at("world_board"), "boards/mit1993.board");
  EXPECT_NE(p.at("state_hash"), i.at("state_hash")) << "the model world plays the identified g";
  const CommandResult text = run("sim boards/mit1993.board --balls 1 --max-ball-time 2 --identified " + over.string());
  ASSERT_EQ(text.exit_code, 0) << text.err;
  EXPECT_NE(text.out.find("identified       " + over.string()), std::string::npos) << text.out;

  const fs::path bad = dir_ / "bad.yaml";
  std::ofstream(bad) << head << "gravity_mps2: {value: 25, stderr: 0.01, events: 40}\n";
  const CommandResult r = run("sim boards/mit1993.board --balls 1 --identified " + bad.string());
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_EQ(count_lines(r.err), 1) << r.err;
  EXPECT_NE(r.err.find(bad.string() + ":gravity_mps2.value: 25 is out of range"), std::string::npos) << r.err;
  std::ofstream(bad) << head << "flippers:\n  - name: middle_flipper\n    mu: {value: 1.5, stderr: 0.1, events: 9}\n";
  const CommandResult unknown = run("sim boards/mit1993.board --balls 1 --identified " + bad.string());
  EXPECT_EQ(unknown.exit_code, 1);
  EXPECT_NE(unknown.err.find(bad.string() + ":flippers[0].name: 'middle_flipper' is not a flipper of the board"),
            std::string::npos)
      << unknown.err;
  EXPECT_EQ(run("sim boards/mit1993.board --identified " + (dir_ / "none.yaml").string()).exit_code, 2);

  if (!pinball::simlab::twin_available()) return;
  // The twin stands in for the real table: it plays the board file, the belief the overlay.
  const CommandResult twin =
      run("sim boards/mit1993.board --world twin --balls 1 --max-ball-time 2 --json --identified " + over.string());
  ASSERT_EQ(twin.exit_code, 0) << twin.err;
  const auto t = nlohmann::json::parse(twin.out);
  EXPECT_EQ(t.at("identified"), over.string());
  EXPECT_EQ(t.at("world_board"), "boards/mit1993.board");
}

// An overlay's flipper rise delays are the model world's actuation delay
// unless --actuation-delay says otherwise; the twin keeps its driver's.
TEST_F(Cli, LearnPlaysTheIdentifiedActuationDelayInTheModelWorld) {
  const fs::path over = dir_ / "delay.yaml";
  std::ofstream(over) << "version: 1\ndate: 2026-12-02T13:45:21Z\nboard: boards/mit1993.board\nrecordings: []\n"
                         "flippers:\n"
                         "  - name: left_flipper\n    rise_delay_s: {value: 0.014, stderr: 0.001, events: 9}\n"
                         "  - name: right_flipper\n    rise_delay_s: {value: 0.018, stderr: 0.001, events: 9}\n";
  const std::string learn = "learn boards/mit1993.board --method spastic --eval-balls 2 --seed 3 --json";
  const auto delay_of = [&](const std::string& args) {
    const CommandResult r = run(learn + args);
    EXPECT_EQ(r.exit_code, 0) << r.err;
    return nlohmann::json::parse(r.out).at("evaluation").at("actuation_delay_s").get<double>();
  };
  EXPECT_DOUBLE_EQ(delay_of(""), 0.004);
  EXPECT_NEAR(delay_of(" --identified " + over.string()), 0.016, 1e-12);
  EXPECT_DOUBLE_EQ(delay_of(" --identified " + over.string() + " --actuation-delay 0.009"), 0.009);
  if (!pinball::simlab::twin_available()) return;
  EXPECT_DOUBLE_EQ(delay_of(" --world twin --max-ball-time 2 --identified " + over.string()), 0.004);
}

TEST_F(Cli, BadBoardFileIsOneLineNamingFileAndLine) {
  const fs::path bad = dir_ / "bad.board";
  std::ofstream(bad) << "pinball-board 1\nsize 0.5 1\ncirle 0.1 0.1 0.01\n";
  const CommandResult r = run("sim " + bad.string());
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_EQ(count_lines(r.err), 1) << r.err;
  EXPECT_NE(r.err.find(bad.string() + ":3:"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("cirle"), std::string::npos) << r.err;
  EXPECT_TRUE(r.out.empty());
}

TEST_F(Cli, BadArgumentsExitWithUsageError) {
  for (const char* args : {"sim boards/mit1993.board --balls 0", "sim boards/mit1993.board --policy wild",
                           "sim no/such.board", "sim boards/mit1993.board --dt -1", "frobnicate",
                           "sim boards/mit1993.board --video-camera", "sim boards/mit1993.board --video-fps 30"}) {
    const CommandResult r = run(args);
    EXPECT_EQ(r.exit_code, 2) << args;
    EXPECT_EQ(count_lines(r.err), 1) << args << ": " << r.err;
  }
}

TEST_F(Cli, AnOptionNothingInThePlayReadsIsRefused) {
  // Either order: --world is read first wherever it stands.
  for (const char* args : {"sim boards/mit1993.board --world twin --stepper event",
                           "sim boards/mit1993.board --stepper event --world twin"}) {
    expect_refused("", {args, 2, "--stepper: the twin steps with MuJoCo's own integrator"});
  }
  expect_refused("", {"sim boards/mit1993.board --twin-params config/twin.yaml", 2,
                      "--twin-params: only the twin reads it"});
  expect_refused("", {"sim boards/mit1993.board --reach 0.05", 1, "--reach is the spastic flipper's"});
  expect_refused("", {"sim boards/mit1993.board --controller controllers/imitation.json --reach 0.05", 1,
                      "--reach is the spastic flipper's"});
}

// An output that is an input, or another output spelled otherwise, is refused before any work:
// learn had written its controller over the board and exited 0.
TEST_F(Cli, AnOutputOverAnInputOrAnotherOutputIsRefused) {
  const std::string board = (dir_ / "b.board").string();
  std::filesystem::copy_file(std::string(PINBALL_SOURCE_DIR) + "/boards/mit1993.board", board);
  const std::string kept = pinball::testing::slurp(board);
  expect_refused("", {"learn " + board + " --method tournament --budget-balls 60 --out " + board, 1,
                      "--out " + board + " is the input board " + board + "; it would be replaced"});
  expect_refused("", {"sim " + board + " --balls 1 --trace " + board, 1, "--trace " + board + " is the input board"});
  expect_refused("", {"learn " + board + " --method evaluate --controller controllers/spastic.json --out "
                      "controllers/spastic.json", 1, "is the input --controller controllers/spastic.json"});
  EXPECT_EQ(pinball::testing::slurp(board), kept);
  // The same file spelled two ways: the curve had replaced the controller.
  const CommandResult twice =
      run_shell("cd " + dir_.string() + " && " PINBALL_EXE " learn " PINBALL_SOURCE_DIR
                "/boards/mit1993.board --method tournament --budget-balls 60 --out y.json --curve ./y.json");
  EXPECT_EQ(twice.exit_code, 1);
  EXPECT_NE(twice.err.find("--out and --curve both name y.json"), std::string::npos) << twice.err;
  EXPECT_FALSE(std::filesystem::exists(dir_ / "y.json"));
}

TEST_F(Cli, AnEmptyOutputPathIsRefusedNotTakenAsNone) {
  // An unset shell variable ("--out $OUT") had silently written nothing.
  for (const char* args : {"sim boards/mit1993.board --trace ''", "sim boards/mit1993.board --video ''",
                           "identify boards/mit1993.board --board boards/mit1993.board --out ''",
                           "learn boards/mit1993.board --out ''",
                           "calibrate gravity --sim boards/mit1993.board --out ''",
                           "play --headless --keys 0:launch boards/mit1993.board --csv ''",
                           "bench precision --csv ''", "render boards/mit1993.board --out ''",
                           "view --snapshot ''"}) {
    const CommandResult r = run(args);
    EXPECT_EQ(r.exit_code, 2) << args;
    EXPECT_NE(r.err.find("an empty path names no file to write"), std::string::npos) << args << ": " << r.err;
  }
}

// A flipper ten times as fast as the thesis's: 5 ms, within --dt's range, is too long for them.
TEST_F(Cli, TimeStepThatBreaksTheFlipperConditionIsRefused) {
  const fs::path fast = variant_board(dir_, "-25 30 2000 ", "-25 30 3700 ");  // the left flipper, 65 rad/s
  const CommandResult r = run("sim " + fast.string() + " --dt 0.008");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("l*sin(omega*dt/2)"), std::string::npos) << r.err;
}

// --dt has the board's own range: 1e-12 would never end a ball, 0.3 s jumps through posts.
TEST_F(Cli, TimeStepOutsideTheBoardsRangeIsABadArgument) {
  for (const char* dt : {"1e-9", "0.3"}) {
    const CommandResult r = run(std::string("sim boards/mit1993.board --dt ") + dt);
    EXPECT_EQ(r.exit_code, 2) << dt;
    EXPECT_NE(r.err.find(std::string(dt) + " is not in [1e-06, 0.01]"), std::string::npos) << r.err;
  }
}

// CLI11's own message for a value not in the map read "Check bogus value in {event->,thesis->".
TEST_F(Cli, AnUnknownWorldOrStepperNamesTheChoices) {
  const CommandResult stepper = run("sim boards/mit1993.board --stepper bogus");
  EXPECT_EQ(stepper.exit_code, 2);
  EXPECT_NE(stepper.err.find("--stepper: bogus not in {thesis,event}"), std::string::npos) << stepper.err;
  const CommandResult world = run("bench speed --world bogus");
  EXPECT_EQ(world.exit_code, 2);
  EXPECT_NE(world.err.find("--world: bogus not in {model,twin}"), std::string::npos) << world.err;
}

// In range, but too long for the board's flippers: the message named the board's rule, not --dt.
TEST_F(Cli, ATimeStepTooLongForTheFlippersNamesTheOption) {
  std::string text = slurp(fs::path(PINBALL_SOURCE_DIR) / "boards/mit1993.board");
  for (std::size_t at = text.find(" 76 -25 30 2000"); at != std::string::npos; at = text.find(" 76 -25 30 2000")) {
    text.replace(at, 15, " 76 -25 30 3000");  // strokes of 3000 deg/s sweep 20 mm in 10 ms
  }
  const fs::path board = dir_ / "fast_flippers.board";
  std::ofstream(board) << text;
  ASSERT_EQ(run("sim " + board.string() + " --balls 1 --max-ball-time 1").exit_code, 0);  // at the board's dt
  const CommandResult r = run("sim " + board.string() + " --dt 0.01");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("the time step asked for (--dt 0.01 s) is too long for this board's flippers: flipper "),
            std::string::npos)
      << r.err;
}

TEST_F(Cli, RenderWritesAPng) {
  const fs::path png = dir_ / "board.png";
  const CommandResult r = run("render boards/mit1993.board --out " + png.string() + " --json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_GT(j.at("width_px").get<int>(), 100);
  ASSERT_TRUE(fs::exists(png));
  EXPECT_EQ(slurp(png).substr(1, 3), "PNG");
  // A board under a picture's name, drawn onto itself, had become its own picture, exit 0.
  const fs::path board = dir_ / "board_as.png";
  fs::copy_file(fs::path(PINBALL_SOURCE_DIR) / "boards/mit1993.board", board);
  const CommandResult self = run("render " + board.string() + " --out " + board.string());
  EXPECT_EQ(self.exit_code, 1);
  EXPECT_NE(self.err.find("--out " + board.string() + " is the input board"), std::string::npos) << self.err;
  EXPECT_EQ(slurp(board), slurp(PINBALL_SOURCE_DIR "/boards/mit1993.board"));
}

TEST_F(Cli, VideoRecordsFrames) {
  const fs::path avi = dir_ / "play.avi";
  const CommandResult r = run("sim boards/mit1993.board --balls 1 --max-ball-time 2 --video " + avi.string());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  ASSERT_TRUE(fs::exists(avi));
  EXPECT_GT(fs::file_size(avi), 10'000u);
}

TEST_F(Cli, VideoCanRecordTheSimulatedCamera) {
  const fs::path avi = dir_ / "camera.avi";
  const CommandResult r =
      run("sim boards/mit1993.board --balls 1 --max-ball-time 1 --video-camera --video-fps 100 --video " + avi.string());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  cv::VideoCapture in(avi.string(), cv::CAP_OPENCV_MJPEG);
  ASSERT_TRUE(in.isOpened());
  EXPECT_EQ(static_cast<int>(in.get(cv::CAP_PROP_FRAME_WIDTH)), 640);
  EXPECT_EQ(static_cast<int>(in.get(cv::CAP_PROP_FRAME_HEIGHT)), 480);
  EXPECT_GE(static_cast<int>(in.get(cv::CAP_PROP_FRAME_COUNT)), 50);
}

TEST_F(Cli, BenchSpeedJson) {
  const CommandResult r = run("bench speed --steps 20000 --repeats 1 --json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j.at("runs").size(), 4u);
  EXPECT_TRUE(j.at("grid_matches_linear").get<bool>());
  EXPECT_GT(j.at("grid_speedup").get<double>(), 0.0);
}

TEST_F(Cli, BenchCeilingJsonAndBadBallCount) {
  const CommandResult r = run("bench ceiling --balls 2 --max-ball-time 3 --threads 1 --json --progress");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j.at("benchmark"), "ceiling");
  EXPECT_EQ(j.at("balls"), 2);
  EXPECT_EQ(j.at("max_ball_time_s"), 3.0);
  EXPECT_EQ(j.at("players").size(), 4u) << "ceiling, spastic and no flipping on the true state; spastic through the tracker";
  EXPECT_NE(r.err.find("bench ceiling: ceiling: 2/2 balls (100 %)"), std::string::npos) << r.err;
  EXPECT_EQ(run("bench ceiling --balls 0").exit_code, 2);
}

TEST_F(Cli, BenchCeilingWithThePlannerPlansWithItsSettingsOnTheTrueState) {
  const CommandResult r =
      run("bench ceiling --balls 1 --max-ball-time 2 --threads 1 --controller controllers/planner.json --json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j.at("players").size(), 5u);
  const auto& planner = j.at("planner");
  EXPECT_EQ(planner.at("fire_frames"), 4) << "the file's settings, not the ceiling's own";
  EXPECT_EQ(planner.at("horizon_s"), 0.5);
  EXPECT_EQ(planner.at("step_budget"), 12000);

  const CommandResult fed = run("bench ceiling --balls 1 --max-ball-time 2 --threads 1 --controller "
                                "controllers/planner.json --true-state-noise 0.3 0.005 --json");
  ASSERT_EQ(fed.exit_code, 0) << fed.err;
  const auto k = nlohmann::json::parse(fed.out);
  EXPECT_TRUE(k.at("players").contains("controller_true_state"));
  EXPECT_DOUBLE_EQ(k.at("true_state_feed").at("position_noise_m").get<double>(), 0.0003);
  EXPECT_NE(run("bench ceiling --balls 1 --true-state-noise 0.3 0.005").exit_code, 0) << "no controller to feed";
  EXPECT_NE(run("bench speed --true-state-noise 0.3 0.005").exit_code, 0);
}

TEST_F(Cli, BenchRefusesAFlagTheChosenBenchWouldNotRead) {
  // Each would otherwise run the bench quietly without it: the tracker at 0.3 px, not 1.
  for (const Refusal& refusal :
       {Refusal{"bench tracker --quick --noise-px 1", 1, "--noise-px applies to ceiling and transfer only"},
        Refusal{"bench cradle --quick --latency 0.01", 1, "--latency applies to ceiling and transfer only"},
        Refusal{"bench tracker --quick --world twin", 1, "--world applies to ceiling and cradle only"},
        Refusal{"bench aim --quick --stepper event", 1, "--stepper applies to ceiling and cradle only"},
        Refusal{"bench transfer --quick --world model", 1, "--world applies to ceiling and cradle only"},
        Refusal{"bench aim --balls 1 --max-ball-time 1", 1, "bench aim: no shot to measure in 1 balls"},
        Refusal{"bench speed --quick", 1, "--quick applies to tracker, latency,"},
        Refusal{"bench protocol --balls 3", 1, "--balls applies to"},
        Refusal{"bench latency --seed 3", 1, "--seed applies to"},
        Refusal{"bench detector --threads 1", 1, "--threads applies to ceiling, cradle and transfer only"},
        Refusal{"bench cradle --quick --twin-balls 2", 1, "--twin-balls applies to transfer only"},
        Refusal{"bench tracker --quick --csv x.csv", 1, "--csv applies to precision and transfer only"}}) {
    const CommandResult r = expect_refused("", refusal);
    EXPECT_EQ(count_lines(r.err), 1) << refusal.args << "\n" << r.err;
  }
}

// --quick sets a short run's sizes; a size given on the command line wins over it (the
// protocol bench ran 100000 frames for --frames 1000).
TEST_F(Cli, ASizeGivenWinsOverQuick) {
  const CommandResult r = run("bench protocol --quick --frames 1000 --json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(nlohmann::json::parse(r.out).at("frames").get<int>(), 1000);
}

TEST_F(Cli, BenchLatencyPlaysTheControllerGivenAndRefusesTwo) {
  const CommandResult given = run("bench latency --quick --controller controllers/spastic.json --json");
  ASSERT_EQ(given.exit_code, 0) << given.err;
  const nlohmann::json d = nlohmann::json::parse(given.out).at("daemon");
  EXPECT_EQ(fs::path(d.at("controller").get<std::string>()).filename(), "spastic.json");
  EXPECT_GT(d.at("lockstep").at("frames").get<double>(), 0.0);
  expect_refused("", {"bench latency --quick --controller controllers/spastic.json --controller controllers/best.json", 1,
                      "bench latency: pinballd plays one --controller"});
}

TEST_F(Cli, BenchPrecisionQuickWritesJsonCsvAndPng) {
  const fs::path csv = dir_ / "precision.csv";
  const fs::path png = dir_ / "precision.png";
  const CommandResult r =
      run("bench precision --quick --json --csv " + csv.string() + " --png " + png.string());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j.at("benchmark"), "precision");
  EXPECT_FALSE(j.at("points").empty());
  EXPECT_TRUE(j.at("targets").at("error_target_met").get<bool>()) << j.at("targets").dump();
  EXPECT_TRUE(fs::exists(csv));
  EXPECT_GT(fs::file_size(png), 10'000u);
}

// 40 frames at 200 fps of the ball at `at(t)`, as an observations CSV.
template <class Path>
void write_observations(const fs::path& file, Path at) {
  std::ofstream f(file);
  f << "t,x,y\n";
  for (int i = 0; i < 40; ++i) {
    const double t = i * 0.005;
    const pinball::Vec2 p = at(t);
    f << t << "," << p.x() << "," << p.y() << "\n";
  }
}

TEST_F(Cli, TrackPrintsOneProjectionPerObservation) {
  // A ball falling straight onto the left flipper of the thesis table, seen at 200 fps.
  const fs::path obs = dir_ / "obs.csv";
  write_observations(obs, [](double t) { return pinball::Vec2(0.21, 0.40 - 1.0 * t - 0.5 * 1.11 * t * t); });
  const CommandResult r = run("track --board boards/mit1993.board --observations " + obs.string());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.out.rfind("t,valid,flipper,speed,angle,h,d,t_impact,rolling\n", 0), 0u);
  EXPECT_EQ(count_lines(r.out), 41);
  EXPECT_NE(r.out.find(",1,left,"), std::string::npos) << r.out;

  const CommandResult j = run("track --board boards/mit1993.board --json --observations " + obs.string());
  ASSERT_EQ(j.exit_code, 0) << j.err;
  const auto report = nlohmann::json::parse(j.out);
  ASSERT_EQ(report.at("projections").size(), 40u);
  const auto& last_valid = report.at("projections").at(20);
  EXPECT_TRUE(last_valid.at("valid").get<bool>());
  EXPECT_EQ(last_valid.at("flipper"), "left");
  EXPECT_NEAR(last_valid.at("angle_rad").get<double>(), -1.5707963267948966, 1e-9) << "a vertical fall";
}

TEST_F(Cli, TrackKeepsASkiddingBallsPathAsOnePushedFit) {
  // A ball skidding down the table: 1.5 m/s² of sliding friction besides g.
  const fs::path obs = dir_ / "skid.csv";
  write_observations(obs, [](double t) {
    return pinball::Vec2(0.21 + 0.3 * t, 0.45 - 0.5 * t - 0.5 * (1.11 + 1.5) * t * t);
  });
  const CommandResult j = run("track --board boards/mit1993.board --json --observations " + obs.string());
  ASSERT_EQ(j.exit_code, 0) << j.err;
  const auto report = nlohmann::json::parse(j.out);
  EXPECT_EQ(report.at("collision_flushes"), 0);
  EXPECT_GT(report.at("pushed_fits").get<int>(), 10);
  EXPECT_TRUE(report.at("projections").at(39).at("pushed").get<bool>());
  EXPECT_NE(j.err.find(" pushed fits"), std::string::npos) << j.err;
}

// Two paths 2 s apart: the second is tracked alone (one parabola across the gap named the wrong flipper),
// and a clock since the epoch keeps its microseconds in the CSV.
TEST_F(Cli, TrackStartsANewPathAfterAGap) {
  const fs::path obs = dir_ / "gap.csv";
  {
    std::ofstream f(obs);
    f << std::fixed << std::setprecision(6) << "t,x,y\n";
    const double t0 = 1.7e9;
    for (int i = 0; i < 40; ++i) f << t0 + i * 0.005 << "," << 0.30 - 0.2 * i * 0.005 << "," << 0.45 << "\n";
    for (int i = 0; i < 6; ++i) {
      const double t = 2.2 + i * 0.005;
      f << t0 + t << "," << 0.20 + 0.1 * (t - 2.2) << "," << 0.45 - 0.5 * (t - 2.2) - 0.555 * (t - 2.2) * (t - 2.2)
        << "\n";
    }
  }
  const CommandResult j = run("track --board boards/mit1993.board --json --observations " + obs.string());
  ASSERT_EQ(j.exit_code, 0) << j.err;
  const auto report = nlohmann::json::parse(j.out);
  EXPECT_EQ(report.at("gap_restarts"), 1);
  EXPECT_EQ(report.at("projections").at(41).at("window"), 2) << "the new path's own points only";
  EXPECT_NE(j.err.find(", 1 new paths after a gap"), std::string::npos) << j.err;
  const CommandResult csv = run("track --board boards/mit1993.board --observations " + obs.string());
  ASSERT_EQ(csv.exit_code, 0) << csv.err;
  EXPECT_NE(csv.out.find("\n1700000000.005000,"), std::string::npos) << csv.out.substr(0, 300);
}

TEST_F(Cli, TrackRejectsABadObservationFileNamingTheLine) {
  const fs::path obs = dir_ / "bad.csv";
  std::ofstream(obs) << "t,x,y\n0,0.1,0.2\n0.01,0.1,abc\n";
  const CommandResult r = run("track --board boards/mit1993.board --observations " + obs.string());
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_EQ(count_lines(r.err), 1) << r.err;
  EXPECT_NE(r.err.find(obs.string() + ":3: column 'y'"), std::string::npos) << r.err;
}

// Outputs are checked before the work, and a run refused on its inputs
// leaves no recording behind.
TEST_F(Cli, OutputsAreCheckedFirstAndARefusedRunWritesNothing) {
  const std::string nowhere = (dir_ / "nowhere").string();
  for (const char* option : {"--out", "--curve", "--plot"}) {
    const std::string out = std::string(option) == "--out" ? " " : " --out " + (dir_ / "c.json").string() + " ";
    const CommandResult r = run("learn boards/mit1993.board --method tournament --budget-balls 100 --threads 1" + out +
                                option + " " + nowhere + "/f");
    EXPECT_EQ(r.exit_code, 1) << option;
    EXPECT_NE(r.err.find(std::string(option) + " " + nowhere + "/f: the folder " + nowhere + " does not exist"),
              std::string::npos)
        << r.err;
    EXPECT_EQ(r.err.find("tournament"), std::string::npos) << "no search ran: " << r.err;
  }
  EXPECT_FALSE(fs::exists(dir_ / "c.json"));
  // A picture's name is checked with its folder, before the work.
  const CommandResult jpg = run("learn boards/mit1993.board --method tournament --budget-balls 100 --threads 1 --out " +
                                (dir_ / "c.json").string() + " --plot " + (dir_ / "curve.jpg").string());
  EXPECT_EQ(jpg.exit_code, 1);
  EXPECT_NE(jpg.err.find("--plot " + (dir_ / "curve.jpg").string() + ": a PNG is written"), std::string::npos)
      << jpg.err;
  EXPECT_FALSE(fs::exists(dir_ / "c.json"));
  const CommandResult precision = run("bench precision --quick --csv " + (dir_ / "p.csv").string() + " --png " +
                                      nowhere + "/p.png");
  EXPECT_EQ(precision.exit_code, 1);
  EXPECT_NE(precision.err.find("--png " + nowhere + "/p.png: the folder"), std::string::npos) << precision.err;
  EXPECT_FALSE(fs::exists(dir_ / "p.csv"));
  const CommandResult video = run("sim boards/mit1993.board --balls 1 --trace " + (dir_ / "t.csv").string() +
                                  " --video " + (dir_ / "v.txt").string());
  EXPECT_EQ(video.exit_code, 1);
  EXPECT_NE(video.err.find("--video " + (dir_ / "v.txt").string() + ": an MJPG AVI is written"), std::string::npos)
      << video.err;
  EXPECT_FALSE(fs::exists(dir_ / "t.csv"));
  const fs::path empty = dir_ / "empty.json";
  std::ofstream(empty) << "{}\n";
  const CommandResult sim = run("sim boards/mit1993.board --balls 1 --controller " + empty.string() + " --trace " +
                                (dir_ / "t.csv").string() + " --video " + (dir_ / "v.avi").string());
  EXPECT_EQ(sim.exit_code, 1);
  EXPECT_NE(sim.err.find("format: missing"), std::string::npos) << sim.err;
  EXPECT_FALSE(fs::exists(dir_ / "t.csv"));
  EXPECT_FALSE(fs::exists(dir_ / "v.avi"));
}

// A board named in Latin-1 (caf\xe9.board) ended every --json report with nlohmann's type_error.316 and exit
// 1, after the run and its files: the report now carries U+FFFD for the bad byte.
TEST_F(Cli, AFileNameThatIsNotUtf8StillGivesTheJsonReport) {
  const fs::path board = dir_ / "caf\xe9.board";
  fs::copy_file(fs::path(PINBALL_SOURCE_DIR) / "boards/mit1993.board", board);
  const std::string png = (dir_ / "r.png").string();
  const CommandResult render = run("render '" + board.string() + "' --out " + png + " --json");
  ASSERT_EQ(render.exit_code, 0) << render.err;
  EXPECT_EQ(nlohmann::json::parse(render.out).at("board"), (dir_ / "caf\xef\xbf\xbd.board").string());
  const CommandResult sim = run("sim '" + board.string() + "' --balls 1 --max-ball-time 2 --json");
  ASSERT_EQ(sim.exit_code, 0) << sim.err;
  EXPECT_EQ(nlohmann::json::parse(sim.out).at("balls"), 1);
}

// What a whole-file output cannot become is found before the work too: a device (the rename
// would replace it), a folder that takes no file, two outputs on one file.
TEST_F(Cli, OutputsThatCannotBeWrittenWholeAreRefusedFirst) {
  const std::string learn = "learn boards/mit1993.board --method tournament --budget-balls 100 --threads 1 ";
  const std::string out = (dir_ / "c.json").string();
  const struct {
    std::string args;
    std::string says;
  } cases[] = {
      {"--out /dev/null", "--out /dev/null: is not a regular file"},
      {"--out /proc/c.json", "--out /proc/c.json: cannot write in /proc (its file system takes no new files)"},
      {"--out " + out + " --curve " + out, "--out and --curve both name " + out},
      {"--out " + out + " --checkpoint " + out, "--out and --checkpoint both name " + out},
      {"--out " + out + " --curve " + out + ".cycle.json", "--curve and --out's cycle file both name"},
      {"--out " + out + " --curve /dev/full", "--curve /dev/full: is not a regular file"},
  };
  for (const auto& c : cases) {
    const CommandResult r = run(learn + c.args);
    EXPECT_EQ(r.exit_code, 1) << c.args;
    EXPECT_NE(r.err.find(c.says), std::string::npos) << c.args << "\n" << r.err;
    EXPECT_EQ(r.err.find("tournament"), std::string::npos) << "no search ran: " << r.err;
  }
  EXPECT_FALSE(fs::exists(out));
  // A trace is streamed, not renamed into place: a pipe or a device is its reader's business.
  EXPECT_EQ(run("sim boards/mit1993.board --balls 1 --max-ball-time 1 --trace /dev/null").exit_code, 0);
}

// A device given as an input would be read for ever (/dev/zero: found filling 24 GB of memory):
// refused at the parse, naming the option.
TEST_F(Cli, ADeviceIsNoInputFile) {
  for (const std::string& args : {std::string("sim /dev/zero"), std::string("render /dev/zero --out x.png"),
                                  std::string("learn boards/mit1993.board --method evaluate --controller /dev/zero"),
                                  std::string("play --stats /dev/zero"), std::string("replay /dev/zero")}) {
    const CommandResult r = run(args);
    EXPECT_EQ(r.exit_code, 2) << args;
    EXPECT_NE(r.err.find("/dev/zero is a device, not a file"), std::string::npos) << args << "\n" << r.err;
  }
  const CommandResult keys = run("play boards/mit1993.board --headless --keys /dev/zero --balls 1");
  EXPECT_EQ(keys.exit_code, 1);
  EXPECT_NE(keys.err.find("--keys /dev/zero is a device, not a file"), std::string::npos) << keys.err;
  const CommandResult csv = run("play boards/mit1993.board --headless --keys 0.1:launch --balls 1 --csv /dev/full");
  EXPECT_EQ(csv.exit_code, 1);
  EXPECT_NE(csv.err.find("/dev/full: is not a regular file"), std::string::npos) << csv.err;
}

// A search resumed from a checkpoint that holds it whole played no ball: no rate made up from
// the balls it read (it had said 88 balls/s for a search that ran at 62). A checkpoint that is
// a folder is named as one.
TEST_F(Cli, AResumedSearchRatesOnlyTheBallsItPlayed) {
  const std::string ckpt = (dir_ / "t.ckpt").string();
  const std::string learn = "learn boards/mit1993.board --method tournament --budget-balls 60 --eval-balls 0 --out " +
                            (dir_ / "t.json").string() + " --checkpoint " + ckpt + " --json";
  const CommandResult first = run(learn);
  ASSERT_EQ(first.exit_code, 0) << first.err;
  EXPECT_GT(nlohmann::json::parse(first.out).at("search_balls_per_s").get<double>(), 0.0);
  const CommandResult again = run(learn + " --resume");
  ASSERT_EQ(again.exit_code, 0) << again.err;
  EXPECT_TRUE(nlohmann::json::parse(again.out).at("search_balls_per_s").is_null()) << again.out;
  const CommandResult folder = run("learn boards/mit1993.board --method tournament --budget-balls 60 --out " +
                                   (dir_ / "f.json").string() + " --checkpoint " + dir_.string());
  EXPECT_EQ(folder.exit_code, 1);
  EXPECT_NE(folder.err.find("--checkpoint " + dir_.string() + ": is a folder, not a file"), std::string::npos)
      << folder.err;
}

// A method refuses the options it would not read: launcher wrote none of its --out, --curve
// or --checkpoint and exited 0; shot-values kept no checkpoint.
TEST_F(Cli, LearnMethodsRefuseOptionsTheyDoNotRead) {
  for (const auto& [args, says] : std::vector<std::pair<std::string, std::string>>{
           {"--method launcher --out l.json", "--method launcher does not read --out"},
           {"--method launcher --checkpoint l.ckpt", "--method launcher does not read --checkpoint"},
           {"--method shot-values --out sv.yaml --curve sv.csv", "--method shot-values does not read --curve"},
           {"--method shot-values --out sv.yaml --checkpoint sv.ckpt",
            "--method shot-values does not read --checkpoint"},
           // Had exited 0: nothing written, the option's world or setting not played.
           {"--method evaluate --controller controllers/spastic.json --curve c.csv",
            "learn evaluate: --curve applies to tournament, relay, cem and imitate only"},
           {"--method launcher --randomize config/randomize.yaml",
            "learn launcher: --randomize applies to tournament, relay, cem and imitate only"},
           {"--method launcher --threads 2", "learn launcher: --threads applies to"},
           {"--method tournament --population 40 --out t.json",
            "learn tournament: --population applies to relay and cem only"},
           {"--method shot-values --out sv.yaml --eval-balls 5", "learn shot-values: --eval-balls applies to"},
           {"--method none --rounds 3", "learn none: --rounds applies to imitate only"},
           // Ran as if not given: evaluate plays the file's own launch, and only the relay credits a lost ball.
           {"--method evaluate --controller controllers/best.json --pull 0.5",
            "learn evaluate: --pull applies to tournament, relay, cem, imitate, none, spastic and shot-values only"},
           {"--method cem --loss-penalty 5 --out c.json", "learn cem: --loss-penalty applies to relay only"},
       }) {
    const CommandResult r = run("learn boards/mit1993.board " + args);
    EXPECT_EQ(r.exit_code, 1) << args;
    EXPECT_NE(r.err.find(says), std::string::npos) << args << "\n" << r.err;
  }
}

// Every ball cut at a limit of 1 ms scored 0, and the text said nothing of it (the JSON did).
TEST_F(Cli, LearnSaysWhenTheBallsItEvaluatedWereCut) {
  const CommandResult r = run("learn boards/mit1993.board --method evaluate --controller controllers/best.json "
                              "--eval-balls 3 --max-ball-time 0.001");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("3 of 3 balls cut at --max-ball-time 0.001 s"), std::string::npos) << r.out;
}

// A budget the seed search spends whole leaves no generation: refused, not an
// untrained controller written as if learned.
TEST_F(Cli, LearnWithABudgetTooSmallForOneGenerationWritesNothing) {
  const std::string out = (dir_ / "small.json").string();
  const CommandResult r = run("learn boards/mit1993.board --method cem --budget-balls 40 --threads 1 --out " + out);
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("learn: --budget-balls 40 ran out before the first cem generation"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("a generation needs "), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(out));
}

// A method that only plays refuses what it would drop: an --out it would not
// write, and --eval-balls 0, which left it 1000 balls (0 read as not given).
TEST_F(Cli, LearnMethodsThatOnlyPlayRefuseWhatTheyWouldDrop) {
  const std::string out = (dir_ / "sp.json").string();
  CommandResult r = run("learn boards/mit1993.board --method spastic --out " + out);
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("--method spastic writes no controller"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(out));
  r = run("learn boards/mit1993.board --method none --eval-balls 0");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("--eval-balls 0 leaves --method none nothing to do"), std::string::npos) << r.err;
  r = run("learn boards/mit1993.board --method none --eval-balls 2 --threads 1 --json --progress");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(nlohmann::json::parse(r.out).at("evaluation").at("balls").get<int>(), 2);
  // The evaluation shows its progress (it printed none: a planner's takes minutes).
  EXPECT_NE(r.err.find("learn evaluation: 2/2 balls (100 %)"), std::string::npos) << r.err;
}

TEST_F(Cli, HelpShowsEveryDefault) {
  const CommandResult sim = run("sim --help");
  ASSERT_EQ(sim.exit_code, 0) << sim.err;
  // CLI11 2.1 writes a default after '=' ("--max-ball-time FLOAT:> 0=300").
  EXPECT_NE(sim.out.find("=300\n"), std::string::npos) << "--max-ball-time's default\n" << sim.out;
  EXPECT_NE(sim.out.find("=0.02\n"), std::string::npos) << "--reach's default\n" << sim.out;
  EXPECT_NE(sim.out.find("--stepper {thesis,event}=thesis"), std::string::npos) << sim.out;
  EXPECT_EQ(sim.out.find("> 0=0 "), std::string::npos) << "a sentinel (0: the board's) is not a default\n"
                                                            << sim.out;
  const CommandResult learn = run("learn --help");
  EXPECT_NE(learn.out.find("=2000"), std::string::npos) << "--budget-balls' default\n" << learn.out;
  const CommandResult bench = run("bench --help");
  EXPECT_NE(bench.out.find("=boards/mit1993.board"), std::string::npos) << "--board's default\n" << bench.out;
  // A -1 sentinel outside its own range is no default a user could pass.
  for (const char* command : {"sim", "learn", "bench", "track", "calibrate", "view", "play", "identify", "replay"}) {
    const CommandResult help = run(std::string(command) + " --help");
    EXPECT_EQ(help.out.find("]=-1"), std::string::npos) << command << "\n" << help.out;
  }
}

TEST_F(Cli, FindsTheShippedBoardsAndControllersFromAnyFolder) {
  ASSERT_FALSE(fs::exists(dir_ / "boards"));
  const CommandResult r = run_in(dir_, "sim boards/mit1993.board --controller controllers/best.json --balls 1 "
                                         "--max-ball-time 2 --json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(fs::path(j.at("board").get<std::string>()), fs::path(PINBALL_SOURCE_DIR) / "boards/mit1993.board");
  EXPECT_EQ(fs::path(j.at("controller").get<std::string>()), fs::path(PINBALL_SOURCE_DIR) / "controllers/best.json");
  // bench's default --board too.
  EXPECT_EQ(run_in(dir_, "bench ceiling --balls 1 --max-ball-time 2 --threads 1 --json").exit_code, 0);
  // The shipped overlay and randomization files too.
  const CommandResult overlay = run_in(dir_, "sim boards/mit1993.board --identified config/twin.identified.yaml "
                                             "--balls 1 --max-ball-time 2");
  EXPECT_EQ(overlay.exit_code, 0) << overlay.err;
  // (found: the refusal is the method's, after the parse)
  const CommandResult drawn =
      run_in(dir_, "learn boards/mit1993.board --method spastic --randomize config/randomize.yaml");
  EXPECT_NE(drawn.err.find("--randomize applies to tournament, relay, cem and imitate only"), std::string::npos)
      << drawn.err;
  // A board found nowhere is still refused, naming what was typed.
  const CommandResult missing = run_in(dir_, "sim boards/no_such.board");
  EXPECT_EQ(missing.exit_code, 2);
  EXPECT_NE(missing.err.find("boards/no_such.board"), std::string::npos) << missing.err;
}

TEST_F(Cli, ProgressOnlyWhenAskedOrOnATerminal) {
  // stderr here is a file, not a terminal: no progress unless --progress.
  const CommandResult quiet = run("sim boards/mit1993.board --balls 2 --max-ball-time 2 --json");
  ASSERT_EQ(quiet.exit_code, 0) << quiet.err;
  EXPECT_EQ(quiet.err.find("balls ("), std::string::npos) << quiet.err;
  const CommandResult shown = run("sim boards/mit1993.board --balls 2 --max-ball-time 2 --json --progress");
  EXPECT_NE(shown.err.find("sim: 2/2 balls (100 %)"), std::string::npos) << shown.err;
  EXPECT_TRUE(nlohmann::json::accept(shown.out)) << "stdout stays one JSON object";
}

TEST_F(Cli, TextReportsRoundTheirNumbers) {
  const CommandResult r = run("sim boards/mit1993.board --policy spastic --balls 4 --seed 3 --max-ball-time 5");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find(" ± "), std::string::npos) << r.out;
  // No decimal number with more than 4 significant digits (a raw double prints 6, or 17).
  const std::regex decimal(R"((\d+)\.(\d+))");
  for (auto it = std::sregex_iterator(r.out.begin(), r.out.end(), decimal); it != std::sregex_iterator(); ++it) {
    const std::string digits = (*it)[1].str() + (*it)[2].str();
    const std::size_t first = digits.find_first_not_of('0');
    EXPECT_LE(first == std::string::npos ? 0 : digits.size() - first, 4u) << it->str() << " in\n" << r.out;
  }
  const auto j = nlohmann::json::parse(run("sim boards/mit1993.board --policy spastic --balls 4 --seed 3 "
                                           "--max-ball-time 5 --json").out);
  const double half = j.at("score_ci95_half_width").get<double>();
  EXPECT_NE(half * 1e4, std::round(half * 1e4)) << "JSON keeps full precision: " << half;
}

}  // namespace
