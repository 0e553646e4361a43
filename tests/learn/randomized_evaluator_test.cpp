#include "pinball/learn/randomized_evaluator.h"

#include <gtest/gtest.h>

#include <set>

#include "common/thesis_board.h"
#include "pinball/core/name_value.h"
#include "pinball/sim/model_world.h"

namespace pinball::learn {
namespace {

const char* kRanges = R"(variants: 16
seed: 3
event_stepper_share: 0.5
ranges:
  gravity_pct: [-5, 5]
  wall_rho: [-0.1, 0.1]
  flipper_mu_pct: [-20, 20]
  actuation_delay_ms: [2, 10]
  camera_latency_ms: [0, 10]
)";

std::string error_of(const std::string& text) {
  try {
    parse_randomization(text, "r.yaml");
  } catch (const std::exception& e) {
    return e.what();
  }
  return "";
}

TEST(Randomization, ParsesRangesAndLeavesTheRestNominal) {
  const Randomization r = parse_randomization(kRanges, "r.yaml");
  EXPECT_EQ(r.source, "r.yaml");
  EXPECT_EQ(r.variants, 16);
  EXPECT_EQ(r.seed, 3u);
  ASSERT_TRUE(r.range(Perturbation::kGravity_pct).has_value());
  EXPECT_EQ((*r.range(Perturbation::kGravity_pct))[0], -5.0);
  EXPECT_FALSE(r.range(Perturbation::kPivotY_mm).has_value());
  EXPECT_FALSE(r.range(Perturbation::kCameraNoise_px).has_value());
}

TEST(Randomization, RefusesBadFilesNamingTheKey) {
  const std::string base = "variants: 4\nseed: 1\nevent_stepper_share: 0\nranges:\n";
  EXPECT_NE(error_of(base + "  gravity_percent: [-5, 5]\n").find("gravity_percent"), std::string::npos);
  EXPECT_NE(error_of(base + "  gravity_pct: [5, -5]\n").find("r.yaml:ranges.gravity_pct"), std::string::npos);
  EXPECT_NE(error_of(base + "  camera_latency_ms: [-1, 5]\n").find("ranges.camera_latency_ms"), std::string::npos);
  EXPECT_NE(error_of("variants: 0\nseed: 1\nevent_stepper_share: 0\nranges: {}\n").find("variants"),
            std::string::npos);
  EXPECT_NE(error_of("variants: 4\nseed: 1\nevent_stepper_share: 2\nranges: {}\n").find("event_stepper_share"),
            std::string::npos);
  EXPECT_NE(error_of("variants: 4\nseed: 1\nranges: {}\n").find("event_stepper_share"), std::string::npos);
  EXPECT_THROW(load_randomization("/nonexistent/r.yaml"), std::runtime_error);
}

TEST(Randomization, DrawsEveryWorldWithinItsRangesTheSameWayEachTime) {
  const table::Board& belief = pinball::testing::thesis_board();
  EvaluatorConfig config;
  const Randomization r = parse_randomization(kRanges, "r.yaml");
  const std::vector<DrawnWorld> worlds = draw_worlds(belief, config, r);
  ASSERT_EQ(worlds.size(), 16u);
  int event = 0;
  std::set<double> gravities;
  for (const DrawnWorld& w : worlds) {
    event += w.stepper == sim::StepperKind::kEvent ? 1 : 0;
    ASSERT_EQ(w.values.size(), 5u);
    const double g = w.settings.board.gravity_mps2 / belief.gravity_mps2;
    EXPECT_GE(g, 0.95);
    EXPECT_LE(g, 1.05);
    gravities.insert(g);
    EXPECT_GE(w.settings.actuation_delay_s, 0.002);
    EXPECT_LE(w.settings.actuation_delay_s, 0.010);
    EXPECT_LE(w.settings.camera.latency_s, 0.010);
    EXPECT_EQ(w.settings.camera.noise_px, config.camera.noise_px);  // not in the ranges: nominal
    EXPECT_EQ(w.settings.board.flippers[0].pivot, belief.flippers[0].pivot);
  }
  EXPECT_EQ(event, 8);
  EXPECT_EQ(gravities.size(), 16u);
  const std::vector<DrawnWorld> again = draw_worlds(belief, config, r);
  for (std::size_t i = 0; i < worlds.size(); ++i)
    EXPECT_EQ(again[i].settings.board.gravity_mps2, worlds[i].settings.board.gravity_mps2);
}

// A range whose end no world allows was refused or not by what the seed drew (4 variants of
// g -150..0 % passed, 32 did not): both ends are tried first. A range past any calibration
// error (pivots 1 km off) is refused as such.
TEST(Randomization, BothEndsOfEveryRangeAreTriedBeforeAnyDraw) {
  const table::Board& belief = pinball::testing::thesis_board();
  const std::string base = "variants: 4\nseed: 1\nevent_stepper_share: 0\nranges:\n";
  const auto draw_error = [&](const std::string& ranges) -> std::string {
    try {
      draw_worlds(belief, EvaluatorConfig{}, parse_randomization(base + ranges, "r.yaml"));
    } catch (const std::invalid_argument& e) {
      return e.what();
    }
    return "";
  };
  EXPECT_EQ(draw_error("  gravity_pct: [-150, 0]\n"),
            "r.yaml: ranges.gravity_pct: its end -150: perturbation: g must stay > 0 (g -100 % or less)");
  EXPECT_EQ(draw_error("  pivot_y_mm: [0, 1000000]\n"),
            "r.yaml: ranges.pivot_y_mm: its end 1000000: perturbation: pivot_y must be in [-100, 100] mm");
  EXPECT_NE(draw_error("  camera_noise_px: [0, 1000000000]\n").find("camera noise must be in [0, 100] px"),
            std::string::npos);
  EXPECT_EQ(draw_error("  gravity_pct: [-50, 50]\n"), "");
}

TEST(RandomizedEvaluator, EachBallPlaysTheWorldItsSeedPicksBelievingTheBoard) {
  const table::Board& belief = pinball::testing::thesis_board();
  EvaluatorConfig config;
  config.max_ball_time_s = 20.0;
  const Randomization r = parse_randomization(kRanges, "r.yaml");
  const RandomizedEvaluator randomized(belief, config, r);
  std::set<std::size_t> used;
  for (std::uint64_t seed = 0; seed < 200; ++seed) {
    used.insert(randomized.world_of(seed));
    EXPECT_EQ(randomized.world_of(seed), drawn_world_index(seed, 16));  // the rule imitation's teacher uses too
  }
  EXPECT_EQ(used.size(), 16u);
  const control::ControllerSpec spec = randomized.prototype();
  for (std::uint64_t seed : {5u, 6u, 7u}) {
    const DrawnWorld& w = randomized.worlds()[randomized.world_of(seed)];
    EvaluatorConfig c = config;
    c.actuation_delay_s = w.settings.actuation_delay_s;
    c.world_camera = w.settings.camera;
    sim::ModelWorldOptions options;
    options.stepper = w.stepper;
    const PinballEvaluator alone(belief, c, sim::make_model_world(w.settings.board, options));
    const BallOutcome a = randomized.play(spec, seed);
    const BallOutcome b = alone.play(spec, seed);
    EXPECT_EQ(a.score, b.score) << seed;
    EXPECT_EQ(a.duration_s, b.duration_s) << seed;
    EXPECT_EQ(a.score, randomized.play(spec, seed).score);  // the same ball twice
  }
}

}  // namespace
}  // namespace pinball::learn
