#pragma once
// Camera intrinsics from images of a printed target (`pinball calibrate
// intrinsics`, docs/calibration.md "Camera intrinsics"): the target is found in
// each image (a chessboard by cv::findChessboardCorners and cv::cornerSubPix, a
// ChArUco board by cv::aruco's marker detection and corner interpolation), the
// lens is fitted over all views by cv::calibrateCamera (pinhole plus k1 k2 p1
// p2 k3), images where the target is not found or whose own reprojection error
// is poor are left out by name, and the fit is repeated without them.

#include <functional>
#include <span>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "pinball/calibration/calibration_file.h"
#include "pinball/calibration/calibration_target.h"
#include "pinball/vision/lens_model.h"

namespace pinball::calibration {

/// One image of the target.
struct TargetImage {
  std::string name;  ///< the file (for messages)
  cv::Mat gray;      ///< 8-bit gray
};

/// When an image or the whole set is good enough.
struct IntrinsicsFitConfig {
  int min_images = 5;            ///< fewer usable images is an error
  double max_image_rms_px = 1.0; ///< an image whose own reprojection RMS exceeds this after a fit is rejected and the fit repeated
  int min_corners = 8;           ///< ChArUco: fewer corners in an image and it is rejected
};

/// The first setting out of range: min_images >= 3, max_image_rms_px > 0, min_corners >= 6.
RangeViolation check_intrinsics_fit_config(const IntrinsicsFitConfig& config);

/// What became of one image.
struct ImageResult {
  std::string name;                          ///< the file
  bool used = false;                         ///< in the final fit
  std::string rejection;                     ///< empty when used: "target not found", "only 5 ChArUco corners", "reprojection 2.3 px > 1.0 px"
  int corners = 0;                           ///< corners detected
  double reprojection_rms_px = 0.0;          ///< RMS distance detected - reprojected (px); rejected for a poor fit: in the fit that rejected it
  std::vector<cv::Point2d> corners_px;       ///< detected corners (px)
  std::vector<cv::Point2d> reprojected_px;   ///< the same corners reprojected by the final fit (used images; rejected for a poor fit: by the fit that rejected it)
};

/// The fitted lens and every image's part in it.
struct IntrinsicsFit {
  IntrinsicsCalibration calibration;  ///< the file's intrinsics section
  std::vector<ImageResult> images;    ///< one per input image, in input order
};

/// Finds the target in one 8-bit gray image: the corners (px) and their ids
/// (indices into target_points_m). Empty when it is not found; `why` says why.
struct TargetDetection {
  std::vector<cv::Point2d> corners_px;  ///< sub-pixel corners (px)
  std::vector<int> ids;                 ///< each corner's index into target_points_m
  std::string why;                      ///< empty when found: "target not found", "only 5 ChArUco corners", ...
};
TargetDetection detect_target(const cv::Mat& gray, const TargetSpec& target, const IntrinsicsFitConfig& config = {});

/// Detects the target in each image, fits the lens with cv::calibrateCamera
/// (flags in the source: every coefficient free), rejects the worst image while its
/// own reprojection RMS exceeds max_image_rms_px and refits. Throws
/// std::invalid_argument for a bad target or config, and std::runtime_error
/// "<name>: <what>" for an image of another size than the first ("<name>:
/// 800x600, but <first> is 640x480"), an empty or not 8-bit gray image, and
/// "intrinsics: only N of M images show the target; at least min_images
/// needed (rejected: a.png target not found, ...)" (or "... fit within
/// max_image_rms_px ..." after the rejections), and "intrinsics: ..." for a
/// fit whose lens is out of range (vision::check_intrinsics).
/// `searched(n)`, when given, is called after the n-th image's search: the
/// search is the long part (seconds for a large image without the target).
IntrinsicsFit calibrate_intrinsics(std::span<const TargetImage> images, const TargetSpec& target,
                                   const IntrinsicsFitConfig& config = {},
                                   const std::function<void(std::size_t searched)>& searched = {});

/// A fitted lens against another (the truth in simulation, or the previous calibration).
struct LensComparison {
  double fx_error_pct = 0.0;              ///< (fx - fx_ref) / fx_ref (%)
  double fy_error_pct = 0.0;              ///< (fy - fy_ref) / fy_ref (%)
  double principal_point_error_px = 0.0;  ///< distance between the principal points (px)
  /// Largest distance between where the two lenses' distortions put the same
  /// ideal pixel, vision::distort_pixel(lens, p) against
  /// distort_pixel(reference, p), over a grid of ideal pixels p over the image (px).
  double distortion_max_error_px = 0.0;
  /// The same over the ideal pixels the reference lens images on a grid over
  /// the whole sensor (px). A barrel lens images the sensor's outermost
  /// corners from ideal pixels beyond the image: there a fit is extrapolated
  /// unless views reached them.
  double distortion_sensor_max_error_px = 0.0;
};
/// `lens` against `reference` (same image size). Throws std::invalid_argument otherwise.
LensComparison compare_lenses(const vision::CameraIntrinsics& lens, const vision::CameraIntrinsics& reference);

/// The figure for `--png` (BGR): a grid of thumbnails with the detected
/// corners, the residual arrows (scaled, the scale in the title), each
/// image's name, RMS or rejection in its caption, and a title naming the
/// command, the target and the lens.
cv::Mat draw_intrinsics_figure(const IntrinsicsFit& fit, std::span<const TargetImage> images);

}  // namespace pinball::calibration
