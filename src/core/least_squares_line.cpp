#include "pinball/core/least_squares_line.h"

#include <cmath>
#include <stdexcept>
#include <string>

#include "pinball/core/statistics.h"

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

namespace {

constexpr double kMadToSigma = 1.4826;  // a normal's σ over its median absolute deviation

TrimmedLineFit fit_with_errors(const std::vector<std::pair<double, double>>& xy, bool through_origin) {
  const std::size_t needed = through_origin ? 2 : 3;
  if (xy.size() < needed)
    throw std::invalid_argument("fit_line_trimmed: need " + std::to_string(needed) + " points");
  const double n = static_cast<double>(xy.size());
  double sx = 0, sy = 0, sxx = 0, sxy = 0;
  for (const auto& [x, y] : xy) sx += x, sy += y, sxx += x * x, sxy += x * y;
  const double sxx_about = through_origin ? sxx : sxx - sx * sx / n;  // spread of x the slope rests on
  if (!(sxx_about > 0.0)) throw std::invalid_argument("fit_line_trimmed: every x is the same");
  TrimmedLineFit f;
  f.line.slope = through_origin ? sxy / sxx : (sxy - sx * sy / n) / sxx_about;
  f.line.intercept = through_origin ? 0.0 : (sy - f.line.slope * sx) / n;
  const double rms = rms_residual(xy, f.line);
  const double s2 = rms * rms * n / (n - (through_origin ? 1.0 : 2.0));
  f.slope_stderr = std::sqrt(s2 / sxx_about);
  if (!through_origin) f.intercept_stderr = std::sqrt(s2 * (1.0 / n + (sx / n) * (sx / n) / sxx_about));
  f.used = static_cast<int>(xy.size());
  return f;
}

}  // namespace

TrimmedLineFit fit_line_trimmed(const std::vector<std::pair<double, double>>& xy, bool through_origin,
                                double trim_sigmas) {
  const TrimmedLineFit first = fit_with_errors(xy, through_origin);
  std::vector<double> abs_residuals;
  for (const auto& [x, y] : xy) abs_residuals.push_back(std::abs(y - first.line.intercept - first.line.slope * x));
  const double robust_sigma = kMadToSigma * median(abs_residuals);
  std::vector<std::pair<double, double>> kept;
  for (std::size_t i = 0; i < xy.size(); ++i)
    if (robust_sigma <= 0.0 || abs_residuals[i] <= trim_sigmas * robust_sigma) kept.push_back(xy[i]);
  if (kept.size() == xy.size() || kept.size() < (through_origin ? 2u : 3u)) return first;
  TrimmedLineFit second;
  try {
    second = fit_with_errors(kept, through_origin);
  } catch (const std::invalid_argument&) {
    return first;  // the points kept all share one x: the untrimmed fit stands
  }
  second.outliers = static_cast<int>(xy.size() - kept.size());
  return second;
}

double rms_residual(const std::vector<std::pair<double, double>>& xy, const LineFit& line) {
  double ss = 0.0;
  for (const auto& [x, y] : xy) ss += std::pow(y - line.intercept - line.slope * x, 2);
  return xy.empty() ? 0.0 : std::sqrt(ss / static_cast<double>(xy.size()));
}

}  // namespace pinball
