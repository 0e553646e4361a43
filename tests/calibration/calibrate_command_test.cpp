// `pinball calibrate` as the lab runs it: JSON on stdout, the file written and
// updated section by section, and `pinball track --calibration` reading it.

#include <filesystem>
#include <fstream>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "common/command_test.h"
#include "pinball/calibration/calibration_file.h"

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

}  // namespace
