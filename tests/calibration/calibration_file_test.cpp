#include "pinball/calibration/calibration_file.h"

#include <cstdio>
#include <filesystem>
#include <stdexcept>

#include <gtest/gtest.h>

#include "pinball/table/board_loader.h"

namespace pinball::calibration {
namespace {

Calibration sample() {
  Calibration c;
  c.date = "2026-11-21T12:00:00Z";
  c.board = "boards/mit1993.board";
  CameraCalibration k;
  k.image_from_board = cv::Matx33d(-14.5, 598.9, 23.0, 562.2, 29.4, 88.7, 0.00036, 0.0593, 1.0);
  k.image_width_px = 640;
  k.image_height_px = 480;
  k.markers_used = 7;
  k.reprojection_rms_px = 0.05;
  k.reprojection_max_px = 0.1;
  c.camera = k;
  FlipperCalibration l;
  l.name = "left_flipper";
  l.side = table::Side::kLeft;
  l.pivot_m = {0.168, 0.158};
  l.tip_m = {0.239, 0.1259};
  l.length_m = 0.078;
  l.theta_min_rad = -0.4248;
  l.theta_max_rad = 0.5358;
  l.points = 4;
  FlipperDisagreement d;
  d.pivot_m = 0.0022;
  d.theta_max_rad = -0.008;
  l.disagreement = d;
  FlipperCalibration r = l;
  r.name = "right_flipper";
  r.side = table::Side::kRight;
  r.method = FlipperMethod::kMarkerless;
  r.pivot_m = {0.348, 0.158};
  r.tip_m = {0.2768, 0.1259};
  r.fit_rms_m = 0.0003;
  r.points = 600;
  r.disagreement.reset();
  c.flippers = {l, r};
  GravityEstimate g;
  g.g_mps2 = 1.1083;
  g.ci_low_mps2 = 1.1042;
  g.ci_high_mps2 = 1.1124;
  g.rolls_used = 5;
  g.rolls_rejected = 1;
  g.per_roll_mps2 = {1.10, 1.11, 1.12, 1.108, 1.109, 1.4};
  c.gravity = g;
  return c;
}

TEST(CalibrationFile, RoundTripKeepsEveryField) {
  const Calibration a = sample();
  const std::string path = (std::filesystem::temp_directory_path() / "pinball_calibration_roundtrip.yaml").string();
  write_calibration(a, path);
  const Calibration b = read_calibration(path);
  std::filesystem::remove(path);
  EXPECT_EQ(b.version, kCalibrationFileVersion);
  EXPECT_EQ(b.date, a.date);
  EXPECT_EQ(b.board, a.board);
  ASSERT_TRUE(b.camera);
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) EXPECT_EQ(b.camera->image_from_board(i, j), a.camera->image_from_board(i, j));
  EXPECT_EQ(b.camera->markers_used, 7);
  ASSERT_EQ(b.flippers.size(), 2u);
  EXPECT_EQ(b.flippers[1].name, "right_flipper");
  EXPECT_EQ(b.flippers[1].side, table::Side::kRight);
  EXPECT_EQ(b.flippers[1].method, FlipperMethod::kMarkerless);
  EXPECT_EQ(b.flippers[0].pivot_m, a.flippers[0].pivot_m);
  EXPECT_EQ(b.flippers[0].theta_max_rad, a.flippers[0].theta_max_rad);
  ASSERT_TRUE(b.flippers[0].disagreement);
  EXPECT_EQ(b.flippers[0].disagreement->pivot_m, 0.0022);
  EXPECT_FALSE(b.flippers[1].disagreement);
  ASSERT_TRUE(b.gravity);
  EXPECT_EQ(b.gravity->g_mps2, 1.1083);
  EXPECT_EQ(b.gravity->per_roll_mps2, a.gravity->per_roll_mps2);
  EXPECT_EQ(calibration_to_yaml(b), calibration_to_yaml(a));
}

void expect_error(const std::string& text, const std::string& needle) {
  try {
    parse_calibration(text, "lab.yaml");
    FAIL() << "accepted: " << text;
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
  }
}

TEST(CalibrationFile, ErrorsNameFileAndKey) {
  const std::string good = calibration_to_yaml(sample());
  auto without = [&](const std::string& line) {
    std::string t = good;
    const std::size_t at = t.find(line);
    EXPECT_NE(at, std::string::npos) << line;
    t.erase(at, t.find('\n', at) - at + 1);
    return t;
  };
  expect_error(without("version:"), "lab.yaml:version: missing");
  expect_error(without("date:"), "lab.yaml:date: missing");
  expect_error(without("  markers_used:"), "lab.yaml:camera.markers_used: missing");
  expect_error(without("    theta_min_rad:"), "lab.yaml:flippers[0].theta_min_rad: missing");
  expect_error(without("  g_mps2:"), "lab.yaml:gravity.g_mps2: missing");
  std::string bad = good;
  bad.replace(bad.find("length_m: 0.078"), 15, "length_m: long");
  expect_error(bad, "lab.yaml:flippers[0].length_m: expected a number (double), got 'long'");
  // A g no table has (a wild gravity roll once wrote 1e6): refused as the board format refuses it.
  std::string steep = good;
  steep.replace(steep.find("g_mps2: 1.1083"), 14, "g_mps2: 1000000");
  const std::size_t low = steep.find("ci_low_mps2: ");
  steep.replace(low, steep.find('\n', low) - low, "ci_low_mps2: 999999");
  const std::size_t high = steep.find("ci_high_mps2: ");
  steep.replace(high, steep.find('\n', high) - high, "ci_high_mps2: 1000001");
  expect_error(steep, "lab.yaml:gravity.g_mps2: must be in (0, 10] m/s^2, as a board's g along the table");
  expect_error("version: 2\ndate: x\nboard: b\n", "lab.yaml:version: 2 is not the supported version");
  expect_error("version: [1\n", "lab.yaml:");
  expect_error("just text", "lab.yaml:version");
}

TEST(CalibrationFile, UnknownAndRepeatedKeysAreRefused) {
  const std::string good = calibration_to_yaml(sample());
  auto with = [&](const std::string& from, const std::string& to) {
    std::string t = good;
    const std::size_t at = t.find(from);
    EXPECT_NE(at, std::string::npos) << from;
    return t.replace(at, from.size(), to);
  };
  // A misspelt key used to pass unseen.
  expect_error(with("  markers_used:", "  markers_usde: 7\n  markers_used:"), "lab.yaml:camera.markers_usde: unknown key");
  expect_error(with("gravity:", "gravty: {g_mps2: 9.81}\ngravity:"), "lab.yaml:gravty: unknown key");
  expect_error(with("    points: 4\n", "    points: 4\n    pionts: 4\n"), "lab.yaml:flippers[0].pionts: unknown key");
  // yaml-cpp keeps both values of a repeated key; which one counts is not the file's to leave open.
  expect_error(with("  g_mps2:", "  g_mps2: 9.81\n  g_mps2:"), "lab.yaml:gravity.g_mps2: duplicate key");
  expect_error(with("version: 1\n", "version: 1\nversion: 1\n"), "lab.yaml:version: duplicate key");
  expect_error(good + "---\nversion: 1\n", "a second YAML document");
}

TEST(CalibrationFile, FlippersMustBeTheBoards) {
  const table::Board board = table::load_board(PINBALL_SOURCE_DIR "/boards/mit1993.board");
  EXPECT_NO_THROW(check_calibration_matches_board(sample(), "lab.yaml", board));
  auto error_of = [&](const Calibration& c) -> std::string {
    try {
      check_calibration_matches_board(c, "lab.yaml", board);
    } catch (const std::runtime_error& e) {
      return e.what();
    }
    return "";
  };
  Calibration typo = sample();
  typo.flippers[1].name = "rigth_flipper";
  EXPECT_EQ(error_of(typo).rfind("lab.yaml:flippers[1].name: 'rigth_flipper' is not a flipper of the board", 0), 0u)
      << error_of(typo);
  Calibration swapped = sample();
  swapped.flippers[0].side = table::Side::kRight;
  EXPECT_EQ(error_of(swapped), "lab.yaml:flippers[0].side: right, but the board's 'left_flipper' is a left flipper");
  Calibration twice = sample();
  twice.flippers[1] = twice.flippers[0];
  EXPECT_EQ(error_of(twice), "lab.yaml:flippers[1].name: 'left_flipper' is calibrated twice");
  table::Board b = board;
  EXPECT_THROW(apply_calibration(typo, "lab.yaml", b), std::runtime_error);
}

TEST(CalibrationFile, AppliesToTrackerAndBoard) {
  const Calibration c = sample();
  const table::Board board = table::load_board(PINBALL_SOURCE_DIR "/boards/mit1993.board");
  track::TrackerConfig config = track::default_tracker_config(board, track::CameraModelConfig{});
  track::FlipperGeometry geometry = track::flipper_geometry_from_board(board);
  apply_calibration(c, "lab.yaml", config, geometry);
  EXPECT_EQ(config.g_mps2, 1.1083);
  EXPECT_EQ(geometry.lines[track::kLeftFlipper].pivot, c.flippers[0].pivot_m);
  EXPECT_EQ(geometry.lines[track::kRightFlipper].tip, c.flippers[1].tip_m);
  EXPECT_NEAR(config.window_distance_m, 0.039, 1e-12);
  table::Board b = board;
  apply_calibration(c, "lab.yaml", b);
  EXPECT_EQ(b.flippers[0].pivot, c.flippers[0].pivot_m);
  EXPECT_EQ(b.gravity_mps2, 1.1083);
  Calibration one = c;
  one.flippers.pop_back();
  try {
    flipper_geometry_from_calibration(one, "lab.yaml");
    FAIL();
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("lab.yaml:flippers"), std::string::npos) << e.what();
  }
  Calibration none = c;
  none.camera.reset();
  EXPECT_THROW(camera_homography(none, "lab.yaml"), std::runtime_error);
  EXPECT_NO_THROW(camera_homography(c, "lab.yaml"));
}

}  // namespace
}  // namespace pinball::calibration
