// `pinball bench cradle` end to end: the quick run's one JSON object in the
// twin, a perturbed model world, and bad input refused on one line with
// nothing on stdout.
#include <nlohmann/json.hpp>

#include "common/command_test.h"
#include "pinball/simlab/world_factory.h"

namespace pinball::testing {
namespace {

using CradleCommand = CommandTest;

TEST_F(CradleCommand, QuickRunInTheTwinGivesEveryDropInOneJsonObject) {
  if (!simlab::twin_available()) GTEST_SKIP() << "built without the MuJoCo twin";
  const CommandResult r = run("bench cradle --quick --world twin --drop-ms 240 242 1 --json --progress");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j.at("benchmark"), "cradle");
  EXPECT_EQ(j.at("world"), "twin");
  EXPECT_EQ(j.at("balls_per_drop"), 2);
  EXPECT_EQ(j.at("max_ball_time_s"), 60.0) << "--quick cuts at 60 s";
  ASSERT_EQ(j.at("drops").size(), 3u);
  EXPECT_DOUBLE_EQ(j.at("drops")[0].at("drop_s").get<double>(), 0.240);
  EXPECT_DOUBLE_EQ(j.at("drops")[2].at("drop_s").get<double>(), 0.242);
  for (const auto& d : j.at("drops")) {
    EXPECT_LE(d.at("return_ci95_low").get<double>(), d.at("return_share").get<double>());
    EXPECT_GE(d.at("return_ci95_high").get<double>(), d.at("return_share").get<double>());
    EXPECT_EQ(d.at("balls"), 2);
    EXPECT_GE(d.at("score_ci95_half_width").get<double>(), 0.0) << "a score is a noisy mean: its interval";
  }
  EXPECT_NE(r.err.find("ETA"), std::string::npos) << r.err;
}

TEST_F(CradleCommand, PerturbPlaysTheSweepsCellAndSaysSo) {
  const std::string quick = "bench cradle --quick --drop-ms 390 390 1 --balls 4 --json";
  const CommandResult nominal = run(quick);
  const CommandResult lighter = run(quick + " --perturb gravity_pct=-10 --perturb wall_rho=-0.1");
  ASSERT_EQ(nominal.exit_code, 0) << nominal.err;
  ASSERT_EQ(lighter.exit_code, 0) << lighter.err;
  const auto n = nlohmann::json::parse(nominal.out);
  const auto l = nlohmann::json::parse(lighter.out);
  EXPECT_TRUE(n.at("perturbations").empty());
  EXPECT_EQ(l.at("perturbations").at("gravity_pct"), -10.0);
  EXPECT_EQ(l.at("perturbations").at("wall_rho"), -0.1);
  EXPECT_EQ(l.at("world"), "thesis");
  EXPECT_NE(n.at("drops")[0].at("mean_ball_time_s"), l.at("drops")[0].at("mean_ball_time_s"))
      << "another table plays another game";
  const CommandResult text = run("bench cradle --quick --drop-ms 390 390 1 --balls 1 --perturb pivot_y_mm=+3");
  ASSERT_EQ(text.exit_code, 0) << text.err;
  EXPECT_NE(text.out.find("the world's table perturbed: pivot_y_mm=+3"), std::string::npos) << text.out;
}

TEST_F(CradleCommand, RefusesWhatItCannotUse) {
  for (const Refusal& refusal :
       {Refusal{"bench cradle --drop-ms 250 240 1", 1, "from <= to"},
        Refusal{"bench cradle --drop-ms 240 250", 2, "--drop-ms"},
        Refusal{"bench cradle --drop-ms 0 250 1", 2, "--drop-ms"},
        Refusal{"bench aim --quick --drop-ms 240 250 1", 1, "cradle only"},
        Refusal{"bench cradle --balls 0", 2, "--balls"},
        Refusal{"bench cradle --quick --perturb gravity=-3", 1, "gravity_pct"},
        Refusal{"bench cradle --quick --perturb gravity_pct", 1, "NAME=VALUE"},
        Refusal{"bench cradle --quick --perturb gravity_pct=lots", 1, "not a finite number"},
        Refusal{"bench cradle --quick --perturb camera_noise_px=2", 1, "camera do not apply"},
        Refusal{"bench cradle --quick --perturb gravity_pct=-100", 1, "g must stay > 0"},
        Refusal{"bench cradle --quick --perturb gravity_pct=1 --perturb gravity_pct=2", 1,
                "--perturb gravity_pct is given twice"},
        Refusal{"bench cradle --quick --world twin --perturb gravity_pct=-3", 1, "not with --world twin"},
        Refusal{"bench aim --quick --perturb gravity_pct=-3", 1, "cradle only"}}) {
    expect_refused("", refusal);
  }
}

}  // namespace
}  // namespace pinball::testing
