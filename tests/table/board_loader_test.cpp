#include "pinball/table/board_loader.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>

namespace pinball::table {
namespace {

// Seven lines of required statements in SI; the body of each test starts at line 8.
constexpr const char* kHead =
    "pinball-board 1\n"
    "size 0.51 1.07\n"
    "ball 0.0135 5\n"
    "gravity 1.11\n"
    "dt 0.0005\n"
    "balls 3\n"
    "launcher 0.45 0.05\n";

Board parse(const std::string& body) { return parse_board(std::string(kHead) + body, "t.board"); }

/// Parses `text` expecting a BoardError at `line` whose what() contains `part`.
void expect_error(const std::string& text, int line, const std::string& part) {
  try {
    parse_board(text, "x.board");
    ADD_FAILURE() << "no error for:\n" << text;
  } catch (const BoardError& e) {
    EXPECT_EQ(e.line(), line) << e.what();
    EXPECT_EQ(e.file(), "x.board");
    EXPECT_NE(std::string(e.what()).find(part), std::string::npos) << "what(): " << e.what() << "\nwanted: " << part;
    if (line > 0) {
      const std::string prefix = "x.board:" + std::to_string(line) + ": ";
      EXPECT_EQ(std::string(e.what()).rfind(prefix, 0), 0u) << e.what();
    }
  }
}

/// Same, for a body after kHead.
void expect_body_error(const std::string& body, int line, const std::string& part) {
  expect_error(std::string(kHead) + body, line, part);
}

constexpr double kDeg = std::numbers::pi / 180.0;

TEST(BoardLoader, ReadsSiHeader) {
  const Board b = parse("");
  EXPECT_EQ(b.source, "t.board");
  EXPECT_DOUBLE_EQ(b.width_m, 0.51);
  EXPECT_DOUBLE_EQ(b.height_m, 1.07);
  EXPECT_DOUBLE_EQ(b.ball.radius_m, 0.0135);
  EXPECT_DOUBLE_EQ(b.ball.speed_max_mps, 5.0);
  EXPECT_DOUBLE_EQ(b.gravity_mps2, 1.11);
  EXPECT_DOUBLE_EQ(b.dt_s, 0.0005);
  EXPECT_EQ(b.balls_per_game, 3);
  EXPECT_TRUE(b.launcher.position.isApprox(Vec2(0.45, 0.05)));
  EXPECT_DOUBLE_EQ(b.launcher.pull, 1.0);
  EXPECT_DOUBLE_EQ(b.launcher.noise_max, 0.03);
  EXPECT_TRUE(b.shapes.empty());
}

TEST(BoardLoader, ConvertsMillimetresAndDegreesToSi) {
  const Board b = parse_board(
      "pinball-board 1   # header\n"
      "units mm\n"
      "angles deg\n"
      "size 510 1070\n"
      "ball 13.5 5000\n"
      "gravity 1110\n"
      "dt 0.0005\n"
      "balls 2\n"
      "launcher 450 50 pull=0.5 noise=0.1\n"
      "circle 100 200 30 kick=400 friction=0.15\n"
      "flipper right 300 150 76 -30 30 2000\n"
      "hole 250 800 20 kickout=100,-200\n",
      "mm.board");
  EXPECT_DOUBLE_EQ(b.width_m, 0.51);
  EXPECT_DOUBLE_EQ(b.height_m, 1.07);
  EXPECT_DOUBLE_EQ(b.ball.radius_m, 0.0135);
  EXPECT_DOUBLE_EQ(b.ball.speed_max_mps, 5.0);
  EXPECT_DOUBLE_EQ(b.gravity_mps2, 1.11);
  EXPECT_DOUBLE_EQ(b.dt_s, 0.0005);  // times are always seconds
  EXPECT_TRUE(b.launcher.position.isApprox(Vec2(0.45, 0.05)));
  EXPECT_DOUBLE_EQ(b.launcher.pull, 0.5);  // fractions are not lengths
  EXPECT_DOUBLE_EQ(b.launcher.noise_max, 0.1);
  ASSERT_EQ(b.shapes.size(), 1u);
  EXPECT_TRUE(b.shapes[0].p0.isApprox(Vec2(0.1, 0.2)));
  EXPECT_DOUBLE_EQ(b.shapes[0].radius_m, 0.03);
  EXPECT_DOUBLE_EQ(b.obstacles[0].action.kick_mps, 0.4);
  EXPECT_DOUBLE_EQ(b.obstacles[0].friction, 0.15);  // a coefficient, not a length
  ASSERT_EQ(b.flippers.size(), 1u);
  const Flipper& f = b.flippers[0];
  EXPECT_EQ(f.side, Side::kRight);
  EXPECT_TRUE(f.pivot.isApprox(Vec2(0.3, 0.15)));
  EXPECT_DOUBLE_EQ(f.length_m, 0.076);
  EXPECT_DOUBLE_EQ(f.theta_min_rad, -30 * kDeg);
  EXPECT_DOUBLE_EQ(f.theta_max_rad, 30 * kDeg);
  EXPECT_DOUBLE_EQ(f.omega_rad_s, 2000 * kDeg);
  ASSERT_EQ(b.sensors.size(), 1u);
  EXPECT_TRUE(b.sensors[0].kickout_mps.isApprox(Vec2(0.1, -0.2)));
  EXPECT_DOUBLE_EQ(b.sensors[0].shape.radius_m, 0.02);
}

TEST(BoardLoader, LineIsOneDirectedSegmentWithLeftNormal) {
  const Board b = parse("line 0.1 0.5 0.3 0.5\n");
  ASSERT_EQ(b.shapes.size(), 1u);
  const Shape& s = b.shapes[0];
  EXPECT_EQ(s.kind, ShapeKind::kLine);
  EXPECT_TRUE(s.p0.isApprox(Vec2(0.1, 0.5)));
  EXPECT_TRUE(s.p1.isApprox(Vec2(0.3, 0.5)));
  EXPECT_TRUE(s.normal.isApprox(Vec2(0, 1)));  // left of +x is +y
  EXPECT_EQ(b.obstacles[0].name, "line@8");
  EXPECT_EQ(b.obstacles[0].source_line, 8);
  EXPECT_EQ(b.obstacles.size(), b.shapes.size());
}

TEST(BoardLoader, WallIsTwoSegmentsAndTwoPointsSharingAttributes) {
  const Board b = parse("wall 0.1 0.2 0.1 0.6 rho=0.5 score=10\n");
  ASSERT_EQ(b.shapes.size(), 4u);
  ASSERT_EQ(b.obstacles.size(), 4u);
  EXPECT_EQ(b.shapes[0].kind, ShapeKind::kLine);
  EXPECT_EQ(b.shapes[1].kind, ShapeKind::kLine);
  EXPECT_TRUE(b.shapes[0].p0.isApprox(b.shapes[1].p1));
  EXPECT_TRUE(b.shapes[0].p1.isApprox(b.shapes[1].p0));
  EXPECT_TRUE(b.shapes[0].normal.isApprox(Vec2(-1, 0)));  // left of +y is -x
  EXPECT_TRUE(b.shapes[1].normal.isApprox(Vec2(1, 0)));
  for (int i : {2, 3}) {
    EXPECT_EQ(b.shapes[i].kind, ShapeKind::kCircle);
    EXPECT_EQ(b.shapes[i].radius_m, 0.0);
  }
  EXPECT_TRUE(b.shapes[2].p0.isApprox(Vec2(0.1, 0.2)));
  EXPECT_TRUE(b.shapes[3].p0.isApprox(Vec2(0.1, 0.6)));
  for (const Obstacle& o : b.obstacles) {
    EXPECT_EQ(o.name, "wall@8");
    EXPECT_DOUBLE_EQ(o.rho, 0.5);
    EXPECT_DOUBLE_EQ(o.action.score, 10);
  }
}

TEST(BoardLoader, PointAndCircle) {
  const Board b = parse("point 0.2 0.3\ncircle 0.3 0.4 0.05 name=bumper\n");
  ASSERT_EQ(b.shapes.size(), 2u);
  EXPECT_EQ(b.shapes[0].kind, ShapeKind::kCircle);
  EXPECT_EQ(b.shapes[0].radius_m, 0.0);
  EXPECT_EQ(b.obstacles[0].name, "point@8");
  EXPECT_EQ(b.shapes[1].kind, ShapeKind::kCircle);
  EXPECT_DOUBLE_EQ(b.shapes[1].radius_m, 0.05);
  EXPECT_EQ(b.obstacles[1].name, "bumper");
  EXPECT_EQ(b.obstacles[1].source_line, 9);
}

TEST(BoardLoader, PolylineHasSegmentsAlongThePathAndPointsAtEveryVertex) {
  const Board one = parse("polyline 0.1 0.5 0.2 0.5 0.2 0.7\n");
  ASSERT_EQ(one.shapes.size(), 5u);  // 2 segments + 3 points
  EXPECT_TRUE(one.shapes[0].p0.isApprox(Vec2(0.1, 0.5)));
  EXPECT_TRUE(one.shapes[0].normal.isApprox(Vec2(0, 1)));
  EXPECT_TRUE(one.shapes[1].p0.isApprox(Vec2(0.2, 0.5)));
  EXPECT_TRUE(one.shapes[1].p1.isApprox(Vec2(0.2, 0.7)));
  EXPECT_TRUE(one.shapes[1].normal.isApprox(Vec2(-1, 0)));
  const Vec2 vertices[] = {{0.1, 0.5}, {0.2, 0.5}, {0.2, 0.7}};
  for (int i = 0; i < 3; ++i) {
    EXPECT_EQ(one.shapes[2 + i].kind, ShapeKind::kCircle);
    EXPECT_TRUE(one.shapes[2 + i].p0.isApprox(vertices[i]));  // including the joint
  }

  const Board two = parse("polyline 0.1 0.5 0.2 0.5 0.2 0.7 two-sided\n");
  ASSERT_EQ(two.shapes.size(), 7u);  // 4 segments + 3 points
  int lines = 0;
  for (const Shape& s : two.shapes) lines += s.kind == ShapeKind::kLine;
  EXPECT_EQ(lines, 4);
  EXPECT_TRUE(two.shapes[1].normal.isApprox(Vec2(0, -1)));  // reverse of the first segment
}

/// Every edge's normal points away from the centroid of a convex polygon.
void expect_outward(const Board& b, std::size_t vertex_count, const Vec2& centroid) {
  ASSERT_EQ(b.shapes.size(), 2 * vertex_count);
  for (std::size_t i = 0; i < vertex_count; ++i) {
    const Shape& s = b.shapes[i];
    ASSERT_EQ(s.kind, ShapeKind::kLine);
    EXPECT_GT(s.normal.dot(0.5 * (s.p0 + s.p1) - centroid), 0.0) << "edge " << i;
    EXPECT_TRUE(s.p1.isApprox(b.shapes[(i + 1) % vertex_count].p0)) << "edges chain, closed";
    EXPECT_NEAR(s.normal.norm(), 1.0, 1e-12);
  }
  for (std::size_t i = vertex_count; i < 2 * vertex_count; ++i) {
    EXPECT_EQ(b.shapes[i].kind, ShapeKind::kCircle);
  }
}

TEST(BoardLoader, PolygonNormalsFaceOutwardForEitherVertexOrder) {
  const Vec2 centroid(0.3, 0.5);
  expect_outward(parse("polygon 0.2 0.4 0.4 0.4 0.4 0.6 0.2 0.6\n"), 4, centroid);  // counter-clockwise
  expect_outward(parse("polygon 0.2 0.4 0.2 0.6 0.4 0.6 0.4 0.4\n"), 4, centroid);  // clockwise
  expect_outward(parse("polygon 0.2 0.4 0.4 0.4 0.3 0.7\n"), 3, Vec2(0.3, 0.5));
}

TEST(BoardLoader, ObstacleAttributesDefaultsAndBanks) {
  const Board b = parse(
      "defaults rho=0.6\n"                             // 8
      "bank drops bonus=500\n"                         // 9
      "circle 0.1 0.5 0.01 bank=drops score=5\n"       // 10
      "point 0.2 0.5 bank=drops hidden\n"              // 11
      "line 0.1 0.1 0.3 0.1 eat rho=0 contact=20\n"    // 12
      "flipper left 0.1 0.2 0.076 -0.5 0.5 35\n"       // 13
      "defaults rho=1.2\n"                             // 14
      "point 0.3 0.5\n"                                // 15
      "flipper right 0.4 0.2 0.076 -0.5 0.5 35 mu=0.8 rho=0.9 name=R\n");  // 16
  ASSERT_EQ(b.obstacles.size(), 4u);
  EXPECT_DOUBLE_EQ(b.obstacles[0].rho, 0.6);
  EXPECT_DOUBLE_EQ(b.obstacles[0].action.score, 5);
  EXPECT_EQ(b.obstacles[0].bank, 0);
  EXPECT_TRUE(b.obstacles[0].visible);
  EXPECT_EQ(b.obstacles[1].bank, 0);
  EXPECT_FALSE(b.obstacles[1].visible);
  EXPECT_EQ(b.obstacles[2].bank, -1);
  EXPECT_TRUE(b.obstacles[2].action.eats_ball);
  EXPECT_DOUBLE_EQ(b.obstacles[2].rho, 0.0);
  EXPECT_DOUBLE_EQ(b.obstacles[2].action.contact_score_per_s, 20);
  EXPECT_DOUBLE_EQ(b.obstacles[3].rho, 1.2);
  ASSERT_EQ(b.banks.size(), 1u);
  EXPECT_EQ(b.banks[0].name, "drops");
  EXPECT_DOUBLE_EQ(b.banks[0].bonus, 500);
  EXPECT_EQ(b.banks[0].members, (std::vector<int>{0, 1}));
  ASSERT_EQ(b.flippers.size(), 2u);
  EXPECT_EQ(b.flippers[0].side, Side::kLeft);
  EXPECT_DOUBLE_EQ(b.flippers[0].rho, 0.6);  // the defaults in force at its line
  EXPECT_DOUBLE_EQ(b.flippers[0].mu, 1.0);
  EXPECT_EQ(b.flippers[0].name, "flipper@13");
  EXPECT_EQ(b.flippers[0].source_line, 13);
  EXPECT_DOUBLE_EQ(b.flippers[1].rho, 0.9);
  EXPECT_DOUBLE_EQ(b.flippers[1].mu, 0.8);
  EXPECT_EQ(b.flippers[1].name, "R");
}

TEST(BoardLoader, BankMembersAreEveryShapeOfAMultiShapeStatement) {
  const Board b = parse("bank gate bonus=1\npoint 0.2 0.9\nwall 0.1 0.5 0.2 0.5 bank=gate\n");
  EXPECT_EQ(b.banks[0].members, (std::vector<int>{1, 2, 3, 4}));
  for (int i : b.banks[0].members) EXPECT_EQ(b.obstacles[static_cast<std::size_t>(i)].bank, 0);
  EXPECT_EQ(b.obstacles[0].bank, -1);
}

TEST(BoardLoader, SensorsAndHoles) {
  const Board b = parse(
      "sensor line 0.1 0.5 0.3 0.5 score=3\n"
      "sensor circle 0.2 0.8 0.02 eat name=drain\n"
      "hole 0.3 0.9 0.02 score=100 eat\n"
      "hole 0.1 0.9 0.02 kickout=0.5,-1\n");
  ASSERT_EQ(b.sensors.size(), 4u);
  EXPECT_TRUE(b.shapes.empty());  // sensors are not obstacles
  EXPECT_EQ(b.sensors[0].kind, SensorKind::kProximity);
  EXPECT_EQ(b.sensors[0].shape.kind, ShapeKind::kLine);
  EXPECT_TRUE(b.sensors[0].shape.normal.isApprox(Vec2(0, 1)));
  EXPECT_DOUBLE_EQ(b.sensors[0].action.score, 3);
  EXPECT_EQ(b.sensors[0].name, "sensor@8");
  EXPECT_EQ(b.sensors[1].kind, SensorKind::kProximity);
  EXPECT_EQ(b.sensors[1].shape.kind, ShapeKind::kCircle);
  EXPECT_TRUE(b.sensors[1].action.eats_ball);
  EXPECT_EQ(b.sensors[1].name, "drain");
  EXPECT_EQ(b.sensors[2].kind, SensorKind::kHole);
  EXPECT_TRUE(b.sensors[2].action.eats_ball);
  EXPECT_FALSE(b.sensors[2].has_kickout);
  EXPECT_EQ(b.sensors[2].name, "hole@10");
  EXPECT_EQ(b.sensors[3].kind, SensorKind::kHole);
  EXPECT_FALSE(b.sensors[3].action.eats_ball);
  EXPECT_TRUE(b.sensors[3].has_kickout);
  EXPECT_TRUE(b.sensors[3].kickout_mps.isApprox(Vec2(0.5, -1)));
  EXPECT_EQ(b.sensors[3].source_line, 11);
}

TEST(BoardLoader, HoleKickoutSpreadAndNoise) {
  // Defaults: 5 degrees either way and up to 10 % slower.
  const Board d = parse("hole 0.1 0.9 0.02 kickout=0.5,-1\n");
  EXPECT_DOUBLE_EQ(d.sensors[0].kickout_spread_rad, kDefaultKickoutSpread_rad);
  EXPECT_NEAR(d.sensors[0].kickout_spread_rad, 5 * kDeg, 1e-15);
  EXPECT_DOUBLE_EQ(d.sensors[0].kickout_noise, kDefaultKickoutNoise);
  // In the file's angle unit; 0 and 0 give the exact kickout of old.
  const Board e = parse_board(
      "pinball-board 1\nangles deg\nsize 0.51 1.07\nball 0.0135 5\ngravity 1.11\ndt 0.0005\nballs 3\n"
      "launcher 0.45 0.05\nhole 0.1 0.9 0.02 kickout=0.5,-1 spread=2 noise=0.05\n"
      "hole 0.3 0.9 0.02 kickout=0.5,-1 spread=0 noise=0\n",
      "t.board");
  EXPECT_NEAR(e.sensors[0].kickout_spread_rad, 2 * kDeg, 1e-15);
  EXPECT_DOUBLE_EQ(e.sensors[0].kickout_noise, 0.05);
  EXPECT_EQ(e.sensors[1].kickout_spread_rad, 0.0);
  EXPECT_EQ(e.sensors[1].kickout_noise, 0.0);
  const Board rad = parse("hole 0.1 0.9 0.02 kickout=0.5,-1 spread=0.1\n");
  EXPECT_DOUBLE_EQ(rad.sensors[0].kickout_spread_rad, 0.1);
}

TEST(BoardLoaderErrors, HoleKickoutSpreadAndNoiseAreBounded) {
  expect_body_error("hole 0.1 0.9 0.02 kickout=0.5,-1 spread=-0.1\n", 8,
                    "hole: attribute spread must be in [0, 1.5708], got -0.1");
  expect_body_error("hole 0.1 0.9 0.02 kickout=0.5,-1 spread=2\n", 8, "attribute spread must be in [0, 1.5708], got 2");
  expect_body_error("hole 0.1 0.9 0.02 kickout=0.5,-1 noise=0.6\n", 8, "hole: attribute noise must be in [0, 0.5], got 0.6");
  expect_body_error("hole 0.1 0.9 0.02 eat spread=0.1\n", 8, "hole: attributes spread and noise need kickout=VX,VY");
  expect_body_error("hole 0.1 0.9 0.02 kickout=0.5,-1 noise=lots\n", 8, "attribute noise is not a finite number: 'lots'");
}

TEST(BoardLoader, StartServesTheBallAtAPositionAndVelocity) {
  const Board none = parse("");
  EXPECT_FALSE(none.start.has_value());
  const Board b = parse("start 0.1 0.9 1.5 -0.5\n");
  ASSERT_TRUE(b.start.has_value());
  EXPECT_TRUE(b.start->position.isApprox(Vec2(0.1, 0.9)));
  EXPECT_TRUE(b.start->velocity_mps.isApprox(Vec2(1.5, -0.5)));
  // In the file's length unit, velocities per second; at rest is allowed.
  const Board mm = parse_board(
      "pinball-board 1\nunits mm\nsize 510 1070\nball 13.5 5000\ngravity 1110\ndt 0.0005\nballs 1\n"
      "launcher 450 50\nstart 255 800 -300 0\n",
      "t.board");
  ASSERT_TRUE(mm.start.has_value());
  EXPECT_TRUE(mm.start->position.isApprox(Vec2(0.255, 0.8)));
  EXPECT_TRUE(mm.start->velocity_mps.isApprox(Vec2(-0.3, 0.0)));
  EXPECT_TRUE(parse("start 0.25 0.5 0 0\n").start.has_value());
}

TEST(BoardLoaderErrors, StartIsOnTheTableClearAndFinite) {
  expect_body_error("start 0.1 0.9 1.5\n", 8, "start: expected 4 numbers (X Y VX VY), got 3");
  expect_body_error("start 0.1 nan 1.5 0\n", 8, "start: field Y is not a finite number: 'nan'");
  expect_body_error("start 0.1 0.9 inf 0\n", 8, "start: field VX is not a finite number: 'inf'");
  expect_body_error("start 0.1 0.9 1000 0\n", 8, "start: speed of fields VX VY must be at most 100 m/s, got 1000");
  expect_body_error("start 0.1 0.9 1 0\nstart 0.2 0.9 1 0\n", 9, "duplicate 'start' statement (first at line 8)");
  expect_body_error("start 0.1 1.2 0 0\n", 8, "start: ball at fields X Y (0.1, 1.2) m lies outside the table");
  expect_body_error("start -0.01 0.5 0 0\n", 8, "start: ball at fields X Y (-0.01, 0.5) m lies outside the table");
  expect_body_error("start 0.1 0.9 6 0\n", 8, "start: speed of fields VX VY (6 m/s) exceeds the ball's SPEED_MAX (5 m/s)");
  expect_body_error("start 0.1 0.5 0 0\ncircle 0.1 0.52 0.01 name=post\n", 8,
                    "start: ball at fields X Y (0.1, 0.5) m overlaps 'post' (distance 0.01 m, ball radius 0.0135 m)");
  expect_body_error("start 0.1 0.5 0 0\nflipper left 0.05 0.505 0.076 0 0.5 35 name=lf\n", 8,
                    "start: ball at fields X Y (0.1, 0.5) m overlaps flipper 'lf' in its down position");
  expect_body_error("start 0.1 0.5 0 0\nhole 0.1 0.51 0.02 eat name=drain\n", 8,
                    "start: ball at fields X Y starts inside hole 'drain'");
  expect_body_error("start 0.45 0.055 0 0.1\n", 8, "counts as resting in the launcher");
  // Inside a solid, clear of its edges: the distance test alone passed it.
  expect_body_error("start 0.2 0.5 0 0\npolygon 0.1 0.4 0.3 0.4 0.3 0.6 0.1 0.6 name=block\n", 8,
                    "start: ball at fields X Y (0.2, 0.5) m lies inside polygon 'block'");
}

// A no-break space in 'balls 1' read "unknown keyword 'balls 1'", which looks like a good line.
TEST(BoardLoaderErrors, AnInvisibleCharacterInAKeywordIsShown) {
  expect_body_error("circle\xc2\xa0" "0.3 0.5 0.01\n", 8,
                    "unknown keyword 'circle??0.3' (holding bytes that are not printable ASCII, shown as '?': a "
                    "no-break space");
}

// A coordinate with a digit too many (x = 5 m on a 0.51 m table) loaded: only 100 m from the origin was refused.
TEST(BoardLoaderErrors, APieceOffThePlayfieldIsRefusedAtItsLine) {
  expect_body_error("circle 5.0 0.5 0.01 name=far\n", 8,
                    "obstacle 'far' at (5, 0.5) m lies over 5 cm off the 0.51 x 1.07 m playfield of x.board");
  expect_body_error("wall 0.1 0.5 0.1 2.0\n", 8, "obstacle 'wall@8' at (0.1, 2) m lies over 5 cm off");
  expect_body_error("sensor circle 0.25 -0.2 0.01 name=s\n", 8, "sensor 's' at (0.25, -0.2) m lies");
  expect_body_error("flipper left 0.15 1.5 0.076 -0.5 0.5 35 name=lf\n", 8, "the pivot of flipper 'lf' at (0.15, 1.5)");
  EXPECT_NO_THROW(parse("circle 0.54 0.5 0.01\n"));  // on the rim: within 5 cm
}

// THETA -1e9 .. 1e9, and a stroke of 360 degrees, had been accepted (sim played them).
TEST(BoardLoaderErrors, FlipperAnglesAreElevationsWithinAQuarterTurn) {
  expect_body_error("flipper left 0.15 0.16 0.076 -0.5 6.0 35\n", 8,
                    "flipper: field THETA_MAX must be within +-1.5708 rad, got 6");
  expect_body_error("flipper right 0.35 0.16 0.076 -1e9 0.5 35\n", 8, "field THETA_MIN must be within +-1.5708 rad");
  expect_error("pinball-board 1\nangles deg\nsize 0.51 1.07\nball 0.0135 5\ngravity 1.11\nballs 3\n"
               "launcher 0.45 0.05\ndt 0.0005\nflipper left 0.15 0.16 0.076 -25 335 2000\n",
               9, "field THETA_MAX must be within +-90 deg, got 335");
  EXPECT_NO_THROW(parse("flipper left 0.15 0.16 0.076 -1.5 1.5 35\n"));
}

// A blade no longer than the ball's radius passes the chord rule at any speed: 1e5 rad/s, the whole
// stroke inside one step, had been played (the event stepper's guard holding the ball in mid-air).
TEST(BoardLoaderErrors, AFlipperTurnsNoFasterThanACoilCanTurnIt) {
  expect_body_error("flipper left 0.15 0.16 0.01 -0.5 0.5 100000\n", 8,
                    "flipper: field OMEGA must be at most 200 rad/s, got 1e+05");
  expect_error("pinball-board 1\nangles deg\nsize 0.51 1.07\nball 0.0135 5\ngravity 1.11\nballs 3\n"
               "launcher 0.45 0.05\ndt 0.0005\nflipper left 0.15 0.16 0.01 -25 30 20000\n",
               9, "field OMEGA must be at most 11459.2 deg/s, got 20000");
  EXPECT_NO_THROW(parse("flipper left 0.15 0.16 0.02 -0.5 0.5 200\n"));
  // A tip at or above the ball's speed clamp: the event stepper struck the ball again and again, frozen
  // mid-stroke, until its guard held it; mit1993's tips move at 2.65 m/s under a 5 m/s clamp.
  expect_body_error("flipper left 0.15 0.16 0.076 -0.5 0.5 70 name=lf\n", 8,
                    "flipper: flipper 'lf': its tip moves at 5.32 m/s (OMEGA x LENGTH), not below the ball's speed "
                    "clamp SPEED_MAX 5 m/s: a struck ball, held to the clamp, could never leave the blade");
  EXPECT_NO_THROW(parse("flipper left 0.15 0.16 0.076 -0.5 0.5 60\n"));
}

// Found by a helper: mu=1e300 overflowed the speed clamp to a stopped ball, and score=1e308
// a game's sum to inf (the report's mean: nan).
TEST(BoardLoaderErrors, FrictionAndPointsHaveUpperBounds) {
  expect_body_error("flipper left 0.15 0.16 0.076 -0.4 0.5 35 mu=1e300\n", 8, "attribute mu must be at most 10");
  expect_body_error("circle 0.2 0.5 0.01 score=1e308\n", 8, "attribute score must be at most 1e+06");
  expect_body_error("circle 0.2 0.5 0.01 score=-5\n", 8, "attribute score must be >= 0");
  expect_body_error("circle 0.2 0.5 0.01 contact=-1\n", 8, "attribute contact must be >= 0");
  expect_body_error("bank b bonus=1e9\n", 8, "attribute bonus must be at most 1e+06");
  // The value refused is shown to its last digit: rounded, it read "at most 2, got 2".
  expect_body_error("circle 0.2 0.5 0.01 rho=2.0000001\n", 8, "attribute rho must be at most 2, got 2.0000001");
}

// Found by a helper: each of these loaded, and the ball then began, or went, inside a solid.
TEST(BoardLoaderErrors, NoBallBeginsInsideASolid) {
  // A bow tie: one lobe's edges faced in, and a ball was trapped in it for good.
  expect_body_error("polygon 0.05 0.4 0.4 0.7 0.4 0.5 0.05 0.7 name=bowtie\n", 8,
                    "polygon: edges 1 and 3 cross: a polygon's outline must not cross itself");
  // A hole kicks the ball out at its centre: not onto a post, not into a wall.
  expect_body_error("circle 0.25 0.5 0.01 name=post\nhole 0.25 0.5 0.05 kickout=0,2 name=saucer\n", 9,
                    "hole: the ball kicked out at its centre overlaps 'post'");
  expect_body_error("polygon 0.2 0.4 0.3 0.4 0.3 0.6 0.2 0.6 name=block\nhole 0.25 0.5 0.01 kickout=0,2\n", 9,
                    "hole: the ball kicked out at its centre lies inside polygon 'block'");
  // The launcher (line 7) inside a solid.
  expect_body_error("polygon 0.4 0.0 0.5 0.0 0.5 0.2 0.4 0.2 name=block\n", 7,
                    "launcher: ball at the launch position lies inside polygon 'block'");
}

TEST(BoardLoaderErrors, LaunchTooSlowToLeaveTheLauncher) {
  // √(2·1.11·0.0135 + 0.05²) + 1.11·0.0005 ≈ 0.1807 m/s; 0.03·0.97·5 = 0.1455.
  const std::string head =
      "pinball-board 1\nsize 0.51 1.07\nball 0.0135 5\ngravity 1.11\ndt 0.0005\nballs 3\n";
  expect_error(head + "launcher 0.45 0.05 pull=0.03\n", 7,
               "launcher: attribute pull=0.03 launches as slowly as 0.1455 m/s (pull x (1 - noise) x SPEED_MAX), "
               "below the 0.180749 m/s");
  EXPECT_NO_THROW(parse_board(head + "launcher 0.45 0.05 pull=0.04\n", "t.board"));  // 0.194 m/s
  // The noise counts: the slowest launch is the one that matters.
  expect_error(head + "launcher 0.45 0.05 pull=0.04 noise=0.5\n", 7, "launches as slowly as 0.1 m/s");
  // Without gravity a launch still has to beat the launcher's still speed.
  expect_error("pinball-board 1\nsize 0.51 1.07\nball 0.0135 5\ngravity 0\ndt 0.0005\nballs 3\n"
               "launcher 0.45 0.05 pull=0.005 noise=0\n",
               7, "attribute pull=0.005 launches as slowly as 0.025 m/s");
  // In a `units mm` file the speeds are stated in mm/s, as every bound is.
  expect_error("pinball-board 1\nunits mm\nsize 510 1070\nball 13.5 5000\ngravity 1110\ndt 0.0005\nballs 3\n"
               "launcher 450 50 pull=0.03\n",
               8, "launches as slowly as 145.5 mm/s (pull x (1 - noise) x SPEED_MAX), below the 180.749 mm/s");
  expect_error("pinball-board 1\nunits mm\nsize 510 1070\nball 13.5 5000\ngravity 1110\ndt 0.0005\nballs 1\n"
               "launcher 450 50\nstart 100 500 0 0\ncircle 100 520 10 name=post\n",
               9, "overlaps 'post' (distance 10 mm, ball radius 13.5 mm)");
  // A board that serves from `start` never launches.
  EXPECT_NO_THROW(parse_board(head + "launcher 0.45 0.05 pull=0.03\nstart 0.25 0.5 0 0\n", "t.board"));
}

TEST(BoardLoader, CommentsBlankLinesTabsAndCrlf) {
  const Board b = parse_board(
      "# a comment line\r\n"
      "\r\n"
      "pinball-board 1\r\n"
      "size\t0.51 1.07  # trailing comment\r\n"
      "ball 0.0135 5\nballs 1\ngravity 1.11\ndt 0.0005\nlauncher 0.45 0.05\n"
      "   \t \n"
      "circle 0.1 0.1 0.01#no space before comment\n",
      "c.board");
  EXPECT_DOUBLE_EQ(b.width_m, 0.51);
  EXPECT_EQ(b.balls_per_game, 1);
  ASSERT_EQ(b.obstacles.size(), 1u);
  EXPECT_EQ(b.obstacles[0].source_line, 11);
}

// What editors write: a byte-order mark first, CR alone at each line end (old
// Mac). Both read as the plain file, with its line numbers. A NUL byte is no
// text: refused at its line (it read as a silent end of a statement).
TEST(BoardLoader, AByteOrderMarkAndLoneCrLineEndsReadLikeThePlainFile) {
  const std::string body = "circle 0.1 0.5 0.01\ncircle 0.2 0.5 0.01 name=c\n";
  const Board plain = parse(body);
  std::string mac = std::string(kHead) + body;
  std::replace(mac.begin(), mac.end(), '\n', '\r');
  for (const std::string& text : {"\xEF\xBB\xBF" + std::string(kHead) + body, mac}) {
    const Board b = parse_board(text, "t.board");
    ASSERT_EQ(b.obstacles.size(), plain.obstacles.size());
    EXPECT_EQ(b.obstacles[1].source_line, 9);
    EXPECT_EQ(b.obstacles[1].name, "c");
  }
  expect_error(std::string(kHead) + "circle 0.1 0.5\r\n0.01\n" + std::string(1, '\0') + "\n", 10,
               "a NUL byte (at byte ");
  expect_error(mac + std::string(1, '\0'), 10, "a board file is text");
}

// ---- errors: each names the file, the line and what is wrong ----

TEST(BoardLoaderErrors, UnknownKeyword) { expect_body_error("cirle 0.1 0.1 0.01\n", 8, "unknown keyword 'cirle'"); }

TEST(BoardLoaderErrors, UnknownAttribute) {
  expect_body_error("circle 0.1 0.1 0.01 colour=red\n", 8, "circle: unknown attribute 'colour'");
  expect_body_error("line 0.1 0.1 0.2 0.1 hiden\n", 8, "line: unknown attribute 'hiden'");
}

TEST(BoardLoaderErrors, AttributeNotAllowedOnThisKind) {
  expect_body_error("wall 0.1 0.1 0.2 0.1 two-sided\n", 8, "wall: attribute 'two-sided' does not apply to 'wall'");
  expect_body_error("sensor circle 0.1 0.5 0.01 kick=3\n", 8, "attribute 'kick' does not apply to 'sensor'");
  expect_body_error("flipper left 0.1 0.2 0.076 -0.5 0.5 35 score=1\n", 8, "attribute 'score' does not apply");
}

// An overlay names what it changes (obstacle_groups[].obstacles, flippers[].name): two statements
// of one name were both changed, or the one meant was not.
TEST(BoardLoaderErrors, TwoStatementsOfOneNameAreRefusedAtTheSecond) {
  const std::string taken = "' is already line 8's: an overlay names obstacles, flippers and sensors by it";
  expect_body_error("circle 0.1 0.5 0.01 name=post\ncircle 0.2 0.5 0.01 name=post\n", 9,
                    "circle: attribute name 'post" + taken);
  expect_body_error("circle 0.1 0.5 0.01 name=left\nflipper left 0.1 0.2 0.076 -0.5 0.5 35 name=left\n", 9,
                    "attribute name 'left" + taken);
  expect_body_error("circle 0.1 0.5 0.01\nsensor circle 0.3 0.5 0.01 name=circle@8\n", 9,
                    "attribute name 'circle@8" + taken);
  EXPECT_EQ(parse("circle 0.1 0.5 0.01 name=a\ncircle 0.2 0.5 0.01 name=b\n").obstacles.size(), 2u);
}

// name=bot,tom gave a trace row of 7 columns; name=a|lost an event "hit:a|lost" that reads as a lost ball.
TEST(BoardLoaderErrors, ANameThatATraceWouldSplitIsRefused) {
  for (const std::string bad : {"bot,tom", "a|lost", "say\"hi\""}) {
    expect_body_error("circle 0.1 0.5 0.01 name=" + bad + "\n", 8,
                      "attribute name '" + bad + "' may not contain ',', '|' or '\"'");
  }
  EXPECT_EQ(parse("circle 0.1 0.5 0.01 name=bumper_1.left-top\n").obstacles.size(), 1u);
}

TEST(BoardLoaderErrors, AttributeMisuse) {
  expect_body_error("circle 0.1 0.5 0.01 rho=1 rho=2\n", 8, "attribute 'rho' given twice");
  expect_body_error("circle 0.1 0.5 0.01 eat=1\n", 8, "attribute 'eat' is a flag and takes no value");
  expect_body_error("circle 0.1 0.5 0.01 rho=\n", 8, "attribute 'rho' needs a value");
  expect_body_error("circle 0.1 0.5 rho=1 0.01\n", 8, "'0.01' after the attributes");
  expect_body_error("circle 0.1 0.5 0.01 rho=-1\n", 8, "circle: attribute rho must be >= 0, got -1");
  expect_body_error("circle 0.1 0.5 0.01 kick=-2\n", 8, "attribute kick must be >= 0, got -2");
  expect_body_error("wall 0.1 0.5 0.2 0.5 friction=-0.1\n", 8, "wall: attribute friction must be >= 0, got -0.1");
  expect_body_error("wall 0.1 0.5 0.2 0.5 friction=2.5\n", 8, "wall: attribute friction must be at most 2, got 2.5");
  expect_body_error("circle 0.1 0.5 0.01 score=lots\n", 8, "attribute score is not a finite number: 'lots'");
  expect_error("pinball-board 1\nlauncher 1 1 pull=1.5\n", 2, "launcher: attribute pull must be in (0, 1], got 1.5");
  expect_error("pinball-board 1\nlauncher 1 1 noise=0.6\n", 2, "attribute noise must be in [0, 0.5], got 0.6");
}

TEST(BoardLoaderErrors, WrongNumberOfNumbers) {
  expect_body_error("line 0.1 0.2 0.3\n", 8, "line: expected 4 numbers (X1 Y1 X2 Y2), got 3");
  expect_body_error("circle 0.1 0.2 0.3 0.4\n", 8, "circle: expected 3 numbers (X Y R), got 4");
  expect_body_error("polyline 0.1 0.2 0.3\n", 8, "polyline: expected at least 2 vertices");
  expect_body_error("polygon 0.1 0.2 0.3 0.2\n", 8, "polygon: expected at least 3 vertices");
  expect_body_error("flipper left 0.1 0.2 0.076 -0.5 0.5\n", 8,
                    "expected 6 numbers (PX PY LENGTH THETA_MIN THETA_MAX OMEGA), got 5");
  expect_error("pinball-board 1\nsize 0.5\n", 2, "size: expected 2 numbers (W H), got 1");
}

TEST(BoardLoaderErrors, NotANumber) {
  expect_body_error("line 0.1 1.5x 0.3 0.4\n", 8, "line: field Y1 is not a finite number: '1.5x'");
  expect_body_error("polyline 0.1 0.2 0.3 zero\n", 8, "polyline: field Y2 is not a finite number: 'zero'");
  expect_body_error("flipper up 0.1 0.2 0.076 -0.5 0.5 35\n", 8, "field SIDE must be 'left' or 'right', got 'up'");
  expect_body_error("sensor square 0.1 0.2 0.3\n", 8, "field SHAPE must be 'line' or 'circle', got 'square'");
  expect_error("pinball-board 1\nunits cm\n", 2, "units: expected 'm' or 'mm', got 'cm'");
}

TEST(BoardLoaderErrors, NanAndInfinity) {
  expect_body_error("line 0.1 nan 0.3 0.4\n", 8, "line: field Y1 is not a finite number: 'nan'");
  expect_body_error("circle 0.1 0.2 inf\n", 8, "circle: field R is not a finite number: 'inf'");
  expect_body_error("circle -infinity 0.2 0.1\n", 8, "field X is not a finite number: '-infinity'");
  expect_body_error("circle 1e999 0.2 0.1\n", 8, "field X is not a finite number: '1e999'");
  expect_error("pinball-board 1\ngravity NaN\n", 2, "gravity: field G is not a finite number: 'NaN'");
}

TEST(BoardLoaderErrors, OutOfRangeFields) {
  expect_body_error("circle 0.1 0.5 -3\n", 8, "circle: field R (radius) must be >= 0, got -3");
  expect_body_error("hole 0.1 0.5 0\n", 8, "hole: field R (radius) must be > 0, got 0");
  expect_error("pinball-board 1\nball 0 5\n", 2, "ball: field R (radius) must be > 0, got 0");
  expect_error("pinball-board 1\nsize 0.5 -1\n", 2, "size: field H (height) must be > 0, got -1");
  expect_error("pinball-board 1\ngravity -1\n", 2, "gravity: field G must be >= 0, got -1");
  expect_error("pinball-board 1\ndt 0\n", 2, "dt: field DT (seconds) must be > 0, got 0");
  expect_error("pinball-board 1\nballs 2.5\n", 2, "balls: field N (balls per game) must be an integer >= 1, got 2.5");
  expect_error("pinball-board 1\nballs 0\n", 2, "must be an integer >= 1, got 0");
  expect_error("pinball-board 2\n", 1, "pinball-board: unsupported format version 2");
  expect_body_error("flipper left 0.1 0.2 0 -0.5 0.5 35\n", 8, "flipper: field LENGTH must be > 0, got 0");
  expect_body_error("flipper left 0.1 0.2 0.07 -0.5 0.5 -1\n", 8, "flipper: field OMEGA must be > 0, got -1");
  expect_body_error("flipper left 0.1 0.2 0.07 -0.5 0.5 35 mu=-1\n", 8, "attribute mu must be >= 0, got -1");
}

TEST(BoardLoaderErrors, TimeStepIsBounded) {
  // 1e-12 s would make every ball take forever; 0.1 s jumps through posts.
  expect_error("pinball-board 1\ndt 1e-12\n", 2, "dt: field DT (seconds) must be in [1e-06, 0.01], got 1e-12");
  expect_error("pinball-board 1\ndt 0.1\n", 2, "dt: field DT (seconds) must be in [1e-06, 0.01], got 0.1");
  std::string head = kHead;
  for (const char* dt : {"dt 1e-6\n", "dt 0.01\n"}) {
    const std::string text = head.replace(head.find("dt 0.0005\n"), 10, dt);
    EXPECT_NO_THROW(parse_board(text, "x.board")) << dt;
    head = kHead;
  }
}

TEST(BoardLoaderErrors, SizesSpeedsAndGravityAreBounded) {
  expect_error("pinball-board 1\nsize 20 1\n", 2, "size: field W (width) must be at most 10 m, got 20");
  // The bound is stated in the file's unit.
  expect_error("pinball-board 1\nunits mm\nsize 510 1070000\n", 3,
               "size: field H (height) must be at most 10000 mm, got 1070000");
  expect_error("pinball-board 1\nball 0.5 5\n", 2, "ball: field R (radius) must be at most 0.1 m, got 0.5");
  // 1e-300 m was accepted (a board without flippers played it): below 1 mm the contact tolerance is the ball.
  expect_error("pinball-board 1\nball 1e-300 5\n", 2, "ball: field R (radius) must be at least 0.001 m, got 1e-300");
  expect_error("pinball-board 1\nunits mm\nball 0.5 5000\n", 3, "field R (radius) must be at least 1 mm, got 0.5");
  expect_error("pinball-board 1\nball 0.0135 500\n", 2, "ball: field SPEED_MAX must be at most 100 m/s, got 500");
  expect_error("pinball-board 1\ngravity 11\n", 2, "gravity: field G must be at most 10 m/s^2, got 11");
  expect_error("pinball-board 1\nunits mm\ngravity 98100\n", 3, "gravity: field G must be at most 10000 mm/s^2");
  expect_body_error("circle 0.1 0.5 20\n", 8, "circle: field R (radius) must be at most 10 m, got 20");
  expect_body_error("hole 0.1 0.5 11 eat\n", 8, "hole: field R (radius) must be at most 10 m, got 11");
  expect_body_error("flipper left 0.1 0.2 50 -0.5 0.5 1\n", 8, "flipper: field LENGTH must be at most 10 m, got 50");
  EXPECT_NO_THROW(parse("circle 0.3 0.9 0.01 rho=2 kick=100\n"));
}

TEST(BoardLoaderErrors, RestitutionAndKicksAreBounded) {
  expect_body_error("circle 0.1 0.5 0.01 rho=2.5\n", 8, "circle: attribute rho must be at most 2, got 2.5");
  expect_body_error("defaults rho=3\n", 8, "defaults: attribute rho must be at most 2, got 3");
  expect_body_error("flipper left 0.1 0.2 0.07 -0.5 0.5 35 rho=5\n", 8, "flipper: attribute rho must be at most 2, got 5");
  expect_body_error("circle 0.1 0.5 0.01 kick=200\n", 8, "circle: attribute kick must be at most 100 m/s, got 200");
  expect_body_error("hole 0.1 0.5 0.02 kickout=1000,0\n", 8,
                    "hole: attribute kickout speed must be at most 100 m/s, got 1000");
}

TEST(BoardLoaderErrors, PositionsAreBounded) {
  expect_body_error("point 1e300 0.5\n", 8,
                    "point: fields X Y must lie within 100 m of the origin on each axis, got (1e+300, 0.5)");
  expect_body_error("line 0 0 0.1 -200\n", 8, "line: fields X2 Y2 must lie within 100 m");
  expect_body_error("polyline 0 0 1 1 0 1e9\n", 8, "polyline: vertex 3 must lie within 100 m");
  expect_body_error("flipper left 1e6 0.2 0.07 -0.5 0.5 35\n", 8, "flipper: fields PX PY must lie within 100 m");
  expect_error("pinball-board 1\nunits mm\nlauncher 450 -1e6\n", 3,
               "launcher: fields X Y must lie within 100000 mm of the origin on each axis, got (450, -1e+06)");
}

TEST(BoardLoaderErrors, ZeroLengthSegments) {
  expect_body_error("line 0.1 0.2 0.1 0.2\n", 8, "line: zero-length segment");
  expect_body_error("wall 0.1 0.2 0.1 0.2\n", 8, "wall: zero-length segment");
  expect_body_error("sensor line 0.1 0.2 0.1 0.2\n", 8, "sensor: zero-length segment");
  expect_body_error("polyline 0.1 0.2 0.3 0.2 0.3 0.2\n", 8, "polyline: zero-length segment (vertices 2 and 3)");
  expect_body_error("polygon 0.1 0.2 0.3 0.2 0.3 0.4 0.1 0.2\n", 8, "polygon: zero-length segment (vertices 4 and 1)");
  expect_body_error("polygon 0.1 0.2 0.2 0.2 0.3 0.2\n", 8, "polygon: the vertices enclose no area");
}

TEST(BoardLoaderErrors, FlipperThetaMinNotBelowThetaMax) {
  expect_body_error("flipper left 0.1 0.2 0.076 0.5 0.5 35\n", 8,
                    "flipper: field THETA_MIN (0.5) must be less than THETA_MAX (0.5)");
  expect_body_error("flipper right 0.1 0.2 0.076 0.6 -0.5 35\n", 8, "THETA_MIN (0.6) must be less than THETA_MAX");
}

TEST(BoardLoaderErrors, FlipperTooFastForTheTimeStep) {
  // A 0.1 m blade at 45 rad/s (tip 4.5 m/s, under the clamp): 0.1 * sin(45 * 0.0005 / 2) = 1.1 mm at
  // dt 0.5 ms, fine; 0.1 * sin(45 * 0.008 / 2) = 17.9 mm > 13.5 mm at dt 8 ms.
  const std::string head =
      "pinball-board 1\nsize 0.51 1.07\nball 0.0135 5\ngravity 1.11\nballs 3\nlauncher 0.45 0.05\n";
  EXPECT_NO_THROW(parse("point 0.3 0.9\nflipper left 0.1 0.2 0.1 -0.5 0.5 45\n"));
  expect_error(head + "dt 0.008\nflipper left 0.1 0.2 0.1 -0.5 0.5 45 name=lf\n", 8, "l*sin(omega*dt/2)");
  expect_error(head + "dt 0.008\nflipper left 0.1 0.2 0.1 -0.5 0.5 45 name=lf\n", 8, "flipper: flipper 'lf'");
  // dt after the flipper still counts: the check runs on the whole file.
  expect_error(head + "flipper left 0.1 0.2 0.1 -0.5 0.5 45\ndt 0.008\n", 7, "l*sin(omega*dt/2)");
  // Said in the file's unit.
  expect_error("pinball-board 1\nunits mm\nsize 510 1070\nball 13.5 5000\ngravity 1110\nballs 3\nlauncher 450 50\n"
               "dt 0.008\nflipper left 100 200 100 -0.5 0.5 45 name=lf\n",
               9, "l*sin(omega*dt/2) = 17.903 mm is not below the ball radius 13.5 mm at dt = 0.008 s");
}

TEST(BoardLoaderErrors, BallAtTheLauncherOverlaps) {
  expect_body_error("point 0.3 0.9\nwall 0.44 0.0 0.44 0.2\n", 7,
                    "launcher: ball at the launch position overlaps 'wall@9'");
  expect_body_error("circle 0.45 0.1 0.04 name=post\n", 7, "overlaps 'post'");
  // A one-sided line counts from either side.
  expect_body_error("line 0.4 0.06 0.5 0.06\n", 7, "overlaps 'line@8'");
  expect_body_error("line 0.5 0.06 0.4 0.06\n", 7, "overlaps 'line@8'");
  // Flipper in its down position: pivot left of the launcher, tip lowered onto it.
  expect_body_error("flipper left 0.38 0.09 0.076 -0.5 0.5 35 name=lf\n", 7, "overlaps flipper 'lf'");
  // Just clear of an obstacle is fine; a sensor that only counts never blocks.
  EXPECT_NO_THROW(parse("circle 0.45 0.0837 0.02\nsensor circle 0.45 0.05 0.01 score=5\n"));
  // One that takes the ball at once is refused: every ball was lost at its first step, scoring 0.
  expect_body_error("hole 0.45 0.05 0.01 eat name=h\n", 7,
                    "launcher: ball at the launch position starts inside hole 'h'");
  expect_body_error("sensor line 0.4 0.06 0.5 0.06 eat name=s\n", 7, "starts inside eating sensor 's'");
  EXPECT_NO_THROW(parse("flipper left 0.38 0.09 0.076 0.1 0.5 35\n"));  // raised rest clears the ball
}

TEST(BoardLoaderErrors, MissingRequiredStatement) {
  try {
    parse_board("pinball-board 1\nsize 0.51 1.07\ngravity 1.11\ndt 0.0005\nballs 3\nlauncher 0.45 0.05\n", "x.board");
    FAIL() << "no error";
  } catch (const BoardError& e) {
    EXPECT_EQ(e.line(), 0);
    EXPECT_STREQ(e.what(), "x.board: missing required 'ball' statement");
  }
  expect_error("", 0, "x.board: missing required 'pinball-board' statement");
  expect_error("# only a comment\n", 0, "missing required 'pinball-board'");
  expect_error("pinball-board 1\nsize 1 1\nball 0.01 1\ngravity 1\ndt 0.001\nballs 1\n", 0,
               "missing required 'launcher' statement");
}

TEST(BoardLoaderErrors, HeaderMustComeFirst) {
  expect_error("size 0.51 1.07\npinball-board 1\n", 1, "expected 'pinball-board 1' as the first statement, got 'size'");
}

TEST(BoardLoaderErrors, DuplicateSingleton) {
  expect_body_error("point 0.3 0.9\nball 0.01 4\n", 9, "duplicate 'ball' statement (first at line 3)");
  expect_body_error("launcher 0.3 0.05\n", 8, "duplicate 'launcher' statement (first at line 7)");
  expect_error("pinball-board 1\nunits mm\nunits mm\n", 3, "duplicate 'units' statement (first at line 2)");
}

TEST(BoardLoaderErrors, UnitsAndAnglesAfterGeometry) {
  expect_error("pinball-board 1\nsize 0.51 1.07\nunits mm\n", 3,
               "units: must come before the first statement that uses a length or angle (line 2)");
  // Millimetres read as metres are refused at once: the table would be half a kilometre wide.
  expect_error("pinball-board 1\nsize 510 1070\nunits mm\n", 2, "size: field W (width) must be at most 10 m, got 510");
  expect_body_error("angles deg\n", 8, "angles: must come before the first statement that uses a length or angle");
  // Statements without lengths may come first.
  EXPECT_NO_THROW(parse_board(
      "pinball-board 1\ndt 0.0005\nballs 3\ndefaults rho=0.5\nunits mm\nangles deg\nsize 510 1070\n"
      "ball 13.5 5000\ngravity 1110\nlauncher 450 50\n",
      "x.board"));
}

TEST(BoardLoaderErrors, Banks) {
  expect_body_error("circle 0.1 0.5 0.01 bank=drops\n", 8, "circle: attribute bank names an undeclared bank 'drops'");
  // Declared below its member is too late.
  expect_body_error("circle 0.1 0.5 0.01 bank=drops\nbank drops bonus=5\n", 8, "undeclared bank 'drops'");
  expect_body_error("bank drops bonus=5\nbank drops bonus=6\n", 9, "bank: bank 'drops' is declared twice");
  expect_body_error("bank drops\n", 8, "bank: needs bonus=POINTS");
  expect_body_error("point 0.3 0.9\nbank drops bonus=5\n", 9, "bank: bank 'drops' has no members");
}

TEST(BoardLoaderErrors, HoleNeedsEatOrKickout) {
  expect_body_error("hole 0.1 0.5 0.02 score=5\n", 8, "hole: needs exactly one of 'eat' or 'kickout=VX,VY'");
  expect_body_error("hole 0.1 0.5 0.02 eat kickout=1,1\n", 8, "needs exactly one of 'eat' or 'kickout=VX,VY'");
  expect_body_error("hole 0.1 0.5 0.02 kickout=1\n", 8, "hole: attribute kickout must be VX,VY, got '1'");
  expect_body_error("hole 0.1 0.5 0.02 kickout=1,x\n", 8, "attribute kickout VY is not a finite number: 'x'");
}

TEST(BoardLoaderErrors, UnreadableFile) {
  const std::string path = "/nonexistent/dir/table.board";
  try {
    load_board(path);
    FAIL() << "no error";
  } catch (const BoardError& e) {
    EXPECT_EQ(e.file(), path);
    EXPECT_EQ(e.line(), 0);
    EXPECT_EQ(std::string(e.what()).rfind(path + ": cannot open board file", 0), 0u) << e.what();
  }
}

// ---- the scene files in boards/scenes ----

Board load_scene(const std::string& name) {
  return load_board(std::string(PINBALL_SOURCE_DIR) + "/boards/scenes/" + name);
}

void expect_realistic_mm_constants(const Board& b) {
  EXPECT_DOUBLE_EQ(b.ball.radius_m, 0.0135);
  EXPECT_DOUBLE_EQ(b.ball.speed_max_mps, 5.0);
  EXPECT_DOUBLE_EQ(b.gravity_mps2, 1.11);
  EXPECT_DOUBLE_EQ(b.dt_s, 0.0005);
  EXPECT_DOUBLE_EQ(b.width_m, 0.51);
  EXPECT_DOUBLE_EQ(b.height_m, 1.07);
}

TEST(BoardScenes, Line) {
  const Board b = load_scene("line.board");
  expect_realistic_mm_constants(b);
  EXPECT_NE(b.source.find("line.board"), std::string::npos);
  ASSERT_EQ(b.shapes.size(), 1u);
  EXPECT_EQ(b.shapes[0].kind, ShapeKind::kLine);
  EXPECT_DOUBLE_EQ(b.shapes[0].p0.y(), b.shapes[0].p1.y());  // horizontal
  EXPECT_TRUE(b.shapes[0].normal.isApprox(Vec2(0, 1)));
  EXPECT_GT(b.launcher.position.y(), b.shapes[0].p0.y());   // the ball starts above it
  EXPECT_TRUE(b.flippers.empty());
}

TEST(BoardScenes, Box) {
  const Board b = load_scene("box.board");
  expect_realistic_mm_constants(b);
  ASSERT_EQ(b.shapes.size(), 16u);  // four walls
  EXPECT_TRUE(b.flippers.empty());
  // Closed: the launcher is inside the walls' bounding box and every wall end meets another.
  Vec2 lo = b.shapes[0].p0, hi = lo;
  for (const Shape& s : b.shapes) {
    lo = lo.cwiseMin(s.p0);
    hi = hi.cwiseMax(s.p0);
  }
  EXPECT_TRUE((b.launcher.position.array() > lo.array()).all());
  EXPECT_TRUE((b.launcher.position.array() < hi.array()).all());
  for (const Shape& s : b.shapes) {
    if (s.kind != ShapeKind::kLine) continue;
    int meets = 0;
    for (const Shape& t : b.shapes) meets += t.kind == ShapeKind::kLine && t.p0.isApprox(s.p1);
    EXPECT_EQ(meets, 2) << "each segment end starts two segments (the next wall, both directions)";
  }
}

TEST(BoardScenes, Wedge) {
  const Board b = load_scene("wedge.board");
  expect_realistic_mm_constants(b);
  ASSERT_EQ(b.shapes.size(), 8u);  // two walls
  EXPECT_TRUE(b.shapes[0].p1.isApprox(b.shapes[4].p1));  // they meet at the bottom
  EXPECT_GT(b.launcher.position.y(), b.shapes[0].p0.y());
  EXPECT_TRUE(b.flippers.empty());
}

TEST(BoardScenes, Flipper) {
  const Board b = load_scene("flipper.board");
  expect_realistic_mm_constants(b);
  ASSERT_EQ(b.flippers.size(), 1u);
  const Flipper& f = b.flippers[0];
  EXPECT_EQ(f.side, Side::kLeft);
  EXPECT_DOUBLE_EQ(f.length_m, 0.076);
  EXPECT_NEAR(f.omega_rad_s, 2000 * kDeg, 1e-9);
  EXPECT_LT(f.theta_min_rad, f.theta_max_rad);
  EXPECT_LT(f.length_m * std::sin(f.omega_rad_s * b.dt_s / 2), b.ball.radius_m);
  ASSERT_EQ(b.shapes.size(), 1u);  // the floor
  EXPECT_LT(b.shapes[0].p0.y(), flipper_tip(f, f.theta_min_rad).y());
}

}  // namespace
}  // namespace pinball::table
