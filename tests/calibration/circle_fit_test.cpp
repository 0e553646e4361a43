#include "pinball/calibration/circle_fit.h"

#include <cmath>
#include <stdexcept>
#include <vector>

#include <gtest/gtest.h>

#include "pinball/core/rng.h"

namespace pinball::calibration {
namespace {

std::vector<Vec2> arc(const Vec2& c, double r, double a0, double a1, int n, double noise, std::uint64_t seed) {
  Rng rng(seed);
  std::vector<Vec2> p;
  for (int k = 0; k < n; ++k) {
    const double a = a0 + (a1 - a0) * k / (n - 1);
    p.push_back(c + r * Vec2{std::cos(a), std::sin(a)} + noise * Vec2{rng.normal(), rng.normal()});
  }
  return p;
}

TEST(CircleFit, ExactPointsOnAShortArc) {
  const std::vector<Vec2> p = arc({0.165, 0.16}, 0.078, -0.43, 0.53, 40, 0.0, 1);
  for (const CircleFit& f : {fit_circle_algebraic(p), fit_circle(p)}) {
    EXPECT_NEAR(f.centre.x(), 0.165, 1e-9);
    EXPECT_NEAR(f.centre.y(), 0.16, 1e-9);
    EXPECT_NEAR(f.radius, 0.078, 1e-9);
    EXPECT_LT(f.rms, 1e-9);
  }
}

TEST(CircleFit, NoisyArcWithinAFractionOfAMillimetre) {
  // 0.3 mm noise on 600 points over 55 degrees, as a tip tracked through a sweep.
  const std::vector<Vec2> p = arc({0.3, 0.2}, 0.078, 2.0, 2.96, 600, 0.0003, 3);
  const CircleFit f = fit_circle(p);
  EXPECT_LT((f.centre - Vec2{0.3, 0.2}).norm(), 0.0008);
  EXPECT_NEAR(f.radius, 0.078, 0.0008);
  EXPECT_NEAR(f.rms, 0.0003 * std::sqrt(2.0) / std::sqrt(2.0), 0.0001);
}

TEST(CircleFit, OutliersAreTrimmed) {
  std::vector<Vec2> p = arc({0.0, 0.0}, 1.0, 0.0, 1.5, 200, 0.001, 5);
  for (int k = 0; k < 10; ++k) p[static_cast<std::size_t>(k * 17)] *= 1.2;  // 10 wild points
  const CircleFit f = fit_circle(p);
  EXPECT_GE(f.rejected, 10);
  EXPECT_LT(f.centre.norm(), 0.01);
  EXPECT_NEAR(f.radius, 1.0, 0.01);
}

TEST(CircleFit, DegenerateInputThrows) {
  EXPECT_THROW(fit_circle(std::vector<Vec2>{{0, 0}, {1, 1}}), std::invalid_argument);
  EXPECT_THROW(fit_circle(std::vector<Vec2>{{0, 0}, {1, 1}, {2, 2}, {3, 3}}), std::invalid_argument);
}

// Lines through `pivot` at angles spread over [a0, a1], each moved `noise` (m)
// across itself and turned by noise_rad, as a blade's centre lines in a sweep.
std::vector<Line2> pencil(const Vec2& pivot, double a0, double a1, int n, double noise, double noise_rad,
                          std::uint64_t seed) {
  Rng rng(seed);
  std::vector<Line2> lines;
  for (int k = 0; k < n; ++k) {
    const double a = a0 + (a1 - a0) * k / (n - 1) + noise_rad * rng.normal();
    const Vec2 d{std::cos(a), std::sin(a)};
    const Vec2 across{-d.y(), d.x()};
    // A point some way along the line, as a blade's middle is.
    lines.push_back({pivot + 0.04 * d + noise * rng.normal() * across, d});
  }
  return lines;
}

TEST(LinesMeet, ExactLinesMeetAtTheirCommonPoint) {
  const std::vector<Line2> lines = pencil({0.345, 0.16}, 2.2, 3.16, 30, 0.0, 0.0, 1);
  const LinesMeet m = meet_lines(lines);
  EXPECT_NEAR(m.point.x(), 0.345, 1e-12);
  EXPECT_NEAR(m.point.y(), 0.16, 1e-12);
  EXPECT_LT(m.rms, 1e-12);
  EXPECT_EQ(m.lines, 30);
  EXPECT_EQ(m.rejected, 0);
  // Two lines are enough, and the direction's sign and length do not matter.
  const std::vector<Line2> two{{{1.0, 0.0}, {-2.0, 0.0}}, {{0.5, 3.0}, {0.0, 1.0}}};
  EXPECT_LT((meet_lines(two).point - Vec2{0.5, 0.0}).norm(), 1e-12);
}

TEST(LinesMeet, NoisyLinesWithinTheirNoise) {
  // 0.3 mm and 0.3° of noise on 600 lines over 55 degrees: the point is far better than one line.
  const std::vector<Line2> lines = pencil({0.165, 0.16}, -0.43, 0.53, 600, 0.0003, 0.005, 7);
  const LinesMeet m = meet_lines(lines);
  EXPECT_LT((m.point - Vec2{0.165, 0.16}).norm(), 0.0002);
  EXPECT_GT(m.rms, 0.0002);
  EXPECT_LT(m.rms, 0.0006);
}

TEST(LinesMeet, OutliersAreTrimmed) {
  std::vector<Line2> lines = pencil({0.0, 0.0}, 0.0, 1.0, 200, 0.0002, 0.0, 9);
  for (int k = 0; k < 10; ++k) lines[static_cast<std::size_t>(k * 19)].point += Vec2{0.0, 0.01};  // 10 wild lines
  const LinesMeet m = meet_lines(lines);
  EXPECT_GE(m.rejected, 10);
  EXPECT_LT(m.point.norm(), 0.0002);
}

TEST(LinesMeet, ParallelOrTooFewLinesThrow) {
  EXPECT_THROW(meet_lines(std::vector<Line2>{{{0, 0}, {1, 0}}}), std::invalid_argument);
  EXPECT_THROW(meet_lines(pencil({0, 0}, 0.3, 0.3, 20, 0.001, 0.0, 2)), std::invalid_argument);
}

}  // namespace
}  // namespace pinball::calibration
