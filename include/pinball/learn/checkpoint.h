#pragma once
// A run's checkpoint: every batch of results the run has gathered, appended
// to a file as the run goes. A run cut short (a cluster's time limit, a
// cancelled job, a crash) is started again with the same command and
// `--resume`: it replays its search from the seed, taking the batches it
// already played from the file instead of playing them again, and ends with
// exactly the result of an uninterrupted run. Rank 0 alone reads and writes
// the file; the other ranks receive its batches (team_broadcast).
//
// File: a text header ("pinball checkpoint 1", then the run's fingerprint),
// then one record per batch: "PBCK", the result count, each result's size
// and bytes, and an FNV-1a hash of the record. A record cut off by a crash
// fails its hash and is dropped (the file is cut back to the last whole one).

#include <cstdint>
#include <string>
#include <vector>

#include "pinball/learn/blob.h"

namespace pinball::learn {

/// How a run uses its checkpoint.
struct CheckpointOptions {
  std::string path;         ///< the file; empty: no checkpoint
  bool resume = false;      ///< continue the file (it must exist and match) instead of starting one
  std::string fingerprint;  ///< what makes two runs the same run (command, seed, board bytes)
};

/// What the checkpoint did in this run.
struct CheckpointStatus {
  bool open = false;
  std::uint64_t batches_in_file = 0;  ///< whole batches found when the run started (resume)
  std::uint64_t replayed = 0;         ///< batches taken from the file
  std::uint64_t replayed_items = 0;   ///< what those batches held (balls): taken in no time, no part of a rate
  std::uint64_t recorded = 0;         ///< batches appended by this run
  std::uint64_t dropped_bytes = 0;    ///< a cut-off last record removed on resume
};

/// Opens the run's checkpoint (on every rank; a collective under MPI).
/// Throws std::runtime_error naming the file and what is wrong: a new
/// checkpoint over an existing file (pass --resume or remove it), --resume
/// without a file, a file of another run (its fingerprint), a damaged header.
void open_checkpoint(const CheckpointOptions& options);
/// Closes it (the file stays, whole).
void close_checkpoint();
/// The counts so far.
CheckpointStatus checkpoint_status();

/// The next batch from the file, when the file has it (collective): true and
/// `out` filled; false when this batch is to be played. Throws when the
/// file's batch has another size than `count` (the run is not the one that
/// wrote it).
bool checkpoint_replay(std::size_t count, std::vector<Blob>& out);
/// Appends a batch just played (rank 0 writes and flushes it; others do nothing).
void checkpoint_record(const std::vector<Blob>& batch);

}  // namespace pinball::learn
