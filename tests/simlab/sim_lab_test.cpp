#include "pinball/simlab/sim_lab.h"

#include <gtest/gtest.h>

#include "pinball/calibration/camera_calibration.h"
#include "pinball/table/board_loader.h"

namespace pinball::simlab {
namespace {

// The practice lab is the machine its board file describes, as pinballd's
// simulated table is: a practice calibration fed to pinballd used to mount
// the flippers 3.6 mm, 2 mm and 0.7 degrees off and cut the score per ball
// from 9193 to 1237. The mounting error is there when asked for.
TEST(SimLab, ThePracticeMachineIsTheBoardFilesUnlessAMountingErrorIsAsked) {
  const table::Board board = table::load_board(PINBALL_SOURCE_DIR "/boards/mit1993.board");
  const SimLab practice(board);
  ASSERT_EQ(practice.truth().flippers.size(), board.flippers.size());
  for (std::size_t i = 0; i < board.flippers.size(); ++i) {
    const table::Flipper& t = practice.truth().flippers[i];
    EXPECT_EQ(t.pivot, board.flippers[i].pivot);
    EXPECT_EQ(t.length_m, board.flippers[i].length_m);
    EXPECT_EQ(t.theta_min_rad, board.flippers[i].theta_min_rad);
    EXPECT_EQ(t.theta_max_rad, board.flippers[i].theta_max_rad);
  }
  const SimLab off(board, with_mounting_error({}));
  EXPECT_NEAR((off.truth().flippers[0].pivot - board.flippers[0].pivot).norm(), 0.0036, 1e-4);
  EXPECT_NEAR(off.truth().flippers[1].length_m - board.flippers[1].length_m, 0.002, 1e-12);
}

TEST(SimLab, TheCameraImageShowsTheMarkersWhereTheTrueHomographyPutsThem) {
  const table::Board board = table::load_board(PINBALL_SOURCE_DIR "/boards/mit1993.board");
  SimLab lab(board, with_mounting_error({}));
  EXPECT_EQ(lab.image_size(), cv::Size(640, 480));
  // The camera image shows the layout's markers where the true homography puts them.
  const std::vector<Vec2> layout = calibration::default_marker_layout(board);
  const calibration::HomographyFit fit = calibration::calibrate_camera(lab.camera_image(), layout);
  EXPECT_EQ(fit.calibration.markers_used, 7);
  for (const calibration::MarkerMatch& m : fit.matches) {
    EXPECT_LT(cv::norm(m.uv_px - lab.true_homography().image_from_board(m.board)), 0.3);
  }
}

TEST(SimLab, SweepVideosRepeatAndRollsStartAtRest) {
  const table::Board board = table::load_board(PINBALL_SOURCE_DIR "/boards/mit1993.board");
  const SimLab lab(board);
  vision::Frame a, b;
  auto first = lab.sweep_video(1);
  auto second = lab.sweep_video(1);
  for (int k = 0; k < 5; ++k) {
    ASSERT_TRUE(first->read(a));
    ASSERT_TRUE(second->read(b));
  }
  EXPECT_EQ(cv::norm(a.gray, b.gray, cv::NORM_INF), 0.0);
  EXPECT_DOUBLE_EQ(lab.sweep_angle(1, 0.0), lab.truth().flippers[1].theta_min_rad);
  const std::vector<calibration::GravityRoll> rolls = lab.rolls(3);
  ASSERT_EQ(rolls.size(), 3u);
  for (const calibration::GravityRoll& r : rolls) {
    ASSERT_GT(r.observations.size(), 50u);
    EXPECT_GT(r.observations.front().p_board.y() - r.observations.back().p_board.y(), 0.2);
  }
}

}  // namespace
}  // namespace pinball::simlab
