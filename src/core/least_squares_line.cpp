#include "pinball/core/least_squares_line.h"

#include <stdexcept>

namespace pinball {

std::vector<double> slope_weights(const std::vector<std::pair<double, double>>& xy) {
  if (xy.size() < 2) throw std::invalid_argument("fit_line: need two points");
  double mean_x = 0.0;
  for (const auto& p : xy) mean_x += p.first;
  mean_x /= static_cast<double>(xy.size());
  double sxx = 0.0;
  for (const auto& p : xy) sxx += (p.first - mean_x) * (p.first - mean_x);
  std::vector<double> w(xy.size(), 0.0);
  if (sxx == 0.0) return w;
  for (std::size_t i = 0; i < xy.size(); ++i) w[i] = (xy[i].first - mean_x) / sxx;
  return w;
}

LineFit fit_line(const std::vector<std::pair<double, double>>& xy) {
  const std::vector<double> w = slope_weights(xy);
  double mean_x = 0.0, mean_y = 0.0;
  for (const auto& p : xy) {
    mean_x += p.first;
    mean_y += p.second;
  }
  const double n = static_cast<double>(xy.size());
  mean_x /= n;
  mean_y /= n;
  LineFit f;
  for (std::size_t i = 0; i < xy.size(); ++i) f.slope += w[i] * xy[i].second;
  f.intercept = mean_y - f.slope * mean_x;
  return f;
}

}  // namespace pinball
