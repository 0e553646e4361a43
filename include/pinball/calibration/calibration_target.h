#pragma once
// The printed target `pinball calibrate intrinsics` photographs: a chessboard
// or a ChArUco board (a chessboard with an ArUco marker in every white square,
// OpenCV 4.6's aruco module), its description on the command line, the
// printable image and where each corner lies on it.
//
// Target frame (OpenCV 4.6's ChArUco board frame, used for both kinds): origin
// at the top-left outer corner of the squares as printed, x to the right along
// the top edge, y down the print, z into the paper (m). A camera facing the
// print upright sees it with a rotation near the identity. Square (i, j)
// spans [i·s, (i+1)·s] x [j·s, (j+1)·s]; squares with i + j even are black
// (the top-left one); a ChArUco board's markers sit in the white ones.

#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "pinball/core/check.h"

namespace pinball::calibration {

/// Which pattern.
enum class TargetKind { kChessboard, kCharuco };

/// What the lab printed.
struct TargetSpec {
  TargetKind kind = TargetKind::kChessboard;
  int squares_x = 10;          ///< squares across (chessboard inner corners = squares - 1)
  int squares_y = 7;           ///< squares down
  double square_m = 0.025;     ///< printed square side (m)
  double marker_m = 0.018;     ///< ChArUco: marker side (m)
  std::string dictionary = "DICT_4X4_50";  ///< ChArUco dictionary name (cv::aruco predefined)

  /// For people and the calibration file: "chessboard 10x7 squares (9x6 inner
  /// corners), 25 mm" or "ChArUco 10x7 squares (54 corners), 25 mm, 18 mm
  /// markers DICT_4X4_50".
  std::string describe() const;
};

/// The first setting out of range: squares_x and squares_y in [3, 100],
/// square_m in (0, 1] m, ChArUco: marker_m in (0, square_m), a known
/// dictionary with a marker for every white square.
RangeViolation check_target(const TargetSpec& target);

/// Parses "chessboard:10x7:0.025" or "charuco:10x7:0.025:0.018[:DICT_4X4_50]"
/// (sizes in m). Throws std::invalid_argument "target 'text': what is wrong"
/// for another shape or a setting out of range (check_target).
TargetSpec parse_target(const std::string& text);

/// Number of inner corners (the points a view can show).
int target_corner_count(const TargetSpec& target);

/// The printable pattern: 8-bit gray, `px_per_m` pixels per metre, a white
/// margin of `margin_px` on every side (a chessboard needs one at least a
/// square wide to be found). The ChArUco board is OpenCV's own drawing.
/// Throws std::invalid_argument for a bad target, scale or margin.
cv::Mat target_image(const TargetSpec& target, double px_per_m, int margin_px);

/// Every inner corner's position on the target plane (z = 0, m), in id
/// order: row by row from the top-left, x fastest; corner (i, j) at
/// ((i + 1)·s, (j + 1)·s). The order of cv::aruco's ChArUco corner ids.
std::vector<cv::Point3d> target_points_m(const TargetSpec& target);

/// The pattern as a function of the place on the target, for rendering it
/// at any resolution (simulated views): exact square edges, ChArUco markers
/// from the dictionary's bits.
class TargetPattern {
 public:
  /// Throws std::invalid_argument for a bad target (check_target).
  explicit TargetPattern(const TargetSpec& target);

  /// Whether the point (x, y) of the target frame (m) is ink; false off the squares.
  bool ink(double x_m, double y_m) const;

  /// Width and height of the squares (m).
  double width_m() const { return squares_x_ * square_m_; }
  double height_m() const { return squares_y_ * square_m_; }

 private:
  int squares_x_;
  int squares_y_;
  double square_m_;
  double marker_m_;
  int cells_ = 0;                    ///< ChArUco: marker cells per side (bits + 2 border cells)
  std::vector<int> marker_of_square_;  ///< ChArUco: index into bits_ of square (i, j), -1: none
  std::vector<cv::Mat> bits_;          ///< ChArUco: each marker's bits (1: white), top row first
};

}  // namespace pinball::calibration
