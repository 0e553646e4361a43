#include "pinball/vision/lens_model.h"

#include <cmath>
#include <stdexcept>

#include <opencv2/calib3d.hpp>

namespace pinball::vision {

CameraIntrinsics typical_wide_lens(int width_px, int height_px) {
  const double scale = width_px / 640.0;
  CameraIntrinsics c;
  c.width_px = width_px;
  c.height_px = height_px;
  c.fx_px = 530.0 * scale;
  c.fy_px = 530.0 * scale;
  // A lens is never centred on the sensor exactly: a few pixels off.
  c.cx_px = 0.5 * (width_px - 1) + 4.0 * scale;
  c.cy_px = 0.5 * (height_px - 1) - 3.0 * scale;
  c.k1 = -0.25;
  c.k2 = 0.08;
  c.k3 = 0.0;
  c.p1 = 0.0008;
  c.p2 = -0.0005;
  return c;
}

CameraIntrinsics without_distortion(CameraIntrinsics intrinsics) {
  intrinsics.k1 = intrinsics.k2 = intrinsics.k3 = intrinsics.p1 = intrinsics.p2 = 0.0;
  return intrinsics;
}

bool has_distortion(const CameraIntrinsics& c) {
  return c.k1 != 0.0 || c.k2 != 0.0 || c.k3 != 0.0 || c.p1 != 0.0 || c.p2 != 0.0;
}

RangeViolation check_intrinsics(const CameraIntrinsics& c) {
  if (c.width_px < 32 || c.width_px > 8192) return {"width_px", "must be in [32, 8192] px"};
  if (c.height_px < 32 || c.height_px > 8192) return {"height_px", "must be in [32, 8192] px"};
  if (!std::isfinite(c.fx_px) || !(c.fx_px > 0.0)) return {"fx_px", "must be > 0 px"};
  if (!std::isfinite(c.fy_px) || !(c.fy_px > 0.0)) return {"fy_px", "must be > 0 px"};
  if (!std::isfinite(c.cx_px) || c.cx_px < 0.0 || c.cx_px > c.width_px) return {"cx_px", "must be inside the image"};
  if (!std::isfinite(c.cy_px) || c.cy_px < 0.0 || c.cy_px > c.height_px) return {"cy_px", "must be inside the image"};
  const std::array<std::pair<const char*, double>, 5> coefficients{
      {{"k1", c.k1}, {"k2", c.k2}, {"k3", c.k3}, {"p1", c.p1}, {"p2", c.p2}}};
  for (const auto& [name, value] : coefficients) {
    if (!std::isfinite(value) || std::abs(value) >= 10.0) return {name, "must be finite and in (-10, 10)"};
  }
  return {};
}

cv::Matx33d camera_matrix(const CameraIntrinsics& c) {
  return {c.fx_px, 0.0, c.cx_px, 0.0, c.fy_px, c.cy_px, 0.0, 0.0, 1.0};
}

cv::Vec<double, 5> distortion_coefficients(const CameraIntrinsics& c) { return {c.k1, c.k2, c.p1, c.p2, c.k3}; }

CameraIntrinsics intrinsics_from_opencv(const cv::Matx33d& k, const cv::Mat& coefficients, cv::Size image_size) {
  cv::Mat d;
  coefficients.convertTo(d, CV_64F);
  d = d.reshape(1, 1);
  check_input(d.cols == 4 || d.cols >= 5, "intrinsics", "expected 4, 5 or more distortion coefficients");
  for (int i = 5; i < d.cols; ++i) {
    check_input(d.at<double>(0, i) == 0.0, "intrinsics", "only k1, k2, p1, p2, k3 are modelled; higher terms must be 0");
  }
  CameraIntrinsics c;
  c.width_px = image_size.width;
  c.height_px = image_size.height;
  c.fx_px = k(0, 0);
  c.fy_px = k(1, 1);
  c.cx_px = k(0, 2);
  c.cy_px = k(1, 2);
  c.k1 = d.at<double>(0, 0);
  c.k2 = d.at<double>(0, 1);
  c.p1 = d.at<double>(0, 2);
  c.p2 = d.at<double>(0, 3);
  c.k3 = d.cols >= 5 ? d.at<double>(0, 4) : 0.0;
  return c;
}

cv::Point2d distort_pixel(const CameraIntrinsics& c, const cv::Point2d& ideal_px) {
  const double x = (ideal_px.x - c.cx_px) / c.fx_px;
  const double y = (ideal_px.y - c.cy_px) / c.fy_px;
  const double r2 = x * x + y * y;
  const double radial = 1.0 + r2 * (c.k1 + r2 * (c.k2 + r2 * c.k3));
  const double xd = x * radial + 2.0 * c.p1 * x * y + c.p2 * (r2 + 2.0 * x * x);
  const double yd = y * radial + c.p1 * (r2 + 2.0 * y * y) + 2.0 * c.p2 * x * y;
  return {c.fx_px * xd + c.cx_px, c.fy_px * yd + c.cy_px};
}

PointUndistorter::PointUndistorter(const CameraIntrinsics& intrinsics)
    : intrinsics_(intrinsics), k_(camera_matrix(intrinsics)) {
  check_input(check_intrinsics(intrinsics), "lens");
  const cv::Vec<double, 5> d = distortion_coefficients(intrinsics);
  for (int i = 0; i < 5; ++i) d_(0, i) = d[i];
}

cv::Point2d PointUndistorter::ideal_from_distorted(const cv::Point2d& distorted_px) const {
  if (!has_distortion(intrinsics_)) return distorted_px;
  // Matx-backed arrays: OpenCV wraps them without copying, so nothing is allocated.
  cv::Matx<double, 1, 2> src(distorted_px.x, distorted_px.y);
  cv::Matx<double, 1, 2> dst;
  cv::Mat src_view(1, 1, CV_64FC2, src.val);
  cv::Mat dst_view(1, 1, CV_64FC2, dst.val);
  // OpenCV's default stops after 5 iterations, which leaves tenths of a pixel
  // at the corners of a wide lens; iterate to 1e-6 px instead. No P: OpenCV
  // would multiply it in with a temporary matrix (an allocation per call); the
  // normalised point goes back to pixels through K here.
  cv::undistortPoints(src_view, dst_view, k_, d_, cv::noArray(), cv::noArray(),
                      cv::TermCriteria(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, 50, 1e-6));
  return {intrinsics_.fx_px * dst(0, 0) + intrinsics_.cx_px, intrinsics_.fy_px * dst(0, 1) + intrinsics_.cy_px};
}

}  // namespace pinball::vision
