#pragma once
// The human benchmark's score file (`pinball play`, thesis 2.3): one CSV row
// per ball a person played, appended, and the per-player statistics of
// Table 2.1 ("Means for Human Subjects") with the project's 95 % interval.
//
// Columns: player,date,board,world,ball,score,duration_s,cut
//   player      the person's name (no comma, quote or newline)
//   date        when the ball ended, ISO 8601 UTC (2026-12-02T13:45:21Z)
//   board       the board file played
//   world       thesis, event or twin
//   ball        the ball's number within its session, from 1
//   score       points scored during the ball
//   duration_s  simulated seconds from its launch to its loss or cut
//   cut         1 when the ball was cut at the time limit, 0 when it was lost

#include <cstdint>
#include <string>
#include <vector>

#include "pinball/core/name_value.h"

namespace pinball::simlab {

/// The header line every play score file starts with.
inline constexpr const char* kPlayCsvHeader = "player,date,board,world,ball,score,duration_s,cut";

/// One ball a person played.
struct PlayRow {
  std::string player;      ///< the player's name
  std::string date;        ///< ISO 8601 UTC
  std::string board;       ///< board file
  std::string world;       ///< thesis | event | twin
  int ball = 0;            ///< ball number in its session, from 1
  double score = 0.0;      ///< points (≥ 0)
  double duration_s = 0.0; ///< simulated seconds (≥ 0)
  bool cut = false;        ///< cut at the time limit
};

/// Throws std::invalid_argument unless the row's text fields (player, board,
/// world) can stand in the file: not empty, no comma, quote or control
/// character. append_play_rows checks every row; a command checks its
/// first row before the game, so that nothing fails after it.
void check_play_row(const PlayRow& row);

/// Throws std::runtime_error naming `path` unless rows can be appended to it:
/// an existing file must be writable and be empty or start with the header;
/// a new one needs a writable folder. Writes nothing.
void check_play_csv_appendable(const std::string& path);

/// Appends `rows` (with the header first when the file is new or empty) under
/// an exclusive lock, so two players on one machine never interleave (thesis
/// 2.3's footnote). Throws std::runtime_error naming the file on failure.
void append_play_rows(const std::string& path, const std::vector<PlayRow>& rows);

/// Reads a whole score file. Throws std::runtime_error "file:line: what is
/// wrong" (missing file, bad header, wrong column count, a bad number, name
/// or flag) and returns nothing partial.
std::vector<PlayRow> read_play_csv(const std::string& path);

/// One line of Table 2.1.
struct PlayerStats {
  std::string player;         ///< the player, or "all" for the pooled line
  std::int64_t balls = 0;     ///< balls played
  double mean_score = 0.0;    ///< mean score per ball
  double ci95_half_width = 0.0;  ///< half-width of the mean's 95 % interval (Student's t; infinite for one ball)
  double max_score = 0.0;     ///< best ball

  /// The line as reports spell it (the keys of `pinball sim`'s report; an
  /// infinite interval is written as null).
  template <class Archive>
  void Serialize(Archive* a) {
    a->Visit(PINBALL_NVP(player));
    a->Visit(PINBALL_NVP(balls));
    a->Visit(make_name_value("mean_score_per_ball", &mean_score));
    a->Visit(make_name_value("score_ci95_half_width", &ci95_half_width));
    a->Visit(PINBALL_NVP(max_score));
  }
};

/// Per player (sorted by name), then all players pooled (last, named "all").
/// Empty for no rows.
std::vector<PlayerStats> play_stats(const std::vector<PlayRow>& rows);

}  // namespace pinball::simlab
