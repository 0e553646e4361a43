#include "pinball/learn/prediction_error.h"

#include <gtest/gtest.h>

#include "common/thesis_board.h"
#include "model_recording.h"

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

}  // namespace
}  // namespace pinball::learn
