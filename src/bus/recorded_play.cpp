#include "pinball/bus/recorded_play.h"

#include <algorithm>
#include <bit>
#include <map>
#include <set>
#include <stdexcept>
#include <tuple>

#include "pinball/bus/channels.h"
#include "pinball/bus/lcm_log_format.h"
#include "pinball/bus/message_convert.h"
#include "pinball/core/format.h"
#include "pinball/core/utime.h"
#include "pinball_lcm/lcmt_pinball_flipper_command.hpp"
#include "pinball_lcm/lcmt_pinball_observation.hpp"

namespace pinball::bus {
namespace {

// "A (12), B (3)": what a log holds, for the message that says what it lacks.
std::string describe_channels(const std::map<std::string, std::uint64_t>& counts) {
  if (counts.empty()) return "no messages";
  std::string text;
  for (const auto& [channel, n] : counts) {
    if (!text.empty()) text += ", ";
    text += channel + " (" + std::to_string(n) + ")";
  }
  return text;
}

template <class Message>
bool decode(const LcmLogEvent& e, Message& m) {
  return m.decode(e.data.data(), 0, static_cast<int>(e.data.size())) == static_cast<int>(e.data.size());
}

}  // namespace

void check_one_run(const std::string& path, RunClock& clock, double t_s, std::int64_t seq) {
  // More than any interleaving of the daemon's threads, less than any run.
  constexpr double kAppendedRunGap_s = 1.0;
  if (t_s < clock.latest_s - kAppendedRunGap_s) {
    if (t_s >= clock.before_latest_s - kAppendedRunGap_s) {  // back in step: the one frame before leapt alone
      throw std::runtime_error(path + ": the PINBALL_OBSERVATION of frame " + std::to_string(clock.latest_seq) +
                               " is stamped " + format_number(clock.latest_s - t_s) +
                               " s ahead of the frames around it: a damaged timestamp");
    }
    throw std::runtime_error(path + ": its clock goes back " + format_number(clock.latest_s - t_s) +
                             " s at the PINBALL_OBSERVATION of frame " + std::to_string(seq) +
                             ": several runs appended to one log (mode=a)? Record each run to a file of its own");
  }
  if (t_s > clock.latest_s) {
    clock.before_latest_s = clock.latest_s;
    clock.latest_s = t_s;
    clock.latest_seq = seq;
  }
}

void check_log_holds_one_run(const std::string& path, const std::vector<LcmLogEvent>& events) {
  RunClock clock;
  for (const LcmLogEvent& e : events) {
    if (e.channel != kObservationChannel) continue;
    pinball_lcm::lcmt_pinball_observation m;
    if (decode_observation(e.data.data(), e.data.size(), m) == ObservationLayout::kMalformed || m.utime < 0) continue;
    check_one_run(path, clock, from_utime(m.utime), m.seq);
  }
}

RecordedPlay read_recorded_play(const std::string& path) {
  const std::vector<LcmLogEvent> events = read_lcm_log(path);  // refuses empty, non-LCM and damaged logs
  RecordedPlay play;
  play.source = path;
  std::map<std::string, std::uint64_t> channel_counts;
  std::uint64_t observation_messages = 0, command_messages = 0, sightings = 0;
  // Messages that decode but fail the check: of our type, with a bad field (not "another type").
  std::uint64_t observations_decoded = 0, commands_decoded = 0;
  auto left_out = [&](const std::string& channel, std::uint64_t nth, std::size_t event, const char* why) {
    if (play.malformed++ == 0) {
      play.first_malformed =
          channel + " message " + std::to_string(nth) + " (log event " + std::to_string(event + 1) + "): " + why;
    }
  };
  RunClock frame_clock;
  for (std::size_t i = 0; i < events.size(); ++i) {
    const LcmLogEvent& e = events[i];
    ++channel_counts[e.channel];
    if (e.channel == kObservationChannel) {
      ++observation_messages;
      pinball_lcm::lcmt_pinball_observation m;
      bool found = false;
      track::Observation o;
      track::ContactSensors contacts;
      if (decode_observation(e.data.data(), e.data.size(), m) == ObservationLayout::kMalformed) {
        left_out(e.channel, observation_messages, i, "does not decode as lcmt_pinball_observation");
        continue;
      }
      ++observations_decoded;
      if (!from_lcm_observation(m, found, o, contacts)) {
        left_out(e.channel, observation_messages, i, observation_fault(m));
        continue;
      }
      check_one_run(path, frame_clock, o.t_s, m.seq);
      play.frames.push_back({o.t_s, m.seq, found, o.p_board, contacts.left, contacts.right});
      sightings += found ? 1 : 0;
    } else if (e.channel == kFlipperCommandChannel) {
      ++command_messages;
      pinball_lcm::lcmt_pinball_flipper_command m;
      if (!decode(e, m)) {
        left_out(e.channel, command_messages, i, "does not decode as lcmt_pinball_flipper_command");
        continue;
      }
      ++commands_decoded;
      if (!valid_flipper_command(m)) {
        left_out(e.channel, command_messages, i, flipper_command_fault(m));
        continue;
      }
      play.commands.push_back({from_utime(m.utime), m.flipper, m.energize != 0, m.cause});
    }
  }
  const std::string has = " (it has " + describe_channels(channel_counts) + ")";
  if (observation_messages == 0)
    throw std::runtime_error(path + ": no " + kObservationChannel + " messages: the camera's sightings are missing" + has);
  if (command_messages == 0)
    throw std::runtime_error(path + ": no " + kFlipperCommandChannel + " messages: the coil commands are missing" + has);
  // None usable: another type on the channel when none decodes, else our type with bad fields.
  auto none_usable = [&](const std::string& channel, std::uint64_t messages, std::uint64_t decoded,
                         const char* type) {
    const std::string of = path + ": none of its " + std::to_string(messages) + " " + channel + " messages ";
    if (decoded == 0) return std::runtime_error(of + "decodes as " + type + " (another type?)");
    return std::runtime_error(of + "is well formed (first: " + play.first_malformed + ")");
  };
  if (play.frames.empty())
    throw none_usable(kObservationChannel, observation_messages, observations_decoded, "lcmt_pinball_observation");
  if (play.commands.empty())
    throw none_usable(kFlipperCommandChannel, command_messages, commands_decoded, "lcmt_pinball_flipper_command");
  if (sightings == 0) throw std::runtime_error(path + ": no frame of its " + std::to_string(play.frames.size()) +
                                               " saw the ball");
  // A log keeps the order messages were written in; threads may interleave.
  std::stable_sort(play.frames.begin(), play.frames.end(), [](const auto& a, const auto& b) { return a.t_s < b.t_s; });
  std::stable_sort(play.commands.begin(), play.commands.end(),
                   [](const auto& a, const auto& b) { return a.t_s < b.t_s; });
  return play;
}

SharedSightings shared_sightings(const RecordedPlay& a, const RecordedPlay& b) {
  // Exact doubles are the point: a copy keeps them bit for bit, another run never does.
  using Key = std::tuple<std::int64_t, std::uint64_t, std::uint64_t, std::uint64_t>;
  const auto key = [](const RecordedFrame& f) {
    return Key{f.seq, std::bit_cast<std::uint64_t>(f.t_s), std::bit_cast<std::uint64_t>(f.p_board.x()),
               std::bit_cast<std::uint64_t>(f.p_board.y())};
  };
  const auto for_each_moving = [](const RecordedPlay& play, const auto& visit) {
    std::size_t count = 0;
    for (std::size_t i = 1; i < play.frames.size(); ++i) {
      const RecordedFrame& f = play.frames[i];
      const RecordedFrame& before = play.frames[i - 1];
      if (!f.found || !before.found || f.p_board == before.p_board) continue;
      ++count;
      visit(f);
    }
    return count;
  };
  SharedSightings s;
  std::set<Key> in_b;
  s.moving_b = for_each_moving(b, [&](const RecordedFrame& f) { in_b.insert(key(f)); });
  s.moving_a = for_each_moving(a, [&](const RecordedFrame& f) {
    if (!in_b.contains(key(f))) return;
    if (s.shared++ == 0) {
      s.first_seq = f.seq;
      s.first_t_s = f.t_s;
    }
  });
  return s;
}

std::string recorded_play_log(const RecordedPlay& play) {
  std::string log;
  std::int64_t event = 0;
  std::size_t f = 0, c = 0;
  while (f < play.frames.size() || c < play.commands.size()) {
    const bool frame_next =
        c == play.commands.size() || (f < play.frames.size() && play.frames[f].t_s <= play.commands[c].t_s);
    if (frame_next) {
      const RecordedFrame& r = play.frames[f++];
      track::Observation o{r.t_s, r.p_board, r.found ? 1.0 : 0.0, 0.0};
      auto m = to_lcm_observation(to_utime(r.t_s), to_utime(r.t_s), r.seq, r.found, o, 0.0, 0.0,
                                  {r.contact_left, r.contact_right});
      const std::vector<std::uint8_t> data = encode_message(m);
      append_lcm_event(log, event++, m.utime, kObservationChannel, data.data(), data.size());
    } else {
      const RecordedCommand& r = play.commands[c];
      auto m = to_lcm_flipper_command(to_utime(r.t_s), static_cast<std::int64_t>(c), -1,
                                      r.flipper, r.energize, static_cast<std::int8_t>(r.cause));
      ++c;
      const std::vector<std::uint8_t> data = encode_message(m);
      append_lcm_event(log, event++, m.utime, kFlipperCommandChannel, data.data(), data.size());
    }
  }
  return log;
}

}  // namespace pinball::bus
