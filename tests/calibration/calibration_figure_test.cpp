#include "pinball/calibration/calibration_figure.h"

#include <gtest/gtest.h>

#include "pinball/simlab/sim_lab.h"
#include "pinball/table/board_loader.h"

namespace pinball::calibration {
namespace {

TEST(CalibrationFigure, DrawsEachKind) {
  const table::Board board = table::load_board(PINBALL_SOURCE_DIR "/boards/mit1993.board");
  simlab::SimLab lab(board);
  const cv::Mat image = lab.camera_image();
  const HomographyFit fit = calibrate_camera(image, default_marker_layout(board));
  const cv::Mat cam = draw_camera_figure(image, fit);
  EXPECT_EQ(cam.type(), CV_8UC3);
  EXPECT_EQ(cam.cols, 2 * image.cols);
  // The markers are drawn in colour at their places.
  const cv::Point p(static_cast<int>(2 * fit.matches[0].uv_px.x), static_cast<int>(2 * fit.matches[0].uv_px.y));
  const cv::Mat around = cam(cv::Rect(p - cv::Point(10, 10), cv::Size(21, 21)));
  cv::Mat channels[3];
  cv::split(around, channels);
  EXPECT_GT(cv::norm(channels[0], channels[2], cv::NORM_INF), 100.0);

  FlipperCalibration f = calibrate_flipper_markers(board.flippers[0], std::vector<Vec2>{lab.truth().flippers[0].pivot, table::flipper_tip(lab.truth().flippers[0], lab.truth().flippers[0].theta_min_rad)},
                                                   std::vector<Vec2>{lab.truth().flippers[0].pivot, table::flipper_tip(lab.truth().flippers[0], lab.truth().flippers[0].theta_max_rad)});
  const std::vector<FlipperFigureItem> items{{nullptr, &f, nullptr}};
  EXPECT_EQ(draw_flipper_figure(image, lab.true_homography(), items).size(), cam.size());

  const std::vector<GravityRoll> rolls = lab.rolls(2);
  const GravityCalibration g = calibrate_gravity(rolls);
  const cv::Mat plot = draw_gravity_figure(rolls, g);
  EXPECT_EQ(plot.type(), CV_8UC3);
  EXPECT_GT(cv::countNonZero(plot.reshape(1) > 200), 100);
}

}  // namespace
}  // namespace pinball::calibration
