#include "pinball/core/least_squares_line.h"

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

}  // namespace
}  // namespace pinball
