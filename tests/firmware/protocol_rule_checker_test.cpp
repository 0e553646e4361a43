#include "pinball/firmware/protocol_rule_checker.h"

#include <gtest/gtest.h>

namespace pinball::firmware {
namespace {

// The checker must catch a board that breaks the rules: fed by hand, as a
// broken board would behave.
class BrokenBoard : public ::testing::Test {
 protected:
  void frame(const Payload& p, double t) {
    checker_.before_frame(encode(0, p), t);
    checker_.after_frame(t);
  }
  void open_session(double t) {
    frame(Hello{kProtocolVersion, 100}, t);
    frame(Configure{0, DriverConfig{30, 25, 40, 500, 10}}, t);
    frame(Heartbeat{kProtocolVersion, 1}, t);
  }
  // Board output change during a frame (the frame switched it).
  void change_in_frame(const Payload& p, double t, CoilState s, double duty) {
    checker_.before_frame(encode(0, p), t);
    checker_.on_coil_change(0, CoilOutput{s, duty, t});
    checker_.after_frame(t);
  }
  ProtocolRuleChecker checker_{0, 2};
};

TEST_F(BrokenBoard, AGoodSessionHasNoViolation) {
  open_session(0.0);
  change_in_frame(Fire{0, FireMode::kPulseHold, 0, 2}, 0.001, CoilState::kPulse, 1.0);
  checker_.on_coil_change(0, CoilOutput{CoilState::kHold, 0.25, 0.031});
  change_in_frame(Release{0, 3}, 0.05, CoilState::kOff, 0.0);
  EXPECT_EQ(checker_.violations(), 0u) << checker_.first_violation();
  EXPECT_EQ(checker_.switch_ons(), 1u);
}

TEST_F(BrokenBoard, CoilOnWithoutAFire) {
  open_session(0.0);
  change_in_frame(Heartbeat{kProtocolVersion, 2}, 0.01, CoilState::kPulse, 1.0);
  EXPECT_EQ(checker_.violations(), 1u);
  EXPECT_NE(checker_.first_violation().find("rule 11"), std::string::npos) << checker_.first_violation();
}

TEST_F(BrokenBoard, FireBeforeConfigure) {
  frame(Hello{kProtocolVersion, 100}, 0.0);
  frame(Heartbeat{kProtocolVersion, 1}, 0.0);
  change_in_frame(Fire{1, FireMode::kPulseHold, 0, 2}, 0.001, CoilState::kPulse, 1.0);
  EXPECT_GE(checker_.violations(), 1u);
}

TEST_F(BrokenBoard, OnPastTheWatchdog) {
  open_session(0.0);
  change_in_frame(Fire{0, FireMode::kPulseHold, 0, 2}, 0.001, CoilState::kPulse, 1.0);
  checker_.on_coil_change(0, CoilOutput{CoilState::kHold, 0.25, 0.031});
  checker_.check_at(0.2);  // no heartbeat since 0.0, watchdog 100 ms
  EXPECT_GE(checker_.violations(), 1u);
  EXPECT_NE(checker_.first_violation().find("rule 4"), std::string::npos) << checker_.first_violation();
}

TEST_F(BrokenBoard, ReleaseIgnored) {
  open_session(0.0);
  change_in_frame(Fire{0, FireMode::kPulseHold, 0, 2}, 0.001, CoilState::kPulse, 1.0);
  frame(Release{0, 3}, 0.01);  // the board did not switch it off
  EXPECT_NE(checker_.first_violation().find("rule 10"), std::string::npos) << checker_.first_violation();
}

TEST_F(BrokenBoard, HoldAfterAPulseOnlyFireOrAboveItsDuty) {
  open_session(0.0);
  change_in_frame(Fire{0, FireMode::kPulseOnly, 0, 2}, 0.001, CoilState::kPulse, 1.0);
  checker_.on_coil_change(0, CoilOutput{CoilState::kHold, 0.6, 0.031});
  EXPECT_GE(checker_.violations(), 2u);  // pulse-only, and 60 % above both caps
}

TEST_F(BrokenBoard, PulseLongerThanItsCap) {
  open_session(0.0);
  change_in_frame(Fire{0, FireMode::kPulseOnly, 0, 2}, 0.001, CoilState::kPulse, 1.0);
  frame(Heartbeat{kProtocolVersion, 3}, 0.05);  // 49 ms of full power; max_pulse_ms 40
  EXPECT_NE(checker_.first_violation().find("rule 5"), std::string::npos) << checker_.first_violation();
}

TEST_F(BrokenBoard, FireAfterAHoldCapWithoutRelease) {
  open_session(0.0);
  change_in_frame(Fire{0, FireMode::kPulseHold, 0, 2}, 0.001, CoilState::kPulse, 1.0);
  checker_.on_coil_change(0, CoilOutput{CoilState::kHold, 0.25, 0.031});
  for (int k = 1; k <= 5; ++k) frame(Heartbeat{kProtocolVersion, static_cast<std::uint16_t>(2 + k)}, k * 0.09);
  checker_.on_coil_change(0, CoilOutput{CoilState::kOff, 0.0, 0.531});  // the cap: 500 ms
  frame(Heartbeat{kProtocolVersion, 20}, 0.54);
  change_in_frame(Fire{0, FireMode::kPulseHold, 0, 21}, 0.57, CoilState::kPulse, 1.0);
  EXPECT_NE(checker_.first_violation().find("locked"), std::string::npos) << checker_.first_violation();
}

TEST_F(BrokenBoard, FireWithinTheRecycleTime) {
  open_session(0.0);
  change_in_frame(Fire{0, FireMode::kPulseOnly, 0, 2}, 0.001, CoilState::kPulse, 1.0);
  checker_.on_coil_change(0, CoilOutput{CoilState::kOff, 0.0, 0.031});
  change_in_frame(Fire{0, FireMode::kPulseOnly, 0, 3}, 0.035, CoilState::kPulse, 1.0);  // recycle 10 ms
  EXPECT_NE(checker_.first_violation().find("rule 8"), std::string::npos) << checker_.first_violation();
}

TEST_F(BrokenBoard, ABadFrameThatSwitchesACoilOn) {
  open_session(0.0);
  CanFrame f = encode(0, Fire{0, FireMode::kPulseHold, 0, 2});
  f.data[5] ^= 0x01;  // CRC broken
  checker_.before_frame(f, 0.001);
  checker_.on_coil_change(0, CoilOutput{CoilState::kPulse, 1.0, 0.001});
  checker_.after_frame(0.001);
  EXPECT_NE(checker_.first_violation().find("rule 11"), std::string::npos) << checker_.first_violation();
}

}  // namespace
}  // namespace pinball::firmware
