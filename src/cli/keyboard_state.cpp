#include "keyboard_state.h"

#include <vector>

#ifdef PINBALL_HAVE_X11
#include <X11/Xlib.h>
#include <X11/keysym.h>
#endif

namespace pinball::cli {

#ifdef PINBALL_HAVE_X11

struct KeyboardState::Impl {
  Display* display = nullptr;
  char keys[32] = {};
  std::vector<KeyCode> codes[3];  // per simlab::Key

  bool is_down(KeyCode code) const { return code != 0 && (keys[code / 8] & (1 << (code % 8))) != 0; }
};

KeyboardState::KeyboardState() : impl_(std::make_unique<Impl>()) {
  impl_->display = XOpenDisplay(nullptr);
  if (impl_->display == nullptr) return;
  // The bindings of docs/play.md: left Z, left Shift, Left arrow; right M, '/',
  // right Shift, Right arrow; launch Space, Return, Down arrow.
  const KeySym left[] = {XK_z, XK_Shift_L, XK_Left};
  const KeySym right[] = {XK_m, XK_slash, XK_Shift_R, XK_Right};
  const KeySym launch[] = {XK_space, XK_Return, XK_KP_Enter, XK_Down};
  auto bind = [&](simlab::Key k, const KeySym* syms, std::size_t n) {
    for (std::size_t i = 0; i < n; ++i) {
      const KeyCode code = XKeysymToKeycode(impl_->display, syms[i]);
      if (code != 0) impl_->codes[static_cast<int>(k)].push_back(code);
    }
  };
  bind(simlab::Key::kLeftFlipper, left, std::size(left));
  bind(simlab::Key::kRightFlipper, right, std::size(right));
  bind(simlab::Key::kLaunch, launch, std::size(launch));
}

KeyboardState::~KeyboardState() {
  if (impl_->display != nullptr) XCloseDisplay(impl_->display);
}

bool KeyboardState::available() const { return impl_->display != nullptr; }

void KeyboardState::poll() {
  if (impl_->display != nullptr) XQueryKeymap(impl_->display, impl_->keys);
}

bool KeyboardState::down(simlab::Key key) const {
  for (const KeyCode code : impl_->codes[static_cast<int>(key)]) {
    if (impl_->is_down(code)) return true;
  }
  return false;
}

#else  // no X11 in this build: waitKey presses only

struct KeyboardState::Impl {};
KeyboardState::KeyboardState() = default;
KeyboardState::~KeyboardState() = default;
bool KeyboardState::available() const { return false; }
void KeyboardState::poll() {}
bool KeyboardState::down(simlab::Key) const { return false; }

#endif

}  // namespace pinball::cli
