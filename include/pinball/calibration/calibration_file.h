#pragma once
// The lab machine's calibration (thesis 4.1.1, 4.1.3) and its YAML file: the
// camera homography, each flipper's pivot, tip, length and stops, and gravity
// along the table. Every section is optional in the file (each `pinball
// calibrate` kind writes its own and keeps the others); what a consumer needs
// it asks for by name, and a missing or bad key is reported as file:key.
// Format field by field: docs/calibration.md. Each struct lists its keys once,
// in Serialize(); core/yaml_read_archive.h reads them, every key required,
// no unknown key and none twice. Whether the flippers are the board's is
// checked where the board is known (check_calibration_matches_board).

#include <array>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "pinball/core/geometry.h"
#include "pinball/core/name_value.h"
#include "pinball/table/board.h"
#include "pinball/track/flipper_geometry.h"
#include "pinball/track/tracker.h"
#include "pinball/vision/camera_homography.h"
#include "pinball/vision/lens_model.h"

namespace pinball::calibration {

/// The version this code writes and reads.
inline constexpr int kCalibrationFileVersion = 1;

/// The camera section: board (m) -> image (px) homography and its quality.
struct CameraCalibration {
  cv::Matx33d image_from_board = cv::Matx33d::eye();  ///< board (x, y, 1) m -> image (u, v, w) px
  int image_width_px = 0;             ///< size of the images it was measured on (px)
  int image_height_px = 0;
  int markers_used = 0;               ///< markers matched and kept by RANSAC
  double reprojection_rms_px = 0.0;   ///< RMS distance between detected and reprojected markers (px)
  double reprojection_max_px = 0.0;   ///< largest such distance (px)

  template <class Archive>
  void Serialize(Archive* a) {
    a->Visit(PINBALL_NVP(image_width_px));
    a->Visit(PINBALL_NVP(image_height_px));
    // The matrix as 3 rows of 3 numbers, through a copy (cv::Matx is not a list).
    std::array<std::array<double, 3>, 3> rows{};
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) rows[static_cast<std::size_t>(i)][static_cast<std::size_t>(j)] = image_from_board(i, j);
    a->Visit(make_name_value("image_from_board", &rows));
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) image_from_board(i, j) = rows[static_cast<std::size_t>(i)][static_cast<std::size_t>(j)];
    a->Visit(PINBALL_NVP(markers_used));
    a->Visit(PINBALL_NVP(reprojection_rms_px));
    a->Visit(PINBALL_NVP(reprojection_max_px));
  }
};

/// The intrinsics section: the lens, from images of a printed target
/// (`pinball calibrate intrinsics`). With it the detector undistorts each
/// centroid and the homography is fitted on undistorted points.
struct IntrinsicsCalibration {
  vision::CameraIntrinsics lens;       ///< camera matrix and distortion coefficients (OpenCV's model)
  std::string target;                  ///< what was photographed ("chessboard 9x6 inner corners, 25 mm squares")
  int images_used = 0;                 ///< images in the fit
  int images_rejected = 0;             ///< images left out (target not found, or a poor fit)
  double reprojection_rms_px = 0.0;    ///< RMS reprojection error over the used images (px)

  template <class Archive>
  void Serialize(Archive* a) {
    a->Visit(PINBALL_NVP(lens));
    a->Visit(PINBALL_NVP(target));
    a->Visit(PINBALL_NVP(images_used));
    a->Visit(PINBALL_NVP(images_rejected));
    a->Visit(PINBALL_NVP(reprojection_rms_px));
  }
};

/// The camera_timing section: when a frame's pixels were exposed, relative to
/// the time the host stamps on it. The detector dates an observation
/// t = frame stamp − latency_s + v · row_time_s (v: the ball's row on the sensor).
struct CameraTiming {
  double latency_s = 0.0;         ///< frame stamp minus the middle of row 0's exposure (s)
  double latency_spread_s = 0.0;  ///< standard deviation of that delay over the measured events (s)
  double row_time_s = 0.0;        ///< rolling shutter: row v is exposed v · this after row 0 (s); 0: global shutter
  int events_used = 0;            ///< events behind latency_s (`pinball calibrate latency`); 0: configured, not measured

