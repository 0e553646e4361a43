#include "pinball/calibration/circle_fit.h"

#include <cmath>
#include <stdexcept>
#include <vector>

#include <gtest/gtest.h>

#include "pinball/core/rng.h"

namespace pinball::calibration {
namespace {

std::vector<Vec2> arc(const Vec2& c, double r, double a0, double a1, int n, double noise, std::uint64_t seed) {
  Rng rng(seed);
  std::vector<Vec2> p;
  for (int k = 0; k < n; ++k) {
    const double a = a0 + (a1 - a0) * k / (n - 1);
    p.push_back(c + r * Vec2{std::cos(a), std::sin(a)} + noise * Vec2{rng.normal(), rng.normal()});
  }
  return p;
}

TEST(CircleFit, ExactPointsOnAShortArc) {
  const std::vector<Vec2> p = arc({0.165, 0.16}, 0.078, -0.43, 0.53, 40, 0.0, 1);
  for (const CircleFit& f : {fit_circle_algebraic(p), fit_circle(p)}) {
    EXPECT_NEAR(f.centre.x(), 0.165, 1e-9);
    EXPECT_NEAR(f.centre.y(), 0.16, 1e-9);
    EXPECT_NEAR(f.radius, 0.078, 1e-9);
    EXPECT_LT(f.rms, 1e-9);
  }
}

TEST(CircleFit, NoisyArcWithinAFractionOfAMillimetre) {
  // 0.3 mm noise on 600 points over 55 degrees, as a tip tracked through a sweep.
  const std::vector<Vec2> p = arc({0.3, 0.2}, 0.078, 2.0, 2.96, 600, 0.0003, 3);
  const CircleFit f = fit_circle(p);
  EXPECT_LT((f.centre - Vec2{0.3, 0.2}).norm(), 0.0008);
  EXPECT_NEAR(f.radius, 0.078, 0.0008);
  EXPECT_NEAR(f.rms, 0.0003 * std::sqrt(2.0) / std::sqrt(2.0), 0.0001);
}

TEST(CircleFit, OutliersAreTrimmed) {
  std::vector<Vec2> p = arc({0.0, 0.0}, 1.0, 0.0, 1.5, 200, 0.001, 5);
  for (int k = 0; k < 10; ++k) p[static_cast<std::size_t>(k * 17)] *= 1.2;  // 10 wild points
  const CircleFit f = fit_circle(p);
  EXPECT_GE(f.rejected, 10);
  EXPECT_LT(f.centre.norm(), 0.01);
  EXPECT_NEAR(f.radius, 1.0, 0.01);
}

TEST(CircleFit, DegenerateInputThrows) {
  EXPECT_THROW(fit_circle(std::vector<Vec2>{{0, 0}, {1, 1}}), std::invalid_argument);
  EXPECT_THROW(fit_circle(std::vector<Vec2>{{0, 0}, {1, 1}, {2, 2}, {3, 3}}), std::invalid_argument);
}

}  // namespace
}  // namespace pinball::calibration
