#include "pinball/calibration/flipper_calibration.h"

#include <cmath>
#include <numbers>
#include <stdexcept>

#include <gtest/gtest.h>

#include "pinball/calibration/sim_lab.h"
#include "pinball/sim/board_loader.h"

namespace pinball::calibration {
namespace {

sim::Flipper flipper(sim::Side side, Vec2 pivot) {
  sim::Flipper f;
  f.side = side;
  f.pivot = pivot;
  f.length_m = 0.078;
  f.theta_min_rad = -0.42;
  f.theta_max_rad = 0.54;
  f.name = side == sim::Side::kLeft ? "left" : "right";
  return f;
}

TEST(FlipperCalibration, AngleFollowsTheBoardConvention) {
  EXPECT_NEAR(flipper_angle(sim::Side::kLeft, {0, 0}, {1, 1}), std::numbers::pi / 4, 1e-12);
  EXPECT_NEAR(flipper_angle(sim::Side::kRight, {0, 0}, {-1, 1}), std::numbers::pi / 4, 1e-12);
  EXPECT_NEAR(flipper_angle(sim::Side::kRight, {0, 0}, {-1, -1}), -std::numbers::pi / 4, 1e-12);
}

TEST(FlipperCalibration, MarkersGivePivotTipAndStops) {
  const sim::Flipper nominal = flipper(sim::Side::kRight, {0.345, 0.16});
  sim::Flipper real = nominal;
  real.pivot += Vec2{0.004, -0.003};
  real.theta_min_rad -= 0.02;
  const std::vector<Vec2> down{real.pivot, sim::flipper_tip(real, real.theta_min_rad), Vec2{0.1, 0.1}};
  const std::vector<Vec2> up{real.pivot, sim::flipper_tip(real, real.theta_max_rad)};
  const FlipperCalibration c = calibrate_flipper_markers(nominal, down, up);
  EXPECT_LT((c.pivot_m - real.pivot).norm(), 1e-12);
  EXPECT_NEAR(c.length_m, 0.078, 1e-12);
  EXPECT_NEAR(c.theta_min_rad, real.theta_min_rad, 1e-12);
  EXPECT_NEAR(c.theta_max_rad, real.theta_max_rad, 1e-12);
  EXPECT_EQ(c.method, FlipperMethod::kMarkers);
  // A missing tip marker is named.
  const std::vector<Vec2> no_tip{real.pivot};
  try {
    calibrate_flipper_markers(nominal, no_tip, up);
    FAIL();
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("tip"), std::string::npos) << e.what();
  }
}

TEST(FlipperCalibration, SweepTrackGivesPivotLengthAndStops) {
  // Tips of a right flipper resting on both stops and moving between them, 0.2 mm noise.
  const sim::Flipper f = flipper(sim::Side::kRight, {0.345, 0.16});
  SweepTrack track;
  Rng rng(4);
  for (int k = 0; k < 400; ++k) {
    const double phase = k / 400.0;
    double up = phase < 0.3 ? 0.0 : phase < 0.5 ? (phase - 0.3) / 0.2 : phase < 0.8 ? 1.0 : 1.0 - (phase - 0.8) / 0.2;
    const double theta = f.theta_min_rad + up * (f.theta_max_rad - f.theta_min_rad);
    track.t_s.push_back(k / 200.0);
    track.tips_board.push_back(sim::flipper_tip(f, theta) + 0.0002 * Vec2{rng.normal(), rng.normal()});
  }
  const FlipperCalibration c = flipper_from_sweep_track(track, f, SweepOptions{});
  EXPECT_EQ(c.method, FlipperMethod::kMarkerless);
  EXPECT_LT((c.pivot_m - f.pivot).norm(), 0.001);
  EXPECT_NEAR(c.length_m, f.length_m, 0.001);
  EXPECT_NEAR(c.theta_min_rad, f.theta_min_rad, 0.5 * std::numbers::pi / 180);
  EXPECT_NEAR(c.theta_max_rad, f.theta_max_rad, 0.5 * std::numbers::pi / 180);
  EXPECT_LT((c.tip_m - sim::flipper_tip(f, f.theta_min_rad)).norm(), 0.001);
  const FlipperDisagreement d = compare_flippers(c, c);
  EXPECT_EQ(d.pivot_m, 0.0);
}

TEST(FlipperCalibration, SweepVideoOfTheSimulatedLab) {
  const sim::Board board = sim::load_board(PINBALL_SOURCE_DIR "/boards/mit1993.board");
  SimLabOptions o;
  o.sweeps = 1;
  const SimLab lab(board, o);
  SweepTrack track;
  const FlipperCalibration c =
      calibrate_flipper_sweep([&] { return lab.sweep_video(0); }, lab.true_homography(), board.flippers[0], {}, &track);
  const sim::Flipper& t = lab.truth().flippers[0];
  EXPECT_GT(track.tips_board.size(), 200u);
  // What the bench measures (docs/results.md): within a few millimetres and a degree.
  EXPECT_LT((c.pivot_m - t.pivot).norm(), 0.004);
  EXPECT_NEAR(c.length_m, t.length_m, 0.005);
  EXPECT_NEAR(c.theta_min_rad, t.theta_min_rad, 1.5 * std::numbers::pi / 180);
  EXPECT_NEAR(c.theta_max_rad, t.theta_max_rad, 1.5 * std::numbers::pi / 180);
}

TEST(FlipperCalibration, StillFlipperIsRefused) {
  const sim::Board board = sim::load_board(PINBALL_SOURCE_DIR "/boards/mit1993.board");
  const SimLab lab(board);
  const cv::Mat frame = SimLab(board).flipper_markers_image(false);
  TipTracker t(frame.size(), lab.true_homography());
  for (int k = 0; k < 20; ++k) t.learn(frame);
  for (int k = 0; k < 20; ++k) t.measure(frame, k / 200.0);
  EXPECT_THROW(t.finish(), std::runtime_error);
}

}  // namespace
}  // namespace pinball::calibration
