#include "pinball/core/least_squares_line.h"

#include <cmath>
#include <stdexcept>

#include <gtest/gtest.h>

namespace pinball {
namespace {

TEST(LeastSquaresLine, RecoversALineAndItsWeightsGiveTheSlope) {
  const std::vector<std::pair<double, double>> xy{{0, 5}, {1, 3}, {3, -1}, {5, -5}};
  const LineFit f = fit_line(xy);
  EXPECT_NEAR(f.slope, -2.0, 1e-12);
  EXPECT_NEAR(f.intercept, 5.0, 1e-12);
  const std::vector<double> w = slope_weights(xy);
  double slope = 0.0, sum = 0.0;
  for (std::size_t i = 0; i < xy.size(); ++i) {
    slope += w[i] * xy[i].second;
    sum += w[i];
  }
  EXPECT_NEAR(slope, -2.0, 1e-12);
  EXPECT_NEAR(sum, 0.0, 1e-12) << "a constant added to every y leaves the slope alone";
}

TEST(LeastSquaresLine, NoisyPointsGiveTheBestSlopeAndSameXGivesNone) {
  // Σ(x − x̄)(y − ȳ) / Σ(x − x̄)² = 3 / 5, not the slope through the ends (1/3).
  const LineFit f = fit_line({{0, 1}, {1, 0}, {2, 3}, {3, 2}});
  EXPECT_NEAR(f.slope, 0.6, 1e-12);
  EXPECT_NEAR(f.intercept, 1.5 - 0.6 * 1.5, 1e-12);
  EXPECT_EQ(fit_line({{2, 1}, {2, 5}}).slope, 0.0);
  EXPECT_THROW(fit_line({{1, 1}}), std::invalid_argument);
}

TEST(LeastSquaresLine, TrimmedFitGivesStandardErrorsAndLeavesOutOneWildPoint) {
  // y = 0.2 + 0.5 x with alternating ±0.01: residual σ² = 0.0001·n/(n−2), σ_slope = σ/√Sxx.
  std::vector<std::pair<double, double>> xy;
  for (int i = 0; i < 10; ++i) xy.emplace_back(i, 0.2 + 0.5 * i + (i % 2 == 0 ? 0.01 : -0.01));
  const TrimmedLineFit clean = fit_line_trimmed(xy, false);
  EXPECT_NEAR(clean.line.slope, 0.5, 0.003);
  EXPECT_NEAR(clean.line.intercept, 0.2, 0.02);
  const double sigma = std::sqrt(rms_residual(xy, clean.line) * rms_residual(xy, clean.line) * 10.0 / 8.0);
  EXPECT_NEAR(clean.slope_stderr, sigma / std::sqrt(82.5), 1e-12) << "Sxx of 0..9 is 82.5";
  EXPECT_EQ(clean.outliers, 0);
  EXPECT_EQ(clean.used, 10);

  xy.emplace_back(4.5, 40.0);
  const TrimmedLineFit trimmed = fit_line_trimmed(xy, false);
  EXPECT_EQ(trimmed.outliers, 1);
  EXPECT_EQ(trimmed.used, 10);
  EXPECT_NEAR(trimmed.line.slope, 0.5, 0.003);

  const TrimmedLineFit origin = fit_line_trimmed({{1, 2.0}, {2, 4.1}, {3, 5.9}}, true);
  EXPECT_EQ(origin.line.intercept, 0.0);
  EXPECT_NEAR(origin.line.slope, (2.0 + 8.2 + 17.7) / 14.0, 1e-12);
  EXPECT_EQ(origin.intercept_stderr, 0.0);

  EXPECT_THROW(fit_line_trimmed({{1, 1}, {2, 2}}, false), std::invalid_argument) << "a line needs three points";
  EXPECT_THROW(fit_line_trimmed({{2, 1}, {2, 2}, {2, 3}}, false), std::invalid_argument);
  EXPECT_THROW(fit_line_trimmed({{0, 1}, {0, 2}}, true), std::invalid_argument);
}

}  // namespace
}  // namespace pinball
