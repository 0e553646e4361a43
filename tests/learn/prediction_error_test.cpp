#include "pinball/learn/prediction_error.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "common/thesis_board.h"
#include "model_recording.h"
#include "pinball/learn/free_flight.h"

namespace pinball::learn {
namespace {

TEST(PredictionError, TheTrueModelPredictsBetterThanAWrongOne) {
  table::Board truth = pinball::testing::thesis_board();
  truth.gravity_mps2 = 0.75;  // 0.36 m/s² off: 1.8 mm in 100 ms, beside about 1.8 mm of noise
  const std::vector<bus::RecordedPlay> plays{pinball::testing::record_model_play(truth, 8, 0.0005, 9)};
  PredictionOptions options;
  options.sigma_m = 0.0005;
  const std::vector<PredictionStart> starts = prediction_starts(plays, options);
  ASSERT_GT(starts.size(), 100u);
  const PredictionError wrong = prediction_error(pinball::testing::thesis_board(), plays, starts, options);
  const PredictionError right = prediction_error(truth, plays, starts, options);
  EXPECT_EQ(wrong.moments, right.moments);
  EXPECT_GT(right.moments, 100u);
  EXPECT_LT(right.median_m, wrong.median_m);
  EXPECT_LT(right.mean_m, wrong.mean_m);
  EXPECT_LT(right.median_m, 0.004);  // the noise of a 6-frame start, carried 100 ms
  EXPECT_GT(right.mean_ci95_m, 0.0);
  EXPECT_LE(right.median_m, right.p90_m);
  EXPECT_GT(right.free_moments, 50u);
  EXPECT_LT(right.free_moments, right.moments);  // some windows hold a bounce
  EXPECT_EQ(right.free_moments, wrong.free_moments);  // chosen from the recording alone
  EXPECT_LT(right.free_mean_m, wrong.free_mean_m);
  EXPECT_LT(right.free_mean_m, 0.004);

  // The paired ratio: every start has its error, and the ratio is the means'.
  ASSERT_EQ(right.errors_m.size(), starts.size());
  const ErrorRatio ratio = paired_error_ratio(right, wrong);
  EXPECT_EQ(ratio.moments, right.moments);
  EXPECT_NEAR(ratio.ratio, right.mean_m / wrong.mean_m, 1e-12);
  EXPECT_GT(ratio.ci95, 0.0);
  EXPECT_LT(ratio.ratio + ratio.ci95, 1.0);  // the true model is better beyond the noise

  // Under g or pushed split the moments, the same for both beliefs.
  EXPECT_EQ(right.under_g_moments + right.pushed_moments, right.moments);
  EXPECT_EQ(right.pushed_moments, wrong.pushed_moments);
  EXPECT_NEAR((right.under_g_mean_m * static_cast<double>(right.under_g_moments) +
               right.pushed_mean_m * static_cast<double>(right.pushed_moments)) /
                  static_cast<double>(right.moments),
              right.mean_m, 1e-12);
  // The model's ball never skids: what pushes it in a history is something
  // it rolls along (a wall, a resting flipper), so every pushed moment but a
  // χ² false alarm or two (0.1 % each) has the ball touching something.
  int pushed = 0;
  int pushed_in_the_open = 0;
  for (const PredictionStart& s : starts) {
    if (!s.pushed) continue;
    ++pushed;
    bool touched = false;
    for (int k = 0; k < options.history_frames; ++k)
      touched = touched || !ball_is_clear(truth, plays[0].frames[s.frame - static_cast<std::size_t>(k)].p_board, 0.003);
    if (!touched) ++pushed_in_the_open;
  }
  EXPECT_EQ(static_cast<std::size_t>(pushed), right.pushed_moments);
  EXPECT_GT(pushed, 0);
  EXPECT_LE(pushed_in_the_open, 3);

  // The collision moments, by what the model's ball hit first: every one counted once, most first.
  std::size_t by_hit = 0;
  for (std::size_t i = 0; i < right.collisions_by_model_hit.size(); ++i) {
    const CollisionError& c = right.collisions_by_model_hit[i];
    EXPECT_FALSE(c.model_hit.empty());
    EXPECT_GT(c.moments, 0u);
    if (i > 0) {
      EXPECT_LE(c.moments, right.collisions_by_model_hit[i - 1].moments);
    }
    by_hit += c.moments;
  }
  EXPECT_EQ(by_hit, right.moments - right.free_moments);
  double weighted_m = 0.0;
  for (const CollisionError& c : right.collisions_by_model_hit) weighted_m += c.mean_m * static_cast<double>(c.moments);
  EXPECT_NEAR(weighted_m / static_cast<double>(by_hit), right.collision_mean_m, 1e-12);
  // In the true model a bounce the camera saw is one the model plays: mostly a wall or a flipper, not "nothing".
  ASSERT_FALSE(right.collisions_by_model_hit.empty());
  EXPECT_NE(right.collisions_by_model_hit.front().model_hit, "nothing");
}

// 3 s at 200 frames/s of a ball under g = 1.11 m/s², except from 1.0 to
// 1.6 s, when sliding friction pushes it 2 m/s² more along −y (a ball
// skidding straight up the table after a bounce off the bottom).
constexpr double kG = 1.11, kSkid = 2.0, kSkidFrom = 1.0, kSkidTo = 1.6, kDt = 0.005;

bus::RecordedPlay skid_recording() {
  bus::RecordedPlay play;
  Vec2 p{2.0, 2.0};
  Vec2 v{0.1, 1.6};
  for (int i = 0; i <= 600; ++i) {
    const double t = i * kDt;
    play.frames.push_back({t, i, true, p, false, false});
    const bool skidding = t >= kSkidFrom - 1e-9 && t < kSkidTo - 1e-9;
    const Vec2 a{0.0, -kG - (skidding ? kSkid : 0.0)};
    p += v * kDt + 0.5 * a * kDt * kDt;
    v += a * kDt;
  }
  return play;
}

// A belief with nothing to hit: the ball flies under its g alone.
table::Board open_board() {
  table::Board board;
  board.width_m = 10.0;
  board.height_m = 10.0;
  board.gravity_mps2 = kG;
  board.launcher.position = {5.0, 0.5};
  return board;
}

TEST(PairedErrorRatio, ClosedFormsSkippedMomentsAndMismatchedRuns) {
  PredictionError baseline, half, same;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  baseline.errors_m = {0.002, 0.004, nan, 0.006, 0.008};
  half.errors_m = {0.001, 0.002, 0.5, 0.003, nan};
  same.errors_m = baseline.errors_m;
  const ErrorRatio exact = paired_error_ratio(half, baseline);
  EXPECT_EQ(exact.moments, 3u);  // a NaN on either side drops the moment from both
  EXPECT_NEAR(exact.ratio, 0.5, 1e-15);
  EXPECT_NEAR(exact.ci95, 0.0, 1e-15);  // a = R·b exactly: no spread
  EXPECT_NEAR(paired_error_ratio(same, baseline).ratio, 1.0, 1e-15);
  // a − 0.5·b = ±0.001 about 0 (mean b 0.005): the interval is t(3)·s/√4 / 0.005.
  PredictionError noisy;
  baseline.errors_m = {0.004, 0.004, 0.006, 0.006};
  noisy.errors_m = {0.003, 0.001, 0.004, 0.002};
  const ErrorRatio r = paired_error_ratio(noisy, baseline);
  EXPECT_NEAR(r.ratio, 0.5, 1e-15);
  const double s = std::sqrt(4.0 * 1e-6 / 3.0);
  EXPECT_NEAR(r.ci95, 3.182446305284263 * s / 2.0 / 0.005, 1e-3);
  PredictionError shorter;
  shorter.errors_m = {0.001};
  EXPECT_THROW(paired_error_ratio(shorter, baseline), std::invalid_argument);
}

TEST(PredictionStarts, TellsAPushedBallByItsHistorysAcceleration) {
  const std::vector<bus::RecordedPlay> plays{skid_recording()};
  PredictionOptions options;
  options.sigma_m = 0.0005;
  const std::vector<PredictionStart> starts = prediction_starts(plays, options);
  ASSERT_GT(starts.size(), 60u);
  const double history_s = (options.history_frames - 1) * kDt;
  int pushed = 0;
  int under_g = 0;
  for (const PredictionStart& s : starts) {
    const double t = plays[0].frames[s.frame].t_s;
    const double from = t - history_s;
    if (from >= kSkidFrom - 1e-9 && t < kSkidTo) {
      EXPECT_TRUE(s.pushed) << t;
      ++pushed;
    } else if (t < kSkidFrom || from >= kSkidTo - 1e-9) {
      EXPECT_FALSE(s.pushed) << t;
      ++under_g;
    }
  }
  EXPECT_GT(pushed, 10);
  EXPECT_GT(under_g, 40);
}

TEST(PredictionError, APushedBallStartsFromItsOwnAcceleration) {
  // Noiseless frames: a moment under g is predicted exactly; a pushed one
  // whose push lasts through the window misses by the push alone,
  // kSkid·h²/2 = 10 mm, the start being exact. Forced onto g, the start's
  // velocity would be kSkid·(history)/2 = 0.115 m/s off: 21.5 mm in all.
  const std::vector<bus::RecordedPlay> plays{skid_recording()};
  PredictionOptions options;
  options.sigma_m = 0.0005;
  const double history_s = (options.history_frames - 1) * kDt;
  std::vector<PredictionStart> in_skid, under_g;
  for (const PredictionStart& s : prediction_starts(plays, options)) {
    const double t = plays[0].frames[s.frame].t_s;
    if (t - history_s >= kSkidFrom - 1e-9 && t + options.horizon_s < kSkidTo - 1e-9) in_skid.push_back(s);
    if (t + options.horizon_s < kSkidFrom - 1e-9 || t - history_s >= kSkidTo - 1e-9) under_g.push_back(s);
  }
  ASSERT_GT(in_skid.size(), 5u);
  ASSERT_GT(under_g.size(), 40u);
  const PredictionError skid = prediction_error(open_board(), plays, in_skid, options);
  EXPECT_EQ(skid.moments, in_skid.size());
  EXPECT_EQ(skid.pushed_moments, in_skid.size());
  EXPECT_NEAR(skid.pushed_mean_m, 0.5 * kSkid * options.horizon_s * options.horizon_s, 2e-4);
  const PredictionError free = prediction_error(open_board(), plays, under_g, options);
  EXPECT_EQ(free.under_g_moments, under_g.size());
  EXPECT_LT(free.under_g_mean_m, 1e-4);  // the model's semi-implicit Euler steps alone
  // A class with no moment has no mean: NaN (null in JSON), not the 0 mm it was printed as.
  EXPECT_EQ(skid.under_g_moments, 0u);
  EXPECT_TRUE(std::isnan(skid.under_g_mean_m));
  EXPECT_EQ(free.pushed_moments, 0u);
  EXPECT_TRUE(std::isnan(free.pushed_mean_m));
}

TEST(PredictionError, NoMomentNearACoilCommandOrWithoutTheBall) {
  table::Board truth = pinball::testing::thesis_board();
  std::vector<bus::RecordedPlay> plays{pinball::testing::record_model_play(truth, 2, 0.0005, 10)};
  PredictionOptions options;
  options.sigma_m = 0.0005;
  const std::size_t all = prediction_starts(plays, options).size();
  ASSERT_GT(all, 20u);
  // A fire at every 0.2 s, released at once: every moment is within 0.3 s of one.
  bus::RecordedPlay& play = plays[0];
  for (double t = 0.0; t < play.frames.back().t_s; t += 0.2) {
    play.commands.push_back({t, 0, true, 0});
    play.commands.push_back({t + 0.01, 0, false, 0});
  }
  std::sort(play.commands.begin(), play.commands.end(), [](auto& a, auto& b) { return a.t_s < b.t_s; });
  EXPECT_TRUE(prediction_starts(plays, options).empty());
  play.commands.clear();
  for (bus::RecordedFrame& f : play.frames) f.found = false;
  EXPECT_TRUE(prediction_starts(plays, options).empty());
}

TEST(PredictionError, NoMomentSpansTheJumpToAnotherBall) {
  // A drain, then at once the next ball in the shooter lane: the ball seen at
  // the horizon is not the ball of the moment, so no window may span the jump.
  std::vector<bus::RecordedPlay> plays{pinball::testing::record_model_play(pinball::testing::thesis_board(), 2, 0.0005, 10)};
  PredictionOptions options;
  options.sigma_m = 0.0005;
  bus::RecordedPlay& play = plays[0];
  const std::size_t jump = play.frames.size() / 2;
  const double t_jump = play.frames[jump].t_s;
  const auto spans_jump = [&](const PredictionStart& s) {
    const double t = play.frames[s.frame].t_s;
    return t < t_jump && t_jump <= t + options.horizon_s + 0.01;
  };
  std::size_t spanning = 0;
  for (const PredictionStart& s : prediction_starts(plays, options)) spanning += spans_jump(s) ? 1 : 0;
  ASSERT_GT(spanning, 0u) << "the test needs moments around the jump";
  for (std::size_t i = jump; i < play.frames.size(); ++i) play.frames[i].p_board += Vec2(0.3, 0.0);
  for (const PredictionStart& s : prediction_starts(plays, options)) EXPECT_FALSE(spans_jump(s)) << s.frame;
}

}  // namespace
}  // namespace pinball::learn
