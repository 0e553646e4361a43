#include "pinball/view/view_state.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <vector>

#include "pinball/bus/channels.h"
#include "pinball/bus/message_convert.h"
#include "pinball_lcm/lcmt_pinball_observation.hpp"

namespace pinball::view {
namespace {

bool apply(ViewState& s, const char* channel, const auto& m, double t_s) {
  const std::vector<std::uint8_t> d = bus::encode_message(m);
  return s.apply(channel, d.data(), d.size(), t_s);
}

pinball_lcm::lcmt_pinball_observation seen(std::int64_t seq, double x, double y, bool found = true) {
  pinball_lcm::lcmt_pinball_observation o{};
  o.utime = seq * 5000;
  o.seq = seq;
  o.found = found;
  o.x_m = found ? x : 0.0;
  o.y_m = found ? y : 0.0;
  o.confidence = 1.0;
  return o;
}

TEST(ViewState, TrailKeepsTheLastHalfSecondAndTheBallIsTheNewestSighting) {
  ViewState s;
  for (int k = 0; k < 200; ++k) ASSERT_TRUE(apply(s, bus::kObservationChannel, seen(k, 0.01 * k, 0.5), k / 200.0));
  ASSERT_TRUE(s.ball().has_value());
  EXPECT_DOUBLE_EQ(s.ball()->p_board.x(), 1.99);
  EXPECT_EQ(s.ball()->seq, 199);
  // 0.5 s at 200 frames/s: the sightings from 0.495 s on (101 of them).
  EXPECT_EQ(s.trail().size(), 101u);
  EXPECT_GE(s.trail().front().t_s, s.now_s() - 0.5);
  EXPECT_EQ(s.observations(), 200u);
  EXPECT_NEAR(s.figures().frame_rate_hz, 200.0, 1e-6);
}

TEST(ViewState, AFrameWithoutTheBallHidesItButKeepsTheTrail) {
  ViewState s;
  apply(s, bus::kObservationChannel, seen(0, 0.2, 0.5), 0.0);
  apply(s, bus::kObservationChannel, seen(1, 0.0, 0.0, false), 0.005);
  EXPECT_FALSE(s.ball().has_value());
  EXPECT_EQ(s.trail().size(), 1u);
}

TEST(ViewState, SequenceGapsCountAsDroppedFramesAndStatsCanRaiseThem) {
  ViewState s;
  apply(s, bus::kObservationChannel, seen(0, 0.2, 0.5), 0.0);
  apply(s, bus::kObservationChannel, seen(3, 0.2, 0.5), 0.015);
  EXPECT_EQ(s.figures().frames_dropped, 2);
  EXPECT_FALSE(s.figures().has_stats);
  EXPECT_LT(s.figures().frame_to_can_p99_us, 0.0);
  pinball_lcm::lcmt_pinball_daemon_stats st{};
  st.num_stages = 2;
  st.stage = {"capture->detection", "frame->can_written"};
  st.count = {5, 5};
  st.p50_us = {10.0, 100.0};
  st.p99_us = {20.0, 700.0};
  st.max_us = {30.0, 800.0};
  st.frames_dropped = 7;
  st.camera_stalls = 1;
  ASSERT_TRUE(apply(s, bus::kStatsChannel, st, 0.02));
  const DaemonFigures f = s.figures();
  EXPECT_TRUE(f.has_stats);
  EXPECT_EQ(f.frames_dropped, 7);
  EXPECT_EQ(f.camera_stalls, 1);
  EXPECT_DOUBLE_EQ(f.frame_to_can_p99_us, 700.0);
}

// One damaged frame number had shown 999999999999470 frames dropped, exit 0: a jump no camera makes in
// the time between is a malformed message, counted and not drawn.
TEST(ViewState, AFrameNumberNoCameraCouldReachIsMalformedNotDrops) {
  ViewState s;
  ASSERT_TRUE(apply(s, bus::kObservationChannel, seen(0, 0.2, 0.5), 0.0));
  EXPECT_FALSE(apply(s, bus::kObservationChannel, seen(1000000000000000, 0.2, 0.5), 0.005));
  ASSERT_TRUE(apply(s, bus::kObservationChannel, seen(2, 0.2, 0.5), 0.010));
  EXPECT_EQ(s.figures().frames_dropped, 1);
  EXPECT_EQ(s.observations(), 2u);
}

TEST(ViewState, CommandsAreListedAndFlashOnTheirFlipperForAMoment) {
  ViewState s;
  pinball_lcm::lcmt_pinball_flipper_command c{};
  c.flipper = 1;
  c.energize = true;
  ASSERT_TRUE(apply(s, bus::kFlipperCommandChannel, c, 1.0));
  ASSERT_EQ(s.commands().size(), 1u);
  EXPECT_TRUE(s.flashing_command(1).has_value());
  EXPECT_FALSE(s.flashing_command(0).has_value());
  apply(s, bus::kObservationChannel, seen(0, 0.2, 0.5), 1.5);  // time passes
  EXPECT_FALSE(s.flashing_command(1).has_value());
  for (int i = 0; i < 20; ++i) apply(s, bus::kFlipperCommandChannel, c, 2.0 + i);
  EXPECT_EQ(s.commands().size(), ViewStateOptions{}.command_history);
}

TEST(ViewState, CoilsComeFromTheDriverStatusBits) {
  ViewState s;
  EXPECT_FALSE(s.coil_on(0));
  pinball_lcm::lcmt_pinball_driver_status d{};
  d.coils_on = 0b10;
  ASSERT_TRUE(apply(s, bus::kDriverStatusChannel, d, 0.0));
  EXPECT_FALSE(s.coil_on(0));
  EXPECT_TRUE(s.coil_on(1));
  EXPECT_FALSE(s.coil_on(-1));
  EXPECT_FALSE(s.coil_on(99));
}

TEST(ViewState, TheProjectionStartsFromItsObservation) {
  ViewState s;
  apply(s, bus::kObservationChannel, seen(4, 0.1, 0.6), 0.0);
  apply(s, bus::kObservationChannel, seen(5, 0.2, 0.5), 0.005);
  pinball_lcm::lcmt_pinball_projection p{};
  p.valid = true;
  p.observation_seq = 4;
  p.flipper = 0;
  p.impact_x_m = 0.2;
  p.impact_y_m = 0.1;
  ASSERT_TRUE(apply(s, bus::kProjectionChannel, p, 0.006));
  ASSERT_TRUE(s.projection().has_value());
  EXPECT_DOUBLE_EQ(s.projection_origin().x(), 0.1);
  p.valid = false;
  ASSERT_TRUE(apply(s, bus::kProjectionChannel, p, 0.007));
  EXPECT_FALSE(s.projection().has_value());
}

TEST(ViewState, MalformedMessagesAreCountedNotShown) {
  ViewState s;
  const unsigned char junk[5] = {1, 2, 3, 4, 5};
  EXPECT_FALSE(s.apply(bus::kObservationChannel, junk, sizeof junk, 0.0));
  pinball_lcm::lcmt_pinball_projection p{};
  p.valid = true;
  p.d_m = std::numeric_limits<double>::quiet_NaN();
  EXPECT_FALSE(apply(s, bus::kProjectionChannel, p, 0.0));
  EXPECT_FALSE(s.projection().has_value());
  pinball_lcm::lcmt_pinball_observation o = seen(0, std::numeric_limits<double>::infinity(), 0.5);
  EXPECT_FALSE(apply(s, bus::kObservationChannel, o, 0.0));
  EXPECT_EQ(s.malformed(), 3u);
  EXPECT_EQ(s.messages(), 0u);
  EXPECT_TRUE(s.apply("SOMEONE_ELSES_CHANNEL", junk, sizeof junk, 0.0));  // not ours: ignored
  EXPECT_EQ(s.malformed(), 3u);
}

}  // namespace
}  // namespace pinball::view
