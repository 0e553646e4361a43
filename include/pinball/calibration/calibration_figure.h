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

/// The marker image (8-bit gray), enlarged: every detection (circle), the
/// layout reprojected through the fit (cross: inlier or outlier, each its
/// palette colour), a legend beside it and the reprojection figures in the
/// title banner (pinball/plot). BGR.
cv::Mat draw_camera_figure(const cv::Mat& gray, const HomographyFit& fit);

/// One flipper for the flipper figure.
struct FlipperFigureItem {
  const SweepTrack* sweep = nullptr;           ///< markerless: tips and circle (may be null)
  const FlipperCalibration* markers = nullptr; ///< marker method result (may be null)
  const FlipperCalibration* markerless = nullptr; ///< markerless result (may be null)
};

/// A frame of the table (8-bit gray), enlarged, with each flipper's tip
/// points, fitted circle and arc between the stops, and the marker method's
/// pivot and tip; below it a zoomed inset of each flipper with a scale bar;
/// a legend beside and the figures in the title banner. BGR.
cv::Mat draw_flipper_figure(const cv::Mat& gray, const vision::CameraHomography& homography,
                            std::span<const FlipperFigureItem> flippers);

/// A chart of two panels sharing time: y against t of every roll (points)
/// with its fitted parabola over the part used (one palette colour per roll;
/// grey dashed when left out), and below each roll's residuals (mm); the
/// estimate and its interval in the title. BGR.
cv::Mat draw_gravity_figure(std::span<const GravityRoll> rolls, const GravityCalibration& result);

}  // namespace pinball::calibration
