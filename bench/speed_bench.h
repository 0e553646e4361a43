#pragma once
// `pinball bench speed`: thesis-stepper steps per second with the grid and
// with the linear scan, on the board and on a copy crowded with ten times its
// obstacles out of the ball's reach, all measured in one run.

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "pinball/sim/board.h"

namespace pinball::bench {

/// What to measure.
struct SpeedBenchOptions {
  std::uint64_t steps = 2'000'000;  ///< steps per timed run
  int repeats = 3;                  ///< timed runs per configuration; the median is reported
  std::uint64_t seed = 1;           ///< launch noise seed (same for every configuration)
  int crowd_factor = 10;            ///< the crowded board has this many extra copies of the obstacles
};

/// One configuration's figures.
struct SpeedRun {
  std::string name;                 ///< e.g. "grid", "linear", "grid_crowded"
  bool use_grid = true;             ///< broadphase on
  std::size_t obstacles = 0;        ///< obstacle shapes on the board
  std::uint64_t steps = 0;          ///< steps per timed run
  double median_s = 0.0;            ///< median wall time of one run (s)
  double steps_per_s = 0.0;         ///< steps / median_s
  double mean_candidates = 0.0;     ///< obstacles tested per step on average
  std::uint64_t final_hash = 0;     ///< state hash after the run (equal runs, equal hash)
};

/// The whole measurement.
struct SpeedReport {
  std::string board;                 ///< board file
  double dt_s = 0.0;                 ///< time step used
  std::vector<SpeedRun> runs;        ///< grid, linear, grid_crowded, linear_crowded
  double grid_speedup = 0.0;         ///< grid steps/s over linear steps/s (plain board)
  double crowded_cost_ratio = 0.0;   ///< grid time per step, crowded over plain (target <= 1.5)
  bool grid_matches_linear = false;  ///< the two broadphases produced bit-identical runs
};

/// A copy of `board` with `copies` extra copies of every obstacle placed side
/// by side to the right of the table, where the ball never goes.
sim::Board with_far_obstacles(const sim::Board& board, int copies);

/// Runs the measurement; `progress` (may be empty) receives one line per run.
SpeedReport run_speed_bench(const sim::Board& board, const SpeedBenchOptions& options,
                            const std::function<void(const std::string&)>& progress);

/// The report as one JSON object.
nlohmann::json to_json(const SpeedReport& report);

}  // namespace pinball::bench
