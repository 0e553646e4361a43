#include "pinball/bus/lcm_bus.h"

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <vector>
#include <thread>

#include "pinball/bus/channels.h"

namespace pinball::bus {
namespace {

template <class Pred>
bool eventually(Pred pred, double timeout_s = 5.0) {
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
  while (std::chrono::steady_clock::now() < end) {
    if (pred()) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  return pred();
}

struct Counter {
  std::atomic<int> n{0};
  std::atomic<std::int64_t> last_seq{-1};
  RawHandler handler = typed_handler<pinball_lcm::lcmt_pinball_projection>(
      [this](const pinball_lcm::lcmt_pinball_projection& m) {
        last_seq = m.seq;
        ++n;
      });
};

TEST(LcmBus, PublishesQueuedMessagesInOrder) {
  Counter c;
  LcmBus bus("memq://");
  subscribe_raw(bus.lcm(), kProjectionChannel, c.handler);
  bus.start();
  for (int i = 0; i < 100; ++i) {
    pinball_lcm::lcmt_pinball_projection m{};
    m.seq = i;
    ASSERT_TRUE(bus.try_publish(m));
  }
  EXPECT_TRUE(eventually([&] { return c.n.load() == 100; }));
  EXPECT_EQ(c.last_seq.load(), 99);
  bus.stop();
  EXPECT_EQ(bus.counters().published, 100u);
  EXPECT_EQ(bus.counters().overflows, 0u);
}

TEST(LcmBus, AFullRingDropsAndCountsInsteadOfBlocking) {
  LcmBus bus("memq://");  // not started: nothing drains
  pinball_lcm::lcmt_pinball_flipper_command m{};
  int accepted = 0;
  for (int i = 0; i < 300; ++i) accepted += bus.try_publish(m) ? 1 : 0;
  EXPECT_EQ(accepted, 256);
  EXPECT_EQ(bus.counters().overflows, 44u);
}

TEST(LcmBus, MalformedObservationsAreCountedAndIgnored) {
  LcmBus bus("memq://");
  ObservationRing inbox;
  bus.subscribe_observations(inbox);
  bus.start();
  // Garbage bytes, a truncated message, and a well-formed message with a NaN position.
  const std::uint8_t junk[5] = {1, 2, 3, 4, 5};
  bus.lcm().publish(kObservationChannel, junk, sizeof junk);
  pinball_lcm::lcmt_pinball_observation good{};
  good.utime = 1000;
  good.found = true;
  good.x_m = 0.1;
  good.y_m = 0.2;
  good.confidence = 1.0;
  std::vector<std::uint8_t> buf(static_cast<std::size_t>(good.getEncodedSize()));
  good.encode(buf.data(), 0, static_cast<int>(buf.size()));
  bus.lcm().publish(kObservationChannel, buf.data(), static_cast<unsigned>(buf.size() - 3));
  pinball_lcm::lcmt_pinball_observation nan = good;
  nan.x_m = std::nan("");
  bus.lcm().publish(kObservationChannel, &nan);
  bus.lcm().publish(kObservationChannel, &good);
  EXPECT_TRUE(eventually([&] { return bus.counters().malformed == 3 && bus.counters().received == 1; }));
  pinball_lcm::lcmt_pinball_observation got;
  ASSERT_TRUE(inbox.try_pop(got));
  EXPECT_EQ(got.utime, 1000);
  EXPECT_FALSE(inbox.try_pop(got));
  bus.stop();
}

TEST(LcmBus, BadUrlIsNamed) {
  try {
    LcmBus bus("nonsense://x");
    FAIL();
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("nonsense://x"), std::string::npos);
  }
}

}  // namespace
}  // namespace pinball::bus
