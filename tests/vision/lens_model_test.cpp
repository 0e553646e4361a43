#include "pinball/vision/lens_model.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <vector>

#include <gtest/gtest.h>
#include <opencv2/calib3d.hpp>

namespace pinball::vision {
namespace {

TEST(LensModel, WithoutDistortionEveryPixelStaysPut) {
  const CameraIntrinsics lens = without_distortion(typical_wide_lens());
  EXPECT_FALSE(has_distortion(lens));
  const PointUndistorter undistorter(lens);
  for (const cv::Point2d p : {cv::Point2d(0, 0), cv::Point2d(320, 240), cv::Point2d(639, 479)}) {
    EXPECT_EQ(distort_pixel(lens, p), p);
    EXPECT_EQ(undistorter.ideal_from_distorted(p), p);
  }
}

TEST(LensModel, ClosedFormDistortionIsOpenCvsProjection) {
  const CameraIntrinsics lens = typical_wide_lens();
  std::vector<cv::Point3d> rays;
  for (double x = -0.7; x <= 0.7; x += 0.35) {
    for (double y = -0.5; y <= 0.5; y += 0.25) rays.emplace_back(x, y, 1.0);
  }
  std::vector<cv::Point2d> projected;
  cv::projectPoints(rays, cv::Vec3d(0, 0, 0), cv::Vec3d(0, 0, 0), camera_matrix(lens), distortion_coefficients(lens),
                    projected);
  for (std::size_t i = 0; i < rays.size(); ++i) {
    const cv::Point2d ideal(lens.fx_px * rays[i].x + lens.cx_px, lens.fy_px * rays[i].y + lens.cy_px);
    EXPECT_LT(cv::norm(distort_pixel(lens, ideal) - projected[i]), 1e-9) << i;
  }
}

TEST(LensModel, TheTypicalWideLensMovesTheCornersByManyPixels) {
  const CameraIntrinsics lens = typical_wide_lens();
  const PointUndistorter undistorter(lens);
  // The sensor's corner shows a point the ideal camera would see far outside it (barrel).
  const cv::Point2d corner(0.0, 0.0);
  const double shift = cv::norm(undistorter.ideal_from_distorted(corner) - corner);
  EXPECT_GT(shift, 30.0);
  EXPECT_LT(shift, 120.0);
  // Near the principal point almost nothing moves.
  const cv::Point2d centre(lens.cx_px + 5.0, lens.cy_px - 5.0);
  EXPECT_LT(cv::norm(undistorter.ideal_from_distorted(centre) - centre), 0.05);
}

TEST(LensModel, UndistortionInvertsDistortionEverywhereInTheImage) {
  const CameraIntrinsics lens = typical_wide_lens();
  const PointUndistorter undistorter(lens);
  double worst = 0.0;
  for (double v = 0.0; v <= 479.0; v += 47.9) {
    for (double u = 0.0; u <= 639.0; u += 63.9) {
      const cv::Point2d sensor(u, v);
      const cv::Point2d back = distort_pixel(lens, undistorter.ideal_from_distorted(sensor));
      worst = std::max(worst, cv::norm(back - sensor));
    }
  }
  EXPECT_LT(worst, 1e-4);
}

// OpenCV's fixed-point undistortion wandered off on a short, strongly barrelled lens whose inverse
// exists everywhere (its radial map rises monotonically): 7 % of the image came back up to 292 px wrong.
TEST(LensModel, UndistortionInvertsAShortStronglyBarrelledLensToo) {
  CameraIntrinsics lens = typical_wide_lens();
  lens.fx_px = lens.fy_px = 373.0;  // a 2.8 mm lens
  lens.k1 = -0.4;
  lens.k2 = 0.08;
  ASSERT_FALSE(check_intrinsics(lens));
  const PointUndistorter undistorter(lens);
  double worst_px = 0.0;
  for (double v = 0.0; v < 480.0; v += 8.0) {
    for (double u = 0.0; u < 640.0; u += 8.0) {
      const cv::Point2d p(u, v);
      worst_px = std::max(worst_px, cv::norm(distort_pixel(lens, undistorter.ideal_from_distorted(p)) - p));
    }
  }
  EXPECT_LT(worst_px, 1e-3);
  const cv::Point2d corner(600.0, 440.0);  // where the fixed point had returned (826.7, 604.3)
  EXPECT_LT(cv::norm(undistorter.ideal_from_distorted(corner) - ideal_from_distorted_newton(lens, corner)), 1e-3);
}

TEST(LensModel, TheSimulatorsNewtonInverseAgreesWithOpenCvs) {
  // Two independent inverses: the simulator's (Newton) and the detector's (cv::undistortPoints).
  const CameraIntrinsics lens = typical_wide_lens();
  const PointUndistorter undistorter(lens);
  for (double v = 0.0; v <= 479.0; v += 95.8) {
    for (double u = 0.0; u <= 639.0; u += 127.8) {
      const cv::Point2d sensor(u, v);
      EXPECT_LT(cv::norm(ideal_from_distorted_newton(lens, sensor) - undistorter.ideal_from_distorted(sensor)), 1e-4);
      EXPECT_LT(cv::norm(distort_pixel(lens, ideal_from_distorted_newton(lens, sensor)) - sensor), 1e-9);
    }
  }
}

TEST(LensModel, ScalesWithTheImage) {
  const CameraIntrinsics small = typical_wide_lens(640, 480);
  const CameraIntrinsics large = typical_wide_lens(1280, 960);
  EXPECT_DOUBLE_EQ(large.fx_px, 2.0 * small.fx_px);
  EXPECT_EQ(large.width_px, 1280);
  EXPECT_DOUBLE_EQ(large.k1, small.k1);
}

TEST(LensModel, OpenCvsCoefficientsComeBackAsTheyWent) {
  const CameraIntrinsics lens = typical_wide_lens();
  const cv::Vec<double, 5> d = distortion_coefficients(lens);
  const CameraIntrinsics back = intrinsics_from_opencv(camera_matrix(lens), cv::Mat(d).reshape(1, 1), {640, 480});
  EXPECT_DOUBLE_EQ(back.k1, lens.k1);
  EXPECT_DOUBLE_EQ(back.p2, lens.p2);
  EXPECT_DOUBLE_EQ(back.cx_px, lens.cx_px);
  EXPECT_EQ(back.height_px, 480);
  // Eight coefficients whose rational terms are not zero are a model we do not have.
  cv::Mat eight = cv::Mat::zeros(1, 8, CV_64F);
  eight.at<double>(0, 5) = 0.1;
  EXPECT_THROW(intrinsics_from_opencv(camera_matrix(lens), eight, {640, 480}), std::invalid_argument);
}

TEST(LensModel, OutOfRangeIntrinsicsAreNamed) {
  CameraIntrinsics lens = typical_wide_lens();
  EXPECT_FALSE(check_intrinsics(lens));
  lens.fx_px = 0.0;
  EXPECT_EQ(check_intrinsics(lens).key, "fx_px");
  lens = typical_wide_lens();
  lens.cx_px = 700.0;
  EXPECT_EQ(check_intrinsics(lens).key, "cx_px");
  lens = typical_wide_lens();
  lens.k2 = std::nan("");
  EXPECT_EQ(check_intrinsics(lens).key, "k2");
  EXPECT_THROW(PointUndistorter{lens}, std::invalid_argument);
  // Fifteen views of no one camera fitted fx 1802 px, fy 748 px, and were written as a lens.
  lens = typical_wide_lens();
  lens.fx_px = 1802.0;
  lens.fy_px = 748.0;
  EXPECT_EQ(check_intrinsics(lens).key, "fy_px");
  EXPECT_EQ(check_intrinsics(lens).rule, "must be within a factor 1.25 of fx_px (pixels are square)");
  lens.fy_px = 1802.0 * 1.02;  // a real sensor's few per cent
  EXPECT_FALSE(check_intrinsics(lens));
}

TEST(LensModel, ABlobsCentroidIsUndistortedToSecondOrder) {
  // A uniform disc of radius 7 px far out in the ideal image, seen through the
  // lens: its sensor pixels' centroid, undistorted as a point, misses the
  // disc's centre by the lens's curvature across it; the second-order terms
  // recover it.
  const CameraIntrinsics lens = typical_wide_lens();
  const PointUndistorter undistorter(lens);
  const cv::Point2d centre(40.0, 45.0);
  const double r = 7.0;
  // Sensor pixels whose ideal point falls in the disc: a fine grid, area-weighted by construction.
  double n = 0.0;
  cv::Point2d sum(0.0, 0.0);
  double suu = 0.0, svv = 0.0, suv = 0.0;
  const cv::Point2d c0 = distort_pixel(lens, centre);
  for (double v = c0.y - 12.0; v <= c0.y + 12.0; v += 0.05) {
    for (double u = c0.x - 12.0; u <= c0.x + 12.0; u += 0.05) {
      if (cv::norm(undistorter.ideal_from_distorted({u, v}) - centre) > r) continue;
      n += 1.0;
      sum += cv::Point2d(u, v);
      suu += u * u;
      svv += v * v;
      suv += u * v;
    }
  }
  const cv::Point2d c = sum * (1.0 / n);
  const cv::Matx22d cov(suu / n - c.x * c.x, suv / n - c.x * c.y, suv / n - c.x * c.y, svv / n - c.y * c.y);
  const double first_order = cv::norm(undistorter.ideal_from_distorted(c) - centre);
  const double second_order = cv::norm(undistorter.ideal_centroid(c, cov) - centre);
  EXPECT_GT(first_order, 0.01);
  EXPECT_LT(second_order, 0.3 * first_order);
  EXPECT_LT(second_order, 0.01);
}

}  // namespace
}  // namespace pinball::vision
