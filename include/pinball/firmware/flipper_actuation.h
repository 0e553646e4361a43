#pragma once
// The electromechanical link between a driver's coil output and the flipper it
// moves: the flipper follows the coil after an actuation delay (solenoid
// current rise and plunger travel, a few ms). Generic: it yields a bool that
// the simulator copies into its flipper command, without knowing the simulator.

#include <array>

#include "pinball/firmware/coil_output.h"

namespace pinball::firmware {

/// Command to flipper motion of a flipper solenoid (s): current rise and
/// plunger travel. The one default of every place that models it (the fast
/// loop, the daemon's simulation, `pinball sim`, the teacher, the benches).
inline constexpr double kDefaultActuationDelay_s = 0.004;

/// Follows one driver's coil and answers "is the flipper energised at t?".
class FlipperActuation final : public CoilListener {
 public:
  /// Watches driver `driver`; the flipper reacts `delay_s` (>= 0) after the coil.
  /// Throws std::invalid_argument for a negative or non-finite delay.
  FlipperActuation(int driver, double delay_s);

  void on_coil_change(int driver, const CoilOutput& output) override;
  /// The flipper command at time `now_s` (same clock as the board's).
  bool energized(double now_s);
  /// The actuation delay (s).
  double delay_s() const { return delay_s_; }

  /// Most coil changes remembered within one delay.
  static constexpr int kCapacity = 32;

 private:
  struct Change {
    double t_s;
    bool on;
  };
  int driver_;
  double delay_s_;
  bool state_ = false;  // flipper command after every change already in effect
  std::array<Change, kCapacity> pending_{};
  int head_ = 0;
  int count_ = 0;
};

}  // namespace pinball::firmware
