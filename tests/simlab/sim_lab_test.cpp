#include "pinball/simlab/sim_lab.h"

#include <gtest/gtest.h>

#include "pinball/calibration/camera_calibration.h"
#include "pinball/table/board_loader.h"

namespace pinball::simlab {
namespace {

TEST(SimLab, TheMachineDiffersFromItsBoardFile) {
  const table::Board board = table::load_board(PINBALL_SOURCE_DIR "/boards/mit1993.board");
  SimLab lab(board);
  EXPECT_NEAR((lab.truth().flippers[0].pivot - board.flippers[0].pivot).norm(), 0.0036, 1e-4);
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
