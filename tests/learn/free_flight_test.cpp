#include "pinball/learn/free_flight.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <vector>

#include "common/thesis_board.h"
#include "pinball/core/rng.h"

namespace pinball::learn {
namespace {

constexpr double kFrame_s = 0.005;

// A ball flying under acceleration (lateral, −g) with drag c from p0, v0,
// seen every frame for `duration_s` with noise σ, appended to `play`.
void fly(bus::RecordedPlay& play, double t0, Vec2 p0, Vec2 v0, double g, double lateral, double c, double duration_s,
         double sigma_m, Rng& rng) {
  const Vec2 a(lateral, -g);
  for (double tau = 0.0; tau <= duration_s + 1e-9; tau += kFrame_s) {
    const double f = c > 0.0 ? -std::expm1(-c * tau) / c : tau;
    const double h = c > 0.0 ? (tau - f) / c : 0.5 * tau * tau;
    const Vec2 p = p0 + v0 * f + a * h + sigma_m * Vec2(rng.normal(), rng.normal());
    play.frames.push_back({t0 + tau, static_cast<std::int64_t>(play.frames.size()), true, p, false, false});
  }
}

TEST(FreeFlight, ClearOfObstaclesAndFlipperSweeps) {
  const table::Board& board = pinball::testing::thesis_board();
  EXPECT_TRUE(ball_is_clear(board, {0.22, 0.38}, 0.003));
  EXPECT_FALSE(ball_is_clear(board, {0.0135 + 0.001, 0.30}, 0.003));  // against the left wall
  EXPECT_TRUE(ball_is_clear(board, {0.0135 + 0.004, 0.30}, 0.003));
  // Above the left flipper's down position, where the bat sweeps when it fires.
  const table::Flipper& left = board.flippers[0];
  const Vec2 mid_up = left.pivot + 0.6 * left.length_m * table::flipper_direction(left, left.theta_max_rad);
  EXPECT_FALSE(ball_clear_of_flippers(board, mid_up, 0.003));
  EXPECT_TRUE(ball_clear_of_flippers(board, {0.25, 0.45}, 0.003));
}

TEST(FreeFlight, AKinkInMidAirEndsOneFlightAndStartsTheNext) {
  const table::Board& board = pinball::testing::thesis_board();
  Rng rng(3);
  bus::RecordedPlay play;
  fly(play, 0.0, {0.22, 0.36}, {0.3, 0.4}, 1.11, 0.0, 0.0, 0.15, 0.0005, rng);
  const Vec2 p_kink(0.22 + 0.3 * 0.15, 0.36 + 0.4 * 0.15 - 0.5 * 1.11 * 0.15 * 0.15);
  const Vec2 v_kink(-0.3, 0.4 - 1.11 * 0.15);  // something unseen turned it
  fly(play, 0.15 + kFrame_s, p_kink + kFrame_s * v_kink, v_kink, 1.11, 0.0, 0.0, 0.15, 0.0005, rng);
  const std::vector<FreeFlight> flights = find_free_flights(play, 0, board);
  ASSERT_EQ(flights.size(), 2u);
  EXPECT_LE(flights[0].t_last_s, 0.15 + 2 * kFrame_s);
  EXPECT_GE(flights[1].t_first_s, 0.15 - 2 * kFrame_s);
  for (const FreeFlight& f : flights) {
    EXPECT_GE(f.last - f.first + 1, 20u);
    EXPECT_NEAR(f.fit.g_mps2, 1.11, 0.3);
  }
  EXPECT_NEAR(flights[0].fit.v_ref.x(), 0.3, 0.05);
  EXPECT_NEAR(flights[1].fit.v_ref.x(), -0.3, 0.05);
}

TEST(FreeFlight, AClosedContactSwitchOrAGapEndsAFlight) {
  const table::Board& board = pinball::testing::thesis_board();
  Rng rng(4);
  bus::RecordedPlay play;
  fly(play, 0.0, {0.22, 0.36}, {0.3, 0.4}, 1.11, 0.0, 0.0, 0.3, 0.0005, rng);
  for (std::size_t i = 28; i < 32; ++i) play.frames[i].contact_left = true;
  EXPECT_EQ(find_free_flights(play, 0, board).size(), 2u);
  for (std::size_t i = 28; i < 32; ++i) play.frames[i].contact_left = false;
  play.frames.erase(play.frames.begin() + 28, play.frames.begin() + 34);  // 35 ms unseen
  EXPECT_EQ(find_free_flights(play, 0, board).size(), 2u);
}

TEST(FreeFlight, ABallAtRestIsNotFlying) {
  const table::Board& board = pinball::testing::thesis_board();
  Rng rng(5);
  bus::RecordedPlay play;
  fly(play, 0.0, {0.22, 0.38}, {0.0, 0.0}, 0.0, 0.0, 0.0, 0.5, 0.0003, rng);
  EXPECT_TRUE(find_free_flights(play, 0, board).empty());
}

// Many flights under one known acceleration, each its own recording-free span.
struct Flights {
  std::vector<bus::RecordedPlay> recordings{1};
  std::vector<FreeFlight> flights;
};

Flights many_flights(double g, double lateral, double c, double sigma_m, std::uint64_t seed) {
  Flights out;
  Rng rng(seed);
  bus::RecordedPlay& play = out.recordings[0];
  for (int k = 0; k < 40; ++k) {
    const double t0 = 2.0 * k;
    const std::size_t first = play.frames.size();
    const Vec2 p0(rng.uniform(0.15, 0.35), rng.uniform(0.3, 0.4));
    const Vec2 v0(rng.uniform(-0.5, 0.5), rng.uniform(-0.5, 1.0));
    fly(play, t0, p0, v0, g, lateral, c, rng.uniform(0.08, 0.3), sigma_m, rng);
    FreeFlight f;
    f.first = first;
    f.last = play.frames.size() - 1;
    f.t_first_s = play.frames[f.first].t_s;
    f.t_last_s = play.frames[f.last].t_s;
    out.flights.push_back(f);
  }
  return out;
}

TEST(FreeFlight, SharedFitRecoversGravityTiltAndDrag) {
  const Flights data = many_flights(0.85, 0.02, 0.4, 0.0005, 11);
  const FlightGravity fit = fit_flight_gravity(data.recordings, data.flights, 1.11, 0.0005, true, 0, 1);
  EXPECT_EQ(fit.flights, 40);
  EXPECT_EQ(fit.flights_dropped, 0);
  EXPECT_TRUE(fit.drag_fitted);
  EXPECT_NEAR(fit.g_mps2, 0.85, 4.0 * fit.g_stderr_mps2 + 1e-6);
  EXPECT_NEAR(fit.lateral_mps2, 0.02, 4.0 * fit.lateral_stderr_mps2 + 1e-6);
  EXPECT_NEAR(fit.drag_per_s, 0.4, 4.0 * fit.drag_stderr_per_s + 1e-6);
  EXPECT_LT(fit.g_stderr_mps2, 0.02);
  EXPECT_NEAR(fit.rms_fitted_m, 0.0005, 0.0001);  // down to the camera's noise
  EXPECT_GT(fit.rms_nominal_m, fit.rms_fitted_m);
}

TEST(FreeFlight, WithoutDragTheFitIsExactOnNoiselessFlights) {
  const Flights data = many_flights(0.95, -0.01, 0.0, 0.0, 12);
  const FlightGravity fit = fit_flight_gravity(data.recordings, data.flights, 1.11, 0.0005, false, 0, 1);
  EXPECT_NEAR(fit.g_mps2, 0.95, 1e-6);
  EXPECT_NEAR(fit.lateral_mps2, -0.01, 1e-6);
  EXPECT_EQ(fit.drag_per_s, 0.0);
  EXPECT_LT(fit.rms_fitted_m, 1e-7);
}

TEST(FreeFlight, BootstrapGivesAnUncertaintyNearTheCovariancesOnIndependentNoise) {
  const Flights data = many_flights(0.9, 0.0, 0.0, 0.001, 13);
  std::vector<int> done;
  const FlightGravity fit = fit_flight_gravity(data.recordings, data.flights, 1.11, 0.001, false, 40, 7,
                                               [&](int d, int) { done.push_back(d); });
  ASSERT_EQ(done.size(), 41u) << "0 as it starts, then after each resample";
  EXPECT_EQ(done.front(), 0);
  EXPECT_EQ(done.back(), 40);
  EXPECT_EQ(fit.bootstrap_resamples, 40);
  EXPECT_GT(fit.g_stderr_mps2, fit.g_covariance_stderr_mps2 / 3.0);
  EXPECT_LT(fit.g_stderr_mps2, fit.g_covariance_stderr_mps2 * 3.0);
  EXPECT_NEAR(fit.g_mps2, 0.9, 4.0 * fit.g_stderr_mps2);
}

// Flights that roll under (0, −g_roll), then flights that skid: the slope's
// full pull, 7/5 of the rolling one, less μ·g_n against a slip in a random
// direction; then skids too short to judge.
Flights rolling_and_skidding(double g_roll, double mu_g_n, double sigma_m, std::uint64_t seed) {
  Flights out;
  Rng rng(seed);
  bus::RecordedPlay& play = out.recordings[0];
  for (int k = 0; k < 70; ++k) {
    const bool skids = k >= 30;
    const double heading = rng.uniform(0.0, 2.0 * std::numbers::pi);
    const Vec2 a = skids ? Vec2(1.4 * Vec2(0.0, -g_roll) - mu_g_n * Vec2(std::cos(heading), std::sin(heading)))
                         : Vec2(0.0, -g_roll);
    const std::size_t first = play.frames.size();
    const Vec2 p0(rng.uniform(0.15, 0.35), rng.uniform(0.3, 0.4));
    const Vec2 v0(rng.uniform(-0.5, 0.5), rng.uniform(-0.5, 1.0));
    const double duration_s = k >= 60 ? 0.05 : rng.uniform(0.15, 0.3);
    fly(play, 2.0 * k, p0, v0, -a.y(), a.x(), 0.0, duration_s, sigma_m, rng);
    out.flights.push_back({0, first, play.frames.size() - 1, play.frames[first].t_s, play.frames.back().t_s, {}});
  }
  return out;
}

TEST(SlidingFriction, NoiselessSkidsGiveMuTimesGExactly) {
  const Flights data = rolling_and_skidding(0.79, 1.95, 0.0, 21);
  FlightGravity rolling;
  rolling.g_mps2 = 0.79;
  const SlidingFriction friction = fit_sliding_friction(data.recordings, data.flights, rolling, 0.0005);
  EXPECT_EQ(friction.flights, 60);  // the ten short skids are not judged
  EXPECT_EQ(friction.skidding, 30);
  EXPECT_NEAR(friction.decel_mps2, 1.95, 1e-6);
  EXPECT_DOUBLE_EQ(friction.min_duration_s, 0.1);
}

TEST(SlidingFriction, NoisySkidsGiveMuTimesGWithinItsUncertainty) {
  const Flights data = rolling_and_skidding(0.79, 1.95, 0.0005, 22);
  FlightGravity rolling;
  rolling.g_mps2 = 0.79;
  const SlidingFriction friction = fit_sliding_friction(data.recordings, data.flights, rolling, 0.0005);
  EXPECT_EQ(friction.flights, 60);
  EXPECT_GE(friction.skidding, 30);  // every skid, and at most a false alarm among the 30 rolling flights
  EXPECT_LE(friction.skidding, 31);
  EXPECT_GT(friction.decel_stderr_mps2, 0.0);
  EXPECT_LT(friction.decel_stderr_mps2, 0.1);
  EXPECT_NEAR(friction.decel_mps2, 1.95, 4.0 * friction.decel_stderr_mps2);
}

TEST(SlidingFriction, RollingFlightsShowNone) {
  const Flights data = many_flights(0.9, 0.0, 0.0, 0.0005, 23);
  FlightGravity rolling;
  rolling.g_mps2 = 0.9;
  const SlidingFriction friction = fit_sliding_friction(data.recordings, data.flights, rolling, 0.0005);
  EXPECT_GT(friction.flights, 20);
  EXPECT_LE(friction.skidding, 1);
  if (friction.skidding == 0) {
    EXPECT_EQ(friction.decel_mps2, 0.0);
  }
}

TEST(FreeFlight, RefusesFewerThanTwoFlights) {
  const Flights data = many_flights(0.9, 0.0, 0.0, 0.001, 14);
  EXPECT_THROW(fit_flight_gravity(data.recordings, std::span(data.flights).first(1), 1.11, 0.001, false, 0, 1),
               std::runtime_error);
}

}  // namespace
}  // namespace pinball::learn
