#include <cmath>
#include <stdexcept>

#include <gtest/gtest.h>

#include "pinball/core/statistics.h"
#include "transfer_bench.h"
#include "transfer_report_fixture.h"

namespace pinball::bench {
namespace {

using pinball::testing::made_report;

const TransferSensitivity& find(const TransferReport& r, const std::string& family, const std::string& controller) {
  for (const TransferSensitivity& s : r.sensitivities) {
    if (s.family == family && s.controller == controller) return s;
  }
  throw std::runtime_error("no sensitivity " + family + " " + controller);
}

TEST(TransferSensitivity, TheSlopeOfScoreAgainstTheSizeOfTheError) {
  const TransferReport r = made_report();
  // Points: the model world at 0, and |±1|, |±3| mm.
  const TransferSensitivity& pivot = find(r, "pivot_y_mm", "learned");
  EXPECT_NEAR(pivot.points_per_ball_lost_per_unit, 50.0, 1e-9);
  EXPECT_EQ(pivot.unit, "mm");
  EXPECT_EQ(pivot.worlds, 5);
  EXPECT_NEAR(find(r, "pivot_y_mm", "spastic").points_per_ball_lost_per_unit, 10.0, 1e-9);
  EXPECT_NEAR(find(r, "gravity_pct", "learned").points_per_ball_lost_per_unit, 50.0, 1e-9);
  EXPECT_EQ(find(r, "gravity_pct", "learned").unit, "%");
  // Every mean has standard error 100·√(4/3)/2; the slope's is Σ wᵢ² of that, times Student's t for 3 dof.
  const double se2 = 100.0 * 100.0 * 4.0 / 3.0 / 4.0;
  const double sxx = (0 - 1.6) * (0 - 1.6) + 2 * (1 - 1.6) * (1 - 1.6) + 2 * (3 - 1.6) * (3 - 1.6);  // x̄ = 1.6
  EXPECT_NEAR(pivot.ci95_half_width, student_t95(3) * std::sqrt(se2 / sxx), 1e-9);
}

TEST(TransferSensitivity, OnlyOffsetFamiliesAndOnlyWithAModelWorld) {
  TransferReport r = made_report();
  for (const TransferSensitivity& s : r.sensitivities) {
    EXPECT_TRUE(s.family == "pivot_y_mm" || s.family == "gravity_pct") << s.family << ": no worlds, no slope";
  }
  EXPECT_EQ(r.sensitivities.size(), 4u) << "2 families x 2 controllers";
  r.worlds.erase(r.worlds.begin());  // no model world
  EXPECT_TRUE(transfer_sensitivities(r.worlds, r.options).empty());
}

}  // namespace
}  // namespace pinball::bench
