#include "protocol_bench.h"

#include <cstdio>
#include <vector>

#include "pinball/core/check.h"
#include "pinball/core/clock.h"
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
  return r;
}

nlohmann::json to_json(const ProtocolBenchReport& r) {
  return {{"frames", r.frames},
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
          {"decode_only_frames_per_s", r.decode_only_frames_per_s}};
}

}  // namespace pinball::bench
