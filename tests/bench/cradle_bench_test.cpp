#include "cradle_bench.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include "common/thesis_board.h"
#include "pinball/core/rng.h"
#include "pinball/sim/model_world.h"
#include "pinball/simlab/world_factory.h"

namespace pinball::bench {
namespace {

using pinball::testing::thesis_board;

// The twin, where a ball held on raised bats comes to rest in a crook
// (mit1993.board: 17 of 20 launches).
simlab::OwnedWorld twin() {
  simlab::WorldSpec spec;
  spec.kind = simlab::WorldKind::kTwin;
  return simlab::make_world(spec, thesis_board());
}

CradleBenchOptions short_run(double drop_s, double cap_s) {
  CradleBenchOptions o;
  o.balls = 1;
  o.drop_from_s = drop_s;
  o.drop_to_s = drop_s;
  o.max_ball_time_s = cap_s;
  o.cycling_gap_s = cap_s;
  return o;
}

TEST(CradleBench, ABriefDropOnlyRocksTheBallInTheCrookAndIsNoCycle) {
  if (!simlab::twin_available()) GTEST_SKIP() << "built without the MuJoCo twin";
  const simlab::OwnedWorld world = twin();
  // 10 ms down: the bat hardly moves, the ball stays, and is cradled again.
  const CradleBall b = play_cradle_ball(*world, ball_seed(1, 0), 0.010, short_run(0.010, 15.0));
  EXPECT_TRUE(b.cradled);
  EXPECT_GT(b.duds, 3);
  EXPECT_EQ(b.returns, 0);
  EXPECT_EQ(b.shots, 0) << "a dud neither returns nor loses the ball";
  EXPECT_TRUE(b.cut);
  EXPECT_FALSE(b.cycling_at_cut) << "a ball rocking in the crook is not a cycle";
  EXPECT_EQ(b.passes, 0) << "it rocks back onto the bat it lay on";
  EXPECT_FALSE(b.passing_at_cut);
  EXPECT_FALSE(b.lost_after_drop);
}

TEST(CradleBench, ALongerDropShootsTheBallUpAndItComesBackToTheCradle) {
  if (!simlab::twin_available()) GTEST_SKIP() << "built without the MuJoCo twin";
  const simlab::OwnedWorld world = twin();
  const CradleReport r = run_cradle_bench(*world, short_run(0.241, 30.0));
  ASSERT_EQ(r.drops.size(), 1u);
  const CradleDropResult& d = r.drops[0];
  EXPECT_EQ(d.cradled, 1);
  EXPECT_GE(d.returns, 3);
  EXPECT_GT(d.mean_period_s, 1.0) << "up the table and back";
  EXPECT_LT(d.mean_period_s, 10.0);
  EXPECT_GT(d.points_per_cycle, 0.0);
  EXPECT_EQ(d.shots, d.returns + d.drains.total());
  EXPECT_EQ(r.world, "twin");
}

TEST(CradleBench, ResultsDoNotDependOnTheThreadCount) {
  if (!simlab::twin_available()) GTEST_SKIP() << "built without the MuJoCo twin";
  const simlab::OwnedWorld world = twin();
  CradleBenchOptions o = short_run(0.240, 12.0);
  o.balls = 2;
  o.drop_to_s = 0.242;
  o.drop_step_s = 0.002;
  const CradleReport one = run_cradle_bench(*world, o);
  o.threads = 2;
  const CradleReport two = run_cradle_bench(*world, o);
  EXPECT_EQ(to_json(one).at("drops"), to_json(two).at("drops"));
  EXPECT_EQ(one.drops.size(), 2u);
}

TEST(CradleBench, TenMinutesAtOnePercentNeedsTheReturnShareToThePowerOfTheCycles) {
  CradleDropResult r;
  r.shots = 10;
  r.returns = 9;
  r.mean_period_s = 3.0;  // 200 cycles in 10 minutes
  EXPECT_DOUBLE_EQ(r.return_share(), 0.9);
  EXPECT_NEAR(r.return_share_needed(), std::pow(0.01, 1.0 / 200.0), 1e-12);
  EXPECT_NEAR(r.return_share_needed(), 0.97724, 1e-5);
  EXPECT_NEAR(r.projected_share_at_10_min(), std::pow(0.9, 200.0), 1e-15);
  const CradleDropResult none;
  EXPECT_TRUE(std::isnan(none.return_share())) << "no shot, no share";
  EXPECT_EQ(none.return_share_needed(), 1.0);
  EXPECT_EQ(none.projected_share_at_10_min(), 0.0);
}

// A drop of 230 ms whose 2 shots never came back: no period, no points per cycle.
CradleDropResult drop_with_no_return() {
  CradleDropResult none;
  none.drop_s = 0.230;
  none.shots = 2;
  none.mean_period_s = std::numeric_limits<double>::quiet_NaN();
  none.points_per_cycle = std::numeric_limits<double>::quiet_NaN();
  return none;
}

TEST(CradleBench, TheTextMarksTheBestDropAndLeavesOutThePeriodOfADropWithNoReturn) {
  CradleReport report;
  report.world = "twin";
  const CradleDropResult none = drop_with_no_return();
  CradleDropResult good;
  good.drop_s = 0.240;
  good.shots = 10;
  good.returns = 9;
  good.mean_period_s = 3.0;
  good.mean_score = 391.0;
  good.score_ci95 = 120.0;
  report.drops = {none, good};
  report.best = 1;
  const std::string text = to_text(report);
  EXPECT_NE(text.find("  drop 230 ms: returns 0 of 2 shots = 0 (0-"), std::string::npos) << text;
  EXPECT_EQ(text.find("drop 230 ms: returns 0 of 2 shots = 0 (0-0.658), needed"), std::string::npos) << text;
  EXPECT_NE(text.find("* drop 240 ms: returns 9 of 10 shots = 0.9"), std::string::npos) << text;
  EXPECT_NE(text.find("391 ± 120 points"), std::string::npos) << "a score is given with its interval\n" << text;
  EXPECT_NE(text.find("under 0.01 % of cradled balls would live 10 minutes (1 % needs 0.977"), std::string::npos)
      << text;
}

// No shot measures no share: null, not 0, and no "best drop" chosen from nothing
// (a short --max-ball-time left every drop without a shot).
TEST(CradleBench, DropsWithNoShotHaveNoShareAndNoBest) {
  CradleReport report;
  report.world = "thesis";
  CradleDropResult idle;
  idle.drop_s = 0.230;
  idle.balls = 3;
  idle.mean_period_s = std::numeric_limits<double>::quiet_NaN();
  idle.points_per_cycle = std::numeric_limits<double>::quiet_NaN();
  report.drops = {idle, idle};
  const nlohmann::json j = nlohmann::json::parse(to_json(report).dump());
  EXPECT_TRUE(j.at("drops")[0].at("return_share").is_null());
  EXPECT_TRUE(j.at("best_drop_s").is_null());
  const std::string text = to_text(report);
  EXPECT_NE(text.find("  drop 230 ms: no shot;"), std::string::npos) << text;
  EXPECT_NE(text.find("no drop had a shot"), std::string::npos) << text;
  EXPECT_EQ(text.find("best drop"), std::string::npos) << text;
}

// No return measures no cycle: its period is null, not 0 s, and the best
// drop's line does not quote one.
TEST(CradleBench, ADropWithNoReturnHasNoPeriod) {
  CradleReport report;
  report.world = "twin";
  report.drops = {drop_with_no_return()};
  report.best = 0;
  const nlohmann::json j = nlohmann::json::parse(to_json(report).dump());
  EXPECT_TRUE(j.at("drops")[0].at("mean_period_s").is_null());
  EXPECT_TRUE(j.at("drops")[0].at("points_per_cycle").is_null());
  EXPECT_TRUE(j.at("drops")[0].contains("mean_score_per_ball"));
  EXPECT_TRUE(j.at("drops")[0].contains("balls_cut_at_time_limit"));
  const std::string text = to_text(report);
  EXPECT_NE(text.find("best drop 230 ms: at 0 a return, "), std::string::npos) << text;
  EXPECT_EQ(text.find("nan"), std::string::npos) << text;
}

TEST(CradleBench, RefusesOptionsItCannotUse) {
  const std::unique_ptr<sim::World> world = sim::make_model_world(thesis_board());
  const auto refuses = [&](CradleBenchOptions o) {
    EXPECT_THROW(run_cradle_bench(*world, o), std::invalid_argument);
  };
  CradleBenchOptions o;
  o.balls = 0;
  refuses(o);
  o = {};
  o.drop_to_s = o.drop_from_s - 0.001;
  refuses(o);
  o = {};
  o.drop_step_s = 0.0;
  refuses(o);
  o = {};
  o.drop_from_s = 0.001;
  o.drop_to_s = 2.0;
  o.drop_step_s = 0.001;  // 2000 durations
  refuses(o);
  o = {};
  o.rest_s = 0.0;
  refuses(o);
}

}  // namespace
}  // namespace pinball::bench
