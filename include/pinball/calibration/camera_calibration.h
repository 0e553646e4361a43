#pragma once
// Camera calibration: the board -> image homography from markers at known
// board positions. A marker is a bright disc on a dark ring (a sticker); it is
// found as a bright blob of a disc's shape with a darker surround, its centre
// the intensity-weighted centroid. The detected markers are matched to the
// known positions by trying every assignment of four of them to the layout's
// four outermost points and keeping the one most markers agree with (so the
// camera may look at the table from any side and extra bright blobs do no
// harm), then cv::findHomography with RANSAC fits all matched markers.

#include <optional>
#include <span>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "pinball/calibration/calibration_file.h"
#include "pinball/core/geometry.h"
#include "pinball/table/board.h"

namespace pinball::calibration {

/// The most markers a layout may have: the detector keeps as many candidates,
/// and matching tries every four of them (250 markers took 3 GB, then failed).
inline constexpr int kMaxLayoutMarkers = 24;

/// Marker detector settings.
struct MarkerDetectorConfig {
  int threshold = 200;             ///< pixels brighter than this (gray levels) may belong to a marker
  double min_area_px = 8.0;        ///< smallest marker blob (px)
  double max_area_px = 5000.0;     ///< largest marker blob (px)
  double max_elongation = 2.5;     ///< largest major/minor axis ratio (a disc seen at a slant is an ellipse)
  double min_fill = 0.8;           ///< smallest area / area of the ellipse with the same second moments
  double min_ring_contrast = 60.0; ///< marker mean minus the mean of the ring around it (gray levels)
  int max_markers = kMaxLayoutMarkers;  ///< keep at most this many candidates (highest contrast first)
};

/// One marker found in an image.
struct DetectedMarker {
  cv::Point2d uv_px{0.0, 0.0};  ///< sub-pixel centre (px)
  double area_px = 0.0;         ///< blob area (px)
  double contrast = 0.0;        ///< marker mean minus surround mean (gray levels)
};

/// Finds marker candidates in an 8-bit gray image, highest contrast first.
/// Throws std::invalid_argument for an image that is not 8-bit gray.
std::vector<DetectedMarker> detect_markers(const cv::Mat& gray, const MarkerDetectorConfig& config = {});

/// Checks that markers at these board points can define a homography: at
/// least 4, no two within min_separation_m, and four of them with no three
/// (nearly) collinear, and at most kMaxLayoutMarkers. Throws
/// std::invalid_argument naming the problem
/// ("markers 2, 3, 5 are collinear", "markers 1 and 4 coincide": counted
/// from 1, or by `source_lines`, the file line of each point, when given:
/// "the markers of lines 2 and 5 coincide").
void check_marker_layout(std::span<const Vec2> board_points, double min_separation_m = 0.01,
                         std::span<const int> source_lines = {});

/// A layout for `board`: seven markers spread over the table, no symmetry
/// that would make the matching ambiguous (m, board frame).
std::vector<Vec2> default_marker_layout(const table::Board& board);

/// Reads marker board positions from a CSV with header x,y (m) for `board`.
/// Throws std::runtime_error "file:line: what" for a bad row or a marker over
/// 5 cm off the playfield (a layout in mm, or another table's), and "file:
/// marker layout: ..." for a layout check_marker_layout refuses.
std::vector<Vec2> read_marker_layout_csv(const std::string& path, const table::Board& board);

/// Matching and fitting settings.
struct HomographyFitConfig {
  double match_tolerance_px = 3.0;     ///< a known marker reprojected this close to a detection matches it
  double ransac_threshold_px = 1.5;    ///< cv::findHomography RANSAC reprojection threshold (px)
  int min_markers = 4;                 ///< fewer matched markers is an error
};

/// One known marker and where it was seen.
struct MarkerMatch {
  int layout_index = 0;             ///< index into the layout
  int detection_index = 0;          ///< index into the detections
  Vec2 board{0.0, 0.0};             ///< known position (m)
  cv::Point2d uv_px{0.0, 0.0};      ///< detected centre (px)
  double residual_px = 0.0;         ///< distance to the fitted homography's reprojection (px)
  bool inlier = true;               ///< kept by RANSAC
};

/// The fitted homography with its evidence.
struct HomographyFit {
  CameraCalibration calibration;       ///< matrix, image size, markers used, reprojection errors
  std::vector<MarkerMatch> matches;    ///< every matched marker
  int detections = 0;                  ///< marker candidates in the image
};

/// Matches `detections` to `layout` and fits the homography. Throws
/// std::invalid_argument for a degenerate layout (check_marker_layout) and
/// std::runtime_error when fewer than min_markers match or the matching is
/// ambiguous (a symmetric layout).
HomographyFit fit_homography(std::span<const DetectedMarker> detections, std::span<const Vec2> layout,
                             cv::Size image_size, const HomographyFitConfig& config = {});

/// Moves each marker's centre from where the lens put it to where the ideal
/// pinhole camera sees it, the image the homography maps the board into.
void undistort_markers(std::vector<DetectedMarker>& markers, const vision::CameraIntrinsics& lens);

/// detect_markers then fit_homography on one image; with a lens (the
/// calibration's intrinsics), the markers are undistorted first so the
/// homography is fitted on undistorted points (a homography cannot absorb
/// distortion). Throws std::invalid_argument for a lens of another image size.
HomographyFit calibrate_camera(const cv::Mat& gray, std::span<const Vec2> layout,
                               const MarkerDetectorConfig& detector = {}, const HomographyFitConfig& config = {},
                               const std::optional<vision::CameraIntrinsics>& lens = {});

}  // namespace pinball::calibration
