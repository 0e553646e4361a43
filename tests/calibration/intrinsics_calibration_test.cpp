#include "pinball/calibration/intrinsics_calibration.h"

#include <cstdio>
#include <stdexcept>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

#include "common/error_text.h"
#include "common/figure_check.h"
#include "common/temp_path.h"
#include "pinball/core/rng.h"
#include "pinball/plot/png_file.h"
#include "pinball/simlab/sim_target_view.h"

namespace pinball::calibration {
namespace {

// Views of a target through the simulated camera's lens (640x480, as the
// tests keep it small), each rendered when a test first asks for it.
class Views {
 public:
  Views(const std::string& spec, int count, std::uint64_t seed)
      : target(parse_target(spec)), poses(simlab::default_target_poses(target, lens, count, seed)), seed_(seed) {}

  /// The first n views (n at most the count), named view_1.png, view_2.png, ...
  std::vector<TargetImage> first(std::size_t n) {
    while (images_.size() < n) {
      const std::size_t i = images_.size();
      images_.push_back({"view_" + std::to_string(i + 1) + ".png",
                         simlab::render_target_view(lens, target, poses.at(i), {}, ball_seed(seed_, i))});
    }
    return {images_.begin(), images_.begin() + static_cast<std::ptrdiff_t>(n)};
  }
  /// Every view.
  std::vector<TargetImage> all() { return first(poses.size()); }

  const vision::CameraIntrinsics lens = vision::typical_wide_lens(640, 480);
  const TargetSpec target;
  const std::vector<simlab::TargetPose> poses;

