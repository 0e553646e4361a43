#include "detector_bench.h"

#include <gtest/gtest.h>

#include "pinball/table/board_loader.h"

namespace pinball::bench {
namespace {

const DetectorReport& quick_report() {
  static const DetectorReport report = [] {
    DetectorBenchOptions o = quick_detector_bench_options();
    o.play_frames = 300;
    o.ball_free_frames = 200;
    o.occlusion_frames = 40;
    o.timing_frames = 40;
    return run_detector_bench(table::load_board(PINBALL_SOURCE_DIR "/boards/mit1993.board"), o, nullptr);
  }();
  return report;
}

TEST(DetectorBench, MeasuresAccuracyAgainstTheTruthAndTheBaseline) {
  const DetectorReport& r = quick_report();
  const AccuracyFigures& a = r.accuracy;
  EXPECT_EQ(a.unoccluded, 300u);
  EXPECT_EQ(a.detected + a.missed, a.unoccluded);
  EXPECT_GE(a.detected, 270u);
  EXPECT_EQ(a.error_px.count, a.detected);
  EXPECT_LT(a.error_px.median, kTargetMedianErrorPx);
  EXPECT_GT(a.error_mm.median, 0.0);
  EXPECT_GT(a.median_radius_px, 5.0);
  // The naive centroid (no background) is far worse on the same frames.
  EXPECT_GT(a.naive_error_px.median, 10.0 * a.error_px.median);
}

TEST(DetectorBench, CountsFalseDetectionsOcclusionAndSpeed) {
  const DetectorReport& r = quick_report();
  EXPECT_EQ(r.ball_free_frames, 200u);
  EXPECT_EQ(r.false_detections, 0u);
  EXPECT_GT(r.ball_free_rejected_blobs, 0u);
  EXPECT_EQ(r.occlusion.frames, 40u);
  EXPECT_EQ(r.occlusion.wrong, 0u);
  ASSERT_EQ(r.timing.size(), 1u);
  EXPECT_EQ(r.timing[0].size, cv::Size(640, 480));
  EXPECT_GT(r.timing[0].full_frame_fps, 0.0);
  EXPECT_GT(r.timing[0].roi_fps, 0.0);
  EXPECT_GT(r.timing[0].roi_found_fraction, 0.5);
}

TEST(DetectorBench, JsonCarriesEveryFigure) {
  const nlohmann::json j = to_json(quick_report());
  EXPECT_EQ(j.at("benchmark"), "detector");
  for (const char* key : {"accuracy", "ball_free", "occlusion", "timing", "targets", "options", "wall_s"}) {
    EXPECT_TRUE(j.contains(key)) << key;
  }
  EXPECT_TRUE(j.at("accuracy").contains("baseline_naive_centroid_error_px"));
  EXPECT_TRUE(j.at("timing").at(0).contains("roi_speedup"));
  EXPECT_NE(to_text(quick_report()).find("false detections 0"), std::string::npos);
}

}  // namespace
}  // namespace pinball::bench
