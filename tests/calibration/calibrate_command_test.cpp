// `pinball calibrate` as the lab runs it: JSON on stdout, the file written and
// updated section by section, and `pinball track --calibration` reading it.

#include <filesystem>
#include <fstream>
#include <regex>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <opencv2/imgcodecs.hpp>

#include "common/command_test.h"
#include "pinball/calibration/calibration_file.h"
#include "pinball/calibration/intrinsics_calibration.h"
#include "pinball/core/rng.h"
#include "pinball/simlab/sim_target_view.h"
#include "pinball/table/board_loader.h"
#include "pinball/vision/camera_homography.h"

namespace {

namespace fs = std::filesystem;

using Result = pinball::testing::CommandResult;

class Calibrate : public pinball::testing::CommandTest {};

TEST_F(Calibrate, SimulatedLabEndToEnd) {
  const std::string file = (dir_ / "lab.yaml").string();
  const std::string png = (dir_ / "camera.png").string();
  Result r = run("calibrate camera --sim boards/mit1993.board --out " + file + " --png " + png + " --json");
  ASSERT_EQ(r.exit_code, 0);
  nlohmann::json j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j.at("camera").at("markers_used"), 7);
  // Every figure the file holds is in the JSON too: the homography and the image it was measured on.
  EXPECT_EQ(j.at("camera").at("image_width_px"), 640);
  EXPECT_EQ(j.at("camera").at("image_from_board").size(), 3u);
  EXPECT_EQ(j.at("camera").at("markers_detected"), 7);
  EXPECT_EQ(j.at("camera").at("markers_in_layout"), 7);  // as the text says on stderr
  EXPECT_LT(j.at("camera").at("truth").at("homography_max_error_mm").get<double>(), 1.0);
  EXPECT_TRUE(fs::exists(png));

  r = run("calibrate flippers --sim boards/mit1993.board --out " + file + " --json");
  ASSERT_EQ(r.exit_code, 0);
  j = nlohmann::json::parse(r.out);
  ASSERT_EQ(j.at("flippers").size(), 2u);
  EXPECT_EQ(j.at("markers_seen").at("down"), 4);  // each flipper's pivot and tip
  EXPECT_EQ(j.at("markers_seen").at("up"), 4);
  for (const auto& f : j.at("flippers")) {
    EXPECT_LT(f.at("markers").at("truth").at("pivot_error_mm").get<double>(), 1.0);
    EXPECT_TRUE(f.contains("markerless"));
    EXPECT_TRUE(f.contains("disagreement"));
  }
  // The text gives both methods too, as calibration.md says: it had printed the written one alone.
  EXPECT_NE(r.err.find("left_flipper (markers, written): pivot"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("left_flipper (markerless, not written): pivot"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("left_flipper methods disagree by: pivot"), std::string::npos) << r.err;

  r = run("calibrate gravity --sim boards/mit1993.board --sim-rolls 3 --out " + file + " --json");
  ASSERT_EQ(r.exit_code, 0);
  j = nlohmann::json::parse(r.out);
  EXPECT_NEAR(j.at("gravity").at("g_mps2").get<double>(), 1.11, 0.011);
  EXPECT_EQ(j.at("gravity").at("rolls_used"), 3);

  // The practice machine is the board file's: what the calibration finds is
  // what pinballd's simulated table has (it was 3.6 mm off by default).
  const pinball::calibration::Calibration practice = pinball::calibration::read_calibration(file);
  const pinball::table::Board board = pinball::table::load_board(std::string(PINBALL_SOURCE_DIR) + "/boards/mit1993.board");
  // So does the shipped example (config/lab.example.yaml's calibration), which
  // these commands wrote: it lagged behind the old mounting error once.
  const pinball::calibration::Calibration example =
      pinball::calibration::read_calibration(std::string(PINBALL_SOURCE_DIR) + "/calibration/lab.example.yaml");
  ASSERT_EQ(practice.flippers.size(), board.flippers.size());
  ASSERT_EQ(example.flippers.size(), board.flippers.size());
  for (std::size_t i = 0; i < board.flippers.size(); ++i) {
    for (const pinball::calibration::Calibration* c : {&practice, &example}) {
      EXPECT_LT((c->flippers[i].pivot_m - board.flippers[i].pivot).norm(), 0.001) << "flipper " << i;
      EXPECT_NEAR(c->flippers[i].length_m, board.flippers[i].length_m, 0.001) << "flipper " << i;
    }
  }

  // Every section survived the updates.
  const pinball::calibration::Calibration c = pinball::calibration::read_calibration(file);
  EXPECT_TRUE(c.camera);
  EXPECT_EQ(c.flippers.size(), 2u);
  EXPECT_TRUE(c.gravity);

  // The tracker reads it.
  const std::string csv = (dir_ / "obs.csv").string();
  std::ofstream(csv) << "t,x,y\n0,0.2,0.6\n0.005,0.2,0.599\n0.01,0.2,0.598\n";
  r = run("track --board boards/mit1993.board --observations " + csv + " --calibration " + file + " --json");
  ASSERT_EQ(r.exit_code, 0);
  j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j.at("gravity_mps2").get<double>(), c.gravity->g_mps2);
}

// Flipper pictures resized to 660x495 placed the pivots 10-15 mm off, and the file still said 640x480.
TEST_F(Calibrate, FlipperPicturesOfAnotherSizeThanTheCamerasAreRefused) {
  const std::string file = (dir_ / "lab.yaml").string();
  ASSERT_EQ(run("calibrate camera --sim boards/mit1993.board --out " + file).exit_code, 0);
  const std::string kept = pinball::testing::slurp(file);
  const std::string other_size = (dir_ / "board.png").string();  // any picture that is not 640x480
  ASSERT_EQ(run("render boards/mit1993.board --out " + other_size).exit_code, 0);
  const Result r = run("calibrate flippers --board boards/mit1993.board --down " + other_size + " --up " + other_size +
                       " --out " + file);
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("calibrate flippers: --down " + other_size + " is "), std::string::npos) << r.err;
  EXPECT_NE(r.err.find(", but " + file + "'s camera section was measured on 640x480 images"), std::string::npos)
      << r.err;
  EXPECT_EQ(pinball::testing::slurp(file), kept);
  // A sweep video is the camera's too: named, by option and path.
  const std::string v1 = (dir_ / "a.avi").string(), v2 = (dir_ / "b.avi").string();
  ASSERT_EQ(run("sim boards/mit1993.board --balls 1 --max-ball-time 0.2 --seed 1 --video " + v1).exit_code, 0);
  ASSERT_EQ(run("sim boards/mit1993.board --balls 1 --max-ball-time 0.2 --seed 2 --video " + v2).exit_code, 0);
  const Result sweep = run("calibrate flippers --board boards/mit1993.board --sweep " + v1 + " --sweep " + v2 +
                           " --calibration " + file);
  EXPECT_EQ(sweep.exit_code, 1);
  EXPECT_NE(sweep.err.find("calibrate flippers: --sweep " + v1 + " is "), std::string::npos) << sweep.err;
  EXPECT_NE(sweep.err.find("camera section was measured on 640x480 images"), std::string::npos) << sweep.err;
}

