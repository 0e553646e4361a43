#pragma once
// The drawing vocabulary every figure shares: one colour-blind-safe palette
// (Okabe and Ito), text, markers, dashed lines, a legend box, a scale bar, a
// title banner, side-by-side placement, and writing a PNG. Charts
// (pinball/plot/chart.h) and the annotated camera pictures of calibration
// both draw with these, so every figure looks and reads alike.

#include <span>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

namespace pinball::plot {

/// Colour `i` (BGR) of the palette, cycling after 8: blue, vermillion, bluish
/// green, orange, reddish purple, sky blue, black, yellow (Okabe and Ito).
cv::Scalar palette_colour(int i);
/// Grey for what is drawn but not used (a roll left out, a baseline).
cv::Scalar muted_colour();

/// A point's marker.
enum class Marker { kNone, kCircle, kDot, kSquare, kCross, kTiltedCross, kTriangle };
/// A line's style.
enum class LineStyle { kNone, kSolid, kDashed };

/// Text height scale of labels and of titles (HERSHEY_SIMPLEX).
inline constexpr double kLabelScale = 0.5;
inline constexpr double kTitleScale = 0.62;

/// `text` in the font's ASCII: ±, —, °, ², σ, θ, µ, ρ, × and − spelled out; any
/// other non-ASCII byte becomes '?'. put_text and text_size apply it.
std::string hershey_text(const std::string& text);
/// Draws `text` with its baseline starting at `origin` (anti-aliased HERSHEY_SIMPLEX).
void put_text(cv::Mat& image, const std::string& text, cv::Point origin, double scale, const cv::Scalar& colour);
/// Width and height (above the baseline) of `text` in px.
cv::Size text_size(const std::string& text, double scale);

/// A marker of `size_px` centred at `at_px`.
void draw_marker(cv::Mat& image, cv::Point2d at_px, Marker marker, const cv::Scalar& colour, int size_px = 8);
/// A polyline through `points_px`, solid or dashed (nothing for kNone).
void draw_polyline(cv::Mat& image, std::span<const cv::Point2d> points_px, const cv::Scalar& colour, int thickness_px,
                   LineStyle style);

/// One row of a legend: a swatch (line, marker, or a band's patch) and its label.
struct LegendEntry {
  std::string label{};                 ///< text
  cv::Scalar colour{};                 ///< BGR
  Marker marker = Marker::kNone;       ///< drawn at the swatch's middle
  LineStyle line = LineStyle::kSolid;  ///< the swatch's line
  bool band = false;                   ///< a shaded patch (an interval) behind the line
};

/// A legend row for points drawn with `marker` and no line.
LegendEntry marker_entry(std::string label, const cv::Scalar& colour, Marker marker);
/// A legend row for a line of `style` (and, optionally, a marker on it).
LegendEntry line_entry(std::string label, const cv::Scalar& colour, LineStyle style = LineStyle::kSolid,
                       Marker marker = Marker::kNone);

/// Corner of an image.
enum class Corner { kTopLeft, kTopRight, kBottomLeft, kBottomRight };

/// Height of one legend row (px).
inline constexpr int kLegendRow_px = 20;
/// Width of one legend row: swatch, gap and label (px).
int legend_row_width(const LegendEntry& entry);
/// One legend row (swatch and label, no box) with its top-left at `top_left`.
void draw_legend_row(cv::Mat& image, const LegendEntry& entry, cv::Point top_left);
/// Size of the legend box draw_legend_at draws for `entries`.
cv::Size legend_size(std::span<const LegendEntry> entries);
/// A legend box (white, framed; one row per entry) with its top-left at `top_left`.
void draw_legend_at(cv::Mat& image, std::span<const LegendEntry> entries, cv::Point top_left);
/// A legend box in a corner of `image`, 8 px in from its edges.
void draw_legend(cv::Mat& image, std::span<const LegendEntry> entries, Corner corner);

/// A scale bar of a round length (1, 2, 5 x 10^k m, at most a quarter of the
/// image's width) labelled in mm, cm or m, on a white box in a corner.
/// Returns the bar's length (m). Throws std::invalid_argument for px_per_m <= 0.
double draw_scale_bar(cv::Mat& image, double px_per_m, Corner corner);

/// `image` below a white banner with `title` (bold) and one line per note;
/// the banner widens the image (white at the right) when the text is wider.
cv::Mat with_title(const cv::Mat& image, const std::string& title, std::span<const std::string> notes = {});

/// The images side by side (horizontal) or stacked, `gap_px` of white between,
/// top- or left-aligned on white. BGR 8-bit inputs.
cv::Mat place(std::span<const cv::Mat> images, bool horizontal, int gap_px = 8);

/// A picture that is not a chart (a camera frame, a board) as a figure: the
/// legend in a white column at its right, so it covers nothing, and
/// with_title above both.
cv::Mat annotated_picture(const cv::Mat& picture, std::span<const LegendEntry> legend, const std::string& title,
                          std::span<const std::string> notes = {});

}  // namespace pinball::plot
