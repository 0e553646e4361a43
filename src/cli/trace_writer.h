#pragma once
// `pinball sim --trace FILE.csv`: one row per step, t,x,y,vx,vy,event, with
// every double printed round-trip exact so that equal runs give equal files.

#include <cstdio>
#include <string>

#include "pinball/core/staged_file.h"
#include "pinball/table/board.h"
#include "pinball/sim/game_state.h"
#include "pinball/sim/thesis_stepper.h"

namespace pinball::cli {

/// Names what happened in a step, '|'-separated ("hit:wall@12|sensor:lane"),
/// or an empty string for plain flight.
std::string describe_events(const table::Board& board, const sim::StepEvents& events);

/// A CSV trace file, written under a temporary name beside its path and put
/// in place by commit() (core/staged_file.h); a pipe or a device is written
/// as the run goes.
class TraceWriter {
 public:
  /// Creates the file and writes the header. Throws std::runtime_error naming the path.
  explicit TraceWriter(const std::string& path);
  ~TraceWriter();
  TraceWriter(const TraceWriter&) = delete;
  TraceWriter& operator=(const TraceWriter&) = delete;

  /// Appends one row for the state after a step.
  void write(const table::Board& board, const sim::GameState& state, const sim::StepEvents& events);

  /// True once a row could not be written (a full disk, /dev/full): the run may stop there.
  bool failed() const { return write_errno_ != 0; }

  /// Flushes and closes; throws std::runtime_error naming the path and the
  /// reason if the data could not be written.
  void finish();
  /// Puts the finished file in place (throws naming it when it cannot).
  void commit() { staged_.commit(); }

 private:
  StagedFile staged_;
  std::string path_;
  std::FILE* file_ = nullptr;
  int write_errno_ = 0;  // the first failed write's errno
};

}  // namespace pinball::cli
