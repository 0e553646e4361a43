#pragma once
// `pinball bench speed`: thesis-stepper steps per second with the grid and
// with the linear scan, on the board and on a copy crowded with ten times its
// obstacles out of the ball's reach, all measured in one run; and the event
// stepper's events per second and simulated seconds per wall second on the
// same two boards; and the MuJoCo twin's simulated seconds per wall second on
// the board (when this build has it), all playing the spastic oracle.

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "pinball/table/board.h"

namespace pinball::bench {

/// What to measure.
struct SpeedBenchOptions {
  std::uint64_t steps = 2'000'000;  ///< steps per timed run
  int repeats = 3;                  ///< timed runs per configuration; the median is reported
  std::uint64_t seed = 1;           ///< launch noise seed (same for every configuration)
  int crowd_factor = 10;            ///< the crowded board has this many extra copies of the obstacles
  std::uint64_t twin_steps = 200'000;  ///< twin steps per timed run (it is ~100x slower than the thesis stepper)
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

/// One world's figures (same play as the thesis runs: spastic oracle
/// policy; the event stepper's step horizon is the board's dt, the twin's
/// step its own).
struct EventSpeedRun {
  std::string name;                 ///< "event", "event_crowded" or "twin"
  std::size_t obstacles = 0;        ///< obstacle shapes on the board
  std::uint64_t steps = 0;          ///< step() calls per timed run
  std::uint64_t events = 0;         ///< events per timed run
  double simulated_s = 0.0;         ///< simulated time per timed run (s)
  double median_s = 0.0;            ///< median wall time of one run (s)
  double events_per_s = 0.0;        ///< events / median_s
  double steps_per_s = 0.0;         ///< steps / median_s
  double sim_s_per_wall_s = 0.0;    ///< simulated_s / median_s
};

/// The whole measurement.
struct SpeedReport {
  std::string board;                 ///< board file
  double dt_s = 0.0;                 ///< time step used
  std::vector<SpeedRun> runs;        ///< grid, linear, grid_crowded, linear_crowded
  double grid_speedup = 0.0;         ///< grid steps/s over linear steps/s (plain board)
  double crowded_cost_ratio = 0.0;   ///< grid time per step, crowded over plain (target <= 1.5)
  bool grid_matches_linear = false;  ///< the two broadphases produced bit-identical runs
  std::vector<EventSpeedRun> event_runs;  ///< event, event_crowded
  double event_crowded_cost_ratio = 0.0;  ///< event stepper wall time per simulated second, crowded over plain (target <= 1.5)
  double thesis_sim_s_per_wall_s = 0.0;   ///< the thesis stepper (grid): simulated seconds per wall second
  std::string twin_skipped;               ///< why the twin was not measured (empty when it was: event_runs' "twin")
};

/// A copy of `board` with `copies` extra copies of every obstacle placed side
/// by side to the right of the table, where the ball never goes.
table::Board with_far_obstacles(const table::Board& board, int copies);

/// Runs the measurement; `progress` (may be empty) receives one line per run.
SpeedReport run_speed_bench(const table::Board& board, const SpeedBenchOptions& options,
                            const std::function<void(const std::string&)>& progress);

/// The report as one JSON object.
nlohmann::json to_json(const SpeedReport& report);

}  // namespace pinball::bench
