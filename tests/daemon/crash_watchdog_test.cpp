// A crashed daemon cannot switch its coils off; the driver board's watchdog
// must. The host side (DriverBus with its own thread, as pinballd runs it)
// lives in a child process that fires a coil and is then killed with
// SIGKILL; the reference board in this process must switch everything off
// within its watchdog timeout of the last heartbeat.

#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <thread>

#include "pinball/core/clock.h"
#include "pinball/firmware/driver_bus.h"
#include "pinball/firmware/stream_transport.h"
#include "pinball/firmware/virtual_driver_board.h"

namespace pinball::daemon {
namespace {

TEST(CrashWatchdog, KillingTheHostProcessSwitchesEveryCoilOff) {
  // Named ends, not a structured binding, which a lambda below would capture
  // and clang before 16 cannot parse (C++20 P1091).
  auto ends = firmware::StreamTransport::make_pair();
  auto& host = ends.first;
  auto& far = ends.second;
  const pid_t pid = fork();
  ASSERT_GE(pid, 0);
  if (pid == 0) {
    // The "daemon": a running DriverBus that holds flipper 0 up, forever.
    far->close();
    firmware::DriverBusOptions o;
    firmware::DriverBus bus(*host, o);
    bus.start();
    while (bus.state() != firmware::BusState::kRunning) std::this_thread::sleep_for(std::chrono::milliseconds(1));
    bus.fire(0);
    while (true) std::this_thread::sleep_for(std::chrono::seconds(1));
  }
  host->close();
  firmware::VirtualDriverBoard board(firmware::VirtualDriverBoardOptions{0, 2});
  const double t0 = steady_now_s();
  auto serve_for = [&](double seconds, auto&& until) {
    const double end = steady_now_s() + seconds;
    while (steady_now_s() < end) {
      board.service(*far, steady_now_s() - t0);
      if (until()) return true;
      std::this_thread::sleep_for(std::chrono::microseconds(200));
    }
    return false;
  };
  const bool on = serve_for(5.0, [&] { return board.coil(0).state != firmware::CoilState::kOff; });
  ASSERT_TRUE(on) << "the child never fired the coil";
  // Let it hold for a while: heartbeats keep it on.
  serve_for(0.3, [] { return false; });
  ASSERT_NE(board.coil(0).state, firmware::CoilState::kOff);
  ASSERT_EQ(kill(pid, SIGKILL), 0);
  int status = 0;
  ASSERT_EQ(waitpid(pid, &status, 0), pid);
  const double killed_at = steady_now_s() - t0;
  const bool off = serve_for(2.0, [&] { return board.coil(0).state == firmware::CoilState::kOff; });
  ASSERT_TRUE(off);
  const double off_at = board.coil(0).since_s;
  // The watchdog (100 ms) counts from the last heartbeat, sent at most one period (20 ms) before the kill.
  EXPECT_LE(off_at - killed_at, 0.1 + 0.005);
  EXPECT_EQ(board.counters().watchdog_trips, 1u);
  EXPECT_FALSE(board.armed());
}

}  // namespace
}  // namespace pinball::daemon
