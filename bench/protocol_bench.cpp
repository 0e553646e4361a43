#include "protocol_bench.h"

#include <cstdio>
#include <vector>

#include "pinball/core/check.h"
#include "pinball/core/clock.h"
#include "pinball/core/statistics.h"
#include "pinball/firmware/driver_bus.h"
#include "pinball/firmware/stream_transport.h"
#include "pinball/simlab/faulty_link.h"
#include "pinball/firmware/coil_safety_monitor.h"
#include "pinball/firmware/protocol_rule_checker.h"
#include "pinball/firmware/virtual_driver_board.h"
#include "pinball/simlab/frame_fuzzer.h"

namespace pinball::bench {

using namespace firmware;

namespace {

// One seed's stream through a fresh board; adds to `r`.
void run_seed(std::uint64_t seed, const ProtocolBenchOptions& o, ProtocolBenchReport& r,
              const std::function<void(std::uint64_t)>& tick) {
  VirtualDriverBoardOptions bo;
  bo.driver_count = o.driver_count;
  VirtualDriverBoard board(bo);
  ProtocolRuleChecker checker(bo.board_id, o.driver_count);
  CoilSafetyMonitor monitor;  // the absolute caps of protocol.h: no Configure can lift them
  board.add_listener(&checker);
  board.add_listener(&monitor);
  simlab::FrameFuzzerOptions fo;
  fo.seed = seed;
  fo.driver_count = o.driver_count;
  simlab::FrameFuzzer fuzzer(fo);
  double t = 0.0;
  CanFrame out;
  for (std::uint64_t i = 0; i < o.frames; ++i) {
    double dt = 0.0;
    const CanFrame f = fuzzer.next(dt);
    t += dt;
    board.advance(t);
    checker.check_at(t);
    checker.before_frame(f, t);
    board.on_frame(f, t);
    checker.after_frame(t);
    while (board.pop_tx(out)) {
    }
    if ((i & 0xFFFF) == 0) tick(i);
  }
  monitor.finish(t);
  const BoardCounters& b = board.counters();
  r.frames += fuzzer.counters().frames;
  r.mutated += fuzzer.counters().mutated;
  r.noise += fuzzer.counters().noise;
  r.valid_frames += checker.valid_frames();
  r.bad_frames += b.bad_frames;
  r.switch_ons += checker.switch_ons();
  r.fires_accepted += b.fires_accepted;
  r.stale += b.stale;
  r.watchdog_trips += b.watchdog_trips;
  r.hold_cap_trips += b.hold_cap_trips;
  r.refused_locked += b.refused_locked;
  r.rule_violations += checker.violations();
  r.cap_violations += static_cast<std::uint64_t>(monitor.violations());
  if (r.first_violation.empty()) {
    r.first_violation = !checker.first_violation().empty() ? checker.first_violation() : monitor.first_violation();
    if (!r.first_violation.empty()) r.first_violation = "seed " + std::to_string(seed) + ": " + r.first_violation;
  }
  r.simulated_s += t;
}

// The baseline: the same frames through the codec alone.
double decode_only_rate(const ProtocolBenchOptions& o) {
  simlab::FrameFuzzerOptions fo;
  fo.seed = o.seed;
  fo.driver_count = o.driver_count;
  simlab::FrameFuzzer fuzzer(fo);
  std::vector<CanFrame> frames(static_cast<std::size_t>(std::min<std::uint64_t>(o.frames, 1'000'000)));
  double dt = 0.0;
  for (CanFrame& f : frames) f = fuzzer.next(dt);
  std::uint64_t ok = 0;
  const double t0 = steady_now_s();
  for (const CanFrame& f : frames) ok += decode(f).ok() ? 1 : 0;
  const double elapsed = steady_now_s() - t0;
  return elapsed > 0.0 && ok <= frames.size() ? static_cast<double>(frames.size()) / elapsed : 0.0;
}

}  // namespace

ReleaseUnderLoss measure_release_under_loss(double drop_p, bool closed_loop, int cycles, std::uint64_t seed) {
  // Named, not a structured binding: the lambda below captures board_end, which
  // clang before 16 cannot parse (C++20 P1091), and clang-tidy reads this file.
  const auto [host_end, board_end_ptr] = StreamTransport::make_pair();
  StreamTransport& board_end = *board_end_ptr;
  VirtualDriverBoard board;
  CoilSafetyMonitor monitor;
  board.add_listener(&monitor);
  simlab::FaultyLinkOptions lo;
  lo.drop_p = drop_p;
  lo.on_receive = true;
  lo.seed = seed;
  simlab::FaultyLink lossy(*host_end, lo);
  DriverBusOptions o;
  o.driver_count = 2;
  o.watchdog_timeout_s = 0.2;  // a lost heartbeat or two must not trip it
  o.verify_coils = closed_loop;
  DriverBus bus(lossy, o);
  double t = 0.0;
  auto tick = [&] {
    t += 0.001;
    bus.poll_once(t);
    board.service(board_end, t);
  };
  for (int k = 0; k < 100; ++k) tick();
  std::vector<double> on_after_release_s;
  for (int c = 0; c < cycles; ++c) {
    const int d = c % 2;
    bus.fire(d);
    for (int k = 0; k < 60; ++k) tick();  // pulse, then hold
    bus.release(d);
    const double released_at = t;
    while (board.coil(d).state != CoilState::kOff && t < released_at + 20.0) tick();
    on_after_release_s.push_back(board.coil(d).state == CoilState::kOff ? board.coil(d).since_s - released_at : 20.0);
    for (int k = 0; k < 20; ++k) tick();
  }
  monitor.finish(t);
  ReleaseUnderLoss r;
  r.drop_p = drop_p;
  r.closed_loop = closed_loop;
  r.cycles = cycles;
  r.p50_s = quantile(on_after_release_s, 0.5);
  r.p99_s = quantile(on_after_release_s, 0.99);
  r.worst_s = quantile(on_after_release_s, 1.0);
  r.frames_dropped = lossy.fault_counters().dropped;
  r.release_retries = bus.counters().release_retries;
  r.release_escalations = bus.counters().release_escalations;
  r.cap_violations = static_cast<std::uint64_t>(monitor.violations());
  return r;
}

ProtocolBenchReport run_protocol_bench(const ProtocolBenchOptions& o,
                                       const std::function<void(const std::string&)>& progress) {
  check_input(o.frames >= 1, "ProtocolBenchOptions", "frames must be >= 1");
  check_input(o.seeds >= 1, "ProtocolBenchOptions", "seeds must be >= 1");
  ProtocolBenchReport r;
  const std::uint64_t total = o.frames * static_cast<std::uint64_t>(o.seeds);
  const double t0 = steady_now_s();
  std::uint64_t done_before = 0;
  int next_decile = 1;
  auto tick = [&](std::uint64_t i) {
    const std::uint64_t done = done_before + i;
    if (!progress || done * 10 < total * static_cast<std::uint64_t>(next_decile)) return;
    const double elapsed = steady_now_s() - t0;
    char line[120];
    std::snprintf(line, sizeof line, "%d %% of %llu frames, ETA %.1f s", next_decile * 10,
                  static_cast<unsigned long long>(total), elapsed * (static_cast<double>(total) / done - 1.0));
    progress(line);
    ++next_decile;
  };
  for (int s = 0; s < o.seeds; ++s) {
    run_seed(o.seed + static_cast<std::uint64_t>(s), o, r, tick);
    done_before += o.frames;
  }
  const double elapsed = steady_now_s() - t0;
  r.frames_per_s = elapsed > 0.0 ? static_cast<double>(r.frames) / elapsed : 0.0;
  r.decode_only_frames_per_s = decode_only_rate(o);
  for (const double drop : {0.01, 0.05}) {
    for (const bool closed_loop : {true, false}) {
      if (progress) progress("release under " + std::to_string(static_cast<int>(drop * 100)) + " % loss, closed loop " +
                             (closed_loop ? "on" : "off"));
      r.release_under_loss.push_back(measure_release_under_loss(drop, closed_loop, o.release_cycles, o.seed));
    }
  }
  return r;
}

nlohmann::json to_json(const ProtocolBenchReport& r) {
  return {{"benchmark", "protocol"},
          {"frames", r.frames},
          {"mutated", r.mutated},
          {"noise", r.noise},
          {"valid_frames", r.valid_frames},
          {"bad_frames", r.bad_frames},
          {"switch_ons", r.switch_ons},
          {"fires_accepted", r.fires_accepted},
          {"stale", r.stale},
          {"watchdog_trips", r.watchdog_trips},
          {"hold_cap_trips", r.hold_cap_trips},
          {"refused_locked", r.refused_locked},
          {"rule_violations", r.rule_violations},
          {"cap_violations", r.cap_violations},
          {"first_violation", r.first_violation},
          {"simulated_s", r.simulated_s},
          {"frames_per_s", r.frames_per_s},
          {"decode_only_frames_per_s", r.decode_only_frames_per_s},
          {"release_under_loss", [&] {
             nlohmann::json a = nlohmann::json::array();
             for (const ReleaseUnderLoss& x : r.release_under_loss) {
               a.push_back({{"drop_p", x.drop_p}, {"closed_loop", x.closed_loop}, {"cycles", x.cycles},
                            {"p50_s", x.p50_s}, {"p99_s", x.p99_s}, {"worst_s", x.worst_s},
                            {"frames_dropped", x.frames_dropped}, {"release_retries", x.release_retries},
                            {"release_escalations", x.release_escalations}, {"cap_violations", x.cap_violations}});
             }
             return a;
           }()}};
}

}  // namespace pinball::bench
