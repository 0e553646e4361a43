#include "pinball/sim/polynomial_roots.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "pinball/core/rng.h"

namespace pinball::sim {
namespace {

// Coefficients (ascending) of the monic polynomial with the given roots.
std::vector<double> from_roots(const std::vector<double>& roots, double scale = 1.0) {
  std::vector<double> c{scale};
  for (const double x : roots) {
    std::vector<double> next(c.size() + 1, 0.0);
    for (std::size_t i = 0; i < c.size(); ++i) {
      next[i + 1] += c[i];
      next[i] -= x * c[i];
    }
    c = next;
  }
  return c;
}

TEST(QuadraticRoots, NoCancellationForTinyRoot) {
  // x² − 1e8·x + 1: the small root 1e-8 is lost to cancellation in the school formula.
  const QuadraticRoots q = quadratic_roots(1.0, -1e8, 1.0);
  ASSERT_EQ(q.count, 2);
  EXPECT_NEAR(q.t0, 1e-8, 1e-22);
  EXPECT_NEAR(q.t1, 1e8, 1e-6);
}

TEST(QuadraticRoots, DoubleRootDespiteRoundOff) {
  // (x − 0.1)² with coefficients rounded: the discriminant may come out
  // slightly negative; the answer is still the double root, once.
  const double a = 3.0, x0 = 0.1;
  const QuadraticRoots q = quadratic_roots(a, -2.0 * a * x0, a * x0 * x0);
  ASSERT_EQ(q.count, 1);
  EXPECT_NEAR(q.t0, x0, 1e-15);
  EXPECT_EQ(q.t0, q.t1);
  EXPECT_EQ(quadratic_roots(1.0, 0.0, 1.0).count, 0);
  EXPECT_EQ(quadratic_roots(0.0, 0.0, 1.0).count, 0);
  const QuadraticRoots lin = quadratic_roots(0.0, 2.0, -1.0);
  ASSERT_EQ(lin.count, 1);
  EXPECT_DOUBLE_EQ(lin.t0, 0.5);
}

TEST(RealRoots, QuarticWithFourSimpleRoots) {
  const std::vector<double> roots{-0.7, 0.01, 0.3, 2.5};
  const auto c = from_roots(roots, 0.25);
  double out[4];
  const int n = real_roots(c.data(), 4, -1.0, 3.0, 1e-14, out);
  ASSERT_EQ(n, 4);
  for (int i = 0; i < 4; ++i) EXPECT_NEAR(out[i], roots[i], 1e-12);
  // Only those in the interval.
  ASSERT_EQ(real_roots(c.data(), 4, 0.0, 1.0, 1e-14, out), 2);
  EXPECT_NEAR(out[0], 0.01, 1e-12);
  EXPECT_NEAR(out[1], 0.3, 1e-12);
}

TEST(RealRoots, TangentDoubleRootIsFound) {
  // (x − 0.4)²·(x + 1)·(x − 3): a graze at 0.4 between two simple roots.
  // Round-off may split it into two roots a hair apart, never lose it.
  const auto c = from_roots({0.4, 0.4, -1.0, 3.0});
  double out[4];
  const int n = real_roots(c.data(), 4, 0.0, 2.0, 1e-13, out);
  ASSERT_GE(n, 1);
  ASSERT_LE(n, 2);
  for (int i = 0; i < n; ++i) EXPECT_NEAR(out[i], 0.4, 1e-7);  // a double root is only determined to √eps
}

TEST(RealRoots, RandomQuarticsMatchTheirRoots) {
  Rng rng(7);
  for (int trial = 0; trial < 2000; ++trial) {
    std::vector<double> roots;
    for (int i = 0; i < 4; ++i) roots.push_back(rng.uniform(-1.0, 1.0));
    std::sort(roots.begin(), roots.end());
    bool separated = true;
    for (int i = 0; i + 1 < 4; ++i) separated = separated && roots[i + 1] - roots[i] > 1e-3;
    if (!separated) continue;
    const auto c = from_roots(roots, rng.uniform(0.1, 10.0));
    double out[4];
    ASSERT_EQ(real_roots(c.data(), 4, -1.5, 1.5, 1e-13, out), 4) << trial;
    for (int i = 0; i < 4; ++i) EXPECT_NEAR(out[i], roots[i], 1e-9) << trial;
  }
}

TEST(FirstCrossingDown, NeverAfterTheRootAndWithinTolerance) {
  // Positive at 0, first down-crossing at 0.2 (then up at 0.5, down at 0.9).
  const auto c = from_roots({0.2, 0.5, 0.9, 5.0});
  double t = -1.0;
  ASSERT_TRUE(first_crossing_down(c.data(), 4, 0.0, 2.0, 1e-12, t));
  EXPECT_LE(t, 0.2);
  EXPECT_GE(t, 0.2 - 1e-12);
  EXPECT_GT(poly_eval(c.data(), 4, t), 0.0);
  // Starting inside the negative stretch: the next down-crossing counts.
  ASSERT_TRUE(first_crossing_down(c.data(), 4, 0.3, 2.0, 1e-12, t));
  EXPECT_NEAR(t, 0.9, 1e-12);
  EXPECT_LE(t, 0.9);
  EXPECT_FALSE(first_crossing_down(c.data(), 4, 0.0, 0.19, 1e-12, t));
}

TEST(FirstCrossingDown, GrazeThatTouchesIsNotMissed) {
  // A quartic whose minimum dips 1e-13 below zero for a moment near 0.4:
  // the two roots are ~3e-7 apart, far closer than any fixed step would see.
  auto c = from_roots({0.4, 0.4, -1.0, -3.0});
  c[0] -= 1e-13;
  double t = -1.0;
  ASSERT_TRUE(first_crossing_down(c.data(), 4, 0.0, 1.0, 1e-15, t));
  EXPECT_NEAR(t, 0.4, 1e-6);
  EXPECT_GT(poly_eval(c.data(), 4, t), -1e-15);
  // Lifted 1e-13 above zero it is a miss.
  c[0] += 2e-13;
  EXPECT_FALSE(first_crossing_down(c.data(), 4, 0.0, 1.0, 1e-15, t));
}

TEST(FirstCrossingDown, QuadraticClosedForm) {
  // Ball falling onto a floor: gap 0.1 − ½·g·t² reaches 0 at sqrt(0.2/g).
  const double g = 9.81;
  const double c[3] = {0.1, 0.0, -0.5 * g};
  double t;
  ASSERT_TRUE(first_crossing_down(c, 2, 0.0, 1.0, 1e-12, t));
  EXPECT_NEAR(t, std::sqrt(0.2 / g), 1e-15);
  // Moving away first, then back (gravity): s = −0.01 + 1·t − ½ g t² from an overlap.
  const double up[3] = {-0.01, 1.0, -0.5 * g};
  ASSERT_TRUE(first_crossing_down(up, 2, 0.0, 1.0, 1e-12, t));
  const QuadraticRoots q = quadratic_roots(-0.5 * g, 1.0, -0.01);
  EXPECT_NEAR(t, q.t1, 1e-15);
  // Never in the past: a root at exactly lo is not a crossing after lo.
  const double at0[3] = {0.0, -1.0, 0.0};
  EXPECT_FALSE(first_crossing_down(at0, 2, 0.0, 1.0, 1e-12, t));
}

}  // namespace
}  // namespace pinball::sim
