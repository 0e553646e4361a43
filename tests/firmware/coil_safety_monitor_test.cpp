#include "pinball/firmware/coil_safety_monitor.h"

#include <gtest/gtest.h>

namespace pinball::firmware {
namespace {

TEST(CoilSafetyMonitor, MeasuresIntervalsWithinTheCaps) {
  CoilSafetyMonitor m;
  m.set_caps(0, CoilCaps{0.030, 1.0, 0.25});
  m.on_coil_change(0, {CoilState::kPulse, 1.0, 1.000});
  m.on_coil_change(0, {CoilState::kHold, 0.25, 1.030});
  m.on_coil_change(0, {CoilState::kOff, 0.0, 1.500});
  m.finish(2.0);
  EXPECT_EQ(m.violations(), 0) << m.first_violation();
  EXPECT_EQ(m.record(0).pulses, 1u);
  EXPECT_NEAR(m.record(0).longest_pulse_s, 0.030, 1e-12);
  EXPECT_NEAR(m.record(0).longest_hold_s, 0.470, 1e-12);
  EXPECT_NEAR(m.record(0).on_time_s, 0.5, 1e-12);
}

TEST(CoilSafetyMonitor, CatchesEveryKindOfViolation) {
  CoilSafetyMonitor pulse;
  pulse.set_caps(1, CoilCaps{0.030, 1.0, 0.25});
  pulse.on_coil_change(1, {CoilState::kPulse, 1.0, 0.0});
  pulse.on_coil_change(1, {CoilState::kOff, 0.0, 0.031});
  EXPECT_EQ(pulse.violations(), 1);
  EXPECT_NE(pulse.first_violation().find("driver 1"), std::string::npos);

  CoilSafetyMonitor hold;
  hold.set_caps(0, CoilCaps{0.030, 1.0, 0.25});
  hold.on_coil_change(0, {CoilState::kHold, 0.25, 0.0});
  hold.finish(1.5);  // still on at the end: counted with its time so far
  EXPECT_EQ(hold.violations(), 1);

  CoilSafetyMonitor duty;
  duty.set_caps(0, CoilCaps{0.030, 1.0, 0.25});
  duty.on_coil_change(0, {CoilState::kHold, 0.5, 0.0});
  EXPECT_EQ(duty.violations(), 1);
}

}  // namespace
}  // namespace pinball::firmware
