#include "pinball/core/rng.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <vector>

namespace pinball {
namespace {

TEST(Rng, SameSeedSameSequence) {
  Rng a(12345);
  Rng b(12345);
  for (int i = 0; i < 1000; ++i) ASSERT_EQ(a.next_u64(), b.next_u64()) << "draw " << i;
  for (int i = 0; i < 100; ++i) ASSERT_EQ(a.normal(), b.normal());
}

TEST(Rng, CopyForksTheStream) {
  Rng a(7);
  for (int i = 0; i < 10; ++i) a.next_u64();
  Rng b = a;
  for (int i = 0; i < 100; ++i) ASSERT_EQ(a.next_u64(), b.next_u64());
}

TEST(Rng, DifferentSeedsDiffer) {
  for (std::uint64_t seed = 0; seed < 16; ++seed) {
    Rng a(seed);
    Rng b(seed + 1);
    int equal = 0;
    for (int i = 0; i < 100; ++i) equal += a.next_u64() == b.next_u64() ? 1 : 0;
    EXPECT_EQ(equal, 0) << "seeds " << seed << " and " << seed + 1;
  }
}

TEST(Rng, KnownFirstValueOfSeedZero) {
  // xoshiro256** seeded by splitmix64 from 0: the state words are the first
  // four splitmix64 outputs of 0, so the first draw is rotl(s1 * 5, 7) * 9.
  std::uint64_t x = 0;
  auto splitmix = [&x] {
    std::uint64_t z = (x += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
  };
  splitmix();
  const std::uint64_t s1 = splitmix();
  const std::uint64_t m = s1 * 5;
  const std::uint64_t expected = ((m << 7) | (m >> 57)) * 9;
  Rng r(0);
  EXPECT_EQ(r.next_u64(), expected);
}

TEST(Rng, Uniform01InRangeWithMeanAndVariance) {
  Rng r(42);
  constexpr int kN = 100000;
  double sum = 0.0;
  double sum2 = 0.0;
  double lo = 1.0;
  double hi = 0.0;
  for (int i = 0; i < kN; ++i) {
    const double u = r.uniform01();
    ASSERT_GE(u, 0.0);
    ASSERT_LT(u, 1.0);
    sum += u;
    sum2 += u * u;
    lo = std::min(lo, u);
    hi = std::max(hi, u);
  }
  const double mean = sum / kN;
  const double var = sum2 / kN - mean * mean;
  // Standard error of the mean: sqrt(1/12 / 1e5) = 9.1e-4; allow 5 sigma.
  EXPECT_NEAR(mean, 0.5, 5 * 9.13e-4);
  EXPECT_NEAR(var, 1.0 / 12.0, 2e-3);
  EXPECT_LT(lo, 1e-3);
  EXPECT_GT(hi, 1.0 - 1e-3);
}

TEST(Rng, UniformRange) {
  Rng r(3);
  for (int i = 0; i < 10000; ++i) {
    const double u = r.uniform(-2.0, 5.0);
    ASSERT_GE(u, -2.0);
    ASSERT_LT(u, 5.0);
  }
}

TEST(Rng, UniformBinsAreFlat) {
  // Chi-square over 20 bins, 1e5 draws: 19 dof, P(chi2 > 45) < 1e-3.
  Rng r(99);
  std::vector<int> bins(20, 0);
  constexpr int kN = 100000;
  for (int i = 0; i < kN; ++i) ++bins[static_cast<int>(r.uniform01() * 20.0)];
  double chi2 = 0.0;
  const double expect = kN / 20.0;
  for (int c : bins) chi2 += (c - expect) * (c - expect) / expect;
  EXPECT_LT(chi2, 45.0);
}

TEST(Rng, NormalMeanAndVariance) {
  Rng r(2024);
  constexpr int kN = 100000;
  double sum = 0.0;
  double sum2 = 0.0;
  double sum4 = 0.0;
  int beyond2 = 0;
  for (int i = 0; i < kN; ++i) {
    const double z = r.normal();
    ASSERT_TRUE(std::isfinite(z));
    sum += z;
    sum2 += z * z;
    sum4 += z * z * z * z;
    beyond2 += std::abs(z) > 2.0 ? 1 : 0;
  }
  const double mean = sum / kN;
  const double var = sum2 / kN - mean * mean;
  EXPECT_NEAR(mean, 0.0, 5.0 / std::sqrt(kN));          // SE 3.2e-3
  EXPECT_NEAR(var, 1.0, 5.0 * std::sqrt(2.0 / kN));     // SE of the variance 4.5e-3
  EXPECT_NEAR(sum4 / kN, 3.0, 0.1);                     // fourth moment of N(0, 1)
  EXPECT_NEAR(beyond2 / static_cast<double>(kN), 0.0455, 0.004);
}

}  // namespace
}  // namespace pinball
