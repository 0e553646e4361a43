#include "pinball/learn/planning_controller.h"

#include <gtest/gtest.h>

#include <cmath>

#include "common/thesis_board.h"
#include "pinball/control/actuator_controller.h"
#include "pinball/control/spastic_controller.h"
#include "pinball/learn/evaluator.h"
#include "pinball/track/trajectory_fit.h"

namespace pinball::learn {
namespace {

using pinball::testing::thesis_board;

control::PlannerSettings short_planner() {
  control::PlannerSettings s;
  s.fire_frames = 3;
  s.horizon_s = 1.0;
  return s;
}

// What the tracker says of a ball seen at t_s on the parabola through p with velocity v.
track::TrackerOutput seen(const Vec2& p, const Vec2& v, double t_s) {
  track::TrackerOutput o;
  o.fit = track::exact_trajectory(p, v, thesis_board().gravity_mps2, t_s);
  o.window = 24;
  return o;
}

TEST(PlanningController, SavesABallFallingOntoTheLeftFlipperAndReleasesAfterTheHold) {
  // The lookahead planner's own test ball: left on the resting flipper, it drains.
  PlanningController c(thesis_board(), short_planner());
  std::array<bool, 2> energized{false, false};
  const Vec2 p(0.235, 0.190);
  const Vec2 v(0.5, -1.5);
  double t = 1.0;
  c.update(seen(p, v, t), t, energized);
  EXPECT_EQ(c.decisions(), 1);
  // Frames on: the tracker still sees the same flight (observed 5 ms late).
  int frames_up = 0;
  for (int frame = 1; frame < 40; ++frame) {
    t += 0.005;
    c.update(seen(p, v, 1.0), t, energized);
    EXPECT_FALSE(energized[1]) << "the right flipper has nothing to do with this ball";
    if (energized[0]) ++frames_up;
    if (c.fires() == 1 && !energized[0]) break;
  }
  ASSERT_EQ(c.fires(), 1) << "the ball on the flipper must be saved";
  EXPECT_FALSE(energized[0]) << "released after its hold";
  EXPECT_TRUE(frames_up == 6 || frames_up == 20) << frames_up << " frames: one of the two holds";
}

TEST(PlanningController, FiresTheLeftFlipperOnABoardThatListsTheRightOneFirst) {
  // A controller's commands are [left, right] whatever the board's order.
  table::Board swapped = thesis_board();
  std::swap(swapped.flippers[0], swapped.flippers[1]);
  PlanningController c(swapped, short_planner());
  std::array<bool, 2> energized{false, false};
  double t = 1.0;
  for (int frame = 0; frame < 10 && c.fires() == 0; ++frame, t += 0.005) {
    c.update(seen(Vec2(0.235, 0.190), Vec2(0.5, -1.5), 1.0), t, energized);
  }
  ASSERT_EQ(c.fires(), 1);
  EXPECT_TRUE(energized[track::kLeftFlipper]);
  EXPECT_FALSE(energized[track::kRightFlipper]);
  swapped.flippers[0].side = swapped.flippers[1].side;
  EXPECT_THROW(PlanningController(swapped, short_planner()), std::invalid_argument) << "two left flippers";
}

TEST(PlanningController, NoDecisionSimulatesMoreThanItsStepBudget) {
  // Eight frames of the test ball, planned with the default horizon, then with
  // a budget a tenth of what that horizon needs: the same first decision
  // (fire), and never more steps than the budget.
  control::PlannerSettings tight = short_planner();
  tight.step_budget = 1000;  // 9 plans of 111 steps (55 ms) instead of 2000
  PlanningController c(thesis_board(), tight);
  std::array<bool, 2> energized{false, false};
  double t = 1.0;
  for (int frame = 0; frame < 8 && c.fires() == 0; ++frame, t += 0.005) {
    c.update(seen(Vec2(0.235, 0.190), Vec2(0.5, -1.5), 1.0), t, energized);
  }
  EXPECT_GE(c.decisions(), 1);
  EXPECT_GT(c.max_decision_steps(), 0u);
  EXPECT_LE(c.max_decision_steps(), 1000u);
  EXPECT_EQ(c.fires(), 1) << "55 ms ahead is still enough to see the ball roll off the flipper";
}

TEST(PlanningController, CompensatesTheCameraLatencyByPlanningWhereTheBallIsNow) {
  // Seen 100 ms ago, 0.14 m above the flippers and out of the planning zone,
  // falling fast: by the time of the update it is on the left flipper.
  const double g = thesis_board().gravity_mps2;
  const Vec2 v_now(0.5, -1.5);
  const Vec2 p_now(0.235, 0.190);
  const double ago_s = 0.100;
  const Vec2 v_then(v_now.x(), v_now.y() + g * ago_s);
  const Vec2 p_then(p_now.x() - v_then.x() * ago_s, p_now.y() - v_then.y() * ago_s + 0.5 * g * ago_s * ago_s);
  std::array<bool, 2> energized{false, false};
  PlanningController delivered_late(thesis_board(), short_planner());
  delivered_late.update(seen(p_then, v_then, 1.0 - ago_s), 1.0, energized);
  EXPECT_EQ(delivered_late.decisions(), 1) << "planned from where the ball is now";
  PlanningController delivered_at_once(thesis_board(), short_planner());
  delivered_at_once.update(seen(p_then, v_then, 1.0 - ago_s), 1.0 - ago_s, energized);
  EXPECT_EQ(delivered_at_once.decisions(), 0) << "where it was seen is out of the zone";
}

TEST(PlanningController, NoPlanForAFarOrRisingBallOrWithoutAnEstimate) {
  PlanningController c(thesis_board(), short_planner());
  std::array<bool, 2> energized{false, false};
  c.update(seen(Vec2(0.255, 0.8), Vec2(0.0, -1.0), 1.0), 1.0, energized);
  c.update(seen(Vec2(0.235, 0.190), Vec2(0.0, 1.0), 1.005), 1.005, energized);
  c.update(track::TrackerOutput{}, 1.010, energized);  // no fit, no rolling projection
  EXPECT_EQ(c.decisions(), 0);
  EXPECT_FALSE(energized[0] || energized[1]);
}

TEST(PlanningController, ALostBallReleasesEverything) {
  PlanningController c(thesis_board(), short_planner());
  std::array<bool, 2> energized{false, false};
  double t = 1.0;
  for (int frame = 0; frame < 10 && c.fires() == 0; ++frame, t += 0.005) {
    c.update(seen(Vec2(0.235, 0.190), Vec2(0.5, -1.5), 1.0), t, energized);
  }
  ASSERT_TRUE(energized[0]);
  track::TrackerOutput lost;
  lost.launch.lost = true;
  c.update(lost, t, energized);
  EXPECT_FALSE(energized[0] || energized[1]);
}

TEST(PlanningController, MakeControllerBuildsEveryKindAndRefusesBadSettings) {
  control::ControllerSpec spec;
  EXPECT_NE(dynamic_cast<control::ActuatorController*>(make_controller(spec, thesis_board()).get()), nullptr);
  spec.planner = short_planner();
  EXPECT_NE(dynamic_cast<PlanningController*>(make_controller(spec, thesis_board()).get()), nullptr);
  spec.planner->horizon_s = 0.0;
  EXPECT_THROW(make_controller(spec, thesis_board()), std::invalid_argument);
}

TEST(PlanningController, OutscoresTheSpasticFlipperInItsOwnModel) {
  // The fast loop (camera model, tracker, 4 ms of delay) on the same ball seeds.
  EvaluatorConfig config;
  config.max_ball_time_s = 20.0;
  const PinballEvaluator evaluator(thesis_board(), config);
  control::ControllerSpec spec;
  spec.planner = control::PlannerSettings{};
  double planner = 0.0;
  double spastic = 0.0;
  for (std::uint64_t seed = 1; seed <= 12; ++seed) {
    planner += evaluator.play(spec, seed).score;
    control::SpasticController s;
    spastic += evaluator.play_with(s, -1.0, seed).score;
  }
  EXPECT_GT(planner, 1.2 * spastic) << "planner " << planner / 12 << " spastic " << spastic / 12 << " per ball";
}

}  // namespace
}  // namespace pinball::learn
