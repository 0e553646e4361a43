#include "pinball/view/log_player.h"

#include <algorithm>
#include <stdexcept>

#include "pinball/bus/channels.h"

namespace pinball::view {

LogPlayer::LogPlayer(std::vector<bus::LcmLogEvent> events, ViewStateOptions options)
    : events_(std::move(events)), options_(options), state_(options) {
  if (events_.empty()) throw std::invalid_argument("LogPlayer: the log has no events");
  for (std::size_t i = 0; i < events_.size(); ++i) duration_s_ = std::max(duration_s_, time_of(i));
}

double LogPlayer::time_of(std::size_t i) const { return 1e-6 * static_cast<double>(events_[i].utime - events_[0].utime); }

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
