#include "pinball/learn/launcher_search.h"

#include <gtest/gtest.h>

#include "pinball/table/board_loader.h"

namespace pinball::learn {
namespace {

TEST(LauncherSearch, FindsAPullThatReachesAHittableState) {
  const table::Board board = table::load_board(PINBALL_SOURCE_DIR "/boards/mit1993.board");
  LauncherSearchConfig c;
  c.pulls = 5;  // a quick version of the thesis's 20 x 10
  c.launches_per_pull = 3;
  const LauncherSearchResult r = search_launcher(board, c);
  ASSERT_EQ(r.pull.size(), 5u);
  EXPECT_DOUBLE_EQ(r.pull.back(), 1.0);
  EXPECT_GT(r.best_successes, 0);
  int best = 0;
  for (int s : r.successes) best = std::max(best, s);
  EXPECT_EQ(best, r.best_successes);
  const LauncherSearchResult again = search_launcher(board, c);
  EXPECT_EQ(again.successes, r.successes);  // deterministic by seed
}

}  // namespace
}  // namespace pinball::learn
