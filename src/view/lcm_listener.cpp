#include "pinball/view/lcm_listener.h"

#include <lcm/lcm.h>

#include <stdexcept>

#include "pinball/bus/channels.h"
#include "pinball/bus/lcm_log_format.h"
#include "pinball/bus/lcm_bus.h"
#include "pinball/bus/message_convert.h"

namespace pinball::view {
namespace {

void on_lcm_message(const lcm_recv_buf_t* rbuf, const char* channel, void* user) {
  static_cast<LcmListener*>(user)->on_message(channel, rbuf->data, rbuf->data_size, rbuf->recv_utime);
}

}  // namespace

LcmListener::LcmListener(const std::string& url, ViewState& state) : state_(state) {
  if (const std::string problem = bus::lcm_url_problem(url); !problem.empty()) {
    throw std::runtime_error("lcm: " + problem);
  }
  // liblcm plays a damaged log by the lengths it reads (a segmentation fault): checked as every reader checks it.
  if (const std::optional<std::string> log = bus::lcm_log_source(url)) bus::require_lcm_log(*log);
  lcm_ = lcm_create(url.c_str());
  if (lcm_ == nullptr) throw std::runtime_error("lcm: cannot open '" + url + "'");
  try {
    bus::require_lcm_connected(lcm_, url);
  } catch (...) {
    lcm_destroy(lcm_);
    throw;
  }
  for (const char* channel : bus::kDaemonChannels) {
    if (lcm_subscribe(lcm_, channel, &on_lcm_message, this) == nullptr) {
      lcm_destroy(lcm_);
      throw std::runtime_error("lcm: cannot subscribe to " + std::string(channel) + " on '" + url + "'");
    }
  }
}

LcmListener::~LcmListener() { lcm_destroy(lcm_); }

int LcmListener::poll(int timeout_ms, double stop_at_s) {
  // lcm_handle_timeout handles one message; drain what waits (bounded, so a
  // flood cannot starve the window) after waiting at most timeout_ms for the first.
  constexpr int kMaxPerPoll = 20000;
  handled_in_poll_ = 0;
  for (int i = 0; i < kMaxPerPoll; ++i) {
    const int r = bus::handle_lcm_timeout(lcm_, i == 0 ? timeout_ms : 0);
    if (r < 0) return handled_in_poll_ > 0 ? handled_in_poll_ : -1;
    if (r == 0) break;
    // A log played at full speed arrives in one burst: stop where the caller looks.
    if (stop_at_s >= 0.0 && received_ > 0 && state_.now_s() >= stop_at_s) break;
  }
  return handled_in_poll_;
}

void LcmListener::on_message(const char* channel, const void* data, std::size_t size, std::int64_t recv_utime) {
  // The daemon's own clock (each message's utime) when the message has one,
  // so the view's times do not depend on the network's delays.
  const std::int64_t utime = bus::encoded_utime(data, size).value_or(recv_utime);
  if (first_utime_ < 0) first_utime_ = utime;
  ++received_;
  ++handled_in_poll_;
  state_.apply(channel, data, size, 1e-6 * static_cast<double>(utime - first_utime_));
}

}  // namespace pinball::view
