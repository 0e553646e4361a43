#include "pinball/plot/draw.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <stdexcept>
#include <utility>

#include <opencv2/imgproc.hpp>

#include "pinball/plot/ticks.h"

namespace pinball::plot {
namespace {

constexpr int kFont = cv::FONT_HERSHEY_SIMPLEX;
// Sub-pixel drawing: OpenCV takes fixed-point coordinates with this many fractional bits.
constexpr int kShift = 4;
constexpr double kFixed = 1 << kShift;
constexpr double kDashOn_px = 8.0, kDashOff_px = 5.0;

const cv::Scalar kBlack(0, 0, 0), kWhite(255, 255, 255), kFrame(120, 120, 120);

cv::Point fixed(cv::Point2d p) {
  return {static_cast<int>(std::lround(p.x * kFixed)), static_cast<int>(std::lround(p.y * kFixed))};
}

void segment(cv::Mat& image, cv::Point2d a, cv::Point2d b, const cv::Scalar& colour, int thickness) {
  cv::line(image, fixed(a), fixed(b), colour, thickness, cv::LINE_AA, kShift);
}

// Legend layout: swatch width, row height, padding.
constexpr int kSwatch = 28, kPad = 6;

}  // namespace

cv::Scalar palette_colour(int i) {
  // Okabe and Ito (2008), BGR; yellow last, it reads worst on white.
  static const std::array<cv::Scalar, 8> kPalette{
      cv::Scalar(178, 114, 0),   cv::Scalar(0, 94, 213),   cv::Scalar(115, 158, 0), cv::Scalar(0, 159, 230),
      cv::Scalar(167, 121, 204), cv::Scalar(233, 180, 86), cv::Scalar(0, 0, 0),     cv::Scalar(66, 228, 240)};
  const int n = static_cast<int>(kPalette.size());
  return kPalette[static_cast<std::size_t>(((i % n) + n) % n)];
}

cv::Scalar muted_colour() { return {150, 150, 150}; }

std::string hershey_text(const std::string& text) {
  // The Hershey fonts have ASCII only: the project's few other signs in words.
  static const std::pair<const char*, const char*> kSigns[] = {
      {"\u00b1", "+/-"}, {"\u2014", "-"}, {"\u2013", "-"}, {"\u00b0", " deg"}, {"\u00b2", "^2"},
      {"\u03c3", "sigma"}, {"\u03b8", "theta"}, {"\u03bc", "mu"}, {"\u00b5", "u"}, {"\u03c1", "rho"},
      {"\u00d7", "x"}, {"\u2212", "-"}};
  std::string out = text;
  for (const auto& [sign, words] : kSigns) {
    for (std::size_t at = out.find(sign); at != std::string::npos; at = out.find(sign, at + std::strlen(words))) {
      out.replace(at, std::strlen(sign), words);
    }
  }
  for (char& c : out) {
    if (static_cast<unsigned char>(c) >= 0x80) c = '?';
  }
  return out;
}

void put_text(cv::Mat& image, const std::string& text, cv::Point origin, double scale, const cv::Scalar& colour) {
  cv::putText(image, hershey_text(text), origin, kFont, scale, colour, 1, cv::LINE_AA);
}

cv::Size text_size(const std::string& text, double scale) {
  int baseline = 0;
  return cv::getTextSize(hershey_text(text), kFont, scale, 1, &baseline);
}

void draw_marker(cv::Mat& image, cv::Point2d at, Marker marker, const cv::Scalar& colour, int size_px) {
  const double h = std::floor(0.5 * size_px);  // whole pixels: crisp edges about a whole-pixel centre
  switch (marker) {
    case Marker::kNone:
      return;
    case Marker::kCircle:
      cv::circle(image, fixed(at), static_cast<int>(h * kFixed), colour, 1, cv::LINE_AA, kShift);
      return;
    case Marker::kDot:
      cv::circle(image, fixed(at), static_cast<int>(std::max(1.5, 0.5 * h) * kFixed), colour, cv::FILLED, cv::LINE_AA,
                 kShift);
      return;
    case Marker::kSquare:
      cv::rectangle(image, fixed(at - cv::Point2d(h, h)), fixed(at + cv::Point2d(h, h)), colour, 1, cv::LINE_AA,
                    kShift);
      return;
    case Marker::kCross:
      segment(image, at - cv::Point2d(h, 0), at + cv::Point2d(h, 0), colour, 1);
      segment(image, at - cv::Point2d(0, h), at + cv::Point2d(0, h), colour, 1);
      return;
    case Marker::kTiltedCross:
      segment(image, at - cv::Point2d(h, h), at + cv::Point2d(h, h), colour, 1);
      segment(image, at - cv::Point2d(h, -h), at + cv::Point2d(h, -h), colour, 1);
      return;
    case Marker::kTriangle: {
      const std::vector<cv::Point> t{fixed(at + cv::Point2d(0, -h)), fixed(at + cv::Point2d(h, h)),
                                     fixed(at + cv::Point2d(-h, h))};
      cv::fillConvexPoly(image, t, colour, cv::LINE_AA, kShift);
      return;
    }
  }
}

void draw_polyline(cv::Mat& image, std::span<const cv::Point2d> points, const cv::Scalar& colour, int thickness,
                   LineStyle style) {
  if (style == LineStyle::kNone || points.size() < 2) return;
  if (style == LineStyle::kSolid) {
    for (std::size_t i = 1; i < points.size(); ++i) segment(image, points[i - 1], points[i], colour, thickness);
    return;
  }
  // Dashed: the pattern runs on along the whole polyline, across its corners.
  double phase = 0.0;  // distance into the current on+off period
  for (std::size_t i = 1; i < points.size(); ++i) {
    const cv::Point2d a = points[i - 1], d = points[i] - a;
    const double length = std::hypot(d.x, d.y);
    if (!(length > 0.0) || !std::isfinite(length)) continue;
    double s = 0.0;
    while (s < length) {
      const bool on = phase < kDashOn_px;
      const double left = (on ? kDashOn_px : kDashOn_px + kDashOff_px) - phase;
      const double e = std::min(length, s + left);
      if (!(e > s)) {
        // The dash's end is nearer than s's last digit (fmod left the phase a
        // hair short of it): step the pattern over that end, not along s,
        // or the loop would never advance.
        phase = on ? kDashOn_px : 0.0;
        continue;
      }
      if (on) segment(image, a + d * (s / length), a + d * (e / length), colour, thickness);
      phase = std::fmod(phase + (e - s), kDashOn_px + kDashOff_px);
      s = e;
    }
  }
}

LegendEntry marker_entry(std::string label, const cv::Scalar& colour, Marker marker) {
  return {std::move(label), colour, marker, LineStyle::kNone, false};
}

LegendEntry line_entry(std::string label, const cv::Scalar& colour, LineStyle style, Marker marker) {
  return {std::move(label), colour, marker, style, false};
}

int legend_row_width(const LegendEntry& entry) { return kSwatch + 6 + text_size(entry.label, kLabelScale).width; }

void draw_legend_row(cv::Mat& image, const LegendEntry& e, cv::Point top_left) {
  const int y = top_left.y + 8;
  const cv::Point2d a(top_left.x, y), b(top_left.x + kSwatch, y);
  if (e.band) {
    const cv::Rect r =
        cv::Rect(cv::Point(top_left.x, y - 6), cv::Size(kSwatch, 13)) & cv::Rect(0, 0, image.cols, image.rows);
    cv::Mat patch = image(r);
    cv::Mat tint(patch.size(), patch.type(), e.colour);
    cv::addWeighted(tint, 0.25, patch, 0.75, 0.0, patch);
  }
  const std::array<cv::Point2d, 2> line{a, b};
  draw_polyline(image, line, e.colour, 2, e.line);
  draw_marker(image, 0.5 * (a + b), e.marker, e.colour, 9);
  put_text(image, e.label, cv::Point(top_left.x + kSwatch + 6, y + 5), kLabelScale, kBlack);
}

cv::Size legend_size(std::span<const LegendEntry> entries) {
  int width = 0;
  for (const LegendEntry& e : entries) width = std::max(width, legend_row_width(e));
  return {2 * kPad + width, 2 * kPad + kLegendRow_px * static_cast<int>(entries.size()) - 4};
}

void draw_legend_at(cv::Mat& image, std::span<const LegendEntry> entries, cv::Point top_left) {
  if (entries.empty()) return;
  const cv::Size size = legend_size(entries);
  cv::rectangle(image, cv::Rect(top_left, size), kWhite, cv::FILLED);
  cv::rectangle(image, cv::Rect(top_left, size), kFrame, 1);
  for (std::size_t i = 0; i < entries.size(); ++i) {
    draw_legend_row(image, entries[i], top_left + cv::Point(kPad, kPad + kLegendRow_px * static_cast<int>(i)));
  }
}

namespace {

cv::Point corner_origin(const cv::Mat& image, cv::Size size, Corner corner) {
  constexpr int kInset = 8;
  const bool right = corner == Corner::kTopRight || corner == Corner::kBottomRight;
  const bool bottom = corner == Corner::kBottomLeft || corner == Corner::kBottomRight;
  return {right ? std::max(0, image.cols - kInset - size.width) : kInset,
          bottom ? std::max(0, image.rows - kInset - size.height) : kInset};
}

std::string length_label(double m) {
  if (m >= 1.0) return tick_label(m, m) + " m";
  if (m >= 0.01) return tick_label(m * 100.0, m * 100.0) + " cm";
  return tick_label(m * 1000.0, m * 1000.0) + " mm";
}

}  // namespace

void draw_legend(cv::Mat& image, std::span<const LegendEntry> entries, Corner corner) {
  if (entries.empty()) return;
  draw_legend_at(image, entries, corner_origin(image, legend_size(entries), corner));
}

double draw_scale_bar(cv::Mat& image, double px_per_m, Corner corner) {
  if (!(px_per_m > 0.0) || !std::isfinite(px_per_m)) throw std::invalid_argument("draw_scale_bar: needs px_per_m > 0");
  const double length_m = round_at_most(0.25 * std::max(image.cols, 8) / px_per_m);
  const int bar_px = static_cast<int>(std::lround(length_m * px_per_m));
  const std::string label = length_label(length_m);
  const cv::Size text = text_size(label, kLabelScale);
  const cv::Size box(std::max(bar_px, text.width) + 2 * kPad, text.height + 2 * kPad + 12);
  const cv::Point o = corner_origin(image, box, corner);
  cv::rectangle(image, cv::Rect(o, box), kWhite, cv::FILLED);
  cv::rectangle(image, cv::Rect(o, box), kFrame, 1);
  const int y = o.y + box.height - kPad - 3;
  cv::rectangle(image, cv::Rect(o.x + kPad, y - 3, bar_px, 6), kBlack, cv::FILLED);
  put_text(image, label, cv::Point(o.x + kPad, o.y + kPad + text.height), kLabelScale, kBlack);
  return length_m;
}

cv::Mat with_title(const cv::Mat& image, const std::string& title, std::span<const std::string> notes) {
  constexpr int kTitleRow = 30, kNoteRow = 21;
  int width = std::max(image.cols, text_size(title, kTitleScale).width + 2 * kPad + 2);
  for (const std::string& n : notes) width = std::max(width, text_size(n, kLabelScale).width + 2 * kPad);
  const int banner = kTitleRow + kNoteRow * static_cast<int>(notes.size()) + 6;
  cv::Mat out(banner + image.rows, width, CV_8UC3, kWhite);
  if (!image.empty()) {
    cv::Mat bgr;
    if (image.channels() == 1) {
      cv::cvtColor(image, bgr, cv::COLOR_GRAY2BGR);
    } else {
      bgr = image;
    }
    bgr.copyTo(out(cv::Rect(0, banner, image.cols, image.rows)));
  }
  // Bold by drawing twice a pixel apart.
  put_text(out, title, cv::Point(kPad, 22), kTitleScale, kBlack);
  put_text(out, title, cv::Point(kPad + 1, 22), kTitleScale, kBlack);
  for (std::size_t i = 0; i < notes.size(); ++i) {
    put_text(out, notes[i], cv::Point(kPad, kTitleRow + kNoteRow * static_cast<int>(i) + 14), kLabelScale,
             cv::Scalar(40, 40, 40));
  }
  return out;
}

cv::Mat place(std::span<const cv::Mat> images, bool horizontal, int gap_px) {
  int along = 0, across = 0;
  for (const cv::Mat& m : images) {
    if (m.empty()) continue;
    along += (horizontal ? m.cols : m.rows) + (along > 0 ? gap_px : 0);
    across = std::max(across, horizontal ? m.rows : m.cols);
  }
  cv::Mat out = horizontal ? cv::Mat(across, along, CV_8UC3, kWhite) : cv::Mat(along, across, CV_8UC3, kWhite);
  int at = 0;
  for (const cv::Mat& m : images) {
    if (m.empty()) continue;
    const cv::Rect r = horizontal ? cv::Rect(at, 0, m.cols, m.rows) : cv::Rect(0, at, m.cols, m.rows);
    m.copyTo(out(r));
    at += (horizontal ? m.cols : m.rows) + gap_px;
  }
  return out;
}

cv::Mat annotated_picture(const cv::Mat& picture, std::span<const LegendEntry> legend, const std::string& title,
                          std::span<const std::string> notes) {
  cv::Mat bgr;
  if (picture.channels() == 1) {
    cv::cvtColor(picture, bgr, cv::COLOR_GRAY2BGR);
  } else {
    bgr = picture;
  }
  if (legend.empty()) return with_title(bgr, title, notes);
  cv::Mat key(legend_size(legend) + cv::Size(16, 16), CV_8UC3, kWhite);
  draw_legend(key, legend, Corner::kTopLeft);
  const std::vector<cv::Mat> parts{bgr, key};
  return with_title(place(parts, true), title, notes);
}

}  // namespace pinball::plot
