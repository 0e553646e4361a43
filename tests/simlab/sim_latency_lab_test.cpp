#include "pinball/simlab/sim_latency_lab.h"

#include <cmath>
#include <stdexcept>

#include <gtest/gtest.h>

#include "common/thesis_board.h"

namespace pinball::simlab {
namespace {

using pinball::testing::thesis_board;

TEST(SimLatencyLab, RecordsTheFlippersRegionAtTheCamerasRateWithItsTruth) {
  SimLatencyOptions o;
  o.events = 2;
  o.flipper = 1;
  const SimLatencyRun run = simulate_latency_run(thesis_board(), o);
  ASSERT_EQ(run.recording.command_t_s.size(), 2u);
  const double period = 1.0 / o.camera.fps;
  // Commands at random phases within a frame period of their slots.
  for (int k = 0; k < 2; ++k) {
    const double slot = o.lead_in_s + k * o.spacing_s;
    EXPECT_GE(run.recording.command_t_s[static_cast<std::size_t>(k)], slot);
    EXPECT_LT(run.recording.command_t_s[static_cast<std::size_t>(k)], slot + period);
  }
  // Every frame until a spacing after the last command, each cropped to the region, none lost.
  const double duration = run.recording.command_t_s.back() + o.spacing_s;
  EXPECT_NEAR(static_cast<double>(run.recording.frames.size()), duration / period, 3.0);
  EXPECT_EQ(run.frames_dropped, 0u);
  for (std::size_t k = 1; k < run.recording.frames.size(); ++k) {
    ASSERT_EQ(run.recording.frames[k].sequence, run.recording.frames[k - 1].sequence + 1);
    ASSERT_EQ(run.recording.frames[k].gray.size(), run.region.roi.size());
  }
  // The truth: the typical camera's 7 ms minimum, 1 ms mean jitter.
  EXPECT_EQ(run.true_latency_s, 0.007);
  EXPECT_NEAR(run.true_mean_latency_s, 0.008, 0.0004);
  EXPECT_EQ(run.timing.frame_period_s, period);
  EXPECT_EQ(run.timing.row_time_s, o.camera.realism.row_time_s);
  EXPECT_EQ(run.timing.actuation_delay_s, o.actuation_delay_s);
  // The flipper moved in the frames after the commands and not before.
  const auto changed = [&](double from_s, double to_s) {
    double most = 0.0;
    const cv::Mat& rest = run.recording.frames.front().gray;
    for (const calibration::LatencyFrame& f : run.recording.frames) {
      if (f.t_s > from_s && f.t_s < to_s) most = std::max(most, cv::norm(f.gray, rest, cv::NORM_L1) / rest.total());
    }
    return most;
  };
  const double command = run.recording.command_t_s[0];
  EXPECT_LT(changed(0.0, command), 3.0);
  EXPECT_GT(changed(command + 0.05, command + 0.1), 10.0);
}

TEST(SimLatencyLab, RefusesWhatItCannotSimulate) {
  SimLatencyOptions o;
  o.events = 1;
  o.flipper = 7;
  EXPECT_THROW(simulate_latency_run(thesis_board(), o), std::invalid_argument);
  o = SimLatencyOptions{};
  o.events = 1;
  o.spacing_s = 0.1;  // the flipper would not be back at rest before the next command
  EXPECT_THROW(simulate_latency_run(thesis_board(), o), std::invalid_argument);
  o = SimLatencyOptions{};
  o.events = 1;
  o.camera.realism.latency_min_s = 0.5;  // longer than the camera's history at 0.1 ms steps
  EXPECT_THROW(simulate_latency_run(thesis_board(), o), std::invalid_argument);
  o = SimLatencyOptions{};
  o.dead_events = {3};
  o.events = 2;
  EXPECT_THROW(simulate_latency_run(thesis_board(), o), std::invalid_argument);
}

}  // namespace
}  // namespace pinball::simlab
