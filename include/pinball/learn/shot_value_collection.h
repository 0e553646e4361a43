#pragma once
// Learns what shots are worth (learn/shot_values.h) from the looking-ahead
// player on the true state in the belief's own model: at each of its
// decisions, every plan whose branch shot the ball adds that shot's direction,
// speed and the value of the branch after it (points until the next approach,
// less the drain penalty if the ball was lost). The player cheats, as the
// imitation teacher does; the table is a property of the belief's table, not
// of any controller (the branch after a shot ends at the next approach).

#include <cstdint>
#include <functional>
#include <string>

#include "pinball/firmware/flipper_actuation.h"
#include "pinball/learn/lookahead_player.h"
#include "pinball/learn/shot_values.h"
#include "pinball/table/board.h"

namespace pinball::learn {

/// How the shots are gathered.
struct ShotValueCollectionConfig {
  LookaheadConfig player = [] {
    LookaheadConfig c;
    c.horizon_s = 5.0;  // longer than a shot's usual flight to the next approach (2 to 4 s)
    return c;
  }();
  double actuation_delay_s = firmware::kDefaultActuationDelay_s;
  double max_ball_time_s = 60.0;
  double pull = -1.0;  ///< launcher pull; < 0: the board's
};

/// Plays `balls` balls (ball_seed(seed, i)) in the model of `belief` across
/// the job (distributed_map) and returns the smoothed table. `progress` gets
/// a line now and then. Throws std::invalid_argument for balls < 1.
ShotValueTable collect_shot_values(const table::Board& belief, const ShotValueCollectionConfig& config, int balls,
                                   std::uint64_t seed, int threads,
                                   const std::function<void(const std::string&)>& progress = {});

}  // namespace pinball::learn
