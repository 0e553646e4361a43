#include "pinball/plot/chart.h"

#include <cmath>
#include <stdexcept>

#include <gtest/gtest.h>

#include "common/figure_check.h"

namespace pinball::plot {
namespace {

using pinball::testing::count_colour;
using pinball::testing::count_ink;

Figure two_series_figure() {
  Figure f;
  f.title = "Test chart - plot_tests";
  f.notes = {"a note"};
  Panel p;
  p.x.label = "time (s)";
  p.y.label = "height (m)";
  Series rising{.label = "rising", .colour = palette_colour(0)};
  Series falling{
      .label = "falling", .colour = palette_colour(1), .line = LineStyle::kDashed, .marker = Marker::kSquare};
  for (int i = 0; i <= 20; ++i) {
    rising.x.push_back(0.37 * i);
    rising.y.push_back(0.01 * i * i);
    rising.y_low.push_back(0.01 * i * i - 0.3);
    rising.y_high.push_back(0.01 * i * i + 0.3);
    falling.x.push_back(0.37 * i);
    falling.y.push_back(4.0 - 0.2 * i);
  }
  rising.interval = IntervalStyle::kBand;
  p.series = {rising, falling};
  p.references.push_back(
      {.vertical = false, .at = 0.0, .colour = muted_colour(), .line = LineStyle::kDashed, .label = "zero"});
  f.panels.push_back(p);
  return f;
}

TEST(ChartTest, RenderedChartHasInkSeriesColoursAndLegend) {
  const Figure f = two_series_figure();
  const cv::Mat image = render(f);
  ASSERT_FALSE(image.empty());
  EXPECT_GE(image.cols, f.panel_size.width);
  EXPECT_GT(image.rows, f.panel_size.height + 60);  // title, note and legend above the panel
  EXPECT_GT(count_ink(image), image.rows * image.cols / 50);
  EXPECT_GT(count_colour(image, palette_colour(0)), 300);  // a 2 px line across the panel
  EXPECT_GT(count_colour(image, palette_colour(1)), 150);
  // The legend strip sits between the banner and the panel: swatches of both colours there.
  const cv::Mat top = image(cv::Rect(0, 0, image.cols, image.rows - f.panel_size.height));
  EXPECT_GT(count_colour(top, palette_colour(0)), 20);
  EXPECT_GT(count_colour(top, palette_colour(1)), 10);
  EXPECT_EQ(legend_entries(f).size(), 3u);
}

TEST(ChartTest, SeriesIsDrawnWhereItsDataIs) {
  Figure f;
  f.title = "where";
  Panel p;
  p.x.label = "x";
  p.y.label = "y";
  // Only the upper-right quarter of the data range holds the line.
  Series corner{.label = "corner", .colour = muted_colour(), .line = LineStyle::kNone};
  corner.x = corner.y = {0.0, 1.0};
  Series line{.label = "line", .colour = palette_colour(2)};
  line.x = {0.6, 1.0};
  line.y = {0.9, 0.9};
  p.series = {corner, line};
  f.panels.push_back(p);
  const cv::Mat image = render(f);
  const cv::Mat panel = image(cv::Rect(0, image.rows - f.panel_size.height, f.panel_size.width, f.panel_size.height));
  const cv::Mat left = panel(cv::Rect(0, 0, panel.cols / 2, panel.rows));
  const cv::Mat right_top = panel(cv::Rect(panel.cols / 2, 0, panel.cols / 2, panel.rows / 3));
  EXPECT_EQ(count_colour(left, palette_colour(2)), 0);
  EXPECT_GT(count_colour(right_top, palette_colour(2)), 100);
}

TEST(ChartTest, StackedPanelsLogAxesAndGaps) {
  Figure f = two_series_figure();
  Panel log_panel;
  log_panel.x.label = "run time (s)";
  log_panel.y.label = "error (m)";
  log_panel.x.log = log_panel.y.log = true;
  Series s{.label = "power law", .colour = palette_colour(3), .line = LineStyle::kSolid, .marker = Marker::kCircle};
  for (int i = 1; i <= 10; ++i) {
    s.x.push_back(std::pow(10.0, -i * 0.4));
    s.y.push_back(i == 5 ? std::nan("") : std::pow(10.0, -i * 0.8));  // a gap, and a value <= 0
  }
  s.y[2] = 0.0;
  s.y_low.assign(s.y.size(), 0.0);  // intervals of no use on a log axis: not drawn, no crash
  s.y_high = s.y;
  s.interval = IntervalStyle::kErrorBars;
  log_panel.series.push_back(s);
  f.panels.push_back(log_panel);
  f.share_x = false;
  const cv::Mat image = render(f);
  EXPECT_GT(image.rows, 2 * f.panel_size.height);
  EXPECT_GT(count_colour(image, palette_colour(3)), 100);
}

TEST(ChartTest, RejectsMismatchedSeriesAndNoPanels) {
  EXPECT_THROW(render(Figure{}), std::invalid_argument);
  Figure f = two_series_figure();
  f.panels[0].series[0].y.pop_back();
  EXPECT_THROW(render(f), std::invalid_argument);
}

TEST(ChartTest, EmptyAndConstantSeriesStillRender) {
  Figure f;
  f.title = "nothing yet";
  Panel p;
  p.series.push_back({.label = "empty", .colour = palette_colour(0)});
  Series flat{.label = "flat", .colour = palette_colour(1)};
  flat.x = {1.0, 1.0};
  flat.y = {2.0, 2.0};
  p.series.push_back(flat);
  f.panels.push_back(p);
  EXPECT_FALSE(render(f).empty());
}

}  // namespace
}  // namespace pinball::plot
