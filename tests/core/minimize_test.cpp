#include "pinball/core/minimize.h"

#include <gtest/gtest.h>

#include <cmath>

namespace pinball {
namespace {

TEST(MinimizeOnInterval, FindsAParabolasVertexToTheSectionsPrecision) {
  const double x = minimize_on_interval([](double v) { return (v - 0.3137) * (v - 0.3137); }, 0.0, 1.0, 10, 40);
  EXPECT_NEAR(x, 0.3137, 1e-7);
}

TEST(MinimizeOnInterval, AMinimumAtTheBoundStaysInTheInterval) {
  EXPECT_NEAR(minimize_on_interval([](double v) { return v; }, 0.0, 2.0, 8, 30), 0.0, 1e-6);
  EXPECT_GE(minimize_on_interval([](double v) { return v; }, 0.0, 2.0, 8, 30), 0.0);
  EXPECT_NEAR(minimize_on_interval([](double v) { return -v; }, -1.0, 3.0, 8, 30), 3.0, 1e-6);
}

TEST(MinimizeOnInterval, AKinkOrASecondDipDoesNotTrapIt) {
  // |x - 0.71| has no derivative at its minimum.
  EXPECT_NEAR(minimize_on_interval([](double v) { return std::abs(v - 0.71); }, 0.0, 1.0, 16, 40), 0.71, 1e-7);
  // A shallow dip at 0.2 and the deeper one at 0.8: the grid sees both.
  const auto two_dips = [](double v) {
    return std::min(0.5 + (v - 0.2) * (v - 0.2), (v - 0.8) * (v - 0.8));
  };
  EXPECT_NEAR(minimize_on_interval(two_dips, 0.0, 1.0, 16, 40), 0.8, 1e-7);
}

TEST(MinimizeOnInterval, WithoutSectionsItIsTheGridsBestPoint) {
  EXPECT_DOUBLE_EQ(minimize_on_interval([](double v) { return std::abs(v - 0.26); }, 0.0, 1.0, 4, 0), 0.25);
}

}  // namespace
}  // namespace pinball
