#include "pinball/core/geometry.h"

#include <gtest/gtest.h>

#include <random>
#include <utility>
#include <vector>

#include <cmath>

namespace pinball {
namespace {

TEST(SolveQuadratic, TwoRootsInAscendingOrder) {
  // (t - 2)(t + 3) = t² + t - 6
  const QuadraticRoots r = solve_quadratic(1.0, 1.0, -6.0);
  ASSERT_EQ(r.count, 2);
  EXPECT_DOUBLE_EQ(r.t0, -3.0);
  EXPECT_DOUBLE_EQ(r.t1, 2.0);
  // Negative leading coefficient: same roots, still ascending.
  const QuadraticRoots s = solve_quadratic(-2.0, -2.0, 12.0);
  ASSERT_EQ(s.count, 2);
  EXPECT_DOUBLE_EQ(s.t0, -3.0);
  EXPECT_DOUBLE_EQ(s.t1, 2.0);
}

TEST(SolveQuadratic, ZeroLinearCoefficient) {
  // t² - 4 = 0: b = 0 must not lose a root.
  const QuadraticRoots r = solve_quadratic(1.0, 0.0, -4.0);
  ASSERT_EQ(r.count, 2);
  EXPECT_DOUBLE_EQ(r.t0, -2.0);
  EXPECT_DOUBLE_EQ(r.t1, 2.0);
  // t² - 2t = 0: c = 0, roots 0 and 2.
  const QuadraticRoots s = solve_quadratic(1.0, -2.0, 0.0);
  ASSERT_EQ(s.count, 2);
  EXPECT_DOUBLE_EQ(s.t0, 0.0);
  EXPECT_DOUBLE_EQ(s.t1, 2.0);
}

TEST(SolveQuadratic, DoubleRoot) {
  // (t - 1.5)² = t² - 3t + 2.25
  const QuadraticRoots r = solve_quadratic(1.0, -3.0, 2.25);
  ASSERT_EQ(r.count, 1);
  EXPECT_DOUBLE_EQ(r.t0, 1.5);
  EXPECT_DOUBLE_EQ(r.t1, 1.5);
}

TEST(SolveQuadratic, NoRealRoots) {
  EXPECT_EQ(solve_quadratic(1.0, 0.0, 1.0).count, 0);
  EXPECT_EQ(solve_quadratic(1.0, 1.0, 1.0).count, 0);
  EXPECT_EQ(solve_quadratic(-1.0, 0.0, -1e-12).count, 0);
}

TEST(SolveQuadratic, LinearWhenLeadingCoefficientIsZero) {
  const QuadraticRoots r = solve_quadratic(0.0, 2.0, -3.0);
  ASSERT_EQ(r.count, 1);
  EXPECT_DOUBLE_EQ(r.t0, 1.5);
  EXPECT_DOUBLE_EQ(r.t1, 1.5);
  EXPECT_EQ(solve_quadratic(0.0, 0.0, 1.0).count, 0);
  EXPECT_EQ(solve_quadratic(0.0, 0.0, 0.0).count, 0);
}

TEST(SolveQuadratic, NoCatastrophicCancellation) {
  // t² - 1e8 t + 1 = 0: roots 1e8 and 1/1e8 (to 1e-16 relative). The naive
  // formula (-b - sqrt(disc)) / 2a gets the small root wrong by ~50 %.
  const QuadraticRoots r = solve_quadratic(1.0, -1e8, 1.0);
  ASSERT_EQ(r.count, 2);
  const double small = 1.0 / (0.5 * (1e8 + std::sqrt(1e16 - 4.0)));  // c / q, exact to rounding
  EXPECT_NEAR(r.t0, 1e-8, 1e-15 * 1e-8);
  EXPECT_NEAR(r.t0, small, 1e-15 * small);
  EXPECT_NEAR(r.t1, 1e8, 1e-15 * 1e8);
  // Residual of the small root is at rounding level.
  EXPECT_LT(std::abs(r.t0 * r.t0 - 1e8 * r.t0 + 1.0), 1e-15);
  // Same with the signs mirrored: roots -1e8 and -1e-8.
  const QuadraticRoots m = solve_quadratic(1.0, 1e8, 1.0);
  ASSERT_EQ(m.count, 2);
  EXPECT_NEAR(m.t1, -1e-8, 1e-15 * 1e-8);
  EXPECT_NEAR(m.t0, -1e8, 1e-15 * 1e8);
}

TEST(Geometry, CrossAndPerp) {
  EXPECT_DOUBLE_EQ(cross(Vec2{1.0, 0.0}, Vec2{0.0, 1.0}), 1.0);
  EXPECT_DOUBLE_EQ(cross(Vec2{0.0, 1.0}, Vec2{1.0, 0.0}), -1.0);
  EXPECT_DOUBLE_EQ(cross(Vec2{2.0, 3.0}, Vec2{4.0, 6.0}), 0.0);
  EXPECT_EQ(perp_left(Vec2{1.0, 0.0}), Vec2(0.0, 1.0));
  EXPECT_EQ(perp_left(Vec2{3.0, -2.0}), Vec2(2.0, 3.0));
}

TEST(Geometry, ClosestParamOnSegment) {
  const Vec2 a{0.0, 0.0};
  const Vec2 b{2.0, 0.0};
  EXPECT_DOUBLE_EQ(closest_param_on_segment({0.5, 1.0}, a, b), 0.25);
  EXPECT_DOUBLE_EQ(closest_param_on_segment({-3.0, 1.0}, a, b), 0.0);
  EXPECT_DOUBLE_EQ(closest_param_on_segment({5.0, -1.0}, a, b), 1.0);
  EXPECT_DOUBLE_EQ(closest_param_on_segment({5.0, -1.0}, a, a), 0.0);  // degenerate
}

TEST(Geometry, DistancePointSegment) {
  const Vec2 a{1.0, 1.0};
  const Vec2 b{4.0, 5.0};  // length 5, direction (0.6, 0.8)
  // Perpendicular foot inside: distance is |cross| / length.
  const Vec2 p{1.0 + 0.6 * 2.5 - 0.8 * 0.3, 1.0 + 0.8 * 2.5 + 0.6 * 0.3};
  EXPECT_NEAR(distance_point_segment(p, a, b), 0.3, 1e-15);
  // Beyond the ends: distance to the end point.
  EXPECT_NEAR(distance_point_segment({-2.0, -3.0}, a, b), 5.0, 1e-15);
  EXPECT_NEAR(distance_point_segment({7.0, 9.0}, a, b), 5.0, 1e-15);
  EXPECT_DOUBLE_EQ(distance_point_segment(a, a, b), 0.0);
  // Degenerate segment: distance to the point.
  EXPECT_NEAR(distance_point_segment({4.0, 5.0}, a, a), 5.0, 1e-15);
}

TEST(Geometry, DistanceSegmentSegment) {
  // Crossing segments: exactly 0.
  EXPECT_EQ(distance_segment_segment({0.0, 0.0}, {2.0, 2.0}, {0.0, 2.0}, {2.0, 0.0}), 0.0);
  EXPECT_EQ(distance_segment_segment({-1.0, 0.1}, {1.0, -0.1}, {0.0, -1.0}, {0.0, 1.0}), 0.0);
  // Parallel segments 0.5 apart.
  EXPECT_NEAR(distance_segment_segment({0.0, 0.0}, {1.0, 0.0}, {0.2, 0.5}, {3.0, 0.5}), 0.5, 1e-15);
  // T shape: end point of one at distance 0.25 from the other's interior.
  EXPECT_NEAR(distance_segment_segment({0.0, 0.0}, {2.0, 0.0}, {1.0, 0.25}, {1.0, 3.0}), 0.25, 1e-15);
  // Disjoint collinear: gap between the ends.
  EXPECT_NEAR(distance_segment_segment({0.0, 0.0}, {1.0, 0.0}, {1.75, 0.0}, {3.0, 0.0}), 0.75, 1e-15);
  // End-to-end: 3-4-5.
  EXPECT_NEAR(distance_segment_segment({0.0, 0.0}, {1.0, 0.0}, {4.0, 4.0}, {4.0, 10.0}), 5.0, 1e-15);
  // Touching at an end point.
  EXPECT_EQ(distance_segment_segment({0.0, 0.0}, {1.0, 0.0}, {1.0, 0.0}, {1.0, 1.0}), 0.0);
}

TEST(Geometry, DistancePointBox) {
  const Vec2 lo{0.0, 0.0};
  const Vec2 hi{2.0, 1.0};
  EXPECT_EQ(distance_point_box({1.0, 0.5}, lo, hi), 0.0);
  EXPECT_EQ(distance_point_box({2.0, 1.0}, lo, hi), 0.0);
  EXPECT_DOUBLE_EQ(distance_point_box({3.0, 0.5}, lo, hi), 1.0);
  EXPECT_DOUBLE_EQ(distance_point_box({1.0, -0.25}, lo, hi), 0.25);
  EXPECT_DOUBLE_EQ(distance_point_box({5.0, 5.0}, lo, hi), 5.0);     // corner (2,1): (3,4)
  EXPECT_DOUBLE_EQ(distance_point_box({-3.0, -4.0}, lo, hi), 5.0);  // corner (0,0)
}

TEST(Geometry, DistanceSegmentBox) {
  const Vec2 lo{0.0, 0.0};
  const Vec2 hi{1.0, 1.0};
  EXPECT_EQ(distance_segment_box({0.5, 0.5}, {3.0, 3.0}, lo, hi), 0.0);     // one end inside
  EXPECT_EQ(distance_segment_box({-1.0, 0.5}, {2.0, 0.5}, lo, hi), 0.0);    // passes through
  EXPECT_DOUBLE_EQ(distance_segment_box({2.0, -1.0}, {2.0, 3.0}, lo, hi), 1.0);
  EXPECT_NEAR(distance_segment_box({1.5, 2.0}, {2.0, 1.5}, lo, hi), std::sqrt(2.0) * 0.75 - 0.0, 1e-15);
}

TEST(PointInPolygon, InsideOutsideAndAConcaveNotch) {
  const std::vector<Vec2> u = {{0, 0}, {3, 0}, {3, 3}, {2, 3}, {2, 1}, {1, 1}, {1, 3}, {0, 3}};  // a U
  EXPECT_TRUE(point_in_polygon({0.5, 2.0}, u));
  EXPECT_TRUE(point_in_polygon({1.5, 0.5}, u));
  EXPECT_FALSE(point_in_polygon({1.5, 2.0}, u)) << "in the notch";
  EXPECT_FALSE(point_in_polygon({4.0, 1.0}, u));
}

TEST(PolygonSelfCrossing, ABowTieCrossesASquareDoesNot) {
  EXPECT_EQ(polygon_self_crossing({{0, 0}, {1, 0}, {1, 1}, {0, 1}}), std::make_pair(-1, -1));
  EXPECT_EQ(polygon_self_crossing({{0, 0}, {1, 1}, {1, 0}, {0, 1}}), std::make_pair(0, 2));
  // Two lobes that touch at one point are no simple outline either.
  EXPECT_NE(polygon_self_crossing({{0, 0}, {1, 1}, {2, 0}, {2, 2}, {1, 1}, {0, 2}}).first, -1);
}

// The pairwise scan the sweep replaced: every non-adjacent pair, the first crossing in (i, k) order.
std::pair<int, int> self_crossing_pairwise(const std::vector<Vec2>& v) {
  const std::size_t n = v.size();
  for (std::size_t i = 0; i < n; ++i) {
    for (std::size_t k = i + 2; k < n; ++k) {
      if (i == 0 && k == n - 1) continue;
      if (distance_segment_segment(v[i], v[(i + 1) % n], v[k], v[(k + 1) % n]) == 0.0) {
        return {static_cast<int>(i), static_cast<int>(k)};
      }
    }
  }
  return {-1, -1};
}

TEST(PolygonSelfCrossing, TheSweepReportsThePairwiseScansFirstPairOnRandomOutlines) {
  // Random outlines on a coarse grid cross, touch at vertices and run along each other often.
  std::mt19937 rng(11);
  std::uniform_int_distribution<int> coordinate(0, 6);
  std::uniform_int_distribution<int> size(3, 12);
  int crossing = 0;
  for (int trial = 0; trial < 3000; ++trial) {
    std::vector<Vec2> v(static_cast<std::size_t>(size(rng)));
    for (Vec2& p : v) p = Vec2(coordinate(rng), coordinate(rng));
    const std::pair<int, int> expected = self_crossing_pairwise(v);
    ASSERT_EQ(polygon_self_crossing(v), expected) << "trial " << trial;
    crossing += expected.first >= 0;
  }
  EXPECT_GT(crossing, 1000);
  EXPECT_LT(crossing, 3000);
}

TEST(PolygonSelfCrossing, AFineCircleIsSimpleAndOneDentedVertexIsFound) {
  constexpr int kVertices = 20000;  // past the loader's bound: the pairwise scan took seconds here
  std::vector<Vec2> circle;
  for (int i = 0; i < kVertices; ++i) {
    const double a = 2.0 * M_PI * i / kVertices;
    circle.emplace_back(std::cos(a), std::sin(a));
  }
  EXPECT_EQ(polygon_self_crossing(circle), std::make_pair(-1, -1));
  circle[5000] = Vec2(0.0, -1.5);  // pulled across the far side: its two edges cross the outline there
  const std::pair<int, int> crossing = polygon_self_crossing(circle);
  EXPECT_EQ(crossing.first, 4999);  // its first edge, across the bottom of the circle
  EXPECT_NEAR(crossing.second, 15000, 2);
}

}  // namespace
}  // namespace pinball
