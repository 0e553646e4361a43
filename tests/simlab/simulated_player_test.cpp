#include "pinball/simlab/simulated_player.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <stdexcept>

#include "pinball/control/spastic_controller.h"
#include "pinball/sim/model_world.h"
#include "pinball/sim/ball_runner.h"
#include "pinball/table/board_loader.h"
#include "pinball/sim/thesis_stepper.h"
#include "common/thesis_board.h"

namespace pinball::simlab {
namespace {

constexpr int kBalls = 20;

using pinball::testing::thesis_board;

sim::BallLimits limits() {
  sim::BallLimits l;
  l.max_ball_time_s = 30.0;  // keeps the suite quick; a cut ball still counts its score
  return l;
}

struct Totals {
  double score = 0.0;
  long flips = 0;
  std::uint64_t observations = 0;
  double time_s = 0.0;
};

// One ball per seed, seeds 1..kBalls, with the tracked spastic player.
Totals play_tracked(const track::CameraModelConfig& camera) {
  const std::unique_ptr<sim::World> world = sim::make_model_world(thesis_board());
  Totals t;
  for (int seed = 1; seed <= kBalls; ++seed) {
    sim::GameState s = sim::make_game_state(thesis_board(), static_cast<std::uint64_t>(seed));
    SimulatedSpasticPlayer player(thesis_board(), camera, control::SpasticConfig{}, static_cast<std::uint64_t>(seed));
    const sim::BallResult r = sim::play_ball(
        *world, s, limits(), [&](sim::GameState& st) { player.act(st); },
        [](const sim::GameState&, const sim::StepEvents&) {});
    t.score += r.score;
    t.flips += r.flips;
    t.observations += player.observations();
    t.time_s += r.duration_s;
  }
  return t;
}

// The same balls with nobody at the buttons.
Totals play_idle() {
  const std::unique_ptr<sim::World> world = sim::make_model_world(thesis_board());
  Totals t;
  for (int seed = 1; seed <= kBalls; ++seed) {
    sim::GameState s = sim::make_game_state(thesis_board(), static_cast<std::uint64_t>(seed));
    const sim::BallResult r = sim::play_ball(
        *world, s, limits(), [](sim::GameState&) {}, [](const sim::GameState&, const sim::StepEvents&) {});
    t.score += r.score;
    t.flips += r.flips;
    t.time_s += r.duration_s;
  }
  return t;
}

TEST(SimulatedSpasticPlayer, FlipsAndScoresMoreThanDoingNothing) {
  const Totals idle = play_idle();
  EXPECT_EQ(idle.flips, 0);
  const Totals tracked = play_tracked(track::CameraModelConfig{});
  EXPECT_GT(tracked.flips, kBalls);  // more than one flip a ball on average
  EXPECT_GT(tracked.score / kBalls, idle.score / kBalls);
  EXPECT_GT(tracked.time_s, idle.time_s);  // it keeps balls alive
  // Every frame of the camera reached the tracker: about 200 a second of play.
  EXPECT_NEAR(static_cast<double>(tracked.observations), 200.0 * tracked.time_s, 0.05 * 200.0 * tracked.time_s);
  RecordProperty("idle_mean_score", std::to_string(idle.score / kBalls));
  RecordProperty("tracked_mean_score", std::to_string(tracked.score / kBalls));
}

TEST(SimulatedSpasticPlayer, StillWorksWithLatencyAndNoise) {
  track::CameraModelConfig camera;
  camera.latency_s = 0.010;
  camera.noise_px = 1.0;
  const Totals idle = play_idle();
  const Totals tracked = play_tracked(camera);
  EXPECT_GT(tracked.flips, kBalls);
  EXPECT_GT(tracked.score / kBalls, idle.score / kBalls);
}

TEST(SimulatedSpasticPlayer, SeesTheBallOnlyThroughTheCamera) {
  // Two identical players: one acts on the true state, the other on a copy
  // whose velocity (which no camera measures) is NaN. Their commands must
  // agree at every step: nothing but the position reaches the tracker.
  const std::unique_ptr<sim::World> world = sim::make_model_world(thesis_board());
  track::CameraModelConfig camera;
  camera.latency_s = 0.010;
  for (int seed = 1; seed <= 3; ++seed) {
    sim::GameState s = sim::make_game_state(thesis_board(), static_cast<std::uint64_t>(seed));
    SimulatedSpasticPlayer truth(thesis_board(), camera, control::SpasticConfig{}, 7);
    SimulatedSpasticPlayer blind(thesis_board(), camera, control::SpasticConfig{}, 7);
    long steps = 0;
    long disagreements = 0;
    long energized_steps = 0;
    sim::GameState shadow = s;
    sim::play_ball(
        *world, s, limits(),
        [&](sim::GameState& st) {
          shadow = st;
          shadow.ball.velocity_mps = Vec2::Constant(std::numeric_limits<double>::quiet_NaN());
          shadow.score = -1.0;
          truth.act(st);
          blind.act(shadow);
          ++steps;
          for (std::size_t f = 0; f < st.flippers.size(); ++f) {
            if (st.flippers[f].energized != shadow.flippers[f].energized) ++disagreements;
            if (st.flippers[f].energized) ++energized_steps;
          }
        },
        [](const sim::GameState&, const sim::StepEvents&) {});
    EXPECT_EQ(disagreements, 0) << "seed " << seed;
    EXPECT_GT(steps, 1000);
    EXPECT_GT(energized_steps, 0) << "seed " << seed;  // it did play
    EXPECT_EQ(truth.observations(), blind.observations());
    EXPECT_EQ(truth.last_output().projection.h, blind.last_output().projection.h);
  }
}

TEST(SimulatedSpasticPlayer, BallOutOfPlayReleasesTheFlippersAndSeesNothing) {
  const table::Board& b = thesis_board();
  sim::GameState s = sim::make_game_state(b, 1);
  SimulatedSpasticPlayer player(b, track::CameraModelConfig{}, control::SpasticConfig{}, 1);
  ASSERT_FALSE(s.ball_in_play);
  for (auto& f : s.flippers) f.energized = true;
  for (int i = 0; i < 100; ++i) {
    player.act(s);
    s.time_s += b.dt_s;
  }
  EXPECT_EQ(player.observations(), 0u);
  for (const auto& f : s.flippers) EXPECT_FALSE(f.energized);
}

TEST(SimulatedSpasticPlayer, BadSettingsThrow) {
  track::CameraModelConfig bad;
  bad.fps = 0.0;
  EXPECT_THROW(SimulatedSpasticPlayer(thesis_board(), bad, control::SpasticConfig{}, 1), std::invalid_argument);
  table::Board one = thesis_board();
  one.flippers.pop_back();
  EXPECT_THROW(SimulatedSpasticPlayer(one, track::CameraModelConfig{}, control::SpasticConfig{}, 1), std::invalid_argument);
}


// 20 balls of the tracked spastic flipper with the camera at `noise_px` and the
// tracker calibrated for the default camera: the noise the tracker measured
// (smallest and largest once it has one, after the first second of play) and
// the σ its fits used at the end.
struct MeasuredNoise {
  double least_m = 1e9;
  double most_m = 0.0;
  double in_use_m = 0.0;
  double calibrated_m = 0.0;
};

MeasuredNoise measure_camera_noise(double noise_px) {
  const std::unique_ptr<sim::World> world = sim::make_model_world(thesis_board());
  const track::CameraModelConfig calibrated;
  track::CameraModelConfig camera = calibrated;
  camera.noise_px = noise_px;
  const track::TrackerConfig believed = track::default_tracker_config(thesis_board(), calibrated);
  control::SpasticController spastic;
  SimulatedPlayer player(thesis_board(), camera, believed, spastic, 1);
  MeasuredNoise m;
  m.calibrated_m = believed.sigma_m;
  for (int seed = 1; seed <= kBalls; ++seed) {
    sim::GameState s = sim::make_game_state(thesis_board(), static_cast<std::uint64_t>(seed));
    sim::play_ball(
        *world, s, limits(), [&](sim::GameState& st) { player.act(st); },
        [&](const sim::GameState& st, const sim::StepEvents&) {
          const std::optional<double> sigma = player.tracker().measured_sigma_m();
          if (!sigma || (seed == 1 && st.time_s < 1.0)) return;
          m.least_m = std::min(m.least_m, *sigma);
          m.most_m = std::max(m.most_m, *sigma);
        });
  }
  m.in_use_m = player.tracker().sigma_m();
  return m;
}

TEST(SimulatedPlayer, TheTrackerMeasuresTheCamerasNoiseInPlay) {
  // As calibrated (0.3 px): the estimate stays within the 2x the tracker
  // allows it before it replaces the calibration, so the fits are as before.
  const MeasuredNoise as_calibrated = measure_camera_noise(0.3);
  EXPECT_LT(as_calibrated.most_m, track::kNoiseOverCalibration * as_calibrated.calibrated_m);
  EXPECT_GT(as_calibrated.least_m, 0.5 * as_calibrated.calibrated_m);
  EXPECT_DOUBLE_EQ(as_calibrated.in_use_m, as_calibrated.calibrated_m);
  // At 2 px (σ 4.04 mm with the pixel grid) the tracker weighs by what it measured.
  const MeasuredNoise noisy = measure_camera_noise(2.0);
  const double sigma_2px = track::observation_sigma_m([] {
    track::CameraModelConfig c;
    c.noise_px = 2.0;
    return c;
  }());
  EXPECT_GT(noisy.least_m, track::kNoiseOverCalibration * noisy.calibrated_m);
  EXPECT_NEAR(noisy.in_use_m, sigma_2px, 0.3 * sigma_2px);
}

}  // namespace
}  // namespace pinball::simlab
