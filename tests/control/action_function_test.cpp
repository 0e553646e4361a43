#include "pinball/control/action_function.h"

#include <gtest/gtest.h>

#include "common/projections.h"

#include <cmath>
#include <numbers>
#include <stdexcept>

namespace pinball::control {
namespace {

using pinball::testing::hittable_projection;

TEST(ActionFunction, UniformBordersSplitTheHalfCircle) {
  const ActionFunctionConfig c = uniform_partition(6);
  ASSERT_EQ(c.angle_borders_rad.size(), 5u);
  for (int i = 0; i < 5; ++i) EXPECT_NEAR(c.angle_borders_rad[i], -std::numbers::pi / 2 + std::numbers::pi * (i + 1) / 6, 1e-15);
  const ActionFunction af(c);
  EXPECT_EQ(af.angle_bins(), 6);
  EXPECT_EQ(af.partitions(), 12);
  EXPECT_THROW(uniform_partition(0), std::invalid_argument);
}

TEST(ActionFunction, PartitionLookupAtEveryBorder) {
  const ActionFunction af(uniform_partition(4));
  const auto& b = af.config().angle_borders_rad;
  EXPECT_EQ(af.angle_bin(-std::numbers::pi / 2), 0);
  EXPECT_EQ(af.angle_bin(std::numbers::pi / 2), 3);
  for (std::size_t i = 0; i < b.size(); ++i) {
    EXPECT_EQ(af.angle_bin(b[i]), static_cast<int>(i) + 1) << "a border belongs to the bin above";
    EXPECT_EQ(af.angle_bin(std::nextafter(b[i], -10.0)), static_cast<int>(i)) << "just below border " << i;
  }
  // Flipper then angle: left bins 0..3, right bins 4..7.
  EXPECT_EQ(af.partition_of(hittable_projection(track::kLeftFlipper, -1.5)), 0);
  EXPECT_EQ(af.partition_of(hittable_projection(track::kLeftFlipper, 1.5)), 3);
  EXPECT_EQ(af.partition_of(hittable_projection(track::kRightFlipper, -1.5)), 4);
  EXPECT_EQ(af.partition_of(hittable_projection(track::kRightFlipper, b[1])), 6);
}

TEST(ActionFunction, CustomBordersHAndRollingPartitions) {
  ActionFunctionConfig c;
  c.angle_borders_rad = {-0.5, 0.2};
  c.h_borders = {1.0};
  c.rolling_minicontrollers = true;
  const ActionFunction af(c);
  EXPECT_EQ(af.partitions(), 2 * 3 * 2 + 2);
  EXPECT_EQ(af.partition_of(hittable_projection(track::kLeftFlipper, -0.5, 0.99)), 2);  // angle 1, h 0
  EXPECT_EQ(af.partition_of(hittable_projection(track::kLeftFlipper, -0.5, 1.0)), 3);   // angle 1, h 1 (border goes up)
  EXPECT_EQ(af.partition_of(hittable_projection(track::kRightFlipper, 0.2, 0.0)), 6 + 4);
  track::TrajectoryProjection rolling = hittable_projection(track::kRightFlipper, 0.0);
  rolling.rolling = true;
  EXPECT_EQ(af.partition_of(rolling), 13);
  EXPECT_EQ(af.minicontroller(12).flipper, track::kLeftFlipper);
  EXPECT_EQ(af.minicontroller(13).flipper, track::kRightFlipper);
  EXPECT_EQ(af.partition_name(13), "R rolling");
}

TEST(ActionFunction, RejectsBadBorders) {
  ActionFunctionConfig c;
  c.angle_borders_rad = {0.3, 0.1};
  EXPECT_THROW(ActionFunction{c}, std::invalid_argument);
  c.angle_borders_rad = {2.0};
  EXPECT_THROW(ActionFunction{c}, std::invalid_argument);
  c.angle_borders_rad = {};
  c.gain_range[2] = -1.0;
  EXPECT_THROW(ActionFunction{c}, std::invalid_argument);
}

TEST(ActionFunction, DCriticalIsEquation51) {
  ActionFunction af(uniform_partition(2));
  Minicontroller& m = af.minicontroller(3);  // right flipper, upper angle bin
  m.a = {0.01, -0.02, 0.03, 0.04};
  m.flipper = track::kLeftFlipper;
  const track::TrajectoryProjection p = hittable_projection(track::kRightFlipper, 0.7, 1.2, 2.5);
  EXPECT_DOUBLE_EQ(af.d_critical(3, p), 0.01 * 0.7 - 0.02 * 1.2 + 0.03 * 2.5 + 0.04);
  const Action act = af.action(p);
  EXPECT_EQ(act.partition, 3);
  EXPECT_EQ(act.flipper, track::kLeftFlipper);  // the minicontroller's flipper, not the projection's
  EXPECT_DOUBLE_EQ(act.d_critical_m, af.d_critical(3, p));
}

TEST(ActionFunction, RandomMinicontrollersStayInRange) {
  ActionFunction af(uniform_partition(3));
  Rng rng(5);
  int right = 0;
  for (int i = 0; i < 1000; ++i) {
    const Minicontroller m = af.random_minicontroller(rng);
    for (int k = 0; k < 4; ++k) EXPECT_LE(std::abs(m.a[k]), af.config().gain_range[k]);
    right += m.flipper;
  }
  EXPECT_GT(right, 400);
  EXPECT_LT(right, 600);
}

}  // namespace
}  // namespace pinball::control
