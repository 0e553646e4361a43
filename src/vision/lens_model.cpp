#include "pinball/vision/lens_model.h"

#include <cmath>
#include <stdexcept>

#include <opencv2/calib3d.hpp>

#include "pinball/core/format.h"

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
  // Pixels are square to a few per cent: fx 1800 px with fy 750 px is views of no one camera.
  if (!(c.fy_px <= kMostPixelAspect * c.fx_px && c.fx_px <= kMostPixelAspect * c.fy_px)) {
    return {"fy_px", "must be within a factor " + format_number(kMostPixelAspect) + " of fx_px (pixels are square)"};
  }
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

void undistort_normalised(const CameraIntrinsics& c, double xd, double yd, double& x, double& y) {
  for (int it = 0; it < 30; ++it) {
    const double r2 = x * x + y * y;
    const double radial = 1.0 + r2 * (c.k1 + r2 * (c.k2 + r2 * c.k3));
    const double dradial = c.k1 + r2 * (2.0 * c.k2 + 3.0 * r2 * c.k3);  // d radial / d r2
    const double fx = x * radial + 2.0 * c.p1 * x * y + c.p2 * (r2 + 2.0 * x * x) - xd;
    const double fy = y * radial + c.p1 * (r2 + 2.0 * y * y) + 2.0 * c.p2 * x * y - yd;
    const double a = radial + 2.0 * x * x * dradial + 2.0 * c.p1 * y + 6.0 * c.p2 * x;
    const double b = 2.0 * x * y * dradial + 2.0 * c.p1 * x + 2.0 * c.p2 * y;
    const double d = radial + 2.0 * y * y * dradial + 6.0 * c.p1 * y + 2.0 * c.p2 * x;
    const double det = a * d - b * b;  // the Jacobian is symmetric: [[a, b], [b, d]]
    if (!(std::abs(det) > 0.0) || !std::isfinite(det)) return;  // a fold of the lens: no step from here
    const double dx = (d * fx - b * fy) / det, dy = (a * fy - b * fx) / det;
    x -= dx;
    y -= dy;
    if (std::abs(dx) + std::abs(dy) < 1e-12) return;
  }
}

cv::Point2d ideal_from_distorted_newton(const CameraIntrinsics& c, const cv::Point2d& distorted_px) {
  const double xd = (distorted_px.x - c.cx_px) / c.fx_px;
  const double yd = (distorted_px.y - c.cy_px) / c.fy_px;
  double x = xd, y = yd;
  undistort_normalised(c, xd, yd, x, y);
  return {c.fx_px * x + c.cx_px, c.fy_px * y + c.cy_px};
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
  const cv::Point2d fixed_point(intrinsics_.fx_px * dst(0, 0) + intrinsics_.cx_px,
                                intrinsics_.fy_px * dst(0, 1) + intrinsics_.cy_px);
  // OpenCV's fixed-point iteration can wander off where the inverse exists: on a short, strongly
  // barrelled lens (fx 373 px, k1 -0.4, k2 0.08) 7 % of the image came back up to 292 px wrong.
  // Checked by distorting it again; Newton's method from there where it missed.
  const double missed_px = cv::norm(distort_pixel(intrinsics_, fixed_point) - distorted_px);
  if (missed_px <= 1e-3) return fixed_point;
  double x = (fixed_point.x - intrinsics_.cx_px) / intrinsics_.fx_px;
  double y = (fixed_point.y - intrinsics_.cy_px) / intrinsics_.fy_px;
  if (!std::isfinite(x) || !std::isfinite(y)) {
    x = (distorted_px.x - intrinsics_.cx_px) / intrinsics_.fx_px;
    y = (distorted_px.y - intrinsics_.cy_px) / intrinsics_.fy_px;
  }
  undistort_normalised(intrinsics_, (distorted_px.x - intrinsics_.cx_px) / intrinsics_.fx_px,
                       (distorted_px.y - intrinsics_.cy_px) / intrinsics_.fy_px, x, y);
  const cv::Point2d newton(intrinsics_.fx_px * x + intrinsics_.cx_px, intrinsics_.fy_px * y + intrinsics_.cy_px);
  const double newton_missed_px = cv::norm(distort_pixel(intrinsics_, newton) - distorted_px);
  return newton_missed_px < missed_px ? newton : fixed_point;  // the better of the two (a fold has no exact one)
}

cv::Point2d PointUndistorter::ideal_centroid(const cv::Point2d& c, const cv::Matx22d& cov) const {
  if (!has_distortion(intrinsics_)) return c;
  // The blob's ideal centroid is Σ U(p) J(p) / Σ J(p) over its pixels p (U: the
  // undistortion, J = det dU/dp: ideal area per sensor pixel). To second order
  // about the sensor centroid c (E[p − c] = 0, E[(p − c)(p − c)ᵀ] = Σ):
  //   U(c) + ½ tr(H_U Σ) + A Σ ∇J / J,   A = dU/dp, H_U its Hessian per component,
  // all from central differences on a 3x3 grid of step h.
  constexpr double h = 2.0;
  cv::Point2d g[3][3];
  for (int j = 0; j < 3; ++j) {
    for (int i = 0; i < 3; ++i) g[j][i] = ideal_from_distorted(c + cv::Point2d((i - 1) * h, (j - 1) * h));
  }
  const cv::Point2d u0 = g[1][1];
  const cv::Point2d du = (g[1][2] - g[1][0]) * (0.5 / h);  // ∂U/∂u
  const cv::Point2d dv = (g[2][1] - g[0][1]) * (0.5 / h);  // ∂U/∂v
  const cv::Point2d duu = (g[1][2] - 2.0 * u0 + g[1][0]) * (1.0 / (h * h));
  const cv::Point2d dvv = (g[2][1] - 2.0 * u0 + g[0][1]) * (1.0 / (h * h));
  const cv::Point2d duv = (g[2][2] - g[2][0] - g[0][2] + g[0][0]) * (0.25 / (h * h));
  const double a11 = du.x, a12 = dv.x, a21 = du.y, a22 = dv.y;
  const double jac = a11 * a22 - a12 * a21;
  // ∇J from the Hessians: ∂A11/∂u = ∂²U1/∂u², ∂A22/∂u = ∂²U2/∂u∂v, ...
  const double dj_du = duu.x * a22 + a11 * duv.y - duv.x * a21 - a12 * duu.y;
  const double dj_dv = duv.x * a22 + a11 * dvv.y - dvv.x * a21 - a12 * duv.y;
  const double s_uu = cov(0, 0), s_uv = cov(0, 1), s_vv = cov(1, 1);
  const cv::Point2d curvature = 0.5 * (duu * s_uu + 2.0 * duv * s_uv + dvv * s_vv);
  // A Σ ∇J / J
  const double sg_u = (s_uu * dj_du + s_uv * dj_dv) / jac;
  const double sg_v = (s_uv * dj_du + s_vv * dj_dv) / jac;
  const cv::Point2d area(a11 * sg_u + a12 * sg_v, a21 * sg_u + a22 * sg_v);
  return u0 + curvature + area;
}

}  // namespace pinball::vision
