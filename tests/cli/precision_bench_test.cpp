#include "precision_bench.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <map>
#include <sstream>

#include "common/figure_check.h"
#include "pinball/table/board_loader.h"
#include "pinball/sim/penetration.h"

namespace pinball::bench {
namespace {

TEST(PrecisionBench, ClosedFormsStartWhereTheScenesStartAndStayOutOfTheirObstacles) {
  for (const std::string& name : closed_form_scenes()) {
    const table::Board b = precision_scene_board(name);
    sim::GameState s = sim::make_game_state(b, 1);
    s.ball_in_play = true;
    for (double t = 0.0; t <= 10.0; t += 0.01) {
      s.ball.position_m = precision_scene_exact(name, t);
      ASSERT_LT(sim::max_penetration_m(b, s), 1e-12) << name << " at " << t << " s";
      const Vec2& p = s.ball.position_m;
      ASSERT_TRUE(p.x() > 0.0 && p.x() < b.width_m && p.y() > 0.0 && p.y() < b.height_m) << name << " at " << t;
    }
  }
  // The bounce series has ended well before 10 s: the ball rests r above the line.
  EXPECT_DOUBLE_EQ(precision_scene_exact("bounce_to_rest", 9.0).y(), 0.1 + 0.0135);
  // Free flight: y = y0 + vy t − g t²/2.
  EXPECT_NEAR(precision_scene_exact("free_flight", 10.0).y(), 56.0 + 5.0 - 0.5 * 1.11 * 100.0, 1e-12);
}

TEST(PrecisionBench, BounceSeriesIsContinuousThroughItsImpacts) {
  // Sampled finely, the closed form never jumps: consecutive positions differ
  // by at most the largest speed times the sample interval.
  const double h = 1e-5;
  Vec2 last = precision_scene_exact("bounce_to_rest", 0.0);
  for (double t = h; t < 6.0; t += h) {
    const Vec2 p = precision_scene_exact("bounce_to_rest", t);
    ASSERT_LT((p - last).norm(), 0.82 * h * 1.001) << t;
    last = p;
  }
}

TEST(PrecisionBench, LogLogInterpolationIsExactOnAPowerLaw) {
  const std::vector<std::pair<double, double>> xy{{1e-3, 1e3}, {1e-2, 1e2}, {1e-1, 1e1}};
  bool extrapolated = true;
  EXPECT_NEAR(loglog_interpolate(xy, 3e-2, extrapolated), 1.0 / 3e-2, 1e-9);
  EXPECT_FALSE(extrapolated);
  EXPECT_NEAR(loglog_interpolate(xy, 1e-5, extrapolated), 1e5, 1e-4);
  EXPECT_TRUE(extrapolated);
}

TEST(PrecisionBench, QuickRunErrorsAreSane) {
  const table::Board table = table::load_board(PINBALL_SOURCE_DIR "/boards/mit1993.board");
  const PrecisionBenchOptions options = quick_precision_bench_options();
  int lines = 0;
  std::string last;
  const PrecisionReport r = run_precision_bench(table, options, [&](const std::string& l) {
    ++lines;
    last = l;
  });
  EXPECT_EQ(lines, 6);
  EXPECT_EQ(last.rfind("precision: 6/6 scenes (100 %)", 0), 0u) << "percent and ETA: " << last;
  std::map<std::string, std::map<double, const PrecisionPoint*>> thesis, event;
  for (const PrecisionPoint& p : r.points) {
    EXPECT_TRUE(std::isfinite(p.max_error_m)) << p.scene << " " << p.stepper << " " << p.setting;
    EXPECT_GT(p.run_time_s, 0.0);
    EXPECT_LE(p.final_error_m, p.max_error_m);
    (p.stepper == "thesis" ? thesis : event)[p.scene][p.setting] = &p;
  }
  ASSERT_EQ(thesis.size(), 6u);
  ASSERT_EQ(event.size(), 6u);
  for (const std::string& name : closed_form_scenes()) {
    // The thesis stepper is first order: a tenth of the step, a smaller error.
    const auto& t = thesis.at(name);
    ASSERT_EQ(t.size(), 3u);
    EXPECT_LT(t.at(1e-3)->max_error_m, t.at(1e-2)->max_error_m) << name;
    EXPECT_LT(t.at(1e-4)->max_error_m, t.at(1e-3)->max_error_m) << name;
    EXPECT_GT(t.at(1e-4)->max_error_m, 1e-7) << name << ": Euler cannot be this exact at dt 1e-4";
    // At its tightest tolerance the event stepper meets the 1e-9 m.
    EXPECT_LT(event.at(name).at(1e-14)->max_error_m, 1e-9) << name;
  }
  // Free flight: semi-implicit Euler lags the parabola by g·dt·t/2.
  EXPECT_NEAR(thesis.at("free_flight").at(1e-3)->max_error_m, 1.11 * 1e-3 * 10.0 / 2.0, 1e-4);
  EXPECT_EQ(r.comparisons.size(), 6u * 3u);
  // Outputs: CSV rows, one JSON object, a PNG.
  const std::string csv = to_csv(r);
  EXPECT_EQ(csv.rfind("scene,stepper,setting,max_error_m,final_error_m,run_time_s\n", 0), 0u);
  EXPECT_EQ(static_cast<std::size_t>(std::count(csv.begin(), csv.end(), '\n')), r.points.size() + 1);
  const auto j = to_json(r);
  EXPECT_EQ(j.at("points").size(), r.points.size());
  EXPECT_EQ(j.at("benchmark"), "precision");
  EXPECT_NE(to_markdown(r).find("| thesis dt (s) |"), std::string::npos);
  const auto png = std::filesystem::temp_directory_path() / "pinball_precision_test.png";
  plot_precision_png(r, png.string());
  EXPECT_GT(std::filesystem::file_size(png), 10'000u);
  // Six scenes in two rows of three panels; both steppers' colours (curves and legend swatches).
  pinball::testing::expect_figure(png.string(), cv::Size(3 * 470, 2 * 360 + 60), 2, 2);
  std::filesystem::remove(png);
}

}  // namespace
}  // namespace pinball::bench
