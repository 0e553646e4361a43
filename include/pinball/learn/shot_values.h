#pragma once
// What a flipper shot is worth, by where it goes: the mean value of the
// lookahead planner's branches after a shot (points until the next approach,
// less the drain penalty if the ball was lost), binned by the bat that shot,
// the shot's direction and its speed where the ball rises through a line just
// above the pivots.
//
// Why: a plan's own branch, played seconds past the shot in the belief,
// scores the chaos of the upper field, which a camera-grade estimate cannot
// foretell (docs/results.md, `bench aim`); a shot's direction it can foretell
// to a few degrees. With a table, a plan is worth its points up to the shot
// plus the table's mean for that shot: the expectation over the chaos,
// learned from many branches, rather than one draw of it.

#include <optional>
#include <string>
#include <vector>

#include "pinball/sim/game_state.h"
#include "pinball/table/board.h"

namespace pinball::learn {

/// Branch values after shots, per bat x direction bin x speed bin.
struct ShotValueTable {
  int flippers = 2;
  double direction_bin_deg = 2.0;  ///< bins cover [0, 180) degrees
  double speed_bin_mps = 0.25;     ///< bins cover [0, speed_bins * speed_bin_mps); faster shots fall in the last
  int speed_bins = 24;
  double exit_height_m = 0.10;     ///< a shot is read where the ball rises this far above the highest pivot
  /// Smoothing of the lookup (Gaussian kernel widths) and the weight below
  /// which a lookup has no value.
  double kernel_direction_deg = 4.0;
  double kernel_speed_mps = 0.5;
  double min_weight = 20.0;
  std::vector<double> sum;    ///< per bin: sum of values
  std::vector<double> count;  ///< per bin: shots
  std::vector<double> smoothed;  ///< per bin: the kernel mean (NaN: too few shots near); from smooth()
};

/// A flipper shot: the bat that shot, the direction of travel (deg, atan2 of
/// the velocity) and the speed where the ball rose through the shot line.
struct Shot {
  int flipper = -1;
  double direction_deg = 0.0;
  double speed_mps = 0.0;
};

/// The shot line: `exit_height_m` above the highest pivot (m, board y).
double shot_line_y_m(const table::Board& board, double exit_height_m);

/// Reads a shot step by step: call after every step; `touched` (start at -1)
/// keeps the bat the ball last touched. Returns the shot at the first step
/// where the ball, having touched a bat, is at or above `line_y_m` and rising.
std::optional<Shot> read_shot(const sim::GameState& state, double line_y_m, int& touched);

/// An empty table sized for its settings.
ShotValueTable make_shot_value_table(int flippers);
/// Adds one shot's branch value. Shots outside [0, 180) degrees or of a
/// flipper the table lacks are ignored.
void add_shot(ShotValueTable& table, int flipper, double direction_deg, double speed_mps, double value);
/// Fills `smoothed` from the sums (after the last add_shot).
void smooth(ShotValueTable& table);
/// The smoothed value of a shot; none where too few shots lie near it.
std::optional<double> shot_value(const ShotValueTable& table, int flipper, double direction_deg, double speed_mps);
/// Shots in the table.
double shots_in(const ShotValueTable& table);

/// Writes / reads the table as JSON. read throws std::runtime_error naming the
/// file for a missing file, another format or sizes that do not agree.
void write_shot_value_table(const ShotValueTable& table, const std::string& path);
ShotValueTable read_shot_value_table(const std::string& path);

}  // namespace pinball::learn
