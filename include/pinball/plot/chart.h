#pragma once
// Charts: one or more panels of x-y series (lines, markers, an interval as a
// shaded band or error bars) with labelled axes at round ticks, a grid, a
// legend and a title, rendered to a BGR image. Every chart the commands write
// (learning curves, the gravity fit, the precision and transfer benches) is
// one Figure; the colours come from palette_colour (pinball/plot/draw.h).

#include <optional>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "pinball/plot/draw.h"

namespace pinball::plot {

/// How a series shows its interval [y_low, y_high].
enum class IntervalStyle { kNone, kBand, kErrorBars };

/// One series of a panel: how it looks first (designated initializers name
/// those), then its data.
struct Series {
  std::string label{};                            ///< legend text; empty: not in the legend
  cv::Scalar colour = palette_colour(0);          ///< BGR
  LineStyle line = LineStyle::kSolid;             ///< line through the points
  Marker marker = Marker::kNone;                  ///< marker at each point
  int thickness_px = 2;                           ///< line width
  IntervalStyle interval = IntervalStyle::kNone;  ///< how the interval is drawn
  std::vector<double> x{}, y{};                   ///< points, same length; non-finite points are skipped
  std::vector<double> y_low{}, y_high{};          ///< interval per point (empty, or the length of y)
};

/// One axis.
struct Axis {
  std::string label{};               ///< what and its unit: "time (s)"
  bool log = false;                  ///< log10 scale (values <= 0 are not drawn)
  std::optional<double> lo{}, hi{};  ///< fixed range; else round ticks around the data
  bool include_zero = false;         ///< the range reaches 0 (a linear axis)
};

/// A horizontal or vertical reference line across a panel.
struct ReferenceLine {
  bool vertical = false;                ///< x = at (else y = at)
  double at = 0.0;                      ///< where
  cv::Scalar colour = muted_colour();   ///< BGR
  LineStyle line = LineStyle::kDashed;  ///< style
  std::string label{};                  ///< legend text; empty: not in the legend
};

/// One panel: axes, series and reference lines.
struct Panel {
  std::string title{};                    ///< above the plot area (may be empty)
  Axis x, y;                              ///< axes
  std::vector<Series> series;             ///< drawn in order
  std::vector<ReferenceLine> references;  ///< drawn below the series
};

/// A figure: a title, notes, one legend for all panels, panels in a grid.
struct Figure {
  std::string title{};             ///< what, and from which command: "Gravity fit — pinball calibrate gravity"
  std::vector<std::string> notes;  ///< lines under the title (the estimate, settings)
  std::vector<Panel> panels;       ///< row by row
  int columns = 1;                 ///< panels per row
  cv::Size panel_size{880, 440};   ///< each panel's size (px), axes and labels included
  bool share_x = false;            ///< one x range for every panel
  bool share_y = false;            ///< one y range for every panel
  int max_ticks = 7;               ///< ticks per linear axis at most
};

/// The legend of a figure: one entry per distinct label, in order of appearance.
std::vector<LegendEntry> legend_entries(const Figure& figure);

/// Draws the figure: white background, anti-aliased. Throws std::invalid_argument
/// for a figure without panels or a series whose x, y and interval lengths differ.
cv::Mat render(const Figure& figure);

}  // namespace pinball::plot
