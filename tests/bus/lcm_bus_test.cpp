#include "pinball/bus/lcm_bus.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>
#include <thread>

#include "common/temp_path.h"
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

// Publishes `n` projections (seq 0..n-1), waiting while the ring is full.
void publish_projections(LcmBus& bus, int n) {
  for (int i = 0; i < n; ++i) {
    pinball_lcm::lcmt_pinball_projection m{};
    m.seq = i;
    while (!bus.try_publish(m)) std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
}


// A provider with no connection has no descriptor; liblcm's handle would select on -1, which
// glibc aborts (found with tcpq:// and no server): refused at start instead, and handled as an
// error, not a crash, if it happens later.
TEST(LcmBus, AProviderWithNoConnectionIsRefusedNotSelectedOn) {
  try {
    LcmBus bus("tcpq://127.0.0.1:1");  // nothing listens on port 1
    FAIL() << "a tcpq:// URL with no server was accepted";
  } catch (const std::runtime_error& e) {
    EXPECT_EQ(std::string(e.what()).rfind("lcm: cannot open 'tcpq://127.0.0.1:1': the provider has no connection", 0),
              0u)
        << e.what();
  }
  lcm_t* unconnected = lcm_create("tcpq://127.0.0.1:1");
  ASSERT_NE(unconnected, nullptr);
  EXPECT_EQ(handle_lcm_timeout(unconnected, 1), -1);
  lcm_destroy(unconnected);
}

TEST(LcmBus, FileUrlsThatWriteAreFoundAndOthersLeftToLiblcm) {
  const auto w = lcm_log_target("file:///tmp/game.lcmlog?mode=w");
  ASSERT_TRUE(w.has_value());
  EXPECT_EQ(w->path, "/tmp/game.lcmlog");
  EXPECT_FALSE(w->append);
  const auto a = lcm_log_target("file://game.lcmlog?speed=2&mode=a");
  ASSERT_TRUE(a.has_value());
  EXPECT_EQ(a->path, "game.lcmlog");
  EXPECT_TRUE(a->append);
  EXPECT_FALSE(lcm_log_target("file:///tmp/game.lcmlog").has_value());  // read mode, liblcm's default
  EXPECT_FALSE(lcm_log_target("file:///tmp/game.lcmlog?mode=r").has_value());
  EXPECT_FALSE(lcm_log_target("memq://").has_value());
  EXPECT_FALSE(lcm_log_target("udpm://239.255.76.67:7667?ttl=0").has_value());
}

TEST(LcmBus, AFileLogHoldsEveryMessageInOrderForLiblcm) {
  const std::string path = pinball::testing::temp_path("lcm_bus", "all.lcmlog");
  {
    LcmBus bus("file://" + path + "?mode=w");
    bus.start([](lcm::LCM&) {}, 1.0);
    publish_projections(bus, 500);
    bus.stop();
    const LcmBusCounters c = bus.counters();
    EXPECT_EQ(c.published, 500u);
    EXPECT_EQ(c.publish_failed, 0u);
    EXPECT_EQ(c.first_failure, "");
  }
  lcm::LogFile in(path, "r");
  ASSERT_TRUE(in.good());
  std::int64_t n = 0;
  for (const lcm::LogEvent* e = in.readNextEvent(); e != nullptr; e = in.readNextEvent()) {
    EXPECT_EQ(e->eventnum, n);
    EXPECT_EQ(e->channel, kProjectionChannel);
    pinball_lcm::lcmt_pinball_projection m{};
    ASSERT_GE(m.decode(e->data, 0, static_cast<int>(e->datalen)), 0);
    EXPECT_EQ(m.seq, n);
    ++n;
  }
  EXPECT_EQ(n, 500);
  std::remove(path.c_str());
}

// A log's events follow the game: queued messages of several channels are
// written earliest utime first, each stamped utime + the run's anchor
// (never the moment the bus thread wrote it).
TEST(LcmBus, AFileLogIsInUtimeOrderStampedUtimePlusTheAnchor) {
  const std::string path = pinball::testing::temp_path("lcm_bus", "clock.lcmlog");
  constexpr std::int64_t kAnchorUs = 1'700'000'000'000'000;
  {
    LcmBus bus("file://" + path + "?mode=w");
    bus.set_log_anchor_us(kAnchorUs);
    // Queued before the thread starts, so that one drain sees them all.
    for (int i = 0; i < 10; ++i) {
      pinball_lcm::lcmt_pinball_projection p{};
      p.utime = 2 * i * 1000;  // 0, 2, 4, ... ms
      p.seq = i;
      ASSERT_TRUE(bus.try_publish(p));
      pinball_lcm::lcmt_pinball_game_event g{};
      g.utime = (2 * i + 1) * 1000;  // 1, 3, 5, ... ms
      g.seq = i;
      ASSERT_TRUE(bus.try_publish(g));
    }
    bus.start([](lcm::LCM&) {}, 1.0);
    bus.stop();
  }
  lcm::LogFile in(path, "r");
  ASSERT_TRUE(in.good());
  std::int64_t n = 0;
  for (const lcm::LogEvent* e = in.readNextEvent(); e != nullptr; e = in.readNextEvent()) {
    EXPECT_EQ(e->channel, n % 2 == 0 ? kProjectionChannel : kGameChannel);
    EXPECT_EQ(e->timestamp, kAnchorUs + n * 1000) << "event " << n;
    ++n;
  }
  EXPECT_EQ(n, 20);
  std::remove(path.c_str());
}

// liblcm's own file provider ignores its write errors (it reported all of
// these as published); the bus writes file:// logs itself and counts them.
TEST(LcmBus, AFileLogOnAFullDiskCountsRefusedPublishesApart) {
  ::testing::internal::CaptureStderr();
  constexpr int kMessages = 600;
  LcmBusCounters c;
  {
    LcmBus bus("file:///dev/full?mode=w");
    bus.start();
    publish_projections(bus, kMessages);
    bus.stop();
    c = bus.counters();
  }
  const std::string err = ::testing::internal::GetCapturedStderr();
  EXPECT_EQ(c.published, 0u);
  EXPECT_EQ(c.publish_failed, static_cast<std::uint64_t>(kMessages));
  EXPECT_NE(c.first_failure.find("file:///dev/full?mode=w"), std::string::npos) << c.first_failure;
  EXPECT_NE(c.first_failure.find(kProjectionChannel), std::string::npos) << c.first_failure;
  EXPECT_NE(c.first_failure.find("No space left on device"), std::string::npos) << c.first_failure;
  // Said at once, and once.
  const std::size_t first = err.find(c.first_failure);
  ASSERT_NE(first, std::string::npos) << err;
  EXPECT_EQ(err.find(c.first_failure, first + 1), std::string::npos) << err;
}

// The pipe's write end by path, as `--lcm-url 'file:///dev/stdout?mode=w' | reader` would.
std::string pipe_url(int fd) { return "file:///proc/self/fd/" + std::to_string(fd) + "?mode=w"; }

TEST(LcmBus, APipeNobodyReadsNeitherHoldsStopNorPassesForPublished) {
  int fds[2];
  ASSERT_EQ(pipe(fds), 0);
  ::testing::internal::CaptureStderr();
  constexpr int kMessages = 1000;  // far more than a 64 KiB pipe holds
  LcmBusCounters c;
  double stop_s = 0.0;
  {
    LcmBus bus(pipe_url(fds[1]));
    bus.start();
    for (int i = 0; i < kMessages; ++i) {
      pinball_lcm::lcmt_pinball_projection m{};
      m.seq = i;
      bus.try_publish(m);  // a full ring drops (overflows): the bus thread waits on the pipe
    }
    const auto t0 = std::chrono::steady_clock::now();
    bus.stop();
    stop_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    c = bus.counters();
  }
  ::testing::internal::GetCapturedStderr();
  EXPECT_LT(stop_s, 3.0);  // one second of grace, and a poll period
  EXPECT_GT(c.publish_failed, 0u);
  EXPECT_EQ(c.published + c.publish_failed + c.overflows, static_cast<std::uint64_t>(kMessages));
  ::close(fds[0]);
  ::close(fds[1]);
}

TEST(LcmBus, APipeWhoseReaderLeftCountsFailuresAndDoesNotKillTheProcess) {
  // SIGPIPE keeps its default action (death) in this process.
  int fds[2];
  ASSERT_EQ(pipe(fds), 0);
  ::testing::internal::CaptureStderr();
  LcmBusCounters c;
  {
    LcmBus bus(pipe_url(fds[1]));
    ::close(fds[0]);
    ::close(fds[1]);
    bus.start();
    publish_projections(bus, 100);
    bus.stop();
    c = bus.counters();
  }
  ::testing::internal::GetCapturedStderr();
  EXPECT_EQ(c.published, 0u);
  EXPECT_EQ(c.publish_failed, 100u);
  EXPECT_NE(c.first_failure.find("Broken pipe"), std::string::npos) << c.first_failure;
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
