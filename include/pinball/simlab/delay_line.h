#pragma once
// Flipper commands reach the flippers an actuation delay after they are given:
// the same solenoid model (firmware::FlipperActuation) that the CAN path puts
// behind the board, applied directly to a simulated GameState. Used by the
// learning evaluator and by benchmarks that play on the true state.

#include <cstddef>
#include <vector>

#include "pinball/firmware/flipper_actuation.h"
#include "pinball/sim/game_state.h"

namespace pinball::simlab {

/// Delays each flipper's command by a fixed time. Copyable, so a lookahead can
/// clone it together with the GameState (copy-assigning into an object made for
/// the same board allocates nothing).
class DelayLine {
 public:
  /// `flippers` flippers, each following its command `delay_s` (>= 0) later.
  DelayLine(std::size_t flippers, double delay_s);

  /// Takes state.flippers[i].energized as the command given at state.time_s and
  /// replaces it with the command in effect at that time.
  void apply(sim::GameState& state);

 private:
  std::vector<firmware::FlipperActuation> actuation_;
  std::vector<bool> last_;  // command last passed on, per flipper
};

}  // namespace pinball::simlab
