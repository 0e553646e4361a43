#include "pinball/plot/draw.h"

#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "common/figure_check.h"

namespace pinball::plot {
namespace {

using pinball::testing::count_colour;
using pinball::testing::count_ink;

TEST(PaletteTest, EightDistinctColoursThatCycle) {
  for (int i = 0; i < 8; ++i) {
    for (int k = i + 1; k < 8; ++k) EXPECT_NE(palette_colour(i), palette_colour(k)) << i << " " << k;
  }
  EXPECT_EQ(palette_colour(9), palette_colour(1));
  EXPECT_EQ(palette_colour(-1), palette_colour(7));
}

TEST(LegendTest, DrawsEverySwatchInItsColourInTheCorner) {
  cv::Mat image(300, 400, CV_8UC3, cv::Scalar(30, 30, 30));
  const std::vector<LegendEntry> entries{
      {.label = "tips", .colour = palette_colour(0), .marker = Marker::kDot, .line = LineStyle::kNone},
      {.label = "fitted circle", .colour = palette_colour(1)},
      {.label = "left out", .colour = muted_colour(), .marker = Marker::kNone, .line = LineStyle::kDashed}};
  draw_legend(image, entries, Corner::kTopRight);
  const cv::Size size = legend_size(entries);
  const cv::Mat box = image(cv::Rect(image.cols - 8 - size.width, 8, size.width, size.height));
  EXPECT_GT(count_colour(box, palette_colour(0), 20), 3);
  EXPECT_GT(count_colour(box, palette_colour(1), 20), 20);
  EXPECT_GT(count_colour(box, muted_colour(), 20), 10);
  EXPECT_GT(count_colour(box, cv::Scalar(255, 255, 255), 5), size.area() / 3);                       // a white box
  EXPECT_EQ(count_colour(image(cv::Rect(0, 150, 400, 150)), cv::Scalar(30, 30, 30), 0), 400 * 150);  // only there
}

TEST(ScaleBarTest, RoundLengthAtMostAQuarterOfTheWidth) {
  cv::Mat image(400, 430, CV_8UC3, cv::Scalar(20, 20, 20));
  const double length_m = draw_scale_bar(image, 800.0, Corner::kBottomRight);
  EXPECT_DOUBLE_EQ(length_m, 0.1);  // a quarter of 430 px at 800 px/m is 13 cm: 10 cm
  // The bar: 80 px of black in the bottom-right box.
  const cv::Mat corner = image(cv::Rect(430 - 120, 400 - 60, 120, 60));
  EXPECT_GE(count_colour(corner, cv::Scalar(0, 0, 0), 10), 80 * 5);
  EXPECT_THROW(draw_scale_bar(image, 0.0, Corner::kTopLeft), std::invalid_argument);
}

TEST(TitleTest, BannerAboveTheImageWithTheText) {
  const cv::Mat image(100, 200, CV_8UC3, cv::Scalar(40, 40, 40));
  const std::vector<std::string> notes{"a note under the title"};
  const cv::Mat titled = with_title(image, "A long title naming pinball render and the board file", notes);
  EXPECT_GT(titled.rows, image.rows + 40);
  EXPECT_GT(titled.cols, image.cols);  // the text is wider than the image: the banner widens it
  const cv::Mat banner = titled(cv::Rect(0, 0, titled.cols, titled.rows - image.rows));
  EXPECT_GT(count_ink(banner), 300);
  EXPECT_EQ(count_colour(titled(cv::Rect(0, titled.rows - 100, 200, 100)), cv::Scalar(40, 40, 40), 0), 200 * 100);
}

TEST(PlaceTest, SideBySideAndStacked) {
  const std::vector<cv::Mat> parts{cv::Mat(50, 60, CV_8UC3, cv::Scalar(0, 0, 255)),
                                   cv::Mat(30, 40, CV_8UC3, cv::Scalar(255, 0, 0))};
  EXPECT_EQ(place(parts, true, 8).size(), cv::Size(108, 50));
  EXPECT_EQ(place(parts, false, 8).size(), cv::Size(60, 88));
}

// A dashed line whose phase fmod leaves a hair (6e-14 px) short of a dash's
// end, where s + left == s: it drew for ever (`learn --plot` hung at 100 %
// CPU on some learning curves). Found by searching random polylines.
TEST(PolylineTest, ADashedLineEndsWhereFmodLeavesThePhaseAHairShortOfADash) {
  cv::Mat image(1000, 1800, CV_8UC3, cv::Scalar(255, 255, 255));
  const std::vector<cv::Point2d> points{{495.43508709194094, 788.7233511355132},
                                        {720.18061948631, 788.7233511355132},
                                        {1697.5700785704544, 788.7233511355132}};
  draw_polyline(image, points, cv::Scalar(0, 0, 0), 1, LineStyle::kDashed);
  // Dashes of 8 px and gaps of 5 px along the 1202 px: about 8/13 of it inked.
  const double inked_fraction = count_colour(image, cv::Scalar(0, 0, 0), 100) / (1697.57 - 495.44);
  EXPECT_GT(inked_fraction, 0.5);
  EXPECT_LT(inked_fraction, 0.75);
}

}  // namespace
}  // namespace pinball::plot
