#include "pinball/core/statistics.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <utility>

namespace pinball {

std::size_t quantile_rank(double q, std::size_t n) {
  if (n == 0) return 0;
  const double clamped = std::clamp(std::isnan(q) ? 0.0 : q, 0.0, 1.0);
  const auto k = static_cast<std::size_t>(std::ceil(clamped * static_cast<double>(n)));
  return std::clamp<std::size_t>(k, 1, n);
}

double student_t95(std::int64_t dof) {
  // Exact values to 6 decimals for small samples (the quantile 0.975 of t).
  static constexpr std::array<double, 30> kTable = {
      12.706205, 4.302653, 3.182446, 2.776445, 2.570582, 2.446912, 2.364624, 2.306004, 2.262157, 2.228139,
      2.200985,  2.178813, 2.160369, 2.144787, 2.131450, 2.119905, 2.109816, 2.100922, 2.093024, 2.085963,
      2.079614,  2.073873, 2.068658, 2.063899, 2.059539, 2.055529, 2.051831, 2.048407, 2.045230, 2.042272};
  if (dof < 1) return std::numeric_limits<double>::infinity();
  if (dof <= static_cast<std::int64_t>(kTable.size())) return kTable[static_cast<std::size_t>(dof - 1)];
  // Cornish-Fisher expansion around the normal quantile: within 1e-6 beyond 30 degrees of freedom.
  constexpr double z = 1.959963984540054;
  const double v = static_cast<double>(dof);
  const double z3 = z * z * z, z5 = z3 * z * z, z7 = z5 * z * z;
  return z + (z3 + z) / (4.0 * v) + (5.0 * z5 + 16.0 * z3 + 3.0 * z) / (96.0 * v * v) +
         (3.0 * z7 + 19.0 * z5 + 17.0 * z3 - 15.0 * z) / (384.0 * v * v * v);
}

double median(std::vector<double> values) {
  if (values.empty()) return 0.0;
  const auto mid = values.begin() + static_cast<std::ptrdiff_t>(values.size() / 2);
  std::nth_element(values.begin(), mid, values.end());
  if (values.size() % 2 == 1) return *mid;
  return 0.5 * (*mid + *std::max_element(values.begin(), mid));
}

double robust_sigma(const std::vector<double>& values) {
  constexpr double kMadToSigma = 1.4826;  // a normal's σ over its median absolute deviation
  const double middle = median(values);
  std::vector<double> deviation;
  deviation.reserve(values.size());
  for (const double x : values) deviation.push_back(std::abs(x - middle));
  return kMadToSigma * median(std::move(deviation));
}

Interval wilson_ci95(std::int64_t successes, std::int64_t trials) {
  if (successes < 0 || successes > trials) {
    throw std::invalid_argument("wilson_ci95: " + std::to_string(successes) + " successes of " +
                                std::to_string(trials) + " trials");
  }
  if (trials == 0) return {0.0, 1.0};
  constexpr double z = 1.959963984540054;
  const double n = static_cast<double>(trials);
  const double p = static_cast<double>(successes) / n;
  const double centre = (p + z * z / (2.0 * n)) / (1.0 + z * z / n);
  const double half = z / (1.0 + z * z / n) * std::sqrt(p * (1.0 - p) / n + z * z / (4.0 * n * n));
  return {std::max(0.0, centre - half), std::min(1.0, centre + half)};
}

}  // namespace pinball
