#pragma once
// What a driver board's output stage does to one coil, and the interface
// through which observers (safety monitor, simulator actuation) see each change.

#include "pinball/firmware/protocol.h"

namespace pinball::firmware {

/// One driver's output.
struct CoilOutput {
  CoilState state = CoilState::kOff;  ///< off, full-power pulse or PWM hold
  double duty = 0.0;                  ///< fraction of full power applied, 0..1 (1 in a pulse)
  double since_s = 0.0;               ///< board time at which this state began (s)
};

/// Receives every output change, stamped with the exact time it happened.
class CoilListener {
 public:
  virtual ~CoilListener() = default;
  /// Driver `driver` changed to `output` at `output.since_s`.
  virtual void on_coil_change(int driver, const CoilOutput& output) = 0;
};

}  // namespace pinball::firmware
