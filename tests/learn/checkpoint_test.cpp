// The run's checkpoint (src/learn/checkpoint.cpp): batches come back as they
// went in, a cut-off last record is dropped, another run's file is refused,
// and a search resumed from a cut checkpoint ends exactly as an uninterrupted one.

#include "pinball/learn/checkpoint.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "common/temp_path.h"
#include "pinball/learn/cross_entropy.h"
#include "pinball/learn/parallel_runner.h"
#include "toy_objective.h"

namespace pinball::learn {
namespace {

struct Closer {
  ~Closer() { close_checkpoint(); }
};

std::vector<Blob> batch(std::uint8_t tag, std::size_t n) {
  std::vector<Blob> b;
  for (std::size_t i = 0; i < n; ++i) b.push_back(Blob(i % 3, static_cast<std::uint8_t>(tag + i)));
  return b;
}

TEST(Checkpoint, BatchesComeBackInOrderAndThenTheRunGoesOn) {
  const std::string path = testing::temp_path("checkpoint", "order.ckpt");
  std::filesystem::remove(path);
  const Closer closer;
  open_checkpoint({path, false, "run A"});
  checkpoint_record(batch(1, 5));
  checkpoint_record(batch(7, 2));
  close_checkpoint();

  open_checkpoint({path, true, "run A"});
  EXPECT_EQ(checkpoint_status().batches_in_file, 2u);
  std::vector<Blob> got;
  ASSERT_TRUE(checkpoint_replay(5, got));
  EXPECT_EQ(got, batch(1, 5));
  ASSERT_TRUE(checkpoint_replay(2, got));
  EXPECT_EQ(got, batch(7, 2));
  EXPECT_FALSE(checkpoint_replay(4, got)) << "the file is used up: the run plays on";
  checkpoint_record(batch(9, 4));
  close_checkpoint();

  open_checkpoint({path, true, "run A"});
  EXPECT_EQ(checkpoint_status().batches_in_file, 3u);
}

TEST(Checkpoint, ACutOffLastRecordIsDroppedAndTheFileCutBack) {
  const std::string path = testing::temp_path("checkpoint", "cut.ckpt");
  std::filesystem::remove(path);
  const Closer closer;
  open_checkpoint({path, false, "run B"});
  checkpoint_record(batch(1, 3));
  close_checkpoint();
  const auto whole = std::filesystem::file_size(path);
  open_checkpoint({path, true, "run B"});
  checkpoint_record(batch(2, 3));
  close_checkpoint();
  std::filesystem::resize_file(path, std::filesystem::file_size(path) - 5);  // a crash mid-write
  open_checkpoint({path, true, "run B"});
  EXPECT_EQ(checkpoint_status().batches_in_file, 1u);
  EXPECT_GT(checkpoint_status().dropped_bytes, 0u);
  EXPECT_EQ(std::filesystem::file_size(path), whole);
}

// The error open_checkpoint gives for `options` ("" when it opened).
std::string refusal(const CheckpointOptions& options) {
  try {
    open_checkpoint(options);
  } catch (const std::runtime_error& e) {
    return e.what();
  }
  close_checkpoint();
  return "";
}

TEST(Checkpoint, RefusesWhatWouldLoseOrMixRuns) {
  const std::string path = testing::temp_path("checkpoint", "refuse.ckpt");
  std::filesystem::remove(path);
  const Closer closer;
  const std::string missing = refusal({path, true, "run C"});
  EXPECT_NE(missing.find("no such file"), std::string::npos) << "resumed a file that does not exist: " << missing;
  open_checkpoint({path, false, "run C"});
  checkpoint_record(batch(3, 2));
  close_checkpoint();
  const std::string over = refusal({path, false, "run C"});
  EXPECT_NE(over.find("already exists"), std::string::npos) << "started a new checkpoint over an old one: " << over;
  const std::string other = refusal({path, true, "run D"});
  EXPECT_NE(other.find("another run"), std::string::npos) << "resumed another run's file: " << other;
  open_checkpoint({path, true, "run C"});
  std::vector<Blob> got;
  EXPECT_THROW(checkpoint_replay(3, got), std::runtime_error) << "a batch of another size is another run";
  close_checkpoint();
  { std::ofstream(path) << "not a checkpoint\n"; }
  EXPECT_THROW(open_checkpoint({path, true, "run C"}), std::runtime_error);
  // Format 1 wrote a demonstration's shots with the struct's padding: said as such.
  { std::ofstream(path) << "pinball checkpoint 1\nrun C\n"; }
  const std::string old = refusal({path, true, "run C"});
  EXPECT_NE(old.find("written by an older build (format 1, this one writes 2)"), std::string::npos) << old;
}

SearchResult cem(const std::string& checkpoint, bool resume) {
  const testing_support::ToyObjective toy(2, 5.0);
  SearchConfig c;
  c.budget_balls = 400;
  c.seed = 17;
  c.threads = 2;
  const Closer closer;
  if (!checkpoint.empty()) open_checkpoint({checkpoint, resume, "cem toy"});
  return run_cross_entropy(toy, c, CrossEntropyConfig{});
}

TEST(Checkpoint, AResumedSearchEndsExactlyAsAnUninterruptedOne) {
  const SearchResult whole = cem("", false);
  const std::string path = testing::temp_path("checkpoint", "cem.ckpt");
  std::filesystem::remove(path);
  const SearchResult recorded = cem(path, false);
  EXPECT_EQ(recorded.best_mean, whole.best_mean);
  // Cut the file after its first few batches, as a time limit would, then resume.
  {
    const Closer closer;
    open_checkpoint({path, true, "cem toy"});
    ASSERT_GT(checkpoint_status().batches_in_file, 4u);
  }
  const auto size = std::filesystem::file_size(path);
  std::filesystem::resize_file(path, size / 3);  // mid-record, somewhere after a few whole batches
  const SearchResult resumed = cem(path, true);
  {
    const Closer closer;
    open_checkpoint({path, true, "cem toy"});
    EXPECT_EQ(checkpoint_status().dropped_bytes, 0u) << "the resumed run left the file whole";
  }
  EXPECT_EQ(resumed.best_mean, whole.best_mean);
  EXPECT_EQ(resumed.best_balls, whole.best_balls);
  EXPECT_EQ(resumed.balls_used, whole.balls_used);
  EXPECT_EQ(resumed.generations, whole.generations);
  ASSERT_EQ(resumed.curve.size(), whole.curve.size());
  for (std::size_t g = 0; g < whole.curve.size(); ++g) EXPECT_EQ(resumed.curve[g].best_so_far, whole.curve[g].best_so_far);
  for (int p = 0; p < whole.best.action_function.partitions(); ++p) {
    EXPECT_EQ(resumed.best.action_function.minicontroller(p).a, whole.best.action_function.minicontroller(p).a);
  }
}

}  // namespace
}  // namespace pinball::learn
