#pragma once
// Pictures of a calibration for `pinball calibrate --png`: what was detected
// and what was fitted, drawn so a person can see at a glance whether to trust it.

#include <span>
#include <vector>

#include <opencv2/core.hpp>

#include "pinball/calibration/calibration_file.h"
#include "pinball/calibration/camera_calibration.h"
#include "pinball/calibration/flipper_calibration.h"
#include "pinball/calibration/gravity_calibration.h"
#include "pinball/vision/camera_homography.h"

namespace pinball::calibration {

/// The marker image (8-bit gray), enlarged: every detection (yellow circle),
/// the layout reprojected through the fit (green cross: inlier, red: outlier)
/// and the reprojection figures. BGR.
cv::Mat draw_camera_figure(const cv::Mat& gray, const HomographyFit& fit);

/// One flipper for the flipper figure.
struct FlipperFigureItem {
  const SweepTrack* sweep = nullptr;           ///< markerless: tips and circle (may be null)
  const FlipperCalibration* markers = nullptr; ///< marker method result (may be null)
  const FlipperCalibration* markerless = nullptr; ///< markerless result (may be null)
};

/// A frame of the table (8-bit gray), enlarged, with each flipper's tip
/// points (cyan), fitted circle and arc between the stops (magenta), and the
/// marker method's pivot and tips (green). BGR.
cv::Mat draw_flipper_figure(const cv::Mat& gray, const vision::CameraHomography& homography,
                            std::span<const FlipperFigureItem> flippers);

/// y against t of every roll (points), its fitted parabola over the part used
/// (line; red when the roll was left out), and the estimate. BGR.
cv::Mat draw_gravity_figure(std::span<const GravityRoll> rolls, const GravityCalibration& result);

}  // namespace pinball::calibration
