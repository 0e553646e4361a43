#pragma once
// Observation files: CSV with header t,x,y (s, m, board frame), optionally
// followed by left_contact,right_contact (0/1 flipper contact sensors), or
// `pinball sim --trace`'s t,x,y,vx,vy,event (the true state each step: its
// position is read, its velocity and events are not observations). A line
// starting with '#' is a comment, before the header or between rows.

#include <string>
#include <vector>

#include "pinball/table/board.h"
#include "pinball/track/observation.h"

namespace pinball::track {

/// One row of an observation file.
struct ObservationRow {
  Observation observation;    ///< t, x, y
  ContactSensors contacts;    ///< all false when the file has no contact columns
};

/// Reads a whole file. Throws std::runtime_error "file:line: what is wrong"
/// (bad header, missing or non-finite number, contact not 0/1, time going
/// backwards) and returns nothing partial.
std::vector<ObservationRow> read_observations_csv(const std::string& path);

/// The longest median time between observations a camera gives (s): 1 fps.
inline constexpr double kMostFramePeriod_s = 1.0;

/// Throws std::runtime_error "path: 40 of its 200 observations lie over 5 cm
/// off the ... playfield of B ..." when more than table::kMostOffPlayfield of
/// `rows` lie that far off `board` (a file in mm, or of another table), and
/// "path: its observations are 5 s apart ..." when their median spacing is
/// over kMostFramePeriod_s (times in ms or ns).
void check_observations_on_board(const std::vector<ObservationRow>& rows, const table::Board& board,
                                 const std::string& path);

}  // namespace pinball::track
