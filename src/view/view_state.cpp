#include "pinball/view/view_state.h"

#include <algorithm>
#include <cmath>
#include <cstring>

#include "pinball/bus/channels.h"
#include "pinball/bus/message_convert.h"
#include "pinball_lcm/lcmt_pinball_observation.hpp"

namespace pinball::view {
namespace {

template <class T>
bool decode(const void* data, std::size_t size, T& m) {
  return size <= 0x7fffffffu && m.decode(data, 0, static_cast<int>(size)) >= 0;
}

}  // namespace

ViewState::ViewState(ViewStateOptions options) : options_(options) {}

bool ViewState::apply(std::string_view channel, const void* data, std::size_t size, double t_s) {
  bool ok = true;
  bool known = true;
  if (channel == bus::kObservationChannel) {
    on_observation(data, size, t_s, ok);
  } else if (channel == bus::kProjectionChannel) {
    pinball_lcm::lcmt_pinball_projection m{};
    ok = decode(data, size, m) && bus::valid_projection(m);
    if (ok) no_projection_reason_ = m.valid ? 0 : m.reason;
    if (ok && m.valid) {
      projection_ = m;
      projection_t_s_ = t_s;
      // The projection starts from its observation: normally the newest sighting.
      projection_origin_ = trail_.empty() ? Vec2(m.impact_x_m, m.impact_y_m) : trail_.back().p_board;
      for (auto it = trail_.rbegin(); it != trail_.rend(); ++it) {
        if (it->seq == m.observation_seq) {
          projection_origin_ = it->p_board;
          break;
        }
      }
    } else if (ok) {
      projection_.reset();
    }
  } else if (channel == bus::kFlipperCommandChannel) {
    pinball_lcm::lcmt_pinball_flipper_command m{};
    ok = decode(data, size, m) && bus::valid_flipper_command(m);
    if (ok) {
      commands_.push_back({t_s, m.flipper, m.energize != 0, m.cause});
      while (commands_.size() > options_.command_history) commands_.pop_front();
    }
  } else if (channel == bus::kDriverStatusChannel) {
    pinball_lcm::lcmt_pinball_driver_status m{};
    ok = decode(data, size, m) && m.utime >= 0;
    if (ok) driver_status_ = m;
  } else if (channel == bus::kStatsChannel) {
    pinball_lcm::lcmt_pinball_daemon_stats m{};
    ok = decode(data, size, m) && m.num_stages >= 0;
    if (ok) stats_ = std::move(m);
  } else if (channel == bus::kGameChannel) {
    pinball_lcm::lcmt_pinball_game_event m{};
    ok = decode(data, size, m) && std::isfinite(m.points);
    if (ok) {
      if (m.kind == pinball_lcm::lcmt_pinball_game_event::KIND_LAUNCH) {
        ball_ = m.ball;
        ball_points_ = 0.0;
      } else if (m.kind == pinball_lcm::lcmt_pinball_game_event::KIND_SCORE) {
        ball_points_ += m.points;
      } else {
        ball_points_ = m.points;
      }
    }
  } else {
    known = false;
  }
  if (!known) return true;
  if (!ok) {
    ++malformed_;
    return false;
  }
  ++messages_;
  now_s_ = std::max(now_s_, t_s);
  forget_before(now_s_);
  return true;
}

void ViewState::on_observation(const void* data, std::size_t size, double t_s, bool& ok) {
  pinball_lcm::lcmt_pinball_observation m{};
  bool found = false;
  track::Observation o;
  track::ContactSensors contacts;
  ok = bus::decode_observation(data, size, m) != bus::ObservationLayout::kMalformed &&
       bus::from_lcm_observation(m, found, o, contacts);
  if (!ok) return;
  // A frame number further on than even a 10 kHz camera gets in the time between is a damaged number,
  // not lost frames: one such message had shown 999999999999470 frames dropped.
  constexpr double kFastestCamera_hz = 1e4;
  if (last_seq_ >= 0 && m.seq > last_seq_ + 1 &&
      static_cast<double>(m.seq - last_seq_ - 1) > (t_s - last_seq_t_s_) * kFastestCamera_hz + 1.0) {
    ok = false;
    return;
  }
  ++observations_;
  if (last_seq_ >= 0 && m.seq > last_seq_ + 1) seq_gaps_ += m.seq - last_seq_ - 1;
  last_seq_ = m.seq;
  last_seq_t_s_ = t_s;
  last_found_ = found;
  frame_times_s_.push_back(t_s);
  if (found) trail_.push_back({t_s, o.p_board, m.seq});
}

void ViewState::forget_before(double now_s) {
  while (!trail_.empty() && trail_.front().t_s < now_s - options_.trail_s) trail_.pop_front();
  while (!frame_times_s_.empty() && frame_times_s_.front() < now_s - options_.rate_window_s) {
    frame_times_s_.pop_front();
  }
}

std::optional<Sighting> ViewState::ball() const {
  if (!last_found_ || trail_.empty()) return std::nullopt;
  return trail_.back();
}

std::optional<SentCommand> ViewState::flashing_command(int flipper) const {
  for (auto it = commands_.rbegin(); it != commands_.rend(); ++it) {
    if (it->t_s < now_s_ - options_.command_flash_s) break;
    if (it->flipper == flipper || it->flipper == -1) return *it;
  }
  return std::nullopt;
}

bool ViewState::coil_on(int driver) const {
  return driver_status_ && driver >= 0 && driver < 16 && ((driver_status_->coils_on >> driver) & 1) != 0;
}

DaemonFigures ViewState::figures() const {
  DaemonFigures f;
  if (frame_times_s_.size() >= 2) {
    const double span_s = frame_times_s_.back() - frame_times_s_.front();
    if (span_s > 0.0) f.frame_rate_hz = static_cast<double>(frame_times_s_.size() - 1) / span_s;
  }
  f.frames_dropped = seq_gaps_;
  if (stats_) {
    f.has_stats = true;
    f.frames_dropped = std::max(f.frames_dropped, stats_->frames_dropped);
    f.camera_stalls = stats_->camera_stalls;
    for (int i = 0; i < stats_->num_stages; ++i) {
      if (stats_->stage[static_cast<std::size_t>(i)] == "frame->can_written" &&
          stats_->count[static_cast<std::size_t>(i)] > 0) {
        f.frame_to_can_p99_us = stats_->p99_us[static_cast<std::size_t>(i)];
      }
    }
  }
  return f;
}

}  // namespace pinball::view
