#include "pinball/calibration/calibration_target.h"

#include <stdexcept>
#include <string>

#include <gtest/gtest.h>
#include <opencv2/aruco/charuco.hpp>

namespace pinball::calibration {
namespace {

std::string refusal(const std::string& text) {
  try {
    (void)parse_target(text);
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "accepted";
}

TEST(CalibrationTarget, ParsesBothKinds) {
  const TargetSpec chess = parse_target("chessboard:10x7:0.025");
  EXPECT_EQ(chess.kind, TargetKind::kChessboard);
  EXPECT_EQ(chess.squares_x, 10);
  EXPECT_EQ(chess.squares_y, 7);
  EXPECT_DOUBLE_EQ(chess.square_m, 0.025);
  EXPECT_EQ(chess.describe(), "chessboard 10x7 squares (9x6 inner corners), 25 mm");

  const TargetSpec charuco = parse_target("charuco:8x6:0.03:0.022");
  EXPECT_EQ(charuco.kind, TargetKind::kCharuco);
  EXPECT_EQ(charuco.squares_x, 8);
  EXPECT_DOUBLE_EQ(charuco.marker_m, 0.022);
  EXPECT_EQ(charuco.dictionary, "DICT_4X4_50");
  EXPECT_EQ(charuco.describe(), "ChArUco 8x6 squares (35 corners), 30 mm, 22 mm markers DICT_4X4_50");
  EXPECT_EQ(parse_target("charuco:10x7:0.025:0.018:DICT_5X5_100").dictionary, "DICT_5X5_100");
}

TEST(CalibrationTarget, RefusesBadSpecsSayingWhatIsWrong) {
  EXPECT_NE(refusal("wobble").find("target 'wobble': expected chessboard:SXxSY:SQUARE_M"), std::string::npos);
  EXPECT_NE(refusal("chessboard:10x7").find("expected chessboard"), std::string::npos);
  EXPECT_NE(refusal("chessboard:10y7:0.025").find("should be SXxSY"), std::string::npos);
  EXPECT_NE(refusal("chessboard:10x7:0.025mm").find("square side '0.025mm' is not a number"), std::string::npos);
  EXPECT_NE(refusal("chessboard:10.5x7:0.025").find("whole numbers"), std::string::npos);
  EXPECT_NE(refusal("chessboard:2x7:0.025").find("squares_x must be in [3, 100]"), std::string::npos);
  EXPECT_NE(refusal("chessboard:10x7:25").find("square_m must be in (0, 1] m"), std::string::npos);
  EXPECT_NE(refusal("chessboard:10x7:-0.025").find("square_m"), std::string::npos);
  EXPECT_NE(refusal("charuco:10x7:0.025:0.03").find("marker_m must be in (0, square_m)"), std::string::npos);
  EXPECT_NE(refusal("charuco:10x7:0.025:0.018:DICT_NOPE").find("'DICT_NOPE' is not a cv::aruco predefined"),
            std::string::npos);
  // 12x10 squares hold 60 markers; DICT_4X4_50 has 50.
  EXPECT_NE(refusal("charuco:12x10:0.025:0.018").find("DICT_4X4_50 has 50 markers but a 12x10 board needs 60"),
            std::string::npos);
  EXPECT_EQ(refusal("charuco:12x10:0.025:0.018:DICT_4X4_100"), "accepted");
}

TEST(CalibrationTarget, CornersInIdOrderAsArucoNumbersThem) {
  const TargetSpec t = parse_target("charuco:5x4:0.03:0.02");
  const std::vector<cv::Point3d> points = target_points_m(t);
  ASSERT_EQ(points.size(), 12u);
  EXPECT_EQ(target_corner_count(t), 12);
  EXPECT_EQ(points.front(), cv::Point3d(0.03, 0.03, 0.0));
  EXPECT_EQ(points[1], cv::Point3d(0.06, 0.03, 0.0));  // x fastest
  const cv::Ptr<cv::aruco::CharucoBoard> board = cv::aruco::CharucoBoard::create(
      5, 4, 0.03f, 0.02f, cv::aruco::getPredefinedDictionary(cv::aruco::DICT_4X4_50));
  ASSERT_EQ(board->chessboardCorners.size(), points.size());
  for (std::size_t i = 0; i < points.size(); ++i) {
    EXPECT_NEAR(points[i].x, board->chessboardCorners[i].x, 1e-7) << i;
    EXPECT_NEAR(points[i].y, board->chessboardCorners[i].y, 1e-7) << i;
  }
}

TEST(CalibrationTarget, ChessboardImageHasItsSquaresAndMargin) {
  const TargetSpec t = parse_target("chessboard:4x3:0.02");
  const cv::Mat img = target_image(t, 1000.0, 15);  // 20 px squares
  ASSERT_EQ(img.type(), CV_8UC1);
  EXPECT_EQ(img.cols, 4 * 20 + 30);
  EXPECT_EQ(img.rows, 3 * 20 + 30);
  EXPECT_EQ(img.at<std::uint8_t>(5, 5), 255);  // margin
  for (int j = 0; j < 3; ++j) {
    for (int i = 0; i < 4; ++i) {
      const int expected = (i + j) % 2 == 0 ? 0 : 255;  // the top-left square is black
      EXPECT_EQ(img.at<std::uint8_t>(15 + 20 * j + 10, 15 + 20 * i + 10), expected) << i << "," << j;
    }
  }
  EXPECT_THROW((void)target_image(t, 0.0, 10), std::invalid_argument);
  EXPECT_THROW((void)target_image(t, 1000.0, -1), std::invalid_argument);
  EXPECT_THROW((void)target_image(t, 1e300, 10), std::invalid_argument);  // not a 1e300-pixel image
}

// The renderer's pattern is OpenCV's drawing of the board: squares, markers,
// bits. OpenCV rounds the markers' places to whole pixels (they come out one
// pixel up and left here), so pixels may differ only beside an edge.
TEST(CalibrationTarget, PatternMatchesOpenCvsCharucoDrawing) {
  const TargetSpec t = parse_target("charuco:6x5:0.03:0.021");
  const double px_per_m = 4000.0;  // 120 px squares, 84 px markers, 14 px cells: an integer grid
  const cv::Mat drawn = target_image(t, px_per_m, 0);
  const TargetPattern pattern(t);
  const auto ink = [&](int c, int r) { return pattern.ink((c + 0.5) / px_per_m, (r + 0.5) / px_per_m); };
  int differ = 0, away_from_edges = 0;
  for (int r = 0; r < drawn.rows; ++r) {
    for (int c = 0; c < drawn.cols; ++c) {
      if (ink(c, r) == (drawn.at<std::uint8_t>(r, c) < 128)) continue;
      ++differ;
      bool edge = false;
      for (int dr = -1; dr <= 1; ++dr) {
        for (int dc = -1; dc <= 1; ++dc) edge = edge || ink(c + dc, r + dr) != ink(c, r);
      }
      away_from_edges += edge ? 0 : 1;
    }
  }
  EXPECT_EQ(away_from_edges, 0);
  EXPECT_LT(differ, static_cast<int>(drawn.total()) / 50) << differ << " of " << drawn.total() << " pixels differ";
}

TEST(CalibrationTarget, PatternOfAChessboard) {
  const TargetPattern p(parse_target("chessboard:10x7:0.025"));
  EXPECT_DOUBLE_EQ(p.width_m(), 0.25);
  EXPECT_DOUBLE_EQ(p.height_m(), 0.175);
  EXPECT_TRUE(p.ink(0.01, 0.01));
  EXPECT_FALSE(p.ink(0.035, 0.01));
  EXPECT_TRUE(p.ink(0.035, 0.035));
  EXPECT_FALSE(p.ink(-0.001, 0.01));  // off the squares: paper
  EXPECT_FALSE(p.ink(0.2501, 0.01));
}

}  // namespace
}  // namespace pinball::calibration
