#include "pinball/learn/statistics.h"

#include <cmath>
#include <limits>

namespace pinball::learn {

double hoeffding_half_width(std::int64_t n, double range_b, double confidence) {
  if (n < 1 || !std::isfinite(range_b)) return std::numeric_limits<double>::infinity();
  const double b = std::abs(range_b);
  return std::sqrt(b * b / (2.0 * static_cast<double>(n)) * std::log(2.0 / (1.0 - confidence)));
}

double thesis_range_bound(const RunningStats& stats) { return std::abs(stats.mean()) + 2.0 * stats.stddev(); }

Interval hoeffding_interval(const RunningStats& stats, double confidence) {
  constexpr double kInf = std::numeric_limits<double>::infinity();
  if (stats.count() < 2) return {-kInf, kInf};
  const double t = hoeffding_half_width(stats.count(), thesis_range_bound(stats), confidence);
  return {stats.mean() - t, stats.mean() + t};
}

void ThesisIncrementalStats::add(double x) {
  ++n_;
  const double n = static_cast<double>(n_);
  const double m_prev = m_;
  m_ = (n - 1.0) / n * m_prev + x / n;  // A.5
  if (n_ == 1) {
    x1_ = x;
    var_ = 0.0;
    return;
  }
  if (n_ == 2) {
    alpha_ = x1_ * x1_ + x * x;  // A.12
  } else {
    alpha_ = ((n - 2.0) * alpha_ + x * x) / (n - 1.0);  // A.11
  }
  // A.7 with β_n = 2 m_n Σx / (n − 1) = 2 n m_n² / (n − 1): σ² = α − β + n m² / (n − 1).
  // (A.16 as printed adds the β terms; the derivation subtracts them.)
  var_ = alpha_ - 2.0 * m_ * m_prev - 2.0 * m_ * x / (n - 1.0) + n * m_ * m_ / (n - 1.0);
}

}  // namespace pinball::learn
