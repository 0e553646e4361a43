#include "pinball/simlab/oracle_policy.h"

#include <limits>
#include <tuple>

namespace pinball::simlab {

void oracle_spastic_policy(const table::Board& board, sim::GameState& state, double reach_factor) {
  int nearest = -1;
  double nearest_d = std::numeric_limits<double>::infinity();
  if (state.ball_in_play) std::tie(nearest, nearest_d) = table::nearest_flipper_at_rest(board, state.ball.position_m);
  // Falling balls only: a ball cradled on a raised flipper is let go, so it
  // rolls down and is flipped again instead of resting there forever.
  constexpr double kFallingSpeed_mps = 0.05;
  const bool in_reach = nearest >= 0 && nearest_d <= reach_factor * board.ball.radius_m &&
                        state.ball.velocity_mps.y() < -kFallingSpeed_mps;
  for (std::size_t i = 0; i < state.flippers.size(); ++i) {
    state.flippers[i].energized = in_reach && static_cast<int>(i) == nearest;
  }
}

}  // namespace pinball::simlab
