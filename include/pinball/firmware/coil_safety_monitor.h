#pragma once
// An observer on a board's outputs that records each coil's on-intervals and
// checks them against the caps: a full-power interval never longer than the
// pulse cap, a hold never longer than the hold cap nor above the duty cap.
// Tests attach one to every board they run; the daemon may too.

#include <array>
#include <cstdint>
#include <string>

#include "pinball/firmware/coil_output.h"

namespace pinball::firmware {

/// Caps one driver is checked against.
struct CoilCaps {
  double pulse_s = kAbsMaxPulseMs * 1e-3;     ///< longest full-power interval (s)
  double hold_s = kAbsMaxHoldMs * 1e-3;       ///< longest hold interval (s)
  double duty = kAbsMaxHoldDutyPct / 100.0;   ///< highest hold duty (fraction)
};

/// What one driver did.
struct CoilRecord {
  std::uint64_t pulses = 0;      ///< full-power intervals
  std::uint64_t holds = 0;       ///< hold intervals
  double longest_pulse_s = 0.0;  ///< longest full-power interval seen (s)
  double longest_hold_s = 0.0;   ///< longest hold interval seen (s)
  double on_time_s = 0.0;        ///< total time energised (s)
};

/// The observer.
class CoilSafetyMonitor final : public CoilListener {
 public:
  /// Every driver starts with the absolute caps of protocol.h.
  CoilSafetyMonitor() = default;

  /// Checks driver `d` against `caps` from now on.
  void set_caps(int d, const CoilCaps& caps);
  void on_coil_change(int driver, const CoilOutput& output) override;
  /// Closes the open intervals as of `now_s` and checks them too (a coil still
  /// on at the end of a test counts with its time so far).
  void finish(double now_s);

  /// Number of cap violations seen.
  int violations() const { return violations_; }
  /// Description of the first violation ("" when none).
  const std::string& first_violation() const { return first_violation_; }
  /// Driver `d`'s record.
  const CoilRecord& record(int d) const { return records_[static_cast<std::size_t>(d)]; }
  /// Tolerance on interval lengths (s): floating-point rounding of the board's deadlines.
  static constexpr double kToleranceS = 1e-9;

 private:
  void close(int d, double t_s);
  void violation(int d, const char* what, double value, double cap);

  std::array<CoilCaps, kMaxDrivers> caps_{};
  std::array<CoilOutput, kMaxDrivers> current_{};
  std::array<CoilRecord, kMaxDrivers> records_{};
  int violations_ = 0;
  std::string first_violation_;
};

}  // namespace pinball::firmware
