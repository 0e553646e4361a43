#include "pinball/simlab/sim_target_view.h"

#include <cmath>
#include <stdexcept>

#include <gtest/gtest.h>
#include <opencv2/calib3d.hpp>

#include "pinball/calibration/intrinsics_calibration.h"

namespace pinball::simlab {
namespace {

const vision::CameraIntrinsics kLens = vision::typical_wide_lens(640, 480);

std::vector<cv::Point2d> true_corners(const calibration::TargetSpec& t, const TargetPose& pose) {
  std::vector<cv::Point2d> out;
  cv::projectPoints(calibration::target_points_m(t), pose.rvec, pose.tvec_m, cv::Mat(vision::camera_matrix(kLens)),
                    cv::Mat(vision::distortion_coefficients(kLens)), out);
  return out;
}

TEST(SimTargetView, InvertsTheLensModel) {
  for (int i = 0; i <= 8; ++i) {
    for (int k = 0; k <= 6; ++k) {
      const cv::Point2d seen(639.0 * i / 8, 479.0 * k / 6);
      const cv::Point2d ideal = vision::ideal_from_distorted_newton(kLens, seen);
      EXPECT_LT(cv::norm(vision::distort_pixel(kLens, ideal) - seen), 1e-9) << seen;
    }
  }
  // The barrel lens shows the corner's ray well inside: its ideal pixel lies outside the image.
  EXPECT_LT(vision::ideal_from_distorted_newton(kLens, {0.0, 0.0}).x, -20.0);
}

// The chessboard's corners land where cv::projectPoints with the true lens
// puts them: sub-pixel, in the middle and in a corner of the image.
TEST(SimTargetView, ChessboardCornersLandWhereTheLensProjectsThem) {
  const calibration::TargetSpec t = calibration::parse_target("chessboard:10x7:0.025");
  const std::vector<TargetPose> poses = default_target_poses(t, kLens, 2, 5);  // the middle, then the top-left corner
  TargetViewOptions quiet;
  quiet.noise_sigma = 0.0;
  for (const TargetPose& pose : poses) {
    const calibration::TargetDetection d = calibration::detect_target(render_target_view(kLens, t, pose, quiet, 1), t);
    ASSERT_TRUE(d.why.empty()) << d.why;
    ASSERT_EQ(d.corners_px.size(), 54u);
    const std::vector<cv::Point2d> truth = true_corners(t, pose);
    // findChessboardCorners may number the corners from either end: match each to the nearest.
    double worst = 0.0, sum2 = 0.0;
    for (const cv::Point2d& c : d.corners_px) {
      double nearest = 1e9;
      for (const cv::Point2d& p : truth) nearest = std::min(nearest, cv::norm(p - c));
      worst = std::max(worst, nearest);
      sum2 += nearest * nearest;
    }
    EXPECT_LT(worst, 0.3);
    EXPECT_LT(std::sqrt(sum2 / 54.0), 0.1);
  }
}

TEST(SimTargetView, CharucoCornersLandWhereTheLensProjectsThemById) {
  const calibration::TargetSpec t = calibration::parse_target("charuco:10x7:0.025:0.018");
  const std::vector<TargetPose> poses = default_target_poses(t, kLens, 1, 3);
  TargetViewOptions quiet;
  quiet.noise_sigma = 0.0;
  const calibration::TargetDetection d = calibration::detect_target(render_target_view(kLens, t, poses[0], quiet, 1), t);
  ASSERT_TRUE(d.why.empty()) << d.why;
  EXPECT_GE(d.ids.size(), 50u);
  const std::vector<cv::Point2d> truth = true_corners(t, poses[0]);
  for (std::size_t i = 0; i < d.ids.size(); ++i) {
    EXPECT_LT(cv::norm(d.corners_px[i] - truth[static_cast<std::size_t>(d.ids[i])]), 0.4) << "corner " << d.ids[i];
  }
}

TEST(SimTargetView, PosesShowTheWholeSheetOverTheImage) {
  const calibration::TargetSpec t = calibration::parse_target("chessboard:10x7:0.025");
  const std::vector<TargetPose> poses = default_target_poses(t, kLens, 9, 1);
  ASSERT_EQ(poses.size(), 9u);
  const double b = 0.5 * t.square_m;
  const std::vector<cv::Point3d> sheet{{-b, -b, 0.0}, {0.25 + b, -b, 0.0}, {0.25 + b, 0.175 + b, 0.0}, {-b, 0.175 + b, 0.0}};
  // For each corner of the image, a view whose sheet reaches within 20 px of both edges that meet there.
  bool corner_reached[2][2] = {{false, false}, {false, false}};
  for (const TargetPose& pose : poses) {
    cv::Matx33d r;
    cv::Rodrigues(pose.rvec, r);
    const double tilt_deg = std::acos(r(2, 2)) * 180.0 / M_PI;  // the sheet's normal against the optical axis
    EXPECT_GT(tilt_deg, 10.0);
    EXPECT_LT(tilt_deg, 36.0);
    std::vector<cv::Point2d> corners;
    cv::projectPoints(sheet, pose.rvec, pose.tvec_m, cv::Mat(vision::camera_matrix(kLens)),
                      cv::Mat(vision::distortion_coefficients(kLens)), corners);
    double x_lo = 1e9, x_hi = -1e9, y_lo = 1e9, y_hi = -1e9;
    for (const cv::Point2d& c : corners) {
      EXPECT_GE(c.x, 0.0);
      EXPECT_GE(c.y, 0.0);
      EXPECT_LE(c.x, 639.0);
      EXPECT_LE(c.y, 479.0);
      x_lo = std::min(x_lo, c.x);
      x_hi = std::max(x_hi, c.x);
      y_lo = std::min(y_lo, c.y);
      y_hi = std::max(y_hi, c.y);
    }
    for (int right = 0; right < 2; ++right) {
      for (int bottom = 0; bottom < 2; ++bottom) {
        if ((right ? x_hi > 619.0 : x_lo < 20.0) && (bottom ? y_hi > 459.0 : y_lo < 20.0)) {
          corner_reached[right][bottom] = true;
        }
      }
    }
  }
  for (int i = 0; i < 2; ++i) {
    for (int k = 0; k < 2; ++k) EXPECT_TRUE(corner_reached[i][k]) << "no view in corner " << i << "," << k;
  }
}

TEST(SimTargetView, DeterministicBySeed) {
  const calibration::TargetSpec t = calibration::parse_target("chessboard:10x7:0.025");
  EXPECT_EQ(default_target_poses(t, kLens, 3, 7)[2].tvec_m, default_target_poses(t, kLens, 3, 7)[2].tvec_m);
  EXPECT_NE(default_target_poses(t, kLens, 3, 7)[2].tvec_m, default_target_poses(t, kLens, 3, 8)[2].tvec_m);
  TargetViewOptions small;
  small.supersample = 1;
  const TargetPose pose = default_target_poses(t, kLens, 1, 1)[0];
  const cv::Mat a = render_target_view(kLens, t, pose, small, 4), b = render_target_view(kLens, t, pose, small, 4);
  const cv::Mat c = render_target_view(kLens, t, pose, small, 5);
  EXPECT_EQ(cv::norm(a, b, cv::NORM_INF), 0.0);
  EXPECT_GT(cv::norm(a, c, cv::NORM_INF), 0.0);
  // The sheet, the ink and the background are where they should be.
  ASSERT_EQ(a.type(), CV_8UC1);
  EXPECT_NEAR(a.at<std::uint8_t>(2, 2), 90, 10);  // background in the corner
}

TEST(SimTargetView, RefusesBadSettings) {
  const calibration::TargetSpec t = calibration::parse_target("chessboard:10x7:0.025");
  const TargetPose pose = default_target_poses(t, kLens, 1, 1)[0];
  TargetViewOptions o;
  o.supersample = 0;
  EXPECT_THROW((void)render_target_view(kLens, t, pose, o, 1), std::invalid_argument);
  o = {};
  o.ink_gray = 300;
  EXPECT_THROW((void)render_target_view(kLens, t, pose, o, 1), std::invalid_argument);
  vision::CameraIntrinsics bad = kLens;
  bad.fx_px = 0.0;
  EXPECT_THROW((void)render_target_view(bad, t, pose, {}, 1), std::invalid_argument);
  EXPECT_THROW((void)default_target_poses(t, kLens, 0, 1), std::invalid_argument);
}

}  // namespace
}  // namespace pinball::simlab
