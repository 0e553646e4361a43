#include "pinball/core/running_stats.h"

#include <gtest/gtest.h>

#include <cmath>
#include <initializer_list>
#include <vector>

#include "pinball/core/rng.h"

namespace pinball {
namespace {

struct TwoPass {
  double mean = 0.0;
  double var = 0.0;
};

TwoPass two_pass(const std::vector<double>& x) {
  TwoPass r;
  for (double v : x) r.mean += v;
  r.mean /= static_cast<double>(x.size());
  for (double v : x) r.var += (v - r.mean) * (v - r.mean);
  r.var /= static_cast<double>(x.size() - 1);
  return r;
}

TEST(RunningStats, Empty) {
  RunningStats s;
  EXPECT_EQ(s.count(), 0);
  EXPECT_EQ(s.mean(), 0.0);
  EXPECT_EQ(s.variance(), 0.0);
  EXPECT_TRUE(std::isinf(s.ci95_half_width()));  // no interval from no sample
  EXPECT_EQ(s.min(), 0.0);
  EXPECT_EQ(s.max(), 0.0);
}

TEST(RunningStats, OneSample) {
  RunningStats s;
  s.add(-4.5);
  EXPECT_EQ(s.count(), 1);
  EXPECT_EQ(s.mean(), -4.5);
  EXPECT_EQ(s.variance(), 0.0);
  EXPECT_TRUE(std::isinf(s.ci95_half_width()));  // one sample says nothing of the spread
  EXPECT_EQ(s.min(), -4.5);
  EXPECT_EQ(s.max(), -4.5);
}

TEST(RunningStats, SmallKnownData) {
  // 2, 4, 4, 4, 5, 5, 7, 9: mean 5, sum of squares 32, sample variance 32/7.
  RunningStats s;
  for (double x : {2.0, 4.0, 4.0, 4.0, 5.0, 5.0, 7.0, 9.0}) s.add(x);
  EXPECT_EQ(s.count(), 8);
  EXPECT_DOUBLE_EQ(s.mean(), 5.0);
  EXPECT_NEAR(s.variance(), 32.0 / 7.0, 1e-14);
  EXPECT_NEAR(s.stddev(), std::sqrt(32.0 / 7.0), 1e-14);
  EXPECT_EQ(s.min(), 2.0);
  EXPECT_EQ(s.max(), 9.0);
}

TEST(RunningStats, MatchesTwoPassOnRandomData) {
  Rng rng(5);
  std::vector<double> x;
  RunningStats s;
  for (int i = 0; i < 10000; ++i) {
    const double v = 3.0 + 2.5 * rng.normal() + (rng.uniform01() < 0.01 ? 100.0 : 0.0);
    x.push_back(v);
    s.add(v);
  }
  const TwoPass t = two_pass(x);
  EXPECT_NEAR(s.mean(), t.mean, 1e-12 * std::abs(t.mean));
  EXPECT_NEAR(s.variance(), t.var, 1e-11 * t.var);
  double lo = x[0];
  double hi = x[0];
  for (double v : x) {
    lo = std::min(lo, v);
    hi = std::max(hi, v);
  }
  EXPECT_EQ(s.min(), lo);
  EXPECT_EQ(s.max(), hi);
}

TEST(RunningStats, AccurateWithLargeOffset) {
  // 1e9 + noise of standard deviation 1e-3 over 1e6 samples: the naive
  // sum-of-squares formula loses every digit (1e18 vs 1e-6); Welford must
  // match the variance of the noise itself.
  Rng rng(11);
  constexpr int kN = 1000000;
  std::vector<double> noise(kN);
  RunningStats s;
  RunningStats ref;
  for (int i = 0; i < kN; ++i) {
    noise[i] = 1e-3 * rng.normal();
    s.add(1e9 + noise[i]);
    ref.add(noise[i]);
  }
  // Samples 1e9 + noise are rounded to the spacing of doubles near 1e9
  // (1.2e-7), which changes the variance (1e-6) by about ulp²/12 ~ 1e-15 and
  // by the rounding's correlation with the noise, well under 1e-4 relative.
  EXPECT_NEAR(s.variance(), ref.variance(), 1e-4 * ref.variance());
  EXPECT_NEAR(s.variance(), 1e-6, 5e-9);  // sampling error of the variance: sqrt(2/n) = 1.4e-3 relative
  EXPECT_NEAR(s.mean(), 1e9 + ref.mean(), 1e-6);
}

TEST(RunningStats, Ci95HalfWidth) {
  RunningStats s;
  for (double x : {1.0, 2.0, 3.0, 4.0, 5.0}) s.add(x);  // variance 2.5
  // Student's t with 4 degrees of freedom, not the normal 1.96: five samples are few.
  EXPECT_NEAR(s.ci95_half_width(), 2.776445 * std::sqrt(2.5) / std::sqrt(5.0), 1e-12);
}

TEST(RunningStats, Ci95CoversTheTrueMeanAboutNinetyFivePercent) {
  Rng rng(77);
  int covered = 0;
  constexpr int kTrials = 2000;
  for (int t = 0; t < kTrials; ++t) {
    RunningStats s;
    for (int i = 0; i < 200; ++i) s.add(10.0 + 3.0 * rng.normal());
    covered += std::abs(s.mean() - 10.0) <= s.ci95_half_width() ? 1 : 0;
  }
  // Binomial SE of the coverage: sqrt(0.95 * 0.05 / 2000) = 4.9e-3.
  EXPECT_NEAR(covered / static_cast<double>(kTrials), 0.95, 0.02);
}

RunningStats stats_of(std::initializer_list<double> xs) {
  RunningStats s;
  for (const double x : xs) s.add(x);
  return s;
}

TEST(RatioOfMeans, ClosedForm) {
  // ā = 3, var 2.5; b̄ = 6, var 10; five each: both relative variances 1/18,
  // Welch-Satterthwaite gives 8 degrees of freedom (t = 2.306004).
  const auto r = ratio_of_means_ci95(stats_of({1, 2, 3, 4, 5}), stats_of({2, 4, 6, 8, 10}));
  ASSERT_TRUE(r.has_value());
  const double half_width_log = 2.306004 * std::sqrt(1.0 / 9.0);
  EXPECT_DOUBLE_EQ(r->ratio, 0.5);
  EXPECT_NEAR(r->low, 0.5 * std::exp(-half_width_log), 1e-12);
  EXPECT_NEAR(r->high, 0.5 * std::exp(half_width_log), 1e-12);
  EXPECT_NEAR(r->low * r->high, 0.25, 1e-12);  // as wide each way in log terms
}

TEST(RatioOfMeans, NoSpreadIsNoInterval) {
  const auto r = ratio_of_means_ci95(stats_of({4, 4, 4}), stats_of({2, 2}));
  ASSERT_TRUE(r.has_value());
  EXPECT_EQ(r->ratio, 2.0);
  EXPECT_EQ(r->low, 2.0);
  EXPECT_EQ(r->high, 2.0);
}

TEST(RatioOfMeans, NoneWithoutTwoSamplesEachOrPositiveMeans) {
  EXPECT_FALSE(ratio_of_means_ci95(stats_of({1}), stats_of({1, 2})).has_value());
  EXPECT_FALSE(ratio_of_means_ci95(stats_of({1, 2}), stats_of({3})).has_value());
  EXPECT_FALSE(ratio_of_means_ci95(stats_of({1, 2}), stats_of({0, 0})).has_value());
  EXPECT_FALSE(ratio_of_means_ci95(stats_of({0, 0}), stats_of({1, 2})).has_value());
  EXPECT_FALSE(ratio_of_means_ci95(RunningStats{}, RunningStats{}).has_value());
}

TEST(RatioOfMeans, CoversTheTrueRatioOfSkewedScoresAboutNinetyFivePercent) {
  // Scores per ball are skewed like exponentials (a few long balls): means
  // 12000 and 5000, 300 and 150 balls, true ratio 2.4.
  Rng rng(91);
  const auto exponential = [&](double mean) { return -mean * std::log(1.0 - rng.uniform01()); };
  int covered = 0;
  constexpr int kTrials = 2000;
  for (int t = 0; t < kTrials; ++t) {
    RunningStats a, b;
    for (int i = 0; i < 300; ++i) a.add(exponential(12000.0));
    for (int i = 0; i < 150; ++i) b.add(exponential(5000.0));
    const auto r = ratio_of_means_ci95(a, b);
    ASSERT_TRUE(r.has_value());
    covered += r->low <= 2.4 && 2.4 <= r->high ? 1 : 0;
  }
  EXPECT_NEAR(covered / static_cast<double>(kTrials), 0.95, 0.02);  // binomial SE 4.9e-3
}

}  // namespace
}  // namespace pinball
