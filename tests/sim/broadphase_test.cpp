#include "pinball/sim/broadphase.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <vector>

#include "pinball/core/rng.h"
#include "test_boards.h"

namespace pinball::sim {
namespace {

// 200 random lines and circles (some points) on a 1 m x 1 m table.
std::vector<table::Shape> random_shapes(std::uint64_t seed, int n) {
  Rng rng(seed);
  table::Board b;
  for (int i = 0; i < n; ++i) {
    const Vec2 a{rng.uniform(0.0, 1.0), rng.uniform(0.0, 1.0)};
    const double kind = rng.uniform01();
    if (kind < 0.5) {
      const double len = rng.uniform(0.005, 0.3);
      const double ang = rng.uniform(0.0, 6.283185307179586);
      testing::add_line(b, a, a + len * Vec2{std::cos(ang), std::sin(ang)});
    } else if (kind < 0.9) {
      testing::add_circle(b, a, rng.uniform(0.002, 0.05));
    } else {
      testing::add_point(b, a);
    }
  }
  return b.shapes;
}

TEST(DistanceToShape, LinesAndCircles) {
  table::Board b;
  testing::add_line(b, {0.0, 0.0}, {1.0, 0.0});
  testing::add_circle(b, {0.0, 0.0}, 0.5);
  EXPECT_DOUBLE_EQ(table::distance_to_shape(b.shapes[0], {0.5, 0.25}), 0.25);
  EXPECT_DOUBLE_EQ(table::distance_to_shape(b.shapes[0], {0.5, -0.25}), 0.25);  // either side
  EXPECT_DOUBLE_EQ(table::distance_to_shape(b.shapes[0], {-3.0, 4.0}), 5.0);
  EXPECT_DOUBLE_EQ(table::distance_to_shape(b.shapes[1], {3.0, 4.0}), 4.5);
  EXPECT_DOUBLE_EQ(table::distance_to_shape(b.shapes[1], {0.3, 0.0}), -0.2);  // inside: negative
}

TEST(UniformGrid, CandidatesAreSupersetOfShapesInReach) {
  const std::vector<table::Shape> shapes = random_shapes(2024, 200);
  const double reach = 0.02;
  const UniformGrid grid(shapes, reach, 0.025);
  Rng rng(7);
  std::size_t total_candidates = 0;
  std::size_t total_in_reach = 0;
  for (int q = 0; q < 10000; ++q) {
    const Vec2 p{rng.uniform(-0.2, 1.2), rng.uniform(-0.2, 1.2)};
    const auto cand = grid.candidates(p);
    ASSERT_TRUE(std::is_sorted(cand.begin(), cand.end()));
    ASSERT_EQ(std::adjacent_find(cand.begin(), cand.end()), cand.end()) << "duplicate candidate";
    for (std::size_t i = 0; i < shapes.size(); ++i) {
      if (table::distance_to_shape(shapes[i], p) <= reach) {
        ++total_in_reach;
        ASSERT_TRUE(std::binary_search(cand.begin(), cand.end(), static_cast<std::int32_t>(i)))
            << "shape " << i << " at distance " << table::distance_to_shape(shapes[i], p) << " of (" << p.x() << ", "
            << p.y() << ") missing";
      }
    }
    total_candidates += cand.size();
    for (const std::int32_t i : cand) {
      ASSERT_GE(i, 0);
      ASSERT_LT(i, 200);
      // No shape farther than reach + one cell diagonal from the query can be listed.
      EXPECT_LE(table::distance_to_shape(shapes[i], p), reach + 0.025 * std::sqrt(2.0) + 1e-12);
    }
  }
  EXPECT_GT(total_in_reach, 1000u);  // the test exercised real hits
  // The grid prunes: far fewer candidates than the 200 x 10000 brute force.
  EXPECT_LT(total_candidates, 200u * 10000u / 10u);
  EXPECT_GE(grid.max_candidates(), 1u);
  EXPECT_LE(grid.max_candidates(), 200u);
}

TEST(UniformGrid, EmptyFarAway) {
  const std::vector<table::Shape> shapes = random_shapes(3, 50);
  const UniformGrid grid(shapes, 0.02, 0.03);
  EXPECT_TRUE(grid.candidates({-5.0, 0.5}).empty());
  EXPECT_TRUE(grid.candidates({0.5, 50.0}).empty());
  EXPECT_TRUE(grid.candidates({1e300, -1e300}).empty());
  EXPECT_TRUE(grid.candidates({NAN, 0.5}).empty());
}

TEST(UniformGrid, FarObstacleNotListed) {
  table::Board b;
  testing::add_circle(b, {0.1, 0.1}, 0.02);      // 0
  testing::add_line(b, {0.8, 0.1}, {0.9, 0.2});  // 1
  testing::add_point(b, {0.5, 0.9});              // 2
  const UniformGrid grid(b.shapes, 0.03, 0.01);
  const auto near_circle = grid.candidates({0.1, 0.145});  // 0.025 from the rim
  ASSERT_EQ(near_circle.size(), 1u);
  EXPECT_EQ(near_circle[0], 0);
  const auto near_point = grid.candidates({0.5, 0.88});
  ASSERT_EQ(near_point.size(), 1u);
  EXPECT_EQ(near_point[0], 2);
  // Between them, farther than reach + a cell diagonal from everything: nothing.
  EXPECT_TRUE(grid.candidates({0.5, 0.5}).empty());
  EXPECT_GT(grid.cell_count(), 0);
}

TEST(UniformGrid, NoShapesAndBadArguments) {
  const std::vector<table::Shape> none;
  const UniformGrid empty(none, 0.02, 0.02);
  EXPECT_TRUE(empty.candidates({0.0, 0.0}).empty());
  EXPECT_EQ(empty.entry_count(), 0u);
  const std::vector<table::Shape> shapes = random_shapes(1, 3);
  EXPECT_THROW(UniformGrid(shapes, -1.0, 0.02), std::invalid_argument);
  EXPECT_THROW(UniformGrid(shapes, 0.02, 0.0), std::invalid_argument);
}

TEST(UniformGrid, HugeBoardStaysBounded) {
  // Cells would number 1e10 at this size: the grid must coarsen, not explode.
  table::Board b;
  testing::add_line(b, {0.0, 0.0}, {1000.0, 0.0});
  testing::add_point(b, {1000.0, 1000.0});
  const UniformGrid grid(b.shapes, 0.01, 0.01);
  EXPECT_LE(grid.cell_count(), 4000000);
  const auto c = grid.candidates({500.0, 0.005});
  ASSERT_FALSE(c.empty());
  EXPECT_EQ(c[0], 0);
}

}  // namespace
}  // namespace pinball::sim
