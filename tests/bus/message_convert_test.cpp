#include "pinball/bus/message_convert.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "pinball_lcm/lcmt_pinball_observation_v1.hpp"

namespace pinball::bus {
namespace {

template <class T>
T round_trip(const T& m) {
  std::vector<std::uint8_t> buf(static_cast<std::size_t>(m.getEncodedSize()));
  EXPECT_EQ(m.encode(buf.data(), 0, static_cast<int>(buf.size())), static_cast<int>(buf.size()));
  T out;
  EXPECT_EQ(out.decode(buf.data(), 0, static_cast<int>(buf.size())), static_cast<int>(buf.size()));
  return out;
}

TEST(MessageConvert, ObservationRoundTrip) {
  track::Observation o;
  o.t_s = 1.25;
  o.p_board = Vec2(0.2, 0.7);
  o.confidence = 0.9;
  const auto m = round_trip(to_lcm_observation(1250000, 1258000, 7, true, o, 100.5, 200.25, {true, false}));
  EXPECT_EQ(m.utime, 1250000);
  EXPECT_EQ(m.delivered_utime, 1258000);
  EXPECT_EQ(m.seq, 7);
  bool found = false;
  track::Observation back;
  track::ContactSensors c;
  ASSERT_TRUE(from_lcm_observation(m, found, back, c));
  EXPECT_TRUE(found);
  EXPECT_DOUBLE_EQ(back.t_s, 1.25);
  EXPECT_DOUBLE_EQ(back.latency_s, 0.008) << "delivered 8 ms after the exposure";
  EXPECT_EQ(back.p_board, o.p_board);
  EXPECT_DOUBLE_EQ(back.confidence, 0.9);
  EXPECT_TRUE(c.left);
  EXPECT_FALSE(c.right);
  EXPECT_DOUBLE_EQ(m.u_px, 100.5);
}

TEST(MessageConvert, ProjectionCarriesEveryField) {
  track::TrackerOutput out;
  out.projection.valid = true;
  out.projection.reason = track::NoProjection::kNone;
  out.projection.flipper = track::kRightFlipper;
  out.projection.speed_mps = 1.5;
  out.projection.angle_rad = -0.3;
  out.projection.h = 0.6;
  out.projection.d_m = 0.2;
  out.projection.t_impact_s = 0.12;
  out.projection.impact_point = Vec2(0.3, 0.1);
  out.projection.hittable = true;
  out.launch.launched = true;
  const auto m = round_trip(to_lcm_projection(5, 6, 7, out));
  EXPECT_TRUE(m.valid);
  EXPECT_EQ(m.flipper, 1);
  EXPECT_DOUBLE_EQ(m.speed_mps, 1.5);
  EXPECT_DOUBLE_EQ(m.angle_rad, -0.3);
  EXPECT_DOUBLE_EQ(m.h, 0.6);
  EXPECT_DOUBLE_EQ(m.d_m, 0.2);
  EXPECT_DOUBLE_EQ(m.t_impact_s, 0.12);
  EXPECT_DOUBLE_EQ(m.impact_x_m, 0.3);
  EXPECT_TRUE(m.hittable);
  EXPECT_TRUE(m.launched);
  EXPECT_FALSE(m.lost);
  EXPECT_EQ(m.observation_seq, 7);
}

TEST(MessageConvert, AProjectionReadBackIsTheOneSent) {
  track::TrackerOutput out;
  out.projection.valid = true;
  out.projection.reason = track::NoProjection::kNone;
  out.projection.flipper = track::kLeftFlipper;
  out.projection.speed_mps = 2.5;
  out.projection.angle_rad = -1.1;
  out.projection.h = 0.4;
  out.projection.d_m = 0.15;
  out.projection.t_impact_s = 0.08;
  out.projection.impact_point = Vec2(0.2, 0.18);
  out.projection.hittable = true;
  out.projection.rolling = true;
  const track::TrajectoryProjection p = from_lcm_projection(round_trip(to_lcm_projection(1, 2, 3, out)));
  EXPECT_TRUE(p.valid);
  EXPECT_EQ(p.reason, track::NoProjection::kNone);
  EXPECT_EQ(p.flipper, track::kLeftFlipper);
  EXPECT_EQ(p.speed_mps, 2.5);
  EXPECT_EQ(p.angle_rad, -1.1);
  EXPECT_EQ(p.h, 0.4);
  EXPECT_EQ(p.d_m, 0.15);
  EXPECT_EQ(p.t_impact_s, 0.08);
  EXPECT_EQ(p.impact_point, Vec2(0.2, 0.18));
  EXPECT_TRUE(p.hittable);
  EXPECT_TRUE(p.rolling);
  track::TrackerOutput none;
  none.projection.reason = track::NoProjection::kOutsideCritical;
  const track::TrajectoryProjection q = from_lcm_projection(round_trip(to_lcm_projection(1, 2, 3, none)));
  EXPECT_FALSE(q.valid);
  EXPECT_EQ(q.reason, track::NoProjection::kOutsideCritical);
}

TEST(MessageConvert, InvalidProjectionNamesNoFlipper) {
  track::TrackerOutput out;
  out.projection.valid = false;
  out.projection.reason = track::NoProjection::kTooFewPoints;
  const auto m = to_lcm_projection(1, 1, 1, out);
  EXPECT_FALSE(m.valid);
  EXPECT_EQ(m.flipper, -1);
  EXPECT_EQ(m.reason, static_cast<std::int8_t>(track::NoProjection::kTooFewPoints));
}

TEST(MessageConvert, MalformedObservationsAreRefused) {
  bool found;
  track::Observation o;
  track::ContactSensors c;
  pinball_lcm::lcmt_pinball_observation m{};
  m.found = true;
  m.x_m = std::nan("");
  EXPECT_FALSE(from_lcm_observation(m, found, o, c));
  EXPECT_STREQ(observation_fault(m), "a found ball's position is not finite");
  m.x_m = 0.1;
  m.y_m = 0.2;
  m.confidence = 1.5;
  EXPECT_FALSE(from_lcm_observation(m, found, o, c));
  EXPECT_STREQ(observation_fault(m), "a found ball's confidence is outside 0..1");
  m.confidence = 1.0;
  m.utime = -5;
  EXPECT_FALSE(from_lcm_observation(m, found, o, c));
  m.utime = 5;
  EXPECT_TRUE(from_lcm_observation(m, found, o, c));
  m.delivered_utime = -1;
  EXPECT_FALSE(from_lcm_observation(m, found, o, c));
  EXPECT_STREQ(observation_fault(m), "delivered_utime below 0");
  m.delivered_utime = 2;  // stamped before its exposure (a miscalibrated latency): no negative lead
  ASSERT_TRUE(from_lcm_observation(m, found, o, c));
  EXPECT_EQ(o.latency_s, 0.0);
}

TEST(MessageConvert, MalformedFlipperCommandsNameTheirField) {
  pinball_lcm::lcmt_pinball_flipper_command m{};
  EXPECT_TRUE(valid_flipper_command(m));
  EXPECT_EQ(flipper_command_fault(m), nullptr);
  m.flipper = 7;
  EXPECT_FALSE(valid_flipper_command(m));
  EXPECT_NE(std::string(flipper_command_fault(m)).find("flipper outside -1..1"), std::string::npos);
  m.flipper = -1;
  m.cause = 9;
  EXPECT_STREQ(flipper_command_fault(m), "cause outside 0..5");
  m.cause = 0;
  m.utime = -1;
  EXPECT_STREQ(flipper_command_fault(m), "utime below 0");
}

TEST(MessageConvert, LogsFromBeforeTheDeliveryStampStillDecode) {
  // Every PINBALL_OBSERVATION recorded before 2026-12-03 carries this fingerprint.
  EXPECT_EQ(pinball_lcm::lcmt_pinball_observation_v1::getHash(), static_cast<std::int64_t>(0x88dcd76b0973ee6dULL));
  EXPECT_NE(pinball_lcm::lcmt_pinball_observation::getHash(), pinball_lcm::lcmt_pinball_observation_v1::getHash());
  pinball_lcm::lcmt_pinball_observation_v1 old{};
  old.utime = 2'000'000;
  old.seq = 9;
  old.found = true;
  old.x_m = 0.3;
  old.y_m = 0.4;
  old.confidence = 0.75;
  old.contact_right = true;
  const std::vector<std::uint8_t> old_bytes = encode_message(old);
  pinball_lcm::lcmt_pinball_observation m{};
  ASSERT_EQ(decode_observation(old_bytes.data(), old_bytes.size(), m), ObservationLayout::kBeforeDelivery);
  EXPECT_EQ(m.utime, 2'000'000);
  EXPECT_EQ(m.delivered_utime, 2'000'000) << "delivered at its stamp: latency unknown, 0";
  EXPECT_EQ(m.seq, 9);
  EXPECT_EQ(m.x_m, 0.3);
  EXPECT_EQ(m.y_m, 0.4);
  EXPECT_EQ(m.confidence, 0.75);
  EXPECT_TRUE(m.found);
  EXPECT_TRUE(m.contact_right);
  EXPECT_FALSE(m.contact_left);

  track::Observation o;
  o.p_board = Vec2(0.1, 0.2);
  const std::vector<std::uint8_t> bytes = encode_message(to_lcm_observation(5, 7, 1, true, o, 0, 0, {}));
  ASSERT_EQ(decode_observation(bytes.data(), bytes.size(), m), ObservationLayout::kCurrent);
  EXPECT_EQ(m.delivered_utime, 7);
  std::vector<std::uint8_t> longer = bytes;
  longer.push_back(0);
  EXPECT_EQ(decode_observation(longer.data(), longer.size(), m), ObservationLayout::kMalformed) << "trailing bytes";
  const std::vector<std::uint8_t> garbage(bytes.size(), 0xab);
  EXPECT_EQ(decode_observation(garbage.data(), garbage.size(), m), ObservationLayout::kMalformed);
}

TEST(MessageConvert, DriverStatusNamesTheCoilsThatAreOn) {
  firmware::BoardView view;
  view.valid = true;
  view.status.coil_states = static_cast<std::uint16_t>(static_cast<unsigned>(firmware::CoilState::kHold) << 2);
  firmware::DriverBusCounters k;
  k.frames_sent = 12;
  k.bus_off = 1;
  k.reconnects = 1;
  k.release_retries = 4;
  k.liveness_stalls = 2;
  k.coils_dropped = 3;
  const auto m = round_trip(to_lcm_driver_status(9, 3, firmware::BusState::kRunning, view, k));
  EXPECT_EQ(m.release_retries, 4);  // the host's fault actions travel too
  EXPECT_EQ(m.liveness_stalls, 2);
  EXPECT_EQ(m.coils_dropped, 3);
  EXPECT_EQ(m.coils_on, 0b10);  // driver 1 holds, driver 0 is off
  EXPECT_EQ(m.bus_state, static_cast<std::int8_t>(firmware::BusState::kRunning));
  EXPECT_TRUE(m.board_valid);
  EXPECT_EQ(m.frames_sent, 12);
  EXPECT_EQ(m.bus_off, 1);
  EXPECT_EQ(m.reconnects, 1);
  view.valid = false;
  EXPECT_EQ(to_lcm_driver_status(9, 4, firmware::BusState::kHandshake, view, k).coils_on, 0);
}

TEST(MessageConvert, DaemonStatsCarryTheRecordingCounts) {
  const StageLatency stages[1] = {{"capture->detection", 10, 1.0, 2.0, 3.0}};
  DaemonStatsCounts counts;
  counts.frames = 10;
  counts.can_log_written = 40;
  counts.can_log_dropped = 2;
  counts.lcm_published = 50;
  counts.lcm_publish_failed = 3;
  const pinball_lcm::lcmt_pinball_daemon_stats m = to_lcm_daemon_stats(7, 1, stages, counts);
  EXPECT_EQ(m.num_stages, 1);
  EXPECT_EQ(m.frames, 10);
  EXPECT_EQ(m.can_log_written, 40);
  EXPECT_EQ(m.can_log_dropped, 2);
  EXPECT_EQ(m.lcm_published, 50);
  EXPECT_EQ(m.lcm_publish_failed, 3);
}

TEST(MessageConvert, FlipperCommandRange) {
  pinball_lcm::lcmt_pinball_flipper_command m{};
  m.flipper = 1;
  EXPECT_TRUE(valid_flipper_command(m));
  m.flipper = 2;
  EXPECT_FALSE(valid_flipper_command(m));
  m.flipper = -1;
  m.cause = 9;
  EXPECT_FALSE(valid_flipper_command(m));
}

template <class T>
std::optional<std::int64_t> utime_of_encoded(T m, std::int64_t utime) {
  m.utime = utime;
  const std::vector<std::uint8_t> buf = encode_message(m);
  return encoded_utime(buf.data(), buf.size());
}

TEST(MessageConvert, EveryTypeCarriesItsUtimeFirst) {
  constexpr std::int64_t kUtime = 1'700'000'123'456'789;
  EXPECT_EQ(utime_of_encoded(pinball_lcm::lcmt_pinball_observation{}, kUtime), kUtime);
  EXPECT_EQ(utime_of_encoded(pinball_lcm::lcmt_pinball_projection{}, kUtime), kUtime);
  EXPECT_EQ(utime_of_encoded(pinball_lcm::lcmt_pinball_flipper_command{}, kUtime), kUtime);
  EXPECT_EQ(utime_of_encoded(pinball_lcm::lcmt_pinball_driver_status{}, kUtime), kUtime);
  EXPECT_EQ(utime_of_encoded(pinball_lcm::lcmt_pinball_game_event{}, kUtime), kUtime);
  EXPECT_EQ(utime_of_encoded(pinball_lcm::lcmt_pinball_daemon_stats{}, kUtime), kUtime);
  const std::uint8_t short_message[12] = {};
  EXPECT_FALSE(encoded_utime(short_message, sizeof short_message).has_value());
}

TEST(MessageConvert, ValidProjectionRefusesNonFiniteAndNegativeFields) {
  pinball_lcm::lcmt_pinball_projection m{};
  EXPECT_TRUE(valid_projection(m));  // an invalid projection of zeros is well formed
  m.valid = true;
  EXPECT_TRUE(valid_projection(m));
  m.t_impact_s = -0.01;
  EXPECT_FALSE(valid_projection(m));
  m.t_impact_s = 0.1;
  m.impact_x_m = std::nan("");
  EXPECT_FALSE(valid_projection(m));
  m.impact_x_m = 0.1;
  m.flipper = 2;
  EXPECT_FALSE(valid_projection(m));
}

}  // namespace
}  // namespace pinball::bus
