#include "pinball/calibration/flipper_calibration.h"

#include <cmath>
#include <numbers>
#include <stdexcept>

#include <gtest/gtest.h>

#include "pinball/simlab/sim_lab.h"
#include "pinball/table/board_loader.h"

namespace pinball::calibration {
namespace {

table::Flipper flipper(table::Side side, Vec2 pivot) {
  table::Flipper f;
  f.side = side;
  f.pivot = pivot;
  f.length_m = 0.078;
  f.theta_min_rad = -0.42;
  f.theta_max_rad = 0.54;
  f.name = side == table::Side::kLeft ? "left" : "right";
  return f;
}

// A sweep of `f` as a tip tracker would see it, n frames at 200 fps: resting
// down, moving up, resting up, moving down. The tips carry noise_m of noise
// and a radial bias from bias_down_m (down stop) to bias_up_m (up stop); with
// `lines`, each frame also has the blade's centre line, moved 0.1 mm across
// and turned 0.1° at random.
SweepTrack synthetic_sweep(const table::Flipper& f, int n, double noise_m, double bias_down_m, double bias_up_m,
                           bool lines, std::uint64_t seed) {
  SweepTrack track;
  Rng rng(seed);
  for (int k = 0; k < n; ++k) {
    const double phase = static_cast<double>(k) / n;
    const double up = phase < 0.3 ? 0.0 : phase < 0.5 ? (phase - 0.3) / 0.2 : phase < 0.8 ? 1.0 : 1.0 - (phase - 0.8) / 0.2;
    const double theta = f.theta_min_rad + up * (f.theta_max_rad - f.theta_min_rad);
    const Vec2 tip = table::flipper_tip(f, theta);
    const Vec2 d = (tip - f.pivot).normalized();
    track.t_s.push_back(k / 200.0);
    track.tips_board.push_back(tip + (bias_down_m + up * (bias_up_m - bias_down_m)) * d +
                               noise_m * Vec2{rng.normal(), rng.normal()});
    if (!lines) continue;
    const double turn = 0.0017 * rng.normal();
    const Vec2 dl{d.x() * std::cos(turn) - d.y() * std::sin(turn), d.x() * std::sin(turn) + d.y() * std::cos(turn)};
    track.blades_board.push_back({f.pivot + 0.04 * d + 0.0001 * rng.normal() * Vec2{-d.y(), d.x()}, dl});
  }
  return track;
}

TEST(FlipperCalibration, AngleFollowsTheBoardConvention) {
  EXPECT_NEAR(flipper_angle(table::Side::kLeft, {0, 0}, {1, 1}), std::numbers::pi / 4, 1e-12);
  EXPECT_NEAR(flipper_angle(table::Side::kRight, {0, 0}, {-1, 1}), std::numbers::pi / 4, 1e-12);
  EXPECT_NEAR(flipper_angle(table::Side::kRight, {0, 0}, {-1, -1}), -std::numbers::pi / 4, 1e-12);
}

TEST(FlipperCalibration, MarkersGivePivotTipAndStops) {
  const table::Flipper nominal = flipper(table::Side::kRight, {0.345, 0.16});
  table::Flipper real = nominal;
  real.pivot += Vec2{0.004, -0.003};
  real.theta_min_rad -= 0.02;
  const std::vector<Vec2> down{real.pivot, table::flipper_tip(real, real.theta_min_rad), Vec2{0.1, 0.1}};
  const std::vector<Vec2> up{real.pivot, table::flipper_tip(real, real.theta_max_rad)};
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

// A pivot marker 20 mm to the side in the up picture was averaged in: the pivot 10 mm off, the
// blade 9 mm short. The two sightings of one rigid blade must agree.
TEST(FlipperCalibration, APivotThatMovedBetweenThePicturesIsRefused) {
  const table::Flipper f = flipper(table::Side::kLeft, {0.165, 0.16});
  const std::vector<Vec2> down{f.pivot, table::flipper_tip(f, f.theta_min_rad)};
  const Vec2 moved = f.pivot + Vec2{0.020, 0.0};
  const std::vector<Vec2> up{moved, table::flipper_tip(f, f.theta_max_rad)};
  try {
    calibrate_flipper_markers(f, down, up);
    FAIL() << "no error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("the pivot marker's place differs by 20 mm between the down and up pictures "
                                         "(at most 3 mm): the camera or a marker moved"),
              std::string::npos)
        << e.what();
  }
  // Within a marker's placement error both sightings are kept (and averaged).
  const std::vector<Vec2> up_close{f.pivot + Vec2{0.001, 0.0}, table::flipper_tip(f, f.theta_max_rad)};
  EXPECT_NO_THROW(calibrate_flipper_markers(f, down, up_close));
  // A tip marker 10 mm further out in one picture: the blade's length differs.
  const Vec2 along = (table::flipper_tip(f, f.theta_max_rad) - f.pivot).normalized();
  const std::vector<Vec2> long_up{f.pivot, table::flipper_tip(f, f.theta_max_rad) + 0.010 * along};
  try {
    calibrate_flipper_markers(f, down, long_up);
    FAIL() << "no error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("the blade's length (pivot to tip marker) differs by 10 mm"),
              std::string::npos)
        << e.what();
  }
}

