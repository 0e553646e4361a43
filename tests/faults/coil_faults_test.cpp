// The fault-injection suite (ctest -L faults): the real DriverBus against the
// reference board, on a virtual clock, with frames lost and threads frozen.
// Every test states the bound on how long a coil may stay on; docs/daemon.md's
// fault table quotes these bounds and names these tests.

#include <gtest/gtest.h>

#include <unistd.h>

#include <chrono>
#include <cmath>
#include <functional>
#include <tuple>

#include "../firmware/board_harness.h"
#include "common/forwarding_link.h"
#include "pinball/firmware/driver_bus.h"
#include "pinball/firmware/frame_log.h"
#include "pinball/firmware/liveness.h"
#include "pinball/simlab/faulty_link.h"
#include "protocol_bench.h"

namespace pinball::firmware {
namespace {

constexpr double kTick_s = 0.001;
constexpr double kStatusPeriod_s = 0.01;  // VirtualDriverBoardOptions' default

// The host's end of the link, dropping the frames a test picks.
class DroppingLink final : public pinball::testing::ForwardingLink {
 public:
  DroppingLink(CanTransport& inner, std::function<bool(const CanFrame&)> drop)
      : ForwardingLink(inner), drop_(std::move(drop)) {}
  TxStatus send(const CanFrame& f) override {
    if (drop_(f)) {
      ++dropped;
      return TxStatus::kOk;  // lost on the wire: the sender cannot know
    }
    return ForwardingLink::send(f);
  }
  int dropped = 0;

