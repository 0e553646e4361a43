// pinballd's threads frozen and failing, in the embedded simulation: the
// heartbeat vouches for the chain, and a failing thread makes the coils safe
// before anything else (ctest -L faults).

#include <gtest/gtest.h>

#include <chrono>
#include <string>
#include <thread>

#include "pinball/daemon/daemon.h"
#include "pinball/daemon/thread_table.h"

namespace pinball::daemon {
namespace {

const std::string kSource = PINBALL_SOURCE_DIR;

DaemonConfig sim_config(int balls, bool realtime) {
  DaemonConfig c;
  c.sim.board = kSource + "/boards/mit1993.board";
  c.controller = kSource + "/controllers/best.json";
  c.sim.balls = balls;
  c.sim.seed = 11;
  c.sim.realtime = realtime;
  return c;
}

bool mentions(const std::vector<std::string>& lines, const std::string& what) {
  for (const std::string& l : lines) {
    if (l.find(what) != std::string::npos) return true;
  }
  return false;
}

// On the wall clock, a thread of the chain frozen for 0.4 s: its beats stop,
// the driver thread releases every coil and withholds the heartbeat, and the
// board's watchdog expires (no heartbeat for longer than 0.1 s). The game goes
// on afterwards.
class FrozenChainThread : public ::testing::TestWithParam<int> {};

// Plays on the wall clock, freezes `thread` for 0.4 s after 0.8 s, stops at 2 s.
DaemonReport run_with_a_frozen_thread(int thread) {
  Daemon d(sim_config(1000, true));
  std::thread tester([&] {
    std::this_thread::sleep_for(std::chrono::milliseconds(800));
    d.inject_fault(thread, 0.4);
    std::this_thread::sleep_for(std::chrono::milliseconds(1200));
    d.request_stop();
  });
  const DaemonReport r = d.run();
  tester.join();
  return r;
}

TEST_P(FrozenChainThread, StopsTheHeartbeatAndTheBoardDropsEveryCoil) {
  const int thread = GetParam();
  const DaemonReport r = run_with_a_frozen_thread(thread);
  EXPECT_GE(r.driver.liveness_stalls, 1u);
  EXPECT_GE(r.driver.heartbeats_withheld, 3u);
  EXPECT_GE(r.board.watchdog_trips, 1u);
  EXPECT_GE(r.driver.watchdog_faults, 1u);  // the board's Fault reached the host
  const std::string name = thread == kCameraThread ? "camera" : "controller";
  EXPECT_TRUE(mentions(r.faults, "the " + name + " thread stopped making progress")) << name;
  EXPECT_TRUE(mentions(r.faults, "watchdog expired"));
  EXPECT_TRUE(r.coils_off_at_exit);
  EXPECT_TRUE(r.thread_failures.empty());
}

INSTANTIATE_TEST_SUITE_P(CameraAndController, FrozenChainThread, ::testing::Values(kCameraThread, kControllerThread),
                         [](const auto& param_info) {
                           return std::string(param_info.param == kCameraThread ? "Camera" : "Controller");
                         });

// The driver thread itself frozen: no heartbeat at all, so the board's watchdog acts.
TEST(FrozenDriverThread, TheBoardsWatchdogSwitchesEveryCoilOff) {
  const DaemonReport r = run_with_a_frozen_thread(kDriverThread);
  EXPECT_GE(r.board.watchdog_trips, 1u);
  EXPECT_TRUE(r.coils_off_at_exit);
}

// Any thread that throws: ReleaseAll first, then the failure is reported and
// the run ends cleanly (before, std::terminate with the coils as they were).
class FailingThread : public ::testing::TestWithParam<int> {};

TEST_P(FailingThread, MakesTheCoilsSafeReportsAndEndsTheRun) {
  const int thread = GetParam();
  // Enough balls that the run is still going when the fault lands 300 ms in
  // (3 balls could all be played by then on an idle machine: no failure to report).
  Daemon d(sim_config(200, false));
  std::thread tester([&] {
    std::this_thread::sleep_for(std::chrono::milliseconds(300));
    d.inject_fault(thread, 0.0, /*fail=*/true);
  });
  const DaemonReport r = d.run();
  tester.join();
  ASSERT_EQ(r.thread_failures.size(), 1u);
  const std::string name = kThreadTable[static_cast<std::size_t>(thread)].name;
  EXPECT_EQ(r.thread_failures[0], name + ": injected failure of " + name);
  EXPECT_TRUE(r.coils_off_at_exit);
  EXPECT_GE(r.driver.release_alls, 1u);
}

INSTANTIATE_TEST_SUITE_P(EveryWorker, FailingThread,
                         ::testing::Values(kDriverThread, kControllerThread, kCameraThread, kSimThread),
                         [](const auto& param_info) {
                           std::string n = kThreadTable[static_cast<std::size_t>(param_info.param)].name;
                           return n.substr(3);  // "pb-driver" -> "driver"
                         });

// The LCM thread (its stats callback, once a second) fails the same way.
TEST(FailingLcmThread, MakesTheCoilsSafeReportsAndEndsTheRun) {
  Daemon d(sim_config(200, false));
  d.inject_fault(kLcmThread, 0.0, /*fail=*/true);
  const DaemonReport r = d.run();
  ASSERT_EQ(r.thread_failures.size(), 1u);
  EXPECT_EQ(r.thread_failures[0], "pb-lcm: injected failure of pb-lcm");
  EXPECT_LT(r.balls, 200);
  EXPECT_TRUE(r.coils_off_at_exit);
}

// SIGINT while the daemon learns its background or waits for the board: the
// start-up ends, nothing plays, every coil is off.
TEST(StopDuringStartUp, EndsTheStartUpInsteadOfWaitingItOut) {
  DaemonConfig c = sim_config(5, false);
  c.camera.background_frames = 10000;  // tens of seconds of rendering
  Daemon d(c);
  std::thread stopper([&] {
    std::this_thread::sleep_for(std::chrono::milliseconds(200));
    d.request_stop();
  });
  const auto t0 = std::chrono::steady_clock::now();
  const DaemonReport r = d.run();
  const double took_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  stopper.join();
  EXPECT_LT(took_s, 5.0);  // a hang guard, not a speed figure
  EXPECT_EQ(r.balls, 0);
  EXPECT_TRUE(r.coils_off_at_exit);
}

}  // namespace
}  // namespace pinball::daemon
