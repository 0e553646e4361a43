#include "transfer_bench.h"

#include <limits>
#include <stdexcept>

#include <gtest/gtest.h>

#include "common/thesis_board.h"
#include "pinball/control/spastic_controller.h"
#include "pinball/core/rng.h"
#include "pinball/learn/evaluator.h"
#include "pinball/sim/model_world.h"

namespace pinball::bench {
namespace {

using pinball::testing::thesis_board;

const control::ControllerSpec& best() {
  static const control::ControllerSpec spec = control::load_controller(PINBALL_SOURCE_DIR "/controllers/best.json");
  return spec;
}

// 3 balls of 8 s at most in the model and event worlds, the twin, and two sweep worlds that matter.
TransferBenchOptions tiny() {
  TransferBenchOptions o;
  o.balls = 3;
  o.twin_balls = 2;  // the twin plays ~100x slower: fewer of the same balls
  o.seed = 5;
  o.threads = 2;
  o.max_ball_time_s = 8.0;
  o.sweep = {{Perturbation::kGravity_pct, {10}}, {Perturbation::kActuationDelay_ms, {4, 20}}};
  o.combined = {{"combined_test", sim::StepperKind::kEvent, {{Perturbation::kGravity_pct, -3.0}}}};
  o.controllers = {{"best", "controllers/best.json", &best()}};
  return o;
}

const TransferWorld& world_named(const TransferReport& r, const std::string& name) {
  for (const TransferWorld& w : r.worlds) {
    if (w.name == name) return w;
  }
  throw std::runtime_error("no world " + name);
}

TEST(TransferBench, EveryWorldHasEveryControllerOnTheSameBalls) {
  int lines = 0;
  std::string last;
  const TransferReport r = run_transfer_bench(thesis_board(), tiny(), [&](const std::string& l) {
    ++lines;
    last = l;
  });
  // model, event, twin; the nominal 4 ms delay is the model world, not played twice; the combined world last.
  ASSERT_EQ(r.worlds.size(), 6u);
  EXPECT_EQ(r.worlds[0].name, "model");
  EXPECT_EQ(r.worlds[1].world, "event");
  EXPECT_EQ(r.worlds[3].name, "gravity_pct=+10");
  EXPECT_EQ(r.worlds[4].name, "actuation_delay_ms=20");
  EXPECT_EQ(r.worlds[5].name, "combined_test");
  EXPECT_EQ(r.worlds[5].family, "combined");
  EXPECT_EQ(r.worlds[5].world, "event");
  const TransferWorld& twin = world_named(r, "twin");
  EXPECT_EQ(twin.played, simlab::twin_available());
  if (!twin.played) {
    EXPECT_NE(twin.skipped_reason.find("twin"), std::string::npos) << twin.skipped_reason;
    EXPECT_TRUE(twin.cells.empty()) << "a skipped world is never faked";
  } else {
    EXPECT_EQ(twin.balls, 2);
    EXPECT_EQ(twin.world, "twin");
  }
  for (const TransferWorld& w : r.worlds) {
    if (!w.played) continue;
    ASSERT_EQ(w.cells.size(), 2u) << w.name;
    EXPECT_EQ(w.cells[0].controller, "spastic");
    EXPECT_EQ(w.cells[1].controller, "best");
    const int balls = w.name == "twin" ? 2 : 3;
    EXPECT_EQ(w.balls, balls) << w.name;
    for (const TransferCell& c : w.cells) {
      EXPECT_EQ(c.score.count(), balls) << w.name << " " << c.controller;
      EXPECT_EQ(c.cut + c.drains.total(), balls) << w.name << " " << c.controller;
      EXPECT_LE(c.outlane_after_flipper_s.count(), c.drains.left_outlane + c.drains.right_outlane);
      if (c.outlane_after_flipper_s.count() > 0) {
        EXPECT_GT(c.outlane_after_flipper_s.min(), 0.0) << w.name << " " << c.controller;
        EXPECT_LE(c.outlane_after_flipper_s.max(), c.duration_s.max()) << w.name << " " << c.controller;
      }
      EXPECT_LE(c.duration_s.max(), 8.0 + 1e-9);
      EXPECT_GT(c.wall_s, 0.0);
    }
    EXPECT_EQ(w.cells[0].ratio_to_spastic, 1.0) << "the spastic flipper against itself";
    EXPECT_DOUBLE_EQ(w.cells[1].ratio_to_spastic, w.cells[1].score.mean() / w.cells[0].score.mean());
    EXPECT_FALSE(w.cells[0].ratio_interval.has_value()) << "the spastic flipper against itself";
    const auto expected = ratio_of_means_ci95(w.cells[1].score, w.cells[0].score);
    ASSERT_EQ(w.cells[1].ratio_interval.has_value(), expected.has_value()) << w.name;
    if (expected) {
      EXPECT_EQ(w.cells[1].ratio_interval->low, expected->low) << w.name;
      EXPECT_EQ(w.cells[1].ratio_interval->high, expected->high) << w.name;
    }
  }
  EXPECT_GE(lines, 1);
  EXPECT_EQ(last.rfind("transfer: ", 0), 0u) << last;
  EXPECT_NE(last.find("(100 %)"), std::string::npos) << last;
  EXPECT_FALSE(r.sensitivities.empty()) << "g is an offset family";
}

TEST(TransferBench, RatiosAreAgainstTheFirstCellTheSpasticFlippers) {
  std::vector<TransferCell> cells(3);
  for (const double x : {900.0, 1100.0, 1000.0}) cells[0].score.add(x);
  for (const double x : {2500.0, 1500.0, 2000.0}) cells[1].score.add(x);
  cells[2].score.add(3000.0);  // one ball: a ratio, no interval
  set_ratios_to_spastic(cells);
  EXPECT_EQ(cells[0].ratio_to_spastic, 1.0);
  EXPECT_FALSE(cells[0].ratio_interval.has_value());
  EXPECT_DOUBLE_EQ(cells[1].ratio_to_spastic, 2.0);
  ASSERT_TRUE(cells[1].ratio_interval.has_value());
  EXPECT_LT(cells[1].ratio_interval->low, 2.0);
  EXPECT_GT(cells[1].ratio_interval->high, 2.0);
  EXPECT_DOUBLE_EQ(cells[2].ratio_to_spastic, 3.0);
  EXPECT_FALSE(cells[2].ratio_interval.has_value());
  std::vector<TransferCell> none;
  set_ratios_to_spastic(none);  // no cells, nothing to do
  EXPECT_TRUE(none.empty());
}

TEST(TransferBench, ACombinedWorldAppliesEachChangeToTheNominalWorld) {
  // On the thesis stepper, g +10 % alone is the sweep's g +10 % world, and 5 ms
  // more latency than the nominal 5 ms is its 10 ms world: the same balls, bit for bit.
  TransferBenchOptions o = tiny();
  o.sweep = {{Perturbation::kGravity_pct, {10}}, {Perturbation::kCameraLatency_ms, {10}}};
  o.combined = {{"g", sim::StepperKind::kThesis, {{Perturbation::kGravity_pct, 10.0}}},
                {"latency", sim::StepperKind::kThesis, {{Perturbation::kCameraLatency_ms, 5.0}}},
                {"both", sim::StepperKind::kThesis,
                 {{Perturbation::kGravity_pct, 10.0}, {Perturbation::kCameraLatency_ms, 5.0}}}};
  const TransferReport r = run_transfer_bench(thesis_board(), o, {});
  const auto same = [&](const std::string& a, const std::string& b) {
    const TransferWorld& p = world_named(r, a);
    const TransferWorld& q = world_named(r, b);
    ASSERT_EQ(p.cells.size(), q.cells.size());
    for (std::size_t k = 0; k < p.cells.size(); ++k) {
      EXPECT_EQ(p.cells[k].score.mean(), q.cells[k].score.mean()) << a << " " << b << " " << p.cells[k].controller;
      EXPECT_EQ(p.cells[k].duration_s.mean(), q.cells[k].duration_s.mean()) << a << " " << b;
    }
  };
  same("g", "gravity_pct=+10");
  same("latency", "camera_latency_ms=10");
  const TransferWorld& both = world_named(r, "both");
  EXPECT_NE(both.cells[0].duration_s.mean(), world_named(r, "g").cells[0].duration_s.mean())
      << "the latency moves the tracker-side spastic flipper too";
  EXPECT_EQ(both.world, "thesis");
}

TEST(TransferBench, TheDefaultCombinedWorldsAreTheIssuesDifferencesTogether) {
  const std::vector<CombinedWorld> c = default_combined_worlds();
  ASSERT_EQ(c.size(), 2u);
  for (const CombinedWorld& w : c) {
    EXPECT_EQ(w.stepper, sim::StepperKind::kEvent) << w.name;
    ASSERT_EQ(w.changes.size(), 3u) << w.name;
    EXPECT_EQ(w.changes[1], std::make_pair(Perturbation::kGravity_pct, -3.0));
    EXPECT_EQ(w.changes[2], std::make_pair(Perturbation::kCameraLatency_ms, 5.0));
  }
  EXPECT_EQ(c[0].name, "combined_mu-20");
  EXPECT_EQ(c[0].changes[0], std::make_pair(Perturbation::kFlipperMu_pct, -20.0));
  EXPECT_EQ(c[1].name, "combined_mu+20");
  EXPECT_EQ(c[1].changes[0], std::make_pair(Perturbation::kFlipperMu_pct, 20.0));
}

TEST(TransferBench, SameSeedSameCellsWhateverTheThreads) {
  TransferBenchOptions one = tiny();
  one.threads = 1;
  const TransferReport a = run_transfer_bench(thesis_board(), one, {});
  const TransferReport b = run_transfer_bench(thesis_board(), tiny(), {});
  ASSERT_EQ(a.worlds.size(), b.worlds.size());
  for (std::size_t i = 0; i < a.worlds.size(); ++i) {
    ASSERT_EQ(a.worlds[i].cells.size(), b.worlds[i].cells.size());
    for (std::size_t k = 0; k < a.worlds[i].cells.size(); ++k) {
      const TransferCell& p = a.worlds[i].cells[k];
      const TransferCell& q = b.worlds[i].cells[k];
      EXPECT_EQ(p.score.mean(), q.score.mean()) << a.worlds[i].name;
      EXPECT_EQ(p.score.variance(), q.score.variance()) << a.worlds[i].name;
      EXPECT_EQ(p.flips.mean(), q.flips.mean()) << a.worlds[i].name;
      EXPECT_EQ(p.drains.centre, q.drains.centre) << a.worlds[i].name;
    }
  }
}

TEST(TransferBench, APerturbationThatMattersChangesTheScores) {
  const TransferReport r = run_transfer_bench(thesis_board(), tiny(), {});
  const TransferWorld& model = world_named(r, "model");
  for (const std::string name : {"gravity_pct=+10", "actuation_delay_ms=20"}) {
    const TransferWorld& w = world_named(r, name);
    for (std::size_t k = 0; k < w.cells.size(); ++k) {
      EXPECT_NE(w.cells[k].score.mean(), model.cells[k].score.mean()) << name << " " << w.cells[k].controller;
    }
  }
}

TEST(TransferBench, ABallIsTheEvaluatorsBall) {
  // The bench's loop is the fast loop's: the same ball seed scores what learn's evaluator scores.
  learn::EvaluatorConfig config;
  config.max_ball_time_s = 8.0;
  const learn::PinballEvaluator ev(thesis_board(), config);
  const std::unique_ptr<sim::World> world = sim::make_model_world(thesis_board());
  const WorldSettings nominal{thesis_board(), config.actuation_delay_s, config.camera};
  for (std::uint64_t i = 0; i < 3; ++i) {
    const std::uint64_t seed = ball_seed(5, i);
    control::SpasticController spastic;
    EXPECT_EQ(play_transfer_ball(*world->fork(), nominal, thesis_board(), config.camera, nullptr, 8.0, seed).score,
              ev.play_with(spastic, -1.0, seed).score);
    EXPECT_EQ(play_transfer_ball(*world->fork(), nominal, thesis_board(), config.camera, &best(), 8.0, seed).score,
              ev.play(best(), seed).score);
  }
}

TEST(TransferBench, BadOptionsAreRefused) {
  TransferBenchOptions o = tiny();
  o.balls = 0;
  EXPECT_THROW(run_transfer_bench(thesis_board(), o, {}), std::invalid_argument);
  o = tiny();
  o.max_ball_time_s = 0.0;
  EXPECT_THROW(run_transfer_bench(thesis_board(), o, {}), std::invalid_argument);
  for (const double target : {0.0, -1.0, std::numeric_limits<double>::quiet_NaN()}) {
    o = tiny();
    o.target_ratio = target;
    EXPECT_THROW(run_transfer_bench(thesis_board(), o, {}), std::invalid_argument) << target;
  }
  o = tiny();
  o.controllers.push_back(o.controllers.front());
  EXPECT_THROW(run_transfer_bench(thesis_board(), o, {}), std::invalid_argument) << "two named best";
  control::ControllerSpec random_launch = best();
  random_launch.randomise_launch = true;
  o = tiny();
  o.controllers = {{"random", "random.json", &random_launch}};
  EXPECT_THROW(run_transfer_bench(thesis_board(), o, {}), std::invalid_argument);
  o = tiny();
  o.sweep = {{Perturbation::kGravity_pct, {-100}}};
  EXPECT_THROW(run_transfer_bench(thesis_board(), o, {}), std::invalid_argument);
}

}  // namespace
}  // namespace pinball::bench
