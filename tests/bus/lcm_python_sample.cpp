// Writes two messages encoded by the generated C++ types into a folder, for
// lcm_python_decode_test.py to decode with the generated Python bindings:
// the fingerprints and the fields must agree across the two languages.
// Usage: lcm_python_sample DIR

#include <cstdio>
#include <fstream>
#include <string>
#include <vector>

#include "pinball_lcm/lcmt_pinball_flipper_command.hpp"
#include "pinball_lcm/lcmt_pinball_game_event.hpp"

namespace {

template <class Message>
bool write_encoded(const Message& m, const std::string& path) {
  std::vector<char> bytes(static_cast<std::size_t>(m.getEncodedSize()));
  if (m.encode(bytes.data(), 0, static_cast<int>(bytes.size())) != static_cast<int>(bytes.size())) return false;
  std::ofstream out(path, std::ios::binary);
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  return static_cast<bool>(out);
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fputs("usage: lcm_python_sample DIR\n", stderr);
    return 2;
  }
  const std::string dir = argv[1];
  pinball_lcm::lcmt_pinball_game_event event{};
  event.utime = 1'234'567'890'123;
  event.seq = 42;
  event.kind = pinball_lcm::lcmt_pinball_game_event::KIND_SCORE;
  event.ball = 7;
  event.points = 250.5;
  event.ball_time_s = 3.25;
  pinball_lcm::lcmt_pinball_flipper_command command{};
  command.utime = -5;
  command.seq = 9;
  command.projection_seq = -1;
  command.flipper = 1;
  command.energize = true;
  command.cause = pinball_lcm::lcmt_pinball_flipper_command::CAUSE_CAMERA_STALL;
  if (!write_encoded(event, dir + "/game_event.bin") || !write_encoded(command, dir + "/flipper_command.bin")) {
    std::fputs("lcm_python_sample: cannot write the samples\n", stderr);
    return 1;
  }
  return 0;
}
