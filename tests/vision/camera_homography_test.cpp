#include "pinball/vision/camera_homography.h"

#include <stdexcept>

#include <gtest/gtest.h>

#include "pinball/table/board.h"

namespace pinball::vision {
namespace {

table::Board table() { return table::Board{}; }  // 0.51 x 1.07 m

TEST(CameraHomography, DefaultViewRoundTripsAndKeepsTheTableInTheImage) {
  const table::Board board = table();
  const CameraHomography h = CameraHomography::default_view(board, {640, 480});
  for (const Vec2& p : {Vec2{0.0, 0.0}, Vec2{board.width_m, 0.0}, Vec2{board.width_m, board.height_m},
                        Vec2{0.0, board.height_m}, Vec2{0.2, 0.7}}) {
    const cv::Point2d uv = h.image_from_board(p);
    EXPECT_GT(uv.x, 0.0);
    EXPECT_LT(uv.x, 640.0);
    EXPECT_GT(uv.y, 0.0);
    EXPECT_LT(uv.y, 480.0);
    EXPECT_NEAR((h.board_from_image(uv) - p).norm(), 0.0, 1e-9);
  }
  // A real perspective, not an affine map: the far end is narrower.
  const double near_width = cv::norm(h.image_from_board({0.0, 0.0}) - h.image_from_board({board.width_m, 0.0}));
  const double far_width =
      cv::norm(h.image_from_board({0.0, board.height_m}) - h.image_from_board({board.width_m, board.height_m}));
  EXPECT_LT(far_width, 0.97 * near_width);
  // Up the table runs to the right of the image.
  EXPECT_GT(h.image_from_board({0.25, 1.0}).x, h.image_from_board({0.25, 0.1}).x + 400.0);
}

TEST(CameraHomography, FromPointsMapsThePointsExactly) {
  const std::array<Vec2, 4> board{Vec2{0.0, 0.0}, Vec2{0.5, 0.0}, Vec2{0.5, 1.0}, Vec2{0.0, 1.0}};
  const std::array<cv::Point2d, 4> image{cv::Point2d{10.3, 20.1}, cv::Point2d{15.0, 300.7},
                                         cv::Point2d{600.2, 280.0}, cv::Point2d{590.9, 40.4}};
  const CameraHomography h = CameraHomography::from_points(board, image);
  for (std::size_t i = 0; i < 4; ++i) EXPECT_NEAR(cv::norm(h.image_from_board(board[i]) - image[i]), 0.0, 1e-9);
}

// Degenerate correspondences had been accepted with a matrix that did not map them.
TEST(CameraHomography, FromPointsRefusesPointsNoViewOfAPlaneGives) {
  const std::array<Vec2, 4> board{Vec2{0.0, 0.0}, Vec2{0.5, 0.0}, Vec2{0.5, 1.0}, Vec2{0.0, 1.0}};
  const std::array<cv::Point2d, 4> image{cv::Point2d{10.3, 20.1}, cv::Point2d{15.0, 300.7},
                                         cv::Point2d{600.2, 280.0}, cv::Point2d{590.9, 40.4}};
  const auto error = [](const std::array<Vec2, 4>& b, const std::array<cv::Point2d, 4>& i) {
    try {
      (void)CameraHomography::from_points(b, i);
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  std::array<Vec2, 4> on_a_line = board;
  on_a_line[1] = Vec2{0.25, 0.5};  // between corners 0 and 2
  EXPECT_NE(error(on_a_line, image).find("three of the four board points lie on a line"), std::string::npos);
  std::array<cv::Point2d, 4> flat = image;
  for (cv::Point2d& p : flat) p.y = 20.0;  // the board squashed onto one image row
  EXPECT_NE(error(board, flat).find("three of the four image points lie on a line"), std::string::npos);
  std::array<Vec2, 4> twice = board;
  twice[3] = twice[0];
  EXPECT_NE(error(twice, image).find("board points lie on a line (or two coincide)"), std::string::npos);
  std::array<cv::Point2d, 4> crossed = image;
  std::swap(crossed[2], crossed[3]);  // a bow tie
  EXPECT_NE(error(board, crossed).find("an order no view of a plane gives"), std::string::npos)
      << error(board, crossed);
  EXPECT_EQ(error(board, image), "");
}

TEST(CameraHomography, LocalScaleIsTheSquareRootOfTheAreaMagnification) {
  const CameraHomography h = CameraHomography::default_view(table(), {1280, 1024});
  const Vec2 p{0.3, 0.9};
  const double e = 1e-4;
  const cv::Point2d a = h.image_from_board(p);
  const cv::Point2d bx = h.image_from_board(p + Vec2{e, 0.0}) - a;
  const cv::Point2d by = h.image_from_board(p + Vec2{0.0, e}) - a;
  const double area = std::abs(bx.x * by.y - bx.y * by.x) / (e * e);
  EXPECT_NEAR(h.px_per_m_at(p), std::sqrt(area), 1e-3 * std::sqrt(area));
  // The far end of the table is imaged smaller.
  EXPECT_LT(h.px_per_m_at({0.25, 1.0}), h.px_per_m_at({0.25, 0.05}));
}

TEST(CameraHomography, RejectsSingularMatricesAndBadViews) {
  // Braces: with parentheses the statement may be read as a declaration of
  // cv::Matx33d::zeros (clang does, and refuses it).
  EXPECT_THROW(CameraHomography{cv::Matx33d::zeros()}, std::invalid_argument);
  EXPECT_THROW(CameraHomography(cv::Matx33d(1, 2, 3, 2, 4, 6, 0, 0, 1)), std::invalid_argument);
  CameraView bad;
  bad.keystone = 0.7;
  EXPECT_THROW(CameraHomography::default_view(table(), {640, 480}, bad), std::invalid_argument);
  EXPECT_THROW(CameraHomography::default_view(table(), {0, 480}), std::invalid_argument);
}

}  // namespace
}  // namespace pinball::vision
