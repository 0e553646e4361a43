#include "pinball/calibration/calibration_figure.h"

#include <cstdio>
#include <string>

#include <gtest/gtest.h>

#include "common/figure_check.h"
#include "common/temp_path.h"
#include "pinball/plot/draw.h"
#include "pinball/plot/png_file.h"
#include "pinball/simlab/sim_lab.h"
#include "pinball/table/board_loader.h"

namespace pinball::calibration {
namespace {

using pinball::testing::count_colour;
using pinball::testing::expect_figure;
using pinball::testing::temp_path;

// Writes `figure` to a temporary PNG, checks it non-trivial, and removes it.
void expect_written(const cv::Mat& figure, const std::string& name, cv::Size min_size, int palette_colours,
                    int palette_n = 8) {
  const std::string path = temp_path("calibration_figure", name);
  plot::write_png(figure, path);
  expect_figure(path, min_size, palette_colours, palette_n);
  std::remove(path.c_str());
}

class CalibrationFigure : public ::testing::Test {
 protected:
  CalibrationFigure() : board_(table::load_board(PINBALL_SOURCE_DIR "/boards/mit1993.board")), lab_(board_) {}
  table::Board board_;
  simlab::SimLab lab_;
};

TEST_F(CalibrationFigure, CameraFigureHasMarkersLegendAndTitle) {
  const cv::Mat image = lab_.camera_image();
  const HomographyFit fit = calibrate_camera(image, default_marker_layout(board_));
  const cv::Mat cam = draw_camera_figure(image, fit);
  EXPECT_EQ(cam.type(), CV_8UC3);
  EXPECT_GT(cam.cols, 2 * image.cols) << "the legend beside the enlarged image";
  EXPECT_GT(cam.rows, 2 * image.rows) << "the title above it";
  // The markers are drawn in colour at their places (the picture sits at the bottom left).
  const int top = cam.rows - 2 * image.rows;
  const cv::Point p(static_cast<int>(2 * fit.matches[0].uv_px.x), static_cast<int>(2 * fit.matches[0].uv_px.y) + top);
  const cv::Mat around = cam(cv::Rect(p - cv::Point(10, 10), cv::Size(21, 21)));
  cv::Mat channels[3];
  cv::split(around, channels);
  EXPECT_GT(cv::norm(channels[0], channels[2], cv::NORM_INF), 100.0);
  // Detections, inliers: their colours in the picture and the legend.
  expect_written(cam, "camera.png", image.size() * 2, 2);
}

TEST_F(CalibrationFigure, FlipperFigureHasLegendAndAZoomOnEachFlipper) {
  const cv::Mat image = lab_.camera_image();
  std::vector<FlipperCalibration> fits;
  for (const table::Flipper& truth : lab_.truth().flippers) {
    fits.push_back(
        calibrate_flipper_markers(truth, std::vector<Vec2>{truth.pivot, table::flipper_tip(truth, truth.theta_min_rad)},
                                  std::vector<Vec2>{truth.pivot, table::flipper_tip(truth, truth.theta_max_rad)}));
  }
  std::vector<FlipperFigureItem> items;
  for (const FlipperCalibration& f : fits) items.push_back({nullptr, &f, nullptr});
  const cv::Mat one = draw_flipper_figure(image, lab_.true_homography(), std::span(items).first(1));
  const cv::Mat all = draw_flipper_figure(image, lab_.true_homography(), items);
  EXPECT_GT(one.cols, 2 * image.cols) << "the legend beside";
  EXPECT_GT(one.rows, 2 * image.rows + 100) << "a zoomed inset below the whole view";
  if (items.size() > 1) {
    EXPECT_GE(all.rows, one.rows);
  }
  // The marker method's pivot and blade, in the whole view, the insets and the legend.
  EXPECT_GT(count_colour(all, plot::palette_colour(2)), 100);
  expect_written(all, "flippers.png", image.size() * 2, 1);
}

TEST_F(CalibrationFigure, GravityFigureHasOneColourPerRollAndResiduals) {
  const std::vector<GravityRoll> rolls = lab_.rolls(3);
  const GravityCalibration g = calibrate_gravity(rolls);
  const cv::Mat plot = draw_gravity_figure(rolls, g);
  EXPECT_EQ(plot.type(), CV_8UC3);
  EXPECT_GT(plot.rows, 2 * 380) << "two panels: the fit and its residuals";
  // Each usable roll in its own palette colour (points, parabola, legend swatch).
  int usable = 0;
  for (const RollFit& f : g.rolls) usable += f.usable && !f.outlier ? 1 : 0;
  ASSERT_GE(usable, 2);
  expect_written(plot, "gravity.png", cv::Size(960, 2 * 380), usable, static_cast<int>(rolls.size()));
}

TEST_F(CalibrationFigure, GravityFigureDrawsARollLeftOutInGrey) {
  const std::vector<GravityRoll> rolls = lab_.rolls(3);
  GravityCalibration g = calibrate_gravity(rolls);
  ASSERT_TRUE(g.rolls[1].usable);
  const int grey_before = count_colour(draw_gravity_figure(rolls, g), plot::muted_colour());
  g.rolls[1].outlier = true;
  const cv::Mat plot = draw_gravity_figure(rolls, g);
  // Its points, its dashed parabola and its legend swatch turn grey; its own colour is gone.
  EXPECT_GT(count_colour(plot, plot::muted_colour()), grey_before + 200);
  EXPECT_LT(count_colour(plot, plot::palette_colour(1)), 20);
}

}  // namespace
}  // namespace pinball::calibration