  template <class Archive>
  void Serialize(Archive* a) {
    a->Visit(PINBALL_NVP(latency_s));
    a->Visit(PINBALL_NVP(latency_spread_s));
    a->Visit(PINBALL_NVP(row_time_s));
    a->Visit(PINBALL_NVP(events_used));
  }
};

/// How a flipper's geometry was measured.
enum class FlipperMethod { kMarkers, kMarkerless };

/// "markers" or "markerless".
const char* to_string(FlipperMethod method);

/// Where the two methods differ (first minus second in the file's order; m, rad).
struct FlipperDisagreement {
  double pivot_m = 0.0;        ///< distance between the pivots (m)
  double tip_m = 0.0;          ///< distance between the down tips (m)
  double length_m = 0.0;       ///< difference of lengths (m)
  double theta_min_rad = 0.0;  ///< difference of down stops (rad)
  double theta_max_rad = 0.0;  ///< difference of up stops (rad)

  template <class Archive>
  void Serialize(Archive* a) {
    a->Visit(PINBALL_NVP(pivot_m));
    a->Visit(PINBALL_NVP(tip_m));
    a->Visit(PINBALL_NVP(length_m));
    a->Visit(PINBALL_NVP(theta_min_rad));
    a->Visit(PINBALL_NVP(theta_max_rad));
  }
};

/// One flipper as measured.
struct FlipperCalibration {
  std::string name;                        ///< the board's flipper name
  table::Side side = table::Side::kLeft;       ///< left flippers point right
  FlipperMethod method = FlipperMethod::kMarkers;  ///< how
  Vec2 pivot_m = Vec2::Zero();             ///< pivot (m, board frame)
  Vec2 tip_m = Vec2::Zero();               ///< tip at rest, θ_min (m)
  double length_m = 0.0;                   ///< pivot to tip (m)
  double theta_min_rad = 0.0;              ///< down stop, the board's θ convention (rad)
  double theta_max_rad = 0.0;              ///< up stop (rad)
  double fit_rms_m = 0.0;                  ///< markerless: RMS distance of the tip points to the circle about the pivot (m)
  int points = 0;                          ///< markers or tip points behind the figures
  std::optional<FlipperDisagreement> disagreement;  ///< against the other method, when both were run

  template <class Archive>
  void Serialize(Archive* a) {
    a->Visit(PINBALL_NVP(name));
    a->Visit(PINBALL_NVP(side));
    a->Visit(PINBALL_NVP(method));
    a->Visit(PINBALL_NVP(pivot_m));
    a->Visit(PINBALL_NVP(tip_m));
    a->Visit(PINBALL_NVP(length_m));
    a->Visit(PINBALL_NVP(theta_min_rad));
    a->Visit(PINBALL_NVP(theta_max_rad));
    a->Visit(PINBALL_NVP(fit_rms_m));
    a->Visit(PINBALL_NVP(points));
    a->Visit(PINBALL_NVP(disagreement));
  }
};

/// The gravity section.
struct GravityEstimate {
  double g_mps2 = 0.0;            ///< acceleration of a ball rolling from rest, along −y (m/s²)
  double ci_low_mps2 = 0.0;       ///< confidence interval (t over rolls) lower end
  double ci_high_mps2 = 0.0;      ///< upper end
  double confidence = 0.95;       ///< of that interval
  int rolls_used = 0;             ///< rolls in the estimate
  int rolls_rejected = 0;         ///< outlier or unusable rolls left out
  std::vector<double> per_roll_mps2;  ///< every usable roll's acceleration, rejected ones too

  template <class Archive>
  void Serialize(Archive* a) {
    a->Visit(PINBALL_NVP(g_mps2));
    a->Visit(PINBALL_NVP(ci_low_mps2));
    a->Visit(PINBALL_NVP(ci_high_mps2));
    a->Visit(PINBALL_NVP(confidence));
    a->Visit(PINBALL_NVP(rolls_used));
    a->Visit(PINBALL_NVP(rolls_rejected));
    a->Visit(PINBALL_NVP(per_roll_mps2));
  }
};

