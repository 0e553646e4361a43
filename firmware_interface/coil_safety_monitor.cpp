#include "pinball/firmware/coil_safety_monitor.h"

#include <algorithm>
#include <cstdio>

namespace pinball::firmware {

void CoilSafetyMonitor::set_caps(int d, const CoilCaps& caps) { caps_[static_cast<std::size_t>(d)] = caps; }

void CoilSafetyMonitor::violation(int d, const char* what, double value, double cap) {
  ++violations_;
  if (first_violation_.empty()) {
    char buf[160];
    std::snprintf(buf, sizeof buf, "driver %d: %s %.9f exceeds cap %.9f", d, what, value, cap);
    first_violation_ = buf;
  }
}

void CoilSafetyMonitor::close(int d, double t_s) {
  const auto i = static_cast<std::size_t>(d);
  const CoilOutput& cur = current_[i];
  const double length = t_s - cur.since_s;
  CoilRecord& rec = records_[i];
  if (cur.state == CoilState::kPulse) {
    rec.longest_pulse_s = std::max(rec.longest_pulse_s, length);
    rec.on_time_s += length;
    if (length > caps_[i].pulse_s + kToleranceS) violation(d, "full-power interval (s)", length, caps_[i].pulse_s);
  } else if (cur.state == CoilState::kHold) {
    rec.longest_hold_s = std::max(rec.longest_hold_s, length);
    rec.on_time_s += length;
    if (length > caps_[i].hold_s + kToleranceS) violation(d, "hold interval (s)", length, caps_[i].hold_s);
  }
}

void CoilSafetyMonitor::on_coil_change(int driver, const CoilOutput& output) {
  if (driver < 0 || driver >= kMaxDrivers) {
    violation(driver < 0 ? 0 : kMaxDrivers - 1, "driver index", driver, kMaxDrivers - 1);
    return;
  }
  const auto i = static_cast<std::size_t>(driver);
  if (output.since_s < current_[i].since_s) violation(driver, "time went backwards at", output.since_s, current_[i].since_s);
  close(driver, output.since_s);
  if (output.state == CoilState::kPulse) {
    ++records_[i].pulses;
    if (output.duty > 1.0) violation(driver, "pulse duty", output.duty, 1.0);
  } else if (output.state == CoilState::kHold) {
    ++records_[i].holds;
    if (output.duty > caps_[i].duty + 1e-12) violation(driver, "hold duty", output.duty, caps_[i].duty);
  }
  current_[i] = output;
}

void CoilSafetyMonitor::finish(double now_s) {
  for (int d = 0; d < kMaxDrivers; ++d) {
    close(d, now_s);
    current_[static_cast<std::size_t>(d)].since_s = now_s;
  }
}

}  // namespace pinball::firmware
