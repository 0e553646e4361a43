#include "pinball/sim/world.h"

#include <stdexcept>
#include <string>

namespace pinball::sim {

StepperKind parse_stepper_kind(std::string_view name) {
  if (name == "thesis") return StepperKind::kThesis;
  if (name == "event") return StepperKind::kEvent;
  throw std::invalid_argument("unknown stepper '" + std::string(name) + "' (expected thesis or event)");
}

std::string_view stepper_kind_name(StepperKind kind) { return kind == StepperKind::kEvent ? "event" : "thesis"; }

std::string describe(const WorldWarnings& w) {
  return std::to_string(w.total()) + " warnings (" + std::to_string(w.penetration) + " deep contacts, " +
         std::to_string(w.instability) + " instabilities, " + std::to_string(w.overflow) + " overflows)";
}

void check_same_flippers(const table::Board& world, const table::Board& belief) {
  bool same = world.flippers.size() == belief.flippers.size();
  for (std::size_t i = 0; same && i < world.flippers.size(); ++i) {
    same = world.flippers[i].side == belief.flippers[i].side;
  }
  if (!same) {
    throw std::invalid_argument("the world's board (" + world.source + ") and the belief (" + belief.source +
                                ") must have the same flippers, in the same order and on the same sides");
  }
}

}  // namespace pinball::sim