/// A whole calibration file.
struct Calibration {
  int version = kCalibrationFileVersion;   ///< file format version
  std::string date;                        ///< when written, ISO 8601 UTC; set by write_calibration when empty
  std::string board;                       ///< the board file the machine was described by
  std::optional<CameraCalibration> camera; ///< camera section
  std::optional<IntrinsicsCalibration> intrinsics;  ///< intrinsics section (lens)
  std::optional<CameraTiming> camera_timing;        ///< camera_timing section
  std::vector<FlipperCalibration> flippers;///< flippers section (board order)
  std::optional<GravityEstimate> gravity;  ///< gravity section

  template <class Archive>
  void Serialize(Archive* a) {
    a->Visit(PINBALL_NVP(version));
    a->Visit(PINBALL_NVP(date));
    a->Visit(PINBALL_NVP(board));
    a->Visit(PINBALL_NVP(camera));
    a->Visit(PINBALL_NVP(intrinsics));
    a->Visit(PINBALL_NVP(camera_timing));
    // The section may be absent (an empty list is not written).
    std::optional<std::vector<FlipperCalibration>> listed;
    if (!flippers.empty()) listed = flippers;
    a->Visit(make_name_value("flippers", &listed));
    flippers = listed.value_or(std::vector<FlipperCalibration>{});
    a->Visit(PINBALL_NVP(gravity));
  }
};

/// Writes `calibration` as YAML to `path` (the date set to now when empty).
/// Throws std::runtime_error when the file cannot be written.
void write_calibration(const Calibration& calibration, const std::string& path);

/// The YAML text write_calibration writes.
std::string calibration_to_yaml(const Calibration& calibration);

/// Reads a calibration file. Throws std::runtime_error "path:key: what is
/// wrong" for a missing, unknown, repeated, mistyped or out-of-range key, a
/// wrong version, or YAML that does not parse ("path:line: ...").
Calibration read_calibration(const std::string& path);

/// Parses YAML text; `name` stands for the file in messages.
Calibration parse_calibration(const std::string& text, const std::string& name);

/// The tracker's flipper geometry: the calibrated left and right flippers
/// (pivot and down tip). Throws std::runtime_error "name:flippers: ..." unless
/// exactly one left and one right flipper are present.
track::FlipperGeometry flipper_geometry_from_calibration(const Calibration& calibration, const std::string& name);

/// Applies a calibration to the tracker: g from the gravity section (when
/// present) and the flipper geometry from the flippers section (when
/// present; the window distances follow the calibrated length as
/// track::default_tracker_config derives them from the board).
void apply_calibration(const Calibration& calibration, const std::string& name, track::TrackerConfig& config,
                       track::FlipperGeometry& geometry);

/// The detector's homography from the camera section. Throws
/// std::runtime_error "name:camera: missing" without one.
vision::CameraHomography camera_homography(const Calibration& calibration, const std::string& name);

/// Checks that the file's `board` is `board`'s file (or a copy of it; a
/// recorded board that is no longer found is not compared), and that every
/// calibrated flipper is one of the board's, on its side,
/// and calibrated once: a typo in a name must not leave a flipper on the
/// board's geometry unnoticed. Throws std::runtime_error (a KeyError)
/// "name:board: ...", "name:flippers[i].name: ..." or "...side: ...".
void check_calibration_matches_board(const Calibration& calibration, const std::string& name,
                                     const table::Board& board);

/// Copies the calibrated flippers into a board (pivot, length, stops, by
/// name), for the simulator and the daemon. Throws std::runtime_error
/// (check_calibration_matches_board) unless the flippers are the board's.
void apply_calibration(const Calibration& calibration, const std::string& name, table::Board& board);

}  // namespace pinball::calibration

/// A calibrated flipper's side as the file spells it.
template <>
struct pinball::EnumText<pinball::table::Side> {
  static std::string name(table::Side side) { return std::string(table::side_name(side)); }
  static table::Side parse(const std::string& text) {
    if (const std::optional<table::Side> side = table::parse_side(text)) return *side;
    throw std::invalid_argument("expected left or right");
  }
};

/// A flipper's method as the file spells it.
template <>
struct pinball::EnumText<pinball::calibration::FlipperMethod> {
  static std::string name(calibration::FlipperMethod method) { return calibration::to_string(method); }
  static calibration::FlipperMethod parse(const std::string& text) {
    if (text == "markers") return calibration::FlipperMethod::kMarkers;
    if (text == "markerless") return calibration::FlipperMethod::kMarkerless;
    throw std::invalid_argument("expected markers or markerless");
  }
};
