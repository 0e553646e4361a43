#include "pinball/core/single_writer_counter.h"

#include <gtest/gtest.h>

#include <atomic>
#include <thread>

namespace pinball {
namespace {

TEST(SingleWriterCounter, AReaderOnAnotherThreadSeesItGrowToTheTotal) {
  SingleWriterCounter counter;
  constexpr std::uint64_t kCount = 200'000;
  std::atomic<bool> done{false};
  std::uint64_t last_seen = 0;
  bool monotonic = true;
  std::thread reader([&] {
    while (!done.load(std::memory_order_acquire)) {
      const std::uint64_t v = counter.load();
      monotonic = monotonic && v >= last_seen;
      last_seen = v;
    }
  });
  for (std::uint64_t i = 0; i < kCount; ++i) counter.add();
  counter.add(5);
  done.store(true, std::memory_order_release);
  reader.join();
  EXPECT_TRUE(monotonic);
  EXPECT_EQ(counter.load(), kCount + 5);
}

}  // namespace
}  // namespace pinball
