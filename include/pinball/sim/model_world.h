#pragma once
// The thesis model as a world: the board's physics on the thesis stepper or on
// the exact event stepper, with the thesis's launch (3.3.1). Forks share the
// stepper (its grids are built once), so every thread and ball plays the same
// immutable model.

#include <memory>

#include "pinball/sim/event_stepper.h"
#include "pinball/sim/thesis_stepper.h"
#include "pinball/sim/world.h"

namespace pinball::sim {

/// Settings of a model world.
struct ModelWorldOptions {
  StepperKind stepper = StepperKind::kThesis;  ///< which integrator
  double dt_s = 0.0;             ///< step (thesis) or step horizon (event) (s); 0: the stepper options' (then the board's)
  ThesisStepperOptions thesis;   ///< the rest of the thesis stepper's settings
  EventStepperOptions event;     ///< the rest of the event stepper's settings
};

/// Builds a model world over `board` (borrowed: it must outlive every fork).
/// Throws std::invalid_argument for a bad time step (the steppers' checks).
std::unique_ptr<World> make_model_world(const table::Board& board, const ModelWorldOptions& options = {});

}  // namespace pinball::sim
