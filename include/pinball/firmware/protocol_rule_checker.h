#pragma once
// An independent check of PROTOCOL.md's firmware rules from the outside: it
// sees the frames offered to a board and the board's output changes, and
// flags every change the rules forbid. It keeps its own model of the session
// (Hello, Configure, Heartbeat, Release, the hold-cap lock), deliberately
// lenient where a board may refuse more (sequence freshness): a violation is
// always a real one. The protocol property test and `pinball bench protocol`
// run it over random and mutated frame streams against VirtualDriverBoard; a
// recorded session of a real board can be replayed through it the same way.

#include <array>
#include <cstdint>
#include <string>

#include "pinball/firmware/can_frame.h"
#include "pinball/firmware/codec.h"
#include "pinball/firmware/coil_output.h"

namespace pinball::firmware {

/// The checker. Call before_frame / after_frame around each frame the board
/// handles, and register it as the board's CoilListener.
class ProtocolRuleChecker final : public CoilListener {
 public:
  /// Checks board `board_id` with `driver_count` drivers.
  ProtocolRuleChecker(std::uint8_t board_id, int driver_count);

  /// `frame` is about to be handled at board time `now_s`.
  void before_frame(const CanFrame& frame, double now_s);
  /// The board handled it; applies its effect to the model and checks the
  /// outputs it must have left (Release: off; Hello: all off; ...).
  void after_frame(double now_s);
  /// Checks the outputs at a time with no frame (the watchdog bound).
  void check_at(double now_s);
  void on_coil_change(int driver, const CoilOutput& output) override;

  /// Rule violations seen.
  std::uint64_t violations() const { return violations_; }
  /// The first one, in words ("" when none).
  const std::string& first_violation() const { return first_violation_; }
  /// Frames that decoded for this board (the rest must change nothing).
  std::uint64_t valid_frames() const { return valid_frames_; }
  /// Coil switch-ons checked.
  std::uint64_t switch_ons() const { return switch_ons_; }

  /// Slack on every time comparison (s): the board's deadlines are sums of doubles.
  static constexpr double kToleranceS = 1e-9;

 private:
  struct Driver {
    bool configured = false;
    DriverConfig config;
    bool locked = false;       // a hold cap ended a hold; only Release / ReleaseAll unlock
    CoilOutput out;
    double off_since_s = -1e300;
    FireMode mode = FireMode::kPulseOnly;
  };

  void violation(int driver, const char* rule, double t_s);
  void check_switch_on(int d, const CoilOutput& o);
  void check_leaving(int d, const CoilOutput& from, const CoilOutput& to);

  std::uint8_t board_id_;
  int driver_count_;
  std::array<Driver, kMaxDrivers> drivers_{};
  bool session_ = false;
  double watchdog_s_ = kDefaultWatchdogMs * 1e-3;
  double last_heartbeat_s_ = -1e300;
  bool in_frame_ = false;
  double frame_t_s_ = 0.0;
  bool frame_valid_ = false;
  Message frame_;            // the frame being handled, when valid
  std::uint64_t violations_ = 0;
  std::uint64_t valid_frames_ = 0;
  std::uint64_t switch_ons_ = 0;
  std::string first_violation_;
};

}  // namespace pinball::firmware
