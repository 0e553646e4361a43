#include "tracker_bench.h"

#include <stdexcept>

#include <gtest/gtest.h>

#include "pinball/table/board_loader.h"
#include "pinball/track/flipper_geometry.h"

namespace pinball::bench {
namespace {

table::Board mit1993() { return table::load_board(PINBALL_SOURCE_DIR "/boards/mit1993.board"); }

// A tiny run: 60 approaches, the headline camera with and without noise plus a
// 1 px camera, one miscalibrated g, two window caps.
TrackerBenchOptions tiny() {
  TrackerBenchOptions o = quick_tracker_bench_options();
  o.approaches = 60;
  o.noise_px = {0.0, 0.3, 1.0};
  o.g_factors = {1.5};
  o.cost_windows = {4, 16};
  return o;
}

const TrackerReport& tiny_report() {
  static const TrackerReport report = [] {
    return run_tracker_bench(mit1993(), tiny(), nullptr);
  }();
  return report;
}

const MethodErrors& method(const TrackerSetting& s, const std::string& name) {
  for (const MethodErrors& m : s.methods) {
    if (m.method == name) return m;
  }
  throw std::runtime_error("no method " + name);
}

TEST(TrackerBench, ApproachesAreExactFreeFlightToTheV) {
  const table::Board b = mit1993();
  TrackerBenchOptions o = tiny();
  o.approaches = 30;
  ApproachCounts counts;
  const std::vector<TrackerApproach> a = collect_tracker_approaches(b, o, &counts);
  ASSERT_EQ(a.size(), 30u);
  EXPECT_EQ(counts.kept, 30u);
  EXPECT_EQ(counts.segments, counts.kept + counts.no_impact + counts.too_short + counts.obstacle);
  const track::FlipperGeometry g = track::flipper_geometry_from_board(b);
  for (const TrackerApproach& x : a) {
    EXPECT_TRUE(x.truth.valid && x.truth.hittable);
    EXPECT_GE(x.truth.d_m, o.min_start_distance_m);
    EXPECT_GT(x.truth.t_impact_s, 0.0);
    EXPECT_LE(x.truth.h, g.h_apex[x.truth.flipper] + 1e-12);
    EXPECT_DOUBLE_EQ(x.g_mps2, b.gravity_mps2);
  }
  // Deterministic by seed.
  const std::vector<TrackerApproach> again = collect_tracker_approaches(b, o);
  ASSERT_EQ(again.size(), a.size());
  for (std::size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(again[i].p0, a[i].p0);
    EXPECT_EQ(again[i].v0, a[i].v0);
  }
}

TEST(TrackerBench, ReportHasEverySettingMethodAndBin) {
  const TrackerReport& r = tiny_report();
  EXPECT_EQ(r.approaches, 60u);
  ASSERT_EQ(r.settings.size(), 4u);  // three noise levels, then g x1.5
  EXPECT_EQ(r.settings.back().g_factor, 1.5);
  for (const TrackerSetting& s : r.settings) {
    ASSERT_EQ(s.methods.size(), 3u);
    EXPECT_GT(s.observations, 60u * 10u);
    for (const MethodErrors& m : s.methods) {
      std::size_t total = 0;
      for (const BinErrors& b : m.bins) {
        total += b.observations;
        EXPECT_LE(b.valid, b.observations);
        EXPECT_EQ(b.abs_dh.count, b.valid);
        EXPECT_LE(b.abs_dh.median, b.abs_dh.p90);
      }
      EXPECT_EQ(total, s.observations) << m.method;
      EXPECT_GT(m.beyond_headline.valid_fraction, 0.5) << m.method;
    }
  }
  ASSERT_EQ(r.cost.size(), 3u);  // two caps and the default
  EXPECT_EQ(r.cost.back().name, "default");
  for (const TrackerCostPoint& p : r.cost) {
    EXPECT_GT(p.updates, 0u);
    EXPECT_GT(p.median_us, 0.0);
    EXPECT_LE(p.median_us, p.p99_us);
    EXPECT_LE(p.mean_window, p.max_window + 1e-9);
  }
  EXPECT_GT(r.cost[0].full_window_updates, 0u);
  EXPECT_TRUE(r.headline.present);

  const nlohmann::json j = to_json(r);
  EXPECT_EQ(j.at("benchmark"), "tracker");
  EXPECT_EQ(j.at("settings").size(), 4u);
  EXPECT_EQ(j.at("distance_bins").size(), kTrackerDistanceBins);
  EXPECT_EQ(j.at("settings")[0].at("methods").at("tracker").at("bins").size(), kTrackerDistanceBins);
  for (const char* m : {"tracker", "two_point", "free_g"}) EXPECT_TRUE(j.at("headline").contains(m)) << m;
  EXPECT_TRUE(j.at("targets").contains("all_met"));
  const std::string text = to_text(r);
  EXPECT_NE(text.find("headline"), std::string::npos);
  EXPECT_NE(text.find("cost per Tracker::update"), std::string::npos);
}

TEST(TrackerBench, ErrorsBehaveAsExpected) {
  const TrackerReport& r = tiny_report();
  const BinErrors& clean = method(r.settings[0], "tracker").beyond_headline;
  const BinErrors& target = method(r.settings[1], "tracker").beyond_headline;
  const BinErrors& noisy = method(r.settings[2], "tracker").beyond_headline;
  // A noiseless camera (quantisation only) beats a 1 px one by far.
  EXPECT_LT(clean.abs_dh.median, 0.5 * noisy.abs_dh.median);
  EXPECT_LT(clean.abs_dt_impact_ms.median, 0.5 * noisy.abs_dt_impact_ms.median);
  // The fit beats the two-point parabola and the g-free fit on the same observations.
  const TrackerSetting& s = r.settings[1];
  EXPECT_LT(target.abs_dh.median, method(s, "two_point").beyond_headline.abs_dh.median);
  EXPECT_LT(target.abs_dh.median, method(s, "free_g").beyond_headline.abs_dh.median);
  // Errors shrink as the ball nears the V.
  const MethodErrors& t = method(s, "tracker");
  EXPECT_LT(t.bins[1].abs_dt_impact_ms.median, t.bins[kTrackerDistanceBins - 1].abs_dt_impact_ms.median);
  // g 50 % off is worse than the true g.
  EXPECT_GT(method(r.settings[3], "tracker").beyond_headline.abs_dh.median, target.abs_dh.median);
  // A 4-point window is worse than a 16-point one.
  EXPECT_GT(r.cost[0].median_abs_dh, r.cost[1].median_abs_dh);
}

TEST(TrackerBench, ProgressLinesAndDeterminism) {
  TrackerBenchOptions o = quick_tracker_bench_options();
  o.approaches = 15;
  o.g_factors = {0.9};
  o.cost_windows = {8};
  int lines = 0;
  std::string last;
  const TrackerReport a = run_tracker_bench(mit1993(), o, [&](const std::string& l) {
    ++lines;
    last = l;
  });
  EXPECT_EQ(lines, 1 + 2 + 2);  // approaches, two settings, two cost points
  EXPECT_EQ(last.rfind("tracker: 5/5 stages (100 %)", 0), 0u) << "percent and ETA: " << last;
  const TrackerReport b = run_tracker_bench(mit1993(), o, nullptr);
  ASSERT_EQ(a.settings.size(), b.settings.size());
  for (std::size_t i = 0; i < a.settings.size(); ++i) {
    EXPECT_EQ(a.settings[i].observations, b.settings[i].observations);
    EXPECT_EQ(a.settings[i].methods[0].beyond_headline.abs_dh.median,
              b.settings[i].methods[0].beyond_headline.abs_dh.median);
  }
}

}  // namespace
}  // namespace pinball::bench
