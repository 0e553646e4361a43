#pragma once
// The exact event-driven stepper: between events the ball follows the exact
// parabola under constant gravity; events are times of impact found from
// polynomial roots (lines: quadratic, circles and points: quartic), a
// certified root search for rotating flippers, flippers reaching a stop,
// sensor and hole entries and flipper commands changing. It uses the same
// collision response as the thesis stepper (collision.h), so the two differ
// only by integration error. A ball whose normal speed after a bounce is below
// the rest threshold enters a contact mode and slides along the surface under
// the tangential component of gravity instead of bouncing forever (Zeno).
// Its choices are written down in docs/physics.md.

#include <cstdint>
#include <vector>

#include "pinball/table/board.h"
#include "pinball/sim/broadphase.h"
#include "pinball/sim/game_state.h"
#include "pinball/sim/thesis_stepper.h"

namespace pinball::sim {

/// Settings of the event stepper.
struct EventStepperOptions {
  /// Step horizon (s): step() advances exactly this much simulated time and
  /// handles every event inside it. It is the rate at which a policy may change
  /// the flipper commands, not an integration step. 0 takes the board's dt_s.
  double dt_s = 0.0;
  /// Root tolerance relative to the board's size (the diagonal): times of
  /// impact are found to within tolerance·size/speed. The precision report
  /// sweeps it.
  double relative_tolerance = 1e-12;
  /// A bounce whose normal speed leaves less than this apex height
  /// (v_n²/2g_n) is a resting contact: the ball slides instead (m).
  double rest_height_m = 1e-5;
  /// Apply the board's speed clamp after a collision response (a model choice:
  /// the clamp stands in for friction and caps kicker energy).
  bool speed_clamp = true;
  /// false: test every obstacle (the baseline for the broadphase bench).
  bool use_grid = true;
  /// Ball within this of a surface counts as touching (contact score, sensors,
  /// the flipper contact switch), as in the thesis stepper (m).
  double contact_tolerance_m = 5e-4;
};

/// Advances a GameState event by event over a Board it borrows. step()
/// allocates nothing and counts every event in GameState::events.
class EventStepper {
 public:
  /// Builds the grids. Throws std::invalid_argument if dt or a tolerance is not
  /// positive and finite.
  explicit EventStepper(const table::Board& board, EventStepperOptions options = {});

  /// Advances state.time_s by dt_s exactly: flippers move toward the commanded
  /// stop, the ball flies, slides and collides, sensors fire. Events in the
  /// returned StepEvents have the same meaning as the thesis stepper's.
  StepEvents step(GameState& state) const;

  /// The step horizon (s).
  double dt_s() const { return options_.dt_s; }
  /// The board it steps.
  const table::Board& board() const { return board_; }
  /// The settings in force.
  const EventStepperOptions& options() const { return options_; }

 private:
  const table::Board& board_;
  EventStepperOptions options_;
  UniformGrid obstacle_grid_;
  UniformGrid sensor_grid_;
  double length_tol_m_ = 0.0;   // relative_tolerance x board diagonal: root accuracy in metres
  double touch_m_ = 0.0;        // a ball this close to a surface touches it (root accuracy + round-off)
  double touch_speed_mps_ = 0.0;  // normal speeds below this are zero (resting, sliding)
  double separation_speed_mps_ = 0.0;  // a moving flipper sends the ball off at least this much faster than its face
  double circle_slide_m_ = 0.0;  // half-length of a slide along the tangent of a circle (contact mode)
  bool has_contact_score_ = false;
  std::vector<std::int32_t> all_obstacles_;  // 0..n-1 for use_grid = false
  std::vector<std::int32_t> all_sensors_;
  std::vector<table::Shape> sensor_shapes_;
};

}  // namespace pinball::sim
