// `pinball calibrate` as the lab runs it: JSON on stdout, the file written and
// updated section by section, and `pinball track --calibration` reading it.

#include <filesystem>
#include <fstream>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "common/command_test.h"
#include "pinball/calibration/calibration_file.h"
#include "pinball/table/board_loader.h"

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
  EXPECT_LT(j.at("camera").at("truth").at("homography_max_error_mm").get<double>(), 1.0);
  EXPECT_TRUE(fs::exists(png));

  r = run("calibrate flippers --sim boards/mit1993.board --out " + file + " --json");
  ASSERT_EQ(r.exit_code, 0);
  j = nlohmann::json::parse(r.out);
  ASSERT_EQ(j.at("flippers").size(), 2u);
  for (const auto& f : j.at("flippers")) {
    EXPECT_LT(f.at("markers").at("truth").at("pivot_error_mm").get<double>(), 1.0);
    EXPECT_TRUE(f.contains("markerless"));
    EXPECT_TRUE(f.contains("disagreement"));
  }

  r = run("calibrate gravity --sim boards/mit1993.board --sim-rolls 3 --out " + file + " --json");
  ASSERT_EQ(r.exit_code, 0);
  j = nlohmann::json::parse(r.out);
  EXPECT_NEAR(j.at("gravity").at("g_mps2").get<double>(), 1.11, 0.011);
  EXPECT_EQ(j.at("gravity").at("rolls_used"), 3);

  // The practice machine is the board file's: what the calibration finds is
  // what pinballd's simulated table has (it was 3.6 mm off by default).
  const pinball::calibration::Calibration practice = pinball::calibration::read_calibration(file);
  const pinball::table::Board board = pinball::table::load_board(std::string(PINBALL_SOURCE_DIR) + "/boards/mit1993.board");
  ASSERT_EQ(practice.flippers.size(), board.flippers.size());
  for (std::size_t i = 0; i < board.flippers.size(); ++i) {
    EXPECT_LT((practice.flippers[i].pivot_m - board.flippers[i].pivot).norm(), 0.001) << "flipper " << i;
    EXPECT_NEAR(practice.flippers[i].length_m, board.flippers[i].length_m, 0.001) << "flipper " << i;
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

TEST_F(Calibrate, BadInputsExitWithOne) {
  EXPECT_EQ(run("calibrate camera --board boards/mit1993.board").exit_code, 1);  // no image
  EXPECT_EQ(run("calibrate wobble --sim boards/mit1993.board").exit_code, 2);
  const std::string bad = (dir_ / "bad.yaml").string();
  std::ofstream(bad) << "version: 1\nboard: x\n";
  EXPECT_EQ(run("calibrate flippers --board boards/mit1993.board --down " + bad + " --up " + bad +
                " --calibration " + bad)
                .exit_code,
            1);
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

}  // namespace
