// The transfer bench's figure: each controller's score ratio to the spastic
// flipper against each perturbation, one panel per family, the `model` world
// as every family's nominal point (the report: transfer_bench_report.cpp).
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <map>
#include <stdexcept>

#include <opencv2/imgproc.hpp>

#include "pinball/sim/renderer.h"
#include "transfer_bench.h"

namespace pinball::bench {
namespace {

constexpr int kPanelW = 400, kPanelH = 300, kCols = 4, kLeft = 56, kRight = 18, kTop = 34, kBottom = 46;
constexpr int kHeader = 56;

// One curve: (value, ratio) points of a controller in a family, by value.
using Curve = std::map<double, double>;

std::string short_number(double v) {
  char buf[32];
  std::snprintf(buf, sizeof(buf), "%g", v);
  return buf;
}

}  // namespace

void plot_transfer_png(const TransferReport& report, const std::string& path) {
  const TransferWorld* model = nullptr;
  for (const TransferWorld& w : report.worlds) {
    if (w.name == "model" && w.played) model = &w;
  }
  if (model == nullptr) throw std::runtime_error(path + ": no model world to plot against");
  std::vector<std::string> names;  // the controllers drawn: all but the baseline, whose ratio is 1
  for (const TransferCell& c : model->cells) {
    if (c.controller != "spastic") names.push_back(c.controller);
  }
  // curves[family][controller]
  std::vector<std::pair<Perturbation, std::map<std::string, Curve>>> panels;
  double y_lo = 1.0, y_hi = 1.0;
  for (const SweepFamily& f : report.options.sweep) {
    std::map<std::string, Curve> curves;
    const std::string family(perturbation_name(f.kind));
    for (const TransferCell& c : model->cells) curves[c.controller][nominal_value(f.kind, report.options)] = c.ratio_to_spastic;
    for (const TransferWorld& w : report.worlds) {
      if (!w.played || w.family != family) continue;
      for (const TransferCell& c : w.cells) curves[c.controller][w.value] = c.ratio_to_spastic;
    }
    for (const auto& [name, curve] : curves) {
      for (const auto& [x, y] : curve) {
        y_lo = std::min(y_lo, y);
        y_hi = std::max(y_hi, y);
      }
    }
    panels.emplace_back(f.kind, std::move(curves));
  }
  if (panels.empty()) throw std::runtime_error(path + ": no sweep to plot");
  // Tenths around the data, shared by every panel so that panels compare.
  y_lo = std::floor(y_lo * 10.0 - 1.0) / 10.0;
  y_hi = std::ceil(y_hi * 10.0 + 1.0) / 10.0;
  const int rows = (static_cast<int>(panels.size()) + kCols - 1) / kCols;
  cv::Mat img(kHeader + rows * kPanelH, kCols * kPanelW, CV_8UC3, cv::Scalar(255, 255, 255));
  const cv::Scalar black(0, 0, 0), grey(215, 215, 215), baseline(140, 140, 140);
  const std::array<cv::Scalar, 6> colours{cv::Scalar(200, 90, 0), cv::Scalar(0, 0, 210), cv::Scalar(0, 150, 0),
                                          cv::Scalar(160, 0, 160), cv::Scalar(0, 140, 220), cv::Scalar(120, 80, 40)};
  const auto font = cv::FONT_HERSHEY_SIMPLEX;
  char title[256];
  std::snprintf(title, sizeof(title),
                "score ratio to the spastic flipper in the same world, %d balls per cell (seed %llu), cut at %g s; "
                "belief: the nominal board; triangle: the nominal world (model)",
                report.options.balls, static_cast<unsigned long long>(report.options.seed),
                report.options.max_ball_time_s);
  cv::putText(img, title, cv::Point(10, 20), font, 0.5, black, 1, cv::LINE_AA);
  // Legend: one swatch per controller, and the baseline.
  int lx = 10;
  for (std::size_t k = 0; k <= names.size(); ++k) {
    const bool base = k == names.size();
    const cv::Scalar colour = base ? baseline : colours[k % colours.size()];
    cv::line(img, cv::Point(lx, 40), cv::Point(lx + 24, 40), colour, 2, cv::LINE_AA);
    const std::string label = base ? "spastic (= 1)" : names[k];
    cv::putText(img, label, cv::Point(lx + 30, 45), font, 0.45, black, 1, cv::LINE_AA);
    lx += 50 + 9 * static_cast<int>(label.size());
  }
  for (std::size_t p = 0; p < panels.size(); ++p) {
    const auto& [kind, curves] = panels[p];
    const int ox = static_cast<int>(p % kCols) * kPanelW;
    const int oy = kHeader + static_cast<int>(p / kCols) * kPanelH;
    const int w = kPanelW - kLeft - kRight, h = kPanelH - kTop - kBottom;
    double x_lo = 1e300, x_hi = -1e300;
    for (const auto& [name, curve] : curves) {
      x_lo = std::min(x_lo, curve.begin()->first);
      x_hi = std::max(x_hi, curve.rbegin()->first);
    }
    if (x_hi <= x_lo) x_hi = x_lo + 1.0;
    const double pad = 0.06 * (x_hi - x_lo);
    const double x0 = x_lo - pad, x1 = x_hi + pad;
    auto to_px = [&](double x, double y) {
      return cv::Point(ox + kLeft + static_cast<int>(w * (x - x0) / (x1 - x0)),
                       oy + kTop + h - static_cast<int>(h * (y - y_lo) / (y_hi - y_lo)));
    };
    // Grid: the family's values across, ratios up.
    for (const auto& [x, y] : curves.begin()->second) {
      cv::line(img, to_px(x, y_lo), to_px(x, y_hi), grey, 1);
      cv::putText(img, short_number(x), to_px(x, y_lo) + cv::Point(-10, 16), font, 0.38, black, 1, cv::LINE_AA);
    }
    const double y_step = y_hi - y_lo > 2.0 ? 0.5 : 0.2;
    for (double y = std::ceil(y_lo / y_step) * y_step; y <= y_hi + 1e-9; y += y_step) {
      cv::line(img, to_px(x0, y), to_px(x1, y), grey, 1);
      cv::putText(img, short_number(std::round(y * 100.0) / 100.0), to_px(x0, y) + cv::Point(-34, 4), font, 0.38,
                  black, 1, cv::LINE_AA);
    }
    cv::rectangle(img, to_px(x0, y_hi), to_px(x1, y_lo), black, 1);
    cv::line(img, to_px(x0, 1.0), to_px(x1, 1.0), baseline, 2, cv::LINE_AA);
    cv::putText(img, "ratio to spastic", cv::Point(ox + 8, oy + kTop - 10), font, 0.42, black, 1, cv::LINE_AA);
    cv::putText(img, std::string(perturbation_label(kind)), cv::Point(ox + kLeft + 10, oy + kPanelH - 10), font, 0.42,
                black, 1, cv::LINE_AA);
    for (std::size_t k = 0; k < names.size(); ++k) {
      const auto it = curves.find(names[k]);
      if (it == curves.end()) continue;
      std::vector<cv::Point> pts;
      for (const auto& [x, y] : it->second) pts.push_back(to_px(x, y));
      const cv::Scalar colour = colours[k % colours.size()];
      if (pts.size() >= 2) cv::polylines(img, pts, false, colour, 2, cv::LINE_AA);
      for (const cv::Point& q : pts) cv::circle(img, q, 3, colour, cv::FILLED, cv::LINE_AA);
    }
    // The nominal point (the model world): a triangle on the axis.
    const cv::Point n = to_px(nominal_value(kind, report.options), y_lo);
    const std::vector<cv::Point> triangle{n, n + cv::Point(-6, -10), n + cv::Point(6, -10)};
    cv::fillConvexPoly(img, triangle, baseline, cv::LINE_AA);
  }
  sim::write_png(img, path);
}

}  // namespace pinball::bench
