#pragma once
// The project's one rule for a quantile and its one interval for a mean:
// every p50 and p99 (benches, latency histograms, detector errors) is the
// nearest-rank quantile below, and every 95 % interval of a mean uses
// Student's t, which a handful of balls needs (1.96 is 6.5x too narrow for 2).
// A share (k of n) gets Wilson's interval, which stays inside [0, 1] and
// does not collapse to a point at 0 or n as the normal one does.

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace pinball {

/// Rank (from 1) of the q-quantile among n sorted samples: the smallest k
/// with k >= q·n, at least 1 (nearest rank). q is clamped to [0, 1]; 0 for n = 0.
std::size_t quantile_rank(double q, std::size_t n);

/// The q-quantile of `values` by quantile_rank (0 for none). Takes its own
/// copy (benches and reports, not hot loops: a histogram uses quantile_rank).
template <class T>
double quantile(std::vector<T> values, double q) {
  if (values.empty()) return 0.0;
  const auto k = static_cast<std::ptrdiff_t>(quantile_rank(q, values.size()) - 1);
  std::nth_element(values.begin(), values.begin() + k, values.end());
  return static_cast<double>(values[static_cast<std::size_t>(k)]);
}

/// The median of `values`: the middle value, or the mean of the two middle
/// values for an even count (0 for none). Takes its own copy.
double median(std::vector<double> values);

/// A normal's σ estimated robustly from `values`: 1.4826 × their median
/// absolute deviation from their median (0 for none). Takes its own copy.
double robust_sigma(const std::vector<double>& values);

/// Two-sided 95 % critical value of Student's t with `dof` degrees of freedom:
/// 12.71 for 1, 2.23 for 10, 1.96 in the limit. Infinite for dof < 1.
double student_t95(std::int64_t dof);

/// A confidence interval [low, high].
struct Interval {
  double low = 0.0;   ///< lower end
  double high = 0.0;  ///< upper end
};

/// Wilson's 95 % score interval of the share `successes` / `trials`; [0, 1]
/// for no trials. Throws std::invalid_argument for successes outside [0, trials].
Interval wilson_ci95(std::int64_t successes, std::int64_t trials);

}  // namespace pinball