// A gravity measured on another table was applied without a word (track: g 2.5 from another board's file).
TEST_F(Calibrate, ACalibrationOfAnotherBoardIsRefusedWhereItIsRead) {
  const std::string table = (dir_ / "other_table.board").string();  // the thesis table with one post moved
  std::string text = pinball::testing::slurp(std::string(PINBALL_SOURCE_DIR) + "/boards/mit1993.board");
  text += "\ncircle 255 600 5 name=extra_post\n";
  std::ofstream(table) << text;
  const std::string other = (dir_ / "other.yaml").string();
  ASSERT_EQ(run("calibrate gravity --sim " + table + " --sim-rolls 2 --out " + other).exit_code, 0);
  const std::string csv = (dir_ / "obs.csv").string();
  std::ofstream(csv) << "t,x,y\n0,0.2,0.6\n0.005,0.2,0.599\n0.01,0.2,0.598\n";
  const Result r = run("track --board boards/mit1993.board --observations " + csv + " --calibration " + other);
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find(other + ":board: is " + table + ", not the board boards/mit1993.board: a calibration of "
                                                        "another table"),
            std::string::npos)
      << r.err;
  // Its own board, or a copy of that board's file, reads it.
  EXPECT_EQ(run("track --board " + table + " --observations " + csv + " --calibration " + other).exit_code, 0);
  const std::string copy = (dir_ / "other_table_copy.board").string();
  fs::copy_file(table, copy);
  EXPECT_EQ(run("track --board " + copy + " --observations " + csv + " --calibration " + other).exit_code, 0);
}

