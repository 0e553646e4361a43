#include "daemon_latency_bench.h"

#include <algorithm>
#include <atomic>
#include <thread>
#include <vector>

#include "pinball/core/statistics.h"
#include "pinball/core/clock.h"
#include "pinball/daemon/doorbell.h"

namespace pinball::bench {
namespace {

DaemonLatencyRun run_once(const DaemonLatencyOptions& o, bool realtime, const daemon::ThreadSettings& threads) {
  daemon::DaemonConfig c;
  c.threads = threads;
  c.sim.board = o.board;
  c.controller = o.controller;
  c.sim.seed = o.seed;
  c.sim.realtime = realtime;
  c.sim.balls = realtime ? 1'000'000 : o.lockstep_balls;
  daemon::Daemon d(c);
  std::atomic<bool> done{false};
  std::thread stopper;
  if (realtime) {
    stopper = std::thread([&] {
      // The window opens at the first frame, not at the call: a slow start-up (a sanitizer
      // build on a loaded machine) once used the whole window and left no frame to measure.
      const double give_up = steady_now_s() + 120.0;
      while (!done.load() && d.snapshot().frames == 0 && steady_now_s() < give_up) {
        std::this_thread::sleep_for(std::chrono::milliseconds(10));
      }
      const double end = steady_now_s() + o.realtime_s;
      while (!done.load() && steady_now_s() < end) std::this_thread::sleep_for(std::chrono::milliseconds(10));
      d.request_stop();
    });
  }
  const daemon::DaemonReport r = d.run();
  done = true;
  if (stopper.joinable()) stopper.join();
  DaemonLatencyRun run;
  run.stages = r.latency;
  run.frames = r.frames;
  run.dropped = r.frames_dropped;
  run.wall_s = r.wall_s;
  run.sim_s = r.sim_s;
  run.cpus = r.cpus;
  run.warnings = r.warnings;
  return run;
}

// One thread rings, the other wakes: the cost of one hand-off between the daemon's threads.
void doorbell_baseline(int samples, double& p50_us, double& p99_us) {
  daemon::Doorbell ping, pong;
  std::atomic<double> rung_at{0.0};
  std::vector<double> lat;
  lat.reserve(static_cast<std::size_t>(samples));
  std::thread waiter([&] {
    for (int i = 0; i < samples; ++i) {
      ping.wait(1.0);
      lat.push_back((steady_now_s() - rung_at.load()) * 1e6);
      pong.ring();
    }
  });
  for (int i = 0; i < samples; ++i) {
    std::this_thread::sleep_for(std::chrono::microseconds(200));  // let the waiter fall asleep, as between frames
    rung_at = steady_now_s();
    ping.ring();
    pong.wait(1.0);
  }
  waiter.join();
  p50_us = quantile(lat, 0.5);
  p99_us = quantile(lat, 0.99);
}

nlohmann::json run_json(const DaemonLatencyRun& r) {
  nlohmann::json stages = nlohmann::json::object();
  for (int s = 0; s < daemon::kStageCount; ++s) {
    stages[daemon::stage_name(s)] = daemon::latency_to_json(r.stages[static_cast<std::size_t>(s)]);
  }
  // No command, no latency: null, not 0 us.
  const nlohmann::json e2e = daemon::latency_to_json(r.stages[daemon::kFrameToCan]);
  return {{"frame_to_can_p50_us", e2e["p50_us"]}, {"frame_to_can_p99_us", e2e["p99_us"]},
          {"frame_to_can_max_us", e2e["max_us"]}, {"frame_to_can_samples", e2e["count"]},
          {"frames", r.frames}, {"frames_dropped", r.dropped}, {"wall_s", r.wall_s}, {"sim_s", r.sim_s},
          {"cpus", r.cpus}, {"warnings", r.warnings}, {"stages", stages}};
}

}  // namespace

DaemonLatencyReport run_daemon_latency_bench(const DaemonLatencyOptions& options,
                                             const std::function<void(const std::string&)>& progress) {
  DaemonLatencyReport r;
  r.controller = options.controller;
  if (progress) progress("baseline: eventfd wake-up between two threads");
  doorbell_baseline(options.baseline_samples, r.wake_p50_us, r.wake_p99_us);
  const daemon::ThreadSettings defaults;
  daemon::ThreadSettings unpinned;
  unpinned.chain_cpu = "off";
  daemon::ThreadSettings idle_poll;
  idle_poll.cpu_dma_latency_us = 0;
  const std::string balls = std::to_string(options.lockstep_balls);
  const std::string secs = std::to_string(static_cast<int>(options.realtime_s));
  if (progress) progress("pinballd lockstep, " + balls + " balls, chain on one CPU (default)");
  r.lockstep = run_once(options, false, defaults);
  if (progress) progress("pinballd lockstep, " + balls + " balls, threads free to move (baseline)");
  r.lockstep_unpinned = run_once(options, false, unpinned);
  if (progress) progress("pinballd paced to the wall clock, " + secs + " s (default)");
  r.realtime = run_once(options, true, defaults);
  if (progress) progress("pinballd paced to the wall clock, " + secs + " s, idle cores polling");
  r.realtime_idle_poll = run_once(options, true, idle_poll);
  return r;
}

nlohmann::json to_json(const DaemonLatencyReport& r) {
  return {{"fps", r.fps},
          {"controller", r.controller},
          {"lockstep", run_json(r.lockstep)},
          {"lockstep_unpinned", run_json(r.lockstep_unpinned)},
          {"realtime", run_json(r.realtime)},
          {"realtime_idle_poll", run_json(r.realtime_idle_poll)},
          {"baseline_wake_p50_us", r.wake_p50_us},
          {"baseline_wake_p99_us", r.wake_p99_us},
          {"target_frame_to_can_p99_us", 1000.0}};
}

}  // namespace pinball::bench
