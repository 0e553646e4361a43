#pragma once
// The seam between the tracker and the flipper solenoids (thesis 5.2.3): a
// flipper controller turns each tracker update into solenoid commands.
// Implementations: the spastic flipper, the learned action function with its
// actuator controller, the imitation shot table and learn::PlanningController;
// a controller file says which (make_flipper_controller, learn::make_controller).

#include <array>
#include <optional>

#include "pinball/core/check.h"
#include "pinball/firmware/protocol.h"
#include "pinball/track/tracker.h"

namespace pinball::control {

/// Longest hold a controller setting may ask for (s): the CAN protocol's
/// absolute hold cap, past which the driver board cuts the coil anyway.
inline constexpr double kMaxHold_s = firmware::kAbsMaxHoldMs * 1e-3;

/// Longest actuation delay a controller may lead by (s): 20 frames at 200 fps.
inline constexpr double kMaxLeadActuationDelay_s = 0.1;

/// The projection a controller acts on (issue 20, "lead"). With an actuation
/// delay: the tracker's projection advanced by the newest frame's camera
/// latency plus that delay, to where the ball will be when a command given now
/// takes effect (track::lead_projection), so a learned d_critical means the
/// same whatever the latency. Without: the projection from the newest frame,
/// as the thesis's controller acts.
track::TrajectoryProjection projection_to_act_on(const track::TrackerOutput& output,
                                                 const std::optional<double>& lead_actuation_delay_s);

/// A lead outside [0, kMaxLeadActuationDelay_s] s (absent is in range), under `key`.
RangeViolation check_lead_actuation_delay(const std::optional<double>& lead_actuation_delay_s,
                                          const char* key = "lead_actuation_delay_s");

/// Anything that decides flipper commands from tracker output.
class FlipperController {
 public:
  virtual ~FlipperController() = default;

  /// Updates the commands from one tracker update at time now_s.
  /// energized[track::kLeftFlipper] / [track::kRightFlipper] are the solenoid commands.
  virtual void update(const track::TrackerOutput& output, double now_s, std::array<bool, 2>& energized) = 0;

  /// Releases everything and forgets (new ball, lost ball).
  virtual void reset(std::array<bool, 2>& energized) = 0;
};

}  // namespace pinball::control
