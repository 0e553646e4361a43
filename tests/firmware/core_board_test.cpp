// The C core's board rules (firmware_interface/core/board.c) through its C API, on the
// integer nanosecond clock the STM32 board uses: exact deadlines, and the
// safety properties under random, mutated and replayed frame streams checked
// by an observer that knows nothing of the core's state.

#include "pinball/firmware/core/board.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cstdint>
#include <random>
#include <string>
#include <vector>

namespace {

constexpr pbfw_time_ns kMs = PBFW_NS_PER_MS;

struct CoilEvent {
  unsigned driver;
  pbfw_coil_state state;
  std::uint8_t duty_pct;
  pbfw_time_ns at;
};

// A board, the frames it sent, and every output change it made.
struct Rig {
  explicit Rig(std::uint8_t driver_count = 8) {
    pbfw_board_options o{};
    o.board_id = 0;
    o.driver_count = driver_count;
    o.status_period_ns = 10 * kMs;
    o.fw_major = 1;
    o.set_coil = [](void* self, unsigned d, pbfw_coil_state s, std::uint8_t duty, pbfw_time_ns at) {
      static_cast<Rig*>(self)->events.push_back({d, s, duty, at});
    };
    o.set_coil_context = this;
    EXPECT_EQ(pbfw_board_init(&board, &o), PBFW_INIT_OK);
  }

  void send(pbfw_message m, pbfw_time_ns at) {
    pbfw_frame f;
    m.board = 0;
    pbfw_encode(&m, &f);
    pbfw_board_on_frame(&board, &f, at);
  }
  void hello(pbfw_time_ns at, std::uint16_t watchdog_ms = 100) {
    pbfw_message m{};
    m.kind = PBFW_HELLO;
    m.u.hello = {PBFW_PROTOCOL_VERSION, watchdog_ms};
    send(m, at);
  }
  void configure(std::uint8_t d, pbfw_driver_config c, pbfw_time_ns at) {
    pbfw_message m{};
    m.kind = PBFW_CONFIGURE;
    m.u.configure = {d, c};
    send(m, at);
  }
  void heartbeat(pbfw_time_ns at) {
    pbfw_message m{};
    m.kind = PBFW_HEARTBEAT;
    m.u.heartbeat = {PBFW_PROTOCOL_VERSION, ++seq};
    send(m, at);
  }
  void fire(std::uint8_t d, std::uint8_t mode, pbfw_time_ns at, std::uint8_t pulse_ms = 0) {
    pbfw_message m{};
    m.kind = PBFW_FIRE;
    m.u.fire = {d, mode, pulse_ms, ++seq};
    send(m, at);
  }
  std::vector<pbfw_message> replies() {
    std::vector<pbfw_message> out;
    pbfw_frame f;
    while (pbfw_board_pop_tx(&board, &f)) {
      pbfw_message m{};
      EXPECT_EQ(pbfw_decode(&f, &m, nullptr), PBFW_DECODE_OK);
      out.push_back(m);
    }
    return out;
  }

