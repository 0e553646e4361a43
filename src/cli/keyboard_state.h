#pragma once
// Which of the player's keys are held down right now, read from the X server
// (XQueryKeymap) for `pinball play`. OpenCV's waitKey reports presses only,
// with the keyboard's auto-repeat, never releases, so it cannot tell a held
// flipper button from a tap; the X server's key map can. Without X11 (a build
// without libx11-dev, or a display that refuses the connection) available()
// is false and the window falls back to waitKey presses (play_window.cpp).

#include <memory>

#include "pinball/simlab/human_play.h"

namespace pinball::cli {

/// The true key-down state of the play keys (docs/play.md, "Keys").
class KeyboardState {
 public:
  /// Connects to $DISPLAY; available() says whether it worked.
  KeyboardState();
  ~KeyboardState();
  KeyboardState(const KeyboardState&) = delete;
  KeyboardState& operator=(const KeyboardState&) = delete;

  /// True when the key map can be read.
  bool available() const;
  /// Reads the key map once; then down() answers from it.
  void poll();
  /// True while any key bound to `key` was down at the last poll().
  bool down(simlab::Key key) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace pinball::cli
