#pragma once
// Inside pinball_calibration: the cv::aruco ChArUco board of a target, so that
// the public headers need not include the aruco module.

#include <opencv2/aruco/charuco.hpp>

#include "pinball/calibration/calibration_target.h"

namespace pinball::calibration::detail {

/// The board cv::aruco draws and detects for a ChArUco target (check_target must pass).
cv::Ptr<cv::aruco::CharucoBoard> make_charuco_board(const TargetSpec& target);

}  // namespace pinball::calibration::detail
