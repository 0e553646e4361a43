#include "pinball/firmware/driver_bus.h"

#include <gtest/gtest.h>
#include <linux/can/error.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <string>
#include <thread>

#include "board_harness.h"
#include "common/forwarding_link.h"
#include "pinball/firmware/frame_log.h"
#include "pinball/simlab/faulty_link.h"

namespace pinball::firmware {
namespace {

// DriverBus on a virtual clock (poll_once) against the reference board.
class DriverBusTest : public testing::BoardTest {
 protected:
  DriverBusOptions bus_options() {
    DriverBusOptions o;
    o.driver_count = 2;
    o.heartbeat_period_s = 0.02;
    o.watchdog_timeout_s = 0.1;
    for (int d = 0; d < 2; ++d) monitor_.set_caps(d, testing::caps_of(o.drivers[static_cast<std::size_t>(d)]));
    return o;
  }
  // Runs host and board in lockstep for `seconds` in 1 ms ticks.
  void run(DriverBus& bus, double seconds, bool host_alive = true) {
    const int ticks = static_cast<int>(std::lround(seconds * 1000.0));
    for (int k = 0; k < ticks; ++k) {
      t_ += 0.001;
      if (host_alive) bus.poll_once(t_);
      board_.service(*link_, t_);
    }
  }
};

TEST_F(DriverBusTest, SessionReachesRunningAndFireReleaseMoveTheCoil) {
  DriverBus bus(*host_, bus_options());
  run(bus, 0.05);
  ASSERT_EQ(bus.state(), BusState::kRunning);
  EXPECT_TRUE(board_.configured(0) && board_.configured(1));
  EXPECT_TRUE(board_.armed());
  EXPECT_TRUE(bus.fire(0));
  run(bus, 0.002);
  EXPECT_EQ(board_.coil(0).state, CoilState::kPulse);
  run(bus, 0.05);
  EXPECT_EQ(board_.coil(0).state, CoilState::kHold);
  EXPECT_TRUE(bus.board().valid);
  EXPECT_EQ(bus.board().status.coil(0), CoilState::kHold);
  EXPECT_TRUE(bus.release(0));
  run(bus, 0.002);
  EXPECT_EQ(board_.coil(0).state, CoilState::kOff);
  EXPECT_FALSE(bus.fire(2));  // only 2 flippers
  EXPECT_FALSE(bus.fire(-1));
  const DriverBusCounters c = bus.counters();
  EXPECT_EQ(c.sessions, 1u);
  EXPECT_GE(c.heartbeats, 4u);
  EXPECT_GT(c.statuses, 5u);
  EXPECT_EQ(c.rx_bad, 0u);
}

// A log attached to a running session holds every frame from then on, and
// none from before (pinballd attaches its CAN log once its start has passed).
TEST_F(DriverBusTest, AnAttachedLogRecordsEveryFrameFromThenOn) {
  DriverBus bus(*host_, bus_options());
  run(bus, 0.05);
  ASSERT_EQ(bus.state(), BusState::kRunning);
  const DriverBusCounters before = bus.counters();
  const std::string path = ::testing::TempDir() + "/driver_bus_attach_" + std::to_string(::getpid()) + ".log";
  FrameLog log(path, "can0");
  bus.attach_log(&log);
  EXPECT_TRUE(bus.fire(0));
  run(bus, 0.05);
  bus.attach_log(nullptr);
  const DriverBusCounters after = bus.counters();
  run(bus, 0.02);  // after detaching: not recorded
  log.close();
  // Every frame sent (or tried) and received in the attached stretch, no other.
  const auto delta = [&](std::uint64_t DriverBusCounters::*field) { return after.*field - before.*field; };
  const std::uint64_t expected = delta(&DriverBusCounters::frames_sent) + delta(&DriverBusCounters::tx_failures) +
                                 delta(&DriverBusCounters::rx_frames) + delta(&DriverBusCounters::rx_bad) +
                                 delta(&DriverBusCounters::error_frames);
  EXPECT_GE(expected, 4u);  // the Fire, two heartbeats, Statuses
  EXPECT_EQ(log.counters().written, expected);
  EXPECT_EQ(log.counters().dropped(), 0u);
  std::remove(path.c_str());
}

TEST_F(DriverBusTest, HeartbeatLossMidHoldSwitchesEverythingOffWithinTheTimeout) {
  DriverBus bus(*host_, bus_options());
  run(bus, 0.05);
  bus.fire(0);
  bus.fire(1);
  run(bus, 0.1);
  ASSERT_EQ(board_.coil(0).state, CoilState::kHold);
  const double hang_at = t_;
  run(bus, 0.2, /*host_alive=*/false);  // the host hangs
  for (int d = 0; d < 2; ++d) {
    EXPECT_EQ(board_.coil(d).state, CoilState::kOff);
    EXPECT_LE(board_.coil(d).since_s, hang_at + 0.1 + 1e-9);
  }
  EXPECT_EQ(board_.counters().watchdog_trips, 1u);
  // The host comes back: it sees the fault, and the board takes commands again after a heartbeat.
  run(bus, 0.05);
  EXPECT_GE(bus.counters().watchdog_faults, 1u);
  bus.fire(0);
  run(bus, 0.002);
  EXPECT_EQ(board_.coil(0).state, CoilState::kPulse);
}

TEST_F(DriverBusTest, BusOffIsRecoveredWithANewSession) {
  DriverBus bus(*host_, bus_options());
  run(bus, 0.05);
  bus.fire(0);
  run(bus, 0.05);
  ASSERT_EQ(board_.coil(0).state, CoilState::kHold);
  ASSERT_EQ(link_->send(make_error_frame(CAN_ERR_BUSOFF)), TxStatus::kOk);  // the controller reports bus-off
  run(bus, 0.002);
  EXPECT_EQ(bus.state(), BusState::kBusOff);
  bus.fire(0);  // accepted into the queue, dropped while bus-off (counted)
  run(bus, 0.3);
  EXPECT_EQ(bus.state(), BusState::kRunning);
  EXPECT_EQ(board_.coil(0).state, CoilState::kOff);  // off: the watchdog or the recovery's ReleaseAll
  const DriverBusCounters c = bus.counters();
  EXPECT_EQ(c.bus_off, 1u);
  EXPECT_EQ(c.reconnects, 1u);
  EXPECT_EQ(c.sessions, 2u);
  EXPECT_GE(c.dropped_not_running, 1u);
  bus.fire(1);
  run(bus, 0.002);
  EXPECT_EQ(board_.coil(1).state, CoilState::kPulse);
}

TEST_F(DriverBusTest, WorksThroughALossyLink) {
  simlab::FaultyLinkOptions o;
  o.drop_p = 0.05;
  o.duplicate_p = 0.05;
  o.delay_p = 0.05;
  o.corrupt_p = 0.05;
  o.seed = 3;
  simlab::FaultyLink lossy(*host_, o);
  DriverBus bus(lossy, bus_options());
  run(bus, 0.2);
  ASSERT_EQ(bus.state(), BusState::kRunning);
  int on = 0;
  for (int i = 0; i < 20; ++i) {
    bus.fire(i % 2);
    run(bus, 0.003);
    on += board_.coil(i % 2).state != CoilState::kOff;
    bus.release(i % 2);
    run(bus, 0.02);
  }
  EXPECT_GE(on, 14);  // most commands get through
  EXPECT_GT(board_.counters().bad_frames, 0u);
  EXPECT_GT(lossy.fault_counters().dropped, 0u);
}

TEST_F(DriverBusTest, ReleaseAllDiscardsQueuedFires) {
  DriverBus bus(*host_, bus_options());
  run(bus, 0.05);
  bus.fire(0);
  bus.fire(1);
  bus.release_all();
  run(bus, 0.002);
  EXPECT_EQ(board_.coil(0).state, CoilState::kOff);
  EXPECT_EQ(board_.coil(1).state, CoilState::kOff);
  EXPECT_EQ(board_.counters().fires_accepted, 0u);
}

TEST_F(DriverBusTest, StatusSilenceRestartsTheSession) {
  DriverBus bus(*host_, bus_options());
  run(bus, 0.05);
  ASSERT_EQ(bus.state(), BusState::kRunning);
  for (int k = 0; k < 300; ++k) {  // the board stops talking (its replies are lost)
    t_ += 0.001;
    bus.poll_once(t_);
    CanFrame f;
    while (link_->receive(f, 0) == RxStatus::kFrame) {
    }
  }
  EXPECT_NE(bus.state(), BusState::kRunning);
  EXPECT_GE(bus.counters().status_timeouts, 1u);
  run(bus, 0.1);
  EXPECT_EQ(bus.state(), BusState::kRunning);
}

TEST_F(DriverBusTest, FireNeverBlocksAndCountsAFullQueue) {
  DriverBus bus(*host_, bus_options());  // not started: nobody drains the queue
  const auto start = std::chrono::steady_clock::now();
  int accepted = 0;
  for (int i = 0; i < 10'000; ++i) accepted += bus.fire(i % 2);
  const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  EXPECT_EQ(accepted, DriverBus::kQueueSize);
  EXPECT_EQ(bus.counters().queue_full, 10'000u - DriverBus::kQueueSize);
  EXPECT_LT(s, 0.5);
}

TEST(DriverBusOptions, BadConfigurationThrowsWithTheFieldName) {
  auto [a, b] = StreamTransport::make_pair();
  DriverBusOptions o;
  o.heartbeat_period_s = 0.05;  // watchdog 0.1 < 3 periods
  try {
    DriverBus bus(*a, o);
    FAIL() << "no throw";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("watchdog_timeout_s"), std::string::npos) << e.what();
  }
  o = {};
  o.drivers[1].pulse_ms = 90;  // above max_pulse_ms
  EXPECT_THROW(DriverBus(*a, o), std::invalid_argument);
  o = {};
  o.driver_count = 9;
  EXPECT_THROW(DriverBus(*a, o), std::invalid_argument);
}

// The real thread on the steady clock: fire, then the host hangs mid-hold.
TEST_F(DriverBusTest, ThreadedHeartbeatKeepsTheBoardAliveUntilTheHostHangs) {
  DriverBus bus(*host_, bus_options());
  auto steady = [] { return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count(); };
  auto serve_until = [&](double until, auto done) {
    while (steady() < until) {
      CanFrame f;
      if (link_->receive(f, 1) == RxStatus::kFrame) board_.on_frame(f, t_ = steady());
      board_.service(*link_, t_ = steady());
      if (done()) return true;
    }
    return false;
  };
  t_ = steady();
  board_.advance(t_);
  bus.start();
  ASSERT_TRUE(serve_until(t_ + 1.0, [&] { return bus.state() == BusState::kRunning; }));
  bus.fire(0);
  ASSERT_TRUE(serve_until(t_ + 0.5, [&] { return board_.coil(0).state == CoilState::kHold; }));
  // Held well past the watchdog timeout: the heartbeat thread keeps it alive.
  serve_until(t_ + 0.3, [] { return false; });
  EXPECT_EQ(board_.coil(0).state, CoilState::kHold);
  EXPECT_EQ(board_.counters().watchdog_trips, 0u);
  bus.simulate_hang();
  const double hang_at = steady();
  ASSERT_TRUE(serve_until(hang_at + 0.5, [&] { return board_.coil(0).state == CoilState::kOff; }));
  EXPECT_LE(board_.coil(0).since_s - hang_at, 0.1 + 0.005);
  EXPECT_EQ(board_.counters().watchdog_trips, 1u);
}

TEST_F(DriverBusTest, StopSwitchesEveryCoilOff) {
  DriverBus bus(*host_, bus_options());
  run(bus, 0.05);
  bus.fire(0);
  run(bus, 0.05);
  ASSERT_EQ(board_.coil(0).state, CoilState::kHold);
  bus.start();
  bus.stop();
  board_.service(*link_, t_ += 0.001);
  EXPECT_EQ(board_.coil(0).state, CoilState::kOff);
  EXPECT_EQ(board_.counters().watchdog_trips, 0u);
}

// The controller's fast path: the frame leaves on the caller's thread, with no poll_once.
TEST_F(DriverBusTest, SendQueuedWritesTheCommandOnTheCallersThread) {
  DriverBus bus(*host_, bus_options());
  run(bus, 0.05);
  ASSERT_EQ(bus.state(), BusState::kRunning);
  const std::uint64_t sent_before = bus.counters().frames_sent;
  ASSERT_TRUE(bus.fire(0));
  EXPECT_TRUE(bus.send_queued(t_));
  EXPECT_EQ(bus.counters().frames_sent, sent_before + 1);
  board_.service(*link_, t_ += 0.0005);
  EXPECT_EQ(board_.coil(0).state, CoilState::kPulse);
  // Nothing is sent twice: the queue is empty for the next poll.
  run(bus, 0.001);
  EXPECT_EQ(board_.counters().fires_accepted, 1u);
}

TEST_F(DriverBusTest, SendQueuedSendsReleaseAllFirstAndDropsWhenNotRunning) {
  DriverBus bus(*host_, bus_options());
  ASSERT_TRUE(bus.fire(0));  // no session yet
  EXPECT_TRUE(bus.send_queued(t_));
  EXPECT_EQ(bus.counters().dropped_not_running, 1u);
  run(bus, 0.05);
  bus.fire(0);
  bus.fire(1);
  bus.release_all();
  EXPECT_TRUE(bus.send_queued(t_));
  board_.service(*link_, t_ += 0.0005);
  EXPECT_EQ(board_.coil(0).state, CoilState::kOff);
  EXPECT_EQ(board_.coil(1).state, CoilState::kOff);
  EXPECT_EQ(board_.counters().fires_accepted, 0u);
}

// A link whose receive() can be held, to catch poll_once in the middle of its work.
class GatedLink : public pinball::testing::ForwardingLink {
 public:
  using ForwardingLink::ForwardingLink;
  RxStatus receive(CanFrame& frame, int timeout_ms) override {
    if (armed_.exchange(false)) {
      inside_ = true;
      while (!open_.load()) std::this_thread::yield();
    }
    return ForwardingLink::receive(frame, timeout_ms);
  }
  std::atomic<bool> armed_{false}, inside_{false}, open_{false};
};

TEST_F(DriverBusTest, SendQueuedNeverWaitsForABusyPoll) {
  GatedLink gated(*host_);
  DriverBus bus(gated, bus_options());
  run(bus, 0.05);
  ASSERT_EQ(bus.state(), BusState::kRunning);
  gated.armed_ = true;
  std::thread poller([&] { bus.poll_once(t_); });
  while (!gated.inside_.load()) std::this_thread::yield();
  // poll_once holds the bus: the fast path returns at once and leaves the command queued.
  ASSERT_TRUE(bus.fire(0));
  const auto start = std::chrono::steady_clock::now();
  EXPECT_FALSE(bus.send_queued(t_));
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), 0.05);
  gated.open_ = true;
  poller.join();  // its command step takes the queued fire
  board_.service(*link_, t_ += 0.0005);
  EXPECT_EQ(board_.coil(0).state, CoilState::kPulse);
  EXPECT_EQ(board_.counters().fires_accepted, 1u);
}

// A link whose kernel queue can be full (send() would back off until it drains: here, at once), or
// whose next send fails outright.
class ScriptedLink : public pinball::testing::ForwardingLink {
 public:
  using ForwardingLink::ForwardingLink;
  TxStatus send(const CanFrame& frame) override {
    return fail_next_ ? (fail_next_ = false, TxStatus::kError) : ForwardingLink::send(frame);
  }
  TxStatus send_without_waiting(const CanFrame& frame) override {
    return full_ ? TxStatus::kBufferFull : send(frame);
  }
  bool full_ = false;
  bool fail_next_ = false;
};

// The controller's thread must not sleep in SocketCAN's back-off (up to 750 us a frame, 4 ms
// measured for two Fires): on a full queue it leaves the commands, in order, to the bus thread.
TEST_F(DriverBusTest, OnAFullKernelQueueTheRealTimeCallerLeavesTheCommandsToTheBusThread) {
  ScriptedLink link(*host_);
  DriverBus bus(link, bus_options());
  run(bus, 0.05);
  ASSERT_EQ(bus.state(), BusState::kRunning);
  link.full_ = true;
  bus.fire(0);
  bus.release(0);
  bus.fire(1);
  EXPECT_TRUE(bus.send_queued(t_, DriverBus::WhenFull::kLeaveQueued));
  board_.service(*link_, t_ += 0.0005);
  EXPECT_EQ(board_.counters().fires_accepted, 0u) << "nothing left on the caller's thread";
  EXPECT_EQ(bus.counters().sends_left_queued, 1u) << "the first command found the queue full; the rest waited";
  EXPECT_EQ(bus.counters().tx_failures, 0u) << "a full queue is no failure: no ReleaseAll follows";
  bus.poll_once(t_ += 0.0005);  // the bus thread's turn: it sends all three, in order
  board_.service(*link_, t_ += 0.0005);
  EXPECT_EQ(board_.counters().fires_accepted, 2u);
  EXPECT_EQ(board_.coil(0).state, CoilState::kOff);
  EXPECT_EQ(board_.coil(1).state, CoilState::kPulse);
  // A ReleaseAll left by a full queue goes first on the bus thread, and discards what it discarded.
  bus.fire(0);
  bus.release_all();
  EXPECT_TRUE(bus.send_queued(t_, DriverBus::WhenFull::kLeaveQueued));
  EXPECT_EQ(bus.counters().sends_left_queued, 2u);
  bus.poll_once(t_ += 0.0005);
  board_.service(*link_, t_ += 0.0005);
  EXPECT_EQ(board_.coil(0).state, CoilState::kOff);
  EXPECT_EQ(board_.coil(1).state, CoilState::kOff);
  EXPECT_EQ(board_.counters().fires_accepted, 2u);
}

// After a failed send the bus switches every coil off: a flipper the controller holds up went down
// behind its back, and it must be told (coils_dropped) to fire again.
TEST_F(DriverBusTest, ASendFailureThatSwitchesAHeldCoilOffTellsTheController) {
  ScriptedLink link(*host_);
  DriverBus bus(link, bus_options());
  run(bus, 0.05);
  bus.fire(1);
  run(bus, 0.05);
  ASSERT_EQ(board_.coil(1).state, CoilState::kHold);
  const std::uint64_t dropped = bus.counters().coils_dropped;
  link.fail_next_ = true;
  bus.fire(0);
  run(bus, 0.002);
  EXPECT_EQ(board_.coil(1).state, CoilState::kOff);
  EXPECT_EQ(bus.counters().tx_failures, 1u);
  EXPECT_EQ(bus.counters().coils_dropped, dropped + 1);
}

}  // namespace
}  // namespace pinball::firmware
