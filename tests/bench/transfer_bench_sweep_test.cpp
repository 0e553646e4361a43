#include <algorithm>
#include <cmath>
#include <numbers>
#include <set>
#include <stdexcept>

#include <gtest/gtest.h>

#include "common/thesis_board.h"
#include "transfer_bench.h"

namespace pinball::bench {
namespace {

using pinball::testing::thesis_board;

WorldSettings nominal() { return {thesis_board(), 0.004, track::CameraModelConfig{}}; }

TEST(TransferSweep, DefaultSweepIsTheIssuesAndQuickHasOneValuePerFamily) {
  const std::vector<SweepFamily> sweep = default_transfer_sweep();
  ASSERT_EQ(sweep.size(), std::size(kAllPerturbations));
  std::set<std::string_view> names;
  for (const SweepFamily& f : sweep) names.insert(perturbation_name(f.kind));
  EXPECT_EQ(names.size(), sweep.size()) << "every family once";
  EXPECT_EQ(sweep[0].values, (std::vector<double>{-5, -3, -1, 1, 3, 5}));
  EXPECT_EQ(sweep[4].values, (std::vector<double>{-10, -5, -3, 3, 5, 10}));
  for (const SweepFamily& f : quick_transfer_sweep()) EXPECT_EQ(f.values.size(), 1u) << perturbation_name(f.kind);
  TransferBenchOptions o;
  EXPECT_EQ(nominal_value(Perturbation::kActuationDelay_ms, o), 4.0);
  EXPECT_EQ(nominal_value(Perturbation::kCameraLatency_ms, o), 5.0);
  EXPECT_EQ(nominal_value(Perturbation::kCameraNoise_px, o), 0.3);
  EXPECT_EQ(nominal_value(Perturbation::kGravity_pct, o), 0.0);
}

TEST(TransferSweep, EveryPerturbationIsFoundByItsNameAndOnlyTheTableOnesChangeTheTable) {
  for (const Perturbation p : kAllPerturbations) EXPECT_EQ(learn::parse_perturbation(perturbation_name(p)), p);
  try {
    learn::parse_perturbation("gravity");
    ADD_FAILURE() << "an unknown name is refused";
  } catch (const std::invalid_argument& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("'gravity'"), std::string::npos) << what;
    EXPECT_NE(what.find("gravity_pct"), std::string::npos) << "the message lists the names: " << what;
  }
  EXPECT_EQ(learn::parse_perturbation_setting("gravity_pct=-10"), std::make_pair(Perturbation::kGravity_pct, -10.0));
  EXPECT_EQ(learn::parse_perturbation_setting("pivot_y_mm=+3"), std::make_pair(Perturbation::kPivotY_mm, 3.0))
      << "a sweep row's own spelling";
  EXPECT_EQ(learn::parse_perturbation_setting("wall_rho=0.1"), std::make_pair(Perturbation::kWallRho, 0.1));
  for (const char* bad : {"gravity_pct", "gravity_pct=", "gravity_pct=ten", "gravity_pct=3x", "gravity_pct=nan",
                          "gravity_pct=inf", "=3", "gravity_pct=+-3"}) {
    EXPECT_THROW(learn::parse_perturbation_setting(bad), std::invalid_argument) << bad;
  }
  const WorldSettings n = nominal();
  for (const Perturbation p : kAllPerturbations) {
    const WorldSettings w = perturb(n, p, 1.0);
    const bool table_changed = w.board.gravity_mps2 != n.board.gravity_mps2 ||
                               w.board.flippers[0].pivot != n.board.flippers[0].pivot ||
                               w.board.flippers[0].theta_min_rad != n.board.flippers[0].theta_min_rad ||
                               w.board.flippers[0].mu != n.board.flippers[0].mu ||
                               std::ranges::any_of(w.board.obstacles, [&](const table::Obstacle& o) {
                                 return o.rho != n.board.obstacles[static_cast<std::size_t>(&o - w.board.obstacles.data())].rho;
                               });
    EXPECT_EQ(learn::changes_table(p), table_changed) << perturbation_name(p);
  }
}

TEST(TransferSweep, GeometryMovesBothFlippersTheSameWay) {
  const WorldSettings n = nominal();
  const WorldSettings up = perturb(n, Perturbation::kPivotY_mm, 3);
  const WorldSettings turned = perturb(n, Perturbation::kThetaMin_deg, -0.5);
  const WorldSettings slick = perturb(n, Perturbation::kFlipperMu_pct, -20);
  for (std::size_t i = 0; i < n.board.flippers.size(); ++i) {
    const table::Flipper& f = n.board.flippers[i];
    EXPECT_NEAR(up.board.flippers[i].pivot.y(), f.pivot.y() + 0.003, 1e-15);
    EXPECT_EQ(up.board.flippers[i].pivot.x(), f.pivot.x());
    EXPECT_NEAR(turned.board.flippers[i].theta_min_rad, f.theta_min_rad - 0.5 * std::numbers::pi / 180.0, 1e-15);
    EXPECT_EQ(turned.board.flippers[i].theta_max_rad, f.theta_max_rad);
    EXPECT_NEAR(slick.board.flippers[i].mu, f.mu * 0.8, 1e-15);
  }
  EXPECT_EQ(up.board.gravity_mps2, n.board.gravity_mps2) << "one thing at a time";
}

TEST(TransferSweep, WallRhoLeavesKickersAndTheDrainAlone) {
  const WorldSettings n = nominal();
  const WorldSettings bouncy = perturb(n, Perturbation::kWallRho, 0.1);
  const WorldSettings dull = perturb(n, Perturbation::kWallRho, -0.1);
  int changed = 0;
  for (std::size_t i = 0; i < n.board.obstacles.size(); ++i) {
    const table::Obstacle& o = n.board.obstacles[i];
    if (o.rho > 1.0 || o.action.eats_ball) {
      EXPECT_EQ(bouncy.board.obstacles[i].rho, o.rho) << o.name;
      EXPECT_EQ(dull.board.obstacles[i].rho, o.rho) << o.name;
      continue;
    }
    EXPECT_EQ(bouncy.board.obstacles[i].rho, std::min(1.0, o.rho + 0.1)) << o.name;
    EXPECT_EQ(dull.board.obstacles[i].rho, std::max(0.0, o.rho - 0.1)) << o.name;
    ++changed;
  }
  EXPECT_GT(changed, 20) << "the walls";
  for (std::size_t i = 0; i < n.board.flippers.size(); ++i) {
    EXPECT_EQ(bouncy.board.flippers[i].rho, n.board.flippers[i].rho) << "flippers are not walls";
  }
}

TEST(TransferSweep, GravityAndTheWorldSideSettings) {
  const WorldSettings n = nominal();
  EXPECT_NEAR(perturb(n, Perturbation::kGravity_pct, 10).board.gravity_mps2, 1.11 * 1.1, 1e-12);
  EXPECT_EQ(perturb(n, Perturbation::kActuationDelay_ms, 20).actuation_delay_s, 0.020);
  EXPECT_EQ(perturb(n, Perturbation::kCameraLatency_ms, 0).camera.latency_s, 0.0);
  const WorldSettings noisy = perturb(n, Perturbation::kCameraNoise_px, 2);
  EXPECT_EQ(noisy.camera.noise_px, 2.0);
  EXPECT_EQ(noisy.camera.latency_s, n.camera.latency_s);
  EXPECT_EQ(noisy.actuation_delay_s, n.actuation_delay_s);
}

TEST(TransferSweep, ValuesThatMakeNoTableAreRefused) {
  const WorldSettings n = nominal();
  EXPECT_THROW(perturb(n, Perturbation::kGravity_pct, -100), std::invalid_argument);
  EXPECT_THROW(perturb(n, Perturbation::kFlipperMu_pct, -150), std::invalid_argument);
  EXPECT_THROW(perturb(n, Perturbation::kActuationDelay_ms, -1), std::invalid_argument);
  EXPECT_THROW(perturb(n, Perturbation::kCameraNoise_px, -0.1), std::invalid_argument);
  EXPECT_THROW(perturb(n, Perturbation::kThetaMin_deg, 90), std::invalid_argument);
  EXPECT_THROW(perturb(n, Perturbation::kPivotY_mm, std::nan("")), std::invalid_argument);
}

}  // namespace
}  // namespace pinball::bench
