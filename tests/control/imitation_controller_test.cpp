#include "pinball/control/imitation_controller.h"

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <stdexcept>

#include "common/projections.h"
#include "pinball/core/rng.h"

namespace pinball::control {
namespace {

constexpr double kPi = 3.14159265358979323846;

using pinball::testing::hittable_projection;

track::TrackerOutput update_of(const track::TrajectoryProjection& p) {
  track::TrackerOutput o;
  o.projection = p;
  return o;
}

ShotExample fire(int flipper, double angle, double h, double s, double d, int fired = -2, double hold = 0.03) {
  return {flipper, false, angle, h, s, fired == -2 ? flipper : fired, d, hold};
}
ShotExample pass(int flipper, double angle, double h, double s) { return {flipper, false, angle, h, s, -1, 0.0, 0.0}; }

ImitationConfig k_of(int k, double lead_s = 0.0) {
  ImitationConfig c;
  c.neighbours = k;
  c.lead_s = lead_s;
  return c;
}

TEST(ShotTable, MajorityOfTheNearestDecidesAndDIsTheirMedian) {
  // Near (θ=-1, h=0.5, s=2): three fire at 40, 50, 90 mm and one passes; far away, passes only.
  const ShotTable t({fire(0, -1.0, 0.5, 2.0, 0.050), fire(0, -1.01, 0.5, 2.0, 0.040), fire(0, -1.0, 0.51, 2.0, 0.090),
                     pass(0, -1.0, 0.5, 2.05), pass(0, 0.5, 1.0, 1.0), pass(0, 0.5, 1.0, 1.1), pass(0, 0.5, 1.0, 1.2)},
                    k_of(4));
  const ImitationDecision d = t.decide(hittable_projection(0, -1.0, 0.5, 2.0, 0.3));
  EXPECT_EQ(d.neighbours, 4);
  EXPECT_TRUE(d.fire);
  EXPECT_EQ(d.flipper, 0);
  EXPECT_DOUBLE_EQ(d.d_critical_m, 0.050);  // median of 40, 50, 90
  EXPECT_DOUBLE_EQ(d.hold_s, 0.03);
  EXPECT_FALSE(t.decide(hittable_projection(0, 0.5, 1.0, 1.1, 0.3)).fire) << "near the passes";
}

TEST(ShotTable, ATieAndAnEmptyLinePass) {
  const ShotTable t({fire(0, -1.0, 0.5, 2.0, 0.05), pass(0, -1.0, 0.5, 2.0)}, k_of(2));
  EXPECT_FALSE(t.decide(hittable_projection(0, -1.0, 0.5, 2.0, 0.0)).fire);
  const ImitationDecision other_line = t.decide(hittable_projection(1, -1.0, 0.5, 2.0, 0.0));
  EXPECT_FALSE(other_line.fire) << "no examples on the right flipper's line";
  EXPECT_EQ(other_line.neighbours, 0);
}

TEST(ShotTable, FlipperLinesAndRollingAreSeparateTables) {
  ShotExample rolling = fire(1, 0.4, 1.3, 1.0, 0.06);
  rolling.rolling = true;
  const ShotTable t({fire(0, 0.4, 1.3, 1.0, 0.02), rolling}, k_of(1));
  track::TrajectoryProjection p = hittable_projection(1, 0.4, 1.3, 1.0, 0.0);
  EXPECT_FALSE(t.decide(p).fire) << "the right line has a rolling example only";
  p.rolling = true;
  EXPECT_DOUBLE_EQ(t.decide(p).d_critical_m, 0.06);
  EXPECT_DOUBLE_EQ(t.decide(hittable_projection(0, 0.4, 1.3, 1.0, 0.0)).d_critical_m, 0.02);
}

TEST(ShotTable, FiringNeighboursChooseTheFlipper) {
  // A ball heading for the left line that the teacher hit with the right flipper.
  const ShotTable t({fire(0, 0.3, 1.2, 2.0, 0.05, 1), fire(0, 0.3, 1.2, 2.1, 0.05, 1), fire(0, 0.3, 1.2, 2.2, 0.05, 0)},
                    k_of(3));
  EXPECT_EQ(t.decide(hittable_projection(0, 0.3, 1.2, 2.0, 0.0)).flipper, 1);
}

TEST(ShotTable, AnglesCompareModuloPi) {
  // Straight down is -π/2 or +π/2 by the sign of a tiny vx: the two are neighbours.
  const ShotTable t({fire(0, kPi / 2 - 0.01, 0.5, 2.0, 0.07), pass(0, 0.0, 0.5, 2.0)}, k_of(1));
  EXPECT_TRUE(t.decide(hittable_projection(0, -kPi / 2 + 0.01, 0.5, 2.0, 0.0)).fire);
}

TEST(ShotTable, RejectsBadSettingsAndExamples) {
  EXPECT_THROW(ShotTable({}, k_of(0)), std::invalid_argument);
  EXPECT_THROW(ShotTable({}, k_of(kMaxNeighbours + 1)), std::invalid_argument);
  ImitationConfig c;
  c.h_scale = 0.0;
  EXPECT_THROW(ShotTable({}, c), std::invalid_argument);
  c = ImitationConfig{};
  c.lead_s = -0.001;
  EXPECT_THROW(ShotTable({}, c), std::invalid_argument);
  EXPECT_THROW(ShotTable({fire(2, 0, 0, 1, 0.1)}, k_of(1)), std::invalid_argument);
  EXPECT_THROW(ShotTable({fire(0, 0, 0, 1, 0.1, 3)}, k_of(1)), std::invalid_argument);
  EXPECT_THROW(ShotTable({fire(0, std::nan(""), 0, 1, 0.1)}, k_of(1)), std::invalid_argument);
  EXPECT_THROW(ShotTable({fire(0, 0, 0, 1, 0.1, 0, -0.1)}, k_of(1)), std::invalid_argument);
}

TEST(ShotTable, SettingsAndShotsHaveSaneRanges) {
  // 1e-6 rad made the lookup spin for ever; 1.5e-9 asked for an oversized grid.
  for (const double scale : {1e-6, 1.5e-9, 4.0}) {
    ImitationConfig c;
    c.angle_scale_rad = scale;
    EXPECT_EQ(check_imitation_config(c).key, "angle_scale_rad") << scale;
    EXPECT_THROW(ShotTable({}, c), std::invalid_argument) << scale;
  }
  ImitationConfig c;
  c.max_hold_s = kMaxHold_s + 1.0;  // longer than the driver board lets a coil hold
  EXPECT_EQ(check_imitation_config(c).key, "max_hold_s");
  c = ImitationConfig{};
  c.speed_scale_mps = 1e-4;
  EXPECT_EQ(check_imitation_config(c).key, "speed_scale_mps");
  EXPECT_FALSE(check_imitation_config(ImitationConfig{}));
  EXPECT_EQ(check_shot_example(fire(0, 4.0, 0.5, 1, 0.1)).key, "angle_rad");
  EXPECT_EQ(check_shot_example(fire(0, 0, 1e9, 1, 0.1)).key, "h");
  EXPECT_EQ(check_shot_example(fire(0, 0, 0.5, 1e3, 0.1)).key, "speed_mps");
  EXPECT_EQ(check_shot_example(fire(0, 0, 0.5, 1, 1e3)).key, "d_fire_m");
  EXPECT_EQ(check_shot_example(fire(0, 0, 0.5, 1, 0.1, 0, 60.0)).key, "hold_s");
  EXPECT_THROW(ShotTable({fire(0, 0, 0.5, 1, 0.1, 0, 60.0)}, k_of(1)), std::invalid_argument);
}

TEST(ShotTable, ASparseTableAnswersInBoundedTime) {
  // A few shots at the corners of a wide (θ, h, s) box with the finest
  // scales: a grid of one-scale cells would be 512^3 cells, and a query in the
  // middle would walk hundreds of empty shells (a sparse table once took
  // 40 ms a decision). The grid shrinks to the shots and the search is capped.
  ImitationConfig c = k_of(3);
  c.angle_scale_rad = c.h_scale = c.speed_scale_mps = 1e-3;
  std::vector<ShotExample> shots;
  for (const double h : {0.0, 1.3}) {
    for (const double s : {0.0, 5.0}) {
      for (const double a : {-1.5, 0.0, 1.5}) shots.push_back(fire(0, a, h, s, 0.05));
    }
  }
  const ShotTable t(shots, c);
  Rng rng(5);
  const auto start = std::chrono::steady_clock::now();
  for (int q = 0; q < 200; ++q) {
    const track::TrajectoryProjection p =
        hittable_projection(0, rng.uniform(-kPi / 2, kPi / 2), rng.uniform(-1.0, 2.0), rng.uniform(0.0, 8.0), 0.0);
    const ImitationDecision a = t.decide(p);
    const ImitationDecision b = t.decide_by_scan(p);
    ASSERT_EQ(a.neighbours, b.neighbours);
    ASSERT_EQ(a.d_critical_m, b.d_critical_m);
  }
  const double elapsed_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  EXPECT_LT(elapsed_s, 1.0) << "200 decisions (sanitizer builds included)";
}

TEST(ShotTable, AFarQueryFallsBackToTheScanAndStaysExact) {
  // Dense shots in one corner, queries across the table: the shell search
  // gives up once it has done a scan's worth of work and scans, with the same answer.
  Rng rng(9);
  std::vector<ShotExample> shots;
  for (int i = 0; i < 5000; ++i) {
    shots.push_back(fire(1, rng.uniform(-1.5, -1.4), rng.uniform(0.0, 0.05), rng.uniform(0.0, 0.1), rng.uniform(0.0, 0.1),
                         rng.uniform01() < 0.5 ? -1 : 1));
  }
  shots.push_back(fire(1, 1.5, 1.3, 5.0, 0.05));
  ImitationConfig c = k_of(7);
  c.angle_scale_rad = c.h_scale = c.speed_scale_mps = 1e-3;
  const ShotTable t(shots, c);
  for (int q = 0; q < 50; ++q) {
    const track::TrajectoryProjection p =
        hittable_projection(1, rng.uniform(-kPi / 2, kPi / 2), rng.uniform(0.0, 1.3), rng.uniform(0.0, 5.0), 0.0);
    const ImitationDecision a = t.decide(p);
    const ImitationDecision b = t.decide_by_scan(p);
    ASSERT_EQ(a.fire, b.fire);
    ASSERT_EQ(a.d_critical_m, b.d_critical_m);
    ASSERT_EQ(a.hold_s, b.hold_s);
  }
}

TEST(ShotTable, TheGridSearchFindsExactlyWhatAFullScanFinds) {
  Rng rng(17);
  std::vector<ShotExample> examples;
  for (int i = 0; i < 3000; ++i) {
    ShotExample e;
    e.flipper = rng.uniform01() < 0.5 ? 0 : 1;
    e.rolling = rng.uniform01() < 0.1;
    e.angle_rad = rng.uniform(-kPi / 2, kPi / 2);
    e.h = rng.uniform(0.0, 1.3);
    e.speed_mps = rng.uniform(0.4, 5.0);
    e.fired_flipper = rng.uniform01() < 0.3 ? -1 : (rng.uniform01() < 0.5 ? 0 : 1);
    e.d_fire_m = e.fired_flipper < 0 ? 0.0 : rng.uniform(0.0, 0.15);
    e.hold_s = e.fired_flipper < 0 ? 0.0 : 0.03;
    // Coarse values make exact distance ties, which both searches break by example index.
    if (i % 3 == 0) e.h = std::round(e.h * 10.0) / 10.0;
    examples.push_back(e);
  }
  for (const int k : {1, 7, 32}) {
    ImitationConfig c = k_of(k);
    c.angle_scale_rad = k == 32 ? 0.7 : 0.1;  // also a coarse θ axis (4 cells)
    const ShotTable t(examples, c);
    for (int q = 0; q < 2000; ++q) {
      // Queries inside and outside the examples' ranges.
      track::TrajectoryProjection p = hittable_projection(q % 2, rng.uniform(-kPi / 2, kPi / 2), rng.uniform(-0.5, 2.0),
                                                 rng.uniform(0.0, 8.0), 0.0);
      p.rolling = q % 7 == 0;
      const ImitationDecision a = t.decide(p);
      const ImitationDecision b = t.decide_by_scan(p);
      ASSERT_EQ(a.neighbours, b.neighbours);
      ASSERT_EQ(a.fire, b.fire) << "k " << k << " query " << q;
      ASSERT_EQ(a.flipper, b.flipper);
      ASSERT_EQ(a.d_critical_m, b.d_critical_m);
      ASSERT_EQ(a.hold_s, b.hold_s);
    }
  }
}

TEST(ImitationController, FiresOnceDWithItsLeadReachesDCriticalAndReleasesAfterTheHold) {
  ImitationController c(ShotTable({fire(1, -1.0, 0.5, 2.0, 0.050, 1, 0.030)}, k_of(1, 0.0025)));
  std::array<bool, 2> e{};
  double t = 0.0;
  // Lead: fires once d - 2 m/s x 2.5 ms <= 50 mm, i.e. at d <= 55 mm.
  double fired_at_d = -1.0;
  for (double d = 0.100; d > 0.0; d -= 0.010, t += 0.005) {
    c.update(update_of(hittable_projection(1, -1.0, 0.5, 2.0, d)), t, e);
    if (e[1] && fired_at_d < 0.0) fired_at_d = d;
    if (fired_at_d > 0.0 && t < 0.02) {
      EXPECT_TRUE(e[1]);
    }
  }
  EXPECT_NEAR(fired_at_d, 0.050, 1e-9) << "first d <= 55 mm in 10 mm steps from 100 mm";
  EXPECT_EQ(c.fires(), 1);
  EXPECT_FALSE(e[0]);
  // The hold (30 ms) is over by now; the next frame may fire again (the same approach continues).
  c.update(update_of(hittable_projection(1, -1.0, 0.5, 2.0, 0.2)), 1.0, e);
  EXPECT_FALSE(e[1]);
}

TEST(ImitationController, WithALeadItLooksUpAndFiresWhereTheBallWillBeWhenTheCoilActs) {
  // d_critical 50 mm; a ball rolling at 2 m/s, seen 10 ms late; the lead adds
  // 5 ms of actuation delay: the coil acts 30 mm further on.
  ImitationConfig led_config = k_of(1);
  led_config.lead_actuation_delay_s = 0.005;
  track::TrackerOutput o = update_of(hittable_projection(1, -1.0, 0.5, 2.0, 0.075));
  o.projection.rolling = true;  // advances at its speed (no fit needed)
  o.projection.t_impact_s = 0.075 / 2.0;
  o.projection.latency_s = 0.010;
  const ShotExample rolling_shot{1, true, -1.0, 0.5, 2.0, 1, 0.050, 0.030};  // on the rolling line
  ImitationController led(ShotTable({rolling_shot}, led_config));
  ImitationController plain(ShotTable({rolling_shot}, k_of(1)));
  std::array<bool, 2> e_led{}, e_plain{};
  led.update(o, 0.0, e_led);
  plain.update(o, 0.0, e_plain);
  EXPECT_TRUE(e_led[1]) << "75 - 30 = 45 mm <= 50 mm";
  EXPECT_FALSE(e_plain[1]) << "75 mm > 50 mm";
  // The same table with a lead out of range is refused.
  led_config.lead_actuation_delay_s = 0.5;
  EXPECT_EQ(check_imitation_config(led_config).key, "lead_actuation_delay_s");
  EXPECT_THROW(ShotTable({}, led_config), std::invalid_argument);
}

TEST(ImitationController, ReleasesOnLaunchAndLossAndIgnoresUnhittable) {
  ImitationController c(ShotTable({fire(0, -1.0, 0.5, 2.0, 0.5, 0, 10.0)}, k_of(1)));
  std::array<bool, 2> e{};
  track::TrajectoryProjection unhittable = hittable_projection(0, -1.0, 0.5, 2.0, 0.1);
  unhittable.hittable = false;
  c.update(update_of(unhittable), 0.0, e);
  EXPECT_FALSE(e[0]);
  c.update(update_of(hittable_projection(0, -1.0, 0.5, 2.0, 0.1)), 0.005, e);
  EXPECT_TRUE(e[0]);
  track::TrackerOutput launch;
  launch.launch.launched = true;
  c.update(launch, 0.010, e);
  EXPECT_FALSE(e[0]);
  c.update(update_of(hittable_projection(0, -1.0, 0.5, 2.0, 0.1)), 0.015, e);
  EXPECT_TRUE(e[0]);
  track::TrackerOutput lost;
  lost.launch.lost = true;
  c.update(lost, 0.020, e);
  EXPECT_FALSE(e[0]);
}

TEST(ImitationController, MaxHoldReleasesACradledBall) {
  ImitationConfig cfg = k_of(1);
  cfg.max_hold_s = 0.5;
  ImitationController c(ShotTable({fire(0, -1.0, 0.5, 2.0, 0.5, 0, 10.0)}, cfg));
  std::array<bool, 2> e{};
  c.update(update_of(hittable_projection(0, -1.0, 0.5, 2.0, 0.1)), 0.0, e);
  EXPECT_TRUE(e[0]);
  c.update(update_of(hittable_projection(0, -1.0, 0.5, 2.0, 0.1)), 0.4, e);
  EXPECT_TRUE(e[0]);
  c.update(update_of(hittable_projection(0, -1.0, 0.5, 2.0, 0.1)), 0.6, e);
  EXPECT_FALSE(e[0]);
}

}  // namespace
}  // namespace pinball::control
