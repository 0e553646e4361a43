#include "pinball/core/statistics.h"

#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>
#include <vector>

#include "pinball/core/running_stats.h"

namespace pinball {
namespace {

TEST(Quantile, IsTheNearestRank) {
  std::vector<double> v;
  for (int i = 100; i >= 1; --i) v.push_back(i);  // 1..100, unsorted
  EXPECT_EQ(quantile(v, 0.5), 50.0);
  EXPECT_EQ(quantile(v, 0.99), 99.0);
  EXPECT_EQ(quantile(v, 1.0), 100.0);
  EXPECT_EQ(quantile(v, 0.0), 1.0);
  EXPECT_EQ(quantile(v, 0.991), 100.0);  // rank ceil(99.1) = 100
  EXPECT_EQ(v.front(), 100.0);           // the caller's samples are left alone
  EXPECT_EQ(quantile(std::vector<double>{}, 0.5), 0.0);
  EXPECT_EQ(quantile(std::vector<float>{3.0f, 1.0f, 2.0f}, 0.5), 2.0);
}

TEST(Quantile, RankIsAtLeastOneAndAtMostN) {
  EXPECT_EQ(quantile_rank(0.5, 0), 0u);
  EXPECT_EQ(quantile_rank(0.0, 7), 1u);
  EXPECT_EQ(quantile_rank(0.99, 7), 7u);
  EXPECT_EQ(quantile_rank(0.5, 7), 4u);
  EXPECT_EQ(quantile_rank(0.5, 8), 4u);
  EXPECT_EQ(quantile_rank(2.0, 8), 8u);
  EXPECT_EQ(quantile_rank(std::nan(""), 8), 1u);
}

TEST(StudentT, MatchesTheTableAndTendsToTheNormal) {
  EXPECT_NEAR(student_t95(1), 12.7062, 1e-4);
  EXPECT_NEAR(student_t95(2), 4.3027, 1e-4);
  EXPECT_NEAR(student_t95(10), 2.2281, 1e-4);
  EXPECT_NEAR(student_t95(30), 2.0423, 1e-4);
  EXPECT_NEAR(student_t95(31), 2.0395, 1e-4);   // the expansion takes over from the table
  EXPECT_NEAR(student_t95(60), 2.0003, 1e-4);
  EXPECT_NEAR(student_t95(120), 1.9799, 1e-4);
  EXPECT_NEAR(student_t95(999), 1.96234, 1e-5);
  EXPECT_NEAR(student_t95(1'000'000'000), 1.959964, 1e-6);
  EXPECT_TRUE(std::isinf(student_t95(0)));
  for (int dof = 1; dof < 200; ++dof) EXPECT_GT(student_t95(dof), student_t95(dof + 1)) << dof;
}

TEST(RunningStats, TheIntervalOfTwoBallsUsesStudentsT) {
  RunningStats s;
  s.add(1000.0);
  s.add(3000.0);  // stddev sqrt(2)·1000
  EXPECT_NEAR(s.ci95_half_width(), 12.706205 * std::sqrt(2.0) * 1000.0 / std::sqrt(2.0), 1e-6);
  EXPECT_GT(s.ci95_half_width() / (1.96 * 1000.0), 6.4);  // the normal approximation is 6.5x too narrow
}

TEST(Statistics, RobustSigmaIsTheScaledMedianAbsoluteDeviation) {
  // Median 3, deviations {2, 1, 0, 1, 97}: their median 1.
  EXPECT_DOUBLE_EQ(robust_sigma({1.0, 2.0, 3.0, 4.0, 100.0}), 1.4826);
  EXPECT_DOUBLE_EQ(robust_sigma({5.0, 5.0, 5.0}), 0.0);
  EXPECT_DOUBLE_EQ(robust_sigma({}), 0.0);
}

TEST(Statistics, TheMedianIsTheMiddleOrTheMeanOfTheTwoMiddleValues) {
  EXPECT_EQ(median({}), 0.0);
  EXPECT_EQ(median({3.0}), 3.0);
  EXPECT_EQ(median({5.0, 1.0, 3.0}), 3.0);
  EXPECT_EQ(median({4.0, 1.0, 3.0, 2.0}), 2.5);
  EXPECT_EQ(median({1.0, 1.0, 7.0, 100.0}), 4.0);
}

TEST(Statistics, WilsonsIntervalOfAShareMatchesTheTextbookAndStaysInsideZeroToOne) {
  // Newcombe (1998), table I: 0 of 10 gives 0 to 0.2775; 5 of 10, 0.2366 to 0.7634.
  const Interval none = wilson_ci95(0, 10);
  EXPECT_DOUBLE_EQ(none.low, 0.0);
  EXPECT_NEAR(none.high, 0.2775, 1e-4);
  const Interval half = wilson_ci95(5, 10);
  EXPECT_NEAR(half.low, 0.2366, 1e-4);
  EXPECT_NEAR(half.high, 0.7634, 1e-4);
  const Interval all = wilson_ci95(10, 10);
  EXPECT_NEAR(all.low, 0.7225, 1e-4);
  EXPECT_DOUBLE_EQ(all.high, 1.0);
  const Interval no_trials = wilson_ci95(0, 0);
  EXPECT_EQ(no_trials.low, 0.0);
  EXPECT_EQ(no_trials.high, 1.0);
  EXPECT_THROW(wilson_ci95(11, 10), std::invalid_argument);
  EXPECT_THROW(wilson_ci95(-1, 10), std::invalid_argument);
}

}  // namespace
}  // namespace pinball
