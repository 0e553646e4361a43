// `pinball bench cradle` end to end: the quick run's one JSON object in the
// twin, and bad input refused on one line with nothing on stdout.
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

TEST_F(CradleCommand, RefusesWhatItCannotUse) {
  struct Case {
    std::string args;
    int exit_code;
    std::string names;
  };
  for (const Case& c : {Case{"bench cradle --drop-ms 250 240 1", 1, "from <= to"},
                        Case{"bench cradle --drop-ms 240 250", 2, "--drop-ms"},
                        Case{"bench cradle --drop-ms 0 250 1", 2, "--drop-ms"},
                        Case{"bench aim --quick --drop-ms 240 250 1", 1, "cradle only"},
                        Case{"bench cradle --balls 0", 2, "--balls"}}) {
    const CommandResult r = run(c.args);
    EXPECT_EQ(r.exit_code, c.exit_code) << c.args << "\n" << r.err;
    EXPECT_NE(r.err.find(c.names), std::string::npos) << c.args << "\n" << r.err;
    EXPECT_TRUE(r.out.empty()) << c.args;
  }
}

}  // namespace
}  // namespace pinball::testing
