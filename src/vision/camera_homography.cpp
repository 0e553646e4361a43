#include "pinball/vision/camera_homography.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <vector>

#include <opencv2/imgproc.hpp>

namespace pinball::vision {
namespace {

bool finite(const cv::Matx33d& m) {
  for (int i = 0; i < 9; ++i) {
    if (!std::isfinite(m.val[i])) return false;
  }
  return true;
}

// Twice the area of the triangle a, b, c over the square of its longest side: 0 when the three lie on
// a line, about 1 for a well-shaped one; scale-free, so metres and pixels are judged alike.
double triangle_shape(const cv::Point2d& a, const cv::Point2d& b, const cv::Point2d& c) {
  const double twice_area = std::abs((b - a).cross(c - a));
  const double longest = std::max({cv::norm(b - a), cv::norm(c - b), cv::norm(a - c)});
  return longest > 0.0 ? twice_area / (longest * longest) : 0.0;
}

// The four correspondences a homography can be fitted to: no three on a line on either side.
void check_four_points(const std::array<cv::Point2d, 4>& p, const char* side) {
  constexpr double kLeastShape = 1e-6;  // a corner 1 um off the line through two 1 m apart
  for (int skip = 0; skip < 4; ++skip) {
    std::array<cv::Point2d, 3> t;
    for (int i = 0, k = 0; i < 4; ++i) {
      if (i != skip) t[static_cast<std::size_t>(k++)] = p[static_cast<std::size_t>(i)];
    }
    if (!(triangle_shape(t[0], t[1], t[2]) > kLeastShape)) {
      throw std::invalid_argument(std::string("camera homography: three of the four ") + side +
                                  " points lie on a line (or two coincide): no homography maps them");
    }
  }
}

}  // namespace

CameraHomography::CameraHomography(const cv::Matx33d& image_from_board) : h_(image_from_board) {
  const double det = cv::determinant(h_);
  if (!finite(h_) || !std::isfinite(det) || !(cv::norm(h_) > 0.0) || std::abs(det) < 1e-12 * std::pow(cv::norm(h_), 3)) {
    throw std::invalid_argument("camera homography: the 3x3 matrix is singular or not finite");
  }
  h_inv_ = h_.inv();
}

CameraHomography CameraHomography::from_points(const std::array<Vec2, 4>& p_board,
                                               const std::array<cv::Point2d, 4>& uv_px) {
  // A degenerate set had been accepted: three board points on a line gave a matrix that mapped
  // (0, 0) 73 px from where it was told to, and (0.4, 0) to 1.8e16 px.
  std::array<cv::Point2d, 4> board_points;
  for (std::size_t i = 0; i < 4; ++i) board_points[i] = cv::Point2d(p_board[i].x(), p_board[i].y());
  check_four_points(board_points, "board");
  check_four_points(uv_px, "image");
  std::vector<cv::Point2f> src(4);
  std::vector<cv::Point2f> dst(4);
  for (std::size_t i = 0; i < 4; ++i) {
    src[i] = cv::Point2f(static_cast<float>(p_board[i].x()), static_cast<float>(p_board[i].y()));
    dst[i] = cv::Point2f(static_cast<float>(uv_px[i].x), static_cast<float>(uv_px[i].y));
  }
  cv::Mat m;
  try {
    m = cv::getPerspectiveTransform(src, dst, cv::DECOMP_SVD);
  } catch (const cv::Exception& e) {
    throw std::invalid_argument(std::string("camera homography: degenerate points: ") + e.what());
  }
  cv::Matx33d h;
  m.convertTo(cv::Mat(3, 3, CV_64F, h.val), CV_64F);
  // float inputs lose a little; refine in double by solving the 8x8 system again.
  cv::Matx<double, 8, 8> a;
  cv::Matx<double, 8, 1> b;
  for (int i = 0; i < 4; ++i) {
    const double x = p_board[static_cast<std::size_t>(i)].x();
    const double y = p_board[static_cast<std::size_t>(i)].y();
    const double u = uv_px[static_cast<std::size_t>(i)].x;
    const double v = uv_px[static_cast<std::size_t>(i)].y;
    const double ru[8] = {x, y, 1, 0, 0, 0, -u * x, -u * y};
    const double rv[8] = {0, 0, 0, x, y, 1, -v * x, -v * y};
    for (int j = 0; j < 8; ++j) {
      a(2 * i, j) = ru[j];
      a(2 * i + 1, j) = rv[j];
    }
    b(2 * i) = u;
    b(2 * i + 1) = v;
  }
  cv::Matx<double, 8, 1> sol;
  if (cv::solve(a, b, sol, cv::DECOMP_LU)) {
    h = cv::Matx33d(sol(0), sol(1), sol(2), sol(3), sol(4), sol(5), sol(6), sol(7), 1.0);
  }
  // The points on one side of the horizon, and each mapped where it was told to: a crossed corner
  // order (a bow tie) puts one behind the camera.
  double image_scale = 0.0;
  for (const cv::Point2d& q : uv_px) image_scale = std::max(image_scale, cv::norm(q - uv_px[0]));
  double first_w = 0.0;
  for (std::size_t i = 0; i < 4; ++i) {
    const cv::Vec3d q = h * cv::Vec3d(p_board[i].x(), p_board[i].y(), 1.0);
    if (i == 0) first_w = q[2];
    const bool same_side = q[2] * first_w > 0.0;
    const cv::Point2d mapped(q[0] / q[2], q[1] / q[2]);
    if (!same_side || !(cv::norm(mapped - uv_px[i]) <= 1e-6 * std::max(image_scale, 1.0))) {
      throw std::invalid_argument("camera homography: the four points are in an order no view of a plane gives "
                                  "(corners crossed, or the horizon between them)");
    }
  }
  return CameraHomography(h);
}

CameraHomography CameraHomography::default_view(const table::Board& board, cv::Size image_size, const CameraView& view) {
  if (image_size.width <= 0 || image_size.height <= 0 || !(board.width_m > 0.0) || !(board.height_m > 0.0)) {
    throw std::invalid_argument("camera homography: default view needs a positive image size and board");
  }
  if (!(view.margin_fraction >= 0.0 && view.margin_fraction < 0.4) || !(view.keystone >= 0.0 && view.keystone < 0.5) ||
      !std::isfinite(view.rotation_deg) || !std::isfinite(view.shift_u_px) || !std::isfinite(view.shift_v_px)) {
    throw std::invalid_argument(
        "camera homography: view needs margin_fraction in [0, 0.4), keystone in [0, 0.5) and finite rotation/shift");
  }
  const double w = image_size.width;
  const double h = image_size.height;
  // The table's long axis (board y) along u, its width (board x) along v.
  const double free_u = w * (1.0 - 2.0 * view.margin_fraction);
  const double free_v = h * (1.0 - 2.0 * view.margin_fraction);
  const double s = std::min(free_u / board.height_m, free_v / board.width_m);
  const double len_u = s * board.height_m;
  const double len_v = s * board.width_m;
  const double u0 = 0.5 * (w - len_u);
  const double v0 = 0.5 * (h - len_v);
  const double half_far = 0.5 * len_v * (1.0 - view.keystone);  // far end (top of the table) is narrower
  const double vc = v0 + 0.5 * len_v;
  // Board corners: bottom-left, bottom-right, top-right, top-left.
  const std::array<Vec2, 4> p_board{Vec2{0.0, 0.0}, Vec2{board.width_m, 0.0}, Vec2{board.width_m, board.height_m},
                                    Vec2{0.0, board.height_m}};
  std::array<cv::Point2d, 4> uv{cv::Point2d{u0, v0}, cv::Point2d{u0, v0 + len_v},
                                cv::Point2d{u0 + len_u, vc + half_far}, cv::Point2d{u0 + len_u, vc - half_far}};
  const double a = view.rotation_deg * std::numbers::pi / 180.0;
  const cv::Point2d c{0.5 * w, 0.5 * h};
  for (cv::Point2d& p : uv) {
    const cv::Point2d d = p - c;
    p = c + cv::Point2d{std::cos(a) * d.x - std::sin(a) * d.y, std::sin(a) * d.x + std::cos(a) * d.y} +
        cv::Point2d{view.shift_u_px, view.shift_v_px};
  }
  return from_points(p_board, uv);
}

cv::Point2d CameraHomography::image_from_board(const Vec2& p_board) const {
  const cv::Vec3d q = h_ * cv::Vec3d(p_board.x(), p_board.y(), 1.0);
  return {q[0] / q[2], q[1] / q[2]};
}

Vec2 CameraHomography::board_from_image(const cv::Point2d& uv_px) const {
  const cv::Vec3d q = h_inv_ * cv::Vec3d(uv_px.x, uv_px.y, 1.0);
  return Vec2{q[0] / q[2], q[1] / q[2]};
}

double CameraHomography::px_per_m_at(const Vec2& p_board) const {
  // Jacobian of (u, v) = (a/w, b/w) at p.
  const cv::Vec3d q = h_ * cv::Vec3d(p_board.x(), p_board.y(), 1.0);
  const double w = q[2];
  const double du_dx = (h_(0, 0) - q[0] / w * h_(2, 0)) / w;
  const double du_dy = (h_(0, 1) - q[0] / w * h_(2, 1)) / w;
  const double dv_dx = (h_(1, 0) - q[1] / w * h_(2, 0)) / w;
  const double dv_dy = (h_(1, 1) - q[1] / w * h_(2, 1)) / w;
  return std::sqrt(std::abs(du_dx * dv_dy - du_dy * dv_dx));
}

}  // namespace pinball::vision
