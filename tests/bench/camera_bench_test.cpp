#include "camera_bench.h"

#include <gtest/gtest.h>

#include "common/thesis_board.h"

namespace pinball::bench {
namespace {

using pinball::testing::thesis_board;

const CameraReport& quick_report() {
  static const CameraReport report = run_camera_bench(thesis_board(), quick_camera_bench_options(), {});
  return report;
}

const CameraScenarioResult& scenario(const std::string& name) {
  for (const CameraScenarioResult& s : quick_report().scenarios) {
    if (s.scenario.name == name) return s;
  }
  throw std::runtime_error("no scenario " + name);
}

TEST(CameraBench, EveryFaultIsMeasuredUncorrectedAndCorrectedBesideTheIdealCamera) {
  std::vector<std::string> names;
  for (const CameraScenario& s : camera_scenarios(quick_camera_bench_options())) names.push_back(s.name);
  const std::vector<std::string> expected{"ideal",
                                          "distortion_uncorrected",
                                          "distortion_corrected",
                                          "rolling_shutter_uncorrected",
                                          "rolling_shutter_corrected",
                                          "latency_uncompensated",
                                          "latency_mean_subtracted",
                                          "latency_compensated",
                                          "flicker_and_drift",
                                          "all_uncorrected",
                                          "all_corrected"};
  EXPECT_EQ(names, expected);
  CameraBenchOptions with_lens = quick_camera_bench_options();
  with_lens.calibrated_lens = vision::typical_wide_lens();
  EXPECT_EQ(camera_scenarios(with_lens).size(), expected.size() + 2);  // the lens alone, and everything calibrated
  CameraBenchOptions with_latency = quick_camera_bench_options();
  with_latency.measured_latency_s = 0.007;
  EXPECT_EQ(camera_scenarios(with_latency).size(), expected.size() + 2);  // the latency alone, and everything

}

TEST(CameraBench, CorrectionsWinBackWhatTheFaultsCostAndTheReportSaysSo) {
  const CameraScenarioResult& ideal = scenario("ideal");
  ASSERT_GT(ideal.detector.front().detected, 30u);
  for (const auto& [fault, fix] : {std::pair{"distortion_uncorrected", "distortion_corrected"},
                                   std::pair{"rolling_shutter_uncorrected", "rolling_shutter_corrected"},
                                   std::pair{"latency_uncompensated", "latency_compensated"},
                                   std::pair{"all_uncorrected", "all_corrected"}}) {
    const CameraScenarioResult& bad = scenario(fault);
    const CameraScenarioResult& good = scenario(fix);
    EXPECT_GT(bad.pooled_median_error_mm, 5.0 * good.pooled_median_error_mm) << fault;
    EXPECT_LT(good.pooled_median_error_mm, 0.5) << fix;  // well under a millimetre
    EXPECT_GT(bad.tracker.median_abs_dt_impact_ms, good.tracker.median_abs_dt_impact_ms) << fault;
  }
  // Uncompensated, every observation is late by the camera's latency (7 ms + about 1 ms).
  EXPECT_NEAR(scenario("latency_uncompensated").detector.front().mean_dt_ms, 8.0, 1.0);
  EXPECT_LT(std::abs(scenario("latency_compensated").detector.front().mean_dt_ms), 0.1);

  // Every figure as JSON and as text.
  const nlohmann::json j = to_json(quick_report());
  EXPECT_EQ(j["benchmark"], "camera");
  EXPECT_EQ(j["scenarios"].size(), quick_report().scenarios.size());
  EXPECT_TRUE(j["scenarios"][1]["camera"].contains("lens"));
  EXPECT_TRUE(j["scenarios"][0]["tracker"].contains("median_abs_dt_impact_ms"));
  EXPECT_GT(j["cost"]["corrected_roi_fps"].get<double>(), 0.0);
  const std::string text = to_text(quick_report());
  EXPECT_NE(text.find("all_corrected"), std::string::npos);
  EXPECT_NE(text.find("detector cost"), std::string::npos);
}

}  // namespace
}  // namespace pinball::bench
