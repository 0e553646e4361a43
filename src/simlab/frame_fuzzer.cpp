#include "pinball/simlab/frame_fuzzer.h"

#include "pinball/core/check.h"
#include "pinball/firmware/codec.h"

namespace pinball::simlab {

using namespace firmware;

FrameFuzzer::FrameFuzzer(FrameFuzzerOptions options) : options_(options), rng_(options.seed) {
  auto probability = [](double p) { return p >= 0.0 && p <= 1.0; };
  check_input(probability(options.mutate_p) && probability(options.noise_p), "FrameFuzzerOptions",
              "mutate_p and noise_p must be in [0, 1]");
  check_input(options.board_id < kMaxBoards, "FrameFuzzerOptions", "board_id must be 0..15");
  check_input(options.driver_count >= 1 && options.driver_count <= kMaxDrivers, "FrameFuzzerOptions",
              "driver_count must be 1..8");
}

// Mostly the next number; sometimes an old one (a duplicate, a replay) or any.
std::uint16_t FrameFuzzer::next_seq() {
  const double u = rng_.uniform01();
  if (u < 0.05) return static_cast<std::uint16_t>(seq_ - below(50));
  if (u < 0.07) return static_cast<std::uint16_t>(rng_.next_u64());
  return ++seq_;
}

// Bursts of frames within a millisecond, gaps of a few frames, and now and
// then a silence long enough for the watchdog, a pulse or a hold cap.
double FrameFuzzer::time_step_s() {
  const double u = rng_.uniform01();
  if (u < 0.70) return rng_.uniform(0.0, 0.002);
  if (u < 0.95) return rng_.uniform(0.002, 0.03);
  return rng_.uniform(0.03, 0.6);
}

CanFrame FrameFuzzer::plausible() {
  const auto driver = static_cast<std::uint8_t>(below(options_.driver_count + 1));  // one past the last, too
  const double u = rng_.uniform01();
  Payload p;
  if (u < 0.35) {
    p = Heartbeat{kProtocolVersion, next_seq()};
  } else if (u < 0.55) {
    const std::uint8_t pulse = rng_.uniform01() < 0.8 ? 0 : static_cast<std::uint8_t>(below(kAbsMaxPulseMs + 1));
    p = Fire{driver, below(2) == 0 ? FireMode::kPulseOnly : FireMode::kPulseHold, pulse, next_seq()};
  } else if (u < 0.67) {
    p = Release{driver, next_seq()};
  } else if (u < 0.70) {
    p = ReleaseAll{next_seq()};
  } else if (u < 0.80) {
    DriverConfig c;
    c.max_pulse_ms = static_cast<std::uint8_t>(1 + below(kAbsMaxPulseMs));
    c.pulse_ms = static_cast<std::uint8_t>(1 + below(c.max_pulse_ms));
    c.hold_duty_pct = static_cast<std::uint8_t>(below(kAbsMaxHoldDutyPct + 1));
    c.max_hold_ms = static_cast<std::uint16_t>(rng_.uniform01() < 0.7 ? 1 + below(500) : 1 + below(kAbsMaxHoldMs));
    c.recycle_ms = static_cast<std::uint8_t>(below(256));
    p = Configure{driver, c};
  } else if (u < 0.83) {
    p = Hello{kProtocolVersion, static_cast<std::uint16_t>(kMinWatchdogMs + below(kMaxWatchdogMs - kMinWatchdogMs + 1))};
  } else if (u < 0.86) {
    p = Status{};  // a board -> host kind sent to the board
  } else {
    // The rest: keep the board armed and fed with Fires, the common case.
    p = below(2) == 0 ? Payload{Heartbeat{kProtocolVersion, next_seq()}}
                      : Payload{Fire{driver, FireMode::kPulseHold, 0, next_seq()}};
  }
  const std::uint8_t board = rng_.uniform01() < 0.03 ? static_cast<std::uint8_t>((options_.board_id + 1) % kMaxBoards)
                                                     : options_.board_id;
  return encode(board, p);
}

CanFrame FrameFuzzer::next(double& dt_s) {
  dt_s = time_step_s();
  ++counters_.frames;
  CanFrame f;
  if (rng_.uniform01() < options_.noise_p) {
    ++counters_.noise;
    f.id = kIdBase | static_cast<std::uint32_t>(below(256));
    f.len = static_cast<std::uint8_t>(below(kMaxFrameBytes + 1));
    for (int i = 0; i < f.len; ++i) f.data[static_cast<std::size_t>(i)] = static_cast<std::uint8_t>(below(256));
  } else {
    f = plausible();
    if (rng_.uniform01() >= options_.mutate_p) return f;
    ++counters_.mutated;
    const int flips = 1 + below(3);
    for (int k = 0; k < flips; ++k) {
      const int bit = below(11 + 4 + 8 * f.len);
      if (bit < 11) {
        f.id ^= 1u << bit;
      } else if (bit < 15) {
        f.len = static_cast<std::uint8_t>((f.len ^ (1u << (bit - 11))) % (kMaxFrameBytes + 1));
      } else {
        f.data[static_cast<std::size_t>((bit - 15) / 8)] ^= static_cast<std::uint8_t>(1u << ((bit - 15) % 8));
      }
    }
  }
  // Half the damaged frames carry a correct CRC, so that decoding gets past it.
  if (f.len > 0 && below(2) == 0) {
    f.data[static_cast<std::size_t>(f.len - 1)] =
        frame_crc(f.id, std::span<const std::uint8_t>(f.data.data(), static_cast<std::size_t>(f.len - 1)));
  }
  return f;
}

}  // namespace pinball::simlab
