#include "pinball/sim/state_hash.h"

#include <cstring>

namespace pinball::sim {
namespace {

constexpr std::uint64_t kFnvOffset = 0xcbf29ce484222325ull;
constexpr std::uint64_t kFnvPrime = 0x100000001b3ull;

template <class T>
void mix(std::uint64_t& h, const T& value) {
  unsigned char bytes[sizeof(T)];
  std::memcpy(bytes, &value, sizeof(T));
  for (const unsigned char b : bytes) h = (h ^ b) * kFnvPrime;
}

}  // namespace

std::uint64_t hash_combine_state(std::uint64_t seed, const GameState& s) {
  std::uint64_t h = seed;
  mix(h, s.time_s);
  mix(h, s.steps);
  mix(h, s.ball.position_m.x());
  mix(h, s.ball.position_m.y());
  mix(h, s.ball.velocity_mps.x());
  mix(h, s.ball.velocity_mps.y());
  mix(h, s.ball_in_play);
  mix(h, s.balls_left);
  mix(h, s.score);
  for (const FlipperState& f : s.flippers) {
    mix(h, f.theta_rad);
    mix(h, f.omega_rad_s);
    mix(h, f.energized);
  }
  for (const std::uint8_t v : s.visible) mix(h, v);
  mix(h, s.rising_flags);
  return h;
}

std::uint64_t hash_state(const GameState& state) { return hash_combine_state(kFnvOffset, state); }

std::uint64_t hash_combine_ball_end(std::uint64_t seed, const BallResult& ball) {
  std::uint64_t h = seed;
  mix(h, ball.end_position_m.x());
  mix(h, ball.end_position_m.y());
  mix(h, ball.end_velocity_mps.x());
  mix(h, ball.end_velocity_mps.y());
  mix(h, ball.cut);
  return h;
}

}  // namespace pinball::sim
