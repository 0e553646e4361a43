#pragma once
// The live side of `pinball view`: subscribes to the daemon's channels on an
// LCM URL (udpm:// on the lab's network, or any provider liblcm has, e.g.
// file:// to play a log through liblcm itself) and feeds what arrives into a
// ViewState, stamped with each message's utime (the daemon's clock; seconds
// since the first message). The window's thread polls it with a short timeout between frames:
// nothing here blocks for long or runs a thread of its own.

#include <cstdint>
#include <memory>
#include <string>

#include "pinball/view/view_state.h"

typedef struct _lcm_t lcm_t;  // NOLINT(bugprone-reserved-identifier): liblcm's own name (lcm/lcm.h)

namespace pinball::view {

class LcmListener {
 public:
  /// Opens `url` and subscribes to the daemon's channels. Throws
  /// std::runtime_error naming the URL when LCM cannot open it.
  LcmListener(const std::string& url, ViewState& state);
  ~LcmListener();
  LcmListener(const LcmListener&) = delete;
  LcmListener& operator=(const LcmListener&) = delete;

  /// Handles what arrives within `timeout_ms`: >= 0 messages handled, -1 when
  /// the provider has ended (a file:// log played out) or failed. With
  /// `stop_at_s` >= 0 it stops once the view's time reaches it.
  int poll(int timeout_ms, double stop_at_s = -1.0);
  /// Messages received so far.
  std::uint64_t received() const { return received_; }

  /// For liblcm's callback.
  void on_message(const char* channel, const void* data, std::size_t size, std::int64_t recv_utime);

 private:
  lcm_t* lcm_ = nullptr;
  ViewState& state_;
  std::int64_t first_utime_ = -1;
  std::uint64_t received_ = 0;
  int handled_in_poll_ = 0;
};

}  // namespace pinball::view