TEST(FlipperCalibration, SweepTrackGivesPivotLengthAndStops) {
  // Tips of a right flipper resting on both stops and moving between them, 0.2 mm noise.
  const table::Flipper f = flipper(table::Side::kRight, {0.345, 0.16});
  SweepTrack track = synthetic_sweep(f, 400, 0.0002, 0.0, 0.0, false, 4);
  const FlipperCalibration c = flipper_from_sweep_track(track, f, SweepOptions{});
  EXPECT_EQ(c.method, FlipperMethod::kMarkerless);
  EXPECT_LT((c.pivot_m - f.pivot).norm(), 0.001);
  EXPECT_NEAR(c.length_m, f.length_m, 0.001);
  EXPECT_NEAR(c.theta_min_rad, f.theta_min_rad, 0.5 * std::numbers::pi / 180);
  EXPECT_NEAR(c.theta_max_rad, f.theta_max_rad, 0.5 * std::numbers::pi / 180);
  EXPECT_LT((c.tip_m - table::flipper_tip(f, f.theta_min_rad)).norm(), 0.001);
  const FlipperDisagreement d = compare_flippers(c, c);
  EXPECT_EQ(d.pivot_m, 0.0);
}

TEST(FlipperCalibration, SweepTrackWithBladeLinesTakesThePivotFromTheLines) {
  // The tips carry a radial bias that changes with the blade's angle (−0.6 to
  // −1.2 mm): a circle through them moves its centre by about 0.65 mm.
  // The blade's centre lines still pass through the pivot, so the pivot is
  // exact and only the length takes the (median) bias.
  const table::Flipper f = flipper(table::Side::kLeft, {0.165, 0.16});
  SweepTrack track = synthetic_sweep(f, 300, 0.0, -0.0006, -0.0012, true, 5);
  SweepTrack circle_only = track;
  circle_only.blades_board.clear();
  const FlipperCalibration by_lines = flipper_from_sweep_track(track, f, SweepOptions{});
  const FlipperCalibration by_circle = flipper_from_sweep_track(circle_only, f, SweepOptions{});
  EXPECT_LT((by_lines.pivot_m - f.pivot).norm(), 0.0002);
  EXPECT_GT((by_circle.pivot_m - f.pivot).norm(), 0.0005);
  EXPECT_NEAR(by_lines.length_m, f.length_m - 0.0009, 0.0004);
  EXPECT_EQ(track.meet.lines + track.meet.rejected, 300);
  EXPECT_NEAR(by_lines.theta_min_rad, f.theta_min_rad, 0.1 * std::numbers::pi / 180);
  EXPECT_NEAR(by_lines.theta_max_rad, f.theta_max_rad, 0.1 * std::numbers::pi / 180);
}

TEST(FlipperCalibration, SweepVideoOfTheSimulatedLab) {
  const table::Board board = table::load_board(PINBALL_SOURCE_DIR "/boards/mit1993.board");
  simlab::SimLabOptions o = simlab::with_mounting_error({});  // the machine, not its drawing, is found
  o.sweeps = 1;
  const simlab::SimLab lab(board, o);
  SweepTrack track;
  const FlipperCalibration c =
      calibrate_flipper_sweep([&] { return lab.sweep_video(0); }, lab.true_homography(), board.flippers[0], {}, &track);
  const table::Flipper& t = lab.truth().flippers[0];
  // The tip's end fits a circle in (nearly) every frame of the 1.75 s video.
  EXPECT_GT(track.tips_board.size(), 330u);
  EXPECT_EQ(track.blades_board.size(), track.tips_board.size());
  // The targets (thesis 4.1.3; docs/results.md has what the bench measures).
  EXPECT_LT((c.pivot_m - t.pivot).norm(), 0.001);
  EXPECT_LT((c.tip_m - table::flipper_tip(t, t.theta_min_rad)).norm(), 0.001);
  EXPECT_NEAR(c.length_m, t.length_m, 0.001);
  EXPECT_NEAR(c.theta_min_rad, t.theta_min_rad, 0.5 * std::numbers::pi / 180);
  EXPECT_NEAR(c.theta_max_rad, t.theta_max_rad, 0.5 * std::numbers::pi / 180);
}

TEST(FlipperCalibration, StillFlipperIsRefused) {
  const table::Board board = table::load_board(PINBALL_SOURCE_DIR "/boards/mit1993.board");
  const simlab::SimLab lab(board);
  const cv::Mat frame = simlab::SimLab(board).flipper_markers_image(false);
  TipTracker t(frame.size(), lab.true_homography());
  for (int k = 0; k < 20; ++k) t.learn(frame);
  for (int k = 0; k < 20; ++k) t.measure(frame, k / 200.0);
  EXPECT_THROW(t.finish(), std::runtime_error);
}

}  // namespace
}  // namespace pinball::calibration
