#include "pinball/firmware/virtual_driver_board.h"

#include <gtest/gtest.h>

#include "board_harness.h"
#include "pinball/simlab/faulty_link.h"

namespace pinball::firmware {
namespace {

using testing::BoardTest;
using VirtualDriverBoardTest = BoardTest;

constexpr double kEps = 1e-9;

TEST_F(VirtualDriverBoardTest, RefusesCommandsBeforeHelloAndConfiguration) {
  fire(0);
  EXPECT_EQ(board_.coil(0).state, CoilState::kOff);
  EXPECT_EQ(board_.counters().refused_not_configured, 1u);
  send(Hello{kProtocolVersion, 100});
  heartbeat();
  fire(0);  // session, heartbeat, but driver 0 not configured
  EXPECT_EQ(board_.coil(0).state, CoilState::kOff);
  EXPECT_EQ(board_.counters().refused_not_configured, 2u);
  send(Configure{0, DriverConfig{}});
  monitor_.set_caps(0, testing::caps_of(DriverConfig{}));
  fire(0);
  EXPECT_EQ(board_.coil(0).state, CoilState::kPulse);
  const auto msgs = board_messages();
  EXPECT_EQ(faults(msgs, FaultCode::kNotConfigured), 2);
  bool acked = false;
  for (const Message& m : msgs) acked |= std::holds_alternative<HelloAck>(m.payload);
  EXPECT_TRUE(acked);
}

TEST_F(VirtualDriverBoardTest, RefusesFireUntilTheFirstHeartbeat) {
  send(Hello{kProtocolVersion, 100});
  send(Configure{0, DriverConfig{}});
  fire(0);
  EXPECT_EQ(board_.coil(0).state, CoilState::kOff);
  EXPECT_EQ(board_.counters().refused_not_armed, 1u);
  heartbeat();
  fire(0);
  EXPECT_EQ(board_.coil(0).state, CoilState::kPulse);
}

TEST_F(VirtualDriverBoardTest, PulsesThenHoldsAtTheConfiguredDuty) {
  const DriverConfig c{30, 25, 40, 5000, 10};
  open_session(c);
  advance_to(1.0);
  heartbeat();
  fire(0);
  EXPECT_EQ(board_.coil(0).state, CoilState::kPulse);
  EXPECT_DOUBLE_EQ(board_.coil(0).duty, 1.0);
  advance_to(1.0295);
  EXPECT_EQ(board_.coil(0).state, CoilState::kPulse);
  advance_to(1.0305);
  ASSERT_EQ(board_.coil(0).state, CoilState::kHold);
  EXPECT_NEAR(board_.coil(0).since_s, 1.030, kEps);  // the switch happens at the deadline, not at the poll
  EXPECT_DOUBLE_EQ(board_.coil(0).duty, 0.25);
  heartbeat();
  release(0);
  EXPECT_EQ(board_.coil(0).state, CoilState::kOff);
  EXPECT_NEAR(monitor_.record(0).longest_pulse_s, 0.030, kEps);
  EXPECT_EQ(board_.coil(1).state, CoilState::kOff);
}

TEST_F(VirtualDriverBoardTest, PulseOnlyModeSwitchesOffAfterThePulse) {
  open_session();
  fire(1, FireMode::kPulseOnly, 15);
  advance_to(0.0151);
  EXPECT_EQ(board_.coil(1).state, CoilState::kOff);
  EXPECT_NEAR(board_.coil(1).since_s, 0.015, kEps);
}

TEST_F(VirtualDriverBoardTest, PulseIsCappedWhateverTheCommandSays) {
  const DriverConfig c{20, 25, 25, 5000, 0};
  open_session(c);
  fire(0, FireMode::kPulseHold, 90);  // asks for 90 ms, cap 25 ms
  advance_to(0.0249);
  EXPECT_EQ(board_.coil(0).state, CoilState::kPulse);
  advance_to(0.026);
  EXPECT_EQ(board_.coil(0).state, CoilState::kHold);
  EXPECT_EQ(board_.counters().pulse_clamps, 1u);
  EXPECT_NEAR(monitor_.record(0).longest_pulse_s, 0.025, kEps);
  EXPECT_EQ(faults(board_messages(), FaultCode::kPulseClamped), 1);
}

TEST_F(VirtualDriverBoardTest, HoldIsCappedAndTheDriverStaysLockedUntilRelease) {
  const DriverConfig c{30, 25, 40, 500, 0};
  open_session(c, 2, 1000);
  fire(0);
  // Keep heartbeats coming so only the hold cap can end it.
  for (int k = 1; k <= 80; ++k) {
    advance_to(k * 0.01);
    heartbeat();
    fire(0);  // a host insisting: must not restart the pulse
  }
  EXPECT_EQ(board_.coil(0).state, CoilState::kOff);
  EXPECT_NEAR(board_.coil(0).since_s, 0.030 + 0.500, kEps);
  EXPECT_EQ(board_.counters().hold_cap_trips, 1u);
  EXPECT_GT(board_.counters().refused_locked, 0u);
  EXPECT_GT(board_.counters().refused_busy, 0u);
  EXPECT_EQ(monitor_.record(0).pulses, 1u);
  EXPECT_NEAR(monitor_.record(0).longest_hold_s, 0.5, kEps);
  EXPECT_EQ(faults(board_messages(), FaultCode::kHoldCapReached), 1);
  release(0);
  fire(0);
  EXPECT_EQ(board_.coil(0).state, CoilState::kPulse);
}

TEST_F(VirtualDriverBoardTest, OnlyReleaseUnlocksAHoldCappedDriverNotConfigureOrHello) {
  const DriverConfig c{30, 25, 40, 200, 0};
  open_session(c, 2, 1000);
  fire(0);
  for (int k = 1; k <= 30; ++k) {
    advance_to(k * 0.01);
    heartbeat();
  }
  ASSERT_EQ(board_.counters().hold_cap_trips, 1u);
  send(Configure{0, c});  // protocol v1 unlocked here
  fire(0);
  EXPECT_EQ(board_.coil(0).state, CoilState::kOff);
  send(Hello{kProtocolVersion, 1000});  // nor does a new session
  send(Configure{0, c});
  heartbeat();
  fire(0);
  EXPECT_EQ(board_.coil(0).state, CoilState::kOff);
  EXPECT_EQ(board_.counters().refused_locked, 2u);
  EXPECT_EQ(faults(board_messages(), FaultCode::kLocked), 2);  // each refusal is reported
  release(0);
  fire(0);
  EXPECT_EQ(board_.coil(0).state, CoilState::kPulse);
}

TEST_F(VirtualDriverBoardTest, AStaleFireIsReportedAsAFault) {
  open_session(DriverConfig{30, 25, 40, 5000, 0});
  const CanFrame fire_frame = encode(0, Fire{0, FireMode::kPulseHold, 0, ++seq_});
  send_raw(fire_frame);
  release(0);
  advance_to(0.05);
  send_raw(fire_frame);
  const std::vector<Message> msgs = board_messages();
  ASSERT_EQ(faults(msgs, FaultCode::kStale), 1);
  for (const Message& m : msgs) {
    if (const auto* f = std::get_if<Fault>(&m.payload); f != nullptr && f->code == FaultCode::kStale) {
      EXPECT_EQ(f->driver, 0);
      EXPECT_EQ(f->detail, 2);  // the stale Fire's seq (the first heartbeat was seq 1)
    }
  }
}

// Protocol v1 compared a Fire with the driver's last command only: after 2^15
// heartbeats (11 minutes at 20 ms) the host's next Fire looked older than it.
TEST_F(VirtualDriverBoardTest, AFlipperFiresAfterTwoHoursOfIdleHeartbeats) {
  open_session(DriverConfig{30, 25, 40, 5000, 0}, 2, 100);
  fire(0);
  release(0);
  const int heartbeats = 2 * 3600 * 50;  // 2 h at 20 ms: the 16-bit seq wraps five times
  for (int k = 1; k <= heartbeats; ++k) {
    t_ = 0.1 + k * 0.02;
    heartbeat();
    if (k % 20 == 0) board_messages();  // keep the socket pair from filling
    if (k % 36000 == 0) {  // every 12 min, the other flipper too
      fire(1);
      EXPECT_EQ(board_.coil(1).state, CoilState::kPulse) << "after " << k << " heartbeats";
      release(1);
    }
  }
  fire(0);
  EXPECT_EQ(board_.coil(0).state, CoilState::kPulse);
  EXPECT_EQ(board_.counters().stale, 0u);
  // Serial arithmetic still refuses a duplicate of that Fire.
  const CanFrame dup = encode(0, Fire{0, FireMode::kPulseHold, 0, seq_});
  release(0);
  advance_to(t_ + 0.05);
  send_raw(dup);
  EXPECT_EQ(board_.coil(0).state, CoilState::kOff);
  EXPECT_EQ(board_.counters().stale, 1u);
}

TEST_F(VirtualDriverBoardTest, RecycleTimeIsRespected) {
  const DriverConfig c{10, 0, 40, 100, 50};  // no hold, 50 ms recycle
  open_session(c);
  fire(0);
  advance_to(0.011);
  EXPECT_EQ(board_.coil(0).state, CoilState::kOff);
  advance_to(0.059);  // 49 ms after the coil went off
  heartbeat();
  fire(0);
  EXPECT_EQ(board_.coil(0).state, CoilState::kOff);
  EXPECT_EQ(board_.counters().refused_recycle, 1u);
  advance_to(0.0605);
  fire(0);
  EXPECT_EQ(board_.coil(0).state, CoilState::kPulse);
}

TEST_F(VirtualDriverBoardTest, HeartbeatLossSwitchesEverythingOffWithinTheTimeout) {
  open_session(DriverConfig{}, 2, 100);
  fire(0);
  fire(1);
  advance_to(0.040);
  heartbeat();  // the last heartbeat, at 40 ms
  ASSERT_EQ(board_.coil(0).state, CoilState::kHold);
  ASSERT_EQ(board_.coil(1).state, CoilState::kHold);
  const double last_hb = t_;
  for (double t = 0.041; t < 0.3; t += 0.001) advance_to(t);  // host dead: nothing more arrives
  for (int d = 0; d < 2; ++d) {
    EXPECT_EQ(board_.coil(d).state, CoilState::kOff);
    EXPECT_NEAR(board_.coil(d).since_s, last_hb + 0.100, kEps);
  }
  EXPECT_FALSE(board_.armed());
  EXPECT_EQ(board_.counters().watchdog_trips, 1u);
  EXPECT_EQ(faults(board_messages(), FaultCode::kWatchdogExpired), 1);
  // Fire without a fresh heartbeat is refused; a fresh one re-arms.
  fire(0);
  EXPECT_EQ(board_.coil(0).state, CoilState::kOff);
  heartbeat();
  fire(0);
  EXPECT_EQ(board_.coil(0).state, CoilState::kPulse);
}

TEST_F(VirtualDriverBoardTest, WatchdogActsEvenWhenTheBoardIsPolledLate) {
  open_session(DriverConfig{}, 1, 50);
  fire(0);
  advance_to(10.0);  // one late poll: every deadline is applied at its own time
  EXPECT_EQ(board_.coil(0).state, CoilState::kOff);
  EXPECT_NEAR(board_.coil(0).since_s, 0.050, kEps);
  EXPECT_NEAR(monitor_.record(0).longest_hold_s, 0.020, kEps);
}

TEST_F(VirtualDriverBoardTest, StaleHeartbeatsDoNotKeepTheBoardAlive) {
  open_session(DriverConfig{}, 1, 100);
  const std::uint16_t old = seq_;
  fire(0);
  for (double t = 0.01; t < 0.3; t += 0.01) {
    advance_to(t);
    send(Heartbeat{kProtocolVersion, old});  // a duplicate replayed forever
  }
  EXPECT_EQ(board_.coil(0).state, CoilState::kOff);
  EXPECT_EQ(board_.counters().watchdog_trips, 1u);
  EXPECT_GT(board_.counters().stale, 20u);
}

TEST_F(VirtualDriverBoardTest, DuplicatedAndReorderedFramesAreHarmless) {
  open_session(DriverConfig{30, 25, 40, 5000, 0});
  const CanFrame fire_frame = encode(0, Fire{0, FireMode::kPulseHold, 0, ++seq_});
  send_raw(fire_frame);
  send_raw(fire_frame);  // duplicate while on: no second pulse
  advance_to(0.035);
  const CanFrame release_frame = encode(0, Release{0, ++seq_});
  send_raw(release_frame);
  advance_to(0.050);
  send_raw(fire_frame);  // the old Fire arrives again after the Release: must not switch on
  send_raw(release_frame);
  EXPECT_EQ(board_.coil(0).state, CoilState::kOff);
  EXPECT_EQ(monitor_.record(0).pulses, 1u);
  EXPECT_EQ(board_.counters().fires_accepted, 1u);
  EXPECT_EQ(board_.counters().stale, 2u);
  // Reordered: Release overtaken by a later Fire of the other driver changes nothing for driver 0.
  const CanFrame f1 = encode(0, Fire{1, FireMode::kPulseHold, 0, ++seq_});
  const CanFrame r1 = encode(0, Release{1, ++seq_});
  send_raw(r1);
  send_raw(f1);  // arrives after its own Release: refused as stale
  EXPECT_EQ(board_.coil(1).state, CoilState::kOff);
}

TEST_F(VirtualDriverBoardTest, CorruptedFramesAreCountedAndIgnored) {
  open_session();
  simlab::FaultyLinkOptions o;
  o.corrupt_p = 1.0;
  o.seed = 7;
  simlab::FaultyLink noisy(*host_, o);
  for (int i = 0; i < 200; ++i) {
    ASSERT_EQ(noisy.send(encode(0, Fire{static_cast<std::uint8_t>(i % 2), FireMode::kPulseHold, 0, ++seq_})), TxStatus::kOk);
    board_.service(*link_, t_);
  }
  EXPECT_EQ(noisy.fault_counters().corrupted, 200u);
  EXPECT_EQ(board_.counters().bad_frames, 200u);
  EXPECT_GT(board_.counters().bad_checksum, 150u);
  EXPECT_EQ(board_.coil(0).state, CoilState::kOff);
  EXPECT_EQ(board_.coil(1).state, CoilState::kOff);
  EXPECT_EQ(board_.counters().fires_accepted, 0u);
  EXPECT_GT(faults(board_messages(), FaultCode::kBadFrame), 0);
}

TEST_F(VirtualDriverBoardTest, ReleaseIsObeyedWhateverItsSequenceNumber) {
  open_session();
  fire(0);
  send(Release{0, static_cast<std::uint16_t>(seq_ - 100)});
  EXPECT_EQ(board_.coil(0).state, CoilState::kOff);
  fire(1);
  send(ReleaseAll{0});
  EXPECT_EQ(board_.coil(1).state, CoilState::kOff);
}

TEST_F(VirtualDriverBoardTest, VersionMismatchIsRefusedAndReported) {
  CanFrame hello = encode(0, Hello{});
  hello.data[0] = kProtocolVersion + 1;
  hello.data[3] = frame_crc(hello.id, std::span<const std::uint8_t>(hello.data.data(), 3));
  send_raw(hello);
  EXPECT_FALSE(board_.in_session());
  EXPECT_EQ(board_.counters().version_mismatch, 1u);
  const auto msgs = board_messages();
  ASSERT_EQ(faults(msgs, FaultCode::kVersionMismatch), 1);
  for (const Message& m : msgs) {
    if (const auto* f = std::get_if<Fault>(&m.payload)) {
      EXPECT_EQ(f->detail, kProtocolVersion + 1);
    }
  }
}

TEST_F(VirtualDriverBoardTest, HelloStartsAFreshSessionWithEverythingOff) {
  open_session();
  fire(0);
  send(Hello{kProtocolVersion, 100});
  EXPECT_EQ(board_.coil(0).state, CoilState::kOff);
  EXPECT_FALSE(board_.configured(0));
  EXPECT_FALSE(board_.armed());
  seq_ = 0;  // a restarted host starts its sequence again
  advance_to(0.020);  // past the recycle time of the pulse that Hello cut short
  open_session();
  fire(0);
  EXPECT_EQ(board_.coil(0).state, CoilState::kPulse);
}

TEST_F(VirtualDriverBoardTest, StatusReportsCoilsSwitchesConfigurationAndSequence) {
  open_session();
  fire(1);
  board_.set_end_of_stroke(1, true);
  const Status s = board_.status();
  EXPECT_EQ(s.coil(0), CoilState::kOff);
  EXPECT_EQ(s.coil(1), CoilState::kPulse);
  EXPECT_EQ(s.end_of_stroke, 0b10);
  EXPECT_EQ(s.configured, 0b11);
  EXPECT_EQ(s.last_seq, seq_);
  EXPECT_TRUE(s.faults & kFaultBitArmed);
  board_messages();
  advance_to(0.05);
  int statuses = 0;
  for (const Message& m : board_messages()) statuses += std::holds_alternative<Status>(m.payload);
  EXPECT_GE(statuses, 1);
}

TEST_F(VirtualDriverBoardTest, IgnoresOtherBoardsFrames) {
  open_session();
  send_raw(encode(3, Fire{0, FireMode::kPulseHold, 0, ++seq_}));
  EXPECT_EQ(board_.coil(0).state, CoilState::kOff);
  EXPECT_EQ(board_.counters().foreign, 1u);
}

TEST(VirtualDriverBoardOptions, RejectsBadSettings) {
  VirtualDriverBoardOptions o;
  o.driver_count = 0;
  EXPECT_THROW(VirtualDriverBoard{o}, std::invalid_argument);
  o.driver_count = 9;
  EXPECT_THROW(VirtualDriverBoard{o}, std::invalid_argument);
  o = {};
  o.board_id = 16;
  EXPECT_THROW(VirtualDriverBoard{o}, std::invalid_argument);
}

// Random traffic with every kind of link fault: the caps hold whatever arrives.
TEST_F(VirtualDriverBoardTest, RandomCommandsOverAFaultyLinkNeverBreakTheCaps) {
  const DriverConfig c{25, 30, 30, 300, 5};
  open_session(c, 2, 100);
  simlab::FaultyLinkOptions o;
  o.drop_p = 0.1;
  o.delay_p = 0.1;
  o.duplicate_p = 0.1;
  o.corrupt_p = 0.1;
  o.seed = 99;
  simlab::FaultyLink link(*host_, o);
  Rng rng(5);
  for (int step = 0; step < 4000; ++step) {
    t_ += 0.001;
    const double u = rng.uniform01();
    const auto d = static_cast<std::uint8_t>(rng.next_u64() % 2);
    Payload p = Heartbeat{kProtocolVersion, ++seq_};
    if (u < 0.05) {
      p = Fire{d, FireMode::kPulseHold, static_cast<std::uint8_t>(rng.next_u64() % 101), ++seq_};
    } else if (u < 0.08) {
      p = Release{d, ++seq_};
    } else if (u > 0.5 || step >= 3000) {
      continue;  // heartbeats about every 2 ms, then silence for the last 1 s
    }
    (void)link.send(encode(0, p));
    board_.service(*link_, t_);
  }
  EXPECT_GT(monitor_.record(0).pulses + monitor_.record(1).pulses, 10u);
  EXPECT_GT(board_.counters().bad_frames, 10u);
  EXPECT_GT(board_.counters().stale, 10u);
}

}  // namespace
}  // namespace pinball::firmware
