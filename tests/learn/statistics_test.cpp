#include "pinball/learn/statistics.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <vector>

#include "pinball/core/rng.h"

#if defined(__SANITIZE_ADDRESS__)
#define PINBALL_SANITIZED 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define PINBALL_SANITIZED 1
#endif
#endif

namespace pinball::learn {
namespace {

TEST(Statistics, WelfordMatchesDirectFormulas) {
  Rng rng(7);
  std::vector<double> x;
  RunningStats s;
  for (int i = 0; i < 1000; ++i) {
    x.push_back(rng.uniform(-50.0, 300.0));
    s.add(x.back());
  }
  double mean = 0.0;
  for (double v : x) mean += v;
  mean /= static_cast<double>(x.size());
  double ss = 0.0;
  for (double v : x) ss += (v - mean) * (v - mean);
  EXPECT_NEAR(s.mean(), mean, 1e-12 * std::abs(mean));
  EXPECT_NEAR(s.variance(), ss / (x.size() - 1), 1e-10 * ss / (x.size() - 1));
}

TEST(Statistics, ThesisRecurrenceMatchesDirectFormulasOnSmallValues) {
  ThesisIncrementalStats t;
  RunningStats w;
  const double xs[] = {3.0, 7.0, 1.0, 9.0, 4.0, 4.0, 12.0};
  for (double x : xs) {
    t.add(x);
    w.add(x);
    EXPECT_NEAR(t.mean(), w.mean(), 1e-12);
    if (t.count() >= 2) {
      EXPECT_NEAR(t.variance(), w.variance(), 1e-9);
    }
  }
}

// Welford stays accurate over 10^9 samples of large values (1e9 + U[0, 1):
// true variance 1/12); the thesis's recurrence (App. A) loses every digit.
// Eight interleaved Welford states merged at the end keep the run to a few
// seconds; each is the plain Welford update. Under sanitizers: 10^7 samples.
TEST(Statistics, WelfordStaysAccurateOverABillionLargeSamples) {
#ifdef PINBALL_SANITIZED
  constexpr std::int64_t kSamples = 10'000'000;
#else
  constexpr std::int64_t kSamples = 1'000'000'000;
#endif
  constexpr int kLanes = 8;
  RunningStats lanes[kLanes];
  std::uint64_t state = 0x243F6A8885A308D3ull;
  for (std::int64_t i = 0; i < kSamples; i += kLanes) {
    for (int l = 0; l < kLanes; ++l) {
      state = state * 6364136223846793005ull + 1442695040888963407ull;  // LCG: cheap, uniform enough
      lanes[l].add(1e9 + static_cast<double>(state >> 11) * 0x1.0p-53);
    }
  }
  RunningStats all;
  for (const auto& l : lanes) all.merge(l);
  EXPECT_EQ(all.count(), kSamples);
  EXPECT_NEAR(all.mean(), 1e9 + 0.5, 1e-3);
  EXPECT_NEAR(all.variance(), 1.0 / 12.0, 1e-3);  // relative error < 1.2 %

  ThesisIncrementalStats thesis;
  for (int i = 0; i < 100000; ++i) {
    state = state * 6364136223846793005ull + 1442695040888963407ull;
    thesis.add(1e9 + static_cast<double>(state >> 11) * 0x1.0p-53);
  }
  EXPECT_GT(std::abs(thesis.variance() - 1.0 / 12.0), 1.0) << "the thesis recurrence is expected to fail here";
}

TEST(Statistics, MergeEqualsSequentialAdds) {
  RunningStats a, b, all;
  for (int i = 0; i < 100; ++i) {
    const double x = std::sin(i) * 10.0 + i;
    (i < 37 ? a : b).add(x);
    all.add(x);
  }
  a.merge(b);
  EXPECT_EQ(a.count(), all.count());
  EXPECT_NEAR(a.mean(), all.mean(), 1e-12);
  EXPECT_NEAR(a.variance(), all.variance(), 1e-10);
  EXPECT_EQ(a.min(), all.min());
  EXPECT_EQ(a.max(), all.max());
}

TEST(Statistics, HoeffdingHalfWidthIsEquationB8) {
  for (std::int64_t n : {1, 2, 10, 1000}) {
    for (double b : {1.0, 250.0, 7e4}) {
      for (double c : {0.5, 0.9, 0.99}) {
        const double t = std::sqrt(b * b / (-2.0 * n) * std::log((1.0 - c) / 2.0));
        EXPECT_NEAR(hoeffding_half_width(n, b, c), t, 1e-12 * t);
        // B.7: the bound 1 - 2 exp(-2 n t^2 / B^2) equals c at this t.
        EXPECT_NEAR(1.0 - 2.0 * std::exp(-2.0 * n * t * t / (b * b)), c, 1e-12);
      }
    }
  }
  EXPECT_TRUE(std::isinf(hoeffding_half_width(0, 1.0, 0.9)));
  EXPECT_EQ(hoeffding_half_width(5, 0.0, 0.9), 0.0);
}

TEST(Statistics, HoeffdingIntervalUsesMeanPlusTwoSigma) {
  RunningStats s;
  for (double x : {100.0, 200.0, 300.0, 400.0}) s.add(x);
  const double b = s.mean() + 2.0 * s.stddev();
  EXPECT_DOUBLE_EQ(thesis_range_bound(s), b);
  const Interval iv = hoeffding_interval(s, 0.9);
  const double t = std::sqrt(b * b / 8.0 * std::log(2.0 / 0.1));
  EXPECT_NEAR(iv.low, s.mean() - t, 1e-9);
  EXPECT_NEAR(iv.high, s.mean() + t, 1e-9);
  RunningStats one;
  one.add(5.0);
  EXPECT_TRUE(std::isinf(hoeffding_interval(one).high));
}

}  // namespace
}  // namespace pinball::learn
