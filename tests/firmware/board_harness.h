#pragma once
// Test harness: a VirtualDriverBoard on one end of a socket pair, a safety
// monitor on its outputs (checked at the end of every test), and helpers to
// send host messages through the real encode/send/receive path on a virtual clock.

#include <gtest/gtest.h>

#include <memory>

#include "pinball/firmware/codec.h"
#include "pinball/firmware/coil_safety_monitor.h"
#include "pinball/firmware/stream_transport.h"
#include "pinball/firmware/virtual_driver_board.h"

namespace pinball::firmware::testing {

/// Caps a monitor should hold driver `config` to.
inline CoilCaps caps_of(const DriverConfig& c) {
  CoilCaps caps;
  caps.pulse_s = std::min(c.max_pulse_ms, kAbsMaxPulseMs) * 1e-3;
  caps.hold_s = std::min(c.max_hold_ms, kAbsMaxHoldMs) * 1e-3;
  caps.duty = c.hold_duty_pct / 100.0;
  return caps;
}

/// A board, its link and its safety observer.
class BoardTest : public ::testing::Test {
 protected:
  BoardTest() : board_(make_options()) {
    auto [h, b] = StreamTransport::make_pair();
    host_ = std::move(h);
    link_ = std::move(b);
    board_.add_listener(&monitor_);
  }

  virtual VirtualDriverBoardOptions make_options() { return {}; }

  void TearDown() override {
    monitor_.finish(t_);
    EXPECT_EQ(monitor_.violations(), 0) << monitor_.first_violation();
  }

  /// Host -> board through the socket pair; the board handles it at time t_.
  void send(const Payload& p) {
    ASSERT_EQ(host_->send(encode(board_id_, p)), TxStatus::kOk);
    board_.service(*link_, t_);
  }
  /// A raw frame host -> board.
  void send_raw(const CanFrame& f) {
    ASSERT_EQ(host_->send(f), TxStatus::kOk);
    board_.service(*link_, t_);
  }
  /// Moves the clock to t (s) and lets the board run its timers.
  void advance_to(double t) {
    t_ = t;
    board_.service(*link_, t_);
  }
  /// Hello, configure drivers 0..n-1 with `c` (monitor caps follow), first heartbeat.
  void open_session(const DriverConfig& c = {}, int n = 2, std::uint16_t watchdog_ms = 100) {
    send(Hello{kProtocolVersion, watchdog_ms});
    for (int d = 0; d < n; ++d) {
      send(Configure{static_cast<std::uint8_t>(d), c});
      monitor_.set_caps(d, caps_of(c));
    }
    heartbeat();
  }
  void heartbeat() { send(Heartbeat{kProtocolVersion, ++seq_}); }
  void fire(std::uint8_t d, FireMode mode = FireMode::kPulseHold, std::uint8_t pulse_ms = 0) {
    send(Fire{d, mode, pulse_ms, ++seq_});
  }
  void release(std::uint8_t d) { send(Release{d, ++seq_}); }
  /// Every frame the board sent so far, decoded (bad ones fail the test).
  std::vector<Message> board_messages() {
    std::vector<Message> out;
    CanFrame f;
    while (host_->receive(f, 0) == RxStatus::kFrame) {
      const DecodeResult r = decode(f);
      EXPECT_TRUE(r.ok()) << r.reason;
      if (r.ok()) out.push_back(r.message);
    }
    return out;
  }
  /// Count of board Fault frames with `code` among `msgs`.
  static int faults(const std::vector<Message>& msgs, FaultCode code) {
    int n = 0;
    for (const Message& m : msgs) {
      if (const auto* f = std::get_if<Fault>(&m.payload); f != nullptr && f->code == code) ++n;
    }
    return n;
  }

  std::uint8_t board_id_ = 0;
  VirtualDriverBoard board_;
  CoilSafetyMonitor monitor_;
  std::unique_ptr<StreamTransport> host_;
  std::unique_ptr<StreamTransport> link_;
  double t_ = 0.0;
  std::uint16_t seq_ = 0;
};

}  // namespace pinball::firmware::testing