 private:
  std::uint64_t seed_;
  std::vector<TargetImage> images_;
};

// Twelve views of the chessboard, sixteen of the ChArUco board (its corners
// are found less precisely, about 0.1 px against 0.05, in the small white
// margin around its markers), shared by the tests of one process.
Views& chessboard_views() {
  static Views v("chessboard:10x7:0.025", 12, 1);
  return v;
}
Views& charuco_views() {
  static Views v("charuco:10x7:0.025:0.018", 16, 1);
  return v;
}

cv::Mat blank(int value = 90) { return cv::Mat(480, 640, CV_8UC1, cv::Scalar(value)); }

std::string failure(std::span<const TargetImage> images, const TargetSpec& target, const IntrinsicsFitConfig& c = {}) {
  return pinball::testing::error_text([&] { (void)calibrate_intrinsics(images, target, c); });
}

// The target: reprojection <= 0.3 px, focal lengths within 0.5 %,
// and the distortion within 0.5 px over the image (out to the sensor's
// corners, where a barrel lens extrapolates, it is reported, not held to it:
// docs/calibration.md).
void expect_recovered(Views& v, const IntrinsicsFit& fit) {
  const IntrinsicsCalibration& c = fit.calibration;
  EXPECT_EQ(c.images_used, static_cast<int>(v.poses.size()));
  EXPECT_EQ(c.images_rejected, 0);
  EXPECT_LE(c.reprojection_rms_px, 0.3);
  EXPECT_GT(c.reprojection_rms_px, 0.01);  // noise and blur leave something
  const LensComparison e = compare_lenses(c.lens, v.lens);
  EXPECT_LT(std::abs(e.fx_error_pct), 0.5);
  EXPECT_LT(std::abs(e.fy_error_pct), 0.5);
  EXPECT_LT(e.principal_point_error_px, 2.0);
  EXPECT_LT(e.distortion_max_error_px, 0.5);
  EXPECT_EQ(c.lens.width_px, 640);
  EXPECT_EQ(c.lens.height_px, 480);
  EXPECT_EQ(c.target, v.target.describe());
  for (const ImageResult& r : fit.images) {
    EXPECT_TRUE(r.used) << r.name << ": " << r.rejection;
    EXPECT_EQ(r.reprojected_px.size(), r.corners_px.size()) << r.name;
    EXPECT_LT(r.reprojection_rms_px, 0.3) << r.name;
  }
}

TEST(IntrinsicsCalibration, RecoversTheLensFromAChessboard) {
  Views& v = chessboard_views();
  const IntrinsicsFit fit = calibrate_intrinsics(v.all(), v.target);
  expect_recovered(v, fit);
  for (const ImageResult& r : fit.images) EXPECT_EQ(r.corners, 54) << r.name;
}

TEST(IntrinsicsCalibration, RecoversTheLensFromACharucoBoard) {
  Views& v = charuco_views();
  const IntrinsicsFit fit = calibrate_intrinsics(v.all(), v.target);
  expect_recovered(v, fit);
  for (const ImageResult& r : fit.images) EXPECT_GE(r.corners, 40) << r.name;
}

TEST(IntrinsicsCalibration, DetectsTheTargetWithIds) {
  Views& v = charuco_views();
  const TargetDetection d = detect_target(v.first(1)[0].gray, v.target);
  EXPECT_TRUE(d.why.empty()) << d.why;
  ASSERT_EQ(d.ids.size(), d.corners_px.size());
  EXPECT_GE(d.ids.size(), 40u);
  const TargetDetection none = detect_target(blank(), v.target);
  EXPECT_EQ(none.why, "target not found");
  EXPECT_TRUE(none.corners_px.empty());
  EXPECT_EQ(detect_target(blank(), chessboard_views().target).why, "target not found");
}

TEST(IntrinsicsCalibration, AnImageWithoutTheTargetIsRejectedByName) {
  Views& v = chessboard_views();
  std::vector<TargetImage> images = v.first(6);
  images.insert(images.begin() + 3, {"lens_cap.png", blank(20)});
  const IntrinsicsFit fit = calibrate_intrinsics(images, v.target);
  ASSERT_EQ(fit.images.size(), 7u);
  EXPECT_EQ(fit.images[3].name, "lens_cap.png");
  EXPECT_FALSE(fit.images[3].used);
  EXPECT_EQ(fit.images[3].rejection, "target not found");
  EXPECT_EQ(fit.calibration.images_used, 6);
  EXPECT_EQ(fit.calibration.images_rejected, 1);
}

// A view through another lens (pincushion instead of barrel) fits the others
// poorly: it is named and left out, and the fit without it is the lens.
TEST(IntrinsicsCalibration, AViewThatFitsPoorlyIsRejectedAndTheFitRepeated) {
  Views& v = chessboard_views();
  std::vector<TargetImage> images = v.first(8);
  vision::CameraIntrinsics other = v.lens;
  other.k1 = 0.15;
  other.k2 = 0.0;
  images.push_back({"other_lens.png", simlab::render_target_view(other, v.target, v.poses[3], {}, 99)});
  const IntrinsicsFit fit = calibrate_intrinsics(images, v.target);
  const ImageResult& odd = fit.images.back();
  EXPECT_FALSE(odd.used);
  EXPECT_EQ(odd.rejection.rfind("reprojection ", 0), 0u) << odd.rejection;
  EXPECT_NE(odd.rejection.find(" px > 1 px"), std::string::npos) << odd.rejection;
  EXPECT_GT(odd.reprojection_rms_px, 1.0);
  EXPECT_EQ(odd.reprojected_px.size(), odd.corners_px.size());  // from the fit that rejected it, for the figure
  EXPECT_EQ(fit.calibration.images_used, 8);
  EXPECT_LE(fit.calibration.reprojection_rms_px, 0.3);
  EXPECT_LT(std::abs(compare_lenses(fit.calibration.lens, v.lens).fx_error_pct), 0.5);
}

TEST(IntrinsicsCalibration, ACharucoViewWithFewCornersIsRejectedSayingHowMany) {
  Views& v = charuco_views();
  std::vector<TargetImage> images = v.first(6);
  // Only the top-left 2x2 squares' neighbourhood stays; the rest is covered.
  std::vector<cv::Point3d> keep{{0.0, 0.0, 0.0}, {0.075, 0.0, 0.0}, {0.075, 0.075, 0.0}, {0.0, 0.075, 0.0}};
  std::vector<cv::Point2d> at;
  cv::projectPoints(keep, v.poses[0].rvec, v.poses[0].tvec_m, cv::Mat(vision::camera_matrix(v.lens)),
                    cv::Mat(vision::distortion_coefficients(v.lens)), at);
  cv::Mat mask(480, 640, CV_8UC1, cv::Scalar(0));
  std::vector<cv::Point> polygon;
  for (const cv::Point2d& p : at) polygon.emplace_back(cvRound(p.x), cvRound(p.y));
  cv::fillConvexPoly(mask, polygon, cv::Scalar(255));
  cv::Mat covered = blank();
  images[0].gray.copyTo(covered, mask);
  const TargetDetection d = detect_target(covered, v.target);
  EXPECT_EQ(d.why.rfind("only ", 0), 0u) << d.why;
  EXPECT_NE(d.why.find(" ChArUco corners"), std::string::npos) << d.why;
  images[0] = {"corner_only.png", covered};
  const IntrinsicsFit fit = calibrate_intrinsics(images, v.target);
  EXPECT_EQ(fit.images[0].rejection, d.why);
  EXPECT_EQ(fit.calibration.images_used, 5);
}

TEST(IntrinsicsCalibration, TooFewImagesShowingTheTargetIsAnErrorNamingThem) {
  Views& v = chessboard_views();
  std::vector<TargetImage> images = v.first(4);
  images.push_back({"dark.png", blank(0)});
  images.push_back({"wall.png", blank(200)});
  EXPECT_EQ(failure(images, v.target),
            "intrinsics: only 4 of 6 images show the target; at least 5 needed (rejected: dark.png target not found, "
            "wall.png target not found)");
  IntrinsicsFitConfig four;
  four.min_images = 4;
  EXPECT_EQ(failure(images, v.target, four), "no error");
  std::vector<TargetImage> none;
  EXPECT_EQ(failure(none, v.target), "intrinsics: no images");
}

// Refused before any image is searched: blank images do.
TEST(IntrinsicsCalibration, ImagesOfAnotherSizeOrNotGrayAreRefusedByName) {
  const TargetSpec target = parse_target("chessboard:10x7:0.025");
  std::vector<TargetImage> images{{"view_1.png", blank()}, {"view_2.png", blank()}};
  images.push_back({"small.png", cv::Mat(240, 320, CV_8UC1, cv::Scalar(90))});
  EXPECT_EQ(failure(images, target), "small.png: 320x240, but view_1.png is 640x480");
  images.back() = {"colour.png", cv::Mat(480, 640, CV_8UC3, cv::Scalar(90, 90, 90))};
  EXPECT_EQ(failure(images, target), "colour.png: not an 8-bit gray image (3 channels, 8-bit)");
  images.back() = {"deep.png", cv::Mat(480, 640, CV_16UC1, cv::Scalar(90))};
  EXPECT_EQ(failure(images, target), "deep.png: not an 8-bit gray image (1 channels, 16-bit)");
  images.back() = {"empty.png", cv::Mat()};
  EXPECT_EQ(failure(images, target), "empty.png: empty image");
}

TEST(IntrinsicsCalibration, RefusesBadSettings) {
  const TargetSpec target = parse_target("chessboard:10x7:0.025");
  const std::vector<TargetImage> images{{"a.png", blank()}};
  IntrinsicsFitConfig c;
  c.min_images = 2;
  EXPECT_THROW((void)calibrate_intrinsics(images, target, c), std::invalid_argument);
  c = {};
  c.max_image_rms_px = 0.0;
  EXPECT_THROW((void)calibrate_intrinsics(images, target, c), std::invalid_argument);
  c = {};
  c.min_corners = 3;
  EXPECT_THROW((void)calibrate_intrinsics(images, target, c), std::invalid_argument);
  TargetSpec t = target;
  t.squares_x = 2;
  EXPECT_THROW((void)calibrate_intrinsics(images, t, {}), std::invalid_argument);
}

TEST(IntrinsicsCalibration, ComparesLenses) {
  const vision::CameraIntrinsics truth = vision::typical_wide_lens(640, 480);
  const LensComparison same = compare_lenses(truth, truth);
  EXPECT_EQ(same.fx_error_pct, 0.0);
  EXPECT_EQ(same.principal_point_error_px, 0.0);
  EXPECT_LT(same.distortion_max_error_px, 1e-9);
  EXPECT_LT(same.distortion_sensor_max_error_px, 1e-9);
  vision::CameraIntrinsics other = truth;
  other.fx_px *= 1.01;
  other.cx_px += 3.0;
  other.cy_px -= 4.0;
  other.k1 = -0.2;
  const LensComparison e = compare_lenses(other, truth);
  EXPECT_NEAR(e.fx_error_pct, 1.0, 1e-9);
  EXPECT_EQ(e.fy_error_pct, 0.0);
  EXPECT_NEAR(e.principal_point_error_px, 5.0, 1e-9);
  EXPECT_GT(e.distortion_max_error_px, 5.0);  // k1 -0.2 instead of -0.25 moves the corners by pixels
  EXPECT_GT(e.distortion_sensor_max_error_px, e.distortion_max_error_px);  // the sensor reaches further out
  EXPECT_THROW((void)compare_lenses(vision::typical_wide_lens(800, 600), truth), std::invalid_argument);
}

TEST(IntrinsicsCalibration, FigureShowsEveryImage) {
  Views& v = chessboard_views();
  std::vector<TargetImage> images = v.first(5);
  images.push_back({"lens_cap.png", blank(20)});
  const IntrinsicsFit fit = calibrate_intrinsics(images, v.target);
  const cv::Mat fig = draw_intrinsics_figure(fit, images);
  ASSERT_EQ(fig.type(), CV_8UC3);
  const int grid_w = 4 * (320 + 8) + 8, grid_h = 8 + 2 * (240 + 40 + 8);  // six thumbnails: two rows
  EXPECT_GT(fig.cols, grid_w + 100) << "the legend beside the thumbnails";
  EXPECT_GT(fig.rows, grid_h + 60) << "the title and its notes above";
  const int grid_y = fig.rows - grid_h;
  // The title banner carries text; the rejected image's caption is in the "not found" colour.
  EXPECT_GT(pinball::testing::count_ink(fig(cv::Rect(0, 0, fig.cols, grid_y))), 500);
  EXPECT_GT(pinball::testing::count_colour(fig(cv::Rect(8 + 328, grid_y + 8 + 288 + 240, 320, 40)),
                                           plot::palette_colour(1), 30),
            20);
  // Written and read back: the corners, the arrows and the legend's swatches in their palette colours.
  const std::string png = pinball::testing::temp_path("intrinsics_figure", "fig.png");
  plot::write_png(fig, png);
  pinball::testing::expect_figure(png, cv::Size(grid_w + 100, grid_h + 60), 3);
  std::remove(png.c_str());
  EXPECT_THROW((void)draw_intrinsics_figure(fit, v.first(3)), std::invalid_argument);
}

}  // namespace
}  // namespace pinball::calibration
