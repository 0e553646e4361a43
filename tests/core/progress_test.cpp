// The one progress line of every long run: percent, elapsed, ETA.

#include "pinball/core/progress.h"

#include <algorithm>
#include <sstream>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

namespace pinball {
namespace {

TEST(FormatDuration, ReadsLikeAPersonWouldSayIt) {
  EXPECT_EQ(format_duration(0.25), "250 ms");
  EXPECT_EQ(format_duration(12.7), "12 s");
  EXPECT_EQ(format_duration(185.0), "3 min 05 s");
  EXPECT_EQ(format_duration(7440.0), "2 h 04 min");
  EXPECT_EQ(format_duration(-1.0), "?");
}

TEST(FormatProgress, ShowsPercentElapsedAndTimeLeft) {
  EXPECT_EQ(format_progress("sim", 40, 100, "balls", 12.0, "mean score 8120"),
            "sim: 40/100 balls (40 %), 12 s elapsed, ETA 18 s; mean score 8120");
  // Nothing done yet: no estimate; finished: 100 % and no ETA.
  EXPECT_EQ(format_progress("learn", 0, 6000, "balls", 0.5), "learn: 0/6000 balls (0 %), 500 ms elapsed");
  EXPECT_EQ(format_progress("learn", 6000, 6000, "balls", 90.0), "learn: 6000/6000 balls (100 %), 1 min 30 s elapsed");
  // 99.9 % is not yet 100 %.
  EXPECT_NE(format_progress("x", 999, 1000, "", 1.0).find("(99 %)"), std::string::npos);
}

// A resumed run takes its first balls from a checkpoint in no time: they count
// as done, not in the rate (3000 from the file, 1000 played in 10 s: 20 s left).
TEST(FormatProgress, UnitsDoneInNoTimeAreNotInTheRate) {
  EXPECT_EQ(format_progress("cem", 4000, 6000, "balls", 10.0, "", 3000),
            "cem: 4000/6000 balls (66 %), 10 s elapsed, ETA 20 s");
  // Only those so far: no rate yet, so no estimate.
  EXPECT_EQ(format_progress("cem", 3000, 6000, "balls", 0.1, "", 3000), "cem: 3000/6000 balls (50 %), 100 ms elapsed");
}

TEST(Progress, AnEtaByKindTakesEachKindsOwnRate) {
  // 100 model balls done in 10 s, 10 twin balls done in 10 s: a twin ball costs ten.
  const KindProgress model{300, 100, 10.0}, twin{20, 10, 10.0};
  EXPECT_DOUBLE_EQ(eta_by_kind_s(std::vector<KindProgress>{model, twin}, 1.0), 200 * 0.1 + 10 * 1.0);
  // A kind none of which is done yet goes at the rate so far.
  const KindProgress sweep{50, 0, 0.0};
  EXPECT_DOUBLE_EQ(eta_by_kind_s(std::vector<KindProgress>{model, sweep}, 0.25), 200 * 0.1 + 50 * 0.25);
  EXPECT_EQ(format_progress("transfer", 110, 320, "balls", 20.0, "twin", 0.0, 30.0),
            "transfer: 110/320 balls (34 %), 20 s elapsed, ETA 30 s; twin");
}

TEST(ProgressMeter, ShowsAtMostOncePerIntervalAndAlwaysTheEnd) {
  std::ostringstream out;
  ProgressMeter meter(&out, "sim", 4, "balls", false, 1.0);
  meter.update_at(1, 0.1);
  meter.update_at(2, 0.5);  // too soon after the first
  meter.update_at(3, 1.2);
  meter.update_at(4, 1.3);  // the end is always shown
  meter.update_at(4, 5.0);  // and only once
  EXPECT_EQ(out.str(),
            "sim: 1/4 balls (25 %), 100 ms elapsed, ETA 300 ms\n"
            "sim: 3/4 balls (75 %), 1 s elapsed, ETA 400 ms\n"
            "sim: 4/4 balls (100 %), 1 s elapsed\n");
}

TEST(ProgressMeter, RewritesOneLineOnATerminal) {
  std::ostringstream out;
  ProgressMeter meter(&out, "bench", 2, "runs", true, 0.0);
  meter.update_at(1, 1.0);
  meter.update_at(2, 2.0);
  EXPECT_EQ(out.str(),
            "\rbench: 1/2 runs (50 %), 1 s elapsed, ETA 1 s\x1b[K"
            "\rbench: 2/2 runs (100 %), 2 s elapsed\x1b[K\n");
}

TEST(ProgressMeter, ANullStreamShowsNothing) {
  ProgressMeter meter(nullptr, "sim", 1, "balls");
  meter.update_at(1, 1.0);  // must not crash
  SUCCEED();
}

// Threads finishing together: every report at least the one before, the
// last one the total, and nothing lost from the count.
TEST(SharedProgress, ReportsInOrderFromManyThreads) {
  constexpr long kTotal = 4000;
  std::vector<long> reported;  // written under the count's own lock
  SharedProgress count(kTotal, 7, [&](long done, double elapsed_s) {
    EXPECT_GE(elapsed_s, 0.0);
    reported.push_back(done);
  });
  std::vector<std::thread> threads;
  for (int t = 0; t < 4; ++t) {
    threads.emplace_back([&] {
      for (long i = 0; i < kTotal / 4; ++i) count.one_done();
    });
  }
  for (std::thread& t : threads) t.join();
  EXPECT_EQ(count.done(), kTotal);
  ASSERT_FALSE(reported.empty());
  EXPECT_TRUE(std::is_sorted(reported.begin(), reported.end()));
  EXPECT_EQ(reported.back(), kTotal);
  EXPECT_EQ(reported.size(), static_cast<std::size_t>(kTotal / 7 + 1));  // every 7th, and the last
}

}  // namespace
}  // namespace pinball
