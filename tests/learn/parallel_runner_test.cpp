#include "pinball/learn/parallel_runner.h"

#include <gtest/gtest.h>

#include <stdexcept>
#include <vector>

#include "pinball/table/board_loader.h"

namespace pinball::learn {
namespace {

TEST(ParallelRunner, ResultsDoNotDependOnTheThreadCount) {
  const table::Board board = table::load_board(PINBALL_SOURCE_DIR "/boards/mit1993.board");
  const PinballEvaluator ev(board, EvaluatorConfig{});
  std::vector<control::ControllerSpec> specs(3, ev.prototype());
  Rng rng(9);
  for (auto& s : specs) s.action_function.randomise(rng);
  std::vector<BallTask> tasks;
  for (int i = 0; i < 12; ++i) tasks.push_back({&specs[static_cast<std::size_t>(i % 3)], ball_seed(4, static_cast<std::uint64_t>(i))});
  const auto one = play_balls(ev, tasks, 1);
  const auto three = play_balls(ev, tasks, 3);
  ASSERT_EQ(one.size(), three.size());
  for (std::size_t i = 0; i < one.size(); ++i) {
    EXPECT_EQ(one[i].score, three[i].score);
    EXPECT_EQ(one[i].duration_s, three[i].duration_s);
    EXPECT_EQ(one[i].flips, three[i].flips);
  }
}

struct Throwing final : BallObjective {
  BallOutcome play(const control::ControllerSpec&, std::uint64_t seed) const override {
    if (seed == 5) throw std::runtime_error("boom");
    return {};
  }
  control::ControllerSpec prototype() const override { return {}; }
};

TEST(ParallelRunner, RethrowsATaskError) {
  const Throwing t;
  control::ControllerSpec s;
  std::vector<BallTask> tasks;
  for (std::uint64_t i = 0; i < 10; ++i) tasks.push_back({&s, i});
  EXPECT_THROW(play_balls(t, tasks, 2), std::runtime_error);
}

// A long map in batches: every item once, in order, a batch at a time, and
// the same results as one distributed_map.
TEST(ParallelRunner, BatchesTakeEveryItemInOrderAndMatchOneMap) {
  auto task = [](std::size_t i) {
    return Blob{static_cast<std::uint8_t>(i % 251), static_cast<std::uint8_t>(i / 251)};
  };
  std::vector<std::size_t> firsts, sizes;
  std::vector<Blob> all;
  distributed_batches(1050, 500, 2, task, [&](std::size_t first, std::vector<Blob>& results) {
    firsts.push_back(first);
    sizes.push_back(results.size());
    all.insert(all.end(), results.begin(), results.end());
  });
  EXPECT_EQ(firsts, (std::vector<std::size_t>{0, 500, 1000}));
  EXPECT_EQ(sizes, (std::vector<std::size_t>{500, 500, 50}));
  EXPECT_EQ(all, distributed_map(1050, 2, task));
  EXPECT_THROW(distributed_batches(1, 0, 1, task, [](std::size_t, std::vector<Blob>&) {}), std::invalid_argument);
}

}  // namespace
}  // namespace pinball::learn
