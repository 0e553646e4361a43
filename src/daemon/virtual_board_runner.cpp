#include "virtual_board_runner.h"

#include <pthread.h>

#include <chrono>

#include "pinball/core/clock.h"

namespace pinball::daemon {

VirtualBoardRunner::VirtualBoardRunner(firmware::CanTransport& link, firmware::VirtualDriverBoardOptions options)
    : link_(link), board_(options) {
  thread_ = std::thread([this] { run(); });
}

VirtualBoardRunner::~VirtualBoardRunner() { stop(); }

void VirtualBoardRunner::stop() {
  stop_.store(true, std::memory_order_release);
  if (thread_.joinable()) thread_.join();
}

void VirtualBoardRunner::run() {
  pthread_setname_np(pthread_self(), "pb-vboard");
  while (!stop_.load(std::memory_order_acquire)) {
    board_.service(link_, steady_now_s());
    std::this_thread::sleep_for(std::chrono::microseconds(500));
  }
}

}  // namespace pinball::daemon
