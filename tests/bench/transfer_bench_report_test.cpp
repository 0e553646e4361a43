#include <algorithm>
#include <sstream>

#include <gtest/gtest.h>

#include "transfer_bench.h"
#include "transfer_report_fixture.h"

namespace pinball::bench {
namespace {

using pinball::testing::made_report;

TEST(TransferReport, JsonHasTheOptionsEveryCellAndTheSameKeysAsEveryCommand) {
  const nlohmann::json j = to_json(made_report());
  EXPECT_EQ(j.at("benchmark"), "transfer");
  for (const char* k : {"board", "balls", "seed", "threads", "max_ball_time_s", "actuation_delay_s", "camera",
                        "pivot_axis", "wall_rho_rule", "drains_rule", "ratio_interval", "controllers", "sweep",
                        "worlds", "sensitivity", "wall_s"}) {
    EXPECT_TRUE(j.contains(k)) << k;
  }
  EXPECT_EQ(j.at("controllers").size(), 2u);
  EXPECT_EQ(j.at("worlds").size(), 8u);
  for (const auto& w : j.at("worlds")) {
    if (!w.at("played").get<bool>()) {
      EXPECT_EQ(w.at("name"), "twin");
      EXPECT_FALSE(w.at("skipped_reason").get<std::string>().empty());
      EXPECT_TRUE(w.at("cells").empty());
      continue;
    }
    for (const char* c : {"spastic", "learned"}) {
      for (const char* k : {"mean_score_per_ball", "score_ci95_half_width", "balls_cut_at_time_limit", "wall_s",
                            "ratio_to_spastic", "drains_left_outlane", "drains_right_outlane", "drains_centre",
                            "drains_other", "drains_left_table", "outlane_drain_after_flipper_s_mean",
                            "max_score_per_ball"}) {
        EXPECT_TRUE(w.at("cells").at(c).contains(k)) << w.at("name") << " " << c << " " << k;
      }
    }
    EXPECT_EQ(w.at("cells").at("spastic").at("ratio_to_spastic"), 1.0);
    // The best ball: a heavy tail (one ball scoring for a minute on end) shows here before it moves a mean.
    EXPECT_EQ(w.at("cells").at("spastic").at("max_score_per_ball").get<double>(),
              w.at("cells").at("spastic").at("mean_score_per_ball").get<double>() + 100.0);
    EXPECT_TRUE(w.at("cells").at("spastic").at("ratio_ci95_low").is_null()) << "no interval for itself";
    const auto& learned = w.at("cells").at("learned");
    EXPECT_LT(learned.at("ratio_ci95_low").get<double>(), learned.at("ratio_to_spastic").get<double>());
    EXPECT_GT(learned.at("ratio_ci95_high").get<double>(), learned.at("ratio_to_spastic").get<double>());
  }
  const auto& pivot = j.at("sensitivity").at("pivot_y_mm");
  EXPECT_EQ(pivot.at("unit"), "mm");
  EXPECT_NEAR(pivot.at("controllers").at("learned").at("points_per_ball_lost_per_unit").get<double>(), 50.0, 1e-9);
}

TEST(TransferReport, SummaryHasEachControllersMedianAndLowestWorldAgainstTheTarget) {
  // learned / spastic: 2 in model and event, 1950/990 at pivots ±1 mm, 1850/970 at ±3, 1750/950 at g +5 %.
  const TransferReport r = made_report();
  ASSERT_EQ(r.summaries.size(), 1u) << "none for the spastic flipper";
  const TransferSummary& m = r.summaries[0];
  EXPECT_EQ(m.controller, "learned");
  EXPECT_EQ(m.worlds, 7) << "the skipped twin is no world";
  EXPECT_DOUBLE_EQ(m.median_ratio, 1950.0 / 990.0);
  EXPECT_DOUBLE_EQ(m.lowest_ratio, 1750.0 / 950.0);
  EXPECT_EQ(m.lowest_world, "gravity_pct=+5");
  ASSERT_TRUE(m.lowest_interval.has_value());
  EXPECT_EQ(m.lowest_interval->high, r.worlds.back().cells[1].ratio_interval->high);
  EXPECT_EQ(m.worlds_at_target, 0);
  EXPECT_EQ(m.worlds_below_target, 7) << "4 balls of ±100 each: every interval ends under 2.5";
  // At 1.95 the four worlds at 1.97x or more reach it, and no interval lies wholly below it.
  const std::vector<TransferSummary> lower = transfer_summaries(r.worlds, 1.95);
  EXPECT_EQ(lower[0].worlds_at_target, 4);
  EXPECT_EQ(lower[0].worlds_below_target, 0);

  const nlohmann::json j = to_json(r);
  EXPECT_EQ(j.at("target_ratio"), 2.5);
  ASSERT_EQ(j.at("summary").size(), 1u);
  EXPECT_EQ(j.at("summary")[0].at("lowest_world"), "gravity_pct=+5");
  EXPECT_EQ(j.at("summary")[0].at("worlds_below_target"), 7);
  const std::string text = to_text(r);
  EXPECT_NE(text.find("| learned | 1.97x | 1.84x ("), std::string::npos) << text;
  EXPECT_NE(text.find(", gravity_pct=+5 | 0 | 7 |"), std::string::npos) << text;
}

// One ball a cell (--balls 1) has no interval: 'inf' was written in every row, where JSON has null.
TEST(TransferReport, CsvLeavesAnUndefinedIntervalEmpty) {
  bench::TransferReport r = made_report();
  r.worlds[0].cells = {pinball::testing::made_cell("spastic", 1000.0, 1),
                       pinball::testing::made_cell("learned", 2000.0, 1)};
  bench::set_ratios_to_spastic(r.worlds[0].cells);
  const std::string csv = to_csv(r);
  EXPECT_EQ(csv.find("inf"), std::string::npos) << csv;
  EXPECT_NE(csv.find("model,nominal,0,thesis,learned,played,1,1900,,2.111111111,"), std::string::npos) << csv;
}

TEST(TransferReport, CsvHasAHeaderAndOneRowPerWorldAndController) {
  const std::string csv = to_csv(made_report());
  std::istringstream in(csv);
  std::string header;
  std::getline(in, header);
  EXPECT_EQ(header.rfind("world,family,value,stepper,controller,status,balls,mean_score_per_ball,"
                         "score_ci95_half_width,ratio_to_spastic,balls_cut_at_time_limit,max_ball_time_s",
                         0),
            0u)
      << header;
  EXPECT_EQ(std::count(csv.begin(), csv.end(), '\n'), 1 + 8 * 2);
  const auto columns = [](const std::string& line) {
    int n = 1;
    bool quoted = false;
    for (const char c : line) {
      if (c == '"') quoted = !quoted;
      if (c == ',' && !quoted) ++n;
    }
    return n;
  };
  for (std::string line; std::getline(in, line);) EXPECT_EQ(columns(line), columns(header)) << line;

  EXPECT_NE(csv.find("twin,nominal,0,twin,spastic,\"skipped: this build has no MuJoCo twin, so no \"\"twin\"\" row is played\""),
            std::string::npos)
      << csv;
  EXPECT_NE(csv.find("pivot_y_mm=+3,pivot_y_mm,3,thesis,learned,played,4,1850,"), std::string::npos) << csv;
  EXPECT_NE(header.find(",ratio_ci95_low,ratio_ci95_high"), std::string::npos) << header;
  // The model row: 2000 ± 100 against 1000 ± 100 over 4 balls each.
  const auto interval = ratio_of_means_ci95(made_report().worlds[0].cells[1].score,
                                            made_report().worlds[0].cells[0].score);
  ASSERT_TRUE(interval.has_value());
  std::ostringstream tail;
  tail.precision(10);
  tail << ',' << interval->low << ',' << interval->high << ",2.5,2100\n";  // the best of 1900, 2100, 1900, 2100
  EXPECT_NE(csv.find(tail.str()), std::string::npos) << tail.str() << csv;
  EXPECT_NE(csv.find("model,nominal,0,thesis,spastic,played,4,1000,"), std::string::npos) << csv;
}

TEST(TransferReport, TextRoundsAndSaysWhatWasSkipped) {
  const std::string text = to_text(made_report());
  EXPECT_NE(text.find("| world | spastic | learned |"), std::string::npos) << text;
  EXPECT_NE(text.find("| model (thesis) | 1000 ± "), std::string::npos) << text;
  EXPECT_NE(text.find("2x ("), std::string::npos) << "learned / spastic in the model world, with its interval\n" << text;
  EXPECT_NE(text.find("| twin | skipped: this build has no MuJoCo twin"), std::string::npos) << text;
  EXPECT_NE(text.find("balls cut at 60 s"), std::string::npos) << "the cap in every output\n" << text;
  EXPECT_NE(text.find("| pivot_y_mm | mm | 10 ± "), std::string::npos) << text;
  EXPECT_EQ(text.find("1849.999"), std::string::npos) << "rounded\n" << text;
  EXPECT_NE(text.find("| model | 1 / 0 / 1 / 0; 0; 2.5 s |"), std::string::npos) << "the drains with the time from the last "
                                                                                   "flipper touch\n"
                                                                                << text;
}

}  // namespace
}  // namespace pinball::bench
