#pragma once
// The plane-to-plane map between the playfield (board frame, metres, +y up
// the table) and the camera image (pixels, u right, v down). A camera looking
// down at a flat table sees it through a homography: p_img ~ H · p_board in
// homogeneous coordinates. Calibration (its own issue) will measure H on the
// lab machine; until then the simulator's default view stands in for it.

#include <array>

#include <opencv2/core.hpp>

#include "pinball/core/geometry.h"
#include "pinball/table/board.h"

namespace pinball::vision {

/// How the simulated camera sits over the table. The default is a camera
/// turned so the table's long axis runs along the image's width (top of the
/// table on the right), slightly tilted (keystone) and rotated, as a camera
/// bolted over a real machine never is perfectly square to it.
struct CameraView {
  double margin_fraction = 0.03;  ///< free border around the table, fraction of the image size
  double keystone = 0.06;         ///< the far (top) end of the table appears this fraction narrower
  double rotation_deg = 1.5;      ///< rotation of the whole view about the image centre (deg, clockwise on screen)
  double shift_u_px = 0.0;        ///< extra shift of the view (px)
  double shift_v_px = 0.0;        ///< extra shift of the view (px)
};

/// Board <-> image mapping around a 3x3 matrix (board metres -> image pixels).
class CameraHomography {
 public:
  /// Identity-free construction from a matrix mapping board (x, y, 1) to
  /// image (u, v, w). Throws std::invalid_argument when it is singular or not finite.
  explicit CameraHomography(const cv::Matx33d& image_from_board);

  /// The homography that maps the four board points to the four image points
  /// (cv::getPerspectiveTransform). Throws std::invalid_argument when
  /// degenerate: three points of either side on a line (or two coincide), or
  /// an order no view of a plane gives (a bow tie: one point behind the camera).
  static CameraHomography from_points(const std::array<Vec2, 4>& p_board, const std::array<cv::Point2d, 4>& uv_px);

  /// The simulator's default camera over `board` for an image of `image_size`.
  static CameraHomography default_view(const table::Board& board, cv::Size image_size, const CameraView& view = {});

  /// Board point (m) to image point (px).
  cv::Point2d image_from_board(const Vec2& p_board) const;

  /// Image point (px) to board point (m).
  Vec2 board_from_image(const cv::Point2d& uv_px) const;

  /// Local scale at a board point: square root of the area magnification
  /// (px per m), i.e. a small disc of radius r m images as about r·scale px.
  double px_per_m_at(const Vec2& p_board) const;

  /// The matrix (board -> image) and its inverse (image -> board).
  const cv::Matx33d& image_from_board_matrix() const { return h_; }
  const cv::Matx33d& board_from_image_matrix() const { return h_inv_; }

 private:
  cv::Matx33d h_;
  cv::Matx33d h_inv_;
};

}  // namespace pinball::vision
