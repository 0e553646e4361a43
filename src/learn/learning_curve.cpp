#include "pinball/learn/learning_curve.h"

#include <algorithm>
#include <cstdio>
#include <fstream>
#include <stdexcept>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

namespace pinball::learn {

void write_curve_csv(const SearchResult& r, const std::string& path) {
  std::ofstream f(path);
  if (!f) throw std::runtime_error(path + ": cannot open for writing");
  f << "method,generation,balls,population_mean,generation_best,best_so_far,wall_s\n";
  for (const CurvePoint& p : r.curve) {
    f << r.method << ',' << p.generation << ',' << p.balls << ',' << p.population_mean << ',' << p.generation_best
      << ',' << p.best_so_far << ',' << p.wall_s << '\n';
  }
  if (!f) throw std::runtime_error(path + ": write failed");
}

void plot_curve_png(const SearchResult& r, const std::string& path) {
  constexpr int kW = 800, kH = 500, kLeft = 80, kRight = 20, kTop = 40, kBottom = 60;
  cv::Mat img(kH, kW, CV_8UC3, cv::Scalar(255, 255, 255));
  double x_max = 1.0, y_min = 0.0, y_max = 1.0;
  for (const CurvePoint& p : r.curve) {
    x_max = std::max(x_max, static_cast<double>(p.balls));
    for (double v : {p.population_mean, p.generation_best, p.best_so_far}) {
      y_min = std::min(y_min, v);
      y_max = std::max(y_max, v);
    }
  }
  y_max += 0.05 * (y_max - y_min);
  auto to_px = [&](double x, double y) {
    return cv::Point(kLeft + static_cast<int>((kW - kLeft - kRight) * x / x_max),
                     kH - kBottom - static_cast<int>((kH - kTop - kBottom) * (y - y_min) / (y_max - y_min)));
  };
  const cv::Scalar black(0, 0, 0), grey(200, 200, 200);
  cv::line(img, to_px(0, y_min), to_px(x_max, y_min), black, 1);
  cv::line(img, to_px(0, y_min), to_px(0, y_max), black, 1);
  char label[64];
  for (int i = 0; i <= 4; ++i) {
    const double y = y_min + (y_max - y_min) * i / 4.0;
    const double x = x_max * i / 4.0;
    cv::line(img, to_px(0, y), to_px(x_max, y), grey, 1);
    std::snprintf(label, sizeof(label), "%.0f", y);
    cv::putText(img, label, to_px(0, y) + cv::Point(-75, 5), cv::FONT_HERSHEY_SIMPLEX, 0.45, black, 1);
    std::snprintf(label, sizeof(label), "%.0f", x);
    cv::putText(img, label, to_px(x, y_min) + cv::Point(-15, 20), cv::FONT_HERSHEY_SIMPLEX, 0.45, black, 1);
  }
  cv::putText(img, "balls played", cv::Point(kW / 2 - 50, kH - 15), cv::FONT_HERSHEY_SIMPLEX, 0.5, black, 1);
  cv::putText(img, r.method + ": mean score per ball (green: best so far, blue: generation best, grey: population)",
              cv::Point(10, 22), cv::FONT_HERSHEY_SIMPLEX, 0.45, black, 1);
  auto series = [&](auto value, const cv::Scalar& colour) {
    std::vector<cv::Point> pts;
    for (const CurvePoint& p : r.curve) pts.push_back(to_px(static_cast<double>(p.balls), value(p)));
    if (pts.size() >= 2) cv::polylines(img, pts, false, colour, 2, cv::LINE_AA);
  };
  series([](const CurvePoint& p) { return p.population_mean; }, cv::Scalar(150, 150, 150));
  series([](const CurvePoint& p) { return p.generation_best; }, cv::Scalar(200, 80, 0));
  series([](const CurvePoint& p) { return p.best_so_far; }, cv::Scalar(0, 160, 0));
  if (!cv::imwrite(path, img)) throw std::runtime_error(path + ": cannot write PNG");
}

}  // namespace pinball::learn
