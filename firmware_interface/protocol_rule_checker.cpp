#include "pinball/firmware/protocol_rule_checker.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "pinball/core/check.h"

namespace pinball::firmware {
namespace {

constexpr double kMs = 1e-3;

double pulse_cap_s(const DriverConfig& c) { return std::min(c.max_pulse_ms, kAbsMaxPulseMs) * kMs; }
double hold_cap_s(const DriverConfig& c) { return std::min(c.max_hold_ms, kAbsMaxHoldMs) * kMs; }
double duty_cap(const DriverConfig& c) { return std::min(c.hold_duty_pct, kAbsMaxHoldDutyPct) / 100.0; }

}  // namespace

ProtocolRuleChecker::ProtocolRuleChecker(std::uint8_t board_id, int driver_count)
    : board_id_(board_id), driver_count_(driver_count) {
  check_input(board_id < kMaxBoards, "ProtocolRuleChecker", "board_id must be 0..15");
  check_input(driver_count >= 1 && driver_count <= kMaxDrivers, "ProtocolRuleChecker", "driver_count must be 1..8");
}

void ProtocolRuleChecker::violation(int driver, const char* rule, double t_s) {
  if (violations_++ == 0) {
    char line[160];
    std::snprintf(line, sizeof line, "t=%.6f s driver %d: %s", t_s, driver, rule);
    first_violation_ = line;
  }
}

void ProtocolRuleChecker::before_frame(const CanFrame& frame, double now_s) {
  in_frame_ = true;
  frame_t_s_ = now_s;
  const DecodeResult r = decode(frame);
  frame_valid_ = r.ok() && r.message.board == board_id_;
  if (frame_valid_) {
    frame_ = r.message;
    ++valid_frames_;
  }
}

void ProtocolRuleChecker::after_frame(double now_s) {
  in_frame_ = false;
  if (!frame_valid_) return;
  const Payload& p = frame_.payload;
  auto must_be_off = [&](int d, const char* rule) {
    if (drivers_[static_cast<std::size_t>(d)].out.state != CoilState::kOff) violation(d, rule, now_s);
  };
  if (const auto* hello = std::get_if<Hello>(&p)) {
    for (int d = 0; d < driver_count_; ++d) {
      must_be_off(d, "rule 1: on after Hello");
      drivers_[static_cast<std::size_t>(d)].configured = false;
    }
    session_ = true;
    watchdog_s_ = hello->watchdog_ms * kMs;
    last_heartbeat_s_ = -1e300;
  } else if (const auto* cfg = std::get_if<Configure>(&p)) {
    if (session_ && cfg->driver < driver_count_) {
      must_be_off(cfg->driver, "rule 1: on after its Configure");
      Driver& drv = drivers_[cfg->driver];
      drv.configured = true;
      drv.config = cfg->config;
    }
  } else if (std::holds_alternative<Heartbeat>(p)) {
    if (session_) last_heartbeat_s_ = now_s;  // an upper bound: the board may refuse a stale one
  } else if (const auto* rel = std::get_if<Release>(&p)) {
    if (rel->driver < driver_count_) {
      must_be_off(rel->driver, "rule 10: on after its Release");
      drivers_[rel->driver].locked = false;
    }
  } else if (std::holds_alternative<ReleaseAll>(p)) {
    for (int d = 0; d < driver_count_; ++d) {
      must_be_off(d, "rule 10: on after ReleaseAll");
      drivers_[static_cast<std::size_t>(d)].locked = false;
    }
  }
  check_at(now_s);
}

void ProtocolRuleChecker::check_at(double now_s) {
  for (int d = 0; d < driver_count_; ++d) {
    const Driver& drv = drivers_[static_cast<std::size_t>(d)];
    if (drv.out.state == CoilState::kOff) continue;
    if (now_s > last_heartbeat_s_ + watchdog_s_ + kToleranceS) violation(d, "rule 4: on past the watchdog", now_s);
    if (drv.out.state == CoilState::kPulse && now_s > drv.out.since_s + pulse_cap_s(drv.config) + kToleranceS) {
      violation(d, "rule 5: pulse past its cap", now_s);
    }
    if (drv.out.state == CoilState::kHold && now_s > drv.out.since_s + hold_cap_s(drv.config) + kToleranceS) {
      violation(d, "rule 6: hold past its cap", now_s);
    }
  }
}

// Switching on: only by a valid Fire for this driver, in session, configured,
// armed, unlocked, past the recycle time (rules 2, 3, 6, 8, 11).
void ProtocolRuleChecker::check_switch_on(int d, const CoilOutput& o) {
  ++switch_ons_;
  const Driver& drv = drivers_[static_cast<std::size_t>(d)];
  const Fire* fire = in_frame_ && frame_valid_ ? std::get_if<Fire>(&frame_.payload) : nullptr;
  if (fire == nullptr || fire->driver != d) return violation(d, "rule 11: switched on by no Fire of its own", o.since_s);
  if (!session_ || !drv.configured) return violation(d, "rule 2: fired unconfigured", o.since_s);
  if (o.since_s > last_heartbeat_s_ + watchdog_s_ + kToleranceS) return violation(d, "rule 3: fired unarmed", o.since_s);
  if (drv.locked) return violation(d, "rule 6: fired while locked by its hold cap", o.since_s);
  if (o.since_s < drv.off_since_s + drv.config.recycle_ms * kMs - kToleranceS) {
    return violation(d, "rule 8: fired within its recycle time", o.since_s);
  }
  if (o.state != CoilState::kPulse || o.duty != 1.0) return violation(d, "rule 5: a Fire must start a full pulse", o.since_s);
}

void ProtocolRuleChecker::check_leaving(int d, const CoilOutput& from, const CoilOutput& to) {
  const Driver& drv = drivers_[static_cast<std::size_t>(d)];
  const double t = to.since_s;
  if (from.state == CoilState::kPulse && t > from.since_s + pulse_cap_s(drv.config) + kToleranceS) {
    violation(d, "rule 5: pulse longer than its cap", t);
  }
  if (from.state == CoilState::kHold && t > from.since_s + hold_cap_s(drv.config) + kToleranceS) {
    violation(d, "rule 6: hold longer than its cap", t);
  }
  if (to.state == CoilState::kHold) {
    if (from.state != CoilState::kPulse) violation(d, "rule 6: hold not after a pulse", t);
    if (drv.mode != FireMode::kPulseHold) violation(d, "rule 6: hold after a pulse-only Fire", t);
    if (to.duty <= 0.0 || to.duty > duty_cap(drv.config) + 1e-12) violation(d, "rule 6: hold duty above its cap", t);
  }
  if (to.state == CoilState::kPulse) violation(d, "rule 7: pulse restarted on an energised coil", t);
}

void ProtocolRuleChecker::on_coil_change(int d, const CoilOutput& o) {
  if (d < 0 || d >= driver_count_) return violation(d, "output change on a driver not fitted", o.since_s);
  Driver& drv = drivers_[static_cast<std::size_t>(d)];
  const CoilOutput from = drv.out;
  if (from.state == CoilState::kOff) {
    if (o.state != CoilState::kOff) {
      check_switch_on(d, o);
      if (const Fire* f = in_frame_ && frame_valid_ ? std::get_if<Fire>(&frame_.payload) : nullptr) drv.mode = f->mode;
    }
  } else {
    check_leaving(d, from, o);
    // A hold that ends at its cap locks the driver (rule 6). When the cap
    // coincides with the watchdog or with a frame that switches it off, the
    // board may not lock: the model stays unlocked, the lenient side.
    const double cap_at = from.since_s + hold_cap_s(drv.config);
    const bool at_cap = from.state == CoilState::kHold && o.state == CoilState::kOff && o.since_s >= cap_at - kToleranceS;
    const bool at_watchdog = std::abs(o.since_s - (last_heartbeat_s_ + watchdog_s_)) <= 1e-6;
    const bool at_frame = in_frame_ && o.since_s >= frame_t_s_ - 1e-6;
    if (at_cap && !at_watchdog && !at_frame) drv.locked = true;
  }
  if (o.state == CoilState::kOff) drv.off_since_s = o.since_s;
  drv.out = o;
}

}  // namespace pinball::firmware
