#pragma once
// The launcher controller (thesis 5.1): try a set of pull values, launch each
// several times without flipping, and keep the pull that most often brings the
// ball to a hittable state (a projection onto the 'V' of the flippers).

#include <cstdint>
#include <vector>

#include "pinball/sim/world.h"
#include "pinball/table/board.h"
#include "pinball/track/camera_model.h"

namespace pinball::learn {

/// Settings of the search.
struct LauncherSearchConfig {
  int pulls = 20;                ///< pull values i/pulls, i = 1..pulls (the thesis: 20)
  int launches_per_pull = 10;    ///< launches per value (the thesis: 10)
  double time_limit_s = 20.0;    ///< a launch not hittable after this counts as a failure
  std::uint64_t seed = 1;        ///< launch noise and camera seed
  track::CameraModelConfig camera;  ///< the camera the tracker sees through
};

/// Outcome of the search.
struct LauncherSearchResult {
  double best_pull = 1.0;         ///< the pull that most often reached a hittable state (ties: the first)
  int best_successes = 0;         ///< its successes out of launches_per_pull
  std::vector<double> pull;       ///< every value tried
  std::vector<int> successes;     ///< successes per value
};

/// Runs the search with the tracker believing `board`, in forks of `world`
/// (null: the model of `board` on the thesis stepper at the board's time step).
LauncherSearchResult search_launcher(const table::Board& board, const LauncherSearchConfig& config = {},
                                     const sim::World* world = nullptr);

}  // namespace pinball::learn
