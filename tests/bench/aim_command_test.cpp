// `pinball bench aim` end to end: the quick run's one JSON object, a single
// noise level from --true-state-noise, and bad input refused on one line.
#include <nlohmann/json.hpp>

#include "common/command_test.h"

namespace pinball::testing {
namespace {

using AimCommand = CommandTest;

TEST_F(AimCommand, QuickRunGivesEveryNoiseLevelInOneJsonObject) {
  const CommandResult r = run("bench aim --quick --json --progress");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j.at("benchmark"), "aim");
  EXPECT_EQ(j.at("balls"), 3);
  EXPECT_EQ(j.at("planner_horizon_s"), 3.0) << "the ceiling's own planner by default";
  ASSERT_EQ(j.at("results").size(), 3u) << "three noise levels by default";
  EXPECT_GT(j.at("shots").get<int>(), 0);
  for (const auto& level : j.at("results")) {
    EXPECT_EQ(level.at("copies").get<int>(), 10 * j.at("shots").get<int>());
    EXPECT_GE(level.at("within_10_deg").get<double>(), level.at("within_5_deg").get<double>());
  }
  EXPECT_NE(r.err.find("ETA"), std::string::npos) << r.err;
}

TEST_F(AimCommand, OneNoiseLevelFromTrueStateNoiseAndThePlannersSettings) {
  const CommandResult r =
      run("bench aim --quick --json --true-state-noise 1 0.02 --controller controllers/planner.json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  ASSERT_EQ(j.at("results").size(), 1u);
  EXPECT_DOUBLE_EQ(j.at("results")[0].at("position_noise_m").get<double>(), 1e-3);
  EXPECT_DOUBLE_EQ(j.at("results")[0].at("velocity_noise_mps").get<double>(), 0.02);
  EXPECT_EQ(j.at("planner_horizon_s"), 0.5) << "controllers/planner.json's horizon";
}

TEST_F(AimCommand, RefusesWhatItCannotUse) {
  for (const Refusal& refusal : {Refusal{"--controller controllers/best.json", 1, "not a planner file"},
                                 Refusal{"--world twin", 1, "--world applies to ceiling and cradle only"},
                                 Refusal{"--stepper event", 1, "--stepper"},
                                 Refusal{"--true-state-noise -1 0", 2, "--true-state-noise"},
                                 Refusal{"--balls 0", 2, "--balls"}}) {
    expect_refused("bench aim --quick ", refusal);
  }
}

}  // namespace
}  // namespace pinball::testing
