// One pass of the board's main loop (firmware_interface/core/service.c) over a scripted
// HAL: bounded work per pass, replies held back (never lost) while the
// transmitter is full, the switches reported.

#include "pinball/firmware/core/hal.h"

#include <gtest/gtest.h>

#include <deque>
#include <vector>

namespace {

struct ScriptedHal {
  pbfw_time_ns now = 0;
  std::deque<pbfw_frame> rx;
  std::vector<pbfw_frame> tx;
  unsigned tx_room = 100;  // frames the transmitter takes per pass
  unsigned taken_this_pass = 0;
  bool eos[PBFW_MAX_DRIVERS] = {};

  pbfw_hal hal() {
    pbfw_hal h{};
    h.context = this;
    h.now_ns = [](void* c) {
      auto* s = static_cast<ScriptedHal*>(c);
      s->taken_this_pass = 0;
      return s->now;
    };
    h.receive = [](void* c, pbfw_frame* f) {
      auto* s = static_cast<ScriptedHal*>(c);
      if (s->rx.empty()) return false;
      *f = s->rx.front();
      s->rx.pop_front();
      return true;
    };
    h.send = [](void* c, const pbfw_frame* f) {
      auto* s = static_cast<ScriptedHal*>(c);
      if (s->taken_this_pass >= s->tx_room) return false;
      ++s->taken_this_pass;
      s->tx.push_back(*f);
      return true;
    };
    h.end_of_stroke = [](void* c) {
      std::uint8_t closed = 0;
      for (unsigned d = 0; d < PBFW_MAX_DRIVERS; ++d) closed |= static_cast<std::uint8_t>(static_cast<ScriptedHal*>(c)->eos[d] << d);
      return closed;
    };
    return h;
  }
  void queue(pbfw_message m) {
    pbfw_frame f;
    pbfw_encode(&m, &f);
    rx.push_back(f);
  }
};

pbfw_board make_board() {
  pbfw_board b;
  pbfw_board_options o{};
  o.driver_count = 4;
  o.status_period_ns = 10 * PBFW_NS_PER_MS;
  EXPECT_EQ(pbfw_board_init(&b, &o), PBFW_INIT_OK);
  return b;
}

TEST(CoreService, HandlesAtMostTheGivenFramesPerPassAllAtOneTime) {
  pbfw_board b = make_board();
  ScriptedHal s;
  for (std::uint16_t i = 1; i <= 10; ++i) {
    pbfw_message m{};
    m.kind = PBFW_RELEASE_ALL;
    m.u.release_all = {i};
    s.queue(m);
  }
  const pbfw_hal h = s.hal();
  s.now = 5 * PBFW_NS_PER_MS;
  EXPECT_EQ(pbfw_board_service(&b, &h, 4), 4u);
  EXPECT_EQ(s.rx.size(), 6u);
  EXPECT_EQ(b.now_ns, 5 * PBFW_NS_PER_MS);
  EXPECT_EQ(b.last_seq, 4);
  s.now = 6 * PBFW_NS_PER_MS;
  EXPECT_EQ(pbfw_board_service(&b, &h, 100), 6u);
  EXPECT_EQ(b.last_seq, 10);
}

TEST(CoreService, RepliesWaitForTheTransmitterInOrderAndNoneIsLost) {
  pbfw_board b = make_board();
  ScriptedHal s;
  pbfw_message hello{};
  hello.kind = PBFW_HELLO;
  hello.u.hello = {PBFW_PROTOCOL_VERSION, 100};
  s.queue(hello);  // HelloAck + Status
  pbfw_message configure{};
  configure.kind = PBFW_CONFIGURE;
  configure.u.configure = {0, {30, 25, 40, 5000, 10}};
  s.queue(configure);  // Status
  s.tx_room = 1;
  const pbfw_hal h = s.hal();
  for (int pass = 0; pass < 5; ++pass) pbfw_board_service(&b, &h, 8);
  ASSERT_EQ(s.tx.size(), 4u);  // one per pass so far, the rest still queued
  s.tx_room = 100;
  pbfw_board_service(&b, &h, 8);
  std::vector<pbfw_kind> kinds;
  for (const pbfw_frame& f : s.tx) {
    pbfw_message m{};
    ASSERT_EQ(pbfw_decode(&f, &m, nullptr), PBFW_DECODE_OK);
    kinds.push_back(m.kind);
  }
  // Status at t=0 (the first frame runs the timers first), HelloAck and
  // Status for Hello, Status for Configure.
  ASSERT_EQ(kinds.size(), 4u);
  EXPECT_EQ(kinds[0], PBFW_STATUS);
  EXPECT_EQ(kinds[1], PBFW_HELLO_ACK);
  EXPECT_EQ(kinds[2], PBFW_STATUS);
  EXPECT_EQ(kinds[3], PBFW_STATUS);
  EXPECT_EQ(b.counters.tx_dropped, 0u);
}

TEST(CoreService, ReportsTheEndOfStrokeSwitches) {
  pbfw_board b = make_board();
  ScriptedHal s;
  s.eos[2] = true;
  const pbfw_hal h = s.hal();
  pbfw_board_service(&b, &h, 8);
  EXPECT_EQ(pbfw_board_status(&b).end_of_stroke, 0x04);
  s.eos[2] = false;
  s.eos[0] = true;
  pbfw_board_service(&b, &h, 8);
  EXPECT_EQ(pbfw_board_status(&b).end_of_stroke, 0x01);
}

}  // namespace