 private:
  std::function<bool(const CanFrame&)> drop_;
};

bool is_kind(const CanFrame& f, MessageKind k) { return ((f.id >> 4) & 0xFu) == static_cast<std::uint32_t>(k); }

class CoilFaults : public testing::BoardTest {
 protected:
  DriverBusOptions options() {
    DriverBusOptions o;
    o.driver_count = 2;
    for (int d = 0; d < 2; ++d) monitor_.set_caps(d, testing::caps_of(o.drivers[static_cast<std::size_t>(d)]));
    return o;
  }
  // Host and board in lockstep; `each_tick` runs before the host polls (the
  // watched threads' beats, a test's commands).
  void run(DriverBus& bus, double seconds, const std::function<void()>& each_tick = [] {}) {
    const int ticks = static_cast<int>(std::lround(seconds / kTick_s));
    for (int k = 0; k < ticks; ++k) {
      t_ += kTick_s;
      each_tick();
      bus.poll_once(t_);
      board_.service(*link_, t_);
    }
  }
  // Runs until driver d is off; returns when (s), or a large number.
  bool bus_running_ = false;  // a DroppingLink may start dropping once the session runs
  double run_until_off(DriverBus& bus, int d, double limit_s, const std::function<void()>& each_tick = [] {}) {
    for (double end = t_ + limit_s; t_ < end;) {
      run(bus, kTick_s, each_tick);
      if (board_.coil(d).state == CoilState::kOff) return board_.coil(d).since_s;
    }
    return 1e9;
  }
};

TEST_F(CoilFaults, ALostReleaseIsSentAgainWithinOneStatusPeriod) {
  bool drop_next_release = false;
  DroppingLink lossy(*host_, [&](const CanFrame& f) {
    if (!drop_next_release || !is_kind(f, MessageKind::kRelease)) return false;
    drop_next_release = false;
    return true;
  });
  DriverBus bus(lossy, options());
  run(bus, 0.05);
  ASSERT_EQ(bus.state(), BusState::kRunning);
  bus.fire(0);
  run(bus, 0.1);
  ASSERT_EQ(board_.coil(0).state, CoilState::kHold);
  drop_next_release = true;
  bus.release(0);
  const double released_at = t_;
  const double off_at = run_until_off(bus, 0, 1.0);
  EXPECT_EQ(lossy.dropped, 1);
  EXPECT_EQ(bus.counters().release_retries, 1u);
  // The next Status after the retry allowance shows the coil on; the Release
  // goes again at once. Protocol v1's host left it on until the hold cap (5 s).
  EXPECT_LE(off_at - released_at, kStatusPeriod_s + options().release_retry_s + 2 * kTick_s);
  EXPECT_EQ(bus.counters().release_escalations, 0u);
}

TEST_F(CoilFaults, ACoilThatStaysOnGetsAReleaseAllPastTheDeadline) {
  // Every Release is lost (a board that ignores them would look the same).
  DroppingLink lossy(*host_, [](const CanFrame& f) { return is_kind(f, MessageKind::kRelease); });
  DriverBus bus(lossy, options());
  run(bus, 0.05);
  bus.fire(1);
  run(bus, 0.1);
  bus.release(1);
  const double released_at = t_;
  const double off_at = run_until_off(bus, 1, 1.0);
  EXPECT_GE(bus.counters().release_retries, 3u);
  EXPECT_EQ(bus.counters().release_escalations, 1u);
  EXPECT_LE(off_at - released_at, options().release_deadline_s + 2 * kStatusPeriod_s);
  BusFault f;
  bool escalated = false;
  while (bus.pop_fault(f)) escalated |= f.kind == BusFaultKind::kReleaseEscalated && f.driver == 1;
  EXPECT_TRUE(escalated);
}

// With 1 % and 5 % of frames lost both ways, the host's own retries keep every
// released coil's on-time short; protocol v1 measured 1.4 s and 2.9 s. The
// measurement is `pinball bench protocol`'s; the baseline (closed loop off)
// shows what the retries are worth.
class LossyLink : public ::testing::TestWithParam<double> {};

TEST_P(LossyLink, EveryReleasedCoilIsOffWithinTheReleaseDeadline) {
  const bench::ReleaseUnderLoss on = bench::measure_release_under_loss(GetParam(), true, 400, 7);
  EXPECT_LE(on.worst_s, DriverBusOptions{}.release_deadline_s + 3 * kStatusPeriod_s) << "drop " << GetParam();
  EXPECT_GT(on.frames_dropped, 0u);
  EXPECT_GT(on.release_retries, 0u);
  EXPECT_EQ(on.cap_violations, 0u);
  const bench::ReleaseUnderLoss off = bench::measure_release_under_loss(GetParam(), false, 400, 7);
  EXPECT_GT(off.worst_s, 1.0) << "without the closed loop a lost Release waits for the hold cap";
}

INSTANTIATE_TEST_SUITE_P(OneAndFivePercent, LossyLink, ::testing::Values(0.01, 0.05));

// A watched thread that stops beating: the host releases every coil at once
// and withholds the heartbeat; even with that ReleaseAll lost, the board's
// watchdog switches everything off within watchdog + one liveness timeout.
class FrozenThread : public CoilFaults, public ::testing::WithParamInterface<std::tuple<int, bool>> {};

TEST_P(FrozenThread, EveryCoilIsOffWithinTheWatchdogPlusOneHeartbeatPeriod) {
  // Not a structured binding: the lambda below captures frozen, which clang
  // before 16 cannot parse (C++20 P1091), and clang-tidy reads this file.
  const int frozen = std::get<0>(GetParam());
  const bool lose_release_all = std::get<1>(GetParam());
  DroppingLink lossy(*host_, [&, lose = lose_release_all](const CanFrame& f) {
    return lose && is_kind(f, MessageKind::kReleaseAll) && bus_running_;
  });
  DriverBusOptions o = options();
  Liveness live(o.heartbeat_period_s);
  const int camera = live.watch("camera");
  const int controller = live.watch("controller");
  o.liveness = &live;
  DriverBus bus(lossy, o);
  bool freeze = false;
  auto beats = [&] {
    if (!freeze || frozen != camera) live.beat(camera, t_);
    if (!freeze || frozen != controller) live.beat(controller, t_);
  };
  run(bus, 0.05, beats);
  ASSERT_EQ(bus.state(), BusState::kRunning);
  bus_running_ = true;
  bus.fire(0);
  bus.fire(1);
  run(bus, 0.1, beats);
  ASSERT_EQ(board_.coil(0).state, CoilState::kHold);
  freeze = true;
  const double frozen_at = t_;
  const double off0 = run_until_off(bus, 0, 1.0, beats);
  const double off1 = run_until_off(bus, 1, 1.0, beats);
  const double bound = o.watchdog_timeout_s + o.heartbeat_period_s + kTick_s;
  EXPECT_LE(std::max(off0, off1) - frozen_at, bound);
  if (!lose_release_all) {
    EXPECT_LE(std::max(off0, off1) - frozen_at, live.timeout_s() + 2 * kTick_s);
  }
  EXPECT_EQ(bus.counters().liveness_stalls, 1u);
  run(bus, 0.3, beats);
  EXPECT_EQ(board_.counters().watchdog_trips, 1u);  // no heartbeat while frozen
  EXPECT_GT(bus.counters().heartbeats_withheld, 5u);
  // The thread comes back: heartbeats resume, and the board fires again.
  freeze = false;
  run(bus, 0.03, beats);
  EXPECT_TRUE(board_.armed());
  bus.fire(0);
  run(bus, 0.002, beats);
  EXPECT_EQ(board_.coil(0).state, CoilState::kPulse);
  EXPECT_GE(bus.counters().coils_dropped, 2u);  // the stall, then the watchdog's own report
}

INSTANTIATE_TEST_SUITE_P(CameraOrController, FrozenThread,
                         ::testing::Combine(::testing::Values(0, 1), ::testing::Bool()));

TEST_F(CoilFaults, ThreadsStillStartingDoNotCountAsStalledButGetNoHeartbeat) {
  DriverBusOptions o = options();
  Liveness live(o.heartbeat_period_s);
  const int camera = live.watch("camera");
  o.liveness = &live;
  DriverBus bus(*host_, o);
  run(bus, 0.2);
  EXPECT_EQ(bus.state(), BusState::kRunning);
  EXPECT_FALSE(board_.armed());  // nothing vouches for the chain yet: Fire would be refused
  EXPECT_EQ(bus.counters().liveness_stalls, 0u);
  run(bus, 0.03, [&] { live.beat(camera, t_); });
  EXPECT_TRUE(board_.armed());
}

TEST_F(CoilFaults, AHoldCapIsReleasedByTheHostSoTheFlipperFiresAgain) {
  DriverBusOptions o = options();
  o.drivers[0].max_hold_ms = 300;
  monitor_.set_caps(0, testing::caps_of(o.drivers[0]));
  DriverBus bus(*host_, o);
  run(bus, 0.05);
  bus.fire(0);
  run(bus, 0.4);
  EXPECT_EQ(board_.counters().hold_cap_trips, 1u);
  EXPECT_EQ(bus.counters().hold_cap_faults, 1u);
  EXPECT_EQ(bus.counters().coils_dropped, 1u);
  bus.fire(0);  // the host acknowledged the cap: no lock left
  run(bus, 0.002);
  EXPECT_EQ(board_.coil(0).state, CoilState::kPulse);
  EXPECT_EQ(board_.counters().refused_locked, 0u);
}

// Protocol v1 refused every Fire after about 700 s of heartbeats, silently.
TEST_F(CoilFaults, AFlipperFiresAfterTwoHoursOfIdleHeartbeats) {
  DriverBus bus(*host_, options());
  run(bus, 0.05);
  bus.fire(0);
  run(bus, 0.05);
  bus.release(0);
  run(bus, 0.05);
  // Two hours of heartbeats on 10 ms ticks (heartbeat 20 ms, Status 10 ms).
  for (int k = 0; k < 2 * 3600 * 100; ++k) {
    t_ += 0.01;
    bus.poll_once(t_);
    board_.service(*link_, t_);
  }
  EXPECT_GT(bus.counters().heartbeats, 300000u);  // the 16-bit seq wrapped five times
  EXPECT_EQ(board_.counters().watchdog_trips, 0u);
  for (int d = 0; d < 2; ++d) {
    bus.fire(d);
    run(bus, 0.002);
    EXPECT_EQ(board_.coil(d).state, CoilState::kPulse) << "driver " << d;
  }
  EXPECT_EQ(board_.counters().stale, 0u);
  EXPECT_EQ(bus.counters().stale_faults, 0u);
}

TEST_F(CoilFaults, AStaleRefusalReachesTheHostAsAFault) {
  // A frame duplicated on the wire behind its own Release: the board refuses it and says so.
  DriverBus bus(*host_, options());
  run(bus, 0.05);
  const CanFrame old_fire = encode(0, Fire{0, FireMode::kPulseHold, 0, 1});
  bus.fire(0);
  run(bus, 0.05);
  bus.release(0);
  run(bus, 0.05);
  ASSERT_EQ(host_->send(old_fire), TxStatus::kOk);  // seq 1 is long past
  run(bus, 0.02);
  EXPECT_EQ(board_.coil(0).state, CoilState::kOff);
  EXPECT_EQ(bus.counters().stale_faults, 1u);
}

// The CAN log on a pipe nobody reads: the bus's polls (heartbeats, Status,
// commands) never wait for it; the log drops and counts once its queue is
// full. Before, one full pipe stopped the heartbeats.
TEST_F(CoilFaults, ACanLogThatBlocksNeverHoldsTheBus) {
  int fds[2];
  ASSERT_EQ(::pipe(fds), 0);  // the read end is never read
  {
    FrameLog log("/dev/fd/" + std::to_string(fds[1]), "can0", 0.1);
    DriverBusOptions o = options();
    o.log = &log;
    DriverBus bus(*host_, o);
    double slowest_poll_s = 0.0;
    auto poll_timed = [&] {
      const auto t0 = std::chrono::steady_clock::now();
      bus.poll_once(t_);
      slowest_poll_s = std::max(slowest_poll_s, std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
    };
    for (int k = 0; k < 20'000; ++k) {  // 20 s of bus time: about 3000 frames, far more than a pipe's 64 KiB
      t_ += kTick_s;
      if (k % 100 == 50) bus.fire(k % 2);
      if (k % 100 == 90) bus.release(k % 2);
      poll_timed();
      board_.service(*link_, t_);
    }
    EXPECT_EQ(board_.counters().watchdog_trips, 0u);
    EXPECT_GT(bus.counters().heartbeats, 900u);
    EXPECT_LT(slowest_poll_s, 0.05);  // a hang guard: no poll waits on the pipe
    log.close();
    EXPECT_GT(log.counters().dropped(), 0u);
    EXPECT_GT(log.counters().written, 0u);
  }
  ::close(fds[0]);
  ::close(fds[1]);
}

}  // namespace
}  // namespace pinball::firmware
