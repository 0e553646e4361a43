#pragma once
// The camera's lens: pinhole intrinsics and Brown–Conrady distortion, in
// OpenCV's convention (docs.opencv.org calib3d): a ray through the pinhole
// meets the normalised plane at (x, y); the lens moves it to
//   x' = x (1 + k1 r² + k2 r⁴ + k3 r⁶) + 2 p1 x y + p2 (r² + 2 x²)
//   y' = y (1 + k1 r² + k2 r⁴ + k3 r⁶) + p1 (r² + 2 y²) + 2 p2 x y
// and the sensor sees u = fx x' + cx, v = fy y' + cy. The table's homography
// maps the board to the *ideal* (undistorted) image u = fx x + cx, v = fy y + cy;
// the detector undistorts one centroid per frame (cv::undistortPoints) before
// applying it, never the whole frame.

#include <array>

#include <opencv2/core.hpp>

#include "pinball/core/check.h"
#include "pinball/core/name_value.h"

namespace pinball::vision {

/// A camera's intrinsics for images of one size.
struct CameraIntrinsics {
  int width_px = 640;     ///< image size the intrinsics belong to (px)
  int height_px = 480;
  double fx_px = 530.0;   ///< focal length along u (px)
  double fy_px = 530.0;   ///< focal length along v (px)
  double cx_px = 319.5;   ///< principal point (px)
  double cy_px = 239.5;
  double k1 = 0.0;        ///< radial distortion coefficients (of r², r⁴, r⁶ in the normalised plane)
  double k2 = 0.0;
  double k3 = 0.0;
  double p1 = 0.0;        ///< tangential (decentring) distortion coefficients
  double p2 = 0.0;

  /// The fields as files and reports spell them (core/json_write_archive.h, yaml_read_archive.h).
  template <class Archive>
  void Serialize(Archive* a) {
    a->Visit(PINBALL_NVP(width_px));
    a->Visit(PINBALL_NVP(height_px));
    a->Visit(PINBALL_NVP(fx_px));
    a->Visit(PINBALL_NVP(fy_px));
    a->Visit(PINBALL_NVP(cx_px));
    a->Visit(PINBALL_NVP(cy_px));
    a->Visit(PINBALL_NVP(k1));
    a->Visit(PINBALL_NVP(k2));
    a->Visit(PINBALL_NVP(k3));
    a->Visit(PINBALL_NVP(p1));
    a->Visit(PINBALL_NVP(p2));
  }
};

/// A 640x480 camera with a 4 mm lens on a 1/3" sensor (4.8 mm wide: fx = 4/4.8·640
/// ≈ 530 px, a 62° horizontal view that takes in a 1.07 m table from 0.9 m) and the
/// barrel distortion of such a wide M12 lens (k1 = −0.25, k2 = 0.08: about 47 px
/// inwards at the image corners), its principal point a few pixels off centre and
/// a little decentring. Scaled to `width_px` x `height_px`.
CameraIntrinsics typical_wide_lens(int width_px = 640, int height_px = 480);

/// The same camera without distortion.
CameraIntrinsics without_distortion(CameraIntrinsics intrinsics);

/// Whether any distortion coefficient is non-zero.
bool has_distortion(const CameraIntrinsics& intrinsics);

/// The most fx and fy may differ by, as a factor: a camera's pixels are square to a few per cent.
inline constexpr double kMostPixelAspect = 1.25;

/// The first setting out of range (sizes in [32, 8192], focal lengths > 0 and
/// finite and within kMostPixelAspect of each other, principal point inside
/// the image, coefficients finite and |k| < 10).
RangeViolation check_intrinsics(const CameraIntrinsics& intrinsics);

/// The camera matrix K.
cv::Matx33d camera_matrix(const CameraIntrinsics& intrinsics);

/// The distortion coefficients in OpenCV's order (k1, k2, p1, p2, k3).
cv::Vec<double, 5> distortion_coefficients(const CameraIntrinsics& intrinsics);

/// Intrinsics from OpenCV's K and coefficients (4, 5 or more; more than 5 must be zero).
/// Throws std::invalid_argument for another shape or non-zero higher terms.
CameraIntrinsics intrinsics_from_opencv(const cv::Matx33d& k, const cv::Mat& coefficients, cv::Size image_size);

/// Where the lens puts a point the ideal pinhole camera sees at `ideal_px` (closed form).
cv::Point2d distort_pixel(const CameraIntrinsics& intrinsics, const cv::Point2d& ideal_px);

/// The ideal (pinhole) pixel that `intrinsics` images at `distorted_px`: the
/// inverse of distort_pixel by Newton's method on the normalised plane, to
/// 1e-12. The simulator's inverse, cheap enough for every rendered sample;
/// the detector uses OpenCV's (PointUndistorter), so the two sides of every
/// simulated measurement are computed independently.
cv::Point2d ideal_from_distorted_newton(const CameraIntrinsics& intrinsics, const cv::Point2d& distorted_px);

/// The same on the normalised plane: solves distortion(x, y) = (xd, yd) for
/// (x, y), starting from the (x, y) given (a neighbour's solution converges in
/// a step or two).
void undistort_normalised(const CameraIntrinsics& intrinsics, double xd, double yd, double& x, double& y);

/// Undistorts single points without allocating: cv::undistortPoints on
/// fixed-size buffers with K and the coefficients held as cv::Matx.
class PointUndistorter {
 public:
  /// Throws std::invalid_argument for intrinsics out of range.
  explicit PointUndistorter(const CameraIntrinsics& intrinsics);

  /// The ideal (pinhole) pixel of a pixel the sensor saw.
  cv::Point2d ideal_from_distorted(const cv::Point2d& distorted_px) const;

  /// The ideal-image centroid of a small blob (a ball's image) whose centroid
  /// on the sensor is `distorted_px` and whose pixels spread with covariance
  /// `covariance_px2` about it: the undistorted centroid plus the second-order
  /// terms of the lens's curvature across the blob and of its area change
  /// (about 0.02 px for a 7 px ball at the edge of the typical wide lens).
  cv::Point2d ideal_centroid(const cv::Point2d& distorted_px, const cv::Matx22d& covariance_px2) const;

  /// The intrinsics in use.
  const CameraIntrinsics& intrinsics() const { return intrinsics_; }

 private:
  CameraIntrinsics intrinsics_;
  cv::Matx33d k_;
  cv::Matx<double, 1, 5> d_;
};

}  // namespace pinball::vision