  pbfw_board board{};
  std::vector<CoilEvent> events;
  std::uint16_t seq = 0;
};

const pbfw_driver_config kFlipper{30, 25, 40, 5000, 10};

TEST(CoreBoard, RefusesBadOptions) {
  pbfw_board b;
  pbfw_board_options o{};
  o.driver_count = 8;
  o.status_period_ns = 10 * kMs;
  o.board_id = 16;
  EXPECT_EQ(pbfw_board_init(&b, &o), PBFW_INIT_BAD_BOARD_ID);
  o.board_id = 0;
  o.driver_count = 9;
  EXPECT_EQ(pbfw_board_init(&b, &o), PBFW_INIT_BAD_DRIVER_COUNT);
  o.driver_count = 8;
  o.status_period_ns = 0;
  EXPECT_EQ(pbfw_board_init(&b, &o), PBFW_INIT_BAD_STATUS_PERIOD);
}

TEST(CoreBoard, PulseAndHoldEndAtTheirDeadlinesToTheNanosecondEvenWhenTheLoopIsLate) {
  Rig r;
  r.hello(0);
  r.configure(0, kFlipper, 1 * kMs);
  r.heartbeat(2 * kMs);
  r.fire(0, PBFW_PULSE_HOLD, 3 * kMs + 17);
  ASSERT_EQ(r.events.size(), 1u);
  EXPECT_EQ(r.events[0].state, PBFW_COIL_PULSE);
  EXPECT_EQ(r.events[0].duty_pct, 100);
  // The main loop comes back 40 ms late: the pulse still ended at 30 ms and
  // the watchdog (100 ms after the heartbeat) has not yet fired.
  pbfw_board_advance(&r.board, 73 * kMs);
  ASSERT_EQ(r.events.size(), 2u);
  EXPECT_EQ(r.events[1].state, PBFW_COIL_HOLD);
  EXPECT_EQ(r.events[1].duty_pct, 25);
  EXPECT_EQ(r.events[1].at, 33 * kMs + 17);
  // No more heartbeats: every coil off at heartbeat + 100 ms exactly (rule 4),
  // though the loop only looks at 250 ms.
  pbfw_board_advance(&r.board, 250 * kMs);
  ASSERT_EQ(r.events.size(), 3u);
  EXPECT_EQ(r.events[2].state, PBFW_COIL_OFF);
  EXPECT_EQ(r.events[2].at, 102 * kMs);
  EXPECT_EQ(r.board.counters.watchdog_trips, 1u);
}

TEST(CoreBoard, HoldCapLocksTheDriverUntilRelease) {
  Rig r;
  r.hello(0);
  r.configure(0, {30, 25, 40, 200, 0}, 0);
  pbfw_time_ns t = 0;
  r.heartbeat(t);
  r.fire(0, PBFW_PULSE_HOLD, t);
  for (t = 50 * kMs; t <= 400 * kMs; t += 50 * kMs) r.heartbeat(t);
  // Pulse 30 ms, then the hold's 200 ms cap: off at 230 ms, locked.
  ASSERT_EQ(r.events.size(), 3u);
  EXPECT_EQ(r.events[2].state, PBFW_COIL_OFF);
  EXPECT_EQ(r.events[2].at, 230 * kMs);
  r.fire(0, PBFW_PULSE_HOLD, t);
  EXPECT_EQ(r.events.size(), 3u);
  EXPECT_EQ(r.board.counters.refused_locked, 1u);
  // Hello does not unlock it; Release does.
  r.hello(t);
  r.configure(0, {30, 25, 40, 200, 0}, t);
  r.heartbeat(t);
  r.fire(0, PBFW_PULSE_ONLY, t);
  EXPECT_EQ(r.board.counters.refused_locked, 2u);
  pbfw_message rel{};
  rel.kind = PBFW_RELEASE;
  rel.u.release = {0, ++r.seq};
  r.send(rel, t);
  r.fire(0, PBFW_PULSE_ONLY, t);
  EXPECT_EQ(r.events.back().state, PBFW_COIL_PULSE);
}

TEST(CoreBoard, RecycleTimeAndClampedPulseAreExact) {
  Rig r;
  r.hello(0);
  r.configure(1, {30, 0, 40, 5000, 10}, 0);
  r.heartbeat(0);
  r.fire(1, PBFW_PULSE_ONLY, 0, 90);  // asks 90 ms, clamped to 40
  ASSERT_EQ(r.events.size(), 1u);
  pbfw_board_advance(&r.board, 45 * kMs);
  ASSERT_EQ(r.events.size(), 2u);
  EXPECT_EQ(r.events[1].at, 40 * kMs);
  EXPECT_EQ(r.board.counters.pulse_clamps, 1u);
  r.fire(1, PBFW_PULSE_ONLY, 50 * kMs - 1);  // 1 ns inside the recycle time
  EXPECT_EQ(r.events.size(), 2u);
  EXPECT_EQ(r.board.counters.refused_recycle, 1u);
  r.fire(1, PBFW_PULSE_ONLY, 50 * kMs);
  EXPECT_EQ(r.events.size(), 3u);
  bool clamp_reported = false;
  for (const pbfw_message& m : r.replies()) {
    clamp_reported |= m.kind == PBFW_FAULT && m.u.fault.code == PBFW_FAULT_PULSE_CLAMPED && m.u.fault.detail == 90;
  }
  EXPECT_TRUE(clamp_reported);
}

TEST(CoreBoard, NextDeadlineIsTheEarliestTimer) {
  Rig r;
  r.hello(0);
  r.configure(0, kFlipper, 0);
  r.heartbeat(5 * kMs);
  r.fire(0, PBFW_PULSE_ONLY, 6 * kMs);
  pbfw_board_advance(&r.board, 7 * kMs);
  EXPECT_EQ(pbfw_board_next_deadline(&r.board), 10 * kMs);  // the next Status
  pbfw_board_advance(&r.board, 10 * kMs);
  pbfw_board_advance(&r.board, 20 * kMs);
  pbfw_board_advance(&r.board, 30 * kMs);
  EXPECT_EQ(pbfw_board_next_deadline(&r.board), 36 * kMs);  // the pulse's end
}

TEST(CoreBoard, StatusEveryPeriodAndAfterHelloAndConfigure) {
  Rig r;
  pbfw_board_advance(&r.board, 0);
  r.hello(1 * kMs);
  r.configure(0, kFlipper, 2 * kMs);
  for (pbfw_time_ns t = 3 * kMs; t <= 100 * kMs; t += kMs) pbfw_board_advance(&r.board, t);
  int statuses = 0;
  int acks = 0;
  for (const pbfw_message& m : r.replies()) {
    statuses += m.kind == PBFW_STATUS;
    acks += m.kind == PBFW_HELLO_ACK;
  }
  EXPECT_EQ(acks, 1);
  EXPECT_EQ(statuses, 11 + 2);  // t = 0, 10, ..., 100 ms, and one each after Hello and Configure
}

// ---- the properties ----

// Watches outputs only, from outside: caps, duty, recycle, watchdog, replays.
struct SafetyObserver {
  struct Driver {
    bool on = false;
    pbfw_coil_state state = PBFW_COIL_OFF;
    pbfw_time_ns since = 0;
    pbfw_time_ns pulse_since = 0;
    pbfw_time_ns off_since = INT64_MIN / 2;
    pbfw_driver_config config{};
  };
  std::array<Driver, PBFW_MAX_DRIVERS> drivers{};
  pbfw_time_ns last_heartbeat = INT64_MIN / 2;  // any valid Heartbeat frame delivered
  pbfw_time_ns watchdog = 100 * kMs;
  std::vector<std::string> violations;

