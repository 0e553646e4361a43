#include "drain_cause.h"

#include <cmath>

#include <gtest/gtest.h>

#include "common/thesis_board.h"

namespace pinball::bench {
namespace {

using pinball::testing::thesis_board;

sim::GameState at(double x_m, double y_m) {
  sim::GameState s = sim::make_game_state(thesis_board(), 1);
  s.ball.position_m = Vec2(x_m, y_m);
  return s;
}

TEST(DrainCause, ZonesAreTheThesisTablesPivots) {
  const DrainZones z = drain_zones(thesis_board());
  EXPECT_DOUBLE_EQ(z.line_y_m, 0.160);
  EXPECT_DOUBLE_EQ(z.centre_min_x_m, 0.165);
  EXPECT_DOUBLE_EQ(z.centre_max_x_m, 0.345);
  table::Board one = thesis_board();
  one.flippers.pop_back();
  EXPECT_EQ(classify_drain(drain_zones(one), 0.25), DrainCause::kOther) << "no gap without two flippers";
}

TEST(DrainCause, ClassifiesByWhereTheBallWentDownPastThePivots) {
  const DrainZones z = drain_zones(thesis_board());
  EXPECT_EQ(classify_drain(z, 0.02), DrainCause::kLeftOutlane);
  EXPECT_EQ(classify_drain(z, 0.25), DrainCause::kCentre);
  EXPECT_EQ(classify_drain(z, 0.165), DrainCause::kCentre);
  EXPECT_EQ(classify_drain(z, 0.40), DrainCause::kRightOutlane);
  EXPECT_EQ(classify_drain(z, std::nan("")), DrainCause::kOther);
  EXPECT_EQ(drain_cause_name(DrainCause::kCentre), "centre");
}

TEST(DrainCause, WatchKeepsTheLastDownwardCrossingSinceTheLaunch) {
  const DrainZones z = drain_zones(thesis_board());
  DrainWatch w(at(0.49, 0.054), z);
  w(at(0.49, 0.054), sim::StepEvents{sim::StepEvents::kLaunch});
  w(at(0.49, 0.30), {});  // up the chute: not a crossing
  EXPECT_TRUE(std::isnan(w.crossing_x_m()));
  w(at(0.02, 0.17), {});
  w(at(0.04, 0.15), {});  // down past 0.16 halfway between the two steps
  EXPECT_NEAR(w.crossing_x_m(), 0.03, 1e-12);
  w(at(0.25, 0.20), {});  // back up (a bounce)
  w(at(0.25, 0.10), {});
  EXPECT_NEAR(w.crossing_x_m(), 0.25, 1e-12);
  w(at(0.49, 0.054), sim::StepEvents{sim::StepEvents::kBallLost});  // moved to the launcher: ignored
  EXPECT_NEAR(w.crossing_x_m(), 0.25, 1e-12);
  w(at(0.49, 0.054), sim::StepEvents{sim::StepEvents::kLaunch});
  EXPECT_TRUE(std::isnan(w.crossing_x_m())) << "a new launch forgets the old crossing";
}

sim::GameState at_time(double x_m, double y_m, double t_s) {
  sim::GameState s = at(x_m, y_m);
  s.time_s = t_s;
  return s;
}

TEST(DrainCause, WatchKeepsTheTimeFromTheLastFlipperTouchToTheCrossing) {
  const DrainZones z = drain_zones(thesis_board());
  sim::StepEvents touch;
  touch.flags = sim::StepEvents::kHitFlipper;
  sim::StepEvents push;
  push.flags = sim::StepEvents::kFlipperPush;
  DrainWatch w(at(0.49, 0.054), z);
  w(at_time(0.49, 0.054, 0.0), sim::StepEvents{sim::StepEvents::kLaunch});
  w(at_time(0.30, 0.17, 1.0), {});
  w(at_time(0.30, 0.15, 1.1), {});  // down past the line with no flipper touch since the launch
  EXPECT_NEAR(w.crossing_x_m(), 0.30, 1e-12);
  EXPECT_TRUE(std::isnan(w.crossing_after_flipper_s())) << "no flipper touched it";
  w(at_time(0.25, 0.18, 2.0), touch);
  w(at_time(0.25, 0.30, 2.5), push);  // the last touch: a push at 2.5 s
  w(at_time(0.02, 0.17, 5.0), {});
  w(at_time(0.02, 0.15, 5.2), {});
  EXPECT_NEAR(w.crossing_after_flipper_s(), 5.2 - 2.5, 1e-12);
  w(at_time(0.49, 0.054, 5.3), sim::StepEvents{sim::StepEvents::kBallLost});
  EXPECT_NEAR(w.crossing_after_flipper_s(), 2.7, 1e-12) << "kept past the loss";
  w(at_time(0.49, 0.054, 5.4), sim::StepEvents{sim::StepEvents::kLaunch});
  EXPECT_TRUE(std::isnan(w.crossing_after_flipper_s())) << "a new launch forgets it";
  w(at_time(0.02, 0.17, 6.0), {});
  w(at_time(0.02, 0.15, 6.1), {});
  EXPECT_TRUE(std::isnan(w.crossing_after_flipper_s())) << "and the old ball's touches";
}

TEST(DrainCause, CountsAddUp) {
  DrainCounts c;
  c.add(DrainCause::kLeftOutlane, false);
  c.add(DrainCause::kCentre, true);
  c.add(DrainCause::kRightOutlane, false);
  c.add(DrainCause::kOther, true);
  EXPECT_EQ(c.total(), 4);
  EXPECT_EQ(c.left_table, 2);
  EXPECT_EQ(c.left_outlane + c.right_outlane + c.centre + c.other, 4);
}

}  // namespace
}  // namespace pinball::bench