TEST_F(Calibrate, BadInputsExitWithOne) {
  EXPECT_EQ(run("calibrate camera --board boards/mit1993.board").exit_code, 1);  // no image
  EXPECT_EQ(run("calibrate wobble --sim boards/mit1993.board").exit_code, 2);
  const std::string bad = (dir_ / "bad.yaml").string();
  std::ofstream(bad) << "version: 1\nboard: x\n";
  EXPECT_EQ(run("calibrate flippers --board boards/mit1993.board --down " + bad + " --up " + bad +
                " --calibration " + bad)
                .exit_code,
            1);
  // Flippers before the camera: said so, not "cannot open".
  const std::string first = (dir_ / "first.yaml").string();
  const Result no_camera = run("calibrate flippers --board boards/mit1993.board --down " + bad + " --up " + bad +
                               " --out " + first);
  EXPECT_EQ(no_camera.exit_code, 1);
  EXPECT_NE(no_camera.err.find("run `calibrate camera --out " + first + "` first"), std::string::npos)
      << no_camera.err;
  // Updating a file of another board renamed it to this board and kept the other's sections.
  const std::string other = (dir_ / "other.yaml").string();
  ASSERT_EQ(run("calibrate gravity --sim boards/mit1993.board --sim-rolls 2 --out " + other).exit_code, 0);
  const std::string kept = pinball::testing::slurp(other);
  const Result foreign = run("calibrate gravity --sim boards/scenes/box.board --sim-rolls 2 --out " + other);
  EXPECT_EQ(foreign.exit_code, 1);
  EXPECT_NE(foreign.err.find("--out " + other + " is a calibration of boards/mit1993.board, not of "
                                                 "boards/scenes/box.board"),
            std::string::npos)
      << foreign.err;
  EXPECT_EQ(pinball::testing::slurp(other), kept);
  // One roll given twice counted twice and narrowed the interval to nothing.
  const std::string roll = (dir_ / "roll.csv").string();
  std::ofstream(roll) << "t,x,y\n0,0.2,0.9\n";
  const Result twice = run("calibrate gravity --board boards/mit1993.board --roll " + roll + " --roll " + roll);
  EXPECT_EQ(twice.exit_code, 1);
  EXPECT_NE(twice.err.find("calibrate gravity: --roll " + roll + " is given twice: one roll would count twice"),
            std::string::npos)
      << twice.err;
  // So did a copy of it under another name (g "1.11322 [1.11322, 1.11322]" from one roll copied five times).
  const std::string copy = (dir_ / "roll_copy.csv").string();
  fs::copy_file(roll, copy);
  const Result copied = run("calibrate gravity --board boards/mit1993.board --roll " + roll + " --roll " + copy);
  EXPECT_EQ(copied.exit_code, 1);
  EXPECT_NE(copied.err.find("calibrate gravity: --roll " + copy + " is a copy of " + roll +
                            ": one roll would count twice"),
            std::string::npos)
      << copied.err;
}

// A flag the kind (or the simulation) would not read is refused, not ignored.
TEST_F(Calibrate, AFlagTheKindDoesNotReadIsRefused) {
  const Result rolls = run("calibrate latency --sim boards/mit1993.board --sim-rolls 9");
  EXPECT_EQ(rolls.exit_code, 1);
  EXPECT_NE(rolls.err.find("calibrate latency: --sim-rolls applies to gravity only"), std::string::npos) << rolls.err;
  const Result fps = run("calibrate gravity --sim boards/mit1993.board --fps 60");
  EXPECT_EQ(fps.exit_code, 1);
  EXPECT_NE(fps.err.find("calibrate gravity: --fps applies to latency only"), std::string::npos) << fps.err;
  const Result progress = run("calibrate gravity --sim boards/mit1993.board --progress");
  EXPECT_EQ(progress.exit_code, 1);
  EXPECT_NE(progress.err.find("calibrate gravity: --progress applies to intrinsics only"), std::string::npos)
      << progress.err;
  const Result png = run("calibrate latency --sim boards/mit1993.board --png " + (dir_ / "x.png").string());
  EXPECT_NE(png.err.find("--png applies to intrinsics, camera, flippers and gravity only"), std::string::npos)
      << png.err;
  // The simulation makes its own images, rolls and hardware.
  const std::string roll = (dir_ / "roll.csv").string();
  std::ofstream(roll) << "t,x,y\n0,0.2,0.9\n";
  const Result lab_input = run("calibrate gravity --sim boards/mit1993.board --roll " + roll);
  EXPECT_EQ(lab_input.exit_code, 2);
  EXPECT_NE(lab_input.err.find("--sim excludes --roll"), std::string::npos) << lab_input.err;
  // ... and only the simulation reads a seed or a number of rolls: in the lab they ran as if not given.
  for (const char* sim_only : {"--seed 5", "--sim-rolls 3"}) {
    const Result lab = run("calibrate gravity --board boards/mit1993.board --roll " + roll + " " + sim_only);
    EXPECT_EQ(lab.exit_code, 2) << sim_only;
    EXPECT_NE(lab.err.find("requires --sim"), std::string::npos) << lab.err;
  }
  // --method chooses what is written when both methods ran: one that did not run wrote the other.
  const Result method = run("calibrate flippers --board boards/mit1993.board --down " + roll + " --up " + roll +
                            " --method markerless --calibration " + roll);
  EXPECT_EQ(method.exit_code, 1);
  EXPECT_NE(method.err.find("calibrate flippers: --method markerless needs --sweep videos, which were not given"),
            std::string::npos)
      << method.err;
  // Printing the target is all such a run does: images, a file or a picture beside it were ignored.
  const std::string target = (dir_ / "target.png").string();
  for (const std::string& beside : {"--out " + (dir_ / "c.yaml").string(), "--images " + dir_.string(),
                                    std::string("--sim boards/mit1993.board")}) {
    const Result both = run("calibrate intrinsics --print-target " + target + " " + beside);
    EXPECT_EQ(both.exit_code, 2) << beside;
    EXPECT_NE(both.err.find("--print-target"), std::string::npos) << both.err;
  }
  EXPECT_FALSE(fs::exists(target));
}

