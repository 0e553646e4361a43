#include "pinball/view/log_player.h"

#include <algorithm>
#include <optional>
#include <stdexcept>

#include "pinball/bus/channels.h"
#include "pinball/bus/message_convert.h"

namespace pinball::view {

LogPlayer::LogPlayer(std::vector<bus::LcmLogEvent> events, ViewStateOptions options)
    : events_(std::move(events)), options_(options), state_(options) {
  if (events_.empty()) throw std::invalid_argument("LogPlayer: the log has no events");
  auto daemon_utime = [](const bus::LcmLogEvent& e) -> std::optional<std::int64_t> {
    const bool daemon = std::ranges::find_if(bus::kDaemonChannels, [&](const char* c) { return e.channel == c; }) !=
                        bus::kDaemonChannels.end();
    if (!daemon) return std::nullopt;
    return bus::encoded_utime(e.data.data(), e.data.size()).value_or(e.utime);
  };
  // The clock starts at the daemon's first message; what comes before it (another program's) starts too.
  std::optional<std::int64_t> first;
  for (std::size_t i = 0; i < events_.size() && !first; ++i) first = daemon_utime(events_[i]);
  std::int64_t last = first.value_or(events_.front().utime);
  const std::int64_t start = last;
  times_s_.reserve(events_.size());
  for (const bus::LcmLogEvent& e : events_) {
    last = daemon_utime(e).value_or(first ? last : e.utime);
    times_s_.push_back(1e-6 * static_cast<double>(last - start));
    duration_s_ = std::max(duration_s_, times_s_.back());
  }
}

double LogPlayer::time_of(std::size_t i) const { return times_s_[i]; }

void LogPlayer::seek(double t_s) {
  t_s = std::clamp(t_s, 0.0, duration_s_);
  if (t_s < position_s_) {
    state_ = ViewState(options_);
    next_ = 0;
  }
  while (next_ < events_.size() && time_of(next_) <= t_s) {
    const bus::LcmLogEvent& e = events_[next_];
    state_.apply(e.channel, e.data.data(), e.data.size(), time_of(next_));
    ++next_;
  }
  position_s_ = t_s;
}

bool LogPlayer::step_frame_forward() {
  for (std::size_t i = next_; i < events_.size(); ++i) {
    if (events_[i].channel == bus::kObservationChannel) {
      seek(time_of(i));
      return true;
    }
  }
  return false;
}

bool LogPlayer::step_frame_back() {
  // The newest frame applied is the current one; go to the one before it.
  bool seen_current = false;
  for (std::size_t i = next_; i-- > 0;) {
    if (events_[i].channel != bus::kObservationChannel) continue;
    if (!seen_current) {
      seen_current = true;
      continue;
    }
    seek(time_of(i));
    return true;
  }
  return false;
}

}  // namespace pinball::view
