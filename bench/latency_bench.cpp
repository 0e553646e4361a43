#include "latency_bench.h"

#include <sys/socket.h>
#include <linux/can.h>
#include <poll.h>

#include <algorithm>
#include <chrono>
#include <stdexcept>
#include <vector>

#include "pinball/core/statistics.h"
#include "pinball/firmware/codec.h"
#include "pinball/firmware/coil_safety_monitor.h"
#include "pinball/firmware/driver_bus.h"
#include "pinball/firmware/stream_transport.h"
#include "pinball/firmware/virtual_driver_board.h"

namespace pinball::bench {
namespace {

using Clock = std::chrono::steady_clock;
namespace fw = pinball::firmware;

double now_s() { return std::chrono::duration<double>(Clock::now().time_since_epoch()).count(); }

// Board side: serve frames until `done` or the deadline (s).
template <typename Done>
bool serve(fw::VirtualDriverBoard& board, fw::StreamTransport& link, double deadline, Done done) {
  while (now_s() < deadline) {
    fw::CanFrame f;
    if (link.receive(f, 1) == fw::RxStatus::kFrame) board.on_frame(f, now_s());
    board.service(link, now_s());
    if (done()) return true;
  }
  return false;
}

}  // namespace

LatencyReport run_latency_bench(const LatencyBenchOptions& options,
                                const std::function<void(const std::string&)>& progress) {
  if (options.samples < 1 || options.codec_frames < 1 || options.baseline_samples < 1) {
    throw std::invalid_argument("LatencyBenchOptions: samples, codec_frames and baseline_samples must be >= 1");
  }
  LatencyReport r;
  auto say = [&](const std::string& s) {
    if (progress) progress(s);
  };

  // 1. fire() -> coil output through the whole stack.
  {
    auto [host, link] = fw::StreamTransport::make_pair();
    fw::VirtualDriverBoard board;
    fw::CoilSafetyMonitor monitor;
    board.add_listener(&monitor);
    fw::DriverBusOptions o;
    o.driver_count = 1;
    o.drivers[0].recycle_ms = 0;  // back-to-back samples
    fw::DriverBus bus(*host, o);
    board.advance(now_s());
    bus.start();
    if (!serve(board, *link, now_s() + 2.0, [&] { return bus.state() == fw::BusState::kRunning; })) {
      throw std::runtime_error("bench latency: the bus did not reach kRunning within 2 s");
    }
    std::vector<double> lat_us;
    lat_us.reserve(static_cast<std::size_t>(options.samples));
    for (int i = 0; i < options.samples; ++i) {
      const double t0 = now_s();
      bus.fire(0);
      const double t1 = now_s();
      r.fire_call_max_us = std::max(r.fire_call_max_us, (t1 - t0) * 1e6);
      if (!serve(board, *link, t0 + 0.5, [&] { return board.coil(0).state != fw::CoilState::kOff; })) {
        throw std::runtime_error("bench latency: a fire did not reach the coil within 0.5 s");
      }
      lat_us.push_back((board.coil(0).since_s - t0) * 1e6);
      bus.release(0);
      serve(board, *link, now_s() + 0.5, [&] { return board.coil(0).state == fw::CoilState::kOff; });
    }
    bus.stop();
    monitor.finish(now_s());
    r.samples = options.samples;
    r.fire_to_coil_p50_us = quantile(lat_us, 0.50);
    r.fire_to_coil_p99_us = quantile(lat_us, 0.99);
    r.fire_to_coil_max_us = *std::max_element(lat_us.begin(), lat_us.end());
    r.coil_violations = static_cast<std::uint64_t>(monitor.violations());
    say("fire -> coil: p50 " + std::to_string(r.fire_to_coil_p50_us) + " us, p99 " +
        std::to_string(r.fire_to_coil_p99_us) + " us");
  }

  // 2. Baseline: one raw 16-byte frame written and read on a socketpair, same thread.
  {
    auto [a, b] = fw::StreamTransport::make_pair();
    std::vector<double> raw_us;
    raw_us.reserve(static_cast<std::size_t>(options.baseline_samples));
    can_frame out{};
    out.can_id = 0x120;
    out.len = 6;
    can_frame in{};
    for (int i = 0; i < options.baseline_samples; ++i) {
      const double t0 = now_s();
      if (::send(a->fd(), &out, sizeof out, MSG_DONTWAIT) != static_cast<ssize_t>(sizeof out)) {
        throw std::runtime_error("bench latency: baseline send failed");
      }
      pollfd p{b->fd(), POLLIN, 0};
      (void)::poll(&p, 1, 100);
      if (::recv(b->fd(), &in, sizeof in, MSG_DONTWAIT) != static_cast<ssize_t>(sizeof in)) {
        throw std::runtime_error("bench latency: baseline recv failed");
      }
      raw_us.push_back((now_s() - t0) * 1e6);
    }
    r.raw_p50_us = quantile(raw_us, 0.50);
    r.raw_p99_us = quantile(raw_us, 0.99);
    r.stack_overhead_ratio = r.raw_p50_us > 0.0 ? r.fire_to_coil_p50_us / r.raw_p50_us : 0.0;
    say("raw socketpair frame: p50 " + std::to_string(r.raw_p50_us) + " us");
  }

  // 3. Codec cost per frame, against copying the frame and touching its bytes.
  {
    std::uint64_t sink = 0;
    const auto t0 = Clock::now();
    for (int i = 0; i < options.codec_frames; ++i) {
      const fw::CanFrame f = fw::encode(0, fw::Fire{static_cast<std::uint8_t>(i & 7), fw::FireMode::kPulseHold, 0,
                                                    static_cast<std::uint16_t>(i)});
      const fw::DecodeResult d = fw::decode(f);
      sink += d.ok() ? std::get<fw::Fire>(d.message.payload).seq : 1u;
    }
    const auto t1 = Clock::now();
    fw::CanFrame f = fw::encode(0, fw::Fire{});
    for (int i = 0; i < options.codec_frames; ++i) {
      f.data[0] = static_cast<std::uint8_t>(i);
      fw::CanFrame copy = f;
      asm volatile("" : : "r"(&copy) : "memory");  // the copy really happens
      std::uint64_t s = 0;
      for (int k = 0; k < 8; ++k) s += copy.data[static_cast<std::size_t>(k)];
      sink += s;
    }
    const auto t2 = Clock::now();
    r.encode_decode_ns = std::chrono::duration<double, std::nano>(t1 - t0).count() / options.codec_frames;
    r.copy_baseline_ns = std::chrono::duration<double, std::nano>(t2 - t1).count() / options.codec_frames;
    if (sink == 42) say("");  // keeps `sink` alive
    say("encode+decode: " + std::to_string(r.encode_decode_ns) + " ns/frame");
  }
  return r;
}

nlohmann::json to_json(const LatencyReport& r) {
  return {{"benchmark", "latency"},
          {"transport", "stream (AF_UNIX SOCK_SEQPACKET socketpair)"},
          {"samples", r.samples},
          {"fire_to_coil_p50_us", r.fire_to_coil_p50_us},
          {"fire_to_coil_p99_us", r.fire_to_coil_p99_us},
          {"fire_to_coil_max_us", r.fire_to_coil_max_us},
          {"fire_call_max_us", r.fire_call_max_us},
          {"raw_frame_p50_us", r.raw_p50_us},
          {"raw_frame_p99_us", r.raw_p99_us},
          {"stack_overhead_ratio", r.stack_overhead_ratio},
          {"encode_decode_ns_per_frame", r.encode_decode_ns},
          {"copy_baseline_ns_per_frame", r.copy_baseline_ns},
          {"coil_violations", r.coil_violations}};
}

}  // namespace pinball::bench
