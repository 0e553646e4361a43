#pragma once
// The processes a run's balls are played on: one, or the ranks of an MPI job
// started by `mpirun -n N pinball ...` (Open MPI). Every rank runs the same
// command; the balls of each batch are dealt to the ranks in small chunks,
// played on each rank's threads, and every rank receives every result in
// ball order, so each continues with exactly the numbers a single process
// would have had (results depend on the seed only). Rank 0 alone prints and
// writes files.
//
// MPI is process-wide by nature; so is this module: one TeamSession in main.

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "pinball/learn/blob.h"

namespace pinball::learn {

/// Starts MPI when this process was launched by mpirun (and the build has
/// MPI), and ends it on destruction. Without mpirun it does nothing: a plain
/// run is a team of one and never touches MPI.
class TeamSession {
 public:
  TeamSession(int& argc, char**& argv);
  ~TeamSession();
  TeamSession(const TeamSession&) = delete;
  TeamSession& operator=(const TeamSession&) = delete;
};

/// True when the build has MPI (Open MPI found at configure time).
bool team_has_mpi();
/// True when this process was started by mpirun (its environment says so).
bool launched_by_mpirun();
/// This process's rank, 0..team_size()-1 (0 without MPI).
int team_rank();
/// The job's ranks (1 without MPI).
int team_size();
/// True on the rank that prints and writes files.
inline bool team_root() { return team_rank() == 0; }

/// Balls per chunk when a batch is dealt to the ranks: small, because a
/// ball's length varies a hundredfold, and dealt round robin.
inline constexpr std::size_t kBallsPerChunk = 4;
/// The rank that plays item i of a batch on `ranks` ranks.
inline int rank_of_item(std::size_t i, int ranks) {
  return static_cast<int>((i / kBallsPerChunk) % static_cast<std::size_t>(ranks));
}

/// What the collectives cost this process (wall time).
struct TeamCounters {
  double wait_s = 0.0;          ///< waiting for the slowest rank (load imbalance) at each batch's end
  double comm_s = 0.0;          ///< moving the results once every rank was there
  std::uint64_t bytes = 0;      ///< result bytes received from other ranks
  std::uint64_t batches = 0;    ///< batches gathered across ranks
};
TeamCounters team_counters();

/// Every rank's results of one batch of `count` items, in item order, on
/// every rank. `mine` are this rank's results, for its items in increasing
/// order (those with rank_of_item(i) == team_rank()). Blocks until every
/// rank has called it for the same batch.
std::vector<Blob> team_gather(std::size_t count, std::vector<Blob> mine);

/// Rank 0's blobs, on every rank (a checkpoint's batch being replayed).
std::vector<Blob> team_broadcast(std::vector<Blob> from_root);

/// Ends every rank of the job with `message` on stderr and exit status 1: a
/// rank that cannot go on must not leave the others waiting in a collective.
/// Without MPI it prints and exits.
[[noreturn]] void team_abort(const std::string& message);

}  // namespace pinball::learn