  void violation(unsigned d, const std::string& what, pbfw_time_ns t) {
    if (violations.size() < 5) violations.push_back("driver " + std::to_string(d) + " at " + std::to_string(t) + " ns: " + what);
  }
  void check_on(pbfw_time_ns t) {
    for (unsigned d = 0; d < PBFW_MAX_DRIVERS; ++d) {
      const Driver& drv = drivers[d];
      if (!drv.on) continue;
      if (t > last_heartbeat + watchdog) violation(d, "on past the watchdog", t);
      if (drv.state == PBFW_COIL_PULSE && t - drv.since > std::min<pbfw_time_ns>(drv.config.max_pulse_ms, 100) * kMs) {
        violation(d, "pulse past its cap", t);
      }
      if (drv.state == PBFW_COIL_HOLD && t - drv.since > std::min<pbfw_time_ns>(drv.config.max_hold_ms, 10000) * kMs) {
        violation(d, "hold past its cap", t);
      }
    }
  }
  void on_change(const CoilEvent& e) {
    Driver& drv = drivers[e.driver];
    check_on(e.at);
    if (e.state == PBFW_COIL_PULSE) {
      if (drv.on) violation(e.driver, "pulse restarted on an energised coil", e.at);
      if (e.duty_pct != 100) violation(e.driver, "pulse below full power", e.at);
      if (e.at < drv.off_since + drv.config.recycle_ms * kMs) violation(e.driver, "fired within the recycle time", e.at);
    }
    if (e.state == PBFW_COIL_HOLD && (e.duty_pct > 50 || e.duty_pct > drv.config.hold_duty_pct)) {
      violation(e.driver, "hold above its duty", e.at);
    }
    if (e.state == PBFW_COIL_OFF) drv.off_since = e.at;
    drv.on = e.state != PBFW_COIL_OFF;
    drv.state = e.state;
    drv.since = e.at;
  }
};

// Random valid commands, mutated copies, replays of earlier frames and
// silences longer than the watchdog, delivered at random nanosecond times.
struct StreamStats {
  std::uint64_t switch_ons = 0, watchdog_trips = 0, stale = 0, bad = 0, hold_caps = 0, replayed_fires = 0;
  std::uint64_t events_hash = 0;
};

// A frame of kind `kind` for board 0 with random bytes, sealed with a valid
// CRC: what a host with a bug could send.
pbfw_frame random_sealed(std::mt19937_64& rng, unsigned kind) {
  pbfw_frame f{};
  f.id = PBFW_ID_BASE | (kind << 4);
  const int len = pbfw_frame_length(kind);
  f.len = static_cast<std::uint8_t>(len > 0 ? len : static_cast<int>(rng() % 9));
  for (auto& b : f.data) b = static_cast<std::uint8_t>(rng());
  if (f.len > 0) f.data[f.len - 1] = pbfw_crc8(f.id, f.data, f.len - 1u);
  return f;
}

StreamStats run_stream(std::uint32_t seed, int frames, std::uint8_t driver_count, SafetyObserver& obs) {
  Rig r(driver_count);
  std::mt19937_64 rng(seed);
  auto uniform = [&rng](int lo, int hi) { return std::uniform_int_distribution<int>(lo, hi)(rng); };
  // Fires that switched a coil on, and the session they did it in: replaying
  // one in the same session must be refused as stale (rule 9).
  struct Accepted {
    pbfw_frame frame;
    int session;
  };
  std::vector<Accepted> accepted;
  int session = 0;  // valid Hellos seen
  pbfw_time_ns t = 0;
  StreamStats st;
  std::size_t seen = 0;
  auto deliver = [&](const pbfw_frame& f, bool replay) {
    // What the observer may know from the frame alone.
    pbfw_message m{};
    const bool valid = pbfw_decode(&f, &m, nullptr) == PBFW_DECODE_OK && m.board == 0;
    const std::size_t before = r.events.size();
    pbfw_board_on_frame(&r.board, &f, t);
    for (; seen < r.events.size(); ++seen) obs.on_change(r.events[seen]);
    if (valid && m.kind == PBFW_HELLO) {
      obs.watchdog = m.u.hello.watchdog_ms * kMs;
      ++session;
    }
    if (valid && m.kind == PBFW_HEARTBEAT) obs.last_heartbeat = t;
    if (valid && m.kind == PBFW_CONFIGURE && session > 0 && m.u.configure.driver < driver_count) {
      obs.drivers[m.u.configure.driver].config = m.u.configure.config;
    }
    bool switched_on = false;
    for (std::size_t i = before; i < r.events.size(); ++i) switched_on |= r.events[i].state == PBFW_COIL_PULSE;
    if (replay) {
      ++st.replayed_fires;
      if (switched_on) obs.violation(m.u.fire.driver, "a replayed Fire switched a coil on", t);
    } else if (switched_on) {
      accepted.push_back({f, session});
    }
    if (switched_on) ++st.switch_ons;
  };
  for (int i = 0; i < frames; ++i) {
    // Time: mostly a few ms, sometimes a silence past the watchdog.
    t += uniform(0, 99) < 2 ? static_cast<pbfw_time_ns>(uniform(100, 1200)) * kMs
                            : static_cast<pbfw_time_ns>(uniform(0, 8 * 1000)) * 1000 + uniform(0, 999);
    pbfw_board_advance(&r.board, t);
    for (; seen < r.events.size(); ++seen) obs.on_change(r.events[seen]);
    obs.check_on(t);
    const int what = uniform(0, 99);
    if (what < 8 && !accepted.empty()) {
      const std::size_t back = static_cast<std::size_t>(uniform(0, std::min<int>(50, static_cast<int>(accepted.size()) - 1)));
      const Accepted& a = accepted[accepted.size() - 1 - back];
      if (a.session == session) {
        deliver(a.frame, true);
        continue;
      }
    }
    pbfw_message m{};
    pbfw_frame f;
    const std::uint8_t d = static_cast<std::uint8_t>(uniform(0, driver_count));  // sometimes one past the last
    if (what < 3) {
      m.kind = PBFW_HELLO;
      m.u.hello = {PBFW_PROTOCOL_VERSION, static_cast<std::uint16_t>(uniform(10, 300))};
    } else if (what < 10) {
      m.kind = PBFW_CONFIGURE;
      const auto max_pulse = static_cast<std::uint8_t>(uniform(1, 100));
      m.u.configure = {d, {static_cast<std::uint8_t>(uniform(1, max_pulse)), static_cast<std::uint8_t>(uniform(0, 50)), max_pulse,
                           static_cast<std::uint16_t>(uniform(1, 400)), static_cast<std::uint8_t>(uniform(0, 40))}};
    } else if (what < 45) {
      m.kind = PBFW_HEARTBEAT;
      m.u.heartbeat = {PBFW_PROTOCOL_VERSION, ++r.seq};
    } else if (what < 80) {
      m.kind = PBFW_FIRE;
      m.u.fire = {d, static_cast<std::uint8_t>(uniform(0, 1)), static_cast<std::uint8_t>(uniform(0, 3) == 0 ? uniform(0, 100) : 0), ++r.seq};
    } else if (what < 88) {
      m.kind = PBFW_RELEASE;
      m.u.release = {d, ++r.seq};
    } else if (what < 90) {
      m.kind = PBFW_RELEASE_ALL;
      m.u.release_all = {++r.seq};
    }
    if (what < 90) {
      pbfw_encode(&m, &f);
    } else {
      // Any kind without a sequence number, any bytes, a valid CRC. (Random
      // sequence numbers would defeat any 16-bit serial-number scheme: the
      // host's are monotonic, and the replay property is stated for those.)
      f = random_sealed(rng, static_cast<unsigned>(uniform(4, 15)));
    }
    if (uniform(0, 99) < 15) {  // mutate: a flipped bit, a wrong length or another board's id
      switch (uniform(0, 2)) {
        case 0: f.data[uniform(0, 7)] ^= static_cast<std::uint8_t>(1u << uniform(0, 7)); break;
        case 1: f.len = static_cast<std::uint8_t>(uniform(0, 8)); break;
        default: f.id ^= static_cast<std::uint32_t>(uniform(1, 0x7FF)); break;
      }
    }
    deliver(f, false);
    pbfw_frame out;
    while (pbfw_board_pop_tx(&r.board, &out)) {
      pbfw_message reply{};
      EXPECT_EQ(pbfw_decode(&out, &reply, nullptr), PBFW_DECODE_OK) << "the board sends only valid frames";
    }
  }
  t += 2000 * kMs;  // the host goes silent: everything must be off by the watchdog
  pbfw_board_advance(&r.board, t);
  for (; seen < r.events.size(); ++seen) obs.on_change(r.events[seen]);
  obs.check_on(t);
  for (unsigned d = 0; d < driver_count; ++d) EXPECT_EQ(r.board.drivers[d].state, PBFW_COIL_OFF) << "driver " << d;
  st.watchdog_trips = r.board.counters.watchdog_trips;
  st.stale = r.board.counters.stale;
  st.bad = r.board.counters.bad_frames;
  st.hold_caps = r.board.counters.hold_cap_trips;
  for (const CoilEvent& e : r.events) {
    st.events_hash = st.events_hash * 1099511628211ull ^ (static_cast<std::uint64_t>(e.at) * 31 + e.driver * 7 + e.state);
  }
  return st;
}

TEST(CoreBoardProperty, RandomMutatedAndReplayedStreamsKeepEveryCoilWithinItsCaps) {
  for (std::uint32_t seed : {1u, 2u, 3u}) {
    SafetyObserver obs;
    const StreamStats st = run_stream(seed, 60'000, 8, obs);
    EXPECT_TRUE(obs.violations.empty()) << "seed " << seed << ": " << obs.violations.front();
    // The streams reach the corners the rules speak of.
    EXPECT_GT(st.switch_ons, 2'000u);
    EXPECT_GT(st.watchdog_trips, 50u);
    EXPECT_GT(st.stale, 500u);
    EXPECT_GT(st.bad, 2'000u);
    EXPECT_GT(st.hold_caps, 20u);
    EXPECT_GT(st.replayed_fires, 1'000u);
  }
}

TEST(CoreBoardProperty, FewerDriversAndTheSameStreamGivesTheSameOutputs) {
  SafetyObserver a;
  SafetyObserver b;
  const StreamStats first = run_stream(11, 20'000, 3, a);
  const StreamStats again = run_stream(11, 20'000, 3, b);
  EXPECT_TRUE(a.violations.empty()) << a.violations.front();
  EXPECT_EQ(first.events_hash, again.events_hash) << "the core is deterministic";
  EXPECT_GT(first.switch_ons, 500u);
}

}  // namespace