// 1000 us a row: 480 ms to read out a frame of a camera at 200 frames/s, which wrote latency_s 0.214, exit 0.
TEST_F(Calibrate, ALineTimeLongerThanAFrameIsRefusedBeforeAnyWork) {
  const Result r = run("calibrate latency --sim boards/mit1993.board --events 3 --row-time-us 1000");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("--row-time-us 1000: 480 rows take 480 ms to read out, longer than a frame at --fps 200 (5 ms): "
                       "the line time is at most 10.4 us"),
            std::string::npos)
      << r.err;
  EXPECT_EQ(r.err.find("simulating"), std::string::npos) << r.err;
}

// Messages in the simulation's and the target image's own words ("spacing_s must leave ...",
// "choose another px_per_m"), of settings no option sets.
TEST_F(Calibrate, ALongDelayRunsAndAHugeTargetIsSaidInTheOptionsGiven) {
  const Result slow = run("calibrate latency --sim boards/mit1993.board --events 3 --actuation-delay-ms 100");
  EXPECT_EQ(slow.exit_code, 0) << slow.err;
  const Result huge = run("calibrate intrinsics --print-target " + (dir_ / "t.png").string() +
                          " --target chessboard:100x100:1");
  EXPECT_EQ(huge.exit_code, 1);
  EXPECT_NE(huge.err.find("--target chessboard:100x100:1 printed at 10 px/mm: "), std::string::npos) << huge.err;
  EXPECT_NE(huge.err.find("print a target of fewer or smaller squares"), std::string::npos) << huge.err;
  EXPECT_EQ(huge.err.find("px_per_m"), std::string::npos) << huge.err;
}

// Two outputs on one file: the figure was lost under the YAML, exit 0.
TEST_F(Calibrate, TwoOutputsOnOneFileAreRefused) {
  const std::string same = (dir_ / "same.png").string();
  const Result r = run("calibrate gravity --sim boards/mit1993.board --out " + same + " --png " + same);
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("--out and --png both name " + same), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(same));
}

// What is written at the end is checked before any work: in the lab,
// `latency` would otherwise fire the flipper twenty times and then fail.
TEST_F(Calibrate, AnOutputThatCannotBeWrittenIsRefusedBeforeAnyWork) {
  const std::string nowhere = (dir_ / "nowhere" / "o.yaml").string();
  Result r = run("calibrate latency --sim boards/mit1993.board --events 3 --out " + nowhere);
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("--out " + nowhere + ": the folder " + (dir_ / "nowhere").string() + " does not exist"),
            std::string::npos)
      << r.err;
  EXPECT_EQ(r.err.find("simulating"), std::string::npos) << "nothing was simulated first: " << r.err;
  r = run("calibrate gravity --sim boards/mit1993.board --out " + dir_.string());
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("--out " + dir_.string() + ": is a folder, not a file"), std::string::npos) << r.err;
  r = run("calibrate camera --sim boards/mit1993.board --png " + nowhere + ".png");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("--png " + nowhere + ".png: the folder"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir_ / "nowhere"));
}

