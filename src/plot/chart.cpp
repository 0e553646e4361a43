#include "pinball/plot/chart.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include <opencv2/imgproc.hpp>

#include "pinball/plot/ticks.h"

namespace pinball::plot {
namespace {

const cv::Scalar kInk(0, 0, 0), kPaper(255, 255, 255), kGrid(228, 228, 228), kAxisFrame(90, 90, 90);
constexpr double kTickScale = 0.45;

// An axis resolved against its data: the drawn range, ticks, and the transform.
struct Scale {
  bool log = false;
  double lo = 0.0, hi = 1.0;  // drawn range (values)
  std::vector<double> ticks;
  double step = 1.0;  // linear tick step (labels)

  double t(double v) const { return log ? std::log10(v) : v; }
  double fraction(double v) const { return (t(v) - t(lo)) / (t(hi) - t(lo)); }
  bool drawable(double v) const { return std::isfinite(v) && (!log || v > 0.0); }
};

struct Extent {
  double lo = std::numeric_limits<double>::infinity(), hi = -std::numeric_limits<double>::infinity();
  void add(double v, bool log) {
    if (!std::isfinite(v) || (log && !(v > 0.0))) return;
    lo = std::min(lo, v);
    hi = std::max(hi, v);
  }
  void add(const Extent& e) {
    lo = std::min(lo, e.lo);
    hi = std::max(hi, e.hi);
  }
  bool empty() const { return !(lo <= hi); }
};

Extent data_extent(const Panel& p, bool x_axis) {
  const bool log = x_axis ? p.x.log : p.y.log;
  Extent e;
  for (const Series& s : p.series) {
    if (x_axis) {
      for (double v : s.x) e.add(v, log);
    } else {
      for (double v : s.y) e.add(v, log);
      if (s.interval != IntervalStyle::kNone) {
        for (double v : s.y_low) e.add(v, log);
        for (double v : s.y_high) e.add(v, log);
      }
    }
  }
  for (const ReferenceLine& r : p.references) {
    if (r.vertical == x_axis) e.add(r.at, log);
  }
  return e;
}

Scale resolve(const Axis& axis, Extent e, int max_ticks, double margin) {
  Scale s;
  s.log = axis.log;
  if (axis.lo) e.lo = *axis.lo;
  if (axis.hi) e.hi = *axis.hi;
  if (e.empty()) e = s.log ? Extent{1.0, 10.0} : Extent{0.0, 1.0};
  if (!s.log && axis.include_zero) {
    e.lo = std::min(e.lo, 0.0);
    e.hi = std::max(e.hi, 0.0);
  }
  if (!s.log && margin > 0.0) {  // data on the frame is hard to see: a little room at free ends
    const double room = margin * (e.hi - e.lo);
    if (!axis.lo && e.lo != 0.0) e.lo -= room;
    if (!axis.hi && e.hi != 0.0) e.hi += room;
  }
  if (s.log) {
    s.ticks = decade_ticks(e.lo, e.hi, max_ticks);
  } else {
    s.ticks = nice_ticks(e.lo, e.hi, max_ticks);
    if (s.ticks.size() >= 2) s.step = s.ticks[1] - s.ticks[0];
  }
  s.lo = axis.lo ? *axis.lo : s.ticks.front();
  s.hi = axis.hi ? *axis.hi : s.ticks.back();
  if (!(s.hi > s.lo)) s.hi = s.log ? s.lo * 10.0 : s.lo + 1.0;
  std::erase_if(s.ticks, [&](double v) { return v < s.lo - 1e-9 * (s.hi - s.lo) || v > s.hi + 1e-9 * (s.hi - s.lo); });
  return s;
}

std::string label_of(const Scale& s, double v) { return s.log ? decade_label(v) : tick_label(v, s.step); }

// Text rotated a quarter turn anticlockwise, its left end at the bottom, centred on `centre`.
void put_vertical_text(cv::Mat& image, const std::string& text, cv::Point centre) {
  const cv::Size size = text_size(text, kLabelScale);
  cv::Mat strip(size.height + 8, size.width + 4, CV_8UC3, kPaper);
  put_text(strip, text, cv::Point(2, size.height + 2), kLabelScale, kInk);
  cv::Mat turned;
  cv::rotate(strip, turned, cv::ROTATE_90_COUNTERCLOCKWISE);
  cv::Rect r(centre.x - turned.cols / 2, centre.y - turned.rows / 2, turned.cols, turned.rows);
  r &= cv::Rect(0, 0, image.cols, image.rows);
  if (r.area() <= 0) return;
  cv::Mat target = image(r);
  cv::min(target, turned(cv::Rect(0, 0, r.width, r.height)), target);
}

// Consecutive drawable points as runs (a non-finite point breaks a line).
std::vector<std::vector<cv::Point2d>> runs(const Series& s, const Scale& sx, const Scale& sy, cv::Size area,
                                           const std::vector<double>& ys) {
  std::vector<std::vector<cv::Point2d>> out(1);
  for (std::size_t i = 0; i < s.x.size() && i < ys.size(); ++i) {
    if (!sx.drawable(s.x[i]) || !sy.drawable(ys[i])) {
      if (!out.back().empty()) out.emplace_back();
      continue;
    }
    out.back().emplace_back(sx.fraction(s.x[i]) * area.width, (1.0 - sy.fraction(ys[i])) * area.height);
  }
  if (out.back().empty()) out.pop_back();
  return out;
}

cv::Scalar tint(const cv::Scalar& c, double t) {
  return {c[0] + (255.0 - c[0]) * t, c[1] + (255.0 - c[1]) * t, c[2] + (255.0 - c[2]) * t};
}

void draw_series(cv::Mat& area, const Series& s, const Scale& sx, const Scale& sy) {
  const bool has_interval =
      s.interval != IntervalStyle::kNone && s.y_low.size() == s.y.size() && s.y_high.size() == s.y.size();
  if (has_interval && s.interval == IntervalStyle::kBand) {
    const auto low = runs(s, sx, sy, area.size(), s.y_low), high = runs(s, sx, sy, area.size(), s.y_high);
    cv::Mat overlay = area.clone();
    for (std::size_t r = 0; r < low.size() && r < high.size(); ++r) {
      std::vector<cv::Point> poly;
      for (const cv::Point2d& p : low[r]) poly.emplace_back(cvRound(p.x), cvRound(p.y));
      for (auto it = high[r].rbegin(); it != high[r].rend(); ++it) poly.emplace_back(cvRound(it->x), cvRound(it->y));
      if (poly.size() >= 3)
        cv::fillPoly(overlay, std::vector<std::vector<cv::Point>>{poly}, tint(s.colour, 0.55), cv::LINE_AA);
    }
    cv::addWeighted(overlay, 0.45, area, 0.55, 0.0, area);
  }
  if (has_interval && s.interval == IntervalStyle::kErrorBars) {
    for (std::size_t i = 0; i < s.x.size(); ++i) {
      if (!sx.drawable(s.x[i]) || !sy.drawable(s.y_low[i]) || !sy.drawable(s.y_high[i])) continue;
      const double u = sx.fraction(s.x[i]) * area.cols;
      const double v0 = (1.0 - sy.fraction(s.y_low[i])) * area.rows, v1 = (1.0 - sy.fraction(s.y_high[i])) * area.rows;
      const std::vector<cv::Point2d> bar{{u, v0}, {u, v1}}, cap0{{u - 3, v0}, {u + 3, v0}},
          cap1{{u - 3, v1}, {u + 3, v1}};
      for (const auto* l : {&bar, &cap0, &cap1}) draw_polyline(area, *l, s.colour, 1, LineStyle::kSolid);
    }
  }
  for (const auto& run : runs(s, sx, sy, area.size(), s.y)) {
    draw_polyline(area, run, s.colour, s.thickness_px, s.line);
    for (const cv::Point2d& p : run) draw_marker(area, p, s.marker, s.colour, 9);
  }
}

void draw_panel(cv::Mat& image, cv::Rect cell, const Panel& p, const Scale& sx, const Scale& sy) {
  int label_width = 0;
  for (double v : sy.ticks) label_width = std::max(label_width, text_size(label_of(sy, v), kTickScale).width);
  const int top = p.title.empty() ? 12 : 30, left = label_width + 40, bottom = 50, right = 22;
  const cv::Rect plot(cell.x + left, cell.y + top, std::max(10, cell.width - left - right),
                      std::max(10, cell.height - top - bottom));
  if (!p.title.empty()) put_text(image, p.title, cv::Point(plot.x, cell.y + 20), kLabelScale, kInk);
  const auto u_of = [&](double v) { return plot.x + static_cast<int>(std::lround(sx.fraction(v) * plot.width)); };
  const auto v_of = [&](double v) {
    return plot.y + static_cast<int>(std::lround((1.0 - sy.fraction(v)) * plot.height));
  };
  for (double v : sx.ticks) {
    const int u = u_of(v);
    cv::line(image, {u, plot.y}, {u, plot.br().y}, kGrid, 1);
    cv::line(image, {u, plot.br().y}, {u, plot.br().y + 5}, kAxisFrame, 1);
    const std::string text = label_of(sx, v);
    put_text(image, text, cv::Point(u - text_size(text, kTickScale).width / 2, plot.br().y + 20), kTickScale, kInk);
  }
  for (double v : sy.ticks) {
    const int w = v_of(v);
    cv::line(image, {plot.x, w}, {plot.br().x, w}, kGrid, 1);
    cv::line(image, {plot.x - 5, w}, {plot.x, w}, kAxisFrame, 1);
    const std::string text = label_of(sy, v);
    const cv::Size size = text_size(text, kTickScale);
    put_text(image, text, cv::Point(plot.x - 8 - size.width, w + size.height / 2), kTickScale, kInk);
  }
  cv::Mat area = image(plot);
  for (const ReferenceLine& r : p.references) {
    const Scale& s = r.vertical ? sx : sy;
    if (!s.drawable(r.at)) continue;
    const double f = s.fraction(r.at);
    const std::vector<cv::Point2d> line =
        r.vertical
            ? std::vector<cv::Point2d>{{f * plot.width, 0.0}, {f * plot.width, double(plot.height)}}
            : std::vector<cv::Point2d>{{0.0, (1 - f) * plot.height}, {double(plot.width), (1 - f) * plot.height}};
    draw_polyline(area, line, r.colour, 1, r.line);
  }
  for (const Series& s : p.series) draw_series(area, s, sx, sy);
  cv::rectangle(image, plot, kAxisFrame, 1);
  const cv::Size xl = text_size(p.x.label, kLabelScale);
  put_text(image, p.x.label, cv::Point(plot.x + (plot.width - xl.width) / 2, plot.br().y + 42), kLabelScale, kInk);
  put_vertical_text(image, p.y.label, cv::Point(cell.x + 14, plot.y + plot.height / 2));
}

// The legend as one framed strip `width` wide, entries flowing left to right.
cv::Mat legend_strip(const std::vector<LegendEntry>& entries, int width) {
  if (entries.empty()) return {};
  constexpr int kStripPad = 6, kEntryGap = 22;
  std::vector<cv::Point> at;
  int x = 0, y = 0, used = 0;
  for (const LegendEntry& e : entries) {
    const int w = legend_row_width(e);
    if (x > 0 && x + w > width - 2 * kStripPad - 20) {
      x = 0;
      y += kLegendRow_px;
    }
    at.emplace_back(x, y);
    x += w + kEntryGap;
    used = std::max(used, x - kEntryGap);
  }
  const cv::Rect frame(10, 2, used + 2 * kStripPad, y + kLegendRow_px + 2 * kStripPad - 4);
  cv::Mat strip(frame.br().y + 4, std::max(width, frame.br().x + 2), CV_8UC3, kPaper);
  cv::rectangle(strip, frame, cv::Scalar(120, 120, 120), 1);
  for (std::size_t i = 0; i < entries.size(); ++i)
    draw_legend_row(strip, entries[i], frame.tl() + cv::Point(kStripPad, kStripPad) + at[i]);
  return strip;
}

}  // namespace

std::vector<LegendEntry> legend_entries(const Figure& figure) {
  std::vector<LegendEntry> out;
  const auto add = [&](const LegendEntry& e) {
    if (e.label.empty()) return;
    for (const LegendEntry& o : out) {
      if (o.label == e.label) return;
    }
    out.push_back(e);
  };
  for (const Panel& p : figure.panels) {
    for (const ReferenceLine& r : p.references) add({r.label, r.colour, Marker::kNone, r.line, false});
    for (const Series& s : p.series) {
      add({s.label, s.colour, s.marker, s.line, s.interval == IntervalStyle::kBand});
    }
  }
  return out;
}

cv::Mat render(const Figure& figure) {
  if (figure.panels.empty()) throw std::invalid_argument("plot::render: a figure needs at least one panel");
  for (const Panel& p : figure.panels) {
    for (const Series& s : p.series) {
      const bool interval_ok =
          (s.y_low.empty() || s.y_low.size() == s.y.size()) && (s.y_high.empty() || s.y_high.size() == s.y.size());
      if (s.x.size() != s.y.size() || !interval_ok) {
        throw std::invalid_argument("plot::render: series '" + s.label +
                                    "' has x, y and interval of different lengths");
      }
    }
  }
  const int columns = std::max(1, figure.columns);
  const int n = static_cast<int>(figure.panels.size()), rows = (n + columns - 1) / columns;
  Extent shared_x, shared_y;
  for (const Panel& p : figure.panels) {
    shared_x.add(data_extent(p, true));
    shared_y.add(data_extent(p, false));
  }
  cv::Mat grid(rows * figure.panel_size.height, columns * figure.panel_size.width, CV_8UC3, kPaper);
  for (int i = 0; i < n; ++i) {
    const Panel& p = figure.panels[static_cast<std::size_t>(i)];
    const Scale sx = resolve(p.x, figure.share_x ? shared_x : data_extent(p, true), figure.max_ticks, 0.0);
    const Scale sy = resolve(p.y, figure.share_y ? shared_y : data_extent(p, false), figure.max_ticks, 0.03);
    const cv::Rect cell(cv::Point((i % columns) * figure.panel_size.width, (i / columns) * figure.panel_size.height),
                        figure.panel_size);
    draw_panel(grid, cell, p, sx, sy);
  }
  const cv::Mat legend = legend_strip(legend_entries(figure), grid.cols);
  const std::vector<cv::Mat> parts{legend, grid};
  return with_title(place(parts, false, 4), figure.title, figure.notes);
}

}  // namespace pinball::plot
