#include "pinball/learn/team.h"

#include <chrono>
#include <cstdlib>
#include <iostream>
#include <limits>
#include <stdexcept>

#ifdef PINBALL_HAVE_MPI
#include <mpi.h>
#endif

namespace pinball::learn {
namespace {

bool g_mpi_started = false;
int g_rank = 0;
int g_size = 1;
TeamCounters g_counters;

double now_s() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

#ifdef PINBALL_HAVE_MPI
int as_count(std::size_t n, const char* what) {
  if (n > static_cast<std::size_t>(std::numeric_limits<int>::max())) {
    team_abort(std::string("MPI: a batch's ") + what + " exceed 2^31 bytes; use smaller batches");
  }
  return static_cast<int>(n);
}

// Concatenates the blobs; their sizes go separately.
std::vector<std::uint8_t> concatenate(const std::vector<Blob>& blobs, std::vector<std::uint64_t>& sizes) {
  std::vector<std::uint8_t> bytes;
  for (const Blob& b : blobs) {
    sizes.push_back(b.size());
    bytes.insert(bytes.end(), b.begin(), b.end());
  }
  return bytes;
}
#endif

}  // namespace

TeamSession::TeamSession(int& argc, char**& argv) {
#ifdef PINBALL_HAVE_MPI
  if (!launched_by_mpirun()) return;
  int provided = 0;
  // Only the main thread calls MPI; the worker threads play balls.
  MPI_Init_thread(&argc, &argv, MPI_THREAD_FUNNELED, &provided);
  g_mpi_started = true;
  MPI_Comm_rank(MPI_COMM_WORLD, &g_rank);
  MPI_Comm_size(MPI_COMM_WORLD, &g_size);
#else
  (void)argc;
  (void)argv;
#endif
}

TeamSession::~TeamSession() {
#ifdef PINBALL_HAVE_MPI
  if (g_mpi_started) MPI_Finalize();
#endif
  g_mpi_started = false;
  g_rank = 0;
  g_size = 1;
}

bool team_has_mpi() {
#ifdef PINBALL_HAVE_MPI
  return true;
#else
  return false;
#endif
}

bool launched_by_mpirun() {
  // Open MPI's launcher sets these (and Slurm's srun with PMIx the second).
  return std::getenv("OMPI_COMM_WORLD_SIZE") != nullptr || std::getenv("PMIX_RANK") != nullptr;
}

int team_rank() { return g_rank; }
int team_size() { return g_size; }
TeamCounters team_counters() { return g_counters; }

std::vector<Blob> team_gather(std::size_t count, std::vector<Blob> mine) {
  if (g_size == 1) return mine;
#ifdef PINBALL_HAVE_MPI
  // Wait for every rank first, so the two costs are told apart: the wait is
  // load imbalance, the rest is communication.
  const double t0 = now_s();
  MPI_Barrier(MPI_COMM_WORLD);
  const double t1 = now_s();
  std::vector<int> items(static_cast<std::size_t>(g_size), 0);
  for (std::size_t i = 0; i < count; ++i) ++items[static_cast<std::size_t>(rank_of_item(i, g_size))];
  if (mine.size() != static_cast<std::size_t>(items[static_cast<std::size_t>(g_rank)])) {
    team_abort("team_gather: this rank has " + std::to_string(mine.size()) + " results, the deal gives it " +
               std::to_string(items[static_cast<std::size_t>(g_rank)]));
  }
  // 1. every item's size, rank by rank
  std::vector<std::uint64_t> my_sizes;
  const std::vector<std::uint8_t> my_bytes = concatenate(mine, my_sizes);
  std::vector<int> size_displ(static_cast<std::size_t>(g_size), 0);
  for (int r = 1; r < g_size; ++r) size_displ[static_cast<std::size_t>(r)] = size_displ[static_cast<std::size_t>(r - 1)] + items[static_cast<std::size_t>(r - 1)];
  std::vector<std::uint64_t> sizes(count);
  MPI_Allgatherv(my_sizes.data(), as_count(my_sizes.size(), "items"), MPI_UINT64_T, sizes.data(), items.data(),
                 size_displ.data(), MPI_UINT64_T, MPI_COMM_WORLD);
  // 2. the bytes, rank by rank
  std::vector<int> byte_counts(static_cast<std::size_t>(g_size), 0);
  std::vector<int> byte_displ(static_cast<std::size_t>(g_size), 0);
  std::size_t total = 0;
  for (int r = 0, k = 0; r < g_size; ++r) {
    std::size_t n = 0;
    for (int j = 0; j < items[static_cast<std::size_t>(r)]; ++j) n += sizes[static_cast<std::size_t>(k++)];
    byte_displ[static_cast<std::size_t>(r)] = as_count(total, "results");
    byte_counts[static_cast<std::size_t>(r)] = as_count(n, "results");
    total += n;
  }
  std::vector<std::uint8_t> bytes(total);
  MPI_Allgatherv(my_bytes.data(), as_count(my_bytes.size(), "results"), MPI_BYTE, bytes.data(), byte_counts.data(),
                 byte_displ.data(), MPI_BYTE, MPI_COMM_WORLD);
  // 3. back into item order: rank r's k-th blob is its k-th item.
  std::vector<Blob> all(count);
  std::vector<std::size_t> next_of_rank(static_cast<std::size_t>(g_size), 0);
  std::vector<std::size_t> first_of_rank(static_cast<std::size_t>(g_size), 0);
  for (int r = 1; r < g_size; ++r) first_of_rank[static_cast<std::size_t>(r)] = first_of_rank[static_cast<std::size_t>(r - 1)] + static_cast<std::size_t>(items[static_cast<std::size_t>(r - 1)]);
  std::vector<std::size_t> offset(count + 1, 0);  // byte offset of the k-th received blob
  for (std::size_t k = 0; k < count; ++k) offset[k + 1] = offset[k] + sizes[k];
  for (std::size_t i = 0; i < count; ++i) {
    const auto r = static_cast<std::size_t>(rank_of_item(i, g_size));
    const std::size_t k = first_of_rank[r] + next_of_rank[r]++;
    all[i].assign(bytes.begin() + static_cast<std::ptrdiff_t>(offset[k]), bytes.begin() + static_cast<std::ptrdiff_t>(offset[k + 1]));
  }
  const double t2 = now_s();
  g_counters.wait_s += t1 - t0;
  g_counters.comm_s += t2 - t1;
  g_counters.bytes += total - my_bytes.size();
  ++g_counters.batches;
  return all;
#else
  (void)count;
  return mine;
#endif
}

std::vector<Blob> team_broadcast(std::vector<Blob> from_root) {
  if (g_size == 1) return from_root;
#ifdef PINBALL_HAVE_MPI
  std::vector<std::uint64_t> sizes;
  std::uint64_t count = from_root.size();
  MPI_Bcast(&count, 1, MPI_UINT64_T, 0, MPI_COMM_WORLD);
  std::vector<std::uint8_t> bytes;
  if (g_rank == 0) bytes = concatenate(from_root, sizes);
  sizes.resize(static_cast<std::size_t>(count));
  MPI_Bcast(sizes.data(), as_count(sizes.size(), "items"), MPI_UINT64_T, 0, MPI_COMM_WORLD);
  std::uint64_t total = bytes.size();
  MPI_Bcast(&total, 1, MPI_UINT64_T, 0, MPI_COMM_WORLD);
  bytes.resize(static_cast<std::size_t>(total));
  MPI_Bcast(bytes.data(), as_count(bytes.size(), "results"), MPI_BYTE, 0, MPI_COMM_WORLD);
  std::vector<Blob> all(static_cast<std::size_t>(count));
  std::size_t at = 0;
  for (std::size_t k = 0; k < all.size(); ++k) {
    all[k].assign(bytes.begin() + static_cast<std::ptrdiff_t>(at), bytes.begin() + static_cast<std::ptrdiff_t>(at + sizes[k]));
    at += sizes[k];
  }
  return all;
#else
  return from_root;
#endif
}

void team_abort(const std::string& message) {
  std::cerr << "pinball";
  if (g_size > 1) std::cerr << " (rank " << g_rank << " of " << g_size << ")";
  std::cerr << ": " << message << std::endl;
#ifdef PINBALL_HAVE_MPI
  if (g_mpi_started) MPI_Abort(MPI_COMM_WORLD, 1);
#endif
  std::exit(1);
}

}  // namespace pinball::learn