// One roll gives a number and an interval from that roll's fit alone: said.
TEST_F(Calibrate, GravityFromOneRollSaysItsIntervalIsThatRollsFit) {
  Result r = run("calibrate gravity --sim boards/mit1993.board --sim-rolls 1 --json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j.at("gravity").at("rolls_used"), 1);
  EXPECT_NE(j.at("gravity").at("warning").get<std::string>().find("one roll used"), std::string::npos);
  EXPECT_NE(r.err.find("warning: one roll used"), std::string::npos) << r.err;
  r = run("calibrate gravity --sim boards/mit1993.board --sim-rolls 3 --json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_FALSE(nlohmann::json::parse(r.out).at("gravity").contains("warning"));
}

// A mounting error is there when asked for, and the calibration finds it.
TEST_F(Calibrate, TheSimulatedMachineIsMountedOffOnlyWhenAsked) {
  const std::string file = (dir_ / "off.yaml").string();
  Result r = run("calibrate camera --sim boards/mit1993.board --out " + file + " --json");
  ASSERT_EQ(r.exit_code, 0);
  r = run("calibrate flippers --sim boards/mit1993.board --sim-pivot-offset-mm 3 -2 --sim-length-offset-mm 2 "
          "--sim-theta-offset-deg 0.7 --out " + file + " --json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j.at("sim_mounting_error").at("pivot_offset_mm"), nlohmann::json::array({3.0, -2.0}));
  const pinball::calibration::Calibration c = pinball::calibration::read_calibration(file);
  const pinball::table::Board board = pinball::table::load_board(std::string(PINBALL_SOURCE_DIR) + "/boards/mit1993.board");
  for (std::size_t i = 0; i < board.flippers.size(); ++i) {
    const pinball::Vec2 moved = c.flippers[i].pivot_m - board.flippers[i].pivot;
    EXPECT_NEAR(moved.x(), 0.003, 0.001) << "flipper " << i;
    EXPECT_NEAR(moved.y(), -0.002, 0.001) << "flipper " << i;
  }
  EXPECT_EQ(run("calibrate flippers --board boards/mit1993.board --sim-length-offset-mm 2").exit_code, 2);  // needs --sim
}

// The lab's file before the latency is measured: camera and flippers as the
// board file and the simulated camera's default view have them, and gravity.
pinball::calibration::Calibration lab_file() {
  namespace cal = pinball::calibration;
  const pinball::table::Board board = pinball::table::load_board(std::string(PINBALL_SOURCE_DIR) + "/boards/mit1993.board");
  cal::Calibration c;
  c.board = "boards/mit1993.board";
  cal::CameraCalibration camera;
  camera.image_from_board = pinball::vision::CameraHomography::default_view(board, {640, 480}).image_from_board_matrix();
  camera.image_width_px = 640;
  camera.image_height_px = 480;
  camera.markers_used = 7;
  c.camera = camera;
  for (const pinball::table::Flipper& f : board.flippers) {
    cal::FlipperCalibration fc;
    fc.name = f.name;
    fc.side = f.side;
    fc.pivot_m = f.pivot;
    fc.tip_m = pinball::table::flipper_tip(f, f.theta_min_rad);
    fc.length_m = f.length_m;
    fc.theta_min_rad = f.theta_min_rad;
    fc.theta_max_rad = f.theta_max_rad;
    c.flippers.push_back(fc);
  }
  cal::GravityEstimate g;
  g.g_mps2 = 1.11;
  g.ci_low_mps2 = 1.10;
  g.ci_high_mps2 = 1.12;
  g.rolls_used = 5;
  c.gravity = g;
  return c;
}

// `calibrate latency --sim`: the simulated typical camera's 7 ms are found,
// the camera_timing section is written and the others are kept.
TEST_F(Calibrate, LatencyOnTheSimulatedCameraWritesTheTimingAndKeepsTheRest) {
  const std::string file = (dir_ / "lab.yaml").string();
  pinball::calibration::write_calibration(lab_file(), file);
  Result r = run("calibrate latency --sim boards/mit1993.board --events 8 --out " + file + " --json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  nlohmann::json j = nlohmann::json::parse(r.out);
  const nlohmann::json& l = j.at("latency");
  EXPECT_EQ(l.at("events").size(), 8u);
  EXPECT_GE(l.at("events_used").get<int>(), 7);
  EXPECT_EQ(l.at("truth").at("latency_ms").get<double>(), 7.0);
  EXPECT_LT(std::abs(l.at("truth").at("error_ms").get<double>()), 0.5);
  EXPECT_NEAR(l.at("row_time_us").get<double>(), 10.0, 1e-9);
  EXPECT_EQ(l.at("flipper"), "left_flipper");
  const pinball::calibration::Calibration c = pinball::calibration::read_calibration(file);
  ASSERT_TRUE(c.camera_timing);
  EXPECT_NEAR(c.camera_timing->latency_s, l.at("latency_ms").get<double>() * 1e-3, 1e-12);
  EXPECT_EQ(c.camera_timing->events_used, l.at("events_used").get<int>());
  EXPECT_NEAR(c.camera_timing->row_time_s, 1e-5, 1e-12);
  EXPECT_TRUE(c.camera);
  EXPECT_TRUE(c.gravity);
  EXPECT_EQ(c.flippers.size(), 2u);

  // Text: the events, the result and the truth; another latency and flipper.
  r = run("calibrate latency --sim boards/mit1993.board --events 5 --sim-latency-ms 12 --flipper right_flipper");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  std::smatch m;
  ASSERT_TRUE(std::regex_search(r.out, m, std::regex("camera latency ([0-9.]+) ms"))) << r.out;
  EXPECT_NEAR(std::stod(m[1]), 12.0, 0.5);
  EXPECT_NE(r.out.find("true minimum latency 12.000 ms, error "), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("flipper right_flipper"), std::string::npos) << r.out;
  EXPECT_EQ(pinball::testing::count_lines(r.out), 1 + 5 + 2);
  EXPECT_EQ(run("calibrate latency --sim boards/mit1993.board --events 5 --flipper middle").exit_code, 1);
}

// --fps is the simulated camera's rate too (it had stayed 200), within what that camera can do;
// too slow a camera for the stroke is told how to cure it.
TEST_F(Calibrate, LatencySimRunsTheCameraAtTheRateAskedOfIt) {
  Result r = run("calibrate latency --sim boards/mit1993.board --events 6 --fps 120 --json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  EXPECT_NEAR(j["latency"]["frame_period_ms"].get<double>(), 1000.0 / 120.0, 1e-9);
  EXPECT_NEAR(j["latency"]["latency_ms"].get<double>(), 7.0, 0.5);
  r = run("calibrate latency --sim boards/mit1993.board --events 6 --fps 60");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("run the camera faster (--fps)"), std::string::npos) << r.err;
  // The machine's true delay apart from the one assumed: the error goes one for one into the latency.
  r = run("calibrate latency --sim boards/mit1993.board --events 6 --sim-actuation-delay-ms 6 --json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json late = nlohmann::json::parse(r.out)["latency"];
  EXPECT_EQ(late["actuation_delay_ms"].get<double>(), 4.0) << "assumed: --actuation-delay-ms's default";
  EXPECT_EQ(late["truth"]["actuation_delay_ms"].get<double>(), 6.0);
  EXPECT_NEAR(late["truth"]["error_ms"].get<double>(), 2.0, 0.3);
  // A slow camera with a long latency is simulated (its step lengthens), and fails as a real one would.
  r = run("calibrate latency --sim boards/mit1993.board --events 3 --fps 10 --sim-latency-ms 100");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_EQ(r.err.find("step_s"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("events usable"), std::string::npos) << r.err;
  r = run("calibrate latency --sim boards/mit1993.board --fps 300");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("--fps 300: the simulated camera runs at 10 to 208 frames/s"), std::string::npos) << r.err;
}

// The lab path on a machine without the camera or the CAN interface: one
// line naming both, nothing fired, nothing written.
TEST_F(Calibrate, LatencyInTheLabWithoutHardwareFailsClearlyAndWritesNothing) {
  const std::string file = (dir_ / "lab.yaml").string();
  const std::string out = (dir_ / "out.yaml").string();
  pinball::calibration::write_calibration(lab_file(), file);
  Result r = run("calibrate latency --board boards/mit1993.board --calibration " + file +
                 " --device /dev/video97 --can pinballcan7 --row-time-us 10 --out " + out);
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_EQ(pinball::testing::count_lines(r.err), 1) << r.err;
  EXPECT_NE(r.err.find("/dev/video97: no such camera device"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("pinballcan7"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("nothing was fired or written"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(out));
  // What it needs is asked for before any hardware is touched.
  r = run("calibrate latency --board boards/mit1993.board --calibration " + file + " --device /dev/video97 --can can0");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("--row-time-us"), std::string::npos) << r.err;
  r = run("calibrate latency --board boards/mit1993.board --calibration " + file);
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("give --device"), std::string::npos) << r.err;
  // pinballd's configuration gives the camera, the interface and the board id it fires.
  const std::string pinballd = (dir_ / "pinballd.yaml").string();
  std::ofstream(pinballd) << "version: 1\nmode: lab\nboard: " PINBALL_SOURCE_DIR "/boards/mit1993.board\n"
                          << "camera: {source: v4l2, device: /dev/video96}\n"
                          << "can: {interface: pinballcan8, board_id: 3}\n";
  r = run("calibrate latency --board boards/mit1993.board --calibration " + file + " --config " + pinballd +
          " --row-time-us 10");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("/dev/video96: no such camera device"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("--can no interface pinballcan8"), std::string::npos) << r.err;
  EXPECT_EQ(run("calibrate gravity --sim boards/mit1993.board --config " + pinballd).exit_code, 2) << "latency only";
  const std::string before = pinball::testing::slurp(file);
  r = run("calibrate latency --board boards/mit1993.board --calibration " + file +
          " --device /dev/video97 --can pinballcan7 --row-time-us 10 --out " + file);
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_EQ(pinball::testing::slurp(file), before) << "a failed run leaves the file as it was";
}

// A calibration file with a camera section of this image size and a gravity section.
pinball::calibration::Calibration lab_file(int width_px, int height_px) {
  pinball::calibration::Calibration c;
  c.board = "boards/mit1993.board";
  c.camera.emplace();
  c.camera->image_width_px = width_px;
  c.camera->image_height_px = height_px;
  c.camera->markers_used = 7;
  c.gravity.emplace();
  c.gravity->g_mps2 = 1.1;
  c.gravity->ci_low_mps2 = 1.09;
  c.gravity->ci_high_mps2 = 1.11;
  c.gravity->rolls_used = 5;
  return c;
}

// The text report of gravity (or camera, or flippers) is the section written, not the whole file again.
TEST_F(Calibrate, TheTextReportIsTheSectionWrittenNotTheWholeFile) {
  const std::string file = (dir_ / "lab.yaml").string();
  pinball::calibration::write_calibration(lab_file(640, 480), file);
  const Result r = run("calibrate gravity --sim boards/mit1993.board --sim-rolls 3 --out " + file);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("\ngravity:\n  g_mps2: "), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("board: boards/mit1993.board"), std::string::npos) << r.out;
  EXPECT_EQ(r.out.find("camera:"), std::string::npos) << r.out;
  EXPECT_NE(pinball::testing::slurp(file).find("\ncamera:\n"), std::string::npos) << "the file keeps it";
}

TEST_F(Calibrate, IntrinsicsSimulatedWritesTheLensAndKeepsTheOtherSections) {
  const std::string file = (dir_ / "lab.yaml").string();
  const std::string png = (dir_ / "intrinsics.png").string();
  pinball::calibration::Calibration gravity_only = lab_file(640, 480);
  gravity_only.camera.reset();  // the lens comes before the camera (below)
  pinball::calibration::write_calibration(gravity_only, file);
  const Result r = run("calibrate intrinsics --sim boards/mit1993.board --sim-views 12 --out " + file + " --png " + png +
                       " --json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j.at("kind"), "intrinsics");
  EXPECT_EQ(j.at("images_used"), 12);
  EXPECT_EQ(j.at("images").size(), 12u);
  EXPECT_EQ(j.at("images")[0].at("name"), "sim_view_01.png");
  EXPECT_TRUE(j.at("images")[0].at("used").get<bool>());
  EXPECT_LE(j.at("reprojection_rms_px").get<double>(), 0.3);
  const nlohmann::json& truth = j.at("truth");
  EXPECT_LT(std::abs(truth.at("fx_error_pct").get<double>()), 0.5);
  EXPECT_LT(std::abs(truth.at("fy_error_pct").get<double>()), 0.5);
  EXPECT_LT(truth.at("principal_point_error_px").get<double>(), 2.0);
  EXPECT_LT(truth.at("distortion_max_error_px").get<double>(), 0.5);
  EXPECT_EQ(truth.at("lens").at("fx_px"), 530.0);
  EXPECT_TRUE(fs::exists(png));

  const pinball::calibration::Calibration c = pinball::calibration::read_calibration(file);
  ASSERT_TRUE(c.intrinsics);
  EXPECT_EQ(c.intrinsics->lens.fx_px, j.at("lens").at("fx_px").get<double>());
  EXPECT_EQ(c.intrinsics->images_used, 12);
  EXPECT_EQ(c.intrinsics->target, "chessboard 10x7 squares (9x6 inner corners), 25 mm");
  ASSERT_TRUE(c.gravity);  // the other sections stay
  EXPECT_EQ(c.gravity->g_mps2, 1.1);

  // The text report: the lens, every image, the truth.
  const Result text = run("calibrate intrinsics --sim boards/mit1993.board --sim-views 6 --progress");
  ASSERT_EQ(text.exit_code, 0) << text.err;
  // The search for the target, the long part, shows its progress when asked (stderr is no terminal here).
  EXPECT_NE(text.err.find("calibrate intrinsics: searching for the target: 6/6 images (100 %)"), std::string::npos)
      << text.err;
  EXPECT_EQ(r.err.find("searching for the target"), std::string::npos) << r.err;
  EXPECT_NE(text.out.find("lens (640x480): fx "), std::string::npos) << text.out;
  EXPECT_NE(text.out.find("sim_view_06.png  used"), std::string::npos) << text.out;
  EXPECT_NE(text.out.find("against the simulated lens: fx "), std::string::npos) << text.out;
}

// A lens added beside a camera section: the homography had been fitted on raw pixels, and the
// detector would now undistort before applying it (the file disagreeing with itself, exit 0).
TEST_F(Calibrate, IntrinsicsRefusesAFileThatHoldsACameraSectionAndWritesNothing) {
  const std::string file = (dir_ / "lab.yaml").string();
  const std::string png = (dir_ / "intrinsics.png").string();
  pinball::calibration::write_calibration(lab_file(640, 480), file);
  const std::string before = pinball::testing::slurp(file);
  const Result r = run("calibrate intrinsics --sim boards/mit1993.board --sim-views 12 --out " + file + " --png " + png);
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("--out " + file + " holds a camera section fitted without a lens model: the lens comes first, "
                                          "then camera and flippers"),
            std::string::npos)
      << r.err;
  EXPECT_EQ(pinball::testing::count_lines(r.err), 1) << r.err;
  EXPECT_EQ(pinball::testing::slurp(file), before);
  EXPECT_FALSE(fs::exists(png));
}

// Real files: a directory of images, one of them without the target; an unreadable one refused by name.
TEST_F(Calibrate, IntrinsicsFromADirectoryOfImages) {
  const pinball::calibration::TargetSpec target = pinball::calibration::parse_target("charuco:10x7:0.025:0.018");
  const pinball::vision::CameraIntrinsics lens = pinball::vision::typical_wide_lens(640, 480);
  const fs::path images = dir_ / "shots";
  fs::create_directories(images);
  const std::vector<pinball::simlab::TargetPose> poses = pinball::simlab::default_target_poses(target, lens, 8, 3);
  for (std::size_t i = 0; i < poses.size(); ++i) {
    cv::imwrite((images / ("shot" + std::to_string(i) + ".png")).string(),
                pinball::simlab::render_target_view(lens, target, poses[i], {}, pinball::ball_seed(3, i)));
  }
  cv::imwrite((images / "ceiling.jpg").string(), cv::Mat(480, 640, CV_8UC3, cv::Scalar(120, 130, 140)));
  std::ofstream(images / "notes.txt") << "not an image, and not read\n";
  const std::string file = (dir_ / "lens.yaml").string();
  Result r = run("calibrate intrinsics --target charuco:10x7:0.025:0.018 --images " + images.string() + " --out " +
                 file + " --json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  ASSERT_EQ(j.at("images").size(), 9u);  // sorted: ceiling.jpg first
  EXPECT_EQ(j.at("images")[0].at("name"), (images / "ceiling.jpg").string());
  EXPECT_FALSE(j.at("images")[0].at("used").get<bool>());
  EXPECT_EQ(j.at("images")[0].at("rejection"), "target not found");
  EXPECT_EQ(j.at("images_used"), 8);
  EXPECT_FALSE(j.contains("truth"));
  const pinball::calibration::Calibration c = pinball::calibration::read_calibration(file);
  ASSERT_TRUE(c.intrinsics);
  EXPECT_NEAR(c.intrinsics->lens.fx_px, 530.0, 530.0 * 0.005);
  EXPECT_FALSE(c.camera);

  // An unreadable image: named, nothing written.
  const std::string broken = (images / "broken.png").string();
  std::ofstream(broken) << "this is text\n";
  const std::string other = (dir_ / "other.yaml").string();
  r = run("calibrate intrinsics --target charuco:10x7:0.025:0.018 --images " + images.string() + " --out " + other);
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find(broken + ": cannot be read as an image"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(other));
}

TEST_F(Calibrate, IntrinsicsPrintsTheTarget) {
  const std::string png = (dir_ / "target.png").string();
  const Result r = run("calibrate intrinsics --target chessboard:10x7:0.025 --print-target " + png + " --json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j.at("px_per_mm"), 10.0);
  const cv::Mat img = cv::imread(png, cv::IMREAD_UNCHANGED);
  ASSERT_FALSE(img.empty());
  EXPECT_EQ(img.cols, 2500 + 2 * 250);  // 250 mm of squares and a square's margin each side, at 10 px/mm
  EXPECT_EQ(img.rows, 1750 + 2 * 250);
  EXPECT_EQ(img.channels(), 1);
  EXPECT_EQ(img.at<std::uint8_t>(250 + 125, 250 + 125), 0);    // the top-left square is black
  EXPECT_EQ(img.at<std::uint8_t>(250 + 125, 500 + 125), 255);  // its neighbour white
}

TEST_F(Calibrate, IntrinsicsBadArguments) {
  EXPECT_EQ(run("calibrate intrinsics --target chessboard:10x7").exit_code, 2);
  EXPECT_EQ(run("calibrate intrinsics --sim boards/mit1993.board --camera-size 640by480").exit_code, 2);
  EXPECT_EQ(run("calibrate intrinsics --camera-size 640x480").exit_code, 2);  // needs --sim
  const Result r = run("calibrate intrinsics");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("give --images"), std::string::npos) << r.err;
}

TEST_F(Calibrate, ThroughAWideLensTheHomographyNeedsTheIntrinsicsFirst) {
  const std::string file = (dir_ / "lens.yaml").string();
  // Without the lens the markers cannot be matched by any homography: a clear error with the remedy, nothing written.
  Result r = run("calibrate camera --sim boards/mit1993.board --sim-camera typical --out " + file);
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("pinball calibrate intrinsics"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(file));
  // The lab's order: the lens, then the homography on undistorted markers, then the flippers.
  r = run("calibrate intrinsics --sim boards/mit1993.board --sim-views 12 --out " + file);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  r = run("calibrate camera --sim boards/mit1993.board --sim-camera typical --out " + file + " --json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  nlohmann::json j = nlohmann::json::parse(r.out);
  EXPECT_LT(j.at("camera").at("reprojection_rms_px").get<double>(), 0.3);
  EXPECT_LT(j.at("camera").at("truth").at("homography_max_error_mm").get<double>(), 1.0);
  r = run("calibrate flippers --sim boards/mit1993.board --sim-camera typical --out " + file + " --json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  j = nlohmann::json::parse(r.out);
  for (const auto& f : j.at("flippers")) EXPECT_LT(f.at("markers").at("truth").at("pivot_error_mm").get<double>(), 1.0);
}

}  // namespace
