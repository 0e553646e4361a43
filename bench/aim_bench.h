#pragma once
// `pinball bench aim`: how exactly a shot's direction can be foretold from a
// ball state known only to a given precision.
//
// Where a shot goes decides whether the ball later drains down the outlane
// (bench/outlane_routes.py's shot table: 0.07 to 0.21 of the shots of one bat,
// by 10° of direction). A controller aims by predicting the shot from its
// estimate of the ball. The ceiling player (true state, learn::LookaheadPlayer)
// plays balls in the belief's model; at each of its fires the shot is replayed
// in the belief from the exact state before the fire, and from copies whose
// ball position and velocity carry Gaussian noise. The report gives how far
// the copies' directions fall from the exact one, and how many made no shot.
// A shot's direction is the ball's direction of travel where it first rises
// through `exit_height_m` above the highest pivot, within `shot_time_s`.

#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "pinball/firmware/flipper_actuation.h"
#include "pinball/learn/lookahead_player.h"
#include "pinball/sim/game_state.h"
#include "pinball/sim/thesis_stepper.h"
#include "pinball/table/board.h"

namespace pinball::bench {

/// Gaussian noise on an estimate, per coordinate.
struct StateNoise {
  double position_m = 0.0;    ///< standard deviation of x and y (m)
  double velocity_mps = 0.0;  ///< standard deviation of vx and vy (m/s)
};

/// What to measure.
struct AimBenchOptions {
  int balls = 20;                 ///< ceiling balls whose fires are replayed
  std::uint64_t seed = 1;         ///< ball i plays ball_seed(seed, i); the noise draws follow from it
  int copies = 10;                ///< noisy copies per fire
  double max_ball_time_s = 60.0;  ///< a ceiling ball alive after this is cut
  double actuation_delay_s = firmware::kDefaultActuationDelay_s;  ///< command to bat motion, ceiling and replays
  double exit_height_m = 0.10;    ///< a shot's direction is read this far above the highest pivot
  double shot_time_s = 0.6;       ///< a replay with no shot by then counts as none
  learn::LookaheadConfig planner; ///< the ceiling player's planner
  /// The estimates' noise levels: far below a camera's, about a good
  /// tracker's, and a poor one's.
  std::vector<StateNoise> noise = {{0.3e-3, 0.005}, {1e-3, 0.02}, {3e-3, 0.1}};
};

/// How the copies at one noise level missed.
struct AimNoiseResult {
  StateNoise noise;
  int copies = 0;                ///< copies replayed (shots x options.copies)
  int no_shot = 0;               ///< copies that made no shot (lost, or never rose through the line in time)
  double median_error_deg = 0.0; ///< |direction - exact| over the copies that shot (nearest rank)
  double p90_error_deg = 0.0;
  double within_5_deg = 0.0;     ///< share of all copies within 5° of the exact shot (a copy with no shot is not)
  double within_10_deg = 0.0;
};

struct AimReport {
  AimBenchOptions options;
  int fires = 0;  ///< the ceiling player's fires
  int shots = 0;  ///< fires whose exact replay made a shot: the ones the copies are compared with
  /// The baseline, knowing only which bat fires: each exact shot against the
  /// median direction of its bat's exact shots.
  double bat_only_median_error_deg = 0.0;
  double bat_only_within_10_deg = 0.0;
  std::vector<AimNoiseResult> results;  ///< one per options.noise
  double wall_s = 0.0;
};

/// The direction (deg, atan2 of the velocity) of the shot from `state`:
/// `flipper` commanded on now for `hold_s`, every other off, through a fresh
/// actuation delay line, stepped on `stepper` until the ball, having touched
/// a flipper, rises through y = `exit_y_m`. None if the ball is lost first or
/// `shot_time_s` passes.
std::optional<double> shot_direction_deg(const sim::ThesisStepper& stepper, sim::GameState state, int flipper,
                                         double hold_s, double actuation_delay_s, double exit_y_m,
                                         double shot_time_s);

/// Runs the bench on `belief` (its model world, thesis stepper). Throws
/// std::invalid_argument for balls or copies < 1, a negative or non-finite
/// noise, an exit height or shot time <= 0.
AimReport run_aim_bench(const table::Board& belief, const AimBenchOptions& options,
                        const std::function<void(const std::string&)>& progress = {});

nlohmann::json to_json(const AimReport& report);
std::string to_text(const AimReport& report);

}  // namespace pinball::bench
