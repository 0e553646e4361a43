// The twin's MJCF is generated from the board: one geom per board shape, the
// surfaces' materials from their ρ and kick, and boards it cannot represent refused.

#include "pinball/simlab/twin_model.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>

#include "common/thesis_board.h"
#include "common/twin_params.h"
#include "pinball/table/board_loader.h"

namespace pinball::simlab {
namespace {

TEST(TwinModel, EveryBoardShapeBelongsToExactlyOneGeom) {
  const table::Board& board = testing::thesis_board();
  const TwinModelText model = twin_model_text(board, testing::shipped_twin_params(), 0.0005, {});
  std::vector<int> owners(board.shapes.size(), 0);
  std::size_t flippers = 0, bars = 0;
  for (const TwinGeom& g : model.geoms) {
    flippers += g.kind == TwinGeom::kFlipper;
    for (const int m : g.members) ++owners[static_cast<std::size_t>(m)];
    const bool two_lines = g.members.size() > 1 && board.shapes[static_cast<std::size_t>(g.members[1])].kind ==
                                                       table::ShapeKind::kLine;
    bars += two_lines;
    EXPECT_FALSE(two_lines && g.one_sided) << "a bar is solid from both sides";
  }
  for (std::size_t i = 0; i < owners.size(); ++i) EXPECT_EQ(owners[i], 1) << board.obstacles[i].name;
  EXPECT_EQ(flippers, board.flippers.size());
  EXPECT_GE(bars, 17u) << "every wall is one bar";
  EXPECT_LT(model.geoms.size(), board.shapes.size() / 2) << "walls and their end points share a geom";
  EXPECT_NE(model.mjcf.find("condim=\"6\""), std::string::npos) << "the ball rolls and spins";
  EXPECT_NEAR(model.slope_rad * 180.0 / std::numbers::pi, 6.5, 0.01);
}

TEST(TwinModel, AWallIsOneBarWithItsEndPoints) {
  const table::Board board = table::parse_board(
      "pinball-board 1\nunits mm\nsize 510 1070\nball 13.5 5000\ngravity 1110\ndt 0.0005\nballs 1\n"
      "launcher 255 100\nwall 100 500 400 500 name=w\nline 100 300 400 300 name=l\npoint 50 50\n",
      "scene");
  const std::vector<std::vector<int>> groups = twin_obstacle_groups(board);
  ASSERT_EQ(groups.size(), 3u);
  EXPECT_EQ(groups[0], (std::vector<int>{0, 1, 2, 3})) << "both lines and both end points";
  EXPECT_EQ(groups[1], (std::vector<int>{4}));
  EXPECT_EQ(groups[2], (std::vector<int>{5})) << "a lone point is a pin";
}

TEST(TwinModel, SurfacesAreRubberRailOrDeadByTheirRhoAndKick) {
  const table::Board& board = testing::thesis_board();
  auto material_of = [&](const std::string& name) {
    for (std::size_t i = 0; i < board.obstacles.size(); ++i) {
      if (board.obstacles[i].name == name) return twin_material(board, static_cast<int>(i), testing::shipped_twin_params());
    }
    ADD_FAILURE() << "no obstacle " << name;
    return TwinMaterial::kRail;
  };
  EXPECT_EQ(material_of("bumper_left"), TwinMaterial::kRubber);     // a kicker
  EXPECT_EQ(material_of("left_sling"), TwinMaterial::kRubber);      // a kicker
  EXPECT_EQ(material_of("post_left"), TwinMaterial::kRubber);       // ρ 0.9
  EXPECT_EQ(material_of("right_wall"), TwinMaterial::kRail);        // ρ 0.6
  EXPECT_EQ(material_of("chute_floor"), TwinMaterial::kDead);       // ρ 0.2
  EXPECT_EQ(material_of("drain"), TwinMaterial::kDead);             // ρ 0
}

TEST(TwinModel, RefusesABoardItCannotRepresentNamingIt) {
  table::Board board = testing::thesis_board();
  board.gravity_mps2 = 9.0;
  try {
    twin_model_text(board, testing::shipped_twin_params(), 0.0005, {});
    FAIL() << "a 66 degree playfield";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("mit1993.board"), std::string::npos) << e.what();
  }
  board = testing::thesis_board();
  board.flippers[0].length_m = 0.005;
  EXPECT_THROW(twin_model_text(board, testing::shipped_twin_params(), 0.0005, {}), std::invalid_argument);
}

std::string refusal(const table::Board& board) {
  try {
    check_board_fits_the_twin(board, testing::shipped_twin_params(), 0.0005);
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "";
}

// Boards the model plays and the twin cannot, found by probing: each had played on with no warning.
TEST(TwinModel, RefusesABallTheTwinsSolidsCannotHold) {
  const table::Board thesis = testing::thesis_board();
  EXPECT_EQ(refusal(thesis), "");
  table::Board big = thesis;  // wedged between the playfield and the glass, creeping at 1e-5 m/s
  big.ball.radius_m = 0.05;
  EXPECT_NE(refusal(big).find("a ball 100 mm across does not fit under the twin's glass, 85 mm above the playfield"),
            std::string::npos)
      << refusal(big);
  table::Board fast = thesis;  // 100 m/s: every ball left through a wall
  fast.ball.speed_max_mps = 100.0;
  EXPECT_NE(refusal(fast).find("at 100 m/s (SPEED_MAX, or a kickout) would pass through the twin's thinnest solid: "
                               "it moves 50 mm a step"),
            std::string::npos)
      << refusal(fast);
  table::Board small = thesis;  // 1 mm at 2.3 m/s: through a 2 mm bar, leaving faster than it came
  small.ball.radius_m = 0.001;
  small.ball.speed_max_mps = 2.3;
  EXPECT_NE(refusal(small).find("sinks about 2.2 mm into a contact"), std::string::npos) << refusal(small);
}

// The loader clears a served ball of the board's lines; the twin's bars and rubbers are thicker, and a
// ball served 1 µm from a wall had been shot off at 2 m/s.
TEST(TwinModel, RefusesABallPutWhereItWouldOverlapASolid) {
  table::Board board = testing::thesis_board();
  const table::Flipper& f = board.flippers[0];
  const Vec2 tip = table::flipper_tip(f, f.theta_min_rad);
  board.start = table::BallStart{tip + (board.ball.radius_m + 1e-6) * table::flipper_up_normal(f, f.theta_min_rad),
                                 Vec2::Zero()};
  EXPECT_NE(refusal(board).find("the ball at the start would overlap flipper '" + f.name + "' at rest by 6 mm"),
            std::string::npos)
      << refusal(board);
}

}  // namespace
}  // namespace pinball::simlab
