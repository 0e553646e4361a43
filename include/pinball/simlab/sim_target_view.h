#pragma once
// The simulated camera looking at a printed calibration target (`pinball
// calibrate intrinsics --sim`): poses that a lab engineer would hold the target
// at, and the image the lens makes of it. Every output pixel is traced back
// through the lens (the inverse of vision::distort_pixel's Brown–Conrady
// model, by Newton's method) and the pinhole onto the target plane, where the
// pattern is sampled exactly (calibration::TargetPattern), several samples a
// pixel; then the optics' blur and the sensor's noise. The truth is known, so
// the intrinsics fit can be measured against it.

#include <cstdint>
#include <vector>

#include <opencv2/core.hpp>

#include "pinball/calibration/calibration_target.h"
#include "pinball/calibration/intrinsics_calibration.h"
#include "pinball/vision/lens_model.h"

namespace pinball::simlab {

/// Where the target is: target frame -> camera frame (OpenCV's convention:
/// x_camera = R(rvec) · x_target + tvec).
struct TargetPose {
  cv::Vec3d rvec;    ///< rotation vector (Rodrigues, rad)
  cv::Vec3d tvec_m;  ///< translation (m)
};

/// `views` poses as a person holds a target before a camera: tilted 12-35
/// degrees about varied axes, turned up to 20 degrees in its plane (3 in a
/// corner), the squares filling 40-60 % of the image width (less where a
/// tilted target would not fit), the views taking turns at the image's
/// middle, corners and edges, each pushed from the middle towards its place
/// as far as the whole sheet (the squares and a half-square white border)
/// stays in view, so that the distortion is seen where it is largest.
/// Deterministic by seed. Throws std::invalid_argument for a bad target, lens
/// or views outside [1, 10000].
std::vector<TargetPose> default_target_poses(const calibration::TargetSpec& target,
                                             const vision::CameraIntrinsics& lens, int views, std::uint64_t seed);

/// How the view is imaged.
struct TargetViewOptions {
  double noise_sigma = 2.0;       ///< sensor noise, standard deviation (gray levels)
  double blur_sigma_px = 0.6;     ///< optics: Gaussian blur (px); 0: none
  int supersample = 3;            ///< samples per pixel along each axis (anti-aliasing), 1..8
  double paper_gray = 220;        ///< the sheet's white (gray level)
  double ink_gray = 30;           ///< its black
  double background_gray = 90;    ///< everything behind it
};

/// The first option out of range (gray levels in [0, 255], noise and blur in [0, 50], supersample in [1, 8]).
RangeViolation check_target_view_options(const TargetViewOptions& options);

/// The 8-bit gray image `lens` makes of `target` at `pose`: the sheet is the
/// squares plus a white border half a square wide. A pixel that an edge may
/// cross is the mean of supersample² samples; then the blur and the noise.
/// Deterministic by seed. Throws std::invalid_argument for a bad lens,
/// target or option.
cv::Mat render_target_view(const vision::CameraIntrinsics& lens, const calibration::TargetSpec& target,
                           const TargetPose& pose, const TargetViewOptions& options, std::uint64_t seed);

/// `views` images of `target` through `lens` at default_target_poses(...,
/// seed), named sim_view_01.png ... and each rendered with ball_seed(seed, i):
/// what `pinball calibrate intrinsics --sim` calibrates on.
std::vector<calibration::TargetImage> simulated_target_images(const vision::CameraIntrinsics& lens,
                                                              const calibration::TargetSpec& target, int views,
                                                              std::uint64_t seed);


}  // namespace pinball::simlab
