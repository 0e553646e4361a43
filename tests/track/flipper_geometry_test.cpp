#include "pinball/track/flipper_geometry.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <stdexcept>

#include "pinball/table/board_loader.h"
#include "common/thesis_board.h"

namespace pinball::track {
namespace {

using pinball::testing::thesis_board;

TEST(MakeFlipperGeometry, SymmetricPairByHand) {
  // Left from (-2, 0) to (-1, -1), right from (2, 0) to (1, -1): the lines
  // y = -x - 2 and y = x - 2 meet at (0, -2), two flipper lengths out.
  const FlipperGeometry g = make_flipper_geometry({{-2.0, 0.0}, {-1.0, -1.0}}, {{2.0, 0.0}, {1.0, -1.0}});
  EXPECT_NEAR(g.apex.x(), 0.0, 1e-15);
  EXPECT_NEAR(g.apex.y(), -2.0, 1e-15);
  EXPECT_NEAR(g.h_apex[kLeftFlipper], 2.0, 1e-15);
  EXPECT_NEAR(g.h_apex[kRightFlipper], 2.0, 1e-15);
  EXPECT_EQ(g.lines[kLeftFlipper].pivot, Vec2(-2.0, 0.0));
  EXPECT_EQ(g.lines[kRightFlipper].tip, Vec2(1.0, -1.0));
  EXPECT_EQ(g.lines[kLeftFlipper].axis(), Vec2(1.0, -1.0));
}

TEST(MakeFlipperGeometry, AsymmetricPairByHand) {
  // Left: horizontal from (0, 0) to (1, 0). Right: from (3, 1) to (2, 0), so
  // its tip already lies on the left line at h = 2 of the left flipper.
  const FlipperGeometry g = make_flipper_geometry({{0.0, 0.0}, {1.0, 0.0}}, {{3.0, 1.0}, {2.0, 0.0}});
  EXPECT_NEAR(g.apex.x(), 2.0, 1e-15);
  EXPECT_NEAR(g.apex.y(), 0.0, 1e-15);
  EXPECT_NEAR(g.h_apex[kLeftFlipper], 2.0, 1e-15);
  EXPECT_NEAR(g.h_apex[kRightFlipper], 1.0, 1e-15);
}

TEST(MakeFlipperGeometry, ParallelOrDivergingLinesThrow) {
  EXPECT_THROW(make_flipper_geometry({{0.0, 0.0}, {1.0, -0.5}}, {{3.0, 0.0}, {4.0, -0.5}}), std::invalid_argument);
  EXPECT_THROW(make_flipper_geometry({{0.0, 0.0}, {1.0, 0.0}}, {{3.0, 1.0}, {2.0, 1.0}}), std::invalid_argument);
  // Flippers pointing away from each other meet behind both pivots: no 'V'.
  EXPECT_THROW(make_flipper_geometry({{0.0, 0.0}, {-1.0, -1.0}}, {{4.0, 0.0}, {5.0, -1.0}}), std::invalid_argument);
  // A degenerate flipper (tip on the pivot) has no line.
  EXPECT_THROW(make_flipper_geometry({{0.0, 0.0}, {0.0, 0.0}}, {{4.0, 0.0}, {3.0, -1.0}}), std::invalid_argument);
}

TEST(FlipperGeometryFromBoard, Mit1993) {
  const FlipperGeometry g = flipper_geometry_from_board(thesis_board());
  // flipper left 165 160 76 -25 ... / right 345 160 76 -25 (mm, degrees).
  const double c = std::cos(25.0 * std::numbers::pi / 180.0);
  const double s = std::sin(25.0 * std::numbers::pi / 180.0);
  const FlipperLine& l = g.lines[kLeftFlipper];
  const FlipperLine& r = g.lines[kRightFlipper];
  EXPECT_NEAR(l.pivot.x(), 0.165, 1e-12);
  EXPECT_NEAR(r.pivot.x(), 0.345, 1e-12);
  EXPECT_NEAR((l.tip - Vec2(0.165 + 0.076 * c, 0.160 - 0.076 * s)).norm(), 0.0, 1e-12);
  EXPECT_NEAR((r.tip - Vec2(0.345 - 0.076 * c, 0.160 - 0.076 * s)).norm(), 0.0, 1e-12);
  // Symmetric about x = 0.255: the apex is on the centre line, 0.09 m / (l cos 25°) along each.
  const double h = 0.09 / (0.076 * c);
  EXPECT_NEAR(g.apex.x(), 0.255, 1e-12);
  EXPECT_NEAR(g.apex.y(), 0.160 - 0.09 * std::tan(25.0 * std::numbers::pi / 180.0), 1e-12);
  EXPECT_NEAR(g.h_apex[kLeftFlipper], h, 1e-12);
  EXPECT_NEAR(g.h_apex[kRightFlipper], h, 1e-12);
  EXPECT_GT(g.h_apex[kLeftFlipper], 1.0);
  EXPECT_LT(g.h_apex[kLeftFlipper], 2.0);
}

TEST(FlipperGeometryFromBoard, AssignsSidesWhateverTheFileOrder) {
  table::Board b = thesis_board();
  std::swap(b.flippers[0], b.flippers[1]);  // right first
  const FlipperGeometry g = flipper_geometry_from_board(b);
  EXPECT_NEAR(g.lines[kLeftFlipper].pivot.x(), 0.165, 1e-12);
  EXPECT_NEAR(g.lines[kRightFlipper].pivot.x(), 0.345, 1e-12);
}

TEST(FlipperGeometryFromBoard, NeedsOneFlipperPerSide) {
  table::Board one = thesis_board();
  one.flippers.pop_back();
  EXPECT_THROW(flipper_geometry_from_board(one), std::invalid_argument);
  table::Board two_left = thesis_board();
  two_left.flippers[1].side = table::Side::kLeft;
  EXPECT_THROW(flipper_geometry_from_board(two_left), std::invalid_argument);
  table::Board three = thesis_board();
  three.flippers.push_back(three.flippers[0]);
  EXPECT_THROW(flipper_geometry_from_board(three), std::invalid_argument);
}

// Flippers whose rest lines form no V are named by the board file and their lines.
TEST(FlipperGeometryFromBoard, NoVNamesTheFileAndTheFlippers) {
  table::Board swapped = thesis_board();
  std::swap(swapped.flippers[0].pivot, swapped.flippers[1].pivot);  // each points away from the other
  try {
    flipper_geometry_from_board(swapped);
    FAIL() << "flippers pointing apart formed a V";
  } catch (const std::invalid_argument& e) {
    const std::string what = e.what();
    EXPECT_EQ(what.rfind(swapped.source + ":" + std::to_string(swapped.flippers[0].source_line) + ": flipper '", 0),
              0u)
        << what;
    EXPECT_NE(what.find("they form no 'V'"), std::string::npos) << what;
  }
}

TEST(AboveFlippers, PointsAboveAndBelowTheV) {
  const FlipperGeometry g = flipper_geometry_from_board(thesis_board());
  EXPECT_TRUE(above_flippers(g, {0.255, 0.5}));              // high on the centre line
  EXPECT_TRUE(above_flippers(g, g.apex + Vec2(0.0, 0.002)));  // just above the V's centre
  EXPECT_FALSE(above_flippers(g, g.apex - Vec2(0.0, 0.002))); // just below it: in the gap
  EXPECT_FALSE(above_flippers(g, {0.255, 0.02}));             // over the drain
  // Just above / below the middle of each flipper.
  for (const FlipperLine& line : g.lines) {
    const Vec2 mid = 0.5 * (line.pivot + line.tip);
    EXPECT_TRUE(above_flippers(g, mid + Vec2(0.0, 0.001)));
    EXPECT_FALSE(above_flippers(g, mid - Vec2(0.0, 0.001)));
  }
  EXPECT_TRUE(above_flippers(g, {0.165, 0.20}));   // over the left pivot
  EXPECT_FALSE(above_flippers(g, {0.05, 0.20}));   // outside the pivot, below the left line's extension
  EXPECT_FALSE(above_flippers(g, g.apex));         // on the lines is not above them
}

}  // namespace
}  // namespace pinball::track
