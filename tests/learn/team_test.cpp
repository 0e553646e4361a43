// The team of processes (src/learn/team.cpp) seen from one process: the deal
// of items to ranks, and a team of one that never touches MPI.

#include "pinball/learn/team.h"

#include <gtest/gtest.h>

#include <set>

namespace pinball::learn {
namespace {

TEST(Team, DealsSmallChunksRoundRobin) {
  // 3 ranks: items 0-3 to rank 0, 4-7 to rank 1, 8-11 to rank 2, 12-15 to rank 0 ...
  EXPECT_EQ(rank_of_item(0, 3), 0);
  EXPECT_EQ(rank_of_item(3, 3), 0);
  EXPECT_EQ(rank_of_item(4, 3), 1);
  EXPECT_EQ(rank_of_item(11, 3), 2);
  EXPECT_EQ(rank_of_item(12, 3), 0);
  // Every rank gets a share within one chunk of the others'.
  for (int ranks : {2, 3, 7}) {
    std::vector<int> share(static_cast<std::size_t>(ranks), 0);
    for (std::size_t i = 0; i < 1000; ++i) ++share[static_cast<std::size_t>(rank_of_item(i, ranks))];
    const auto [lo, hi] = std::minmax_element(share.begin(), share.end());
    EXPECT_LE(*hi - *lo, static_cast<int>(kBallsPerChunk)) << ranks << " ranks";
  }
}

TEST(Team, AProcessNotStartedByMpirunIsATeamOfOne) {
  ASSERT_FALSE(launched_by_mpirun()) << "run this test without mpirun";
  EXPECT_EQ(team_size(), 1);
  EXPECT_EQ(team_rank(), 0);
  EXPECT_TRUE(team_root());
  const std::vector<Blob> mine = {Blob{1}, Blob{2, 3}, Blob{}};
  EXPECT_EQ(team_gather(3, mine), mine);
  EXPECT_EQ(team_broadcast(mine), mine);
  EXPECT_EQ(team_counters().batches, 0u);
}

}  // namespace
}  // namespace pinball::learn
